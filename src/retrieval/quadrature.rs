//! Gaussian quadrature for a discrete measure: K nodes and weights that integrate every
//! polynomial of degree < 2K exactly against the weights w_i at points x_i.
//!
//! A band's response on the simulation grid is such a measure (20–40 points); the retrieval's
//! band model evaluates the water model at K ≈ 4 nodes per band instead of at every grid point.
//! Recurrence coefficients by the Stieltjes procedure, nodes and weights by Golub–Welsch (the
//! eigen-decomposition of the Jacobi matrix, here by cyclic Jacobi rotations, exact to rounding
//! for K ≤ 8).
//!
//! ## References
//! - Gautschi, W. (2004) Orthogonal Polynomials: Computation and Approximation. Oxford
//!   University Press, §2.2.3.1 (discrete Stieltjes procedure).
//! - Golub, G. H. & Welsch, J. H. (1969) Calculation of Gauss quadrature rules. Math. Comp. 23,
//!   221–230.

/// K-point Gauss rule of the discrete measure (`x`, `w`); fewer points if the measure has fewer
/// than K support points with positive weight. Returns (nodes, weights), the weights summing to
/// Σw.
#[must_use]
pub fn gauss_rule(x: &[f64], w: &[f64], k: usize) -> (Vec<f64>, Vec<f64>) {
    let support: Vec<(f64, f64)> = x.iter().zip(w).filter(|(_, w)| **w > 0.0).map(|(x, w)| (*x, *w)).collect();
    let total: f64 = support.iter().map(|p| p.1).sum();
    if support.is_empty() || !(total > 0.0) {
        return (Vec::new(), Vec::new());
    }
    let k = k.clamp(1, support.len());
    if k == support.len() {
        return (support.iter().map(|p| p.0).collect(), support.iter().map(|p| p.1).collect());
    }
    // Work on t = (x − c)/h ∈ [−1, 1] for conditioning.
    let (lo, hi) = support.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (c, h) = (0.5 * (lo + hi), (0.5 * (hi - lo)).max(1e-12));
    let t: Vec<f64> = support.iter().map(|p| (p.0 - c) / h).collect();
    let wt: Vec<f64> = support.iter().map(|p| p.1 / total).collect();
    let (mut alpha, mut beta) = (vec![0.0; k], vec![0.0; k]);
    let mut prev = vec![0.0; t.len()];
    let mut cur = vec![1.0; t.len()];
    let mut norm_cur: f64 = 1.0;
    for j in 0..k {
        let num: f64 = t.iter().zip(&wt).zip(&cur).map(|((t, w), p)| w * t * p * p).sum();
        alpha[j] = num / norm_cur;
        let next: Vec<f64> =
            (0..t.len()).map(|i| (t[i] - alpha[j]) * cur[i] - if j > 0 { beta[j] * prev[i] } else { 0.0 }).collect();
        let norm_next: f64 = next.iter().zip(&wt).map(|(p, w)| w * p * p).sum();
        if j + 1 < k {
            beta[j + 1] = norm_next / norm_cur;
        }
        prev = cur;
        cur = next;
        norm_cur = norm_next;
    }
    // Jacobi matrix and its eigen-decomposition.
    let mut a = vec![vec![0.0; k]; k];
    for j in 0..k {
        a[j][j] = alpha[j];
        if j + 1 < k {
            let b = beta[j + 1].max(0.0).sqrt();
            a[j][j + 1] = b;
            a[j + 1][j] = b;
        }
    }
    let (values, vectors) = symmetric_eigen(a);
    let mut rule: Vec<(f64, f64)> =
        (0..k).map(|j| (c + h * values[j], total * vectors[0][j] * vectors[0][j])).collect();
    rule.sort_by(|p, q| p.0.total_cmp(&q.0));
    (rule.iter().map(|p| p.0).collect(), rule.iter().map(|p| p.1).collect())
}

/// Eigenvalues and eigenvectors (columns) of a small symmetric matrix by cyclic Jacobi
/// rotations (Golub & Van Loan 2013, §8.5).
pub(crate) fn symmetric_eigen(mut a: Vec<Vec<f64>>) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = a.len();
    let mut v: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| f64::from(u8::from(i == j))).collect()).collect();
    for _sweep in 0..64 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        let scale: f64 = (0..n).map(|i| a[i][i] * a[i][i]).sum::<f64>().max(1e-300);
        if off <= 1e-30 * scale {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if a[p][q].abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for k in 0..n {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for row in &mut v {
                    let (vkp, vkq) = (row[p], row[q]);
                    row[p] = c * vkp - s * vkq;
                    row[q] = s * vkp + c * vkq;
                }
            }
        }
    }
    ((0..n).map(|i| a[i][i]).collect(), v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_to_degree_2k_minus_1() {
        // A Gaussian-like band response sampled every nm.
        let x: Vec<f64> = (0..31).map(|i| 545.0 + f64::from(i)).collect();
        let w: Vec<f64> =
            x.iter().map(|x| (-0.5 * ((x - 560.0) / 5.0).powi(2)).exp() * (1.0 + 0.01 * (x - 560.0))).collect();
        for k in 1..=5 {
            let (nodes, weights) = gauss_rule(&x, &w, k);
            assert_eq!(nodes.len(), k);
            for degree in 0..2 * k {
                let f = |x: f64| ((x - 550.0) / 10.0).powi(degree as i32);
                let exact: f64 = x.iter().zip(&w).map(|(x, w)| w * f(*x)).sum();
                let rule: f64 = nodes.iter().zip(&weights).map(|(x, w)| w * f(*x)).sum();
                assert!(
                    (rule - exact).abs() < 1e-10 * exact.abs().max(1.0),
                    "k {k}, degree {degree}: {rule} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn few_support_points_are_returned_as_they_are() {
        let (n, w) = gauss_rule(&[1.0, 2.0, 3.0], &[0.0, 2.0, 1.0], 4);
        assert_eq!(n, vec![2.0, 3.0]);
        assert_eq!(w, vec![2.0, 1.0]);
        assert!(gauss_rule(&[1.0], &[0.0], 3).0.is_empty());
    }
}
