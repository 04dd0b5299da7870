//! aLMI as the reference code runs it (Geoscience Australia's DEA-Water-Quality `Python-aLMI-X`,
//! `aLMI_main` with its default configuration), for reproducing published numbers; Shoal's own
//! [`super::almi::invert`] is the design default. The behaviour, step by step, as documented from
//! running the unmodified code on 302 pixels (`tests/data/retrieval_reference/almi`):
//!
//! 1. a pixel is processed only if every band has Rrs > 1e-6 (NaN, zero, negative or a tiny
//!    value anywhere drops the whole pixel — no band is skipped);
//! 2. rrs = Rrs/(0.52 + 1.7·Rrs) and u the positive root of rrs = g0·u + g1·u²;
//! 3. y_λ = −a_w·u + bb_w·(1 − u) with the water of the *first* set, reused for every set;
//! 4. per set: A[λ, j] = a*_j·u − bb*_j·(1 − u); C = the least-squares solution through the SVD,
//!    singular values below 1e-6·s_max dropped (`numpy.linalg.lstsq(rcond=1e-6)`), unconstrained,
//!    stored as float32;
//! 5. forward check with that set's own water: u' = bb/(a + bb), rrs' = (g0 + g1·u')·u', cost =
//!    √(Σ(rrs − rrs')²/N) / mean(rrs) over all N bands;
//! 6. the set is *dropped* unless every float32 concentration ≥ float32(1e-5) (`minValidConc`) —
//!    so a truly absent constituent, solved as ±1e-12, drops the right set;
//! 7. sets are visited in order from a best cost of 100 (`costThreshhold`); a valid set replaces
//!    the best when its cost is strictly below the best stored as float32 (the earliest set wins
//!    ties); no valid set: the pixel is not returned.
//!
//! ## References
//! - Brando, V. E. et al. (2012) Appl. Opt. 51, 2808–2833 (aLMI).
//! - Golub, G. H., Van Loan, C. F. (2013) Matrix Computations, 4th ed., §5.5.4 (the truncated-SVD
//!   least-squares solution) and §8.5 (the cyclic Jacobi method for symmetric eigenproblems).

use super::almi::{AlmiFlags, AlmiPixel, AlmiSet, u_from_rrs};
use crate::water::rrs_below_from_above;

/// Smallest Rrs a band may have for the pixel to be processed (strict), sr⁻¹.
pub const MIN_RRS: f64 = 1e-6;
/// Smallest concentration a set's solution may have to stay valid (`minValidConc`).
pub const MIN_VALID_CONC: f32 = 1e-5;
/// The cost a set must beat (`costThreshhold`).
pub const COST_THRESHOLD: f32 = 100.0;
/// Relative singular-value cut-off of the least-squares solve (`rcond`).
pub const RCOND: f64 = 1e-6;

/// Why a reference-mode pixel was not returned (for the paper's pixel accounting).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NotReturned {
    /// A band failed the Rrs > 1e-6 screen (DEA's SIOPindex −999).
    Screened,
    /// Every set was dropped or cost 100 or more (DEA's SIOPindex −1).
    NoValidSet,
}

/// One pixel, as the reference code inverts it: `rrs_above[k]` for every band in use, `valid[k]`
/// false where the chain flagged the band (saturated, invalid), which screens the pixel like a
/// bad value does. Concentrations and cost are the reference's float32 values.
#[must_use]
pub fn invert_reference(sets: &[AlmiSet], g0: f64, g1: f64, rrs_above: &[f64], valid: &[bool]) -> AlmiPixel {
    let screened = AlmiPixel { flags: AlmiFlags::FAILED | AlmiFlags::SCREENED, ..AlmiPixel::FAILED };
    let n = rrs_above.len();
    if n < 3 || sets.is_empty() || (0..n).any(|k| !valid.get(k).copied().unwrap_or(false) || !(rrs_above[k] > MIN_RRS))
    {
        return screened;
    }
    let rrs: Vec<f64> = rrs_above.iter().map(|&r| rrs_below_from_above(r)).collect();
    let u: Vec<f64> = rrs.iter().map(|&r| u_from_rrs(r, g0, g1)).collect();
    if u.iter().any(|v| !v.is_finite()) {
        // +inf passes DEA's screen and aborts its whole call; here it fails this pixel only.
        return screened;
    }
    let water = &sets[0].iops;
    let y: Vec<f64> = (0..n).map(|k| -water.a_w[k] * u[k] + water.bb_w[k] * (1.0 - u[k])).collect();
    let mean_rrs = rrs.iter().sum::<f64>() / n as f64;
    let mut best_cost = COST_THRESHOLD;
    let mut best: Option<(usize, [f32; 3])> = None;
    for (s, set) in sets.iter().enumerate() {
        let o = &set.iops;
        let rows: Vec<[f64; 3]> = (0..n)
            .map(|k| {
                let w = 1.0 - u[k];
                [o.a_ph[k] * u[k] - o.bb_ph[k] * w, o.a_cdom[k] * u[k], o.a_nap[k] * u[k] - o.bb_nap[k] * w]
            })
            .collect();
        let Some(c) = lstsq3(&rows, &y) else { continue };
        let c32 = c.map(|v| v as f32);
        let x = c32.map(f64::from);
        let mut sq = 0.0;
        for k in 0..n {
            let a = o.a_w[k] + x[0] * o.a_ph[k] + x[1] * o.a_cdom[k] + x[2] * o.a_nap[k];
            let bb = o.bb_w[k] + x[0] * o.bb_ph[k] + x[2] * o.bb_nap[k];
            let up = bb / (a + bb);
            sq += ((g0 + g1 * up) * up - rrs[k]).powi(2);
        }
        let cost = (sq / n as f64).sqrt() / mean_rrs;
        let valid_conc = c32.iter().all(|&v| v >= MIN_VALID_CONC);
        if valid_conc && cost < f64::from(best_cost) {
            best_cost = cost as f32;
            best = Some((s, c32));
        }
    }
    match best {
        Some((s, c)) => AlmiPixel {
            chl: f64::from(c[0]),
            cdom: f64::from(c[1]),
            nap: f64::from(c[2]),
            set: u8::try_from(s).ok(),
            cost: f64::from(best_cost),
            flags: AlmiFlags::PHYSICAL,
        },
        None => AlmiPixel { flags: AlmiFlags::FAILED | AlmiFlags::NO_VALID_SET, ..AlmiPixel::FAILED },
    }
}

/// Which reason a failed reference-mode pixel carries, if any.
#[must_use]
pub fn not_returned(p: &AlmiPixel) -> Option<NotReturned> {
    if p.flags & AlmiFlags::SCREENED != 0 {
        Some(NotReturned::Screened)
    } else if p.flags & AlmiFlags::NO_VALID_SET != 0 {
        Some(NotReturned::NoValidSet)
    } else {
        None
    }
}

/// The minimum-norm least-squares solution of rows·x = y through the truncated SVD: with
/// AᵀA = V Λ Vᵀ (cyclic Jacobi, Golub & Van Loan §8.5), singular values σᵢ = √λᵢ, x = Σ_{σᵢ > rcond·σ_max} vᵢ (vᵢ·Aᵀy)/λᵢ.
/// `None` when the system has no finite solution.
fn lstsq3(rows: &[[f64; 3]], y: &[f64]) -> Option<[f64; 3]> {
    let mut g = [[0.0; 3]; 3];
    let mut b = [0.0; 3];
    for (r, &yk) in rows.iter().zip(y) {
        for p in 0..3 {
            b[p] += r[p] * yk;
            for q in 0..3 {
                g[p][q] += r[p] * r[q];
            }
        }
    }
    let (lambda, v) = super::quadrature::symmetric_eigen(g.iter().map(|r| r.to_vec()).collect());
    let max = lambda.iter().copied().fold(0.0f64, f64::max);
    if !(max > 0.0) || !max.is_finite() {
        return None;
    }
    let cut = (RCOND * max.sqrt()).powi(2);
    let mut x = [0.0; 3];
    for i in 0..3 {
        if lambda[i] > cut {
            let proj = (0..3).map(|p| v[p][i] * b[p]).sum::<f64>() / lambda[i];
            for p in 0..3 {
                x[p] += v[p][i] * proj;
            }
        }
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lstsq_matches_a_known_solution_and_truncates_a_null_direction() {
        let rows = [[1.0, 2.0, 0.5], [0.3, -1.0, 2.0], [2.0, 0.1, -0.7], [1.1, 1.0, 1.0]];
        let truth = [0.7, -1.3, 2.1];
        let y: Vec<f64> = rows.iter().map(|r| r[0] * truth[0] + r[1] * truth[1] + r[2] * truth[2]).collect();
        let x = lstsq3(&rows, &y).unwrap();
        for i in 0..3 {
            assert!((x[i] - truth[i]).abs() < 1e-12, "{x:?}");
        }
        // Rank 2 (third column = first + second): the minimum-norm solution, as SVD lstsq gives.
        let rows: Vec<[f64; 3]> =
            [[1.0, 2.0], [0.3, -1.0], [2.0, 0.1]].iter().map(|r| [r[0], r[1], r[0] + r[1]]).collect();
        let y: Vec<f64> = rows.iter().map(|r| r[0] * 1.0 + r[1] * 2.0).collect();
        let x = lstsq3(&rows, &y).unwrap();
        // Minimum-norm solution of x0 + x2 = 1, x1 + x2 = 2: x = (0, 1, 1).
        for (got, want) in x.iter().zip([0.0, 1.0, 1.0]) {
            assert!((got - want).abs() < 1e-9, "{x:?}");
        }
    }
}
