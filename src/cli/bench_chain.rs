//! `shoal bench` rows for the whole chain: the full Lake Hume scene (forward model, Level-0,
//! Level-1, correction; 19 bands), and the 256-pixel-wide preview after an instrument change,
//! stage by stage.

use std::fmt::Write as _;
use std::time::Instant;

use super::CliError;
use crate::control::RunControl;
use crate::engine::{Engine, RunConfig, RunReport, Stage, StageStatus};
use crate::instrument::InstrumentSpec;
use crate::scene::SceneSpec;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn run(engine: &mut Engine, config: &RunConfig) -> Result<RunReport, CliError> {
    engine.run(config, &RunControl::new()).map(|o| o.report).map_err(|e| CliError::Run(e.to_string()))
}

/// Per-stage medians of several reports, as "stage 12 ms" for the stages that ran.
fn stage_summary(reports: &[RunReport]) -> String {
    Stage::ALL
        .iter()
        .filter_map(|&s| {
            let times: Vec<f64> = reports
                .iter()
                .filter_map(|r| {
                    r.stages.iter().find(|x| x.stage == s && x.status == StageStatus::Ran).map(|x| x.seconds)
                })
                .collect();
            (times.len() * 2 > reports.len()).then(|| format!("{s} {:.0} ms", 1e3 * median(times)))
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Append the chain rows to `out`.
pub fn chain_rows(out: &mut String, quick: bool) -> Result<(), CliError> {
    let scene = SceneSpec::preset("lake_hume_bloom")?;
    let nominal = InstrumentSpec::preset("nominal")?;
    let _ = writeln!(out, "## Whole chain, Lake Hume (3000 × 2000 scene), nominal instrument, 19 OLCI bands");
    let _ = writeln!(out);
    let _ = writeln!(out, "| run | pixels | wall time (median) | target | stages that ran (median) |");
    let _ = writeln!(out, "|---|---|---|---|---|");
    // Full resolution from a cold engine: every stage runs.
    let reps = if quick { 1 } else { 3 };
    let mut reports = Vec::new();
    for _ in 0..reps {
        let mut engine = Engine::new();
        let start = Instant::now();
        let mut r = run(&mut engine, &RunConfig::new(scene.clone(), nominal.clone()))?;
        r.total_seconds = start.elapsed().as_secs_f64();
        reports.push(r);
    }
    let (rows, cols, _) = reports[0].shape;
    let _ = writeln!(
        out,
        "| full scene, cold (scene maps, LUT, forward, Level-0, Level-1, correction, SNR) | {rows} × {cols} | {:.2} s | < 10 s | {} |",
        median(reports.iter().map(|r| r.total_seconds).collect()),
        stage_summary(&reports)
    );
    // The preview: 256 pixels wide (decimation 4), after each kind of instrument change.
    let mut engine = Engine::new();
    let mut config = RunConfig::new(scene, nominal);
    config.fidelity.decimation = 4;
    let first = run(&mut engine, &config)?;
    let (rows, cols, _) = first.shape;
    let n = if quick { 5 } else { 15 };
    type Change = fn(&mut InstrumentSpec, usize);
    // Targets: ≤ 20 ms after an electronics change (gain, read noise), which reruns only the
    // readout and what follows; < 50 ms for the others.
    let changes: [(&str, &str, Change); 4] = [
        ("gain (electronics)", "≤ 20 ms", |i, k| i.gain_e_per_dn = 3.0 + 0.01 * (k + 1) as f64),
        ("aperture (photon counts)", "< 50 ms", |i, k| i.aperture_mm = 120.0 + (k + 1) as f64),
        ("read noise (electronics)", "≤ 20 ms", |i, k| i.read_noise_e = 15.0 + (k + 1) as f64),
        ("pixel pitch (geometry: re-samples the scene)", "< 50 ms", |i, k| {
            i.pixel_pitch_um = 5.5 + 0.01 * (k + 1) as f64;
        }),
    ];
    for (what, target, change) in changes {
        let mut times = Vec::new();
        let mut reports = Vec::new();
        for k in 0..n {
            let mut c = config.clone();
            change(&mut c.instrument, k);
            let start = Instant::now();
            reports.push(run(&mut engine, &c)?);
            times.push(start.elapsed().as_secs_f64());
        }
        let _ = writeln!(
            out,
            "| preview after a {what} change | {rows} × {cols} | {:.0} ms | {target} | {} |",
            1e3 * median(times),
            stage_summary(&reports)
        );
    }
    let _ = writeln!(out);
    Ok(())
}
