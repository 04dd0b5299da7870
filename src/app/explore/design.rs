//! The Design window: `shoal design` in the app. Instrument A is the starting design; the
//! parameters to vary come from the range table; the search (`crate::design`) runs on a helper
//! thread against the Requirements panel, under the built-in budget models chosen here, and
//! streams every design it evaluates. The plot shows cost against the product's error (every
//! design, the feasible ones, the front and the requirement); a design from the table goes into
//! A, or added beside the others, with one click.

use egui_plot::{HLine, Legend, Line, Plot, PlotPoints, Points};

use super::super::model::Slot;
use crate::design::{Dimension, Evaluation, Evaluator, Settings, cheapest_feasible, pareto_front};
use crate::instrument::budgets::BudgetModels;
use crate::jobs::{Task, TaskNews};

/// The window's state (not persisted).
pub struct DesignState {
    /// Varied fields: (path, lowest, highest).
    vars: Vec<(String, f64, f64)>,
    evaluations: usize,
    decimation: usize,
    /// Built-in budget models (`cubesat_class` extrapolates the cost below 0.3 m).
    models: String,
    task: Option<Task<Evaluation>>,
    /// The search's variables and designs so far.
    searched: Vec<Dimension>,
    results: Vec<Evaluation>,
    status: String,
    /// Currency of the costs shown (the budget models' of the last search).
    currency: String,
    /// A's run configuration and the requirements the last search started from: its designs are
    /// that configuration with the varied fields set, and "→ A" builds them from it.
    searched_from: Option<(crate::engine::RunConfig, crate::study::Requirements)>,
}

impl Default for DesignState {
    fn default() -> Self {
        Self {
            vars: vec![("instrument.aperture_mm".into(), 40.0, 200.0), ("instrument.exposure_s".into(), 0.0005, 0.003)],
            evaluations: 20,
            decimation: 8,
            models: "cubesat_class".into(),
            task: None,
            searched: Vec::new(),
            results: Vec::new(),
            status: String::new(),
            currency: String::new(),
            searched_from: None,
        }
    }
}

impl DesignState {
    /// Is a search running?
    #[must_use]
    pub fn busy(&self) -> bool {
        self.task.is_some()
    }

    /// Designs evaluated so far.
    #[must_use]
    pub fn results(&self) -> &[Evaluation] {
        &self.results
    }

    /// Stop a running search (the window closed); what it evaluated stays, and the status says
    /// it was cut short.
    pub fn cancel(&mut self) {
        if self.task.take().is_some() {
            self.status = format!("cancelled after {} of {} designs", self.results.len(), self.evaluations);
        }
    }

    /// Take what the search sent.
    pub fn poll(&mut self) {
        let Some(task) = &self.task else { return };
        let mut finished = None;
        while let Some(news) = task.poll() {
            match news {
                TaskNews::Item(e) => {
                    self.status = format!("{} of {} designs", self.results.len() + 1, self.evaluations);
                    self.results.push(e);
                }
                TaskNews::Done(r) => finished = Some(r),
            }
        }
        if let Some(r) = finished {
            self.status = match (r, cheapest_feasible(&self.results)) {
                (Ok(()), Some(i)) => format!("done: cheapest feasible is #{}", i + 1),
                (Ok(()), None) => {
                    let closest = (0..self.results.len())
                        .filter(|&i| self.results[i].error.is_none())
                        .min_by(|&a, &b| self.results[a].worst().total_cmp(&self.results[b].worst()));
                    match closest {
                        Some(i) => format!(
                            "done: no feasible design in the ranges searched; the closest, #{}, misses {}",
                            i + 1,
                            misses(&self.results[i])
                        ),
                        None => "done: no design ran".into(),
                    }
                }
                (Err(e), _) => e,
            };
            self.task = None;
        }
    }

    /// Start a search from A's configuration against the app's requirements.
    pub fn start(&mut self, ctx: &egui::Context, state: &super::super::model::AppState) {
        let vars: Result<Vec<Dimension>, String> =
            self.vars.iter().map(|(p, lo, hi)| Dimension::parse(&format!("{p}={lo}:{hi}"))).collect();
        let vars = match vars {
            Ok(v) => v,
            Err(e) => {
                self.status = e;
                return;
            }
        };
        let budgets = match BudgetModels::preset(&self.models) {
            Ok(b) => b,
            Err(e) => {
                self.status = e.to_string();
                return;
            }
        };
        let base = state.configs().swap_remove(0);
        let requirements = state.requirements.clone();
        let seeds = vec![state.noise_seed];
        let settings = Settings {
            evaluations: self.evaluations,
            initial: 0,
            decimation: self.decimation,
            confirm_decimation: None,
            seed: 1,
            stall_after: Some(10),
            stall_gain: 0.001,
            shard: None,
        };
        // Checked by the search itself: a refusal comes back as the task's error, in the status.
        self.searched.clone_from(&vars);
        self.searched_from = Some((base.clone(), requirements.clone()));
        self.currency.clone_from(&budgets.cost.currency);
        self.results.clear();
        self.status = format!("searching at 1/{} …", self.decimation);
        let wake = ctx.clone();
        let task = Task::spawn(
            "shoal-design",
            move || wake.request_repaint(),
            move |control, send| {
                let evaluator = Evaluator {
                    base: &base,
                    vars: &vars,
                    seeds: &seeds,
                    requirements: &requirements,
                    budgets: &budgets,
                    decimation: settings.decimation,
                };
                crate::design::search(&evaluator, &settings, control, |e, _, _| send(e.clone()))
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            },
        );
        match task {
            Ok(t) => self.task = Some(t),
            Err(e) => self.status = e,
        }
    }
}

/// The Design window.
pub fn design_window(app: &mut super::super::ShoalApp, ctx: &egui::Context) {
    let mut open = app.ui.explore.design_open;
    let mut start = false;
    let mut put: Option<(Put, usize)> = None;
    // A as it is now: the parameters it can vary, and whether the last search still describes
    // the scene and requirements on screen.
    let current = app.state.configs().into_iter().next();
    let paths: Vec<&'static str> =
        current.as_ref().map(|c| super::sweep::sweepable(c).iter().map(|r| r.path).collect()).unwrap_or_default();
    egui::Window::new("Design search").open(&mut open).default_size([900.0, 600.0]).show(ctx, |ui| {
        ui.label("The cheapest design, starting from A, that meets the Requirements panel on the noise seed in use: constrained Bayesian optimisation (egobox) of the telescope cost under Gaussian-process models of every requirement.");
        let d = &mut app.ui.explore.design;
        let mut remove = None;
        for (i, (path, lo, hi)) in d.vars.iter_mut().enumerate() {
            ui.horizontal(|ui| {
                egui::ComboBox::from_id_salt(("design-var", i)).selected_text(path.rsplit('.').next().unwrap_or(path)).show_ui(ui, |ui| {
                    for p in &paths {
                        ui.selectable_value(path, (*p).to_string(), *p);
                    }
                });
                ui.add(egui::DragValue::new(lo).speed(0.01).prefix("from ").update_while_editing(false));
                ui.add(egui::DragValue::new(hi).speed(0.01).prefix("to ").update_while_editing(false));
                if ui.small_button("remove").clicked() {
                    remove = Some(i);
                }
            });
        }
        if let Some(i) = remove.filter(|_| d.vars.len() > 1) {
            d.vars.remove(i);
        }
        ui.horizontal(|ui| {
            if ui.button("+ parameter").clicked() && d.vars.len() < 8 {
                d.vars.push(("instrument.focal_length_mm".into(), 100.0, 300.0));
            }
            ui.add(egui::Slider::new(&mut d.evaluations, 4..=200).text("Designs"))
                .on_hover_text("Designs evaluated in all, the Latin-hypercube start (2 × parameters + 1) included");
            egui::ComboBox::from_label("Search resolution").selected_text(format!("1/{}", d.decimation)).show_ui(ui, |ui| {
                for k in [1, 2, 4, 8, 16] {
                    ui.selectable_value(&mut d.decimation, k, format!("1/{k}"));
                }
            });
            egui::ComboBox::from_label("budget models").selected_text(d.models.clone()).show_ui(ui, |ui| {
                for m in crate::parse::preset_names::<BudgetModels>() {
                    ui.selectable_value(&mut d.models, m.clone(), m);
                }
            });
            if ui.add_enabled(!d.busy(), egui::Button::new("Search")).clicked() {
                start = true;
            }
            // Stop keeps the designs evaluated so far (closing the window also stops it).
            if ui.add_enabled(d.busy(), egui::Button::new("Stop")).on_hover_text("Stop the search; the designs evaluated so far stay").clicked() {
                d.cancel();
                d.status = format!("stopped after {} designs", d.results.len());
            }
        });
        ui.label(&d.status);
        let now = (current.as_ref(), &app.state.requirements);
        if let Some((base, requirements)) = &d.searched_from
            && !d.results.is_empty()
            && (now.0.is_none_or(|c| c.scene != base.scene || c.seed != base.seed || c.retrievals != base.retrievals) || now.1 != requirements)
        {
            ui.colored_label(
                super::super::theme::WARN,
                "The scene, retrieval, noise seed or requirements changed since this search: its figures are for those it ran with. Search again.",
            );
        }
        plot(ui, d, &app.state.requirements);
        table(ui, d, &mut put);
    });
    if start {
        app.ui.explore.design.start(ctx, &app.state);
    }
    if let Some((to, i)) = put {
        let d = &app.ui.explore.design;
        if let (Some(e), Some((base, _))) = (d.results.get(i), &d.searched_from) {
            match (crate::design::space::configure(base, &d.searched, &e.x), to) {
                (Ok(config), Put::IntoA) => app.state.designs[0].spec = config.instrument,
                (Ok(config), Put::New) => {
                    // Named as the list will show it, everywhere; described by its parameters
                    // (the pack), never by the preset's text it was searched from.
                    // (A file-safe name, as every instrument's: `#` is not one.)
                    let name = format!("search {}", i + 1);
                    let mut spec = config.instrument;
                    spec.name.clone_from(&name);
                    spec.description = format!("found by the design search from {}", base.instrument.name);
                    let slot = Slot::new(&name, spec);
                    if app.state.add_design(slot).is_none() {
                        app.ui.explore.design.status = "the app already holds as many designs as it can".into();
                    }
                }
                (Err(err), _) => app.ui.explore.design.status = err,
            }
        }
    }
    if !open {
        app.ui.explore.design.cancel();
    }
    app.ui.explore.design_open = open;
}

/// Cost against chl-a MAE: every design, the feasible ones, the front and the requirement.
fn plot(ui: &mut egui::Ui, d: &DesignState, requirements: &crate::study::Requirements) {
    let variable = "chl_mg_m3";
    let point = |e: &Evaluation| Some([e.cost?, e.mae_pct.iter().find(|(v, _)| v == variable)?.1]);
    let all: Vec<[f64; 2]> = d.results.iter().filter_map(point).collect();
    let feasible: Vec<[f64; 2]> = d.results.iter().filter(|e| e.feasible()).filter_map(point).collect();
    let front: Vec<[f64; 2]> =
        pareto_front(&d.results, variable).into_iter().filter_map(|i| point(&d.results[i])).collect();
    Plot::new("design-plot")
        .height(240.0)
        .legend(Legend::default())
        .x_axis_label(if d.currency.is_empty() {
            "telescope cost".to_string()
        } else {
            format!("telescope cost, {}", d.currency)
        })
        .y_axis_label("chl-a log-space MAE, %")
        .allow_scroll(false)
        .show(ui, |p| {
            p.points(Points::new("designs", all).radius(3.0).color(egui::Color32::GRAY));
            p.points(Points::new("feasible", feasible).radius(5.0).color(super::super::theme::PASS));
            p.line(Line::new("front", PlotPoints::from(front)).color(super::super::theme::design(1)));
            if let Some(limit) = requirements.for_variable(variable).and_then(|r| r.mae_pct) {
                p.hline(HLine::new("requirement", limit).color(super::super::theme::FAIL));
            }
        });
}

/// Where a design found goes: into A (the design searched from), or beside the others.
#[derive(Clone, Copy)]
enum Put {
    IntoA,
    New,
}

/// The designs by cost, with their values, error and verdict, and buttons to use one.
fn table(ui: &mut egui::Ui, d: &DesignState, put: &mut Option<(Put, usize)>) {
    let mut order: Vec<usize> = (0..d.results.len()).collect();
    order.sort_by(|&a, &b| {
        d.results[a].cost.unwrap_or(f64::INFINITY).total_cmp(&d.results[b].cost.unwrap_or(f64::INFINITY))
    });
    egui::ScrollArea::vertical().id_salt("design-table").show(ui, |ui| {
        egui::Grid::new("design-grid").striped(true).show(ui, |ui| {
            ui.strong("#");
            for v in &d.searched {
                ui.strong(v.name());
            }
            for h in ["cost", "chl MAE %", "feasible", "worst excess %", ""] {
                ui.strong(h);
            }
            ui.end_row();
            for i in order {
                let e = &d.results[i];
                ui.label(format!("{}", i + 1));
                for x in &e.x {
                    ui.label(format!("{x:.4}"));
                }
                ui.label(e.cost.map_or_else(|| "–".into(), |c| format!("{c:.3}")));
                let chl = e.mae_pct.iter().find(|(v, _)| v == "chl_mg_m3").map(|m| m.1);
                ui.label(chl.map_or_else(|| "–".into(), |m| format!("{m:.1}")));
                if e.feasible() && !e.warnings.is_empty() {
                    // Its numbers pass, but no one could build it as set (as the metrics table's "pass?").
                    ui.colored_label(super::super::theme::WARN, "yes?")
                        .on_hover_text(format!("Meets every requirement, but: {}", e.warnings.join("; ")));
                } else if e.feasible() {
                    ui.colored_label(super::super::theme::PASS, "yes");
                } else {
                    ui.label(e.error.as_deref().map_or("no", |_| "error"))
                        .on_hover_text(e.error.as_deref().unwrap_or(""));
                }
                ui.label(if e.constraints.is_empty() { "–".into() } else { format!("{:+.1}", 100.0 * e.worst()) })
                    .on_hover_text(if e.feasible() { "meets every requirement".into() } else { misses(e) });
                ui.horizontal(|ui| {
                    if ui.small_button("→ A").on_hover_text("Set design A's parameters to these").clicked() {
                        *put = Some((Put::IntoA, i));
                    }
                    if ui.small_button("+ design").on_hover_text("Add this as a new design beside the others").clicked()
                    {
                        *put = Some((Put::New, i));
                    }
                });
                ui.end_row();
            }
        });
    });
}

/// The requirements `e` misses and by how much of each limit.
fn misses(e: &Evaluation) -> String {
    let failing: Vec<String> =
        e.constraints.iter().filter(|(_, g)| *g > 0.0).map(|(k, g)| format!("{k} by {:.1} %", 100.0 * g)).collect();
    if failing.is_empty() { e.error.clone().unwrap_or_else(|| "nothing".into()) } else { failing.join(", ") }
}
