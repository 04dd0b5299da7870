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

mod normal;

use normal::{damped_step, normal_equations};

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

/// The working arrays of [`levenberg_marquardt_in`] whose size follows the residual count m:
/// kept between fits, so that a pixel's fits (one per substrate pair and start) allocate them
/// once rather than at every fit.
#[derive(Debug, Clone, Default)]
pub struct Workspace {
    r: Vec<f64>,
    jac: Vec<Row>,
    trial_r: Vec<f64>,
    trial_jac: Vec<Row>,
}

impl Workspace {
    fn resize(&mut self, m: usize) {
        self.r.resize(m, 0.0);
        self.trial_r.resize(m, 0.0);
        self.jac.resize(m, [0.0; MAX_PARAMETERS]);
        self.trial_jac.resize(m, [0.0; MAX_PARAMETERS]);
    }
}

/// Bounded Levenberg–Marquardt of n = `x0.len()` ≤ [`MAX_PARAMETERS`] parameters (panics
/// above). `residuals(x, r, j)` fills the residual vector `r` and the Jacobian rows
/// `j[i][k]` = ∂r_i/∂x_k (k < n); it returns false if x is not admissible (the step is then
/// rejected). The Jacobian is computed at every trial point, so an accepted step costs one
/// evaluation.
pub fn levenberg_marquardt(
    residuals: impl FnMut(&[f64], &mut [f64], &mut [Row]) -> bool,
    x0: &[f64],
    lo: &[f64],
    hi: &[f64],
    m: usize,
    tol: &Tolerances,
) -> Solution {
    levenberg_marquardt_in(&mut Workspace::default(), residuals, (x0, lo, hi), m, tol)
}

/// [`levenberg_marquardt`] in `work` (whatever it held: the same solution).
pub fn levenberg_marquardt_in(
    work: &mut Workspace,
    mut residuals: impl FnMut(&[f64], &mut [f64], &mut [Row]) -> bool,
    (x0, lo, hi): (&[f64], &[f64], &[f64]),
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
    work.resize(m);
    let Workspace { r, jac, trial_r, trial_jac } = work;
    // The n-sized arrays live on the stack; only their first n entries are used.
    let mut x = [0.0; MAX_PARAMETERS];
    x[..n].copy_from_slice(x0);
    clamp(&mut x);
    if !residuals(&x[..n], r, jac) {
        return Solution { x: x[..n].to_vec(), value: f64::INFINITY, iterations: 0, converged: false };
    }
    let mut value = 0.5 * r.iter().map(|v| v * v).sum::<f64>();
    let mut lambda = 1e-3;
    let mut trial = [0.0; MAX_PARAMETERS];
    let mut g = [0.0; MAX_PARAMETERS];
    let mut a = [[0.0; MAX_PARAMETERS]; MAX_PARAMETERS];
    let mut free = [true; MAX_PARAMETERS];
    let mut step = [0.0; MAX_PARAMETERS];
    let mut iterations = 0;
    let mut converged = false;
    while iterations < tol.max_iterations {
        iterations += 1;
        if value <= tol.absolute {
            converged = true;
            break;
        }
        normal_equations(&jac[..m], &r[..m], &mut g[..n], &mut a[..n]);
        for k in 0..n {
            free[k] = !((x[k] <= lo[k] && g[k] > 0.0) || (x[k] >= hi[k] && g[k] < 0.0));
        }
        if !free[..n].iter().any(|f| *f) {
            converged = true;
            break;
        }
        let mut accepted = false;
        while lambda < 1e16 {
            if !damped_step(&a, &g[..n], lambda, &free[..n], &mut step[..n]) {
                lambda *= 10.0;
                continue;
            }
            for k in 0..n {
                trial[k] = (x[k] + step[k]).clamp(lo[k], hi[k]);
            }
            if trial[..n] == x[..n] {
                break;
            }
            if residuals(&trial[..n], trial_r, trial_jac) {
                let trial_value = 0.5 * trial_r.iter().map(|v| v * v).sum::<f64>();
                if trial_value < value {
                    let decrease = (value - trial_value) / value;
                    std::mem::swap(&mut x, &mut trial);
                    std::mem::swap(r, trial_r);
                    std::mem::swap(jac, trial_jac);
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
    Solution { x: x[..n].to_vec(), value, iterations, converged }
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
