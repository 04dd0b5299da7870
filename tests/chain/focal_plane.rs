//! The focal-plane effects through the whole chain (`instrument::effects::{nonlinearity,
//! fixed_patterns}`): carried by the detector, linearised, filled or flagged by the calibration.

use crate::common::Kept;

use shoal::engine::{RunConfig, RunOutput};
use shoal::instrument::{DetectorMode, Flags};

use super::{on_one_and_two_threads, run, small, small_lake};

/// A noise-free CubeSat over a cut of Lake Hume with `effects` (RON), calibrated from its
/// diffuser frames (the analogue values: no quantisation).
fn config(effects: &str) -> RunConfig {
    let mut instrument = small("cubesat", 96, 64);
    instrument.effects = ron::from_str(effects).unwrap();
    let mut c = RunConfig::new(small_lake(), instrument);
    c.detector = DetectorMode::IDEAL;
    c
}

/// Level-1 over the pupil radiance, minus 1, for every value brighter than 1e-6.
fn residuals(out: &RunOutput) -> Vec<f64> {
    let (l1, truth) = (&out.kept().level1.radiance, &out.kept().radiance.radiance);
    l1.iter().zip(truth).filter(|(_, t)| **t > 1e-6).map(|(l, t)| f64::from(*l) / f64::from(*t) - 1.0).collect()
}

fn worst(values: &[f64]) -> f64 {
    values.iter().map(|v| v.abs()).fold(0.0, f64::max)
}

fn non_linearity(quadratic: f64, cubic: f64, corrected: bool, error: f64) -> String {
    format!(
        "[NonLinearity((quadratic: {quadratic:?}, cubic: {cubic:?}, correction: (corrected: {corrected}, error: {error:?})))]"
    )
}

#[test]
fn a_straight_line_changes_nothing_and_a_known_curve_closes() {
    let ideal = run(&config("[]"));
    // A straight line stated as a non-linearity: the same bits as no effect at all.
    let line = run(&config(&non_linearity(0.0, 0.0, true, 0.0)));
    assert_eq!(line.kept().level1.radiance, ideal.kept().level1.radiance);
    assert_eq!(line.kept().level0.analog, ideal.kept().level0.analog);
    let base = residuals(&ideal);
    // 2 % low at full well as a quadratic with a cubic 0.5 % back (a CMOS-like curve).
    let raw = residuals(&run(&config(&non_linearity(-0.025, 0.005, false, 0.0))));
    let exact = residuals(&run(&config(&non_linearity(-0.025, 0.005, true, 0.0))));
    let wrong = residuals(&run(&config(&non_linearity(-0.025, 0.005, true, 0.1))));
    let moved: Vec<f64> = raw.iter().zip(&base).map(|(r, b)| r - b).collect();
    eprintln!(
        "non-linearity: noise-free chain {:.1e}; uncorrected {:.2e}; known exactly {:.1e}",
        worst(&base),
        worst(&moved),
        worst(&exact.iter().zip(&base).map(|(e, b)| e - b).collect::<Vec<_>>())
    );
    // The diffuser sits at 60 % of the range, the lake far below: the uncorrected curve reads
    // the water high by about |a₂|·0.6 (the calibration's gain is 1.5 % low there).
    assert!(worst(&moved) > 5e-3, "the curve moves Level-1: {}", worst(&moved));
    // Known exactly: the linearisation closes to the f32 rounding of the analogue values.
    for (e, b) in exact.iter().zip(&base) {
        assert!((e - b).abs() < 2e-6, "known exactly: {e} against {b}");
    }
    // Known 10 % too strong: to first order the processor removes 1.1 × the curve, so −0.1 of
    // the uncorrected error is left; second-order terms are a₂x ≤ 2.5 % of that (tolerance
    // 5 % of the error, plus the f32 rounding).
    for ((w, r), b) in wrong.iter().zip(&raw).zip(&base) {
        let (left, uncorrected) = (w - b, r - b);
        assert!(
            (left + 0.1 * uncorrected).abs() <= 0.05 * uncorrected.abs() + 2e-6,
            "10 % wrong: {left} against {}",
            -0.1 * uncorrected
        );
    }
}

/// Each detector's own curve, known exactly, closes too: the calibration's noise-free frames
/// are read through the element's curve, not detector 0's (which left every other column's
/// gain and offset off by the curves' difference: a 5 % spread striped Level-1 by percents).
#[test]
fn a_curve_that_differs_by_column_closes_column_by_column() {
    let base = residuals(&run(&config("[]")));
    let spread = "[NonLinearity((quadratic: -0.025, cubic: 0.005, column_spread: 0.05, \
                  correction: (corrected: true, error: 0.0)))]";
    let exact = residuals(&run(&config(spread)));
    for (e, b) in exact.iter().zip(&base) {
        assert!((e - b).abs() < 2e-6, "known exactly, per column: {e} against {b}");
    }
}

#[test]
fn a_curve_that_falls_is_refused_by_name() {
    let mut c = config(&non_linearity(-0.2, -0.2, true, 0.0));
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("NonLinearity.cubic") && e.contains("0.5"), "{e}");
    c.instrument.effects = ron::from_str("[NonLinearity((quadratic: 0.3))]").unwrap();
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("quadratic") && e.contains("0.2"), "{e}");
}

fn patterns(fields: &str) -> String {
    format!("[FixedPatterns(({fields}))]")
}

#[test]
fn a_gain_drift_stripes_level1_by_its_rms() {
    let base = residuals(&run(&config("[]")));
    let drift = 0.005;
    let striped = residuals(&run(&config(&patterns(&format!("gain_drift: {drift:?}")))));
    // Noise-free: each (column, band) element reads its drift factor, the same down the column.
    let moved: Vec<f64> = striped.iter().zip(&base).map(|(s, b)| s - b).collect();
    let rms = (moved.iter().map(|m| m * m).sum::<f64>() / moved.len() as f64).sqrt();
    // 96 × 19 elements: the sample rms of 1824 normal draws is within 5 % of σ at 3 standard
    // errors (1/√(2n) = 1.7 %); the pixels weight the elements unevenly (the lake's cut), so
    // 10 %.
    eprintln!("gain drift {drift}: Level-1 rms {rms:.4e}");
    assert!((rms / drift - 1.0).abs() < 0.1, "rms {rms} for a drift of {drift}");
}

#[test]
fn dead_elements_are_found_and_filled_or_flagged() {
    let ideal = run(&config("[]"));
    let filled = run(&config(&patterns("dead_fraction: 0.02")));
    let flagged = run(&config(&patterns("dead_fraction: 0.02, interpolate_dead: false")));
    let defects = filled.calibration.defects.as_ref().expect("2 % of 1824 elements: some are dead");
    let (nb, cols) = (filled.response.n_bands(), filled.viewing.detector_index.len());
    let dead: Vec<(usize, usize)> = (0..cols)
        .flat_map(|c| (0..nb).map(move |b| (c, b)))
        .filter(|&(c, b)| defects.is_dead(filled.viewing.detector_index[c], b))
        .collect();
    // About 2 % of the elements (36 of 1824; 3 σ of a binomial: 18).
    eprintln!("dead elements: {} of {}", dead.len(), cols * nb);
    assert!((18..=54).contains(&dead.len()), "{} dead", dead.len());
    let (l1, fl, truth) = (&filled.kept().level1, &flagged.kept().level1, &ideal.kept().level1.radiance);
    for &(c, b) in &dead {
        for r in 0..l1.radiance.dim().0 {
            // Flagged where not filled: Level-1 0 and DEFECTIVE, and the Rrs invalid.
            assert_eq!(fl.radiance[(r, c, b)], 0.0);
            assert!(fl.flags[(r, c, b)] & Flags::DEFECTIVE != 0);
            assert!(flagged.kept().rrs.flags[(r, c, b)] & shoal::correction::RrsFlags::INVALID != 0);
            // Filled: a neighbour's value, within the scene's contrast of the truth there.
            let (v, t) = (l1.radiance[(r, c, b)], truth[(r, c, b)]);
            assert!(v.is_finite() && v > 0.0 && l1.flags[(r, c, b)] & Flags::DEFECTIVE == 0, "{v}");
            assert!((v / t - 1.0).abs() < 0.5, "filled {v} against {t}");
        }
    }
    // Every working element is calibrated as without the effect (to the f32 rounding: the
    // diffuser's incidence follows the brightest working element).
    let ideal_l1 = &ideal.kept().level1.radiance;
    for ((r, c, b), v) in l1.radiance.indexed_iter() {
        let t = ideal_l1[(r, c, b)];
        if !dead.contains(&(c, b)) && t > 1e-6 {
            assert!((v / t - 1.0).abs() < 1e-5, "working ({r}, {c}, {b}): {v} against {t}");
        }
    }
}

#[test]
fn hot_elements_need_dark_frames_as_long_as_the_scene() {
    let hot = "hot_fraction: 0.05, hot_dark_current_e_s: 20000.0";
    let base = residuals(&run(&config("[]")));
    let zero_length = residuals(&run(&config(&patterns(hot))));
    let mut long = config(&patterns(hot));
    long.calibration.dark_exposure_s = long.instrument.exposure_s;
    let long = residuals(&run(&long));
    let moved = |r: &[f64]| worst(&r.iter().zip(&base).map(|(a, b)| a - b).collect::<Vec<_>>());
    eprintln!(
        "hot elements: 0 s dark frames {:.2e}, scene-length dark frames {:.1e}",
        moved(&zero_length),
        moved(&long)
    );
    // Zero-second dark frames miss the extra dark current (20 000 e⁻/s for 1.5 ms is 30 e⁻ over
    // a lake signal of a few thousand).
    assert!(moved(&zero_length) > 1e-3);
    // The scene's dark frames remove it, to the f32 rounding of the analogue values.
    assert!(moved(&long) < 2e-6, "{}", moved(&long));
}

#[test]
fn focal_plane_effects_do_not_depend_on_threads() {
    let c = config(
        "[NonLinearity((quadratic: -0.02, column_spread: 0.2, correction: (corrected: true, error: 0.1))), \
         FixedPatterns((gain_drift: 0.002, offset_drift_e: 3.0, dead_fraction: 0.02, hot_fraction: 0.02, \
         hot_dark_current_e_s: 5000.0))]",
    );
    let mut noisy = c.clone();
    noisy.detector = DetectorMode::default();
    for c in [c, noisy] {
        let (one, two) = on_one_and_two_threads(&c);
        assert_eq!(one.kept().level0.dn, two.kept().level0.dn);
        assert_eq!(one.kept().level1.radiance, two.kept().level1.radiance);
    }
}

#[test]
fn compression_is_exact_when_lossless_and_keeps_its_bound_otherwise() {
    let quantised = |effects: &str| {
        let mut c = config(effects);
        c.detector = DetectorMode { noise: true, quantise: true };
        run(&c)
    };
    let plain = quantised("[]");
    let lossless = quantised("[Compression(())]");
    assert_eq!(lossless.kept().level0.dn, plain.kept().level0.dn);
    let report = lossless.report.compression.expect("a compressed run reports its coder");
    eprintln!("lossless: {:.2} bits per sample, ratio {:.2}", report.bits_per_sample, report.ratio);
    assert!(report.ratio > 1.0 && report.largest_error_dn == 0, "{report:?}");
    // Near-lossless: every count within the bound, and Level-1 within bound/gain of the
    // uncompressed one (the calibration's gain in DN per radiance unit).
    let bound = 4;
    let lossy = quantised(&format!("[Compression((max_error_dn: {bound}))]"));
    let worst = lossy.kept().level0.dn.iter().zip(plain.kept().level0.dn.iter()).map(|(a, b)| a.abs_diff(*b)).max();
    assert!(worst.is_some_and(|w| u32::from(w) <= bound), "{worst:?}");
    let coded = lossy.report.compression.unwrap();
    assert!(coded.bits_per_sample < report.bits_per_sample, "{coded:?} against {report:?}");
    let (nb, cols) = (plain.response.n_bands(), plain.viewing.detector_index.len());
    for ((r, c, b), v) in lossy.kept().level1.radiance.indexed_iter() {
        let j = plain.viewing.detector_index[c];
        let gain = plain.calibration.gain_dn_per_radiance[j * nb + b];
        let d = f64::from(*v) - f64::from(plain.kept().level1.radiance[(r, c, b)]);
        assert!(d.abs() <= f64::from(bound) / gain * (1.0 + 1e-5) + 1e-7, "({r}, {c}/{cols}, {b}): {d}");
    }
    // A rate target: the smallest bound that meets it, and an error no larger than that bound.
    let target = quantised("[Compression((bits_per_sample: 3.0))]");
    let r = target.report.compression.unwrap();
    eprintln!("3 bits per sample: bound {} DN, {:.2} bits", r.max_error_dn, r.bits_per_sample);
    assert!(r.max_error_dn > 0 && r.bits_per_sample < 3.2 && r.largest_error_dn <= r.max_error_dn, "{r:?}");
}

#[test]
fn misregistration_moves_level1_and_co_registration_takes_most_of_it_back() {
    let ideal = run(&config("[]"));
    let shifted = |corrected: bool, error: f64| {
        run(&config(&format!(
            "[Misregistration((sigma_px: 0.3, correction: (corrected: {corrected}, error: {error:?})))]"
        )))
    };
    let rms = |out: &RunOutput| {
        let (a, b) = (&out.kept().level1.radiance, &ideal.kept().level1.radiance);
        let d: Vec<f64> =
            a.iter().zip(b).filter(|(_, t)| **t > 1e-6).map(|(x, t)| f64::from(*x) / f64::from(*t) - 1.0).collect();
        (d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64).sqrt()
    };
    let (raw, exact, wrong) = (rms(&shifted(false, 0.0)), rms(&shifted(true, 0.0)), rms(&shifted(true, 0.5)));
    eprintln!("misregistration 0.3 px: uncorrected {raw:.2e}, co-registered {exact:.2e}, 50 % wrong {wrong:.2e}");
    // The cut of Lake Hume is smooth at the CubeSat's 300 m pixel: a third of a pixel moves
    // Level-1 by a few 1e-4 rms.
    assert!(raw > 1e-4, "{raw}");
    // Co-registered exactly, what is left is two bilinear resamplings' smoothing, well under
    // the shift's own error.
    assert!(exact < 0.5 * raw, "{exact} against {raw}");
    // Half wrong: half of each shift is left, and the smoothing with it; the two add in
    // quadrature (independent, to within 10 %).
    let expected = (0.5 * raw).hypot(exact);
    assert!((wrong / expected - 1.0).abs() < 0.1, "{wrong} against {expected}");
    // The pupil radiance is untouched: the shift is the instrument's.
    assert_eq!(shifted(false, 0.0).kept().radiance.radiance, ideal.kept().radiance.radiance);
}

/// A per-band curve sets every band: the non-linearity a study judges is the list's worst, the
/// stated curve applying to none (it once counted too, and a requirement failed on a curve no
/// band had).
#[test]
fn the_judged_non_linearity_is_the_per_band_lists_where_there_is_one() {
    let mut spec = small("cubesat", 8, 8);
    let list = ["(-0.004, 0.001)", "(-0.001, 0.0)", "(0.002, 0.0)"].join(", ");
    spec.effects = ron::from_str(&format!(
        "[NonLinearity((quadratic: -0.05, cubic: 0.0, per_band: [{list}], correction: (corrected: false)))]"
    ))
    .unwrap();
    assert!((shoal::study::nonlinearity_left_pct(&spec) - 0.3).abs() < 1e-9);
}
