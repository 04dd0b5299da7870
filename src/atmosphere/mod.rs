//! Atmosphere: Rayleigh and aerosol optics, gas transmittance and a plane-parallel
//! successive-orders-of-scattering (SOS) radiative-transfer solver over a flat Fresnel surface,
//! tabulated once per scene in a look-up table.
//!
//! | symbol | name in code | meaning | unit |
//! |---|---|---|---|
//! | τ_R, τ_a | `tau_rayleigh`, `tau_aerosol` | Rayleigh and aerosol optical depth | – |
//! | ω_a | `ssa` | aerosol single-scattering albedo | – |
//! | P(Θ), βₗ | `PhaseFunction`, `moments` | phase function and its Legendre coefficients | – |
//! | μ₀, μ_v | `mu_sun`, `mu_view` | cosines of sun and view zenith angles | – |
//! | Δφ | `relative_azimuth` | view azimuth − sun azimuth (0: sensor on the sun's side) | rad |
//! | E₀ | `e0` | extraterrestrial irradiance at the date's Sun–Earth distance | W m⁻² nm⁻¹ |
//! | L_path | `l_path` | path radiance incl. Fresnel-reflected sky light (black water) | W m⁻² sr⁻¹ nm⁻¹ |
//! | ρ_path | `rho_path` | π L_path/(E₀ μ₀) | – |
//! | T_up, T_down | `t_up`, `t_down` | total (direct + diffuse) transmittances | – |
//! | S | `spherical_albedo` | atmospheric spherical albedo (illuminated from below) | – |
//! | Ed(0⁺) | `ed_0plus` | downwelling irradiance just above the surface | W m⁻² nm⁻¹ |

mod aerosol;
pub mod aerosol_6sv;
mod fresnel;
mod gas;
mod gas_swir;
mod glint;
mod kernel_cache;
mod kernels;
mod lut;
mod mie;
mod phase;
mod profile;
mod quadrature;
mod rayleigh;
mod rt;
mod single_scattering;
mod solar;
mod sos;
mod sos_transfer;
mod spec;
pub mod stokes;
mod user_aerosol;
mod wmo;

pub use aerosol::{
    AerosolOptics, ComponentOptics, ComponentTable, TABLE_ASSET, TABLE_WAVELENGTHS_NM, component_table_csv,
    compute_component, mixture_optics, table_angles_deg,
};
pub use fresnel::{SEA_REFRACTIVE_INDEX, fresnel_matrix, fresnel_reflectance};
pub use gas::{GasAmounts, air_mass, transmittance as gas_transmittance};
pub use glint::{glint_radiance_norm, glint_reflectance};
pub use kernels::delta_m;
pub use lut::{AtmosphereLut, LutAxes};
pub use mie::{BulkOptics, LogNormal, MieSphere, SizeGrid, integrate_lognormal, mie_sphere};
pub use phase::{PhaseFunction, rayleigh_beta2};
pub use profile::{AltitudeQuadrature, ColumnOptics, Layering};
pub use quadrature::{gauss_half, gauss_legendre, legendre_polynomials, normalized_legendre};
pub use rayleigh::{AIR_DEPOLARIZATION, RayleighColumn, RayleighDepth, STANDARD_PRESSURE_HPA, bodhaine_tau};
pub use rt::{
    RtAccuracy, Scatterers, SsCoefficients, SunSolution, Transmittance, WavelengthColumn, fourier_sum,
    fourier_sum_with, solve_sun, solve_transmittance,
};
/// Complex numbers of the Mie series: num-complex's (through rustfft, already a dependency).
/// Divisions use [`Complex::fdiv`], which scales by |z| and cannot overflow where the textbook
/// quotient would (the Mie code divides by terms that grow like the Riccati–Bessel functions).
pub use rustfft::num_complex::Complex64 as Complex;
pub use solar::{e0_on_grid, sun_distance_factor, tsis1};
pub use sos::Streams;
pub use spec::{Atmosphere, AtmosphereSpec, AtmosphereTerms, GasLegs, Geometry, Normalised, SeaSurface};
pub use user_aerosol::{AerosolMode, R_MAX_UM, SizeDistribution};
pub use wmo::{AerosolType, Component, WmoFractions};

use crate::spectral::SpectralError;

/// Errors from the atmosphere stage; each names the field and the allowed range.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum AtmosphereError {
    /// A number outside its documented range.
    #[error("{field} = {value} is out of range (allowed: {allowed})")]
    OutOfRange {
        /// The field.
        field: String,
        /// The value given.
        value: f64,
        /// The allowed range.
        allowed: String,
    },
    /// Embedded or user data that cannot be used.
    #[error("atmosphere data: {0}")]
    Data(String),
    /// An error from the spectral layer.
    #[error(transparent)]
    Spectral(#[from] SpectralError),
}

/// `value` against `range`; the error names the field (its path below `scene.atmosphere.` for a
/// scene's atmosphere, below `atmosphere_run.` for `shoal atmosphere`'s own inputs), the value
/// and the range.
pub(crate) fn check(range: &crate::ranges::Range, value: f64) -> Result<(), AtmosphereError> {
    if range.contains(value) {
        return Ok(());
    }
    let field = ["scene.atmosphere.", "atmosphere_run.atmosphere.", "atmosphere_run."]
        .iter()
        .find_map(|section| range.path.strip_prefix(section))
        .unwrap_or(range.path);
    Err(AtmosphereError::OutOfRange { field: field.into(), value, allowed: range.allowed() })
}
