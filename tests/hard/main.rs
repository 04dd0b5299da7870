//! Hard cases: every stage at its extremes, random valid inputs (proptest), injected faults,
//! and the loaders against hostile text. Each test asserts finiteness, physical bounds and that
//! degraded results are flagged and counted (never silently replaced); see docs/ARCHITECTURE.md, "Hard cases".
//!
//! The bounds: 0 ≤ Rrs ≤ 1/π sr⁻¹ (a Lambertian reflector of albedo 1 has Rrs = 1/π),
//! 0 ≤ T ≤ 1 for every transmittance and the spherical albedo, 0 ≤ DN ≤ 2^bits − 1.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod atmosphere;
mod attacks;
mod chain;
#[path = "../common/mod.rs"]
mod common;
mod faults;
mod fuzz;
mod loaders;
mod properties;
mod ranges;
mod water;

use crate::common::Kept;
use shoal::correction::RrsFlags;
use shoal::engine::{RunConfig, RunOutput};
use shoal::instrument::{Detector, Flags, InstrumentSpec};
use shoal::retrieval::{ProductFlags, RetrievalSpec};
use shoal::scene::{MapSpec, SceneSpec};

/// 1/π, sr⁻¹: Rrs of a perfect Lambertian reflector.
pub const RRS_MAX: f64 = std::f64::consts::FRAC_1_PI;

/// Lake Hume's preset (atmosphere, SIOP, date) made uniform: `chl` mg m⁻³, `nap` g m⁻³, `cdom`
/// m⁻¹ everywhere, 48 × 48 cells of 20 m (960 m, wider than the 16-detector swath below).
pub fn uniform(chl: f64, nap: f64, cdom: f64) -> SceneSpec {
    let mut s = SceneSpec::preset("lake_hume_bloom").unwrap();
    s.width = 48;
    s.height = 48;
    s.cell_m = 20.0;
    s.chl_mg_m3 = MapSpec::Constant(chl);
    s.nap_g_m3 = MapSpec::Constant(nap);
    s.cdom_per_m = MapSpec::Constant(cdom);
    s.land = None;
    s.effects.clear();
    s
}

/// The Table 1 instrument `name` cut to `detectors` × `lines`.
pub fn instrument(name: &str, detectors: usize, lines: usize) -> InstrumentSpec {
    let mut i = InstrumentSpec::preset(name).unwrap();
    i.detectors = detectors;
    i.lines = lines;
    i
}

/// What a checked run degraded, counted from its flags.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Degraded {
    /// Image pixels (rows × columns) and pixel-bands of the run.
    pub pixels: usize,
    /// Pixel-bands.
    pub pixel_bands: usize,
    /// Level-0 pixel-bands saturated.
    pub saturated: usize,
    /// Level-0 pixel-bands at zero counts.
    pub zero: usize,
    /// Rrs pixel-bands flagged negative.
    pub negative: usize,
    /// Rrs pixel-bands flagged invalid.
    pub invalid: usize,
    /// Water pixels every retrieval failed on (the fewest any retrieval failed on).
    pub failed: usize,
}

/// Every invariant of a finished run; returns the degraded counts (which the run's own report
/// must agree with).
pub fn check(out: &RunOutput, case: &str) -> Degraded {
    let c = &out.config;
    let rad = &out.kept().radiance;
    for (name, v) in [("radiance", &rad.radiance), ("true Rrs", &rad.truth_rrs)] {
        assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0), "{case}: {name} not finite or negative");
    }
    for ((r, col, _), x) in rad.truth_rrs.indexed_iter() {
        if rad.truth.surface.codes()[[r, col]] == 0 {
            assert!(f64::from(*x) <= RRS_MAX, "{case}: true Rrs {x} above 1/π");
        }
    }
    // Band atmosphere: everything finite, the spherical albedo a fraction.
    let atm = &out.band_atmosphere;
    for (name, v) in [("l_path", &atm.l_path), ("glint", &atm.glint), ("ed", &atm.ed), ("t_ed", &atm.t_ed)] {
        assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0), "{case}: band {name} not finite");
    }
    assert!(atm.spherical_albedo.iter().all(|s| (0.0..=1.0).contains(s)), "{case}: spherical albedo out of 0–1");
    // Level-0, recounted from the counts and the mean photo-electrons rather than from the flags.
    let l0 = &out.kept().level0;
    let (rows, cols, nb) = l0.dn.dim();
    let count = |flags: &ndarray::Array3<u8>, bit: u8| flags.iter().filter(|f| **f & bit != 0).count();
    let mut d = Degraded {
        pixels: rows * cols,
        pixel_bands: rows * cols * nb,
        saturated: count(&l0.flags, Flags::SATURATED),
        zero: count(&l0.flags, Flags::ZERO),
        ..Degraded::default()
    };
    let (sure, possible, zero) = level0_recount(out, case);
    // The run's report counts what the flags say; both lie between the pixel-bands that surely
    // saturated and those that may have.
    assert_eq!((d.saturated, d.zero), (out.report.saturated, out.report.zero_counts), "{case}: report vs flags");
    assert!(
        sure <= d.saturated && d.saturated <= possible,
        "{case}: {} saturated, recount {sure}–{possible}",
        d.saturated
    );
    assert_eq!(d.zero, zero, "{case}: zero counts flagged vs counted from the DN");
    assert!(out.kept().level1.radiance.iter().all(|x| x.is_finite()), "{case}: Level-1 not finite");
    // Rrs: finite everywhere; a pixel-band made invalid is flagged, never a silent number.
    let rrs = &out.kept().rrs;
    assert!(rrs.rrs.iter().all(|x| x.is_finite()), "{case}: Rrs not finite");
    for (x, f) in rrs.rrs.iter().zip(&rrs.flags) {
        if *x < 0.0 {
            assert!(f & RrsFlags::NEGATIVE != 0, "{case}: negative Rrs {x} not flagged");
        }
    }
    d.negative = count(&rrs.flags, RrsFlags::NEGATIVE);
    d.invalid = count(&rrs.flags, RrsFlags::INVALID);
    // SNR: never NaN or negative; infinite only without noise (saturation gives 0, a signal
    // the converter rounds to one value its quantisation limit).
    for s in out.snr.iter() {
        for v in [s.snr_analytic, s.snr_measured] {
            assert!(v >= 0.0 && (v.is_finite() || !c.detector.noise), "{case}: SNR {s:?}");
        }
    }
    d.failed = check_retrievals(out, case);
    d
}

/// The retrievals' part of [`check`]; returns the fewest pixels any retrieval failed on.
fn check_retrievals(out: &RunOutput, case: &str) -> usize {
    let c = &out.config;
    let rrs = &out.kept().rrs;
    let nb = rrs.rrs.dim().2;
    let mut fewest_failed = usize::MAX;
    // Retrievals: returned pixels are finite and non-negative; failures are flagged, counted
    // in the metrics, and excluded from them. Recounted from the Rrs: aLMI and SAMBUCA need three
    // usable bands (src/retrieval/almi.rs, sambuca.rs `MIN_BANDS`), QAA all five it reads — a
    // band is usable unless flagged INVALID or SATURATED, and for aLMI and QAA only with a
    // positive Rrs — so a water pixel with fewer usable bands among those the retrieval fits
    // must be FAILED (in every case of tests/hard/chain.rs the aLMI failures are exactly these
    // pixels). Every water pixel (the truth's land mask) is either FAILED or RETURNED, never both.
    let land = &out.truth.surface.codes();
    let water = land.iter().filter(|l| **l == 0).count();
    for (ret, spec) in out.retrievals.iter().zip(&c.retrievals) {
        let p = &ret.product;
        // The bands each retrieval fits: aLMI's are its settings' or, by default, those centred
        // in 400–780 nm outside the O₂ A band, 759–771 nm (`AlmiSettings::bands`); SAMBUCA
        // fits every band.
        // QAA reads the bands nearest 412, 443, 490, 555 and 670 nm, each positive: all five.
        let mut needed = 3;
        let (almi, fitted): (bool, Vec<bool>) = match spec {
            RetrievalSpec::Almi { settings, .. } => (
                true,
                out.response
                    .bands
                    .bands
                    .iter()
                    .map(|band| match &settings.bands {
                        Some(names) => names.contains(&band.name),
                        None => (400.0..=780.0).contains(&band.centre_nm) && !(759.0..=771.0).contains(&band.centre_nm),
                    })
                    .collect(),
            ),
            RetrievalSpec::Sambuca { .. } => (false, vec![true; nb]),
            RetrievalSpec::Qaa { .. } => {
                let centres = out.response.bands.centres_nm();
                let qaa = shoal::retrieval::qaa::QaaBands::new(centres.clone(), vec![0.0; nb], vec![0.0; nb]).unwrap();
                needed = qaa.at.len();
                (true, (0..nb).map(|b| qaa.at.contains(&b)).collect())
            }
            RetrievalSpec::External(_) => unreachable!("the hard cases run no external program"),
        };
        let (mut failed, mut returned, mut too_few) = (0, 0, 0);
        for ((r, col), f) in p.flags.indexed_iter() {
            if land[[r, col]] != 0 {
                assert!(f & (ProductFlags::FAILED | ProductFlags::RETURNED) == 0, "{case}: land at ({r}, {col}): {f}");
                continue;
            }
            let usable = (0..nb)
                .filter(|&b| fitted[b])
                .filter(|&b| {
                    let x = rrs.rrs[[r, col, b]];
                    rrs.flags[[r, col, b]] & (RrsFlags::INVALID | RrsFlags::SATURATED) == 0
                        && x.is_finite()
                        && (!almi || x > 0.0)
                })
                .count();
            assert!(
                (f & ProductFlags::FAILED != 0) != (f & ProductFlags::RETURNED != 0),
                "{case}: water pixel ({r}, {col}) neither or both failed and returned: {f}"
            );
            if usable < needed {
                too_few += 1;
                assert!(
                    f & ProductFlags::FAILED != 0,
                    "{case}: {}: {usable} usable bands at ({r}, {col}) but returned",
                    p.name
                );
            }
            if f & ProductFlags::FAILED != 0 {
                failed += 1;
                continue;
            }
            returned += 1;
            for (name, map) in p.maps() {
                let v = map[[r, col]];
                assert!(v.is_finite() && v >= 0.0, "{case}: {} {name} {v} at ({r}, {col})", p.name);
            }
            if let Some(depth) = &p.depth_m {
                assert!(depth[[r, col]].is_finite(), "{case}: depth at ({r}, {col})");
            }
        }
        assert!(too_few <= failed, "{case}: {}: {too_few} pixels with too few bands, {failed} failed", p.name);
        assert_eq!(failed + returned, water, "{case}: {}: {failed} failed + {returned} returned", p.name);
        assert_eq!(failed, ret.metrics.failed, "{case}: failed pixels vs metrics");
        for v in &ret.metrics.variables {
            let m = &v.metrics;
            assert!(m.returned_pct.is_finite() && (0.0..=100.0).contains(&m.returned_pct), "{case}: {v:?}");
            if m.n > 0 {
                assert!(m.mae.is_finite() && m.bias.is_finite(), "{case}: {} metrics {m:?}", v.variable);
            }
        }
        fewest_failed = fewest_failed.min(failed);
    }
    if fewest_failed == usize::MAX { 0 } else { fewest_failed }
}

/// Level-0 recounted independently of its flags, asserting per pixel-band that the flags agree:
/// returns (pixel-bands that surely saturated, pixel-bands that may have, pixel-bands at zero
/// counts), and asserts every DN and analogue value within the converter's range.
///
/// The detector model (src/instrument/detector.rs; Janesick 2007 ch. 2–3): electrons
/// e ~ Poisson(μ) with μ = K·L + D (K the responsivity of the pixel's detector and band, L its
/// band radiance, D the dark electrons), clipped at the well W; then DN = round(e/g + bias + n),
/// n the read noise σ_r/g DN rms, clipped to 0 … 2^bits − 1. A pixel-band saturates when e ≥ W
/// (not for the ideal radiometer, which has no well) or, with quantisation, when the DN reaches
/// 2^bits − 1; it reads zero counts, with quantisation, when the DN is 0.
///
/// Without shot noise e = min(μ, W) exactly (to the f32 storage, 1e-6 here). With it, the
/// Poisson draw is below μ − 8√μ − 1 or above μ + 8√μ + 8 with probability under 1e-12 per
/// pixel-band (normal tail at 8σ; the +8 covers small μ, where P(e ≥ μ + 8√μ + 8) < 1e-12 for
/// every μ ≥ 0): so e ≥ W surely when μ − 8√μ − 1 ≥ W and surely not when μ + 8√μ + 8 < W.
/// Read noise beyond 8σ_r is as unlikely, which bounds the counts of a full well.
fn level0_recount(out: &RunOutput, case: &str) -> (usize, usize, usize) {
    let c = &out.config;
    let spec = &c.instrument;
    let l0 = &out.kept().level0;
    let det = Detector::new(spec, &out.response, c.detector, c.seed);
    let mode = det.mode();
    let ideal = !spec.kind.model().capabilities().real_detector;
    // The converter's ceiling, 2^bits − 1, from the bit count (the ADC clips whether or not
    // Level-1 uses the quantised value).
    let adc_max = f64::from((1u32 << spec.adc_bits) - 1);
    let read_dn = if mode.noise { 8.0 * spec.read_noise_e / spec.gain_e_per_dn } else { 0.0 };
    // A full well reads at most (W/g + bias + 8σ_r/g), rounded.
    let full_well_dn = spec.well_depth_e / spec.gain_e_per_dn + spec.bias_dn + read_dn;
    let dn_ceiling = if ideal { adc_max } else { adc_max.min((full_well_dn + 0.5).floor()) };
    let t = det.exposure_s();
    let well = spec.well_depth_e;
    let (rows, cols, nb) = l0.dn.dim();
    let (mut sure, mut possible, mut zero) = (0, 0, 0);
    for r in 0..rows {
        for col in 0..cols {
            let j = out.viewing.detector_index[col];
            for b in 0..nb {
                let dn = f64::from(l0.dn[[r, col, b]]);
                assert!(dn <= dn_ceiling, "{case}: DN {dn} above {dn_ceiling} at ({r},{col},{b})");
                if let Some(a) = &l0.analog {
                    // Quantisation off: the analogue value is e/g + bias + noise, clipped at the
                    // ADC's ceiling (never for the ideal radiometer); e ≥ 0.
                    let a = f64::from(a[[r, col, b]]);
                    let lo = spec.bias_dn - read_dn;
                    let hi = if ideal { f64::INFINITY } else { adc_max.min(full_well_dn) };
                    // f32 storage: 1e-6 relative.
                    let slack = 1e-6 * (lo.abs() + hi.min(adc_max).abs() + 1.0);
                    assert!(
                        a.is_finite() && a >= lo - slack && a <= hi + slack,
                        "{case}: analog DN {a} at ({r},{col},{b})"
                    );
                }
                let l = f64::from(out.kept().radiance.radiance[[r, col, b]]).max(0.0);
                let mu = det.responsivity(j, b) * l + det.dark_mean_e(j, b, t);
                let (well_sure, well_possible) = if ideal {
                    (false, false)
                } else if mode.noise {
                    (mu - 8.0 * mu.sqrt() - 1.0 >= well, mu + 8.0 * mu.sqrt() + 8.0 >= well)
                } else {
                    (mu >= well * (1.0 + 1e-6), mu >= well * (1.0 - 1e-6))
                };
                let adc_full = mode.quantise && dn >= adc_max;
                let flagged = l0.flags[[r, col, b]] & Flags::SATURATED != 0;
                if well_sure || adc_full {
                    sure += 1;
                    assert!(flagged, "{case}: ({r},{col},{b}) saturated (μ {mu:.0} e-, DN {dn}) but not flagged");
                }
                if well_possible || adc_full {
                    possible += 1;
                } else {
                    assert!(!flagged, "{case}: ({r},{col},{b}) flagged saturated at μ {mu:.0} e-, DN {dn}");
                }
                let at_zero = mode.quantise && dn == 0.0;
                zero += usize::from(at_zero);
                assert_eq!(l0.flags[[r, col, b]] & Flags::ZERO != 0, at_zero, "{case}: ZERO flag at ({r},{col},{b})");
            }
        }
    }
    (sure, possible, zero)
}

/// A run that must succeed.
pub fn run(config: &RunConfig) -> RunOutput {
    shoal::engine::Engine::new().run(config, &shoal::control::RunControl::new()).unwrap()
}

/// Cases per property: `PROPTEST_CASES` when set (a long run), else `default` (CI).
pub fn proptest_cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}
