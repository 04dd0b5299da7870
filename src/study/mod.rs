//! Studies: a scene, one or more instruments, the retrievals and their settings, and seeds —
//! run through the whole chain and reported side by side (metrics tables, figures, cubes).
//!
//! A study file (`presets/studies/*.ron`) names its scene and instruments by built-in name or
//! file, and may override the chain's settings for every run:
//!
//! ```text
//! StudySpec(
//!     name: "cubesat_vs_smallsat",
//!     scene: Preset("lake_hume_bloom"),
//!     instruments: [Preset("cubesat"), Preset("smallsat")],
//!     retrievals: [Almi()],
//!     seeds: [1],
//! )
//! ```

/// The study `shoal study` and the app open with: the paper's trade-off (CubeSat vs SmallSat
/// over the Lake Hume bloom) corrected as a mission would correct it, from each design's own
/// 779/865 nm bands with the NIR iteration, not with the atmosphere the scene was made with.
pub const DEFAULT_STUDY: &str = "cubesat_vs_smallsat_image";
/// The paper's trade-off study (Matthews et al. 2023, §3.2) with its perfect (exact)
/// atmospheric correction: what `shoal reproduce` and the paper's comparisons keep.
pub const PAPER_STUDY: &str = "cubesat_vs_smallsat";

mod budget;
mod curves;
mod figures;
mod geotiff_out;
mod histogram_figure;
mod maps_figure;
pub mod netcdf_out;
mod optics_checks;
mod optics_figure;
mod outdir;
mod output;
mod render;
pub mod reproduction;
mod requirements;
mod rrs_figure;
mod run;
mod slide;
mod snr_figure;
pub mod spectrum_figure;
mod spread;
mod substrate_figure;

pub use budget::{BudgetLine, ErrorBudget, ErrorSource, budget_table, error_budget};
pub use curves::{CurvePoint, CurveSeries, Curves, curve_figure, first_crossing};
pub use figures::{difference_bar, difference_title, figure_set};
pub use geotiff_out::{NODATA, swath_geotransform, write_run_geotiff};
pub use optics_checks::{
    MTF_MAX_WHAT, MTF_MIN_WHAT, NONLINEARITY_WHAT, POLARISATION_WHAT, REGISTRATION_WHAT, StrayLightRequirement,
};
pub use optics_checks::{nonlinearity_left_pct, registration_px};
pub use outdir::{MARKER, OutputDir};
pub use output::{CubeFormat, Outputs, metrics_csv, write_bytes, write_run, write_run_as, write_study};
pub use render::{Figure, base64};
pub use requirements::{Check, ProductRequirement, Requirements, RrsRequirement, checks_csv, verdict};
pub use run::{StudyResult, StudyRun, run_study, study_plan};
pub use slide::{ComparisonPanel, ReviewSlide, SLIDE, SlideSeries, review_slide};
pub use spread::{SeedSpread, seed_spread, seed_spread_csv, spread_of_runs};

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::calibration::CalibrationSpec;
use crate::correction::CorrectionSpec;
use crate::engine::{Fidelity, RunConfig};
use crate::instrument::budgets::{BudgetError, BudgetModels};
use crate::instrument::{DetectorMode, InstrumentSpec};
use crate::parse::{FieldError, ParseError};
use crate::retrieval::RetrievalSpec;
use crate::scene::SceneSpec;

/// Errors of a study, each naming the field or file.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum StudyError {
    /// A field with an invalid value.
    #[error(transparent)]
    Invalid(#[from] FieldError),
    /// A file that does not parse.
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// A run failed.
    #[error("{instrument}: {message}")]
    Run {
        /// Instrument name.
        instrument: String,
        /// The engine's message.
        message: String,
    },
    /// A stage broke (a panic or an injected fault): not the user's input.
    #[error("{instrument}: {message}")]
    Internal {
        /// Instrument name.
        instrument: String,
        /// The engine's message (stage and pixel).
        message: String,
    },
    /// Writing an output failed.
    #[error("{0}")]
    Io(String),
    /// Cancelled.
    #[error("cancelled")]
    Cancelled,
}

/// A scene or instrument by built-in name, by file, or written in place.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Source<T> {
    /// A built-in preset by name.
    Preset(String),
    /// A RON file (relative to the study file).
    File(PathBuf),
    /// Written in place.
    Inline(Box<T>),
}

/// A study as written in RON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// Short name (file names).
    pub name: String,
    /// What it asks.
    #[serde(default)]
    pub description: String,
    /// The scene.
    pub scene: Source<SceneSpec>,
    /// The instruments compared.
    pub instruments: Vec<Source<InstrumentSpec>>,
    /// The retrievals run on each instrument's Rrs.
    pub retrievals: Vec<RetrievalSpec>,
    /// Instrument noise seeds (one run per instrument and seed).
    #[serde(default = "default_seeds")]
    pub seeds: Vec<u64>,
    /// Noise and quantisation switches for every run.
    #[serde(default)]
    pub detector: Option<DetectorMode>,
    /// Calibration settings for every run.
    #[serde(default)]
    pub calibration: Option<CalibrationSpec>,
    /// Correction settings for every run.
    #[serde(default)]
    pub correction: Option<CorrectionSpec>,
    /// Fidelity settings for every run.
    #[serde(default)]
    pub fidelity: Option<Fidelity>,
    /// What the products and bands must achieve (checked and reported with margins).
    #[serde(default)]
    pub requirements: Option<Requirements>,
    /// The radiance every run's SNR is stated at (see [`RunConfig::snr_reference`]).
    #[serde(default)]
    pub snr_reference: Option<crate::spectral::SpectrumSource>,
    /// The models that cost, size and budget each design (built-in `default` when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budgets: Option<Source<BudgetModels>>,
}

fn default_seeds() -> Vec<u64> {
    vec![1]
}

/// A study with its files read: the run configurations, one per instrument and seed.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedStudy {
    /// The study as written.
    pub spec: StudySpec,
    /// (instrument label, seed, configuration) per run.
    pub runs: Vec<(String, u64, RunConfig)>,
    /// The budget models, read and checked.
    pub budgets: BudgetModels,
}

/// Read a scene, instrument or study source: a built-in by name, a RON file relative to `dir`, or
/// inline. Returns the value and the directory its own relative paths are read from.
pub(crate) fn load<T: serde::de::DeserializeOwned + Clone>(
    source: &Source<T>,
    dir: Option<&Path>,
    preset: impl Fn(&str) -> Result<T, String>,
    field: &str,
) -> Result<(T, Option<PathBuf>), StudyError> {
    match source {
        Source::Preset(name) => preset(name)
            .map(|t| (t, None))
            .map_err(|m| StudyError::Invalid(FieldError { field: field.into(), message: m })),
        Source::File(path) => {
            let full = match dir {
                Some(d) if path.is_relative() => d.join(path),
                _ => path.clone(),
            };
            let text = crate::infile::read_text(&full, crate::infile::RON_MAX_BYTES)
                .map_err(|e| StudyError::Invalid(FieldError { field: field.into(), message: e.to_string() }))?;
            let value = ron::from_str(&text).map_err(|e| {
                StudyError::Parse(ParseError {
                    origin: full.display().to_string(),
                    message: crate::parse::describe(&text, &e),
                })
            })?;
            Ok((value, full.parent().map(Path::to_path_buf)))
        }
        Source::Inline(t) => Ok(((**t).clone(), dir.map(Path::to_path_buf))),
    }
}

impl StudySpec {
    /// Parse RON; `origin` names the file in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Self, StudyError> {
        crate::parse::from_ron(text, origin)
    }

    /// A built-in study by name (`presets/studies/NAME.ron`).
    pub fn preset(name: &str) -> Result<Self, StudyError> {
        crate::parse::preset(name)
    }

    /// Names of the built-in studies.
    #[must_use]
    pub fn preset_names() -> Vec<String> {
        crate::parse::preset_names::<Self>()
    }

    /// The built-in default: CubeSat vs SmallSat over Lake Hume with the correction a mission's
    /// processor would make ([`DEFAULT_STUDY`]: the aerosol from each design's own 779/865 nm
    /// bands). The paper's study with its perfect correction is [`PAPER_STUDY`].
    pub fn default_study() -> Result<Self, StudyError> {
        Self::preset(DEFAULT_STUDY)
    }

    /// Read the scene and instruments (`dir`: the study file's directory) and build the runs.
    pub fn resolve(&self, dir: Option<&Path>) -> Result<ResolvedStudy, StudyError> {
        if self.instruments.is_empty() || self.instruments.len() > 16 {
            return Err(StudyError::Invalid(FieldError {
                field: "instruments".into(),
                message: format!("{} (allowed: 1 to 16)", self.instruments.len()),
            }));
        }
        if self.seeds.is_empty() || self.seeds.len() > 1000 {
            return Err(StudyError::Invalid(FieldError {
                field: "seeds".into(),
                message: format!("{} seeds (allowed: 1 to 1000)", self.seeds.len()),
            }));
        }
        crate::parse::check_name("name", &self.name)?;
        let budgets = self.budget_models(dir)?;
        if let Some(r) = &self.requirements {
            r.validate()?;
            r.validate_design(&budgets)?;
        }
        let (scene, scene_dir) = load(&self.scene, dir, |n| SceneSpec::preset(n).map_err(|e| e.to_string()), "scene")?;
        let retrievals = self
            .retrievals
            .iter()
            .map(|r| r.with_dir(dir))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| StudyError::Invalid(FieldError { field: "retrievals".into(), message: e.to_string() }))?;
        let mut runs = Vec::new();
        let mut labels: Vec<String> = Vec::new();
        for (i, source) in self.instruments.iter().enumerate() {
            let (instrument, _) = load(
                source,
                dir,
                |n| InstrumentSpec::preset(n).map_err(|e| e.to_string()),
                &format!("instruments[{i}]"),
            )?;
            instrument.validate().map_err(|e| {
                StudyError::Invalid(FieldError {
                    field: format!("instruments[{i}] ({})", instrument.name),
                    message: e.to_string(),
                })
            })?;
            let mut label = instrument.name.clone();
            if labels.contains(&label) {
                label = format!("{label}_{}", i + 1);
            }
            labels.push(label.clone());
            for &seed in &self.seeds {
                let mut config = RunConfig::new(scene.clone(), instrument.clone());
                config.scene_dir.clone_from(&scene_dir);
                config.seed = seed;
                config.retrievals.clone_from(&retrievals);
                if let Some(d) = self.detector {
                    config.detector = d;
                }
                if let Some(c) = &self.calibration {
                    config.calibration = c.clone();
                }
                if let Some(c) = &self.correction {
                    config.correction = c.clone();
                }
                if let Some(f) = &self.fidelity {
                    config.fidelity = f.clone();
                }
                if let Some(r) = &self.snr_reference {
                    config.snr_reference = Some(r.clone());
                }
                runs.push((label.clone(), seed, config));
            }
        }
        Ok(ResolvedStudy { spec: self.clone(), runs, budgets })
    }

    /// The study's budget models (`budgets:`, else the built-in `default`), checked.
    pub fn budget_models(&self, dir: Option<&Path>) -> Result<BudgetModels, StudyError> {
        let source = self.budgets.clone().unwrap_or_else(|| Source::Preset("default".into()));
        let (models, _) = load(&source, dir, |n| BudgetModels::preset(n).map_err(|e| e.to_string()), "budgets")?;
        models.validate().map_err(|e| match e {
            BudgetError::Invalid(f) => StudyError::Invalid(f),
            BudgetError::Parse(p) => StudyError::Parse(p),
        })?;
        Ok(models)
    }
}

impl crate::parse::Preset for StudySpec {
    const FOLDER: &'static str = "studies";
    type Error = StudyError;
    fn parse_error(origin: &str, message: String) -> StudyError {
        StudyError::Parse(ParseError { origin: origin.into(), message })
    }
    fn unknown(name: &str, known: &[String]) -> StudyError {
        StudyError::Invalid(FieldError {
            field: "study".into(),
            message: format!("no built-in study `{name}` (known: {})", known.join(", ")),
        })
    }
}
