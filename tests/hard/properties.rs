//! Property tests (proptest): random valid scenes and instruments through the whole chain.
//!
//! - every run passes [`check`] (finite, within physical bounds, degraded pixels flagged and
//!   recounted from the counts);
//! - one and two threads give bit-identical products;
//! - noise-free, with chl-a 1–300 mg m⁻³, NAP 0.1–20 g m⁻³ and CDOM 0.01–2 m⁻¹, aLMI with the
//!   scene's own SIOP set gets chl-a back within 12 % at every pixel no band of which saturated.
//!   The 12 % is what aLMI's band-averaged linear model allows over that domain: its error,
//!   measured, is 0.46 % median and 3.1 % at the 99th percentile (3,200 pixels, 200 random
//!   cases), and at most 11.1 % at the domain's turbid, CDOM-rich, low-chl corner (chl 1, NAP
//!   20, CDOM 2, sun at 70°), which runs as a fixed case. That error is the model's, not the
//!   chain's: aLMI on the true band Rrs of that corner (no atmosphere, no instrument) is off by
//!   10.3 % (sun at 40°), and the delivered Rrs changes chl by 1e-4 of it.
//!   A saturated band is dropped from the fit (and `check` asserts it is flagged and counted),
//!   so such a pixel is either FAILED or fitted from fewer bands and is not held to the 12 %.
//!   The nominal instrument saturates in every band under a zenith sun at nadir with AOT ≈ 0.44:
//!   the flat sea mirrors the sun's aerosol aureole into the view (ρ_path = 1.98 at 412 nm,
//!   against 0.18 with the sun at 5°; see tests/physics/atmosphere_limits.rs). Found by a
//!   300-case run, kept in tests/proptest-regressions. Only suns within a few degrees of the
//!   zenith saturate (none of 200 random cases with the zenith uniform in 0–70°), so the test
//!   asserts that at least half its cases, and at least half their pixels, were held to the
//!   tolerance.
//!
//! CI runs `PROPTEST_CASES` cases per property (default 16: about a minute on 2 cores). A long
//! run: `PROPTEST_CASES=1000 cargo test --release --test hard properties`.

use crate::common::Kept;
use proptest::prelude::*;
use shoal::control::RunControl;
use shoal::engine::{Engine, RunConfig, RunOutput};
use shoal::instrument::DetectorMode;
use shoal::retrieval::{AlmiSettings, RetrievalSpec, SambucaSettings};
use shoal::scene::{Effect, MapSpec, SubstrateLayer};

use super::{check, instrument, uniform};

/// Log-uniform in [lo, hi].
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..=hi.ln()).prop_map(f64::exp)
}

/// Scene settings: chl, NAP, CDOM, depth (None: deep), sand fraction, sun zenith, AOT.
type SceneDraw = (f64, f64, f64, Option<f64>, f64, f64, f64);

fn scene_draw() -> impl Strategy<Value = SceneDraw> {
    (
        log_uniform(0.001, 1000.0),
        prop_oneof![Just(0.0), log_uniform(0.01, 100.0)],
        prop_oneof![Just(0.0), log_uniform(0.001, 100.0)],
        prop_oneof![Just(None), log_uniform(0.01, 1000.0).prop_map(Some)],
        0.0..=1.0,
        0.0..=85.0,
        0.0..=1.0,
    )
}

/// Instrument settings: base preset, aperture mm, exposure s, ADC bits, gain e-/DN, read noise
/// e-, detectors, lines, forward tilt degrees.
type InstrumentDraw = (&'static str, f64, f64, u32, f64, f64, usize, usize, f64);

fn instrument_draw() -> impl Strategy<Value = InstrumentDraw> {
    (
        prop_oneof![Just("nominal"), Just("cubesat"), Just("smallsat")],
        log_uniform(10.0, 500.0),
        log_uniform(1e-4, 0.1),
        4u32..=16,
        log_uniform(0.1, 100.0),
        0.0..=100.0,
        1usize..=12,
        1usize..=8,
        -30.0..=30.0,
    )
}

fn build(s: SceneDraw, i: InstrumentDraw) -> RunConfig {
    let (chl, nap, cdom, depth, sand, zenith, aot) = s;
    let mut scene = uniform(chl, nap, cdom);
    scene.sun.zenith_deg = zenith;
    scene.atmosphere.aot550 = aot;
    if let Some(d) = depth {
        scene.depth_m = Some(MapSpec::Constant(d));
        scene.substrates = vec![
            SubstrateLayer { name: "sand".into(), fraction: MapSpec::Constant(sand) },
            SubstrateLayer { name: "acropora".into(), fraction: MapSpec::Constant(1.0 - sand) },
        ];
        scene.effects = vec![Effect::ShallowBottom];
    }
    let (name, aperture, exposure, bits, gain, read_noise, detectors, lines, tilt) = i;
    let mut c = RunConfig::new(scene, instrument(name, detectors, lines));
    c.instrument.aperture_mm = aperture;
    c.instrument.exposure_s = exposure;
    c.instrument.adc_bits = bits;
    c.instrument.gain_e_per_dn = gain;
    c.instrument.read_noise_e = read_noise;
    c.instrument.forward_tilt_deg = tilt;
    c.retrievals = vec![RetrievalSpec::Almi {
        siop_sets: shoal::retrieval::sets::default_almi_sets(),
        settings: AlmiSettings::default(),
    }];
    if depth.is_some() {
        c.retrievals.push(RetrievalSpec::Sambuca {
            siop: None,
            substrates: None,
            settings: SambucaSettings::default(),
        });
    }
    c
}

fn run_on(threads: usize, config: &RunConfig) -> RunOutput {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| Engine::new().run(config, &RunControl::new()).unwrap())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(super::proptest_cases(16)))]

    #[test]
    fn any_valid_scene_and_instrument_is_finite_bounded_and_thread_independent(
        s in scene_draw(),
        i in instrument_draw(),
        seed in 0u64..1000,
    ) {
        let mut c = build(s, i);
        c.seed = seed;
        c.instrument.validate().unwrap();
        let one = run_on(1, &c);
        check(&one, &format!("{s:?} {i:?}"));
        let two = run_on(2, &c);
        prop_assert_eq!(&one.kept().level0.dn, &two.kept().level0.dn);
        prop_assert_eq!(&one.kept().rrs.rrs, &two.kept().rrs.rrs);
        for (a, b) in one.retrievals.iter().zip(&two.retrievals) {
            prop_assert_eq!(&a.product.chl_mg_m3, &b.product.chl_mg_m3);
            prop_assert_eq!(&a.product.flags, &b.product.flags);
            prop_assert_eq!(&a.product.depth_m, &b.product.depth_m);
        }
    }

}

/// Largest relative chl-a error allowed in the noise-free closure (see the module docs: the
/// measured worst over the domain is 11.1 %).
const CHL_TOLERANCE: f64 = 0.12;

/// One noise-free closure case: (pixels held to the tolerance, pixels skipped because a band
/// saturated, the largest relative error).
fn closure_case(chl: f64, nap: f64, cdom: f64, zenith: f64, aot: f64) -> Result<(usize, usize, f64), TestCaseError> {
    let mut scene = uniform(chl, nap, cdom);
    scene.sun.zenith_deg = zenith;
    scene.atmosphere.aot550 = aot;
    let mut c = RunConfig::new(scene, instrument("nominal", 4, 4));
    c.detector = DetectorMode::IDEAL;
    c.calibration.dark_exposure_s = c.instrument.exposure_s;
    c.retrievals = vec![RetrievalSpec::Almi {
        siop_sets: vec![shoal::water::SiopSource::Preset("cyanobacteria_reservoir".into())],
        settings: AlmiSettings::default(),
    }];
    let out = super::run(&c);
    check(&out, "closure");
    let p = &out.retrievals[0].product;
    let rrs_flags = &out.kept().rrs.flags;
    let (mut checked, mut skipped, mut worst) = (0, 0, 0.0f64);
    for ((r, c), f) in p.flags.indexed_iter() {
        let saturated =
            (0..rrs_flags.dim().2).any(|b| rrs_flags[[r, c, b]] & shoal::correction::RrsFlags::SATURATED != 0);
        if saturated {
            skipped += 1;
            continue;
        }
        prop_assert!(f & shoal::retrieval::ProductFlags::RETURNED != 0, "not returned: flags {}", f);
        let got = f64::from(p.chl_mg_m3.as_ref().unwrap()[[r, c]]);
        let err = (got / chl - 1.0).abs();
        prop_assert!(
            err < CHL_TOLERANCE,
            "chl {} (NAP {}, CDOM {}, sun {}°, AOT {}) retrieved {} ({:.1} %)",
            chl,
            nap,
            cdom,
            zenith,
            aot,
            got,
            100.0 * err
        );
        checked += 1;
        worst = worst.max(err);
    }
    Ok((checked, skipped, worst))
}

/// What the closure property saw: cases run, cases with at least one pixel held to the
/// tolerance, pixels held to it, pixels skipped for a saturated band, and the worst error.
#[derive(Debug, Default)]
struct Seen {
    cases: usize,
    checked_cases: usize,
    checked: usize,
    skipped: usize,
    worst: f64,
}

#[test]
fn noise_free_almi_returns_chl_where_chl_shapes_the_signal() {
    // The domain's worst corner, always: 11.1 % measured.
    let (checked, _, worst) = closure_case(1.0, 20.0, 2.0, 70.0, 0.0).unwrap();
    assert_eq!(checked, 16);
    assert!(worst > 0.10, "the corner's error was 11.1 %, now {:.2} %: revisit the tolerance", 100.0 * worst);
    // Random cases (a manual runner, as `proptest!` expands, so the cases can be counted);
    // persisted failures (tests/proptest-regressions) run first.
    let cases = super::proptest_cases(16);
    let mut config = ProptestConfig::with_cases(cases);
    config.source_file = Some(file!());
    let mut runner = proptest::test_runner::TestRunner::new(config);
    let seen = std::sync::Mutex::new(Seen::default());
    let draw = (log_uniform(1.0, 300.0), log_uniform(0.1, 20.0), log_uniform(0.01, 2.0), 0.0f64..=70.0, 0.0f64..=0.5);
    let result = runner.run(&draw, |(chl, nap, cdom, zenith, aot)| {
        let (checked, skipped, worst) = closure_case(chl, nap, cdom, zenith, aot)?;
        let mut s = seen.lock().unwrap();
        s.cases += 1;
        s.checked_cases += usize::from(checked > 0);
        s.checked += checked;
        s.skipped += skipped;
        s.worst = s.worst.max(worst);
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}\n{runner}");
    }
    let s = seen.into_inner().unwrap();
    eprintln!("noise-free aLMI closure: {s:?}");
    // Each case has 4 × 4 pixels. Saturation needs the sun within a few degrees of the zenith
    // (probability < 5/70 per random case): at least half the cases and half the pixels checked.
    assert!(s.cases >= cases as usize, "{s:?}");
    assert!(2 * s.checked_cases >= s.cases && 2 * s.checked >= 16 * s.cases, "{s:?}");
}
