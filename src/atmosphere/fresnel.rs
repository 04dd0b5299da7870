//! Fresnel reflection at a flat air–water interface, seen from the air side.
//!
//! With i the incidence angle, t the refraction angle (sin t = sin i/n), the amplitude
//! coefficients are r_ℓ = (n cos i − cos t)/(n cos i + cos t) (in the plane of incidence) and
//! r_r = (cos i − n cos t)/(cos i + n cos t) (perpendicular). The unpolarised reflectance is
//! R = (r_ℓ² + r_r²)/2; the Mueller matrix in the meridian frame (I, Q, U) is
//! [[R, (r_ℓ²−r_r²)/2, 0], [(r_ℓ²−r_r²)/2, R, 0], [0, 0, r_ℓ r_r]].
//!
//! ## References
//! - Born, M. & Wolf, E. (1999) Principles of Optics, 7th ed., §1.5.2.
//! - Mobley, C. D. (1994) Light and Water, §4.2; water index 1.34 as in OSOAA's default.

/// Default refractive index of sea water for the interface (OSOAA GUI and pyOSOAA default).
pub const SEA_REFRACTIVE_INDEX: f64 = 1.34;

/// Amplitude coefficients (r_ℓ, r_r) for incidence cosine `mu` (0 < μ ≤ 1) from air into index `n`.
#[must_use]
pub fn amplitudes(mu: f64, n: f64) -> (f64, f64) {
    let cos_i = mu.clamp(0.0, 1.0);
    let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
    let cos_t = (1.0 - (sin_i / n).powi(2)).max(0.0).sqrt();
    let r_l = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    let r_r = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    (r_l, r_r)
}

/// Unpolarised Fresnel reflectance for incidence cosine `mu` from air into index `n`.
///
/// ```
/// // Normal incidence: ((n−1)/(n+1))² = 0.02107 for n = 1.34.
/// let r = shoal::atmosphere::fresnel_reflectance(1.0, 1.34);
/// assert!((r - (0.34f64 / 2.34).powi(2)).abs() < 1e-15);
/// ```
#[must_use]
pub fn fresnel_reflectance(mu: f64, n: f64) -> f64 {
    let (a, b) = amplitudes(mu, n);
    0.5 * (a * a + b * b)
}

/// Mueller matrix rows for (I, Q, U) in the meridian frame.
#[must_use]
pub fn fresnel_matrix(mu: f64, n: f64) -> [[f64; 3]; 3] {
    let (a, b) = amplitudes(mu, n);
    let (s, d) = (0.5 * (a * a + b * b), 0.5 * (a * a - b * b));
    [[s, d, 0.0], [d, s, 0.0], [0.0, 0.0, a * b]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brewster_angle_extinguishes_the_parallel_component() {
        let n: f64 = 1.34;
        let mu_b = n.atan().cos();
        let (rl, rr) = amplitudes(mu_b, n);
        assert!(rl.abs() < 1e-12 && rr.abs() > 0.1);
        assert!((fresnel_reflectance(1e-9, n) - 1.0).abs() < 1e-6, "grazing incidence reflects all");
    }
}
