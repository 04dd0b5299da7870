//! The bottom panel: the metrics of every design against the requirements, histograms of retrieved
//! and true values, the truth-vs-retrieved scatter, and the SNR per band against its requirement,
//! with the per-stage timings of the runs on display.

use egui_plot::{Bar, BarChart, HLine, Line, Plot, PlotPoints, Points};

use super::metrics_table::{metrics_table, seed_controls, substrate_tables};
use super::model::label;
use super::plot_data::PlotData;
use super::{ShoalApp, theme};
use crate::engine::StageStatus;

/// Grid marks of a log10 axis at 1, 2, …, 9 × each decade in view (a decade's first mark
/// drawn strongest), so a range narrower than a decade (depths of 1–7 m) still has marks.
pub(super) fn log_grid(input: egui_plot::GridInput) -> Vec<egui_plot::GridMark> {
    let (lo, hi) = input.bounds;
    if !(lo.is_finite() && hi.is_finite() && hi > lo) || hi - lo > 40.0 {
        return Vec::new();
    }
    let mut marks = Vec::new();
    for e in (lo.floor() as i32)..=(hi.ceil() as i32) {
        for k in 1..=9 {
            let value = f64::from(e) + f64::from(k).log10();
            if (lo..=hi).contains(&value) {
                marks.push(egui_plot::GridMark { value, step_size: if k == 1 { 1.0 } else { 0.1 } });
            }
        }
    }
    marks
}

/// The label of a [`log_grid`] mark: the value at 1, 2 and 5 × a decade (every mark when less
/// than a decade is in view), nothing at the others.
pub(super) fn log_label(mark: egui_plot::GridMark, range: &std::ops::RangeInclusive<f64>) -> String {
    let span = range.end() - range.start();
    let value = 10f64.powf(mark.value);
    let mantissa = value / 10f64.powf(mark.value.floor());
    let k = mantissa.round();
    if (mantissa - k).abs() > 1e-6 || !(span < 1.2 || [1.0, 2.0, 5.0].contains(&k)) || (span > 4.0 && k != 1.0) {
        return String::new();
    }
    let e = mark.value.floor() as i32;
    if (-3..=5).contains(&e) {
        let decimals = usize::try_from(-e).unwrap_or(0);
        format!("{value:.decimals$}")
    } else {
        format!("{k}e{e}")
    }
}

/// A plot's key, above the plot rather than over its data: a coloured swatch and name each,
/// wrapped when the designs are many.
fn key(ui: &mut egui::Ui, items: &[(String, egui::Color32)]) {
    ui.horizontal_wrapped(|ui| {
        for (name, colour) in items {
            ui.colored_label(*colour, "■");
            ui.small(name.as_str());
        }
    });
}

/// The key items of the designs with results, then `extra`.
fn design_key(
    app: &ShoalApp,
    first: &[(&str, egui::Color32)],
    extra: &[(&str, egui::Color32)],
) -> Vec<(String, egui::Color32)> {
    let designs = (0..app.state.designs.len()).filter(|&i| {
        !matches!(app.link.standing(i), super::link::Standing::Failed(_) | super::link::Standing::Waiting)
    });
    first
        .iter()
        .map(|(n, c)| ((*n).to_string(), *c))
        .chain(designs.map(|i| (label(i), theme::design(i))))
        .chain(extra.iter().map(|(n, c)| ((*n).to_string(), *c)))
        .collect()
}

/// The histograms of the truth and every design. Computed on the raster thread with the maps
/// (app/plot_data.rs): a frame only draws.
fn histogram(app: &ShoalApp, ui: &mut egui::Ui, width: f32) -> egui::Rect {
    let empty = PlotData::default();
    let data = app.images.plot().unwrap_or(&empty);
    let name = crate::metrics::name(&data.variable);
    let unit = crate::metrics::unit(&data.variable);
    let edges = &data.edges_log10;
    ui.vertical(|ui| {
        ui.label(format!("{name}: histograms"));
        key(ui, &design_key(app, &[("truth", theme::TRUTH)], &[]));
        Plot::new("hist")
            .width(width)
            .height(plot_height(ui))
            .x_axis_label(format!("{name} ({unit}), log scale"))
            .x_grid_spacer(log_grid)
            .x_axis_formatter(log_label)
            .y_axis_label("% of water pixels")
            // The wheel scrolls the panel; these plots are read, not explored.
            .allow_scroll(false)
            .allow_zoom(false)
            .allow_drag(false)
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
                // The designs' bars side by side within each bin (two: half a bin each, as before).
                let drawn: Vec<usize> = (0..data.counts.len()).filter(|&i| data.pixels[i] > 0).collect();
                let width = 2.0 * bw / drawn.len().max(1) as f64;
                for (k, &i) in drawn.iter().enumerate() {
                    let offset = -bw + width * (k as f64 + 0.5);
                    let bars: Vec<Bar> = data.counts[i]
                        .iter()
                        .enumerate()
                        .map(|(b, n)| Bar::new(centre(b) + offset, PlotData::percent(*n, data.pixels[i])).width(width))
                        .collect();
                    p.bar_chart(BarChart::new(label(i), bars).color(theme::design(i)));
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
        key(ui, &design_key(app, &[], &[("1:1", theme::REFERENCE)]));
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
            .x_grid_spacer(log_grid)
            .y_grid_spacer(log_grid)
            .x_axis_formatter(log_label)
            .y_axis_formatter(log_label)
            .allow_scroll(false)
            .allow_zoom(false)
            .allow_drag(false)
            .label_formatter(move |h| {
                let egui_plot::HoverPosition::NearDataPoint { plot_name, position, .. } = h else { return None };
                Some(format!(
                    "{plot_name}: true {}, retrieved {} {unit}",
                    super::maps::format_value(10f64.powf(position.x)),
                    super::maps::format_value(10f64.powf(position.y))
                ))
            })
            .show(ui, |p| {
                for (i, d) in data.scatter.iter().enumerate() {
                    p.points(Points::new(label(i), d.clone()).radius(1.2).color(theme::design(i).gamma_multiply(0.6)));
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
        key(ui, &design_key(app, &[], &[("requirement", theme::PASS)]));
        Plot::new("snr")
            .width(width)
            .height(plot_height(ui))
            .x_axis_label("wavelength (nm)")
            .y_axis_label("SNR")
            // Ticks every 100 nm (egui's own spacing left this axis without labels).
            .x_grid_spacer(egui_plot::uniform_grid_spacer(|_| [50.0, 100.0, 500.0]))
            .x_axis_formatter(|mark, _| format!("{:.0}", mark.value))
            .allow_scroll(false)
            .allow_zoom(false)
            .allow_drag(false)
            .label_formatter(|h| {
                let egui_plot::HoverPosition::NearDataPoint { plot_name, position, .. } = h else { return None };
                Some(format!("{plot_name}: {:.0} nm, SNR {:.0}", position.x, position.y))
            })
            .show(ui, |p| {
                for i in 0..app.state.designs.len() {
                    let Some(s) = app.link.current(i) else { continue };
                    let name = label(i);
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
                    p.line(Line::new(name.as_str(), PlotPoints::from(line)).color(theme::design(i)).width(2.0));
                    p.points(Points::new(format!("{name} measured"), dots).radius(2.5).color(theme::design(i)));
                }
                if let Some(snr) = app.state.requirements.snr {
                    p.hline(HLine::new("requirement", snr).color(theme::PASS));
                }
            });
    })
    .response
    .rect
}

fn timings(app: &ShoalApp, ui: &mut egui::Ui) {
    egui::CollapsingHeader::new("Stage timings").default_open(false).show(ui, |ui| {
        for i in 0..app.state.designs.len() {
            let Some(s) = app.link.current(i) else { continue };
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
                label(i),
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
        // The widest the table has been drawn for these designs, stacked or beside the plots.
        // Beside them its grid comes out wider than stacked (egui lays it out again in a row), so
        // a width measured one way and used the other flipped the layout every frame and pushed
        // the plots past the window; the widest of both settles on a layout that holds.
        let designs = app.state.designs.len();
        let table = app.ui.metrics_width.filter(|(n, _)| *n == designs).map(|(_, w)| w);
        let beside = table.is_some_and(|t| total - t - GAP >= 3.0 * MIN_PLOT_WIDTH + 2.0 * GAP);
        let plots = |app: &ShoalApp, ui: &mut egui::Ui, room: f32| -> Vec<egui::Rect> {
            // No axes without data: a failed or pending configuration has nothing to plot.
            if (0..app.state.designs.len()).all(|i| {
                !matches!(app.link.standing(i), super::link::Standing::Current(_) | super::link::Standing::Earlier(_))
            }) {
                // The plots' room kept, so the panel does not shrink to the note and jump back.
                ui.allocate_ui(egui::vec2(room, plot_height(ui) + 40.0), |ui| {
                    ui.set_min_size(egui::vec2(room.min(MIN_PLOT_WIDTH), plot_height(ui) + 40.0));
                    ui.label("No results of the configuration set to plot.");
                });
                return Vec::new();
            }
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
                // The designs as the engine would run them, built once per frame for all.
                let configs = app.state.configs();
                seed_controls(app, ui, &configs);
                metrics_table(app, ui, &configs);
                substrate_tables(app, ui);
                for (i, e) in app.link.errors.iter().enumerate() {
                    if let Some(e) = e {
                        ui.colored_label(theme::FAIL, format!("{}: {e}", label(i)));
                    }
                }
            });
            r.response.rect.width()
        };
        let widest = |app: &mut ShoalApp, width: f32| {
            app.ui.metrics_width = Some((designs, table.map_or(width, |t| t.max(width))));
        };
        let rects = match table {
            Some(t) if beside => {
                ui.horizontal_top(|ui| {
                    let width = metrics(app, ui);
                    widest(app, width);
                    plots(app, ui, total - t - GAP)
                })
                .inner
            }
            _ => {
                let width = metrics(app, ui);
                widest(app, width);
                plots(app, ui, total)
            }
        };
        app.ui.plot_rects = rects;
        super::snr_table::snr_section(app, ui);
        timings(app, ui);
    });
}

#[cfg(test)]
mod tests {
    use egui_plot::{GridInput, GridMark};

    fn labels(lo: f64, hi: f64) -> Vec<String> {
        super::log_grid(GridInput { bounds: (lo, hi), base_step_size: 0.01 })
            .into_iter()
            .map(|m| super::log_label(m, &(lo..=hi)))
            .filter(|l| !l.is_empty())
            .collect()
    }

    #[test]
    fn log_axes_label_values_and_keep_marks_inside_a_decade() {
        // Depths of 1–7 m: less than a decade in view, every integer labelled.
        assert_eq!(labels(0.0, 0.85), ["1", "2", "3", "4", "5", "6", "7"]);
        // Three decades: 1, 2 and 5 of each.
        assert_eq!(labels(-1.0, 2.0), ["0.1", "0.2", "0.5", "1", "2", "5", "10", "20", "50", "100"]);
        // Wide: decades only, in exponent form far from 1.
        assert_eq!(labels(4.0, 9.0), ["10000", "100000", "1e6", "1e7", "1e8", "1e9"]);
        let m = GridMark { value: 0.5, step_size: 0.1 };
        assert_eq!(super::log_label(m, &(0.0..=3.0)), "", "a mark between 1-2-5 values is not labelled");
        assert!(super::log_grid(GridInput { bounds: (f64::NAN, 1.0), base_step_size: 0.1 }).is_empty());
    }
}
