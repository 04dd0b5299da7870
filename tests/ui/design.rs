//! The Design window searches from A against the Requirements panel, lists every design it
//! evaluated with its cost and verdict, and puts a clicked design into A.

use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;

use super::{harness, pick, temp_library};

#[test]
fn the_design_window_searches_and_puts_a_design_into_a() {
    let dir = temp_library("design");
    let mut h = harness("cubesat", 24, &dir);
    h.get_by_label("Design").click();
    h.step();
    h.step();
    // One parameter (the aperture), the default 20 designs, at 1/16.
    h.get_all_by_label("remove").nth(1).expect("two parameters to start").click();
    h.step();
    h.step();
    assert!(h.query_by_role_and_label(Role::Slider, "Designs").is_some());
    pick(&mut h, "Search resolution", "1/16");
    h.get_by_label("Search").click();
    h.step();
    let start = Instant::now();
    while h.state().explore().busy() {
        assert!(start.elapsed() < Duration::from_secs(300), "the search did not finish");
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    h.step();
    h.step();
    let results = h.state().explore().design.results().to_vec();
    assert_eq!(results.len(), 20, "twenty designs evaluated");
    assert!(results.iter().all(|e| e.x.len() == 1), "one parameter varied");
    assert!(results.iter().all(|e| e.error.is_none() && e.cost.is_some_and(|c| c > 0.0)));
    assert!(h.query_by_label_contains("done:").is_some(), "the status says the search ended");
    // The table lists designs by cost: the first "→ A" is the cheapest.
    let cheapest = results.iter().min_by(|a, b| a.cost.unwrap().total_cmp(&b.cost.unwrap())).unwrap();
    h.get_all_by_label("→ A").next().expect("a row per design").click();
    h.step();
    h.step();
    assert!(
        (h.state().state.designs[0].spec.aperture_mm - cheapest.x[0]).abs() < 1e-9,
        "A takes the design's aperture"
    );
    // "+ design" adds it under a file-safe name the list, the slide and the pack share, and a
    // description that says where it came from (not the CubeSat preset's words).
    h.get_all_by_label("+ design").next().expect("a row per design").click();
    h.step();
    h.step();
    let added = h.state().state.designs.last().unwrap().clone();
    assert!(added.preset.starts_with("search ") && added.spec.name == added.preset, "{}", added.preset);
    assert!(added.spec.validate().is_ok(), "the added design's name is refused");
    assert!(added.spec.description.starts_with("found by the design search from"));
    // Stop ends a search at once and keeps what it found.
    h.get_by_label("Search").click();
    h.step();
    assert!(h.state().explore().busy());
    h.get_by_label("Stop").click();
    let start = Instant::now();
    while h.state().explore().busy() {
        assert!(start.elapsed() < Duration::from_secs(30), "Stop did not stop the search");
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    h.step();
    assert!(h.query_by_label_contains("stopped after").is_some(), "the status does not say it stopped");
    let _ = std::fs::remove_dir_all(&dir);
}
