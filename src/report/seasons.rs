//! The review pack's season section: for each season given (`shoal report … --season DIR`), how
//! often each design sees the site well enough and what its products' error is over those
//! looks. What is shown was read from a folder: every text is escaped, every number formatted.

use std::fmt::Write as _;

use super::ReviewData;
use super::html::{escape, num};
use crate::season::summary::SeasonSummary;

fn opt(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "–".into(), |v| num(v, decimals))
}

/// One season's tables.
fn season(h: &mut String, s: &SeasonSummary) {
    let _ = writeln!(
        h,
        "<h3>{}</h3>\n<p>{}</p>\n<p class=\"note\">Study {}; site {}° N, {}° E; {} to {}; {}; roll up to {}°, glint tilt {}°; {}; each valid look run at decimation {}.</p>",
        escape(&s.name),
        escape(&s.description),
        escape(&s.study),
        num(s.site.0, 2),
        num(s.site.1, 2),
        escape(&s.from),
        escape(&s.to),
        escape(&s.orbit),
        num(s.max_roll_deg, 1),
        num(s.glint_tilt_deg, 1),
        escape(&s.clouds),
        s.decimation
    );
    let revisit = s.revisit.map(|(days, pct)| format!("within {} d on {} % of days", num(days, 1), num(pct, 0)));
    let _ = writeln!(
        h,
        "<table>\n<tr><th>design</th><th>passes</th><th>valid</th><th>sun low</th><th>view oblique</th><th>glint</th><th>cloud</th><th>gap median d</th><th>gap 90 % d</th><th>revisit{}</th><th>valid over orbit phases (min–median–max)</th></tr>",
        revisit.as_ref().map_or_else(String::new, |r| format!(" ({})", escape(r)))
    );
    for d in &s.designs {
        let [valid, sun, view, glint, cloud] = d.by_verdict;
        let revisit = match d.revisit {
            Some((pct, ok)) => {
                format!(
                    "<span class=\"{}\">{} % {}</span>",
                    if ok { "pass" } else { "fail" },
                    num(pct, 1),
                    if ok { "pass" } else { "FAIL" }
                )
            }
            None => "–".into(),
        };
        let phases = d.phase_valid.map_or_else(
            || "–".into(),
            |(a, b, c)| format!("{}–{}–{} over {}", num(a, 0), num(b, 0), num(c, 0), d.phases),
        );
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{valid}</td><td class=\"num\">{sun}</td><td class=\"num\">{view}</td><td class=\"num\">{glint}</td><td class=\"num\">{cloud}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td>{revisit}</td><td>{phases}</td></tr>",
            escape(&d.label),
            d.passes,
            opt(d.gap_median_d, 1),
            opt(d.gap_p90_d, 1),
        );
    }
    h.push_str("</table>\n");
    if s.designs.iter().all(|d| d.products.is_empty()) {
        h.push_str(
            "<p class=\"note\">No look was run through the chain (max_runs 0): the looks and revisit only.</p>\n",
        );
        return;
    }
    h.push_str("<table>\n<tr><th>design</th><th>product</th><th>looks run</th><th>MAE % median</th><th>10–90 %</th><th>worst</th><th>returned % median</th><th>least</th></tr>\n");
    for d in &s.designs {
        for p in &d.products {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{} {}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}–{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
                escape(&d.label),
                escape(&p.product),
                escape(&p.variable),
                p.looks,
                num(p.mae_median_pct, 1),
                num(p.mae_p10_pct, 1),
                num(p.mae_p90_pct, 1),
                num(p.mae_worst_pct, 1),
                num(p.returned_median_pct, 1),
                num(p.returned_least_pct, 1)
            );
        }
        for f in &d.failures {
            let _ =
                writeln!(h, "<tr><td>{}</td><td colspan=\"7\">a run failed: {}</td></tr>", escape(&d.label), escape(f));
        }
    }
    h.push_str("</table>\n");
}

/// The season section, when seasons were given.
pub(super) fn section(h: &mut String, d: &ReviewData) {
    if d.seasons.is_empty() {
        return;
    }
    h.push_str("<section id=\"seasons\">\n<h2>Seasons: how often and how well</h2>\n<p class=\"note\">Each design's passes over the site in the period (its own sun-synchronous orbit, or a spacecraft's two-line elements), each judged as a processor would: sun high enough, the site inside the swath and not too oblique, no high glint (Cox–Munk, l2gen's threshold), clear enough under a cover drawn from the month's cloud fraction. Up to <code>max_runs</code> valid looks are run through the whole chain at their own geometry with their clouds in the scene; the errors are log-space MAE over the water each look returned. The season figures are in Figures.</p>\n");
    for s in &d.seasons {
        season(h, s);
    }
    h.push_str("</section>\n");
}
