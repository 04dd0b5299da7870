//! `shoal reproduce`: the paper's Lake Hume and Heron Island studies run with the retrievals in
//! their reference modes (as the published codes run) and in Shoal's improved modes, written as
//! `reproduction.csv`, `reproduction.md` and the Figure 5-like `figure5.png`/`.svg`.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;

use super::CliError;
use crate::study::reproduction::{self, HERON_ISLAND, LAKE_HUME};
use crate::study::{StudyResult, run_study, write_bytes};

/// Arguments of `shoal reproduce`.
#[derive(Debug, Args)]
pub struct ReproduceArgs {
    /// Simulate every n-th line and detector (default: full resolution, the paper's).
    #[arg(long)]
    decimation: Option<usize>,
    /// Output directory.
    #[arg(long, default_value = "results/reproduction")]
    out: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

fn run_one(name: &str, decimation: Option<usize>) -> Result<StudyResult, CliError> {
    let spec = reproduction::both_modes(name)?;
    let mut resolved = spec.resolve(None)?;
    for (_, _, c) in &mut resolved.runs {
        if let Some(d) = decimation {
            c.fidelity.decimation = d;
        }
    }
    let control = super::interrupt::control();
    let start = Instant::now();
    let result = run_study(&resolved, &control, false, |_, _| Ok(()))?;
    eprintln!("{name}: {} runs, both modes, in {:.1} s", resolved.runs.len(), start.elapsed().as_secs_f64());
    Ok(result)
}

/// `shoal reproduce`.
pub fn run(args: &ReproduceArgs) -> Result<(), CliError> {
    if let Some(d) = args.decimation {
        crate::ranges::FIDELITY_DECIMATION
            .check(d as f64)
            .map_err(|m| CliError::Input(format!("--decimation: {m}")))?;
    }
    let out = crate::study::OutputDir::create(&args.out, "shoal reproduce")?;
    let pool = super::pool(args.threads.unwrap_or(0), "shoal-reproduce")?;
    let start = Instant::now();
    let (lake, heron) = pool.install(|| -> Result<_, CliError> {
        Ok((run_one(LAKE_HUME, args.decimation)?, run_one(HERON_ISLAND, args.decimation)?))
    })?;
    let numbers = reproduction::numbers(&lake, &heron)?;
    let rows = reproduction::rows(&numbers, args.decimation);
    let resolution =
        args.decimation.filter(|d| *d > 1).map_or("full resolution".to_string(), |d| format!("decimation {d}"));
    let header = format!(
        "# Matthews et al. (2023) reproduced\n\n`shoal reproduce` ({resolution}, {:.0} s on {} threads): \
         the studies `{LAKE_HUME}` and `{HERON_ISLAND}` with each retrieval run twice, as the published code \
         runs it (reference mode) and as Shoal improves it; one noise seed. MAE and bias are log-space \
         (the paper's eq. 1), over returned water pixels.",
        start.elapsed().as_secs_f64(),
        rayon::current_num_threads().max(pool.current_num_threads())
    );
    let md = reproduction::markdown(&rows, &header);
    write_bytes(&out.path().join("reproduction.csv"), reproduction::csv(&rows).as_bytes())?;
    write_bytes(&out.path().join("reproduction.md"), md.as_bytes())?;
    let figure = pool.install(|| reproduction::figure5(&lake, &heron, &numbers))?;
    write_bytes(&out.path().join("figure5.png"), &figure.png)?;
    write_bytes(&out.path().join("figure5.svg"), figure.svg.as_bytes())?;
    out.commit()?;
    print!("{md}");
    eprintln!("wrote {}", args.out.display());
    Ok(())
}
