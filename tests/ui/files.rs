//! Presets and exports from the app: saving and reloading instruments, refusals by name, a
//! malformed preset, edits kept until the user agrees to lose them, and the comparison figure and
//! review pack written to typed paths.

use super::*;

#[test]
fn a_saved_preset_reloads_with_its_edits() {
    let dir = temp_library("save");
    let mut h = harness("cubesat", 16, &dir);
    h.get_by_role_and_label(Role::Slider, "Aperture").set_value_accesskit(77.0);
    h.step();
    h.get_by_role_and_label(Role::TextInput, "Preset name").set_text_value_accesskit("my_cube");
    h.step();
    h.get_by_label("Save A").click();
    h.step();
    h.step();
    assert_eq!(h.state().error(), None);
    let file = dir.join("instruments").join("my_cube.ron");
    assert!(file.is_file(), "no {}", file.display());
    assert_eq!(h.state().state.designs[0].preset, "my_cube");
    assert!(!h.state().state.designs[0].modified(), "a saved preset is no longer marked modified");

    // Load something else, then the saved preset back.
    pick(&mut h, "A", "smallsat");
    assert!((h.state().state.designs[0].spec.aperture_mm - 240.0).abs() < 1e-9);
    pick(&mut h, "A", "my_cube (mine)");
    assert_eq!(h.state().state.designs[0].preset, "my_cube");
    assert!((h.state().state.designs[0].spec.aperture_mm - 77.0).abs() < 1e-9);
    assert!(!h.state().state.designs[0].modified());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn saving_under_a_built_in_name_is_refused_inline() {
    let dir = temp_library("builtin-name");
    let mut h = harness("cubesat", 16, &dir);
    h.get_by_role_and_label(Role::Slider, "Aperture").set_value_accesskit(77.0);
    h.step();
    h.get_by_role_and_label(Role::TextInput, "Preset name").set_text_value_accesskit("smallsat");
    h.step();
    h.get_by_label("Save A").click();
    h.step();
    h.step();
    let error = h.state().error().unwrap_or_default().to_string();
    assert!(error.contains("`smallsat` is a built-in instrument; save yours under another name"), "{error}");
    assert!(!dir.join("instruments").join("smallsat.ron").exists());
    // The edit is kept, still marked as modified, and B's built-in smallsat is untouched.
    assert!((h.state().state.designs[0].spec.aperture_mm - 77.0).abs() < 1e-9);
    assert!(h.state().state.designs[0].modified());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_malformed_preset_shows_an_error_and_the_app_goes_on() {
    let dir = temp_library("broken");
    let instruments = dir.join("instruments");
    std::fs::create_dir_all(&instruments).unwrap();
    let good =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/presets/instruments/cubesat.ron")).unwrap();
    let broken = good.replace("aperture_mm: 60.0", "aperture_mm: \"wide\"");
    assert_ne!(good, broken);
    std::fs::write(instruments.join("broken.ron"), broken).unwrap();

    let mut h = harness("cubesat", 16, &dir);
    let before = h.state().state.designs[0].clone();
    pick(&mut h, "A", "broken (mine)");
    let error = h.state().error().expect("an error is shown").to_string();
    assert!(error.contains("broken"), "{error}");
    assert!(error.contains("aperture_mm"), "the message names the field: {error}");
    assert!(error.contains("line 12"), "the message names the line: {error}");
    assert_eq!(h.state().state.designs[0], before, "the instrument is unchanged");
    // The dialog shows it; OK closes it and the app goes on drawing.
    assert!(h.query_by_label_contains("aperture_mm").is_some());
    h.get_by_label("OK").click();
    h.step();
    h.step();
    assert_eq!(h.state().error(), None);
    h.get_by_role_and_label(Role::Slider, "Aperture").set_value_accesskit(90.0);
    h.step();
    assert!((h.state().state.designs[0].spec.aperture_mm - 90.0).abs() < 1e-6);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_comparison_figure_exports_to_a_typed_path() {
    let dir = temp_library("export");
    let mut h = harness("cubesat", 16, &dir);
    wait_for_engine(&mut h);
    h.get_by_label("Path").click();
    h.step();
    h.step();
    let stem = dir.join("review").join("comparison");
    h.get_by_role_and_label(Role::TextInput, "Export to").set_text_value_accesskit(stem.to_str().unwrap());
    h.step();
    h.get_by_label("Write figure").click();
    let start = Instant::now();
    let files = ["comparison.png", "comparison.svg", "comparison_config_A.ron", "comparison_config_B.ron"]
        .map(|f| dir.join("review").join(f));
    while !files.iter().all(|f| f.is_file()) {
        assert!(start.elapsed() < Duration::from_secs(120), "the figure was not written");
        assert_eq!(h.state().error(), None);
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    h.step();
    h.step();
    let png = image::open(&files[0]).unwrap();
    assert_eq!((png.width(), png.height()), (1920, 1080), "a review slide");
    let svg = std::fs::read_to_string(&files[1]).unwrap();
    assert!(svg.contains("cubesat") && svg.contains("smallsat"), "the caption names the presets");
    for part in ["SNR per band", "Retrieved against true", "Verdicts", "A and B differ in", "Aperture", "aLMI"] {
        assert!(svg.contains(part), "the slide has no `{part}`");
    }
    assert!(!svg.contains("Almi"), "the retrieval named as in the app");
    if let Ok(dir) = std::env::var("SHOAL_KEEP_SLIDE") {
        std::fs::copy(&files[0], std::path::Path::new(&dir).join("review_slide.png")).unwrap();
    }
    // The configuration beside the figure is the one that ran, and loads back.
    let config = std::fs::read_to_string(&files[2]).unwrap();
    assert!(shoal::engine::RunConfig::from_ron(&config, "A").is_ok());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_review_pack_exports_from_the_app_to_a_typed_folder() {
    let dir = temp_library("pack");
    let mut h = harness("cubesat", 16, &dir);
    wait_for_engine(&mut h);
    // The top bar's Export menu offers the three exports.
    h.get_by_label("Export").click();
    h.step();
    h.step();
    for entry in ["Figure…", "Data…", "Review pack…"] {
        assert!(h.query_by_label(entry).is_some(), "the Export menu has no `{entry}`");
    }
    h.key_press(egui::Key::Escape);
    h.step();
    h.get_by_label("Path").click();
    h.step();
    h.step();
    // The typed name writes the pack to NAME_review (the data to NAME_data: never one folder).
    let name = dir.join("pack");
    let folder = dir.join("pack_review");
    h.get_by_role_and_label(Role::TextInput, "Export to").set_text_value_accesskit(name.to_str().unwrap());
    h.step();
    h.get_by_label("Write review pack").click();
    let start = Instant::now();
    let index = folder.join("index.html");
    while !index.is_file() || h.state().exporting() {
        assert!(start.elapsed() < Duration::from_secs(120), "the review pack was not written");
        assert_eq!(h.state().error(), None);
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    h.step();
    h.step();
    // Said where it was written, in the row the button is in.
    assert!(h.query_by_label_contains("wrote the review pack").is_some(), "no confirmation beside the buttons");
    let html = std::fs::read_to_string(&index).unwrap();
    // A and B as the app labels them, the app's requirements judged, figures inline.
    for part in ["A: cubesat", "B: smallsat", "Verdict against the requirements", "<svg role=\"img\"", "id=\"fig-snr\""]
    {
        assert!(html.contains(part), "the pack has no `{part}`");
    }
    assert!(!html.contains("http://") && !html.contains("<script"), "self-contained, no script");
    assert!(folder.join("review.json").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Choosing a preset over an edited instrument asks first; Cancel keeps the edits, Replace
/// loads the preset.
#[test]
fn a_preset_does_not_replace_edits_without_asking() {
    let lib = temp_library("discard");
    let mut h = harness("cubesat", 16, &lib);
    h.step();
    h.get_by_role_and_label(Role::Slider, "Aperture").set_value_accesskit(90.0);
    h.step();
    h.step();
    pick(&mut h, "A", "smallsat");
    assert_eq!(h.state().state.designs[0].spec.aperture_mm, 90.0, "nothing replaced before the answer");
    assert!(
        h.query_all_by_label_contains("replaces unsaved edits of A (cubesat: aperture_mm 60 → 90)").next().is_some(),
        "the question names the edits"
    );
    h.get_by_label("Cancel").click();
    h.step();
    h.step();
    assert_eq!(h.state().state.designs[0].preset, "cubesat");
    assert_eq!(h.state().state.designs[0].spec.aperture_mm, 90.0, "Cancel keeps the edits");

    pick(&mut h, "A", "smallsat");
    h.get_by_label("Replace").click();
    h.step();
    h.step();
    assert_eq!(h.state().state.designs[0].preset, "smallsat");
    assert!((h.state().state.designs[0].spec.aperture_mm - 240.0).abs() < 1e-9);
    let _ = std::fs::remove_dir_all(&lib);
}
