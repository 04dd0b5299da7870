//! SLSQP's linear algebra for simple bounds ([`super::slsqp`]): the quasi-Newton matrix kept as
//! its LDLᵀ factor with rank-one modifications (Fletcher & Powell 1974), and the strictly
//! convex box QP min ½sᵀBs + gᵀs, l ≤ s ≤ u solved by a primal active-set method on E = D^½Lᵀ
//! (forming B itself lost digits at condition 1e12), the free part by Householder least squares.
//!
//! ## References
//! - Fletcher, R., Powell, M. J. D. (1974) On the modification of LDLᵀ factorizations.
//!   Math. Comp. 28, 1067–1087.
//! - Lawson, C. L., Hanson, R. J. (1974) Solving Least Squares Problems. Prentice-Hall, ch. 23
//!   (the active-set NNLS/LSI scheme SLSQP builds its QP on).

pub(super) fn dot<const N: usize>(a: &[f64; N], b: &[f64; N]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(super) fn norm<const N: usize>(a: &[f64; N]) -> f64 {
    dot(a, a).sqrt()
}

/// B = LDLᵀ with L unit lower triangular and D > 0.
#[derive(Debug, Clone, Copy)]
pub(super) struct Ldl<const N: usize> {
    l: [[f64; N]; N],
    d: [f64; N],
}

impl<const N: usize> Ldl<N> {
    pub(super) fn identity() -> Self {
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
    pub(super) fn times(&self, v: &[f64; N]) -> [f64; N] {
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
    pub(super) fn rank_one(&mut self, z: &[f64; N], sigma: f64) {
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
pub(super) fn box_qp<const N: usize>(ldl: &Ldl<N>, g: &[f64; N], lo: &[f64; N], hi: &[f64; N]) -> [f64; N] {
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
}
