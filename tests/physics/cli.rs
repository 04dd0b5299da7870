//! The `shoal` binary: outputs, exit codes and messages, as a user sees them.

use std::process::Command;

fn shoal(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run shoal");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn rows(csv: &str) -> Vec<Vec<String>> {
    csv.lines().map(|l| l.split(',').map(str::to_string).collect()).collect()
}

#[test]
fn water_prints_every_intermediate_per_band() {
    let (code, out, err) = shoal(&[
        "water",
        "--chl",
        "10",
        "--cdom",
        "1",
        "--nap",
        "10",
        "--depth",
        "3",
        "--substrate",
        "sand:0.5,coral:0.5",
        "--sun-zenith",
        "60",
        "--view-zenith",
        "30",
        "--bands",
        "olci",
    ]);
    assert_eq!(code, 0, "{err}");
    let r = rows(&out);
    assert_eq!(r.len(), 20, "header + 19 OLCI bands");
    for name in [
        "a_per_m",
        "bb_per_m",
        "kd_per_m",
        "kuc_per_m",
        "kub_per_m",
        "rrs_deep_per_sr",
        "r_substratum",
        "rrs_above_per_sr",
    ] {
        assert!(r[0].iter().any(|c| c == name), "missing {name}");
    }
    for row in &r[1..] {
        for cell in &row[1..] {
            let v: f64 = cell.parse().unwrap();
            assert!(v.is_finite());
        }
    }
}

#[test]
fn atmosphere_prints_the_terms_per_wavelength() {
    let (code, out, err) = shoal(&[
        "atmosphere",
        "--aerosol",
        "continental",
        "--aot550",
        "0.1",
        "--sun-zenith",
        "60",
        "--view-zenith",
        "30",
        "--rel-azimuth",
        "90",
        "--wavelengths",
        "412.5,560,865",
        "--accuracy",
        "fast",
    ]);
    assert_eq!(code, 0, "{err}");
    let r = rows(&out);
    assert_eq!(r.len(), 4);
    for name in ["e0_w_m2_nm", "l_path_w_m2_sr_nm", "t_up", "t_down", "spherical_albedo", "ed_0plus_w_m2_nm"] {
        assert!(r[0].iter().any(|c| c == name), "missing {name}");
    }
}

#[test]
fn band_rows_are_as_wide_as_the_header() {
    for args in [
        &["atmosphere", "--aerosol", "maritime", "--bands", "olci", "--accuracy", "fast"][..],
        &["water", "--depth", "4", "--bands", "msi"][..],
        &["atmosphere", "--spec", "presets/examples/atmosphere_lake_hume.ron", "--accuracy", "fast"][..],
    ] {
        let (code, out, err) = shoal(args);
        assert_eq!(code, 0, "{args:?}: {err}");
        let r = rows(&out);
        assert!(r.len() > 5);
        for row in &r {
            assert_eq!(row.len(), r[0].len(), "{args:?}: {row:?}");
        }
    }
    // And the values sit under the right names: a transmittance, an albedo, an irradiance.
    let (_, out, _) = shoal(&["atmosphere", "--aerosol", "maritime", "--bands", "olci", "--accuracy", "fast"]);
    let r = rows(&out);
    let col = |name: &str| r[0].iter().position(|c| c == name).unwrap();
    for row in &r[1..] {
        let v = |name: &str| row[col(name)].parse::<f64>().unwrap();
        assert!(v("t_down_direct") < v("t_down") && v("t_down") < 1.0);
        assert!(v("spherical_albedo") < 0.4 && v("ed_0plus_w_m2_nm") > 0.3);
    }
}

#[test]
fn example_specs_run() {
    for (cmd, file) in [
        ("water", "presets/examples/water_heron_sand.ron"),
        ("water", "presets/examples/water_lake_hume.ron"),
        ("water", "presets/examples/water_custom_inputs.ron"),
        ("atmosphere", "presets/examples/atmosphere_lake_hume.ron"),
    ] {
        let (code, out, err) = shoal(&[cmd, "--spec", file]);
        assert_eq!(code, 0, "{file}: {err}");
        assert!(out.lines().count() > 10, "{file}");
    }
}

#[test]
fn bad_input_exits_2_with_one_line_naming_the_field() {
    let cases: &[(&[&str], &str)] = &[
        (&["water", "--chl", "-1"], "chl"),
        (&["water", "--nap", "-0.5"], "nap"),
        (&["water", "--depth", "0"], "depth"),
        (&["water", "--depth", "-3"], "depth"),
        (&["water", "--sun-zenith", "90"], "sun_zenith"),
        (&["water", "--depth", "2", "--substrate", "lava"], "lava"),
        (&["water", "--substrate", "sand:0.7,coral:0.7", "--depth", "2"], "sum"),
        (&["water", "--siop", "nile"], "nile"),
        (&["atmosphere", "--aerosol", "volcanic"], "volcanic"),
        (&["atmosphere", "--sun-zenith", "95"], "sun_zenith"),
        (&["atmosphere", "--aot550", "-0.2"], "aot550"),
        (&["atmosphere", "--surface", "wind:fast"], "surface"),
        (&["atmosphere", "--bands", "landsat"], "landsat"),
        (&["water", "--step", "0.0000001"], "step"),
        (&["water", "--rel-azimuth", "400"], "rel-azimuth"),
    ];
    for (args, field) in cases {
        let (code, out, err) = shoal(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?} printed output");
        assert!(err.contains(field), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: one line, got {err}");
        assert!(!err.contains("panicked"));
    }
}

/// `SHOAL_SIMD` caps the vector level: the three levels are accepted, and a value it does not
/// know stops the binary at start with the variable and the values allowed named. (That the
/// levels agree to their roundings is tested on the kernels: `simd`, `water::kernel`.)
#[test]
fn the_simd_cap_is_checked_at_start() {
    let bin = env!("CARGO_BIN_EXE_shoal");
    let run = |cap: &str| Command::new(bin).args(["water", "--depth", "3"]).env("SHOAL_SIMD", cap).output().unwrap();
    let bad = run("sse9");
    assert_eq!(bad.status.code(), Some(2));
    assert!(bad.stdout.is_empty());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("SHOAL_SIMD") && err.contains("baseline, avx2 and avx512"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    for cap in ["baseline", "avx2", "avx512"] {
        let ok = run(cap);
        assert!(ok.status.success(), "{cap}: {}", String::from_utf8_lossy(&ok.stderr));
    }
}

#[test]
fn malformed_ron_names_the_line_and_the_field() {
    let dir = std::env::temp_dir().join(format!("shoal-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let typo = dir.join("typo.ron");
    std::fs::write(&typo, "AtmosphereRun(\n  atmosphere: AtmosphereSpec(aerosl: Maritime),\n)\n").unwrap();
    let (code, _, err) = shoal(&["atmosphere", "--spec", typo.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("aerosl") && err.contains("2:"), "{err}");
    let broken = dir.join("broken.ron");
    std::fs::write(&broken, "WaterRun(chl_mg_m3: 1.0,\n depth_m: Some(3.0)\n").unwrap();
    let (code, _, err) = shoal(&["water", "--spec", broken.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("broken.ron"), "{err}");
    let (code, _, err) = shoal(&["water", "--spec", dir.join("missing.ron").to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("missing.ron"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn out_file_is_written_whole() {
    let dir = std::env::temp_dir().join(format!("shoal-out-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rrs.csv");
    let (code, out, err) = shoal(&["water", "--wavelengths", "443,560", "--out", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.is_empty());
    assert_eq!(std::fs::read_to_string(&path).unwrap().lines().count(), 3);
    assert!(std::fs::read_dir(&dir).unwrap().count() == 1, "no temporary file left behind");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn correct_refuses_a_spectrum_without_its_bands_or_with_a_bad_geometry() {
    let dir = std::env::temp_dir().join(format!("shoal-correct-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let toa = dir.join("toa.csv");
    std::fs::write(&toa, "sun_zenith_deg,view_zenith_deg,relative_azimuth_deg,Oa01\n30,10,90,50\n").unwrap();
    let out = dir.join("res");
    let (code, _, err) =
        shoal(&["correct", "--toa", toa.to_str().unwrap(), "--instrument", "cubesat", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--toa") && err.contains("Oa02"), "{err}");
    std::fs::write(&toa, "sun_zenith_deg,view_zenith_deg,relative_azimuth_deg\n95,10,90\n").unwrap();
    let (code, _, err) =
        shoal(&["correct", "--toa", toa.to_str().unwrap(), "--instrument", "cubesat", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(!out.exists(), "nothing written on a refusal");
    std::fs::remove_dir_all(&dir).ok();
}

/// The AOT(550) a study's image-based correction found, read from its printed aerosol line.
fn aot_found(stdout: &str) -> f64 {
    let line = stdout.lines().find(|l| l.contains("AOT(550)")).expect("an aerosol line");
    line.split("AOT(550) ").nth(1).and_then(|s| s.split_whitespace().next()).and_then(|s| s.parse().ok()).expect("AOT")
}

#[test]
fn the_swir_pair_over_6svs_aerosol_needs_6svs_models() {
    // presets/examples: Lake Hume with 6SV's continental aerosol (AOT 0.100), corrected from
    // the SmallSat-SWIR's 1610/2200 nm pair by a family of WCP-55's models or of 6SV's
    // (docs/RESULTS.md). Measured at 1/8: 0.079 and 0.096 (the same as at 1/2). The bounds hold
    // the finding: WCP-55's family finds 15 % or more too little, 6SV's is within 6 %.
    let out = std::env::temp_dir().join(format!("shoal-swir-6sv-{}", std::process::id()));
    let run = |study: &str| {
        let dir = out.join(study);
        let file = format!("presets/examples/study_swir_pair_{study}.ron");
        let (code, stdout, err) =
            shoal(&["study", &file, "--decimation", "8", "--no-cubes", "--no-figures", "--out", dir.to_str().unwrap()]);
        assert_eq!(code, 0, "{study}: {err}");
        aot_found(&stdout)
    };
    let wcp55 = run("6sv_scene");
    let sixs = run("6sv_scene_6sv_family");
    let _ = std::fs::remove_dir_all(&out);
    assert!(wcp55 < 0.085, "WCP-55's family over 6SV's aerosol found {wcp55}");
    assert!((sixs - 0.1).abs() < 0.006, "6SV's family over 6SV's aerosol found {sixs}");
}
