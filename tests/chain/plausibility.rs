//! Plausibility guards: saturation at the brightest water radiance, smear over a pixel, an
//! f-number below 1 — each against an oracle computed here, and printed and written by the CLI.

use crate::common::Kept;
use std::process::Command;

use shoal::engine::RunConfig;
use shoal::instrument::Flags;
use shoal::instrument::plausibility::Guard;

use super::{run, small, small_lake};

fn config(edit: impl Fn(&mut shoal::instrument::InstrumentSpec)) -> RunConfig {
    let mut instrument = small("cubesat", 24, 16);
    edit(&mut instrument);
    let mut c = RunConfig::new(small_lake(), instrument);
    c.detector.noise = false;
    c
}

/// Water pixel-bands flagged saturated in Level-0, counted from the product itself.
fn saturated_water(out: &shoal::engine::RunOutput) -> usize {
    let (rows, cols, nb) = out.kept().level0.flags.dim();
    let mut n = 0;
    for r in 0..rows {
        for c in 0..cols {
            if out.truth.surface.codes()[[r, c]] == 0 {
                n += (0..nb).filter(|&b| out.kept().level0.flags[[r, c, b]] & Flags::SATURATED != 0).count();
            }
        }
    }
    n
}

#[test]
fn the_table_1_cubesat_raises_no_warning_and_saturates_no_water_pixel() {
    let out = run(&config(|_| {}));
    assert!(out.report.warnings.is_empty(), "{:?}", out.report.warnings);
    assert_eq!(saturated_water(&out), 0);
}

#[test]
fn a_ten_electron_well_warns_and_level_0_agrees() {
    let out = run(&config(|i| i.well_depth_e = 10.0));
    let w = out.report.warnings.iter().find(|w| w.guard == Guard::Saturation).expect("a saturation warning");
    assert!(w.message.contains("19 of 19 bands"), "{}", w.message);
    assert!(w.value > 1.0);
    // The independent count: noise-free Level-0 flags every water pixel in every band.
    let (rows, cols, nb) = out.kept().level0.flags.dim();
    let water = out.truth.surface.codes().iter().filter(|&&l| l == 0).count();
    assert!(water > 0 && rows * cols > 0);
    assert_eq!(saturated_water(&out), water * nb);
}

#[test]
fn the_guard_and_level_0_agree_at_the_edge_of_saturation() {
    // Full scale set just below and just above the brightest water signal, found from the
    // noise-free electrons of a first run: the guard must flip exactly where Level-0 does.
    let probe = run(&config(|i| i.well_depth_e = 1e9));
    let detector_peak_dn = probe
        .kept()
        .level0
        .dn
        .indexed_iter()
        .filter(|((r, c, _), _)| probe.truth.surface.codes()[[*r, *c]] == 0)
        .map(|(_, &dn)| f64::from(dn))
        .fold(0.0, f64::max);
    let gain = probe.config.instrument.gain_e_per_dn;
    let bias = probe.config.instrument.bias_dn;
    let peak_e = (detector_peak_dn - bias) * gain; // electrons of the brightest water pixel-band
    for (scale, saturates) in [(0.9, true), (1.1, false)] {
        let out = run(&config(|i| i.well_depth_e = peak_e * scale));
        let warned = out.report.warnings.iter().any(|w| w.guard == Guard::Saturation);
        assert_eq!(warned, saturates, "well = {scale} × peak ({peak_e:.0} e-)");
        assert_eq!(saturated_water(&out) > 0, saturates, "Level-0 at well = {scale} × peak");
    }
}

#[test]
fn f_number_and_smear_against_first_principles() {
    // f/N = focal / aperture (Smith 2008, §6.3): 165 mm / 999 mm.
    let out = run(&config(|i| i.aperture_mm = 999.0));
    let f = out.report.warnings.iter().find(|w| w.guard == Guard::FNumber).expect("f-number warning");
    assert!((f.value - 165.0 / 999.0).abs() < 1e-12);
    assert!(f.message.contains("f/0.17"), "{}", f.message);

    // Line period = nadir GSD / ground speed: GSD = pitch · altitude / focal length, ground speed
    // of a circular orbit v = √(GM/(R+h))·R/(R+h) (WGS-84 GM, mean Earth radius 6371.0088 km).
    let (pitch_m, altitude_m, focal_m) = (5.86e-6, 560e3, 0.165);
    let gsd_m = pitch_m * altitude_m / focal_m;
    let (gm, r) = (3.986_004_418e14_f64, 6_371_008.8_f64);
    let v = (gm / (r + altitude_m)).sqrt() * r / (r + altitude_m);
    let line_period_s = gsd_m / v;
    assert!((line_period_s - 2.85e-3).abs() < 0.01e-3, "{line_period_s}"); // the 2.85 ms
    let out = run(&config(|i| i.exposure_s = 0.010));
    let s = out.report.warnings.iter().find(|w| w.guard == Guard::Smear).expect("smear warning");
    // Within 0.5 %: the chain's GSD is the spherical-Earth footprint of the centre detector.
    assert!((s.value / (0.010 / line_period_s) - 1.0).abs() < 5e-3, "{} vs {}", s.value, 0.010 / line_period_s);
    // Table 1's 1.5 ms is about half a line period: no smear warning.
    assert!(!run(&config(|_| {})).report.warnings.iter().any(|w| w.guard == Guard::Smear));
}

#[test]
fn the_cli_prints_the_warnings_and_writes_them_into_report_json() {
    let dir = crate::common::TempDir::new("plausible", "cli");
    let mut instrument = small("cubesat", 12, 8);
    instrument.aperture_mm = 999.0;
    instrument.well_depth_e = 10.0;
    let path = dir.join("fast.ron");
    std::fs::write(&path, ron::ser::to_string(&instrument).unwrap()).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .env("SHOAL_HOME", &dir)
        .args(["simulate", "--scene", "lake_hume_bloom", "--instrument"])
        .arg(&path)
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("warning: cubesat: f-number f/0.17"), "{stderr}");
    assert!(stderr.contains("warning: cubesat: saturates"), "{stderr}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out").join("report.json")).unwrap()).unwrap();
    let guards: Vec<&str> =
        report["warnings"].as_array().unwrap().iter().map(|w| w["guard"].as_str().unwrap()).collect();
    assert_eq!(guards, ["FNumber", "Saturation"]);
}

#[test]
fn the_report_counts_the_truths_depth_and_substrate_shares() {
    let mut c = RunConfig::new(super::reef(), small("cubesat", 64, 48));
    c.fidelity.decimation = 1;
    let out = run(&c);
    let s = &out.report.truth_shares;
    let depth = out.truth.depth_m.as_ref().unwrap();
    let fractions = out.truth.substrate_fractions.as_ref().unwrap();
    // Independent count: water pixels and, per substrate, the pixels where it is the largest.
    let water: Vec<(usize, usize)> =
        out.truth.surface.codes().indexed_iter().filter(|(_, l)| **l == 0).map(|(rc, _)| rc).collect();
    assert_eq!(s.water_pixels, water.len());
    let (lo, hi) = water
        .iter()
        .map(|&(r, c)| f64::from(depth[[r, c]]))
        .fold((f64::MAX, f64::MIN), |(a, b), d| (a.min(d), b.max(d)));
    assert_eq!(s.depth_range_m, Some((lo, hi)));
    let bins: f64 = s.depth_bins.iter().map(|b| b.share_pct).sum();
    assert!((bins - 100.0).abs() < 1e-9, "{bins}");
    for (k, sub) in s.substrates.iter().enumerate() {
        let dominant = water
            .iter()
            .filter(|&&(r, c)| {
                let v = fractions[[r, c, k]];
                (0..fractions.dim().2).all(|j| fractions[[r, c, j]] <= v)
            })
            .count();
        // Ties (two equal fractions) go to one substrate in the report and to both here.
        assert!((sub.dominant_pct - 100.0 * dominant as f64 / water.len() as f64).abs() < 1.0, "{}", sub.name);
    }
    assert!(out.report.truth_shares.table().contains("depth"));
}
