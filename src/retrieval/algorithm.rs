//! The one seam every retrieval goes through: what the engine, the studies and the app ask of
//! an algorithm ([`Algorithm`]), and the one place that says which spec runs which algorithm
//! ([`RetrievalSpec::algorithm`]). A new retrieval is a module implementing the trait, a variant
//! of [`RetrievalSpec`] (its settings as a study writes them) and an arm here.

use std::any::Any;

use super::run::{Product, RetrievalInputs, RetrievalSpec};
use super::{RetrievalError, external, qaa, run, run_sambuca};
use crate::control::RunControl;
use crate::parse::FieldError;

/// A retrieval's model at the instrument's bands (SIOP sets, substrates, pure water integrated
/// over the band responses): built once per band set and kept by the engine while the Rrs
/// changes; each algorithm knows its own type.
pub type Model = Box<dyn Any + Send + Sync>;

/// What every retrieval does.
pub trait Algorithm {
    /// Short name for reports, series and file names (`alm`, `sambuca`, `qaa`, a program's).
    fn name(&self) -> &str;

    /// Its name for people (`aLMI`, `SAMBUCA`, `QAA v6`).
    fn title(&self) -> String;

    /// The variables it returns: keys of [`crate::variable::PRODUCTS`] and
    /// [`crate::variable::EXTRAS`].
    fn variables(&self) -> Vec<String>;

    /// Check the settings that need no image (counts, coefficients, bounds) against
    /// [`crate::ranges`], so a run can refuse them before any stage runs.
    fn validate(&self) -> Result<(), RetrievalError>;

    /// Prepare the model at `inputs.bands` (reads the bands, the scene's SIOP and substrates,
    /// and `base_dir`; never the Rrs).
    fn prepare(&self, inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError>;

    /// Run over the image with `model`, prepared by [`Self::prepare`] of the same settings.
    fn invert(
        &self,
        model: &Model,
        inputs: &RetrievalInputs<'_>,
        control: &RunControl,
    ) -> Result<Product, RetrievalError>;

    /// The true maps of the extra products it returns (by key), when the truth's concentrations
    /// and its model say what they are; none by default (an extra is then mapped, not scored).
    fn extra_truths(&self, _model: &Model, _truth: &crate::instrument::Truth) -> Vec<(String, ndarray::Array2<f32>)> {
        Vec::new()
    }
}

/// `model` as the type `name`'s prepare made, or an error saying it was made for another.
pub(super) fn model_of<'m, T: 'static>(model: &'m Model, name: &str) -> Result<&'m T, RetrievalError> {
    model.downcast_ref::<T>().ok_or_else(|| {
        RetrievalError::Invalid(FieldError {
            field: "retrieval".into(),
            message: format!("the model given was prepared for another retrieval than {name}"),
        })
    })
}

/// aLMI (Brando et al. 2012) over its SIOP sets.
struct Almi<'a>(&'a [crate::water::SiopSource], &'a super::AlmiSettings);

impl Algorithm for Almi<'_> {
    fn name(&self) -> &str {
        "alm"
    }
    fn title(&self) -> String {
        "aLMI".into()
    }
    fn variables(&self) -> Vec<String> {
        use crate::variable::key;
        [key::CHL, key::NAP, key::CDOM].map(String::from).to_vec()
    }
    fn validate(&self) -> Result<(), RetrievalError> {
        run::validate_almi(self.0, self.1)
    }
    fn prepare(&self, inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError> {
        Ok(Box::new(run::almi_model(self.0, self.1, inputs)?))
    }
    fn invert(
        &self,
        model: &Model,
        inputs: &RetrievalInputs<'_>,
        control: &RunControl,
    ) -> Result<Product, RetrievalError> {
        run::retrieve_almi(model_of(model, self.name())?, self.1, inputs, control)
    }
}

/// SAMBUCA-style (Brando et al. 2009) with one SIOP set and a substrate library.
struct Sambuca<'a>(Option<&'a crate::water::SiopSource>, Option<&'a [String]>, &'a super::SambucaSettings);

impl Algorithm for Sambuca<'_> {
    fn name(&self) -> &str {
        "sambuca"
    }
    fn title(&self) -> String {
        "SAMBUCA".into()
    }
    fn variables(&self) -> Vec<String> {
        crate::variable::KEYS.map(String::from).to_vec()
    }
    fn validate(&self) -> Result<(), RetrievalError> {
        run::validate_sambuca(self.2)
    }
    fn prepare(&self, inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError> {
        Ok(Box::new(run_sambuca::sambuca_model(self.0, self.1, self.2, inputs)?))
    }
    fn invert(
        &self,
        model: &Model,
        inputs: &RetrievalInputs<'_>,
        control: &RunControl,
    ) -> Result<Product, RetrievalError> {
        run_sambuca::retrieve_sambuca(model_of(model, self.name())?, self.2, inputs, control)
    }
}

/// A user's program ([`external`]).
struct External<'a>(&'a external::ExternalSpec);

impl Algorithm for External<'_> {
    fn name(&self) -> &str {
        &self.0.name
    }
    fn title(&self) -> String {
        self.0.name.clone()
    }
    fn variables(&self) -> Vec<String> {
        self.0.products.clone()
    }
    fn validate(&self) -> Result<(), RetrievalError> {
        self.0.validate()
    }
    fn prepare(&self, _inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError> {
        Ok(Box::new(()))
    }
    fn invert(
        &self,
        _model: &Model,
        inputs: &RetrievalInputs<'_>,
        control: &RunControl,
    ) -> Result<Product, RetrievalError> {
        external::retrieve_external(self.0, inputs, control)
    }
}

/// QAA v6 ([`qaa`]).
struct Qaa<'a>(&'a qaa::QaaSettings);

impl Algorithm for Qaa<'_> {
    fn name(&self) -> &str {
        "qaa"
    }
    fn title(&self) -> String {
        "QAA v6".into()
    }
    fn variables(&self) -> Vec<String> {
        std::iter::once(crate::variable::key::CHL)
            .chain(crate::variable::EXTRAS.iter().map(|v| v.key))
            .map(String::from)
            .collect()
    }
    fn validate(&self) -> Result<(), RetrievalError> {
        Ok(())
    }
    fn prepare(&self, inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError> {
        Ok(Box::new(qaa::qaa_model(inputs)?))
    }
    fn invert(
        &self,
        model: &Model,
        inputs: &RetrievalInputs<'_>,
        control: &RunControl,
    ) -> Result<Product, RetrievalError> {
        qaa::retrieve_qaa(model_of(model, self.name())?, self.0, inputs, control)
    }
    fn extra_truths(&self, model: &Model, truth: &crate::instrument::Truth) -> Vec<(String, ndarray::Array2<f32>)> {
        model_of::<qaa::QaaModel>(model, self.name()).map(|m| qaa::truth_iops(m, truth)).unwrap_or_default()
    }
}

impl RetrievalSpec {
    /// The algorithm this spec runs: the registry of retrievals.
    #[must_use]
    pub fn algorithm(&self) -> Box<dyn Algorithm + '_> {
        match self {
            Self::Almi { siop_sets, settings } => Box::new(Almi(siop_sets, settings)),
            Self::Sambuca { siop, substrates, settings } => {
                Box::new(Sambuca(siop.as_ref(), substrates.as_deref(), settings))
            }
            Self::External(e) => Box::new(External(e)),
            Self::Qaa { settings } => Box::new(Qaa(settings)),
        }
    }
}
