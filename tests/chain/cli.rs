//! `shoal simulate` end to end: files, formats, exit codes, and the resolved configuration.

use std::path::Path;
use std::process::Command;

fn shoal() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shoal"))
}

/// Shape of a version-1 .npy file (from its header).
fn npy_shape(path: &Path) -> Vec<usize> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + len]).unwrap();
    let shape = header.split("'shape': (").nth(1).unwrap().split(')').next().unwrap();
    shape.split(',').filter(|s| !s.trim().is_empty()).map(|s| s.trim().parse().unwrap()).collect()
}

#[test]
fn simulate_writes_cubes_tables_report_and_config() {
    let dir = std::env::temp_dir().join(format!("shoal-sim-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let status = shoal()
        .args(["simulate", "--scene", "heron_island_reef", "--instrument", "nominal", "--decimation", "8", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let shape = npy_shape(&dir.join("level0_dn.npy"));
    assert_eq!(shape.len(), 3);
    assert_eq!(shape[2], 19);
    for f in ["level1_radiance.npy", "rrs.npy", "rrs_flags.npy", "truth_rrs.npy", "pupil_radiance.npy"] {
        assert_eq!(npy_shape(&dir.join(f)), shape, "{f}");
    }
    assert_eq!(npy_shape(&dir.join("truth_depth_m.npy")), shape[..2].to_vec());
    assert_eq!(npy_shape(&dir.join("truth_substrate_fractions.npy")), vec![shape[0], shape[1], 4]);
    let snr = std::fs::read_to_string(dir.join("snr.csv")).unwrap();
    assert!(snr.starts_with("band,centre_nm,radiance_w_m2_sr_nm,snr_analytic,snr_measured,signal_over_full_scale\n"));
    assert_eq!(snr.lines().count(), 20);
    let report = std::fs::read_to_string(dir.join("report.json")).unwrap();
    assert!(report.contains("\"stages\"") && report.contains("SunGlint"));
    // The resolved configuration reruns to the same counts.
    let again = dir.join("again");
    let status =
        shoal().args(["simulate", "--config"]).arg(dir.join("config.ron")).arg("--out").arg(&again).output().unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    assert_eq!(std::fs::read(dir.join("level0_dn.npy")).unwrap(), std::fs::read(again.join("level0_dn.npy")).unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn simulate_refuses_bad_input_with_exit_code_2() {
    let dir = std::env::temp_dir().join(format!("shoal-bad-{}", std::process::id()));
    let bad = dir.join("bad.ron");
    std::fs::create_dir_all(&dir).unwrap();
    let mut text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/presets/instruments/nominal.ron")).unwrap();
    text = text.replace("aperture_mm: 120.0", "aperture_mm: 0.0");
    std::fs::write(&bad, text).unwrap();
    let out = shoal().args(["simulate", "--instrument"]).arg(&bad).arg("--out").arg(dir.join("o")).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("aperture_mm") && err.lines().count() <= 2, "{err}");
    assert!(!dir.join("o").exists(), "no output for a refused run");
    let out = shoal().args(["simulate", "--scene", "atlantis", "--out"]).arg(dir.join("o")).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("lake_hume_bloom"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sweep_shards_and_merge_on_the_command_line() {
    let dir = std::env::temp_dir().join(format!("shoal-sweep-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("tiny.ron");
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/presets/sweeps/aperture_lake_hume.ron"))
        .unwrap()
        .replace("Range(from: 40, to: 300, steps: 8, log: true)", "List([50, 250])")
        .replace("seeds: [1, 2, 3, 4, 5]", "seeds: [1, 2]");
    std::fs::write(&file, text).unwrap();
    let run = |extra: &[&str], out: &str| {
        let o = shoal()
            .args(["sweep", file.to_str().unwrap(), "--decimation", "32", "--no-figures", "--out"])
            .arg(dir.join(out))
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    run(&[], "whole");
    run(&["--shard", "0/2"], "s0");
    run(&["--shard", "1/2"], "s1");
    let o = shoal()
        .args(["merge", "--no-figures", "--out"])
        .arg(dir.join("merged"))
        .arg(dir.join("s1"))
        .arg(dir.join("s0"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let whole = std::fs::read(dir.join("whole/table.csv")).unwrap();
    assert_eq!(std::fs::read(dir.join("merged/table.csv")).unwrap(), whole);
    assert!(String::from_utf8_lossy(&whole).lines().count() > 4);
    // A bad shard is one line naming it, exit code 2.
    let o = shoal().args(["sweep", file.to_str().unwrap(), "--shard", "2/2"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("shard `2/2`"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_raster_study_runs_and_writes_geotiff_products() {
    // The built-in raster-driven scene through `shoal study`, products as GeoTIFF.
    let dir = std::env::temp_dir().join(format!("shoal-study-geotiff-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = shoal()
        .args(["study", "reef_survey_depth", "--format", "geotiff", "--decimation", "4", "--no-figures", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for f in ["level1_radiance.tif", "rrs.tif", "truth.tif", "sambuca.tif", "config.ron", "snr.csv"] {
        assert!(dir.join("nominal").join(f).is_file(), "{f}");
    }
    assert!(!dir.join("nominal/rrs.npy").exists(), "geotiff replaces the .npy cubes");
    let truth = shoal::geotiff::read(&dir.join("nominal/truth.tif")).unwrap();
    assert_eq!(truth.crs, shoal::geotiff::Crs::Projected { epsg: 32756 });
    let metrics = std::fs::read_to_string(dir.join("metrics.csv")).unwrap();
    assert!(metrics.contains("nominal,1,SAMBUCA,depth_m,"), "{metrics}");
    let bad = shoal().args(["study", "reef_survey_depth", "--format", "tiff", "--out"]).arg(&dir).output().unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("geotiff"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A run that returns no water (the glint example at a 15° roll: every pixel above l2gen's
/// glint threshold, left out) prints no error for its products and no aerosol numbers: the
/// metrics' MAE of 0 % and the AOT of an empty set (NaN) would read as a perfect answer and as
/// garbage.
#[test]
fn a_run_that_returns_nothing_prints_no_error_and_no_nan() {
    let dir = crate::common::TempDir::new("cli", "nothing-returned");
    let study = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/examples/study_glint_roll_15_on.ron");
    let out = shoal()
        .arg("study")
        .arg(&study)
        .args(["--decimation", "8", "--no-cubes", "--no-figures", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("chl_mg_m3") && text.contains("none returned"), "{text}");
    assert!(text.contains("aerosol  no pixel retrieved"), "{text}");
    assert!(!text.contains("NaN"), "{text}");
}
