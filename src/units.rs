//! Physical constants, unit conversions and angle helpers.
//!
//! Angles are radians inside Shoal and degrees only at the edges (CLI flags, RON files,
//! the UI). Units live in names: `wavelength_nm`, `radiance_w_m2_sr_um`, `depth_m`.
//!
//! ## References
//! - CODATA 2018 exact SI values for `h` and `c` (Tiesinga et al. 2021, Rev. Mod. Phys. 93, 025010).

/// Planck constant, J s (exact, SI 2019).
pub const PLANCK_J_S: f64 = 6.626_070_15e-34;
/// Speed of light in vacuum, m s⁻¹ (exact).
pub const SPEED_OF_LIGHT_M_S: f64 = 299_792_458.0;
/// Mean Earth radius, m (IUGG mean radius R₁, Moritz 2000, Geodetic Reference System 1980).
pub const EARTH_RADIUS_M: f64 = 6_371_008.8;
/// Earth's gravitational parameter GM, m³ s⁻² (WGS 84, NIMA TR8350.2).
pub const EARTH_GM_M3_S2: f64 = 3.986_004_418e14;
/// π as used throughout (re-exported for brevity in formulas).
pub const PI: f64 = std::f64::consts::PI;

/// Degrees → radians.
///
/// ```
/// assert!((shoal::units::rad_from_deg(180.0) - std::f64::consts::PI).abs() < 1e-15);
/// ```
#[must_use]
pub fn rad_from_deg(deg: f64) -> f64 {
    deg.to_radians()
}

/// Radians → degrees.
///
/// ```
/// assert!((shoal::units::deg_from_rad(std::f64::consts::FRAC_PI_2) - 90.0).abs() < 1e-12);
/// ```
#[must_use]
pub fn deg_from_rad(rad: f64) -> f64 {
    rad.to_degrees()
}

/// Energy of one photon at `wavelength_nm`, in joules: E = h c / λ.
///
/// ```
/// let e = shoal::units::photon_energy_j(500.0);
/// assert!((e - 3.9728917e-19).abs() < 1e-25);
/// ```
#[must_use]
pub fn photon_energy_j(wavelength_nm: f64) -> f64 {
    PLANCK_J_S * SPEED_OF_LIGHT_M_S / (wavelength_nm * 1e-9)
}

/// Spectral irradiance W m⁻² nm⁻¹ → W m⁻² µm⁻¹ (×1000), the unit radiometers report.
#[must_use]
pub fn per_um_from_per_nm(value_per_nm: f64) -> f64 {
    value_per_nm * 1000.0
}
