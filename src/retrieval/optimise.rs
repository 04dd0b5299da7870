//! Small bounded optimisers for per-pixel inversions (n ≤ 8 parameters, analytic derivatives).
//!
//! - [`levenberg_marquardt`]: bounded nonlinear least squares min ½‖r(x)‖², lo ≤ x ≤ hi, with
//!   Marquardt's diagonal scaling (Moré 1978) and an active set: a parameter at a bound whose
//!   gradient pushes outward is held there for the step; steps are projected onto the box.
//! - [`projected_bfgs`]: a smooth objective with its gradient, by BFGS on the free variables with
//!   a projected Armijo backtracking line search (Bertsekas 1982, projected Newton methods).
//!
//! Why our own: the per-pixel problem is tiny and runs millions of times; a generic crate's
//! boxing, allocation and dynamic dispatch would cost more than the model evaluation, and the
//! crates at hand either lack box constraints for least squares (the `levenberg-marquardt` crate)
//! or tie us to an older ndarray (argmin-math, see RUST-NOTES). Both routines are ~150 lines and
//! tested on problems with known minima.
//!
//! ## References
//! - Moré, J. J. (1978) The Levenberg–Marquardt algorithm: implementation and theory. Lecture
//!   Notes in Mathematics 630, 105–116.
//! - Bertsekas, D. P. (1982) Projected Newton methods for optimization problems with simple
//!   constraints. SIAM J. Control Optim. 20, 221–246.
//! - Nocedal, J. & Wright, S. J. (2006) Numerical Optimization, 2nd ed., Springer (§6.1 BFGS,
//!   §10.3 Levenberg–Marquardt).
//! - Golub, G. H. & Van Loan, C. F. (2013) Matrix Computations, 4th ed., Johns Hopkins
//!   University Press (§4.1.2, the LDLᵀ factorisation of the damped step).
//! - Higham, N. J. (2002) Accuracy and Stability of Numerical Algorithms, 2nd ed., SIAM (§10.1,
//!   stability of the factorisation without pivoting on positive definite matrices).

/// Where an optimiser stopped.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// The parameters.
    pub x: Vec<f64>,
    /// The objective there (½‖r‖² for least squares).
    pub value: f64,
    /// Iterations taken.
    pub iterations: u32,
    /// Converged (by the tolerances) rather than stopped by the iteration limit.
    pub converged: bool,
}

/// Stopping rules.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Stop when an accepted step lowers the objective by less than this fraction.
    pub relative_decrease: f64,
    /// Stop when the objective falls below this.
    pub absolute: f64,
    /// Iteration limit.
    pub max_iterations: u32,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self { relative_decrease: 1e-10, absolute: 1e-30, max_iterations: 200 }
    }
}

/// Largest number of parameters the optimisers take (their working arrays live on the stack).
pub const MAX_PARAMETERS: usize = 8;

/// A row of a Jacobian (∂r_i/∂x_k for k < n; the rest unused), or of JᵀJ: fixed-size, so that a
/// fit's m rows are one allocation rather than m.
pub type Row = [f64; MAX_PARAMETERS];

/// Solve the n × n system (A + λ·diag A)·δ = −g on the free variables into `step` (zero for
/// fixed variables) by [`ldl_solve`]; false if the damped matrix is not numerically positive
/// definite (the caller then raises λ).
fn damped_step(a: &[Row], g: &[f64], lambda: f64, free: &[bool], step: &mut [f64]) -> bool {
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
/// the same, but its n(n+3)/2 chains of dependent additions overlap instead of running one
/// after another (a Levenberg–Marquardt iteration of a 28-band SAMBUCA fit spent most of its
/// own time waiting on them). The parameter count is a constant of each instance of
/// [`sums`], so that its accumulators can live in registers.
fn normal_equations(jac: &[Row], r: &[f64], g: &mut [f64], a: &mut [Row]) {
    // The match below has an arm for every count up to the damped step's limit.
    const _: () = assert!(MAX_PARAMETERS == 8);
    fn put<const N: usize>((g_sum, a_sum): ([f64; N], [[f64; N]; N]), g: &mut [f64], a: &mut [Row]) {
        g[..N].copy_from_slice(&g_sum);
        for k in 0..N {
            for q in 0..=k {
                (a[k][q], a[q][k]) = (a_sum[k][q], a_sum[k][q]);
            }
        }
    }
    match g.len() {
        0 => {}
        1 => put(sums::<1>(jac, r), g, a),
        2 => put(sums::<2>(jac, r), g, a),
        3 => put(sums::<3>(jac, r), g, a),
        4 => put(sums::<4>(jac, r), g, a),
        5 => put(sums::<5>(jac, r), g, a),
        6 => put(sums::<6>(jac, r), g, a),
        7 => put(sums::<7>(jac, r), g, a),
        _ => put(sums::<8>(jac, r), g, a),
    }
}

/// Jᵀr and the lower triangle of JᵀJ for N parameters (see [`normal_equations`]).
#[inline]
fn sums<const N: usize>(jac: &[Row], r: &[f64]) -> ([f64; N], [[f64; N]; N]) {
    let mut g = [-0.0f64; N];
    let mut a = [[-0.0f64; N]; N];
    for (row, &ri) in jac.iter().zip(r) {
        let row: [f64; N] = std::array::from_fn(|k| row[k]);
        for k in 0..N {
            g[k] += row[k] * ri;
            for q in 0..=k {
                a[k][q] += row[k] * row[q];
            }
        }
    }
    (g, a)
}

/// Bounded Levenberg–Marquardt of n = `x0.len()` ≤ [`MAX_PARAMETERS`] parameters (panics
/// above). `residuals(x, r, j)` fills the residual vector `r` and the Jacobian rows
/// `j[i][k]` = ∂r_i/∂x_k (k < n); it returns false if x is not admissible (the step is then
/// rejected). The Jacobian is computed at every trial point, so an accepted step costs one
/// evaluation.
pub fn levenberg_marquardt(
    mut residuals: impl FnMut(&[f64], &mut [f64], &mut [Row]) -> bool,
    x0: &[f64],
    lo: &[f64],
    hi: &[f64],
    m: usize,
    tol: &Tolerances,
) -> Solution {
    let n = x0.len();
    assert!(n <= MAX_PARAMETERS, "levenberg_marquardt takes at most {MAX_PARAMETERS} parameters, not {n}");
    let clamp = |x: &mut [f64]| {
        for i in 0..n {
            x[i] = x[i].clamp(lo[i], hi[i]);
        }
    };
    let mut x = x0.to_vec();
    clamp(&mut x);
    let mut r = vec![0.0; m];
    let mut jac = vec![[0.0; MAX_PARAMETERS]; m];
    if !residuals(&x, &mut r, &mut jac) {
        return Solution { x, value: f64::INFINITY, iterations: 0, converged: false };
    }
    let mut value = 0.5 * r.iter().map(|v| v * v).sum::<f64>();
    let mut lambda = 1e-3;
    let mut trial = vec![0.0; n];
    let mut trial_r = vec![0.0; m];
    let mut trial_jac = vec![[0.0; MAX_PARAMETERS]; m];
    let mut g = vec![0.0; n];
    let mut a = [[0.0; MAX_PARAMETERS]; MAX_PARAMETERS];
    let mut free = vec![true; n];
    let mut step = vec![0.0; n];
    let mut iterations = 0;
    let mut converged = false;
    while iterations < tol.max_iterations {
        iterations += 1;
        if value <= tol.absolute {
            converged = true;
            break;
        }
        normal_equations(&jac[..m], &r[..m], &mut g, &mut a[..n]);
        for k in 0..n {
            free[k] = !((x[k] <= lo[k] && g[k] > 0.0) || (x[k] >= hi[k] && g[k] < 0.0));
        }
        if !free.iter().any(|f| *f) {
            converged = true;
            break;
        }
        let mut accepted = false;
        while lambda < 1e16 {
            if !damped_step(&a, &g, lambda, &free, &mut step) {
                lambda *= 10.0;
                continue;
            }
            for k in 0..n {
                trial[k] = (x[k] + step[k]).clamp(lo[k], hi[k]);
            }
            if trial == x {
                break;
            }
            if residuals(&trial, &mut trial_r, &mut trial_jac) {
                let trial_value = 0.5 * trial_r.iter().map(|v| v * v).sum::<f64>();
                if trial_value < value {
                    let decrease = (value - trial_value) / value;
                    std::mem::swap(&mut x, &mut trial);
                    std::mem::swap(&mut r, &mut trial_r);
                    std::mem::swap(&mut jac, &mut trial_jac);
                    value = trial_value;
                    lambda = (lambda / 3.0).max(1e-15);
                    accepted = true;
                    if decrease < tol.relative_decrease {
                        converged = true;
                    }
                    break;
                }
            }
            lambda *= 4.0;
        }
        if !accepted || converged {
            // No step lowers the objective: a (bounded) stationary point to working precision.
            converged = true;
            break;
        }
    }
    Solution { x, value, iterations, converged }
}

/// Bounded BFGS. `objective(x, grad)` returns f(x) and fills ∇f (or returns `None` if x is not
/// admissible).
pub fn projected_bfgs(
    mut objective: impl FnMut(&[f64], &mut [f64]) -> Option<f64>,
    x0: &[f64],
    lo: &[f64],
    hi: &[f64],
    tol: &Tolerances,
) -> Solution {
    let n = x0.len();
    let project = |x: &mut [f64]| {
        for i in 0..n {
            x[i] = x[i].clamp(lo[i], hi[i]);
        }
    };
    let mut x = x0.to_vec();
    project(&mut x);
    let mut g = vec![0.0; n];
    let Some(mut f) = objective(&x, &mut g) else {
        return Solution { x, value: f64::INFINITY, iterations: 0, converged: false };
    };
    let mut h: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| f64::from(u8::from(i == j))).collect()).collect();
    let mut iterations = 0;
    let mut converged = false;
    let mut g_new = vec![0.0; n];
    while iterations < tol.max_iterations {
        iterations += 1;
        if f <= tol.absolute {
            converged = true;
            break;
        }
        let free: Vec<bool> =
            (0..n).map(|k| !((x[k] <= lo[k] && g[k] > 0.0) || (x[k] >= hi[k] && g[k] < 0.0))).collect();
        let d: Vec<f64> = (0..n)
            .map(|i| if free[i] { -(0..n).filter(|&j| free[j]).map(|j| h[i][j] * g[j]).sum::<f64>() } else { 0.0 })
            .collect();
        let slope: f64 = d.iter().zip(&g).map(|(a, b)| a * b).sum();
        let d = if slope < 0.0 { d } else { (0..n).map(|i| if free[i] { -g[i] } else { 0.0 }).collect() };
        let mut t = 1.0;
        let mut moved = false;
        for _ in 0..40 {
            let mut trial: Vec<f64> = x.iter().zip(&d).map(|(a, b)| a + t * b).collect();
            project(&mut trial);
            let decrease: f64 = g.iter().zip(trial.iter().zip(&x)).map(|(g, (a, b))| g * (a - b)).sum();
            if let Some(f_new) = objective(&trial, &mut g_new)
                && f_new <= f + 1e-4 * decrease
                && f_new < f
            {
                let s: Vec<f64> = trial.iter().zip(&x).map(|(a, b)| a - b).collect();
                let y: Vec<f64> = g_new.iter().zip(&g).map(|(a, b)| a - b).collect();
                let sy: f64 = s.iter().zip(&y).map(|(a, b)| a * b).sum();
                if sy > 1e-300 {
                    // Inverse-Hessian update (Nocedal & Wright eq. 6.17).
                    let hy: Vec<f64> = (0..n).map(|i| (0..n).map(|j| h[i][j] * y[j]).sum()).collect();
                    let yhy: f64 = y.iter().zip(&hy).map(|(a, b)| a * b).sum();
                    for i in 0..n {
                        for j in 0..n {
                            h[i][j] += (sy + yhy) * s[i] * s[j] / (sy * sy) - (hy[i] * s[j] + s[i] * hy[j]) / sy;
                        }
                    }
                }
                let rel = (f - f_new) / f.abs().max(1e-300);
                x = trial;
                f = f_new;
                g.copy_from_slice(&g_new);
                moved = true;
                if rel < tol.relative_decrease {
                    converged = true;
                }
                break;
            }
            t *= 0.5;
        }
        if !moved || converged {
            converged = true;
            break;
        }
    }
    Solution { x, value: f, iterations, converged }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-pass sums are each sum added alone, bit for bit, for every parameter count
    /// (and a sum of −0.0 terms only, whose sign the starting value decides).
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

    #[test]
    fn lm_fits_an_exponential_and_respects_bounds() {
        // y = 2·exp(−0.7 t); with the rate bounded at 0.5, the fit sits on the bound.
        let t: Vec<f64> = (0..20).map(|i| f64::from(i) * 0.25).collect();
        let y: Vec<f64> = t.iter().map(|t| 2.0 * (-0.7 * t).exp()).collect();
        let model = |x: &[f64], r: &mut [f64], j: &mut [Row]| {
            for (i, (t, y)) in t.iter().zip(&y).enumerate() {
                r[i] = x[0] * (-x[1] * t).exp() - y;
                j[i][0] = (-x[1] * t).exp();
                j[i][1] = -x[0] * t * (-x[1] * t).exp();
            }
            true
        };
        let s = levenberg_marquardt(model, &[1.0, 0.1], &[0.0, 0.0], &[10.0, 5.0], 20, &Tolerances::default());
        assert!((s.x[0] - 2.0).abs() < 1e-9 && (s.x[1] - 0.7).abs() < 1e-9, "{:?}", s.x);
        assert!(s.converged);
        let s = levenberg_marquardt(model, &[1.0, 0.1], &[0.0, 0.0], &[10.0, 0.5], 20, &Tolerances::default());
        assert_eq!(s.x[1], 0.5);
    }

    #[test]
    fn bfgs_minimises_rosenbrock_in_a_box() {
        let rosen = |x: &[f64], g: &mut [f64]| {
            let (a, b) = (1.0 - x[0], x[1] - x[0] * x[0]);
            g[0] = -2.0 * a - 400.0 * x[0] * b;
            g[1] = 200.0 * b;
            Some(a * a + 100.0 * b * b)
        };
        let tol = Tolerances { max_iterations: 2000, relative_decrease: 1e-16, absolute: 1e-20 };
        let s = projected_bfgs(rosen, &[-1.2, 1.0], &[-2.0, -2.0], &[2.0, 2.0], &tol);
        assert!((s.x[0] - 1.0).abs() < 1e-4 && (s.x[1] - 1.0).abs() < 1e-4, "{:?} {}", s.x, s.value);
        // With x ≤ 0.5 the minimum is on the bound.
        let s = projected_bfgs(rosen, &[-1.2, 1.0], &[-2.0, -2.0], &[0.5, 2.0], &tol);
        assert!((s.x[0] - 0.5).abs() < 1e-9 && (s.x[1] - 0.25).abs() < 1e-3, "{:?}", s.x);
    }
}
