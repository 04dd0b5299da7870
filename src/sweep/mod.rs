//! Sweeps: a study re-run while one numeric parameter (or two, as a grid) varies, with several
//! Monte Carlo noise seeds per point — the curve a phase 0/A review asks for ("how big must the
//! aperture be for chl MAE ≤ 20 %?").
//!
//! Any numeric field of a run configuration can be swept by its path — `instrument.aperture_mm`,
//! `instrument.read_noise_e`, `instrument.adc_bits`, `scene.atmosphere.aot550`, … — so new
//! parameters need no code. The runs are numbered in a fixed order (point, instrument, seed);
//! `--shard i/n` runs every n-th of them and [`merge`] joins the shards' tables into the table
//! one unsharded run writes, byte for byte.
//!
//! ```text
//! SweepSpec(
//!     name: "aperture_lake_hume",
//!     study: Inline((name: "cubesat_lake_hume", scene: Preset("lake_hume_bloom"),
//!                    instruments: [Preset("cubesat")], retrievals: [Almi()])),
//!     parameters: [(path: "instrument.aperture_mm", values: Range(from: 40, to: 300, steps: 8, log: true))],
//!     seeds: [1, 2, 3, 4, 5],
//!     requirement: Some((variable: "chl_mg_m3", mae_pct: 20)),
//! )
//! ```

mod apply;
mod cost;
pub mod figure;
mod run;
mod table;

pub use apply::{apply, value};
pub use cost::{
    COST_METHOD, CostRow, ErrorOf, PerPixel, Setting, cheapest_within, cost_of_accuracy, fidelity_of, pareto_front,
    settings_for,
};
pub use figure::sweep_figure;
pub use run::{Job, SweepResult, empty_table, fnv1a, run_job, run_sweep};
pub use table::{Row, Table, merge};

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::engine::RunConfig;
use crate::parse::{FieldError, ParseError};
use crate::study::{Source, StudyError, StudySpec};

/// The values a parameter takes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Values {
    /// These values, in this order.
    List(Vec<f64>),
    /// `steps` values from `from` to `to` inclusive, evenly spaced (in log if `log`).
    Range {
        /// First value.
        from: f64,
        /// Last value.
        to: f64,
        /// Number of values (2 to 200).
        steps: usize,
        /// Spaced evenly in log10 (both ends must be positive).
        #[serde(default)]
        log: bool,
    },
}

impl Values {
    /// The values, checked (finite; a range has 2–200 steps and positive ends when `log`).
    pub fn resolve(&self, field: &str) -> Result<Vec<f64>, StudyError> {
        let bad = |message: String| StudyError::Invalid(FieldError { field: field.into(), message });
        let v = match self {
            Self::List(v) => {
                if v.is_empty() || v.len() > 200 {
                    return Err(bad(format!("{} values (allowed: 1 to 200)", v.len())));
                }
                v.clone()
            }
            &Self::Range { from, to, steps, log } => {
                if !(2..=200).contains(&steps) {
                    return Err(bad(format!("steps {steps} (allowed: 2 to 200)")));
                }
                if log && !(from > 0.0 && to > 0.0) {
                    return Err(bad(format!("a log range needs positive ends (got {from} to {to})")));
                }
                (0..steps)
                    .map(|i| {
                        let t = i as f64 / (steps - 1) as f64;
                        // The ends exactly as written (powf would give 40.000000000000014).
                        if i == 0 {
                            from
                        } else if i == steps - 1 {
                            to
                        } else if log {
                            10f64.powf(from.log10() + t * (to.log10() - from.log10()))
                        } else {
                            from + t * (to - from)
                        }
                    })
                    .collect()
            }
        };
        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
            return Err(bad(format!("value {x} is not a finite number")));
        }
        Ok(v)
    }
}

/// One swept parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Parameter {
    /// Path of a numeric field in the run configuration, e.g. `instrument.aperture_mm`.
    pub path: String,
    /// Its values.
    pub values: Values,
}

/// A requirement on a product's log-space MAE (percent), marked on the curves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Requirement {
    /// The variable (`chl_mg_m3`, `nap_g_m3`, `cdom_per_m`, `depth_m`).
    pub variable: String,
    /// The largest acceptable MAE, %.
    pub mae_pct: f64,
}

/// A sweep as written in RON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// Short name (file names).
    pub name: String,
    /// What it asks.
    #[serde(default)]
    pub description: String,
    /// The study whose runs are repeated at every point (its seeds are replaced by `seeds`).
    pub study: Source<StudySpec>,
    /// One parameter (a curve) or two (a grid).
    pub parameters: Vec<Parameter>,
    /// Monte Carlo noise seeds per point.
    #[serde(default = "default_seeds")]
    pub seeds: Vec<u64>,
    /// The requirement marked on the curves.
    #[serde(default)]
    pub requirement: Option<Requirement>,
}

fn default_seeds() -> Vec<u64> {
    vec![1, 2, 3]
}

/// A sweep with its study read and its points and runs laid out.
#[derive(Debug, Clone)]
pub struct ResolvedSweep {
    /// As written.
    pub spec: SweepSpec,
    /// The base run of each instrument (label, configuration), before any parameter is set.
    pub bases: Vec<(String, RunConfig)>,
    /// The values of each parameter.
    pub axes: Vec<Vec<f64>>,
    /// Every run, in the fixed order: point (first parameter slowest), instrument, seed.
    pub jobs: Vec<Job>,
}

impl SweepSpec {
    /// Parse RON; `origin` names the file in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Self, StudyError> {
        crate::parse::from_ron(text, origin)
    }

    /// A built-in sweep by name (`presets/sweeps/NAME.ron`).
    pub fn preset(name: &str) -> Result<Self, StudyError> {
        crate::parse::preset(name)
    }

    /// Names of the built-in sweeps.
    #[must_use]
    pub fn preset_names() -> Vec<String> {
        crate::parse::preset_names::<Self>()
    }

    /// Read the study (`dir`: the sweep file's directory), check every parameter against every
    /// instrument's configuration, and lay out the runs.
    pub fn resolve(&self, dir: Option<&Path>) -> Result<ResolvedSweep, StudyError> {
        if self.parameters.is_empty() || self.parameters.len() > 2 {
            return Err(StudyError::Invalid(FieldError {
                field: "parameters".into(),
                message: format!("{} (allowed: 1, or 2 for a grid)", self.parameters.len()),
            }));
        }
        if self.seeds.is_empty() || self.seeds.len() > 1000 {
            return Err(StudyError::Invalid(FieldError {
                field: "seeds".into(),
                message: format!("{} seeds (allowed: 1 to 1000)", self.seeds.len()),
            }));
        }
        if let Some(r) = &self.requirement
            && !(r.mae_pct > 0.0 && r.mae_pct.is_finite())
        {
            return Err(StudyError::Invalid(FieldError {
                field: "requirement.mae_pct".into(),
                message: format!("{} (allowed: a positive number of percent)", r.mae_pct),
            }));
        }
        let (mut study, study_dir) =
            crate::study::load(&self.study, dir, |n| StudySpec::preset(n).map_err(|e| e.to_string()), "study")?;
        study.seeds = vec![self.seeds[0]];
        let resolved = study.resolve(study_dir.as_deref())?;
        let bases: Vec<(String, RunConfig)> = resolved.runs.into_iter().map(|(label, _, c)| (label, c)).collect();
        let axes = self
            .parameters
            .iter()
            .enumerate()
            .map(|(i, p)| p.values.resolve(&format!("parameters[{i}].values")))
            .collect::<Result<Vec<_>, _>>()?;
        // Every parameter must name a number in every instrument's configuration.
        for (i, p) in self.parameters.iter().enumerate() {
            for (label, base) in &bases {
                apply(base, &[(p.path.as_str(), axes[i][0])]).map_err(|m| {
                    StudyError::Invalid(FieldError {
                        field: format!("parameters[{i}].path"),
                        message: format!("{label}: {m}"),
                    })
                })?;
            }
        }
        let points: Vec<Vec<f64>> = match axes.as_slice() {
            [a] => a.iter().map(|&x| vec![x]).collect(),
            [a, b] => a.iter().flat_map(|&x| b.iter().map(move |&y| vec![x, y])).collect(),
            _ => Vec::new(),
        };
        // Every point must make a valid configuration: refuse the sweep now, not after hours.
        let paths: Vec<&str> = self.parameters.iter().map(|p| p.path.as_str()).collect();
        for values in &points {
            let settings: Vec<(&str, f64)> = paths.iter().copied().zip(values.iter().copied()).collect();
            for (label, base) in &bases {
                let config = apply(base, &settings).map_err(|m| {
                    StudyError::Invalid(FieldError { field: "parameters".into(), message: format!("{label}: {m}") })
                })?;
                let checked = config
                    .instrument
                    .validate()
                    .map_err(|e| e.to_string())
                    .and_then(|()| config.scene.validate().map_err(|e| e.to_string()));
                checked.map_err(|e| {
                    StudyError::Invalid(FieldError {
                        field: "parameters".into(),
                        message: format!("{label} at {settings:?}: {e}"),
                    })
                })?;
            }
        }
        let mut jobs = Vec::new();
        for (point, values) in points.iter().enumerate() {
            for instrument in 0..bases.len() {
                for &seed in &self.seeds {
                    jobs.push(Job { index: jobs.len(), point, values: values.clone(), instrument, seed });
                }
            }
        }
        Ok(ResolvedSweep { spec: self.clone(), bases, axes, jobs })
    }
}

/// A shard `i/n`: the runs whose index is `i` modulo `n` (0 ≤ i < n).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This shard, 0-based.
    pub index: usize,
    /// Shards in all.
    pub count: usize,
}

impl Shard {
    /// Everything.
    pub const ALL: Self = Self { index: 0, count: 1 };

    /// Parse `i/n` (0-based `i`).
    pub fn parse(text: &str) -> Result<Self, String> {
        let (i, n) = text.split_once('/').ok_or_else(|| format!("shard `{text}`: expected i/n, e.g. 0/4"))?;
        let i: usize = i.trim().parse().map_err(|_| format!("shard `{text}`: `{i}` is not a number"))?;
        let n: usize = n.trim().parse().map_err(|_| format!("shard `{text}`: `{n}` is not a number"))?;
        if n == 0 || n > 100_000 || i >= n {
            return Err(format!("shard `{text}`: allowed 0 ≤ i < n ≤ 100000"));
        }
        Ok(Self { index: i, count: n })
    }

    /// Does this shard run job `index`?
    #[must_use]
    pub fn owns(&self, index: usize) -> bool {
        index % self.count == self.index
    }
}

impl crate::parse::Preset for SweepSpec {
    const FOLDER: &'static str = "sweeps";
    type Error = StudyError;
    fn parse_error(origin: &str, message: String) -> StudyError {
        StudyError::Parse(ParseError { origin: origin.into(), message })
    }
    fn unknown(name: &str, known: &[String]) -> StudyError {
        StudyError::Invalid(FieldError {
            field: "sweep".into(),
            message: format!("no built-in sweep `{name}` (known: {})", known.join(", ")),
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_log_range_keeps_its_ends_and_is_geometric() {
        let v = Values::Range { from: 40.0, to: 300.0, steps: 8, log: true }.resolve("v").unwrap();
        assert_eq!((v[0], v[7]), (40.0, 300.0));
        let ratio = (300.0f64 / 40.0).powf(1.0 / 7.0);
        for w in v.windows(2) {
            assert!((w[1] / w[0] - ratio).abs() < 1e-12);
        }
        let lin = Values::Range { from: 1.0, to: 2.0, steps: 3, log: false }.resolve("v").unwrap();
        assert_eq!(lin, vec![1.0, 1.5, 2.0]);
    }
}
