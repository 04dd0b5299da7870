//! The app driven by its accessible labels, headless (egui_kittest): what an engineer does in a
//! review — load a preset, move a slider, wait for the engine, read the metrics table; save and
//! reload a preset; survive a broken preset file.
//!
//! The engine runs at a single reduced resolution (1/8, 192 × 128 pixels of Lake Hume) so each
//! test takes seconds; the physics of the full-resolution chain is tested in tests/chain.
#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::{Duration, Instant};

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use shoal::app::model::{AppState, Slot};
use shoal::app::{AppOptions, ShoalApp};
use shoal::instrument::InstrumentSpec;
use shoal::library::Library;

#[path = "../common/mod.rs"]
mod common;
mod design;
mod designs;
mod editing;
mod exports;
mod external;
mod files;
mod layout;
mod review;
mod season;
mod session;
mod spectrum;

/// Eight designs of the library, every kind of instrument among them (the app's most).
const EIGHT: [&str; 8] = [
    "cubesat",
    "smallsat",
    "nominal",
    "hyperspectral",
    "filter_imager",
    "sentinel3a_olci",
    "smallsat_swir",
    "modis_aqua",
];

/// A fresh, empty user library in the system temporary directory.
fn temp_library(name: &str) -> common::TempDir {
    common::TempDir::new("ui", name)
}

/// The default study (CubeSat vs SmallSat over Lake Hume) with A set to `a`, run at 1/`level`.
fn harness(a: &str, level: usize, library: &std::path::Path) -> Harness<'static, ShoalApp> {
    let mut state = AppState { decimations: vec![level], ..AppState::default() };
    state.designs[0] = Slot::new(a, InstrumentSpec::preset(a).unwrap());
    with_state(state, library)
}

/// The app at 1500 × 960 with `state`, two engine threads and the user library at `library`.
fn with_state(state: AppState, library: &std::path::Path) -> Harness<'static, ShoalApp> {
    let library = Library::at(library);
    Harness::builder().with_size(egui::vec2(1500.0, 960.0)).build_eframe(move |cc| {
        let mut app =
            ShoalApp::with_state(state, &cc.egui_ctx, AppOptions { engine_threads: 2, ..AppOptions::default() });
        app.set_library(library);
        app
    })
}

/// Draw frames until the engine has finished the current configuration of A and B.
fn wait_for_engine(h: &mut Harness<'static, ShoalApp>) {
    let start = Instant::now();
    loop {
        h.step();
        let app = h.state();
        let generation = app.link.generation();
        let current = app.link.shown.iter().all(|s| s.as_ref().is_some_and(|s| s.generation == generation));
        if current && !app.link.busy() {
            break;
        }
        assert!(app.link.errors.iter().all(Option::is_none), "engine error: {:?}", app.link.errors);
        assert!(start.elapsed() < Duration::from_secs(600), "the engine did not finish in 10 minutes");
        std::thread::sleep(Duration::from_millis(20));
    }
    // Two more frames: one takes the results, one draws the table from them.
    h.step();
    h.step();
}

/// Instrument A's chl-a MAE (%), as the metrics table shows it; asserts the table shows it.
fn displayed_chl_mae(h: &Harness<'static, ShoalApp>) -> f64 {
    let shown = h.state().link.shown[0].as_ref().expect("A has a result");
    let metrics = shown.output.retrievals[0].metrics.get("chl_mg_m3").expect("chl metrics");
    let text = format!("{:.1} %", metrics.mae_pct());
    assert!(h.query_all_by_label(&text).next().is_some(), "the table does not show A's chl MAE `{text}`");
    metrics.mae_pct()
}

/// Pick `item` from the combo box labelled `combo`.
fn pick(h: &mut Harness<'static, ShoalApp>, combo: &str, item: &str) {
    h.get_by_role_and_label(Role::ComboBox, combo).click();
    h.step();
    h.step();
    h.get_by_label(item).click();
    h.step();
    h.step();
}

#[test]
fn a_bigger_aperture_lowers_the_cubesat_chl_error() {
    let dir = temp_library("aperture");
    let mut h = harness("smallsat", 8, &dir);
    pick(&mut h, "A", "cubesat");
    assert_eq!(h.state().state.designs[0].preset, "cubesat");
    assert!((h.state().state.designs[0].spec.aperture_mm - 60.0).abs() < 1e-9);
    wait_for_engine(&mut h);
    let before = displayed_chl_mae(&h);

    // Three times the aperture: nine times the photons, so the shot-noise-limited SNR triples
    // and the chl error of the noise-limited CubeSat must fall clearly (at full resolution the
    // 240 mm SmallSat has 11 % against the 60 mm CubeSat's 37 %).
    h.get_by_role_and_label(Role::Slider, "Aperture").set_value_accesskit(180.0);
    h.step();
    assert!((h.state().state.designs[0].spec.aperture_mm - 180.0).abs() < 1e-6);
    assert!(h.state().state.designs[0].modified(), "an edited preset is marked");
    wait_for_engine(&mut h);
    let after = displayed_chl_mae(&h);
    assert!(
        after < 0.8 * before,
        "chl MAE {before:.1} % → {after:.1} %: a 3× aperture should cut it by more than 20 %"
    );
}

#[test]
fn the_sweep_window_draws_a_curve_for_a_and_b() {
    let dir = temp_library("sweep");
    let mut h = harness("cubesat", 24, &dir);
    h.get_by_label("Sweep").click();
    h.step();
    h.step();
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
    // 2 points × 2 instruments × 1 seed, three variables each (chl, NAP, CDOM).
    assert_eq!(h.state().explore().sweep_rows(), 12);
    assert!(h.query_by_label_contains("done: 4 runs").is_some());
    // Each instrument's line says whether it meets the chl requirement.
    assert!(h.query_all_by_label_contains("chl-a MAE ≤").count() >= 2);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A panic inside A's Level-0 stage at one pixel: the app names the stage and the pixel under
/// the metrics table, B's results still arrive, and once the fault is gone A runs again.
#[test]
fn a_stage_that_panics_is_reported_and_the_app_goes_on() {
    use shoal::engine::{Fault, FaultKind, Stage};
    let lib = temp_library("fault");
    let mut h = harness("cubesat", 8, &lib);
    h.state_mut().inject_fault(Some(Fault { stage: Stage::Level0, row: 7, column: 11, kind: FaultKind::Panic }));
    let start = Instant::now();
    loop {
        h.step();
        let app = h.state();
        if app.link.errors[0].is_some() && !app.link.busy() {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(300), "no error reported for A");
        std::thread::sleep(Duration::from_millis(20));
    }
    h.step();
    h.step();
    let error = h.state().link.errors[0].clone().unwrap();
    assert!(error.contains("level-0") && error.contains("row 7, column 11"), "{error}");
    let shown = format!("A: {error}");
    assert!(h.query_all_by_label(&shown).next().is_some(), "the error is not on screen: {shown}");
    assert!(h.state().link.errors[1].is_none(), "B failed too: {:?}", h.state().link.errors[1]);
    // The fault removed, the same configuration runs to the end.
    h.state_mut().inject_fault(None);
    wait_for_engine(&mut h);
    assert!(displayed_chl_mae(&h) > 0.0);
    let _ = std::fs::remove_dir_all(&lib);
}

#[test]
fn the_reference_mode_selector_reruns_alm_as_the_published_code() {
    let dir = temp_library("mode");
    let mut h = harness("cubesat", 16, &dir);
    wait_for_engine(&mut h);
    let improved = displayed_chl_mae(&h);
    // Below the design list and the sliders: a taller window shows it without scrolling.
    h.set_size(egui::vec2(1500.0, 1200.0));
    h.step();
    h.step();
    h.get_by_label("Reference").click();
    h.step();
    let shoal::retrieval::RetrievalSpec::Almi { settings, .. } = h.state().state.retrieval_spec() else {
        panic!("aLMI runs")
    };
    assert_eq!(settings.mode, shoal::retrieval::Mode::Reference);
    wait_for_engine(&mut h);
    let reference = displayed_chl_mae(&h);
    // The DEA code's unweighted solve drops every set with a concentration below 1e-5: on the
    // noisy CubeSat it returns fewer pixels and a far larger chl error (decimation 24: 151 %
    // against 38 %, `tests/chain/reproduction.rs`).
    assert!(reference > 2.0 * improved, "chl MAE improved {improved:.1} %, reference {reference:.1} %");
}

#[test]
fn an_instrument_that_returns_no_pixel_is_never_a_pass() {
    // A 10 e⁻ well saturates on every water pixel: nothing is retrieved. The metrics of an empty
    // product read MAE 0 %, bias 0 %; before the verdicts were shared with `shoal study` the table
    // said "pass" for chl, NAP and CDOM here.
    let dir = temp_library("nothing");
    let mut broken = InstrumentSpec::preset("cubesat").unwrap();
    broken.well_depth_e = 10.0;
    let mut state = AppState { decimations: vec![16], ..AppState::default() };
    state.designs = vec![Slot::new("cubesat", broken.clone()), Slot::new("cubesat", broken)];
    let mut h = with_state(state, &dir);
    wait_for_engine(&mut h);
    let shown = h.state().link.shown[0].as_ref().unwrap();
    let chl = shown.output.retrievals[0].metrics.get("chl_mg_m3").unwrap();
    assert_eq!(chl.n, 0, "the saturated instrument returns no chl pixel");
    assert_eq!(chl.mae_pct(), 0.0, "the empty metrics the old verdict took for a pass");
    assert!(h.query_all_by_label("pass").next().is_none(), "a verdict of `pass` is on screen");
    // chl, NAP and CDOM for A and B, and the SNR row.
    let fails = h.query_all_by_label("FAIL").count();
    assert!(fails >= 6, "{fails} FAIL verdicts on screen");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_shallow_scene_under_alm_shows_a_banner_whose_button_switches_to_sambuca() {
    // Loading the Heron Island reef once kept aLMI (chl MAE ~985 %, all FAIL, no hint).
    let dir = temp_library("banner");
    let mut h = harness("cubesat", 16, &dir);
    h.step();
    let banner = "has a visible bottom";
    assert!(h.query_by_label_contains(banner).is_none(), "Lake Hume (deep) shows no banner");
    pick(&mut h, "Scene", "heron_island_reef");
    assert_eq!(h.state().state.scene_name, "heron_island_reef");
    assert!(h.query_by_label_contains(banner).is_some(), "no banner over a shallow scene under aLMI");
    h.get_by_label("Use SAMBUCA").click();
    h.step();
    h.step();
    assert!(h.state().state.runs("sambuca"));
    assert_eq!(h.state().state.product, shoal::app::model::ProductKind::Depth, "the depth map is shown");
    assert!(h.query_by_label_contains(banner).is_none(), "the banner goes once SAMBUCA runs");
    // SAMBUCA unmixes substrates: the substrate accuracy of its confusion table is on screen and
    // equals the agreement the metrics report.
    wait_for_engine(&mut h);
    let metrics = &h.state().link.shown[0].as_ref().expect("A has a result").output.retrievals[0].metrics;
    let confusion = metrics.substrate_confusion.as_ref().expect("a substrate confusion table");
    let accuracy = confusion.accuracy_pct().expect("pixels counted");
    assert!((accuracy - metrics.substrate_agreement_pct.unwrap()).abs() < 1e-9);
    let title = format!("A: dominant substrate, {accuracy:.1} % of pixels correct");
    assert!(h.query_by_label_contains(&title).is_some(), "`{title}` is not on screen");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The histogram and scatter data (computed on the raster thread) count every pixel they claim
/// to: the truth histogram every water pixel with a truth, A's every returned pixel, on bins
/// that span the central 99 % of the values; the scatter is a sample no bigger than its cap.
#[test]
fn the_histograms_count_every_returned_pixel_and_the_scatter_is_a_capped_sample() {
    use shoal::app::plot_data::{BINS, PlotData, SCATTER_POINTS, plot_data};
    let mut config = AppState::default().configs().remove(0);
    config.fidelity.decimation = 8;
    let out = std::sync::Arc::new(
        shoal::engine::Engine::new().run(&config, &shoal::control::RunControl::new()).expect("runs"),
    );
    let data = plot_data(&[Some(out.clone()), None], "chl_mg_m3");
    let truth = &out.truth;
    let product = &out.retrievals[0].product;
    let (mut with_truth, mut returned) = (0, 0);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for ((r, c), t) in truth.chl_mg_m3.indexed_iter() {
        if truth.surface.codes()[[r, c]] != 0 || *t <= 0.0 {
            continue;
        }
        with_truth += 1;
        let t = f64::from(*t).log10();
        (lo, hi) = (lo.min(t), hi.max(t));
        let g = product.chl_mg_m3.as_ref().unwrap()[[r, c]];
        if product.returned(r, c) && g > 0.0 {
            returned += 1;
            let g = f64::from(g).log10();
            (lo, hi) = (lo.min(g), hi.max(g));
        }
    }
    assert!(returned > 1000, "a run that returns pixels ({returned})");
    assert_eq!(data.truth.iter().sum::<usize>(), with_truth);
    assert_eq!(data.counts[0].iter().sum::<usize>(), returned);
    assert_eq!(data.counts[1].iter().sum::<usize>(), 0, "no B run");
    // Drawn as shares of each run's water pixels (a preview beside a full-resolution run): the
    // truth's shares sum to 100 %, A's to its returned %.
    assert_eq!((data.pixels.as_slice(), data.truth_pixels), (&[with_truth, 0][..], with_truth));
    let share: f64 = data.counts[0].iter().map(|n| PlotData::percent(*n, data.pixels[0])).sum();
    assert!((share - 100.0 * returned as f64 / with_truth as f64).abs() < 1e-9, "{share}");
    assert_eq!(data.edges_log10.len(), BINS + 1);
    // The bins span the central 99 % of the values (outliers in the end bins): inside the full
    // range, and holding at least 98 % of the truth.
    let (first, last) = (data.edges_log10[0], data.edges_log10[BINS]);
    assert!(first >= lo && last <= hi && last > first, "bins {first}..{last}, values {lo}..{hi}");
    let inside = truth
        .chl_mg_m3
        .indexed_iter()
        .filter(|((r, c), t)| truth.surface.codes()[[*r, *c]] == 0 && **t > 0.0)
        .filter(|(_, t)| (first..=last).contains(&f64::from(**t).log10()))
        .count();
    assert!(inside as f64 >= 0.98 * with_truth as f64, "{inside} of {with_truth} truth values inside the bins");
    assert!(!data.scatter[0].is_empty() && data.scatter[0].len() <= SCATTER_POINTS);
}

/// At 1280 × 720 and at 1920 × 1080 every plot keeps at least its minimum width and lies inside
/// the window (at 1280 × 720 the SNR plot used to collapse to a sliver past the right edge).
#[test]
fn the_plots_keep_their_minimum_width_from_1280x720_to_4k() {
    for (w, h_px) in [(1280.0, 720.0), (1920.0, 1080.0), (3840.0, 2160.0)] {
        let dir = temp_library(&format!("layout{w}"));
        let mut h = harness("cubesat", 16, &dir);
        h.set_size(egui::vec2(w, h_px));
        wait_for_engine(&mut h);
        h.step();
        let rects = h.state().plot_rects().to_vec();
        assert_eq!(rects.len(), 3, "histogram, scatter and SNR plots drawn");
        for r in &rects {
            assert!(
                r.width() >= shoal::app::plots::MIN_PLOT_WIDTH - 8.0,
                "{w}×{h_px}: a plot is {:.0} px wide, below its minimum",
                r.width()
            );
            assert!(r.right() <= w + 0.5, "{w}×{h_px}: a plot ends at {:.0}, past the window", r.right());
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// The seed spread: A and B rerun over two noise seeds, the table shows ± beside the MAE, and an
/// edit marks the spread stale and hides it (it belongs to the designs it was measured for).
#[test]
fn the_seed_spread_shows_beside_the_mae_and_goes_stale_after_an_edit() {
    let dir = temp_library("seeds");
    let mut h = harness("cubesat", 24, &dir);
    wait_for_engine(&mut h);
    assert_eq!(h.query_all_by_label_contains(" ±").count(), 0, "no spread before it is measured");
    h.get_by_role_and_label(Role::SpinButton, "noise seeds").set_value_accesskit(2.0);
    h.get_by_role_and_label(Role::SpinButton, "1/").set_value_accesskit(16.0);
    h.step();
    h.get_by_label("Seed spread").click();
    h.step();
    let start = Instant::now();
    loop {
        h.step();
        if h.query_by_label_contains("2 seeds at 1/16").is_some() {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(300), "the seed spread did not finish");
        std::thread::sleep(Duration::from_millis(20));
    }
    h.step();
    // chl, NAP and CDOM of A and B: six MAE cells carry a ±.
    assert_eq!(h.query_all_by_label_contains(" ±").count(), 6, "a ± on every MAE cell");
    h.state_mut().state.designs[0].spec.aperture_mm *= 1.5;
    h.step();
    h.step();
    assert_eq!(h.query_all_by_label_contains(" ±").count(), 0, "a stale spread is not shown");
    assert!(h.query_by_label_contains("stale").is_some(), "the stale spread is named");
    let _ = std::fs::remove_dir_all(&dir);
}
