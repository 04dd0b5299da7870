//! `shoal budget`: the error budget of a study's instruments (see `study::error_budget`).

use std::path::PathBuf;

use clap::Args;

use super::CliError;
use crate::study::{budget_table, error_budget, write_bytes};

/// Arguments of `shoal budget`.
#[derive(Debug, Args)]
pub struct BudgetArgs {
    /// A study RON file or a built-in study name (default: cubesat_vs_smallsat_image, the paper's
    /// CubeSat vs SmallSat corrected from the designs' own 779/865 nm bands; cubesat_vs_smallsat
    /// keeps the paper's perfect correction).
    study: Option<String>,
    /// Noise seeds per configuration (the spread of the full error comes from them).
    #[arg(long, default_value_t = 5)]
    seeds: u64,
    /// Simulate every n-th line and detector.
    #[arg(long)]
    decimation: Option<usize>,
    /// Output directory (budget.md).
    #[arg(long, default_value = "results/budget")]
    out: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

/// `shoal budget`.
pub fn run(args: &BudgetArgs) -> Result<(), CliError> {
    if !(1..=100).contains(&args.seeds) {
        return Err(CliError::Input(format!("--seeds {} (allowed: 1 to 100)", args.seeds)));
    }
    let (spec, dir) = super::study::load(args.study.as_deref())?;
    let resolved = spec.resolve(dir.as_deref())?;
    super::refuse_unallowed_external(resolved.runs.iter().map(|r| &r.2))?;
    let out = crate::study::OutputDir::create(&args.out, "shoal budget")?;
    let pool = super::pool(args.threads.unwrap_or(0), "shoal-budget")?;
    let seeds: Vec<u64> = (1..=args.seeds).collect();
    let control = super::interrupt::control();
    let start = std::time::Instant::now();
    let mut budgets = Vec::new();
    let mut seen = Vec::new();
    for (label, _, config) in &resolved.runs {
        if seen.contains(label) {
            continue;
        }
        seen.push(label.clone());
        let mut c = config.clone();
        if let Some(d) = args.decimation {
            if d == 0 || d > 64 {
                return Err(CliError::Input(format!("--decimation {d} (allowed: 1 to 64)")));
            }
            c.fidelity.decimation = d;
        }
        eprintln!("{label}: 10 configurations × {} seeds …", seeds.len());
        budgets.extend(pool.install(|| error_budget(label, &c, &seeds, &control))?);
    }
    let table = budget_table(&budgets);
    println!("{table}");
    eprintln!("{}: error budget in {:.1} s", spec.name, start.elapsed().as_secs_f64());
    write_bytes(&out.path().join("budget.md"), table.as_bytes())?;
    Ok(out.commit()?)
}
