//! A click on a map opens the scene's spectrum at that point, with both instruments' bands; a
//! change of A asks again of the new run (the window never shows a run no longer on screen).
//! The atmospheric correction chosen in the app reaches both runs.

use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::kittest::{NodeT, Queryable};

use super::{harness, temp_library, wait_for_engine};

/// Step until a node labelled with `text` (in part) shows, at most a minute.
fn wait_for_text(h: &mut egui_kittest::Harness<'static, shoal::app::ShoalApp>, text: &str) {
    let start = Instant::now();
    while h.query_by_label_contains(text).is_none() {
        assert!(start.elapsed() < Duration::from_secs(60), "`{text}` never showed");
        h.step();
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_click_on_a_map_shows_the_spectrum_there() {
    let dir = temp_library("spectrum");
    let mut h = harness("cubesat", 8, &dir);
    wait_for_engine(&mut h);
    assert!(h.query_by_label("Spectrum at a point").is_none(), "closed until a map is clicked");
    // The truth panel's title sits right above its map (the topmost "truth" on screen; the
    // plots' keys below say it too).
    let title = h
        .query_all_by_label("truth")
        .map(|n| n.rect())
        .min_by(|a, b| a.top().total_cmp(&b.top()))
        .expect("a truth panel");
    let at = egui::pos2(title.left() + 60.0, title.bottom() + 60.0);
    h.event(egui::Event::PointerMoved(at));
    h.step();
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
        h.step();
    }
    wait_for_text(&mut h, "Water at (");
    assert!(h.query_by_label("Spectrum at a point").is_some());
    assert!(h.query_by_label_contains("of A; sun zenith 60.0°").is_some());
    assert!(h.query_by_label_contains("A: bands (FWHM) and what it measured").is_some());
    assert!(h.query_by_label_contains("B: bands (FWHM) and what it measured").is_some());
    // A new A: the spectrum is computed again for its run, and the old one is not shown meanwhile.
    h.state_mut().state.designs[0].spec.aperture_mm *= 1.5;
    h.step();
    h.step();
    assert!(h.query_by_label_contains("Water at (").is_none(), "the previous run's spectrum stays up");
    wait_for_engine(&mut h);
    wait_for_text(&mut h, "Water at (");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_image_based_correction_is_the_default_and_the_perfect_processor_one_choice_away() {
    let dir = temp_library("imagecorr");
    let mut h = harness("cubesat", 8, &dir);
    wait_for_engine(&mut h);
    // The default study corrects as a mission would: the aerosol from each design's own bands.
    for i in 0..2 {
        let out = &h.state().link.shown[i].as_ref().unwrap().output;
        let aerosol = out.correction.aerosol.as_ref().expect("the image-based correction ran");
        assert!(aerosol.aot550.iter().any(|v| v.is_finite() && *v > 0.0));
        assert_eq!(out.config.correction.image().unwrap().pair_nm, [779.0, 865.0]);
    }
    // The metrics table tells what the correction found and what it left in Rrs.
    h.step();
    assert!(h.query_by_label_contains("aerosol found").is_some(), "the aerosol row is shown");
    assert_eq!(h.query_all_by_label_contains("(true 0.100)").count(), 2, "the AOT found for A and B");
    assert!(h.query_by_label_contains("Rrs 400–560 nm").is_some(), "the Rrs row is shown");
    assert!(h.query_by_label_contains("aerosol found (image-based correction)").is_some(), "said on screen");
    // The scene panel's "Atmospheric correction" choice "perfect processor (exact)".
    h.state_mut().state.correction.method = shoal::correction::Method::Exact;
    h.step();
    wait_for_engine(&mut h);
    for i in 0..2 {
        let out = &h.state().link.shown[i].as_ref().unwrap().output;
        assert!(out.correction.aerosol.is_none() && out.config.correction.image().is_none(), "the exact correction");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_swir_pair_the_designs_lack_is_not_offered() {
    let dir = temp_library("swirpair");
    let mut h = harness("cubesat", 8, &dir);
    wait_for_engine(&mut h);
    // The scene panel sits below the left panel's fold: the accessibility actions reach it
    // where a pointer would have to scroll.
    let settle = |h: &mut egui_kittest::Harness<'static, shoal::app::ShoalApp>| {
        h.step();
        h.step();
    };
    h.get_by_label("Scene and atmosphere").click_accesskit();
    settle(&mut h);
    h.get_by_role_and_label(Role::ComboBox, "Atmospheric correction").click_accesskit();
    settle(&mut h);
    // The CubeSat has no band near 1610 or 2200 nm: the SWIR pair is greyed, and choosing it
    // changes nothing; dark-spectrum fitting needs no pair.
    assert!(h.get_by_label("image: 1610/2200 nm").accesskit_node().is_disabled(), "the SWIR pair is offered");
    assert!(!h.get_by_label("image: dark spectrum").accesskit_node().is_disabled());
    h.get_by_label("image: 1610/2200 nm").click_accesskit();
    settle(&mut h);
    let image = h.state().state.correction.image().cloned().expect("the default image-based correction");
    assert_eq!(image.pair_nm, [779.0, 865.0], "a pair the design lacks was taken");
    h.get_by_label("image: dark spectrum").click_accesskit();
    settle(&mut h);
    let image = h.state().state.correction.image().cloned().unwrap();
    assert_eq!(image.fit, shoal::correction::AerosolFit::DarkSpectrum);
    let _ = std::fs::remove_dir_all(&dir);
}
