//! Tests of the review data: the cost rows and the aerosol found as the page prints them, the
//! UTC text.

use super::*;
use crate::report::machine::utc_text;
use crate::timing::{Comparison, Paired};

/// Four timed cost rows: the reference, the defaults, a preview, one whose percentile failed.
fn sample_cost_rows() -> [CostRow; 4] {
    [
        CostRow::timed(
            "reference (full fidelity)",
            &[4.47, 4.32, 4.49],
            Comparison::NoMeasurableDifference(None),
            Some(0.0),
            Some(0.0),
        ),
        CostRow::timed(
            "the defaults",
            &[3.63, 3.57, 3.53],
            Comparison::Ratio(Paired::exact(0.7987)),
            Some(0.003),
            Some(1.713),
        ),
        CostRow::timed("preview 1/4", &[0.49, 0.45, 0.51], Comparison::Ratio(Paired::exact(0.11)), None, None),
        CostRow::timed(
            "a setting whose percentile failed",
            &[4.4, 4.3, 4.5],
            Comparison::NoMeasurableDifference(None),
            Some(0.1),
            Some(f64::NAN),
        ),
    ]
}

#[test]
fn the_review_pack_states_each_cost_row_with_its_range_and_95th_percentile() {
    let rows = sample_cost_rows();
    let table = cost_rows(&rows);
    // Median of three, the range, the CPU median, the comparison's text, both errors.
    assert_eq!(
        table[1],
        ("the defaults".to_string(), 3, 3.57, (3.53, 3.63), Some(7.14), "0.80×".to_string(), Some(0.003), Some(1.713))
    );
    assert_eq!((table[2].6, table[2].7), (None, None), "a preview has other pixels: no per-pixel error");
    assert_eq!((table[3].6, table[3].7), (Some(0.1), None), "a non-finite percentile is left out, not printed as NaN");
    let data = ReviewData {
        study: "s".into(),
        study_description: String::new(),
        scene: String::new(),
        scene_description: String::new(),
        scene_place: String::new(),
        created_utc: String::new(),
        version: String::new(),
        commit: String::new(),
        instruments: ["olci", "cubesat"]
            .map(|label| InstrumentSummary {
                label: label.into(),
                description: String::new(),
                config_ron: String::new(),
                stages: Vec::new(),
                total_seconds: 1.0,
                shape: (1, 1, 1, 1),
                warnings: if label == "olci" { vec!["saturates in 7 of 21 bands".into()] } else { Vec::new() },
                feasibility: Vec::new(),
            })
            .to_vec(),
        parameters: Vec::new(),
        derived: Vec::new(),
        checks: ["olci", "cubesat"]
            .map(|instrument| CheckRow {
                instrument: instrument.into(),
                seed: 1,
                what: "chl_mg_m3 MAE %".into(),
                value: Some(10.0),
                limit: 20.0,
                pass: true,
                margin: Some(10.0),
            })
            .to_vec(),
        has_requirements: true,
        judged_retrieval: String::new(),
        metrics: Vec::new(),
        budget: Vec::new(),
        cost: table,
        data_sources: Vec::new(),
        machine: machine::Machine::this(),
        study_ron: String::new(),
        figures: Vec::new(),
        substrates: Vec::new(),
        aerosol: vec![AerosolRow {
            instrument: "smallsat".into(),
            found: crate::engine::AerosolSummary {
                aot550: (0.121, 0.083, 0.17),
                aot550_true: 0.124,
                aot550_abs_error: 0.012,
                angstrom: 0.22,
                angstrom_true: 1.18,
                outside_family_pct: 0.0,
                passes_mean: 1.0,
                fit: "dark spectrum <tiles>".into(),
                epsilon: (1.21, 1.15, 1.26),
                members_epsilon: vec![("maritime".into(), 1.0421), ("<urban>".into(), 1.1801)],
            },
        }],
        failures: vec![("cubesat".into(), "mine".into(), "exited with 2; <script>alert(1)</script>".into())],
        seasons: Vec::new(),
    };
    let html = html::page(&data, &[]);
    // The aerosol the correction found, its text escaped; the ε at the pair against the models'.
    assert!(html.contains(
        "<tr><td>smallsat</td><td>dark spectrum &lt;tiles&gt;</td><td class=\"num\">0.121</td><td class=\"num\">0.083–0.170</td>\
         <td class=\"num\">0.124</td><td class=\"num\">0.012</td><td class=\"num\">0.22</td><td class=\"num\">1.18</td>\
         <td class=\"num\">0.0</td><td class=\"num\">1.2100 (1.1500–1.2600)</td><td>maritime 1.0421, &lt;urban&gt; 1.1801</td></tr>"
    ));
    let row = |label: &str| {
        let at = html.find(&format!("<tr><td>{label}</td>")).unwrap_or_else(|| panic!("no row {label}"));
        html[at..at + html[at..].find("</tr>").unwrap()].to_string()
    };
    assert_eq!(
        row("the defaults"),
        "<tr><td>the defaults</td><td class=\"num\">3</td><td class=\"num\">3.57</td><td class=\"num\">3.53–3.63</td>\
         <td class=\"num\">7.14</td><td>0.80×</td><td class=\"num\">0.003</td><td class=\"num\">1.713</td>"
    );
    assert!(row("reference (full fidelity)").contains("<td>–</td>"), "the reference has no verdict against itself");
    assert!(row("a setting whose percentile failed").contains("<td>no measurable difference</td>"));
    assert!(row("preview 1/4").ends_with("<td class=\"num\">other grid</td><td class=\"num\">–</td>"));
    assert!(row("a setting whose percentile failed").ends_with("<td class=\"num\">0.100</td><td class=\"num\">–</td>"));
    assert!(!html.contains("NaN"));
    // A design that passes under a plausibility warning is "pass?", as in the app; one without
    // a warning is a plain pass.
    assert!(html.contains("<b class=\"warn\">MEETS ALL?</b> — 1 of 1 checks met; but implausible here: saturates"));
    assert!(html.contains("cubesat<br><b class=\"pass\">MEETS ALL</b>"));
    let v = row("chl_mg_m3 MAE %");
    assert!(v.contains("10.0 (+10.0) <span class=\"warn\">pass?</span>") && v.contains("<span class=\"pass\">pass"));
    // A program's own words are text, never markup.
    assert!(html.contains("<h2>Retrievals that returned nothing</h2>"));
    assert!(
        html.contains("<td>mine</td><td><pre>exited with 2; &lt;script&gt;alert(1)&lt;/script&gt;</pre>"),
        "escaped"
    );
    assert!(!html.contains("<script>"));
}

#[test]
fn an_aerosol_summary_with_missing_values_round_trips_through_review_json() {
    // No aerosol in the scene: the true Ångström exponent is NaN, written as JSON null.
    let a = crate::engine::AerosolSummary {
        aot550: (f64::NAN, 0.1, f64::NAN),
        angstrom_true: f64::NAN,
        fit: "pair".into(),
        epsilon: (f64::NAN, f64::NAN, f64::NAN),
        ..Default::default()
    };
    let text = serde_json::to_string(&a).unwrap();
    let back: crate::engine::AerosolSummary = serde_json::from_str(&text).unwrap();
    assert!(back.aot550.0.is_nan() && back.aot550.2.is_nan() && back.angstrom_true.is_nan(), "{text}");
    assert!(back.epsilon.0.is_nan() && back.members_epsilon.is_empty(), "{text}");
    // A summary written before the ε fields reads with them missing.
    let older = text.replace(",\"epsilon\":[null,null,null],\"members_epsilon\":[]", "");
    assert!(!older.contains("epsilon"), "{older}");
    let back: crate::engine::AerosolSummary = serde_json::from_str(&older).unwrap();
    assert!(back.epsilon.1.is_nan() && back.members_epsilon.is_empty());
    assert_eq!((back.aot550.1, back.fit.as_str()), (0.1, "pair"));
}

#[test]
fn utc_text_matches_the_calendar() {
    // Values from Python's datetime.utcfromtimestamp: the epoch, a leap day, this decade.
    assert_eq!(utc_text(0), "1970-01-01T00:00:00Z");
    assert_eq!(utc_text(951_782_400), "2000-02-29T00:00:00Z");
    assert_eq!(utc_text(1_795_566_896), "2026-11-25T00:34:56Z");
}
