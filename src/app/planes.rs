//! The left panel's focal-plane editor: the instrument's further detectors (a SWIR InGaAs or
//! HgCdTe array beside the silicon one), each with the bands it holds and its own numbers. An
//! edit is kept only if the whole instrument still validates; otherwise the message says why.

use super::model::Slot;
use crate::instrument::{BandSelection, DarkLaw, DarkTemperature, DetectorMaterial, FocalPlane};
use crate::spectral::SpectrumSource;

/// A SWIR plane to start from: extended InGaAs for every band beyond 1000 nm, pixels twice the
/// first plane's, cooled to −20 °C.
fn swir_plane(first_pitch_um: f64, first_detectors: usize) -> FocalPlane {
    FocalPlane {
        name: "SWIR".into(),
        material: DetectorMaterial::ExtendedInGaAs,
        bands: BandSelection::Centres { from_nm: 1000.0, to_nm: 2500.0 },
        pixel_pitch_um: 2.0 * first_pitch_um,
        detectors: first_detectors.div_ceil(2),
        quantum_efficiency: SpectrumSource::Constant(0.7),
        dark_current_e_s: 1e5,
        dark_temperature: Some(DarkTemperature {
            reference_c: 20.0,
            operating_c: -20.0,
            law: DarkLaw::Arrhenius { activation_ev: 0.5 },
        }),
        read_noise_e: 100.0,
        well_depth_e: 1e6,
        gain_e_per_dn: 50.0,
        bias_dn: 100.0,
        adc_bits: 14,
        prnu: 0.0,
        dsnu_e: 0.0,
        exposure_s: None,
    }
}

/// One number of a plane: a drag value with its unit.
pub(super) fn number(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut f64,
    range: std::ops::RangeInclusive<f64>,
    unit: &str,
) {
    ui.label(label);
    let speed = 0.01 * value.abs().max(0.1);
    ui.add(egui::DragValue::new(value).range(range).speed(speed).suffix(unit).update_while_editing(false));
    ui.end_row();
}

/// The focal planes of `slot`'s instrument beyond the first.
pub(super) fn plane_editor(slot: &mut Slot, ui: &mut egui::Ui, error: &mut Option<String>) {
    ui.label("The instrument's own detector numbers are its first focal plane; a band sits there unless a plane below claims it.");
    let mut candidate = slot.spec.clone();
    let mut remove = None;
    for (i, p) in candidate.focal_planes.iter_mut().enumerate() {
        egui::CollapsingHeader::new(format!("{} ({})", p.name, p.material.label())).id_salt(("plane", i)).show(
            ui,
            |ui| {
                egui::Grid::new(("plane-grid", i)).num_columns(2).show(ui, |ui| {
                    ui.label("material");
                    egui::ComboBox::from_id_salt(("material", i)).selected_text(p.material.label()).show_ui(ui, |ui| {
                        for m in [
                            DetectorMaterial::Silicon,
                            DetectorMaterial::InGaAs,
                            DetectorMaterial::ExtendedInGaAs,
                            DetectorMaterial::Mct,
                        ] {
                            ui.selectable_value(&mut p.material, m, m.label());
                        }
                    });
                    ui.end_row();
                    ui.label("bands");
                    match &mut p.bands {
                        BandSelection::Centres { from_nm, to_nm } => {
                            ui.horizontal(|ui| {
                                ui.add(
                                    egui::DragValue::new(from_nm)
                                        .range(325.0..=2500.0)
                                        .suffix(" nm")
                                        .update_while_editing(false),
                                );
                                ui.label("to");
                                ui.add(
                                    egui::DragValue::new(to_nm)
                                        .range(325.0..=2500.0)
                                        .suffix(" nm")
                                        .update_while_editing(false),
                                );
                            });
                        }
                        BandSelection::Names(names) => {
                            let mut text = names.join(", ");
                            if ui.text_edit_singleline(&mut text).lost_focus() {
                                *names =
                                    text.split(',').map(|n| n.trim().to_string()).filter(|n| !n.is_empty()).collect();
                            }
                        }
                    }
                    ui.end_row();
                    number(ui, "pixel pitch", &mut p.pixel_pitch_um, 0.1..=100.0, " µm");
                    let mut detectors = p.detectors as f64;
                    number(ui, "detectors", &mut detectors, 1.0..=40_000.0, "");
                    p.detectors = detectors.round() as usize;
                    if let SpectrumSource::Constant(q) = &mut p.quantum_efficiency {
                        number(ui, "quantum efficiency", q, 0.0..=1.0, "");
                    }
                    number(ui, "dark current", &mut p.dark_current_e_s, 0.0..=1e9, " e⁻/s");
                    if let Some(t) = &mut p.dark_temperature {
                        number(ui, "  specified at", &mut t.reference_c, -273.0..=150.0, " °C");
                        number(ui, "  operating at", &mut t.operating_c, -273.0..=150.0, " °C");
                        match &mut t.law {
                            DarkLaw::Doubling { delta_c } => number(ui, "  doubles every", delta_c, 0.5..=50.0, " °C"),
                            DarkLaw::Arrhenius { activation_ev } => {
                                number(ui, "  activation energy", activation_ev, 0.05..=2.0, " eV")
                            }
                        }
                    }
                    number(ui, "read noise", &mut p.read_noise_e, 0.0..=1e5, " e⁻");
                    number(ui, "full well", &mut p.well_depth_e, 1.0..=1e9, " e⁻");
                    number(ui, "gain", &mut p.gain_e_per_dn, 0.01..=1e4, " e⁻/DN");
                    number(ui, "bias", &mut p.bias_dn, 0.0..=65_534.0, " DN");
                    let mut bits = f64::from(p.adc_bits);
                    number(ui, "ADC", &mut bits, 1.0..=16.0, " bits");
                    p.adc_bits = bits.round() as u32;
                });
                if ui.small_button("Remove this plane").clicked() {
                    remove = Some(i);
                }
            },
        );
    }
    if let Some(i) = remove {
        candidate.focal_planes.remove(i);
    }
    if ui
        .button("Add a SWIR focal plane")
        .on_hover_text("Extended InGaAs for the bands beyond 1000 nm; edit its numbers above")
        .clicked()
    {
        let mut plane = swir_plane(candidate.pixel_pitch_um, candidate.detectors);
        let n = candidate.focal_planes.len();
        if n > 0 {
            plane.name = format!("SWIR {}", n + 1);
        }
        candidate.focal_planes.push(plane);
    }
    if candidate != slot.spec {
        match candidate
            .validate()
            .map_err(|e| e.to_string())
            .and_then(|()| crate::instrument::Response::new(&candidate, 1.0).map(|_| ()).map_err(|e| e.to_string()))
        {
            Ok(()) => {
                slot.spec = candidate;
                *error = None;
            }
            Err(e) => *error = Some(e),
        }
    }
    if let Some(e) = error {
        ui.add(
            egui::Label::new(egui::RichText::new(format!("Focal plane refused: {e}")).color(super::theme::FAIL)).wrap(),
        );
    }
}
