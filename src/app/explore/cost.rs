//! The Cost window: every fidelity setting's time against the error it makes in the product the
//! user picks, compared with the reference paired by round (`sweep::cost`); the Pareto front and
//! the cheapest setting within a tolerance follow the same rule as the CLI.

use egui_plot::{Legend, Line, Plot, PlotPoints, Points};

use super::{at_full_fidelity, fidelity_text};
use crate::engine::Fidelity;
use crate::sweep::{COST_METHOD, CostRow, ErrorOf};

/// The products the rows carry an error for (all of them before any row is measured).
fn products(rows: &[CostRow]) -> Vec<ErrorOf> {
    match rows.first() {
        Some(reference) => ErrorOf::ALL.into_iter().filter(|&of| reference.error_pct(of).is_some()).collect(),
        None => ErrorOf::ALL.to_vec(),
    }
}

/// The cost-of-accuracy window.
pub fn cost_window(app: &mut super::super::ShoalApp, ctx: &egui::Context) {
    let mut open = app.ui.explore.cost_open;
    let mut start = false;
    let mut apply = None;
    // 960 px wide: the table's columns fit (at 640 the p95 column sat past the right edge,
    // behind a horizontal scroll, at 1280 × 720).
    egui::Window::new("Cost of accuracy").open(&mut open).default_size([960.0, 560.0]).show(ctx, |ui| {
        ui.label("Time of the whole chain for instrument A against the error each setting makes. Each row changes what its label names from the reference: full fidelity (per-pixel spectra on the full grid, in double precision); a fresh engine per run.");
        ui.collapsing("How rows are compared", |ui| ui.label(COST_METHOD));
        ui.horizontal(|ui| {
            let e = &mut app.ui.explore;
            egui::ComboBox::from_label("Reference resolution").selected_text(format!("1/{}", e.cost_decimation)).show_ui(ui, |ui| {
                for d in [1, 2, 4, 8] {
                    ui.selectable_value(&mut e.cost_decimation, d, if d == 1 { "full".to_string() } else { format!("1/{d}") });
                }
            });
            ui.add(egui::DragValue::new(&mut e.cost_rounds).range(1..=20).suffix(" rounds").update_while_editing(false))
                .on_hover_text("Each setting is timed once per round, paired with the reference's runs either side of it: 5 rounds for any claim at 90 % coverage, 8 or more to tolerate one slow run");
        });
        ui.horizontal(|ui| {
            let e = &mut app.ui.explore;
            let available = products(&e.cost_rows);
            if !available.contains(&e.cost_error_of) {
                e.cost_error_of = ErrorOf::Chl;
            }
            egui::ComboBox::from_label("error of").selected_text(e.cost_error_of.label()).show_ui(ui, |ui| {
                for of in available {
                    ui.selectable_value(&mut e.cost_error_of, of, of.label());
                }
            });
            ui.add(egui::DragValue::new(&mut e.cost_tolerance_pct).range(0.0..=100.0).speed(0.1).prefix("tolerance ").suffix(" %").update_while_editing(false))
                .on_hover_text(format!("The error the cheapest acceptable setting may make: {}; previews, on a coarser grid, are not candidates", e.cost_error_of.measure()));
            if ui.button("Measure").clicked() {
                start = true;
            }
        });
        let e = &app.ui.explore;
        let of = e.cost_error_of;
        // The rows depend on the run measured (its retrieval and scene): counted once one is.
        match &e.cost_config {
            Some(c) => ui.label(format!("{} ({}/{} settings)", e.cost_status, e.cost_rows.len(), crate::sweep::settings_for(c).len())),
            None => ui.label(&e.cost_status),
        };
        let now = app.state.configs().into_iter().next().map(at_full_fidelity);
        if e.cost_config.is_some() && e.cost_config != now {
            ui.colored_label(crate::app::theme::NOTICE, "Stale: A, the scene or the retrieval changed since these were measured. Press Measure to redo.");
        }
        let front: Vec<&str> = crate::sweep::pareto_front(&e.cost_rows, of).iter().map(|r| r.label.as_str()).collect();
        let cheapest = if e.busy() { None } else { crate::sweep::cheapest_within(&e.cost_rows, of, e.cost_tolerance_pct) };
        if let Some(c) = cheapest {
            ui.horizontal(|ui| {
                let verdict = if std::ptr::eq(c, &e.cost_rows[0]) {
                    format!("the reference ({:.2} s): no setting within it is measurably faster", c.seconds())
                } else {
                    format!("{} ({:.2} s, {} the reference's time)", c.label, c.seconds(), c.comparison.text())
                };
                ui.label(egui::RichText::new(format!("Cheapest full-resolution setting within {} % {} error: {verdict}", e.cost_tolerance_pct, of.label())).strong())
                    .on_hover_text("Measurably faster than the reference, paired by round; of the settings no other is measurably faster than, the one with the smallest error");
                let fidelity = e.cost_config.as_ref().and_then(|base| crate::sweep::fidelity_of(&c.label, base));
                let button = ui.add_enabled(fidelity.is_some(), egui::Button::new("Apply to the app"));
                let button = if fidelity.is_some() {
                    button.on_hover_text("Run every design (previews and full resolution) with this fidelity: the row's change from full fidelity (a study's own fidelity settings are replaced)")
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
        plot(ui, &e.cost_rows, of, &front);
        table(ui, &e.cost_rows, of, &front);
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

/// Time relative to the reference (paired median) against the error of `of`: one point per
/// full-resolution row, named on hover; the front joined by a line, its points numbered as in
/// the table (labels on every point smeared into each other where rows cluster).
fn plot(ui: &mut egui::Ui, rows: &[CostRow], of: ErrorOf, front: &[&str]) {
    let measured: Vec<(usize, &CostRow, f64)> = rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| Some((i, r, r.error_pct(of)?)))
        .filter(|(_, r, _)| r.relative_time().is_finite())
        .collect();
    let names: Vec<String> = measured
        .iter()
        .map(|(i, r, e)| {
            format!("#{} {}\n{} the reference's time · error {e:.3} %", i + 1, r.label, r.comparison.text())
        })
        .collect();
    let unit = of.measure();
    Plot::new("cost-plot")
        .height(220.0)
        .legend(Legend::default())
        .x_axis_label("time vs reference (paired median, ×)")
        .y_axis_label(unit.clone())
        .allow_scroll(false)
        .allow_zoom(false)
        .allow_drag(false)
        .include_x(0.0)
        .include_x(1.0)
        .include_y(0.0)
        .label_formatter(move |h| {
            let egui_plot::HoverPosition::NearDataPoint { plot_name, index, .. } = h else { return None };
            let plot_name: &str = plot_name;
            (plot_name == "settings").then(|| names.get(*index).cloned()).flatten()
        })
        .show(ui, |p| {
            let points: Vec<[f64; 2]> = measured.iter().map(|(_, r, e)| [r.relative_time(), *e]).collect();
            p.points(Points::new("settings", points).radius(4.0));
            let mut on_front: Vec<(usize, [f64; 2])> = measured
                .iter()
                .filter(|(_, r, _)| front.contains(&r.label.as_str()))
                .map(|(i, r, e)| (*i, [r.relative_time(), *e]))
                .collect();
            on_front.sort_by(|a, b| a.1[0].total_cmp(&b.1[0]));
            p.line(Line::new("Pareto front", PlotPoints::from(on_front.iter().map(|(_, q)| *q).collect::<Vec<_>>())));
            for (i, q) in &on_front {
                p.text(
                    egui_plot::Text::new("", egui_plot::PlotPoint::new(q[0], q[1]), format!(" #{}", i + 1))
                        .anchor(egui::Align2::LEFT_BOTTOM),
                );
            }
        });
}

/// The rows: number, label (◆ on the front), times, paired verdicts, errors.
fn table(ui: &mut egui::Ui, rows: &[CostRow], of: ErrorOf, front: &[&str]) {
    egui::ScrollArea::both().show(ui, |ui| {
        egui::Grid::new("cost-table").striped(true).num_columns(8).show(ui, |ui| {
            let error_head = format!("{} %", of.label());
            for h in [
                "#",
                "setting",
                "wall, median",
                "wall vs reference",
                "CPU vs reference",
                "ΔMAE chl",
                &error_head,
                "chl p95 %",
            ] {
                ui.strong(h);
            }
            ui.end_row();
            for (i, r) in rows.iter().enumerate() {
                ui.label(format!("{}", i + 1));
                let label =
                    if front.contains(&r.label.as_str()) { format!("{} ◆", r.label) } else { r.label.clone() };
                ui.label(label)
                    .on_hover_text("◆: on the time–error Pareto front (no setting both measurably faster and closer)");
                ui.label(format!("{:.2} s", r.time.wall_s)).on_hover_text(format!(
                    "{}; CPU {}",
                    r.time.wall_text(),
                    r.time.cpu_text()
                ));
                if i == 0 {
                    ui.label("–");
                    ui.label(format!("– ({} CPU)", r.time.cpu_text()));
                } else {
                    ui.label(r.comparison.text());
                    ui.label(r.cpu_comparison.map_or_else(|| "–".into(), |c| c.text()));
                }
                ui.label(format!("{:+.2}", r.delta_mae_pct));
                ui.label(r.error_pct(of).map_or_else(|| "other grid".into(), |v| format!("{v:.3}")));
                ui.label(
                    r.errors.chl_p95_pct.filter(|v| v.is_finite()).map_or_else(|| "–".into(), |v| format!("{v:.3}")),
                );
                ui.end_row();
            }
        });
    });
}
