//! The Pareto front of cost against a product's error among the designs evaluated: the
//! designs no other design beats on both (Deb 2001, §2.4: non-dominated set).
//!
//! ## References
//! - Deb, K. (2001) Multi-Objective Optimization using Evolutionary Algorithms. Wiley.

use super::Evaluation;

/// Indices of the non-dominated designs in (cost, MAE of `variable`), by increasing cost. Only
/// designs that ran and returned the variable take part.
#[must_use]
pub fn pareto_front(evaluations: &[Evaluation], variable: &str) -> Vec<usize> {
    let point = |e: &Evaluation| -> Option<(f64, f64)> {
        let cost = e.cost?;
        let mae = e.mae_pct.iter().find(|(v, _)| v == variable)?.1;
        (e.error.is_none() && mae.is_finite()).then_some((cost, mae))
    };
    let mut points: Vec<(usize, (f64, f64))> =
        evaluations.iter().enumerate().filter_map(|(i, e)| point(e).map(|p| (i, p))).collect();
    points.sort_by(|a, b| a.1.0.total_cmp(&b.1.0).then(a.1.1.total_cmp(&b.1.1)));
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for (i, (_, mae)) in points {
        if mae < best {
            best = mae;
            front.push(i);
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    fn e(cost: f64, mae: f64) -> Evaluation {
        Evaluation {
            x: vec![],
            cost: Some(cost),
            constraints: vec![],
            seeds_passed: 1,
            seeds: 1,
            mae_pct: vec![("chl_mg_m3".into(), mae)],
            budget: None,
            decimation: 1,
            seconds: 0.0,
            error: None,
            warnings: Vec::new(),
        }
    }

    #[test]
    fn the_front_keeps_what_nothing_beats_on_both() {
        let evs = [e(3.0, 10.0), e(1.0, 30.0), e(2.0, 35.0), e(2.5, 12.0), e(4.0, 10.0)];
        // (2, 35) is beaten by (1, 30); (4, 10) by (3, 10).
        assert_eq!(pareto_front(&evs, "chl_mg_m3"), vec![1, 3, 0]);
        assert!(pareto_front(&evs, "nap_g_m3").is_empty());
    }
}
