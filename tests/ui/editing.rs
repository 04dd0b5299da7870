//! Editing an instrument: typed values applied on Enter, out-of-range values refused inline,
//! undo and redo, and fine slider drags.

use super::*;

/// A typed aperture outside the documented range is refused inline, naming field, value and
/// range; the instrument keeps its value, and a valid value afterwards clears the message.
#[test]
fn an_out_of_range_slider_value_is_refused_inline() {
    let lib = temp_library("range");
    let mut h = harness("cubesat", 8, &lib);
    h.step();
    h.get_by_role_and_label(Role::Slider, "Aperture").set_value_accesskit(5000.0);
    h.step();
    h.step();
    let expected = "aperture_mm: 5000 is out of range (allowed: above 0, at most 2000 mm)";
    assert_eq!(h.state().refused_value(), Some(expected));
    assert!(h.query_all_by_label(&format!("Aperture refused: {expected}")).next().is_some(), "not on screen");
    assert!((h.state().state.designs[0].spec.aperture_mm - 60.0).abs() < 1e-9, "the instrument keeps 60 mm");
    h.get_by_role_and_label(Role::Slider, "Aperture").set_value_accesskit(100.0);
    h.step();
    h.step();
    assert_eq!(h.state().refused_value(), None);
    assert!((h.state().state.designs[0].spec.aperture_mm - 100.0).abs() < 1e-9);
    let _ = std::fs::remove_dir_all(&lib);
}

/// Typing into a parameter's number changes nothing until Enter: a half-typed `99999` is never
/// run as 9, 99 and 999 mm. Enter applies it (here refused, out of range), and a valid number
/// typed after it applies on Enter too.
#[test]
fn a_typed_value_is_applied_on_enter_not_per_keystroke() {
    let lib = temp_library("typing");
    let mut h = harness("cubesat", 16, &lib);
    h.step();
    let type_into_aperture = |h: &mut Harness<'static, ShoalApp>, text: &str| {
        h.get_by_role_and_label(Role::SpinButton, "Aperture").click();
        h.step();
        h.step();
        // The number is now a text field with its text selected: typing replaces it.
        for c in text.chars() {
            h.event(egui::Event::Text(c.to_string()));
            h.step();
            assert!(
                (h.state().state.designs[0].spec.aperture_mm - 60.0).abs() < 1e-9,
                "after typing `{c}` of `{text}` the aperture is {} mm: applied per keystroke",
                h.state().state.designs[0].spec.aperture_mm
            );
        }
    };
    type_into_aperture(&mut h, "99999");
    assert_eq!(h.state().refused_value(), None, "nothing is judged before Enter");
    h.key_press(egui::Key::Enter);
    h.step();
    h.step();
    assert!(h.state().refused_value().is_some_and(|m| m.contains("99999")), "{:?}", h.state().refused_value());
    assert!((h.state().state.designs[0].spec.aperture_mm - 60.0).abs() < 1e-9, "a refused value is not applied");

    type_into_aperture(&mut h, "150");
    h.key_press(egui::Key::Enter);
    h.step();
    h.step();
    assert!(
        (h.state().state.designs[0].spec.aperture_mm - 150.0).abs() < 1e-9,
        "{}",
        h.state().state.designs[0].spec.aperture_mm
    );
    let _ = std::fs::remove_dir_all(&lib);
}

/// Ctrl+Z undoes an edit and Ctrl+Shift+Z redoes it; the Undo button does the same.
#[test]
fn undo_and_redo_walk_the_instrument_edits() {
    let lib = temp_library("undo");
    let mut h = harness("cubesat", 16, &lib);
    h.step();
    h.get_by_role_and_label(Role::Slider, "Aperture").set_value_accesskit(90.0);
    h.step();
    h.step();
    h.get_by_role_and_label(Role::Slider, "Read noise").set_value_accesskit(40.0);
    h.step();
    h.step();
    let aperture = |h: &Harness<'static, ShoalApp>| h.state().state.designs[0].spec.aperture_mm;
    let read_noise = |h: &Harness<'static, ShoalApp>| h.state().state.designs[0].spec.read_noise_e;
    assert_eq!((aperture(&h), read_noise(&h)), (90.0, 40.0));

    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    h.step();
    h.step();
    assert_eq!(aperture(&h), 90.0, "the last edit goes first");
    assert_ne!(read_noise(&h), 40.0);
    h.get_by_label("Undo").click();
    h.step();
    h.step();
    assert!((aperture(&h) - 60.0).abs() < 1e-9, "back to the preset's 60 mm");
    assert!(!h.state().state.designs[0].modified(), "the preset as loaded is no longer marked modified");

    h.key_press_modifiers(egui::Modifiers::COMMAND | egui::Modifiers::SHIFT, egui::Key::Z);
    h.step();
    h.step();
    assert_eq!(aperture(&h), 90.0, "redo brings the aperture back");
    let _ = std::fs::remove_dir_all(&lib);
}

/// Shift held while dragging a slider's rail moves the value a tenth as far, from where it was:
/// on the aperture's log slider (10–500 mm over 160 px) an 80 px drag is a factor
/// 50^(0.1 × 80 / 160) = 1.216, where a plain drag would sweep half the range.
#[test]
fn shift_dragging_a_slider_rail_moves_the_value_a_tenth_as_far() {
    let dir = temp_library("finedrag");
    let mut h = harness("cubesat", 24, &dir);
    h.step();
    let before = h.state().state.designs[0].spec.aperture_mm;
    let rail = h.get_by_role_and_label(Role::Slider, "Aperture").rect();
    let shift = egui::Modifiers::SHIFT;
    let at = |dx: f32| egui::pos2(rail.center().x + dx, rail.center().y);
    h.event(egui::Event::ModifiersChanged(shift));
    h.event(egui::Event::PointerMoved(at(0.0)));
    h.step();
    h.event(egui::Event::PointerButton {
        pos: at(0.0),
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: shift,
    });
    h.step();
    for dx in [20.0, 40.0, 60.0, 80.0] {
        h.event(egui::Event::PointerMoved(at(dx)));
        h.step();
    }
    h.event(egui::Event::PointerButton {
        pos: at(80.0),
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: shift,
    });
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.step();
    h.step();
    let after = h.state().state.designs[0].spec.aperture_mm;
    let expected = before * 50f64.powf(0.1 * 80.0 / 160.0);
    // 1 %: the drag is in whole points, exact in f32; the rest is rounding of the displayed value.
    assert!((after / expected - 1.0).abs() < 0.01, "aperture {before} → {after} mm, expected {expected:.2} mm");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The optics editor adds a design's optical effects, each entry kept only when the instrument
/// validates, and the derived figures show what a review asks of them.
#[test]
fn optical_effects_are_added_per_design_and_shown_in_the_derived_figures() {
    let lib = temp_library("optics");
    let mut h = harness("cubesat", 16, &lib);
    h.step();
    h.get_by_label("Focal planes and optics").click();
    h.step();
    h.get_by_label("Add polarisation sensitivity").click();
    h.step();
    h.step();
    h.get_by_label("Add stray light").click();
    h.step();
    h.step();
    // Two open effect editors push the third button below the panel's fold: the accessibility
    // action reaches it where a pointer would have to scroll.
    h.get_by_label("Add MTF budget").click_accesskit();
    h.step();
    h.step();
    let effects = &h.state().state.designs[0].spec.effects;
    let refused: Vec<String> = h.query_all_by_label_contains("Optics refused").map(|n| format!("{n:?}")).collect();
    assert_eq!(effects.len(), 3, "{effects:?} {refused:?}");
    assert!(matches!(effects[0], shoal::instrument::InstrumentEffect::Polarisation(_)));
    assert!(matches!(effects[1], shoal::instrument::InstrumentEffect::StrayLight(_)));
    assert!(matches!(effects[2], shoal::instrument::InstrumentEffect::SpatialResponse(_)));
    assert!(h.query_all_by_label("1.00 %").next().is_some(), "the derived polarisation sensitivity");
    // The CubeSat's MTF at Nyquist at 560 nm with the starting budget (shoal mtf's numbers).
    let g = shoal::instrument::spatial::first_plane_geometry(&h.state().state.designs[0].spec);
    let shoal::instrument::InstrumentEffect::SpatialResponse(b) = effects[2] else { unreachable!() };
    let at = |axis| b.at_nyquist(&g, 560.0, axis);
    let text = format!(
        "{:.2} / {:.2}",
        at(shoal::instrument::effects::mtf::Axis::Along),
        at(shoal::instrument::effects::mtf::Axis::Across)
    );
    assert!(h.query_all_by_label(&text).next().is_some(), "the derived MTF at Nyquist {text}");
    h.get_by_label("Add spectral stray light").click_accesskit();
    h.step();
    h.step();
    let effects = &h.state().state.designs[0].spec.effects;
    assert!(matches!(effects.get(3), Some(shoal::instrument::InstrumentEffect::SpectralStrayLight(_))), "{effects:?}");
    assert!(h.query_all_by_label("Add stray light").next().is_none(), "one stray light per design");
    // The focal plane's effects sit in the same editor.
    for (label, at) in [
        ("Add non-linearity", 4),
        ("Add TDI", 5),
        ("Add compression", 6),
        ("Add spectral knowledge error", 7),
        ("Add on-board binning", 8),
    ] {
        h.get_by_label(label).click_accesskit();
        h.step();
        h.step();
        let effects = &h.state().state.designs[0].spec.effects;
        assert_eq!(effects.len(), at + 1, "{label}: {effects:?}");
        assert!(effects[at].on_the_focal_plane(), "{label}: {:?}", effects[at]);
    }
    // Binned 2 × 2: the Derived table's GSD is the binned pixel's (the CubeSat's 19.9 m twice).
    let gsd = 2.0 * h.state().state.designs[0].spec.gsd_m();
    assert!(h.query_all_by_label(&format!("{gsd:.1} m")).next().is_some(), "the binned GSD {gsd:.1} m");
    assert!(h.query_all_by_label("2 × 2 charge").next().is_some(), "the binning row");
    let _ = std::fs::remove_dir_all(&lib);
}
