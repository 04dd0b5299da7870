//! The Season window: the designs on screen flown over a season (`crate::season`) — each
//! design's passes over a site in its own sun-synchronous orbit, which of them a processor would
//! keep (sun, view, glint, clouds), and the products' error over the valid looks, each run
//! through the chain at its own geometry with its clouds in the scene. The site, its cloud
//! climatology and the orbit come from a season preset; the period, tilt, roll and the number of
//! chain runs are set here. The looks appear at once; the runs stream in on a helper thread.

use egui_plot::{Legend, Line, LineStyle, Plot, PlotPoints, Points};

use crate::engine::RunConfig;
use crate::jobs::{Task, TaskNews};
use crate::season::run::{LookRun, PhaseSample, SeasonResult, phase_spread, plan_looks, run_plan};
use crate::season::summary::SeasonSummary;
use crate::season::{SeasonSpec, looks::Verdict};
use crate::sweep::Shard;

/// What the helper thread sends.
pub enum SeasonNews {
    /// The looks of every design, no run yet, and the runs to come.
    Plan(Box<SeasonResult>, usize),
    /// One chain run: (design, run).
    Run(usize, LookRun),
    /// Each design's spread over orbit phases, made after the runs.
    Phases(Vec<Vec<PhaseSample>>),
}

/// The window's settings and results (not persisted: results belong to the session).
pub struct SeasonState {
    /// Is the window open?
    pub open: bool,
    /// The season preset the site, climatology and orbit come from.
    preset: String,
    from: String,
    to: String,
    tilt_deg: f64,
    roll_deg: f64,
    max_runs: usize,
    decimation: usize,
    task: Option<Task<SeasonNews>>,
    result: Option<SeasonResult>,
    summary: Option<SeasonSummary>,
    /// The designs' configurations the result is for (to mark it stale).
    ran_with: Vec<RunConfig>,
    total: usize,
    done: usize,
    /// The (product, variable) whose error the plot shows.
    shown: usize,
    status: String,
}

impl Default for SeasonState {
    fn default() -> Self {
        Self {
            open: false,
            preset: "lake_hume_year".into(),
            from: "2023-01-01".into(),
            to: "2023-12-31".into(),
            tilt_deg: 0.0,
            roll_deg: 30.0,
            max_runs: 6,
            decimation: 16,
            task: None,
            result: None,
            summary: None,
            ran_with: Vec::new(),
            total: 0,
            done: 0,
            shown: 0,
            status: String::new(),
        }
    }
}

impl SeasonState {
    /// Is a season running?
    #[must_use]
    pub fn busy(&self) -> bool {
        self.task.is_some()
    }

    /// The season's summary so far (the looks at once, the errors as the runs come in).
    #[must_use]
    pub fn summary(&self) -> Option<&SeasonSummary> {
        self.summary.as_ref()
    }

    /// The season, when it has finished (every run made) for exactly `configs`, the designs
    /// and scene set now: what the review pack may carry.
    #[must_use]
    pub fn finished_for(&self, configs: &[RunConfig]) -> Option<&SeasonResult> {
        let done = !self.busy() && self.done == self.total && self.ran_with == configs;
        self.result.as_ref().filter(|_| done)
    }

    /// Stop the season being run (its looks and the runs made so far stay).
    pub fn cancel(&mut self) {
        if self.task.take().is_some() {
            self.status = match self.result {
                // Every run made: what was stopped is the spread over orbit phases.
                Some(_) if self.done == self.total => {
                    format!("stopped in the spread over orbit phases ({} of {} chain runs made)", self.done, self.total)
                }
                _ => format!("stopped after {} of {} chain runs", self.done, self.total),
            };
        }
    }

    /// The season as set here, from its preset.
    fn spec(&self) -> Result<SeasonSpec, String> {
        let mut s = SeasonSpec::preset(&self.preset).map_err(|e| e.to_string())?;
        s.from = self.from.trim().to_string();
        s.to = self.to.trim().to_string();
        s.glint_tilt_deg = self.tilt_deg;
        s.max_roll_deg = self.roll_deg;
        s.max_runs = self.max_runs;
        s.decimation = self.decimation;
        s.validate().map_err(|e| e.to_string())?;
        Ok(s)
    }

    /// Start the season over `designs` (label, configuration) as they are now.
    pub fn start(&mut self, ctx: &egui::Context, designs: Vec<(String, RunConfig)>) {
        self.task = None;
        let spec = match self.spec() {
            Ok(s) => s,
            Err(e) => {
                self.status = e;
                return;
            }
        };
        self.ran_with = designs.iter().map(|d| d.1.clone()).collect();
        self.result = None;
        self.summary = None;
        (self.done, self.total) = (0, 0);
        self.status = format!("finding the passes of {} designs …", designs.len());
        let wake = ctx.clone();
        let task = Task::spawn(
            "shoal-season",
            move || wake.request_repaint(),
            move |control, send| {
                // The looks at once (a fraction of a second); the runs (held to the machine's
                // budget first) as they come; the spread over orbit phases, which costs twelve
                // times the looks, last.
                let plan = plan_looks(&spec, "the designs on screen", &designs).map_err(|e| e.to_string())?;
                send(SeasonNews::Plan(Box::new(plan.result.clone()), plan.jobs.len()));
                run_plan(&plan, &designs, Shard::ALL, control, |_, _, d, run| send(SeasonNews::Run(d, run.clone())))
                    .map_err(|e| e.to_string())?;
                let phases = phase_spread(&spec, &designs, plan.result.period, control).map_err(|e| e.to_string())?;
                send(SeasonNews::Phases(phases));
                Ok(())
            },
        );
        match task {
            Ok(t) => self.task = Some(t),
            Err(e) => self.status = e,
        }
    }

    /// Take what the helper thread sent.
    pub fn poll(&mut self) {
        if !self.open {
            self.cancel();
        }
        let Some(task) = &self.task else { return };
        let mut finished = None;
        let mut changed = false;
        while let Some(news) = task.poll() {
            match news {
                TaskNews::Item(SeasonNews::Plan(result, total)) => {
                    self.result = Some(*result);
                    self.total = total;
                    changed = true;
                }
                TaskNews::Item(SeasonNews::Run(d, run)) => {
                    if let Some(design) = self.result.as_mut().and_then(|r| r.designs.get_mut(d)) {
                        design.runs.push(run);
                        design.runs.sort_by_key(|r| r.look);
                    }
                    self.done += 1;
                    changed = true;
                }
                TaskNews::Item(SeasonNews::Phases(phases)) => {
                    if let Some(r) = &mut self.result {
                        for (d, p) in r.designs.iter_mut().zip(phases) {
                            d.phases = p;
                        }
                    }
                    changed = true;
                }
                TaskNews::Done(r) => finished = Some(r),
            }
        }
        if changed {
            self.summary = self.result.as_ref().map(SeasonSummary::of);
            self.status = if self.done == self.total {
                format!("{} chain runs; the spread over orbit phases …", self.total)
            } else {
                format!("{} of {} chain runs", self.done, self.total)
            };
        }
        if let Some(r) = finished {
            self.status = match r {
                Ok(()) => format!("done: {} chain runs", self.total),
                Err(e) => e,
            };
            self.task = None;
        }
    }
}

/// The looks-and-revisit table, one row per design.
fn looks_table(ui: &mut egui::Ui, s: &SeasonSummary) {
    egui::Grid::new("season-looks").striped(true).show(ui, |ui| {
        for h in
            ["design", "passes", "valid", "sun low", "oblique", "glint", "cloud", "gap median", "gap 90 %", "revisit"]
        {
            ui.strong(h);
        }
        ui.end_row();
        for d in &s.designs {
            ui.label(&d.label);
            ui.label(d.passes.to_string());
            for n in d.by_verdict {
                ui.label(n.to_string());
            }
            let days = |v: Option<f64>| v.map_or_else(|| "–".to_string(), |v| format!("{v:.1} d"));
            ui.label(days(d.gap_median_d));
            ui.label(days(d.gap_p90_d));
            match d.revisit {
                Some((pct, ok)) => {
                    let colour = if ok { super::super::theme::PASS } else { super::super::theme::FAIL };
                    ui.colored_label(colour, format!("{pct:.0} % {}", if ok { "pass" } else { "fail" }));
                }
                None => {
                    ui.label("–");
                }
            }
            ui.end_row();
        }
    });
}

/// Each product's error over the looks run, one row per design and variable.
fn errors_table(ui: &mut egui::Ui, s: &SeasonSummary) {
    egui::Grid::new("season-errors").striped(true).show(ui, |ui| {
        for h in ["design", "product", "looks", "MAE % median", "10–90 %", "worst", "returned % median"] {
            ui.strong(h);
        }
        ui.end_row();
        for d in &s.designs {
            for p in &d.products {
                ui.label(&d.label);
                ui.label(format!("{} {}", p.product, crate::metrics::name(&p.variable)));
                ui.label(p.looks.to_string());
                ui.label(format!("{:.1}", p.mae_median_pct));
                ui.label(format!("{:.1}–{:.1}", p.mae_p10_pct, p.mae_p90_pct));
                ui.label(format!("{:.1}", p.mae_worst_pct));
                ui.label(format!("{:.1}", p.returned_median_pct));
                ui.end_row();
            }
        }
    });
}

/// Valid looks per month (lines) and the error of the shown variable look by look (points),
/// one colour per design.
fn plots(ui: &mut egui::Ui, r: &SeasonResult, shown: Option<&(String, String)>) {
    let colour =
        |k: usize| super::super::theme::DESIGN.get(k).copied().unwrap_or_else(|| super::super::theme::category(k));
    let height = (ui.available_height() - 8.0).max(160.0);
    let width = ui.available_width() / 2.0 - 8.0;
    ui.horizontal(|ui| {
        Plot::new("season-months")
            .legend(Legend::default())
            .x_axis_label("month of the period")
            .y_axis_label("valid looks")
            .include_y(0.0)
            .width(width)
            .height(height)
            .show(ui, |p| {
                for (k, d) in r.designs.iter().enumerate() {
                    let months = r.per_month(d, Some(Verdict::Valid));
                    let pts: Vec<[f64; 2]> =
                        months.iter().enumerate().map(|(i, (_, n))| [i as f64 + 1.0, *n as f64]).collect();
                    // Designs in one orbit have the same looks: every other one dashed, so
                    // neither hides the other.
                    let style = if k % 2 == 0 { LineStyle::Solid } else { LineStyle::dashed_loose() };
                    p.line(Line::new(d.label.clone(), PlotPoints::from(pts)).color(colour(k)).width(2.0).style(style));
                }
            });
        let Some((product, variable)) = shown else { return };
        // Headroom above the worst look for the legend, which sits at the top right.
        let worst = r
            .designs
            .iter()
            .flat_map(|d| &d.runs)
            .flat_map(|run| &run.errors)
            .filter(|e| e.product == *product && e.variable == *variable)
            .map(|e| e.mae_pct)
            .fold(0.0, f64::max);
        Plot::new("season-errors-plot")
            .legend(Legend::default())
            .x_axis_label(format!("days from {}", r.spec.from))
            .y_axis_label(format!("{} MAE %", crate::metrics::name(variable)))
            .include_y(0.0)
            .include_y(worst * 1.35)
            .width(width)
            .height(height)
            .show(ui, |p| {
                for (k, d) in r.designs.iter().enumerate() {
                    let pts: Vec<[f64; 2]> = d
                        .runs
                        .iter()
                        .filter_map(|run| {
                            let e = run.errors.iter().find(|e| e.product == *product && e.variable == *variable)?;
                            Some([d.looks[run.look].access.days - r.period.0, e.returned_mae_pct()?])
                        })
                        .collect();
                    p.points(Points::new(d.label.clone(), pts).radius(4.0).color(colour(k)));
                }
            });
    });
}

/// The Season window.
pub fn season_window(app: &mut super::super::ShoalApp, ctx: &egui::Context) {
    let mut open = app.ui.explore.season.open;
    let mut start = false;
    let designs: Vec<(String, RunConfig)> =
        app.state.configs().into_iter().enumerate().map(|(i, c)| (app.state.design_name(i), c)).collect();
    egui::Window::new("Season").open(&mut open).default_size([980.0, 640.0]).show(ctx, |ui| {
        let s = &mut app.ui.explore.season;
        ui.label("The designs on screen flown over a season: each design's passes over the site in its own sun-synchronous orbit, kept when the sun is high enough, the site in the swath, the glint low and the sky clear enough; up to the chosen number of valid looks run through the whole chain at their own sun, view, date and clouds.");
        ui.horizontal_wrapped(|ui| {
            egui::ComboBox::from_label("site and climate").selected_text(s.preset.clone()).show_ui(ui, |ui| {
                for name in SeasonSpec::preset_names() {
                    ui.selectable_value(&mut s.preset, name.clone(), name);
                }
            });
            let from = ui.label("from");
            ui.add(egui::TextEdit::singleline(&mut s.from).desired_width(84.0)).labelled_by(from.id);
            let to = ui.label("to");
            ui.add(egui::TextEdit::singleline(&mut s.to).desired_width(84.0)).labelled_by(to.id);
            ui.add(egui::DragValue::new(&mut s.tilt_deg).range(0.0..=30.0).speed(0.5).prefix("glint tilt ").suffix("°"))
                .on_hover_text("Fore/aft tilt away from the glint, whichever side glints less (0: none)");
            ui.add(egui::DragValue::new(&mut s.roll_deg).range(0.0..=45.0).speed(0.5).prefix("roll up to ").suffix("°"))
                .on_hover_text("How far the platform may roll across track to see the site");
            ui.add(egui::DragValue::new(&mut s.max_runs).range(0..=100).prefix("chain runs ").suffix(" per design"))
                .on_hover_text("Valid looks run through the chain per design, evenly spaced (0: the looks and revisit only)");
            egui::ComboBox::from_label("resolution").selected_text(format!("1/{}", s.decimation)).show_ui(ui, |ui| {
                for k in [4, 8, 16, 32] {
                    ui.selectable_value(&mut s.decimation, k, format!("1/{k}"));
                }
            });
            if ui.add_enabled(!s.busy(), egui::Button::new("Run")).clicked() {
                start = true;
            }
            if ui.add_enabled(s.busy(), egui::Button::new("Stop")).on_hover_text("Stop; the looks and the runs made so far stay").clicked() {
                s.cancel();
            }
        });
        ui.label(&s.status);
        let stale = s.result.is_some()
            && (s.ran_with.len() != designs.len() || s.ran_with.iter().zip(&designs).any(|(a, (_, b))| a != b));
        if stale {
            ui.colored_label(super::super::theme::FAIL, "The designs or the scene changed since this season ran: Run again to update it.");
        }
        let (Some(result), Some(summary)) = (&s.result, &s.summary) else { return };
        ui.small(format!("{}, {} to {}, {}; {}", summary.name, summary.from, summary.to, summary.orbit, summary.clouds));
        looks_table(ui, summary);
        let variables = crate::season::summary::variables(result);
        if !variables.is_empty() {
            ui.separator();
            errors_table(ui, summary);
            s.shown = s.shown.min(variables.len() - 1);
            egui::ComboBox::from_label("error plot").selected_text(format!("{} {}", variables[s.shown].0, variables[s.shown].1)).show_ui(ui, |ui| {
                for (i, (p, v)) in variables.iter().enumerate() {
                    ui.selectable_value(&mut s.shown, i, format!("{p} {v}"));
                }
            });
        }
        ui.separator();
        plots(ui, result, variables.get(s.shown));
    });
    app.ui.explore.season.open = open;
    if start {
        app.ui.explore.season.start(ctx, designs);
    }
}
