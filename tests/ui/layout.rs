//! The window's layout with many designs: every control of the maps inside the window at the
//! sizes a reviewer brings (1280 × 720 with eight designs, 900 × 600 with three), the left panel
//! no wider than its share.

use std::time::{Duration, Instant};

use super::*;

fn designs(names: &[&str]) -> Vec<Slot> {
    names.iter().map(|n| Slot::new(n, InstrumentSpec::preset(n).unwrap())).collect()
}

/// The rectangles of the controls a reviewer needs: the product menu, both layouts, Reset zoom,
/// the last design's Edit button and, in the difference layout, the pair selectors; and the
/// colour bars. Each must lie inside `size`.
fn controls_inside(h: &mut Harness<'static, ShoalApp>, size: egui::Vec2, n: usize) {
    let window = egui::Rect::from_min_size(egui::Pos2::ZERO, size);
    let last = shoal::app::model::label(n - 1);
    let mapped: Vec<String> = (0..n.min(4)).map(shoal::app::model::label).collect();
    let truth = format!("truth | {}", mapped.join(" | "));
    let pair = "A | B | A − B";
    let check = |h: &Harness<'static, ShoalApp>, names: &[String]| {
        for name in names {
            let r = h.get_by_label(name).rect();
            assert!(window.contains_rect(r), "`{name}` at {r:?} is outside the {size:?} window");
        }
        for r in h.state().map_rects() {
            assert!(window.contains_rect(*r), "a colour bar at {r:?} is outside the {size:?} window");
        }
        assert!(!h.state().map_rects().is_empty(), "no colour bar drawn");
    };
    let names: Vec<String> = ["Product", "Reset zoom", truth.as_str(), pair, &format!("Edit {last}")]
        .iter()
        .map(|s| s.to_string())
        .collect();
    check(h, &names);
    // The left panel takes at most 45 % of the window.
    let edit = h.get_by_label(&format!("Edit {last}")).rect();
    let product = h.get_by_label("Product").rect();
    assert!(product.left() <= 0.47 * size.x, "the maps start at {} of {}", product.left(), size.x);
    assert!(edit.right() < product.left());
    h.get_by_label(pair).click();
    for _ in 0..4 {
        h.step();
    }
    assert!(h.state().map_rects().len() == 2, "the difference layout has its own colour bar");
    let pair_boxes: Vec<egui::Rect> = h.query_all_by_role(egui::accesskit::Role::ComboBox).map(|n| n.rect()).collect();
    for r in &pair_boxes {
        // Every menu of the window: the designs' presets, the product and the pair's two.
        assert!(r.right() <= size.x && r.left() >= 0.0, "a menu at {r:?} is outside the {size:?} window");
    }
    check(h, &names[..4]);
}

#[test]
fn eight_designs_fit_1280_by_720_and_three_fit_900_by_600() {
    let dir = temp_library("layout");
    for (names, size) in [
        (&super::EIGHT[..], egui::vec2(1280.0, 720.0)),
        (&["cubesat", "smallsat", "nominal"][..], egui::vec2(900.0, 600.0)),
    ] {
        let on_maps = (0..names.len().min(4)).collect();
        let state = AppState { designs: designs(names), on_maps, decimations: vec![16], ..AppState::default() };
        let mut h = with_state(state, &dir);
        h.set_size(size);
        wait_for_engine(&mut h);
        controls_inside(&mut h, size, names.len());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The slide of eight designs: every design's map, legend entry and verdict row, the title and
/// the parameter table within the slide (nothing cut) (`SHOAL_KEEP_SLIDE=DIR` keeps the PNG).
#[test]
fn the_slide_of_eight_designs_cuts_nothing() {
    let dir = temp_library("slide8");
    let names = super::EIGHT;
    let state = AppState { designs: designs(&names), decimations: vec![16], ..AppState::default() };
    let mut h = with_state(state, &dir);
    wait_for_engine(&mut h);
    h.get_by_label("Path").click();
    h.step();
    h.step();
    let stem = dir.join("eight");
    h.get_by_role_and_label(egui::accesskit::Role::TextInput, "Export to")
        .set_text_value_accesskit(stem.to_str().unwrap());
    h.step();
    h.get_by_label("Write figure").click();
    let start = Instant::now();
    while !stem.with_extension("svg").is_file() || h.state().exporting() {
        assert!(start.elapsed() < Duration::from_secs(120), "the figure was not written");
        assert_eq!(h.state().error(), None);
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    let svg = std::fs::read_to_string(stem.with_extension("svg")).unwrap();
    for (i, name) in names.iter().enumerate() {
        let design = format!("{}: {name}", shoal::app::model::label(i));
        // A map title, an SNR and a scatter legend entry, and a verdict row each.
        assert!(svg.matches(&design).count() >= 4, "`{design}` is not on the slide four times");
    }
    if let Ok(keep) = std::env::var("SHOAL_KEEP_SLIDE") {
        std::fs::copy(stem.with_extension("png"), std::path::Path::new(&keep).join("slide_eight.png")).unwrap();
    }
    assert!(!svg.contains("more rows") && !svg.contains("more columns"), "the slide cut a table");
    let _ = std::fs::remove_dir_all(&dir);
}
