//! Running a study: every instrument and seed through one engine (the scene, its maps and the
//! atmosphere are computed once and shared through the stage cache).

use std::sync::Arc;

use super::{ResolvedStudy, StudyError};
use crate::control::RunControl;
use crate::engine::{Engine, EngineError, RetrievalOutput, RunOutput, RunReport};
use crate::instrument::{SnrRow, Truth};

/// One run of a study, kept for its tables and figures.
#[derive(Debug, Clone)]
pub struct StudyRun {
    /// Instrument label.
    pub label: String,
    /// Noise seed.
    pub seed: u64,
    /// The run's report.
    pub report: RunReport,
    /// SNR table.
    pub snr: Arc<Vec<SnrRow>>,
    /// Retrieval products and metrics.
    pub retrievals: Vec<Arc<RetrievalOutput>>,
    /// The truth maps.
    pub truth: Arc<Truth>,
    /// Where each pixel looks (for A − B maps and scale bars).
    pub viewing: Arc<crate::instrument::Viewing>,
    /// Where the scene is on Earth, if georeferenced.
    pub frame: Option<crate::scene::GeoFrame>,
    /// The design's feasibility figures (f-number, smear, Q, peak signal).
    pub feasibility: Arc<crate::instrument::feasibility::Feasibility>,
    /// Per band: the corrected Rrs against the truth (log-space).
    pub rrs_metrics: Vec<crate::correction::BandRrsMetrics>,
    /// The design's cost, envelope and data budgets (under the study's budget models).
    pub budget: crate::instrument::budgets::DesignBudget,
}

/// All runs of a study.
#[derive(Debug, Clone)]
pub struct StudyResult {
    /// The study.
    pub study: ResolvedStudy,
    /// The runs, in instrument then seed order.
    pub runs: Vec<StudyRun>,
    /// The scene's spectrum at a typical water pixel of the first run, with what each
    /// instrument (first seed) measured there (`None` without water).
    pub spectrum: Option<Arc<super::spectrum_figure::StudySpectrum>>,
}

/// What [`run_study`] will hold (its resource plan) and its engine's cache budget: seeds after
/// an instrument's first reuse its pupil radiance, so with several seeds the cache keeps the
/// largest one.
#[must_use]
pub fn study_plan(study: &ResolvedStudy, keep_cubes: bool) -> (crate::budget::Demand, usize) {
    let configs: Vec<&crate::engine::RunConfig> = study.runs.iter().map(|r| &r.2).collect();
    let seeds = study.runs.iter().filter(|r| study.runs.first().is_some_and(|f| f.0 == r.0)).count();
    let radiance = configs.iter().map(|c| crate::engine::resources::radiance_bytes(c)).max().unwrap_or(0);
    let cache_bytes = crate::engine::LEAN_CACHE_BYTES + if seeds > 1 { radiance } else { 0 };
    (crate::engine::resources::study_demand(&configs, keep_cubes, cache_bytes), cache_bytes)
}

/// Run every configuration of `study`; `on_run` sees each run output (with its cubes, to write
/// them, when `keep_cubes`) before it is reduced to what the tables and figures need. Runs are
/// made one at a time by a lean engine ([`Engine::lean`]): a study holds its runs' products and
/// truth maps, never more than one run's cubes.
pub fn run_study(
    study: &ResolvedStudy,
    control: &RunControl,
    keep_cubes: bool,
    mut on_run: impl FnMut(usize, &RunOutput) -> Result<(), StudyError>,
) -> Result<StudyResult, StudyError> {
    // The runs together against the machine's budget, before any runs (each run checks itself
    // alone when the engine validates it).
    let budget = crate::budget::MachineBudget::from_env()
        .map_err(|m| StudyError::Invalid(crate::parse::FieldError { field: "budget".into(), message: m }))?;
    let (demand, cache_bytes) = study_plan(study, keep_cubes);
    budget.check(&demand)?;
    let mut engine = Engine::lean().with_cache_budget(cache_bytes);
    engine.keep_cubes(keep_cubes);
    let mut runs: Vec<StudyRun> = Vec::with_capacity(study.runs.len());
    let mut spectrum: Option<super::spectrum_figure::StudySpectrum> = None;
    for (i, (label, seed, config)) in study.runs.iter().enumerate() {
        // The spectrum figure's pixel: the first run's typical water pixel, then the point it
        // falls on in each later run (kept by the run, which does not keep its cubes).
        let probes = match &spectrum {
            None if i == 0 => vec![crate::engine::Probe::TypicalWater],
            None => Vec::new(),
            Some(s) => vec![crate::engine::Probe::Ground(s.point.ground_m.0, s.point.ground_m.1)],
        };
        let out = engine.run_with(config, control, &probes).map_err(|e| match e {
            EngineError::Cancelled => StudyError::Cancelled,
            internal @ EngineError::Internal { .. } => {
                StudyError::Internal { instrument: label.clone(), message: internal.to_string() }
            }
            other => StudyError::Run { instrument: label.clone(), message: other.to_string() },
        })?;
        on_run(i, &out)?;
        // The spectrum at the first run's typical water pixel; each instrument's first seed adds
        // what it measured there (the outputs are not kept: the cubes would fill the memory).
        let first_seed = !runs.iter().any(|r| r.label == *label);
        if i == 0 {
            spectrum = super::spectrum_figure::StudySpectrum::of(&out, &[])
                .map_err(|message| StudyError::Run { instrument: label.clone(), message })?;
        }
        if let Some(s) = spectrum.as_mut().filter(|_| first_seed) {
            s.instruments.push(crate::engine::spectrum::instrument_at(&out, label, s.point.ground_m));
        }
        runs.push(StudyRun::of(label, *seed, &out, &study.budgets));
    }
    Ok(StudyResult { study: study.clone(), runs, spectrum: spectrum.map(Arc::new) })
}

impl StudyRun {
    /// What a study keeps of a run (`label`: the instrument's name in the study).
    #[must_use]
    pub fn of(label: &str, seed: u64, out: &RunOutput, budgets: &crate::instrument::budgets::BudgetModels) -> Self {
        Self {
            label: label.to_string(),
            seed,
            report: out.report.clone(),
            snr: out.snr.clone(),
            retrievals: out.retrievals.clone(),
            truth: Arc::clone(&out.truth),
            viewing: Arc::clone(&out.viewing),
            feasibility: Arc::clone(&out.feasibility),
            frame: out.scene.frame.clone(),
            rrs_metrics: out.correction.rrs_metrics.clone(),
            budget: budgets.assess(&out.config.instrument, &out.response.plane_of_band),
        }
    }
}

impl StudyResult {
    /// A study made of runs that already exist (the app's A and B): named `name`, over the first
    /// run's scene and retrievals, judged against `requirements`. Each run is `(label, output)`;
    /// `None` without runs.
    #[must_use]
    pub fn of_runs(
        name: &str,
        description: &str,
        runs: &[(String, &RunOutput)],
        requirements: Option<super::Requirements>,
    ) -> Option<Self> {
        use super::{Source, StudySpec};
        let first = &runs.first()?.1.config;
        let spec = StudySpec {
            name: name.to_string(),
            description: description.to_string(),
            scene: Source::Inline(Box::new(first.scene.clone())),
            instruments: runs.iter().map(|(_, o)| Source::Inline(Box::new(o.config.instrument.clone()))).collect(),
            retrievals: first.retrievals.clone(),
            seeds: vec![first.seed],
            detector: None,
            calibration: None,
            correction: (first.correction != crate::correction::CorrectionSpec::default())
                .then(|| first.correction.clone()),
            fidelity: None,
            requirements,
            snr_reference: first.snr_reference.clone(),
            budgets: None,
        };
        // The app judges under the built-in models (embedded and tested: they always load).
        let budgets = crate::instrument::budgets::BudgetModels::default_models().ok()?;
        let resolved = ResolvedStudy {
            spec,
            runs: runs.iter().map(|(label, o)| (label.clone(), o.config.seed, o.config.clone())).collect(),
            budgets,
        };
        // A spectrum that cannot be computed leaves the figure out, not the export.
        let spectrum = super::spectrum_figure::StudySpectrum::of(runs[0].1, runs).ok().flatten().map(Arc::new);
        let runs = runs.iter().map(|(label, o)| StudyRun::of(label, o.config.seed, o, &resolved.budgets)).collect();
        Some(Self { study: resolved, runs, spectrum })
    }
}
