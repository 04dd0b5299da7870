//! The per-pixel water kernels, written once for `f64` and `f32` lanes (Lee et al. 1998, 1999,
//! with SAMBUCA's attenuation factors; see [`super::WaterModel::evaluate`] for the equations).
//!
//! [`super::WaterModel::rrs_above_into`] runs them on `f64`, the single-precision setting
//! ([`super::SingleWater`]) on `f32`, both through [`crate::simd::widest`]. Every slice is
//! re-sliced to one length so that the loops carry no bounds checks and vectorise; the
//! exponential is branch-free for the same reason (`fast_exp_fused`, or its `f32` counterpart),
//! and every a·b + c is one fused multiply-add (one rounding instead of two, and a shorter chain
//! of dependent instructions: the loop is bound by that chain's latency, not by arithmetic).
//!
//! The loops also check, without a branch, that every a and bb is positive (and for the bottom
//! that 0 ≤ ρ_b ≤ 1): a pass of its own over the wavelengths cost a fifth of the
//! single-precision kernel's time. When a check fails the caller builds the message (the
//! output is then not used).

use std::ops::{Add, Div, Mul, Neg, Sub};

/// A lane type the kernels run on.
pub(super) trait Lane:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// A constant of the equations (exact for `f64`, rounded to nearest for `f32`).
    fn c(x: f64) -> Self;
    fn sqrt(self) -> Self;
    /// self·b + c, fused (one rounding; one instruction where the kernel runs with FMA, libm's
    /// exact `fma` on the portable build).
    fn mad(self, b: Self, c: Self) -> Self;
    /// A vectorisable e^x.
    fn exp(self) -> Self;
}

impl Lane for f64 {
    #[inline(always)]
    fn c(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn mad(self, b: Self, c: Self) -> Self {
        self.mul_add(b, c)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        super::fastmath::fast_exp_fused(self)
    }
}

impl Lane for f32 {
    #[inline(always)]
    fn c(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn mad(self, b: Self, c: Self) -> Self {
        self.mul_add(b, c)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        super::single::exp_f32(self)
    }
}

/// A SIOP set's spectra on the grid, and the column's concentrations.
pub(super) struct Spectra<'a, T> {
    pub a_w: &'a [T],
    pub bb_w: &'a [T],
    pub a_ph: &'a [T],
    pub a_cdom: &'a [T],
    pub a_nap: &'a [T],
    pub bb_ph: &'a [T],
    pub bb_nap: &'a [T],
    pub chl: T,
    pub cdom: T,
    pub nap: T,
}

/// The bottom of one evaluation: optically deep, or at `depth_m` with reflectance `rb` (one per
/// wavelength), seen along the under-water sun and view paths 1/cos θ_w = `inv_cos_w`,
/// 1/cos θ_o = `inv_cos_o`.
pub(super) enum Floor<'a, T> {
    Deep,
    Shallow { depth_m: T, inv_cos_w: T, inv_cos_o: T, rb: &'a [T] },
}

/// One evaluation of Rrs above the surface into `out` (one per wavelength), as a
/// [`crate::simd::Kernel`]: its output is whether every a and bb was positive and every ρ_b in
/// [0, 1] (when not, `out` holds no answer).
pub(super) struct Evaluation<'s, 'o, T> {
    pub spectra: &'s Spectra<'s, T>,
    pub floor: Floor<'s, T>,
    pub out: &'o mut [T],
}

impl<T: Lane> crate::simd::Kernel for Evaluation<'_, '_, T> {
    type Output = bool;

    #[inline(always)]
    fn run(self) -> bool {
        match self.floor {
            Floor::Deep => deep(self.spectra, self.out),
            Floor::Shallow { depth_m, inv_cos_w, inv_cos_o, rb } => {
                shallow(self.spectra, depth_m, inv_cos_w, inv_cos_o, rb, self.out)
            }
        }
    }
}

/// Total absorption a = a_w + chl·a*_ph + cdom·a*_CDOM + nap·a*_NAP (m⁻¹; Lee et al. 1999 eq. 2,
/// SAMBUCA's form).
#[inline(always)]
pub(super) fn absorption<T: Lane>(k: &Spectra<'_, T>, i: usize) -> T {
    k.nap.mad(k.a_nap[i], k.cdom.mad(k.a_cdom[i], k.chl.mad(k.a_ph[i], k.a_w[i])))
}

/// Total backscattering bb = bb_w + chl·bb*_ph + nap·bb*_NAP (m⁻¹).
#[inline(always)]
pub(super) fn backscattering<T: Lane>(k: &Spectra<'_, T>, i: usize) -> T {
    k.nap.mad(k.bb_nap[i], k.chl.mad(k.bb_ph[i], k.bb_w[i]))
}

/// Rrs(0⁺) from rrs(0⁻) (Lee et al. 2002), as [`super::rrs_above_from_below`].
#[inline(always)]
fn above<T: Lane>(rrs: T) -> T {
    T::c(0.52) * rrs / T::c(-1.7).mad(rrs, T::c(1.0))
}

/// Both positive (false for NaN).
#[inline(always)]
fn positive<T: Lane>(a: T, bb: T) -> bool {
    (a > T::c(0.0)) & (bb > T::c(0.0))
}

/// Optically deep Rrs into `out` (one per wavelength); whether every a and bb was positive.
#[inline(always)]
fn deep<T: Lane>(k: &Spectra<'_, T>, out: &mut [T]) -> bool {
    let n = out.len();
    let k = Spectra {
        a_w: &k.a_w[..n],
        bb_w: &k.bb_w[..n],
        a_ph: &k.a_ph[..n],
        a_cdom: &k.a_cdom[..n],
        a_nap: &k.a_nap[..n],
        bb_ph: &k.bb_ph[..n],
        bb_nap: &k.bb_nap[..n],
        ..*k
    };
    let mut ok = true;
    for i in 0..n {
        let (a, bb) = (absorption(&k, i), backscattering(&k, i));
        ok &= positive(a, bb);
        let u = bb / (a + bb);
        out[i] = above(T::c(0.17).mad(u, T::c(0.084)) * u);
    }
    ok
}

/// Shallow-water Rrs into `out` (Lee et al. 1999 eq. 5 with the SAMBUCA attenuation factors);
/// whether every a and bb was positive and every ρ_b in [0, 1].
#[inline(always)]
fn shallow<T: Lane>(k: &Spectra<'_, T>, depth_m: T, inv_cos_w: T, inv_cos_o: T, rb: &[T], out: &mut [T]) -> bool {
    let n = out.len();
    let k = Spectra {
        a_w: &k.a_w[..n],
        bb_w: &k.bb_w[..n],
        a_ph: &k.a_ph[..n],
        a_cdom: &k.a_cdom[..n],
        a_nap: &k.a_nap[..n],
        bb_ph: &k.bb_ph[..n],
        bb_nap: &k.bb_nap[..n],
        ..*k
    };
    let rb = &rb[..n];
    let inv_pi = T::c(1.0 / std::f64::consts::PI);
    let mut ok = true;
    for i in 0..n {
        let (a, bb) = (absorption(&k, i), backscattering(&k, i));
        ok &= positive(a, bb) & (rb[i] >= T::c(0.0)) & (rb[i] <= T::c(1.0));
        let kappa = a + bb;
        let u = bb / kappa;
        let kh = kappa * depth_m;
        let du_c = T::c(1.03) * T::c(2.4).mad(u, T::c(1.0)).sqrt();
        let du_b = T::c(1.04) * T::c(5.4).mad(u, T::c(1.0)).sqrt();
        let rrs_dp = T::c(0.17).mad(u, T::c(0.084)) * u;
        // rrs_dp·(1 − e_c) + ρ_b/π·e_b
        let e_c = (-du_c.mad(inv_cos_o, inv_cos_w) * kh).exp();
        let e_b = (-du_b.mad(inv_cos_o, inv_cos_w) * kh).exp();
        out[i] = above((rb[i] * inv_pi).mad(e_b, (-rrs_dp).mad(e_c, rrs_dp)));
    }
    ok
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::Kernel;

    /// Every a·b + c is fused at every level (libm's exact `fma` on the portable build), and
    /// division and square root are exactly rounded, so the portable build and the widest one
    /// this CPU runs give the same bits, in both precisions.
    #[test]
    fn the_portable_and_the_widest_builds_agree_bit_for_bit() {
        fn check<T: Lane + std::fmt::Debug>(narrow: impl Fn(f64) -> T) {
            let n = 451;
            let spectrum = |scale: f64, phase: f64| -> Vec<T> {
                (0..n).map(|i| narrow(scale * (1.1 + (i as f64 * 0.037 + phase).sin()))).collect()
            };
            let (a_w, bb_w, a_ph) = (spectrum(0.3, 0.0), spectrum(0.002, 1.0), spectrum(0.02, 2.0));
            let (a_cdom, a_nap, bb_ph, bb_nap) =
                (spectrum(0.4, 3.0), spectrum(0.03, 4.0), spectrum(0.001, 5.0), spectrum(0.01, 6.0));
            let rb = spectrum(0.15, 0.5);
            let k = Spectra {
                a_w: &a_w,
                bb_w: &bb_w,
                a_ph: &a_ph,
                a_cdom: &a_cdom,
                a_nap: &a_nap,
                bb_ph: &bb_ph,
                bb_nap: &bb_nap,
                chl: narrow(2.5),
                cdom: narrow(0.3),
                nap: narrow(4.0),
            };
            let zero = narrow(0.0);
            for shallow in [false, true] {
                let floor = || {
                    if shallow {
                        Floor::Shallow {
                            depth_m: narrow(3.7),
                            inv_cos_w: narrow(1.1),
                            inv_cos_o: narrow(1.02),
                            rb: &rb,
                        }
                    } else {
                        Floor::Deep
                    }
                };
                let (mut portable, mut widest) = (vec![zero; n], vec![zero; n]);
                assert!(Evaluation { spectra: &k, floor: floor(), out: &mut portable }.run());
                assert!(crate::simd::widest(Evaluation { spectra: &k, floor: floor(), out: &mut widest }));
                assert_eq!(format!("{portable:?}"), format!("{widest:?}"), "shallow {shallow}");
            }
        }
        check(|x| x);
        check(|x| x as f32);
    }
}
