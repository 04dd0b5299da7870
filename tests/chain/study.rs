//! Studies: a small CubeSat vs SmallSat study end to end, through the library and the CLI.

use std::process::Command;

use shoal::control::RunControl;
use shoal::study::{Source, StudySpec, run_study, write_study};

use super::small_lake;

fn tiny_study() -> StudySpec {
    let mut spec = StudySpec::default_study().unwrap();
    let mut scene = small_lake();
    scene.width = 300;
    scene.height = 300;
    spec.scene = Source::Inline(Box::new(scene));
    spec
}

#[test]
fn a_study_writes_tables_and_figures() {
    let mut resolved = tiny_study().resolve(None).unwrap();
    for (_, _, c) in &mut resolved.runs {
        c.fidelity.decimation = 8;
    }
    let result = run_study(&resolved, &RunControl::new(), false, |_, _| Ok(())).unwrap();
    assert_eq!(result.runs.len(), 2);
    let dir = std::env::temp_dir().join(format!("shoal-study-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let outputs = write_study(&result, &dir, true).unwrap();
    let csv = std::fs::read_to_string(dir.join("metrics.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "instrument,seed,product,variable,mae,bias,mae_pct,bias_pct,n,candidates,returned_pct,rmse,r2,mean_abs_error,mean_error,unit"
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 6, "2 instruments × 3 variables");
    assert!(rows.iter().any(|r| r.starts_with("cubesat,1,aLMI,chl_mg_m3,")));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(json["metrics"].as_array().unwrap().len(), 6);
    for kind in ["maps", "scatter", "histogram"] {
        let png = std::fs::read(dir.join("figures").join(format!("{kind}_alm_chl_mg_m3.png"))).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        let svg = std::fs::read_to_string(dir.join("figures").join(format!("{kind}_alm_chl_mg_m3.svg"))).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("chl-a"));
    }
    assert!(outputs.files.iter().any(|f| f == "study.ron"));
    // The spectrum at a typical water pixel, with both instruments' bands and measurements.
    let spectrum = result.spectrum.as_deref().expect("a lake has water");
    assert!(spectrum.point.water);
    let labels: Vec<&str> = spectrum.instruments.iter().map(|i| i.label.as_str()).collect();
    assert_eq!(labels, ["cubesat", "smallsat"]);
    assert!(
        spectrum.instruments.iter().all(|i| i.pixel.is_some() && i.bands.iter().any(|b| b.level1_w_m2_sr_um.is_some()))
    );
    let svg = std::fs::read_to_string(dir.join("figures").join("spectrum.svg")).unwrap();
    assert!(svg.contains("wavelength (nm)") && svg.contains("2400") && svg.contains("cubesat Level-1"));
    // The SmallSat's chl is better than the CubeSat's, as Table 1 predicts.
    let mae = |label: &str| {
        let run = result.runs.iter().find(|r| r.label == label).unwrap();
        run.retrievals[0].metrics.get("chl_mg_m3").unwrap().mae
    };
    assert!(mae("smallsat") < mae("cubesat"), "{} vs {}", mae("smallsat"), mae("cubesat"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_study_command_runs_a_file_and_refuses_a_broken_one() {
    let dir = std::env::temp_dir().join(format!("shoal-study-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("tiny.ron");
    let text = ron::ser::to_string_pretty(&tiny_study(), ron::ser::PrettyConfig::default().struct_names(true)).unwrap();
    std::fs::write(&file, &text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["study"])
        .arg(&file)
        .args(["--decimation", "10", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // The table is the command's output: on stdout, for a pipe; progress stays on stderr.
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("MAE %") && table.contains("cubesat") && table.contains("chl_mg_m3"), "{table}");
    assert!(dir.join("out/cubesat/level0_dn.npy").exists());
    assert!(dir.join("out/smallsat/alm_chl_mg_m3.npy").exists());
    assert!(dir.join("out/figures/maps_alm_chl_mg_m3.png").exists());
    std::fs::write(&file, text.replace("instruments:", "instrumentz:")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["study"])
        .arg(&file)
        .arg("--out")
        .arg(dir.join("bad"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("instrumentz") && err.contains("tiny.ron"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Three noise seeds: the spread table holds each instrument's mean and scatter of the chl MAE,
/// computed here from the runs by hand; `seed_spread.csv` carries it.
#[test]
fn the_seed_spread_is_the_mean_and_scatter_of_the_seeds() {
    let mut spec = tiny_study();
    spec.seeds = vec![1, 2, 3];
    let mut resolved = spec.resolve(None).unwrap();
    for (_, _, c) in &mut resolved.runs {
        c.fidelity.decimation = 8;
    }
    let result = run_study(&resolved, &RunControl::new(), false, |_, _| Ok(())).unwrap();
    assert_eq!(result.runs.len(), 6, "2 instruments × 3 seeds");
    let spread = shoal::study::seed_spread(&result);
    let row = spread.iter().find(|s| s.instrument == "cubesat" && s.variable == "chl_mg_m3").unwrap();
    let maes: Vec<f64> = result
        .runs
        .iter()
        .filter(|r| r.label == "cubesat")
        .map(|r| r.retrievals[0].metrics.get("chl_mg_m3").unwrap().mae_pct())
        .collect();
    assert_eq!((row.seeds, maes.len()), (3, 3));
    let mean = maes.iter().sum::<f64>() / 3.0;
    let sd = (maes.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
    assert!((row.mae_pct_mean - mean).abs() < 1e-12 && (row.mae_pct_std - sd).abs() < 1e-12);
    assert!(sd > 0.0, "three noise draws give three different errors: {maes:?}");
    assert!(row.mae_pct_range.0 <= mean && mean <= row.mae_pct_range.1);
    let dir = std::env::temp_dir().join(format!("shoal-spread-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    write_study(&result, &dir, false).unwrap();
    let csv = std::fs::read_to_string(dir.join("seed_spread.csv")).unwrap();
    assert!(csv.lines().any(|l| l.starts_with("cubesat,aLMI,chl_mg_m3,3,")), "{csv}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every example study (presets/examples/study_*.ron, which docs/RESULTS.md's rows cite) reads
/// and resolves, its scene files and presets included: a renamed preset or a changed field
/// cannot leave a documented result that no longer runs.
#[test]
fn every_example_study_resolves() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/examples");
    let mut studies: Vec<std::path::PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("study_")))
        .collect();
    studies.sort();
    assert!(studies.len() >= 5, "{studies:?}");
    for path in &studies {
        let text = std::fs::read_to_string(path).unwrap();
        let spec = StudySpec::from_ron(&text, &path.to_string_lossy()).unwrap_or_else(|e| panic!("{path:?}: {e}"));
        let resolved = spec.resolve(Some(&dir)).unwrap_or_else(|e| panic!("{path:?}: {e}"));
        assert!(!resolved.runs.is_empty(), "{path:?}");
    }
    // The seasons behind RESULTS rows load and check, and their studies resolve.
    let seasons: Vec<std::path::PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("season_")))
        .collect();
    assert!(seasons.len() >= 3, "{seasons:?}");
    for path in &seasons {
        let text = std::fs::read_to_string(path).unwrap();
        let season = shoal::season::SeasonSpec::from_ron(&text, &path.to_string_lossy())
            .unwrap_or_else(|e| panic!("{path:?}: {e}"));
        season.validate().unwrap_or_else(|e| panic!("{path:?}: {e}"));
        shoal::season::run::designs(&season, Some(&dir)).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    }
}
