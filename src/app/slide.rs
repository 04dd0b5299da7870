//! The comparison figure an engineer takes to a design review: the maps on one scale, the SNR
//! per band against the requirement, retrieved against true values, the verdicts and the
//! parameters the designs differ in, as a 1920 × 1080 slide (PNG and SVG), with the resolved
//! configurations beside it.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::export::Snapshot;
use super::model::AppState;
use super::raster::{Palette, product_map};
use crate::colormap::Scale;
use crate::engine::RunOutput;
use crate::study::{ComparisonPanel, ReviewSlide, SlideSeries, review_slide, write_bytes};

/// Write the comparison figure and the configurations next to `stem`.
pub fn write_figure(snap: &Snapshot, stem: &Path) -> Result<Vec<PathBuf>, String> {
    let state = &snap.state;
    let runs = snap.all()?;
    let kind = state.product;
    let mut panels = Vec::new();
    // The truth, then every design (the figure carries them all, whatever the maps show).
    let maps = std::iter::once((None, runs[0])).chain(runs.iter().enumerate().map(|(i, r)| (Some(i), *r)));
    for (design, out) in maps {
        if let Some(m) = product_map(out, kind, state.band, design.is_none()) {
            let title = design.map_or_else(|| "truth".to_string(), |i| state.design_name(i));
            panels.push(ComparisonPanel { title, values: m.values, valid: m.valid });
        }
    }
    if panels.is_empty() {
        return Err(format!("the runs have no {} to show", kind.label()));
    }
    let refs: Vec<super::raster::MapData> =
        panels.iter().map(|p| super::raster::MapData { values: p.values.clone(), valid: p.valid.clone() }).collect();
    let refs: Vec<&super::raster::MapData> = refs.iter().collect();
    let scale = match super::raster::shared_palette(&refs, kind, false) {
        Palette::Sequential(s) => s,
        _ => Scale { lo: 0.0, hi: 8.0, log: false },
    };
    let designs: Vec<String> = (0..runs.len()).map(|i| state.design_name(i)).collect();
    let wide = verdict_table(state, &runs);
    // Beyond two designs the products go across and the designs down, so the table fits.
    let table = if runs.len() > 2 { by_design(&wide, &designs) } else { wide };
    let changes = state.changes();
    let caption = vec![
        format!(
            "{}   scene: {}   retrieval: {}   resolution 1/{}",
            designs.join("   "),
            state.scene_name,
            super::banners::retrieval_name(state),
            snap.decimation
        ),
        if changes.is_empty() {
            "Instruments as in their presets.".into()
        } else {
            format!("Instrument edits: {}", changes.join("; "))
        },
        "Shoal: one colour scale for all panels; grey: land or not returned; metrics after Seegers et al. (2018)."
            .into(),
    ];
    // What "pass?" means, and why, on the slide itself (the app says it on hover).
    let mut caption = caption;
    // The designs whose row or column holds a "pass?" (a design that fails anyway needs none).
    let questioned = |i: usize| {
        let letter = super::model::label(i);
        if runs.len() > 2 {
            table.get(i + 1).is_some_and(|row| row.iter().any(|c| c.ends_with("pass?")))
        } else {
            let at = table.first().and_then(|h| h.iter().position(|c| *c == letter));
            at.is_some_and(|k| table.iter().skip(1).any(|row| row.get(k).is_some_and(|c| c == "pass?")))
        }
    };
    let warned: Vec<String> = runs
        .iter()
        .enumerate()
        .filter(|(i, _)| questioned(*i))
        .filter_map(|(i, out)| {
            let w = &out.report.warnings;
            let words: Vec<String> = w.iter().map(crate::instrument::plausibility::Warning::short).collect();
            (!words.is_empty()).then(|| format!("{}: {}", super::model::label(i), words.join(", ")))
        })
        .collect();
    if !warned.is_empty() {
        caption.push(format!("pass?: the numbers pass but the design is implausible here ({})", warned.join("; ")));
    }
    // What is compared, as set now (a study's name would outlive a change of scene).
    let title = format!("{} — {}", snap.title(), kind.label());
    let variable = kind.variable().unwrap_or("chl_mg_m3");
    // One series per design, in the designs' colours.
    let series = |i: usize, points: Vec<(f64, f64)>| {
        let [r, g, b, _] = super::theme::design(i).to_array();
        SlideSeries { name: state.design_name(i), colour: [r, g, b], points }
    };
    let plot = super::plot_data::plot_data(&snap.runs, variable);
    let (mut snr, mut scatter) = (Vec::new(), Vec::new());
    for (i, out) in runs.iter().enumerate() {
        let analytic = out.snr.iter().filter(|r| r.snr_analytic.is_finite()).map(|r| (r.centre_nm, r.snr_analytic));
        snr.push(series(i, analytic.collect()));
        scatter.push(series(i, plot.scatter[i].iter().map(|p| (p[0], p[1])).collect()));
    }
    let slide = ReviewSlide {
        title,
        caption,
        label: kind.label().to_string(),
        scale,
        diverging: false,
        panels,
        snr,
        snr_requirement: state.requirements.snr,
        scatter,
        scatter_label: format!("({})", crate::metrics::unit(variable)),
        verdicts: table,
        parameters: parameter_table(state, &runs),
    };
    let fig = review_slide("comparison", &slide).map_err(|e| e.to_string())?;
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    write_bytes(&png, &fig.png).map_err(|e| e.to_string())?;
    write_bytes(&svg, fig.svg.as_bytes()).map_err(|e| e.to_string())?;
    let mut written = vec![png, svg];
    for (i, out) in runs.iter().enumerate() {
        let path = super::export::config_path(stem, i);
        let text = out.config.to_ron().map_err(|e| e.to_string())?;
        write_bytes(&path, text.as_bytes()).map_err(|e| e.to_string())?;
        written.push(path);
    }
    Ok(written)
}

/// The parameters the designs differ in, against the reference design chosen in the app.
fn parameter_table(state: &AppState, runs: &[&Arc<RunOutput>]) -> Vec<Vec<String>> {
    let reference = state.reference.min(runs.len() - 1);
    let order: Vec<usize> = std::iter::once(reference).chain((0..runs.len()).filter(|&i| i != reference)).collect();
    let names: Vec<String> = order.iter().map(|&i| super::model::label(i)).collect();
    let designs: Vec<(&str, &crate::instrument::InstrumentSpec, usize)> = order
        .iter()
        .zip(&names)
        .map(|(&i, n)| (n.as_str(), &runs[i].config.instrument, runs[i].response.bands.bands.len()))
        .collect();
    super::params::differences(&designs)
}

/// [`verdict_table`] turned round: a row per design ("C: nominal"), a column per product with
/// "MAE / bias %" and its verdict ("pass", "FAIL"), the SNR and bottom-type rows as columns.
fn by_design(wide: &[Vec<String>], names: &[String]) -> Vec<Vec<String>> {
    let mut header = vec!["MAE / bias %".to_string()];
    header.extend(wide.iter().skip(1).map(|r| r[0].clone()));
    let mut out = vec![header];
    for (i, name) in names.iter().enumerate() {
        let mut row = vec![name.clone()];
        for r in wide.iter().skip(1) {
            let Some(c) = r.get(1 + 4 * i..5 + 4 * i) else { continue };
            let value = if c[1].is_empty() { c[0].clone() } else { format!("{} / {}", c[0], c[1]) };
            let verdict = if c[3].starts_with("FAIL") { "FAIL" } else { c[3].as_str() };
            row.push(format!("{value} {verdict}").trim().to_string());
        }
        out.push(row);
    }
    out
}

/// The verdict table of the slide: one row per product with the designs side by side (MAE,
/// bias, returned share and the judgement of `Requirements::check_run`, the app's and `shoal
/// study`'s), then the SNR floor's row.
fn verdict_table(state: &AppState, runs: &[&Arc<RunOutput>]) -> Vec<Vec<String>> {
    let mut header = vec!["product".to_string()];
    for i in 0..runs.len() {
        let ab = super::model::label(i);
        // Short headings (every value is a %): the table must leave room for the parameters'.
        header.extend([format!("{ab} MAE"), format!("{ab} bias"), format!("{ab} ret."), ab.clone()]);
    }
    let checks: Vec<Vec<crate::study::Check>> = runs
        .iter()
        .map(|out| {
            let metrics = out.retrievals.first().map(|r| &r.metrics);
            state.requirements.check_run(
                &out.config.instrument.name,
                out.config.seed,
                metrics,
                &out.snr,
                &out.correction.rrs_metrics,
            )
        })
        .collect();
    // A pass under a plausibility warning (saturation, smear, no buildable f-number) reads
    // "pass?", as in the app's metrics table.
    let judged = |checks: &[crate::study::Check], variable: Option<&str>, out: &RunOutput| {
        let mine: Vec<&crate::study::Check> = checks.iter().filter(|c| c.variable.as_deref() == variable).collect();
        match crate::study::verdict(mine.iter().copied()) {
            Some(true) if !out.report.warnings.is_empty() => "pass?".to_string(),
            Some(true) => "pass".to_string(),
            Some(false) if variable.is_none() => {
                // The SNR floor: how many bands miss it (the SNR chart beside shows which).
                format!("FAIL: {} of {} bands", mine.iter().filter(|c| !c.pass).count(), mine.len())
            }
            Some(false) => {
                let name = variable.map_or("SNR", crate::metrics::name);
                let failed: Vec<String> = mine
                    .iter()
                    .filter(|c| !c.pass)
                    .map(|c| {
                        let what = variable.map_or_else(|| c.what.clone(), |v| c.what.replace(v, name));
                        what.replacen(&format!("{name} "), "", 1).trim_end_matches(" %").to_string()
                    })
                    .take(2)
                    .collect();
                format!("FAIL: {}", failed.join(", "))
            }
            None => String::new(),
        }
    };
    let mut table = vec![header];
    let variables: Vec<String> = runs
        .iter()
        .flat_map(|o| o.retrievals.iter().take(1).flat_map(|r| r.metrics.variables.iter().map(|v| v.variable.clone())))
        .fold(Vec::new(), |mut acc, v| {
            if !acc.contains(&v) {
                acc.push(v);
            }
            acc
        });
    for v in &variables {
        let mut row = vec![crate::metrics::label(v).to_string()];
        for (out, checks) in runs.iter().zip(&checks) {
            let m = out.retrievals.first().and_then(|r| r.metrics.get(v));
            match m {
                Some(m) if m.n > 0 => row.extend([
                    format!("{:.1}", m.mae_pct()),
                    format!("{:+.1}", m.bias_pct()),
                    format!("{:.1}", m.returned_pct),
                ]),
                Some(m) => row.extend(["–".into(), "–".into(), format!("{:.1}", m.returned_pct)]),
                None => row.extend(["–".into(), "–".into(), "–".into()]),
            }
            row.push(judged(checks, Some(v), out));
        }
        table.push(row);
    }
    let agreement = |o: &RunOutput| o.retrievals.first().and_then(|r| r.metrics.substrate_agreement_pct);
    if runs.iter().any(|o| agreement(o).is_some()) {
        let mut row = vec!["bottom type".to_string()];
        for (out, checks) in runs.iter().zip(&checks) {
            let right = agreement(out).map_or_else(|| "–".into(), |a| format!("{a:.1} % right"));
            row.extend([right, String::new(), String::new(), judged(checks, Some("substrate"), out)]);
        }
        table.push(row);
    }
    if state.requirements.snr.is_some() {
        let mut row = vec!["SNR, every band".to_string()];
        for (out, checks) in runs.iter().zip(&checks) {
            let saturated = out.snr.iter().filter(|r| r.saturated()).count();
            let lowest = out.snr.iter().map(|r| r.snr_analytic).reduce(f64::min);
            let value = if saturated > 0 {
                format!("{saturated} saturated")
            } else {
                lowest.map_or_else(|| "–".into(), |l| format!("lowest {l:.0}"))
            };
            row.extend([value, String::new(), String::new(), judged(checks, None, out)]);
        }
        table.push(row);
    }
    table
}
