//! Design search: the cheapest instrument that meets every requirement, and the front of cost
//! against each product's error.
//!
//! The objective (telescope cost, [`crate::instrument::budgets`]) is cheap; the constraints
//! (product errors, SNR, Rrs error, and the cheap box and data-volume limits) need a run of the
//! chain per design and noise seed. The search is constrained efficient global optimisation
//! (Jones, Schonlau & Welch 1998; constraints modelled by their own Gaussian processes,
//! Sasena et al. 2002) through egobox's ask-and-tell interface (Lafage 2022): a Latin-hypercube
//! start (McKay et al. 1979), then one design per step where the log expected improvement of
//! ln(cost) is highest among designs whose modelled constraints are met. Integer and listed
//! parameters use egobox's continuous relaxation (Garrido-Merchán & Hernández-Lobato 2020).
//!
//! A design is feasible when every requirement passes on every seed of the study (the worst
//! seed decides each constraint). With all n seeds passing, the one-sided 95 % Clopper–Pearson
//! lower bound on the probability that another seed passes is 0.05^(1/n)
//! ([`pass_probability_lower_bound`]). The search runs at a reduced resolution
//! (`decimation`); the cheapest feasible designs are then confirmed at the confirmation
//! resolution, and the output says which figure came from which.
//!
//! ## References
//! - Jones, D. R., Schonlau, M., Welch, W. J. (1998) Efficient global optimization of expensive
//!   black-box functions. J. Global Optim. 13, 455–492.
//! - Sasena, M. J., Papalambros, P., Goovaerts, P. (2002) Exploration of metamodeling sampling
//!   criteria for constrained global optimization. Eng. Optim. 34, 263–278.
//! - Lafage, R. (2022) egobox, a Rust toolbox for efficient global optimization. J. Open Source
//!   Softw. 7(78), 4737.
//! - McKay, M. D., Beckman, R. J., Conover, W. J. (1979) A comparison of three methods for
//!   selecting values of input variables in the analysis of output from a computer code.
//!   Technometrics 21, 239–245.
//! - Garrido-Merchán, E. C., Hernández-Lobato, D. (2020) Dealing with categorical and
//!   integer-valued variables in Bayesian optimization with Gaussian processes. Neurocomputing
//!   380, 20–35.
//! - Clopper, C. J., Pearson, E. S. (1934) The use of confidence or fiducial limits illustrated
//!   in the case of the binomial. Biometrika 26, 404–413.

pub mod evaluate;
pub mod front;
pub mod record;
pub mod space;

pub use evaluate::{Evaluation, Evaluator};
pub use front::pareto_front;
pub use space::{Dimension, Domain, latin_hypercube};

use crate::control::RunControl;
use crate::engine::Engine;
use crate::parse::FieldError;
use crate::study::StudyError;

/// How a search runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Designs evaluated in all, the start included.
    pub evaluations: usize,
    /// Designs of the Latin-hypercube start (0: 2 · parameters + 1).
    pub initial: usize,
    /// Decimation during the search.
    pub decimation: usize,
    /// Decimation the cheapest feasible designs are confirmed at (`None`: not confirmed).
    pub confirm_decimation: Option<usize>,
    /// Seed of the start and of the optimiser.
    pub seed: u64,
    /// Stop early after this many designs in a row that did not make the cheapest feasible
    /// design at least [`Settings::stall_gain`] cheaper (`None`: run every evaluation).
    pub stall_after: Option<usize>,
    /// The relative cost reduction that counts as progress (0.001: 0.1 %).
    pub stall_gain: f64,
    /// Evaluate only this shard's share of the Latin-hypercube start, then stop (a cluster's
    /// array job; a later search resumes from the shards' records).
    pub shard: Option<crate::sweep::Shard>,
}

impl Settings {
    /// `evaluations` designs at `decimation`, confirmed at full resolution, no early stop.
    #[must_use]
    pub fn new(evaluations: usize, decimation: usize) -> Self {
        Self {
            evaluations,
            initial: 0,
            decimation,
            confirm_decimation: Some(1),
            seed: 1,
            stall_after: None,
            stall_gain: 0.001,
            shard: None,
        }
    }
}

/// Counts designs in a row that did not make the cheapest feasible design cheaper by a share.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Stall {
    best: Option<f64>,
    run: usize,
}

impl Stall {
    /// Take `cost` of a design (`None`: not feasible).
    fn see(&mut self, cost: Option<f64>, gain: f64) {
        match (cost, self.best) {
            (Some(c), Some(b)) if c < b * (1.0 - gain) => (self.best, self.run) = (Some(c), 0),
            (Some(c), None) => (self.best, self.run) = (Some(c), 0),
            (Some(c), Some(b)) => (self.best, self.run) = (Some(c.min(b)), self.run + 1),
            (None, _) => self.run += 1,
        }
    }
}

/// A search's outcome.
#[derive(Debug, Clone)]
pub struct Search {
    /// The varied fields.
    pub vars: Vec<Dimension>,
    /// Every design evaluated, in order.
    pub evaluations: Vec<Evaluation>,
    /// The cheapest feasible design found during the search (index into `evaluations`).
    pub cheapest: Option<usize>,
    /// When nothing is feasible: the design closest to feasible.
    pub closest: Option<usize>,
    /// The confirmation runs (in the order tried; the first feasible one is the answer).
    pub confirmed: Vec<Evaluation>,
    /// Why the search stopped before its evaluations ran out, if it did.
    pub stopped_early: Option<String>,
    /// A shard of the start only: there is no answer to give, only evaluations to resume from.
    pub shard: bool,
    /// Steps at which the optimiser failed (it panicked fitting its surrogates) and a
    /// space-filling design was run instead, with what it said; shown with the answer.
    pub optimiser_failures: Vec<(usize, String)>,
}

impl Search {
    /// The answer: the first confirmed feasible design, else the search's cheapest feasible.
    #[must_use]
    pub fn answer(&self) -> Option<&Evaluation> {
        self.confirmed
            .iter()
            .find(|e| e.feasible())
            .or_else(|| if self.confirmed.is_empty() { self.cheapest.map(|i| &self.evaluations[i]) } else { None })
    }
}

/// What a reader of the answer must know when the optimiser failed at some steps: how often, at
/// which designs, what it said first. `None` when it never failed.
#[must_use]
pub fn optimiser_note(search: &Search) -> Option<String> {
    let (first_step, first_why) = search.optimiser_failures.first()?;
    let steps: Vec<String> = search.optimiser_failures.iter().map(|(s, _)| s.to_string()).collect();
    Some(format!(
        "The optimiser could not propose design {} (it failed fitting its surrogates: at {first_step}, \"{}\"); a space-filling design was run in its place, so the search explored more than it exploited there.",
        steps.join(", "),
        first_why.chars().take(200).collect::<String>()
    ))
}

/// Lower bound on the probability that a further seed passes when all `n` seeds passed
/// (one-sided Clopper–Pearson at `confidence`): (1 − confidence)^(1/n).
#[must_use]
pub fn pass_probability_lower_bound(n: usize, confidence: f64) -> f64 {
    if n == 0 { 0.0 } else { (1.0 - confidence).powf(1.0 / n as f64) }
}

/// Refuse a search that cannot answer before running anything: no requirement to meet, no
/// parameter, too many or too few evaluations, or a cost model that refuses the aperture range.
pub fn check(evaluator: &Evaluator<'_>, settings: &Settings) -> Result<(), StudyError> {
    let bad = |field: &str, message: String| Err(StudyError::Invalid(FieldError { field: field.into(), message }));
    let r = evaluator.requirements;
    if r.products.is_empty() && r.snr.is_none() && r.rrs.is_none() && r.substrate_pct.is_none() && !r.has_design() {
        return bad("requirements", "the study states no requirement: a search needs something to meet".into());
    }
    if evaluator.vars.is_empty() || evaluator.vars.len() > 8 {
        return bad("--vary", format!("{} parameters (allowed: 1 to 8)", evaluator.vars.len()));
    }
    let initial = initial_count(settings, evaluator.vars.len());
    if !(initial + 1..=2000).contains(&settings.evaluations) {
        return bad("--evaluations", format!("{} (allowed: {} to 2000)", settings.evaluations, initial + 1));
    }
    let apertures = match evaluator.vars.iter().find(|v| v.path == "instrument.aperture_mm") {
        Some(v) => v.bounds(),
        None => (evaluator.base.instrument.aperture_mm, evaluator.base.instrument.aperture_mm),
    };
    for a in [apertures.0, apertures.1] {
        let cost = evaluator.budgets.cost.ota(a * 1e-3);
        if let (None, Some(note)) = (cost.ota, cost.note) {
            return bad("budgets.cost.out_of_range", format!("the search needs a cost for every design: {note}"));
        }
    }
    within_budget(evaluator)
}

/// Every corner of the search's box (each parameter at its lowest or highest) against the
/// machine's budget, so that a search whose largest designs would not fit is refused before its
/// first run rather than recording every evaluation as failed.
fn within_budget(evaluator: &Evaluator<'_>) -> Result<(), StudyError> {
    let budget = crate::budget::MachineBudget::from_env()
        .map_err(|m| StudyError::Invalid(FieldError { field: "budget".into(), message: m }))?;
    let n = evaluator.vars.len();
    for corner in 0..1u32 << n {
        let x: Vec<f64> = evaluator
            .vars
            .iter()
            .enumerate()
            .map(|(j, v)| if corner >> j & 1 == 1 { v.bounds().1 } else { v.bounds().0 })
            .collect();
        // A corner the configuration refuses is no design; the search records it as such.
        let Ok(mut config) = space::configure(evaluator.base, evaluator.vars, &x) else { continue };
        config.fidelity.decimation = evaluator.decimation;
        budget.check(&crate::engine::resources::run_demand(&config)).map_err(|e| {
            StudyError::Invalid(FieldError {
                field: "--vary".into(),
                message: format!("the design at {x:?} would not fit: {}: {}", e.field, e.message),
            })
        })?;
    }
    Ok(())
}

fn initial_count(settings: &Settings, nx: usize) -> usize {
    if settings.initial == 0 { 2 * nx + 1 } else { settings.initial }
}

/// Run a search: the start, then one suggested design per step until `settings.evaluations`;
/// `seen` is told of every evaluation (for progress) with the number done and the total.
pub fn search(
    evaluator: &Evaluator<'_>,
    settings: &Settings,
    control: &RunControl,
    seen: impl FnMut(&Evaluation, usize, usize),
) -> Result<Search, StudyError> {
    search_from(evaluator, settings, &[], control, seen)
}

/// [`search`] that takes designs already evaluated (`prior`, from shards' records, checked by
/// [`record::Record::check_matches`]) instead of running them again.
pub fn search_from(
    evaluator: &Evaluator<'_>,
    settings: &Settings,
    prior: &[Evaluation],
    control: &RunControl,
    mut seen: impl FnMut(&Evaluation, usize, usize),
) -> Result<Search, StudyError> {
    check(evaluator, settings)?;
    let mut engine = Engine::new();
    let confirms = settings.confirm_decimation.is_some_and(|d| d != settings.decimation);
    let total = settings.evaluations + if confirms { 3 } else { 0 };
    let mut evaluations: Vec<Evaluation> = Vec::new();
    let mut run = |x: &[f64], evaluations: &mut Vec<Evaluation>| -> Result<(), StudyError> {
        let e = match prior.iter().find(|e| same(&e.x, x)) {
            Some(done) => done.clone(),
            None => evaluator.evaluate(&mut engine, x, control)?,
        };
        seen(&e, evaluations.len() + 1, total);
        evaluations.push(e);
        Ok(())
    };
    let nx = evaluator.vars.len();
    let start = latin_hypercube(evaluator.vars, initial_count(settings, nx), settings.seed);
    if let Some(shard) = settings.shard {
        for x in start.iter().enumerate().filter(|(i, _)| shard.owns(*i)).map(|(_, x)| x) {
            run(x, &mut evaluations)?;
        }
        return Ok(Search {
            vars: evaluator.vars.to_vec(),
            evaluations,
            cheapest: None,
            closest: None,
            confirmed: Vec::new(),
            stopped_early: Some(format!("shard {}/{}: the start's designs only", shard.index, shard.count)),
            shard: true,
            optimiser_failures: Vec::new(),
        });
    }
    for x in start {
        run(&x, &mut evaluations)?;
    }
    let keys = constraint_keys(&evaluations);
    let xtypes: Vec<egobox_ego::XType> = evaluator.vars.iter().map(Dimension::xtype).collect();
    let mut step = 0u64;
    let mut stall = Stall { best: None, run: 0 };
    for e in &evaluations {
        stall.see(e.feasible().then_some(e.cost).flatten(), settings.stall_gain);
    }
    let mut stopped_early = None;
    let mut optimiser_failures = Vec::new();
    while evaluations.len() < settings.evaluations {
        if let Some(n) = settings.stall_after
            && stall.best.is_some()
            && stall.run >= n
        {
            stopped_early = Some(format!(
                "stopped after {} designs: {n} in a row made the cheapest feasible design less than {} % cheaper",
                evaluations.len(),
                100.0 * settings.stall_gain
            ));
            break;
        }
        step += 1;
        let suggested = suggest(&evaluations, &keys, &xtypes, settings.seed.wrapping_add(step)).unwrap_or_else(|why| {
            optimiser_failures.push((evaluations.len() + 1, why));
            None
        });
        let next = suggested.filter(|x| !evaluations.iter().any(|e| same(&e.x, x))).unwrap_or_else(|| {
            // The surrogate proposed a design already run (or could not be fitted): take a
            // fresh space-filling one instead, so every evaluation teaches something.
            latin_hypercube(evaluator.vars, 1, settings.seed.wrapping_add(1000 + step)).remove(0)
        });
        run(&next, &mut evaluations)?;
        if let Some(e) = evaluations.last() {
            stall.see(e.feasible().then_some(e.cost).flatten(), settings.stall_gain);
        }
    }
    let cheapest = cheapest_feasible(&evaluations);
    let closest = if cheapest.is_some() {
        None
    } else {
        (0..evaluations.len())
            .filter(|&i| evaluations[i].error.is_none())
            .min_by(|&a, &b| evaluations[a].worst().total_cmp(&evaluations[b].worst()))
    };
    let mut confirmed = Vec::new();
    // Confirmation at the search's own resolution would only repeat the search's runs.
    if let Some(d) = settings.confirm_decimation.filter(|&d| d != settings.decimation) {
        let confirm = Evaluator { decimation: d, ..*evaluator };
        let mut order: Vec<usize> = (0..evaluations.len()).filter(|&i| evaluations[i].feasible()).collect();
        order.sort_by(|&a, &b| {
            evaluations[a].cost.unwrap_or(f64::INFINITY).total_cmp(&evaluations[b].cost.unwrap_or(f64::INFINITY))
        });
        for &i in order.iter().take(3) {
            let e = confirm.evaluate(&mut engine, &evaluations[i].x, control)?;
            seen(&e, evaluations.len() + confirmed.len() + 1, total);
            let done = e.feasible();
            confirmed.push(e);
            if done {
                break;
            }
        }
    }
    Ok(Search {
        vars: evaluator.vars.to_vec(),
        evaluations,
        cheapest,
        closest,
        confirmed,
        stopped_early,
        shard: false,
        optimiser_failures,
    })
}

/// The items of `items` in the order first seen, each once.
pub fn unique<T: PartialEq>(items: impl IntoIterator<Item = T>) -> Vec<T> {
    let mut out = Vec::new();
    for item in items {
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

/// Every requirement key the evaluations report, in the order first seen.
#[must_use]
pub fn constraint_keys(evaluations: &[Evaluation]) -> Vec<String> {
    unique(evaluations.iter().flat_map(|e| e.constraints.iter().map(|(k, _)| k.clone())))
}

fn same(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-9 * x.abs().max(y.abs()).max(1e-12))
}

/// The cheapest feasible evaluation.
#[must_use]
pub fn cheapest_feasible(evaluations: &[Evaluation]) -> Option<usize> {
    (0..evaluations.len()).filter(|&i| evaluations[i].feasible()).min_by(|&a, &b| {
        evaluations[a].cost.unwrap_or(f64::INFINITY).total_cmp(&evaluations[b].cost.unwrap_or(f64::INFINITY))
    })
}

/// How far inside every limit the optimiser aims, as a share of the limit: egobox accepts a
/// modelled constraint within its tolerance, and a design proposed exactly on a limit (the
/// smear of the longest exposure allowed, say) lands just outside it as often as inside.
pub const AIM_INSIDE: f64 = 1e-3;

/// egobox's next design from the evaluations so far: rows [ln cost, g₁ + [`AIM_INSIDE`] …]
/// (a constraint a design did not report counts as failed by 1). `Ok(None)` when it proposes
/// none (too few designs with a cost), `Err` with its message when it panicked.
fn suggest(
    evaluations: &[Evaluation],
    keys: &[String],
    xtypes: &[egobox_ego::XType],
    seed: u64,
) -> Result<Option<Vec<f64>>, String> {
    use ndarray_egobox::Array2;
    let rows: Vec<&Evaluation> =
        evaluations.iter().filter(|e| e.error.is_none() && e.cost.is_some_and(|c| c > 0.0)).collect();
    if rows.len() < 2 {
        return Ok(None);
    }
    let nx = xtypes.len();
    let x = Array2::from_shape_fn((rows.len(), nx), |(i, j)| rows[i].x[j]);
    let y = Array2::from_shape_fn((rows.len(), 1 + keys.len()), |(i, j)| {
        if j == 0 {
            rows[i].cost.unwrap_or(1.0).ln()
        } else {
            rows[i].constraints.iter().find(|(k, _)| *k == keys[j - 1]).map_or(1.0, |(_, g)| *g) + AIM_INSIDE
        }
    });
    let xtypes = xtypes.to_vec();
    let n_cstr = keys.len();
    // egobox panics on a surrogate it cannot fit (all values equal, say); that is a step to
    // skip and report, not a run to lose.
    let result = std::panic::catch_unwind(move || {
        let service = egobox_ego::EgorServiceBuilder::optimize()
            .configure(|c| c.n_cstr(n_cstr).seed(seed))
            .min_within_mixint_space(&xtypes)
            .ok()?;
        let next = service.suggest(&x, &y);
        (next.nrows() > 0).then(|| next.row(0).to_vec())
    });
    match result {
        Ok(next) => Ok(next.filter(|x| x.iter().all(|v| v.is_finite()))),
        Err(panic) => Err(panic
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".into())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stall_counts_designs_that_do_not_cut_the_cheapest_feasible_cost() {
        let mut s = Stall { best: None, run: 0 };
        s.see(None, 0.001);
        assert_eq!(s.run, 1, "nothing feasible yet counts");
        s.see(Some(1.0), 0.001);
        assert_eq!((s.best, s.run), (Some(1.0), 0), "the first feasible design resets");
        s.see(Some(0.9995), 0.001);
        assert_eq!((s.best, s.run), (Some(0.9995), 1), "0.05 % cheaper is not progress");
        s.see(Some(0.99), 0.001);
        assert_eq!(s.run, 0, "0.95 % cheaper is");
        s.see(Some(2.0), 0.001);
        assert_eq!((s.best, s.run), (Some(0.99), 1));
        assert!((pass_probability_lower_bound(3, 0.95) - 0.368_403).abs() < 1e-6);
    }
}
