//! The review pack's page: [`ReviewData`] and the study's figures as one HTML file. Figures are
//! inline SVG (their map rasters are PNG data URIs inside), the style sheet is inline, there is
//! no script and no reference outside the file: it opens from a USB stick, an e-mail or an
//! air-gapped review room, and prints.

use std::fmt::Write as _;

use super::ReviewData;

/// A figure for the page: its file stem and SVG text (and whether a PNG sits beside the page).
#[derive(Debug, Clone, PartialEq)]
pub struct PageFigure {
    /// File stem (`maps_alm_chl_mg_m3`).
    pub name: String,
    /// The SVG document.
    pub svg: String,
    /// Is `figures/<name>.png` written beside the page?
    pub png: bool,
}

pub use crate::markup::escape;

/// A file name as a URL path segment: unreserved characters kept, the rest percent-encoded
/// (RFC 3986), so a name with `#`, `?`, `%` or spaces still links to its file.
fn url_path(name: &str) -> String {
    name.bytes()
        .map(|b| {
            if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
                (b as char).to_string()
            } else {
                format!("%{b:02X}")
            }
        })
        .collect()
}

/// The page's Content Security Policy: no script, no connection, no resource from outside the
/// file (images only as `data:` URIs, the one inline style sheet). A second wall behind
/// [`super::svg::clean`]: a figure that slipped through could still run nothing and fetch nothing.
pub(super) const CSP: &str =
    "default-src 'none'; img-src data:; style-src 'unsafe-inline'; form-action 'none'; base-uri 'none'";

pub(super) const STYLE: &str = "
body { font: 15px/1.45 'DejaVu Sans', Verdana, sans-serif; color: #1b1b1b; margin: 0 auto; max-width: 1180px; padding: 24px 28px 60px; }
h1 { font-size: 26px; margin: 0 0 4px; } h2 { font-size: 20px; margin: 34px 0 10px; border-bottom: 2px solid #2a5d8f; padding-bottom: 3px; }
h3 { font-size: 16px; margin: 22px 0 6px; }
.lead { font-size: 16px; color: #333; margin: 0 0 14px; }
table { border-collapse: collapse; margin: 6px 0 14px; font-size: 13.5px; }
th, td { border: 1px solid #c9ced6; padding: 3px 8px; text-align: left; vertical-align: top; }
th { background: #eef2f7; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
tr.differs td { background: #fff6dc; }
.pass { color: #0d6b2f; font-weight: bold; } .fail { color: #b3141b; font-weight: bold; } .warn { color: #a35f00; font-weight: bold; }
.meta td:first-child { font-weight: bold; background: #f5f7fa; }
figure { margin: 14px 0 22px; } figure svg { max-width: 100%; height: auto; display: block; border: 1px solid #e1e4e8; }
figcaption { font-size: 13px; color: #444; margin-top: 4px; }
.row { display: flex; flex-wrap: wrap; gap: 12px; align-items: flex-start; } .row figure { margin: 8px 0; }
pre { background: #f6f8fa; border: 1px solid #e1e4e8; padding: 8px; overflow-x: auto; font-size: 12px; max-height: 420px; }
nav ol { columns: 2; font-size: 14px; } .note { color: #555; font-size: 13px; }
.summary { display: flex; gap: 14px; flex-wrap: wrap; margin: 8px 0 6px; }
.card { border: 1px solid #c9ced6; border-radius: 6px; padding: 8px 14px; min-width: 180px; }
.card b { font-size: 18px; }
@media print { body { font-size: 11px; padding: 0; } table { font-size: 9.5px; } th, td { padding: 1px 4px; } h2 { break-before: auto; } figure, table { break-inside: avoid; } pre { max-height: none; } }
";

pub(crate) fn num(v: f64, decimals: usize) -> String {
    if v.is_finite() { format!("{v:.decimals$}") } else { "–".into() }
}

/// The page.
#[must_use]
pub fn page(d: &ReviewData, figures: &[PageFigure]) -> String {
    let mut h = String::with_capacity(1 << 20);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta http-equiv=\"Content-Security-Policy\" content=\"{CSP}\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>Shoal review pack — {}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n",
        escape(&d.study)
    );
    header(&mut h, d);
    verdict(&mut h, d);
    instruments(&mut h, d);
    metrics(&mut h, d);
    figures_section(&mut h, figures);
    super::seasons::section(&mut h, d);
    super::substrate::section(&mut h, d);
    super::sections::aerosol(&mut h, d);
    super::sections::failures(&mut h, d);
    super::sections::budget_and_cost(&mut h, d);
    super::sections::provenance(&mut h, d);
    h += "<footer class=\"note\"><p>Made by Shoal, an end-to-end simulator of satellite optical instruments over water. This page needs no network and no script; every figure is inside it.</p></footer>\n</body>\n</html>\n";
    h
}

fn header(h: &mut String, d: &ReviewData) {
    let _ = write!(
        h,
        "<header>\n<p class=\"note\">Shoal review pack</p>\n<h1>{}</h1>\n<p class=\"lead\">{}</p>\n<table class=\"meta\">\n",
        escape(&d.study),
        escape(&d.study_description)
    );
    let names: Vec<&str> = d.instruments.iter().map(|i| i.label.as_str()).collect();
    for (k, v) in [
        ("Scene", format!("{} — {}", d.scene, d.scene_description)),
        ("Place", d.scene_place.clone()),
        ("Instruments", names.join(" vs ")),
        ("Made", d.created_utc.clone()),
        ("Shoal", format!("version {}, commit {}", d.version, d.commit)),
        ("Machine", d.machine.line()),
    ] {
        let _ = writeln!(h, "<tr><td>{k}</td><td>{}</td></tr>", escape(&v));
    }
    h.push_str("</table>\n");
    // Results at reduced resolution say so before anything else is read.
    let reduced: Vec<String> =
        d.instruments.iter().filter(|i| i.shape.3 > 1).map(|i| format!("{} at 1/{}", i.label, i.shape.3)).collect();
    if !reduced.is_empty() {
        let _ = writeln!(
            h,
            "<p class=\"fail\">Reduced resolution: {} (every n-th line and detector). Errors and verdicts are estimates from fewer pixels; run at full resolution for the review.</p>",
            escape(&reduced.join(", "))
        );
    }
    h.push_str("</header>\n<nav><ol>\n<li><a href=\"#verdict\">Verdict against the requirements</a></li>\n<li><a href=\"#instruments\">The instruments side by side</a></li>\n<li><a href=\"#metrics\">Product errors</a></li>\n<li><a href=\"#figures\">Figures</a></li>\n");
    if !d.seasons.is_empty() {
        h.push_str("<li><a href=\"#seasons\">Seasons</a></li>\n");
    }
    if !d.substrates.is_empty() {
        h.push_str("<li><a href=\"#substrate\">Bottom type</a></li>\n");
    }
    if !d.budget.is_empty() {
        h.push_str("<li><a href=\"#budget\">Error budget</a></li>\n");
    }
    if !d.cost.is_empty() {
        h.push_str("<li><a href=\"#cost\">Cost of accuracy</a></li>\n");
    }
    h.push_str("<li><a href=\"#provenance\">Provenance</a></li>\n</ol></nav>\n");
}

fn verdict(h: &mut String, d: &ReviewData) {
    h.push_str("<section id=\"verdict\">\n<h2>Verdict against the requirements</h2>\n");
    if d.checks.is_empty() {
        h.push_str(if d.has_requirements {
            "<p>The study's requirements apply to nothing these runs produced (a variable no retrieval returns, no SNR floor), so nothing is judged.</p>\n</section>\n"
        } else {
            "<p>The study states no requirements, so nothing is judged. Add <code>requirements</code> to the study file to get a verdict with margins.</p>\n</section>\n"
        });
        return;
    }
    h.push_str("<div class=\"summary\">\n");
    for inst in &d.instruments {
        let mine: Vec<_> = d.checks.iter().filter(|c| c.instrument == inst.label).collect();
        if mine.is_empty() {
            let _ = writeln!(
                h,
                "<div class=\"card\">{}<br><b>NOTHING JUDGED</b> — no check applies</div>",
                escape(&inst.label)
            );
            continue;
        }
        let passed = mine.iter().filter(|c| c.pass).count();
        let all = passed == mine.len();
        // A design that meets every number but is implausible over the scene (saturation,
        // smear, no buildable f-number) is not a plain pass: the app reads "pass?".
        let (class, word, but) = match (all, inst.warnings.is_empty()) {
            (true, true) => ("pass", "MEETS ALL", String::new()),
            (true, false) => ("warn", "MEETS ALL?", format!("; but implausible here: {}", inst.warnings.join("; "))),
            (false, _) => ("fail", "FAILS", String::new()),
        };
        let _ = writeln!(
            h,
            "<div class=\"card\">{}<br><b class=\"{class}\">{word}</b> — {passed} of {} checks met{}</div>",
            escape(&inst.label),
            mine.len(),
            escape(&but)
        );
    }
    let judged = if d.judged_retrieval.is_empty() {
        String::new()
    } else {
        format!(" Product requirements judge the study's first retrieval, {}.", escape(&d.judged_retrieval))
    };
    let _ = writeln!(
        h,
        "</div>\n<p class=\"note\">Margin: how far inside the limit (negative: outside), in the value's unit. A product with no pixel returned has no value and fails. <span class=\"warn\">pass?</span>: the numbers pass, but the design is implausible over this scene (it saturates, smears or has no buildable f-number; its warnings are under the instruments).{judged}</p>"
    );
    super::verdicts::tables(h, d);
    h.push_str("</section>\n");
}

fn instruments(h: &mut String, d: &ReviewData) {
    h.push_str("<section id=\"instruments\">\n<h2>The instruments side by side</h2>\n");
    let head: String = d.instruments.iter().map(|i| format!("<th>{}</th>", escape(&i.label))).collect();
    for i in &d.instruments {
        if !i.description.is_empty() {
            let _ = writeln!(h, "<p><b>{}</b>: {}</p>", escape(&i.label), escape(&i.description));
        }
    }
    let _ = writeln!(h, "<h3>Derived figures</h3>\n<table>\n<tr><th></th>{head}</tr>");
    for row in &d.derived {
        let cells: String = row.values.iter().map(|v| format!("<td class=\"num\">{}</td>", escape(v))).collect();
        let _ = writeln!(h, "<tr><td>{}</td>{cells}</tr>", escape(&row.name));
    }
    h.push_str("</table>\n");
    let differing: Vec<_> = d.parameters.iter().filter(|p| p.differs()).collect();
    let _ = writeln!(
        h,
        "<h3>Parameters that differ ({} of {})</h3>\n<table>\n<tr><th>parameter</th>{head}</tr>",
        differing.len(),
        d.parameters.len()
    );
    for p in &differing {
        let cells: String = p.values.iter().map(|v| format!("<td>{}</td>", escape(v))).collect();
        let _ = writeln!(h, "<tr class=\"differs\"><td>{}</td>{cells}</tr>", escape(&p.name));
    }
    h.push_str("</table>\n<details><summary>Every parameter</summary>\n<table>\n");
    let _ = writeln!(h, "<tr><th>parameter</th>{head}</tr>");
    for p in &d.parameters {
        let cells: String = p.values.iter().map(|v| format!("<td>{}</td>", escape(v))).collect();
        let class = if p.differs() { " class=\"differs\"" } else { "" };
        let _ = writeln!(h, "<tr{class}><td>{}</td>{cells}</tr>", escape(&p.name));
    }
    h.push_str("</table>\n</details>\n<h3>Feasibility</h3>\n");
    for i in &d.instruments {
        if i.warnings.is_empty() {
            let _ = writeln!(
                h,
                "<p><b>{}</b>: no plausibility guard crossed (peak signal below full scale, smear under a pixel, f-number at least 1).</p>",
                escape(&i.label)
            );
        } else {
            let _ = writeln!(h, "<p><b>{}</b>:</p><ul>", escape(&i.label));
            for w in &i.warnings {
                let _ = writeln!(h, "<li class=\"fail\">{}</li>", escape(w));
            }
            h.push_str("</ul>\n");
        }
        let _ = writeln!(
            h,
            "<details><summary>{}: per band (Q = λN/p; peak signal over full scale at the scene's brightest water)</summary>\n<table>\n<tr><th>band</th><th>centre nm</th><th>Q</th><th>peak / full scale</th></tr>",
            escape(&i.label)
        );
        for (band, centre, q, peak) in &i.feasibility {
            let class = if *peak >= 1.0 { " class=\"fail\"" } else { "" };
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\"{class}>{} %</td></tr>",
                escape(band),
                num(*centre, 1),
                num(*q, 2),
                num(100.0 * peak, 1)
            );
        }
        h.push_str("</table>\n</details>\n");
    }
    h.push_str("</section>\n");
}

fn metrics(h: &mut String, d: &ReviewData) {
    h.push_str("<section id=\"metrics\">\n<h2>Product errors</h2>\n<p class=\"note\">Log-space MAE and bias (Seegers et al. 2018) of each retrieved variable against the truth, over the water pixels; with several noise seeds, ± is the standard deviation of the MAE over them.</p>\n<table>\n<tr><th>instrument</th><th>retrieval</th><th>variable</th><th>MAE %</th><th>bias %</th><th>returned %</th><th>pixels</th><th>seeds</th></tr>\n");
    for m in &d.metrics {
        let spread = if m.seeds > 1 { format!(" ± {}", num(m.mae_pct_sd, 1)) } else { String::new() };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td class=\"num\">{}{spread}</td><td class=\"num\">{:+.1}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            escape(&m.instrument),
            escape(&m.product),
            escape(&m.variable),
            num(m.mae_pct, 1),
            m.bias_pct,
            num(m.returned_pct, 1),
            m.n,
            m.seeds
        );
    }
    h.push_str("</table>\n</section>\n");
}

/// "aLMI chl-a" for the key `alm_chl_mg_m3` of a figure's file stem.
fn describe_key(key: &str) -> String {
    let (retrieval, variable) = key.split_once('_').unwrap_or((key, ""));
    let retrieval = crate::retrieval::title_of(if retrieval == "almi" { "alm" } else { retrieval });
    let variable = match variable {
        "chl_mg_m3" => "chlorophyll-a",
        "nap_g_m3" => "NAP",
        "cdom_per_m" => "CDOM absorption",
        "depth_m" => "depth",
        "substrate" => "bottom type (dominant substrate)",
        other => other,
    };
    format!("{retrieval} {variable}")
}

/// A figure's caption from its file stem.
fn caption(name: &str) -> String {
    let (kind, rest) = name.split_once('_').unwrap_or((name, ""));
    let what = describe_key(rest);
    match kind {
        "snr" => "SNR per band at the scene's median water radiance: analytic (line) and measured in the noisy cube (open circles); a dashed line, when drawn, is the study's SNR requirement.".into(),
        "rrs" if rest == "error" => "The corrected Rrs against the truth per band, log-space over the water pixels (as ACIX-Aqua reports an atmospheric correction): MAE (filled, line) and |bias| (open circles) per instrument; a dashed line, when drawn, is the study's Rrs requirement over its band range.".into(),
        "optics" => "The designs' optics: the system MTF against spatial frequency along (solid) and across (dashed) track at 560 nm from each design's MTF budget (an ideal optic's where it states none), Nyquist dashed; and, for designs that state stray light, the stray signal at 443 nm past the edge of a half-bright field relative to the bright half (Metop-3MI's test).".into(),
        "spectrum" => "The scene at a typical water pixel (median true chl-a), 350–2500 nm: TOA radiance (black), path radiance (grey) and true Rrs, the forward model every nm; each instrument's bands shaded at their FWHM, its Level-1 radiance and corrected Rrs there as dots.".into(),
        "maps" if rest.ends_with("substrate") => "The dominant substrate of the truth and of each instrument's retrieval, one colour per substrate; grey: land or not returned; scale bars give the ground distance.".into(),
        "maps" => format!("Truth and each instrument's retrieval ({what}) on one colour scale; grey: land or not returned; scale bars give the ground distance."),
        "agreement" => format!("Where each instrument's {what} is the truth's (green) or not (red), with the share right."),
        "difference" => format!("A − B ({what}): B sampled at the pixel nearest each of A's ground points; diverging scale symmetric about zero."),
        "scatter" => format!("Retrieved against true ({what}), pixel density on log axes; the line is 1:1."),
        "histogram" => format!("Distribution of retrieved values ({what}) by SIOP set or dominant substrate; the outline is the truth."),
        "season" if rest == "valid_looks" => "Valid looks per month of the season per design: passes with the sun high enough, the site in the swath, no high glint and clear enough.".into(),
        "season" => "A product's error look by look through the season, per design: each point one valid look run through the chain at its own sun, view, date and clouds; a dashed line, when drawn, is the study's requirement.".into(),
        "sweep" => "Trade-off curve from `shoal sweep`: the MAE against the swept parameter for each instrument, with the noise seeds' range and the requirement.".into(),
        _ => what,
    }
}

fn figures_section(h: &mut String, figures: &[PageFigure]) {
    h.push_str("<section id=\"figures\">\n<h2>Figures</h2>\n");
    if figures.is_empty() {
        h.push_str("<p>No figures were drawn for these results.</p>\n");
    }
    let mut shown = vec![false; figures.len()];
    let put = |h: &mut String, f: &PageFigure| {
        let svg = match super::svg::clean(&f.svg) {
            // Read aloud as one image with its caption.
            Ok(svg) => svg.replacen("<svg", "<svg role=\"img\"", 1),
            Err(refused) => {
                let _ = writeln!(
                    h,
                    "<p class=\"fail\" id=\"fig-{}\">Figure {} left out: {}.</p>",
                    escape(&f.name),
                    escape(&f.name),
                    escape(&refused.to_string())
                );
                return;
            }
        };
        let link = if f.png {
            format!(" <a href=\"figures/{}.png\">PNG</a>", escape(&url_path(&f.name)))
        } else {
            String::new()
        };
        let _ = write!(
            h,
            "<figure id=\"fig-{}\">\n{}\n<figcaption>{}{link}</figcaption>\n</figure>\n",
            escape(&f.name),
            svg,
            escape(&caption(&f.name))
        );
    };
    // SNR, Rrs error and the spectrum first, then per variable: maps beside their A − B, scatter and histograms.
    for (i, f) in figures.iter().enumerate() {
        if ["snr", "optics", "rrs_error", "spectrum"].contains(&f.name.as_str()) {
            put(h, f);
            shown[i] = true;
        }
    }
    // Variables in the order of the chain's products, whatever order the figures came in.
    let priority = |name: &str| {
        ["chl_mg_m3", "nap_g_m3", "cdom_per_m", "depth_m", "substrate"]
            .iter()
            .position(|v| name.ends_with(v))
            .unwrap_or(9)
    };
    let mut maps: Vec<usize> = (0..figures.len()).filter(|&i| figures[i].name.starts_with("maps_")).collect();
    maps.sort_by_key(|&i| (priority(&figures[i].name), figures[i].name.clone()));
    for i in maps {
        let f = &figures[i];
        let Some(key) = f.name.strip_prefix("maps_") else { continue };
        let _ = writeln!(h, "<h3>{}</h3>\n<div class=\"row\">", escape(&describe_key(key)));
        put(h, f);
        shown[i] = true;
        for kind in ["difference", "agreement", "scatter", "histogram"] {
            if let Some(j) = figures.iter().position(|g| g.name == format!("{kind}_{key}")) {
                put(h, &figures[j]);
                shown[j] = true;
            }
        }
        h.push_str("</div>\n");
    }
    let rest: Vec<&PageFigure> = figures.iter().zip(&shown).filter(|(_, s)| !**s).map(|(f, _)| f).collect();
    if !rest.is_empty() {
        let sweeps = rest.iter().all(|f| f.name.starts_with("sweep_"));
        h.push_str(if sweeps { "<h3>Trade-off curves</h3>\n" } else { "<h3>Other figures</h3>\n" });
        for f in rest {
            put(h, f);
        }
    }
    h.push_str("</section>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped_and_file_names_are_url_encoded() {
        assert_eq!(escape("a < b & \"c\""), "a &lt; b &amp; &quot;c&quot;");

        assert_eq!(url_path("sweep_chl #2?"), "sweep_chl%20%232%3F");
    }
}
