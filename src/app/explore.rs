//! Trade-off windows. **Sweep**: one instrument parameter of A and B over a range with several
//! noise seeds; the chl MAE curve of each instrument grows point by point, with the seeds' range,
//! the requirement and where it is first met. **Cost**: every fidelity setting's time against its
//! error from the full-fidelity run (`sweep::cost`), to pick the cheapest setting whose error is
//! acceptable.
//!
//! Both run on a helper thread (not the engine thread, whose pool serves the maps) and stream
//! their results; a new run or closing the window cancels the old one.

use egui_plot::{HLine, Legend, Line, Plot, PlotPoints, Points};

use super::model::AppState;
use crate::engine::{Engine, Fidelity, RunConfig};
use crate::jobs::{Task, TaskNews};
use crate::study::{Source, StudySpec};
use crate::sweep::{
    CostRow, Parameter, Requirement, Row, SweepSpec, Table, Values, cost_of_accuracy, empty_table, run_job,
};

/// Parameters the sweep window offers: (label, path below `instrument.`, unit, default range).
const SWEEPABLE: [(&str, &str, &str, f64, f64); 8] = [
    ("Aperture", "aperture_mm", "mm", 40.0, 300.0),
    ("Exposure", "exposure_s", "s", 0.0005, 0.005),
    ("Read noise", "read_noise_e", "e⁻", 1.0, 80.0),
    ("Well depth", "well_depth_e", "e⁻", 10_000.0, 400_000.0),
    ("Gain", "gain_e_per_dn", "e⁻/DN", 0.5, 20.0),
    ("Optical transmission", "optical_transmission", "", 0.3, 1.0),
    ("Focal length", "focal_length_mm", "mm", 80.0, 400.0),
    ("Altitude", "altitude_km", "km", 400.0, 800.0),
];

/// The windows' state (not persisted: results belong to the session).
pub struct Explore {
    /// Is the sweep window open?
    pub sweep_open: bool,
    /// Is the cost window open?
    pub cost_open: bool,
    param: usize,
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
    cost_decimation: usize,
    cost_task: Option<Task<(usize, CostRow)>>,
    /// Rounds of the cost measurement (each setting timed once per round, interleaved).
    cost_rounds: usize,
    /// The chl error the cheapest acceptable setting may make, %.
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
            param: 0,
            from: SWEEPABLE[0].3,
            to: SWEEPABLE[0].4,
            steps: 6,
            log: true,
            seeds: 3,
            decimation: 8,
            sweep_task: None,
            table: None,
            sweep_total: 0,
            sweep_status: String::new(),
            cost_decimation: 4,
            cost_task: None,
            cost_rounds: 3,
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
        self.sweep_task.is_some() || self.cost_task.is_some()
    }

    /// Rows of the sweep so far.
    #[must_use]
    pub fn sweep_rows(&self) -> usize {
        self.table.as_ref().map_or(0, |t| t.rows.len())
    }

    /// Take what the helper threads sent.
    pub fn poll(&mut self) {
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

    /// Start the sweep of the chosen parameter over A and B as they are now.
    pub fn start_sweep(&mut self, ctx: &egui::Context, state: &AppState) {
        let (_, key, _, _, _) = SWEEPABLE[self.param];
        let study = StudySpec {
            name: "app".into(),
            description: String::new(),
            scene: Source::Inline(Box::new(state.seeded_scene())),
            instruments: vec![
                Source::Inline(Box::new(state.a.spec.clone())),
                Source::Inline(Box::new(state.b.spec.clone())),
            ],
            retrievals: vec![state.retrieval_spec()],
            seeds: vec![1],
            detector: None,
            calibration: None,
            correction: None,
            fidelity: Some(state.fidelity.clone()),
            requirements: None,
        };
        let spec = SweepSpec {
            name: format!("app_{key}"),
            description: String::new(),
            study: Source::Inline(Box::new(study)),
            parameters: vec![Parameter {
                path: format!("instrument.{key}"),
                values: Values::Range { from: self.from, to: self.to, steps: self.steps, log: self.log },
            }],
            seeds: (1..=self.seeds).collect(),
            requirement: chl_requirement(state),
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

/// The sweep's chl MAE curves (A solid, B dashed, seed range faint) against the swept parameter
/// over its range, on a log axis for a log sweep.
fn sweep_plot(
    ui: &mut egui::Ui,
    curves: &crate::study::Curves,
    requirement: Option<&Requirement>,
    x_label: &str,
    log: bool,
    range: (f64, f64),
) {
    let x_of = move |x: f64| if log { x.log10() } else { x };
    let x_label = x_label.to_string();
    let (from, to) = (x_of(range.0), x_of(range.1));
    Plot::new("sweep-plot")
        .legend(Legend::default().position(egui_plot::Corner::RightTop))
        .x_axis_label(if log { format!("{x_label}, log scale") } else { x_label })
        .y_axis_label("chl log-space MAE (%)")
        // The axes from the sweep's range, not egui's −100…100 before the first point.
        .include_x(from.min(to))
        .include_x(from.max(to))
        .include_y(0.0)
        .x_axis_formatter(move |mark, _| {
            crate::colormap::significant(if log { 10f64.powf(mark.value) } else { mark.value }, 3)
        })
        .show(ui, |p| {
            for (k, s) in curves.series.iter().enumerate() {
                let colour = super::theme::INSTRUMENT.get(k).copied().unwrap_or_else(|| super::theme::category(k));
                // B dashed over A: identical instruments stay visible as two curves.
                let style = if k == 0 { egui_plot::LineStyle::Solid } else { egui_plot::LineStyle::dashed_loose() };
                p.line(
                    Line::new(s.label.clone(), PlotPoints::from_iter(s.points.iter().map(|q| [x_of(q.x), q.mean])))
                        .color(colour)
                        .style(style)
                        .width(2.0),
                );
                p.line(
                    Line::new(
                        format!("{} lowest seed", s.label),
                        PlotPoints::from_iter(s.points.iter().map(|q| [x_of(q.x), q.lo])),
                    )
                    .color(colour.gamma_multiply(0.4)),
                );
                p.line(
                    Line::new(
                        format!("{} highest seed", s.label),
                        PlotPoints::from_iter(s.points.iter().map(|q| [x_of(q.x), q.hi])),
                    )
                    .color(colour.gamma_multiply(0.4)),
                );
                if let (Some(r), Some(x)) = (requirement, s.crossing) {
                    p.points(
                        Points::new(format!("{} meets", s.label), vec![[x_of(x), r.mae_pct]]).radius(6.0).color(colour),
                    );
                }
            }
            if let Some(r) = requirement {
                p.hline(HLine::new("requirement", r.mae_pct).color(super::theme::PASS));
            }
        });
}

fn labelled_drag(ui: &mut egui::Ui, label: &str, value: &mut f64, speed: f64) {
    let l = ui.label(label);
    ui.add(egui::DragValue::new(value).update_while_editing(false).speed(speed)).labelled_by(l.id);
}

/// The sweep window.
pub fn sweep_window(app: &mut super::ShoalApp, ctx: &egui::Context) {
    let mut open = app.ui.explore.sweep_open;
    let mut start = false;
    egui::Window::new("Sweep").open(&mut open).default_size([620.0, 460.0]).show(ctx, |ui| {
        let e = &mut app.ui.explore;
        ui.horizontal(|ui| {
            let before = e.param;
            egui::ComboBox::from_label("Parameter").selected_text(SWEEPABLE[e.param].0).show_ui(ui, |ui| {
                for (i, p) in SWEEPABLE.iter().enumerate() {
                    ui.selectable_value(&mut e.param, i, p.0);
                }
            });
            if e.param != before {
                (e.from, e.to) = (SWEEPABLE[e.param].3, SWEEPABLE[e.param].4);
            }
            let (from_speed, to_speed) = (0.01 * e.from.abs().max(1e-3), 0.01 * e.to.abs().max(1e-3));
            labelled_drag(ui, "From", &mut e.from, from_speed);
            labelled_drag(ui, "To", &mut e.to, to_speed);
            ui.label(SWEEPABLE[e.param].2);
        });
        ui.horizontal(|ui| {
            ui.add(egui::Slider::new(&mut e.steps, 2..=20).update_while_editing(false).text("Points"));
            ui.checkbox(&mut e.log, "Log spacing");
            ui.add(egui::Slider::new(&mut e.seeds, 1..=10).update_while_editing(false).text("Seeds"));
        });
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("Resolution").selected_text(format!("1/{}", e.decimation)).show_ui(ui, |ui| {
                for d in [2, 4, 8, 16, 24] {
                    ui.selectable_value(&mut e.decimation, d, format!("1/{d}"));
                }
            });
            let runs = 2 * e.steps * e.seeds as usize;
            if ui.button("Run sweep").on_hover_text(format!("{runs} runs of A and B")).clicked() {
                start = true;
            }
        });
        if e.sweep_task.is_some() && ui.button("Stop").clicked() {
            e.sweep_task = None;
            e.sweep_status = "stopped".into();
        }
        let done = e.table.as_ref().map_or(0, |t| {
            let mut jobs: Vec<usize> = t.rows.iter().map(|r| r.job).collect();
            jobs.dedup();
            jobs.len()
        });
        ui.label(format!("{} ({done}/{} runs)", e.sweep_status, e.sweep_total));
        let requirement = chl_requirement(&app.state);
        if let Some(table) = &e.table {
            let mut curves = crate::sweep::figure::curves(table, "chl_mg_m3", requirement.as_ref(), false);
            // A and B by their slots, not the study's de-duplicated names (`smallsat_2`).
            if curves.series.len() == 2 {
                for (s, (ab, slot)) in curves.series.iter_mut().zip([("A", &app.state.a), ("B", &app.state.b)]) {
                    s.label = format!("{ab}: {}", slot.preset);
                }
            }
            let (name, _, unit, _, _) = SWEEPABLE[e.param];
            let x_label = if unit.is_empty() { name.to_string() } else { format!("{name} ({unit})") };
            let log = e.log;
            for s in &curves.series {
                match (&requirement, s.crossing) {
                    (Some(r), Some(x)) => ui.label(format!(
                        "{}: meets chl MAE ≤ {:.0} % from {} = {} {unit}",
                        s.label,
                        r.mae_pct,
                        name.to_lowercase(),
                        crate::colormap::significant(x, 3)
                    )),
                    (Some(r), None) => {
                        ui.label(format!("{}: does not meet chl MAE ≤ {:.0} % (so far)", s.label, r.mae_pct))
                    }
                    (None, _) => ui.label(format!("{}: no chl MAE requirement set", s.label)),
                };
            }
            sweep_plot(ui, &curves, requirement.as_ref(), &x_label, log, (e.from, e.to));
        }
    });
    if start {
        let state = app.state.clone();
        app.ui.explore.start_sweep(ctx, &state);
    }
    if !open {
        app.ui.explore.sweep_task = None;
    }
    app.ui.explore.sweep_open = open;
}

/// The cost-of-accuracy window.
pub fn cost_window(app: &mut super::ShoalApp, ctx: &egui::Context) {
    let mut open = app.ui.explore.cost_open;
    let mut start = false;
    let mut apply = None;
    // 880 px wide: the table's seven columns fit (at 640 the p95 column sat past the right
    // edge, behind a horizontal scroll, at 1280 × 720).
    egui::Window::new("Cost of accuracy").open(&mut open).default_size([880.0, 520.0]).show(ctx, |ui| {
        ui.label("Time of the whole chain for instrument A against the error each fidelity setting makes, each one change from full fidelity (a fresh engine per run; rounds interleave the settings with the reference).");
        ui.horizontal(|ui| {
            let e = &mut app.ui.explore;
            egui::ComboBox::from_label("Reference resolution").selected_text(format!("1/{}", e.cost_decimation)).show_ui(ui, |ui| {
                for d in [1, 2, 4, 8] {
                    ui.selectable_value(&mut e.cost_decimation, d, if d == 1 { "full".to_string() } else { format!("1/{d}") });
                }
            });
            ui.add(egui::DragValue::new(&mut e.cost_rounds).range(1..=10).suffix(" rounds").update_while_editing(false))
                .on_hover_text("Each setting is timed once per round; with 3 or more, a setting whose times overlap the reference's says so");
            ui.add(egui::DragValue::new(&mut e.cost_tolerance_pct).range(0.0..=100.0).speed(0.1).prefix("tolerance ").suffix(" %").update_while_editing(false))
                .on_hover_text("The chl error (median per-pixel % difference from the reference, on the same grid) the cheapest acceptable setting may make; previews, on a coarser grid, are not candidates");
            if ui.button("Measure").clicked() {
                start = true;
            }
        });
        let e = &app.ui.explore;
        // The rows depend on the run measured (its retrieval and scene): counted once one is.
        match &e.cost_config {
            Some(c) => ui.label(format!("{} ({}/{} settings)", e.cost_status, e.cost_rows.len(), crate::sweep::settings_for(c).len())),
            None => ui.label(&e.cost_status),
        };
        let now = app.state.configs().into_iter().next().map(at_full_fidelity);
        if e.cost_config.is_some() && e.cost_config != now {
            ui.colored_label(super::theme::NOTICE, "Stale: A, the scene or the retrieval changed since these were measured. Press Measure to redo.");
        }
        let front: Vec<&str> = crate::sweep::pareto_front(&e.cost_rows).iter().map(|r| r.label.as_str()).collect();
        let cheapest = if e.busy() { None } else { crate::sweep::cheapest_within(&e.cost_rows, e.cost_tolerance_pct) };
        if let Some(c) = cheapest {
            ui.horizontal(|ui| {
                ui.label(egui::RichText::new(format!(
                    "Cheapest full-resolution setting within {} % chl per pixel: {} ({:.2} s, {})",
                    e.cost_tolerance_pct,
                    c.label,
                    c.seconds(),
                    c.comparison.text()
                )).strong())
                .on_hover_text("Measurably faster than the reference; of the settings no other is measurably faster than, the one with the smallest chl error");
                let fidelity = e.cost_config.as_ref().and_then(|base| crate::sweep::fidelity_of(&c.label, base));
                let button = ui.add_enabled(fidelity.is_some(), egui::Button::new("Apply to the app"));
                let button = if fidelity.is_some() {
                    button.on_hover_text("Run A and B (previews and full resolution) with this fidelity: the row's change from full fidelity (a study's own fidelity settings are replaced)")
                } else {
                    button.on_disabled_hover_text("Not a fidelity setting alone (it changes the atmosphere's accuracy, the retrieval or the resolution): set it where it lives")
                };
                if button.clicked() {
                    apply = fidelity;
                }
            });
        }
        ui.horizontal(|ui| {
            ui.label(format!("The app runs with: {}", fidelity_text(&app.state.fidelity)));
            if app.state.fidelity != Fidelity::default() && ui.button("Back to the defaults").clicked() {
                apply = Some(Fidelity::default());
            }
        });
        Plot::new("cost-plot").height(220.0).legend(Legend::default()).x_axis_label("time, s (median)").y_axis_label("error, %").show(ui, |p| {
            let same: Vec<[f64; 2]> = e.cost_rows.iter().filter_map(|r| r.chl_pixel_pct.map(|v| [r.seconds(), v])).collect();
            let other: Vec<[f64; 2]> = e.cost_rows.iter().filter(|r| r.chl_pixel_pct.is_none()).map(|r| [r.seconds(), r.delta_mae_pct.abs()]).collect();
            p.points(Points::new("chl per pixel vs reference (median %)", same).radius(4.0));
            p.points(Points::new("previews: |ΔMAE| (points)", other).radius(4.0).shape(egui_plot::MarkerShape::Diamond));
            // Each point named by its setting, on the plot only: a named item would also take a
            // legend line, and 22 of them covered the plot and the table at 1280 × 720.
            for r in &e.cost_rows {
                p.text(egui_plot::Text::new("", egui_plot::PlotPoint::new(r.seconds(), r.chl_error_pct().unwrap_or(r.delta_mae_pct.abs())), format!("  {}", r.label)).anchor(egui::Align2::LEFT_CENTER));
            }
        });
        egui::ScrollArea::both().show(ui, |ui| {
            egui::Grid::new("cost-table").striped(true).num_columns(7).show(ui, |ui| {
                for h in ["setting", "wall, median (range, n)", "CPU", "vs reference", "ΔMAE", "chl per pixel %", "p95 %"] {
                    ui.strong(h);
                }
                ui.end_row();
                for r in &e.cost_rows {
                    let label = if front.contains(&r.label.as_str()) { format!("{} ◆", r.label) } else { r.label.clone() };
                    ui.label(label).on_hover_text("◆: on the time–error Pareto front (no setting both faster and closer)");
                    ui.label(r.time.wall_text());
                    ui.label(r.time.cpu_text());
                    ui.label(r.comparison.text());
                    ui.label(format!("{:+.2}", r.delta_mae_pct));
                    ui.label(r.chl_pixel_pct.map_or_else(|| "other grid".into(), |v| format!("{v:.3}")));
                    ui.label(r.chl_pixel_p95_pct.map_or_else(|| "–".into(), |v| format!("{v:.3}")));
                    ui.end_row();
                }
            });
        });
    });
    if let Some(fidelity) = apply {
        app.state.fidelity = Fidelity { decimation: 1, ..fidelity };
    }
    if start {
        let config = app.state.configs().swap_remove(0);
        app.ui.explore.start_cost(ctx, config);
    }
    if !open {
        app.ui.explore.cost_task = None;
    }
    app.ui.explore.cost_open = open;
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

/// The sweep's requirement: the chl MAE limit in use, when there is one.
fn chl_requirement(state: &AppState) -> Option<Requirement> {
    let mae_pct = state.requirements.for_variable("chl_mg_m3")?.mae_pct?;
    Some(Requirement { variable: "chl_mg_m3".into(), mae_pct })
}

#[cfg(test)]
mod tests;
