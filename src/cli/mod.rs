//! The headless command line. Every subcommand validates its input at the boundary: bad input
//! gets one line naming the field and the allowed range, and exit code 2; never a panic.
//!
//! | command | what it does |
//! |---|---|
//! | `shoal water` | the water model alone: CSV of every intermediate per wavelength (or band) |
//! | `shoal atmosphere` | the atmosphere alone: CSV of E₀, L_path, T_up, T_down, S, Ed(0⁺) |
//! | `shoal simulate` | scene × instrument → Level-0, Level-1, Rrs cubes, SNR, report, config |
//! | `shoal study` | a study: instruments × seeds × retrievals → metrics.csv/json, figures, cubes |
//! | `shoal report` | the review pack: one self-contained HTML page of a study (verdict, figures, provenance) |
//! | `shoal mtf` | the system MTF at Nyquist per band and focal plane, with the budget's parts |
//! | `shoal bench` | performance and accuracy figures (water evaluations/s, LUT build time vs OSOAA) |

mod atmosphere;
mod bench;
mod bench_accuracy;
mod bench_chain;
mod bench_reference;
mod bench_retrieval;
mod budget;
mod correct;
mod design;
mod grid;
mod interrupt;
mod lookup;
mod mtf;
mod output;
mod report;
mod reproduce;
mod score;
mod season;
pub mod simulate;
pub mod study;
mod sweep;
mod water;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Shoal: end-to-end simulation of satellite optical instruments over water.
#[derive(Debug, Parser)]
#[command(name = "shoal", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Let external retrievals (`External(…)` in a study) run the programs they name. A study
    /// file may be anyone's: without this flag a study that names a program is refused before it
    /// runs anything.
    #[arg(long, global = true)]
    allow_external: bool,
}

/// Refuse, before anything runs, configurations with an external retrieval when
/// `--allow-external` was not given (the message names the program).
pub(crate) fn refuse_unallowed_external<'a>(
    configs: impl IntoIterator<Item = &'a crate::engine::RunConfig>,
) -> Result<(), CliError> {
    for c in configs {
        for r in &c.retrievals {
            if let crate::retrieval::RetrievalSpec::External(e) = r
                && !e.may_run()
            {
                return Err(CliError::Input(format!(
                    "the retrieval `{}` runs a program ({}); read the study, then pass --allow-external to run it",
                    e.name,
                    e.what_runs()
                )));
            }
        }
    }
    Ok(())
}

/// Arguments of `shoal app` (the binary runs the app; the command line only parses them).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct AppArgs {
    /// Start from the built-in default study, not the saved session.
    #[arg(long)]
    pub fresh: bool,
    /// Save the window once the results are in, then quit (implies --fresh).
    #[arg(long, value_name = "FILE.png")]
    pub screenshot: Option<std::path::PathBuf>,
    /// Window size in logical pixels, WIDTHxHEIGHT (default 1500x960; at least 900x600).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<[f32; 2]>,
    /// Open this study of the library (built-in or yours) instead of the saved session; it
    /// becomes the session.
    #[arg(long, value_name = "NAME")]
    pub study: Option<String>,
}

/// `1280x720` → [1280, 720], within 900x600 to 7680x4320.
fn parse_size(text: &str) -> Result<[f32; 2], String> {
    let (w, h) =
        text.split_once(['x', 'X']).ok_or_else(|| format!("`{text}`: expected WIDTHxHEIGHT, e.g. 1280x720"))?;
    let num = |s: &str| s.trim().parse::<u32>().map_err(|e| format!("`{text}`: {e}"));
    let (w, h) = (num(w)?, num(h)?);
    if !(900..=7680).contains(&w) || !(600..=4320).contains(&h) {
        return Err(format!("`{text}`: the window must be 900x600 to 7680x4320"));
    }
    Ok([w as f32, h as f32])
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Open the desktop app on the saved session or the built-in default study (also what
    /// `shoal` with no command does; needs a display and the `gui` feature).
    App(AppArgs),
    /// Evaluate the water model (Lee et al. 1998/1999, SAMBUCA) and print CSV.
    Water(water::WaterArgs),
    /// Evaluate the atmosphere (successive orders of scattering) and print CSV.
    Atmosphere(atmosphere::AtmosphereArgs),
    /// Fly an instrument over a scene: Level-0, Level-1 and Rrs cubes (.npy), the truth, the SNR
    /// table, the run report and the resolved configuration.
    Simulate(simulate::SimulateArgs),
    /// Run a study (default: CubeSat vs SmallSat over Lake Hume): metrics table, figures,
    /// cubes and the resolved configuration.
    Study(study::StudyArgs),
    /// Reproduce Matthews et al. (2023): the paper's studies with the retrievals as the published
    /// codes run them and as Shoal improves them, beside the published numbers.
    Reproduce(reproduce::ReproduceArgs),
    /// Run a sweep: a study repeated over one parameter (or a grid of two) with several noise
    /// seeds per point; writes the table and the curves with the requirement's crossing.
    Sweep(sweep::SweepArgs),
    /// Run a season: a study's designs flown in a sun-synchronous orbit over a site for a
    /// period; each pass's sun, view, glint and clouds; how often a look is valid (per month,
    /// gaps, the revisit requirement); and each product's error over the valid looks.
    Season(season::SeasonArgs),
    /// The image-based atmospheric correction on TOA radiance spectra from a CSV (geometry and
    /// band radiances per row): Rrs per band, AOT and Ångström exponent per row.
    Correct(correct::CorrectArgs),
    /// Score products made outside Shoal (a NetCDF file of chl_mg_m3, nap_g_m3, cdom_per_m or
    /// depth_m maps) against the truth of the run whose Rrs they were made from.
    Score(score::ScoreArgs),
    /// Search for the cheapest design of a study's instrument that meets every requirement
    /// (constrained Bayesian optimisation over the parameters given with --vary) and the front
    /// of cost against each product's error.
    Design(design::DesignArgs),
    /// Error budget of a study: how much of each product's error each stage contributes
    /// (noise, calibration, atmospheric correction, SIOP set choice).
    Budget(budget::BudgetArgs),
    /// Write a study's review pack: a self-contained index.html (inline SVG figures, no network)
    /// with its PNGs, from a results directory or by running the study.
    Report(report::ReportArgs),
    /// Join the tables of `shoal sweep --shard` slices into the table one run writes.
    Merge(sweep::MergeArgs),
    /// Measure speed and accuracy: water evaluations per second, atmosphere LUT build times
    /// with their errors against OSOAA.
    Bench(bench::BenchArgs),
    /// The system MTF at Nyquist of every band of instruments (default: every built-in preset)
    /// from the MTF budget each states, with the budget's parts.
    Mtf(mtf::MtfArgs),
    /// Print the allowed range of every number a user sets (Markdown table; docs/MANUAL.md "Ranges").
    Ranges,
    /// Developer tools that regenerate computed assets.
    #[command(subcommand, hide = true)]
    Dev(DevCommand),
}

#[derive(Debug, Subcommand)]
enum DevCommand {
    /// Print the WMO aerosol component Mie table (assets/atmosphere/wmo_aerosol_mie.csv).
    AerosolTable,
    /// Print the per-band accuracy table against OSOAA (docs/PHYSICS.md).
    OsoaaTable,
    /// Regenerate the eight aLMI SIOP sets (presets/siop/almi_*.ron) into DIR.
    AlmiSets {
        /// Directory to write into.
        dir: std::path::PathBuf,
    },
}

/// What went wrong, and which exit code it earns.
#[derive(Debug)]
pub enum CliError {
    /// The user's input is invalid (exit code 2).
    Input(String),
    /// Something failed while running (exit code 1), e.g. writing the output.
    Run(String),
    /// Ctrl-C or SIGTERM stopped the run (exit code 130); nothing half-written was left.
    Interrupted,
}

impl CliError {
    fn exit_code(&self) -> ExitCode {
        match self {
            Self::Input(_) => ExitCode::from(2),
            Self::Run(_) => ExitCode::from(1),
            Self::Interrupted => ExitCode::from(interrupt::EXIT_INTERRUPTED),
        }
    }
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Input(m) | Self::Run(m) => f.write_str(m),
            Self::Interrupted => {
                f.write_str("interrupted: the run stopped; finished files are whole, nothing partial was left")
            }
        }
    }
}

macro_rules! input_error {
    ($($t:ty),*) => {$(
        impl From<$t> for CliError {
            fn from(e: $t) -> Self {
                Self::Input(e.to_string())
            }
        }
    )*};
}
input_error!(crate::water::WaterError, crate::atmosphere::AtmosphereError, crate::spectral::SpectralError);

/// Most worker threads a command starts (`--threads`): beyond a few per core threads only
/// contend, and a typo of 100 000 would stall the machine starting them.
pub const MAX_THREADS: usize = 256;

/// A command's rayon pool, its `--threads` checked first (0: one per core).
fn pool(threads: usize, name: &'static str) -> Result<rayon::ThreadPool, CliError> {
    if threads > MAX_THREADS {
        return Err(CliError::Input(format!(
            "--threads {threads} is out of range (allowed: 0, one per core, to {MAX_THREADS})"
        )));
    }
    crate::jobs::pool(threads, name).map_err(|e| CliError::Run(e.to_string()))
}

/// Refuse, before it starts, work that would not fit the machine's budget
/// ([`crate::budget::MachineBudget::from_env`]): the one resource plan every heavy command passes.
pub(crate) fn within_budget(demand: &crate::budget::Demand) -> Result<(), CliError> {
    let budget = crate::budget::MachineBudget::from_env().map_err(CliError::Input)?;
    budget.check(demand).map_err(|e| CliError::Input(e.to_string()))
}

/// `shoal dev almi-sets DIR`.
fn almi_sets(dir: &std::path::Path) -> Result<(), CliError> {
    use crate::retrieval::sets::{ALMI_SETS, almi_clusters, set_ron};
    let clusters = almi_clusters().map_err(|e| CliError::Run(e.to_string()))?;
    let total: usize = clusters.iter().map(|c| c.stations).sum();
    for (i, c) in clusters.iter().enumerate() {
        output::emit(&set_ron(i, c, total), Some(&dir.join(format!("{}.ron", ALMI_SETS[i]))))?;
    }
    Ok(())
}

/// Entry point of the `shoal` binary; `app` opens the desktop app (the binary passes it, so that
/// the command line does not depend on the app to open it; only `shoal bench`'s app rows, in the
/// `gui` build, call into `crate::app`).
#[must_use]
pub fn main(app: impl FnOnce(&AppArgs) -> ExitCode) -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { ExitCode::from(2) } else { ExitCode::SUCCESS };
        }
    };
    if cli.allow_external {
        crate::retrieval::external::allow_all();
    }
    // The budget's environment variables are read by every command alike: one that does not
    // read is refused here, whatever the command.
    if let Err(m) = crate::budget::MachineBudget::from_env() {
        eprintln!("error: {m}");
        return ExitCode::from(2);
    }
    let result = match cli.command {
        Command::App(args) => return app(&args),
        Command::Water(args) => water::run(&args),
        Command::Atmosphere(args) => atmosphere::run(&args),
        Command::Simulate(args) => simulate::run(&args),
        Command::Study(args) => study::run(&args),
        Command::Sweep(args) => sweep::run(&args),
        Command::Season(args) => season::run(&args),
        Command::Reproduce(args) => reproduce::run(&args),
        Command::Merge(args) => sweep::merge_run(&args),
        Command::Budget(args) => budget::run(&args),
        Command::Design(args) => design::run(&args),
        Command::Correct(args) => correct::run(&args),
        Command::Score(args) => score::run(&args),
        Command::Report(args) => report::run(&args),
        Command::Bench(args) => bench::run(&args),
        Command::Mtf(args) => mtf::run(&args),
        Command::Ranges => output::emit(&crate::ranges::markdown_table(), None),
        Command::Dev(DevCommand::AerosolTable) => output::emit(&crate::atmosphere::component_table_csv(), None),
        Command::Dev(DevCommand::OsoaaTable) => bench::osoaa_table(),
        Command::Dev(DevCommand::AlmiSets { dir }) => almi_sets(&dir),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            e.exit_code()
        }
    }
}
