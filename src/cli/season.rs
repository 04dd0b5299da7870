//! `shoal season`: a design's looks at a site over a period (orbit, glint, clouds), how often
//! one is valid, and its products' error over the valid looks.

use std::path::{Path, PathBuf};

use clap::Args;

use super::CliError;
use crate::csvtext::Csv;
use crate::season::looks::Verdict;
use crate::season::run::{SeasonResult, run_season};
use crate::season::{SeasonSpec, stats};
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
    let (study, designs) = crate::season::run::designs(&spec, dir.as_deref())?;
    super::refuse_unallowed_external(designs.iter().map(|d| &d.1))?;
    let out = crate::study::OutputDir::create(&args.out, "shoal season")?;
    let pool = super::pool(args.threads.unwrap_or(0), "shoal-season")?;
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
        run_season(&spec, &study, &designs, &control, |done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        })
    })?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    print!("{}", summary(&result, seconds));
    write_bytes(&out.path().join("looks.csv"), looks_csv(&result).as_bytes())?;
    write_bytes(&out.path().join("months.csv"), months_csv(&result).as_bytes())?;
    if !args.no_figures {
        let limits = crate::season::run::mae_limits(&spec, dir.as_deref());
        for fig in crate::season::figure::figures(&result, &limits)? {
            write_bytes(&out.path().join(format!("{}.png", fig.name)), &fig.png)?;
            write_bytes(&out.path().join(format!("{}.svg", fig.name)), fig.svg.as_bytes())?;
        }
    }
    write_bytes(
        &out.path().join("season.ron"),
        ron::ser::to_string_pretty(&spec, ron::ser::PrettyConfig::default()).unwrap_or_default().as_bytes(),
    )?;
    Ok(out.commit()?)
}

fn fmt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "–".to_string(), |v| format!("{v:.digits$}"))
}

/// The variables every design's runs returned, as (product, variable), in first-seen order.
fn variables(result: &SeasonResult) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    for d in &result.designs {
        for e in d.runs.iter().flat_map(|r| &r.errors) {
            if !out.iter().any(|(p, v)| *p == e.product && *v == e.variable) {
                out.push((e.product.clone(), e.variable.clone()));
            }
        }
    }
    out
}

/// The printed summary: per design, looks by verdict, valid looks per month, gaps, the revisit
/// requirement, and each product's error over the valid looks run.
#[must_use]
pub fn summary(result: &SeasonResult, seconds: f64) -> String {
    let s = &result.spec;
    let mut t = format!(
        "{}: study {}, site {:.2}°, {:.2}°, {} to {}, {}, roll up to {}°, glint tilt {}°, {} in {seconds:.1} s\n",
        s.name,
        result.study,
        s.site.0,
        s.site.1,
        s.from,
        s.to,
        match &s.orbit.tle {
            Some((line1, _)) => format!("two-line elements of {} (SGP4)", line1.get(2..7).unwrap_or("?").trim()),
            None => format!("descending node {:.2} h", s.orbit.descending_node_h),
        },
        s.max_roll_deg,
        s.glint_tilt_deg,
        match &s.clouds {
            Some(c) => format!("clouds from {}", c.source),
            None => "no clouds".to_string(),
        },
    );
    for d in &result.designs {
        let count = |v: Verdict| d.looks.iter().filter(|l| l.verdict == v).count();
        t += &format!(
            "\n{} ({} km, half field of view {:.2}°): {} passes; valid {}, sun low {}, view oblique {}, glint {}, cloud {}\n",
            d.label,
            d.altitude_km,
            d.half_fov_deg,
            d.looks.len(),
            count(Verdict::Valid),
            count(Verdict::SunLow),
            count(Verdict::ViewOblique),
            count(Verdict::Glint),
            count(Verdict::Cloud)
        );
        let months = d.per_month(Some(Verdict::Valid), result.period.0, result.period.1);
        let row: Vec<String> = months.iter().map(|((y, m), n)| format!("{y}-{m:02} {n}")).collect();
        t += &format!("  valid looks per month: {}\n", row.join(", "));
        let (median, p90) = d.gap_percentiles();
        t += &format!("  gap between valid looks: median {} d, 90th percentile {} d\n", fmt(median, 1), fmt(p90, 1));
        if let (Some(q), Some((pct, ok))) = (s.revisit, result.revisit(d)) {
            t += &format!(
                "  revisit: a valid look within {} d on {pct:.1} % of days (required {} %): {}\n",
                q.days,
                q.pct,
                if ok { "pass" } else { "FAIL" }
            );
        }
        let valid: Vec<f64> = d.phases.iter().map(|p| p.valid as f64).collect();
        let revisit: Vec<f64> = d.phases.iter().filter_map(|p| p.revisit_pct).collect();
        let spread = |v: &[f64], digits: usize| {
            format!(
                "{}–{}–{}",
                fmt(stats::percentile(v, 0.0), digits),
                fmt(stats::percentile(v, 50.0), digits),
                fmt(stats::percentile(v, 100.0), digits)
            )
        };
        if !d.phases.is_empty() {
            t += &format!(
                "  over {} orbit phases (min–median–max): valid looks {}{}\n",
                d.phases.len(),
                spread(&valid, 0),
                if revisit.is_empty() { String::new() } else { format!(", revisit {} % of days", spread(&revisit, 1)) }
            );
        }
        let failed = d.runs.iter().filter(|r| r.failure.is_some()).count();
        t += &format!(
            "  chain runs: {} of the valid looks{}\n",
            d.runs.len(),
            if failed > 0 { format!(", {failed} failed") } else { String::new() }
        );
        for (product, variable) in variables(result) {
            let errs: Vec<f64> = d.errors_of(&product, &variable).iter().map(|e| e.mae_pct).collect();
            if errs.is_empty() {
                continue;
            }
            let p = |q: f64| fmt(stats::percentile(&errs, q), 1);
            // The water each look returned: clouds, their shadows and glint take their share.
            let returned: Vec<f64> = d.errors_of(&product, &variable).iter().map(|e| e.returned_pct).collect();
            t += &format!(
                "  {product} {variable} MAE %: median {}, 10th–90th percentile {}–{}, worst {} ({} looks); returned % median {}, least {}\n",
                p(50.0),
                p(10.0),
                p(90.0),
                p(100.0),
                errs.len(),
                fmt(stats::percentile(&returned, 50.0), 1),
                fmt(stats::percentile(&returned, 0.0), 1),
            );
        }
        for r in d.runs.iter().filter(|r| r.failure.is_some()).take(3) {
            t += &format!("  a run failed: {}\n", r.failure.as_deref().unwrap_or_default());
        }
    }
    t
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
        "date",
        "time_ut",
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
    for d in &result.designs {
        for (k, l) in d.looks.iter().enumerate() {
            let run = d.runs.iter().find(|r| r.look == k);
            let (date, time) = date_time(l.access.days);
            let mut row = vec![
                d.label.clone(),
                date,
                time,
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
                row.push(e.map_or_else(String::new, |e| format!("{:.2}", e.mae_pct)));
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
        let all = d.per_month(None, result.period.0, result.period.1);
        let by = |v: Verdict| d.per_month(Some(v), result.period.0, result.period.1);
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
