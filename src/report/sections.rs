//! The review pack's closing sections: the error budget and the cost of accuracy when they were
//! run, and the provenance — data files with their sources and licences, the resolved
//! configurations to download, the stage timings and the machine.

use std::fmt::Write as _;

use super::ReviewData;
use super::html::{escape, num};
use crate::study::base64;

/// A provenance cell as written in Markdown (`**bold**`, `` `code` ``), escaped, with those two
/// marks as HTML (links and the rest stay text).
fn inline_markdown(s: &str) -> String {
    let mut out = String::new();
    for (i, part) in escape(s).split('`').enumerate() {
        if i % 2 == 1 {
            out.push_str(&format!("<code>{part}</code>"));
            continue;
        }
        for (j, piece) in part.split("**").enumerate() {
            if j % 2 == 1 {
                out.push_str(&format!("<b>{piece}</b>"));
            } else {
                out.push_str(piece);
            }
        }
    }
    out
}

/// Retrievals whose program returned nothing, and why (its own words, escaped).
pub(super) fn failures(h: &mut String, d: &ReviewData) {
    if d.failures.is_empty() {
        return;
    }
    h.push_str("<section id=\"failures\">\n<h2>Retrievals that returned nothing</h2>\n<p class=\"note\">An external retrieval's program failed on these runs; the rest of each run is in the tables above. The reason ends with the program's own standard error.</p>\n<table>\n<tr><th>instrument</th><th>retrieval</th><th>why</th></tr>\n");
    for (instrument, retrieval, why) in &d.failures {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td><pre>{}</pre></td></tr>",
            escape(instrument),
            escape(retrieval),
            escape(why)
        );
    }
    h.push_str("</table>\n</section>\n");
}

/// The aerosol an image-based correction found from each design's own bands, against the truth.
pub(super) fn aerosol(h: &mut String, d: &ReviewData) {
    if d.aerosol.is_empty() {
        return;
    }
    h.push_str("<section id=\"aerosol\">\n<h2>Aerosol the correction found</h2>\n<p class=\"note\">The image-based correction knows nothing of the scene's atmosphere: it finds the aerosol from the design's own Level-1. AOT(550) over the water pixels (median, 5–95 %) against the scene's; the per-pixel error is the median |retrieved − true| with each pixel against the AOT under it; Ångström exponent 443–865 nm; the share of pixels whose band ratio lay outside the family of models; the band ratio ε measured at the pair (median, 5–95 %) against each model's: two models closer than its spread cannot be told apart.</p>\n<table>\n<tr><th>instrument</th><th>correction</th><th>AOT(550) found</th><th>5–95 %</th><th>true</th><th>per-pixel error</th><th>Ångström found</th><th>true</th><th>outside family %</th><th>ε at the pair</th><th>the models' ε</th></tr>\n");
    for row in &d.aerosol {
        let a = &row.found;
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}–{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{} ({}–{})</td><td>{}</td></tr>",
            escape(&row.instrument),
            escape(&a.fit),
            num(a.aot550.0, 3),
            num(a.aot550.1, 3),
            num(a.aot550.2, 3),
            num(a.aot550_true, 3),
            num(a.aot550_abs_error, 3),
            num(a.angstrom, 2),
            num(a.angstrom_true, 2),
            num(a.outside_family_pct, 1),
            num(a.epsilon.0, 4),
            num(a.epsilon.1, 4),
            num(a.epsilon.2, 4),
            escape(&a.members_epsilon.iter().map(|(m, e)| format!("{m} {e:.4}")).collect::<Vec<_>>().join(", "))
        );
    }
    h.push_str("</table>\n</section>\n");
}

pub(super) fn budget_and_cost(h: &mut String, d: &ReviewData) {
    if !d.budget.is_empty() {
        h.push_str("<section id=\"budget\">\n<h2>Error budget</h2>\n<p class=\"note\">Each stage of the chain made perfect in turn (sequential share: the MAE it removes after those before it) and alone (the MAE with only this stage imperfect, above the floor). Points of %.</p>\n<table>\n<tr><th>instrument</th><th>variable</th><th>full MAE %</th><th>stage</th><th>sequential share</th><th>alone share</th><th>floor MAE %</th></tr>\n");
        for (inst, var, full, stage, seq, alone, floor) in &d.budget {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
                escape(inst),
                escape(var),
                num(*full, 1),
                escape(stage),
                num(*seq, 1),
                num(*alone, 1),
                num(*floor, 1)
            );
        }
        h.push_str("</table>\n</section>\n");
    }
    if !d.cost.is_empty() {
        h.push_str("<section id=\"cost\">\n<h2>Cost of accuracy</h2>\n<p class=\"note\">");
        h.push_str(&escape(crate::sweep::COST_METHOD));
        h.push_str(" Error: per-pixel chl-a difference from the reference run, median and 95th percentile (an error that lives at edges or in a few hard pixels shows in the second while the first stays at zero).</p>\n<table>\n<tr><th>setting</th><th>runs</th><th>wall s (median)</th><th>range</th><th>CPU s</th><th>vs reference, paired by round (wall; CPU)</th><th>chl per pixel %</th><th>p95 %</th></tr>\n");
        for (setting, n, wall, range, cpu, vs, err, p95) in &d.cost {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td class=\"num\">{n}</td><td class=\"num\">{}</td><td class=\"num\">{}–{}</td><td class=\"num\">{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
                escape(setting),
                num(*wall, 2),
                num(range.0, 2),
                num(range.1, 2),
                cpu.map_or_else(|| "–".into(), |c| num(c, 2)),
                escape(vs),
                err.map_or_else(|| "other grid".into(), |e| num(e, 3)),
                p95.map_or_else(|| "–".into(), |e| num(e, 3))
            );
        }
        h.push_str("</table>\n</section>\n");
    }
}

pub(super) fn provenance(h: &mut String, d: &ReviewData) {
    h.push_str("<section id=\"provenance\">\n<h2>Provenance</h2>\n<h3>Data</h3>\n");
    if d.data_sources.is_empty() {
        h.push_str("<p>No embedded data file was recorded for these results.</p>\n");
    } else {
        h.push_str("<p class=\"note\">The embedded data files read to make these results, with their sources and licences (the full index and licence texts are in Shoal's <code>assets/PROVENANCE.md</code> and <code>assets/licenses/</code>).</p>\n<table>\n<tr><th>files</th><th>content</th><th>source</th><th>licence</th></tr>\n");
        for (files, content, source, licence) in &d.data_sources {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                inline_markdown(files),
                inline_markdown(content),
                inline_markdown(source),
                inline_markdown(licence)
            );
        }
        h.push_str("</table>\n");
    }
    h.push_str("<h3>Configurations</h3>\n<p class=\"note\">The resolved run configuration of each instrument: <code>shoal simulate --config FILE</code> reruns it exactly.</p>\n");
    let download = |name: &str, text: &str| {
        format!(
            "<a download=\"{}\" href=\"data:text/plain;charset=utf-8;base64,{}\">download {}</a>",
            escape(name),
            base64(text.as_bytes()),
            escape(name)
        )
    };
    for i in &d.instruments {
        let file = format!("{}.ron", i.label);
        let _ = writeln!(
            h,
            "<details><summary>{} — {}</summary>\n<pre>{}</pre>\n</details>",
            escape(&i.label),
            download(&file, &i.config_ron),
            escape(&i.config_ron)
        );
    }
    let _ = writeln!(
        h,
        "<details><summary>study — {}</summary>\n<pre>{}</pre>\n</details>",
        download(&format!("{}.ron", d.study), &d.study_ron),
        escape(&d.study_ron)
    );
    h.push_str("<h3>Stage timings</h3>\n<p class=\"note\">Seconds per stage of the first run of each instrument (\"cached\": reused from an earlier run whose inputs had not changed).</p>\n");
    for i in &d.instruments {
        let (rows, cols, bands, decimation) = i.shape;
        let _ = writeln!(
            h,
            "<p><b>{}</b>: {rows} lines × {cols} detectors × {bands} bands ({}), {} s in all.</p>\n<table>\n<tr><th>stage</th><th></th><th>s</th></tr>",
            escape(&i.label),
            if decimation == 1 {
                "full resolution".to_string()
            } else {
                format!("preview: every {decimation}th line and detector")
            },
            num(i.total_seconds, 2)
        );
        for (stage, status, s) in &i.stages {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td></tr>",
                escape(stage),
                escape(status),
                num(*s, 3)
            );
        }
        h.push_str("</table>\n");
    }
    let _ = writeln!(h, "<h3>Machine</h3>\n<p>{}</p>\n</section>", escape(&d.machine.line()));
}

#[cfg(test)]
mod tests {
    #[test]
    fn provenance_markdown_becomes_html_and_the_rest_is_escaped() {
        assert_eq!(
            super::inline_markdown("**computed** by `shoal dev` <x>"),
            "<b>computed</b> by <code>shoal dev</code> &lt;x&gt;"
        );
    }
}
