//! A branch-free `exp` that the compiler can vectorise, for the water model's inner loop.
//!
//! One formula at each instruction-set level: [`fast_exp`] with separate multiplies and adds
//! (what a caller compiled for baseline x86-64 can run fast), and in the water kernels with
//! fused multiply-adds where the level has FMA (one instruction each and one rounding; see
//! [`crate::simd`]).
//!
//! `f64::exp` is a libm call, which stops loops from vectorising. This version reduces
//! x = k ln2 + r with |r| ≤ ln2/2 (Cody–Waite split of ln2), evaluates the degree-13 Taylor
//! polynomial of e^r (truncation error r¹⁴/14! < 5·10⁻¹⁸) by Estrin's scheme (short dependency
//! chains, so neighbouring wavelengths overlap in the pipeline), and builds 2^k from the bits of
//! the rounding constant, so every step is plain arithmetic on f64 and u64 lanes.
//! Accuracy: within 4.5·10⁻¹⁶ relative of `f64::exp` on [−708, 709] (tested below); inputs below −708 return
//! e^−708 ≈ 3·10⁻³⁰⁸ (denormals are not produced), inputs above 709 return e^709.
//!
//! ## References
//! - Cody, W. J. & Waite, W. (1980) Software Manual for the Elementary Functions, Prentice-Hall
//!   (argument reduction with a two-part constant).
//! - Muller, J.-M. (2016) Elementary Functions, 3rd ed., Birkhäuser, §11 (exponent-field
//!   construction of 2^k).
//! - Estrin, G. (1960) Organization of computer systems: the fixed plus variable structure
//!   computer. Proc. Western Joint IRE-AIEE-ACM Computer Conference, 33–40.

use crate::simd::{Baseline, Level, mad};

const LOG2_E: f64 = std::f64::consts::LOG2_E;
// Cody–Waite split of ln 2 (fdlibm's e_exp.c values): LN2_HI has trailing zero bits so that
// k·LN2_HI is exact for |k| < 2¹¹.
const LN2_HI: f64 = 6.931_471_803_691_238e-1;
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
/// 1.5·2⁵²: adding it rounds to an integer held in the low mantissa bits.
const SHIFT: f64 = 6_755_399_441_055_744.0;

/// e^x, vectorisable; see the module docs for range and accuracy.
///
/// ```
/// let x = -3.7;
/// assert!((shoal::water::fast_exp(x) / x.exp() - 1.0).abs() < 1e-15);
/// ```
#[inline(always)]
#[must_use]
pub fn fast_exp(x: f64) -> f64 {
    exp::<Baseline>(x)
}

/// [`fast_exp`] with fused multiply-adds (for code compiled with FMA; without it each is a libm
/// call). Same accuracy bound (tested below).
#[cfg(test)]
fn fast_exp_fused(x: f64) -> f64 {
    exp::<crate::simd::Avx2>(x)
}

/// e^x with a·b + c as level `L` computes it ([`crate::simd::mad`]).
#[inline(always)]
pub(crate) fn exp<L: Level>(x: f64) -> f64 {
    let mad = mad::<L, f64>;
    let x = x.clamp(-708.0, 709.0);
    let t = mad(x, LOG2_E, SHIFT);
    let k = t - SHIFT;
    // (x − k·LN2_HI) − k·LN2_LO
    let r = mad(k, -LN2_LO, mad(k, -LN2_HI, x));
    // Taylor coefficients 1/k!, evaluated by Estrin's scheme: pairs, then powers r², r⁴, r⁸.
    // Horner's rule would chain 13 dependent multiply-adds (latency-bound in the water loop);
    // Estrin's tree is four levels deep.
    let r2 = r * r;
    let r4 = r2 * r2;
    let r8 = r4 * r4;
    let q0 = 1.0 + r;
    let q1 = mad(r, 1.0 / 6.0, 0.5);
    let q2 = mad(r, 1.0 / 120.0, 1.0 / 24.0);
    let q3 = mad(r, 1.0 / 5_040.0, 1.0 / 720.0);
    let q4 = mad(r, 1.0 / 362_880.0, 1.0 / 40_320.0);
    let q5 = mad(r, 1.0 / 39_916_800.0, 1.0 / 3_628_800.0);
    let q6 = mad(r, 1.0 / 6_227_020_800.0, 1.0 / 479_001_600.0);
    let s0 = mad(q1, r2, q0);
    let s1 = mad(q3, r2, q2);
    let s2 = mad(q5, r2, q4);
    let t0 = mad(s1, r4, s0);
    let t1 = mad(q6, r4, s2);
    let p = mad(t1, r8, t0);
    // Low mantissa bits of t hold 2⁵¹ + k; adding the bias and shifting leaves (k+1023)<<52.
    let two_k = f64::from_bits(t.to_bits().wrapping_add(1023) << 52);
    p * two_k
}

#[cfg(test)]
mod tests {
    use super::{fast_exp, fast_exp_fused};

    #[test]
    fn matches_libm_to_4p5e_minus_16() {
        let (mut worst, mut worst_fused) = (0.0f64, 0.0f64);
        let mut x: f64 = -708.0;
        while x < 709.0 {
            let b = x.exp();
            worst = worst.max((fast_exp(x) - b).abs() / b);
            worst_fused = worst_fused.max((fast_exp_fused(x) - b).abs() / b);
            x += 0.012_345_6;
        }
        assert!(worst < 4.5e-16, "worst relative error {worst:e}");
        assert!(worst_fused < 4.5e-16, "worst relative error, fused {worst_fused:e}");
    }

    #[test]
    fn exact_at_zero_and_finite_at_the_clamps() {
        assert_eq!(fast_exp(0.0), 1.0);
        assert!(fast_exp(-1e9) > 0.0 && fast_exp(-1e9) < 1e-300);
        assert!(fast_exp(1e9).is_finite());
        assert!(fast_exp(f64::NEG_INFINITY) >= 0.0);
    }
}
