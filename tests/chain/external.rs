//! External retrievals: a user's program run on a NetCDF file of the Rrs, its products read back
//! and scored like aLMI's — and every way it can go wrong (cannot start, exits with an error,
//! runs too long, writes the wrong thing, was not allowed) costs its own product only, with a
//! message that says why.

use crate::common::Kept;
use shoal::correction::RrsFlags;
use shoal::engine::{RunConfig, RunOutput};
use shoal::instrument::DetectorMode;
use shoal::retrieval::RetrievalSpec;
use shoal::retrieval::external::{ExternalSpec, allow};

use super::netcdf::{product_file, tempfile_dir::Dir};
use super::{run, small, small_lake};

/// An external retrieval of `products` running `command` (allowed for this process: commands
/// are allowed one by one, so a test that needs a refusal uses a command no other test allows).
pub(super) fn external(name: &str, command: &[&str], products: &[&str]) -> RetrievalSpec {
    let command: Vec<String> = command.iter().map(|s| (*s).to_string()).collect();
    allow(&command);
    RetrievalSpec::External(ExternalSpec {
        name: name.into(),
        command,
        products: products.iter().map(|s| (*s).to_string()).collect(),
        bands: None,
        function: None,
        time_limit_s: 60.0,
    })
}

/// A small noise-free lake with aLMI and `retrieval` after it.
pub(super) fn run_with(retrieval: RetrievalSpec) -> RunOutput {
    let mut c = RunConfig::new(small_lake(), small("cubesat", 24, 16));
    c.detector = DetectorMode::IDEAL;
    c.retrievals = vec![
        RetrievalSpec::Almi { siop_sets: shoal::retrieval::sets::default_almi_sets(), settings: Default::default() },
        retrieval,
    ];
    run(&c)
}

/// The truth's chl × `factor` on water, the fill value on land, as a (line, pixel) vector.
fn scaled_truth(out: &RunOutput, factor: f32) -> Vec<f32> {
    let t = &out.truth;
    t.chl_mg_m3
        .indexed_iter()
        .map(|((r, c), v)| if t.surface.codes()[[r, c]] != 0 { -9999.0 } else { v * factor })
        .collect()
}

/// The run's aLMI is untouched by the external retrieval beside it.
pub(super) fn assert_almi_kept(out: &RunOutput) {
    let almi = &out.retrievals[0];
    assert_eq!(almi.product.name, "aLMI");
    assert!(almi.failure.is_none());
    assert!(almi.metrics.get("chl_mg_m3").unwrap().n > 100, "aLMI returned pixels");
}

#[test]
fn a_program_s_products_are_read_back_and_scored_like_any_retrieval() {
    let reference = run_with(external("copy_missing", &["true"], &["chl_mg_m3"]));
    let dir = Dir::new("external-copy");
    let file = dir.path().join("made.nc");
    product_file(&file, reference.truth.chl_mg_m3.dim(), &[("chl_mg_m3", scaled_truth(&reference, 1.1))]);
    let out = run_with(external("copier", &["cp", file.to_str().unwrap(), "{output}"], &["chl_mg_m3"]));
    assert_almi_kept(&out);
    let ext = &out.retrievals[1];
    assert!(ext.failure.is_none(), "{:?}", ext.failure);
    assert_eq!(ext.product.name, "copier");
    assert!(ext.product.nap_g_m3.is_none() && ext.product.depth_m.is_none());
    let m = ext.metrics.get("chl_mg_m3").unwrap();
    // Every water pixel returned, 10 % high: log-space MAE and bias are both 10 % (f32 values).
    assert_eq!(m.returned_pct, 100.0);
    assert!(
        (m.mae_pct() - 10.0).abs() < 1e-4 && (m.bias_pct() - 10.0).abs() < 1e-4,
        "{} {}",
        m.mae_pct(),
        m.bias_pct()
    );
    assert!(ext.metrics.get("nap_g_m3").is_none(), "a product the program does not make has no metrics");
    // The same run with a program that wrote nothing: the "true" program exits 0 silently.
    let nothing = &reference.retrievals[1];
    let why = nothing.failure.as_deref().unwrap();
    assert!(why.contains("without writing its output"), "{why}");
    assert_eq!(nothing.metrics.failed, reference.truth.surface.codes().iter().filter(|l| **l == 0).count());
    // Its promised product keeps its row, returned nowhere, so its requirement fails.
    let chl = nothing.metrics.get("chl_mg_m3").expect("the promised chl-a is scored");
    assert_eq!((chl.n, chl.returned_pct), (0, 0.0));
    let limits = shoal::study::Requirements {
        products: vec![shoal::study::ProductRequirement {
            variable: "chl_mg_m3".into(),
            mae_pct: Some(1000.0),
            bias_pct: None,
            returned_pct: None,
        }],
        ..Default::default()
    };
    let checks = limits.check_run("A", 1, Some(&nothing.metrics), &[], &[]);
    assert_eq!(shoal::study::verdict(&checks), Some(false), "{checks:?}");
}

#[test]
fn the_program_sees_the_rrs_bands_and_geometry_but_never_the_truth() {
    let dir = Dir::new("external-input");
    let saved = dir.path().join("input_seen.nc");
    let out = run_with(external("peek", &["cp", "{input}", saved.to_str().unwrap()], &["chl_mg_m3"]));
    assert_almi_kept(&out);
    let mut reader = netcdf3::FileReader::open(&saved).unwrap();
    let rrs = reader.read_var_f32("rrs").unwrap();
    let wavelength = reader.read_var_f32("wavelength").unwrap();
    let sza = reader.read_var_f32("solar_zenith_angle").unwrap();
    let (ds, _) = reader.close();
    let names = ds.get_var_names();
    for v in ["rrs", "surface_class", "wavelength", "bandwidth", "nedr", "solar_zenith_angle", "sensor_zenith_angle"] {
        assert!(names.iter().any(|n| n == v), "{v} in {names:?}");
    }
    assert!(!names.iter().any(|n| n.starts_with("true")), "no truth: {names:?}");
    let (rows, cols, nb) = out.kept().rrs.rrs.dim();
    assert_eq!((ds.dim_size("line"), ds.dim_size("pixel"), ds.dim_size("band")), (Some(rows), Some(cols), Some(nb)));
    // The run's Rrs where valid and on water, the fill value elsewhere.
    let (flags, land) = (&out.kept().rrs.flags, &out.truth.surface.codes());
    let mut valid = 0;
    for ((r, c, b), v) in out.kept().rrs.rrs.indexed_iter() {
        let keep = flags[[r, c, b]] & (RrsFlags::INVALID | RrsFlags::SATURATED) == 0 && land[[r, c]] == 0;
        let got = rrs[(r * cols + c) * nb + b];
        if keep && v.is_finite() {
            assert_eq!(got, *v);
            valid += 1;
        } else {
            assert_eq!(got, -9999.0, "({r}, {c}, {b})");
        }
    }
    assert!(valid > 1000, "{valid}");
    let bands = &out.response.bands.bands;
    for (w, b) in wavelength.iter().zip(bands) {
        assert!((f64::from(*w) - b.centre_nm).abs() < 5.0, "centroid {w} of band {} at {}", b.name, b.centre_nm);
    }
    for (c, look) in out.viewing.looks[0].iter().enumerate() {
        assert!((f64::from(sza[c]) - look.geometry.sun_zenith_rad.to_degrees()).abs() < 1e-4, "column {c}");
    }
}

#[test]
fn a_failing_program_costs_only_its_own_product_and_says_why() {
    let out = run_with(external(
        "boom",
        &["sh", "-c", "echo 'Traceback: no module named xarray' >&2; exit 3"],
        &["chl_mg_m3"],
    ));
    assert_almi_kept(&out);
    assert!(out.kept().rrs.rrs.iter().any(|v| *v > 0.0), "the Rrs is kept");
    let why = out.retrievals[1].failure.as_deref().unwrap();
    assert!(why.contains("`boom`") && why.contains("exit") && why.contains("3"), "{why}");
    assert!(why.contains("no module named xarray"), "its standard error is quoted: {why}");

    let missing = run_with(external("nowhere", &["/no/such/program", "{input}"], &["chl_mg_m3"]));
    let why = missing.retrievals[1].failure.as_deref().unwrap();
    assert!(why.contains("cannot start `/no/such/program`"), "{why}");
}

#[test]
fn a_program_past_its_time_limit_is_stopped() {
    let mut spec = external("sleeper", &["sleep", "30"], &["chl_mg_m3"]);
    if let RetrievalSpec::External(e) = &mut spec {
        e.time_limit_s = 1.0;
    }
    let start = std::time::Instant::now();
    let out = run_with(spec);
    // Well under the program's 30 s: the limit stopped it (the run itself takes a second or so).
    assert!(start.elapsed().as_secs_f64() < 20.0, "{:?}", start.elapsed());
    let why = out.retrievals[1].failure.as_deref().unwrap();
    assert!(why.contains("time limit of 1 s"), "{why}");
    assert_almi_kept(&out);
}

#[test]
fn stopping_a_program_stops_what_it_started() {
    // A shell that starts a long sleep in the background and waits: past the limit, the sleep
    // (the shell's child, in the program's process group) must go too.
    let dir = Dir::new("external-group");
    let pid_file = dir.path().join("child.pid");
    let script = format!("sleep 60 & echo $! > '{}'; wait", pid_file.display());
    let mut spec = external("spawner", &["sh", "-c", &script], &["chl_mg_m3"]);
    if let RetrievalSpec::External(e) = &mut spec {
        e.time_limit_s = 1.0;
    }
    let out = run_with(spec);
    assert!(out.retrievals[1].failure.as_deref().unwrap().contains("time limit"));
    let pid = std::fs::read_to_string(&pid_file).unwrap().trim().to_string();
    assert!(gone(&pid), "the program's child {pid} still runs");
}

/// Is process `pid` gone (or a zombie waiting for init to reap it)? Waits up to 5 s for it.
pub(super) fn gone(pid: &str) -> bool {
    (0..50).any(|_| {
        let state = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
        let alive = state.split(") ").nth(1).is_some_and(|s| !s.starts_with('Z'));
        if alive {
            std::thread::sleep(std::time::Duration::from_millis(100));
        }
        !alive
    })
}

#[test]
fn an_output_without_the_product_or_of_another_size_is_refused_by_name() {
    let reference = run_with(external("ref_missing", &["true"], &["chl_mg_m3"]));
    let shape = reference.truth.chl_mg_m3.dim();
    let dir = Dir::new("external-wrong");
    let only_nap = dir.path().join("only_nap.nc");
    product_file(&only_nap, shape, &[("nap_g_m3", vec![1.0; shape.0 * shape.1])]);
    let out = run_with(external("napper", &["cp", only_nap.to_str().unwrap(), "{output}"], &["chl_mg_m3"]));
    let why = out.retrievals[1].failure.as_deref().unwrap();
    assert!(why.contains("has no `chl_mg_m3`") && why.contains("nap_g_m3"), "{why}");

    let small_file = dir.path().join("small.nc");
    product_file(&small_file, (3, 4), &[("chl_mg_m3", vec![1.0; 12])]);
    let out = run_with(external("shrinker", &["cp", small_file.to_str().unwrap(), "{output}"], &["chl_mg_m3"]));
    let why = out.retrievals[1].failure.as_deref().unwrap();
    assert!(why.contains("3 × 4") && why.contains(&format!("{} × {}", shape.0, shape.1)), "{why}");
}

#[test]
fn nothing_runs_until_the_program_is_allowed() {
    // A command no test allows.
    let spec = RetrievalSpec::External(ExternalSpec {
        name: "unasked".into(),
        command: vec!["sh".into(), "-c".into(), "echo never > /dev/null".into()],
        products: vec!["chl_mg_m3".into()],
        bands: None,
        function: None,
        time_limit_s: 10.0,
    });
    let out = run_with(spec);
    let why = out.retrievals[1].failure.as_deref().unwrap();
    assert!(why.contains("allow it first") && why.contains("echo never"), "{why}");
    assert_almi_kept(&out);
}

#[test]
fn a_bad_external_spec_names_its_field() {
    let base = ExternalSpec {
        name: "mine".into(),
        command: vec!["python3".into(), "{example:oc4.py}".into()],
        products: vec!["chl_mg_m3".into()],
        bands: None,
        function: None,
        time_limit_s: 60.0,
    };
    assert!(base.validate().is_ok());
    let cases: Vec<(ExternalSpec, &str)> = vec![
        (ExternalSpec { name: "../etc".into(), ..base.clone() }, "External.name"),
        (ExternalSpec { name: "alm".into(), ..base.clone() }, "External.name"),
        (ExternalSpec { command: vec![], ..base.clone() }, "External.command"),
        (
            ExternalSpec { command: vec!["python3".into(), "{example:nope.py}".into()], ..base.clone() },
            "External.command",
        ),
        (ExternalSpec { products: vec!["chlorophyll".into()], ..base.clone() }, "External.products"),
        (ExternalSpec { products: vec![], ..base.clone() }, "External.products"),
        (ExternalSpec { time_limit_s: 0.0, ..base.clone() }, "External.time_limit_s"),
        (ExternalSpec { time_limit_s: f64::NAN, ..base.clone() }, "External.time_limit_s"),
    ];
    for (spec, field) in cases {
        let e = spec.validate().unwrap_err().to_string();
        assert!(e.contains(field), "{spec:?}: {e}");
    }
    // Two retrievals of one name would write the same files: the run is refused, naming it.
    let mut c = RunConfig::new(small_lake(), small("cubesat", 24, 16));
    let twice = RetrievalSpec::External(base.clone());
    c.retrievals = vec![twice.clone(), twice];
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("retrievals[1].External.name") && e.contains("`mine`"), "{e}");
    // `{dir}` needs a study file; a study read from a file resolves it.
    let with_dir = ExternalSpec { command: vec!["{dir}/mine.py".into()], ..base };
    assert!(with_dir.with_dir(None).unwrap_err().to_string().contains("{dir}"));
    let resolved = with_dir.with_dir(Some(std::path::Path::new("/studies"))).unwrap();
    assert_eq!(resolved.command, vec!["/studies/mine.py".to_string()]);
}

/// OC4v6 (O'Reilly et al. 1998; NASA's coefficients) of one pixel from its blue and green Rrs, as
/// `presets/examples/oc4.py` computes it.
fn oc4(blue: &[f64], green: f64) -> f64 {
    const A: [f64; 5] = [0.3272, -2.9940, 2.7218, -1.2259, -0.5683];
    let x = (blue.iter().copied().fold(f64::NEG_INFINITY, f64::max) / green).log10();
    10f64.powf(A.iter().rev().fold(0.0, |acc, a| acc * x + a))
}

#[test]
fn the_built_in_oc4_example_runs_through_python_and_matches_its_formula() {
    let Some(python) = crate::common::python_with("xarray, netCDF4", "python3-xarray python3-netcdf4") else { return };
    let out = run_with(external("oc4", &[python, "{example:oc4.py}", "{input}", "{output}"], &["chl_mg_m3"]));
    assert_almi_kept(&out);
    let ext = &out.retrievals[1];
    assert!(ext.failure.is_none(), "{:?}", ext.failure);
    let chl = ext.product.chl_mg_m3.as_ref().unwrap();
    // The bands nearest 443, 490, 510 and 555 nm, by the centroid the program is given.
    let centroid = |b: usize| ext.bands[b].centroid_nm();
    let nearest = |w: f64| {
        (0..ext.bands.len()).min_by(|&i, &j| (centroid(i) - w).abs().total_cmp(&(centroid(j) - w).abs())).unwrap()
    };
    let (blue, green) = ([nearest(443.0), nearest(490.0), nearest(510.0)], nearest(555.0));
    let rrs = &out.kept().rrs;
    let mut compared = 0;
    for ((r, c), got) in chl.indexed_iter() {
        if !ext.product.returned(r, c) {
            continue;
        }
        let ok = |b: usize| rrs.flags[[r, c, b]] & (RrsFlags::INVALID | RrsFlags::SATURATED) == 0;
        if !blue.iter().chain([&green]).all(|&b| ok(b)) {
            continue;
        }
        let want = oc4(&blue.map(|b| f64::from(rrs.rrs[[r, c, b]])), f64::from(rrs.rrs[[r, c, green]]));
        // The program computes in float64 from the float32 Rrs and writes float32.
        assert!((f64::from(*got) / want - 1.0).abs() < 1e-5, "({r}, {c}): {got} vs {want}");
        compared += 1;
    }
    assert!(compared > 100, "{compared}");
    let m = ext.metrics.get("chl_mg_m3").unwrap();
    assert!(m.n > 100 && m.mae_pct().is_finite(), "{m:?}");
}

#[test]
fn the_command_line_refuses_a_program_unless_allowed_and_keeps_the_study_when_it_fails() {
    let dir = Dir::new("external-cli");
    let study = dir.path().join("mine.ron");
    std::fs::write(
        &study,
        r#"StudySpec(
    name: "mine",
    scene: Preset("lake_hume_bloom"),
    instruments: [Preset("cubesat")],
    retrievals: [Almi(), External((name: "mine", command: ["sh", "-c", "echo 'mine: cannot read band 865' >&2; exit 4"], products: ["chl_mg_m3"]))],
)"#,
    )
    .unwrap();
    let shoal = |extra: &[&str], out: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_shoal"))
            .arg("study")
            .arg(&study)
            .args(["--decimation", "16", "--no-figures", "--out"])
            .arg(dir.path().join(out))
            .args(extra)
            .output()
            .unwrap()
    };
    let refused = shoal(&[], "refused");
    assert_eq!(refused.status.code(), Some(2));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("--allow-external") && err.contains("cannot read band 865"), "names the program: {err}");
    assert!(!dir.path().join("refused").exists(), "nothing is written before the refusal");

    let failed = shoal(&["--allow-external"], "kept");
    assert_eq!(failed.status.code(), Some(1), "{}", String::from_utf8_lossy(&failed.stderr));
    let err = String::from_utf8_lossy(&failed.stderr);
    assert!(err.contains("returned nothing") && err.contains("exit"), "{err}");
    let table = String::from_utf8_lossy(&failed.stdout);
    assert!(table.contains("cannot read band 865") && table.contains("aLMI"), "{table}");
    // The study's outputs are all there: aLMI's products and the metrics with the failure.
    let kept = dir.path().join("kept");
    assert!(kept.join("cubesat/alm_chl_mg_m3.npy").exists());
    let metrics = std::fs::read_to_string(kept.join("metrics.json")).unwrap();
    assert!(metrics.contains("cannot read band 865"), "{metrics}");
}
