//! Faults: a panic or an error injected at one pixel of a stage is reported with the stage and
//! the pixel, the engine that met it goes on working (its cache is not poisoned), the CLI exits
//! 1 naming both, and a run cancelled mid-stage leaves no partial files.

use crate::common::Kept;
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use shoal::control::{PixelSite, RunControl};
use shoal::engine::{Engine, EngineError, Fault, FaultKind, RunConfig, Stage};
use shoal::retrieval::{AlmiSettings, RetrievalSpec};

use super::{instrument, uniform};

fn config() -> RunConfig {
    let mut c = RunConfig::new(uniform(5.0, 2.0, 0.3), instrument("nominal", 16, 12));
    c.retrievals = vec![RetrievalSpec::Almi {
        siop_sets: shoal::retrieval::sets::default_almi_sets(),
        settings: AlmiSettings::default(),
    }];
    c
}

#[test]
fn a_panic_in_any_pixel_stage_names_the_stage_and_pixel_and_the_engine_recovers() {
    let clean = config();
    let reference = super::run(&clean);
    let mut engine = Engine::new();
    for stage in [Stage::Radiance, Stage::Electrons, Stage::Level0, Stage::Level1, Stage::Correction, Stage::Retrieval]
    {
        for kind in [FaultKind::Panic, FaultKind::Error] {
            let mut c = clean.clone();
            c.fault = Some(Fault { stage, row: 9, column: 4, kind });
            // A stage served from the cache does not execute, so cannot fail: start cold.
            engine.clear();
            let e = match engine.run(&c, &RunControl::new()) {
                Ok(_) => panic!("{stage} {kind:?}: the fault did not fire"),
                Err(e) => e,
            };
            let EngineError::Internal { stage: s, site, ref message } = e else { panic!("{stage} {kind:?}: {e}") };
            assert_eq!(s, stage);
            assert_eq!(site, Some(PixelSite { row: 9, column: Some(4) }), "{stage} {kind:?}: {e}");
            assert!(e.to_string().contains(&format!("{stage}: internal error at row 9, column 4")), "{e}");
            assert!(message.contains("injected"), "{message}");
            // The same engine, the fault gone: the run completes and equals a fresh engine's.
            let out = engine.run(&clean, &RunControl::new()).unwrap();
            assert_eq!(out.kept().rrs.rrs, reference.kept().rrs.rrs, "after a fault in {stage}");
            assert_eq!(out.retrievals[0].product.chl_mg_m3, reference.retrievals[0].product.chl_mg_m3);
        }
    }
}

/// With the noise off Level-0 draws nothing, and still visits every pixel: a fault armed at
/// one fires there (the row-at-once readout once visited columns only to draw their noise).
#[test]
fn a_panic_in_level_0_without_noise_names_its_pixel() {
    let mut c = config();
    c.detector = shoal::instrument::DetectorMode { noise: false, quantise: true };
    c.fault = Some(Fault { stage: Stage::Level0, row: 9, column: 4, kind: FaultKind::Panic });
    let Err(e) = Engine::new().run(&c, &RunControl::new()) else { panic!("the fault did not fire") };
    let EngineError::Internal { stage, site, .. } = e else { panic!("{e}") };
    assert_eq!((stage, site), (Stage::Level0, Some(PixelSite { row: 9, column: Some(4) })));
}

#[test]
fn a_panic_in_a_stage_without_pixels_names_the_stage() {
    let mut c = config();
    c.fault = Some(Fault { stage: Stage::Lut, row: 0, column: 0, kind: FaultKind::Panic });
    let Err(e) = Engine::new().run(&c, &RunControl::new()) else { panic!("the fault did not fire") };
    assert!(matches!(e, EngineError::Internal { stage: Stage::Lut, site: None, .. }), "{e}");
    assert!(e.to_string().starts_with("atmosphere LUT: internal error: injected fault on entry"), "{e}");
}

#[test]
fn the_cli_reports_an_injected_fault_with_exit_code_1_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("shoal-fault-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["simulate", "--scene", "heron_island_reef", "--instrument", "cubesat", "--decimation", "16", "--out"])
        .arg(&dir)
        .env(Fault::ENV, "level-0:3:5:panic")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("error: level-0: internal error at row 3, column 5: injected fault"), "{stderr}");
    assert!(!dir.exists(), "a failed run wrote {}", dir.display());
    // A malformed fault is the user's input: exit 2, naming the variable and the stages.
    let out = Command::new(env!("CARGO_BIN_EXE_shoal"))
        .args(["simulate", "--decimation", "16", "--out"])
        .arg(&dir)
        .env(Fault::ENV, "lens:1:1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("SHOAL_FAULT") && stderr.contains("level-0"), "{stderr}");
}

#[test]
fn cancelling_mid_stage_leaves_only_whole_files_of_finished_runs() {
    use shoal::study::{StudySpec, run_study, write_run};
    let dir = std::env::temp_dir().join(format!("shoal-cancel-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut study = StudySpec::preset(shoal::study::PAPER_STUDY).unwrap().resolve(None).unwrap();
    for (_, _, c) in &mut study.runs {
        c.fidelity.decimation = 16;
    }
    assert!(study.runs.len() >= 2);
    let control = Arc::new(RunControl::new());
    // Rows done when the first run finished; the watcher cancels once the second run has done
    // more (it is then inside a per-row stage).
    let first_done = Arc::new(AtomicU64::new(u64::MAX));
    let (watch, mark) = (control.clone(), first_done.clone());
    let watcher = std::thread::Builder::new().name("cancel-watcher".into()).spawn(move || {
        for _ in 0..60_000 {
            let done = watch.progress().0;
            if done > mark.load(Ordering::SeqCst) {
                watch.cancel();
                return true;
            }
            std::thread::sleep(std::time::Duration::from_micros(500));
        }
        false
    });
    let watcher = watcher.unwrap();
    let result = run_study(&study, &control, true, |i, out| {
        write_run(out, &dir.join(format!("run{i}")))?;
        if i == 0 {
            first_done.store(control.progress().0, Ordering::SeqCst);
        }
        Ok(())
    });
    assert!(watcher.join().unwrap(), "the watcher never saw the second run start");
    assert!(matches!(result, Err(shoal::study::StudyError::Cancelled)), "{result:?}");
    let mut names: Vec<String> = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let entry = entry.unwrap();
        names.push(entry.file_name().to_string_lossy().into_owned());
        for f in std::fs::read_dir(entry.path()).unwrap() {
            let f = f.unwrap().file_name().to_string_lossy().into_owned();
            assert!(!f.ends_with(".partial"), "partial file {f}");
        }
    }
    assert_eq!(names, vec!["run0".to_string()], "only the finished run has files");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Ctrl-C (SIGINT) and a batch scheduler's SIGTERM during `shoal study`: the run stops, the
/// command exits 130 saying so, and no `.partial` file is left anywhere under the output.
#[test]
fn an_interrupted_cli_study_exits_130_and_leaves_nothing_partial() {
    for signal in ["INT", "TERM"] {
        let dir = std::env::temp_dir().join(format!("shoal-interrupt-{signal}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        // The full-resolution default study takes ~40 s; the signal comes 3 s in.
        let child = Command::new(env!("CARGO_BIN_EXE_shoal"))
            .args(["study", "--out"])
            .arg(&dir)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_secs(3));
        let sent = Command::new("kill").args([&format!("-{signal}"), &child.id().to_string()]).status().unwrap();
        assert!(sent.success());
        let started = std::time::Instant::now();
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(130), "SIG{signal}: {stderr}");
        assert!(stderr.contains("interrupted"), "{stderr}");
        assert!(started.elapsed().as_secs() < 20, "SIG{signal}: took {:?} to stop", started.elapsed());
        let mut stack = vec![dir.clone()];
        while let Some(d) = stack.pop() {
            let Ok(entries) = std::fs::read_dir(&d) else { continue };
            for e in entries {
                let path = e.unwrap().path();
                assert!(!path.to_string_lossy().ends_with(".partial"), "left behind: {}", path.display());
                if path.is_dir() {
                    stack.push(path);
                }
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
