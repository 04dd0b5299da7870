//! Bad input gets a clear error naming the field; nothing panics, nothing turns into NaN.

use shoal::control::RunControl;
use shoal::engine::{Engine, EngineError, RunConfig};
use shoal::scene::MapSpec;

use super::{small, small_lake};

fn error_of(config: &RunConfig) -> String {
    match Engine::new().run(config, &RunControl::new()) {
        Err(EngineError::Failed { stage, message }) => format!("{stage}: {message}"),
        Err(e) => panic!("unexpected {e}"),
        Ok(_) => panic!("accepted bad input"),
    }
}

fn base() -> RunConfig {
    RunConfig::new(small_lake(), small("nominal", 16, 16))
}

#[test]
fn zero_aperture_names_the_field() {
    let mut c = base();
    c.instrument.aperture_mm = 0.0;
    let e = error_of(&c);
    assert!(e.contains("aperture_mm") && e.contains("out of range"), "{e}");
}

#[test]
fn more_than_sixteen_bits_names_the_field() {
    let mut c = base();
    c.instrument.adc_bits = 17;
    let e = error_of(&c);
    assert!(e.contains("adc_bits") && e.contains("1 to 16"), "{e}");
}

#[test]
fn negative_depth_map_names_the_field() {
    let mut c = RunConfig::new(super::reef(), small("nominal", 16, 16));
    c.scene.depth_m = Some(MapSpec::Gradient { from: -1.0, to: 5.0, angle_deg: 0.0 });
    let e = error_of(&c);
    assert!(e.contains("depth_m"), "{e}");
}

#[test]
fn missing_image_file_names_the_field_and_path() {
    let mut c = base();
    c.scene.chl_mg_m3 = MapSpec::Image { path: "no/such/chl.png".into(), min: 1.0, max: 100.0 };
    let e = error_of(&c);
    assert!(e.contains("chl_mg_m3") && e.contains("no/such/chl.png"), "{e}");
}

#[test]
fn other_out_of_range_fields_are_named() {
    type Change = Box<dyn Fn(&mut RunConfig)>;
    let cases: Vec<(&str, Change)> = vec![
        ("exposure_s", Box::new(|c| c.instrument.exposure_s = -1.0)),
        ("gain_e_per_dn", Box::new(|c| c.instrument.gain_e_per_dn = f64::NAN)),
        ("optical_transmission", Box::new(|c| c.instrument.optical_transmission = 1.5)),
        ("detectors", Box::new(|c| c.instrument.detectors = 0)),
        ("sun.zenith_deg", Box::new(|c| c.scene.sun.zenith_deg = 95.0)),
        ("fidelity.decimation", Box::new(|c| c.fidelity.decimation = 0)),
        ("calibration.diffuser_bias_pct", Box::new(|c| c.calibration.diffuser_bias_pct = 80.0)),
        ("chl_mg_m3", Box::new(|c| c.scene.chl_mg_m3 = MapSpec::Constant(-3.0))),
    ];
    for (field, change) in cases {
        let mut c = base();
        change(&mut c);
        let e = error_of(&c);
        assert!(e.contains(field), "{field}: {e}");
    }
}

#[test]
fn a_malformed_instrument_file_names_the_line_and_field() {
    let text = "InstrumentSpec(name: \"x\", aperture_mmm: 3.0)";
    let e = shoal::instrument::InstrumentSpec::from_ron(text, "bad.ron").unwrap_err().to_string();
    assert!(e.contains("bad.ron") && e.contains("aperture_mmm") && e.contains("line 1, column 27"), "{e}");
}
