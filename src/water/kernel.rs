//! The per-pixel water kernels, written once for `f64` and `f32` lanes (Lee et al. 1998, 1999,
//! with SAMBUCA's attenuation factors; see [`super::WaterModel::evaluate`] for the equations).
//!
//! [`super::WaterModel::rrs_above_into`] runs them on `f64`, the single-precision setting
//! ([`super::SingleWater`]) on `f32`. Every slice is re-sliced to one length so that the loops
//! carry no bounds checks and vectorise; the exponential is branch-free for the same reason
//! ([`super::fast_exp`], or its `f32` counterpart). For `f64` the expression tree is the one the
//! kernels always had, so the results are the same bits.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// A lane type the kernels run on.
pub(super) trait Lane:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// A constant of the equations (exact for `f64`, rounded to nearest for `f32`).
    fn c(x: f64) -> Self;
    fn sqrt(self) -> Self;
    /// A vectorisable e^x.
    fn exp(self) -> Self;
    /// The value as the `f64` the callers store.
    fn widen(self) -> f64;
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
    fn exp(self) -> Self {
        super::fast_exp(self)
    }
    #[inline(always)]
    fn widen(self) -> f64 {
        self
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
    fn exp(self) -> Self {
        super::single::exp_f32(self)
    }
    #[inline(always)]
    fn widen(self) -> f64 {
        f64::from(self)
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

/// Rrs(0⁺) from rrs(0⁻) (Lee et al. 2002), as [`super::rrs_above_from_below`].
#[inline(always)]
fn above<T: Lane>(rrs: T) -> f64 {
    (T::c(0.52) * rrs / (T::c(1.0) - T::c(1.7) * rrs)).widen()
}

/// Optically deep Rrs into `out` (one per wavelength).
#[inline(always)]
pub(super) fn deep<T: Lane>(k: &Spectra<'_, T>, out: &mut [f64]) {
    let n = out.len();
    let (a_w, bb_w, a_ph, a_cdom, a_nap, bb_ph, bb_nap) =
        (&k.a_w[..n], &k.bb_w[..n], &k.a_ph[..n], &k.a_cdom[..n], &k.a_nap[..n], &k.bb_ph[..n], &k.bb_nap[..n]);
    let (chl, cdom, nap) = (k.chl, k.cdom, k.nap);
    for i in 0..n {
        let a = a_w[i] + chl * a_ph[i] + cdom * a_cdom[i] + nap * a_nap[i];
        let bb = bb_w[i] + chl * bb_ph[i] + nap * bb_nap[i];
        let u = bb / (a + bb);
        out[i] = above((T::c(0.084) + T::c(0.17) * u) * u);
    }
}

/// Shallow-water Rrs into `out` (Lee et al. 1999 eq. 5 with the SAMBUCA attenuation factors):
/// the bottom at `depth_m` with reflectance `rb`, the under-water sun and view paths
/// 1/cos θ_w = `inv_cos_w`, 1/cos θ_o = `inv_cos_o`.
#[inline(always)]
pub(super) fn shallow<T: Lane>(k: &Spectra<'_, T>, depth_m: T, inv_cos_w: T, inv_cos_o: T, rb: &[T], out: &mut [f64]) {
    let n = out.len();
    let (a_w, bb_w, a_ph, a_cdom, a_nap, bb_ph, bb_nap, rb) = (
        &k.a_w[..n],
        &k.bb_w[..n],
        &k.a_ph[..n],
        &k.a_cdom[..n],
        &k.a_nap[..n],
        &k.bb_ph[..n],
        &k.bb_nap[..n],
        &rb[..n],
    );
    let (chl, cdom, nap) = (k.chl, k.cdom, k.nap);
    let inv_pi = T::c(1.0 / std::f64::consts::PI);
    for i in 0..n {
        let a = a_w[i] + chl * a_ph[i] + cdom * a_cdom[i] + nap * a_nap[i];
        let bb = bb_w[i] + chl * bb_ph[i] + nap * bb_nap[i];
        let kappa = a + bb;
        let u = bb / kappa;
        let kh = kappa * depth_m;
        let du_c = T::c(1.03) * (T::c(1.0) + T::c(2.4) * u).sqrt();
        let du_b = T::c(1.04) * (T::c(1.0) + T::c(5.4) * u).sqrt();
        let rrs_dp = (T::c(0.084) + T::c(0.17) * u) * u;
        let column = rrs_dp * (T::c(1.0) - (-(inv_cos_w + du_c * inv_cos_o) * kh).exp());
        let bottom = rb[i] * inv_pi * (-(inv_cos_w + du_b * inv_cos_o) * kh).exp();
        out[i] = above(column + bottom);
    }
}
