//! `shoal season`: a design's looks at a site over a period (orbit, glint, clouds), how often
//! one is valid, and its products' error over the valid looks.

use std::path::{Path, PathBuf};

use clap::Args;

use super::CliError;
use crate::csvtext::Csv;
use crate::season::looks::Verdict;
use crate::season::run::{LookError, SeasonPlan, SeasonResult, plan_season, run_plan};
use crate::season::summary::{SUMMARY_JSON, SeasonSummary, variables};
use crate::season::{SeasonSpec, shard};
use crate::study::write_bytes;

/// Arguments of `shoal season`.
#[derive(Debug, Args)]
pub struct SeasonArgs {
    /// A season RON file or a built-in season name (e.g. lake_hume_year).
    season: String,
    /// First day, YYYY-MM-DD (default: the season file's).
    #[arg(long)]
    from: Option<String>,
    /// Last day, YYYY-MM-DD (default: the season file's).
    #[arg(long)]
    to: Option<String>,
    /// Decimation of each look's chain run (default: the season file's).
    #[arg(long)]
    decimation: Option<usize>,
    /// Most chain runs per design (0: the looks and revisit only).
    #[arg(long)]
    max_runs: Option<usize>,
    /// Fore/aft tilt away from the glint, degrees (default: the season file's).
    #[arg(long)]
    glint_tilt_deg: Option<f64>,
    /// Largest roll towards the site, degrees (default: the season file's).
    #[arg(long)]
    max_roll_deg: Option<f64>,
    /// Output directory.
    #[arg(long, default_value = "results/season")]
    out: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Do not draw the figures.
    #[arg(long)]
    no_figures: bool,
    /// Make one slice of the chain runs: `i/n` makes the runs of every n-th pass starting at i
    /// (0-based) and writes them to `runs.ron`; join the slices with `--merge`.
    #[arg(long, conflicts_with = "merge")]
    shard: Option<String>,
    /// Join shards' output directories (each holds `runs.ron`) into the tables and figures one
    /// whole run writes; give the season and options the shards ran with.
    #[arg(long, num_args = 1..)]
    merge: Vec<PathBuf>,
}

fn load(arg: &str) -> Result<(SeasonSpec, Option<PathBuf>), CliError> {
    if arg.ends_with(".ron") || Path::new(arg).exists() {
        let text = crate::infile::read_text(Path::new(arg), crate::infile::RON_MAX_BYTES)
            .map_err(|e| CliError::Input(e.to_string()))?;
        Ok((SeasonSpec::from_ron(&text, arg)?, Path::new(arg).parent().map(Path::to_path_buf)))
    } else {
        Ok((SeasonSpec::preset(arg)?, None))
    }
}

/// `shoal season`.
pub fn run(args: &SeasonArgs) -> Result<(), CliError> {
    let (mut spec, dir) = load(&args.season)?;
    if let Some(f) = &args.from {
        spec.from.clone_from(f);
    }
    if let Some(t) = &args.to {
        spec.to.clone_from(t);
    }
    if let Some(d) = args.decimation {
        spec.decimation = d;
    }
    if let Some(n) = args.max_runs {
        spec.max_runs = n;
    }
    if let Some(t) = args.glint_tilt_deg {
        spec.glint_tilt_deg = t;
    }
    if let Some(r) = args.max_roll_deg {
        spec.max_roll_deg = r;
    }
    spec.validate().map_err(|e| CliError::Input(e.to_string()))?;
    let shard = match &args.shard {
        Some(text) => crate::sweep::Shard::parse(text).map_err(CliError::Input)?,
        None => crate::sweep::Shard::ALL,
    };
    let (study, designs) = crate::season::run::designs(&spec, dir.as_deref())?;
    super::refuse_unallowed_external(designs.iter().map(|d| &d.1))?;
    let pool = super::pool(args.threads.unwrap_or(0), "shoal-season")?;
    // Planned once, on the season's threads: the runs, the shard's share and the merge all
    // work from this plan.
    let plan = pool.install(|| plan_season(&spec, &study, &designs))?;
    let key = shard::key(&plan, &designs);
    if !args.merge.is_empty() {
        let mut parts = Vec::with_capacity(args.merge.len());
        for d in &args.merge {
            parts.push((d.display().to_string(), shard::read(d)?));
        }
        let result = shard::merge(&plan, &key, &parts)?;
        let out = crate::study::OutputDir::create(&args.out, "shoal season --merge")?;
        eprintln!("{}: merged {} shards, {} chain runs", spec.name, parts.len(), plan.jobs.len());
        print!("{}", SeasonSummary::of(&result).text(None));
        write_outputs(&result, &plan, &key, crate::sweep::Shard::ALL, &out, args, dir.as_deref())?;
        return Ok(out.commit()?);
    }
    let out = crate::study::OutputDir::create(&args.out, "shoal season")?;
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{prefix} [{bar:30}] look {pos}/{len}, {elapsed} (eta {eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_prefix(spec.name.clone());
    let control = super::interrupt::control();
    let start = std::time::Instant::now();
    let result = pool.install(|| {
        run_plan(&plan, &designs, shard, &control, |done, total, _, _| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        })
    })?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    if shard.count > 1 {
        // A slice: its runs only; the tables and figures come from the merge.
        let mine = plan.owned(shard).len();
        eprintln!(
            "{}: shard {}/{}, {mine} of {} chain runs in {seconds:.1} s; join with `shoal season {} --merge DIR…`",
            spec.name,
            shard.index,
            shard.count,
            plan.jobs.len(),
            args.season
        );
    } else {
        print!("{}", SeasonSummary::of(&result).text(Some(seconds)));
    }
    write_outputs(&result, &plan, &key, shard, &out, args, dir.as_deref())?;
    Ok(out.commit()?)
}

/// Write a season's outputs into `out`: its runs (`runs.ron`, which `--merge` reads) and the
/// season as run; for a whole season (or a merge) also the tables and, unless turned off, the
/// figures.
fn write_outputs(
    result: &SeasonResult,
    plan: &SeasonPlan,
    key: &str,
    shard: crate::sweep::Shard,
    out: &crate::study::OutputDir,
    args: &SeasonArgs,
    dir: Option<&Path>,
) -> Result<(), CliError> {
    let runs = shard::shard_runs(plan, key.to_string(), shard, result);
    write_bytes(&out.path().join(shard::RUNS_FILE), shard::to_ron(&runs).as_bytes())?;
    write_bytes(
        &out.path().join("season.ron"),
        ron::ser::to_string_pretty(&result.spec, ron::ser::PrettyConfig::default()).unwrap_or_default().as_bytes(),
    )?;
    if shard.count > 1 {
        return Ok(());
    }
    let summary = serde_json::to_string_pretty(&SeasonSummary::of(result))
        .map_err(|e| CliError::Input(format!("{SUMMARY_JSON}: {e}")))?;
    write_bytes(&out.path().join(SUMMARY_JSON), summary.as_bytes())?;
    write_bytes(&out.path().join("looks.csv"), looks_csv(result).as_bytes())?;
    write_bytes(&out.path().join("months.csv"), months_csv(result).as_bytes())?;
    if !args.no_figures {
        let limits = crate::season::run::mae_limits(&result.spec, dir);
        for fig in crate::season::figure::figures(result, &limits)? {
            write_bytes(&out.path().join(format!("{}.png", fig.name)), &fig.png)?;
            write_bytes(&out.path().join(format!("{}.svg", fig.name)), fig.svg.as_bytes())?;
        }
    }
    Ok(())
}

fn date_time(days: f64) -> (String, String) {
    let ((y, m, d), minutes) = crate::orbit::sun::date_and_minute(days);
    (format!("{y:04}-{m:02}-{d:02}"), format!("{:02}:{:02}", minutes / 60, minutes % 60))
}

/// Every look of every design, with the errors of the looks that were run.
#[must_use]
pub fn looks_csv(result: &SeasonResult) -> String {
    let vars = variables(result);
    let mut header: Vec<String> = [
        "design",
        "date_ut",
        "time_ut",
        "date_local",
        "descending",
        "sun_zenith_deg",
        "sun_azimuth_deg",
        "view_zenith_deg",
        "relative_azimuth_deg",
        "off_nadir_deg",
        "forward_tilt_deg",
        "glint_lgn_per_sr",
        "cloud_cover",
        "verdict",
        "run",
    ]
    .iter()
    .map(ToString::to_string)
    .collect();
    header.extend(vars.iter().flat_map(|(p, v)| [format!("{p}_{v}_mae_pct"), format!("{p}_{v}_returned_pct")]));
    let refs: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut csv = Csv::new(&refs);
    // The site's date (local mean solar time), by which months.csv counts the look.
    let local_offset_days = result.spec.local_offset_days();
    for d in &result.designs {
        for (k, l) in d.looks.iter().enumerate() {
            let run = d.runs.iter().find(|r| r.look == k);
            let (date, time) = date_time(l.access.days);
            let (local_date, _) = date_time(l.access.days + local_offset_days);
            let mut row = vec![
                d.label.clone(),
                date,
                time,
                local_date,
                l.access.descending.to_string(),
                format!("{:.2}", l.geometry.sun_zenith_rad.to_degrees()),
                format!("{:.2}", l.access.sun.azimuth_rad.to_degrees()),
                format!("{:.2}", l.geometry.view_zenith_rad.to_degrees()),
                format!("{:.2}", l.geometry.relative_azimuth_rad.to_degrees()),
                format!("{:.2}", l.access.off_nadir_rad.to_degrees()),
                format!("{:.1}", l.forward_tilt_deg),
                format!("{:.5}", l.glint_per_sr),
                format!("{:.3}", l.cloud_cover),
                l.verdict.name().to_string(),
                match run {
                    Some(r) if r.failure.is_some() => "failed".into(),
                    Some(_) => "yes".into(),
                    None => "no".into(),
                },
            ];
            for (p, v) in &vars {
                let e = run.and_then(|r| r.errors.iter().find(|e| e.product == *p && e.variable == *v));
                row.push(e.and_then(LookError::returned_mae_pct).map_or_else(String::new, |m| format!("{m:.2}")));
                row.push(e.map_or_else(String::new, |e| format!("{:.2}", e.returned_pct)));
            }
            csv.row(row);
        }
    }
    csv.finish()
}

/// Looks per calendar month and verdict, per design.
#[must_use]
pub fn months_csv(result: &SeasonResult) -> String {
    let mut csv = Csv::new(&["design", "month", "passes", "valid", "sun_low", "view_oblique", "glint", "cloud"]);
    for d in &result.designs {
        let all = result.per_month(d, None);
        let by = |v: Verdict| result.per_month(d, Some(v));
        let (valid, sun, view) = (by(Verdict::Valid), by(Verdict::SunLow), by(Verdict::ViewOblique));
        let (glint, cloud) = (by(Verdict::Glint), by(Verdict::Cloud));
        for (i, ((y, m), n)) in all.iter().enumerate() {
            csv.row([
                d.label.clone(),
                format!("{y}-{m:02}"),
                n.to_string(),
                valid[i].1.to_string(),
                sun[i].1.to_string(),
                view[i].1.to_string(),
                glint[i].1.to_string(),
                cloud[i].1.to_string(),
            ]);
        }
    }
    csv.finish()
}
