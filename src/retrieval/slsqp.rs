//! SLSQP for simple bounds, as SciPy's `minimize(method="SLSQP")` runs it with no Jacobian: the
//! optimiser of SAMBUCA's reference mode ([`super::sambuca_reference`]).
//!
//! Kraft's sequential least-squares quadratic programming (Kraft 1988; ACM TOMS 733, 1994) with
//! bounds only, so that no general constraint enters the merit function:
//!
//! 1. **Search direction.** s minimises ½sᵀBs + gᵀs subject to l − x ≤ s ≤ u − x, where
//!    B = LDLᵀ is the quasi-Newton matrix (B = I at the start and after a reset). SLSQP solves
//!    this QP as a least-distance problem (LSQ → LSEI → LSI → NNLS); the QP is strictly convex, so
//!    its solution is unique and any exact method gives it: here a primal active-set method
//!    (`box_qp`). The step is then clipped into the box, as SciPy's SLSQP does.
//! 2. **Stationarity.** If |gᵀs| < acc the run ends with success (mode 0).
//! 3. **Descent.** If gᵀs ≥ 0, B is reset to I (at most 5 times; then SLSQP's relaxed test,
//!    |f − f0| < 10·acc or ‖s‖ < 10·acc, which passes since f − f0 = 0 there).
//! 4. **Line search** (inexact, Armijo with the L1 test function, which is f itself without
//!    constraints): α = 1; accept when f(x0 + αs) − f0 ≤ 0.1·α·gᵀs or after 10 trials, else
//!    α ← max(α·gᵀs / (2(α·gᵀs − Δf)), 0.1) relative to the current step.
//! 5. **Convergence.** Success (mode 0) when |f − f0| < acc or ‖s‖ < acc after the step — the
//!    test that stops SAMBUCA's fits where the bottom is out of sight: f changes by less than
//!    acc = ftol = 1e-6 although depth and q have not moved.
//! 6. **BFGS update** of LDLᵀ with Powell's damping: y = g₁ − g₀; if sᵀy < 0.2·sᵀBs, y is replaced
//!    by θy + (1 − θ)Bs with θ = 0.8·sᵀBs/(sᵀBs − sᵀy); then LDLᵀ + yyᵀ/sᵀy − (Bs)(Bs)ᵀ/sᵀBs as two
//!    rank-one modifications (Fletcher & Powell 1974), which keep D positive.
//!
//! Gradients are SciPy's 2-point forward differences with the absolute step √ε = 1.49e-8 (the
//! `eps` option's default), taken backwards where the forward point would leave the box, and
//! divided by the step as actually represented, (x + h) − x.
//!
//! Iterations (`nit`) count as SciPy's `nit` does: every pass of the main loop, resets included;
//! more than `max_iterations` ends with mode 9 ("Iteration limit reached", not a success).
//!
//! One departure, for the hard-case promise: a non-finite objective in the line search counts as
//! no decrease (the step is shortened), where SLSQP would carry the NaN on; if no trial is finite
//! the run ends at the last finite point ([`SlsqpStatus::NonFinite`], not a success).
//!
//! ## References
//! - Kraft, D. (1988) A software package for sequential quadratic programming. DFVLR-FB 88-28.
//! - Kraft, D. (1994) Algorithm 733: TOMP — Fortran modules for optimal control calculations.
//!   ACM Trans. Math. Softw. 20, 262–281.
//! - Fletcher, R., Powell, M. J. D. (1974) On the modification of LDLᵀ factorizations.
//!   Math. Comp. 28, 1067–1087.
//! - Powell, M. J. D. (1978) A fast algorithm for nonlinearly constrained optimization
//!   calculations. Lecture Notes in Mathematics 630, 144–157 (the damped BFGS update).

use super::slsqp_qp::{Ldl, box_qp, dot, norm};

/// Settings of one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlsqpOptions {
    /// Iteration limit (SciPy's `maxiter`).
    pub max_iterations: u32,
    /// Accuracy `acc` (SciPy's `ftol`): the absolute change of f that ends the run.
    pub ftol: f64,
    /// Absolute finite-difference step (SciPy's `eps`).
    pub fd_step: f64,
}

impl Default for SlsqpOptions {
    /// SciPy's defaults: `maxiter` 100, `ftol` 1e-6, `eps` √ε.
    fn default() -> Self {
        Self { max_iterations: 100, ftol: 1e-6, fd_step: f64::EPSILON.sqrt() }
    }
}

/// How a run ended, with SLSQP's mode numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlsqpStatus {
    /// Mode 0: "Optimization terminated successfully".
    Converged,
    /// Mode 8: "Positive directional derivative for linesearch".
    PositiveDirectionalDerivative,
    /// Mode 9: "Iteration limit reached".
    IterationLimit,
    /// Shoal's own (SLSQP would carry a NaN on): no finite f along the step.
    NonFinite,
}

impl SlsqpStatus {
    /// SLSQP's mode number.
    #[must_use]
    pub fn mode(self) -> i32 {
        match self {
            Self::Converged => 0,
            Self::PositiveDirectionalDerivative => 8,
            Self::IterationLimit => 9,
            Self::NonFinite => -1,
        }
    }
}

/// The result of one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlsqpResult<const N: usize> {
    /// The last iterate.
    pub x: [f64; N],
    /// f at `x`.
    pub fun: f64,
    /// How the run ended.
    pub status: SlsqpStatus,
    /// Main-loop iterations.
    pub nit: u32,
    /// Objective evaluations, finite differences included.
    pub nfev: u32,
}

impl<const N: usize> SlsqpResult<N> {
    /// SciPy's `success`: mode 0.
    #[must_use]
    pub fn success(&self) -> bool {
        self.status == SlsqpStatus::Converged
    }
}

/// Minimise `f` over the box [`lo`, `hi`] from `x0` (clipped into the box first).
pub fn slsqp<const N: usize>(
    mut f: impl FnMut(&[f64; N]) -> f64,
    x0: &[f64; N],
    lo: &[f64; N],
    hi: &[f64; N],
    options: &SlsqpOptions,
) -> SlsqpResult<N> {
    let acc = options.ftol.abs();
    let relaxed = 10.0 * acc;
    let mut nfev = 0u32;
    let mut eval = |x: &[f64; N], nfev: &mut u32| {
        *nfev += 1;
        let v = f(x);
        if v.is_finite() { v } else { f64::INFINITY }
    };
    let mut x = clip(x0, lo, hi);
    let mut fx = eval(&x, &mut nfev);
    let mut g = gradient(&mut eval, &x, fx, lo, hi, options.fd_step, &mut nfev);
    let mut ldl = Ldl::<N>::identity();
    let mut resets = 1u32;
    let mut nit = 0u32;
    let done =
        |x: [f64; N], fun: f64, status: SlsqpStatus, nit: u32, nfev: u32| SlsqpResult { x, fun, status, nit, nfev };
    loop {
        nit += 1;
        if nit > options.max_iterations {
            return done(x, fx, SlsqpStatus::IterationLimit, options.max_iterations, nfev);
        }
        // 1. The QP: the step to the minimum of the quadratic model inside the box.
        let mut lo_s = [0.0; N];
        let mut hi_s = [0.0; N];
        for i in 0..N {
            lo_s[i] = lo[i] - x[i];
            hi_s[i] = hi[i] - x[i];
        }
        let mut s = clip(&box_qp(&ldl, &g, &lo_s, &hi_s), &lo_s, &hi_s);
        let (f0, x0) = (fx, x);
        let gs = dot(&g, &s);
        // 2. Stationary: the model predicts (almost) no decrease.
        if gs.abs() < acc {
            return done(x, fx, SlsqpStatus::Converged, nit, nfev);
        }
        // 3. Not a descent direction: restart from B = I, at most five times.
        if gs >= 0.0 {
            resets += 1;
            if resets > 5 {
                return done(x, fx, relaxed_test(fx - f0, &s, relaxed), nit, nfev);
            }
            ldl = Ldl::identity();
            continue;
        }
        // 4. Armijo line search on f (the L1 test function without constraints).
        let (mut alpha, mut slope, mut line) = (1.0, gs, 0);
        loop {
            line += 1;
            slope *= alpha;
            for i in 0..N {
                s[i] *= alpha;
                x[i] = x0[i] + s[i];
            }
            x = clip(&x, lo, hi);
            fx = eval(&x, &mut nfev);
            let decrease = fx - f0;
            if decrease <= slope / 10.0 || line > 10 {
                break;
            }
            alpha = (slope / (2.0 * (slope - decrease))).max(0.1);
        }
        if !fx.is_finite() {
            // Eleven trials along the step found no finite f: end at the last finite point.
            return done(x0, f0, SlsqpStatus::NonFinite, nit, nfev);
        }
        // 5. Converged when f stopped changing or the step vanished.
        if (fx - f0).abs() < acc || norm(&s) < acc {
            return done(x, fx, SlsqpStatus::Converged, nit, nfev);
        }
        // 6. Damped BFGS update of B = LDLᵀ.
        let g_new = gradient(&mut eval, &x, fx, lo, hi, options.fd_step, &mut nfev);
        let mut y = [0.0; N];
        for i in 0..N {
            y[i] = g_new[i] - g[i];
        }
        let bs = ldl.times(&s);
        let (mut sy, sbs) = (dot(&s, &y), dot(&s, &bs));
        if sy < 0.2 * sbs {
            let theta = (sbs - 0.2 * sbs) / (sbs - sy);
            for i in 0..N {
                y[i] = theta * y[i] + (1.0 - theta) * bs[i];
            }
            sy = 0.2 * sbs;
        }
        if sy == 0.0 || sbs == 0.0 {
            // A singular update: restart from B = I (SciPy ≥ 1.16 does the same).
            g = g_new;
            resets += 1;
            if resets > 5 {
                return done(x, fx, relaxed_test(fx - f0, &s, relaxed), nit, nfev);
            }
            ldl = Ldl::identity();
            continue;
        }
        ldl.rank_one(&y, 1.0 / sy);
        ldl.rank_one(&bs, -1.0 / sbs);
        g = g_new;
    }
}

/// SLSQP's relaxed test after five resets, as SciPy ≥ 1.16 runs it (no constraint violation to
/// test): success if f changed by less than 10·acc (on the reset path f − f0 is 0, so it passes)
/// or the step is that short.
fn relaxed_test<const N: usize>(df: f64, s: &[f64; N], relaxed: f64) -> SlsqpStatus {
    if df.abs() < relaxed || norm(s) < relaxed {
        SlsqpStatus::Converged
    } else {
        SlsqpStatus::PositiveDirectionalDerivative
    }
}

/// SciPy's 2-point forward-difference gradient with absolute step `h`: backwards where x + h
/// would leave the box (and the backward point fits), divided by the represented step.
fn gradient<const N: usize>(
    eval: &mut impl FnMut(&[f64; N], &mut u32) -> f64,
    x: &[f64; N],
    fx: f64,
    lo: &[f64; N],
    hi: &[f64; N],
    h: f64,
    nfev: &mut u32,
) -> [f64; N] {
    let mut g = [0.0; N];
    for i in 0..N {
        let mut step = h;
        if x[i] + h == x[i] {
            // Too small to move x: SciPy falls back to a relative step.
            step = f64::EPSILON.sqrt() * x[i].abs().max(1.0) * if x[i] >= 0.0 { 1.0 } else { -1.0 };
        }
        let forward = x[i] + step;
        let fits = step.abs() <= (lo[i] - x[i]).max(hi[i] - x[i]);
        if (forward < lo[i] || forward > hi[i]) && fits {
            step = -step;
        }
        let mut xs = *x;
        xs[i] = x[i] + step;
        let dx = xs[i] - x[i];
        g[i] = (eval(&xs, nfev) - fx) / dx;
    }
    g
}

fn clip<const N: usize>(x: &[f64; N], lo: &[f64; N], hi: &[f64; N]) -> [f64; N] {
    let mut out = *x;
    for i in 0..N {
        out[i] = out[i].max(lo[i]).min(hi[i]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimises_a_bounded_rosenbrock() {
        // Rosenbrock with the box cutting off the minimum at (1, 1): the constrained minimum
        // lies on x0 = 0.5 at x1 = 0.25.
        let f = |x: &[f64; 2]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
        let r = slsqp(f, &[-1.0, 2.0], &[-2.0, -2.0], &[0.5, 2.0], &SlsqpOptions::default());
        assert!(r.success(), "{r:?}");
        assert!((r.x[0] - 0.5).abs() < 1e-6 && (r.x[1] - 0.25).abs() < 1e-3, "{r:?}");
    }

    #[test]
    fn stops_where_f_stops_changing() {
        // A function nearly flat in x1: SLSQP's |Δf| < ftol test ends the run with success
        // although x1 is far from its minimiser (the SAMBUCA stall, in two variables).
        let f = |x: &[f64; 2]| (x[0] - 1.0).powi(2) + 1e-9 * (x[1] - 5.0).powi(2);
        let r = slsqp(f, &[0.0, 0.0], &[-10.0, -10.0], &[10.0, 10.0], &SlsqpOptions::default());
        assert!(r.success());
        assert!((r.x[0] - 1.0).abs() < 1e-3);
        assert!(r.x[1].abs() < 0.1, "x1 moved to {}", r.x[1]);
    }

    #[test]
    fn iteration_limit_is_not_success() {
        let f = |x: &[f64; 2]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
        let options = SlsqpOptions { max_iterations: 2, ..SlsqpOptions::default() };
        let r = slsqp(f, &[-1.2, 1.0], &[-5.0, -5.0], &[5.0, 5.0], &options);
        assert_eq!(r.status, SlsqpStatus::IterationLimit);
        assert!(!r.success());
    }
}
