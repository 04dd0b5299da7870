//! `shoal reproduce` at a decimation that fits CI: both paper studies with each retrieval in its
//! reference and improved modes. Each figure is pinned within a band around the value measured
//! at this decimation (a regression guard, not a tuning target), with the reason for its width;
//! the relations the paper reports are asserted outright.

use shoal::control::RunControl;
use shoal::study::reproduction::{self, HERON_ISLAND, LAKE_HUME, Numbers};
use shoal::study::{StudyResult, run_study};

/// 1/24 of the lines and detectors: ~2,700 Lake Hume and ~330 Heron pixels per instrument.
const DECIMATION: usize = 24;

fn run(name: &str) -> StudyResult {
    let spec = reproduction::both_modes(name).unwrap();
    let mut resolved = spec.resolve(None).unwrap();
    for (_, _, c) in &mut resolved.runs {
        c.fidelity.decimation = DECIMATION;
    }
    run_study(&resolved, &RunControl::new(), false, |_, _| Ok(())).unwrap()
}

fn within(what: &str, value: f64, (lo, hi): (f64, f64)) {
    assert!((lo..=hi).contains(&value), "{what}: {value:.2} outside [{lo}, {hi}]");
}

#[test]
fn the_paper_studies_reproduce_at_ci_size() {
    let (lake, heron) = (run(LAKE_HUME), run(HERON_ISLAND));
    let n: Numbers = reproduction::numbers(&lake, &heron).unwrap();
    let rows = reproduction::rows(&n, Some(DECIMATION));
    println!("{}", reproduction::markdown(&rows, "reproduction at decimation 24"));
    println!("{n:?}");
    // Relations the paper reports, in both modes.
    for mode in 0..2 {
        let [nominal, cubesat, smallsat] = [n.chl_mae_pct[0][mode], n.chl_mae_pct[1][mode], n.chl_mae_pct[2][mode]];
        assert!(
            smallsat < nominal && nominal < cubesat,
            "mode {mode}: chl MAE order {smallsat} < {nominal} < {cubesat}"
        );
    }
    // The reference aLMI leaves more CubeSat pixels unreturned than SmallSat ones (§3.2).
    assert!(n.not_returned[1][0] > n.not_returned[2][0], "{:?}", n.not_returned);
    // Bands around the values measured at this decimation (seed 1; release and test builds give
    // the same numbers). ±15 % of each value: a refinement of any stage moves these by a few %,
    // while a broken mode moves them by far more (the reference aLMI without its drop rule gives
    // the improved column's 18 % instead of 72 %; a SAMBUCA reference fit that no longer stalls
    // anywhere, or stalls everywhere, moves the depth MAE by tens of %).
    let band = |v: f64| (v * 0.85, v * 1.15);
    let measured_chl = [[72.1, 18.3], [151.0, 37.6], [30.3, 11.0]];
    for (i, label) in ["nominal", "CubeSat", "SmallSat"].iter().enumerate() {
        for (mode, name) in ["reference", "improved"].iter().enumerate() {
            within(&format!("{label} chl MAE, {name}"), n.chl_mae_pct[i][mode], band(measured_chl[i][mode]));
        }
    }
    within("CubeSat pixels not returned, reference", n.not_returned[1][0] as f64, band(1300.0));
    assert!(n.not_returned[2][0] <= 10, "SmallSat pixels not returned, reference: {}", n.not_returned[2][0]);
    assert_eq!(n.not_returned.iter().map(|m| m[1]).sum::<usize>(), 0, "improved aLMI returns every pixel here");
    assert_eq!(n.sets_used[0], [8, 8], "CubeSat chooses all eight sets in both modes");
    assert!((5..=8).contains(&n.sets_used[1][0]), "SmallSat sets, reference: {:?}", n.sets_used[1]);
    within("Heron seagrass share", n.seagrass_share_pct, (24.0, 33.0));
    // The stall: with 0.1-30 m bounds the package's start (14.95 m) leaves the bottom out of
    // sight and ~14 % of the fits stay there, which makes the published-size error; with the
    // start in sight (0.1-7 m) almost none stall and the error is Shoal's improved one.
    within("Heron depth MAE, reference", n.depth_mae_pct[0], band(97.2));
    within("Heron depth MAE, improved", n.depth_mae_pct[1], band(4.5));
    within("Heron depth MAE, reference, start in sight", n.depth_mae_pct_shallow_start, band(4.4));
    within("Heron stalled pixels, %", n.stalled_pct, band(14.1));
    assert!(n.stalled_pct_shallow_start < 2.0, "{}", n.stalled_pct_shallow_start);
    within("Heron depth bias over seagrass, reference", -n.seagrass_depth_bias_pct[0], band(4.0));
    within("Heron depth bias over seagrass, improved", -n.seagrass_depth_bias_pct[1], band(4.2));
    let figure = reproduction::figure5(&lake, &heron, &n).unwrap();
    assert!(figure.png.starts_with(b"\x89PNG") && figure.svg.contains("Figure 5 reproduced"));
    let csv = reproduction::csv(&rows);
    assert_eq!(csv.lines().count(), 1 + rows.len());
    assert!(csv.starts_with("quantity,paper,shoal_reference,shoal_improved,note"));
}
