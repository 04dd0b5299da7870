//! The left panel: the preset library (instruments A and B, scene, study), the instrument editor
//! with units, tooltips and A/B links, the band editor, and the retrieval, seeds, preview and
//! requirement settings (the derived figures and feasibility checks are in `derived`).

use super::ShoalApp;
use super::logic::UiCommand;
use super::model::{Ab, RetrievalKind, Slot};
use super::params::PARAMS;
use crate::instrument::InstrumentKind;
use crate::library::{Entry, Kind};
use crate::retrieval::{Mode, Objective, Starts};
use crate::spectral::{BandSetSpec, GaussianBand, Platform};

fn library_combo(ui: &mut egui::Ui, label: &str, current: &str, entries: &[Entry]) -> Option<Entry> {
    let mut picked = None;
    egui::ComboBox::from_label(label).selected_text(current).show_ui(ui, |ui| {
        for e in entries {
            let text = if e.builtin { e.name.clone() } else { format!("{} (mine)", e.name) };
            if ui.selectable_label(e.name == current, text).clicked() {
                picked = Some(e.clone());
            }
        }
    });
    picked
}

fn presets(app: &mut ShoalApp, ui: &mut egui::Ui) {
    ui.heading("Presets");
    let instruments = app.listing.get(Kind::Instrument).to_vec();
    for ab in Ab::BOTH {
        let current = app.state.slot(ab).preset.clone();
        if let Some(entry) = library_combo(ui, &format!("Instrument {}", ab.label()), &current, &instruments) {
            app.ui.commands.push(UiCommand::LoadInstrument { ab, entry });
        }
    }
    let scenes = app.listing.get(Kind::Scene).to_vec();
    if let Some(entry) = library_combo(ui, "Scene", &app.state.scene_name.clone(), &scenes) {
        app.ui.commands.push(UiCommand::LoadScene(entry));
    }
    let studies = app.listing.get(Kind::Study).to_vec();
    if let Some(entry) = library_combo(ui, "Study", &app.state.study_name.clone(), &studies) {
        app.ui.commands.push(UiCommand::LoadStudy(entry));
    }
}

fn save_presets(app: &mut ShoalApp, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        let l = ui.label("Preset name");
        ui.add(egui::TextEdit::singleline(&mut app.ui.preset_name).desired_width(130.0)).labelled_by(l.id);
    });
    ui.horizontal(|ui| {
        for ab in Ab::BOTH {
            let label = format!("Save {}", ab.label());
            if ui.button(label).on_hover_text("Save this instrument in your preset library").clicked() {
                let name = app.ui.preset_name.trim().to_string();
                app.ui.commands.push(UiCommand::SaveInstrument { ab, name });
            }
        }
        if ui.button("Save study").clicked() {
            let name = app.ui.preset_name.trim().to_string();
            app.ui.commands.push(UiCommand::SaveStudy { name });
        }
    });
}

fn band_editor(slot: &mut Slot, ui: &mut egui::Ui) {
    let bands = match &mut slot.spec.kind {
        InstrumentKind::Multispectral { bands }
        | InstrumentKind::IdealRadiometer { bands }
        | InstrumentKind::FilterImager { bands, .. } => bands,
        InstrumentKind::Spectrograph { start_nm, end_nm, sampling_nm, resolution_nm, .. } => {
            ui.add(
                egui::Slider::new(start_nm, 350.0..=700.0).update_while_editing(false).text("First band").suffix(" nm"),
            );
            ui.add(
                egui::Slider::new(end_nm, 500.0..=1000.0).update_while_editing(false).text("Last band").suffix(" nm"),
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
                        .range(380.0..=1000.0)
                        .speed(0.5)
                        .suffix(" c"),
                );
                ui.add(
                    egui::DragValue::new(&mut b.fwhm_nm)
                        .update_while_editing(false)
                        .range(1.0..=100.0)
                        .speed(0.2)
                        .suffix(" w"),
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
            let c = list.last().map_or(560.0, |b| (b.centre_nm + 20.0).min(990.0));
            list.push(GaussianBand { name: None, centre_nm: c, fwhm_nm: 10.0 });
        }
    }
}

/// Fine control on a slider rail: `value` moved by a tenth of `fraction` of the rail (the
/// pointer's motion over the rail's width), in the slider's own scale (log or linear), kept in
/// `range` (integer sliders have no fine mode: a tenth of a pixel's step rounds to nothing).
fn fine_step(value: f64, fraction: f32, range: (f64, f64), log: bool) -> f64 {
    let step = f64::from(fraction) / 10.0;
    let (lo, hi) = range;
    let moved = if log && lo > 0.0 && value > 0.0 {
        (value.ln() + step * (hi.ln() - lo.ln())).exp()
    } else {
        value + step * (hi - lo)
    };
    // A value already outside the span (a typed one) is not pulled into it by a small drag.
    moved.clamp(lo.min(value), hi.max(value))
}

fn editor(app: &mut ShoalApp, ui: &mut egui::Ui) {
    ui.heading("Instrument");
    ui.horizontal(|ui| {
        ui.selectable_value(&mut app.state.editing, Ab::A, "Edit A");
        ui.selectable_value(&mut app.state.editing, Ab::B, "Edit B");
    });
    let editing = app.state.editing;
    let mut changed: Vec<(&'static str, f64)> = Vec::new();
    // Wider than egui's 100 px (on which a log slider jumped from 90 to 200 mm in a 20 px drag),
    // fixed so the panel does not grow with its own content; Shift held makes a drag of the rail
    // or of the number 10× finer.
    ui.spacing_mut().slider_width = 160.0;
    egui::Grid::new("params").num_columns(2).show(ui, |ui| {
        for p in &PARAMS {
            let slot = app.state.slot_mut(editing);
            let mut v = (p.get)(&slot.spec) * p.scale;
            let before = v;
            // Never clamped: a preset outside the slider's span keeps its value, and a typed
            // value outside it is checked against the instrument's documented range below.
            let slider = egui::Slider::new(&mut v, p.range.0..=p.range.1)
                .update_while_editing(false)
                .text(p.label)
                .suffix(p.unit)
                .logarithmic(p.log)
                .clamping(egui::SliderClamping::Never);
            let integer = matches!(p.key, "detectors" | "lines" | "adc_bits");
            let slider = if integer { slider.integer() } else { slider };
            // The hover text states the documented range (src/ranges.rs) a typed value must meet;
            // built only while the pointer is on the slider.
            let response = ui.add(slider);
            // Shift held on the rail: the pointer's motion moves the value a tenth as far, from
            // where it was (egui would jump to the pointer). A drag begun with Shift stays fine
            // to its release, even if Shift is let go first (egui also sets the value on the
            // release frame).
            let fine_id = response.id.with("fine");
            let interacting = !integer && response.interact_pointer_pos().is_some();
            let fine = interacting
                && (ui.input(|i| i.modifiers.shift) || ui.data(|d| d.get_temp::<bool>(fine_id)).unwrap_or(false));
            ui.data_mut(|d| {
                if fine {
                    d.insert_temp(fine_id, true);
                } else {
                    d.remove::<bool>(fine_id);
                }
            });
            if fine {
                v = fine_step(before, response.drag_delta().x / ui.spacing().slider_width, p.range, p.log);
            }
            response.on_hover_ui(|ui| {
                ui.label(p.tip);
                ui.label("Type a value and press Enter; hold Shift while dragging the slider or the number for 10× finer steps.");
                if let Some(r) = crate::ranges::ALL.iter().find(|r| r.field("instrument.") == p.key) {
                    ui.label(format!("Allowed: {} (`{}`)", r.allowed(), p.key));
                }
            });
            let mut linked = app.state.linked.iter().any(|k| k == p.key);
            if ui
                .checkbox(&mut linked, "link")
                .on_hover_text(format!("Link {} across A and B", p.label.to_lowercase()))
                .changed()
            {
                if linked {
                    app.state.linked.push(p.key.to_string());
                } else {
                    app.state.linked.retain(|k| k != p.key);
                }
            }
            ui.end_row();
            if let Some((key, message)) = &app.ui.param_error
                && *key == p.key
            {
                ui.colored_label(super::theme::FAIL, format!("refused: {message}"));
                ui.end_row();
            }
            if v != before {
                let slot = app.state.slot_mut(editing);
                let mut candidate = slot.spec.clone();
                (p.set)(&mut candidate, v / p.scale);
                match candidate.validate() {
                    Ok(()) => {
                        slot.spec = candidate;
                        changed.push((p.key, v / p.scale));
                        app.ui.param_error = None;
                    }
                    // The value is refused and the instrument keeps its last valid one.
                    Err(e) => app.ui.param_error = Some((p.key, e.to_string())),
                }
            }
        }
    });
    // Linked parameters follow to the other instrument.
    for (key, value) in changed {
        if app.state.linked.iter().any(|k| k == key)
            && let Some(p) = PARAMS.iter().find(|p| p.key == key)
        {
            let other = app.state.slot_mut(editing.other());
            (p.set)(&mut other.spec, value);
        }
    }
    let slot = app.state.slot_mut(editing);
    egui::CollapsingHeader::new("Bands").default_open(false).show(ui, |ui| band_editor(slot, ui));
    super::derived::derived(app, ui);
    super::derived::a_vs_b(app, ui);
}

fn settings(app: &mut ShoalApp, ui: &mut egui::Ui) {
    egui::CollapsingHeader::new("Retrieval, seeds, preview").default_open(true).show(ui, |ui| {
        let s = &mut app.state;
        ui.horizontal(|ui| {
            ui.selectable_value(&mut s.retrieval, RetrievalKind::Almi, "aLMI");
            ui.selectable_value(&mut s.retrieval, RetrievalKind::Sambuca, "SAMBUCA");
        });
        // Reference: the published code's behaviour, to reproduce published numbers; Improved:
        // Shoal's inversion, the design default.
        let mode = match s.retrieval {
            RetrievalKind::Almi => &mut s.almi.mode,
            RetrievalKind::Sambuca => &mut s.sambuca.mode,
        };
        ui.horizontal(|ui| {
            ui.label("Mode");
            ui.selectable_value(mode, Mode::Improved, "Improved")
                .on_hover_text("Shoal's inversion: what a design study should use");
            ui.selectable_value(mode, Mode::Reference, "Reference").on_hover_text(
                "The published code step for step (DEA aLMI; CSIRO SAMBUCA with SLSQP from one start), \
                 to reproduce the paper's numbers",
            );
        });
        let reference = *mode == Mode::Reference;
        match s.retrieval {
            RetrievalKind::Almi if reference => {
                ui.small("As DEA's code: unweighted least squares per set, a set dropped below 1e-5.");
            }
            RetrievalKind::Sambuca if reference => {
                ui.small("As the CSIRO package: distance f with NEDR, one start at (max − min)/2, SLSQP; stalls kept.");
            }
            RetrievalKind::Almi => {
                ui.checkbox(&mut s.almi.noise_weighting, "Noise weighting")
                    .on_hover_text("Weight each band by its noise (off: as the reference code)");
            }
            RetrievalKind::Sambuca => {
                egui::ComboBox::from_label("Objective").selected_text(format!("{:?}", s.sambuca.objective)).show_ui(
                    ui,
                    |ui| {
                        ui.selectable_value(&mut s.sambuca.objective, Objective::F, "F");
                        ui.selectable_value(&mut s.sambuca.objective, Objective::AlphaF, "AlphaF");
                        ui.selectable_value(&mut s.sambuca.objective, Objective::Lsq, "Lsq");
                    },
                );
                egui::ComboBox::from_label("Starts").selected_text(format!("{:?}", s.sambuca.starts)).show_ui(
                    ui,
                    |ui| {
                        ui.selectable_value(&mut s.sambuca.starts, Starts::Adaptive, "Adaptive");
                        ui.selectable_value(&mut s.sambuca.starts, Starts::Shallow, "Shallow");
                        ui.selectable_value(&mut s.sambuca.starts, Starts::ShallowAndDeep, "ShallowAndDeep");
                    },
                );
            }
        }
        ui.horizontal(|ui| {
            let l = ui.label("Scene seed");
            ui.add(egui::DragValue::new(&mut s.scene_seed).update_while_editing(false).range(0..=1_000_000).speed(1.0))
                .labelled_by(l.id);
            let l = ui.label("Noise seed");
            ui.add(egui::DragValue::new(&mut s.noise_seed).update_while_editing(false).range(0..=1_000_000).speed(1.0))
                .labelled_by(l.id);
        });
        let decimations = s.decimations();
        let (preview, finest) = (decimations[0], decimations.last().copied().unwrap_or(1));
        let (mut pre, mut fin) = (preview, finest);
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("Preview").selected_text(format!("1/{pre}")).show_ui(ui, |ui| {
                for d in [8, 16, 24, 32] {
                    ui.selectable_value(&mut pre, d, format!("1/{d}"));
                }
            });
            egui::ComboBox::from_label("Final")
                .selected_text(if fin == 1 { "full".to_string() } else { format!("1/{fin}") })
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut fin, 1, "full");
                    ui.selectable_value(&mut fin, 2, "1/2");
                    ui.selectable_value(&mut fin, 4, "1/4");
                });
        });
        if (pre, fin) != (preview, finest) {
            // Preview first, then 1/4 while the final level is finer, then the final level.
            s.decimations = [pre, 4, fin].into_iter().filter(|&d| d <= pre).collect();
        }
    });
    egui::CollapsingHeader::new("Requirements").default_open(false).show(ui, |ui| requirements_editor(app, ui));
}

/// Per product: largest MAE and |bias| (log-space, %) and smallest share returned; the SNR floor.
/// An unticked limit is not checked. The verdicts use these, as `shoal study` does.
fn requirements_editor(app: &mut ShoalApp, ui: &mut egui::Ui) {
    let r = &mut app.state.requirements;
    egui::Grid::new("requirements").num_columns(4).show(ui, |ui| {
        for h in ["", "MAE ≤ %", "|bias| ≤ %", "returned ≥ %"] {
            ui.strong(h);
        }
        ui.end_row();
        for (variable, label) in
            [("chl_mg_m3", "chl-a"), ("nap_g_m3", "NAP"), ("cdom_per_m", "CDOM"), ("depth_m", "depth")]
        {
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

/// The left panel.
pub fn left(app: &mut ShoalApp, ui: &mut egui::Ui) {
    presets(app, ui);
    save_presets(app, ui);
    ui.separator();
    editor(app, ui);
    ui.separator();
    settings(app, ui);
}

#[cfg(test)]
mod tests {
    use super::fine_step;

    #[test]
    fn a_fine_drag_moves_a_tenth_of_the_rail_in_the_sliders_own_scale() {
        // Linear 0–100: a whole rail's width moves 10.
        assert!((fine_step(50.0, 1.0, (0.0, 100.0), false) - 60.0).abs() < 1e-9);
        // Log 10–1000 (two decades): a whole rail's width is a fifth of a decade, ×10^0.2.
        let v = fine_step(100.0, 1.0, (10.0, 1000.0), true);
        assert!((v / 100.0 - 10f64.powf(0.2)).abs() < 1e-9, "{v}");
        // Kept in the span, but a typed value outside it is not pulled in.
        assert_eq!(fine_step(99.0, 1.0, (0.0, 100.0), false), 100.0);
        assert!((fine_step(150.0, -0.125, (0.0, 100.0), false) - 148.75).abs() < 1e-9);
    }
}
