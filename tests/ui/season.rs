//! The Season window flies the designs on screen over a site for a period: the looks and the
//! revisit at once, then the chain runs streaming in; a bad period is refused by field.

use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;

use super::{harness, pick, temp_library};

/// The app on the CubeSat at 1/24 in a library of its own (`name`), its Season window open.
fn season_window(name: &str) -> (super::common::TempDir, egui_kittest::Harness<'static, shoal::app::ShoalApp>) {
    let dir = temp_library(name);
    let mut h = harness("cubesat", 24, &dir);
    h.get_by_label("Season").click();
    h.step();
    h.step();
    (dir, h)
}

#[test]
fn the_season_window_runs_the_designs_on_screen_over_a_month() {
    let (dir, mut h) = season_window("season");
    // A bad date is refused naming the field, and nothing runs.
    h.get_by_role_and_label(Role::TextInput, "to").set_text_value_accesskit("2023-13-01");
    h.step();
    h.get_by_label("Run").click();
    h.step();
    h.step();
    assert!(!h.state().explore().busy());
    assert!(h.query_by_label_contains("month 13").is_some(), "the refusal names the month");
    // March at Lake Hume, six runs per design at 1/32.
    h.get_by_role_and_label(Role::TextInput, "from").set_text_value_accesskit("2023-03-01");
    h.get_by_role_and_label(Role::TextInput, "to").set_text_value_accesskit("2023-03-31");
    h.step();
    pick(&mut h, "resolution", "1/32");
    h.get_by_label("Run").click();
    h.step();
    let start = Instant::now();
    while h.state().explore().busy() {
        assert!(start.elapsed() < Duration::from_secs(300), "the season did not finish");
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    h.step();
    h.step();
    assert!(h.query_by_label_contains("done: 12 chain runs").is_some(), "the status says the runs ended");
    let s = h.state().explore().season.summary().expect("a season summary").clone();
    assert_eq!(s.designs.len(), 2, "both designs on screen");
    for d in &s.designs {
        assert!(d.by_verdict[0] > 0, "{}: no valid look in March", d.label);
        assert_eq!(d.runs, 6, "{}: six runs", d.label);
        assert!(d.phases == 12 && d.phase_valid.is_some(), "{}: the orbit phases come after the runs", d.label);
        assert!(d.products.iter().any(|p| p.variable == "chl_mg_m3" && p.looks == 6 && p.mae_median_pct > 0.0));
    }
    assert!(h.query_by_label("MAE % median").is_some(), "the error table is shown");
    // The review pack written now carries the season, as `shoal report --season` does (the
    // window closed: its finished season stays).
    h.get_by_label("Close window").click();
    h.step();
    h.step();
    super::wait_for_engine(&mut h);
    let stem = dir.join("season");
    super::exports::export(&mut h, &stem, "Write review pack", &dir.join("season_review").join("index.html"));
    let html = std::fs::read_to_string(dir.join("season_review").join("index.html")).unwrap();
    for part in ["id=\"seasons\"", "<h3>lake_hume_year</h3>", "id=\"fig-season_valid_looks\"", "A: cubesat"] {
        assert!(html.contains(part), "the pack has no `{part}`");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Stop while the spread over orbit phases is being made: the looks and the runs stay, the
/// status says where it stopped, and the window is free to run again. Ten years of looks, so the
/// spread (12 phases of ten years' passes, ~0.3 s a year and phase on one core) is still running
/// after the runs end: seconds on two cores, and on any number of cores at least one phase's ten
/// years (~3 s), while the click comes a frame or two (milliseconds) after them.
#[test]
fn stop_in_the_spread_over_orbit_phases_keeps_the_looks() {
    let (dir, mut h) = season_window("season-stop");
    h.get_by_role_and_label(Role::TextInput, "from").set_text_value_accesskit("2023-01-01");
    h.get_by_role_and_label(Role::TextInput, "to").set_text_value_accesskit("2032-12-31");
    h.step();
    pick(&mut h, "resolution", "1/32");
    h.get_by_label("Run").click();
    h.step();
    let start = Instant::now();
    while h.query_by_label_contains("the spread over orbit phases …").is_none() {
        assert!(h.state().explore().busy(), "the season ended before its spread could be stopped");
        assert!(start.elapsed() < Duration::from_secs(300), "the runs did not end");
        std::thread::sleep(Duration::from_millis(5));
        h.step();
    }
    h.get_by_label("Stop").click();
    h.step();
    h.step();
    assert!(!h.state().explore().busy(), "Stop ends the season's task");
    assert!(
        h.query_by_label_contains("stopped in the spread over orbit phases (12 of 12 chain runs made)").is_some(),
        "the status says where it stopped"
    );
    let s = h.state().explore().season.summary().expect("the looks stay").clone();
    for d in &s.designs {
        assert!(d.passes > 1000 && d.by_verdict[0] > 0, "{}: ten years of looks", d.label);
        assert_eq!(d.runs, 6, "{}: the runs made stay", d.label);
        assert_eq!(d.phases, 0, "{}: no spread was kept", d.label);
    }
    assert!(h.query_by_label("Run").is_some(), "the window can run again");
    let _ = std::fs::remove_dir_all(&dir);
}
