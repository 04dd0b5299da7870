//! A season split over machines: `shoal season S --shard i/n` makes the chain runs of every n-th
//! pass (the designs in one orbit pass together, sharing their tables) and writes them to
//! `runs.ron`; `shoal season S --merge DIR…` joins the shards'
//! runs into the result one whole run gives, so its tables and figures are the same, byte for
//! byte.
//!
//! The looks themselves are not shipped: a shard and the merge each plan the season
//! ([`super::run::plan_season`]: the orbit, the looks and their spread over orbit phases, no
//! chain run; a third of a second for a year), and
//! a fingerprint of everything that decides the runs (the season and each design's
//! configuration) ties a shard's runs to that plan. What a shard file holds comes from another
//! machine and is checked before it is used: the fingerprint, each shard once, each run once and
//! owned by its shard, the run's design and look the plan's, its numbers finite and in range, its
//! names plain and its messages without control characters.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::run::{LookError, LookRun, SeasonPlan, SeasonResult};
use crate::engine::RunConfig;
use crate::parse::FieldError;
use crate::study::StudyError;
use crate::sweep::Shard;

/// The file a season run writes its chain runs to (a whole run is shard 0/1).
pub const RUNS_FILE: &str = "runs.ron";

/// The format tag of [`RUNS_FILE`]. Runs of another version are refused: version 2 draws each
/// look's cloud cover from its local month, so a version-1 run of the same look may have seen
/// other weather.
const FORMAT: &str = "shoal season runs 2";

/// The largest runs file read: a shard of 400 runs of 8 designs with 20 variables each is
/// under 2 MB.
const RUNS_MAX_BYTES: u64 = 64 << 20;

/// The longest failure message kept from a shard file.
const MAX_MESSAGE_CHARS: usize = 2_000;

/// One chain run as a shard writes it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JobRun {
    /// Index of the run in the plan's jobs.
    pub job: usize,
    /// The design's label.
    pub design: String,
    /// The look's index in the design's looks.
    pub look: usize,
    /// The look's time, days since J2000.0.
    pub days: f64,
    /// Every retrieval variable's error (empty when the run failed).
    pub errors: Vec<LookError>,
    /// Why the run failed, if it did.
    pub failure: Option<String>,
}

/// A shard's chain runs (`runs.ron`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardRuns {
    /// [`FORMAT`].
    pub format: String,
    /// The season's name.
    pub season: String,
    /// The plan's fingerprint ([`key`]).
    pub key: String,
    /// This shard, 0-based.
    pub index: usize,
    /// Shards in all.
    pub count: usize,
    /// Chain runs in the whole plan.
    pub jobs: usize,
    /// This shard's runs, in job order.
    pub runs: Vec<JobRun>,
}

/// The fingerprint of everything that decides a season's chain runs: the season as run and
/// each design's label and configuration (FNV-1a of their RON, the same on every machine).
#[must_use]
pub fn key(plan: &SeasonPlan, designs: &[(String, RunConfig)]) -> String {
    let mut text = ron::to_string(&plan.result.spec).unwrap_or_default();
    for (label, config) in designs {
        text.push_str(label);
        text.push_str(&config.to_ron().unwrap_or_default());
    }
    format!("{:016x}", crate::sweep::fnv1a(&text))
}

/// The runs of `result` (a shard's result from [`super::run::run_season`]) as its runs file.
#[must_use]
pub fn shard_runs(plan: &SeasonPlan, key: String, shard: Shard, result: &SeasonResult) -> ShardRuns {
    let mut runs: Vec<JobRun> = plan
        .owned(shard)
        .into_iter()
        .filter_map(|job| {
            let (d, k) = plan.jobs[job];
            let design = &result.designs[d];
            let run = design.runs.iter().find(|r| r.look == k)?;
            Some(JobRun {
                job,
                design: design.label.clone(),
                look: k,
                days: design.looks[k].access.days,
                errors: run.errors.clone(),
                failure: run.failure.clone(),
            })
        })
        .collect();
    runs.sort_by_key(|r| r.job);
    ShardRuns {
        format: FORMAT.into(),
        season: plan.result.spec.name.clone(),
        key,
        index: shard.index,
        count: shard.count,
        jobs: plan.jobs.len(),
        runs,
    }
}

/// The runs file's RON text.
#[must_use]
pub fn to_ron(runs: &ShardRuns) -> String {
    ron::ser::to_string_pretty(runs, ron::ser::PrettyConfig::default()).unwrap_or_default()
}

fn invalid(message: String) -> StudyError {
    StudyError::Invalid(FieldError { field: "merge".into(), message })
}

/// Read the runs file of the shard output directory `dir`.
pub fn read(dir: &Path) -> Result<ShardRuns, StudyError> {
    let path = dir.join(RUNS_FILE);
    let text = crate::infile::read_text(&path, RUNS_MAX_BYTES).map_err(|e| invalid(e.to_string()))?;
    let runs: ShardRuns = ron::from_str(&text).map_err(|e| {
        StudyError::Parse(crate::parse::ParseError {
            origin: path.display().to_string(),
            message: crate::parse::describe(&text, &e),
        })
    })?;
    if runs.format != FORMAT {
        return Err(invalid(format!("{}: format `{}` (expected `{FORMAT}`)", path.display(), runs.format)));
    }
    Ok(runs)
}

/// Is `text` a message that may be printed (no control characters, not too long)?
fn plain_message(text: &str) -> bool {
    text.chars().count() <= MAX_MESSAGE_CHARS && !text.chars().any(char::is_control)
}

/// Check one run of shard `part` (named `name` in messages) against the plan, whose runs'
/// passes are `passes` ([`SeasonPlan::passes`]).
fn check_run(
    plan: &SeasonPlan,
    passes: &[usize],
    name: &str,
    shard: Shard,
    run: &JobRun,
) -> Result<(usize, usize), StudyError> {
    let &(d, k) = plan
        .jobs
        .get(run.job)
        .ok_or_else(|| invalid(format!("{name}: run {} is outside the season's {} runs", run.job, plan.jobs.len())))?;
    if !shard.owns(passes[run.job]) {
        return Err(invalid(format!("{name}: run {} is not shard {}/{}'s", run.job, shard.index, shard.count)));
    }
    let design = &plan.result.designs[d];
    if run.design != design.label || run.look != k || run.days.to_bits() != design.looks[k].access.days.to_bits() {
        return Err(invalid(format!(
            "{name}: run {} is `{}`'s look {} at day {}, but this season's run {} is `{}`'s look {k}",
            run.job, run.design, run.look, run.days, run.job, design.label
        )));
    }
    for e in &run.errors {
        crate::parse::check_name("product", &e.product)
            .map_err(|f| invalid(format!("{name}: run {}: {f}", run.job)))?;
        crate::parse::check_name("variable", &e.variable)
            .map_err(|f| invalid(format!("{name}: run {}: {f}", run.job)))?;
        let numbers_ok = e.mae_pct.is_finite()
            && e.mae_pct >= 0.0
            && e.bias_pct.is_finite()
            && (0.0..=100.0).contains(&e.returned_pct);
        if !numbers_ok {
            return Err(invalid(format!(
                "{name}: run {}: {} {} has MAE {} %, bias {} %, returned {} % (allowed: MAE ≥ 0, bias finite, \
                 returned 0–100 %)",
                run.job, e.product, e.variable, e.mae_pct, e.bias_pct, e.returned_pct
            )));
        }
    }
    if run.failure.as_deref().is_some_and(|m| !plain_message(m)) {
        return Err(invalid(format!(
            "{name}: run {}: its failure message holds control characters or is over {MAX_MESSAGE_CHARS} characters",
            run.job
        )));
    }
    Ok((d, k))
}

/// Join the shards' runs (`parts`, each with the name used in messages) into `plan`'s result:
/// the result a whole run gives. Refused, naming the shard, when a part belongs to another
/// season or plan, a shard is missing or given twice, or a run is not the plan's.
pub fn merge(plan: &SeasonPlan, key: &str, parts: &[(String, ShardRuns)]) -> Result<SeasonResult, StudyError> {
    let (first_name, first) = parts.first().ok_or_else(|| invalid("no shards to merge".into()))?;
    let count = first.count;
    let mut seen: Vec<Option<&str>> = vec![None; count.min(100_000)];
    for (name, p) in parts {
        if p.key != key || p.jobs != plan.jobs.len() {
            return Err(invalid(format!(
                "{name} is a shard of another season or settings (`{}`, key {}, {} runs; this one: `{}`, key {key}, {} \
                 runs): merge with the season, period and options the shards ran with",
                p.season,
                p.key,
                p.jobs,
                plan.result.spec.name,
                plan.jobs.len()
            )));
        }
        if p.count != count {
            return Err(invalid(format!("{name} is shard {}/{} but {first_name} is one of {count}", p.index, p.count)));
        }
        let slot = seen.get_mut(p.index).ok_or_else(|| invalid(format!("{name}: shard {}/{}", p.index, p.count)))?;
        if let Some(other) = slot {
            return Err(invalid(format!("{name} and {other} are both shard {}/{count}", p.index)));
        }
        *slot = Some(name.as_str());
    }
    let missing: Vec<String> =
        seen.iter().enumerate().filter(|(_, s)| s.is_none()).map(|(i, _)| format!("{i}/{count}")).collect();
    if !missing.is_empty() {
        return Err(invalid(format!("shard {} not given (every shard of {count} is needed)", missing.join(", "))));
    }
    let mut result = plan.result.clone();
    let passes = plan.passes();
    let mut done = vec![false; plan.jobs.len()];
    for (name, p) in parts {
        let shard = Shard { index: p.index, count };
        for run in &p.runs {
            let (d, k) = check_run(plan, &passes, name, shard, run)?;
            if std::mem::replace(&mut done[run.job], true) {
                return Err(invalid(format!("{name}: run {} is given twice", run.job)));
            }
            result.designs[d].runs.push(LookRun { look: k, errors: run.errors.clone(), failure: run.failure.clone() });
        }
    }
    if let Some(j) = done.iter().position(|d| !d) {
        let (d, k) = plan.jobs[j];
        let ((y, m, day), _) = crate::orbit::sun::date_and_minute(plan.result.designs[d].looks[k].access.days);
        return Err(invalid(format!(
            "run {j} (`{}`'s look of {y:04}-{m:02}-{day:02}) is in no shard: shard {}/{count} did not finish it",
            plan.result.designs[d].label,
            passes[j] % count
        )));
    }
    for d in &mut result.designs {
        d.runs.sort_by_key(|r| r.look);
    }
    Ok(result)
}
