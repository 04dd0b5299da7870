//! Extraterrestrial solar irradiance E₀(λ) (TSIS-1 HSRS) and its scaling with the Sun–Earth
//! distance on a given date.
//!
//! ## References
//! - Coddington, O. M. et al. (2021) The TSIS-1 Hybrid Solar Reference Spectrum. Geophys. Res.
//!   Lett. 48, e2020GL091709.
//! - Spencer, J. W. (1971) Fourier series representation of the position of the Sun. Search 2, 172
//!   (eccentricity correction factor (r₀/r)²).

use super::AtmosphereError;
use crate::spectral::{Extrapolation, Spectrum, WavelengthGrid};

const ASSET: &str = "solar/solar_tsis1_hsrs_1nm.csv";

/// The TSIS-1 HSRS spectrum at 1 AU, W m⁻² nm⁻¹.
pub fn tsis1() -> Result<Spectrum, AtmosphereError> {
    Ok(Spectrum::from_asset(ASSET, "irradiance_W_m2_nm")?)
}

/// E₀ on `grid` at 1 AU, W m⁻² nm⁻¹.
pub fn e0_on_grid(grid: &WavelengthGrid) -> Result<Vec<f64>, AtmosphereError> {
    Ok(tsis1()?.resample(grid, Extrapolation::Error)?)
}

/// (r₀/r)², the factor that scales 1-AU irradiance to day of year `doy` (1–366) (Spencer 1971):
/// 1.000110 + 0.034221 cosΓ + 0.001280 sinΓ + 0.000719 cos2Γ + 0.000077 sin2Γ, Γ = 2π(doy−1)/365.
///
/// ```
/// let jan = shoal::atmosphere::sun_distance_factor(3);
/// let jul = shoal::atmosphere::sun_distance_factor(185);
/// assert!(jan > 1.03 && jul < 0.97);
/// ```
#[must_use]
pub fn sun_distance_factor(doy: u32) -> f64 {
    let g = 2.0 * std::f64::consts::PI * (f64::from(doy.clamp(1, 366)) - 1.0) / 365.0;
    1.000_110 + 0.034_221 * g.cos() + 0.001_280 * g.sin() + 0.000_719 * (2.0 * g).cos() + 0.000_077 * (2.0 * g).sin()
}
