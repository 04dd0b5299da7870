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
//! | images | [`run`] | a retrieval over a whole Rrs cube, the products and their flags |

pub mod almi;
pub mod almi_lanes;
pub mod almi_reference;
pub mod band_model;
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

/// Run `spec` over the image.
pub fn retrieve(
    spec: &RetrievalSpec,
    inputs: &RetrievalInputs<'_>,
    control: &crate::control::RunControl,
) -> Result<Product, RetrievalError> {
    spec.validate()?;
    match spec {
        RetrievalSpec::Almi { siop_sets, settings } => run::retrieve_almi(siop_sets, settings, inputs, control),
        RetrievalSpec::Sambuca { siop, substrates, settings } => {
            run_sambuca::retrieve_sambuca(siop.as_ref(), substrates.as_deref(), settings, inputs, control)
        }
    }
}
