//! The per-pixel water kernels, written once for `f64` and `f32` lanes (Lee et al. 1998, 1999,
//! with SAMBUCA's attenuation factors; see [`super::WaterModel::evaluate`] for the equations).
//!
//! [`super::WaterModel::rrs_above_into`] runs them on `f64`, the single-precision setting
//! ([`super::SingleWater`]) on `f32`, both through [`crate::simd::widest`]. Every slice is
//! re-sliced to one length so that the loops carry no bounds checks and vectorise; the
//! exponential is branch-free for the same reason (`fast_exp`, or its `f32` counterpart), and
//! where the level has FMA every a·b + c is one fused multiply-add (one rounding instead of two,
//! and a shorter chain of dependent instructions: the loop is bound by that chain's latency, not
//! by arithmetic; [`crate::simd::mad`]).
//!
//! The loops also check, without a branch, that every a and bb is positive (and for the bottom
//! that 0 ≤ ρ_b ≤ 1): the checks' passes of their own took 11 % of a single-precision call
//! (perf), against the kernel's 81 %. When a check fails the caller builds the message (the
//! output is then not used).

use std::ops::{Add, Div, Mul, Neg, Sub};

use crate::simd::{Level, MulAdd, mad};

/// A lane type the kernels run on.
pub(super) trait Lane:
    MulAdd
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
    /// A vectorisable e^x, its steps fused multiply-adds where `L` has FMA.
    fn exp<L: Level>(self) -> Self;
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
    fn exp<L: Level>(self) -> Self {
        super::fastmath::exp::<L>(self)
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
    fn exp<L: Level>(self) -> Self {
        super::single::exp_f32::<L>(self)
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

impl<'a, T: Copy> Spectra<'a, T> {
    /// The first `n` wavelengths: every slice re-sliced to one length, so that the loop over them
    /// carries no bounds checks and vectorises (panics if a spectrum is shorter).
    #[inline(always)]
    fn first(&self, n: usize) -> Self {
        self.range(0..n)
    }

    /// The wavelengths in `range`, every slice re-sliced alike (panics if a spectrum is shorter).
    #[inline(always)]
    fn range(&self, range: std::ops::Range<usize>) -> Self {
        Spectra {
            a_w: &self.a_w[range.clone()],
            bb_w: &self.bb_w[range.clone()],
            a_ph: &self.a_ph[range.clone()],
            a_cdom: &self.a_cdom[range.clone()],
            a_nap: &self.a_nap[range.clone()],
            bb_ph: &self.bb_ph[range.clone()],
            bb_nap: &self.bb_nap[range],
            ..*self
        }
    }
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
    fn run<L: Level>(self) -> bool {
        match self.floor {
            Floor::Deep => deep::<T, L>(self.spectra, self.out),
            Floor::Shallow { depth_m, inv_cos_w, inv_cos_o, rb } => {
                shallow::<T, L>(self.spectra, depth_m, inv_cos_w, inv_cos_o, rb, self.out)
            }
        }
    }
}

/// Total absorption a = a_w + chl·a*_ph + cdom·a*_CDOM + nap·a*_NAP (m⁻¹; Lee et al. 1999 eq. 2,
/// SAMBUCA's form).
#[inline(always)]
pub(super) fn absorption<T: Lane, L: Level>(k: &Spectra<'_, T>, i: usize) -> T {
    mad::<L, T>(k.nap, k.a_nap[i], mad::<L, T>(k.cdom, k.a_cdom[i], mad::<L, T>(k.chl, k.a_ph[i], k.a_w[i])))
}

/// Total backscattering bb = bb_w + chl·bb*_ph + nap·bb*_NAP (m⁻¹).
#[inline(always)]
pub(super) fn backscattering<T: Lane, L: Level>(k: &Spectra<'_, T>, i: usize) -> T {
    mad::<L, T>(k.nap, k.bb_nap[i], mad::<L, T>(k.chl, k.bb_ph[i], k.bb_w[i]))
}

/// Rrs(0⁺) = 0.52·rrs/(1 − 1.7·rrs) (Lee et al. 2002, as [`super::rrs_above_from_below`]) from
/// rrs(0⁻) given as a ratio `p`/κ²: 0.52·p/(κ² − 1.7·p), one division for the whole pixel's
/// chain (u = bb/κ is never divided out; see [`deep`]).
#[inline(always)]
fn above<T: Lane, L: Level>(p: T, kappa2: T) -> T {
    T::c(0.52) * p / mad::<L, T>(T::c(-1.7), p, kappa2)
}

/// Both positive (false for NaN).
#[inline(always)]
fn positive<T: Lane>(a: T, bb: T) -> bool {
    (a > T::c(0.0)) & (bb > T::c(0.0))
}

/// Optically deep Rrs into `out` (one per wavelength); whether every a and bb was positive.
///
/// rrs_dp = (0.084 + 0.17u)·u with u = bb/κ (Lee et al. 1999 eq. 4) is carried as
/// κ²·rrs_dp = (0.084κ + 0.17bb)·bb, so that a wavelength costs one division (in [`above`])
/// instead of two: perf put this loop's time on its divisions' latency.
#[inline(always)]
fn deep<T: Lane, L: Level>(k: &Spectra<'_, T>, out: &mut [T]) -> bool {
    let n = out.len();
    let k = k.first(n);
    let mad = mad::<L, T>;
    let mut ok = true;
    for i in 0..n {
        let (a, bb) = (absorption::<T, L>(&k, i), backscattering::<T, L>(&k, i));
        ok &= positive(a, bb);
        let kappa = a + bb;
        let p = mad(T::c(0.084), kappa, T::c(0.17) * bb) * bb;
        out[i] = above::<T, L>(p, kappa * kappa);
    }
    ok
}

/// Wavelengths per block of [`shallow`]'s passes (its four work arrays: 2 kB in `f64`).
const BLOCK: usize = 64;

/// Shallow-water Rrs into `out` (Lee et al. 1999 eq. 5 with the SAMBUCA attenuation factors);
/// whether every a and bb was positive and every ρ_b in [0, 1].
///
/// With u = bb/κ, the attenuation exponents (D_C/μo + 1/μw)·κH, D_C = 1.03·√(1 + 2.4u), are
/// carried as (1.03·√(κ(κ + 2.4bb))/μo + κ/μw)·H (and D_B's alike), and rrs as p/κ² with
/// p = κ²·rrs_dp·(1 − e_C) + κ²·ρ_b/π·e_B: the same quantities with no division until [`above`]
/// (one per wavelength instead of two; the same formulas as [`super::WaterModel::evaluate`],
/// rounded otherwise: the test below bounds the difference).
///
/// A wavelength's operations form one long chain (IOPs → square roots → exponentials → the
/// division, some 140 cycles of latency), and one loop over them all kept only about two
/// wavelength vectors in flight: the loop ran at about half of what its instructions need of
/// the CPU's units. So the work runs in blocks of [`BLOCK`] wavelengths, in three passes (the
/// roots and the exponents' arguments; the exponentials; the combination and the division),
/// each a short chain that the CPU overlaps across wavelengths. Each wavelength goes through
/// the same operations in the same order as in one loop, so the result is the same bits.
#[inline(always)]
fn shallow<T: Lane, L: Level>(
    k: &Spectra<'_, T>,
    depth_m: T,
    inv_cos_w: T,
    inv_cos_o: T,
    rb: &[T],
    out: &mut [T],
) -> bool {
    let n = out.len();
    let rb = &rb[..n];
    let inv_pi = T::c(1.0 / std::f64::consts::PI);
    // The constants of D_C and D_B folded into the view path and the depth: −1.03·H/μo, −H/μw.
    let (c_view, b_view, sun) =
        (T::c(-1.03) * inv_cos_o * depth_m, T::c(-1.04) * inv_cos_o * depth_m, -(inv_cos_w * depth_m));
    let mad = mad::<L, T>;
    let mut ok = true;
    let zero = T::c(0.0);
    let (mut e_c, mut e_b, mut p_dp, mut kappa2) = ([zero; BLOCK], [zero; BLOCK], [zero; BLOCK], [zero; BLOCK]);
    for start in (0..n).step_by(BLOCK) {
        let end = (start + BLOCK).min(n);
        let len = end - start;
        let k = k.range(start..end);
        let (rb, out) = (&rb[start..end], &mut out[start..end]);
        let (e_c, e_b, p_dp, kappa2) = (&mut e_c[..len], &mut e_b[..len], &mut p_dp[..len], &mut kappa2[..len]);
        // The IOPs, the roots and the exponents' arguments.
        for i in 0..len {
            let (a, bb) = (absorption::<T, L>(&k, i), backscattering::<T, L>(&k, i));
            ok &= positive(a, bb) & (rb[i] >= T::c(0.0)) & (rb[i] <= T::c(1.0));
            let kappa = a + bb;
            let k2 = kappa * kappa;
            // κ·√(1 + 2.4u) = √(κ² + 2.4·κ·bb), and 5.4 alike.
            let kbb = kappa * bb;
            let root_c = mad(T::c(2.4), kbb, k2).sqrt();
            let root_b = mad(T::c(5.4), kbb, k2).sqrt();
            p_dp[i] = mad(T::c(0.084), kappa, T::c(0.17) * bb) * bb;
            e_c[i] = mad(c_view, root_c, sun * kappa);
            e_b[i] = mad(b_view, root_b, sun * kappa);
            kappa2[i] = k2;
        }
        for i in 0..len {
            (e_c[i], e_b[i]) = (e_c[i].exp::<L>(), e_b[i].exp::<L>());
        }
        // κ²·(rrs_dp·(1 − e_c) + ρ_b/π·e_b), and Rrs.
        for i in 0..len {
            let p = mad(rb[i] * inv_pi * kappa2[i], e_b[i], mad(-p_dp[i], e_c[i], p_dp[i]));
            out[i] = above::<T, L>(p, kappa2[i]);
        }
    }
    ok
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{Baseline, Kernel};

    /// The baseline build multiplies and adds apart, the vector builds fuse: the two agree to
    /// the roundings that fusing saves — measured 5.4·10⁻¹⁶ (f64) and 2.8·10⁻⁷ (f32) relative
    /// over these spectra, allowed 4·10⁻¹⁵ and 2·10⁻⁶ (the bounds of the f64 path against
    /// `evaluate` and of f32 against f64).
    #[test]
    fn the_baseline_and_the_widest_builds_agree_to_their_roundings() {
        fn check<T: Lane>(narrow: impl Fn(f64) -> T, widen: impl Fn(T) -> f64, tolerance: f64) {
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
                let (mut baseline, mut widest) = (vec![zero; n], vec![zero; n]);
                assert!(Evaluation { spectra: &k, floor: floor(), out: &mut baseline }.run::<Baseline>());
                assert!(crate::simd::widest(Evaluation { spectra: &k, floor: floor(), out: &mut widest }));
                let worst = baseline
                    .iter()
                    .zip(&widest)
                    .map(|(&a, &b)| ((widen(b) - widen(a)) / widen(a)).abs())
                    .fold(0.0, f64::max);
                assert!(worst < tolerance, "shallow {shallow}: {worst:e}");
            }
        }
        check(|x| x, |x| x, 4e-15);
        check(|x| x as f32, f64::from, 2e-6);
    }
}
