//! The left panel's optics editor: the instrument's optical effects (stray light, polarisation
//! sensitivity, the MTF budget, spectral stray light; `instrument::effects`), each with what the processor knows of it. An edit is kept
//! only if the whole instrument still validates; otherwise the message says why.

use super::model::Slot;
use crate::instrument::effects::{
    InstrumentEffect, Knowledge, MtfBudget, Polarisation, SpectralStrayLight, StrayLight,
};

/// One number shown in `scale` × its stored unit (a focal plane's number otherwise).
fn number(ui: &mut egui::Ui, label: &str, value: &mut f64, range: (f64, f64), scale: f64, unit: &str) {
    let mut shown = *value * scale;
    super::planes::number(ui, label, &mut shown, range.0 * scale..=range.1 * scale, unit);
    *value = shown / scale;
}

/// What the processor knows of an effect.
fn knowledge(ui: &mut egui::Ui, k: &mut Knowledge) {
    ui.label("processor corrects it");
    ui.checkbox(&mut k.corrected, "");
    ui.end_row();
    if k.corrected {
        number(ui, "  its model's error", &mut k.error, (-1.0, 1.0), 100.0, " %");
    }
}

/// A stray light to start from: a 3 % halo at 550 nm out to 3 km, a 0.5 % veil (assumptions).
fn stray_light() -> InstrumentEffect {
    InstrumentEffect::StrayLight(StrayLight {
        halo_fraction: 0.03,
        knee_m: 40.0,
        slope: 2.5,
        radius_m: 3000.0,
        out_of_field_fraction: 0.005,
        wavelength_exponent: 2.0,
        correction: Knowledge::default(),
    })
}

/// A polarisation sensitivity to start from: 1 % (PACE OCI's requirement), axis along track.
fn polarisation() -> InstrumentEffect {
    InstrumentEffect::Polarisation(Polarisation {
        sensitivity: 0.01,
        per_band: Vec::new(),
        axis_deg: 0.0,
        correction: Knowledge::default(),
    })
}

/// An MTF budget to start from (assumptions of a good small telescope): a 30 % obstruction,
/// λ/16 RMS wavefront error at 550 nm, 2 µm diffusion, 2 % crosstalk, 2 µrad jitter.
fn mtf_budget() -> InstrumentEffect {
    InstrumentEffect::SpatialResponse(MtfBudget {
        obstruction: 0.3,
        wavefront_rms_nm: 34.0,
        pixel_fill: 1.0,
        diffusion_um: 2.0,
        crosstalk: 0.02,
        jitter_urad: 2.0,
    })
}

/// A spectral stray light to start from: 0.2 % of each band's light, over ~100 nm (assumption).
fn spectral_stray() -> InstrumentEffect {
    InstrumentEffect::SpectralStrayLight(SpectralStrayLight {
        fraction: 0.002,
        width_nm: 100.0,
        correction: Knowledge::default(),
    })
}

/// The optical effects of `slot`'s instrument.
pub(super) fn optics_editor(slot: &mut Slot, ui: &mut egui::Ui, error: &mut Option<String>) {
    ui.label("What the optics do between the pupil and the detector; none: an ideal optic.");
    let mut candidate = slot.spec.clone();
    let mut remove = None;
    for (i, effect) in candidate.effects.iter_mut().enumerate() {
        let title = match effect {
            InstrumentEffect::StrayLight(_) => "Stray light",
            InstrumentEffect::Polarisation(_) => "Polarisation sensitivity",
            InstrumentEffect::SpatialResponse(_) => "MTF budget",
            InstrumentEffect::SpectralStrayLight(_) => "Spectral stray light",
        };
        egui::CollapsingHeader::new(title).id_salt(("effect", i)).default_open(true).show(ui, |ui| {
            egui::Grid::new(("effect-grid", i)).num_columns(2).show(ui, |ui| match effect {
                InstrumentEffect::StrayLight(s) => {
                    number(ui, "halo at 550 nm", &mut s.halo_fraction, (0.0, 0.5), 100.0, " %");
                    number(ui, "knee", &mut s.knee_m, (0.1, 1e5), 1.0, " m");
                    number(ui, "slope", &mut s.slope, (0.5, 6.0), 1.0, "");
                    number(ui, "extent", &mut s.radius_m, (1.0, 50_000.0), 1.0, " m");
                    number(ui, "out-of-field veil", &mut s.out_of_field_fraction, (0.0, 0.5), 100.0, " %");
                    knowledge(ui, &mut s.correction);
                }
                InstrumentEffect::Polarisation(p) => {
                    number(ui, "sensitivity", &mut p.sensitivity, (0.0, 0.2), 100.0, " %");
                    number(ui, "axis from along track", &mut p.axis_deg, (-180.0, 180.0), 1.0, "°");
                    knowledge(ui, &mut p.correction);
                }
                InstrumentEffect::SpatialResponse(m) => {
                    number(ui, "central obstruction", &mut m.obstruction, (0.0, 0.8), 100.0, " %");
                    number(ui, "wavefront error RMS", &mut m.wavefront_rms_nm, (0.0, 70.0), 1.0, " nm");
                    number(ui, "pixel fill", &mut m.pixel_fill, (0.3, 1.0), 100.0, " %");
                    number(ui, "charge diffusion σ", &mut m.diffusion_um, (0.0, 20.0), 1.0, " µm");
                    number(ui, "crosstalk per neighbour", &mut m.crosstalk, (0.0, 0.2), 100.0, " %");
                    number(ui, "jitter RMS", &mut m.jitter_urad, (0.0, 100.0), 1.0, " µrad");
                }
                InstrumentEffect::SpectralStrayLight(s) => {
                    number(ui, "share scattered", &mut s.fraction, (0.0, 0.2), 100.0, " %");
                    number(ui, "spectral scale", &mut s.width_nm, (1.0, 5000.0), 1.0, " nm");
                    knowledge(ui, &mut s.correction);
                }
            });
            if ui.small_button("Remove").clicked() {
                remove = Some(i);
            }
        });
    }
    if let Some(i) = remove {
        candidate.effects.remove(i);
    }
    let has_stray = candidate.effects.iter().any(|e| matches!(e, InstrumentEffect::StrayLight(_)));
    let has_polarisation = candidate.effects.iter().any(|e| matches!(e, InstrumentEffect::Polarisation(_)));
    let has_mtf = candidate.effects.iter().any(|e| matches!(e, InstrumentEffect::SpatialResponse(_)));
    let has_spectral = candidate.effects.iter().any(|e| matches!(e, InstrumentEffect::SpectralStrayLight(_)));
    ui.horizontal_wrapped(|ui| {
        if !has_stray
            && ui.button("Add stray light").on_hover_text("A far-field halo and an out-of-field veil").clicked()
        {
            candidate.effects.push(stray_light());
        }
        if !has_polarisation
            && ui
                .button("Add polarisation sensitivity")
                .on_hover_text("The response depends on the light's linear polarisation")
                .clicked()
        {
            candidate.effects.push(polarisation());
        }
        if !has_mtf
            && ui
                .button("Add MTF budget")
                .on_hover_text("Sample the scene with the PSF of the optics, detector and motion")
                .clicked()
        {
            candidate.effects.push(mtf_budget());
        }
        if !has_spectral
            && ui
                .button("Add spectral stray light")
                .on_hover_text("Each band's light partly scattered into the others")
                .clicked()
        {
            candidate.effects.push(spectral_stray());
        }
    });
    if candidate != slot.spec {
        match candidate.validate() {
            Ok(()) => {
                slot.spec = candidate;
                *error = None;
            }
            Err(e) => *error = Some(e.to_string()),
        }
    }
    if let Some(e) = error {
        ui.add(egui::Label::new(egui::RichText::new(format!("Optics refused: {e}")).color(super::theme::FAIL)).wrap());
    }
}
