//! Trade-off windows. **Sweep**: one instrument parameter of every design over a range with several
//! noise seeds; the chl MAE curve of each instrument grows point by point, with the seeds' range,
//! the requirement and where it is first met. **Cost**: every fidelity setting's time against its
//! error from the full-fidelity run (`sweep::cost`), to pick the cheapest setting whose error is
//! acceptable. **Design**: the cheapest design from A that meets the requirements
//! (`crate::design`), with its cost–error plot and a click to put a design into A or beside the others.
//!
//! **Season**: the designs flown over a site for a period (`crate::season`), how often they
//! see it and their products' error over those looks.
//!
//! All run on a helper thread (not the engine thread, whose pool serves the maps) and stream
//! their results; a new run or closing the window cancels the old one.

use super::model::AppState;
use crate::engine::{Engine, Fidelity, RunConfig};
use crate::jobs::{Task, TaskNews};
use crate::study::{Source, StudySpec};
use crate::sweep::{
    CostRow, ErrorOf, Parameter, Requirement, Row, SweepSpec, Table, Values, cost_of_accuracy, empty_table, run_job,
};

/// The windows' state (not persisted: results belong to the session).
pub struct Explore {
    /// Is the sweep window open?
    pub sweep_open: bool,
    /// Is the cost window open?
    pub cost_open: bool,
    /// Is the design window open?
    pub design_open: bool,
    /// The design search's settings and results.
    pub design: design::DesignState,
    /// The season's settings and results (its window's open flag inside).
    pub season: season::SeasonState,
    /// The swept field's path in the run configuration (`instrument.aperture_mm`).
    param: String,
    /// A second parameter and its span (a curve per value), if any.
    second: Option<(String, f64, f64)>,
    /// The product whose MAE the curves show.
    variable: String,
    /// The MAE on a log axis.
    log_y: bool,
    /// The requirement on `variable` in use.
    requirement: Option<Requirement>,
    from: f64,
    to: f64,
    steps: usize,
    log: bool,
    seeds: u64,
    decimation: usize,
    sweep_task: Option<Task<Vec<Row>>>,
    table: Option<Table>,
    sweep_total: usize,
    sweep_status: String,
    /// The sweep's instrument names (file-safe: "C search 2") and the design list's ("C: search 2").
    sweep_names: Vec<(String, String)>,
    cost_decimation: usize,
    cost_task: Option<Task<(usize, CostRow)>>,
    /// Rounds of the cost measurement (each setting timed once per round, interleaved).
    cost_rounds: usize,
    /// The product whose error the plot, the front and the tolerance read.
    cost_error_of: ErrorOf,
    /// The error the cheapest acceptable setting may make, %.
    cost_tolerance_pct: f64,
    cost_rows: Vec<CostRow>,
    /// Instrument A's configuration the cost rows were measured for (to mark them stale).
    cost_config: Option<RunConfig>,
    cost_status: String,
}

impl Default for Explore {
    fn default() -> Self {
        Self {
            sweep_open: false,
            cost_open: false,
            design_open: false,
            design: design::DesignState::default(),
            season: season::SeasonState::default(),
            param: "instrument.aperture_mm".into(),
            second: None,
            variable: "chl_mg_m3".into(),
            log_y: true,
            requirement: None,
            from: 40.0,
            to: 300.0,
            steps: 6,
            log: true,
            seeds: 3,
            decimation: 8,
            sweep_task: None,
            table: None,
            sweep_total: 0,
            sweep_status: String::new(),
            sweep_names: Vec::new(),
            cost_decimation: 4,
            cost_task: None,
            cost_rounds: 5,
            cost_error_of: ErrorOf::Chl,
            cost_tolerance_pct: 1.0,
            cost_rows: Vec::new(),
            cost_config: None,
            cost_status: String::new(),
        }
    }
}

impl Explore {
    /// Is a helper thread working?
    #[must_use]
    pub fn busy(&self) -> bool {
        self.sweep_task.is_some() || self.cost_task.is_some() || self.design.busy() || self.season.busy()
    }

    /// Rows of the sweep so far.
    #[must_use]
    pub fn sweep_rows(&self) -> usize {
        self.table.as_ref().map_or(0, |t| t.rows.len())
    }

    /// A sweep series' label as the design list names its design ("C search 2, …" → "C: search
    /// 2, …").
    #[must_use]
    pub fn shown_label(&self, label: &str) -> String {
        self.sweep_names
            .iter()
            .find_map(|(safe, shown)| {
                label
                    .strip_prefix(safe.as_str())
                    .filter(|r| r.is_empty() || r.starts_with(", "))
                    .map(|r| format!("{shown}{r}"))
            })
            .unwrap_or_else(|| label.to_string())
    }

    /// The sweep's last status line ("running 12 runs at 1/24", or why it stopped).
    #[must_use]
    pub fn sweep_status(&self) -> &str {
        &self.sweep_status
    }

    /// Take what the helper threads sent.
    pub fn poll(&mut self) {
        // Closing the window, by its cross or the top bar's toggle, stops its search.
        if !self.design_open {
            self.design.cancel();
        }
        self.design.poll();
        self.season.poll();
        if let Some(task) = &self.sweep_task {
            let mut finished = None;
            while let Some(msg) = task.poll() {
                match msg {
                    TaskNews::Item(rows) => {
                        if let Some(t) = &mut self.table {
                            t.rows.extend(rows);
                        }
                    }
                    TaskNews::Done(r) => finished = Some(r),
                }
            }
            if let Some(r) = finished {
                self.sweep_status = match r {
                    Ok(()) => format!("done: {} runs", self.sweep_total),
                    Err(e) => e,
                };
                self.sweep_task = None;
            }
        }
        if let Some(task) = &self.cost_task {
            let mut finished = None;
            while let Some(msg) = task.poll() {
                match msg {
                    TaskNews::Item((round, row)) => {
                        self.cost_status = format!("round {} of {}: {}", round + 1, self.cost_rounds, row.label);
                        match self.cost_rows.iter_mut().find(|r| r.label == row.label) {
                            Some(r) => *r = row,
                            None => self.cost_rows.push(row),
                        }
                    }
                    TaskNews::Done(r) => finished = Some(r),
                }
            }
            if let Some(r) = finished {
                self.cost_status = match r {
                    Ok(()) => format!("done: {} settings × {} rounds", self.cost_rows.len(), self.cost_rounds),
                    Err(e) => e,
                };
                self.cost_task = None;
            }
        }
    }

    /// Start the sweep of the chosen parameter (and the second, when set) over the designs as they
    /// are now.
    pub fn start_sweep(&mut self, ctx: &egui::Context, state: &AppState) {
        let whole = |path: &str| crate::ranges::ALL.iter().any(|r| r.path == path && r.whole);
        // Whole-number fields take whole values (a list), the rest a range.
        let values = |path: &str, from: f64, to: f64, steps: usize, log: bool| {
            if whole(path) {
                let mut v: Vec<f64> =
                    (0..steps).map(|i| (from + (to - from) * i as f64 / (steps.max(2) - 1) as f64).round()).collect();
                v.dedup();
                Values::List(v)
            } else {
                Values::Range { from, to, steps, log: log && from > 0.0 }
            }
        };
        let mut parameters = vec![Parameter {
            path: self.param.clone(),
            values: values(&self.param, self.from, self.to, self.steps, self.log),
        }];
        if let Some((path, a, b)) = &self.second {
            parameters.push(Parameter { path: path.clone(), values: values(path, *a, *b, 3, false) });
        }
        let key = self.param.rsplit('.').next().unwrap_or("parameter").to_string();
        self.sweep_names = (0..state.designs.len()).map(|i| (sweep_name(state, i), state.design_name(i))).collect();
        let study = StudySpec {
            name: "app".into(),
            description: String::new(),
            scene: Source::Inline(Box::new(state.seeded_scene())),
            // Each named by its letter and preset ("C cubesat": an instrument's name must be
            // file-safe); the plot shows the design list's name ("C: cubesat").
            instruments: (0..state.designs.len())
                .map(|i| {
                    let mut spec = state.designs[i].spec.clone();
                    spec.name = sweep_name(state, i);
                    Source::Inline(Box::new(spec))
                })
                .collect(),
            retrievals: vec![state.retrieval_spec()],
            seeds: vec![1],
            detector: None,
            calibration: None,
            correction: None,
            fidelity: Some(state.fidelity.clone()),
            requirements: None,
            snr_reference: state.snr_reference.clone(),
            budgets: None,
        };
        let spec = SweepSpec {
            name: format!("app_{key}"),
            description: String::new(),
            study: Source::Inline(Box::new(study)),
            parameters,
            seeds: (1..=self.seeds).collect(),
            requirement: sweep::requirement(state, &self.variable),
        };
        let mut sweep = match spec.resolve(None) {
            Ok(s) => s,
            Err(e) => {
                self.sweep_status = e.to_string();
                return;
            }
        };
        for (_, c) in &mut sweep.bases {
            c.fidelity.decimation = self.decimation;
        }
        self.table = Some(empty_table(&sweep, crate::sweep::Shard::ALL));
        self.sweep_total = sweep.jobs.len();
        self.sweep_status = format!("running {} runs at 1/{}", sweep.jobs.len(), self.decimation);
        let wake = ctx.clone();
        let task = Task::spawn(
            "shoal-explore",
            move || wake.request_repaint(),
            move |control, send| {
                let mut engine = Engine::new();
                for job in &sweep.jobs {
                    let (rows, _) = run_job(&mut engine, &sweep, job, control).map_err(|e| e.to_string())?;
                    send(rows);
                }
                Ok(())
            },
        );
        match task {
            Ok(t) => self.sweep_task = Some(t),
            Err(e) => self.sweep_status = e,
        }
    }

    /// Start measuring the cost of accuracy for instrument A at 1/`cost_decimation`.
    pub fn start_cost(&mut self, ctx: &egui::Context, config: RunConfig) {
        // The reference is full fidelity, whatever the app runs with now: the table prices each
        // setting against it, and a setting applied from it does not become the next table's
        // reference.
        let mut base = at_full_fidelity(config);
        self.cost_config = Some(base.clone());
        base.fidelity.decimation = self.cost_decimation;
        self.cost_rows.clear();
        self.cost_status = format!("measuring at 1/{} …", self.cost_decimation);
        let rounds = self.cost_rounds;
        let wake = ctx.clone();
        let task = Task::spawn(
            "shoal-explore",
            move || wake.request_repaint(),
            move |control, send| {
                cost_of_accuracy(&base, rounds, control, |round, row| send((round, row.clone())))
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            },
        );
        match task {
            Ok(t) => self.cost_task = Some(t),
            Err(e) => self.cost_status = e,
        }
    }
}

/// The trade-off windows that are open.
pub fn windows(app: &mut super::ShoalApp, ctx: &egui::Context) {
    if app.ui.explore.sweep_open {
        sweep_window(app, ctx);
    }
    if app.ui.explore.cost_open {
        cost_window(app, ctx);
    }
    if app.ui.explore.design_open {
        design_window(app, ctx);
    }
    if app.ui.explore.season.open {
        season_window(app, ctx);
    }
}

/// `config` at full fidelity (its decimation kept).
fn at_full_fidelity(mut config: RunConfig) -> RunConfig {
    config.fidelity = Fidelity { decimation: config.fidelity.decimation, ..Fidelity::full() };
    config
}

/// The fields of `f` that differ from the defaults ("defaults" when none does).
fn fidelity_text(f: &Fidelity) -> String {
    let d = Fidelity::default();
    let mut parts = Vec::new();
    if f.band_nodes != d.band_nodes {
        parts.push(if f.band_nodes == 0 {
            "water spectra on the full grid".to_string()
        } else {
            format!("band nodes {} per band", f.band_nodes)
        });
    }
    if f.water_single_precision != d.water_single_precision {
        parts.push(
            if f.water_single_precision {
                "water kernel in single precision"
            } else {
                "water kernel in double precision"
            }
            .to_string(),
        );
    }
    if f.spectral_step_nm != d.spectral_step_nm {
        parts.push(format!("spectral step {} nm", f.spectral_step_nm));
    }
    if f.lut_wavelength_step_nm != d.lut_wavelength_step_nm {
        parts.push(format!("LUT wavelength nodes {} nm", f.lut_wavelength_step_nm));
    }
    if f.lut_view_step_deg != d.lut_view_step_deg {
        parts.push(format!("LUT view nodes {}°", f.lut_view_step_deg));
    }
    if f.spatial_samples_per_gsd != d.spatial_samples_per_gsd {
        parts.push(format!("{} spatial samples per GSD", f.spatial_samples_per_gsd));
    }
    if f.snr_frames != d.snr_frames || f.snr_detectors != d.snr_detectors {
        parts.push(format!("SNR patch {} frames × {} detectors", f.snr_frames, f.snr_detectors));
    }
    if parts.is_empty() {
        format!("the default fidelity (band nodes {} per band)", d.band_nodes)
    } else {
        parts.join(", ")
    }
}

/// Design `i`'s instrument name in a sweep: its letter and preset ("C cubesat"), within the 64
/// characters an instrument's (file-safe) name may have.
fn sweep_name(state: &AppState, i: usize) -> String {
    let preset: String = state.designs[i].preset.chars().take(60).collect();
    format!("{} {}", super::model::label(i), preset.trim())
}

mod cost;
pub use cost::cost_window;
mod design;
pub use design::design_window;
mod season;
pub use season::season_window;
mod sweep;
pub use sweep::sweep_window;

#[cfg(test)]
mod tests;
