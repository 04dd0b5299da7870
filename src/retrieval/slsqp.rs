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

fn dot<const N: usize>(a: &[f64; N], b: &[f64; N]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm<const N: usize>(a: &[f64; N]) -> f64 {
    dot(a, a).sqrt()
}

/// B = LDLᵀ with L unit lower triangular and D > 0.
#[derive(Debug, Clone, Copy)]
struct Ldl<const N: usize> {
    l: [[f64; N]; N],
    d: [f64; N],
}

impl<const N: usize> Ldl<N> {
    fn identity() -> Self {
        let mut l = [[0.0; N]; N];
        for (i, row) in l.iter_mut().enumerate() {
            row[i] = 1.0;
        }
        Self { l, d: [1.0; N] }
    }

    /// B as a dense matrix.
    #[cfg(test)]
    fn matrix(&self) -> [[f64; N]; N] {
        let mut b = [[0.0; N]; N];
        for i in 0..N {
            for j in 0..=i {
                let v: f64 = (0..=j).map(|k| self.l[i][k] * self.d[k] * self.l[j][k]).sum();
                b[i][j] = v;
                b[j][i] = v;
            }
        }
        b
    }

    /// B·v.
    fn times(&self, v: &[f64; N]) -> [f64; N] {
        // Lᵀv, then D, then L.
        let mut t = [0.0; N];
        for k in 0..N {
            t[k] = self.d[k] * (k..N).map(|i| self.l[i][k] * v[i]).sum::<f64>();
        }
        let mut out = [0.0; N];
        for i in 0..N {
            out[i] = (0..=i).map(|k| self.l[i][k] * t[k]).sum();
        }
        out
    }

    /// LDLᵀ ← LDLᵀ + σzzᵀ (Fletcher & Powell 1974, the "t" form of Gill et al.'s method C1).
    /// With σ < 0 the t_i are computed backwards from t_n = 1/σ + zᵀB⁻¹z, and t_n is kept
    /// negative (ε/σ if rounding made it ≥ 0) so that every D stays positive.
    fn rank_one(&mut self, z: &[f64; N], sigma: f64) {
        if sigma == 0.0 || !sigma.is_finite() {
            return;
        }
        // v = L⁻¹z.
        let mut v = *z;
        for i in 0..N {
            for k in 0..i {
                v[i] -= self.l[i][k] * v[k];
            }
        }
        let mut t = vec![0.0; N + 1];
        if sigma > 0.0 {
            t[0] = 1.0 / sigma;
            for i in 0..N {
                t[i + 1] = t[i] + v[i] * v[i] / self.d[i];
            }
        } else {
            let mut tn = 1.0 / sigma + (0..N).map(|i| v[i] * v[i] / self.d[i]).sum::<f64>();
            if tn >= 0.0 {
                tn = f64::EPSILON / sigma;
            }
            t[N] = tn;
            for i in (0..N).rev() {
                t[i] = t[i + 1] - v[i] * v[i] / self.d[i];
            }
        }
        // Forward sweep; where a column's D grows by more than 4× the update is formed from the old
        // column instead (the composite-t method's second form, better conditioned there).
        let mut w = *z;
        for j in 0..N {
            let p = w[j];
            let beta = p / (self.d[j] * t[j + 1]);
            let ratio = t[j + 1] / t[j];
            self.d[j] *= ratio;
            if ratio <= 4.0 {
                for r in j + 1..N {
                    w[r] -= p * self.l[r][j];
                    self.l[r][j] += beta * w[r];
                }
            } else {
                let gamma = t[j] / t[j + 1];
                for r in j + 1..N {
                    let old = self.l[r][j];
                    self.l[r][j] = gamma * old + beta * w[r];
                    w[r] -= p * old;
                }
            }
        }
    }
}

/// Where a variable of [`box_qp`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Bound {
    Free,
    Lower,
    Upper,
}

/// The minimiser of ½sᵀBs + gᵀs over lo ≤ s ≤ hi for B = LDLᵀ (D > 0; lo ≤ 0 ≤ hi).
///
/// Posed, as SLSQP's LSQ poses it, as the bounded least-squares problem min ‖Es − f‖ with
/// E = D^½Lᵀ and f = −D^−½L⁻¹g (‖Es − f‖² = sᵀBs + 2gᵀs + const), so that the conditioning is that
/// of E, the square root of B's: quasi-Newton matrices here reach condition numbers of 1e12,
/// where forming B and factoring it again would lose half the digits of the step.
///
/// Solved by a primal active-set method (Nocedal & Wright 2006, Algorithm 16.3) from s = 0: on
/// the free variables, the least-squares step by Householder QR; step to it or to the first bound
/// in the way (which joins the active set); at a stationary point release the bound whose
/// multiplier (the gradient Eᵀ(Es − f)) has the wrong sign, or stop. Finite for a strictly convex
/// QP.
fn box_qp<const N: usize>(ldl: &Ldl<N>, g: &[f64; N], lo: &[f64; N], hi: &[f64; N]) -> [f64; N] {
    // E = D^½Lᵀ (upper triangular), f = −D^−½L⁻¹g.
    let mut e = [[0.0; N]; N];
    let mut f = *g;
    for k in 0..N {
        let root = ldl.d[k].sqrt();
        for i in k..N {
            e[k][i] = root * ldl.l[i][k];
        }
    }
    for i in 0..N {
        for k in 0..i {
            f[i] -= ldl.l[i][k] * f[k];
        }
    }
    for k in 0..N {
        f[k] = -f[k] / ldl.d[k].sqrt();
    }
    let mut s = [0.0; N];
    let mut state = [Bound::Free; N];
    for i in 0..N {
        // A box that does not contain 0 (rounding in hi − x): start on its nearest side.
        if lo[i] >= 0.0 {
            s[i] = lo[i];
            state[i] = Bound::Lower;
        } else if hi[i] <= 0.0 {
            s[i] = hi[i];
            state[i] = Bound::Upper;
        }
    }
    for _ in 0..20 * (N + 1) {
        // Residual f − Es and the model's gradient −Eᵀ(f − Es).
        let mut r = f;
        for k in 0..N {
            r[k] -= (k..N).map(|i| e[k][i] * s[i]).sum::<f64>();
        }
        let free: Vec<usize> = (0..N).filter(|&i| state[i] == Bound::Free).collect();
        let p = least_squares_step(&e, &r, &free);
        let moving = free.iter().any(|&i| p[i].abs() > 1e-15 * (1.0 + s[i].abs()));
        if !moving {
            let grad = |i: usize| -(0..=i).map(|k| e[k][i] * r[k]).sum::<f64>();
            // Multipliers: at a lower bound the gradient must be ≥ 0, at an upper ≤ 0.
            let worst = (0..N)
                .filter_map(|i| match state[i] {
                    Bound::Lower if grad(i) < 0.0 => Some((i, -grad(i))),
                    Bound::Upper if grad(i) > 0.0 => Some((i, grad(i))),
                    _ => None,
                })
                .max_by(|a, b| a.1.total_cmp(&b.1));
            match worst {
                Some((i, _)) => state[i] = Bound::Free,
                None => return s,
            }
            continue;
        }
        let mut alpha = 1.0;
        let mut blocking = None;
        for &i in &free {
            let limit = if p[i] < 0.0 {
                (lo[i] - s[i]) / p[i]
            } else if p[i] > 0.0 {
                (hi[i] - s[i]) / p[i]
            } else {
                f64::INFINITY
            };
            if limit < alpha {
                alpha = limit.max(0.0);
                blocking = Some(i);
            }
        }
        for &i in &free {
            s[i] += alpha * p[i];
        }
        if let Some(i) = blocking {
            if p[i] < 0.0 {
                s[i] = lo[i];
                state[i] = Bound::Lower;
            } else {
                s[i] = hi[i];
                state[i] = Bound::Upper;
            }
        }
    }
    s
}

/// argmin_p ‖E_F p − r‖ over the columns `free` of E (Householder QR; zeros elsewhere).
fn least_squares_step<const N: usize>(e: &[[f64; N]; N], r: &[f64; N], free: &[usize]) -> [f64; N] {
    let k = free.len();
    let mut out = [0.0; N];
    if k == 0 {
        return out;
    }
    // Working copy: columns of E_F, then the right-hand side.
    let mut a = [[0.0; N]; N];
    for (c, &j) in free.iter().enumerate() {
        for row in 0..N {
            a[row][c] = e[row][j];
        }
    }
    let mut b = *r;
    for c in 0..k {
        let norm = (c..N).map(|row| a[row][c] * a[row][c]).sum::<f64>().sqrt();
        if norm == 0.0 {
            continue;
        }
        let alpha = if a[c][c] > 0.0 { -norm } else { norm };
        // v = a[c..][c] − alpha·e₁, applied as H = I − 2vvᵀ/vᵀv.
        let mut v = [0.0; N];
        for row in c..N {
            v[row] = a[row][c];
        }
        v[c] -= alpha;
        let vv: f64 = (c..N).map(|row| v[row] * v[row]).sum();
        if vv == 0.0 {
            continue;
        }
        for col in c..k {
            let t = 2.0 * (c..N).map(|row| v[row] * a[row][col]).sum::<f64>() / vv;
            for row in c..N {
                a[row][col] -= t * v[row];
            }
        }
        let t = 2.0 * (c..N).map(|row| v[row] * b[row]).sum::<f64>() / vv;
        for row in c..N {
            b[row] -= t * v[row];
        }
    }
    // Back substitution R p = (Qᵀr)[..k].
    let mut p = [0.0; N];
    for c in (0..k).rev() {
        let mut v = b[c];
        for col in c + 1..k {
            v -= a[c][col] * p[col];
        }
        p[c] = if a[c][c] != 0.0 { v / a[c][c] } else { 0.0 };
    }
    for (c, &j) in free.iter().enumerate() {
        out[j] = p[c];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// LDLᵀ of a symmetric positive definite matrix.
    fn ldl_of<const N: usize>(b: &[[f64; N]; N]) -> Ldl<N> {
        let mut ldl = Ldl::<N>::identity();
        for j in 0..N {
            ldl.d[j] = b[j][j] - (0..j).map(|k| ldl.l[j][k] * ldl.l[j][k] * ldl.d[k]).sum::<f64>();
            for i in j + 1..N {
                ldl.l[i][j] = (b[i][j] - (0..j).map(|k| ldl.l[i][k] * ldl.l[j][k] * ldl.d[k]).sum::<f64>()) / ldl.d[j];
            }
        }
        ldl
    }

    /// The box QP's minimum by brute force: every free/lower/upper pattern, the free part solved
    /// by Cramer-free Gaussian elimination, the best feasible value kept.
    fn brute_force(b: &[[f64; 3]; 3], g: &[f64; 3], lo: &[f64; 3], hi: &[f64; 3]) -> [f64; 3] {
        let value = |s: &[f64; 3]| {
            (0..3).map(|i| g[i] * s[i] + 0.5 * s[i] * (0..3).map(|j| b[i][j] * s[j]).sum::<f64>()).sum::<f64>()
        };
        let mut best = ([0.0; 3], f64::INFINITY);
        for code in 0..27 {
            let state = [code % 3, (code / 3) % 3, code / 9];
            let mut s = [0.0; 3];
            for i in 0..3 {
                s[i] = [0.0, lo[i], hi[i]][state[i]];
            }
            let free: Vec<usize> = (0..3).filter(|&i| state[i] == 0).collect();
            // Solve B_FF s_F = −(g + B_FX s_X) by elimination on the small system.
            let n = free.len();
            let mut m = vec![vec![0.0; n + 1]; n];
            for (a, &i) in free.iter().enumerate() {
                for (c, &j) in free.iter().enumerate() {
                    m[a][c] = b[i][j];
                }
                m[a][n] = -g[i] - (0..3).filter(|j| state[*j] != 0).map(|j| b[i][j] * s[j]).sum::<f64>();
            }
            for c in 0..n {
                for r in c + 1..n {
                    let t = m[r][c] / m[c][c];
                    for k in c..=n {
                        m[r][k] -= t * m[c][k];
                    }
                }
            }
            for c in (0..n).rev() {
                let v = m[c][n] - (c + 1..n).map(|k| m[c][k] * s[free[k]]).sum::<f64>();
                s[free[c]] = v / m[c][c];
            }
            if (0..3).all(|i| s[i] >= lo[i] - 1e-12 && s[i] <= hi[i] + 1e-12) && value(&s) < best.1 {
                best = (s, value(&s));
            }
        }
        best.0
    }

    #[test]
    fn box_qp_matches_enumeration() {
        let b = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        for (g, lo, hi) in [
            ([-10.0, 1.0, -0.5], [-1.0, -0.1, -1.0], [1.0, 1.0, 1.0]),
            ([-10.0, 1.0, -0.5], [-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]),
            ([0.1, -0.2, 0.3], [-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]),
            ([5.0, 5.0, -5.0], [-0.5, 0.0, -2.0], [0.0, 3.0, 0.5]),
        ] {
            let s = box_qp(&ldl_of(&b), &g, &lo, &hi);
            let want = brute_force(&b, &g, &lo, &hi);
            for i in 0..3 {
                assert!((s[i] - want[i]).abs() < 1e-13, "g {g:?}: {s:?} vs {want:?}");
            }
        }
    }

    #[test]
    fn ldl_rank_one_updates_match_dense_algebra() {
        let mut ldl = Ldl::<3>::identity();
        let (u, v) = ([1.0, 2.0, -0.5], [0.3, -0.1, 0.2]);
        ldl.rank_one(&u, 0.7);
        ldl.rank_one(&v, -0.4);
        let b = ldl.matrix();
        for i in 0..3 {
            for j in 0..3 {
                let want = f64::from(u8::from(i == j)) + 0.7 * u[i] * u[j] - 0.4 * v[i] * v[j];
                assert!((b[i][j] - want).abs() < 1e-14, "B[{i}][{j}] = {} vs {want}", b[i][j]);
            }
        }
        assert!(ldl.d.iter().all(|d| *d > 0.0));
    }

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
