//! `shoal sweep`: run a sweep (or one shard of it) and write its table and curves;
//! `shoal merge`: join shard tables into the table one run writes.

use std::path::{Path, PathBuf};

use clap::Args;

use super::CliError;
use crate::study::write_bytes;
use crate::sweep::{Shard, SweepSpec, Table, Values, merge, run_sweep, sweep_figure};

/// Arguments of `shoal sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// A sweep RON file or a built-in sweep name (e.g. aperture_lake_hume).
    sweep: String,
    /// Output directory.
    #[arg(long, default_value = "results/sweep")]
    out: PathBuf,
    /// Run one slice: `i/n` runs every n-th run starting at i (0-based); join with `shoal merge`.
    #[arg(long)]
    shard: Option<String>,
    /// Simulate every n-th line and detector (for a quick curve).
    #[arg(long)]
    decimation: Option<usize>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Do not draw the curves.
    #[arg(long)]
    no_figures: bool,
}

/// Arguments of `shoal merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The shards' output directories (each holds a `table.csv`).
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Output directory for the merged table and curves.
    #[arg(long, default_value = "results/sweep")]
    out: PathBuf,
    /// Do not draw the curves.
    #[arg(long)]
    no_figures: bool,
}

fn load(arg: &str) -> Result<(SweepSpec, Option<PathBuf>), CliError> {
    if arg.ends_with(".ron") || Path::new(arg).exists() {
        let text = crate::infile::read_text(Path::new(arg), crate::infile::RON_MAX_BYTES)
            .map_err(|e| CliError::Input(e.to_string()))?;
        Ok((SweepSpec::from_ron(&text, arg)?, Path::new(arg).parent().map(Path::to_path_buf)))
    } else {
        Ok((SweepSpec::preset(arg)?, None))
    }
}

/// Write the table and, unless told not to, a curve per variable; print where each series
/// first meets the requirement.
fn write_outputs(table: &Table, spec: Option<&SweepSpec>, out: &Path, figures: bool) -> Result<(), CliError> {
    write_bytes(&out.join("table.csv"), table.to_csv().as_bytes())?;
    let mut variables: Vec<String> = table.rows.iter().map(|r| r.variable.clone()).collect();
    variables.dedup();
    variables.sort();
    variables.dedup();
    let requirement = spec.and_then(|s| s.requirement.as_ref());
    let log_x = spec.is_some_and(|s| matches!(s.parameters[0].values, Values::Range { log: true, .. }));
    for v in &variables {
        let curves = crate::sweep::figure::curves(table, v, requirement, log_x);
        for s in &curves.series {
            let pts: Vec<String> = s.points.iter().map(|p| format!("{:.4}: {:.1}", p.x, p.mean)).collect();
            eprintln!("{v} MAE % by {}, {}: {}", curves.x_label, s.label, pts.join("  "));
            if let Some((limit, _)) = &curves.requirement {
                match s.crossing {
                    Some(x) => eprintln!("  first meets MAE ≤ {limit} % at {} = {x:.1}", curves.x_label),
                    None => eprintln!("  never meets MAE ≤ {limit} % in the range"),
                }
            }
        }
        if figures {
            let fig = sweep_figure(table, v, requirement, log_x)?;
            write_bytes(&out.join(format!("{}.png", fig.name)), &fig.png)?;
            write_bytes(&out.join(format!("{}.svg", fig.name)), fig.svg.as_bytes())?;
        }
        // With a band-pair correction: the same curves against the pair's measured SNR.
        if let Some(curves) = crate::sweep::figure::curves_by_pair_snr(table, v, requirement) {
            for s in &curves.series {
                let pts: Vec<String> = s.points.iter().map(|p| format!("SNR {:.1}: {:.1}", p.x, p.mean)).collect();
                eprintln!("{v} MAE % by the pair's measured SNR, {}: {}", s.label, pts.join("  "));
                if let (Some((limit, _)), Some(x)) = (&curves.requirement, s.crossing) {
                    eprintln!("  meets MAE ≤ {limit} % from a long-band SNR of {x:.1}");
                }
            }
            if figures {
                let name = format!("sweep_{v}_by_pair_snr");
                let fig = crate::study::curve_figure(&name, &curves).map_err(CliError::from)?;
                write_bytes(&out.join(format!("{}.png", fig.name)), &fig.png)?;
                write_bytes(&out.join(format!("{}.svg", fig.name)), fig.svg.as_bytes())?;
            }
        }
    }
    Ok(())
}

/// `shoal sweep`.
pub fn run(args: &SweepArgs) -> Result<(), CliError> {
    let (spec, dir) = load(&args.sweep)?;
    let shard = match &args.shard {
        Some(s) => Shard::parse(s).map_err(CliError::Input)?,
        None => Shard::ALL,
    };
    let mut sweep = spec.resolve(dir.as_deref())?;
    super::refuse_unallowed_external(sweep.bases.iter().map(|b| &b.1))?;
    if let Some(d) = args.decimation {
        if d == 0 || d > 64 {
            return Err(CliError::Input(format!("--decimation {d} (allowed: 1 to 64)")));
        }
        for (_, c) in &mut sweep.bases {
            c.fidelity.decimation = d;
        }
    }
    let out = crate::study::OutputDir::create(&args.out, "shoal sweep")?;
    let pool = super::pool(args.threads.unwrap_or(0), "shoal-sweep")?;
    let mine = sweep.jobs.iter().filter(|j| shard.owns(j.index)).count();
    let bar = indicatif::ProgressBar::new(mine as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{prefix} [{bar:30}] run {pos}/{len}, {elapsed} (eta {eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_prefix(spec.name.clone());
    let control = super::interrupt::control();
    let start = std::time::Instant::now();
    let result = pool.install(|| run_sweep(&sweep, shard, &control, |_, _| bar.inc(1)))?;
    bar.finish_and_clear();
    let mut timings = crate::csvtext::Csv::new(&["job", "seconds"]);
    for (j, s) in &result.seconds {
        timings.row([j.to_string(), format!("{s:.3}")]);
    }
    write_bytes(&out.path().join("timings.csv"), timings.finish().as_bytes())?;
    write_bytes(
        &out.path().join("sweep.ron"),
        ron::ser::to_string_pretty(&spec, ron::ser::PrettyConfig::default()).unwrap_or_default().as_bytes(),
    )?;
    eprintln!(
        "{}: {mine} of {} runs{} in {:.1} s",
        spec.name,
        sweep.jobs.len(),
        if shard.count > 1 { format!(" (shard {}/{})", shard.index, shard.count) } else { String::new() },
        start.elapsed().as_secs_f64()
    );
    if shard.count > 1 {
        // A slice: the table only; curves come from `shoal merge`.
        write_bytes(&out.path().join("table.csv"), result.table.to_csv().as_bytes())?;
    } else {
        write_outputs(&result.table, Some(&spec), out.path(), !args.no_figures)?;
    }
    Ok(out.commit()?)
}

/// `shoal merge`.
pub fn merge_run(args: &MergeArgs) -> Result<(), CliError> {
    let out = crate::study::OutputDir::create(&args.out, "shoal merge")?;
    let mut parts = Vec::new();
    let mut spec = None;
    for dir in &args.shards {
        let path = dir.join("table.csv");
        let text = crate::infile::read_text(&path, crate::infile::TABLE_MAX_BYTES)
            .map_err(|e| CliError::Input(e.to_string()))?;
        parts.push(Table::from_csv(&text, &path.display().to_string())?);
        if spec.is_none()
            && let Ok(t) = crate::infile::read_text(&dir.join("sweep.ron"), crate::infile::RON_MAX_BYTES)
        {
            spec = SweepSpec::from_ron(&t, "sweep.ron").ok();
        }
    }
    let table = merge(&parts)?;
    eprintln!("{}: merged {} tables, {} runs, {} rows", table.name, parts.len(), table.jobs, table.rows.len());
    if let Some(s) = &spec {
        write_bytes(
            &out.path().join("sweep.ron"),
            ron::ser::to_string_pretty(s, ron::ser::PrettyConfig::default()).unwrap_or_default().as_bytes(),
        )?;
    }
    write_outputs(&table, spec.as_ref(), out.path(), !args.no_figures)?;
    Ok(out.commit()?)
}
