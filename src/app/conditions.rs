//! The left panel's scene and atmosphere controls, for worst-case checks of a design: the
//! aerosol model and its optical thickness, the sun zenith, a wind-roughened surface and its
//! glint, adjacency (when the scene has land), and the calibration's systematic errors. Each
//! value is checked against its documented range ([`crate::ranges`]) before it is taken; a
//! refused value keeps the last valid one and says why.

use super::ShoalApp;
use crate::atmosphere::{AerosolType, SeaSurface};
use crate::ranges::Range;
use crate::scene::Effect;

/// A slider over `range` (clamped to `span` for dragging, the range checked when typed);
/// returns the refusal, if the value was refused.
fn checked(
    ui: &mut egui::Ui,
    value: &mut f64,
    span: (f64, f64),
    range: &Range,
    label: &str,
    suffix: &str,
) -> Option<String> {
    let mut v = *value;
    ui.add(
        egui::Slider::new(&mut v, span.0..=span.1)
            .update_while_editing(false)
            .clamping(egui::SliderClamping::Never)
            .text(label)
            .suffix(suffix),
    )
    .on_hover_text(format!("{} (allowed: {})", range.meaning, range.allowed()));
    if v == *value {
        return None;
    }
    match range.check(v) {
        Ok(()) => {
            *value = v;
            None
        }
        Err(m) => Some(format!("{}: {m}", range.path)),
    }
}

/// The scene and atmosphere controls.
pub(super) fn conditions(app: &mut ShoalApp, ui: &mut egui::Ui) {
    use crate::ranges as r;
    egui::CollapsingHeader::new("Scene and atmosphere").default_open(false).show(ui, |ui| {
        // (Only while open: a design's bands from its instrument are not free to find each frame.)
        // Each design's band centres (a pair the bands lack is not offered): from its latest result,
        // or, while it waits or has failed, from its instrument (a design without a result was
        // offered any pair).
        let bands: Vec<(String, Vec<f64>)> = (0..app.state.designs.len())
            .filter_map(|i| {
                let centres = match app.link.current(i) {
                    Some(shown) => shown.output.response.bands.centres_nm(),
                    None => app.state.designs[i].spec.kind.model().band_set().ok()?.centres_nm(),
                };
                Some((super::designs::label(i), centres))
            })
            .collect();
        let s = &mut app.state;
        let mut refused = None;
        let atm = &mut s.scene.atmosphere;
        let names = [
            (AerosolType::None, "none"),
            (AerosolType::Maritime, "maritime"),
            (AerosolType::Continental, "continental"),
            (AerosolType::Urban, "urban"),
            (AerosolType::Maritime6sv, "maritime (6SV's components)"),
            (AerosolType::Continental6sv, "continental (6SV's components)"),
            (AerosolType::Urban6sv, "urban (6SV's components)"),
        ];
        // A user's mixture (set in a scene file) shows its fractions; the menu offers the models.
        let current =
            names.iter().find(|(a, _)| *a == atm.aerosol).map_or_else(|| atm.aerosol.name(), |(_, n)| (*n).into());
        egui::ComboBox::from_label("Aerosol (WMO)").selected_text(current).show_ui(ui, |ui| {
            for (a, n) in names {
                ui.selectable_value(&mut atm.aerosol, a, n);
            }
        });
        if s.scene.aot550_map.is_some() {
            // The scene's optical thickness is a map (`aot550_map`): one number would not say it.
            ui.horizontal(|ui| {
                ui.label("AOT(550): the scene's map").on_hover_text(
                    "The scene file gives the aerosol optical thickness as a map (aot550_map); every pixel \
                     sees the atmosphere of its own AOT.",
                );
                if ui.button("one value").on_hover_text("Replace the map by the atmosphere's aot550").clicked() {
                    s.scene.aot550_map = None;
                }
            });
        } else {
            refused = refused.or(checked(ui, &mut atm.aot550, (0.0, 1.0), &r::ATMOSPHERE_AOT550, "AOT(550)", ""));
        }
        refused = refused.or(checked(
            ui,
            &mut s.scene.sun.zenith_deg,
            (0.0, 85.0),
            &r::SCENE_SUN_ZENITH_DEG,
            "Sun zenith",
            "°",
        ));
        // Glint needs a wind-roughened surface: the two move together.
        let mut glint = s.scene.effects.contains(&Effect::SunGlint);
        if ui.checkbox(&mut glint, "Sun glint (Cox–Munk, wind-roughened sea)").changed() {
            if glint {
                if matches!(s.scene.atmosphere.surface, SeaSurface::Flat) {
                    s.scene.atmosphere.surface = SeaSurface::Wind { speed_m_s: 5.0 };
                }
                s.scene.effects.push(Effect::SunGlint);
            } else {
                s.scene.effects.retain(|e| *e != Effect::SunGlint);
            }
        }
        if let SeaSurface::Wind { speed_m_s } = &mut s.scene.atmosphere.surface {
            refused =
                refused.or(checked(ui, speed_m_s, (0.0, 15.0), &r::ATMOSPHERE_WIND_SPEED_M_S, "Wind speed", " m/s"));
        }
        if s.scene.land.is_some() {
            let mut adjacency = s.scene.effects.contains(&Effect::Adjacency);
            if ui.checkbox(&mut adjacency, "Adjacency (light from the land scattered into water pixels)").changed() {
                if adjacency {
                    s.scene.effects.push(Effect::Adjacency);
                } else {
                    s.scene.effects.retain(|e| *e != Effect::Adjacency);
                }
            }
        }
        correction_choice(ui, &mut s.correction, &bands);
        ui.label("Calibration errors (systematic)");
        let c = &mut s.calibration;
        refused = refused.or(checked(
            ui,
            &mut c.diffuser_bias_pct,
            (-10.0, 10.0),
            &r::CALIBRATION_DIFFUSER_BIAS_PCT,
            "Diffuser error",
            " %",
        ));
        refused = refused.or(checked(
            ui,
            &mut c.gain_drift_pct,
            (-10.0, 10.0),
            &r::CALIBRATION_GAIN_DRIFT_PCT,
            "Gain drift",
            " %",
        ));
        if refused.is_some() {
            app.ui.conditions_error = refused;
        }
        if let Some(m) = &app.ui.conditions_error {
            ui.add(egui::Label::new(egui::RichText::new(format!("refused: {m}")).color(super::theme::FAIL)).wrap());
        }
        ui.small("These change the scene and the calibration of every design alike.");
    });
}

/// The atmospheric correction both instruments' Level-1 goes through: exact (the forward
/// model's own atmosphere, the "perfect correction"), the paper's per-scene approximation, or
/// image-based (the aerosol from the design's own bands; `correction::image`): a band pair with
/// the NIR water iteration, a SWIR pair, or dark-spectrum fitting. A pair some design's bands
/// (`bands`: each design's letter and band centres) lack is shown greyed, with which design and
/// why.
fn correction_choice(ui: &mut egui::Ui, spec: &mut crate::correction::CorrectionSpec, bands: &[(String, Vec<f64>)]) {
    use crate::correction::{AerosolFit, ImageCorrection, Method, PRESETS};
    let current = PRESETS.iter().find(|p| p.matches(&spec.method)).map_or("image: custom", |p| p.label);
    egui::ComboBox::from_label("Atmospheric correction").selected_text(current).show_ui(ui, |ui| {
        for preset in &PRESETS {
            let method = (preset.make)();
            // The first design whose bands cannot make the pair, and why.
            // The default pair falls back to each design's own ([`super::model::design_pair`]).
            let default_pair = ImageCorrection::default().pair_nm;
            let image = match &method {
                Method::Image(i) if i.fit != AerosolFit::DarkSpectrum => Some(i),
                _ => None,
            };
            let lacking = image.and_then(|i| {
                bands.iter().find_map(|(design, centres)| {
                    let usable = if i.pair_nm == default_pair { i.for_bands(centres) } else { Some(i.clone()) };
                    let err = usable.map_or_else(|| i.pair(centres).err(), |u| u.pair(centres).err());
                    err.map(|e| format!("{design}: {e}"))
                })
            });
            let label =
                ui.add_enabled(lacking.is_none(), egui::Button::selectable(current == preset.label, preset.label));
            let label = match &lacking {
                Some(why) => label.on_disabled_hover_text(format!("{}\n\nNot offered: design {why}", preset.about)),
                None => label.on_hover_text(preset.about),
            };
            if label.clicked() {
                spec.method = method;
            }
        }
    });
}
