//! `shoal bench --accuracy`: the cost-of-accuracy table (see `sweep::cost`) for the CubeSat over
//! Lake Hume with aLMI, or (`--case sambuca`) the Heron Island reef with SAMBUCA, each setting
//! timed in interleaved rounds; with `--pareto`, the time–error Pareto
//! front; with `--tolerance-pct`, the cheapest setting within that chl error.

use std::fmt::Write as _;
use std::io::IsTerminal as _;

use super::CliError;
use super::bench::{AccuracyCase, BenchArgs};
use crate::control::RunControl;
use crate::engine::RunConfig;
use crate::instrument::InstrumentSpec;
use crate::scene::{Effect, SceneSpec};
use crate::sweep::{CostRow, ErrorOf, cheapest_within, cost_of_accuracy, pareto_front};

fn pct(v: Option<f64>) -> String {
    v.map_or_else(|| "– (other grid)".to_string(), |v| format!("{v:.3}"))
}

/// A row of the table; the reference's verdicts are "–".
fn row_line(r: &CostRow, reference: bool, depth: bool, bottom: bool) -> String {
    let mut extra = String::new();
    if depth {
        let _ = write!(extra, " {} |", pct(r.errors.depth_pct));
    }
    if bottom {
        let _ = write!(extra, " {} |", pct(r.errors.bottom_changed_pct));
    }
    let verdict = |c: Option<crate::timing::Comparison>| {
        if reference { "–".to_string() } else { c.map_or_else(|| "–".into(), |c| c.text()) }
    };
    format!(
        "| {} | {} | {} | {} | {} | {:.1} | {:+.2} | {} | {} | {} |{extra}\n",
        r.label,
        r.time.wall_text(),
        verdict(Some(r.comparison)),
        r.time.cpu_text(),
        verdict(r.cpu_comparison),
        r.chl_mae_pct,
        r.delta_mae_pct,
        pct(r.errors.chl_pct),
        pct(r.errors.chl_p95_pct),
        pct(r.errors.rrs_pct)
    )
}

/// The base configuration of `case` and its heading.
fn case_base(case: AccuracyCase, quick: bool) -> Result<(RunConfig, String), CliError> {
    match case {
        AccuracyCase::Almi => {
            let mut base = RunConfig::new(SceneSpec::preset("lake_hume_bloom")?, InstrumentSpec::preset("cubesat")?);
            base.retrievals = vec![crate::retrieval::RetrievalSpec::Almi {
                siop_sets: crate::retrieval::sets::default_almi_sets(),
                settings: crate::retrieval::AlmiSettings::default(),
            }];
            base.fidelity.decimation = if quick { 4 } else { 1 };
            let heading = format!("CubeSat over Lake Hume{}, aLMI", if quick { ", decimation 4" } else { "" });
            Ok((base, heading))
        }
        AccuracyCase::Sambuca => {
            let mut scene = SceneSpec::preset("heron_island_reef")?;
            if !scene.effects.contains(&Effect::SpatialResponse) {
                scene.effects.push(Effect::SpatialResponse);
            }
            let mut base = RunConfig::new(scene, InstrumentSpec::preset("nominal")?);
            base.retrievals = vec![crate::retrieval::RetrievalSpec::Sambuca {
                siop: None,
                substrates: Some(vec!["acropora".into(), "sand".into(), "turf_algae".into()]),
                settings: crate::retrieval::SambucaSettings::default(),
            }];
            base.fidelity.decimation = if quick { 8 } else { 2 };
            let heading = format!(
                "nominal instrument over the Heron Island reef with its spatial response, decimation {}, SAMBUCA (Acropora, sand, turf algae)",
                base.fidelity.decimation
            );
            Ok((base, heading))
        }
    }
}

/// The cost-of-accuracy table (Markdown): each round's progress as it goes, then the table.
pub fn accuracy_rows(out: &mut String, args: &BenchArgs) -> Result<(), CliError> {
    if let Some(t) = args.tolerance_pct
        && !(t.is_finite() && t >= 0.0)
    {
        return Err(CliError::Input(format!("--tolerance-pct: {t} (allowed: a percentage ≥ 0)")));
    }
    let of = ErrorOf::parse(&args.error_of).ok_or_else(|| {
        CliError::Input(format!("--error-of {} (allowed: chl, nap, cdom, depth, bottom)", args.error_of))
    })?;
    let (base, heading) = case_base(args.case, args.quick)?;
    let rounds = args.rounds as usize;
    let _ = writeln!(
        out,
        "\n## Cost of accuracy ({heading}, seed 1; a fresh engine per run; {rounds} interleaved rounds)\n"
    );
    super::output::emit(&std::mem::take(out), None)?;
    let rows = cost_of_accuracy(&base, rounds, &RunControl::new(), |round, r| {
        // Progress on stderr: the table on stdout is printed once, complete.
        if std::io::stderr().is_terminal() {
            eprint!("\rround {} of {rounds}: {:<40}", round + 1, r.label);
        }
    })?;
    if std::io::stderr().is_terminal() {
        eprintln!();
    }
    let depth = rows.iter().any(|r| r.errors.depth_pct.is_some());
    let bottom = rows.iter().any(|r| r.errors.bottom_changed_pct.is_some());
    let _ = writeln!(
        out,
        "| setting | wall, median (range, n) | wall vs reference, paired | CPU, median | CPU vs reference, paired | chl MAE % | ΔMAE vs reference (points) | chl per pixel vs reference, median % | chl per pixel, 95th percentile % | Rrs(443) per pixel, median % |{}{}\n|---|---|---|---|---|---|---|---|---|---|{}",
        if depth { " depth per pixel vs reference, median % |" } else { "" },
        if bottom { " bottom type changed, % of pixels |" } else { "" },
        "---|".repeat(usize::from(depth) + usize::from(bottom))
    );
    for (i, r) in rows.iter().enumerate() {
        out.push_str(&row_line(r, i == 0, depth, bottom));
    }
    let _ = writeln!(out, "\n{}", crate::sweep::COST_METHOD);
    if args.pareto {
        let _ = writeln!(
            out,
            "\n### Pareto front (full-resolution settings: time relative to the reference against {}; a row must be measurably faster, paired by round, to beat another)\n",
            of.measure()
        );
        let _ = writeln!(
            out,
            "| setting | wall, median | wall vs reference, paired | {} error % |\n|---|---|---|---|",
            of.label()
        );
        for r in pareto_front(&rows, of) {
            let verdict = if std::ptr::eq(r, &rows[0]) { "–".to_string() } else { r.comparison.text() };
            let _ = writeln!(
                out,
                "| {} | {} | {} | {:.3} |",
                r.label,
                r.time.wall_text(),
                verdict,
                r.error_pct(of).unwrap_or(f64::NAN)
            );
        }
    }
    if let Some(t) = args.tolerance_pct {
        match cheapest_within(&rows, of, t) {
            Some(r) if std::ptr::eq(r, &rows[0]) => {
                let _ = writeln!(
                    out,
                    "\nCheapest full-resolution setting within {t} % {} error: **the reference** ({:.2} s): no setting within it is measurably faster, paired by round.",
                    of.label(),
                    r.seconds()
                );
            }
            Some(r) => {
                let _ = writeln!(
                    out,
                    "\nCheapest full-resolution setting within {t} % {} error ({}): **{}** ({:.2} s, {} the reference's time, error {:.3} %). Of settings the timings cannot tell apart, the most accurate is named; previews are not candidates: they return a subset of the pixels.",
                    of.label(),
                    of.measure(),
                    r.label,
                    r.seconds(),
                    r.comparison.text(),
                    r.error_pct(of).unwrap_or(f64::NAN)
                );
            }
            None => {
                let _ = writeln!(out, "\nNo setting was measured.");
            }
        }
    }
    Ok(())
}
