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
//! | images | [`run`] | a retrieval over a whole Rrs cube, the products and their flags |

pub mod almi;
pub mod almi_lanes;
pub mod almi_reference;
pub mod band_model;
pub mod external;
mod external_io;
pub mod nnls;
pub mod optimise;
pub mod quadrature;
pub mod run;
mod run_sambuca;
pub mod sambuca;
pub mod sambuca_reference;
pub mod sets;
pub mod slsqp;
mod slsqp_qp;

pub use almi::{AlmiFlags, AlmiSettings};
pub use band_model::{BandModel, BandResponse, ModelScratch, Parameters};
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

/// A retrieval's model at the instrument's bands: what [`invert`] needs besides the Rrs (each SIOP
/// set and substrate read and integrated over the band responses). It depends on the spec, the
/// bands and the scene's SIOP and substrates, not on the Rrs, so the engine keeps it while a
/// change of noise, aperture or electronics re-runs the pixels (stage `RetrievalModel`).
#[derive(Debug, Clone)]
pub enum Model {
    /// aLMI's sets.
    Almi(run::AlmiModel),
    /// SAMBUCA's set and substrates (boxed: the larger of the two by far).
    Sambuca(Box<run_sambuca::SambucaModel>),
    /// An external program: nothing to prepare.
    External,
}

/// Prepare `spec`'s model at `inputs.bands` (reads `bands`, `scene_siop`, `scene_substrates`
/// and `base_dir` only).
pub fn prepare(spec: &RetrievalSpec, inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError> {
    spec.validate()?;
    Ok(match spec {
        RetrievalSpec::Almi { siop_sets, settings } => Model::Almi(run::almi_model(siop_sets, settings, inputs)?),
        RetrievalSpec::Sambuca { siop, substrates, settings } => Model::Sambuca(Box::new(run_sambuca::sambuca_model(
            siop.as_ref(),
            substrates.as_deref(),
            settings,
            inputs,
        )?)),
        RetrievalSpec::External(_) => Model::External,
    })
}

/// Run `spec` over the image with `model`, prepared by [`prepare`] from the same spec and bands.
pub fn invert(
    spec: &RetrievalSpec,
    model: &Model,
    inputs: &RetrievalInputs<'_>,
    control: &crate::control::RunControl,
) -> Result<Product, RetrievalError> {
    match (spec, model) {
        (RetrievalSpec::Almi { settings, .. }, Model::Almi(m)) => run::retrieve_almi(m, settings, inputs, control),
        (RetrievalSpec::Sambuca { settings, .. }, Model::Sambuca(m)) => {
            run_sambuca::retrieve_sambuca(m, settings, inputs, control)
        }
        (RetrievalSpec::External(e), Model::External) => external::retrieve_external(e, inputs, control),
        _ => Err(RetrievalError::Invalid(FieldError {
            field: "retrieval".into(),
            message: format!("the model given was prepared for another retrieval than {}", spec.name()),
        })),
    }
}

/// Run `spec` over the image: [`prepare`], then [`invert`].
pub fn retrieve(
    spec: &RetrievalSpec,
    inputs: &RetrievalInputs<'_>,
    control: &crate::control::RunControl,
) -> Result<Product, RetrievalError> {
    let model = prepare(spec, inputs)?;
    invert(spec, &model, inputs, control)
}
