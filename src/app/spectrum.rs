//! The spectrum window: the scene's TOA and water-leaving spectra, 350–2500 nm, at the point
//! clicked on a map, with each instrument's bands drawn over them and what each measured there
//! (its Level-1 radiance and corrected Rrs). Computed on a helper thread
//! ([`crate::engine::spectrum`]); the window never shows a spectrum of runs no longer on screen:
//! when a design changes, the same point is asked again of the new runs.

use std::sync::Arc;

use egui_plot::{Line, Plot, PlotPoints, Points, Polygon};

use super::ShoalApp;
use super::link::Standing;
use super::theme;
use crate::engine::RunOutput;
use crate::engine::spectrum::{InstrumentAtPoint, PointSpectrum, SpectrumMaker, instrument_at};
use crate::jobs::Worker;

/// What was clicked: which run's map, where on it (0–1 across and down the image).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pick {
    /// The design whose pixel is the point (0 = A, 1 = B, …).
    pub run: usize,
    /// Position on the map, 0–1 (x right, y down, as drawn).
    pub uv: (f32, f32),
}

/// A request: the runs on display and the pixel.
struct Request {
    runs: Vec<Option<Arc<RunOutput>>>,
    pick: Pick,
}

/// What the helper computes: the scene's spectrum, and per design with a run (its index) what its
/// bands measured there.
type AtPoint = (PointSpectrum, Vec<(usize, InstrumentAtPoint)>);

/// The helper's answer, tagged with the runs it was computed from.
struct Answer {
    from: Vec<Option<usize>>,
    pick: Pick,
    result: Result<AtPoint, String>,
}

/// The window's state.
#[derive(Default)]
pub struct SpectrumWindow {
    /// Open?
    pub open: bool,
    pick: Option<Pick>,
    worker: Option<Worker<Request, Answer>>,
    asked: Option<(Vec<Option<usize>>, Pick)>,
    shown: Option<Answer>,
}

/// Identity of a run on display (its output's address).
fn id(run: Option<&Arc<RunOutput>>) -> Option<usize> {
    run.map(|r| Arc::as_ptr(r) as usize)
}

/// The (row, column) of a run's image at map position `uv` (rows are drawn bottom-up).
fn pixel(out: &RunOutput, uv: (f32, f32)) -> (usize, usize) {
    let (rows, cols) = (out.viewing.lines(), out.viewing.columns());
    let c = ((uv.0 * cols as f32) as usize).min(cols.saturating_sub(1));
    let r = (((1.0 - uv.1) * rows as f32) as usize).min(rows.saturating_sub(1));
    (r, c)
}

fn compute(maker: &mut SpectrumMaker, req: &Request) -> Result<AtPoint, String> {
    let out = req.runs.get(req.pick.run).and_then(Option::as_ref).ok_or("no result of that design on display")?;
    let (row, col) = pixel(out, req.pick.uv);
    let spectrum = maker.at(out, row, col).map_err(|e| e.to_string())?;
    let instruments = req
        .runs
        .iter()
        .enumerate()
        .filter_map(|(i, r)| r.as_ref().map(|r| (i, instrument_at(r, &super::model::label(i), spectrum.ground_m))))
        .collect();
    Ok((spectrum, instruments))
}

impl SpectrumWindow {
    /// Show the spectrum at `pick`.
    pub fn pick(&mut self, pick: Pick) {
        self.pick = Some(pick);
        self.open = true;
    }

    /// Ask the helper for the picked point of the runs on display, unless already asked; take
    /// its answers.
    fn update(&mut self, runs: Vec<Option<Arc<RunOutput>>>, ctx: &egui::Context) -> Result<(), String> {
        let Some(pick) = self.pick else { return Ok(()) };
        let from: Vec<Option<usize>> = runs.iter().map(|r| id(r.as_ref())).collect();
        if self.worker.is_none() {
            let wake = ctx.clone();
            let mut maker = SpectrumMaker::default();
            let worker = Worker::spawn(
                "shoal-spectrum",
                move || wake.request_repaint(),
                move |req: Request| Answer {
                    from: req.runs.iter().map(|r| id(r.as_ref())).collect(),
                    pick: req.pick,
                    result: compute(&mut maker, &req),
                },
            )
            .map_err(|e| e.to_string())?;
            self.worker = Some(worker);
        }
        let worker = self.worker.as_ref().ok_or("no helper thread")?;
        let asked = Some((from, pick));
        if self.asked != asked && runs.get(pick.run).is_some_and(Option::is_some) {
            let _ = worker.request(Request { runs, pick });
            self.asked = asked;
        }
        if let Some(a) = worker.latest() {
            self.shown = Some(a);
        }
        Ok(())
    }
}

/// The window, when open.
pub fn spectrum_window(app: &mut ShoalApp, ctx: &egui::Context) {
    let runs: Vec<_> = (0..app.state.designs.len())
        .map(|i| match app.link.standing(i) {
            Standing::Current(s) => Some(s.output.clone()),
            _ => None,
        })
        .collect();
    let from: Vec<Option<usize>> = runs.iter().map(|r| id(r.as_ref())).collect();
    let w = &mut app.ui.spectrum;
    let failure = w.update(runs, ctx).err();
    let mut open = w.open;
    egui::Window::new("Spectrum at a point").open(&mut open).default_size([860.0, 620.0]).show(ctx, |ui| {
        let Some(pick) = w.pick else {
            ui.label("Click a map to see the scene's spectrum there.");
            return;
        };
        if let Some(f) = &failure {
            ui.colored_label(theme::FAIL, f);
        }
        let current = w.shown.as_ref().filter(|a| a.from == from && a.pick == pick);
        match current.map(|a| &a.result) {
            // The clicked instrument has no result of the configuration set (its run failed or
            // is on its way): nothing is computed from an earlier one.
            None if from.get(pick.run).is_none_or(Option::is_none) => {
                let who = super::model::label(pick.run);
                ui.label(format!(
                    "{who} has no result of the configuration set (failed or updating): the spectrum follows its run."
                ));
            }
            None => {
                ui.horizontal(|ui| {
                    ui.spinner();
                    ui.label("Computing the spectrum at the point clicked …");
                });
            }
            Some(Err(e)) => {
                ui.colored_label(theme::FAIL, format!("No spectrum: {e}"));
            }
            Some(Ok((s, at))) => {
                let (designs, instruments): (Vec<usize>, Vec<InstrumentAtPoint>) = at.iter().cloned().unzip();
                let colours: Vec<egui::Color32> = designs.into_iter().map(theme::design).collect();
                draw(ui, s, &instruments, &colours, pick);
            }
        }
    });
    app.ui.spectrum.open = open;
}

/// Caption, key and the two plots.
fn draw(
    ui: &mut egui::Ui,
    s: &PointSpectrum,
    instruments: &[InstrumentAtPoint],
    colours: &[egui::Color32],
    pick: Pick,
) {
    let who = super::model::label(pick.run);
    ui.label(format!(
        "{} at ({:.0}, {:.0}) m, row {}, column {} of {who}; sun zenith {:.1}°, view zenith {:.1}°; the model every nm{}.",
        if s.water { "Water" } else { "Land" },
        s.ground_m.0,
        s.ground_m.1,
        s.pixel.0,
        s.pixel.1,
        s.sun_zenith_deg,
        s.view_zenith_deg,
        if s.gases { ", gases included" } else { "; this scene's atmosphere leaves the gases out" },
    ));
    let at: Vec<String> =
        instruments.iter().filter_map(|i| i.pixel.map(|(r, c)| format!("{} row {r}, column {c}", i.label))).collect();
    if !at.is_empty() {
        ui.small(format!(
            "Measured at {}: each design's pixel nearest the point (the first of its block where the app keeps \
             one pixel per block).",
            at.join("; ")
        ));
    }
    ui.horizontal_wrapped(|ui| {
        ui.colored_label(theme::TRUTH, "—");
        ui.small("scene (truth)");
        ui.colored_label(theme::REFERENCE, "- -");
        ui.small("path radiance");
        for (k, inst) in instruments.iter().enumerate() {
            let c = colours[k];
            ui.colored_label(c, "▮ ●");
            let off = if inst.pixel.is_none() { " (point off its image)" } else { "" };
            ui.small(format!("{}: bands (FWHM) and what it measured{off}", inst.label));
        }
    });
    let height = (ui.available_height() - 30.0) / 2.0;
    let l_toa: Vec<[f64; 2]> = log_points(&s.wavelengths_nm, &s.l_toa_w_m2_sr_um);
    let l_path: Vec<[f64; 2]> = log_points(&s.wavelengths_nm, &s.l_path_w_m2_sr_um);
    let rrs: Vec<[f64; 2]> = log_points(&s.wavelengths_nm, &s.rrs_per_sr);
    let measured = |f: fn(&crate::engine::spectrum::BandAtPoint) -> Option<f64>| {
        instruments
            .iter()
            .map(|i| {
                i.bands.iter().filter_map(|b| f(b).filter(|v| *v > 0.0).map(|v| [b.centre_nm, v.log10()])).collect()
            })
            .collect::<Vec<Vec<[f64; 2]>>>()
    };
    let l1 = measured(|b| b.level1_w_m2_sr_um);
    let rrs_measured = measured(|b| b.rrs_per_sr);
    let toa_range = span(&[&l_toa, &l_path], &l1);
    panel(
        ui,
        "spectrum-toa",
        "TOA radiance (W m⁻² sr⁻¹ µm⁻¹), log scale",
        height,
        toa_range,
        (instruments, colours),
        |p| {
            p.line(Line::new("scene", PlotPoints::from(l_toa)).color(theme::TRUTH).width(1.5));
            p.line(
                Line::new("path radiance", PlotPoints::from(l_path))
                    .color(theme::REFERENCE)
                    .style(egui_plot::LineStyle::dashed_loose()),
            );
            for (k, pts) in l1.into_iter().enumerate() {
                let name = format!("{} Level-1", instruments[k].label);
                p.points(Points::new(name, pts).radius(4.0).color(colours[k]));
            }
        },
    );
    let rrs_label = if s.water { "Rrs (sr⁻¹), log scale" } else { "Rrs (sr⁻¹): land, none" };
    let rrs_range = span(&[&rrs], &rrs_measured);
    panel(ui, "spectrum-rrs", rrs_label, height, rrs_range, (instruments, colours), |p| {
        p.line(Line::new("scene Rrs", PlotPoints::from(rrs)).color(theme::TRUTH).width(1.5));
        for (k, pts) in rrs_measured.into_iter().enumerate() {
            let name = format!("{} Rrs", instruments[k].label);
            p.points(Points::new(name, pts).radius(4.0).color(colours[k]));
        }
    });
}

/// The log10 range of the curves and points, a tenth of a decade wider each way.
fn span(curves: &[&Vec<[f64; 2]>], points: &[Vec<[f64; 2]>]) -> (f64, f64) {
    let (lo, hi) = curves
        .iter()
        .flat_map(|c| c.iter())
        .chain(points.iter().flatten())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p[1]), b.max(p[1])));
    if lo.is_finite() { (lo - 0.1, hi + 0.1) } else { (-4.0, 0.0) }
}

/// (λ, log10 v) for the positive values.
fn log_points(x: &[f64], v: &[f64]) -> Vec<[f64; 2]> {
    x.iter().zip(v).filter(|(_, v)| **v > 0.0).map(|(x, v)| [*x, v.log10()]).collect()
}

/// One plot over 350–2500 nm with a log y axis, each instrument's bands shaded at their FWHM.
fn panel(
    ui: &mut egui::Ui,
    id: &str,
    y_label: &str,
    height: f32,
    y_range: (f64, f64),
    (instruments, colours): (&[InstrumentAtPoint], &[egui::Color32]),
    add: impl FnOnce(&mut egui_plot::PlotUi<'_>),
) {
    Plot::new(id)
        .height(height.max(120.0))
        .link_axis(egui::Id::unique("spectrum-x"), [true, false])
        .x_axis_label("wavelength (nm)")
        .y_axis_label(y_label)
        .include_x(crate::engine::spectrum::SPECTRUM_START_NM)
        .include_x(crate::engine::spectrum::SPECTRUM_END_NM)
        .y_grid_spacer(super::plots::log_grid)
        .y_axis_formatter(super::plots::log_label)
        .label_formatter(|h| {
            let egui_plot::HoverPosition::NearDataPoint { plot_name, position, .. } = h else { return None };
            Some(format!(
                "{plot_name}\n{:.0} nm → {}",
                position.x,
                crate::colormap::significant(10f64.powf(position.y), 3)
            ))
        })
        .show(ui, |p| {
            // The shading spans the data's decades (not the plot's bounds, which it would grow).
            let (lo, hi) = y_range;
            for (k, inst) in instruments.iter().enumerate() {
                let fill = colours[k].gamma_multiply(0.18);
                for b in &inst.bands {
                    let (a, z) = (b.centre_nm - b.fwhm_nm / 2.0, b.centre_nm + b.fwhm_nm / 2.0);
                    let corners = vec![[a, lo], [z, lo], [z, hi], [a, hi]];
                    p.polygon(
                        Polygon::new(format!("{} {}", inst.label, b.name), PlotPoints::from(corners))
                            .fill_color(fill)
                            .stroke(egui::Stroke::NONE),
                    );
                }
            }
            add(p);
        });
}
