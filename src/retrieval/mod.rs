//! Retrievals: from band Rrs back to chlorophyll-a, CDOM, NAP, depth and bottom type.
//!
//! | part | module | what it does |
//! |---|---|---|
//! | band forward model | [`band_model`] | the Lee/SAMBUCA model at the instrument's bands, with its Jacobian |
//! | Gauss rules | [`quadrature`] | K nodes per band that integrate its response |
//! | aLMI | [`almi`] | linear matrix inversion over SIOP sets (Brando et al. 2012), non-negative |
//! | aLMI, reference mode | [`almi_reference`] | the DEA code's inversion step for step (set dropping, screening) |
//! | SAMBUCA | [`sambuca`] | bounded nonlinear least squares over depth and substrate pairs (Brando et al. 2009) |
//! | SAMBUCA, reference mode | [`sambuca_reference`] | the CSIRO package's fit: one start, SLSQP, the stall kept |
//! | solvers | [`nnls`], [`optimise`], [`slsqp`] | exact small NNLS; bounded Levenberg–Marquardt and BFGS; SciPy's SLSQP for bounds |
//! | external | [`external`] | a user's own program, run on a NetCDF file of the Rrs, its products read back |
//! | QAA v6 | [`qaa`] | the Quasi-Analytical Algorithm (Lee et al. 2002; v6 2014): IOPs, chl from a_ph(443) |
//! | the seam | [`algorithm`] | the [`Algorithm`] and [`Prepared`] traits every retrieval implements, its names, and which spec runs which |
//! | images | [`run`] | a retrieval over a whole Rrs cube, the products and their flags |

pub mod algorithm;
pub mod almi;
pub mod almi_lanes;
pub mod almi_reference;
pub mod band_model;
mod evaluate;
pub mod external;
mod external_io;
pub mod function;
#[cfg(test)]
mod levels_test;
pub mod nnls;
pub mod optimise;
pub mod qaa;
pub mod quadrature;
pub mod run;
mod run_sambuca;
pub mod sambuca;
pub mod sambuca_reference;
pub mod sets;
pub mod slsqp;
mod slsqp_qp;

pub use algorithm::{Algorithm, Identity, Model, Prepared, title_of};
pub use almi::{AlmiFlags, AlmiSettings};
pub use band_model::{BandModel, BandResponse, ModelScratch, Parameters};
pub use evaluate::{dominant, evaluate};
pub use run::{Product, ProductFlags, RetrievalInputs, RetrievalSpec};
pub use sambuca::{Objective, SambucaSettings, Starts};

use serde::{Deserialize, Serialize};

use crate::parse::FieldError;
use crate::spectral::SpectralError;
use crate::water::WaterError;

/// Which inversion a retrieval runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum Mode {
    /// Shoal's inversion: what a design study should use.
    #[default]
    Improved,
    /// The published code's behaviour, to reproduce published numbers.
    Reference,
}

/// Errors from the retrievals; each names the field.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum RetrievalError {
    /// A field with an invalid value.
    #[error(transparent)]
    Invalid(#[from] FieldError),
    /// From the water stage (SIOP sets, substrates).
    #[error(transparent)]
    Water(#[from] WaterError),
    /// From the spectral layer.
    #[error(transparent)]
    Spectral(#[from] SpectralError),
    /// An external retrieval's program failed (could not start, exited with an error, ran too
    /// long, or wrote no product).
    #[error("external retrieval `{name}`: {message}")]
    External {
        /// The retrieval's name.
        name: String,
        /// What went wrong, with the end of the program's standard error.
        message: String,
    },
    /// The run was cancelled.
    #[error("cancelled")]
    Cancelled,
}

impl crate::control::Cancellable for RetrievalError {
    fn cancelled() -> Self {
        Self::Cancelled
    }

    fn is_cancelled(&self) -> bool {
        matches!(self, Self::Cancelled)
    }
}

/// Prepare `spec`'s model at `inputs.bands` (reads `bands`, `scene_siop`, `scene_substrates`
/// and `base_dir` only): what [`invert`] needs besides the Rrs. It depends on the spec, the bands
/// and the scene's SIOP and substrates, not on the Rrs, so the engine keeps it while a change of
/// noise, aperture or electronics re-runs the pixels (stage `RetrievalModel`).
pub fn prepare(spec: &RetrievalSpec, inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError> {
    let algorithm = spec.algorithm();
    algorithm.validate()?;
    algorithm.prepare(inputs)
}

/// Run the retrieval `model` was prepared for ([`prepare`]) over the image at the same bands.
pub fn invert(
    model: &Model,
    inputs: &RetrievalInputs<'_>,
    control: &crate::control::RunControl,
) -> Result<Product, RetrievalError> {
    model.invert(inputs, control)
}

/// Run `spec` over the image: [`prepare`], then [`invert`].
pub fn retrieve(
    spec: &RetrievalSpec,
    inputs: &RetrievalInputs<'_>,
    control: &crate::control::RunControl,
) -> Result<Product, RetrievalError> {
    prepare(spec, inputs)?.invert(inputs, control)
}
