//! Hard cases: every stage at its extremes, random valid inputs (proptest), injected faults,
//! and the loaders against hostile text. Each test asserts finiteness, physical bounds and that
//! degraded results are flagged and counted (never silently replaced); see README "Hard cases".
//!
//! The bounds: 0 ≤ Rrs ≤ 1/π sr⁻¹ (a Lambertian reflector of albedo 1 has Rrs = 1/π),
//! 0 ≤ T ≤ 1 for every transmittance and the spherical albedo, 0 ≤ DN ≤ 2^bits − 1.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod atmosphere;
mod chain;
mod faults;
mod loaders;
mod properties;
mod ranges;
mod water;

use shoal::correction::RrsFlags;
use shoal::engine::{RunConfig, RunOutput};
use shoal::instrument::InstrumentSpec;
use shoal::retrieval::ProductFlags;
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
    i.exposures = lines;
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
    /// Retrieval pixels flagged failed.
    pub failed: usize,
}

/// Every invariant of a finished run; returns the degraded counts (which the run's own report
/// must agree with).
pub fn check(out: &RunOutput, case: &str) -> Degraded {
    let c = &out.config;
    let rad = &out.radiance;
    for (name, v) in [("radiance", &rad.radiance), ("true Rrs", &rad.rrs)] {
        assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0), "{case}: {name} not finite or negative");
    }
    for ((r, col, _), x) in rad.rrs.indexed_iter() {
        if rad.land[[r, col]] == 0 {
            assert!(f64::from(*x) <= RRS_MAX, "{case}: true Rrs {x} above 1/π");
        }
    }
    // Band atmosphere: everything finite, the spherical albedo a fraction.
    let atm = &out.band_atmosphere;
    for (name, v) in [("l_path", &atm.l_path), ("glint", &atm.glint), ("ed", &atm.ed), ("t_ed", &atm.t_ed)] {
        assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0), "{case}: band {name} not finite");
    }
    assert!(atm.spherical_albedo.iter().all(|s| (0.0..=1.0).contains(s)), "{case}: spherical albedo out of 0–1");
    // Level-0: counts within the converter's range; the flags and the report agree.
    let l0 = &out.level0;
    let dn_max = if c.detector.quantise { c.instrument.dn_max() } else { f64::from(u16::MAX) };
    assert!(l0.dn.iter().all(|&d| f64::from(d) <= dn_max), "{case}: DN above {dn_max}");
    if let Some(a) = &l0.analog {
        assert!(a.iter().all(|x| x.is_finite()), "{case}: analog DN not finite");
    }
    let count = |flags: &ndarray::Array3<u8>, bit: u8| flags.iter().filter(|f| **f & bit != 0).count();
    let (rows, cols, nb) = l0.dn.dim();
    let mut d = Degraded {
        pixels: rows * cols,
        pixel_bands: rows * cols * nb,
        saturated: count(&l0.flags, shoal::instrument::Flags::SATURATED),
        zero: count(&l0.flags, shoal::instrument::Flags::ZERO),
        ..Degraded::default()
    };
    assert_eq!((d.saturated, d.zero), (out.report.saturated, out.report.zero_counts), "{case}: report vs flags");
    assert!(out.level1.radiance.iter().all(|x| x.is_finite()), "{case}: Level-1 not finite");
    // Rrs: finite everywhere; a pixel-band made invalid is flagged, never a silent number.
    let rrs = &out.correction.rrs;
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
    // Retrievals: returned pixels are finite and non-negative; failures are flagged, counted
    // in the metrics, and excluded from them.
    for ret in &out.retrievals {
        let p = &ret.product;
        let mut failed = 0;
        for ((r, col), f) in p.flags.indexed_iter() {
            if f & ProductFlags::FAILED != 0 {
                failed += 1;
                continue;
            }
            if f & ProductFlags::RETURNED != 0 {
                for (name, v) in
                    [("chl", p.chl_mg_m3[[r, col]]), ("nap", p.nap_g_m3[[r, col]]), ("cdom", p.cdom_per_m[[r, col]])]
                {
                    assert!(v.is_finite() && v >= 0.0, "{case}: {name} {v} at ({r}, {col})");
                }
                if let Some(depth) = &p.depth_m {
                    assert!(depth[[r, col]].is_finite(), "{case}: depth at ({r}, {col})");
                }
            }
        }
        assert_eq!(failed, ret.metrics.failed, "{case}: failed pixels vs metrics");
        for v in &ret.metrics.variables {
            let m = &v.metrics;
            assert!(m.returned_pct.is_finite() && (0.0..=100.0).contains(&m.returned_pct), "{case}: {v:?}");
            if m.n > 0 {
                assert!(m.mae.is_finite() && m.bias.is_finite(), "{case}: {} metrics {m:?}", v.variable);
            }
        }
        d.failed += failed;
    }
    d
}

/// A run that must succeed.
pub fn run(config: &RunConfig) -> RunOutput {
    shoal::engine::Engine::new().run(config, &shoal::control::RunControl::new()).unwrap()
}

/// Cases per property: `PROPTEST_CASES` when set (a long run), else `default` (CI).
pub fn proptest_cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}
