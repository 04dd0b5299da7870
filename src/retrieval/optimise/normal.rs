//! The linear algebra of each Levenberg–Marquardt iteration ([`super::levenberg_marquardt`]):
//! the normal equations JᵀJ, Jᵀr of the Jacobian rows, and the damped step solved from them by
//! the LDLᵀ factorisation (references in the parent module).

use super::{MAX_PARAMETERS, Row};

/// Solve the n × n system (A + λ·diag A)·δ = −g on the free variables into `step` (zero for
/// fixed variables) by [`ldl_solve`]; false if the damped matrix is not numerically positive
/// definite (the caller then raises λ).
pub(super) fn damped_step(a: &[Row], g: &[f64], lambda: f64, free: &[bool], step: &mut [f64]) -> bool {
    let n = g.len().min(MAX_PARAMETERS);
    let mut idx = [0usize; MAX_PARAMETERS];
    let mut m = 0;
    for i in 0..n {
        if free[i] {
            idx[m] = i;
            m += 1;
        }
    }
    let mut mat = [[0.0f64; MAX_PARAMETERS + 1]; MAX_PARAMETERS];
    for r in 0..m {
        for c in 0..m {
            mat[r][c] = a[idx[r]][idx[c]];
        }
        mat[r][r] += lambda * a[idx[r]][idx[r]].max(1e-30);
        mat[r][m] = -g[idx[r]];
    }
    let mut sol = [0.0f64; MAX_PARAMETERS];
    if !solve(&mat, m, &mut sol) {
        return false;
    }
    step.fill(0.0);
    for k in 0..m {
        step[idx[k]] = sol[k];
    }
    step.iter().all(|v| v.is_finite())
}

/// The m × m symmetric system `mat` (m ≤ [`MAX_PARAMETERS`], its column m the right-hand side)
/// into `sol` by [`ldl_solve`] at that size.
fn solve(mat: &[[f64; MAX_PARAMETERS + 1]; MAX_PARAMETERS], m: usize, sol: &mut [f64]) -> bool {
    // The match below has an arm for every size up to the limit.
    const _: () = assert!(MAX_PARAMETERS == 8);
    match m {
        0 => true,
        1 => ldl_solve::<1>(mat, sol),
        2 => ldl_solve::<2>(mat, sol),
        3 => ldl_solve::<3>(mat, sol),
        4 => ldl_solve::<4>(mat, sol),
        5 => ldl_solve::<5>(mat, sol),
        6 => ldl_solve::<6>(mat, sol),
        7 => ldl_solve::<7>(mat, sol),
        _ => ldl_solve::<8>(mat, sol),
    }
}

/// The M × M symmetric positive definite system `mat` (its lower triangle read; column M the
/// right-hand side) into `sol` by the factorisation LDLᵀ (L unit lower triangular, D diagonal;
/// Golub & Van Loan 2013, *Matrix Computations*, 4th ed., §4.1.2, Algorithm 4.1.2): false if a
/// pivot of D is not above 10⁻³⁰⁰ (the matrix is not numerically positive definite).
///
/// The damped normal equations JᵀJ + λ·diag(JᵀJ) are symmetric positive definite wherever they
/// are nonsingular, so they need no pivoting: LDLᵀ is backward stable on them (Higham 2002,
/// *Accuracy and Stability of Numerical Algorithms*, 2nd ed., §10.1), takes M³/3 multiply-adds
/// against Gaussian elimination's 2M³/3, one division per column (by its reciprocal after) and
/// no row swaps: the damped step had been a sixth of a 28-band SAMBUCA-style fit's time and two
/// fifths of a 4-band one's, in partial pivoting's compare chains, divisions and row copies. M
/// is a constant of each instance, so that the loops unroll.
#[inline]
fn ldl_solve<const M: usize>(mat: &[[f64; MAX_PARAMETERS + 1]; MAX_PARAMETERS], sol: &mut [f64]) -> bool {
    // l[i][k] (k < i): L; ld[i][k] = l[i][k]·d[k]; inv_d[k] = 1/d[k].
    let (mut l, mut ld, mut inv_d) = ([[0.0f64; M]; M], [[0.0f64; M]; M], [0.0f64; M]);
    for j in 0..M {
        let mut d = mat[j][j];
        for k in 0..j {
            d -= l[j][k] * ld[j][k];
        }
        if !(d > 1e-300) {
            return false;
        }
        inv_d[j] = 1.0 / d;
        for i in j + 1..M {
            let mut v = mat[i][j];
            for k in 0..j {
                v -= l[i][k] * ld[j][k];
            }
            ld[i][j] = v;
            l[i][j] = v * inv_d[j];
        }
    }
    // L·y = b, then Lᵀ·x = D⁻¹·y.
    let mut y = [0.0f64; M];
    for i in 0..M {
        let mut v = mat[i][M];
        for k in 0..i {
            v -= l[i][k] * y[k];
        }
        y[i] = v;
    }
    for i in (0..M).rev() {
        let mut v = y[i] * inv_d[i];
        for k in i + 1..M {
            v -= l[k][i] * sol[k];
        }
        sol[i] = v;
    }
    true
}

/// Jᵀr into `g` and JᵀJ into `a` (both triangles) for the Jacobian rows `jac` and residuals `r`
/// (n = `g.len()` parameters).
///
/// One pass over the rows, every sum its own accumulator: each sum adds the same terms in the
/// same order as summing it alone would (from −0.0, as `Iterator::sum` does), so the bits are
/// the same, but its chains of dependent additions overlap instead of running one after
/// another. The parameter count is a constant of each instance of [`Sums`], so that its
/// accumulators live in registers.
pub(super) fn normal_equations(jac: &[Row], r: &[f64], g: &mut [f64], a: &mut [Row]) {
    // The match below has an arm for every count up to the damped step's limit.
    const _: () = assert!(MAX_PARAMETERS == 8);
    fn put<const N: usize>(jac: &[Row], r: &[f64], g: &mut [f64], a: &mut [Row]) {
        let (g_sum, a_sum) = crate::simd::throughput(Sums::<N> { jac, r });
        g[..N].copy_from_slice(&g_sum[..N]);
        for k in 0..N {
            for q in 0..=k {
                (a[k][q], a[q][k]) = (a_sum[k][q], a_sum[k][q]);
            }
        }
    }
    match g.len() {
        0 => {}
        1 => put::<1>(jac, r, g, a),
        2 => put::<2>(jac, r, g, a),
        3 => put::<3>(jac, r, g, a),
        4 => put::<4>(jac, r, g, a),
        5 => put::<5>(jac, r, g, a),
        6 => put::<6>(jac, r, g, a),
        7 => put::<7>(jac, r, g, a),
        _ => put::<8>(jac, r, g, a),
    }
}

/// Jᵀr and rows 0..N of JᵀJ for N parameters (see [`normal_equations`]), as a
/// [`crate::simd::Kernel`]: a Jacobian row is one vector of [`MAX_PARAMETERS`] lanes, and row k
/// of JᵀJ gains J_ik times it, so that a row of J costs N + 1 vector multiplies and adds instead
/// of (N + 1)(N + 2)/2 − 1 scalar ones of each (the normal equations took a sixth of a 28-band
/// SAMBUCA-style fit's time, scalar). Entry (k, q) still adds J_ik·J_iq row after row, as the
/// scalar sum did (the product is commutative, bit for bit, so the triangle the caller reads
/// is the one it had); lanes q ≥ N hold products of unused entries and are not read.
struct Sums<'a, const N: usize> {
    jac: &'a [Row],
    r: &'a [f64],
}

impl<const N: usize> crate::simd::Kernel for Sums<'_, N> {
    type Output = (Row, [Row; N]);

    #[inline(always)]
    fn run<L: crate::simd::Level>(self) -> Self::Output {
        let mut g = [-0.0f64; MAX_PARAMETERS];
        let mut a = [[-0.0f64; MAX_PARAMETERS]; N];
        for (row, &ri) in self.jac.iter().zip(self.r) {
            for q in 0..MAX_PARAMETERS {
                g[q] += row[q] * ri;
            }
            for (k, a_k) in a.iter_mut().enumerate() {
                let j_k = row[k];
                for q in 0..MAX_PARAMETERS {
                    a_k[q] += j_k * row[q];
                }
            }
        }
        (g, a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_equations_are_the_sums_one_at_a_time_to_the_bit() {
        for n in 1..=MAX_PARAMETERS {
            let m = 29;
            let jac: Vec<Row> = (0..m)
                .map(|i| {
                    std::array::from_fn(|k| match k {
                        // Column 0 times column 1 (positive) is −0.0 in every row.
                        0 => -0.0,
                        1 => 1e-3 * (1.5 + (i as f64).sin()),
                        _ => ((i * 7 + k * 13) as f64 * 0.37).sin() * 1e-3,
                    })
                })
                .collect();
            let r: Vec<f64> = (0..m).map(|i| ((i as f64) * 1.3).cos() * 1e-4).collect();
            let (mut g, mut a) = (vec![0.0; n], vec![[0.0; MAX_PARAMETERS]; n]);
            normal_equations(&jac, &r, &mut g, &mut a);
            for k in 0..n {
                let g_k: f64 = (0..m).map(|i| jac[i][k] * r[i]).sum();
                assert_eq!(g[k].to_bits(), g_k.to_bits(), "n {n}, g[{k}]");
                for q in 0..n {
                    let a_kq: f64 = (0..m).map(|i| jac[i][k.max(q)] * jac[i][k.min(q)]).sum();
                    assert_eq!(a[k][q].to_bits(), a_kq.to_bits(), "n {n}, a[{k}][{q}]");
                }
            }
        }
    }

    /// LDLᵀ solves positive definite systems of every size (A = JᵀJ + λ·diag, J of full rank
    /// with a ridge, or rank-deficient as a 4-band fit of 5 parameters) and refuses the others.
    #[test]
    fn ldl_solves_positive_definite_systems_and_refuses_the_others() {
        type Mat = [[f64; MAX_PARAMETERS + 1]; MAX_PARAMETERS];
        for m in 1..=MAX_PARAMETERS {
            for (rows, lambda) in [(m + 3, 0.0), (m.saturating_sub(1).max(1), 1e-3)] {
                let jac: Vec<Vec<f64>> = (0..rows)
                    .map(|r| (0..m).map(|c| ((r * 7 + c * 3 + m) as f64 * 0.91).sin() * (1.0 + c as f64)).collect())
                    .collect();
                let mut mat: Mat = [[0.0; MAX_PARAMETERS + 1]; MAX_PARAMETERS];
                for r in 0..m {
                    for c in 0..m {
                        mat[r][c] = jac.iter().map(|row| row[r] * row[c]).sum();
                    }
                }
                for r in 0..m {
                    mat[r][r] += lambda * mat[r][r] + if lambda == 0.0 { 1e-3 } else { 0.0 };
                    mat[r][m] = (r as f64 * 1.3).cos();
                }
                let mut sol = [0.0; MAX_PARAMETERS];
                assert!(solve(&mat, m, &mut sol), "m {m}, {rows} rows");
                // Backward stable: measured up to 0.06 of ε·M·‖A‖·‖x‖ here, allowed 4.
                let norm_a = (0..m).map(|r| (0..m).map(|c| mat[r][c].abs()).sum::<f64>()).fold(0.0, f64::max);
                let norm_x = sol[..m].iter().fold(0.0f64, |v, x| v.max(x.abs()));
                let bound = 4.0 * f64::EPSILON * m as f64 * norm_a * norm_x;
                for r in 0..m {
                    let residual: f64 = (0..m).map(|c| mat[r][c] * sol[c]).sum::<f64>() - mat[r][m];
                    assert!(residual.abs() < bound, "m {m}, {rows} rows, row {r}: {residual:e} against {bound:e}");
                }
            }
            let mut mat: Mat = [[0.0; MAX_PARAMETERS + 1]; MAX_PARAMETERS];
            for r in 0..m {
                mat[r][r] = if r == m - 1 { -1.0 } else { 2.0 };
            }
            assert!(!solve(&mat, m, &mut [0.0; MAX_PARAMETERS]), "m {m}: indefinite");
            mat[m - 1][m - 1] = 0.0;
            assert!(!solve(&mat, m, &mut [0.0; MAX_PARAMETERS]), "m {m}: singular");
        }
    }
}
