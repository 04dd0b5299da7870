//! The bottom panel: the metrics of A and B against the requirements, histograms of retrieved
//! and true values, the truth-vs-retrieved scatter, and the SNR per band against its requirement,
//! with the per-stage timings of the runs on display.

use egui::Color32;
use egui_plot::{Bar, BarChart, HLine, Legend, Line, Plot, PlotPoints, Points};

use super::ShoalApp;
use crate::engine::{RunOutput, StageStatus};
use crate::metrics::{Metrics, bin_of, log_edges};
use crate::study::Check;

const COLOURS: [Color32; 2] = [Color32::from_rgb(228, 26, 28), Color32::from_rgb(55, 126, 184)];

fn pass(ok: bool) -> egui::RichText {
    if ok {
        egui::RichText::new("pass").color(Color32::from_rgb(40, 150, 40))
    } else {
        egui::RichText::new("FAIL").color(Color32::from_rgb(200, 40, 40)).strong()
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

fn metrics_table(app: &ShoalApp, ui: &mut egui::Ui) {
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
            ui.label(v.as_str());
            for (run, checks) in runs.iter().zip(&checks) {
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
                        if unit == "m" {
                            ui.label(format!("{:.1} % ({:.2} m)", m.mae_pct(), m.mean_abs_error)).on_hover_text(in_units);
                        } else {
                            ui.label(format!("{:.1} %", m.mae_pct())).on_hover_text(in_units);
                        }
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

/// log10 of the returned (retrieved) and true values of the shown product.
fn pairs(out: &RunOutput, variable: &str) -> Vec<(f64, f64)> {
    let Some(ret) = out.retrievals.first() else { return Vec::new() };
    let p = &ret.product;
    let r = &out.radiance;
    let (Some(truth), Some(got)) = (out.radiance.truth.map(variable), p.map(variable)) else { return Vec::new() };
    // A strided sample of at most ~4000 pixels, visited directly: a frame never walks the whole
    // truth array (2 M pixels at full resolution).
    let cols = truth.ncols().max(1);
    let step = (truth.len() / 4000).max(1);
    (0..truth.len())
        .step_by(step)
        .map(|k| (k / cols, k % cols))
        .filter(|&(i, j)| r.truth.land[[i, j]] == 0 && p.returned(i, j) && truth[[i, j]] > 0.0 && got[[i, j]] > 0.0)
        .map(|(i, j)| (f64::from(truth[[i, j]]).log10(), f64::from(got[[i, j]]).log10()))
        .collect()
}

fn histograms_and_scatter(app: &ShoalApp, ui: &mut egui::Ui, width: f32) {
    let variable = app.state.product.variable().unwrap_or("chl_mg_m3");
    let data: Vec<Vec<(f64, f64)>> =
        app.link.shown.iter().map(|s| s.as_ref().map(|s| pairs(&s.output, variable)).unwrap_or_default()).collect();
    let all: Vec<f64> = data.iter().flatten().flat_map(|p| [p.0, p.1]).collect();
    let (lo, hi) = all.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(*v), b.max(*v)));
    ui.vertical(|ui| {
        ui.label(format!("{variable}: histograms (log10)"));
        Plot::new("hist")
            .width(width)
            .height(170.0)
            .legend(Legend::default().position(egui_plot::Corner::LeftTop))
            .x_axis_label("log10 value")
            .show(ui, |p| {
                if lo.is_finite() && hi > lo {
                    let edges = log_edges(10f64.powf(lo), 10f64.powf(hi), 30);
                    let centre = |b: usize| 0.5 * (edges[b].log10() + edges[b + 1].log10());
                    let bw = (edges[1].log10() - edges[0].log10()) * 0.45;
                    let count = |values: &mut dyn Iterator<Item = f64>| {
                        let mut c = vec![0usize; 30];
                        for v in values {
                            if let Some(b) = bin_of(&edges, 10f64.powf(v)) {
                                c[b] += 1;
                            }
                        }
                        c
                    };
                    let truth = count(&mut data[0].iter().map(|p| p.0));
                    let line: Vec<[f64; 2]> = truth.iter().enumerate().map(|(b, n)| [centre(b), *n as f64]).collect();
                    p.line(Line::new("truth", PlotPoints::from(line)).color(Color32::GRAY).width(2.0));
                    for (i, d) in data.iter().enumerate() {
                        let c = count(&mut d.iter().map(|p| p.1));
                        let offset = if i == 0 { -0.5 * bw } else { 0.5 * bw };
                        let bars: Vec<Bar> = c
                            .iter()
                            .enumerate()
                            .map(|(b, n)| Bar::new(centre(b) + offset, *n as f64).width(bw))
                            .collect();
                        p.bar_chart(BarChart::new(if i == 0 { "A" } else { "B" }, bars).color(COLOURS[i]));
                    }
                }
            });
    });
    ui.vertical(|ui| {
        ui.label(format!("{variable}: retrieved vs true (log10)"));
        Plot::new("scatter")
            .width(width)
            .height(170.0)
            .data_aspect(1.0)
            .legend(Legend::default().position(egui_plot::Corner::LeftTop))
            .show(ui, |p| {
                for (i, d) in data.iter().enumerate() {
                    let pts: Vec<[f64; 2]> = d.iter().map(|(t, g)| [*t, *g]).collect();
                    p.points(
                        Points::new(if i == 0 { "A" } else { "B" }, pts)
                            .radius(1.2)
                            .color(COLOURS[i].gamma_multiply(0.6)),
                    );
                }
                if lo.is_finite() && hi > lo {
                    p.line(Line::new("1:1", PlotPoints::from(vec![[lo, lo], [hi, hi]])).color(Color32::DARK_GRAY));
                }
            });
    });
}

fn snr_plot(app: &ShoalApp, ui: &mut egui::Ui, width: f32) {
    ui.vertical(|ui| {
        ui.label("SNR per band (line: analytic, dots: measured)");
        Plot::new("snr")
            .width(width)
            .height(170.0)
            .legend(Legend::default().position(egui_plot::Corner::RightBottom))
            .x_axis_label("nm")
            .show(ui, |p| {
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
                    p.line(Line::new(name, PlotPoints::from(line)).color(COLOURS[i]).width(2.0));
                    p.points(Points::new(format!("{name} measured"), dots).radius(2.5).color(COLOURS[i]));
                }
                if let Some(snr) = app.state.requirements.snr {
                    p.hline(HLine::new("requirement", snr).color(Color32::from_rgb(40, 150, 40)));
                }
            });
    });
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

/// The bottom panel.
pub fn bottom(app: &mut ShoalApp, ui: &mut egui::Ui) {
    egui::ScrollArea::vertical().show(ui, |ui| {
        ui.horizontal_top(|ui| {
            ui.vertical(|ui| {
                ui.strong("Metrics (log-space MAE and bias, Seegers et al. 2018)");
                metrics_table(app, ui);
                for (i, e) in app.link.errors.iter().enumerate() {
                    if let Some(e) = e {
                        ui.colored_label(
                            Color32::from_rgb(200, 40, 40),
                            format!("{}: {e}", if i == 0 { "A" } else { "B" }),
                        );
                    }
                }
            });
            let width = ((ui.available_width() - 24.0) / 3.0).max(160.0);
            histograms_and_scatter(app, ui, width);
            snr_plot(app, ui, width);
        });
        timings(app, ui);
    });
}
