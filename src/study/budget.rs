//! Error budget: how much of a product's error each stage of the chain contributes.
//!
//! Each stage that makes error has a "perfect" switch: the instrument's optical effects removed
//! (stray light, polarisation sensitivity, spectral stray light, the MTF budget: an ideal optic;
//! only where the design states any), its focal-plane effects removed (non-linearity, fixed
//! patterns, misregistration, compression; likewise), instrument noise and quantisation off,
//! calibration perfect (gains and offsets exact), atmospheric correction exact (the per-pixel
//! inversion of the same radiative transfer instead of the per-scene approximation or the
//! image-based correction's aerosol from the design's own bands), and the
//! retrieval given the scene's own SIOP set (no set-selection error). Two budgets:
//!
//! - **sequential**: make the stages perfect one after another in chain order; each stage's share
//!   is the drop in MAE it causes, and the shares plus the floor (what is left with every switch
//!   on: band averaging, the model's bounds) add up to the full error exactly;
//! - **one at a time**: only that stage imperfect, every other perfect; its share is the MAE
//!   above the floor. Their sum differs from the full error by the stages' interaction (errors
//!   in log space do not add), which this shows rather than hides.
//!
//! Every configuration runs with every seed of the study; the spread is the seeds' standard
//! deviation of the full chain's MAE.

use crate::control::RunControl;
use crate::engine::{Engine, EngineError, RunConfig};
use crate::parse::FieldError;
use crate::retrieval::RetrievalSpec;

use super::StudyError;

/// The stages with a perfect switch, in chain order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorSource {
    /// The instrument's optical effects, as the processor leaves them (`instrument::effects`).
    Optics,
    /// The focal plane's and electronics' effects, as the calibration and the ground leave them.
    FocalPlane,
    /// Photon, dark and read noise; quantisation.
    Noise,
    /// Gain and offset estimation from diffuser and dark frames.
    Calibration,
    /// Atmospheric correction (approximation against the exact inversion).
    Correction,
    /// Choosing among SIOP sets (against being given the scene's).
    SiopChoice,
}

impl ErrorSource {
    /// All, in chain order.
    pub const ALL: [Self; 6] =
        [Self::Optics, Self::FocalPlane, Self::Noise, Self::Calibration, Self::Correction, Self::SiopChoice];

    /// Does `config` have this source of error? (Only a design that states optical or
    /// focal-plane effects has the first two.)
    #[must_use]
    pub fn applies(self, config: &RunConfig) -> bool {
        let effects = &config.instrument.effects;
        match self {
            Self::Optics => effects.iter().any(|e| !e.on_the_focal_plane()),
            Self::FocalPlane => effects.iter().any(|e| e.on_the_focal_plane() && e.makes_error()),
            _ => true,
        }
    }

    /// Name in tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Optics => "optical effects",
            Self::FocalPlane => "focal-plane effects",
            Self::Noise => "noise and quantisation",
            Self::Calibration => "calibration",
            Self::Correction => "atmospheric correction",
            Self::SiopChoice => "SIOP set choice",
        }
    }

    /// Make this stage perfect in `config`.
    fn perfect(self, config: &mut RunConfig) {
        match self {
            // A design choice (binning) stays: it is the design, not an error of it.
            Self::Optics => config.instrument.effects.retain(|e| e.on_the_focal_plane() || !e.makes_error()),
            Self::FocalPlane => config.instrument.effects.retain(|e| !e.on_the_focal_plane() || !e.makes_error()),
            Self::Noise => {
                config.detector.noise = false;
                config.detector.quantise = false;
            }
            Self::Calibration => config.calibration.perfect = true,
            Self::Correction => {
                // The perfect correction: the exact inversion with the forward model's atmosphere
                // and its wind.
                config.correction.method = crate::correction::Method::Exact;
                config.correction.glint_wind_error_m_s = 0.0;
            }
            Self::SiopChoice => {
                let truth = config.scene.siop.clone();
                for r in &mut config.retrievals {
                    if let RetrievalSpec::Almi { siop_sets, .. } = r {
                        *siop_sets = vec![truth.clone()];
                    }
                }
            }
        }
    }
}

/// One line of a budget.
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetLine {
    /// The stage.
    pub stage: ErrorSource,
    /// Sequential share: MAE drop when this stage is made perfect after those before it, points of %.
    pub sequential_pct: f64,
    /// One-at-a-time share: MAE with only this stage imperfect, minus the floor, points of %.
    pub alone_pct: f64,
}

/// The budget of one variable of one instrument.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorBudget {
    /// Instrument label.
    pub instrument: String,
    /// Variable.
    pub variable: String,
    /// MAE of the chain as configured, % (mean over seeds).
    pub full_pct: f64,
    /// Standard deviation of `full_pct` over seeds (0 with one seed).
    pub full_spread_pct: f64,
    /// MAE with every stage perfect, %.
    pub floor_pct: f64,
    /// Per stage.
    pub lines: Vec<BudgetLine>,
}

/// Mean MAE (%) per variable of `config` over `seeds`, and each seed's values.
fn mae(
    engine: &mut Engine,
    config: &RunConfig,
    seeds: &[u64],
    control: &RunControl,
) -> Result<Vec<(String, Vec<f64>)>, StudyError> {
    let mut out: Vec<(String, Vec<f64>)> = Vec::new();
    for &seed in seeds {
        let mut c = config.clone();
        c.seed = seed;
        let run = engine.run(&c, control).map_err(|e| match e {
            EngineError::Cancelled => StudyError::Cancelled,
            other => StudyError::Run { instrument: c.instrument.name.clone(), message: other.to_string() },
        })?;
        let Some(ret) = run.retrievals.first() else {
            return Err(StudyError::Invalid(FieldError {
                field: "retrievals".into(),
                message: "an error budget needs a retrieval".into(),
            }));
        };
        for v in &ret.metrics.variables {
            match out.iter_mut().find(|(name, _)| *name == v.variable) {
                Some((_, values)) => values.push(v.metrics.mae_pct()),
                None => out.push((v.variable.clone(), vec![v.metrics.mae_pct()])),
            }
        }
    }
    Ok(out)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn get(values: &[(String, Vec<f64>)], variable: &str) -> f64 {
    values.iter().find(|(n, _)| n == variable).map_or(f64::NAN, |(_, v)| mean(v))
}

/// The budget of `config` (labelled `label`) over `seeds`: 2 + 2 × (4 or 5) configurations,
/// each run with every seed.
pub fn error_budget(
    label: &str,
    config: &RunConfig,
    seeds: &[u64],
    control: &RunControl,
) -> Result<Vec<ErrorBudget>, StudyError> {
    if seeds.is_empty() {
        return Err(StudyError::Invalid(FieldError { field: "seeds".into(), message: "at least one seed".into() }));
    }
    let mut engine = Engine::new();
    let stages: Vec<ErrorSource> = ErrorSource::ALL.into_iter().filter(|s| s.applies(config)).collect();
    let full = mae(&mut engine, config, seeds, control)?;
    // Sequential: perfect stages cumulatively in chain order.
    let mut cumulative = config.clone();
    let mut after = Vec::new();
    for &stage in &stages {
        stage.perfect(&mut cumulative);
        after.push(mae(&mut engine, &cumulative, seeds, control)?);
    }
    let floor = after.last().cloned().unwrap_or_default();
    // One at a time: everything perfect except `stage`.
    let mut alone = Vec::new();
    for &stage in &stages {
        let mut c = config.clone();
        for &other in stages.iter().filter(|s| **s != stage) {
            other.perfect(&mut c);
        }
        alone.push(mae(&mut engine, &c, seeds, control)?);
    }
    Ok(full
        .iter()
        .map(|(variable, values)| {
            let full_pct = mean(values);
            let spread =
                (values.iter().map(|v| (v - full_pct).powi(2)).sum::<f64>() / (values.len().max(2) - 1) as f64).sqrt();
            let floor_pct = get(&floor, variable);
            let lines = stages
                .iter()
                .enumerate()
                .map(|(k, &stage)| {
                    let before = if k == 0 { full_pct } else { get(&after[k - 1], variable) };
                    BudgetLine {
                        stage,
                        sequential_pct: before - get(&after[k], variable),
                        alone_pct: get(&alone[k], variable) - floor_pct,
                    }
                })
                .collect();
            ErrorBudget {
                instrument: label.to_string(),
                variable: variable.clone(),
                full_pct,
                full_spread_pct: if values.len() > 1 { spread } else { 0.0 },
                floor_pct,
                lines,
            }
        })
        .collect())
}

/// The budgets as a Markdown table.
#[must_use]
pub fn budget_table(budgets: &[ErrorBudget]) -> String {
    let mut s = String::from(
        "| instrument | variable | full MAE % (± seeds' sd) | stage | sequential share | alone share | floor MAE % |\n|---|---|---|---|---|---|---|\n",
    );
    for b in budgets {
        for (k, l) in b.lines.iter().enumerate() {
            let (inst, var, full, floor) = if k == 0 {
                (
                    b.instrument.as_str(),
                    b.variable.as_str(),
                    format!("{:.1} ± {:.1}", b.full_pct, b.full_spread_pct),
                    format!("{:.1}", b.floor_pct),
                )
            } else {
                ("", "", String::new(), String::new())
            };
            s.push_str(&format!(
                "| {inst} | {var} | {full} | {} | {:+.1} | {:+.1} | {floor} |\n",
                l.stage.name(),
                l.sequential_pct,
                l.alone_pct
            ));
        }
        let seq: f64 = b.lines.iter().map(|l| l.sequential_pct).sum();
        let alone: f64 = b.lines.iter().map(|l| l.alone_pct).sum();
        s.push_str(&format!("| | | | sum | {seq:+.1} | {alone:+.1} | |\n"));
    }
    s
}
