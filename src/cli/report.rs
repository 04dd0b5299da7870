//! `shoal report`: the review pack of a study — a self-contained `index.html` with its PNGs —
//! from a results directory `shoal study` wrote (no rerun), or by running a study.

use std::path::{Path, PathBuf};

use clap::Args;

use super::CliError;
use crate::report::{is_results_dir, load_results, review_data, write_pack};
use crate::study::{error_budget, figure_set, run_study};

/// Arguments of `shoal report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// A results directory written by `shoal study`, or a study (RON file or built-in name) to
    /// run first (default: cubesat_vs_smallsat_image).
    target: Option<String>,
    /// Output directory of the pack (index.html, figures/, review.json).
    #[arg(long, default_value = "results/review")]
    out: PathBuf,
    /// When running a study: simulate every n-th line and detector.
    #[arg(long)]
    decimation: Option<usize>,
    /// When running a study: add the error budget (each stage made perfect; 10 runs per
    /// instrument and seed).
    #[arg(long)]
    budget: bool,
    /// When running a study: add the cost-of-accuracy table of the first instrument, timed in
    /// this many interleaved rounds (3 is the bench's default).
    #[arg(long, value_name = "ROUNDS")]
    cost: Option<usize>,
    /// A sweep's output directory (`shoal sweep --out DIR`) whose curves go into the pack;
    /// repeat for several sweeps.
    #[arg(long, value_name = "DIR")]
    sweep: Vec<PathBuf>,
    /// A season's output directory (`shoal season --out DIR`, or its `--merge`) whose summary and
    /// figures go into the pack; repeat for several seasons.
    #[arg(long, value_name = "DIR")]
    season: Vec<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

/// The largest season summary read (eight designs, twenty variables and ten years of months
/// are well under 1 MB).
const SEASON_JSON_MAX_BYTES: u64 = 16 << 20;

/// The summary and figures a season wrote into `dir`: `season.json` (the season's numbers,
/// checked against its schema; every text is escaped on the page) and its `season_*.svg`.
fn season_dir(dir: &Path) -> Result<(crate::season::summary::SeasonSummary, Vec<crate::study::Figure>), CliError> {
    use crate::season::summary::{SUMMARY_JSON, SeasonSummary};
    let path = dir.join(SUMMARY_JSON);
    let text = crate::infile::read_text(&path, SEASON_JSON_MAX_BYTES).map_err(|e| {
        CliError::Input(format!(
            "--season {}: {e} (write one with `shoal season … --out {}`, or its --merge)",
            dir.display(),
            dir.display()
        ))
    })?;
    let summary: SeasonSummary = serde_json::from_str(&text)
        .map_err(|e| CliError::Input(format!("--season {}: not a season summary: {e}", path.display())))?;
    Ok((summary, prefixed_figures(dir, "season_", "--season")?))
}

/// The curves (`sweep_*.svg`, and their PNGs) a sweep wrote into `dir`.
fn sweep_figures(dir: &Path) -> Result<Vec<crate::study::Figure>, CliError> {
    prefixed_figures(dir, "sweep_", "--sweep")
}

/// The figures (`PREFIX*.svg`, and their PNGs) a command wrote into `dir`, named with the
/// folder's name so that two folders' figures do not collide; `flag` names the option in errors.
fn prefixed_figures(dir: &Path, prefix: &str, flag: &str) -> Result<Vec<crate::study::Figure>, CliError> {
    let entries = std::fs::read_dir(dir).map_err(|e| CliError::Input(format!("{flag} {}: {e}", dir.display())))?;
    let mut svgs: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| {
            p.extension().is_some_and(|x| x == "svg")
                && p.file_name().is_some_and(|n| n.to_string_lossy().starts_with(prefix))
        })
        .collect();
    if svgs.is_empty() {
        return Err(CliError::Input(format!(
            "{flag} {}: no figures ({prefix}*.svg) there; run `shoal {} … --out {}` without --no-figures",
            dir.display(),
            flag.trim_start_matches('-'),
            dir.display()
        )));
    }
    svgs.sort();
    let tag = dir.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    svgs.into_iter()
        .map(|p| {
            let svg = crate::infile::read_text(&p, crate::report::svg::MAX_SVG_BYTES as u64)
                .map_err(|e| CliError::Input(format!("{flag} {e}")))?;
            // Optional: anything but a regular file within the limit is left out.
            let png = crate::infile::read(&p.with_extension("png"), 64 << 20).unwrap_or_default();
            let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            Ok(crate::study::Figure { name: format!("{stem}_{tag}"), png, svg })
        })
        .collect()
}

/// `shoal report`.
pub fn run(args: &ReportArgs) -> Result<(), CliError> {
    let start = std::time::Instant::now();
    let sweeps = args.sweep.iter().map(|d| sweep_figures(d)).collect::<Result<Vec<_>, _>>()?;
    let seasons = args.season.iter().map(|d| season_dir(d)).collect::<Result<Vec<_>, _>>()?;
    let results_dir = args.target.as_deref().map(Path::new).filter(|p| p.is_dir());
    if let Some(dir) = results_dir
        && let (Ok(d), Ok(o)) = (dir.canonicalize(), args.out.canonicalize())
        && (o.starts_with(&d) || d.starts_with(&o))
    {
        return Err(CliError::Input(format!(
            "--out {}: the pack goes to a folder of its own, not into or around the results it reads ({})",
            args.out.display(),
            dir.display()
        )));
    }
    let out = crate::study::OutputDir::create(&args.out, "shoal report")?;
    let (mut data, mut figures) = match results_dir {
        Some(dir) => {
            if !is_results_dir(dir) {
                return Err(CliError::Input(format!(
                    "{}: not a results directory (no review.json); write one with `shoal study … --out {}`",
                    dir.display(),
                    dir.display()
                )));
            }
            if args.budget || args.cost.is_some() || args.decimation.is_some() {
                return Err(CliError::Input(
                    "--budget, --cost and --decimation apply when a study is run, not to a results directory".into(),
                ));
            }
            load_results(dir)?
        }
        None => run_for_report(args)?,
    };
    figures.extend(sweeps.into_iter().flatten());
    for (summary, season_figures) in seasons {
        data.seasons.push(summary);
        figures.extend(season_figures);
    }
    write_pack(&data, &figures, out.path())?;
    out.commit()?;
    let index = args.out.join("index.html");
    eprintln!("review pack of {} in {:.1} s: {}", data.study, start.elapsed().as_secs_f64(), index.display());
    Ok(())
}

fn run_for_report(args: &ReportArgs) -> Result<(crate::report::ReviewData, Vec<crate::study::Figure>), CliError> {
    let (spec, dir) = super::study::load(args.target.as_deref())?;
    let mut resolved = spec.resolve(dir.as_deref())?;
    super::refuse_unallowed_external(resolved.runs.iter().map(|r| &r.2))?;
    if let Some(d) = args.decimation {
        if d == 0 || d > 64 {
            return Err(CliError::Input(format!("--decimation {d} (allowed: 1 to 64)")));
        }
        for (_, _, c) in &mut resolved.runs {
            c.fidelity.decimation = d;
        }
    }
    if let Some(r) = args.cost
        && !(1..=20).contains(&r)
    {
        return Err(CliError::Input(format!("--cost {r} (allowed: 1 to 20 rounds)")));
    }
    let pool = super::pool(args.threads.unwrap_or(0), "shoal-report")?;
    let control = super::interrupt::control();
    eprintln!("{}: running {} runs …", spec.name, resolved.runs.len());
    let result = pool.install(|| run_study(&resolved, &control, false, |_, _| Ok(())))?;
    let mut budgets = Vec::new();
    if args.budget {
        let seeds: Vec<u64> = spec.seeds.clone();
        let mut seen: Vec<&str> = Vec::new();
        for (label, _, config) in &resolved.runs {
            if !seen.contains(&label.as_str()) {
                seen.push(label);
                eprintln!("{label}: error budget, 10 configurations × {} seeds …", seeds.len());
                budgets.extend(pool.install(|| error_budget(label, config, &seeds, &control))?);
            }
        }
    }
    let mut cost = Vec::new();
    if let (Some(rounds), Some((_, _, base))) = (args.cost, resolved.runs.first()) {
        eprintln!("cost of accuracy: {rounds} interleaved rounds …");
        cost = pool.install(|| crate::sweep::cost_of_accuracy(base, rounds, &control, |_, _| {}))?;
    }
    let figures = pool.install(|| figure_set(&result))?;
    Ok((review_data(&result, &budgets, &cost), figures))
}
