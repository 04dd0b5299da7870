//! Incremental re-runs: a change re-runs only the stages downstream of it.

use shoal::control::RunControl;
use shoal::engine::{Engine, RunConfig, Stage};

use super::{small, small_lake};

fn counts(engine: &Engine) -> Vec<(Stage, u64)> {
    Stage::ALL.iter().map(|&s| (s, engine.executions(s))).collect()
}

#[test]
fn a_gain_change_reruns_only_digitisation_onward() {
    let mut engine = Engine::new();
    let mut config = RunConfig::new(small_lake(), small("nominal", 64, 48));
    let first = engine.run(&config, &RunControl::new()).unwrap();
    // Every stage ran once, except the retrieval: none is configured.
    assert!(
        Stage::ALL.iter().all(|&s| engine.executions(s) == u64::from(s != Stage::Retrieval)),
        "{:?}",
        counts(&engine)
    );

    config.instrument.gain_e_per_dn = 2.0;
    let second = engine.run(&config, &RunControl::new()).unwrap();
    for stage in Stage::ALL {
        let expected = match stage {
            // The electronics: the detector model, counts, calibration and everything after.
            Stage::Detector | Stage::Level0 | Stage::Calibration | Stage::Level1 | Stage::Correction | Stage::Snr => 2,
            Stage::Retrieval => 0,
            // Never the scene, the atmosphere or the photon counts.
            _ => 1,
        };
        assert_eq!(engine.executions(stage), expected, "{stage}: {:?}", counts(&engine));
    }
    assert!(!second.report.ran(Stage::Radiance) && !second.report.ran(Stage::Electrons));
    assert!(second.report.ran(Stage::Level0));
    // The counts changed; the photon-side products are the very same objects.
    assert!(std::sync::Arc::ptr_eq(&first.radiance, &second.radiance));
    assert_ne!(first.level0.dn, second.level0.dn);

    // Back to the first gain (an A/B toggle): everything comes from the cache.
    config.instrument.gain_e_per_dn = 3.0;
    let again = engine.run(&config, &RunControl::new()).unwrap();
    assert!(
        again.report.stages.iter().all(|s| s.status == shoal::engine::StageStatus::Cached),
        "{}",
        again.report.table()
    );
    assert_eq!(again.level0.dn, first.level0.dn);

    // The aperture changes the photon counts but not the scene or its radiance.
    config.instrument.aperture_mm = 100.0;
    engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(engine.executions(Stage::Radiance), 1);
    assert_eq!(engine.executions(Stage::Electrons), 2);
    assert_eq!(engine.executions(Stage::Lut), 1);
}

#[test]
fn a_sun_change_rebuilds_the_atmosphere_but_a_band_free_change_does_not() {
    let mut engine = Engine::new();
    let mut config = RunConfig::new(small_lake(), small("nominal", 32, 32));
    engine.run(&config, &RunControl::new()).unwrap();
    config.seed = 99; // noise only
    engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(engine.executions(Stage::Lut), 1);
    assert_eq!(engine.executions(Stage::Radiance), 1);
    assert_eq!(engine.executions(Stage::Electrons), 2);
    config.scene.sun.zenith_deg = 50.0;
    engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(engine.executions(Stage::Lut), 2);
    assert_eq!(engine.executions(Stage::Scene), 2, "the scene spec changed");
    assert_eq!(engine.executions(Stage::Response), 1, "the bands did not");
}

#[test]
fn a_cancelled_run_stops_and_leaves_the_engine_usable() {
    let mut engine = Engine::new();
    let config = RunConfig::new(small_lake(), small("nominal", 64, 64));
    let control = RunControl::new();
    control.cancel();
    assert_eq!(engine.run(&config, &control).unwrap_err(), shoal::engine::EngineError::Cancelled);
    assert!(engine.run(&config, &RunControl::new()).is_ok());
}
