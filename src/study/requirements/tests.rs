use super::*;
use crate::metrics::{VariableMetrics, compare};

fn product(variable: &str, metrics: crate::metrics::Metrics) -> ProductMetrics {
    ProductMetrics {
        product: "aLMI".into(),
        variables: vec![VariableMetrics { variable: variable.into(), metrics }],
        substrate_agreement_pct: None,
        substrate_confusion: None,
        depth_by_true_substrate: Vec::new(),
        siop_set_counts: Vec::new(),
        siop_sets_used: 0,
        failed: 0,
        stalled: 0,
    }
}

fn chl_limits(returned_pct: Option<f64>) -> Requirements {
    Requirements {
        products: vec![ProductRequirement {
            variable: "chl_mg_m3".into(),
            mae_pct: Some(20.0),
            bias_pct: Some(10.0),
            returned_pct,
        }],
        snr: None,
        substrate_pct: None,
        rrs: None,
        ..Requirements::default()
    }
}

#[test]
fn a_product_with_no_pixel_returned_fails_every_check_even_without_a_returned_limit() {
    // The metrics of an empty product read MAE 0 %, bias 0 %: the false pass this guards.
    let empty = product("chl_mg_m3", compare(&[None, None, None], &[Some(1.0), Some(2.0), Some(3.0)]));
    assert_eq!(empty.get("chl_mg_m3").unwrap().mae_pct(), 0.0);
    let checks = chl_limits(None).check_run("A", 1, Some(&empty), &[], &[]);
    assert_eq!(checks.len(), 2);
    for c in &checks {
        assert!(!c.pass && c.value.is_none() && c.margin.is_none(), "{c:?}");
        assert!(c.describe().contains("no pixel returned"), "{}", c.describe());
    }
    assert_eq!(verdict(&checks), Some(false));
    let csv = checks_csv(&checks, &["A"]);
    assert!(
        csv.lines().nth(1).unwrap().starts_with("A,1,chl_mg_m3 MAE %,,20,FAIL,"),
        "a warning never makes a FAIL pass: {csv}"
    );
}

#[test]
fn a_returned_product_is_judged_by_mae_bias_and_share_with_margins() {
    // Retrieved 1.05× the truth on 3 of 4 pixels: MAE = bias = 5 %, 75 % returned.
    let m = compare(&[Some(1.05), Some(2.1), Some(3.15), None], &[Some(1.0), Some(2.0), Some(3.0), Some(4.0)]);
    let p = product("chl_mg_m3", m);
    let checks = chl_limits(Some(70.0)).check_run("A", 1, Some(&p), &[], &[]);
    let values: Vec<(bool, f64)> = checks.iter().map(|c| (c.pass, c.margin.unwrap())).collect();
    assert!((values[0].1 - 15.0).abs() < 1e-9 && values[0].0, "MAE 5 % under 20 %: {values:?}");
    assert!((values[1].1 - 5.0).abs() < 1e-9 && values[1].0, "|bias| 5 % under 10 %: {values:?}");
    assert!((values[2].1 - 5.0).abs() < 1e-9 && values[2].0, "75 % returned over 70 %: {values:?}");
    assert_eq!(verdict(&checks), Some(true));
    // A design with a plausibility warning passes with a question mark in the CSV too.
    let csv = checks_csv(&checks, &["A"]);
    assert!(csv.lines().skip(1).all(|l| l.contains(",pass?,")), "{csv}");
    assert!(checks_csv(&checks, &[]).lines().skip(1).all(|l| l.contains(",pass,")));
    let checks = chl_limits(Some(80.0)).check_run("A", 1, Some(&p), &[], &[]);
    assert_eq!(verdict(&checks), Some(false), "75 % returned under an 80 % floor fails");
    assert_eq!(verdict(&[]), None, "nothing checked: no verdict");
}
