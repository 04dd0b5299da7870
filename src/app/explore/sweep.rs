//! The Sweep window: any number of the run configuration from the range table (`src/ranges.rs`)
//! swept over a range for every design, optionally against a second one (a curve per value), with
//! noise seeds; the MAE of any product the retrieval makes, on a linear or log axis; where each
//! curve first meets its requirement; and the points where the design saturates marked, so a
//! jump in a curve is explained where it happens.

use egui_plot::{HLine, Line, Plot, PlotPoints, Points};

use super::Explore;
use crate::engine::RunConfig;
use crate::ranges::Range;
use crate::sweep::{Requirement, Table};

/// The sweepable numbers of `config`: every range-table field that exists in it as a number
/// (an instrument kind's own fields only for that kind; map values, study thresholds and
/// `shoal atmosphere`'s inputs are not run numbers).
#[must_use]
pub fn sweepable(config: &RunConfig) -> Vec<&'static Range> {
    crate::ranges::ALL
        .iter()
        .filter(|r| {
            !r.path.contains("[i]") && !r.path.starts_with("requirements.") && !r.path.starts_with("atmosphere_run.")
        })
        .filter(|r| crate::sweep::value(config, r.path).is_some())
        .collect()
}

/// A range to start from for `range` at the current value `now`: half to twice it, inside the
/// field's range (the whole range when the value is 0).
#[must_use]
pub fn default_span(range: &Range, now: f64) -> (f64, f64) {
    let (lo, hi) = if now > 0.0 { (now / 2.0, now * 2.0) } else { (range.lo, range.hi) };
    let clamp = |v: f64| {
        let v = v.clamp(range.lo, range.hi);
        if range.whole { v.round() } else { v }
    };
    let (a, b) = (clamp(lo), clamp(hi));
    if a < b { (a, b) } else { (range.lo, range.hi) }
}

/// The core variables ([`crate::variable::KEYS`]) the retrievals of `config` make, in that order.
fn variables(config: &RunConfig) -> Vec<&'static str> {
    let made: Vec<String> = config.retrievals.iter().flat_map(|r| r.algorithm().variables()).collect();
    crate::variable::KEYS.into_iter().filter(|k| made.iter().any(|m| m == k)).collect()
}

/// The requirement the curves of `variable` are judged against, when the app has one.
pub(super) fn requirement(state: &super::AppState, variable: &str) -> Option<Requirement> {
    let mae_pct = state.requirements.for_variable(variable)?.mae_pct?;
    Some(Requirement { variable: variable.into(), mae_pct })
}

/// The x values at which `instrument`'s run saturated (Level-0 pixel-bands at full scale).
fn saturated_at(table: &Table, instrument: &str, second: Option<f64>) -> Vec<f64> {
    let mut xs: Vec<f64> = table
        .rows
        .iter()
        .filter(|r| r.instrument == instrument && r.values.get(1).copied() == second && r.saturated_pct > 0.0)
        .map(|r| r.values[0])
        .collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    xs
}

/// The curves (A solid, B dashed, the seeds' range faint; a second parameter's values in their
/// own colours), the requirement, where it is met, and red rings where the design saturates.
fn sweep_plot(ui: &mut egui::Ui, e: &Explore, table: &Table, curves: &crate::study::Curves, x_label: &str) {
    let log = e.log;
    let log_y = e.log_y;
    let x_of = move |x: f64| if log { x.log10() } else { x };
    let y_of = move |y: f64| if log_y { y.max(0.1).log10() } else { y };
    let requirement = requirement_of(e);
    let (from, to) = (x_of(e.from), x_of(e.to));
    let colour_of = |k: usize| {
        if curves.series.len() <= 2 {
            super::super::theme::DESIGN.get(k).copied().unwrap_or_else(|| super::super::theme::category(k))
        } else {
            super::super::theme::category(k)
        }
    };
    // The key above the plot, not over its data.
    ui.horizontal_wrapped(|ui| {
        for (k, s) in curves.series.iter().enumerate() {
            ui.colored_label(colour_of(k), "■");
            ui.small(&s.label);
        }
        ui.colored_label(super::super::theme::FAIL, "○");
        ui.small("saturates");
        if requirement.is_some() {
            ui.colored_label(super::super::theme::PASS, "—");
            ui.small("requirement");
        }
    });
    let mut plot = Plot::new("sweep-plot")
        .x_axis_label(if log { format!("{x_label}, log scale") } else { x_label.to_string() })
        .y_axis_label(format!(
            "{} log-space MAE (%){}",
            crate::metrics::name(&e.variable),
            if log_y { ", log scale" } else { "" }
        ))
        // The axes from the sweep's range, not egui's −100…100 before the first point.
        .include_x(from.min(to))
        .include_x(from.max(to))
        .label_formatter(move |h| {
            let egui_plot::HoverPosition::NearDataPoint { plot_name, position, .. } = h else { return None };
            let x = if log { 10f64.powf(position.x) } else { position.x };
            let y = if log_y { 10f64.powf(position.y) } else { position.y };
            Some(format!("{plot_name}\n{} → MAE {y:.1} %", crate::colormap::significant(x, 3)))
        });
    plot = if log {
        plot.x_grid_spacer(crate::app::plots::log_grid).x_axis_formatter(crate::app::plots::log_label)
    } else {
        plot.x_axis_formatter(|mark, _| crate::colormap::significant(mark.value, 3))
    };
    plot = if log_y {
        plot.y_grid_spacer(crate::app::plots::log_grid).y_axis_formatter(crate::app::plots::log_label)
    } else {
        plot.include_y(0.0)
    };
    plot.show(ui, |p| {
        for (k, s) in curves.series.iter().enumerate() {
            let colour = colour_of(k);
            // The design list's name ("C: search 2"), the sweep's own kept for finding its rows.
            let name = e.shown_label(&s.label);
            // B dashed over A: identical instruments stay visible as two curves.
            let style = if k % 2 == 0 { egui_plot::LineStyle::Solid } else { egui_plot::LineStyle::dashed_loose() };
            let pts = |f: fn(&crate::study::CurvePoint) -> f64| {
                PlotPoints::from_iter(s.points.iter().map(|q| [x_of(q.x), y_of(f(q))]))
            };
            p.line(Line::new(name.clone(), pts(|q| q.mean)).color(colour).style(style).width(2.0));
            p.line(Line::new(format!("{name} lowest seed"), pts(|q| q.lo)).color(colour.gamma_multiply(0.4)));
            p.line(Line::new(format!("{name} highest seed"), pts(|q| q.hi)).color(colour.gamma_multiply(0.4)));
            if let (Some(r), Some(x)) = (&requirement, s.crossing) {
                p.points(
                    Points::new(format!("{name} meets"), vec![[x_of(x), y_of(r.mae_pct)]]).radius(6.0).color(colour),
                );
            }
            // Which run the series is: its instrument, and the second parameter's value.
            let (instrument, second) = series_key(table, &s.label);
            let rings: Vec<[f64; 2]> = saturated_at(table, &instrument, second)
                .into_iter()
                .filter_map(|x| s.points.iter().find(|q| q.x == x).map(|q| [x_of(x), y_of(q.mean)]))
                .collect();
            if !rings.is_empty() {
                p.points(
                    Points::new(format!("{name} saturates"), rings)
                        .radius(7.0)
                        .filled(false)
                        .color(super::super::theme::FAIL),
                );
            }
        }
        if let Some(r) = &requirement {
            p.hline(HLine::new("requirement", y_of(r.mae_pct)).color(super::super::theme::PASS));
        }
    });
}

/// The instrument and second-parameter value a series of `table` was drawn from (its label is
/// "instrument" or "instrument, path = value").
fn series_key(table: &Table, label: &str) -> (String, Option<f64>) {
    let (instrument, rest) = label.split_once(", ").unwrap_or((label, ""));
    let second = rest.rsplit_once(" = ").and_then(|(_, v)| v.parse::<f64>().ok()).and_then(|v| {
        table.rows.iter().filter_map(|r| r.values.get(1).copied()).find(|x| (x - v).abs() <= 1e-3 * v.abs().max(1e-9))
    });
    (instrument.to_string(), second)
}

fn requirement_of(e: &Explore) -> Option<Requirement> {
    e.requirement.clone().filter(|r| r.variable == e.variable)
}

fn labelled_drag(ui: &mut egui::Ui, label: &str, value: &mut f64, speed: f64) {
    let l = ui.label(label);
    ui.add(egui::DragValue::new(value).update_while_editing(false).speed(speed)).labelled_by(l.id);
}

/// A parameter choice: the field's path below its section and its meaning.
fn choice_text(r: &Range) -> String {
    let unit = if r.unit.is_empty() { String::new() } else { format!(" ({})", r.unit) };
    // The editor's name first where the registry gives one ("Aperture: instrument.aperture_mm").
    match &r.editor {
        Some(e) => format!("{}: {}{unit}", e.label, r.path),
        None => format!("{}{unit}", r.path),
    }
}

/// Where each curve first meets its requirement, in words.
fn describe_curves(
    ui: &mut egui::Ui,
    variable: &str,
    curves: &crate::study::Curves,
    requirement: Option<&Requirement>,
    name: &str,
    unit: &str,
) {
    for s in &curves.series {
        match (requirement, s.crossing) {
            (Some(r), Some(x)) => ui.label(format!(
                "{}: meets {} MAE ≤ {:.0} % from {name} = {} {unit}",
                s.label,
                crate::metrics::name(variable),
                r.mae_pct,
                crate::colormap::significant(x, 3)
            )),
            (Some(r), None) => ui.label(format!(
                "{}: does not meet {} MAE ≤ {:.0} % (so far)",
                s.label,
                crate::metrics::name(variable),
                r.mae_pct
            )),
            (None, _) => ui.label(format!("{}: no {} MAE requirement set", s.label, crate::metrics::name(variable))),
        };
    }
}

/// The sweep window.
pub fn sweep_window(app: &mut super::super::ShoalApp, ctx: &egui::Context) {
    let mut open = app.ui.explore.sweep_open;
    let mut start = false;
    let config = app.state.configs().swap_remove(0);
    let fields = sweepable(&config);
    egui::Window::new("Sweep").open(&mut open).default_size([680.0, 500.0]).show(ctx, |ui| {
        let e = &mut app.ui.explore;
        if !fields.iter().any(|r| r.path == e.param) {
            e.param = "instrument.aperture_mm".into();
        }
        ui.horizontal(|ui| {
            let before = e.param.clone();
            egui::ComboBox::from_label("Parameter").selected_text(e.param.as_str()).height(400.0).show_ui(ui, |ui| {
                for r in &fields {
                    ui.selectable_value(&mut e.param, r.path.to_string(), choice_text(r)).on_hover_text(r.meaning);
                }
            });
            if e.param != before
                && let Some(r) = fields.iter().find(|r| r.path == e.param)
            {
                (e.from, e.to) = default_span(r, crate::sweep::value(&config, r.path).unwrap_or(0.0));
                // The registry's scale where the editor has one (aperture on a log axis).
                e.log = r.editor.map_or(!r.whole, |ed| ed.log) && e.from > 0.0;
            }
            let (from_speed, to_speed) = (0.01 * e.from.abs().max(1e-3), 0.01 * e.to.abs().max(1e-3));
            labelled_drag(ui, "From", &mut e.from, from_speed);
            labelled_drag(ui, "To", &mut e.to, to_speed);
        });
        ui.horizontal(|ui| {
            let mut second = e.second.is_some();
            ui.checkbox(&mut second, "Against a second parameter")
                .on_hover_text("A curve per value of it (three values)");
            if second && e.second.is_none() {
                let r = fields.iter().find(|r| r.path == "instrument.exposure_s").or(fields.first());
                e.second = r.map(|r| {
                    let (a, b) = default_span(r, crate::sweep::value(&config, r.path).unwrap_or(0.0));
                    (r.path.to_string(), a, b)
                });
            } else if !second {
                e.second = None;
            }
            if let Some((path, a, b)) = &mut e.second {
                egui::ComboBox::from_id_salt("second").selected_text(path.as_str()).height(400.0).show_ui(ui, |ui| {
                    for r in &fields {
                        if ui.selectable_label(*path == r.path, choice_text(r)).clicked() {
                            *path = r.path.to_string();
                            (*a, *b) = default_span(r, crate::sweep::value(&config, r.path).unwrap_or(0.0));
                        }
                    }
                });
                labelled_drag(ui, "from", a, 0.01 * a.abs().max(1e-3));
                labelled_drag(ui, "to", b, 0.01 * b.abs().max(1e-3));
            }
        });
        ui.horizontal(|ui| {
            ui.add(egui::Slider::new(&mut e.steps, 2..=20).update_while_editing(false).text("Points"));
            ui.checkbox(&mut e.log, "Log spacing");
            ui.add(egui::Slider::new(&mut e.seeds, 1..=10).update_while_editing(false).text("Seeds"));
        });
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("MAE of").selected_text(crate::metrics::label(&e.variable)).show_ui(ui, |ui| {
                for v in variables(&config) {
                    ui.selectable_value(&mut e.variable, v.to_string(), crate::metrics::label(v));
                }
            });
            ui.checkbox(&mut e.log_y, "Log MAE axis");
            egui::ComboBox::from_label("Resolution").selected_text(format!("1/{}", e.decimation)).show_ui(ui, |ui| {
                for d in [2, 4, 8, 16, 24] {
                    ui.selectable_value(&mut e.decimation, d, format!("1/{d}"));
                }
            });
            let runs = app.state.designs.len() * e.steps * e.seeds as usize * if e.second.is_some() { 3 } else { 1 };
            if ui
                .button("Run sweep")
                .on_hover_text(format!("{runs} runs: every design at every value and seed"))
                .clicked()
            {
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
        e.requirement = requirement(&app.state, &e.variable);
        let requirement = requirement_of(e);
        if let Some(table) = &e.table {
            let mut curves = crate::sweep::figure::curves(table, &e.variable, requirement.as_ref(), false);
            let name = table.parameters.first().cloned().unwrap_or_default();
            let unit = crate::ranges::ALL.iter().find(|r| r.path == name).map_or("", |r| r.unit);
            describe_curves(ui, &e.variable, &curves, requirement.as_ref(), &name, unit);
            let x_label = if unit.is_empty() { name.clone() } else { format!("{name} ({unit})") };
            curves.series.retain(|s| !s.points.is_empty());
            sweep_plot(ui, e, table, &curves, &x_label);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_instrument_number_and_scene_number_can_be_swept_from_a_sensible_span() {
        let config = super::super::super::model::AppState::default().configs().swap_remove(0);
        let paths: Vec<&str> = sweepable(&config).iter().map(|r| r.path).collect();
        for p in [
            "instrument.aperture_mm",
            "instrument.pixel_pitch_um",
            "instrument.adc_bits",
            "instrument.detectors",
            "scene.sun.zenith_deg",
            "scene.atmosphere.aot550",
            "fidelity.band_nodes",
        ] {
            assert!(paths.contains(&p), "{p} is not offered: {paths:?}");
        }
        assert!(!paths.iter().any(|p| p.contains("Spectrograph")), "a multispectral imager has no spectrograph fields");
        assert!(!paths.iter().any(|p| p.starts_with("requirements.")));
        let bits =
            crate::ranges::ALL.iter().find(|r| r.path == "instrument.adc_bits").unwrap_or(&crate::ranges::ALL[0]);
        assert_eq!(default_span(bits, 12.0), (6.0, 16.0), "whole numbers, inside 1–16");
        let aperture = &crate::ranges::INSTRUMENT_APERTURE_MM;
        assert_eq!(default_span(aperture, 60.0), (30.0, 120.0));
    }
}
