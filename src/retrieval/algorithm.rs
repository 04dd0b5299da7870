//! The one seam every retrieval goes through: what the engine, the studies and the app ask of
//! an algorithm ([`Algorithm`]), what it prepares at an instrument's bands ([`Prepared`]), and
//! the registry ([`RetrievalSpec::algorithm`], [`RetrievalSpec::name`],
//! [`RetrievalSpec::mode_mut`]): the one place that matches on the spec's kinds. A new retrieval
//! is a module implementing the two traits, a variant of [`RetrievalSpec`] (its settings as a
//! study writes them), an [`Identity`] in [`BUILT_IN`] and an arm in each registry function (the
//! compiler points at them: the matches are exhaustive).

use super::run::{Product, RetrievalInputs, RetrievalSpec};
use super::{Mode, RetrievalError, external, qaa, run, run_sambuca};
use crate::control::RunControl;

/// A built-in retrieval's names, given once here and read everywhere else (reports, file names,
/// the pack's captions, the app's banners).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Identity {
    /// Short name for reports, series and file names (`alm`).
    pub name: &'static str,
    /// Its name for people (`aLMI`), also the name of its products.
    pub title: &'static str,
}

/// aLMI (Brando et al. 2012).
pub const ALMI: Identity = Identity { name: "alm", title: "aLMI" };
/// SAMBUCA (Brando et al. 2009).
pub const SAMBUCA: Identity = Identity { name: "sambuca", title: "SAMBUCA" };
/// QAA v6 (Lee et al. 2002, v6 2014).
pub const QAA: Identity = Identity { name: "qaa", title: "QAA v6" };

/// The built-in retrievals, in the order the app offers them.
pub const BUILT_IN: [Identity; 3] = [ALMI, SAMBUCA, QAA];

/// The title of the retrieval called `name` ([`Identity::name`]), or `name` itself (a user's
/// program is called by its own name).
#[must_use]
pub fn title_of(name: &str) -> &str {
    BUILT_IN.iter().find(|i| i.name == name).map_or(name, |i| i.title)
}

/// A retrieval prepared at an instrument's bands (SIOP sets, substrates, pure water integrated
/// over the band responses, with the settings it was prepared from): kept by the engine while
/// the Rrs changes. Each retrieval's own type; nothing is downcast.
pub trait Prepared: Send + Sync {
    /// Run over the image.
    fn invert(&self, inputs: &RetrievalInputs<'_>, control: &RunControl) -> Result<Product, RetrievalError>;

    /// The true maps of the extra products it returns (by key), when the truth's concentrations
    /// and its model say what they are; none by default (an extra is then mapped, not scored).
    fn extra_truths(&self, _truth: &crate::instrument::Truth) -> Vec<(String, ndarray::Array2<f32>)> {
        Vec::new()
    }
}

/// A prepared retrieval, as the engine keeps it.
pub type Model = Box<dyn Prepared>;

/// What every retrieval does.
pub trait Algorithm {
    /// Short name for reports, series and file names (`alm`, `sambuca`, `qaa`, a program's).
    fn name(&self) -> &str;

    /// Its name for people (`aLMI`, `SAMBUCA`, `QAA v6`).
    fn title(&self) -> &str;

    /// The variables it returns: keys of [`crate::variable::PRODUCTS`] and
    /// [`crate::variable::EXTRAS`].
    fn variables(&self) -> Vec<String>;

    /// Check the settings that need no image (counts, coefficients, bounds) against
    /// [`crate::ranges`], so a run can refuse them before any stage runs.
    fn validate(&self) -> Result<(), RetrievalError>;

    /// Prepare it at `inputs.bands` (reads the bands, the scene's SIOP and substrates, and
    /// `base_dir`; never the Rrs).
    fn prepare(&self, inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError>;

    /// The variable people look at first (the app's map when it is chosen): chl-a by default.
    fn headline(&self) -> &'static str {
        crate::variable::key::CHL
    }

    /// The class maps it makes besides its variables.
    fn classes(&self) -> Classes {
        Classes::default()
    }

    /// Its settings that trade accuracy for time, for the cost-of-accuracy table
    /// ([`crate::sweep::cost`]): each a label and an edit of the spec, one change from the spec as
    /// given. None by default (a user's program, or QAA, closed-form per pixel, is measured as it
    /// is).
    fn cheaper(&self) -> Vec<Cheaper> {
        Vec::new()
    }
}

/// The class maps a retrieval makes ([`Algorithm::classes`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Classes {
    /// The substrates it unmixed, and so the dominant one per pixel.
    pub substrates: bool,
    /// The SIOP set it chose per pixel.
    pub siop_sets: bool,
}

/// A label and an edit of a [`RetrievalSpec`] ([`Algorithm::cheaper`]).
pub type Cheaper = (&'static str, fn(&mut RetrievalSpec));

/// aLMI's settings and sets of `spec`, if it is aLMI.
fn almi_mut(spec: &mut RetrievalSpec) -> Option<(&mut Vec<crate::water::SiopSource>, &mut super::AlmiSettings)> {
    match spec {
        RetrievalSpec::Almi { siop_sets, settings } => Some((siop_sets, settings)),
        _ => None,
    }
}

/// SAMBUCA's settings of `spec`, if it is SAMBUCA.
fn sambuca_mut(spec: &mut RetrievalSpec) -> Option<&mut super::SambucaSettings> {
    match spec {
        RetrievalSpec::Sambuca { settings, .. } => Some(settings),
        _ => None,
    }
}

/// aLMI (Brando et al. 2012) over its SIOP sets.
struct Almi<'a>(&'a [crate::water::SiopSource], &'a super::AlmiSettings);

/// aLMI's sets at the bands, with its settings.
struct PreparedAlmi(run::AlmiModel, super::AlmiSettings);

impl Algorithm for Almi<'_> {
    fn name(&self) -> &str {
        ALMI.name
    }
    fn title(&self) -> &str {
        ALMI.title
    }
    fn variables(&self) -> Vec<String> {
        use crate::variable::key;
        [key::CHL, key::NAP, key::CDOM].map(String::from).to_vec()
    }
    fn validate(&self) -> Result<(), RetrievalError> {
        run::validate_almi(self.0, self.1)
    }
    fn prepare(&self, inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError> {
        Ok(Box::new(PreparedAlmi(run::almi_model(self.0, self.1, inputs)?, self.1.clone())))
    }
    fn classes(&self) -> Classes {
        Classes { siop_sets: true, ..Classes::default() }
    }
    fn cheaper(&self) -> Vec<Cheaper> {
        vec![
            ("aLMI unweighted (one solve per set)", |r| {
                almi_mut(r).into_iter().for_each(|(_, s)| s.noise_weighting = false);
            }),
            ("aLMI 4 of 8 SIOP sets", |r| almi_mut(r).into_iter().for_each(|(sets, _)| sets.truncate(4))),
        ]
    }
}

impl Prepared for PreparedAlmi {
    fn invert(&self, inputs: &RetrievalInputs<'_>, control: &RunControl) -> Result<Product, RetrievalError> {
        run::retrieve_almi(&self.0, &self.1, inputs, control)
    }
}

/// SAMBUCA-style (Brando et al. 2009) with one SIOP set and a substrate library.
struct Sambuca<'a>(Option<&'a crate::water::SiopSource>, Option<&'a [String]>, &'a super::SambucaSettings);

/// SAMBUCA's model at the bands, with its settings.
struct PreparedSambuca(run_sambuca::SambucaModel, super::SambucaSettings);

impl Algorithm for Sambuca<'_> {
    fn name(&self) -> &str {
        SAMBUCA.name
    }
    fn title(&self) -> &str {
        SAMBUCA.title
    }
    fn variables(&self) -> Vec<String> {
        crate::variable::KEYS.map(String::from).to_vec()
    }
    fn validate(&self) -> Result<(), RetrievalError> {
        run::validate_sambuca(self.2)
    }
    fn prepare(&self, inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError> {
        let model = run_sambuca::sambuca_model(self.0, self.1, self.2, inputs)?;
        Ok(Box::new(PreparedSambuca(model, self.2.clone())))
    }
    fn headline(&self) -> &'static str {
        crate::variable::key::DEPTH
    }
    fn classes(&self) -> Classes {
        Classes { substrates: true, ..Classes::default() }
    }
    // The defaults: 3 Gauss nodes per band, 100 iterations, adaptive starts, warm pairs,
    // noise-weighted.
    fn cheaper(&self) -> Vec<Cheaper> {
        use super::Starts;
        vec![
            ("SAMBUCA 1 Gauss node per band", |r| sambuca_mut(r).into_iter().for_each(|s| s.nodes_per_band = 1)),
            ("SAMBUCA 2 Gauss nodes per band", |r| sambuca_mut(r).into_iter().for_each(|s| s.nodes_per_band = 2)),
            ("SAMBUCA 5 Gauss nodes per band", |r| sambuca_mut(r).into_iter().for_each(|s| s.nodes_per_band = 5)),
            ("SAMBUCA 25 iterations per start", |r| sambuca_mut(r).into_iter().for_each(|s| s.max_iterations = 25)),
            ("SAMBUCA 50 iterations per start", |r| sambuca_mut(r).into_iter().for_each(|s| s.max_iterations = 50)),
            ("SAMBUCA shallow start only", |r| sambuca_mut(r).into_iter().for_each(|s| s.starts = Starts::Shallow)),
            ("SAMBUCA shallow and deep starts, every pixel", |r| {
                sambuca_mut(r).into_iter().for_each(|s| s.starts = Starts::ShallowAndDeep);
            }),
            ("SAMBUCA cold start for every pair", |r| sambuca_mut(r).into_iter().for_each(|s| s.warm_pairs = false)),
            ("SAMBUCA unweighted", |r| sambuca_mut(r).into_iter().for_each(|s| s.noise_weighting = false)),
        ]
    }
}

impl Prepared for PreparedSambuca {
    fn invert(&self, inputs: &RetrievalInputs<'_>, control: &RunControl) -> Result<Product, RetrievalError> {
        run_sambuca::retrieve_sambuca(&self.0, &self.1, inputs, control)
    }
}

/// A user's program ([`external`]): nothing to prepare but the spec.
struct External<'a>(&'a external::ExternalSpec);

impl Algorithm for External<'_> {
    fn name(&self) -> &str {
        &self.0.name
    }
    fn title(&self) -> &str {
        &self.0.name
    }
    fn variables(&self) -> Vec<String> {
        self.0.products.clone()
    }
    fn validate(&self) -> Result<(), RetrievalError> {
        self.0.validate()
    }
    fn prepare(&self, _inputs: &RetrievalInputs<'_>) -> Result<Model, RetrievalError> {
        Ok(Box::new(self.0.clone()))
    }
}

impl Prepared for external::ExternalSpec {
    fn invert(&self, inputs: &RetrievalInputs<'_>, control: &RunControl) -> Result<Product, RetrievalError> {
        external::retrieve_external(self, inputs, control)
    }
}

/// QAA v6 ([`qaa`]).
struct Qaa<'a>(&'a qaa::QaaSettings);

/// QAA's bands and the scene's IOPs at them, with its settings.
struct PreparedQaa(qaa::QaaModel, qaa::QaaSettings);

impl Algorithm for Qaa<'_> {
    fn name(&self) -> &str {
        QAA.name
    }
    fn title(&self) -> &str {
        QAA.title
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
        Ok(Box::new(PreparedQaa(qaa::qaa_model(inputs)?, self.0.clone())))
    }
}

impl Prepared for PreparedQaa {
    fn invert(&self, inputs: &RetrievalInputs<'_>, control: &RunControl) -> Result<Product, RetrievalError> {
        qaa::retrieve_qaa(&self.0, &self.1, inputs, control)
    }
    fn extra_truths(&self, truth: &crate::instrument::Truth) -> Vec<(String, ndarray::Array2<f32>)> {
        qaa::truth_iops(&self.0, truth)
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

    /// The built-in's names (`None`: a user's program, called by its own name). A new retrieval
    /// gets an arm here and its [`Identity`] in [`BUILT_IN`] (`tests/chain/external_hostile.rs`
    /// checks both).
    #[must_use]
    pub const fn identity(&self) -> Option<Identity> {
        match self {
            Self::Almi { .. } => Some(ALMI),
            Self::Sambuca { .. } => Some(SAMBUCA),
            Self::Qaa { .. } => Some(QAA),
            Self::External(_) => None,
        }
    }

    /// Short name for reports and file names ([`Algorithm::name`]).
    #[must_use]
    pub fn name(&self) -> &str {
        match self {
            Self::External(e) => &e.name,
            built_in => built_in.identity().map_or("", |i| i.name),
        }
    }

    /// Its name for people ([`Algorithm::title`]).
    #[must_use]
    pub fn title(&self) -> &str {
        self.identity().map_or_else(|| self.name(), |i| i.title)
    }

    /// The retrieval's inversion mode and what its two modes are called for people (Shoal's
    /// inversion, then the published code's), or `None` for a user's program (one behaviour).
    pub fn mode_mut(&mut self) -> Option<(&mut Mode, [&'static str; 2])> {
        match self {
            Self::Almi { settings, .. } => Some((&mut settings.mode, ["Improved", "Reference"])),
            Self::Sambuca { settings, .. } => Some((&mut settings.mode, ["Improved", "Reference"])),
            Self::Qaa { settings } => Some((&mut settings.mode, ["Document", "IOCCG sheet"])),
            Self::External(_) => None,
        }
    }
}
