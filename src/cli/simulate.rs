//! `shoal simulate`: fly an instrument over a scene and write what it delivers — Level-0,
//! Level-1 and Rrs cubes (.npy), the truth, the SNR table, the run report and the fully
//! resolved configuration.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use clap::Args;
use ndarray_npy::WriteNpyExt;

use super::CliError;
use super::output::{Csv, emit};
use crate::control::RunControl;
use crate::engine::{Engine, EngineError, RunConfig, RunOutput};
use crate::instrument::{InstrumentError, InstrumentSpec};
use crate::scene::{SceneError, SceneSpec};

/// Arguments of `shoal simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Scene: a built-in name (lake_hume_bloom, heron_island_reef, aquaculture_turbidity,
    /// reservoir_chl_cdom) or a scene RON file.
    #[arg(long, default_value = "lake_hume_bloom")]
    scene: String,
    /// Instrument: a built-in name (nominal, cubesat, smallsat, hyperspectral, filter_imager) or
    /// an instrument RON file.
    #[arg(long, default_value = "nominal")]
    instrument: String,
    /// A full run configuration (RON, as written to config.ron); flags override it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Output directory (created; files in it are replaced atomically).
    #[arg(long)]
    out: PathBuf,
    /// Simulate every n-th line and detector (a quick preview).
    #[arg(long)]
    decimation: Option<usize>,
    /// Seed of the instrument's noise, fixed patterns and calibration frames.
    #[arg(long)]
    seed: Option<u64>,
    /// No shot, dark or read noise.
    #[arg(long)]
    no_noise: bool,
    /// No ADC quantisation or clipping (Level-1 from the analogue value).
    #[arg(long)]
    no_quantise: bool,
    /// Inject a diffuser reflectance error into calibration, %.
    #[arg(long)]
    diffuser_bias_pct: Option<f64>,
    /// Inject a responsivity drift since calibration, %.
    #[arg(long)]
    gain_drift_pct: Option<f64>,
    /// Deliver the paper's per-scene atmospheric correction instead of the exact one.
    #[arg(long)]
    approximate_correction: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

impl From<InstrumentError> for CliError {
    fn from(e: InstrumentError) -> Self {
        Self::Input(e.to_string())
    }
}

impl From<SceneError> for CliError {
    fn from(e: SceneError) -> Self {
        Self::Input(e.to_string())
    }
}

/// A built-in name or a RON file: the parsed spec and the file's directory.
fn load_scene(arg: &str) -> Result<(SceneSpec, Option<PathBuf>), CliError> {
    if arg.ends_with(".ron") || Path::new(arg).exists() {
        let text = std::fs::read_to_string(arg).map_err(|e| CliError::Input(format!("--scene {arg}: {e}")))?;
        Ok((SceneSpec::from_ron(&text, arg)?, Path::new(arg).parent().map(Path::to_path_buf)))
    } else {
        Ok((SceneSpec::preset(arg)?, None))
    }
}

fn load_instrument(arg: &str) -> Result<InstrumentSpec, CliError> {
    if arg.ends_with(".ron") || Path::new(arg).exists() {
        let text = std::fs::read_to_string(arg).map_err(|e| CliError::Input(format!("--instrument {arg}: {e}")))?;
        Ok(InstrumentSpec::from_ron(&text, arg)?)
    } else {
        Ok(InstrumentSpec::preset(arg)?)
    }
}

/// The run configuration the arguments describe.
pub fn config_from(args: &SimulateArgs) -> Result<RunConfig, CliError> {
    let mut config = match &args.config {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| CliError::Input(format!("--config {}: {e}", path.display())))?;
            RunConfig::from_ron(&text, &path.display().to_string())?
        }
        None => {
            let (scene, dir) = load_scene(&args.scene)?;
            let mut c = RunConfig::new(scene, load_instrument(&args.instrument)?);
            c.scene_dir = dir;
            c
        }
    };
    if let Some(d) = args.decimation {
        config.fidelity.decimation = d;
    }
    if let Some(s) = args.seed {
        config.seed = s;
    }
    if args.no_noise {
        config.detector.noise = false;
    }
    if args.no_quantise {
        config.detector.quantise = false;
    }
    if let Some(b) = args.diffuser_bias_pct {
        config.calibration.diffuser_bias_pct = b;
    }
    if let Some(g) = args.gain_drift_pct {
        config.calibration.gain_drift_pct = g;
    }
    if args.approximate_correction {
        config.correction.use_approximation = true;
    }
    // Scene paths in the resolved configuration are absolute, so it runs from anywhere.
    if let Some(dir) = &config.scene_dir
        && let Ok(abs) = std::path::absolute(dir)
    {
        config.scene_dir = Some(abs);
    }
    Ok(config)
}

/// Run `config` on `threads` threads with a progress bar on standard error.
pub fn run_with_progress(config: &RunConfig, threads: Option<usize>, label: &str) -> Result<RunOutput, CliError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| CliError::Run(format!("cannot start worker threads: {e}")))?;
    let control = Arc::new(RunControl::new());
    let bar = indicatif::ProgressBar::new(1);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} rows, {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_prefix(label.to_string());
    let result = std::thread::scope(|s| {
        let done = Arc::new(std::sync::atomic::AtomicBool::new(false));
        let (watch, flag, progress) = (control.clone(), done.clone(), bar.clone());
        s.spawn(move || {
            while !flag.load(std::sync::atomic::Ordering::Relaxed) {
                let (d, t) = watch.progress();
                progress.set_length(t.max(1));
                progress.set_position(d);
                std::thread::sleep(Duration::from_millis(100));
            }
        });
        let mut engine = Engine::new();
        let result = pool.install(|| engine.run(config, &control));
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        result
    });
    bar.finish_and_clear();
    result.map_err(|e| match e {
        EngineError::Cancelled => CliError::Run("cancelled".into()),
        EngineError::Failed { stage, message } => CliError::Input(format!("{stage}: {message}")),
    })
}

/// Write `array` as .npy to `dir/name` atomically.
fn write_npy<A: WriteNpyExt + ?Sized>(dir: &Path, name: &str, array: &A) -> Result<(), CliError> {
    let path = dir.join(name);
    let mut bytes = Vec::new();
    array.write_npy(&mut bytes).map_err(|e| CliError::Run(format!("cannot encode {name}: {e}")))?;
    write_bytes(&path, &bytes)
}

/// Write bytes atomically (temporary file beside the target, then rename).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let tmp = path.with_extension("partial");
    let fail = |e: std::io::Error| CliError::Run(format!("cannot write {}: {e}", path.display()));
    std::fs::write(&tmp, bytes).map_err(fail)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        fail(e)
    })
}

/// The SNR table as CSV.
#[must_use]
pub fn snr_csv(out: &RunOutput) -> String {
    let mut s = String::from("band,centre_nm,radiance_w_m2_sr_nm,snr_analytic,snr_measured\n");
    for r in out.snr.iter() {
        let f = |v: f64| if v.is_finite() { super::output::number(v) } else { "inf".into() };
        s.push_str(&format!(
            "{},{},{},{},{}\n",
            r.band,
            f(r.centre_nm),
            f(r.radiance),
            f(r.snr_analytic),
            f(r.snr_measured)
        ));
    }
    s
}

/// Write every product of `out` into `dir`.
pub fn write_outputs(out: &RunOutput, dir: &Path) -> Result<Vec<String>, CliError> {
    std::fs::create_dir_all(dir).map_err(|e| CliError::Run(format!("cannot create {}: {e}", dir.display())))?;
    let mut written = Vec::new();
    let mut npy = |name: &str, r: Result<(), CliError>| -> Result<(), CliError> {
        r?;
        written.push(name.to_string());
        Ok(())
    };
    let rad = &out.radiance;
    npy("level0_dn.npy", write_npy(dir, "level0_dn.npy", &out.level0.dn))?;
    npy("level0_flags.npy", write_npy(dir, "level0_flags.npy", &out.level0.flags))?;
    npy("level1_radiance.npy", write_npy(dir, "level1_radiance.npy", &out.level1.radiance))?;
    npy("rrs.npy", write_npy(dir, "rrs.npy", &out.correction.rrs.rrs))?;
    npy("rrs_flags.npy", write_npy(dir, "rrs_flags.npy", &out.correction.rrs.flags))?;
    npy("pupil_radiance.npy", write_npy(dir, "pupil_radiance.npy", &rad.radiance))?;
    npy("truth_rrs.npy", write_npy(dir, "truth_rrs.npy", &rad.rrs))?;
    npy("truth_chl_mg_m3.npy", write_npy(dir, "truth_chl_mg_m3.npy", &rad.chl_mg_m3))?;
    npy("truth_nap_g_m3.npy", write_npy(dir, "truth_nap_g_m3.npy", &rad.nap_g_m3))?;
    npy("truth_cdom_per_m.npy", write_npy(dir, "truth_cdom_per_m.npy", &rad.cdom_per_m))?;
    npy("land_mask.npy", write_npy(dir, "land_mask.npy", &rad.land))?;
    if let Some(d) = &rad.depth_m {
        npy("truth_depth_m.npy", write_npy(dir, "truth_depth_m.npy", d))?;
    }
    if let Some(f) = &rad.substrate_fractions {
        npy("truth_substrate_fractions.npy", write_npy(dir, "truth_substrate_fractions.npy", f))?;
    }
    let mut bands = Csv::new(vec!["band".into(), "centre_nm".into(), "fwhm_nm".into()]);
    for b in &out.response.bands.bands {
        bands.row(Some(&b.name), &[b.centre_nm, b.fwhm_nm])?;
    }
    emit(&bands.render(), Some(&dir.join("bands.csv")))?;
    emit(&snr_csv(out), Some(&dir.join("snr.csv")))?;
    let report = serde_json::to_string_pretty(&out.report).map_err(|e| CliError::Run(format!("report: {e}")))?;
    emit(&report, Some(&dir.join("report.json")))?;
    emit(&out.config.to_ron()?, Some(&dir.join("config.ron")))?;
    written.extend(["bands.csv", "snr.csv", "report.json", "config.ron"].map(str::to_string));
    Ok(written)
}

/// `shoal simulate`.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let config = config_from(args)?;
    let label = format!("{} over {}", config.instrument.name, config.scene.name);
    let out = run_with_progress(&config, args.threads, &label)?;
    let written = write_outputs(&out, &args.out)?;
    let (rows, cols, nb) = out.report.shape;
    eprintln!("{label}: {rows} lines × {cols} detectors × {nb} bands in {:.2} s", out.report.total_seconds);
    eprint!("{}", out.report.table());
    eprintln!("wrote {} files to {}", written.len(), args.out.display());
    Ok(())
}
