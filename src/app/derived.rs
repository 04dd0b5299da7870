//! The left panel's read-only figures of every design: derived figures (GSD, swath, f-number,
//! étendue, line period, peak SNR), the feasibility checks, and the parameters in which the
//! designs differ from the reference design.

use super::ShoalApp;
use super::model::label;
use crate::instrument::InstrumentSpec;

/// A grid's header row: an empty corner, then each design's letter in its colour.
fn design_header(ui: &mut egui::Ui, designs: usize) {
    ui.label("");
    for i in 0..designs {
        ui.colored_label(super::theme::design(i), label(i));
    }
    ui.end_row();
}

/// A derived figure: its name and how to compute it from an instrument.
type DerivedRow = (&'static str, fn(&InstrumentSpec) -> String);

pub(super) fn derived(app: &ShoalApp, ui: &mut egui::Ui) {
    egui::CollapsingHeader::new("Derived").default_open(true).show(ui, |ui| {
        let n = app.state.designs.len();
        egui::Grid::new("derived").num_columns(n + 1).striped(true).show(ui, |ui| {
            design_header(ui, n);
            // A binned design's GSD, swath, étendue and line period are its binned pixel's
            // (the instrument as flown).
            let rows: [DerivedRow; 13] = [
                ("GSD", |s| format!("{:.1} m", s.as_flown().gsd_m())),
                ("Swath", |s| format!("{:.1} km", s.as_flown().swath_m() / 1000.0)),
                ("f-number", |s| format!("f/{:.2}", s.f_number())),
                ("Étendue", |s| format!("{:.2e} m² sr", s.as_flown().etendue_m2_sr())),
                ("Line period", |s| {
                    let s = s.as_flown();
                    format!("{:.2} ms", 1e3 * s.gsd_m() / crate::instrument::ground_speed_m_s(s.altitude_km))
                }),
                ("Stray light 1 km past an edge", |s| {
                    crate::instrument::effects::edge_ratio(&s.effects, 1000.0, 443.0)
                        .map_or_else(|| "–".to_string(), |r| format!("{:.3} %", 100.0 * r))
                }),
                ("Polarisation sensitivity", |s| {
                    crate::instrument::effects::polarisation_sensitivity(&s.effects)
                        .map_or_else(|| "–".to_string(), |v| format!("{:.2} %", 100.0 * v))
                }),
                ("MTF at Nyquist, 560 nm", |s| {
                    use crate::instrument::effects::{MtfBudget, mtf::Axis, spatial_response};
                    let g = crate::instrument::spatial::first_plane_geometry(s);
                    let b = spatial_response(&s.effects).copied().unwrap_or_default();
                    let at = |axis| MtfBudget::at_nyquist(&b, &g, 560.0, axis);
                    format!("{:.2} / {:.2}", at(Axis::Along), at(Axis::Across))
                }),
                ("TDI stages", |s| {
                    crate::instrument::effects::tdi(&s.effects).map_or_else(
                        || "–".to_string(),
                        |t| format!("{} {}", t.stages, if t.digital { "digital" } else { "charge" }),
                    )
                }),
                ("Non-linearity left", |s| format!("{:.2} %", crate::study::nonlinearity_left_pct(s))),
                ("Registration left", |s| format!("{:.3} px", crate::study::registration_px(&s.as_flown()))),
                ("On-board coder", |s| {
                    crate::instrument::effects::compression(&s.effects).map_or_else(
                        || "–".to_string(),
                        |c| match (c.bits_per_sample > 0.0, c.max_error_dn) {
                            (true, _) => format!("≤ {:.1} bit", c.bits_per_sample),
                            (false, 0) => "lossless".to_string(),
                            (false, m) => format!("±{m} DN"),
                        },
                    )
                }),
                ("On-board binning", |s| {
                    crate::instrument::effects::binning(&s.effects)
                        .map_or_else(|| "–".to_string(), crate::instrument::effects::Binning::describe)
                }),
            ];
            // The optics rows only where a design has the effect (an ideal optic has no figure).
            let any = |has: fn(&InstrumentSpec) -> bool| app.state.designs.iter().any(|d| has(&d.spec));
            let stray =
                any(|s| s.effects.iter().any(|e| matches!(e, crate::instrument::InstrumentEffect::StrayLight(_))));
            let polarised = any(|s| crate::instrument::effects::polarisation_sensitivity(&s.effects).is_some());
            let mtf = any(|s| crate::instrument::effects::spatial_response(&s.effects).is_some());
            use crate::instrument::effects as fx;
            let shown = [
                stray,
                polarised,
                mtf,
                any(|s| fx::tdi(&s.effects).is_some()),
                any(|s| fx::non_linearity(&s.effects).is_some()),
                any(|s| fx::misregistration(&s.effects).is_some()),
                any(|s| fx::compression(&s.effects).is_some()),
                any(|s| fx::binning(&s.effects).is_some()),
            ];
            for (k, (name, f)) in rows.into_iter().enumerate() {
                // The first five rows always; each effect's only where a design states it.
                if k >= 5 && !shown[k - 5] {
                    continue;
                }
                ui.label(name);
                for d in &app.state.designs {
                    ui.label(f(&d.spec));
                }
                ui.end_row();
            }
            ui.label("Peak SNR");
            for i in 0..n {
                // Only the configuration set: a failed or pending run shows no figure.
                let snr = app
                    .link
                    .current(i)
                    .map(|s| s.output.snr.iter().map(|r| r.snr_analytic).fold(0.0, f64::max))
                    .map_or_else(|| "–".to_string(), |v| format!("{v:.0}"));
                ui.label(snr);
            }
            ui.end_row();
        });
        ui.small("Peak SNR: the best band at the scene's median radiance.");
        if app.state.designs.iter().any(|d| !d.spec.effects.is_empty()) {
            ui.small(
                "Stray light: the 443 nm signal 1 km into the dark half of a half-bright field, relative \
                 to the bright half. MTF: along / across track on the first focal plane (an ideal \
                 optic's for a design with no MTF budget; `shoal mtf` gives every band).",
            );
        }
    });
    feasibility(app, ui);
}

/// Cost, box and data budgets of every design under the built-in models (src/instrument/budgets),
/// from the bands of the run on screen; inside the folded Feasibility section.
fn budgets(app: &ShoalApp, ui: &mut egui::Ui) {
    use crate::instrument::budgets::BudgetModels;
    static MODELS: std::sync::OnceLock<Option<BudgetModels>> = std::sync::OnceLock::new();
    let Some(models) = MODELS.get_or_init(|| BudgetModels::default_models().ok()) else { return };
    let rows: Vec<Option<Vec<(String, String)>>> = (app.state.designs.iter().enumerate())
        .map(|(i, d)| {
            app.link.current(i).map(|s| models.assess(&d.spec.as_flown(), &s.output.response.plane_of_band).rows())
        })
        .collect();
    ui.separator();
    ui.strong("Budgets");
    {
        egui::Grid::new("budgets").num_columns(rows.len() + 1).striped(true).show(ui, |ui| {
            design_header(ui, rows.len());
            let n = rows.iter().flatten().map(Vec::len).next().unwrap_or(0);
            for k in 0..n {
                let name = rows.iter().flatten().next().map_or(String::new(), |r| r[k].0.clone());
                ui.label(name);
                for r in &rows {
                    ui.label(r.as_ref().map_or_else(|| "–".to_string(), |r| r[k].1.clone()));
                }
                ui.end_row();
            }
        });
        ui.small(format!(
            "Models `{}`: telescope cost by Stahl (2020), FY2017 US$ M, for apertures of {}–{} m; box, packaging and downlink as in presets/budgets.",
            models.name, models.cost.valid_aperture_m.0, models.cost.valid_aperture_m.1
        ));
    }
}

/// A value coloured by how far it is from sensible: red past a hard limit, amber near one.
fn graded(ui: &mut egui::Ui, text: String, level: u8, why: &str) {
    let colour = match level {
        0 => ui.visuals().text_color(),
        1 => super::theme::WARN,
        _ => super::theme::FAIL,
    };
    ui.colored_label(colour, text).on_hover_text(why);
}

/// The engine's `Feasibility` stage for every design over this scene
/// (src/instrument/feasibility.rs).
fn feasibility(app: &ShoalApp, ui: &mut egui::Ui) {
    use crate::instrument::feasibility::{Q_DETECTOR_LIMITED, Q_OPTICS_LIMITED, SATURATION_HEADROOM};
    let figures: Vec<_> =
        (0..app.state.designs.len()).map(|i| app.link.current(i).map(|s| s.output.feasibility.clone())).collect();
    // The warnings stay in sight; the figures behind them fold away.
    for (i, figure) in figures.iter().enumerate() {
        for w in figure.iter().flat_map(|f| &f.warnings) {
            ui.colored_label(super::theme::FAIL, format!("{}: {}", label(i), w.message));
        }
    }
    egui::CollapsingHeader::new("Feasibility").default_open(false).show(ui, |ui| {
        egui::Grid::new("feasibility").num_columns(figures.len() + 1).striped(true).show(ui, |ui| {
            design_header(ui, figures.len());
            type Row = (&'static str, fn(&crate::instrument::feasibility::Feasibility) -> (String, u8), &'static str);
            let rows: [Row; 4] = [
                (
                    "Peak / full scale",
                    |f| {
                        let peak = f.bands.iter().map(|b| b.peak_fraction_of_full_scale).fold(0.0, f64::max);
                        (format!("{:.0} %", 100.0 * peak), u8::from(peak >= SATURATION_HEADROOM) + u8::from(peak >= 1.0))
                    },
                    "Brightest water pixel's signal over full scale, worst band and detector: 100 % saturates",
                ),
                (
                    "Smear",
                    |f| (format!("{:.2} px", f.smear_px), 2 * u8::from(f.smear_px > 1.0)),
                    "Exposure over line period: the ground moves this many pixels during one exposure",
                ),
                (
                    "Optical Q",
                    |f| {
                        let (lo, hi) = f.bands.iter().fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x.q), b.max(x.q)));
                        (format!("{lo:.2}–{hi:.2}"), u8::from(lo < Q_DETECTOR_LIMITED || hi > Q_OPTICS_LIMITED))
                    },
                    "Q = λN/p over the bands (Fiete 1999): below 0.5 the pixel limits resolution (aliasing); above 2 the optics blur over two pixels",
                ),
                (
                    "ADC step / read noise",
                    |f| {
                        let r = f.quantisation_noise_e / f.read_noise_e.max(1e-9);
                        (format!("{:.2}", r), u8::from(r > 0.5))
                    },
                    "Quantisation noise gain/√12 over the read noise: above 0.5 the ADC step adds to the noise floor",
                ),
            ];
            for (name, f, why) in rows {
                ui.label(name).on_hover_text(why);
                for figure in &figures {
                    match figure {
                        Some(fig) => {
                            let (text, level) = f(fig);
                            graded(ui, text, level, why);
                        }
                        None => {
                            ui.label("–");
                        }
                    }
                }
                ui.end_row();
            }
        });
        budgets(app, ui);
    });
}

/// The parameters in which the designs differ from the reference design, which the user picks
/// (the review slide shows the same table).
pub(super) fn differences(app: &mut ShoalApp, ui: &mut egui::Ui) {
    let reference = app.state.reference;
    egui::CollapsingHeader::new(format!("Parameters against {}", label(reference)))
        .id_salt("parameters-against")
        .default_open(false)
        .show(ui, |ui| {
            let n = app.state.designs.len();
            ui.horizontal(|ui| {
                ui.label("Reference");
                for i in 0..n {
                    ui.selectable_value(&mut app.state.reference, i, label(i))
                        .on_hover_text(format!("Compare every design with {}", app.state.design_name(i)));
                }
            });
            // The reference first, then the others in order.
            let order: Vec<usize> = std::iter::once(reference).chain((0..n).filter(|&i| i != reference)).collect();
            let names: Vec<String> = order.iter().map(|&i| label(i)).collect();
            let designs: Vec<(&str, &InstrumentSpec, usize)> = order
                .iter()
                .zip(&names)
                .map(|(&i, name)| {
                    let bands = app.link.current(i).map_or(0, |s| s.output.response.bands.bands.len());
                    (name.as_str(), &app.state.designs[i].spec, bands)
                })
                .collect();
            let rows = super::params::differences(&designs);
            egui::Grid::new("differences").num_columns(n + 1).striped(true).show(ui, |ui| {
                for row in &rows {
                    for cell in row {
                        ui.label(cell);
                    }
                    ui.end_row();
                }
            });
        });
}
