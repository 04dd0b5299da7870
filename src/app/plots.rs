//! The bottom panel: the metrics of A and B against the requirements, histograms of retrieved
//! and true values, the truth-vs-retrieved scatter, and the SNR per band against its requirement,
//! with the per-stage timings of the runs on display.

use egui_plot::{Bar, BarChart, HLine, Line, Plot, PlotPoints, Points};

use super::plot_data::PlotData;
use super::{ShoalApp, theme};
use crate::engine::{RunOutput, StageStatus};
use crate::metrics::Metrics;
use crate::study::Check;

fn pass(ok: bool) -> egui::RichText {
    if ok {
        egui::RichText::new("pass").color(theme::PASS)
    } else {
        egui::RichText::new("FAIL").color(theme::FAIL).strong()
    }
}

/// The verdict cell of a set of checks, the checks listed on hover.
fn verdict_cell(ui: &mut egui::Ui, checks: &[&Check]) {
    match crate::study::verdict(checks.iter().copied()) {
        Some(ok) => {
            let text = checks.iter().map(|c| c.describe()).collect::<Vec<_>>().join("\n");
            ui.label(pass(ok)).on_hover_text(text);
        }
        None => {
            ui.label("").on_hover_text("no requirement on this product (Requirements, left panel)");
        }
    }
}

/// The dominant-substrate confusion tables of A and B (rows: true class; cells: % of the row
/// retrieved as each class), when the retrieval unmixes substrates.
fn substrate_tables(app: &ShoalApp, ui: &mut egui::Ui) {
    for (i, s) in app.link.shown.iter().enumerate() {
        let Some(c) =
            s.as_ref().and_then(|s| s.output.retrievals.first()).and_then(|r| r.metrics.substrate_confusion.as_ref())
        else {
            continue;
        };
        let ab = if i == 0 { "A" } else { "B" };
        let accuracy = c.accuracy_pct().map_or_else(|| "–".into(), |a| format!("{a:.1} %"));
        egui::CollapsingHeader::new(format!("{ab}: dominant substrate, {accuracy} of pixels correct"))
            .id_salt(format!("confusion-{ab}"))
            .default_open(false)
            .show(ui, |ui| {
                egui::Grid::new(format!("confusion-grid-{ab}")).striped(true).show(ui, |ui| {
                    ui.strong("true \\ retrieved");
                    for name in &c.classes {
                        ui.strong(name.replace('_', " "));
                    }
                    ui.strong("correct");
                    ui.end_row();
                    for (t, row) in c.counts.iter().enumerate() {
                        let n: usize = row.iter().sum();
                        if n == 0 {
                            continue;
                        }
                        ui.label(c.classes[t].replace('_', " "));
                        for &k in row {
                            ui.label(format!("{:.0} %", 100.0 * k as f64 / n as f64))
                                .on_hover_text(format!("{k} of {n} pixels"));
                        }
                        ui.label(c.recall_pct(t).map_or_else(|| "–".into(), |r| format!("{r:.0} %")));
                        ui.end_row();
                    }
                });
            });
    }
}

fn metrics_table(app: &ShoalApp, ui: &mut egui::Ui, configs: &[crate::engine::RunConfig]) {
    let runs: Vec<Option<&RunOutput>> = app.link.shown.iter().map(|s| s.as_ref().map(|s| s.output.as_ref())).collect();
    // One judgement for app, export and CLI: `Requirements::check_run`.
    let checks: Vec<Vec<Check>> = runs
        .iter()
        .map(|run| {
            run.map_or_else(Vec::new, |o| {
                let metrics = o.retrievals.first().map(|r| &r.metrics);
                app.state.requirements.check_run(&o.config.instrument.name, o.config.seed, metrics, &o.snr)
            })
        })
        .collect();
    // The seed spread, when measured for these very designs.
    let spread = app.ui.seeds.spread_for(configs).unwrap_or_default();
    egui::Grid::new("metrics").num_columns(9).striped(true).show(ui, |ui| {
        for h in ["product", "A MAE", "A bias", "A returned", "A", "B MAE", "B bias", "B returned", "B"] {
            ui.strong(h);
        }
        ui.end_row();
        let variables: Vec<String> = runs
            .iter()
            .flatten()
            .flat_map(|o| o.retrievals.iter().flat_map(|r| r.metrics.variables.iter().map(|v| v.variable.clone())))
            .fold(Vec::new(), |mut acc, v| {
                if !acc.contains(&v) {
                    acc.push(v);
                }
                acc
            });
        for v in &variables {
            ui.label(crate::metrics::label(v)).on_hover_text(format!("`{v}`"));
            for (index, (run, checks)) in runs.iter().zip(&checks).enumerate() {
                let m: Option<&Metrics> = run.and_then(|o| o.retrievals.first()).and_then(|r| r.metrics.get(v));
                match m {
                    Some(m) if m.n == 0 => {
                        // Nothing returned: no MAE or bias to show (never "0.0 %").
                        ui.label("–").on_hover_text("no pixel returned");
                        ui.label("–").on_hover_text("no pixel returned");
                        ui.label(format!("{:.1} %", m.returned_pct));
                    }
                    Some(m) => {
                        let unit = crate::metrics::unit(v);
                        let in_units = format!(
                            "log-space MAE {:.1} %; mean |error| {:.3} {unit}, mean error {:+.3} {unit}, RMSE {:.3} {unit} ({} pixels)",
                            m.mae_pct(),
                            m.mean_abs_error,
                            m.mean_error,
                            m.rmse,
                            m.n
                        );
                        // Depth errors read in metres too (a log-space % alone hides whether 10 % is 0.2 m or 2 m).
                        let mut text = if unit == "m" {
                            format!("{:.1} % ({:.2} m)", m.mae_pct(), m.mean_abs_error)
                        } else {
                            format!("{:.1} %", m.mae_pct())
                        };
                        let mut hover = in_units;
                        let ab = if index == 0 { "A" } else { "B" };
                        if let Some(s) =
                            spread.iter().find(|s| s.instrument == ab && s.variable == *v).filter(|s| s.seeds > 1)
                        {
                            text.push_str(&format!(" ±{:.1}", s.mae_pct_std));
                            hover.push_str(&format!(
                                "\n± is the standard deviation of the MAE over {} noise seeds at 1/{} (mean {:.1} %, range {:.1}–{:.1} %)",
                                s.seeds, app.ui.seeds.decimation, s.mae_pct_mean, s.mae_pct_range.0, s.mae_pct_range.1
                            ));
                        }
                        ui.label(text).on_hover_text(hover);
                        ui.label(format!("{:+.1} %", m.bias_pct()));
                        ui.label(format!("{:.1} %", m.returned_pct));
                    }
                    None => {
                        for _ in 0..3 {
                            ui.label("–");
                        }
                    }
                }
                let mine: Vec<&Check> = checks.iter().filter(|c| c.variable.as_deref() == Some(v.as_str())).collect();
                verdict_cell(ui, &mine);
            }
            ui.end_row();
        }
        if app.state.requirements.snr.is_some() && runs.iter().any(Option::is_some) {
            ui.label("SNR, every band");
            for (run, checks) in runs.iter().zip(&checks) {
                let lowest = run.and_then(|o| o.snr.iter().map(|r| r.snr_analytic).reduce(f64::min));
                ui.label(lowest.map_or_else(|| "–".into(), |s| format!("lowest {s:.0}")));
                ui.label("");
                ui.label("");
                let mine: Vec<&Check> = checks.iter().filter(|c| c.variable.is_none()).collect();
                verdict_cell(ui, &mine);
            }
            ui.end_row();
        }
    });
    if runs.iter().flatten().next().is_none() {
        ui.label("No results yet.");
    }
}

/// Start (or cancel) the seed-spread runs, and say what the ± in the table means.
fn seed_controls(app: &mut ShoalApp, ui: &mut egui::Ui, configs: &[crate::engine::RunConfig]) {
    ui.horizontal(|ui| {
        let job = &mut app.ui.seeds;
        if job.busy() {
            let (done, total) = job.progress();
            ui.spinner();
            ui.label(format!("seed spread: {done} of {total} runs"));
            if ui.button("Cancel").clicked() {
                job.cancel();
            }
            return;
        }
        let start = ui
            .button("Seed spread")
            .on_hover_text("Rerun A and B over several detector-noise seeds; the table then shows ± the MAE's standard deviation over them");
        ui.add(egui::DragValue::new(&mut job.seeds).range(2..=20).suffix(" seeds").update_while_editing(false));
        ui.add(egui::DragValue::new(&mut job.decimation).range(1..=16).prefix("at 1/").update_while_editing(false));
        if start.clicked() {
            job.start(ui.ctx(), configs);
        } else if job.stale(configs) {
            ui.label(egui::RichText::new("stale: the designs changed").color(theme::WARN))
                .on_hover_text("The spread was measured for other designs; it is not shown. Run it again.");
        } else if !job.status.is_empty() {
            ui.label(&job.status);
        }
    });
}

/// The label of a log10 axis mark: the value itself at whole decades (0.1, 1, 10, 100), nothing
/// between them (the plots hold log10 values; a reader wants the concentration).
fn decade(log10: f64) -> String {
    if (log10 - log10.round()).abs() > 1e-6 {
        return String::new();
    }
    let e = log10.round() as i32;
    match e {
        -3..=-1 => format!("{:.*}", (-e) as usize, 10f64.powi(e)),
        0..=5 => format!("{}", 10i64.pow(e as u32)),
        _ => format!("1e{e}"),
    }
}

/// A plot's key, above the plot rather than over its data: a coloured swatch and name each.
fn key(ui: &mut egui::Ui, items: &[(&str, egui::Color32)]) {
    ui.horizontal(|ui| {
        for (name, colour) in items {
            ui.colored_label(*colour, "■");
            ui.small(*name);
        }
    });
}

/// The histograms of the truth, A and B. Computed on the raster thread with the maps
/// (app/plot_data.rs): a frame only draws.
fn histogram(app: &ShoalApp, ui: &mut egui::Ui, width: f32) -> egui::Rect {
    let empty = PlotData::default();
    let data = app.images.plot().unwrap_or(&empty);
    let name = crate::metrics::name(&data.variable);
    let unit = crate::metrics::unit(&data.variable);
    let edges = &data.edges_log10;
    ui.vertical(|ui| {
        ui.label(format!("{name}: histograms"));
        key(ui, &[("truth", theme::TRUTH), ("A", theme::INSTRUMENT[0]), ("B", theme::INSTRUMENT[1])]);
        Plot::new("hist")
            .width(width)
            .height(plot_height(ui))
            .x_axis_label(format!("{name} ({unit}), log scale"))
            .x_axis_formatter(|mark, _| decade(mark.value))
            .y_axis_label("% of water pixels")
            .show(ui, |p| {
                if edges.len() < 2 {
                    return;
                }
                let centre = |b: usize| 0.5 * (edges[b] + edges[b + 1]);
                let bw = (edges[1] - edges[0]) * 0.45;
                // Shares of each run's own water pixels: a preview beside a full-resolution run
                // compares as a distribution (A's bars sum to its returned %).
                let line: Vec<[f64; 2]> = data
                    .truth
                    .iter()
                    .enumerate()
                    .map(|(b, n)| [centre(b), PlotData::percent(*n, data.truth_pixels)])
                    .collect();
                p.line(Line::new("truth", PlotPoints::from(line)).color(theme::TRUTH).width(2.0));
                for (i, c) in data.counts.iter().enumerate() {
                    let offset = if i == 0 { -0.5 * bw } else { 0.5 * bw };
                    let bars: Vec<Bar> = c
                        .iter()
                        .enumerate()
                        .map(|(b, n)| Bar::new(centre(b) + offset, PlotData::percent(*n, data.pixels[i])).width(bw))
                        .collect();
                    p.bar_chart(BarChart::new(if i == 0 { "A" } else { "B" }, bars).color(theme::INSTRUMENT[i]));
                }
            });
    })
    .response
    .rect
}

/// The plots' height: 170 px up to a 950 px tall window, growing with it to 360 px (at 4K the
/// maps would otherwise take everything and leave the plots a strip).
fn plot_height(ui: &egui::Ui) -> f32 {
    (ui.ctx().content_rect().height() * 0.18).clamp(170.0, 360.0)
}

/// The bottom panel's first height: the plots, their titles and keys, and the timings line.
#[must_use]
pub fn panel_height(ctx: &egui::Context) -> f32 {
    (ctx.content_rect().height() * 0.18).clamp(170.0, 360.0) + 130.0
}

/// Retrieved against true values, log–log, with the 1:1 line.
fn scatter(app: &ShoalApp, ui: &mut egui::Ui, width: f32) -> egui::Rect {
    let empty = PlotData::default();
    let data = app.images.plot().unwrap_or(&empty);
    let name = crate::metrics::name(&data.variable);
    let unit = crate::metrics::unit(&data.variable);
    let edges = &data.edges_log10;
    ui.vertical(|ui| {
        ui.label(format!("{name}: retrieved vs true"));
        key(ui, &[("A", theme::INSTRUMENT[0]), ("B", theme::INSTRUMENT[1]), ("1:1", theme::REFERENCE)]);
        Plot::new("scatter")
            .width(width)
            .height(plot_height(ui))
            // The same decades on both axes (not `data_aspect`, which on a wide plot stretched
            // the x axis over 20 decades at 4K), so the 1:1 line is the box's diagonal.
            .include_x(edges.first().copied().unwrap_or(-1.0))
            .include_x(edges.last().copied().unwrap_or(1.0))
            .include_y(edges.first().copied().unwrap_or(-1.0))
            .include_y(edges.last().copied().unwrap_or(1.0))
            .x_axis_label(format!("true ({unit}), log scale"))
            .y_axis_label(format!("retrieved ({unit})"))
            .x_axis_formatter(|mark, _| decade(mark.value))
            .y_axis_formatter(|mark, _| decade(mark.value))
            .show(ui, |p| {
                for (i, d) in data.scatter.iter().enumerate() {
                    p.points(
                        Points::new(if i == 0 { "A" } else { "B" }, d.clone())
                            .radius(1.2)
                            .color(theme::INSTRUMENT[i].gamma_multiply(0.6)),
                    );
                }
                if let (Some(lo), Some(hi)) = (edges.first(), edges.last()) {
                    p.line(Line::new("1:1", PlotPoints::from(vec![[*lo, *lo], [*hi, *hi]])).color(theme::REFERENCE));
                }
            });
    })
    .response
    .rect
}

fn snr_plot(app: &ShoalApp, ui: &mut egui::Ui, width: f32) -> egui::Rect {
    ui.vertical(|ui| {
        ui.label("SNR per band (line: analytic, dots: measured)");
        key(ui, &[("A", theme::INSTRUMENT[0]), ("B", theme::INSTRUMENT[1]), ("requirement", theme::PASS)]);
        Plot::new("snr").width(width).height(plot_height(ui)).x_axis_label("wavelength (nm)").y_axis_label("SNR").show(
            ui,
            |p| {
                for (i, s) in app.link.shown.iter().enumerate() {
                    let Some(s) = s else { continue };
                    let name = if i == 0 { "A" } else { "B" };
                    let line: Vec<[f64; 2]> = s
                        .output
                        .snr
                        .iter()
                        .filter(|r| r.snr_analytic.is_finite())
                        .map(|r| [r.centre_nm, r.snr_analytic])
                        .collect();
                    let dots: Vec<[f64; 2]> = s
                        .output
                        .snr
                        .iter()
                        .filter(|r| r.snr_measured.is_finite())
                        .map(|r| [r.centre_nm, r.snr_measured])
                        .collect();
                    p.line(Line::new(name, PlotPoints::from(line)).color(theme::INSTRUMENT[i]).width(2.0));
                    p.points(Points::new(format!("{name} measured"), dots).radius(2.5).color(theme::INSTRUMENT[i]));
                }
                if let Some(snr) = app.state.requirements.snr {
                    p.hline(HLine::new("requirement", snr).color(theme::PASS));
                }
            },
        );
    })
    .response
    .rect
}

fn timings(app: &ShoalApp, ui: &mut egui::Ui) {
    egui::CollapsingHeader::new("Stage timings").default_open(false).show(ui, |ui| {
        for (i, s) in app.link.shown.iter().enumerate() {
            let Some(s) = s else { continue };
            let r = &s.output.report;
            let ran: Vec<String> = r
                .stages
                .iter()
                .map(|st| match st.status {
                    StageStatus::Ran => format!("{} {:.0} ms", st.stage, st.seconds * 1e3),
                    StageStatus::Cached => format!("{} cached", st.stage),
                })
                .collect();
            let skipped: Vec<String> = r.skipped_effects.iter().map(|e| format!("{:?}", e.effect)).collect();
            ui.label(format!(
                "{} (1/{}): {:.0} ms — {}; skipped: {}",
                if i == 0 { "A" } else { "B" },
                s.decimation,
                r.total_seconds * 1e3,
                ran.join(", "),
                if skipped.is_empty() { "none".into() } else { skipped.join(", ") }
            ));
        }
        if let Some(l) = app.link.last_latency_s {
            ui.label(format!("last change → preview: {:.0} ms", l * 1e3));
        }
    });
}

/// Smallest width of a plot before the plots move to a row of their own, then wrap.
pub const MIN_PLOT_WIDTH: f32 = 230.0;
const GAP: f32 = 8.0;

/// The bottom panel: the metrics table, then the histogram, scatter and SNR plots beside it
/// when the window is wide enough for all three at [`MIN_PLOT_WIDTH`], else in rows below it
/// (three, two or one to a row), so a plot never collapses to a sliver.
pub fn bottom(app: &mut ShoalApp, ui: &mut egui::Ui) {
    egui::ScrollArea::vertical().show(ui, |ui| {
        let total = ui.available_width();
        // The table's width as last drawn (it depends on the products shown).
        let table = app.ui.metrics_width.unwrap_or(560.0);
        let beside = total - table - GAP >= 3.0 * MIN_PLOT_WIDTH + 2.0 * GAP;
        let plots = |app: &ShoalApp, ui: &mut egui::Ui, room: f32| -> Vec<egui::Rect> {
            let per_row = (((room + GAP) / (MIN_PLOT_WIDTH + GAP)).floor() as usize).clamp(1, 3);
            let width = (room - GAP * (per_row - 1) as f32) / per_row as f32 - 4.0;
            let draw: [&dyn Fn(&mut egui::Ui) -> egui::Rect; 3] =
                [&|ui| histogram(app, ui, width), &|ui| scatter(app, ui, width), &|ui| snr_plot(app, ui, width)];
            let mut rects = Vec::new();
            for row in draw.chunks(per_row) {
                ui.horizontal_top(|ui| {
                    for d in row {
                        rects.push(d(ui));
                    }
                });
            }
            rects
        };
        let metrics = |app: &mut ShoalApp, ui: &mut egui::Ui| {
            let r = ui.vertical(|ui| {
                ui.strong("Metrics (log-space MAE and bias, Seegers et al. 2018)");
                // A and B as the engine would run them, built once per frame for both.
                let configs = app.state.configs();
                seed_controls(app, ui, &configs);
                metrics_table(app, ui, &configs);
                substrate_tables(app, ui);
                for (i, e) in app.link.errors.iter().enumerate() {
                    if let Some(e) = e {
                        ui.colored_label(theme::FAIL, format!("{}: {e}", if i == 0 { "A" } else { "B" }));
                    }
                }
            });
            app.ui.metrics_width = Some(r.response.rect.width());
        };
        let rects = if beside {
            ui.horizontal_top(|ui| {
                metrics(app, ui);
                plots(app, ui, total - table - GAP)
            })
            .inner
        } else {
            metrics(app, ui);
            plots(app, ui, total)
        };
        app.ui.plot_rects = rects;
        timings(app, ui);
    });
}

#[cfg(test)]
mod tests {
    #[test]
    fn log_axes_print_decades_as_values() {
        let t: Vec<String> = [-2.0, -1.0, 0.0, 1.0, 2.0, 0.5, 7.0].map(super::decade).to_vec();
        assert_eq!(t, ["0.01", "0.1", "1", "10", "100", "", "1e7"]);
    }
}
