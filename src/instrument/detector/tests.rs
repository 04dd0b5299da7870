use super::*;

#[test]
fn generators_are_per_pixel() {
    use rand::Rng;
    let a = pixel_rng(7, Stream::Exposure, 3, 4).next_u64();
    let b = pixel_rng(7, Stream::Exposure, 3, 4).next_u64();
    let c = pixel_rng(7, Stream::Exposure, 4, 3).next_u64();
    let d = pixel_rng(7, Stream::Readout, 3, 4).next_u64();
    assert_eq!(a, b);
    assert_ne!(a, c);
    assert_ne!(a, d);
}

/// Mean and variance of `values`.
fn moments(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    (mean, values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0))
}

#[test]
fn the_frames_mean_drawn_at_once_is_the_frame_by_frame_mean_in_distribution() {
    let mut spec = InstrumentSpec::preset("nominal").unwrap();
    // A bias 20 σ above zero, so that dim frames do not clip either.
    spec.bias_dn = 100.0;
    let response = Response::new(&spec, 1.0).unwrap();
    let d = Detector::new(&spec, &response, DetectorMode::default(), 1);
    let (frames, trials) = (100, 2000);
    // Dark-like (Poisson, tens of e⁻), mid (Poisson, hundreds) and bright (the normal
    // approximation, 20 000 e⁻): read noise 15 e⁻ = 5 DN, so the rounding is dithered.
    for target_e in [20.0, 400.0, 20_000.0] {
        let exposure = d.exposure(0, 0, target_e / d.responsivity(0, 0), d.exposure_s());
        let by_frame: Vec<f64> = (0..trials)
            .map(|t| {
                let mut rng = pixel_rng(t, Stream::CalibrationLight, 0, 0);
                let sum: f64 =
                    (0..frames).map(|_| d.level0_value(&d.read_out(0, exposure.draw(&mut rng), &mut rng))).sum();
                sum / frames as f64
            })
            .collect();
        let at_once: Vec<f64> = (0..trials)
            .map(|t| d.frames_mean(0, &exposure, frames, &mut pixel_rng(t, Stream::CalibrationLightSum, 0, 0)).unwrap())
            .collect();
        let ((m1, v1), (m2, v2)) = (moments(&by_frame), moments(&at_once));
        // Means within 4 standard errors of their difference; variances within 15 % (the
        // ratio of two 2000-sample variances has a standard error of 4.5 %: 3.3 σ).
        let se = (v1 / trials as f64 + v2 / trials as f64).sqrt();
        assert!((m1 - m2).abs() < 4.0 * se, "{target_e} e: means {m1} vs {m2} (se {se})");
        assert!((v2 / v1 - 1.0).abs() < 0.15, "{target_e} e: variances {v1} vs {v2}");
    }
}

#[test]
fn the_frames_mean_is_refused_where_frames_clip_or_rounding_is_not_dithered() {
    let mut spec = InstrumentSpec::preset("nominal").unwrap();
    let response = Response::new(&spec, 1.0).unwrap();
    let d = Detector::new(&spec, &response, DetectorMode::default(), 1);
    let mut rng = pixel_rng(1, Stream::CalibrationLightSum, 0, 0);
    let near_well = d.exposure(0, 0, 0.999 * d.well_e(0) / d.responsivity(0, 0), d.exposure_s());
    assert_eq!(d.frames_mean(0, &near_well, 100, &mut rng), None);
    let mid = d.exposure(0, 0, 400.0 / d.responsivity(0, 0), d.exposure_s());
    assert!(d.frames_mean(0, &mid, 100, &mut rng).is_some());
    assert_eq!(d.frames_mean(0, &mid, 0, &mut rng), None);
    // The nominal bias (10.4 DN) is 2 σ of read noise (5 DN) above zero: dark frames clip.
    let dark = d.exposure(0, 0, 0.0, 0.0);
    assert_eq!(d.frames_mean(0, &dark, 100, &mut rng), None);
    // 1 e⁻ of read noise at 3 e⁻/DN: a third of a DN, the rounding shows in the mean.
    spec.read_noise_e = 1.0;
    let quiet = Detector::new(&spec, &response, DetectorMode::default(), 1);
    let mid = quiet.exposure(0, 0, 400.0 / quiet.responsivity(0, 0), quiet.exposure_s());
    assert_eq!(quiet.frames_mean(0, &mid, 100, &mut rng), None);
    // Without noise every frame is the same value, and so is the mean.
    let ideal = Detector::new(&spec, &response, DetectorMode { noise: false, ..DetectorMode::default() }, 1);
    let mid = ideal.exposure(0, 0, 400.0 / ideal.responsivity(0, 0), ideal.exposure_s());
    let one = ideal.level0_value(&ideal.read_out(0, mid.draw(&mut rng), &mut rng));
    assert_eq!(ideal.frames_mean(0, &mid, 100, &mut rng), Some(one));
}

#[test]
fn a_prepared_exposure_draws_what_expose_draws() {
    use rand::RngExt;
    let spec = InstrumentSpec::preset("nominal").unwrap();
    let response = Response::new(&spec, 1.0).unwrap();
    for noise in [true, false] {
        let mode = DetectorMode { noise, ..DetectorMode::default() };
        let d = Detector::new(&spec, &response, mode, 1);
        let mut pick = pixel_rng(9, Stream::Exposure, 1, 1);
        for _ in 0..200 {
            let (j, b) = (pick.random_range(0..spec.detectors), pick.random_range(0..d.n_bands()));
            // Radiances from dark (Poisson) to bright (normal approximation, clipped).
            let radiance = 10f64.powf(pick.random_range(-4.0..3.0));
            let t = if pick.random_range(0.0..1.0) < 0.5 { d.exposure_s() } else { 0.0 };
            let prepared = d.exposure(j, b, radiance, t);
            let (mut r1, mut r2) = (pixel_rng(3, Stream::Exposure, j, b), pixel_rng(3, Stream::Exposure, j, b));
            for _ in 0..5 {
                let (a, e) = (d.expose(j, b, radiance, t, &mut r1), prepared.draw(&mut r2));
                assert_eq!(a.to_bits(), e.to_bits(), "noise {noise}: {a} vs {e}");
            }
        }
    }
}

#[test]
fn shot_noise_mean_and_variance() {
    let mut rng = pixel_rng(1, Stream::Exposure, 0, 0);
    for mean in [3.0, 500.0, 20_000.0] {
        let n = 40_000;
        let xs: Vec<f64> = (0..n).map(|_| shot(mean, &mut rng)).collect();
        let m = xs.iter().sum::<f64>() / n as f64;
        let v = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1) as f64;
        // Standard errors: mean √(μ/n), variance μ·√(2/n) (normal), 5σ allowed.
        assert!((m - mean).abs() < 5.0 * (mean / n as f64).sqrt(), "{mean}: {m}");
        assert!((v - mean).abs() < 5.0 * mean * (2.0 / n as f64).sqrt() + 0.1, "{mean}: {v}");
    }
}

/// The readout as first written, one branch at a time: round half up after the sum, then clip
/// to the ADC's range.
fn readout_as_written(d: &Detector, electrons: f64, z: f64) -> Readout {
    let p = d.plane(0);
    let noisy = if d.mode.noise { electrons + p.read_noise_e * z } else { electrons };
    let analog = noisy * p.dn_per_e + p.bias_dn;
    let mut flags = 0;
    if !d.ideal && electrons >= p.well_e {
        flags |= Flags::SATURATED;
    }
    let dn = (if analog > 0.0 { (analog + 0.5) as i64 as f64 } else { 0.0 }).min(p.dn_max);
    if d.mode.quantise {
        if dn >= p.dn_max {
            flags |= Flags::SATURATED;
        }
        if dn <= 0.0 {
            flags |= Flags::ZERO;
        }
    }
    let analog = if d.mode.quantise || d.ideal { analog } else { analog.min(p.dn_max) };
    Readout { dn: dn as u16, analog_dn: analog as f32, flags }
}

/// The readout's branch-free arithmetic, at one value ([`Detector::read_out`]) and in Level-0's
/// vector lanes ([`Detector::read_out_run`]), gives exactly the readout as first written: in
/// every mode, at the ties of the rounding, at both ends of the ADC and the well, and for NaN
/// and ∞ (which a corrupt cube could hold).
#[test]
fn the_vectorised_readout_is_the_one_value_readout() {
    for adc_bits in [12, 16, 1] {
        let mut spec = InstrumentSpec::preset("nominal").unwrap();
        spec.adc_bits = adc_bits;
        spec.bias_dn = 0.3;
        readout_matches_as_written(&spec);
    }
}

fn readout_matches_as_written(spec: &InstrumentSpec) {
    let response = Response::new(spec, 1.0).unwrap();
    let modes = [
        DetectorMode::default(),
        DetectorMode { noise: false, quantise: true },
        DetectorMode { noise: true, quantise: false },
        DetectorMode::IDEAL,
    ];
    let mut ideal_spec = spec.clone();
    let crate::instrument::spec::InstrumentKind::Multispectral { bands } = &spec.kind else {
        panic!("the nominal instrument is a multispectral imager")
    };
    ideal_spec.kind = crate::instrument::spec::InstrumentKind::IdealRadiometer { bands: bands.clone() };
    let detectors = modes.iter().map(|&m| Detector::new(spec, &response, m, 1)).chain(std::iter::once(Detector::new(
        &ideal_spec,
        &response,
        DetectorMode::default(),
        1,
    )));
    for d in detectors {
        let k = d.gain_e_per_dn(0);
        // Electrons that land on ties and on either side of them, at zero, at the top of the
        // ADC and of the well, beyond both, and values no readout should see but must survive.
        let mut electrons: Vec<f32> = vec![0.0, -0.0, -5.0, 1e-30, f32::MAX, f32::INFINITY, f32::NAN, -f32::INFINITY];
        for dn in [0.0, 1.0, 2.0, 7.5, 100.0, d.dn_max(0) - 1.0, d.dn_max(0), d.dn_max(0) + 3.0] {
            for half in [-0.5, 0.5, 0.0] {
                let e = ((dn + half - d.bias_dn(0)) * k) as f32;
                electrons.extend([e, f32::from_bits(e.to_bits() + 1), f32::from_bits(e.to_bits().saturating_sub(1))]);
            }
        }
        let well = d.well_e(0) as f32;
        electrons.extend([well, f32::from_bits(well.to_bits() - 1), 2.0 * well]);
        let mut rng = pixel_rng(3, Stream::Readout, 0, 0);
        for draws in 0..3 {
            let z: Vec<f64> = electrons
                .iter()
                .enumerate()
                .map(|(i, _)| match (draws, d.mode.noise) {
                    (_, false) | (0, _) => 0.0,
                    (1, _) => normal(&mut rng),
                    // Draws that carry the value exactly onto a tie of the rounding.
                    _ => (i % 3) as f64 * 0.5 * k / d.read_noise_e(0),
                })
                .collect();
            let n = electrons.len();
            let (mut dn, mut flags, mut analog) = (vec![0u16; n], vec![0u8; n], vec![0.0f32; n]);
            d.read_out_run(&[(0, 0)], &electrons, &z, &mut dn, &mut flags, Some(&mut analog));
            let mut dn_only = vec![0u16; n];
            d.read_out_run(&[(0, 0)], &electrons, &z, &mut dn_only, &mut flags.clone(), None);
            for i in 0..n {
                let one = readout_as_written(&d, f64::from(electrons[i]), z[i]);
                let scalar = d.read_out_with(0, f64::from(electrons[i]), z[i]);
                let what = format!("mode {:?}, ideal {}, {} e, z {}", d.mode, d.ideal, electrons[i], z[i]);
                assert_eq!((dn[i], flags[i]), (one.dn, one.flags), "{what}");
                assert_eq!(dn_only[i], one.dn, "{what}");
                assert_eq!((scalar.dn, scalar.flags), (one.dn, one.flags), "{what}");
                let same = |a: f32| a.to_bits() == one.analog_dn.to_bits() || (a.is_nan() && one.analog_dn.is_nan());
                assert!(same(scalar.analog_dn), "{what}");
                assert!(
                    analog[i].to_bits() == one.analog_dn.to_bits() || (analog[i].is_nan() && one.analog_dn.is_nan()),
                    "{what}: {} vs {}",
                    analog[i],
                    one.analog_dn
                );
            }
        }
    }
}

/// The frame loops' batched readout draws and reads out exactly what drawing and reading out
/// one value at a time does, band order and generators included.
#[test]
fn frames_read_out_at_once_are_the_frames_read_out_one_by_one() {
    let spec = InstrumentSpec::preset("nominal").unwrap();
    let response = Response::new(&spec, 1.0).unwrap();
    for mode in [DetectorMode::default(), DetectorMode { noise: false, quantise: true }] {
        let d = Detector::new(&spec, &response, mode, 1);
        let t = d.exposure_s();
        // No light (a fixed value), Poisson (tens of e⁻) and the normal approximation (20 000 e⁻).
        let exposures: Vec<Exposure> = [0.0, 30.0, 20_000.0, 500.0]
            .iter()
            .enumerate()
            .map(|(b, &e)| d.exposure(0, b, e / d.responsivity(0, b), t))
            .collect();
        let bands = [2, 0, 3];
        let rng_of = |f: usize| pixel_rng(9, Stream::CalibrationDark, f, 4);
        let mut batched = Vec::new();
        d.read_out_frames(0, &exposures, &bands, 5, rng_of, |f, b, r| batched.push((f, b, r.dn, r.flags, r.analog_dn)));
        let mut one_by_one = Vec::new();
        for f in 0..5 {
            let mut rng = rng_of(f);
            for &b in &bands {
                let r = d.read_out(b, exposures[b].draw(&mut rng), &mut rng);
                one_by_one.push((f, b, r.dn, r.flags, r.analog_dn));
            }
        }
        assert_eq!(batched, one_by_one, "mode {mode:?}");
    }
}

/// TDI over N stages: √N in SNR where shot noise dominates, for charge-domain and digital TDI
/// alike; where read noise dominates, N (charge: one read) against √N (digital: N reads).
#[test]
fn tdi_gains_root_n_when_shot_limited() {
    use crate::instrument::effects::{InstrumentEffect, Tdi};
    let mut spec = InstrumentSpec::preset("cubesat").unwrap();
    spec.dark_current_e_s = 0.0;
    let snr = |spec: &InstrumentSpec, electrons: f64| {
        let response = Response::new(spec, 1.0).unwrap();
        let one =
            Detector::new(&InstrumentSpec { effects: vec![], ..spec.clone() }, &response, DetectorMode::default(), 1);
        let d = Detector::new(spec, &response, DetectorMode { noise: true, quantise: false }, 1);
        crate::instrument::analytic_snr(&d, 0, 3, electrons / one.responsivity(0, 3))
    };
    for digital in [false, true] {
        let n = 9;
        let mut tdi = spec.clone();
        tdi.effects = vec![InstrumentEffect::Tdi(Tdi { stages: n, digital, ..Tdi::default() })];
        // Shot-limited: no read noise, 1000 e⁻ a row.
        let (mut quiet, mut quiet_tdi) = (spec.clone(), tdi.clone());
        quiet.read_noise_e = 0.0;
        quiet_tdi.read_noise_e = 0.0;
        let gain = snr(&quiet_tdi, 1000.0) / snr(&quiet, 1000.0);
        assert!((gain - 3.0).abs() < 1e-9, "digital {digital}: {gain}");
        // Read-limited: 1 e⁻ a row under 100 e⁻ of read noise.
        let (mut loud, mut loud_tdi) = (spec.clone(), tdi.clone());
        loud.read_noise_e = 100.0;
        loud_tdi.read_noise_e = 100.0;
        let gain = snr(&loud_tdi, 1.0) / snr(&loud, 1.0);
        let expected = if digital { 3.0 } else { 9.0 };
        assert!((gain / expected - 1.0).abs() < 0.01, "digital {digital}: {gain} against {expected}");
    }
    // A spectrograph's along-track axis is its spectrum.
    let mut spectrograph = InstrumentSpec::preset("hyperspectral").unwrap();
    spectrograph.effects = vec![InstrumentEffect::Tdi(Tdi { stages: 4, ..Tdi::default() })];
    let e = spectrograph.validate().unwrap_err().to_string();
    assert!(e.contains("Tdi.stages") && e.contains("spectrograph"), "{e}");
}
