//! The pack's verdict tables: one row per requirement, the designs as columns (four to a table,
//! so eight designs print within an A4 page), each cell the value, its margin and the verdict.
//! Per-band checks (SNR, Rrs) differ in their bands from design to design: each family is one
//! row ("SNR, every band ≥ 100": the lowest band and how many miss), its bands listed below.

use std::fmt::Write as _;

use super::CheckRow as Check;
use super::ReviewData;
use super::html::{escape, num};

/// Designs per table: eight columns of value, margin and verdict do not fit a printed page.
const PER_TABLE: usize = 4;

/// The family of a per-band check ("SNR" of "SNR Oa03 (443 nm)"), `None` for a product's.
fn band_family(c: &Check) -> Option<&'static str> {
    // (A product's check begins with its variable's key, `chl_mg_m3 MAE`.)
    ["SNR ", "Rrs "].into_iter().find(|p| c.what.starts_with(p)).map(str::trim_end)
}

/// The band of a per-band check ("Oa03 (443 nm)").
fn band_of(c: &Check) -> &str {
    let rest = c.what.split_once(' ').map_or(c.what.as_str(), |(_, r)| r);
    rest.split(", saturated").next().unwrap_or(rest).trim_end_matches(" MAE %")
}

/// The verdict's class and word: a pass under a plausibility warning reads "pass?".
fn word(pass: bool, warned: bool) -> (&'static str, &'static str) {
    match (pass, warned) {
        (true, false) => ("pass", "pass"),
        (true, true) => ("warn", "pass?"),
        (false, _) => ("fail", "FAIL"),
    }
}

/// One row of the table: a requirement of a product or the design, or a family of per-band
/// checks.
enum Row<'a> {
    One { seed: u64, what: &'a str, limit: f64 },
    Bands { seed: u64, family: &'static str, limit: f64 },
}

/// The verdict tables and, folded, every per-band check.
pub(super) fn tables(h: &mut String, d: &ReviewData) {
    let mut rows: Vec<Row<'_>> = Vec::new();
    for c in &d.checks {
        let known = rows.iter().any(|r| match (r, band_family(c)) {
            (Row::One { seed, what, .. }, None) => *seed == c.seed && *what == c.what,
            (Row::Bands { seed, family, .. }, Some(f)) => *seed == c.seed && *family == f,
            _ => false,
        });
        if !known {
            rows.push(match band_family(c) {
                Some(family) => Row::Bands { seed: c.seed, family, limit: c.limit },
                None => Row::One { seed: c.seed, what: &c.what, limit: c.limit },
            });
        }
    }
    let seeds: Vec<u64> = d.checks.iter().map(|c| c.seed).collect();
    let several_seeds = seeds.iter().any(|&s| s != seeds[0]);
    let of = |label: &str, seed: u64| -> Vec<&Check> {
        d.checks.iter().filter(|c| c.instrument == label && c.seed == seed).collect()
    };
    let chunks: Vec<&[super::InstrumentSummary]> = d.instruments.chunks(PER_TABLE).collect();
    for (k, chunk) in chunks.iter().enumerate() {
        if chunks.len() > 1 {
            let _ = writeln!(h, "<h3>Designs {} to {}</h3>", k * PER_TABLE + 1, k * PER_TABLE + chunk.len());
        }
        h.push_str("<table class=\"verdicts\">\n<tr><th>requirement</th><th>limit</th>");
        for i in *chunk {
            let _ = write!(h, "<th>{}</th>", escape(&i.label));
        }
        h.push_str("</tr>\n<tr><th></th><th></th>");
        for _ in *chunk {
            h.push_str("<th class=\"num\">value (margin) verdict</th>");
        }
        h.push_str("</tr>\n");
        for row in &rows {
            let (seed, name, limit) = match row {
                Row::One { seed, what, limit } => (*seed, (*what).to_string(), *limit),
                Row::Bands { seed, family, limit } => {
                    let at = if *family == "SNR" { "≥" } else { "≤" };
                    (*seed, format!("{family}, every band {at}"), *limit)
                }
            };
            let name = if several_seeds { format!("{name} (seed {seed})") } else { name };
            let _ = write!(h, "<tr><td>{}</td><td class=\"num\">{}</td>", escape(&name), num(limit, 1));
            for inst in *chunk {
                let warned = !inst.warnings.is_empty();
                let mine = of(&inst.label, seed);
                let cell = match row {
                    Row::One { what, .. } => mine.iter().find(|c| c.what == *what).map(|c| {
                        let (class, w) = word(c.pass, warned);
                        let value = c.value.map_or_else(|| "none".into(), |v| num(v, 1));
                        let margin = c.margin.map_or_else(|| "no pixel".into(), |m| format!("{m:+.1}"));
                        format!("{value} ({margin}) <span class=\"{class}\">{w}</span>")
                    }),
                    Row::Bands { family, .. } => {
                        let bands: Vec<&&Check> = mine.iter().filter(|c| band_family(c) == Some(*family)).collect();
                        let worst = bands.iter().min_by(|a, b| {
                            a.margin.unwrap_or(f64::NEG_INFINITY).total_cmp(&b.margin.unwrap_or(f64::NEG_INFINITY))
                        });
                        worst.map(|c| {
                            let missed = bands.iter().filter(|c| !c.pass).count();
                            let (class, w) = word(missed == 0, warned);
                            let value = c.value.map_or_else(|| "none".into(), |v| num(v, 1));
                            let of_n =
                                if missed > 0 { format!("; {missed} of {} miss", bands.len()) } else { String::new() };
                            format!(
                                "worst {value}, {}{of_n} <span class=\"{class}\">{w}</span>",
                                escape(band_of(c).split(" (").next().unwrap_or_default())
                            )
                        })
                    }
                };
                let _ = write!(h, "<td class=\"num\">{}</td>", cell.unwrap_or_else(|| "–".into()));
            }
            h.push_str("</tr>\n");
        }
        h.push_str("</table>\n");
    }
    band_details(h, d);
}

/// Every per-band check, per design, folded under the tables (the SNR figure shows them too).
fn band_details(h: &mut String, d: &ReviewData) {
    if !d.checks.iter().any(|c| band_family(c).is_some()) {
        return;
    }
    h.push_str("<details><summary>Every band's check</summary>\n");
    for inst in &d.instruments {
        let warned = !inst.warnings.is_empty();
        let bands: Vec<String> = d
            .checks
            .iter()
            .filter(|c| c.instrument == inst.label && band_family(c).is_some())
            .map(|c| {
                let (class, w) = word(c.pass, warned);
                let value = c.value.map_or_else(|| "none".into(), |v| num(v, 1));
                format!("{} {} <span class=\"{class}\">{w}</span>", escape(&c.what), value)
            })
            .collect();
        let _ = writeln!(h, "<p><b>{}</b>: {}</p>", escape(&inst.label), bands.join("; "));
    }
    h.push_str("</details>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eight designs with different bands: one SNR row (not one per band, mostly "–"), four
    /// designs to a table, the worst band and how many miss.
    #[test]
    fn eight_designs_make_two_tables_of_four_with_one_snr_row() {
        let label = |i: usize| format!("{}: design", char::from(b'A' + i as u8));
        let mut d = ReviewData {
            instruments: (0..8)
                .map(|i| super::super::InstrumentSummary { label: label(i), ..Default::default() })
                .collect(),
            ..Default::default()
        };
        d.instruments[2].warnings = vec!["smears 1.05 px".into()];
        for i in 0..8 {
            let check = |what: String, value: f64, limit: f64, at_most: bool| {
                let margin = if at_most { limit - value } else { value - limit };
                Check {
                    instrument: label(i),
                    seed: 1,
                    what,
                    value: Some(value),
                    limit,
                    pass: margin >= 0.0,
                    margin: Some(margin),
                }
            };
            d.checks.push(check("chl_mg_m3 MAE %".into(), 10.0 + i as f64, 20.0, true));
            // Each design its own bands: 4 + i of them, the first i below the floor.
            for b in 0..4 + i {
                let snr = if b < i { 50.0 } else { 150.0 + b as f64 };
                d.checks.push(check(format!("SNR D{i}B{b} ({} nm)", 400 + 10 * b), snr, 100.0, false));
            }
        }
        let mut h = String::new();
        tables(&mut h, &d);
        assert_eq!(h.matches("<table class=\"verdicts\">").count(), 2, "{h}");
        assert_eq!(h.matches("<td>SNR, every band ≥</td>").count(), 2, "one SNR row per table");
        assert!(!h.contains("<td>SNR D"), "no row per band");
        let first = &h[..h.find("</table>").unwrap()];
        assert_eq!(first.matches("<th>").count(), 2 + 4 + 2, "requirement, limit, four designs; two blank heads");
        assert!(first.contains("worst 150.0, D0B0 <span class=\"pass\">pass</span>"), "{first}");
        assert!(first.contains("worst 50.0, D3B0; 3 of 7 miss <span class=\"fail\">FAIL</span>"), "{first}");
        assert!(first.contains("12.0 (+8.0) <span class=\"warn\">pass?</span>"), "C passes under a warning");
        assert!(h.contains("<details><summary>Every band's check</summary>") && h.contains("SNR D7B10 (500 nm)"));
    }
}
