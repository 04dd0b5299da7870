//! `shoal simulate`: fly an instrument over a scene and write what it delivers — Level-0,
//! Level-1 and Rrs cubes (.npy), the truth, the SNR table, the run report and the fully
//! resolved configuration (see [`crate::study::write_run`]).

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use clap::Args;

use super::CliError;
use super::lookup::Lookup;
use crate::engine::{Engine, EngineError, RunConfig, RunOutput};
use crate::instrument::{InstrumentError, InstrumentSpec};
use crate::library::{Library, PresetKind};
use crate::scene::{SceneError, SceneSpec};

/// Arguments of `shoal simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Scene: a preset name (yours in the library first, then the built-ins lake_hume_bloom,
    /// heron_island_reef, aquaculture_turbidity, reservoir_chl_cdom, paper_lake_hume,
    /// paper_heron_island) or a scene RON file.
    #[arg(long, default_value = "lake_hume_bloom")]
    scene: String,
    /// Instrument: a preset name (yours in the library first, then the built-ins nominal,
    /// cubesat, smallsat, hyperspectral, filter_imager, sentinel2a_msi, landsat8_oli,
    /// sentinel3a_olci, modis_aqua, smallsat_swir) or an instrument RON file.
    #[arg(long, default_value = "nominal")]
    instrument: String,
    /// A full run configuration (RON, as written to config.ron); flags override it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Output directory (written whole: a new folder, or one Shoal wrote, which is replaced).
    #[arg(long)]
    out: PathBuf,
    /// Format of the cubes and maps: npy, geotiff (georeferenced, for GIS tools) or netcdf (one CF file).
    #[arg(long, value_enum, default_value_t)]
    format: super::output::Format,
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

/// A RON file, or a preset name as the app's library resolves it (the user's own preset in
/// `SHOAL_HOME/presets` first, then the built-in): the parsed spec and the file's directory.
/// `--scene`: a file, the user's library, or a built-in.
pub(super) const SCENES: Lookup<SceneSpec> = Lookup {
    kind: PresetKind::Scene,
    flag: "--scene",
    from_ron: |text, origin| Ok(SceneSpec::from_ron(text, origin)?),
    from_library: Library::load_scene,
    preset: |name| Ok(SceneSpec::preset(name)?),
};

/// `--instrument`: a file, the user's library, or a built-in.
pub(super) const INSTRUMENTS: Lookup<InstrumentSpec> = Lookup {
    kind: PresetKind::Instrument,
    flag: "--instrument",
    from_ron: |text, origin| Ok(InstrumentSpec::from_ron(text, origin)?),
    from_library: Library::load_instrument,
    preset: |name| Ok(InstrumentSpec::preset(name)?),
};

/// A scene as `--scene` resolves `arg` (a file, the user's library, or a built-in), with the
/// directory its own paths are read from.
pub fn scene(arg: &str) -> Result<(SceneSpec, Option<std::path::PathBuf>), CliError> {
    SCENES.resolve(arg)
}

/// An instrument as `--instrument` resolves `arg`.
pub fn instrument(arg: &str) -> Result<(InstrumentSpec, Option<std::path::PathBuf>), CliError> {
    INSTRUMENTS.resolve(arg)
}

/// The run configuration the arguments describe.
pub fn config_from(args: &SimulateArgs) -> Result<RunConfig, CliError> {
    let mut config = match &args.config {
        Some(path) => {
            let text = crate::infile::read_text(path, crate::infile::RON_MAX_BYTES)
                .map_err(|e| CliError::Input(format!("--config {e}")))?;
            RunConfig::from_ron(&text, &path.display().to_string())?
        }
        None => {
            let (scene, dir) = SCENES.resolve(&args.scene)?;
            let mut c = RunConfig::new(scene, INSTRUMENTS.resolve(&args.instrument)?.0);
            c.scene_dir = dir;
            c
        }
    };
    if let Some(d) = args.decimation {
        config.fidelity.decimation = d;
    }
    config.fault = crate::engine::Fault::from_env().map_err(CliError::Input)?;
    super::refuse_unallowed_external([&config])?;
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
        if config.correction.image().is_some() {
            return Err(CliError::Input(
                "--approximate-correction: the configuration asks for the image-based correction \
                 (correction.image); choose one"
                    .into(),
            ));
        }
        config.correction.method = crate::correction::Method::PerScene;
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
    let pool = super::pool(threads.unwrap_or(0), "shoal-simulate")?;
    let control = Arc::new(super::interrupt::control());
    let bar = indicatif::ProgressBar::new(1);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} rows, {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_prefix(label.to_string());
    let progress = bar.clone();
    let report = move |c: &crate::control::RunControl| {
        let (d, t) = c.progress();
        progress.set_length(t.max(1));
        progress.set_position(d);
    };
    let result = crate::control::observed(&control, Duration::from_millis(100), report, || {
        pool.install(|| Engine::new().run(config, &control))
    });
    bar.finish_and_clear();
    result.map_err(|e| match e {
        EngineError::Cancelled => CliError::Interrupted,
        EngineError::Failed { stage, message } => CliError::Input(format!("{stage}: {message}")),
        internal @ EngineError::Internal { .. } => CliError::Run(internal.to_string()),
    })
}

/// `shoal simulate`.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let config = config_from(args)?;
    let dir = crate::study::OutputDir::create(&args.out, "shoal simulate")?;
    let label = format!("{} over {}", config.instrument.name, config.scene.name);
    let out = run_with_progress(&config, args.threads, &label)?;
    let written = crate::study::write_run_as(&out, dir.path(), args.format.into())
        .map_err(|e| CliError::Run(e.to_string()))?
        .files;
    dir.commit()?;
    let (rows, cols, nb) = out.report.shape;
    eprintln!("{label}: {rows} lines × {cols} detectors × {nb} bands in {:.2} s", out.report.total_seconds);
    eprint!("{}", out.report.table());
    eprint!("{}", out.report.truth_shares.table());
    for w in &out.report.warnings {
        eprintln!("warning: {}: {}", out.config.instrument.name, w.message);
    }
    eprintln!("wrote {} files to {}", written.len(), args.out.display());
    Ok(())
}
