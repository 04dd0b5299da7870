//! The instrument's optical effects through the whole chain (`instrument::effects`): applied
//! between the pupil and the detector, corrected on Level-1 as the processor knows them.

use crate::common::Kept;

use shoal::control::RunControl;
use shoal::engine::{Engine, EngineError, RunConfig, RunOutput, Stage};
use shoal::instrument::DetectorMode;

use super::{run, small, small_lake};

/// A noise-free CubeSat over a cut of Lake Hume (shore included) with `effects` (RON).
fn config(effects: &str) -> RunConfig {
    let mut instrument = small("cubesat", 96, 64);
    instrument.effects = ron::from_str(effects).unwrap();
    let mut c = RunConfig::new(small_lake(), instrument);
    c.detector = DetectorMode::IDEAL;
    c.calibration.perfect = true;
    c
}

/// Largest |a/b − 1| over Level-1 pixels brighter than 1e-6.
fn worst_relative(a: &RunOutput, b: &RunOutput) -> f64 {
    let (a, b) = (&a.kept().level1.radiance, &b.kept().level1.radiance);
    a.iter().zip(b).filter(|(_, y)| **y > 1e-6).map(|(x, y)| f64::from(x / y - 1.0).abs()).fold(0.0, f64::max)
}

const STRAY: &str = "StrayLight((halo_fraction: 0.05, knee_m: 40.0, slope: 2.5, radius_m: 800.0, \
                     out_of_field_fraction: 0.01, correction: (corrected: @C, error: @E)))";
const POLARISATION: &str = "Polarisation((sensitivity: 0.03, axis_deg: 20.0, correction: (corrected: @C, error: @E)))";

fn with(effect: &str, corrected: bool, error: f64) -> String {
    format!("[{}]", effect.replace("@C", &corrected.to_string()).replace("@E", &format!("{error:?}")))
}

#[test]
fn each_effect_moves_level1_and_the_processor_that_knows_it_takes_it_back() {
    let ideal = run(&config("[]"));
    for (name, effect, moved_at_least) in [("stray light", STRAY, 1e-3), ("polarisation", POLARISATION, 1e-3)] {
        let raw = run(&config(&with(effect, false, 0.0)));
        let exact = run(&config(&with(effect, true, 0.0)));
        let wrong = run(&config(&with(effect, true, 0.2)));
        let (e_raw, e_exact, e_wrong) =
            (worst_relative(&raw, &ideal), worst_relative(&exact, &ideal), worst_relative(&wrong, &ideal));
        eprintln!("{name}: uncorrected {e_raw:.2e}, known exactly {e_exact:.2e}, known to 20 % {e_wrong:.2e}");
        assert!(e_raw > moved_at_least, "{name} changes Level-1: {e_raw}");
        // Known exactly: the correction closes to f32 rounding of the radiance (and, for the
        // stray light, the fixed point's 1e-6 of the brightest pixel).
        assert!(e_exact < 1e-4, "{name} corrected exactly: {e_exact}");
        // Known to 20 %: about a fifth of the effect is left (the halo's interplay with the
        // veil makes it not exactly a fifth), of the opposite sign.
        assert!(e_wrong > 0.1 * e_raw && e_wrong < 0.35 * e_raw, "{name}: {e_wrong} of {e_raw}");
        // The pupil radiance is the same: the effect sits between the pupil and the detector.
        assert_eq!(raw.kept().radiance.radiance, ideal.kept().radiance.radiance);
    }
}

#[test]
fn effects_are_deterministic_across_thread_counts_and_cached_by_what_they_read() {
    let both = |e: f64| {
        let (a, b) = (with(STRAY, true, e), with(POLARISATION, true, e));
        format!("[{}, {}]", &a[1..a.len() - 1], &b[1..b.len() - 1])
    };
    let c = config(&both(0.1));
    let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
    let one = pool(1).install(|| run(&c));
    let two = pool(2).install(|| run(&c));
    assert_eq!(one.kept().level1.radiance, two.kept().level1.radiance);
    assert_eq!(one.kept().rrs.rrs, two.kept().rrs.rrs);
    // A change of the processor's knowledge reruns Level-1 onward, not the effects.
    let mut engine = Engine::new();
    engine.run(&c, &RunControl::new()).unwrap();
    let mut changed = c.clone();
    changed.instrument.effects = ron::from_str(&both(0.3)).unwrap();
    let known = engine.run(&changed, &RunControl::new()).unwrap();
    assert!(known.report.ran(Stage::Level1), "the processor's knowledge reruns Level-1");
    assert!(!known.report.ran(Stage::Effects) && !known.report.ran(Stage::Level0), "but not the effects or Level-0");
    changed.instrument.effects = ron::from_str(&with(POLARISATION, true, 0.1)).unwrap();
    let fewer = engine.run(&changed, &RunControl::new()).unwrap();
    assert!(fewer.report.ran(Stage::Effects) && fewer.report.ran(Stage::Level0), "another list reruns them");
}

#[test]
fn polarisation_without_the_vector_atmosphere_is_refused_by_name() {
    let mut c = config(&with(POLARISATION, true, 0.0));
    c.scene.atmosphere.accuracy.polarization_correction = false;
    let e = Engine::new().run(&c, &RunControl::new()).unwrap_err();
    let EngineError::Failed { message, .. } = &e else { panic!("{e}") };
    assert!(message.contains("polarization_correction") && message.contains("Polarisation"), "{message}");
}
