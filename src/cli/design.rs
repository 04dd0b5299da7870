//! `shoal design`: search for the cheapest design of a study's instrument that meets every
//! requirement (see `crate::design`), and write the evaluations, the cost–error fronts, the
//! answer with its margins and its instrument file.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Args;

use super::CliError;
use crate::design::record::{self, Record};
use crate::design::{Dimension, Evaluation, Evaluator, Search, Settings, pareto_front, pass_probability_lower_bound};
use crate::study::{CurvePoint, CurveSeries, Curves, curve_figure, write_bytes};

/// Arguments of `shoal design`.
#[derive(Debug, Args)]
pub struct DesignArgs {
    /// A study RON file or a built-in study name: its scene, retrieval, requirements, seeds and
    /// budget models; its first instrument (or `--instrument`) is the starting design.
    study: String,
    /// A parameter to vary: `PATH=LO:HI`, `PATH=LO:HI:int` or `PATH=A,B,C` (repeat; a path
    /// without a dot is an instrument field, e.g. `aperture_mm=40:200`).
    #[arg(long = "vary", required = true)]
    vary: Vec<String>,
    /// Which of the study's instruments to start from (0-based).
    #[arg(long, default_value_t = 0)]
    instrument: usize,
    /// Designs evaluated in all (the Latin-hypercube start included).
    #[arg(long, default_value_t = 40)]
    evaluations: usize,
    /// Designs in the start (0: 2 × parameters + 1).
    #[arg(long, default_value_t = 0)]
    initial: usize,
    /// Decimation of lines and detectors while searching (2: at 4 the Lake Hume search's
    /// chlorophyll error was optimistic enough to change the answer; see RESULTS.md).
    #[arg(long, default_value_t = 2)]
    decimation: usize,
    /// Decimation the cheapest feasible designs are confirmed at (0: no confirmation).
    #[arg(long, default_value_t = 1)]
    confirm_decimation: usize,
    /// Seed of the start and the optimiser.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Stop early after this many designs in a row that made the cheapest feasible design less
    /// than 0.1 % cheaper (0: run every evaluation).
    #[arg(long, default_value_t = 0)]
    stall: usize,
    /// Evaluate only the designs `i`, `i + n`, … of the Latin-hypercube start and stop (`i/n`,
    /// 0-based; one per job of a cluster's array). Each shard writes `evaluations.ron`.
    #[arg(long)]
    shard: Option<String>,
    /// Shard output folders (or earlier searches) whose evaluations this search takes instead
    /// of running them again; they must be of the same study, parameters, resolution and seeds.
    #[arg(long, num_args = 1..)]
    resume: Vec<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "results/design")]
    out: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Do not draw the fronts.
    #[arg(long)]
    no_figures: bool,
}

/// `shoal design`.
pub fn run(args: &DesignArgs) -> Result<(), CliError> {
    for (flag, d) in [("--decimation", args.decimation), ("--confirm-decimation", args.confirm_decimation)] {
        if d > 64 || (d == 0 && flag == "--decimation") {
            return Err(CliError::Input(format!("{flag} {d} (allowed: 1 to 64; 0 skips confirmation)")));
        }
    }
    let vars = args.vary.iter().map(|v| Dimension::parse(v)).collect::<Result<Vec<_>, _>>().map_err(CliError::Input)?;
    let (spec, dir) = super::study::load(Some(&args.study))?;
    let resolved = spec.resolve(dir.as_deref())?;
    super::refuse_unallowed_external(resolved.runs.iter().map(|r| &r.2))?;
    let labels: Vec<&String> = crate::design::unique(resolved.runs.iter().map(|r| &r.0));
    let label = labels.get(args.instrument).ok_or_else(|| {
        CliError::Input(format!("--instrument {} (allowed: 0 to {})", args.instrument, labels.len() - 1))
    })?;
    let base = &resolved
        .runs
        .iter()
        .find(|r| &r.0 == *label)
        .map(|r| r.2.clone())
        .unwrap_or_else(|| resolved.runs[0].2.clone());
    let requirements = spec.requirements.clone().unwrap_or_default();
    let evaluator = Evaluator {
        base,
        vars: &vars,
        seeds: &spec.seeds,
        requirements: &requirements,
        budgets: &resolved.budgets,
        decimation: args.decimation,
    };
    let settings = Settings {
        evaluations: args.evaluations,
        initial: args.initial,
        decimation: args.decimation,
        confirm_decimation: (args.confirm_decimation > 0).then_some(args.confirm_decimation),
        seed: args.seed,
        stall_after: (args.stall > 0).then_some(args.stall),
        stall_gain: 0.001,
        shard: args.shard.as_deref().map(crate::sweep::Shard::parse).transpose().map_err(CliError::Input)?,
    };
    crate::design::check(&evaluator, &settings)?;
    let expected = Record {
        study: spec.name.clone(),
        instrument: (*label).clone(),
        vars: record::vars_of(&vars),
        decimation: args.decimation,
        seeds: spec.seeds.clone(),
        seed: args.seed,
        evaluations: Vec::new(),
    };
    // The variables the study's retrieval makes: the fronts' file names come from them (never
    // from a record), and a record's constraints are judged against them.
    let made: Vec<String> = base.retrievals.first().map(|r| r.algorithm().variables()).unwrap_or_default();
    let plan = crate::design::evaluate::constraint_plan(&requirements, &made);
    let mut prior = Vec::new();
    for dir in &args.resume {
        let r = Record::read(dir)?;
        let origin = dir.display().to_string();
        r.check_matches(&expected, &origin)?;
        r.check_evaluations(&vars, &plan, &resolved.budgets.cost.currency, &origin)?;
        prior.extend(r.evaluations);
    }
    let out = crate::study::OutputDir::create(&args.out, "shoal design")?;
    let pool = super::pool(args.threads.unwrap_or(0), "shoal-design")?;
    let bar = indicatif::ProgressBar::new(args.evaluations as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{prefix} [{bar:30}] design {pos}/{len}, {elapsed}, ~{eta} left {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_prefix(format!("{} ({label})", spec.name));
    let control = super::interrupt::control();
    let start = std::time::Instant::now();
    let search = pool.install(|| {
        crate::design::search_from(&evaluator, &settings, &prior, &control, |e, done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
            let cost = e.cost.map_or_else(|| "–".into(), |c| format!("{c:.3}"));
            bar.set_message(format!("last: cost {cost}, {}", if e.feasible() { "feasible" } else { "not feasible" }));
        })
    });
    bar.finish_and_clear();
    let search = search?;
    let seconds = start.elapsed().as_secs_f64();
    let summary = summary(&search, &spec.name, label, &resolved.budgets.cost.currency, spec.seeds.len(), seconds);
    print!("{summary}");
    let dir = out.path();
    write_bytes(&dir.join("design.md"), summary.as_bytes())?;
    Record { evaluations: search.evaluations.clone(), ..expected }.write(dir)?;
    write_bytes(&dir.join("evaluations.csv"), evaluations_csv(&search).as_bytes())?;
    let mut fronts = Vec::new();
    for variable in front_variables(&made, &requirements) {
        let front = pareto_front(&search.evaluations, &variable);
        let name = format!("front_{variable}");
        write_bytes(&dir.join(format!("{name}.csv")), front_csv(&search, &front, &variable).as_bytes())?;
        if !args.no_figures && !front.is_empty() {
            let limit = requirements.for_variable(&variable).and_then(|p| p.mae_pct);
            let figure =
                curve_figure(&name, &front_curves(&search, &front, &variable, limit, &resolved.budgets.cost.currency))?;
            write_bytes(&dir.join(format!("{}.png", figure.name)), &figure.png)?;
            write_bytes(&dir.join(format!("{}.svg", figure.name)), figure.svg.as_bytes())?;
            fronts.push(crate::report::html::PageFigure { name: figure.name, svg: figure.svg, png: false });
        }
    }
    // The review page: the answer, its margins and budgets, the fronts, every design.
    let context = crate::report::design_page::DesignContext {
        study: spec.name.clone(),
        description: spec.description.clone(),
        instrument: (*label).clone(),
        currency: resolved.budgets.cost.currency.clone(),
        seeds: spec.seeds.len(),
        seconds,
    };
    let page = crate::report::design_page::design_page(&search, &context, &fronts);
    write_bytes(&dir.join("index.html"), page.as_bytes())?;
    if let Some(answer) = search.answer() {
        let config = crate::design::space::configure(base, &search.vars, &answer.x).map_err(CliError::Run)?;
        let ron = ron::ser::to_string_pretty(&config.instrument, ron::ser::PrettyConfig::default())
            .map_err(|e| CliError::Run(format!("cannot write the instrument: {e}")))?;
        write_bytes(&dir.join("cheapest_instrument.ron"), ron.as_bytes())?;
    }
    out.commit()?;
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

/// The product variables a front is drawn for: the required ones, else every one the study's
/// retrieval makes. Shoal's own keys, so each is a safe file name (`front_chl_mg_m3.csv`).
fn front_variables(made: &[String], requirements: &crate::study::Requirements) -> Vec<String> {
    let required: Vec<String> =
        requirements.products.iter().filter(|p| p.mae_pct.is_some()).map(|p| p.variable.clone()).collect();
    let chosen = if required.is_empty() { made.to_vec() } else { required };
    chosen.into_iter().filter(|v| crate::variable::of(v).is_some()).collect()
}

fn row(e: &Evaluation) -> Vec<String> {
    let mut cells: Vec<String> = e.x.iter().map(ToString::to_string).collect();
    cells.extend([
        e.cost.map_or_else(String::new, |c| format!("{c:.4}")),
        (if e.feasible() { "yes" } else { "no" }).to_string(),
        e.decimation.to_string(),
        format!("{}/{}", e.seeds_passed, e.seeds),
        format!("{:.2}", e.seconds),
    ]);
    cells
}

fn evaluations_csv(search: &Search) -> String {
    let keys = crate::design::constraint_keys(&search.evaluations);
    // The constraint columns keep the `;` they have always had for a comma in a key.
    let excess: Vec<String> = keys.iter().map(|k| format!("excess {}", k.replace(',', ";"))).collect();
    let header: Vec<&str> = ["step", "phase"]
        .into_iter()
        .chain(search.vars.iter().map(Dimension::name))
        .chain(["cost", "feasible", "decimation", "seeds_passed", "seconds"])
        .chain(excess.iter().map(String::as_str))
        .chain(["error"])
        .collect();
    let mut csv = crate::csvtext::Csv::new(&header);
    let n = search.evaluations.len();
    for (i, e) in search.evaluations.iter().chain(&search.confirmed).enumerate() {
        let phase = if i >= n { "confirm" } else { "search" };
        let mut cells = vec![(i + 1).to_string(), phase.to_string()];
        cells.extend(row(e));
        for k in &keys {
            let g =
                e.constraints.iter().find(|(name, _)| name == k).map_or_else(String::new, |(_, g)| format!("{g:.4}"));
            cells.push(g);
        }
        cells.push(e.error.as_deref().unwrap_or("").replace([',', '\n'], ";"));
        csv.row(&cells);
    }
    csv.finish()
}

fn front_csv(search: &Search, front: &[usize], variable: &str) -> String {
    let mae = format!("{variable}_mae_pct");
    let header: Vec<&str> = search.vars.iter().map(Dimension::name).chain(["cost", mae.as_str(), "feasible"]).collect();
    let mut csv = crate::csvtext::Csv::new(&header);
    for &i in front {
        let e = &search.evaluations[i];
        let mut cells: Vec<String> = e.x.iter().map(ToString::to_string).collect();
        let mae = e.mae_pct.iter().find(|(v, _)| v == variable).map_or(f64::NAN, |m| m.1);
        cells.extend([
            format!("{:.4}", e.cost.unwrap_or(f64::NAN)),
            format!("{mae:.2}"),
            (if e.feasible() { "yes" } else { "no" }).to_string(),
        ]);
        csv.row(&cells);
    }
    csv.finish()
}

fn front_curves(search: &Search, front: &[usize], variable: &str, limit: Option<f64>, currency: &str) -> Curves {
    let point = |i: usize| {
        let e = &search.evaluations[i];
        let y = e.mae_pct.iter().find(|(v, _)| v == variable).map_or(f64::NAN, |m| m.1);
        CurvePoint { x: e.cost.unwrap_or(f64::NAN), mean: y, lo: y, hi: y }
    };
    let feasible: Vec<CurvePoint> =
        front.iter().copied().filter(|&i| search.evaluations[i].feasible()).map(point).collect();
    let mut series = vec![CurveSeries {
        label: "front (designs evaluated)".into(),
        points: front.iter().map(|&i| point(i)).collect(),
        crossing: None,
    }];
    if !feasible.is_empty() {
        series.push(CurveSeries {
            label: "feasible (every requirement, every seed)".into(),
            points: feasible,
            crossing: None,
        });
    }
    Curves {
        title: format!(
            "{}: cost against {} error",
            search.vars.iter().map(Dimension::name).collect::<Vec<_>>().join(", "),
            crate::metrics::name(variable)
        ),
        x_label: format!("telescope cost, {currency}"),
        y_label: format!("{} log-space MAE, %", crate::metrics::name(variable)),
        log_x: false,
        series,
        requirement: limit.map(|l| (l, format!("requirement {l} %"))),
        caption: vec![format!(
            "{} designs evaluated at decimation {}; the front is the designs no other beats on both cost and error.",
            search.evaluations.len(),
            search.evaluations.first().map_or(1, |e| e.decimation)
        )],
    }
}

fn describe(search: &Search, e: &Evaluation) -> String {
    search.vars.iter().zip(&e.x).map(|(v, x)| format!("{} = {}", v.name(), fmt(*x))).collect::<Vec<_>>().join(", ")
}

fn fmt(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e9 { format!("{x:.0}") } else { format!("{x:.5}") }
}

fn summary(search: &Search, study: &str, label: &str, currency: &str, seeds: usize, seconds: f64) -> String {
    let mut s = String::new();
    let evaluated = search.evaluations.len();
    let feasible = search.evaluations.iter().filter(|e| e.feasible()).count();
    let search_s: f64 = search.evaluations.iter().map(|e| e.seconds).sum::<f64>() + 0.0;
    // `+ 0.0`: an empty sum is −0.0, which would print as "-0.0 s".
    let confirm_s: f64 = search.confirmed.iter().map(|e| e.seconds).sum::<f64>() + 0.0;
    let _ = writeln!(s, "# Design search: {study} ({label})\n");
    if let Some(why) = &search.stopped_early {
        let _ = writeln!(s, "{why}.\n");
    }
    if let Some(note) = crate::design::optimiser_note(search) {
        let _ = writeln!(s, "{note}\n");
    }
    if search.shard {
        let _ = writeln!(
            s,
            "{} designs evaluated; resume the search from this folder and the other shards' (--resume).",
            search.evaluations.len()
        );
        return s;
    }
    let _ = writeln!(
        s,
        "{evaluated} designs at decimation {} ({search_s:.1} s), {} confirmation runs ({confirm_s:.1} s); {feasible} feasible during the search; {seconds:.1} s in all.\n",
        search.evaluations.first().map_or(0, |e| e.decimation),
        search.confirmed.len()
    );
    match search.answer() {
        Some(a) => {
            let _ = writeln!(s, "Cheapest feasible design: {}", describe(search, a));
            let _ = writeln!(
                s,
                "  telescope cost {:.3} {currency}{}, at decimation {}; every requirement passed on all {} seeds (95 % lower bound on a further seed passing: {:.2}).",
                a.cost.unwrap_or(f64::NAN),
                if a.budget.as_ref().is_some_and(|b| b.cost.extrapolated) { " (extrapolated)" } else { "" },
                a.decimation,
                a.seeds,
                pass_probability_lower_bound(seeds, 0.95)
            );
            let _ = writeln!(s, "  margins (worst seed; negative excess = inside the limit, as a share of it):");
            for (k, g) in &a.constraints {
                let _ = writeln!(s, "    {k:<28} {:+.2} %", -100.0 * g);
            }
            if let Some(b) = &a.budget {
                for (name, value) in b.rows() {
                    let _ = writeln!(s, "  {name:<32} {value}");
                }
            }
        }
        None => {
            let _ = writeln!(s, "No feasible design in the range searched.");
            if let Some(c) = search.closest.and_then(|i| search.evaluations.get(i)) {
                let _ = writeln!(
                    s,
                    "Closest: {} (cost {:.3} {currency}); it misses:",
                    describe(search, c),
                    c.cost.unwrap_or(f64::NAN)
                );
                for (k, g) in c.constraints.iter().filter(|(_, g)| *g > 0.0) {
                    let _ = writeln!(s, "    {k:<28} by {:.1} % of the limit", 100.0 * g);
                }
            }
            if !search.confirmed.is_empty() {
                let _ = writeln!(
                    s,
                    "The search's feasible designs failed at the confirmation resolution: see evaluations.csv (phase confirm)."
                );
            }
        }
    }
    s
}
