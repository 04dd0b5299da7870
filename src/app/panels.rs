//! The left panel: the designs (each a library instrument, added, removed, reordered, on the
//! maps or not), the scene and study presets, the instrument editor with units, tooltips and
//! links across designs, the band editor, and the retrieval, seeds, preview and
//! requirement settings (the derived figures and feasibility checks are in `derived`).

use super::ShoalApp;
use super::logic::UiCommand;
use super::model::{MAX_DESIGNS, label};
use super::params::{param, params};
use crate::library::{Entry, PresetKind};
use crate::retrieval::{Mode, Objective, Starts};

/// A preset picker: each entry with its description on hover, the chosen one's on the box.
fn library_combo(ui: &mut egui::Ui, label: &str, current: &str, entries: &[Entry]) -> Option<Entry> {
    library_combo_sized(ui, label, current, entries, None)
}

/// [`library_combo`] at a fixed width (`None`: egui's).
fn library_combo_sized(
    ui: &mut egui::Ui,
    label: &str,
    current: &str,
    entries: &[Entry],
    width: Option<f32>,
) -> Option<Entry> {
    let mut picked = None;
    let chosen = entries.iter().find(|e| e.name == current).map(|e| e.description.as_str()).unwrap_or_default();
    // Tall enough for the whole library at 1280 × 720 (the default height hid user presets
    // below ten built-in instruments).
    let height = 0.6 * ui.ctx().content_rect().height();
    let combo = egui::ComboBox::from_label(label).selected_text(current).height(height);
    let combo = if let Some(w) = width { combo.width(w) } else { combo };
    let r = combo.show_ui(ui, |ui| {
        for e in entries {
            let text = if e.builtin { e.name.clone() } else { format!("{} (mine)", e.name) };
            let item = ui.selectable_label(e.name == current, text);
            let item = if e.description.is_empty() { item } else { item.on_hover_text(&e.description) };
            if item.clicked() {
                picked = Some(e.clone());
            }
        }
    });
    if !chosen.is_empty() {
        r.response.on_hover_text(chosen);
    }
    picked
}

/// The designs: per design its colour, its instrument preset, whether it is edited and on the
/// maps, and buttons to move it up or down or remove it; then a menu to add one.
fn designs(app: &mut ShoalApp, ui: &mut egui::Ui) {
    ui.heading("Designs");
    let instruments = app.listing.get(PresetKind::Instrument).to_vec();
    let n = app.state.designs.len();
    egui::Grid::new("designs").num_columns(5).spacing([6.0, 4.0]).show(ui, |ui| {
        for i in 0..n {
            let name = label(i);
            ui.colored_label(super::theme::design(i), "■")
                .on_hover_text(format!("Design {name}'s colour in the plots"));
            let current = app.state.designs[i].preset.clone();
            let current = if app.state.designs[i].modified() { format!("{current}*") } else { current };
            if let Some(entry) = library_combo_sized(ui, &name, &current, &instruments, Some(118.0)) {
                app.ui.commands.push(UiCommand::LoadInstrument { design: i, entry });
            }
            ui.radio_value(&mut app.state.editing, i, "edit")
                .on_hover_text(format!("Show design {name} in the instrument editor below"));
            let mut mapped = app.state.on_maps.contains(&i);
            if ui.checkbox(&mut mapped, "map").on_hover_text(format!("Show design {name} on the maps")).changed() {
                if mapped {
                    app.state.on_maps.push(i);
                    app.state.on_maps.sort_unstable();
                } else {
                    app.state.on_maps.retain(|&k| k != i);
                }
            }
            ui.horizontal(|ui| {
                ui.spacing_mut().item_spacing.x = 2.0;
                if ui
                    .add_enabled(i > 0, egui::Button::new("▲").small())
                    .on_hover_text(format!("Move {name} up"))
                    .clicked()
                {
                    app.ui.commands.push(UiCommand::MoveDesign { design: i, earlier: true });
                }
                if ui
                    .add_enabled(i + 1 < n, egui::Button::new("▼").small())
                    .on_hover_text(format!("Move {name} down"))
                    .clicked()
                {
                    app.ui.commands.push(UiCommand::MoveDesign { design: i, earlier: false });
                }
                if ui
                    .add_enabled(n > 1, egui::Button::new("✖").small())
                    .on_hover_text(format!("Remove design {name}"))
                    .clicked()
                {
                    app.ui.commands.push(UiCommand::RemoveDesign(i));
                }
            });
            ui.end_row();
        }
    });
    ui.add_enabled_ui(n < MAX_DESIGNS, |ui| {
        ui.menu_button("Add design", |ui| {
            egui::ScrollArea::vertical().max_height(0.6 * ui.ctx().content_rect().height()).show(ui, |ui| {
                for e in &instruments {
                    let text = if e.builtin { e.name.clone() } else { format!("{} (mine)", e.name) };
                    let item = ui.button(text);
                    let item = if e.description.is_empty() { item } else { item.on_hover_text(&e.description) };
                    if item.clicked() {
                        app.ui.commands.push(UiCommand::AddDesign(e.clone()));
                        ui.close();
                    }
                }
            });
        })
        .response
        .on_hover_text(format!("Compare another instrument (up to {MAX_DESIGNS} designs)"))
        .on_disabled_hover_text(format!("The app compares {MAX_DESIGNS} designs at most"));
    });
}

fn presets(app: &mut ShoalApp, ui: &mut egui::Ui) {
    designs(app, ui);
    ui.heading("Presets");
    let scenes = app.listing.get(PresetKind::Scene).to_vec();
    if let Some(entry) = library_combo(ui, "Scene", &app.state.scene_name.clone(), &scenes) {
        app.ui.commands.push(UiCommand::LoadScene(entry));
    }
    // What the scene is, in its own words (the state's copy: it is the scene that runs).
    if !app.state.scene.description.is_empty() {
        ui.add(egui::Label::new(egui::RichText::new(&app.state.scene.description).small().weak()).wrap());
    }
    let studies = app.listing.get(PresetKind::Study).to_vec();
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
        let design = app.state.editing;
        let text = format!("Save {}", label(design));
        if ui.button(text).on_hover_text("Save the design being edited in your preset library").clicked() {
            let name = app.ui.preset_name.trim().to_string();
            app.ui.commands.push(UiCommand::SaveInstrument { design, name });
        }
        if ui.button("Save study").clicked() {
            let name = app.ui.preset_name.trim().to_string();
            app.ui.commands.push(UiCommand::SaveStudy { name });
        }
    });
}

/// A number typed into a slider's field: the number alone or followed by the slider's unit
/// (`60`, `60 mm`, `6e1`); anything else is `None`.
fn parse_typed(text: &str, unit: &str) -> Option<f64> {
    let t = text.trim();
    let t = t.strip_suffix(unit.trim()).unwrap_or(t).trim();
    t.parse::<f64>().ok().filter(|v| v.is_finite())
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
    // Wrapped: eight designs' buttons on one row widened the panel past a 1280-pixel screen.
    ui.horizontal_wrapped(|ui| {
        ui.heading("Instrument");
        for i in 0..app.state.designs.len() {
            ui.selectable_value(&mut app.state.editing, i, format!("Edit {}", label(i)));
        }
    });
    let editing = app.state.editing.min(app.state.designs.len() - 1);
    let mut changed: Vec<(&'static str, f64)> = Vec::new();
    // Wider than egui's 100 px (on which a log slider jumped from 90 to 200 mm in a 20 px drag),
    // fixed so the panel does not grow with its own content; Shift held makes a drag of the rail
    // or of the number 10× finer.
    ui.spacing_mut().slider_width = 160.0;
    // The parameters and their values, read once a frame from the registry and the instrument.
    let stored = super::params::values(&app.state.designs[editing].spec);
    egui::Grid::new("params").num_columns(2).show(ui, |ui| {
        for (p, stored) in params().zip(stored) {
            let (e, suffix) = (p.editor, p.suffix());
            let mut v = stored * e.scale;
            let before = v;
            // Never clamped: a preset outside the slider's span keeps its value, and a typed
            // value outside it is checked against the instrument's documented range below.
            // A typed text that is not a number is refused aloud (egui would ignore it).
            let not_a_number: std::cell::Cell<Option<String>> = std::cell::Cell::new(None);
            let slider = egui::Slider::new(&mut v, e.slider.0..=e.slider.1)
                .update_while_editing(false)
                .text(e.label)
                .suffix(suffix.as_str())
                .logarithmic(e.log)
                .clamping(egui::SliderClamping::Never)
                .custom_parser(|text| {
                    let parsed = parse_typed(text, &suffix);
                    if parsed.is_none() {
                        not_a_number.set(Some(text.to_string()));
                    }
                    parsed
                });
            let integer = p.range.whole;
            let slider = if integer { slider.integer() } else { slider };
            // The hover text states the documented range (src/ranges.rs) a typed value must meet;
            // built only while the pointer is on the slider.
            let response = ui.add(slider);
            if let Some(text) = not_a_number.take() {
                let allowed = format!(" (allowed: {})", p.range.allowed());
                app.ui.param_error = Some((p.key, format!("{}: `{text}` is not a number{allowed}", p.key)));
            }
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
                v = fine_step(before, response.drag_delta().x / ui.spacing().slider_width, e.slider, e.log);
            }
            response.on_hover_ui(|ui| {
                ui.label(e.tip);
                ui.label("Type a value and press Enter; hold Shift while dragging the slider or the number for 10× finer steps.");
                ui.label(format!("Allowed: {} (`{}`)", p.range.allowed(), p.key));
            });
            let mut linked = app.state.linked.iter().any(|k| k == p.key);
            if ui
                .checkbox(&mut linked, "link")
                .on_hover_text(format!("Link {} across the designs", e.label.to_lowercase()))
                .changed()
            {
                if linked {
                    app.state.linked.push(p.key.to_string());
                } else {
                    app.state.linked.retain(|k| k != p.key);
                }
            }
            ui.end_row();
            if v != before {
                let slot = &mut app.state.designs[editing];
                let candidate = super::params::with_value(&slot.spec, p.key, v / e.scale)
                    .map_err(|m| crate::instrument::InstrumentError::Invalid(crate::parse::FieldError { field: p.key.into(), message: m }));
                match candidate.and_then(|c| c.validate().map(|()| c)) {
                    Ok(candidate) => {
                        slot.spec = candidate;
                        changed.push((p.key, v / e.scale));
                        app.ui.param_error = None;
                    }
                    // The value is refused and the instrument keeps its last valid one.
                    Err(e) => app.ui.param_error = Some((p.key, e.to_string())),
                }
            }
        }
    });
    // A refused value, under the sliders and wrapped to the panel (inside the grid it widened
    // the panel for good).
    if let Some((key, message)) = &app.ui.param_error {
        let label = param(key).map_or(*key, |p| p.label());
        ui.add(
            egui::Label::new(egui::RichText::new(format!("{label} refused: {message}")).color(super::theme::FAIL))
                .wrap(),
        );
    }
    // Linked parameters follow to the other designs.
    for (key, value) in changed {
        if app.state.linked.iter().any(|k| k == key)
            && let Some(p) = param(key)
        {
            for (i, other) in app.state.designs.iter_mut().enumerate() {
                if i != editing
                    && let Ok(spec) = super::params::with_value(&other.spec, p.key, value)
                {
                    other.spec = spec;
                }
            }
        }
    }
    let slot = &mut app.state.designs[editing];
    egui::CollapsingHeader::new("Bands").default_open(false).show(ui, |ui| super::editors::band_editor(slot, ui));
    planes_and_optics(app, ui, editing);
    super::derived::derived(app, ui);
    super::derived::differences(app, ui);
}

/// The editing design's further focal planes and its optical effects.
fn planes_and_optics(app: &mut ShoalApp, ui: &mut egui::Ui, editing: usize) {
    // One header for both (the panel keeps its height): the focal planes beyond the first, then
    // the optics between the pupil and the detector.
    let slot = &app.state.designs[editing];
    let mut title = String::from("Focal planes and optics");
    if !slot.spec.focal_planes.is_empty() || !slot.spec.effects.is_empty() {
        title = format!("{title} ({} planes, {} effects)", slot.spec.focal_planes.len() + 1, slot.spec.effects.len());
    }
    egui::CollapsingHeader::new(title).id_salt("focal-planes").default_open(false).show(ui, |ui| {
        let slot = &mut app.state.designs[editing];
        super::planes::plane_editor(slot, ui, &mut app.ui.plane_error);
        ui.separator();
        ui.strong("Optics");
        let slot = &mut app.state.designs[editing];
        super::optics::optics_editor(slot, ui, &mut app.ui.optics_error);
    });
}

fn settings(app: &mut ShoalApp, ui: &mut egui::Ui) {
    egui::CollapsingHeader::new("Retrieval, seeds, preview").default_open(true).show(ui, |ui| {
        let s = &mut app.state;
        // The retrievals offered: aLMI, SAMBUCA and the study's own, each by its title.
        ui.horizontal_wrapped(|ui| {
            for i in 0..s.retrievals.len() {
                let title = s.retrievals[i].title();
                ui.selectable_value(&mut s.selected_retrieval, i, title);
            }
        });
        if let Some(spec) = s.retrieval_mut() {
            retrieval_settings(spec, ui);
        }
        ui.horizontal(|ui| {
            let l = ui.label("Scene seed");
            ui.add(egui::DragValue::new(&mut s.scene_seed).update_while_editing(false).range(0..=1_000_000).speed(1.0))
                .labelled_by(l.id);
            let l = ui.label("Noise seed");
            ui.add(egui::DragValue::new(&mut s.noise_seed).update_while_editing(false).range(0..=1_000_000).speed(1.0))
                .labelled_by(l.id);
        });
        let decimations = s.levels();
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
        ui.checkbox(&mut s.preview_only, "Preview only").on_hover_text(
            "Run the previews and stop: the final level runs when this is off (for a long retrieval at full resolution)",
        );
    });
    egui::CollapsingHeader::new("Requirements")
        .default_open(false)
        .show(ui, |ui| super::editors::requirements_editor(app, ui));
}

/// The left panel.
pub fn left(app: &mut ShoalApp, ui: &mut egui::Ui) {
    presets(app, ui);
    save_presets(app, ui);
    ui.separator();
    editor(app, ui);
    ui.separator();
    settings(app, ui);
    super::conditions::conditions(app, ui);
}

/// The settings of the retrieval that runs, edited in its spec: the mode of aLMI, SAMBUCA and
/// QAA, aLMI's noise weighting, SAMBUCA's objective and starts; a program's command, shown.
fn retrieval_settings(spec: &mut crate::retrieval::RetrievalSpec, ui: &mut egui::Ui) {
    use crate::retrieval::RetrievalSpec;
    // Reference: the published code's behaviour, to reproduce published numbers; Improved:
    // Shoal's inversion, the design default (QAA: the v6 document against the IOCCG sheet).
    let Some((mode, names)) = spec.mode_mut() else {
        if let RetrievalSpec::External(e) = spec {
            ui.small(format!(
                "Runs {} on the Rrs (NetCDF) and scores its {} (time limit {} s).",
                e.what_runs(),
                e.products.join(", "),
                e.time_limit_s
            ));
        }
        return;
    };
    ui.horizontal(|ui| {
        ui.label("Mode");
        ui.selectable_value(mode, Mode::Improved, names[0]).on_hover_text(
            "Shoal's inversion (QAA: the v6 document's equations, as NASA's l2gen): what a design study should use",
        );
        ui.selectable_value(mode, Mode::Reference, names[1]).on_hover_text(
            "The published code step for step (DEA aLMI; CSIRO SAMBUCA with SLSQP from one start; the IOCCG QAA_v6 \
             spreadsheet), to reproduce published numbers",
        );
    });
    let reference = *mode == Mode::Reference;
    match spec {
        RetrievalSpec::Almi { .. } if reference => {
            ui.small("As DEA's code: unweighted least squares per set, a set dropped below 1e-5.");
        }
        RetrievalSpec::Sambuca { .. } if reference => {
            ui.small("As the CSIRO package: distance f with NEDR, one start at (max − min)/2, SLSQP; stalls kept.");
        }
        RetrievalSpec::Almi { settings, .. } => {
            ui.checkbox(&mut settings.noise_weighting, "Noise weighting")
                .on_hover_text("Weight each band by its noise (off: as the reference code)");
        }
        RetrievalSpec::Sambuca { settings, .. } => {
            egui::ComboBox::from_label("Objective").selected_text(format!("{:?}", settings.objective)).show_ui(
                ui,
                |ui| {
                    ui.selectable_value(&mut settings.objective, Objective::F, "F");
                    ui.selectable_value(&mut settings.objective, Objective::AlphaF, "AlphaF");
                    ui.selectable_value(&mut settings.objective, Objective::Lsq, "Lsq");
                },
            );
            egui::ComboBox::from_label("Starts").selected_text(format!("{:?}", settings.starts)).show_ui(ui, |ui| {
                ui.selectable_value(&mut settings.starts, Starts::Adaptive, "Adaptive");
                ui.selectable_value(&mut settings.starts, Starts::Shallow, "Shallow");
                ui.selectable_value(&mut settings.starts, Starts::ShallowAndDeep, "ShallowAndDeep");
            });
            ui.checkbox(&mut settings.warm_pairs, "Warm pair starts").on_hover_text(
                "Start each substrate pair from the best fit so far (off: every pair from the shallow start)",
            );
        }
        RetrievalSpec::Qaa { .. } => {
            ui.small("IOPs from the Rrs with no SIOP assumed; chl from a_ph(443) (Bricaud et al. 1998).");
        }
        RetrievalSpec::External(_) => {}
    }
}

#[cfg(test)]
mod tests {
    use super::fine_step;

    #[test]
    fn a_typed_number_reads_with_or_without_its_unit_and_letters_do_not() {
        assert_eq!(super::parse_typed(" 60 ", " mm"), Some(60.0));
        assert_eq!(super::parse_typed("60 mm", " mm"), Some(60.0));
        assert_eq!(super::parse_typed("6e1", " mm"), Some(60.0));
        assert_eq!(super::parse_typed("sixty", " mm"), None);
        assert_eq!(super::parse_typed("60x", " mm"), None);
        assert_eq!(super::parse_typed("inf", " mm"), None);
    }

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
