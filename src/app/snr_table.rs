//! The SNR and NEΔL of every design per band, at the radiance a requirement states: the scene's
//! median water radiance, one radiance for every band, or a spectrum typed as (wavelength,
//! radiance) points — as IOCCG reports and mission requirements state SNR ("SNR ≥ 1000 at
//! L_typ"). NEΔL = L / SNR, the radiance difference the noise equals (W m⁻² sr⁻¹ µm⁻¹). The
//! numbers come from the engine's SNR stage (`RunConfig::snr_reference`); this panel only
//! draws them and edits the reference.

use super::ShoalApp;
use crate::spectral::{Extrapolation, SpectrumSource};

/// How the reference is given, as the editor shows it.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    Scene,
    Constant,
    Points,
}

fn mode_of(r: Option<&SpectrumSource>) -> Mode {
    match r {
        None => Mode::Scene,
        Some(SpectrumSource::Constant(_)) => Mode::Constant,
        Some(_) => Mode::Points,
    }
}

/// The editor of the reference radiance.
fn reference_editor(app: &mut ShoalApp, ui: &mut egui::Ui) {
    let r = &mut app.state.snr_reference;
    let before = mode_of(r.as_ref());
    let mut mode = before;
    ui.horizontal(|ui| {
        ui.label("SNR at");
        ui.selectable_value(&mut mode, Mode::Scene, "the scene's median water radiance");
        ui.selectable_value(&mut mode, Mode::Constant, "one radiance");
        ui.selectable_value(&mut mode, Mode::Points, "a spectrum");
    });
    if mode != before {
        *r = match mode {
            Mode::Scene => None,
            Mode::Constant => Some(SpectrumSource::Constant(40.0)),
            Mode::Points => Some(SpectrumSource::Table {
                wavelength_nm: vec![412.0, 560.0, 865.0],
                values: vec![60.0, 40.0, 10.0],
                outside: Extrapolation::Clamp,
            }),
        };
    }
    match r {
        Some(SpectrumSource::Constant(v)) => {
            ui.add(
                egui::DragValue::new(v)
                    .range(0.001..=10_000.0)
                    .speed(0.5)
                    .suffix(" W m⁻² sr⁻¹ µm⁻¹")
                    .update_while_editing(false),
            );
        }
        Some(SpectrumSource::Table { wavelength_nm, values, .. }) => {
            let mut remove = None;
            egui::Grid::new("snr-reference").num_columns(3).show(ui, |ui| {
                ui.strong("nm");
                ui.strong("W m⁻² sr⁻¹ µm⁻¹");
                ui.end_row();
                for (i, (w, v)) in wavelength_nm.iter_mut().zip(values.iter_mut()).enumerate() {
                    ui.add(egui::DragValue::new(w).range(350.0..=2500.0).speed(1.0).update_while_editing(false));
                    ui.add(egui::DragValue::new(v).range(0.001..=10_000.0).speed(0.5).update_while_editing(false));
                    if ui.small_button("remove").clicked() {
                        remove = Some(i);
                    }
                    ui.end_row();
                }
            });
            if let Some(i) = remove.filter(|_| wavelength_nm.len() > 2) {
                wavelength_nm.remove(i);
                values.remove(i);
            }
            if ui.small_button("add a point").clicked() {
                let w = wavelength_nm.last().map_or(560.0, |w| (w + 50.0).min(2500.0));
                let v = values.last().copied().unwrap_or(40.0);
                wavelength_nm.push(w);
                values.push(v);
            }
            // The table must increase in wavelength: sort it as typed.
            let mut pairs: Vec<(f64, f64)> = wavelength_nm.iter().copied().zip(values.iter().copied()).collect();
            pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
            pairs.dedup_by(|a, b| a.0 == b.0);
            (*wavelength_nm, *values) = pairs.into_iter().unzip();
            ui.small("Linear between the points, the end values beyond them.");
        }
        _ => {}
    }
}

/// The section: the reference's editor and the table of every design.
pub(super) fn snr_section(app: &mut ShoalApp, ui: &mut egui::Ui) {
    egui::CollapsingHeader::new("SNR and NEΔL per band").default_open(false).show(ui, |ui| {
        reference_editor(app, ui);
        let runs: Vec<Option<&crate::engine::RunOutput>> =
            (0..app.state.designs.len()).map(|i| app.link.current(i).map(|s| s.output.as_ref())).collect();
        let Some(bands) = runs.iter().flatten().next().map(|o| o.snr.len()) else {
            ui.label("No results of the configuration set yet.");
            return;
        };
        egui::ScrollArea::horizontal().id_salt("snr-scroll").show(ui, |ui| {
            egui::Grid::new("snr-table").striped(true).num_columns(3 + 2 * runs.len()).show(ui, |ui| {
                for h in ["band", "nm", "L (W m⁻² sr⁻¹ µm⁻¹)"] {
                    ui.strong(h);
                }
                for i in 0..runs.len() {
                    let ab = super::model::label(i);
                    for h in [format!("{ab} SNR"), format!("{ab} NEΔL")] {
                        ui.label(egui::RichText::new(h).strong().color(super::theme::design(i)));
                    }
                }
                ui.end_row();
                for b in 0..bands {
                    let first = runs.iter().flatten().next().and_then(|o| o.snr.get(b));
                    let Some(row) = first else { continue };
                    ui.label(&row.band);
                    ui.label(format!("{:.0}", row.centre_nm));
                    ui.label(format!("{:.2}", 1000.0 * row.radiance));
                    for run in &runs {
                        match run.and_then(|o| o.snr.get(b)) {
                            Some(r) if r.saturated() => {
                                ui.colored_label(super::theme::FAIL, "saturated").on_hover_text(format!(
                                    "{:.0} % of full scale at this radiance",
                                    100.0 * r.full_scale_fraction
                                ));
                                ui.label("–");
                            }
                            Some(r) => {
                                ui.label(format!("{:.0}", r.snr_analytic))
                                    .on_hover_text(format!("measured on the simulated patch: {:.0}", r.snr_measured));
                                let nedl = 1000.0 * r.radiance / r.snr_analytic;
                                ui.label(if nedl.is_finite() { format!("{nedl:.3}") } else { "–".into() });
                            }
                            None => {
                                ui.label("–");
                                ui.label("–");
                            }
                        }
                    }
                    ui.end_row();
                }
            });
        });
    });
}
