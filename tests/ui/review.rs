//! What a reviewer carries from the app must belong to the configuration on screen: a failed run
//! greys nothing into a pass and the top bar never says "up to date" over it; a run can be
//! cancelled at its preview and refined later; a saturating design fails its SNR verdict; the
//! sweep takes any product and any number of the run; buttons do not move under the pointer;
//! the wheel over a plot scrolls the panel.

use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use shoal::app::ShoalApp;

use super::{harness, pick, temp_library, wait_for_engine};

/// Frames until the engine is idle (its runs finished or failed).
fn wait_until_idle(h: &mut Harness<'static, ShoalApp>) {
    let start = Instant::now();
    loop {
        h.step();
        if !h.state().link.busy() {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(300), "the engine did not settle");
        std::thread::sleep(Duration::from_millis(20));
    }
    h.step();
    h.step();
}

#[test]
fn a_failed_run_shows_its_reason_not_the_previous_numbers_and_offers_the_way_out() {
    let dir = temp_library("failed");
    let mut h = harness("cubesat", 16, &dir);
    pick(&mut h, "Scene", "heron_island_reef");
    h.get_by_label("Use SAMBUCA").click();
    wait_for_engine(&mut h);
    assert!(h.query_all_by_label_contains("up to date").next().is_some());
    let reef_mae = h.state().link.shown[0].as_ref().expect("a reef result").output.retrievals[0]
        .metrics
        .get("chl_mg_m3")
        .map(|m| format!("{:.1} %", m.mae_pct()))
        .expect("chl");
    // Back to the deep lake: SAMBUCA cannot run there (no substrate).
    pick(&mut h, "Scene", "lake_hume_bloom");
    wait_until_idle(&mut h);
    assert!(h.query_all_by_label_contains("up to date").next().is_none(), "`up to date` over a failed run");
    assert!(h.query_all_by_label_contains("A and B failed").next().is_some(), "the top bar names the failure");
    assert!(h.query_all_by_label_contains("the run of the configuration set failed").next().is_some());
    assert!(h.query_all_by_label_contains("SAMBUCA needs at least one substrate").next().is_some(), "the reason");
    assert!(h.query_all_by_label_contains("(failed)").next().is_some(), "the metrics columns say failed");
    assert!(h.query_all_by_label(&reef_mae).next().is_none(), "the reef's chl MAE {reef_mae} is still on screen");
    assert!(h.query_all_by_label("pass").next().is_none(), "a verdict of the reef's run is on screen");
    assert_eq!(h.state().map_panels(), 0, "a map of the reef is on screen");
    // The way out.
    h.get_all_by_label("Use aLMI").next().expect("a `Use aLMI` button").click();
    h.step();
    assert!(h.state().state.runs("alm"));
    wait_for_engine(&mut h);
    assert!(h.query_all_by_label_contains("up to date").next().is_some());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_run_cancelled_at_its_preview_stays_a_preview_until_refined() {
    let dir = temp_library("cancel");
    let mut h = harness("cubesat", 24, &dir);
    // Preview at 1/24, then full resolution: long enough to cancel.
    h.state_mut().state.decimations = vec![24, 1];
    let start = Instant::now();
    loop {
        h.step();
        let previewed = (0..2).all(|i| h.state().link.current(i).is_some_and(|s| s.decimation == 24));
        if previewed && h.state().link.busy() {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(120), "no preview");
        std::thread::sleep(Duration::from_millis(10));
    }
    h.get_by_label("Cancel run").click();
    h.step();
    h.step();
    assert!(!h.state().link.busy(), "the engine still counts as working");
    assert!(h.query_all_by_label_contains("stopped: previews").next().is_some());
    assert!(
        h.query_all_by_label_contains("(preview 1/24)").next().is_some(),
        "the table says its numbers are a preview"
    );
    // Nothing runs again by itself.
    for _ in 0..10 {
        h.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(h.state().link.current(0).is_some_and(|s| s.decimation == 24));
    h.get_by_label("Refine").click();
    h.step();
    h.step();
    assert!(h.state().link.busy(), "Refine runs on");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_saturating_design_fails_its_snr_verdict() {
    let dir = temp_library("saturated");
    let mut h = harness("cubesat", 16, &dir);
    h.step();
    h.get_by_role_and_label(Role::Slider, "Aperture").set_value_accesskit(2000.0);
    wait_for_engine(&mut h);
    let a = &h.state().link.shown[0].as_ref().expect("A").output;
    assert!(a.snr.iter().all(shoal::instrument::SnrRow::saturated), "2000 mm saturates every band");
    assert!(h.query_all_by_label_contains("19 saturated").next().is_some(), "the SNR row says so");
    // A's SNR verdict fails; B (the SmallSat, unchanged) keeps its own.
    let snr_checks = h.state().state.requirements.check_run("a", 1, None, &a.snr, &[]);
    assert!(snr_checks.iter().all(|c| !c.pass && c.what.contains("saturated")), "{snr_checks:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_sweep_takes_any_product_and_any_number_of_the_run() {
    let dir = temp_library("sweepvar");
    let mut h = harness("cubesat", 24, &dir);
    h.get_by_label("Sweep").click();
    h.step();
    h.step();
    pick(&mut h, "Parameter", "Pixel pitch: instrument.pixel_pitch_um (µm)");
    pick(&mut h, "MAE of", "NAP (g m⁻³)");
    h.get_by_role_and_label(Role::Slider, "Points").set_value_accesskit(2.0);
    h.get_by_role_and_label(Role::Slider, "Seeds").set_value_accesskit(1.0);
    h.step();
    pick(&mut h, "Resolution", "1/24");
    h.get_by_label("Run sweep").click();
    h.step();
    let start = Instant::now();
    while h.state().explore().busy() {
        assert!(start.elapsed() < Duration::from_secs(300), "the sweep did not finish");
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    h.step();
    h.step();
    assert_eq!(h.state().explore().sweep_rows(), 12, "{}", h.state().explore().sweep_status());
    assert!(h.query_all_by_label_contains("NAP MAE ≤").count() >= 2, "the lines judge NAP, not chl-a");
    // Its series are named as the design list names the designs.
    let e = h.state().explore();
    assert_eq!(
        (e.shown_label("A cubesat"), e.shown_label("B smallsat, x = 2")),
        ("A: cubesat".into(), "B: smallsat, x = 2".into())
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_toolbar_does_not_move_when_an_instrument_becomes_modified() {
    let dir = temp_library("toolbar");
    let mut h = harness("cubesat", 16, &dir);
    h.set_size(egui::vec2(1280.0, 720.0));
    h.step();
    let rects = |h: &Harness<'static, ShoalApp>| -> Vec<egui::Rect> {
        ["Undo", "Redo", "Export", "Sweep", "Cost", "Path", "Light", "Dark"]
            .iter()
            .map(|l| h.get_by_label(l).rect())
            .collect()
    };
    let before = rects(&h);
    h.get_by_role_and_label(Role::Slider, "Aperture").set_value_accesskit(90.0);
    h.step();
    h.step();
    assert!(h.query_all_by_label_contains("(modified)").next().is_some());
    assert_eq!(rects(&h), before, "a button moved when `(modified)` appeared");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_wheel_over_a_plot_scrolls_the_panel_and_does_not_zoom_it() {
    let dir = temp_library("wheel");
    let mut h = harness("cubesat", 16, &dir);
    h.set_size(egui::vec2(1280.0, 720.0));
    wait_for_engine(&mut h);
    let before = h.state().plot_rects().to_vec();
    // A point of the plot inside the window (the metrics table of the default study's image-based
    // correction has rows that push the plots' centres below its bottom edge).
    let plot = before.first().expect("a plot");
    let over = egui::pos2(plot.center().x, (plot.top() + 20.0).min(700.0));
    h.event(egui::Event::PointerMoved(over));
    h.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, -120.0),
        modifiers: egui::Modifiers::NONE,
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Unknown,
    });
    for _ in 0..6 {
        h.step();
    }
    let after = h.state().plot_rects().to_vec();
    assert!(after[0].top() < before[0].top() - 20.0, "the panel did not scroll: {before:?} → {after:?}");
    assert_eq!(after[0].size(), before[0].size(), "the plot changed size");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The slide over the reef under SAMBUCA: titled by what is compared (not the study it came
/// from), every product's row and the bottom type and SNR rows present with nothing cut, the
/// caption true to the instruments (`SHOAL_KEEP_SLIDE=DIR` keeps the PNG).
#[test]
fn the_slide_over_the_reef_names_what_is_compared_and_cuts_no_row() {
    let dir = temp_library("reefslide");
    let mut h = harness("cubesat", 16, &dir);
    pick(&mut h, "Scene", "heron_island_reef");
    h.get_by_label("Use SAMBUCA").click();
    wait_for_engine(&mut h);
    h.get_by_label("Path").click();
    h.step();
    h.step();
    let stem = dir.join("review").join("reef");
    h.get_by_role_and_label(Role::TextInput, "Export to").set_text_value_accesskit(stem.to_str().unwrap());
    h.step();
    h.get_by_label("Write figure").click();
    let svg_path = dir.join("review").join("reef.svg");
    let start = Instant::now();
    while !svg_path.is_file() {
        assert!(start.elapsed() < Duration::from_secs(120), "the figure was not written");
        assert_eq!(h.state().error(), None);
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    assert!(svg.contains("cubesat vs smallsat over heron_island_reef"), "the title names the comparison");
    assert!(!svg.contains("cubesat_vs_smallsat"), "the study's name over another scene");
    for row in ["depth (m)", "bottom type", "SNR, every band", "SAMBUCA"] {
        assert!(svg.contains(row), "the slide has no `{row}`");
    }
    assert!(!svg.contains("more rows"), "rows were cut");
    assert!(svg.contains("Instruments as in their presets."), "the caption says what it knows");
    if let Ok(keep) = std::env::var("SHOAL_KEEP_SLIDE") {
        std::fs::copy(dir.join("review").join("reef.png"), std::path::Path::new(&keep).join("reef_slide.png")).unwrap();
    }
    let _ = std::fs::remove_dir_all(&dir);
}
