//! A season's figures: valid looks per month, and each product's error look by look through the
//! period, one line per design (drawn by the study's curve figure).

use super::looks::Verdict;
use super::run::SeasonResult;
use crate::study::{CurvePoint, CurveSeries, Curves, Figure, StudyError, curve_figure};

fn point(x: f64, y: f64) -> CurvePoint {
    CurvePoint { x, mean: y, lo: y, hi: y }
}

/// Valid looks in each month of the period (x: the month's number from the period's first),
/// per design.
#[must_use]
pub fn valid_looks_curves(result: &SeasonResult) -> Curves {
    let series = result
        .designs
        .iter()
        .map(|d| {
            let months = result.per_month(d, Some(Verdict::Valid));
            CurveSeries {
                label: d.label.clone(),
                points: months.iter().enumerate().map(|(i, (_, n))| point((i + 1) as f64, *n as f64)).collect(),
                crossing: None,
            }
        })
        .collect();
    let first = result.designs.first().map(|d| result.per_month(d, None));
    let span = first
        .as_ref()
        .and_then(|m| {
            Some(format!(
                "month 1 = {}-{:02}, month {} = {}-{:02}",
                m.first()?.0.0,
                m.first()?.0.1,
                m.len(),
                m.last()?.0.0,
                m.last()?.0.1
            ))
        })
        .unwrap_or_default();
    Curves {
        title: format!("{}: valid looks per month", result.spec.name),
        x_label: "month of the period".into(),
        y_label: "valid looks".into(),
        log_x: false,
        series,
        requirement: None,
        caption: vec![
            span,
            format!(
                "valid: sun within {}° of the zenith, normalised glint at most {} sr⁻¹, at least {} % of the site clear",
                result.spec.max_sun_zenith_deg, result.spec.glint_threshold_per_sr, result.spec.min_clear_pct
            ),
        ],
    }
}

/// The error (log-space MAE, %) of `variable` of `product` at each look run, against the day
/// of the period, per design; `limit`: the study's requirement, if any.
#[must_use]
pub fn error_curves(result: &SeasonResult, product: &str, variable: &str, limit: Option<f64>) -> Curves {
    let series = result
        .designs
        .iter()
        .map(|d| {
            let points = d
                .runs
                .iter()
                .filter_map(|r| {
                    // A look that returned none of the product has no error to plot.
                    let e = r.errors.iter().find(|e| e.product == product && e.variable == variable)?;
                    Some(point(d.looks[r.look].access.days - result.period.0, e.returned_mae_pct()?))
                })
                .collect();
            CurveSeries { label: d.label.clone(), points, crossing: None }
        })
        .collect();
    Curves {
        title: format!("{}: {product} {variable} error over the valid looks", result.spec.name),
        x_label: format!("days from {}", result.spec.from),
        y_label: format!("{variable} MAE %"),
        log_x: false,
        series,
        requirement: limit.map(|l| (l, format!("requirement: MAE ≤ {l} %"))),
        caption: vec![format!(
            "each point one valid look run through the chain at its own sun, view and date (decimation {})",
            result.spec.decimation
        )],
    }
}

/// Every figure of a season: valid looks per month, then one error figure per variable run.
pub fn figures(result: &SeasonResult, limits: &[(String, f64)]) -> Result<Vec<Figure>, StudyError> {
    let mut out = vec![curve_figure("season_valid_looks", &valid_looks_curves(result))?];
    let mut seen: Vec<(String, String)> = Vec::new();
    for e in result.designs.iter().flat_map(|d| d.runs.iter().flat_map(|r| &r.errors)) {
        if seen.iter().any(|(p, v)| *p == e.product && *v == e.variable) {
            continue;
        }
        seen.push((e.product.clone(), e.variable.clone()));
        let limit = limits.iter().find(|(v, _)| *v == e.variable).map(|(_, l)| *l);
        let name = format!("season_{}_{}", stem(&e.product), stem(&e.variable));
        out.push(curve_figure(&name, &error_curves(result, &e.product, &e.variable, limit))?);
    }
    Ok(out)
}

/// A product or variable name as part of a file name: letters, digits, `-` and `_` kept, anything
/// else `_`, at most 40 characters (an external retrieval's name comes from a study file).
fn stem(name: &str) -> String {
    name.chars().take(40).map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn names_become_safe_stems() {
        assert_eq!(super::stem("aLMI"), "aLMI");
        assert_eq!(super::stem("../../etc/x y"), "______etc_x_y");
        assert_eq!(super::stem(&"a".repeat(100)).len(), 40);
    }
}
