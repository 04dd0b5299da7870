//! Noise statistics against the analytic model, saturation at the well and at the ADC limit, zero
//! counts, and the CubeSat and SmallSat SNR against the instrument equation with Table 1's
//! parameters (Matthews et al. 2023, Sensors 23, 7824).

use crate::common::Kept;
use shoal::engine::RunConfig;
use shoal::instrument::detector::{Stream, pixel_rng};
use shoal::instrument::{Detector, DetectorMode, Flags, InstrumentSpec, Response};

use super::{run, small, small_lake};

fn detector(spec: &InstrumentSpec) -> Detector {
    Detector::new(spec, &Response::new(spec, 1.0).unwrap(), DetectorMode::default(), 7)
}

#[test]
fn count_noise_matches_the_analytic_value_at_three_radiances() {
    let spec = InstrumentSpec::preset("nominal").unwrap();
    let det = detector(&spec);
    let (j, b) = (512, 5); // Oa06, 560 nm
    let k = det.responsivity(j, b);
    // Three levels: dark water NIR-like (~2 000 e-), mid (~20 000 e-), bright (~60 000 e-).
    for electrons in [2_000.0, 20_000.0, 60_000.0] {
        let radiance = electrons / k;
        let n = 20_000;
        let dn: Vec<f64> = (0..n)
            .map(|f| {
                let mut rng = pixel_rng(3, Stream::Exposure, f, j);
                let e = det.expose(j, b, radiance, spec.exposure_s, &mut rng);
                det.level0_value(&det.read_out(0, e, &mut rng))
            })
            .collect();
        let mean = dn.iter().sum::<f64>() / n as f64;
        let std = (dn.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
        let analytic_dn = det.variance_e2(0, electrons, 0.0).sqrt() / spec.gain_e_per_dn;
        // The standard deviation of a sample std over 20 000 draws is 0.5 %: 2 % is 4σ.
        let rel = (std - analytic_dn).abs() / analytic_dn;
        assert!(rel < 0.02, "{electrons} e-: std {std:.3} DN vs analytic {analytic_dn:.3} DN ({:.2} %)", 100.0 * rel);
        let expected_mean = electrons / spec.gain_e_per_dn + spec.bias_dn;
        assert!(
            (mean - expected_mean).abs() < 5.0 * analytic_dn / (n as f64).sqrt() + 0.5,
            "{mean} vs {expected_mean}"
        );
    }
}

#[test]
fn saturation_at_the_well_and_at_the_adc_limit() {
    let mut spec = InstrumentSpec::preset("nominal").unwrap();
    let det = detector(&spec);
    let (j, b) = (100, 3);
    let radiance = 3.0 * spec.well_depth_e / det.responsivity(j, b);
    let mut rng = pixel_rng(1, Stream::Exposure, 0, j);
    let e = det.expose(j, b, radiance, spec.exposure_s, &mut rng);
    assert_eq!(e, spec.well_depth_e, "the well clips");
    let r = det.read_out(0, e, &mut rng);
    assert!(r.flags & Flags::SATURATED != 0);
    assert!(f64::from(r.dn) < spec.dn_max(), "80 000 e- at 3 e-/DN fit a 16-bit ADC");
    // A gain of 1 e-/DN puts the ADC limit (65 535 e-) below the well: the ADC clips first.
    spec.gain_e_per_dn = 1.0;
    let det = detector(&spec);
    let e = det.expose(j, b, 0.95 * spec.well_depth_e / det.responsivity(j, b), spec.exposure_s, &mut rng);
    assert!(e < spec.well_depth_e);
    let r = det.read_out(0, e, &mut rng);
    assert_eq!(r.dn, 65_535);
    assert!(r.flags & Flags::SATURATED != 0);
    // 8 bits: 255 is the ceiling.
    spec.adc_bits = 8;
    let det = detector(&spec);
    let r = det.read_out(0, 10_000.0, &mut rng);
    assert_eq!(r.dn, 255);
    assert!(r.flags & Flags::SATURATED != 0);
    // Through the chain, whose electrons cube is stored in f32: a well of 12 345.6 e- (not an
    // f32 number) under a 10 s exposure (the lake's dimmest band gives over 10⁶ e-) fills every
    // pixel-band, and each is flagged; its count is W/g + bias = 4 125.6 DN within 8σ of the
    // read noise (15/3 = 5 DN).
    let mut c = RunConfig::new(small_lake(), small("nominal", 8, 8));
    c.instrument.well_depth_e = 12_345.6;
    c.instrument.exposure_s = 10.0;
    let out = run(&c);
    assert_eq!(out.report.saturated, out.kept().level0.dn.len(), "pixel-bands at the well, flagged");
    assert!(out.kept().level0.flags.iter().all(|f| f & Flags::SATURATED != 0));
    assert!(
        out.kept().level0.dn.iter().all(|&d| (f64::from(d) - 4_125.6).abs() < 8.0 * 5.0 + 0.5),
        "{:?}",
        out.kept().level0.dn
    );
    // Below the ADC's range: zero counts are flagged. Without noise, 0 e- with no bias reads 0.
    spec.bias_dn = 0.0;
    let det = detector(&spec);
    let quiet =
        Detector::new(&spec, &Response::new(&spec, 1.0).unwrap(), DetectorMode { noise: false, quantise: true }, 7);
    let r = quiet.read_out(0, 0.0, &mut rng);
    assert_eq!((r.dn, r.flags), (0, Flags::ZERO));
    // With read noise σ = 15 e- at 1 e-/DN, DN = round(15·z) clipped at 0 is 0 exactly when
    // 15·z < 0.5: probability Φ(0.5/15) = 0.513 30. Over 2 000 pixels the count of zeros has
    // standard deviation √(2000·p·(1 − p)) = 22.4; 5σ allowed. Every zero must be flagged ZERO,
    // and no other count.
    assert_eq!((spec.read_noise_e, spec.gain_e_per_dn), (15.0, 1.0));
    let n = 2_000;
    let p_zero = 0.513_30;
    let mut zeros = 0;
    for i in 0..n {
        let r = det.read_out(0, 0.0, &mut pixel_rng(2, Stream::Readout, i, 0));
        assert_eq!(r.flags & Flags::ZERO != 0, r.dn == 0, "pixel {i}: DN {} flags {}", r.dn, r.flags);
        zeros += usize::from(r.dn == 0);
    }
    let (expected, sd) = (n as f64 * p_zero, (n as f64 * p_zero * (1.0 - p_zero)).sqrt());
    assert!((zeros as f64 - expected).abs() < 5.0 * sd, "{zeros} zero counts of {n}, expected {expected:.0} ± {sd:.1}");
}

/// Planck constant, J s, and speed of light, m s⁻¹ (SI 2019, exact).
const H_J_S: f64 = 6.626_070_15e-34;
const C_M_S: f64 = 299_792_458.0;

/// ∫R(λ)·λ dλ, nm², of every Sentinel-3A OLCI band's spectral response R (peak-normalised as
/// supplied by ESA), by the trapezoid rule on its native samples (~0.12 nm) in
/// assets/srf/srf_s3a_olci.csv (the engine instead weights its simulation grid's nodes).
pub(crate) fn olci_srf_lambda_integrals() -> Vec<(String, f64)> {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/srf/srf_s3a_olci.csv")).unwrap();
    let mut out: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (wl, r): (f64, f64) = (f[1].parse().unwrap(), f[2].parse().unwrap());
        match out.last_mut() {
            Some((name, v)) if name == f[0] => v.push((wl, r)),
            _ => out.push((f[0].to_string(), vec![(wl, r)])),
        }
    }
    out.into_iter()
        .map(|(name, v)| {
            let integral = v.windows(2).map(|w| 0.5 * (w[1].0 - w[0].0) * (w[0].1 * w[0].0 + w[1].1 * w[1].0)).sum();
            (name, integral)
        })
        .collect()
}

/// A Table 1 instrument (Matthews et al. 2023, Sensors 23, 7824, Table 1): aperture D, pixel
/// pitch p, focal length f, gain; all share exposure 1.5 ms, optical transmission 0.885, read
/// noise 15 e⁻, no dark current. Quantum efficiency: Table 1 gives none; the presets assume a
/// flat 0.7 (presets/instruments/*.ron).
pub(crate) struct Table1 {
    d_mm: f64,
    p_um: f64,
    f_mm: f64,
    gain: f64,
}

impl Table1 {
    /// CubeSat: 60 mm, 5.86 µm, 165 mm, 3 e⁻/DN.
    pub(crate) const CUBESAT: Self = Self { d_mm: 60.0, p_um: 5.86, f_mm: 165.0, gain: 3.0 };
    /// SmallSat: 240 mm, 15.5 µm, 432 mm, 10 e⁻/DN.
    pub(crate) const SMALLSAT: Self = Self { d_mm: 240.0, p_um: 15.5, f_mm: 432.0, gain: 10.0 };
    const EXPOSURE_S: f64 = 0.0015;
    const TRANSMISSION: f64 = 0.885;
    const READ_NOISE_E: f64 = 15.0;
    const QE: f64 = 0.7;

    /// Photo-electrons at band radiance `l` (W m⁻² sr⁻¹ nm⁻¹), the response-weighted band mean,
    /// from the instrument equation (Matthews et al. 2023 §2.1.2; Janesick 2007 ch. 2):
    /// S = t·τ·QE·(πD²/4)·(p/f)²·L·∫R(λ)·λ/(hc) dλ, with `srf_lambda` = ∫R·λ dλ in nm².
    fn electrons(&self, l: f64, srf_lambda: f64) -> f64 {
        let d = self.d_mm * 1e-3;
        let ifov = self.p_um * 1e-6 / (self.f_mm * 1e-3);
        let etendue = std::f64::consts::PI * d * d / 4.0 * ifov * ifov;
        Self::EXPOSURE_S * Self::TRANSMISSION * Self::QE * etendue * l * srf_lambda * 1e-9 / (H_J_S * C_M_S)
    }

    /// SNR = S/√(S + σ_read² + gain²/12) (Janesick 2007 eq. 2.14; quantisation noise gain²/12).
    pub(crate) fn snr(&self, l: f64, srf_lambda: f64) -> f64 {
        let s = self.electrons(l, srf_lambda);
        s / (s + Self::READ_NOISE_E * Self::READ_NOISE_E + self.gain * self.gain / 12.0).sqrt()
    }
}

#[test]
fn cubesat_and_smallsat_snr_follow_the_instrument_equation_of_table1() {
    let (cube_t1, small_t1) = (Table1::CUBESAT, Table1::SMALLSAT);
    // The presets are Table 1's instruments.
    for (name, t1) in [("cubesat", &cube_t1), ("smallsat", &small_t1)] {
        let i = InstrumentSpec::preset(name).unwrap();
        assert_eq!(
            (i.aperture_mm, i.pixel_pitch_um, i.focal_length_mm, i.gain_e_per_dn),
            (t1.d_mm, t1.p_um, t1.f_mm, t1.gain),
            "{name}"
        );
        assert_eq!((i.exposure_s, i.optical_transmission, i.read_noise_e), (0.0015, 0.885, 15.0), "{name}");
        assert_eq!((i.dark_current_e_s, i.prnu, i.dsnu_e), (0.0, 0.0, 0.0), "{name}");
    }
    let mut outs = Vec::new();
    for name in ["cubesat", "smallsat"] {
        let mut c = RunConfig::new(small_lake(), small(name, 128, 64));
        c.fidelity.snr_detectors = 256;
        c.fidelity.snr_frames = 256;
        outs.push(run(&c));
    }
    let srf = olci_srf_lambda_integrals();
    let (cube, smallsat) = (&outs[0].snr, &outs[1].snr);
    assert_eq!(cube.len(), 19, "Table 1: 19 OLCI bands");
    for (c, s) in cube.iter().zip(smallsat.iter()) {
        assert_eq!(c.band, s.band);
        let integral = srf.iter().find(|(n, _)| *n == c.band).unwrap().1;
        // Each run's SNR refers to its own median water radiance (their ground sampling
        // differs slightly), so each is predicted at its own radiance.
        let (want_c, want_s) = (cube_t1.snr(c.radiance, integral), small_t1.snr(s.radiance, integral));
        // The engine's analytic SNR against the instrument equation. Both integrate the
        // piecewise-linear SRF exactly: the engine by hat-function weights whatever its grid
        // step (src/spectral/bands.rs), the trapezoid here because its error on R·λ, −Σh³R′/6
        // over the intervals, is −h²/6·[R] across the band on the (nearly) evenly spaced samples and
        // vanishes with R ≈ 0 at both ends. What is left is rounding: measured 1.7e-10 at worst
        // (Oa16); 1e-8 allowed. A modelling difference (QE, τ, étendue, the λ/hc weighting)
        // would show at 1e-3 or more.
        for (got, want, who) in [(c.snr_analytic, want_c, "CubeSat"), (s.snr_analytic, want_s, "SmallSat")] {
            assert!((got / want - 1.0).abs() < 1e-8, "{} {who}: analytic SNR {got:.4} vs {want:.4}", c.band);
        }
        // Measured: per detector, SNR from 256 frames has a relative standard error
        // 1/√(2·255) = 4.4 %; the mean over the 128 detectors 0.39 %; the ratio of two such
        // means √2·0.39 = 0.55 %. 2 % is 3.6σ.
        let predicted = want_s / want_c;
        let measured = s.snr_measured / c.snr_measured;
        assert!(
            (measured / predicted - 1.0).abs() < 0.02,
            "{}: measured SmallSat/CubeSat SNR {measured:.3} vs Table 1 {predicted:.3}",
            c.band
        );
        // (D·p/f)² is 16.3 times larger for the SmallSat: SNR about √16.3 = 4.0 times (less
        // where read noise matters).
        assert!(predicted > 3.0, "{}: {predicted}", c.band);
    }
}

/// The SNR stated at a reference radiance (as missions and IOCCG state it): every band's row
/// refers to that radiance (given per µm, kept per nm) and its analytic SNR is the instrument
/// equation's there; the full-scale share grows in proportion; a radiance that is not one is
/// refused naming the field.
#[test]
fn the_snr_is_stated_at_the_reference_radiance_the_user_sets() {
    let t1 = Table1::CUBESAT;
    let srf = olci_srf_lambda_integrals();
    let mut c = RunConfig::new(small_lake(), small("cubesat", 64, 32));
    c.snr_reference = Some(shoal::spectral::SpectrumSource::Constant(40.0));
    let out = run(&c);
    for row in out.snr.iter() {
        assert!((row.radiance - 0.040).abs() < 1e-12, "{}: {} W m⁻² sr⁻¹ nm⁻¹", row.band, row.radiance);
        let integral = srf.iter().find(|(n, _)| *n == row.band).unwrap().1;
        let want = t1.snr(row.radiance, integral);
        assert!((row.snr_analytic / want - 1.0).abs() < 1e-8, "{}: {} vs {want}", row.band, row.snr_analytic);
    }
    // Twice the radiance: twice the signal against full scale.
    c.snr_reference = Some(shoal::spectral::SpectrumSource::Constant(80.0));
    let twice = run(&c);
    for (a, b) in out.snr.iter().zip(twice.snr.iter()) {
        assert!((b.full_scale_fraction / a.full_scale_fraction - 2.0).abs() < 1e-9, "{}", a.band);
    }
    c.snr_reference = Some(shoal::spectral::SpectrumSource::Constant(-1.0));
    let e = shoal::engine::Engine::new().run(&c, &shoal::control::RunControl::new()).unwrap_err().to_string();
    assert!(e.contains("snr_reference") && e.contains("-1"), "{e}");
}
