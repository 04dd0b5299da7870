//! The review pack: one self-contained HTML page (inline SVG figures, no network, no JavaScript)
//! that carries a study to a design review — what was compared, against which requirements,
//! with what margins, the maps and plots, and where every number came from.
//!
//! [`ReviewData`] is everything the page states, as plain data: `shoal study` writes it beside
//! its tables (`review.json`), so `shoal report RESULTS_DIR` rebuilds the page from a results
//! directory without rerunning, and `shoal report STUDY` runs the study and builds it at once.
//! [`html::page`] turns it and the study's figures into the page.

pub mod design_page;
pub mod html;
mod machine;
mod optics_rows;
mod pack;
mod seasons;
mod sections;
pub mod substrate;
pub mod svg;
mod verdicts;

use serde::{Deserialize, Serialize};

pub use machine::{Machine, commit, now_utc};
pub use optics_rows::focal_plane_summary;
pub use pack::{REVIEW_JSON, is_results_dir, load_results, review_json, write_pack};

use crate::engine::RunConfig;
use crate::study::{Check, ErrorBudget, StudyResult, StudyRun};
use crate::sweep::CostRow;

/// One row of the instruments' parameter table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParameterRow {
    /// Dotted field name (`detector.read_noise_e`).
    pub name: String,
    /// Per instrument, the value as written in its RON.
    pub values: Vec<String>,
}

impl ParameterRow {
    /// Do the instruments differ here?
    #[must_use]
    pub fn differs(&self) -> bool {
        self.values.windows(2).any(|w| w[0] != w[1])
    }
}

/// A derived figure of one instrument (GSD, f-number, smear…).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Derived {
    /// What it is.
    pub name: String,
    /// Per instrument, formatted with its unit.
    pub values: Vec<String>,
}

/// One instrument as the review sees it.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct InstrumentSummary {
    /// Label in the study.
    pub label: String,
    /// Its description.
    pub description: String,
    /// The resolved run configuration (RON), as `config.ron` holds it.
    pub config_ron: String,
    /// The run's stages: (stage, "ran" or "cached", seconds).
    pub stages: Vec<(String, String, f64)>,
    /// Whole run, s.
    pub total_seconds: f64,
    /// Image: lines × detectors × bands, and the decimation.
    pub shape: (usize, usize, usize, usize),
    /// Plausibility warnings (saturation, smear, f-number).
    pub warnings: Vec<String>,
    /// Per band: (band, centre nm, Q = λN/p, peak signal / full scale).
    pub feasibility: Vec<(String, f64, f64, f64)>,
}

/// One metrics row (over the noise seeds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MetricRow {
    /// Instrument.
    pub instrument: String,
    /// Retrieval.
    pub product: String,
    /// Variable.
    pub variable: String,
    /// Seeds.
    pub seeds: usize,
    /// Log-space MAE, %, mean over seeds.
    pub mae_pct: f64,
    /// Its standard deviation over seeds.
    pub mae_pct_sd: f64,
    /// Log-space bias, %, mean over seeds.
    pub bias_pct: f64,
    /// Share of candidate pixels returned, % (first seed).
    pub returned_pct: f64,
    /// Pixels compared (first seed).
    pub n: usize,
}

/// The aerosol an image-based correction found in one instrument's image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AerosolRow {
    /// Instrument.
    pub instrument: String,
    /// The run's aerosol summary (AOT, Ångström and their truths, per-pixel error, fit).
    pub found: crate::engine::AerosolSummary,
}

/// One requirement check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckRow {
    /// Instrument.
    pub instrument: String,
    /// Seed.
    pub seed: u64,
    /// What.
    pub what: String,
    /// Value (none: nothing to judge, which fails).
    pub value: Option<f64>,
    /// Limit.
    pub limit: f64,
    /// Met?
    pub pass: bool,
    /// Margin inside the limit (negative: outside).
    pub margin: Option<f64>,
}

impl From<&Check> for CheckRow {
    fn from(c: &Check) -> Self {
        Self {
            instrument: c.instrument.clone(),
            seed: c.seed,
            what: c.what.clone(),
            value: c.value,
            limit: c.limit,
            pass: c.pass,
            margin: c.margin,
        }
    }
}

/// An error-budget line: (instrument, variable, full MAE %, stage, sequential share, alone
/// share, floor MAE %), shares in points of %.
pub type BudgetRow = (String, String, f64, String, f64, f64, f64);

/// A cost-of-accuracy row: (setting, rounds, wall s median, wall range, CPU s median, vs
/// reference, per-pixel chl difference from the reference %: median, 95th percentile).
pub type CostTableRow = (String, usize, f64, (f64, f64), Option<f64>, String, Option<f64>, Option<f64>);

/// A data file the results were made from: (path, content, source, licence).
pub type DataSource = (String, String, String, String);

/// Everything the review pack states.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ReviewData {
    /// Study name.
    pub study: String,
    /// What it asks.
    pub study_description: String,
    /// Scene name.
    pub scene: String,
    /// Scene description.
    pub scene_description: String,
    /// Where the scene is (CRS), or "local frame".
    pub scene_place: String,
    /// When the results were made (UTC, ISO 8601).
    pub created_utc: String,
    /// Shoal's version.
    pub version: String,
    /// The git commit Shoal was built from.
    pub commit: String,
    /// The instruments in study order.
    pub instruments: Vec<InstrumentSummary>,
    /// Parameters side by side.
    pub parameters: Vec<ParameterRow>,
    /// Derived figures side by side.
    pub derived: Vec<Derived>,
    /// Requirement checks (empty: the study has none, or none applies).
    pub checks: Vec<CheckRow>,
    /// Does the study state requirements (even if none applies to what ran)?
    #[serde(default)]
    pub has_requirements: bool,
    /// The retrieval the product requirements judge (the study's first).
    #[serde(default)]
    pub judged_retrieval: String,
    /// Metrics with their spread over seeds.
    pub metrics: Vec<MetricRow>,
    /// The error budget, when run.
    pub budget: Vec<BudgetRow>,
    /// The cost-of-accuracy table, when run.
    pub cost: Vec<CostTableRow>,
    /// The data files read to make the results.
    pub data_sources: Vec<DataSource>,
    /// The machine.
    pub machine: Machine,
    /// The study file as resolved (RON).
    pub study_ron: String,
    /// The figures drawn with these results (file stems under `figures/`): the only ones a pack
    /// built from the results folder takes.
    #[serde(default)]
    pub figures: Vec<String>,
    /// Bottom type per instrument, when the retrieval unmixes substrates.
    #[serde(default)]
    pub substrates: Vec<substrate::SubstrateSummary>,
    /// The aerosol an image-based correction found, per instrument (first seed); empty with the
    /// exact correction (and in packs written before the section).
    #[serde(default)]
    pub aerosol: Vec<AerosolRow>,
    /// Retrievals whose program returned nothing: (instrument, retrieval, why), first seed.
    #[serde(default)]
    pub failures: Vec<(String, String, String)>,
    /// Seasons carried into the pack (`shoal report … --season DIR`): how often each design
    /// sees the site and its products' error over those looks.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub seasons: Vec<crate::season::summary::SeasonSummary>,
}

/// The instruments' parameters side by side: every field of each spec, in the first one's order.
fn parameter_rows(configs: &[&RunConfig]) -> Vec<ParameterRow> {
    // Each leaf by the path a sweep sets it by ([`crate::fields`]).
    let flat: Vec<Vec<(String, String)>> = configs
        .iter()
        .map(|c| crate::fields::flatten(&c.instrument).into_iter().map(|l| (l.path, l.text)).collect())
        .collect();
    let mut names: Vec<String> = Vec::new();
    for f in &flat {
        for (n, _) in f {
            if !names.contains(n) && n != "description" {
                names.push(n.clone());
            }
        }
    }
    names
        .into_iter()
        .map(|name| ParameterRow {
            values: flat
                .iter()
                .map(|f| f.iter().find(|(n, _)| *n == name).map_or_else(|| "–".into(), |(_, v)| v.clone()))
                .collect(),
            name,
        })
        .collect()
}

/// Figures derived from each design and its run.
fn derived_rows(runs: &[&StudyRun], configs: &[&RunConfig]) -> Vec<Derived> {
    let row = |name: &str, f: &dyn Fn(usize) -> String| Derived {
        name: name.into(),
        values: (0..runs.len()).map(f).collect(),
    };
    let budget_rows: Vec<Vec<(String, String)>> = runs.iter().map(|r| r.budget.rows()).collect();
    let budget = budget_rows.first().map_or(0, Vec::len);
    let mut rows = vec![
        row("nadir GSD", &|k| format!("{:.1} m", configs[k].instrument.as_flown().gsd_m())),
        row("swath", &|k| format!("{:.1} km", configs[k].instrument.as_flown().swath_m() / 1000.0)),
        row("f-number", &|k| format!("f/{:.2}", runs[k].feasibility.f_number)),
        row("along-track smear", &|k| format!("{:.2} px", runs[k].feasibility.smear_px)),
        row("read noise", &|k| format!("{:.1} e⁻", runs[k].feasibility.read_noise_e)),
        row("quantisation noise", &|k| format!("{:.1} e⁻", runs[k].feasibility.quantisation_noise_e)),
        row("line period", &|k| format!("{:.2} ms", runs[k].report.line_period_s * 1e3)),
        row("largest view zenith", &|k| format!("{:.1}°", runs[k].viewing.max_view_zenith_deg)),
        row("worst peak signal / full scale", &|k| {
            let worst = runs[k].feasibility.bands.iter().map(|b| b.peak_fraction_of_full_scale).fold(0.0, f64::max);
            format!("{:.0} %", 100.0 * worst)
        }),
        row("lowest SNR at the reference radiance", &|k| {
            runs[k]
                .snr
                .iter()
                .min_by(|a, b| a.snr_analytic.total_cmp(&b.snr_analytic))
                .map_or_else(|| "–".into(), |r| format!("{:.0} ({})", r.snr_analytic, r.band))
        }),
    ];
    // The design's budgets under the study's models (src/instrument/budgets).
    rows.extend((0..budget).map(|i| Derived {
        name: budget_rows[0][i].0.clone(),
        values: budget_rows.iter().map(|r| r[i].1.clone()).collect(),
    }));
    rows.extend(optics_rows::optics_rows(configs));
    rows
}

/// A design as the pack describes it: its parameters (true whatever was edited), then its file's
/// own words.
#[must_use]
pub fn describe(instrument: &crate::instrument::InstrumentSpec) -> String {
    let text = instrument.description.trim();
    if text.is_empty() { instrument.summary() } else { format!("{}. {text}", instrument.summary()) }
}

fn instrument_summary(run: &StudyRun, config: &RunConfig) -> InstrumentSummary {
    InstrumentSummary {
        label: run.label.clone(),
        description: describe(&config.instrument),
        config_ron: config.to_ron().unwrap_or_else(|e| format!("// cannot write the configuration: {e}")),
        stages: run
            .report
            .stages
            .iter()
            .map(|s| {
                let status = match s.status {
                    crate::engine::StageStatus::Ran => "ran",
                    crate::engine::StageStatus::Cached => "cached",
                };
                (format!("{:?}", s.stage), status.to_string(), s.seconds)
            })
            .collect(),
        total_seconds: run.report.total_seconds,
        shape: (run.report.shape.0, run.report.shape.1, run.report.shape.2, run.report.decimation),
        warnings: run.report.warnings.iter().map(|w| w.message.clone()).collect(),
        feasibility: run
            .feasibility
            .bands
            .iter()
            .map(|b| (b.band.clone(), b.centre_nm, b.q, b.peak_fraction_of_full_scale))
            .collect(),
    }
}

fn metric_rows(result: &StudyResult) -> Vec<MetricRow> {
    crate::study::seed_spread(result)
        .into_iter()
        .map(|s| {
            let first = result
                .runs
                .iter()
                .filter(|r| r.label == s.instrument)
                .flat_map(|r| r.retrievals.iter())
                .find(|r| r.metrics.product == s.product)
                .and_then(|r| r.metrics.get(&s.variable));
            MetricRow {
                returned_pct: first.map_or(0.0, |m| m.returned_pct),
                n: first.map_or(0, |m| m.n),
                instrument: s.instrument,
                product: s.product,
                variable: s.variable,
                seeds: s.seeds,
                mae_pct: s.mae_pct_mean,
                mae_pct_sd: s.mae_pct_std,
                bias_pct: s.bias_pct_mean,
            }
        })
        .collect()
}

fn budget_rows(budget: &[ErrorBudget]) -> Vec<BudgetRow> {
    budget
        .iter()
        .flat_map(|b| {
            b.lines.iter().map(move |l| {
                (
                    b.instrument.clone(),
                    b.variable.clone(),
                    b.full_pct,
                    l.stage.name().to_string(),
                    l.sequential_pct,
                    l.alone_pct,
                    b.floor_pct,
                )
            })
        })
        .collect()
}

fn cost_rows(cost: &[CostRow]) -> Vec<CostTableRow> {
    cost.iter()
        .enumerate()
        .map(|(i, r)| {
            let vs = match (i, r.cpu_comparison) {
                (0, _) => "–".to_string(),
                (_, Some(cpu)) => format!("{}; CPU {}", r.comparison.text(), cpu.text()),
                (_, None) => r.comparison.text(),
            };
            (
                r.label.clone(),
                r.time.n,
                r.time.wall_s,
                r.time.wall_range_s,
                r.time.cpu_s,
                vs,
                r.error_pct(crate::sweep::ErrorOf::Chl),
                r.errors.chl_p95_pct.filter(|v| v.is_finite()),
            )
        })
        .collect()
}

/// The data files read so far in this process, with their provenance rows (a row names its
/// files by path, later ones of a row by file name only).
fn data_sources() -> Vec<DataSource> {
    let used = crate::assets::used();
    crate::assets::provenance()
        .into_iter()
        .filter(|(files, ..)| used.iter().any(|u| files.contains(u.rsplit('/').next().unwrap_or(u))))
        .collect()
}

/// The review data of `result` (budget and cost rows when they were run).
#[must_use]
pub fn review_data(result: &StudyResult, budget: &[ErrorBudget], cost: &[CostRow]) -> ReviewData {
    let study = &result.study;
    // First seed of each instrument, in study order.
    let mut firsts: Vec<usize> = Vec::new();
    for (i, run) in result.runs.iter().enumerate() {
        if !firsts.iter().any(|&j| result.runs[j].label == run.label) {
            firsts.push(i);
        }
    }
    let configs: Vec<&RunConfig> = firsts.iter().map(|&i| &study.runs[i].2).collect();
    let runs: Vec<&StudyRun> = firsts.iter().map(|&i| &result.runs[i]).collect();
    let scene = configs.first().map(|c| &c.scene);
    ReviewData {
        study: study.spec.name.clone(),
        study_description: study.spec.description.clone(),
        scene: scene.map(|s| s.name.clone()).unwrap_or_default(),
        scene_description: scene.map(|s| s.description.clone()).unwrap_or_default(),
        scene_place: result.runs.first().and_then(|r| r.frame.as_ref()).map_or_else(
            || "a local frame (the scene has no georeference)".into(),
            |f| format!("{}, scene centre at {:.1} E, {:.1} N", f.crs.describe(), f.centre.0, f.centre.1),
        ),
        created_utc: now_utc(),
        version: env!("CARGO_PKG_VERSION").into(),
        commit: commit().into(),
        instruments: runs.iter().zip(&configs).map(|(r, c)| instrument_summary(r, c)).collect(),
        parameters: parameter_rows(&configs),
        derived: derived_rows(&runs, &configs),
        checks: study
            .spec
            .requirements
            .as_ref()
            .map(|r| r.check(result).iter().map(CheckRow::from).collect())
            .unwrap_or_default(),
        has_requirements: study.spec.requirements.is_some(),
        judged_retrieval: runs
            .first()
            .and_then(|r| r.retrievals.first())
            .map_or_else(String::new, |r| r.metrics.product.clone()),
        metrics: metric_rows(result),
        budget: budget_rows(budget),
        cost: cost_rows(cost),
        data_sources: data_sources(),
        machine: Machine::this(),
        study_ron: ron::ser::to_string_pretty(&study.spec, ron::ser::PrettyConfig::default().struct_names(true))
            .unwrap_or_default(),
        figures: Vec::new(),
        substrates: substrate::summaries(result),
        aerosol: runs
            .iter()
            .filter_map(|r| r.report.aerosol.clone().map(|found| AerosolRow { instrument: r.label.clone(), found }))
            .collect(),
        failures: runs
            .iter()
            .flat_map(|r| r.retrievals.iter().map(move |x| (r, x)))
            .filter_map(|(r, x)| x.failure.clone().map(|f| (r.label.clone(), x.metrics.product.clone(), f)))
            .collect(),
        seasons: Vec::new(),
    }
}

#[cfg(test)]
mod tests;
