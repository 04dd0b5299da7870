//! The review pack's bottom-type section, for a study whose retrieval unmixes substrates: per
//! instrument, how often the dominant substrate is right, the confusion table (true class
//! against retrieved class, as shares of each true class), and the depth error over each true
//! substrate (a dark bottom hides depth differently from a bright one).

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use super::ReviewData;
use super::html::escape;
use crate::study::StudyResult;

/// One instrument's bottom-type results (first seed).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SubstrateSummary {
    /// Instrument.
    pub instrument: String,
    /// Retrieval.
    pub product: String,
    /// Classes, in the confusion table's order.
    pub classes: Vec<String>,
    /// Pixels, (true class, retrieved class).
    pub counts: Vec<Vec<usize>>,
    /// Share of pixels whose dominant substrate is right, %.
    pub agreement_pct: Option<f64>,
    /// Depth over each true dominant substrate: (substrate, log-space MAE %, mean |error| m, pixels).
    pub depth: Vec<(String, f64, f64, usize)>,
}

/// The summaries of `result`'s runs (first seed of each instrument, first retrieval that
/// unmixes substrates); empty when none does.
#[must_use]
pub fn summaries(result: &StudyResult) -> Vec<SubstrateSummary> {
    let mut seen: Vec<&str> = Vec::new();
    let mut out = Vec::new();
    for run in &result.runs {
        if seen.contains(&run.label.as_str()) {
            continue;
        }
        seen.push(&run.label);
        let Some(ret) = run.retrievals.iter().find(|r| r.metrics.substrate_confusion.is_some()) else { continue };
        let m = &ret.metrics;
        let Some(c) = &m.substrate_confusion else { continue };
        out.push(SubstrateSummary {
            instrument: run.label.clone(),
            product: m.product.clone(),
            classes: c.classes.clone(),
            counts: c.counts.clone(),
            agreement_pct: m.substrate_agreement_pct,
            depth: m
                .depth_by_true_substrate
                .iter()
                .map(|v| (v.variable.clone(), v.metrics.mae_pct(), v.metrics.mean_abs_error, v.metrics.n))
                .collect(),
        });
    }
    out
}

/// The section (nothing when no retrieval unmixes substrates).
pub(super) fn section(h: &mut String, d: &ReviewData) {
    if d.substrates.is_empty() {
        return;
    }
    h.push_str("<section id=\"substrate\">\n<h2>Bottom type</h2>\n<p class=\"note\">The dominant substrate of each returned water pixel (the one with the largest fraction) against the truth's. Rows: the true class; cells: the share of its pixels retrieved as each class; the diagonal is right. The depth error is split by the true dominant substrate.</p>\n");
    for s in &d.substrates {
        let agreement = s.agreement_pct.map_or_else(|| "–".into(), |a| format!("{a:.1} %"));
        let _ = writeln!(
            h,
            "<h3>{} ({}): dominant substrate right in {agreement} of pixels</h3>\n<table>\n<tr><th>true \\ retrieved</th>",
            escape(&s.instrument),
            escape(&s.product)
        );
        for c in &s.classes {
            let _ = write!(h, "<th>{}</th>", escape(&c.replace('_', " ")));
        }
        h.push_str("<th>pixels</th></tr>\n");
        for (t, row) in s.counts.iter().enumerate() {
            let n: usize = row.iter().sum();
            if n == 0 {
                continue;
            }
            let _ =
                write!(h, "<tr><td>{}</td>", escape(&s.classes.get(t).map_or(String::new(), |c| c.replace('_', " "))));
            for (k, &count) in row.iter().enumerate() {
                let share = 100.0 * count as f64 / n as f64;
                let class = if k == t { " class=\"num pass\"" } else { " class=\"num\"" };
                let _ = write!(h, "<td{class}>{share:.0} %</td>");
            }
            let _ = writeln!(h, "<td class=\"num\">{n}</td></tr>");
        }
        h.push_str("</table>\n");
        if !s.depth.is_empty() {
            h.push_str("<table>\n<tr><th>depth over</th><th>MAE %</th><th>mean |error| (m)</th><th>pixels</th></tr>\n");
            for (what, mae, abs, n) in &s.depth {
                // `depth_m_over_turf_algae` → "turf algae".
                let over = what.strip_prefix("depth_m_over_").unwrap_or(what).replace('_', " ");
                let _ = writeln!(
                    h,
                    "<tr><td>{}</td><td class=\"num\">{mae:.1}</td><td class=\"num\">{abs:.2}</td><td class=\"num\">{n}</td></tr>",
                    escape(&over)
                );
            }
            h.push_str("</table>\n");
        }
    }
    h.push_str("</section>\n");
}
