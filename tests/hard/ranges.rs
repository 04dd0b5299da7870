//! Every entry of `shoal::ranges` is enforced where users meet it: a value just outside the range
//! (the open end itself, or one step past a closed end) is refused before any stage runs, and
//! the message names the field, the value and the range; both ends that are allowed pass. The
//! CLI turns a refusal into exit code 2.

use std::process::Command;

use shoal::engine::{EngineError, RunConfig};
use shoal::instrument::InstrumentSpec;
use shoal::ranges::{self, Range};
use shoal::scene::{MapSpec, Scene, SceneSpec};
use shoal::study::Requirements;

use crate::common::{both_retrievals, instrument_for, sweep_path};

/// A configuration in which every path of the table exists: both retrievals, a sun incidence,
/// a wind-roughened surface; a user's aerosol mixture or size distribution for its fields; a spectrograph or filter
/// imager for their `kind` fields.
fn base(path: &str) -> RunConfig {
    let mut instrument = InstrumentSpec::preset(instrument_for(path)).unwrap();
    crate::common::with_dark_laws(&mut instrument);
    if path.contains("effects[]") {
        crate::common::with_optical_effects(&mut instrument);
    }
    let mut c = RunConfig::new(SceneSpec::preset("lake_hume_bloom").unwrap(), instrument);
    c.retrievals = both_retrievals();
    if path.contains(".External.") {
        // Checked, never run.
        c.retrievals.push(crate::common::external_retrieval(&["true"]));
    }
    c.calibration.sun_incidence_deg = Some(30.0);
    c.scene.atmosphere.surface = shoal::atmosphere::SeaSurface::Wind { speed_m_s: 5.0 };
    if path.starts_with("scene.atmosphere.aerosol.Mixture") {
        c.scene.atmosphere.aerosol = shoal::atmosphere::AerosolType::Mixture(Default::default());
    }
    if path.starts_with("scene.clouds.") {
        c.scene.clouds = Some(shoal::scene::CloudLayer::default());
    }
    if path.starts_with("scene.atmosphere.aerosol.LogNormal") {
        // The bushfire-smoke scene's two modes.
        c.scene.atmosphere.aerosol = SceneSpec::preset("lake_hume_smoke").unwrap().atmosphere.aerosol;
    }
    c.validate().unwrap();
    c
}

/// The refusal of `value` at `range`, or `None` if it was accepted.
fn refusal(range: &Range, value: f64) -> Option<String> {
    let map = |spec: &mut SceneSpec, v: f64| {
        let m = MapSpec::Constant(v);
        match range.path {
            "scene.chl_mg_m3" => spec.chl_mg_m3 = m,
            "scene.nap_g_m3" => spec.nap_g_m3 = m,
            "scene.cdom_per_m" => spec.cdom_per_m = m,
            "scene.depth_m" => spec.depth_m = Some(m),
            "scene.aot550_map" => spec.aot550_map = Some(m),
            _ => spec.substrates[0].fraction = m,
        }
    };
    if range.path.starts_with("requirements.") {
        let mut r: Requirements = ron::from_str("(products: [(variable: \"chl_mg_m3\")])").unwrap();
        if range.path == "requirements.rrs.mae_pct" {
            r.rrs = Some(shoal::study::RrsRequirement { mae_pct: value, from_nm: 400.0, to_nm: 560.0 });
            return r.validate().err().map(|e| e.to_string());
        }
        match range.name() {
            "mae_pct" => r.products[0].mae_pct = Some(value),
            "bias_pct" => r.products[0].bias_pct = Some(value),
            "returned_pct" => r.products[0].returned_pct = Some(value),
            "substrate_pct" => r.substrate_pct = Some(value),
            _ => r.snr = Some(value),
        }
        return r.validate().err().map(|e| e.to_string());
    }
    if let Some(field) = range.path.strip_prefix("atmosphere_run.") {
        // `shoal atmosphere`'s own inputs: the atmosphere's day and the geometry in degrees.
        let mut atmosphere = shoal::atmosphere::AtmosphereSpec::default();
        let (mut sun, mut view, mut azimuth) = (30.0, 0.0, 90.0);
        match field {
            "atmosphere.day_of_year" => atmosphere.day_of_year = value as u32,
            "sun_zenith_deg" => sun = value,
            "view_zenith_deg" => view = value,
            _ => azimuth = value,
        }
        let geometry = shoal::atmosphere::Geometry::from_degrees(sun, view, azimuth);
        return atmosphere.validate().err().or_else(|| geometry.validate().err()).map(|e| e.to_string());
    }
    if range.path == "spectrum.reference_nm" {
        // Wherever a formula spectrum is given (SIOP, QE, land): checked when it is sampled.
        let grid = shoal::spectral::WavelengthGrid::from_wavelengths(vec![400.0, 500.0]).unwrap();
        let s =
            shoal::spectral::SpectrumSource::Exponential { coefficient: 1.0, reference_nm: value, slope_per_nm: 0.01 };
        return s.sample(&grid, shoal::spectral::Extrapolation::Error, None).err().map(|e| e.to_string());
    }
    if range.path == "scene.land.reflectance" {
        // A spectrum's values: checked on the simulation grid, when the scene's optics are built.
        let mut c = base("scene.chl_mg_m3");
        c.scene.land = Some(shoal::scene::LandSpec {
            mask: MapSpec::Constant(0.0),
            reflectance: shoal::spectral::SpectrumSource::Constant(value),
        });
        c.fidelity.decimation = 1000;
        c.retrievals.clear();
        return match shoal::engine::Engine::new().run(&c, &shoal::control::RunControl::new()) {
            Ok(_) => None,
            Err(EngineError::Failed { message, .. }) => Some(message),
            Err(other) => panic!("{}: not a refusal: {other}", range.path),
        };
    }
    let map_field = ["scene.chl_mg_m3", "scene.nap_g_m3", "scene.cdom_per_m", "scene.depth_m", "scene.aot550_map"]
        .contains(&range.path)
        || range.path.starts_with("scene.substrates");
    if map_field {
        // Map values are checked when the scene stage builds the maps.
        let mut spec = SceneSpec::preset("heron_island_reef").unwrap();
        (spec.width, spec.height) = (4, 4);
        map(&mut spec, value);
        return Scene::build(&spec, None).err().map(|e| e.to_string());
    }
    if range.path.starts_with("correction.image") {
        // The image-based correction's lists: the pair's and the dark-spectrum band range's
        // ends with the other end where it leaves them ordered, an AOT node as the table's
        // only node; counts as whole numbers.
        let mut image = shoal::correction::ImageCorrection::default();
        let dark = &mut image.dark;
        match range.path {
            "correction.image.pair_nm" => {
                image.pair_nm = if value < 1500.0 { [value, 2500.0] } else { [600.0, value] };
            }
            "correction.image.dark.tile_px" => dark.tile_px = value as usize,
            "correction.image.dark.pixels" => dark.pixels = value as usize,
            "correction.image.dark.min_gas_transmittance" => dark.min_gas_transmittance = value,
            "correction.image.glint_threshold_per_sr" => image.glint_threshold_per_sr = value,
            "correction.image.glint_wind_error_m_s" => image.glint_wind_error_m_s = value,
            "correction.image.clouds.threshold" => image.clouds.threshold = value,
            "correction.image.clouds.height_m" => image.clouds.height_m = value,
            "correction.image.dark.wave_range_nm" => {
                dark.wave_range_nm = if value < 1500.0 { [value, 2500.0] } else { [350.0, value] };
            }
            _ => image.aot_nodes = vec![value],
        }
        let mut config = base("scene.chl_mg_m3");
        config.correction.method = shoal::correction::Method::Image(image);
        return match config.validate() {
            Ok(()) => None,
            Err(EngineError::Failed { message, .. }) => Some(message),
            Err(other) => panic!("{}: not a refusal: {other}", range.path),
        };
    }
    let mut config = shoal::sweep::apply(&base(range.path), &[(&sweep_path(range.path), value)]).unwrap();
    if range.path == "instrument.bias_dn" {
        // The offset's range is that of the widest ADC; a narrower one refuses less (tested in
        // the instrument's own tests).
        config.instrument.adc_bits = 16;
    }
    if range.path == "instrument.adc_bits" && value < 8.0 {
        // A few-bit ADC needs an offset below its largest count (the cross-field rule).
        config.instrument.bias_dn = 0.0;
    }
    if range.path == "instrument.focal_planes[].adc_bits" && value < 8.0 {
        config.instrument.focal_planes[0].bias_dn = 0.0;
    }
    match config.validate() {
        Ok(()) => None,
        Err(EngineError::Failed { message, .. }) => Some(message),
        Err(other) => panic!("{}: not a refusal: {other}", range.path),
    }
}

#[test]
fn every_range_refuses_just_outside_and_names_field_value_and_range() {
    let mut refused = 0;
    for range in ranges::ALL {
        for v in range.just_outside() {
            let message = refusal(range, v).unwrap_or_else(|| panic!("{} = {v} was accepted", range.path));
            for part in [range.name().to_string(), v.to_string(), range.allowed()] {
                assert!(message.contains(&part), "{} = {v}: `{message}` does not say `{part}`", range.path);
            }
            refused += 1;
        }
    }
    // Every entry has a value on each side, except whole-number ranges from 0 (nothing below).
    let one_sided = ranges::ALL.iter().filter(|r| r.just_outside().len() == 1).count();
    let zero_based: Vec<&str> = ranges::ALL.iter().filter(|r| r.just_outside().len() == 1).map(|r| r.path).collect();
    assert_eq!(
        zero_based,
        ["instrument.effects[].Compression.max_error_dn", "fidelity.band_nodes", "correction.image.dark.tile_px"],
        "only these have nothing below their range"
    );
    assert_eq!(refused, 2 * ranges::ALL.len() - one_sided, "every entry refused on both sides");
}

#[test]
fn the_allowed_ends_pass() {
    for range in ranges::ALL {
        let inside = |end: f64, open: bool, toward: f64| {
            if !open {
                end
            } else if range.whole {
                end + toward
            } else {
                end + toward * (end.abs() * 1e-6).max(1e-9)
            }
        };
        let mut ends = vec![inside(range.lo, range.lo_open, 1.0), inside(range.hi, range.hi_open, -1.0)];
        if range.path == "instrument.kind.Spectrograph.start_nm" {
            ends.pop(); // start_nm = 2500 would put it above end_nm; the end is checked there.
        }
        if range.path == "instrument.kind.Spectrograph.end_nm" {
            // end_nm = 350 would be below start_nm, and end_nm = 2500 puts the last band's
            // response past 2500 nm (end_nm + 2.5·resolution ≤ 2500): each refused with its own
            // message, tested below.
            ends.clear();
        }
        if range.path == "instrument.kind.Spectrograph.resolution_nm" {
            ends.pop(); // 100 nm puts the first band's response below 325 nm (its own message).
        }
        if range.path == "instrument.focal_planes[].pixel_pitch_um" {
            // A further plane's pitch must also tile the first plane's grid (a whole multiple up
            // to 16× or fraction down to 1/8 of 15.5 µm): neither end does (its own message,
            // tested in the instrument's tests).
            ends.clear();
        }
        if range.path == "instrument.focal_planes[].detectors" {
            ends.remove(0); // One detector cannot cover the first plane's swath (its own message).
        }
        if range.path == "instrument.effects[].NonLinearity.cubic" {
            // a₃ = −0.2 makes any curve with a₂ ≤ 0 fall within the well (its own message,
            // tested in the effect's tests).
            ends.remove(0);
        }
        if range.path == "instrument.kind.Spectrograph.sampling_nm" {
            ends.remove(0); // A tiny step would give more than 2000 samples (its own message).
        }
        for v in ends {
            assert_eq!(refusal(range, v), None, "{} = {v} is inside its range", range.path);
        }
    }
}

#[test]
fn the_cli_refuses_an_out_of_range_flag_with_exit_code_2() {
    let dir = std::env::temp_dir().join(format!("shoal-range-{}", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["simulate", "--gain-drift-pct", "80", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("calibration.gain_drift_pct: 80 is out of range (allowed: -50 to 50 %)"), "{stderr}");
    assert!(!dir.exists(), "nothing written");
    let table = Command::new(env!("CARGO_BIN_EXE_shoal")).arg("ranges").output().unwrap();
    assert!(table.status.success());
    assert_eq!(String::from_utf8_lossy(&table.stdout), ranges::markdown_table());
}

#[test]
fn a_spectrograph_reaching_past_the_data_is_refused_by_name() {
    let base = base("instrument.kind.Spectrograph.end_nm");
    let with_end = |end: f64| {
        let mut c = base.clone();
        // 417 bands to 2500 nm: a preview, so that the memory budget does not refuse it first.
        c.fidelity.decimation = 8;
        if let shoal::instrument::InstrumentKind::Spectrograph { end_nm, .. } = &mut c.instrument.kind {
            *end_nm = end;
        }
        c
    };
    let shoal::instrument::InstrumentKind::Spectrograph { resolution_nm, smile_nm, .. } = base.instrument.kind else {
        panic!("not a spectrograph")
    };
    // The last band's response reaches end + 2.5·FWHM + |smile|: allowed up to exactly 2500 nm.
    let last = 2500.0 - 2.5 * resolution_nm - smile_nm.abs();
    assert!(with_end(last).validate().is_ok(), "{:?}", with_end(last).validate());
    let e = with_end(last + 0.5).validate().unwrap_err().to_string();
    assert!(e.contains("kind.Spectrograph.end_nm") && e.contains("≤ 2500 nm"), "{e}");
}

/// An instrument field's path as the ranges table writes it: list indices as `[]`
/// (`instrument.effects.0.Tdi.stages` → `instrument.effects[].Tdi.stages`).
fn table_path(leaf: &str) -> String {
    let mut out = String::new();
    for part in leaf.split('.') {
        if part.parse::<usize>().is_ok() {
            out.push_str("[]");
        } else {
            if !out.is_empty() {
                out.push('.');
            }
            out.push_str(part);
        }
    }
    out
}

/// Numbers of an instrument that are data, not settings a range could bound, with why.
const NOT_SETTINGS: &[(&str, &str)] = &[
    ("instrument.kind.Multispectral.bands", "a band set's own centres and widths: checked by the band set"),
    ("instrument.kind.FilterImager.bands", "as a multispectral band set (`spectral::bands`: fwhm 0.1 to 300 nm)"),
    ("instrument.quantum_efficiency", "a QE curve: each value checked as a fraction by the response"),
    ("instrument.focal_planes[].quantum_efficiency", "as the instrument's QE curve"),
    (
        "instrument.focal_planes[].dark_temperature",
        "checked with the instrument's `dark_temperature` ranges, the message naming the plane's field",
    ),
    ("instrument.effects[].Misregistration.draw", "a seed: any whole number"),
    ("instrument.effects[].SpectralKnowledge.draw", "a seed: any whole number"),
];

/// Every number of every instrument preset (with each optical and focal-plane effect, every
/// dark-current law and focal planes of its own where the preset has them) is a field of the
/// ranges table, so a new instrument parameter cannot slip in without a documented range, a
/// validator and the MANUAL's row (`manual_shows_the_table`).
#[test]
fn every_number_of_an_instrument_has_a_range() {
    let ranged: Vec<&str> = ranges::ALL.iter().map(|r| r.path).collect();
    let mut missing = std::collections::BTreeSet::new();
    for name in InstrumentSpec::preset_names() {
        let mut instrument = InstrumentSpec::preset(&name).unwrap();
        crate::common::with_dark_laws(&mut instrument);
        crate::common::with_optical_effects(&mut instrument);
        let config = RunConfig::new(SceneSpec::preset("lake_hume_bloom").unwrap(), instrument);
        for leaf in shoal::fields::flatten(&config) {
            let path = table_path(&leaf.path);
            // A number, or a short list of numbers (written as one leaf).
            let list = serde_json::from_str::<Vec<f64>>(&leaf.text).is_ok_and(|v| !v.is_empty());
            let numeric = leaf.text.parse::<f64>().is_ok() || list;
            if !path.starts_with("instrument.") || !numeric || path.ends_with("schema_version") {
                continue;
            }
            let exempt = NOT_SETTINGS.iter().any(|(p, _)| path.starts_with(p));
            if !exempt && !ranged.contains(&path.as_str()) {
                missing.insert(format!("{path} ({name})"));
            }
        }
    }
    assert!(missing.is_empty(), "instrument numbers without a range in shoal::ranges: {missing:#?}");
}
