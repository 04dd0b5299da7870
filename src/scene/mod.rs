//! Scenes: what lies under the instrument — maps of every water parameter, the bottom, land, the
//! sun and the atmosphere, and the list of effects the scene calls for. A [`SceneSpec`] is written
//! in RON (`presets/scenes/`); [`Scene::build`] validates it and rasterises what needs a raster
//! (random fields, images), so that any ground position can be sampled on demand.
//!
//! Frame: metres, origin at the scene centre, x east, y north; azimuths clockwise from north.
//!
//! ## References
//! - Matthews, M. W. et al. (2023) Demonstration of a modular prototype end-to-end simulator for
//!   aquatic remote sensing applications. Sensors 23, 7824 (scenes built from 2-D maps and 1-D
//!   radiative transfer; Appendix B).

pub mod clouds;
mod grf;
mod map;
pub mod raster;
mod spec;

pub use clouds::{CloudField, CloudLayer, Sky};
pub use grf::gaussian_random_field;
pub use map::{Distribution, Extent, Map, MapContext, MapSpec, Shape};
pub use raster::{GeoFrame, Georeference, Resampling};
pub use spec::{Effect, LandSpec, Scene, SceneSpec, SubstrateLayer, SunSpec, day_of_year};

use crate::atmosphere::AtmosphereError;
use crate::parse::{FieldError, ParseError};
use crate::spectral::SpectralError;
use crate::water::WaterError;

/// Errors from scene construction; each names the field.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum SceneError {
    /// A field with an invalid value.
    #[error(transparent)]
    Invalid(#[from] FieldError),
    /// A file that does not parse.
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// From the water stage (SIOP set, substrates).
    #[error(transparent)]
    Water(#[from] WaterError),
    /// From the atmosphere stage.
    #[error(transparent)]
    Atmosphere(#[from] AtmosphereError),
    /// From the spectral layer.
    #[error(transparent)]
    Spectral(#[from] SpectralError),
}
