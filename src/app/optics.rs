//! The left panel's optics and focal-plane editor: the instrument's effects (stray light,
//! polarisation sensitivity, the MTF budget, spectral stray light, non-linearity, fixed patterns,
//! misregistration, TDI, compression, spectral knowledge, binning; `instrument::effects`), each with what the processor knows of it. An edit is kept only if the
//! whole instrument still validates; otherwise the message says why.

use super::model::Slot;
use crate::instrument::effects::{
    Binning, Compression, FixedPatterns, InstrumentEffect, Knowledge, Misregistration, MtfBudget, NonLinearity,
    Polarisation, SpectralKnowledge, SpectralStrayLight, StrayLight, Tdi,
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

/// A non-linearity to start from: 1 % low at full well, a quadratic (a typical CMOS data sheet's
/// integral non-linearity), the calibration's curve 10 % wrong.
fn non_linearity() -> InstrumentEffect {
    InstrumentEffect::NonLinearity(NonLinearity {
        quadratic: -0.01,
        cubic: 0.0,
        per_band: Vec::new(),
        column_spread: 0.0,
        correction: Knowledge { corrected: true, error: 0.1 },
    })
}

/// Fixed patterns to start from: 0.1 % gain drift since calibration, 0.1 % dead elements
/// filled by the processor (assumptions).
fn fixed_patterns() -> InstrumentEffect {
    InstrumentEffect::FixedPatterns(FixedPatterns {
        gain_drift: 0.001,
        dead_fraction: 0.001,
        ..FixedPatterns::default()
    })
}

/// An effect the editor offers: its title, what it does, and where to start.
type Offer = (&'static str, &'static str, fn() -> InstrumentEffect);

/// Every effect the editor offers, in the order of its buttons.
const OFFERED: [Offer; 11] = [
    ("stray light", "A far-field halo and an out-of-field veil", stray_light),
    ("polarisation sensitivity", "The response depends on the light's linear polarisation", polarisation),
    ("MTF budget", "Sample the scene with the PSF of the optics, detector and motion", mtf_budget),
    ("spectral stray light", "Each band's light partly scattered into the others", spectral_stray),
    ("non-linearity", "The detector's response departs from a straight line", non_linearity),
    ("fixed patterns", "Striping, dead and hot elements left after the calibration", fixed_patterns),
    ("misregistration", "Each band's grid shifted from the others by a fraction of a pixel", misregistration),
    ("TDI", "Time-delay integration: each ground line integrated over N rows", tdi),
    ("compression", "On-board coding of Level-0: lossless, or near-lossless to a rate", compression),
    ("spectral knowledge error", "The bands' centres and widths differ from what the processor believes", spectral),
    ("on-board binning", "k × k pixels summed into one: SNR up, GSD and data down", binning),
];

/// Binning to start from: 2 × 2 in charge (a CCD's summing well).
fn binning() -> InstrumentEffect {
    InstrumentEffect::Binning(Binning { factor: 2, spectral: 1, digital: false })
}

/// A spectral knowledge error to start from: each band's centre known to 0.5 nm rms (an
/// assumption; Green (1998) asks a few per cent of the FWHM).
fn spectral() -> InstrumentEffect {
    InstrumentEffect::SpectralKnowledge(SpectralKnowledge {
        centre_nm: 0.0,
        sigma_nm: 0.5,
        per_band_nm: Vec::new(),
        draw: 0,
        width_pct: 0.0,
        smile_pct: 0.0,
    })
}

/// TDI to start from: 8 charge-domain stages, the line rate right to 0.1 %, a CTE of 0.99999
/// (assumptions of a good CCD).
fn tdi() -> InstrumentEffect {
    InstrumentEffect::Tdi(Tdi { stages: 8, digital: false, line_rate_error: 0.001, cte: 0.99999 })
}

/// A misregistration to start from: 0.1 px rms per band (a filter imager's requirement class),
/// co-registered by the processor to 20 % (assumptions).
fn misregistration() -> InstrumentEffect {
    InstrumentEffect::Misregistration(Misregistration {
        sigma_px: 0.1,
        per_band: Vec::new(),
        draw: 0,
        correction: Knowledge { corrected: true, error: 0.2 },
    })
}

/// Compression to start from: lossless (the rate is measured on the scene).
fn compression() -> InstrumentEffect {
    InstrumentEffect::Compression(Compression::default())
}

/// The effects of `slot`'s instrument.
pub(super) fn optics_editor(slot: &mut Slot, ui: &mut egui::Ui, error: &mut Option<String>) {
    ui.label("What the optics do between the pupil and the detector; none: an ideal optic.");
    let mut candidate = slot.spec.clone();
    let mut remove = None;
    for (i, effect) in candidate.effects.iter_mut().enumerate() {
        let kind = std::mem::discriminant(effect);
        let title = OFFERED.iter().find(|o| std::mem::discriminant(&o.2()) == kind).map_or("effect", |o| o.0);
        egui::CollapsingHeader::new(capitalised(title)).id_salt(("effect", i)).default_open(true).show(ui, |ui| {
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
                InstrumentEffect::NonLinearity(n) => {
                    number(ui, "quadratic at full well", &mut n.quadratic, (-0.2, 0.2), 100.0, " %");
                    number(ui, "cubic at full well", &mut n.cubic, (-0.2, 0.2), 100.0, " %");
                    number(ui, "spread between columns", &mut n.column_spread, (0.0, 1.0), 100.0, " %");
                    knowledge(ui, &mut n.correction);
                }
                InstrumentEffect::FixedPatterns(p) => {
                    number(ui, "gain drift since calibration", &mut p.gain_drift, (0.0, 0.1), 100.0, " %");
                    number(ui, "dark drift since calibration", &mut p.offset_drift_e, (0.0, 1000.0), 1.0, " e⁻");
                    number(ui, "dead elements", &mut p.dead_fraction, (0.0, 0.2), 100.0, " %");
                    number(ui, "hot elements", &mut p.hot_fraction, (0.0, 0.2), 100.0, " %");
                    number(ui, "  their extra dark current", &mut p.hot_dark_current_e_s, (0.0, 1e6), 1.0, " e⁻/s");
                    ui.label("processor fills dead elements");
                    ui.checkbox(&mut p.interpolate_dead, "");
                    ui.end_row();
                }
                InstrumentEffect::Misregistration(m) => {
                    number(ui, "band-to-band shift RMS", &mut m.sigma_px, (0.0, 5.0), 1.0, " px");
                    knowledge(ui, &mut m.correction);
                }
                InstrumentEffect::Tdi(t) => {
                    let mut stages = f64::from(t.stages);
                    number(ui, "stages", &mut stages, (1.0, 256.0), 1.0, "");
                    t.stages = stages.round() as u32;
                    ui.label("digital (summed reads)");
                    ui.checkbox(&mut t.digital, "");
                    ui.end_row();
                    number(ui, "line-rate error", &mut t.line_rate_error, (-0.1, 0.1), 100.0, " %");
                    number(ui, "charge transfer efficiency", &mut t.cte, (0.99, 1.0), 100.0, " %");
                }
                InstrumentEffect::SpectralKnowledge(k) => {
                    number(ui, "centre error, every band", &mut k.centre_nm, (-10.0, 10.0), 1.0, " nm");
                    number(ui, "  and per band RMS", &mut k.sigma_nm, (0.0, 5.0), 1.0, " nm");
                    number(ui, "width error", &mut k.width_pct, (-50.0, 100.0), 1.0, " %");
                    number(ui, "smile error", &mut k.smile_pct, (-100.0, 100.0), 1.0, " %");
                }
                InstrumentEffect::Binning(b) => {
                    let mut factor = f64::from(b.factor);
                    number(ui, "pixels summed (k × k)", &mut factor, (1.0, 16.0), 1.0, "");
                    b.factor = factor.round() as u32;
                    let mut spectral = f64::from(b.spectral);
                    number(ui, "spectral samples summed", &mut spectral, (1.0, 16.0), 1.0, "");
                    b.spectral = spectral.round() as u32;
                    ui.label("digital (summed reads)");
                    ui.checkbox(&mut b.digital, "");
                    ui.end_row();
                }
                InstrumentEffect::Compression(c) => {
                    let mut bound = f64::from(c.max_error_dn);
                    number(ui, "largest error", &mut bound, (0.0, 4096.0), 1.0, " DN");
                    c.max_error_dn = bound.round() as u32;
                    number(ui, "rate target (0: none)", &mut c.bits_per_sample, (0.0, 16.0), 1.0, " bit");
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
    ui.horizontal_wrapped(|ui| {
        for (title, what, start) in OFFERED {
            let fresh = start();
            let stated = candidate.effects.iter().any(|e| std::mem::discriminant(e) == std::mem::discriminant(&fresh));
            if !stated && ui.button(format!("Add {title}")).on_hover_text(what).clicked() {
                candidate.effects.push(fresh);
            }
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

/// `text` with its first letter capitalised.
fn capitalised(text: &str) -> String {
    let mut chars = text.chars();
    chars.next().map_or_else(String::new, |first| first.to_uppercase().chain(chars).collect())
}
