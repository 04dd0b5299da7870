//! Incremental re-runs: a change re-runs only the stages downstream of it.

use crate::common::Kept;
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
    // Every stage ran once, except the retrieval and its model (none is configured), the
    // image-based correction's family (the correction is exact) and the optical effects (the
    // instrument lists none).
    let retrieval = |s: Stage| {
        matches!(
            s,
            Stage::Retrieval | Stage::RetrievalModel | Stage::AerosolLuts | Stage::AerosolFamily | Stage::Effects
        )
    };
    assert!(Stage::ALL.iter().all(|&s| engine.executions(s) == u64::from(!retrieval(s))), "{:?}", counts(&engine));

    config.instrument.gain_e_per_dn = 2.0;
    let second = engine.run(&config, &RunControl::new()).unwrap();
    for stage in Stage::ALL {
        let expected = match stage {
            // The electronics: the detector model (and its feasibility figures: the ADC's full
            // scale and step), counts, calibration and everything after.
            Stage::Detector
            | Stage::Feasibility
            | Stage::Level0
            | Stage::Calibration
            | Stage::Level1
            | Stage::Correction
            | Stage::Snr => 2,
            Stage::RetrievalModel | Stage::Retrieval | Stage::AerosolLuts | Stage::AerosolFamily | Stage::Effects => 0,
            // Never the scene, the atmosphere or the photon counts.
            _ => 1,
        };
        assert_eq!(engine.executions(stage), expected, "{stage}: {:?}", counts(&engine));
    }
    assert!(!second.report.ran(Stage::Radiance) && !second.report.ran(Stage::Electrons));
    assert!(second.report.ran(Stage::Level0));
    // The counts changed; the photon-side products are the very same objects.
    assert!(std::sync::Arc::ptr_eq(&first.kept().radiance, &second.kept().radiance));
    assert_ne!(first.kept().level0.dn, second.kept().level0.dn);

    // Back to the first gain (an A/B toggle): everything comes from the cache.
    config.instrument.gain_e_per_dn = 3.0;
    let again = engine.run(&config, &RunControl::new()).unwrap();
    assert!(
        again.report.stages.iter().all(|s| s.status == shoal::engine::StageStatus::Cached),
        "{}",
        again.report.table()
    );
    assert_eq!(again.kept().level0.dn, first.kept().level0.dn);

    // The aperture changes the photon counts but not the scene or its radiance.
    config.instrument.aperture_mm = 100.0;
    engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(engine.executions(Stage::Radiance), 1);
    assert_eq!(engine.executions(Stage::Electrons), 2);
    assert_eq!(engine.executions(Stage::Lut), 1);
}

#[test]
fn an_aperture_change_reruns_the_retrieval_but_keeps_its_model() {
    // The model (SIOP sets and substrates at the bands) reads the bands, not the Rrs: a change of
    // the photon counts re-runs the pixels with the very same model; a change of the bands'
    // view (the pixel pitch moves the central column's T_up·Ed) rebuilds it.
    let mut engine = Engine::new();
    let mut config = RunConfig::new(small_lake(), small("nominal", 32, 24));
    config.retrievals = vec![ron::from_str("Almi()").unwrap()];
    let first = engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!((engine.executions(Stage::RetrievalModel), engine.executions(Stage::Retrieval)), (1, 1));
    config.instrument.aperture_mm *= 1.5;
    let second = engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(engine.executions(Stage::RetrievalModel), 1, "the model is kept");
    assert_eq!(engine.executions(Stage::Retrieval), 2, "the pixels are not");
    assert_ne!(first.retrievals[0].product.chl_mg_m3, second.retrievals[0].product.chl_mg_m3);
    // What the kept model gives is what a fresh one gives, bit for bit (NaN included).
    let fresh = Engine::new().run(&config, &RunControl::new()).unwrap();
    assert_eq!(format!("{:?}", second.retrievals[0].product), format!("{:?}", fresh.retrievals[0].product));
    config.instrument.pixel_pitch_um *= 1.1;
    engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(engine.executions(Stage::RetrievalModel), 2, "new bands, a new model");
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
fn a_siop_file_edited_on_disk_reruns_the_scene_and_matches_a_fresh_engine() {
    // The configuration names the file, not its contents: without the files' fingerprint in the
    // keys, an engine kept warm (the app's) would serve the old set's products.
    let dir = std::env::temp_dir().join(format!("shoal-siop-edit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("a_ph.csv");
    let original =
        std::fs::read_to_string(format!("{}/presets/examples/my_siop.csv", env!("CARGO_MANIFEST_DIR"))).unwrap();
    std::fs::write(&csv, &original).unwrap();
    let mut config = RunConfig::new(small_lake(), small("nominal", 32, 24));
    config.scene.siop = shoal::water::SiopSource::Csv(csv.clone());
    let mut engine = Engine::new();
    let first = engine.run(&config, &RunControl::new()).unwrap();
    // Twice the chl-specific absorption, written under the same name.
    let doubled: String = original
        .lines()
        .map(|l| match l.split_once(',') {
            Some((w, v)) if w.parse::<f64>().is_ok() => format!("{w},{}\n", 2.0 * v.trim().parse::<f64>().unwrap()),
            _ => format!("{l}\n"),
        })
        .collect();
    std::fs::write(&csv, doubled).unwrap();
    let second = engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(engine.executions(Stage::Scene), 2, "the edit re-ran the scene");
    assert_ne!(first.kept().radiance.radiance, second.kept().radiance.radiance, "the edit changed the radiance");
    let fresh = Engine::new().run(&config, &RunControl::new()).unwrap();
    assert_eq!(fingerprint(&second), fingerprint(&fresh), "the warm engine returns what a fresh one does");
    // Unchanged, it comes from the cache.
    engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(engine.executions(Stage::Scene), 2);
    std::fs::remove_dir_all(&dir).unwrap();
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

/// Pupil radiance, Level-0 DN, Level-1 radiance, Rrs and the SNR table of a run.
type Fingerprint = (Vec<f32>, Vec<u16>, Vec<f32>, Vec<f32>, Vec<shoal::instrument::SnrRow>);

/// Every product a run hands on, for bit-wise comparison.
fn fingerprint(out: &shoal::engine::RunOutput) -> Fingerprint {
    (
        out.kept().radiance.radiance.iter().copied().collect(),
        out.kept().level0.dn.iter().copied().collect(),
        out.kept().level1.radiance.iter().copied().collect(),
        out.kept().rrs.rrs.iter().copied().collect(),
        out.snr.as_ref().clone(),
    )
}

#[test]
fn after_a_change_of_any_one_field_a_warm_engine_returns_what_a_fresh_one_does() {
    // The cache serves a product only under the key of everything it was computed from; a field
    // missing from a key would make the warm engine serve the old product. Every numeric field of
    // the instrument, the detector switches and the fidelity settings is changed in turn on the
    // filter imager (whose band view angles depend on the focal plane: the response key lacked
    // the focal length and pixel pitch until the keys were built by exhaustive destructuring,
    // `src/engine/keys.rs`). The comparison is exact: the same inputs give the same bits.
    let base = {
        let mut c = RunConfig::new(small_lake(), small("filter_imager", 48, 40));
        c.fidelity.snr_frames = 20;
        c
    };
    type Change = (&'static str, fn(&mut RunConfig));
    let changes: [Change; 25] = [
        ("altitude_km", |c| c.instrument.altitude_km *= 1.1),
        ("heading_deg", |c| c.instrument.heading_deg += 20.0),
        ("aperture_mm", |c| c.instrument.aperture_mm *= 1.2),
        ("pixel_pitch_um", |c| c.instrument.pixel_pitch_um *= 1.2),
        ("focal_length_mm", |c| c.instrument.focal_length_mm *= 1.2),
        ("detectors", |c| c.instrument.detectors += 8),
        ("exposure_s", |c| c.instrument.exposure_s *= 0.8),
        ("lines", |c| c.instrument.lines += 8),
        ("forward_tilt_deg", |c| c.instrument.forward_tilt_deg += 5.0),
        ("read_noise_e", |c| c.instrument.read_noise_e *= 2.0),
        ("well_depth_e", |c| c.instrument.well_depth_e *= 0.5),
        ("gain_e_per_dn", |c| c.instrument.gain_e_per_dn *= 1.5),
        ("bias_dn", |c| c.instrument.bias_dn += 10.0),
        ("adc_bits", |c| c.instrument.adc_bits -= 2),
        ("optical_transmission", |c| c.instrument.optical_transmission *= 0.9),
        ("dark_current_e_s", |c| c.instrument.dark_current_e_s *= 3.0),
        ("prnu", |c| c.instrument.prnu += 0.01),
        ("dsnu_e", |c| c.instrument.dsnu_e += 5.0),
        ("detector.noise", |c| c.detector.noise = !c.detector.noise),
        ("detector.quantise", |c| c.detector.quantise = !c.detector.quantise),
        ("seed", |c| c.seed += 1),
        ("fidelity.spectral_step_nm", |c| c.fidelity.spectral_step_nm = 2.0),
        ("fidelity.band_nodes", |c| c.fidelity.band_nodes = if c.fidelity.band_nodes == 2 { 3 } else { 2 }),
        ("fidelity.decimation", |c| c.fidelity.decimation = 2),
        ("fidelity.snr_frames", |c| c.fidelity.snr_frames += 5),
    ];
    let mut warm = Engine::new();
    let before = fingerprint(&warm.run(&base, &RunControl::new()).unwrap());
    for (field, change) in changes {
        let mut config = base.clone();
        change(&mut config);
        let from_warm = fingerprint(&warm.run(&config, &RunControl::new()).unwrap());
        let from_fresh = fingerprint(&Engine::new().run(&config, &RunControl::new()).unwrap());
        assert!(from_warm == from_fresh, "{field}: the warm engine served a stale product");
        assert!(from_fresh != before, "{field}: the change changed nothing (the test would not see a stale key)");
        // And back: the base products again, from the cache.
        assert!(fingerprint(&warm.run(&base, &RunControl::new()).unwrap()) == before, "{field}: back to the base");
    }
}

#[test]
fn the_image_based_correction_keeps_its_family_across_gain_and_true_aerosol_changes() {
    let mut engine = Engine::new();
    let mut config = RunConfig::new(small_lake(), small("cubesat", 48, 32));
    config.correction.method = shoal::correction::Method::Image(shoal::correction::ImageCorrection::default());
    engine.run(&config, &RunControl::new()).unwrap();
    // A gain change reruns the correction, not its family.
    config.instrument.gain_e_per_dn = 2.0;
    engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(engine.executions(Stage::Correction), 2);
    assert_eq!((engine.executions(Stage::AerosolLuts), engine.executions(Stage::AerosolFamily)), (1, 1));
    // The scene's true AOT rebuilds the scene's LUT, not the family's atmospheres (the
    // processor does not know the truth).
    config.scene.atmosphere.aot550 = 0.2;
    engine.run(&config, &RunControl::new()).unwrap();
    assert_eq!(engine.executions(Stage::Lut), 2);
    assert_eq!(engine.executions(Stage::AerosolLuts), 1);
}
