//! Sun glint from a wind-roughened sea (Cox & Munk 1954, isotropic slope distribution), a
//! separate term a scene switches on.
//!
//! Facet normal n = (s + v)/|s + v| for unit vectors s (to the sun) and v (to the sensor);
//! tilt β = acos n_z, reflection half-angle ω = acos(s·n). Glint reflectance
//! ρ_g = π R_F(ω) p(β)/(4 μ₀ μ_v cos⁴β), p = exp(−tan²β/σ²)/(πσ²), σ² = 0.003 + 0.00512·W.
//! The glint radiance at TOA is L_g = E₀ μ₀ ρ_g T_dir(μ₀) T_dir(μ_v)/π, with direct
//! transmittances, as in 6S and SeaDAS.
//!
//! ## References
//! - Cox, C. & Munk, W. (1954) Measurement of the roughness of the sea surface from photographs
//!   of the sun's glitter. J. Opt. Soc. Am. 44, 838–850.
//! - Wang, M. & Bailey, S. W. (2001) Correction of sun glint contamination on the SeaWiFS ocean
//!   and atmosphere products. Appl. Opt. 40, 4790–4798.

use super::fresnel::fresnel_reflectance;

/// Glint reflectance ρ_g (dimensionless) for sun zenith θ₀, view zenith θ_v, relative azimuth
/// Δφ (view − sun; 180° puts the sensor opposite the sun), wind speed `wind_m_s`, water index n.
///
/// ```
/// use shoal::atmosphere::glint_reflectance;
/// // Specular geometry at 5 m/s: ρ_g ≈ π·R_F(20°)/(4 cos²20° · π σ²) ≈ 0.21.
/// let specular = glint_reflectance(0.35, 0.35, std::f64::consts::PI, 5.0, 1.34);
/// // Sensor at 40° on the sun's side: facets would have to tilt 30°; almost none do.
/// let away = glint_reflectance(0.35, 0.70, 0.0, 5.0, 1.34);
/// assert!((specular - 0.211).abs() < 0.001 && away < 1e-3 * specular);
/// ```
#[must_use]
pub fn glint_reflectance(
    sun_zenith_rad: f64,
    view_zenith_rad: f64,
    relative_azimuth_rad: f64,
    wind_m_s: f64,
    n: f64,
) -> f64 {
    let sigma2 = 0.003 + 0.005_12 * wind_m_s.max(0.0);
    let s = [sun_zenith_rad.sin(), 0.0, sun_zenith_rad.cos()];
    let v = [
        view_zenith_rad.sin() * relative_azimuth_rad.cos(),
        view_zenith_rad.sin() * relative_azimuth_rad.sin(),
        view_zenith_rad.cos(),
    ];
    let h = [s[0] + v[0], s[1] + v[1], s[2] + v[2]];
    let norm = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    if norm < 1e-12 {
        return 0.0;
    }
    let cos_beta = h[2] / norm;
    let cos_omega = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) / norm;
    let tan2 = (1.0 - cos_beta * cos_beta) / (cos_beta * cos_beta);
    let p = (-tan2 / sigma2).exp() / (std::f64::consts::PI * sigma2);
    let (mu0, muv) = (s[2], v[2]);
    std::f64::consts::PI * fresnel_reflectance(cos_omega, n) * p / (4.0 * mu0 * muv * cos_beta.powi(4))
}

/// Glint radiance at TOA per unit solar flux (multiply by E₀ and gas transmittance):
/// ρ_g μ₀ e^{−τ/μ₀} e^{−τ/μ_v}/π, with direct transmittances through the column of optical
/// depth `tau`.
#[must_use]
pub fn glint_radiance_norm(
    sun_zenith_rad: f64,
    view_zenith_rad: f64,
    relative_azimuth_rad: f64,
    wind_m_s: f64,
    n: f64,
    tau: f64,
) -> f64 {
    let (mu0, muv) = (sun_zenith_rad.cos(), view_zenith_rad.cos());
    glint_reflectance(sun_zenith_rad, view_zenith_rad, relative_azimuth_rad, wind_m_s, n) * mu0 / std::f64::consts::PI
        * (-tau / mu0).exp()
        * (-tau / muv).exp()
}
