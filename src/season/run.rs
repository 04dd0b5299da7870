//! Running a season: each design's valid looks through the chain at their geometry, and what
//! the season reports per design.

use std::path::Path;

use rayon::prelude::*;

use super::looks::{Look, Verdict, half_field_of_view_rad, looks};
use super::{SeasonSpec, stats};
use crate::control::RunControl;
use crate::engine::{Engine, EngineError, RunConfig};
use crate::study::{StudyError, StudySpec};
use crate::sweep::Shard;

/// One product variable's error in one look's run.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LookError {
    /// Retrieval (aLMI, SAMBUCA, …).
    pub product: String,
    /// Variable (`chl_mg_m3`).
    pub variable: String,
    /// Log-space MAE, %.
    pub mae_pct: f64,
    /// Log-space bias, %.
    pub bias_pct: f64,
    /// Share returned, %.
    pub returned_pct: f64,
}

impl LookError {
    /// The MAE, % — `None` where the look returned no pixel (an empty set's MAE is not 0 %).
    #[must_use]
    pub fn returned_mae_pct(&self) -> Option<f64> {
        (self.returned_pct > 0.0).then_some(self.mae_pct)
    }
}

/// One valid look run through the chain.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LookRun {
    /// Index of the look in its design's [`DesignSeason::looks`].
    pub look: usize,
    /// Every retrieval variable's error (empty when the run failed).
    pub errors: Vec<LookError>,
    /// Why the run failed (a geometry the chain refuses, say), if it did.
    pub failure: Option<String>,
}

/// One design over the season.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignSeason {
    /// The design's label in the study.
    pub label: String,
    /// Altitude, km (on an element set, the spacecraft's at its first pass, to 0.1 km).
    pub altitude_km: f64,
    /// Half the across-track field of view, degrees.
    pub half_fov_deg: f64,
    /// Every pass over the site, in time order.
    pub looks: Vec<Look>,
    /// The valid looks run through the chain.
    pub runs: Vec<LookRun>,
    /// The same season at other orbit phases (which months a near-repeating orbit sees the
    /// site depends on where it was at the start, unknown before launch): per phase, degrees,
    /// the valid looks and the revisit share (% of days within the requirement's wait; `None`
    /// without a requirement). Empty on an element set, whose phase is known.
    pub phases: Vec<PhaseSample>,
}

/// One orbit phase's looks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseSample {
    /// Argument of latitude at the start, degrees.
    pub phase_deg: f64,
    /// Valid looks.
    pub valid: usize,
    /// Share of days within the revisit requirement's wait, % (`None` without a requirement).
    pub revisit_pct: Option<f64>,
}

/// Phases the spread is taken over.
pub const PHASE_SAMPLES: usize = 12;

impl DesignSeason {
    /// Times of the valid looks, days since J2000.0.
    #[must_use]
    pub fn valid_days(&self) -> Vec<f64> {
        self.looks.iter().filter(|l| l.verdict == Verdict::Valid).map(|l| l.access.days).collect()
    }

    /// The error of `variable` of `product` over the runs that returned it.
    #[must_use]
    pub fn errors_of(&self, product: &str, variable: &str) -> Vec<&LookError> {
        self.runs.iter().flat_map(|r| &r.errors).filter(|e| e.product == product && e.variable == variable).collect()
    }

    /// Median and 90th-percentile gap between valid looks, days.
    #[must_use]
    pub fn gap_percentiles(&self) -> (Option<f64>, Option<f64>) {
        let gaps = stats::gaps_days(&self.valid_days());
        (stats::percentile(&gaps, 50.0), stats::percentile(&gaps, 90.0))
    }
}

/// A season's result.
#[derive(Debug, Clone, PartialEq)]
pub struct SeasonResult {
    /// The season as written.
    pub spec: SeasonSpec,
    /// The study's name.
    pub study: String,
    /// The period, days since J2000.0 in UT (start, end): the site's local mean midnights
    /// ([`SeasonSpec::period_days`]).
    pub period: (f64, f64),
    /// Per design.
    pub designs: Vec<DesignSeason>,
}

/// The run configuration of `look` from a design's study configuration: the scene's sun and
/// date at the pass, the ground track's heading, the line of sight pointed across track at the
/// site's off-nadir angle and tilted as the look chose, at the season's decimation; the sea
/// wind-roughened at the look's wind with its sun glint on, the glint the look was judged on (a
/// valid look's glint is below the threshold, not zero: the correction takes away what it
/// expects, as a processor does, and the exact correction masks the pixels above the season's
/// threshold at the wind it assumes).
#[must_use]
pub fn look_config(base: &RunConfig, look: &Look, decimation: usize) -> RunConfig {
    let mut config = base.clone();
    let a = &look.access;
    config.scene.sun.zenith_deg = a.sun.zenith_rad.to_degrees();
    config.scene.sun.azimuth_deg = a.sun.azimuth_rad.to_degrees();
    let ((y, m, d), minutes) = crate::orbit::sun::date_and_minute(a.days);
    config.scene.date = format!("{y:04}-{m:02}-{d:02}");
    config.scene.time = format!("{:02}:{:02} UT", minutes / 60, minutes % 60);
    config.instrument.heading_deg = a.heading_rad.to_degrees();
    config.instrument.across_track_tilt_deg = a.off_nadir_rad.to_degrees();
    config.instrument.forward_tilt_deg = look.forward_tilt_deg;
    config.scene.atmosphere.surface = crate::atmosphere::SeaSurface::Wind { speed_m_s: look.wind_m_s };
    if !config.scene.effects.contains(&crate::scene::Effect::SunGlint) {
        config.scene.effects.push(crate::scene::Effect::SunGlint);
    }
    // The processor's glint from the wind it assumes (the look's draw of its error): the
    // image-based correction's own setting, or the exact correction's (the per-scene
    // approximation's terms come from the scene's pixels, glint and all). The exact correction
    // masks high glint at the season's threshold, as the look was judged (the image-based one
    // keeps its own threshold).
    match &mut config.correction.method {
        crate::correction::Method::Image(image) => image.glint_wind_error_m_s = look.processor_wind_error_m_s,
        crate::correction::Method::Exact => {
            config.correction.glint_wind_error_m_s = look.processor_wind_error_m_s;
            config.correction.glint_threshold_per_sr = Some(look.glint_threshold_per_sr);
        }
        crate::correction::Method::PerScene => {}
    }
    if let Some(h) = look.altitude_m {
        config.instrument.altitude_km = h / 1e3;
    }
    // The look's cloud cover as a cloud field in the scene (the scene's own layer's size, height
    // and thickness where it has one), made from the weather its cover was drawn from, so
    // designs in one orbit see the same clouds.
    config.scene.clouds = (look.cloud_cover > 0.0).then(|| crate::scene::CloudLayer {
        cover: look.cloud_cover,
        seed: look.weather_seed,
        ..base.scene.clouds.clone().unwrap_or_default()
    });
    config.fidelity.decimation = decimation;
    config
}

/// Up to `n` of `items`, evenly spaced (all when there are no more than `n`).
fn evenly<T: Copy>(items: &[T], n: usize) -> Vec<T> {
    if items.len() <= n {
        return items.to_vec();
    }
    (0..n).map(|k| items[(k * items.len() + items.len() / 2) / n.max(1)]).collect()
}

/// The study a season names, resolved: its name and one configuration per design (its first
/// seed), labelled as the study labels them.
pub fn designs(season: &SeasonSpec, dir: Option<&Path>) -> Result<(String, Vec<(String, RunConfig)>), StudyError> {
    let (study, study_dir) =
        crate::study::load(&season.study, dir, |n| StudySpec::preset(n).map_err(|e| e.to_string()), "study")?;
    let resolved = study.resolve(study_dir.as_deref().or(dir))?;
    let mut designs: Vec<(String, RunConfig)> = Vec::new();
    for (label, _, config) in &resolved.runs {
        if !designs.iter().any(|(l, _)| l == label) {
            designs.push((label.clone(), config.clone()));
        }
    }
    Ok((study.name, designs))
}

/// The study's product requirements as (variable, largest MAE %), for the figures.
pub fn mae_limits(season: &SeasonSpec, dir: Option<&Path>) -> Vec<(String, f64)> {
    crate::study::load(&season.study, dir, |n| StudySpec::preset(n).map_err(|e| e.to_string()), "study")
        .ok()
        .and_then(|(s, _)| s.requirements)
        .map(|r| r.products.iter().filter_map(|p| Some((p.variable.clone(), p.mae_pct?))).collect())
        .unwrap_or_default()
}

/// A season before its chain runs: every design's looks (and orbit phases), and the chain runs
/// to make, as (design, look) in the order they run.
#[derive(Debug, Clone)]
pub struct SeasonPlan {
    /// The result with no runs yet.
    pub result: SeasonResult,
    /// The chain runs: (index in `result.designs`, index in that design's looks), in time order
    /// across designs.
    pub jobs: Vec<(usize, usize)>,
}

impl SeasonPlan {
    /// The runs `shard` makes, as indices into [`Self::jobs`]. Runs are dealt to shards by the
    /// hour of their pass ([`Self::passes`]), so the designs in one orbit pass in the same
    /// shard, where the second reuses the first's scene and atmosphere tables: a shard `i/n`
    /// makes the passes whose count, in time order, is `i` modulo `n`.
    #[must_use]
    pub fn owned(&self, shard: Shard) -> Vec<usize> {
        self.passes().iter().enumerate().filter(|(_, pass)| shard.owns(**pass)).map(|(j, _)| j).collect()
    }

    /// Each run's pass, by which runs are dealt to shards: runs in the same hour share one,
    /// counted in time order from 0.
    #[must_use]
    pub fn passes(&self) -> Vec<usize> {
        let hour = |&(d, k): &(usize, usize)| (self.result.designs[d].looks[k].access.days * 24.0).floor();
        let mut pass = 0;
        let mut out = Vec::with_capacity(self.jobs.len());
        for (j, job) in self.jobs.iter().enumerate() {
            if j > 0 && hour(job) != hour(&self.jobs[j - 1]) {
                pass += 1;
            }
            out.push(pass);
        }
        out
    }
}

/// Find each design's looks over `season` (from [`designs`]; `study` names them), their spread
/// over orbit phases ([`phase_spread`]), and choose up to `max_runs` of each design's valid
/// looks, evenly spaced, for the chain. No chain run, so a shard and a merge each make the same
/// plan for themselves.
pub fn plan_season(
    season: &SeasonSpec,
    study: &str,
    designs: &[(String, RunConfig)],
) -> Result<SeasonPlan, StudyError> {
    let mut plan = plan_looks(season, study, designs)?;
    let spread = phase_spread(season, designs, plan.result.period, &RunControl::new())?;
    for (d, phases) in plan.result.designs.iter_mut().zip(spread) {
        d.phases = phases;
    }
    Ok(plan)
}

/// The wind a design's looks are judged on: its scene's where the sea is wind-roughened, else
/// the season's.
fn wind_of(season: &SeasonSpec, config: &RunConfig) -> f64 {
    match config.scene.atmosphere.surface {
        crate::atmosphere::SeaSurface::Wind { speed_m_s } => speed_m_s,
        crate::atmosphere::SeaSurface::Flat => season.wind_m_s,
    }
}

/// Each design's valid looks and revisit at [`PHASE_SAMPLES`] orbit phases (none on an element
/// set: the elements say where the spacecraft is). Thirteen times the looks' work: the app
/// shows the looks first and adds this after. Cancelled through `control` between phases.
pub fn phase_spread(
    season: &SeasonSpec,
    designs: &[(String, RunConfig)],
    period: (f64, f64),
    control: &RunControl,
) -> Result<Vec<Vec<PhaseSample>>, StudyError> {
    let phases = if season.orbit.tle.is_some() { 0 } else { PHASE_SAMPLES };
    designs
        .iter()
        .map(|(_, config)| {
            let wind = wind_of(season, config);
            (0..phases)
                .into_par_iter()
                .map(|k| {
                    // Each phase is a season's looks (a second on a year): a stop is heard
                    // between them.
                    if control.cancelled() {
                        return Err(StudyError::Cancelled);
                    }
                    let mut other = season.clone();
                    other.orbit.phase_deg = season.orbit.phase_deg + 360.0 * k as f64 / PHASE_SAMPLES as f64;
                    let valid: Vec<f64> =
                        looks(&other, &config.instrument, wind, config.scene.atmosphere.water_refractive_index)
                            .iter()
                            .filter(|l| l.verdict == Verdict::Valid)
                            .map(|l| l.access.days)
                            .collect();
                    Ok(PhaseSample {
                        phase_deg: other.orbit.phase_deg,
                        valid: valid.len(),
                        revisit_pct: season.revisit.map(|q| stats::revisit_pct(&valid, period.0, period.1, q.days)),
                    })
                })
                .collect()
        })
        .collect()
}

/// [`plan_season`] without the phase spread (each design's `phases` empty).
pub fn plan_looks(season: &SeasonSpec, study: &str, designs: &[(String, RunConfig)]) -> Result<SeasonPlan, StudyError> {
    season.validate().map_err(StudyError::Invalid)?;
    let period = season.period_days().map_err(StudyError::Invalid)?;
    let seasons: Vec<DesignSeason> = designs
        .iter()
        .map(|(label, config)| {
            let found = looks(
                season,
                &config.instrument,
                wind_of(season, config),
                config.scene.atmosphere.water_refractive_index,
            );
            DesignSeason {
                label: label.clone(),
                // On an element set, the spacecraft's altitude at its first pass.
                altitude_km: found
                    .first()
                    .and_then(|l| l.altitude_m)
                    .map_or(config.instrument.altitude_km, |h| (h / 1e3 * 10.0).round() / 10.0),
                half_fov_deg: half_field_of_view_rad(&config.instrument).to_degrees(),
                looks: found,
                runs: Vec::new(),
                phases: Vec::new(),
            }
        })
        .collect();
    let chosen: Vec<Vec<usize>> = seasons
        .iter()
        .map(|d| {
            let valid: Vec<usize> = (0..d.looks.len()).filter(|&k| d.looks[k].verdict == Verdict::Valid).collect();
            evenly(&valid, season.max_runs)
        })
        .collect();
    // Runs in time order across designs: designs in the same orbit pass together, and the
    // second reuses the first's scene and atmosphere tables from the engine's cache.
    let mut jobs: Vec<(usize, usize)> =
        chosen.iter().enumerate().flat_map(|(d, picks)| picks.iter().map(move |&k| (d, k))).collect();
    jobs.sort_by(|a, b| {
        seasons[a.0].looks[a.1].access.days.total_cmp(&seasons[b.0].looks[b.1].access.days).then(a.0.cmp(&b.0))
    });
    let result = SeasonResult { spec: season.clone(), study: study.to_string(), period, designs: seasons };
    Ok(SeasonPlan { result, jobs })
}

/// Plan `season` over `designs` ([`plan_season`]) and make every chain run ([`run_plan`]);
/// `progress(done, total)` after each run.
pub fn run_season(
    season: &SeasonSpec,
    study: &str,
    designs: &[(String, RunConfig)],
    shard: Shard,
    control: &RunControl,
    mut progress: impl FnMut(usize, usize),
) -> Result<SeasonResult, StudyError> {
    let plan = plan_season(season, study, designs)?;
    run_plan(&plan, designs, shard, control, |done, total, _, _| progress(done, total))
}

/// Make the chain runs of `plan` (over the `designs` it was planned for) that `shard` owns (all
/// of them for [`Shard::ALL`]), refused first if they would not fit the machine's budget.
/// `on_run(done, total, design, run)` after each run. A shard's result holds its own runs only;
/// [`super::shard::merge`] joins the shards' into the result one whole run gives.
pub fn run_plan(
    plan: &SeasonPlan,
    designs: &[(String, RunConfig)],
    shard: Shard,
    control: &RunControl,
    mut on_run: impl FnMut(usize, usize, usize, &LookRun),
) -> Result<SeasonResult, StudyError> {
    let jobs: Vec<(usize, usize)> = plan.owned(shard).into_iter().map(|j| plan.jobs[j]).collect();
    let mut result = plan.result.clone();
    let decimation = result.spec.decimation;
    within_budget(&jobs, designs, &result.designs, decimation)?;
    let total = jobs.len();
    let mut engine = Engine::lean();
    for (done, &(d, k)) in jobs.iter().enumerate() {
        let run = run_look(&mut engine, &designs[d].1, &result.designs[d].looks[k], k, decimation, control)?;
        on_run(done + 1, total, d, &run);
        result.designs[d].runs.push(run);
    }
    for d in &mut result.designs {
        d.runs.sort_by_key(|r| r.look);
    }
    Ok(result)
}

/// Run look `k` of a design (its configuration `base`) through the chain on `engine` at the
/// look's geometry ([`look_config`]): every retrieval variable's error, or why the run failed.
/// Only a cancel is an error.
fn run_look(
    engine: &mut Engine,
    base: &RunConfig,
    look: &Look,
    k: usize,
    decimation: usize,
    control: &RunControl,
) -> Result<LookRun, StudyError> {
    let config = look_config(base, look, decimation);
    Ok(match engine.run_with(&config, control, &[]) {
        Ok(out) => LookRun {
            look: k,
            errors: out
                .retrievals
                .iter()
                .flat_map(|r| {
                    r.metrics.variables.iter().map(|v| LookError {
                        product: r.metrics.product.clone(),
                        variable: v.variable.clone(),
                        mae_pct: v.metrics.mae_pct(),
                        bias_pct: v.metrics.bias_pct(),
                        returned_pct: v.metrics.returned_pct,
                    })
                })
                .collect(),
            failure: None,
        },
        Err(EngineError::Cancelled) => return Err(StudyError::Cancelled),
        Err(e) => LookRun { look: k, errors: Vec::new(), failure: Some(e.to_string()) },
    })
}

/// Refuse a season whose chain runs would not fit the machine's budget
/// ([`crate::budget::MachineBudget`]) before any runs: each look's memory as one run's, and the
/// radiative transfer of every look together (each look has its own sun, so its own tables; a
/// second design in the same orbit may reuse the first's, so this is an upper bound).
fn within_budget(
    jobs: &[(usize, usize)],
    designs: &[(String, RunConfig)],
    seasons: &[DesignSeason],
    decimation: usize,
) -> Result<(), StudyError> {
    let budget = crate::budget::MachineBudget::from_env()
        .map_err(|message| StudyError::Invalid(crate::parse::FieldError { field: "budget".into(), message }))?;
    let mut seconds = 0.0;
    for &(d, k) in jobs {
        let demand =
            crate::engine::resources::run_demand(&look_config(&designs[d].1, &seasons[d].looks[k], decimation));
        seconds += demand.atmosphere_s;
        budget
            .check(&crate::budget::Demand { atmosphere_s: 0.0, ..demand })
            .map_err(|e| StudyError::Invalid(crate::parse::FieldError { field: e.field, message: e.message }))?;
    }
    if seconds > budget.atmosphere_s {
        return Err(StudyError::Invalid(crate::parse::FieldError {
            field: "max_runs".into(),
            message: format!(
                "the season's {} chain runs would spend about {seconds:.0} s in radiative transfer (each look has its \
                 own sun) but may take {:.0} s (SHOAL_TIME_BUDGET_S); lower max_runs or shorten the period, or raise \
                 the budget",
                jobs.len(),
                budget.atmosphere_s
            ),
        }));
    }
    Ok(())
}

impl SeasonResult {
    /// Whether `design` meets the revisit requirement, with its share of days, %.
    #[must_use]
    pub fn revisit(&self, design: &DesignSeason) -> Option<(f64, bool)> {
        let q = self.spec.revisit?;
        let pct = stats::revisit_pct(&design.valid_days(), self.period.0, self.period.1, q.days);
        Some((pct, pct >= q.pct))
    }
}
