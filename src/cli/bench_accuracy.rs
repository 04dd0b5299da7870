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
use crate::sweep::{CostRow, cheapest_within, cost_of_accuracy, pareto_front};

fn pct(v: Option<f64>) -> String {
    v.map_or_else(|| "– (other grid)".to_string(), |v| format!("{v:.3}"))
}

fn row_line(r: &CostRow, depth: bool) -> String {
    let depth = if depth { format!(" {} |", pct(r.depth_pixel_pct)) } else { String::new() };
    format!(
        "| {} | {} | {} | {} | {:.1} | {:+.2} | {} | {} | {} |{depth}\n",
        r.label,
        r.time.wall_text(),
        r.time.cpu_text(),
        r.comparison.text(),
        r.chl_mae_pct,
        r.delta_mae_pct,
        pct(r.chl_pixel_pct),
        pct(r.chl_pixel_p95_pct),
        pct(r.rrs_pixel_pct)
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
    let depth = rows.iter().any(|r| r.depth_pixel_pct.is_some());
    let _ = writeln!(
        out,
        "| setting | wall, median (range, n) | CPU, median | time vs reference | chl MAE % | ΔMAE vs reference (points) | chl per pixel vs reference, median % | chl per pixel, 95th percentile % | Rrs(443) per pixel, median % |{}\n|---|---|---|---|---|---|---|---|---|{}",
        if depth { " depth per pixel vs reference, median % |" } else { "" },
        if depth { "---|" } else { "" }
    );
    for r in &rows {
        out.push_str(&row_line(r, depth));
    }
    let _ = writeln!(
        out,
        "\nRounds run reference, setting 1, setting 2, … and again, so a slow spell of the machine falls on every setting; a row whose range of wall times overlaps the reference's says \"no measurable difference\". CPU is the process's user + system time (all threads). Each row changes one setting from the defaults (the last, three). Per-pixel columns compare the same pixels with the same noise, so they isolate the setting's own error; a preview's ΔMAE mixes that with fewer pixels in the sample."
    );
    if args.pareto {
        let _ = writeln!(
            out,
            "\n### Pareto front (full-resolution settings: median wall time against the median per-pixel chl difference from the reference; a row must be measurably faster to beat another)\n"
        );
        let _ = writeln!(out, "| setting | wall, median | chl error % |\n|---|---|---|");
        for r in pareto_front(&rows) {
            let _ = writeln!(
                out,
                "| {} | {} | {:.3} |",
                r.label,
                r.time.wall_text(),
                r.chl_error_pct().unwrap_or(f64::NAN)
            );
        }
    }
    if let Some(t) = args.tolerance_pct {
        match cheapest_within(&rows, t) {
            Some(r) => {
                let _ = writeln!(
                    out,
                    "\nCheapest full-resolution setting within {t} % chl error per pixel: **{}** ({:.2} s, {} the reference's time, chl error {:.3} %). Of settings the timings cannot tell apart, the most accurate is named; previews are not candidates: they return a subset of the pixels.",
                    r.label,
                    r.seconds(),
                    r.comparison.text(),
                    r.chl_error_pct().unwrap_or(f64::NAN)
                );
            }
            None => {
                let _ = writeln!(out, "\nNo setting was measured.");
            }
        }
    }
    Ok(())
}
