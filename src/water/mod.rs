//! Water: SIOP sets, inherent optical properties and the deep/shallow reflectance model of
//! Lee et al. (1998, 1999) as coded in SAMBUCA, returning every intermediate.
//!
//! | symbol | name in code | meaning | unit |
//! |---|---|---|---|
//! | a_w, bb_w | `a_w`, `bb_w` | pure-water absorption, backscattering | m⁻¹ |
//! | a*_ph, bb*_ph | `a_ph_star`, `bb_ph_star` | chl-specific phytoplankton absorption, backscattering | m² mg⁻¹ |
//! | a*_CDOM | `a_cdom_star` | CDOM absorption per unit a_CDOM(λ₀) | – |
//! | a*_NAP, bb*_NAP | `a_nap_star`, `bb_nap_star` | mass-specific NAP absorption, backscattering | m² g⁻¹ |
//! | κ | `kappa` | a + bb | m⁻¹ |
//! | u | `u` | bb/(a+bb) | – |
//! | Kd, kuC, kuB | `kd`, `kuc`, `kub` | attenuation: downwelling, upward column, upward bottom | m⁻¹ |
//! | rrs_dp, rrs | `rrs_deep`, `rrs` | sub-surface remote-sensing reflectance, deep / actual | sr⁻¹ |
//! | Rrs | `rrs_above` | above-surface remote-sensing reflectance | sr⁻¹ |
//! | ρ_b | `r_substratum` | bottom irradiance reflectance (substrate mixture) | – |
//! | θ_w, θ_o | – | sun and view zenith angles under water (Snell) | rad |
//!
//! ## References
//! - Lee, Z., Carder, K. L., Mobley, C. D., Steward, R. G., Patch, J. S. (1998) Hyperspectral
//!   remote sensing for shallow waters. I. A semianalytical model. Appl. Opt. 37, 6329–6338.
//! - Lee, Z., Carder, K. L., Mobley, C. D., Steward, R. G., Patch, J. S. (1999) Hyperspectral
//!   remote sensing for shallow waters. 2. Deriving bottom depths and water properties by
//!   optimization. Appl. Opt. 38, 3831–3843.
//! - Lee, Z., Carder, K. L., Arnone, R. A. (2002) Deriving inherent optical properties from water
//!   color: a multiband quasi-analytical algorithm for optically deep waters. Appl. Opt. 41,
//!   5755–5772 (Rrs ↔ rrs conversion).
//! - Brando, V. E., Anstee, J. M., Wettle, M., Dekker, A. G., Phinn, S. R., Roelfsema, C. (2009)
//!   A physics based retrieval and quality assessment of bathymetry from suboptimal hyperspectral
//!   data. Remote Sens. Environ. 113, 755–770 (SAMBUCA).

mod fastmath;
/// The water inputs' documented ranges (kept with every other range in [`crate::ranges`]).
pub use crate::ranges::limits;
mod kernel;
mod model;
mod single;
mod siop;
mod substrate;

pub(crate) use fastmath::exp as exp_at;
pub use fastmath::fast_exp;
pub use model::{
    Bottom, WaterColumn, WaterGeometry, WaterModel, WaterReflectance, rrs_above_from_below, rrs_below_from_above,
};
pub use single::{SingleScratch, SingleWater};
pub use siop::{Siop, SiopSource, SiopSpec};
pub use substrate::{SubstrateEntry, SubstrateLibrary, SubstrateMix};

use crate::parse::ParseError;
use crate::spectral::SpectralError;

/// Errors from the water stage; each names the field and the allowed range.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum WaterError {
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
    /// A name that is not known (substrate, SIOP set).
    #[error("unknown {field} `{name}` (known: {known})")]
    UnknownName {
        /// What kind of name.
        field: String,
        /// The name given.
        name: String,
        /// The names there are.
        known: String,
    },
    /// A SIOP spectrum that could not be resolved.
    #[error("SIOP set `{set}`, {field}: {message}")]
    Siop {
        /// SIOP set name.
        set: String,
        /// The SIOP field.
        field: String,
        /// What went wrong.
        message: String,
    },
    /// A file that does not parse.
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// An error from the spectral layer.
    #[error(transparent)]
    Spectral(#[from] SpectralError),
}
