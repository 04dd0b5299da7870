//! The Season window flies the designs on screen over a site for a period: the looks and the
//! revisit at once, then the chain runs streaming in; a bad period is refused by field.

use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;

use super::{harness, pick, temp_library};

#[test]
fn the_season_window_runs_the_designs_on_screen_over_a_month() {
    let dir = temp_library("season");
    let mut h = harness("cubesat", 24, &dir);
    h.get_by_label("Season").click();
    h.step();
    h.step();
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
