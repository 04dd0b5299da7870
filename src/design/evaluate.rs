//! One design evaluated: the chain run at the search's fidelity for every seed, judged against
//! the study's requirements, and reduced to what the optimiser needs (the cost, one normalised
//! constraint per requirement kind, worst over seeds) and what the tables show.

use std::time::Instant;

use super::space::{Dimension, configure};
use crate::control::RunControl;
use crate::engine::{Engine, EngineError, RunConfig};
use crate::instrument::budgets::{BudgetModels, DesignBudget};
use crate::study::{Check, Requirements, StudyError};

/// A design and what it achieved.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Evaluation {
    /// The varied parameters' values.
    pub x: Vec<f64>,
    /// Telescope cost (`None`: refused by the cost model, or the run failed).
    pub cost: Option<f64>,
    /// Per constraint key, the worst normalised excess over seeds: (value − limit)/limit for an
    /// upper limit, (limit − value)/limit for a lower one; at most 0 meets it.
    pub constraints: Vec<(String, f64)>,
    /// Seeds on which every requirement passed.
    pub seeds_passed: usize,
    /// Seeds run.
    pub seeds: usize,
    /// Per product variable, the log-space MAE %, mean over seeds.
    pub mae_pct: Vec<(String, f64)>,
    /// The design's budgets.
    pub budget: Option<DesignBudget>,
    /// Line and detector decimation it ran at.
    pub decimation: usize,
    /// Wall time, s.
    pub seconds: f64,
    /// Why it has no result (invalid parameters, a failed run).
    pub error: Option<String>,
    /// Why it is implausible even where its numbers pass (it smears, saturates or has no
    /// buildable f-number), in a few words each ([`crate::instrument::plausibility`]).
    #[serde(default)]
    pub warnings: Vec<String>,
}

impl Evaluation {
    /// Every requirement met on every seed.
    #[must_use]
    pub fn feasible(&self) -> bool {
        self.error.is_none() && self.cost.is_some() && self.constraints.iter().all(|(_, g)| *g <= 0.0)
    }

    /// The worst constraint (largest normalised excess).
    #[must_use]
    pub fn worst(&self) -> f64 {
        self.constraints.iter().map(|(_, g)| *g).fold(f64::NEG_INFINITY, f64::max)
    }
}

/// What the search asks of each design.
pub struct Evaluator<'a> {
    /// The configuration every design starts from (the study's first instrument).
    pub base: &'a RunConfig,
    /// The varied fields.
    pub vars: &'a [Dimension],
    /// Noise seeds each design runs with.
    pub seeds: &'a [u64],
    /// What the products and the design must meet.
    pub requirements: &'a Requirements,
    /// Cost, envelope and data models.
    pub budgets: &'a BudgetModels,
    /// Decimation of lines and detectors.
    pub decimation: usize,
}

/// The constraint a check belongs to: per product variable and kind, and one per band-wise
/// family (the worst band decides).
fn key(c: &Check) -> String {
    if c.variable.is_some() {
        return c.what.clone();
    }
    for (prefix, key) in [
        ("SNR", "SNR, worst band"),
        ("Rrs", "Rrs MAE, worst band"),
        ("cost", "cost"),
        ("fits", "fits"),
        ("data", "data a day"),
    ] {
        if c.what.starts_with(prefix) {
            return key.into();
        }
    }
    c.what.clone()
}

/// The constraint keys a search over `requirements` can report, and those every evaluation
/// without an error must report, when its retrieval makes the variables `made` (the same keys
/// [`key`] gives the checks of [`Requirements::check_run`] and [`Requirements::check_design`]).
/// A shard record is judged against them: a forged record without its constraints would be
/// taken for a feasible design.
#[must_use]
pub fn constraint_plan(requirements: &Requirements, made: &[String]) -> (Vec<String>, Vec<String>) {
    let (mut possible, mut required) = (Vec::new(), Vec::new());
    for p in &requirements.products {
        let is_made = made.contains(&p.variable);
        for (limit, what) in [(p.mae_pct, "MAE %"), (p.bias_pct, "|bias| %"), (p.returned_pct, "returned %")] {
            if limit.is_some() {
                let k = format!("{} {what}", p.variable);
                if is_made {
                    required.push(k.clone());
                }
                possible.push(k);
            }
        }
    }
    if requirements.substrate_pct.is_some() {
        possible.push("substrate right %".into());
    }
    if requirements.rrs.is_some() {
        possible.push("Rrs MAE, worst band".into());
    }
    let design = [
        (requirements.snr.is_some(), "SNR, worst band"),
        (requirements.cost_max.is_some(), "cost"),
        (requirements.fits.is_some(), "fits"),
        (requirements.data_volume_gbit_day.is_some(), "data a day"),
        (requirements.gsd_m_max.is_some(), "GSD, m"),
        (requirements.smear_px_max.is_some(), "smear, px"),
    ];
    let optics = [
        (requirements.mtf_nyquist_min.is_some(), crate::study::MTF_MIN_WHAT.to_string()),
        (requirements.mtf_nyquist_max.is_some(), crate::study::MTF_MAX_WHAT.to_string()),
        (requirements.polarisation_pct_max.is_some(), crate::study::POLARISATION_WHAT.to_string()),
        (requirements.stray_light.is_some(), requirements.stray_light.as_ref().map_or_else(String::new, |s| s.what())),
        (requirements.registration_px_max.is_some(), crate::study::REGISTRATION_WHAT.to_string()),
        (requirements.nonlinearity_pct_max.is_some(), crate::study::NONLINEARITY_WHAT.to_string()),
    ];
    for (stated, k) in design.into_iter().map(|(s, k)| (s, k.to_string())).chain(optics) {
        if stated {
            possible.push(k.clone());
            required.push(k);
        }
    }
    (possible, required)
}

/// The normalised excess of a check (positive: it fails); a check without a value fails by 1.
fn excess(c: &Check) -> f64 {
    match c.margin {
        Some(m) if c.limit.abs() > 0.0 => -m / c.limit.abs(),
        Some(m) => -m,
        None => 1.0,
    }
}

impl Evaluator<'_> {
    /// Run the design `x` on `engine`.
    pub fn evaluate(&self, engine: &mut Engine, x: &[f64], control: &RunControl) -> Result<Evaluation, StudyError> {
        let start = Instant::now();
        let mut e = Evaluation {
            x: x.to_vec(),
            cost: None,
            constraints: Vec::new(),
            seeds_passed: 0,
            seeds: self.seeds.len(),
            mae_pct: Vec::new(),
            budget: None,
            decimation: self.decimation,
            seconds: 0.0,
            error: None,
            warnings: Vec::new(),
        };
        let mut config = match configure(self.base, self.vars, x) {
            Ok(c) => c,
            Err(message) => {
                e.error = Some(message);
                return Ok(e);
            }
        };
        config.fidelity.decimation = self.decimation;
        let mut worst: Vec<(String, f64)> = Vec::new();
        let mut mae: Vec<(String, f64)> = Vec::new();
        for &seed in self.seeds {
            config.seed = seed;
            let out = match engine.run(&config, control) {
                Ok(out) => out,
                Err(EngineError::Cancelled) => return Err(StudyError::Cancelled),
                Err(other) => {
                    e.error = Some(other.to_string());
                    e.seconds = start.elapsed().as_secs_f64();
                    return Ok(e);
                }
            };
            let budget = self.budgets.assess(&config.instrument.as_flown(), &out.response.plane_of_band);
            let metrics = out.retrievals.first().map(|r| &r.metrics);
            let label = &config.instrument.name;
            let mut checks = self.requirements.check_run(label, seed, metrics, &out.snr, &out.correction.rrs_metrics);
            checks.extend(self.requirements.check_design(
                label,
                seed,
                &config.instrument.as_flown(),
                &budget,
                self.budgets,
            ));
            if checks.iter().all(|c| c.pass) {
                e.seeds_passed += 1;
            }
            for c in &checks {
                let (k, g) = (key(c), excess(c));
                match worst.iter_mut().find(|(name, _)| *name == k) {
                    Some(w) => w.1 = w.1.max(g),
                    None => worst.push((k, g)),
                }
            }
            for v in metrics.map(|m| m.variables.as_slice()).unwrap_or_default() {
                let value = if v.metrics.n > 0 { v.metrics.mae_pct() } else { f64::NAN };
                match mae.iter_mut().find(|(name, _)| *name == v.variable) {
                    Some(m) => m.1 += value / self.seeds.len() as f64,
                    None => mae.push((v.variable.clone(), value / self.seeds.len() as f64)),
                }
            }
            for w in &out.report.warnings {
                if !e.warnings.contains(&w.short()) {
                    e.warnings.push(w.short());
                }
            }
            e.cost = budget.cost.ota;
            e.budget = Some(budget);
        }
        e.constraints = worst;
        e.mae_pct = mae;
        e.seconds = start.elapsed().as_secs_f64();
        Ok(e)
    }
}
