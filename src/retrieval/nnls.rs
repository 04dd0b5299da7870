//! Non-negative least squares for a handful of unknowns: min ‖A·x − y‖ subject to x ≥ 0.
//!
//! With n ≤ 6 unknowns the exact solution is found by enumeration: the NNLS optimum is the
//! unconstrained least-squares solution on its own support (the Karush–Kuhn–Tucker conditions,
//! Lawson & Hanson 1974, ch. 23), so among the 2ⁿ supports whose least-squares solution is
//! non-negative, the one with the smallest residual is the optimum. Columns are scaled to unit
//! norm and each subproblem is solved by Householder-free modified Gram–Schmidt QR, so the
//! ~100× spread between the SIOP columns costs no accuracy.
//!
//! ## References
//! - Lawson, C. L. & Hanson, R. J. (1974) Solving Least Squares Problems. Prentice-Hall.

/// Result of [`nnls`].
#[derive(Debug, Clone, PartialEq)]
pub struct NnlsSolution {
    /// The non-negative solution.
    pub x: Vec<f64>,
    /// ‖A·x − y‖.
    pub residual: f64,
    /// The unconstrained least-squares solution (may have negative entries).
    pub unconstrained: Vec<f64>,
}

/// Solve min ‖A·x − y‖, x ≥ 0, for `a` given by columns (`columns[j][i]` = A_ij). `None` if the
/// data are not finite or no column has any weight.
#[must_use]
pub fn nnls(columns: &[Vec<f64>], y: &[f64]) -> Option<NnlsSolution> {
    let n = columns.len();
    if n == 0 || n > 6 || y.iter().any(|v| !v.is_finite()) || columns.iter().flatten().any(|v| !v.is_finite()) {
        return None;
    }
    let norms: Vec<f64> = columns.iter().map(|c| c.iter().map(|v| v * v).sum::<f64>().sqrt()).collect();
    let scaled: Vec<Vec<f64>> = columns
        .iter()
        .zip(&norms)
        .map(|(c, &s)| if s > 0.0 { c.iter().map(|v| v / s).collect() } else { c.clone() })
        .collect();
    let residual_of = |x: &[f64]| -> f64 {
        y.iter()
            .enumerate()
            .map(|(i, yi)| {
                let m: f64 = scaled.iter().zip(x).map(|(c, xj)| c[i] * xj).sum();
                (m - yi) * (m - yi)
            })
            .sum::<f64>()
            .sqrt()
    };
    let unscale =
        |x: &[f64]| -> Vec<f64> { x.iter().zip(&norms).map(|(v, s)| if *s > 0.0 { v / s } else { 0.0 }).collect() };
    let full = least_squares(&scaled, y, (1 << n) - 1)?;
    let mut best: Option<(f64, Vec<f64>)> = None;
    for mask in 0..1u32 << n {
        let Some(x) = least_squares(&scaled, y, mask) else { continue };
        if x.iter().any(|v| *v < 0.0) {
            continue;
        }
        let r = residual_of(&x);
        if best.as_ref().is_none_or(|(b, _)| r < *b) {
            best = Some((r, x));
        }
    }
    let (residual, x) = best?;
    Some(NnlsSolution { x: unscale(&x), residual, unconstrained: unscale(&full) })
}

/// Least squares on the columns in `mask` (others zero) by modified Gram–Schmidt; `None` if the
/// chosen columns are numerically dependent.
fn least_squares(columns: &[Vec<f64>], y: &[f64], mask: u32) -> Option<Vec<f64>> {
    let n = columns.len();
    let chosen: Vec<usize> = (0..n).filter(|j| mask & (1 << j) != 0).collect();
    let mut x = vec![0.0; n];
    if chosen.is_empty() {
        return Some(x);
    }
    let m = y.len();
    if chosen.len() > m {
        return None;
    }
    let mut q: Vec<Vec<f64>> = chosen.iter().map(|&j| columns[j].clone()).collect();
    let k = chosen.len();
    let mut r = vec![vec![0.0; k]; k];
    for j in 0..k {
        for i in 0..j {
            let dot: f64 = q[i].iter().zip(&q[j]).map(|(a, b)| a * b).sum();
            r[i][j] = dot;
            let qi = q[i].clone();
            for (v, u) in q[j].iter_mut().zip(&qi) {
                *v -= dot * u;
            }
        }
        let norm: f64 = q[j].iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm > 1e-10) {
            return None;
        }
        r[j][j] = norm;
        for v in &mut q[j] {
            *v /= norm;
        }
    }
    let qty: Vec<f64> = q.iter().map(|c| c.iter().zip(y).map(|(a, b)| a * b).sum()).collect();
    let mut z = vec![0.0; k];
    for j in (0..k).rev() {
        let s: f64 = (j + 1..k).map(|l| r[j][l] * z[l]).sum();
        z[j] = (qty[j] - s) / r[j][j];
    }
    for (idx, &j) in chosen.iter().enumerate() {
        x[j] = z[idx];
    }
    Some(x)
}

/// The determinant of a 3 × 3 matrix by cofactors along the first row (shared with the lane
/// version in `almi_lanes`, which must perform the same operations in the same order).
#[inline(always)]
#[must_use]
pub(crate) fn det3(c: &[[f64; 3]; 3]) -> f64 {
    c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0])
        + c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0])
}

/// `x.is_finite()` as x·0 = 0, which runs four lanes per instruction: x·0 is ±0 for finite x
/// and NaN for ±∞ and NaN, so the two agree on every input. The spellings the compiler
/// recognises as a class test of x (`is_finite`, |x| < ∞, 0 ≤ x < ∞) it compiles to integer
/// tests of the bits, one lane at a time: for eight lanes of `almi_lanes`' feasibility test,
/// 451 instructions against 54 (rustc 1.95, AVX2), and aLMI ran about 15 % faster with the
/// comparisons. Shared by aLMI's scalar and lane code, so both spell the test this way.
#[inline(always)]
pub(crate) fn finite(x: f64) -> bool {
    x * 0.0 == 0.0
}

/// The smallest |det| of the scaled Gram matrix [`nnls3`] solves with, relative to the product
/// of its diagonal (so the determinant of the columns' correlation matrix: below it the columns
/// are taken as dependent).
pub(crate) const MIN_DET: f64 = 1e-13;

/// The column scale of [`nnls3`] for a column whose Gram diagonal (squared norm) is `g_jj`: the
/// power of two 2⁻ᵏ with 2ᵏ ≤ √g_jj < 2ᵏ⁺¹, read off the exponent of `g_jj`. Scaled, the column's
/// squared norm lies in [1, 4), and since the scale is a power of two, scaling and unscaling
/// round nothing (a scale of 1/√g_jj cost a square root and divisions, and rounded). Integer
/// operations on the bits, so they vectorise in the lane version (`almi_lanes`).
#[inline(always)]
#[must_use]
pub(crate) fn column_scale(g_jj: f64) -> f64 {
    // Biased exponent e of g_jj: g_jj = m·2^(e − 1023), m ∈ [1, 2) (zero and subnormals: e = 0).
    // k = ⌊(e − 1023)/2⌋ = ((e + 1) >> 1) − 512, and 2⁻ᵏ has biased exponent 1023 − k.
    let e = (g_jj.to_bits() >> 52) & 0x7ff;
    f64::from_bits((1535 - ((e + 1) >> 1)) << 52)
}

/// NNLS of at most 3 unknowns from the normal equations: G = AᵀA, b = Aᵀy, yy = yᵀy (the
/// per-pixel path of aLMI: nothing allocated). Columns are scaled by powers of two to squared
/// norms in [1, 4) (`column_scale`); each support is solved by Cramer's rule on the scaled
/// Gram matrix (well conditioned for 3 columns once scaled), with one division per support.
/// Returns (x, ‖A·x − y‖², unconstrained x), or `None` if nothing is solvable.
#[must_use]
pub fn nnls3(g: &[[f64; 3]; 3], b: &[f64; 3], yy: f64) -> Option<([f64; 3], f64, [f64; 3])> {
    // A negative, infinite or NaN squared norm, or non-finite data: no answer.
    if (0..3).any(|j| !(g[j][j] >= 0.0 && g[j][j] < f64::INFINITY))
        || b.iter().any(|v| !v.is_finite())
        || !yy.is_finite()
    {
        return None;
    }
    // A column of zeros is left out of every support.
    let present: [bool; 3] = std::array::from_fn(|j| g[j][j] > 0.0);
    let sc: [f64; 3] = std::array::from_fn(|j| column_scale(g[j][j]));
    let gs: [[f64; 3]; 3] = std::array::from_fn(|i| {
        std::array::from_fn(|j| if present[i] && present[j] { g[i][j] * sc[i] * sc[j] } else { 0.0 })
    });
    let bs: [f64; 3] = std::array::from_fn(|j| if present[j] { b[j] * sc[j] } else { 0.0 });
    let solve = |mask: u8| -> Option<[f64; 3]> {
        let mut idx = [0usize; 3];
        let mut len = 0;
        for j in 0..3 {
            if mask & (1 << j) != 0 && present[j] {
                idx[len] = j;
                len += 1;
            }
        }
        let mut x = [0.0; 3];
        match len {
            0 => {}
            1 => x[idx[0]] = bs[idx[0]] / gs[idx[0]][idx[0]],
            2 => {
                let (p, q) = (idx[0], idx[1]);
                let det = gs[p][p] * gs[q][q] - gs[p][q] * gs[q][p];
                if !(det.abs() > MIN_DET * (gs[p][p] * gs[q][q])) {
                    return None;
                }
                let inv = 1.0 / det;
                x[p] = (bs[p] * gs[q][q] - gs[p][q] * bs[q]) * inv;
                x[q] = (gs[p][p] * bs[q] - gs[q][p] * bs[p]) * inv;
            }
            _ => {
                let m = &gs;
                let det = det3(m);
                if !(det.abs() > MIN_DET * (gs[0][0] * gs[1][1] * gs[2][2])) {
                    return None;
                }
                let inv = 1.0 / det;
                for j in 0..3 {
                    let mut c = *m;
                    for i in 0..3 {
                        c[i][j] = bs[i];
                    }
                    x[j] = det3(&c) * inv;
                }
            }
        }
        Some(x)
    };
    let residual = |x: &[f64; 3]| -> f64 {
        let mut r = yy;
        for i in 0..3 {
            r -= 2.0 * x[i] * bs[i];
            for j in 0..3 {
                r += x[i] * gs[i][j] * x[j];
            }
        }
        r.max(0.0)
    };
    let unscale = |x: [f64; 3]| -> [f64; 3] { std::array::from_fn(|j| if present[j] { x[j] * sc[j] } else { 0.0 }) };
    let full = solve(7);
    // The unconstrained optimum is feasible: it is the constrained one (the problem is convex
    // and its minimum lies in the feasible set; Lawson & Hanson 1974, ch. 23), so the other
    // seven supports need not be tried. Most aLMI pixels end here.
    if let Some(x) = full
        && x.iter().all(|v| *v >= 0.0 && v.is_finite())
    {
        return Some((unscale(x), residual(&x), unscale(x)));
    }
    let full = full.unwrap_or([0.0; 3]);
    let mut best: Option<([f64; 3], f64)> = None;
    // The full support (mask 7) was just solved and is unsolvable or infeasible: it would be
    // skipped below, so it is not solved again.
    for mask in 0..7u8 {
        let Some(x) = solve(mask) else { continue };
        if x.iter().any(|v| *v < 0.0 || !v.is_finite()) {
            continue;
        }
        let r = residual(&x);
        if best.as_ref().is_none_or(|(_, b)| r < *b) {
            best = Some((x, r));
        }
    }
    let (x, r) = best?;
    Some((unscale(x), r, unscale(full)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_non_negative_solution_exactly() {
        let cols = vec![vec![1.0, 0.0, 1.0, 2.0], vec![100.0, 50.0, 0.0, 10.0], vec![0.0, 1.0, 3.0, 1.0]];
        let x_true = [2.0, 0.01, 0.5];
        let y: Vec<f64> = (0..4).map(|i| cols.iter().zip(&x_true).map(|(c, x)| c[i] * x).sum()).collect();
        let s = nnls(&cols, &y).unwrap();
        for (a, b) in s.x.iter().zip(&x_true) {
            assert!((a - b).abs() < 1e-12 * b.max(1.0), "{a} vs {b}");
        }
        assert!(s.residual < 1e-12);
    }

    #[test]
    fn a_negative_unconstrained_entry_goes_to_zero() {
        // y is best fitted with a negative second coefficient; NNLS puts it at the bound.
        let cols = vec![vec![1.0, 1.0, 1.0], vec![1.0, 2.0, 3.0]];
        let y = vec![3.0, 2.0, 1.0];
        let s = nnls(&cols, &y).unwrap();
        assert!(s.unconstrained[1] < 0.0);
        assert_eq!(s.x[1], 0.0);
        assert!((s.x[0] - 2.0).abs() < 1e-12);
        assert!(nnls(&cols, &[f64::NAN, 1.0, 1.0]).is_none());
    }

    #[test]
    fn column_scale_is_the_power_of_two_below_the_norm() {
        // Squared norms from subnormal to 1e300, including exact powers of two.
        let mut g = 5e-324;
        while g < 1e300 {
            for v in [g, g * 1.5, g * 3.999] {
                let s = column_scale(v);
                // A power of two: scaling by it is exact (the mantissa bits are zero).
                assert_eq!(s.to_bits() & ((1u64 << 52) - 1), 0, "{v:e}: scale {s:e}");
                if v >= f64::MIN_POSITIVE {
                    let scaled = v * s * s;
                    assert!((1.0..4.0).contains(&scaled), "{v:e}: scaled squared norm {scaled}");
                    // 2ᵏ ≤ √v < 2ᵏ⁺¹, with s = 2⁻ᵏ.
                    assert!((1.0..2.0).contains(&(v.sqrt() * s)), "{v:e}");
                } else {
                    assert!(v * s * s < 4.0, "{v:e}");
                }
            }
            g *= 7.3;
        }
        assert_eq!(column_scale(1.0), 1.0);
        assert_eq!(column_scale(4.0), 0.5);
        assert_eq!(column_scale(0.25), 2.0);
    }

    #[test]
    fn nnls3_is_unchanged_by_a_power_of_two_column_scale() {
        // Scaling a column by a power of two scales its coefficient by the inverse, exactly:
        // nnls3's column scales absorb it, so the two problems it solves are the same bits.
        let g = [[2.0, 0.3, 0.1], [0.3, 1.0, -0.2], [0.1, -0.2, 0.7]];
        let b = [1.0, -0.5, 0.4];
        let (x, r, u) = nnls3(&g, &b, 3.0).unwrap();
        let k = 2f64.powi(20);
        let g2 = [
            [g[0][0], g[0][1] * k, g[0][2]],
            [g[1][0] * k, g[1][1] * k * k, g[1][2] * k],
            [g[2][0], g[2][1] * k, g[2][2]],
        ];
        let b2 = [b[0], b[1] * k, b[2]];
        let (x2, r2, u2) = nnls3(&g2, &b2, 3.0).unwrap();
        assert_eq!(x[0].to_bits(), x2[0].to_bits());
        assert_eq!(x[1].to_bits(), (x2[1] * k).to_bits());
        assert_eq!(x[2].to_bits(), x2[2].to_bits());
        assert_eq!(r.to_bits(), r2.to_bits());
        assert_eq!(u[1].to_bits(), (u2[1] * k).to_bits());
        // The second coefficient wants to be negative: it sits on the bound.
        assert!(u[1] < 0.0 && x[1] == 0.0, "{x:?} {u:?}");
    }

    #[test]
    fn the_normal_equation_path_agrees_with_the_general_one() {
        let cols =
            vec![vec![1.0, 0.0, 1.0, 2.0, 0.3], vec![100.0, 50.0, 0.0, 10.0, 7.0], vec![0.0, 1.0, 3.0, 1.0, 0.2]];
        for y in [vec![3.0, 2.0, 1.0, 0.5, 0.1], vec![-1.0, 4.0, 2.0, 0.0, 3.0], vec![1.0, 1.0, 1.0, 1.0, 1.0]] {
            let general = nnls(&cols, &y).unwrap();
            let g: [[f64; 3]; 3] = std::array::from_fn(|i| {
                std::array::from_fn(|j| cols[i].iter().zip(&cols[j]).map(|(a, b)| a * b).sum())
            });
            let b: [f64; 3] = std::array::from_fn(|i| cols[i].iter().zip(&y).map(|(a, b)| a * b).sum());
            let yy: f64 = y.iter().map(|v| v * v).sum();
            let (x, r2, _) = nnls3(&g, &b, yy).unwrap();
            for (a, b) in x.iter().zip(&general.x) {
                assert!((a - b).abs() < 1e-9 * b.abs().max(1.0), "{x:?} vs {:?}", general.x);
            }
            assert!((r2.sqrt() - general.residual).abs() < 1e-7 * general.residual.max(1.0));
        }
    }
}
