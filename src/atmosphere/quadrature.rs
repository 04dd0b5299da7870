//! Gauss–Legendre quadrature and normalised associated Legendre functions.
//!
//! ## References
//! - Abramowitz, M. & Stegun, I. A. (1972) Handbook of Mathematical Functions, §25.4.29
//!   (Gauss–Legendre nodes and weights), §8.5 (recurrences).
//! - Wiscombe, W. J. (1977) The delta-M method. J. Atmos. Sci. 34, 1408–1422 (normalised
//!   associated Legendre functions Λₗᵐ = √((l−m)!/(l+m)!) Pₗᵐ in radiative transfer).

/// Gauss–Legendre nodes and weights on [−1, 1] (n ≥ 1), nodes ascending. Newton iteration on
/// Pₙ from Chebyshev initial guesses; weights 2/((1−x²)Pₙ'(x)²).
///
/// ```
/// let (x, w) = shoal::atmosphere::gauss_legendre(5);
/// let integral: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(8)).sum();
/// assert!((integral - 2.0 / 9.0).abs() < 1e-14);
/// ```
#[must_use]
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 1 { z } else { p1 };
            let pn1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (z * pn - pn1) / (z * z - 1.0);
            let dz = pn / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        if n == 1 {
            dp = 1.0;
            z = 0.0;
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        w[i] = wi;
        w[n - 1 - i] = wi;
    }
    (x, w)
}

/// Gauss–Legendre on (0, 1): n nodes ascending and weights summing to 1.
#[must_use]
pub fn gauss_half(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (x, w) = gauss_legendre(n);
    (x.iter().map(|x| 0.5 * (x + 1.0)).collect(), w.iter().map(|w| 0.5 * w).collect())
}

/// Normalised associated Legendre functions Λₗᵐ(μ) for l = m..=l_max (index l − m), with
/// Λₘᵐ = √((2m−1)/(2m))·√(1−μ²)·Λₘ₋₁ᵐ⁻¹, Λₘ₊₁ᵐ = √(2m+1) μ Λₘᵐ and
/// Λₗᵐ = [(2l−1) μ Λₗ₋₁ᵐ − √((l−1)²−m²) Λₗ₋₂ᵐ]/√(l²−m²). With this normalisation the addition
/// theorem reads Pₗ(cosΘ) = Σₘ (2−δₘ₀) Λₗᵐ(μ)Λₗᵐ(μ') cos mΔφ.
#[must_use]
pub fn normalized_legendre(m: usize, l_max: usize, mu: f64) -> Vec<f64> {
    if l_max < m {
        return Vec::new();
    }
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let mut pmm = 1.0;
    for k in 1..=m {
        pmm *= ((2 * k - 1) as f64 / (2 * k) as f64).sqrt() * s;
    }
    let mut out = Vec::with_capacity(l_max - m + 1);
    out.push(pmm);
    if l_max > m {
        out.push(((2 * m + 1) as f64).sqrt() * mu * pmm);
    }
    for l in m + 2..=l_max {
        let (lf, mf) = (l as f64, m as f64);
        let a = (2.0 * lf - 1.0) * mu * out[l - m - 1];
        let b = ((lf - 1.0).powi(2) - mf * mf).sqrt() * out[l - m - 2];
        out.push((a - b) / (lf * lf - mf * mf).sqrt());
    }
    out
}

/// Legendre polynomials P₀..P_{l_max} at x.
#[must_use]
pub fn legendre_polynomials(l_max: usize, x: f64) -> Vec<f64> {
    let mut p = Vec::with_capacity(l_max + 1);
    p.push(1.0);
    if l_max >= 1 {
        p.push(x);
    }
    for l in 2..=l_max {
        let lf = l as f64;
        p.push(((2.0 * lf - 1.0) * x * p[l - 1] - (lf - 1.0) * p[l - 2]) / lf);
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addition_theorem_holds() {
        // Pₗ(cosΘ) = Σₘ (2−δₘ₀) Λₗᵐ(μ)Λₗᵐ(μ') cos mΔφ
        let (mu, mu2, dphi) = (0.3f64, -0.7f64, 1.1f64);
        let cos_theta = mu * mu2 + (1.0 - mu * mu).sqrt() * (1.0 - mu2 * mu2).sqrt() * dphi.cos();
        let l_max = 12;
        let p = legendre_polynomials(l_max, cos_theta);
        for l in 0..=l_max {
            let mut sum = 0.0;
            for m in 0..=l {
                let a = normalized_legendre(m, l_max, mu)[l - m];
                let b = normalized_legendre(m, l_max, mu2)[l - m];
                sum += if m == 0 { 1.0 } else { 2.0 } * a * b * (m as f64 * dphi).cos();
            }
            assert!((sum - p[l]).abs() < 1e-13, "l={l}: {sum} vs {}", p[l]);
        }
    }

    #[test]
    fn half_range_weights_sum_to_one() {
        for n in [1, 2, 7, 24, 48] {
            let (x, w) = gauss_half(n);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            assert!(x.iter().all(|x| *x > 0.0 && *x < 1.0));
        }
    }
}
