//! The fuzz targets: one function per reader of a file someone else made, each taking any bytes.
//! An error is fine; a panic, an abort or a hang is a bug. Shared by the coverage-guided targets
//! of cargo-fuzz (`fuzz_targets/*.rs`, nightly) and by the bounded mutation run every `cargo
//! test` makes on stable (`tests/hard/fuzz.rs`), each over its committed corpus
//! (`corpus/NAME/`).
// Each cargo-fuzz binary uses one target of this file.
#![allow(dead_code)]

use shoal::spectral::{Extrapolation, Spectrum, Table, WavelengthGrid};

/// Presets of every kind (instrument, scene, run configuration, study, sweep): parsed,
/// validated, resolved against the embedded presets only.
pub fn preset_loaders(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(i) = shoal::instrument::InstrumentSpec::from_ron(text, "fuzz")
        && i.validate().is_ok()
    {
        let _ = (i.gsd_m(), i.etendue_m2_sr(), i.dn_max());
    }
    if let Ok(s) = shoal::scene::SceneSpec::from_ron(text, "fuzz") {
        let _ = s.validate();
    }
    if let Ok(c) = shoal::engine::RunConfig::from_ron(text, "fuzz") {
        let _ = c.validate();
    }
    if let Ok(s) = shoal::study::StudySpec::from_ron(text, "fuzz") {
        let _ = s.resolve(None);
    }
    if let Ok(s) = shoal::sweep::SweepSpec::from_ron(text, "fuzz") {
        let _ = s.resolve(None);
    }
}

/// A spectrum table (header row, wavelength column, value columns), each column resampled.
pub fn spectrum_csv(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(table) = Table::parse(text, "fuzz.csv") else { return };
    let Ok(grid) = WavelengthGrid::uniform(400.0, 700.0, 10.0) else { return };
    for column in table.columns.iter().skip(1) {
        if let Ok(s) = Spectrum::from_table(&table, column) {
            let _ = s.resample(&grid, Extrapolation::Error);
            let _ = s.resample(&grid, Extrapolation::Clamp);
        }
    }
}

/// `shoal correct --toa` spectra: the table, its geometry columns and an OLCI band's column.
pub fn toa_csv(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(table) = Table::parse(text, "toa.csv") else { return };
    for name in ["sun_zenith_deg", "view_zenith_deg", "relative_azimuth_deg", "Oa01", "Oa21"] {
        let _ = table.column_f64(name);
    }
}

/// A NetCDF file read for (line, pixel) maps, as `shoal score` and an external retrieval's
/// output are read.
pub fn netcdf(data: &[u8]) {
    let _ = shoal::netcdf::parse_maps(data, &["chl_mg_m3", "true_chl_mg_m3", "nap_g_m3", "depth_m"]);
}

/// A design search's shard record (`evaluations.ron`), checked whole against the search it
/// would join: an aperture search of the default study at decimation 8, seed 1.
pub fn shard_record(data: &[u8]) {
    use shoal::design::Dimension;
    use shoal::design::record::{Record, vars_of};
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(record) = Record::parse(text, "fuzz", "--resume fuzz") else { return };
    let Ok(aperture) = Dimension::parse("aperture_mm=40:200") else { return };
    let vars = vec![aperture];
    let expected = Record {
        study: "cubesat_vs_smallsat".into(),
        instrument: "cubesat".into(),
        vars: vars_of(&vars),
        decimation: 8,
        seeds: vec![1],
        seed: 1,
        evaluations: Vec::new(),
    };
    let keys = vec!["chl_mg_m3 MAE %".to_string(), "SNR, worst band".to_string()];
    let _ = record.check_matches(&expected, "fuzz");
    let _ = record.check_evaluations(&vars, &(keys.clone(), keys), "AUD", "fuzz");
}

/// A GeoTIFF survey raster, read within a 1 M-sample limit.
pub fn geotiff(data: &[u8]) {
    let _ = shoal::geotiff::read_bytes_limited(data, "fuzz.tif", 1 << 20);
}

/// A target: its corpus folder's name and its function.
pub type Target = (&'static str, fn(&[u8]));

/// Every target.
pub const TARGETS: [Target; 6] = [
    ("preset_loaders", preset_loaders),
    ("spectrum_csv", spectrum_csv),
    ("toa_csv", toa_csv),
    ("netcdf", netcdf),
    ("shard_record", shard_record),
    ("geotiff", geotiff),
];
