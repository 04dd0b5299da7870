//! The left panel's editors of lists: an instrument's bands (a band set, or Gaussian bands one
//! by one) and the study's requirements (per product and the SNR and bottom-type floors).

use super::ShoalApp;
use super::model::Slot;
use crate::instrument::InstrumentKind;
use crate::spectral::{BandSetSpec, GaussianBand, Platform};

/// The bands of `slot`'s instrument: a spectrograph's range and sampling, or a band set.
pub(super) fn band_editor(slot: &mut Slot, ui: &mut egui::Ui) {
    let bands = match &mut slot.spec.kind {
        InstrumentKind::Multispectral { bands }
        | InstrumentKind::IdealRadiometer { bands }
        | InstrumentKind::FilterImager { bands, .. } => bands,
        InstrumentKind::Spectrograph { start_nm, end_nm, sampling_nm, resolution_nm, .. } => {
            ui.add(
                egui::Slider::new(start_nm, 350.0..=2400.0)
                    .update_while_editing(false)
                    .text("First band")
                    .suffix(" nm"),
            );
            ui.add(
                egui::Slider::new(end_nm, 400.0..=crate::ranges::MAX_SIMULATED_NM)
                    .update_while_editing(false)
                    .text("Last band")
                    .suffix(" nm"),
            );
            ui.add(
                egui::Slider::new(sampling_nm, 1.0..=30.0).update_while_editing(false).text("Sampling").suffix(" nm"),
            );
            ui.add(
                egui::Slider::new(resolution_nm, 1.0..=50.0)
                    .update_while_editing(false)
                    .text("Resolution")
                    .suffix(" nm"),
            );
            return;
        }
    };
    let name = match bands {
        BandSetSpec::Olci { platform: Platform::A, .. } => "OLCI S3A",
        BandSetSpec::Olci { .. } => "OLCI S3B",
        BandSetSpec::Msi { platform: Platform::A, .. } => "MSI S2A",
        BandSetSpec::Msi { .. } => "MSI S2B",
        BandSetSpec::Gaussian(_) => "Custom (Gaussian)",
        BandSetSpec::Combined(_) => "Combined",
    };
    let mut choice: Option<BandSetSpec> = None;
    egui::ComboBox::from_label("Band set").selected_text(name).show_ui(ui, |ui| {
        if ui.selectable_label(name == "OLCI S3A", "OLCI S3A").clicked() {
            choice = Some(BandSetSpec::Olci { platform: Platform::A, bands: None });
        }
        if ui.selectable_label(name == "OLCI S3B", "OLCI S3B").clicked() {
            choice = Some(BandSetSpec::Olci { platform: Platform::B, bands: None });
        }
        if ui.selectable_label(name == "MSI S2A", "MSI S2A").clicked() {
            choice = Some(BandSetSpec::Msi { platform: Platform::A, bands: None });
        }
        if ui.selectable_label(name == "MSI S2B", "MSI S2B").clicked() {
            choice = Some(BandSetSpec::Msi { platform: Platform::B, bands: None });
        }
        if ui.selectable_label(name.starts_with("Custom"), "Custom (Gaussian)").clicked() {
            // Start from the current bands' centres and widths.
            let list = crate::spectral::BandSet::from_spec(bands)
                .map(|set| {
                    set.bands
                        .iter()
                        .map(|b| GaussianBand {
                            name: Some(b.name.clone()),
                            centre_nm: b.centre_nm,
                            fwhm_nm: b.fwhm_nm,
                        })
                        .collect()
                })
                .unwrap_or_default();
            choice = Some(BandSetSpec::Gaussian(list));
        }
    });
    if let Some(c) = choice {
        *bands = c;
    }
    if let BandSetSpec::Gaussian(list) = bands {
        let mut remove = None;
        egui::Grid::new("bands").num_columns(4).striped(true).show(ui, |ui| {
            ui.label("band");
            ui.label("centre nm");
            ui.label("FWHM nm");
            ui.label("");
            ui.end_row();
            for (i, b) in list.iter_mut().enumerate() {
                ui.label(format!("{}", i + 1));
                ui.add(
                    egui::DragValue::new(&mut b.centre_nm)
                        .update_while_editing(false)
                        .range(crate::ranges::MIN_SIMULATED_NM..=crate::ranges::MAX_SIMULATED_NM)
                        .speed(0.5)
                        .fixed_decimals(1),
                );
                ui.add(
                    egui::DragValue::new(&mut b.fwhm_nm)
                        .update_while_editing(false)
                        .range(1.0..=300.0)
                        .speed(0.2)
                        .fixed_decimals(1),
                );
                if ui.small_button("remove").clicked() {
                    remove = Some(i);
                }
                ui.end_row();
            }
        });
        if let Some(i) = remove {
            list.remove(i);
        }
        if ui.button("Add band").clicked() {
            let c = list.last().map_or(560.0, |b| (b.centre_nm + 20.0).min(crate::ranges::MAX_SIMULATED_NM - 10.0));
            list.push(GaussianBand { name: None, centre_nm: c, fwhm_nm: 10.0 });
        }
    }
}

/// Per product: largest MAE and |bias| (log-space, %) and smallest share returned; the SNR floor.
/// An unticked limit is not checked. The verdicts use these, as `shoal study` does.
pub(super) fn requirements_editor(app: &mut ShoalApp, ui: &mut egui::Ui) {
    let r = &mut app.state.requirements;
    egui::Grid::new("requirements").num_columns(4).show(ui, |ui| {
        for h in ["", "MAE ≤ %", "|bias| ≤ %", "returned ≥ %"] {
            ui.strong(h);
        }
        ui.end_row();
        for (variable, label) in crate::variable::PRODUCTS.map(|v| (v.key, v.name)) {
            // Edit a copy; the study's list changes only when a limit does (a product with no
            // limit left is dropped from it).
            let before = r.for_variable(variable).cloned();
            let mut p = before.clone().unwrap_or(crate::study::ProductRequirement {
                variable: variable.into(),
                mae_pct: None,
                bias_pct: None,
                returned_pct: None,
            });
            ui.label(label);
            optional_limit(ui, &mut p.mae_pct, 20.0, &crate::ranges::REQUIREMENT_MAE_PCT);
            optional_limit(ui, &mut p.bias_pct, 10.0, &crate::ranges::REQUIREMENT_BIAS_PCT);
            optional_limit(ui, &mut p.returned_pct, 95.0, &crate::ranges::REQUIREMENT_RETURNED_PCT);
            ui.end_row();
            if before.as_ref() != Some(&p) {
                r.products.retain(|q| q.variable != variable);
                if p.mae_pct.is_some() || p.bias_pct.is_some() || p.returned_pct.is_some() {
                    r.products.push(p);
                }
            }
        }
        ui.label("SNR ≥");
        optional_limit(ui, &mut r.snr, 100.0, &crate::ranges::REQUIREMENT_SNR);
        ui.end_row();
        ui.label("bottom type right ≥ %").on_hover_text(
            "Share of returned water pixels whose dominant substrate is the truth's (a retrieval that unmixes substrates)",
        );
        optional_limit(ui, &mut r.substrate_pct, 70.0, &crate::ranges::REQUIREMENT_SUBSTRATE_PCT);
        ui.end_row();
    });
}

/// A ticked limit with its value, clamped to the range's bounds; unticked: not checked.
fn optional_limit(ui: &mut egui::Ui, value: &mut Option<f64>, default: f64, range: &crate::ranges::Range) {
    ui.horizontal(|ui| {
        let mut on = value.is_some();
        if ui.checkbox(&mut on, "").on_hover_text(range.meaning).changed() {
            *value = on.then_some(value.unwrap_or(default));
        }
        if let Some(v) = value {
            ui.add(
                egui::DragValue::new(v)
                    .update_while_editing(false)
                    .range(range.lo..=range.hi.min(1e4))
                    .speed(0.5)
                    .max_decimals(1),
            );
        }
    });
}
