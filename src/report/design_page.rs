//! The review page of a design search (`shoal design`): the answer and its margins against every
//! requirement, its budgets, the cost–error fronts and every design evaluated, as one
//! self-contained HTML file under the same rules as the study's pack (inline SVG through the
//! figure gate, no script, no reference outside the file).

use std::fmt::Write as _;

use super::html::{CSP, PageFigure, STYLE, escape, num};
use crate::design::{Search, pass_probability_lower_bound};

/// What the page shows besides the search itself.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignContext {
    /// Study name.
    pub study: String,
    /// Study description.
    pub description: String,
    /// The instrument the search started from.
    pub instrument: String,
    /// Currency of the costs.
    pub currency: String,
    /// Noise seeds per design.
    pub seeds: usize,
    /// Wall time of the whole search, s.
    pub seconds: f64,
}

/// The page.
#[must_use]
pub fn design_page(search: &Search, c: &DesignContext, fronts: &[PageFigure]) -> String {
    let mut h = String::with_capacity(1 << 18);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta http-equiv=\"Content-Security-Policy\" content=\"{CSP}\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>Shoal design search — {}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<header>\n<p class=\"note\">Shoal design search</p>\n<h1>{}</h1>\n<p class=\"lead\">{}</p>\n",
        escape(&c.study),
        escape(&c.study),
        escape(&c.description)
    );
    let search_d = search.evaluations.first().map_or(0, |e| e.decimation);
    let _ = writeln!(
        h,
        "<table class=\"meta\"><tr><td>Starting design</td><td>{}</td></tr><tr><td>Varied</td><td>{}</td></tr><tr><td>Evaluated</td><td>{} designs at decimation {search_d} × {} seeds, {} confirmation runs; {} s in all</td></tr><tr><td>Shoal</td><td>version {}, commit {}</td></tr></table>\n</header>",
        escape(&c.instrument),
        escape(&search.vars.iter().map(|v| format!("{} {:?}", v.path, v.bounds())).collect::<Vec<_>>().join("; ")),
        search.evaluations.len(),
        c.seeds,
        search.confirmed.len(),
        num(c.seconds, 1),
        env!("CARGO_PKG_VERSION"),
        escape(super::commit())
    );
    if let Some(why) = &search.stopped_early {
        let _ = writeln!(h, "<p class=\"note\">{}.</p>", escape(why));
    }
    if let Some(note) = crate::design::optimiser_note(search) {
        let _ = writeln!(h, "<p class=\"note\">{}</p>", escape(&note));
    }
    if !search.shard {
        answer(&mut h, search, c);
    }
    h.push_str("<section id=\"fronts\">\n<h2>Cost against each product's error</h2>\n");
    for f in fronts {
        match super::svg::clean(&f.svg) {
            Ok(svg) => {
                let _ = writeln!(
                    h,
                    "<figure>\n{}\n<figcaption>{}: the designs evaluated that no other beats on both cost and error.</figcaption>\n</figure>",
                    svg.replacen("<svg", "<svg role=\"img\"", 1),
                    escape(&f.name)
                );
            }
            Err(refused) => {
                let _ = writeln!(
                    h,
                    "<p class=\"fail\">Figure {} left out: {}.</p>",
                    escape(&f.name),
                    escape(&refused.to_string())
                );
            }
        }
    }
    h.push_str("</section>\n");
    evaluations(&mut h, search);
    h.push_str("<footer class=\"note\"><p>Made by Shoal. This page needs no network and no script.</p></footer>\n</body>\n</html>\n");
    h
}

fn answer(h: &mut String, search: &Search, c: &DesignContext) {
    h.push_str("<section id=\"answer\">\n<h2>The cheapest feasible design</h2>\n");
    let Some(a) = search.answer() else {
        h.push_str("<p class=\"fail\">No feasible design in the range searched.</p>\n");
        if let Some(closest) = search.closest.and_then(|i| search.evaluations.get(i)) {
            let _ = writeln!(
                h,
                "<p>Closest: {} at cost {} {}.</p>",
                escape(&describe(search, &closest.x)),
                num(closest.cost.unwrap_or(f64::NAN), 3),
                escape(&c.currency)
            );
            margins(h, &closest.constraints);
        }
        h.push_str("</section>\n");
        return;
    };
    let extrapolated = a.budget.as_ref().is_some_and(|b| b.cost.extrapolated);
    let _ = writeln!(
        h,
        "<p class=\"lead\"><b>{}</b>: telescope cost {} {}{}, confirmed at decimation {}. Every requirement passed on all {} seeds (one-sided 95 % lower bound on a further seed passing: {}).</p>",
        escape(&describe(search, &a.x)),
        num(a.cost.unwrap_or(f64::NAN), 3),
        escape(&c.currency),
        if extrapolated { " (extrapolated below the cost model's data)" } else { "" },
        a.decimation,
        a.seeds,
        num(pass_probability_lower_bound(c.seeds, 0.95), 2)
    );
    margins(h, &a.constraints);
    if let Some(b) = &a.budget {
        h.push_str("<h3>Budgets</h3>\n<table>\n");
        for (name, value) in b.rows() {
            let _ = writeln!(h, "<tr><td>{}</td><td>{}</td></tr>", escape(&name), escape(&value));
        }
        h.push_str("</table>\n");
    }
    h.push_str("</section>\n");
}

fn margins(h: &mut String, constraints: &[(String, f64)]) {
    h.push_str("<table>\n<tr><th>requirement (worst seed)</th><th>margin, % of the limit</th><th></th></tr>\n");
    for (k, g) in constraints {
        let (class, word) = if *g <= 0.0 { ("pass", "pass") } else { ("fail", "FAIL") };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"num\">{:+.2}</td><td class=\"{class}\">{word}</td></tr>",
            escape(k),
            -100.0 * g
        );
    }
    h.push_str("</table>\n");
}

fn evaluations(h: &mut String, search: &Search) {
    h.push_str("<section id=\"evaluations\">\n<h2>Every design evaluated</h2>\n<table>\n<tr><th>#</th><th>phase</th>");
    for v in &search.vars {
        let _ = write!(h, "<th>{}</th>", escape(v.name()));
    }
    h.push_str("<th>cost</th><th>worst excess, %</th><th>feasible</th><th>decimation</th><th>s</th></tr>\n");
    let n = search.evaluations.len();
    for (i, e) in search.evaluations.iter().chain(&search.confirmed).enumerate() {
        let _ = write!(h, "<tr><td class=\"num\">{}</td><td>{}</td>", i + 1, if i < n { "search" } else { "confirm" });
        for x in &e.x {
            let _ = write!(h, "<td class=\"num\">{}</td>", num(*x, 5));
        }
        let feasible = if e.feasible() { "<td class=\"pass\">yes</td>" } else { "<td>no</td>" };
        let _ = writeln!(
            h,
            "<td class=\"num\">{}</td><td class=\"num\">{}</td>{feasible}<td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            num(e.cost.unwrap_or(f64::NAN), 4),
            if e.constraints.is_empty() { "–".into() } else { num(100.0 * e.worst(), 1) },
            e.decimation,
            num(e.seconds, 2)
        );
    }
    h.push_str("</table>\n</section>\n");
}

fn describe(search: &Search, x: &[f64]) -> String {
    search
        .vars
        .iter()
        .zip(x)
        .map(|(v, x)| format!("{} = {}", v.name(), num(*x, if x.fract() == 0.0 { 0 } else { 4 })))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::{Dimension, Evaluation};

    fn evaluation(x: f64, cost: f64, g: f64) -> Evaluation {
        Evaluation {
            x: vec![x],
            cost: Some(cost),
            constraints: vec![("chl_mg_m3 MAE %".into(), g), ("fits <6U>".into(), -0.2)],
            seeds_passed: usize::from(g <= 0.0),
            seeds: 1,
            mae_pct: vec![("chl_mg_m3".into(), 20.0 * (1.0 + g))],
            budget: None,
            decimation: 4,
            seconds: 0.5,
            error: None,
            warnings: Vec::new(),
        }
    }

    fn context() -> DesignContext {
        DesignContext {
            study: "s<script>".into(),
            description: "d".into(),
            instrument: "cubesat".into(),
            currency: "FY2017 US$ M".into(),
            seeds: 3,
            seconds: 12.0,
        }
    }

    #[test]
    fn the_page_states_the_answer_its_margins_and_escapes_what_it_was_given() {
        let search = Search {
            vars: vec![Dimension::parse("aperture_mm=40:200").unwrap()],
            evaluations: vec![evaluation(60.0, 0.27, 0.2), evaluation(75.0, 0.4, -0.05)],
            cheapest: Some(1),
            closest: None,
            confirmed: vec![],
            stopped_early: None,
            optimiser_failures: Vec::new(),
            shard: false,
        };
        let page = design_page(&search, &context(), &[]);
        assert!(page.contains("aperture_mm = 75"), "the answer");
        assert!(page.contains("<td class=\"num\">+5.00</td><td class=\"pass\">pass</td>"), "its chl margin");
        assert!(page.contains("fits &lt;6U&gt;") && !page.contains("<script"), "escaped");
        assert!(page.contains("0.37"), "the seed bound 0.05^(1/3)");
    }

    #[test]
    fn no_feasible_design_names_the_closest_and_what_it_misses() {
        let search = Search {
            vars: vec![Dimension::parse("aperture_mm=40:200").unwrap()],
            evaluations: vec![evaluation(60.0, 0.27, 0.2)],
            cheapest: None,
            closest: Some(0),
            confirmed: vec![],
            stopped_early: None,
            optimiser_failures: Vec::new(),
            shard: false,
        };
        let page = design_page(&search, &context(), &[]);
        assert!(page.contains("No feasible design") && page.contains("Closest: aperture_mm = 60"));
        assert!(page.contains("<td class=\"num\">-20.00</td><td class=\"fail\">FAIL</td>"));
    }
}
