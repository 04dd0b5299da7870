//! `shoal study`: run a study (a scene, instruments, retrievals, seeds) and write its metrics
//! table, figures, cubes and resolved configuration. With no study named, the built-in
//! CubeSat vs SmallSat study over Lake Hume runs, so a new user sees a result at once.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use clap::Args;

use super::CliError;
use super::lookup::Lookup;
use crate::study::{StudyError, StudySpec, run_study, write_run_as, write_study};

/// Arguments of `shoal study`.
#[derive(Debug, Args)]
pub struct StudyArgs {
    /// A study RON file or a built-in study name (default: cubesat_vs_smallsat_image, the paper's
    /// CubeSat vs SmallSat corrected from the designs' own 779/865 nm bands; cubesat_vs_smallsat
    /// keeps the paper's perfect correction).
    study: Option<String>,
    /// Output directory.
    #[arg(long, default_value = "results/study")]
    out: PathBuf,
    /// Simulate every n-th line and detector (overrides the study's fidelity).
    #[arg(long)]
    decimation: Option<usize>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Format of the per-instrument cubes and maps: npy, geotiff (georeferenced) or netcdf (one CF file).
    #[arg(long, value_enum, default_value_t)]
    format: super::output::Format,
    /// Do not write the per-instrument cubes (tables and figures only).
    #[arg(long)]
    no_cubes: bool,
    /// Do not draw figures.
    #[arg(long)]
    no_figures: bool,

    /// Print each run's stages and their wall time (what ran, what came from the cache)
    #[arg(long)]
    timings: bool,
}

impl From<StudyError> for CliError {
    fn from(e: StudyError) -> Self {
        match e {
            StudyError::Io(m) => Self::Run(m),
            internal @ StudyError::Internal { .. } => Self::Run(internal.to_string()),
            StudyError::Cancelled => Self::Interrupted,
            other => Self::Input(other.to_string()),
        }
    }
}

/// A study argument: a file, the user's library, or a built-in; none: the default study.
pub fn load(arg: Option<&str>) -> Result<(StudySpec, Option<PathBuf>), CliError> {
    const STUDIES: Lookup<StudySpec> = Lookup {
        kind: crate::library::PresetKind::Study,
        flag: "study",
        from_ron: |text, origin| Ok(StudySpec::from_ron(text, origin)?),
        from_library: crate::library::Library::load_study,
        preset: |name| Ok(StudySpec::preset(name)?),
    };
    match arg {
        None => Ok((StudySpec::default_study()?, None)),
        Some(a) => STUDIES.resolve(a),
    }
}

/// Each run's stages that ran, and their wall time (`--timings`), on standard error.
fn print_timings(result: &crate::study::StudyResult) {
    for run in &result.runs {
        let stages: Vec<String> = run
            .report
            .stages
            .iter()
            .filter(|s| s.status == crate::engine::StageStatus::Ran && s.seconds >= 0.005)
            .map(|s| format!("{} {:.2}", s.stage, s.seconds))
            .collect();
        eprintln!("  {} (seed {}): {:.2} s: {}", run.label, run.seed, run.report.total_seconds, stages.join(", "));
    }
}

/// `shoal study`.
pub fn run(args: &StudyArgs) -> Result<(), CliError> {
    let (spec, dir) = load(args.study.as_deref())?;
    let mut resolved = spec.resolve(dir.as_deref())?;
    super::refuse_unallowed_external(resolved.runs.iter().map(|r| &r.2))?;
    let fault = crate::engine::Fault::from_env().map_err(CliError::Input)?;
    for (_, _, c) in &mut resolved.runs {
        if let Some(d) = args.decimation {
            c.fidelity.decimation = d;
        }
        c.fault = fault;
    }
    // The output folder is checked (and a staging folder beside it opened) before any run.
    let out_dir = crate::study::OutputDir::create(&args.out, "shoal study")?;
    let pool = super::pool(args.threads.unwrap_or(0), "shoal-study")?;
    let n = resolved.runs.len();
    let bar = indicatif::ProgressBar::new(n as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{prefix} [{bar:30}] run {pos}/{len}, {elapsed} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_prefix(spec.name.clone());
    let control = Arc::new(super::interrupt::control());
    let start = std::time::Instant::now();
    let progress = bar.clone();
    let report = move |c: &crate::control::RunControl| {
        let (d, t) = c.progress();
        if t > 0 {
            progress.set_message(format!("({:.0} % of rows)", 100.0 * d as f64 / t as f64));
        }
    };
    let result = crate::control::observed(&control, Duration::from_millis(200), report, || {
        pool.install(|| {
            run_study(&resolved, &control, !args.no_cubes, |i, run_out| {
                let (label, seed, _) = &resolved.runs[i];
                if !args.no_cubes {
                    let sub = if spec.seeds.len() > 1 { format!("{label}_seed{seed}") } else { label.clone() };
                    let dir = crate::parse::join_name(out_dir.path(), "instrument.name", &sub)?;
                    write_run_as(run_out, &dir, args.format.into())?;
                }
                bar.inc(1);
                Ok(())
            })
        })
    });
    bar.finish_and_clear();
    let result = result?;
    let mut outputs = pool.install(|| write_study(&result, out_dir.path(), !args.no_figures))?;
    // What `shoal report DIR` builds the review pack from, without rerunning: the data and the
    // names of the figures drawn (the pack takes only those).
    let mut review = crate::report::review_data(&result, &[], &[]);
    review.figures = outputs.figure_names();
    let review = crate::report::review_json(&review)?;
    crate::study::write_bytes(&out_dir.path().join(crate::report::REVIEW_JSON), review.as_bytes())?;
    outputs.files.push(crate::report::REVIEW_JSON.into());
    out_dir.commit()?;
    const GIB: f64 = 1024.0 * 1024.0 * 1024.0;
    let planned = crate::study::study_plan(&resolved, !args.no_cubes).0.bytes();
    let memory = match crate::budget::peak_resident_bytes() {
        Some(peak) => format!(", peak memory {:.2} GiB (planned {:.2} GiB)", peak / GIB, planned / GIB),
        None => String::new(),
    };
    eprintln!("{}: {n} runs in {:.1} s{memory}", spec.name, start.elapsed().as_secs_f64());
    if args.timings {
        print_timings(&result);
    }
    let mut table = String::new();
    print_metrics(&mut table, &result);
    print_budgets(&mut table, &result);
    if let Some(r) = &spec.requirements {
        let _ = writeln!(
            table,
            "{:<12} {:<28} {:>10} {:>10} {:>6} {:>10}",
            "instrument", "requirement", "value", "limit", "", "margin"
        );
        for c in r.check(&result) {
            let _ = writeln!(
                table,
                "{:<12} {:<28} {:>10} {:>10.1} {:>6} {:>10}",
                c.instrument,
                c.what,
                c.value.map_or_else(|| "none".into(), |v| format!("{v:.1}")),
                c.limit,
                if c.pass { "pass" } else { "FAIL" },
                c.margin.map_or_else(|| "no pixel".into(), |m| format!("{m:+.1}"))
            );
        }
    }
    super::output::emit(&table, None)?;
    let mut warned: Vec<&str> = Vec::new();
    for run in &result.runs {
        if !warned.contains(&run.label.as_str()) {
            warned.push(&run.label);
            for w in &run.report.warnings {
                eprintln!("warning: {}: {}", run.label, w.message);
            }
            if let Some(c) = run.report.compression {
                eprintln!(
                    "{}: on-board coder {:.2} bits per sample (ratio {:.2}), error bound {} DN, largest error {} DN",
                    run.label, c.bits_per_sample, c.ratio, c.max_error_dn, c.largest_error_dn
                );
            }
        }
    }
    eprintln!("wrote {} files to {}", outputs.files.len(), args.out.display());
    // Everything is written; a retrieval whose program failed still fails the command.
    let failures: Vec<String> = result
        .runs
        .iter()
        .flat_map(|run| {
            run.retrievals.iter().filter_map(move |r| r.failure.as_ref().map(|f| format!("{}: {f}", run.label)))
        })
        .collect();
    if let Some(first) = failures.first() {
        return Err(CliError::Run(format!(
            "{} retrieval run(s) returned nothing; the rest of the study is in {}. First: {first}",
            failures.len(),
            args.out.display()
        )));
    }
    Ok(())
}

/// The metrics table (for standard output; progress and warnings go to standard error): per
/// instrument, product and variable; pixel accounting; the spread over the noise seeds when there
/// are several.
fn print_metrics(out: &mut String, result: &crate::study::StudyResult) {
    print_runs(out, result);
    let spread = crate::study::seed_spread(result);
    if spread.iter().any(|s| s.seeds > 1) {
        let _ = writeln!(
            out,
            "\nover the noise seeds: {:<12} {:<8} {:<24} {:>16} {:>17} {:>9}",
            "instrument", "product", "variable", "MAE % (mean ± sd)", "MAE % (min–max)", "bias %"
        );
        for s in &spread {
            let _ = writeln!(
                out,
                "                      {:<12} {:<8} {:<24} {:>16} {:>17} {:>+9.1}",
                s.instrument,
                s.product,
                s.variable,
                s.mae_text(),
                format!("{:.1}–{:.1}", s.mae_pct_range.0, s.mae_pct_range.1),
                s.bias_pct_mean
            );
        }
    }
}

/// Per run: the metrics of each product and variable, and the pixel accounting.
fn print_runs(out: &mut String, result: &crate::study::StudyResult) {
    let _ = writeln!(
        out,
        "{:<12} {:<8} {:<24} {:>9} {:>9} {:>10}  mean |error|, units",
        "instrument", "product", "variable", "MAE %", "bias %", "returned %"
    );
    for run in &result.runs {
        for ret in &run.retrievals {
            for v in ret.metrics.variables.iter().chain(&ret.metrics.depth_by_true_substrate) {
                // Nothing returned: no error to print (the metrics' MAE of 0 % would read as perfect).
                let m = &v.metrics;
                let (mae, bias, error) = if m.n > 0 {
                    (
                        format!("{:.1}", m.mae_pct()),
                        format!("{:+.1}", m.bias_pct()),
                        format!("{:.3} {}", m.mean_abs_error, crate::metrics::unit(&v.variable)),
                    )
                } else {
                    ("–".into(), "–".into(), "none returned".into())
                };
                let _ = writeln!(
                    out,
                    "{:<12} {:<8} {:<24} {:>9} {:>9} {:>10.2}  {error}",
                    run.label, ret.metrics.product, v.variable, mae, bias, m.returned_pct,
                );
            }
            if let Some(a) = ret.metrics.substrate_agreement_pct {
                let _ = writeln!(
                    out,
                    "{:<12} {:<8} dominant substrate right in {a:.1} % of pixels",
                    run.label, ret.metrics.product
                );
            }
            if let Some(f) = &ret.failure {
                let _ = writeln!(out, "{:<12} {:<8} returned nothing: {f}", run.label, ret.metrics.product);
                continue;
            }
            if ret.metrics.failed > 0 || ret.metrics.stalled > 0 {
                let _ = writeln!(
                    out,
                    "{:<12} {:<8} water pixels not returned: {}; stalled at the start depth: {}",
                    run.label, ret.metrics.product, ret.metrics.failed, ret.metrics.stalled
                );
            }
            if !ret.metrics.siop_set_counts.is_empty() {
                let _ = writeln!(
                    out,
                    "{:<12} {:<8} SIOP sets used: {} of {}",
                    run.label,
                    ret.metrics.product,
                    ret.metrics.siop_sets_used,
                    ret.metrics.siop_set_counts.len()
                );
            }
        }
        if let Some(a) = run.report.aerosol.as_ref().filter(|a| !a.aot550.0.is_finite()) {
            let _ = writeln!(
                out,
                "{:<12} aerosol  no pixel retrieved (true AOT(550) {:.3}, Ångström {:.2}); {}",
                run.label, a.aot550_true, a.angstrom_true, a.fit
            );
        } else if let Some(a) = &run.report.aerosol {
            let _ = writeln!(
                out,
                "{:<12} aerosol  AOT(550) {:.3} (5–95 %: {:.3}–{:.3}; true {:.3}; per-pixel error {:.3}), Ångström {:.2} (true {:.2}); outside the family: {:.1} %; {}{}",
                run.label,
                a.aot550.0,
                a.aot550.1,
                a.aot550.2,
                a.aot550_true,
                a.aot550_abs_error,
                a.angstrom,
                a.angstrom_true,
                a.outside_family_pct,
                a.fit,
                if a.passes_mean > 1.0 { format!(", {:.1} passes", a.passes_mean) } else { String::new() }
            );
            let eps = a.epsilon_words();
            if !eps.is_empty() {
                let _ = writeln!(out, "{:<12} aerosol  {eps}", run.label);
            }
        }
        if let Some(g) = &run.report.exact_high_glint {
            let _ = writeln!(
                out,
                "{:<12} glint    {} of {} water pixels left out for high glint (L_GN > {} sr⁻¹ at the assumed wind {:.1} m/s)",
                run.label, g.pixels, g.water_pixels, g.threshold_per_sr, g.assumed_wind_m_s
            );
        }
    }
}

/// The designs' budgets (first seed of each instrument), one column per instrument.
fn print_budgets(out: &mut String, result: &crate::study::StudyResult) {
    let mut labels: Vec<&str> = Vec::new();
    let mut rows: Vec<Vec<(String, String)>> = Vec::new();
    for run in &result.runs {
        if !labels.contains(&run.label.as_str()) {
            labels.push(&run.label);
            rows.push(run.budget.rows());
        }
    }
    let _ = writeln!(out, "\nbudgets (models `{}`)", result.study.budgets.name);
    let _ = write!(out, "{:<32}", "");
    for l in &labels {
        let _ = write!(out, " {l:>36}");
    }
    let _ = writeln!(out);
    for i in 0..rows.first().map_or(0, Vec::len) {
        let _ = write!(out, "{:<32}", rows[0][i].0);
        for r in &rows {
            let _ = write!(out, " {:>36}", r[i].1);
        }
        let _ = writeln!(out);
    }
    let _ = writeln!(out);
}
