//! The lane primitives of [`super`]: per-lane construction, branch-free masks and selects, and
//! the lane-wise 3 × 3 determinant and Cramer's rule, each the same expression per lane as the
//! scalar code it mirrors (so the same bits).

use super::{LANES, Lanes};
use crate::retrieval::nnls::{det3, finite};

/// A value per lane from `f(lane)`. A plain loop rather than `std::array::from_fn`, which the
/// compiler left as a call (compiled without AVX2) inside the AVX2 build: 6 % of the default
/// study's CPU time, in perf.
#[inline(always)]
pub(super) fn lanewise<T: Copy + Default>(f: impl Fn(usize) -> T) -> [T; LANES] {
    let mut out = [T::default(); LANES];
    for (s, v) in out.iter_mut().enumerate() {
        *v = f(s);
    }
    out
}

/// The lane mask of `b`: all bits set when true.
#[inline(always)]
pub(super) fn mask(b: bool) -> u64 {
    u64::from(b).wrapping_neg()
}

/// `a` where `mask` is set, else `b`, by bit operations (no branch).
#[inline(always)]
pub(super) fn select(mask: u64, a: f64, b: f64) -> f64 {
    f64::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// The lane-wise [`det3`]: the same expression per lane, so the same bits.
#[inline(always)]
pub(super) fn det3_lanes(c: &[[&Lanes; 3]; 3]) -> Lanes {
    lanewise(|s| {
        det3(&[
            [c[0][0][s], c[0][1][s], c[0][2][s]],
            [c[1][0][s], c[1][1][s], c[1][2][s]],
            [c[2][0][s], c[2][1][s], c[2][2][s]],
        ])
    })
}

/// Component `j` of the solution of `rows`·x = `bs` by Cramer's rule (`inv_det` = 1/det(rows)),
/// lane by lane as [`nnls3`] computes it. (A function, not a closure: the closure was left out
/// of line.)
#[inline(always)]
pub(super) fn cramer(rows: &[[&Lanes; 3]; 3], bs: &[Lanes; 3], inv_det: &Lanes, j: usize) -> Lanes {
    let mut c = *rows;
    for (i, row) in c.iter_mut().enumerate() {
        row[j] = &bs[i];
    }
    let num = det3_lanes(&c);
    lanewise(|s| num[s] * inv_det[s])
}

/// Whether `x` is feasible: every component finite and non-negative.
#[inline(always)]
pub(super) fn feasible(x: &[f64; 3]) -> bool {
    x.iter().fold(true, |ok, v| ok & (*v >= 0.0) & finite(*v))
}
