//! The sweep's curves: MAE of one variable against the first parameter, one series per
//! instrument (and per value of the second parameter), seeds' spread as a band, the requirement
//! and where it is first met.

use crate::study::{CurvePoint, CurveSeries, Curves, Figure, StudyError, curve_figure, first_crossing};

use super::Requirement;
use super::table::Table;

/// The series of `variable` in `table`: (instrument, second parameter's value), in the order of
/// their first row.
fn series_keys(table: &Table, variable: &str) -> Vec<(String, Option<f64>)> {
    let mut keys: Vec<(String, Option<f64>)> = Vec::new();
    for r in table.rows.iter().filter(|r| r.variable == variable) {
        let key = (r.instrument.clone(), r.values.get(1).copied());
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    keys
}

/// The curves of `variable` in `table` (points ordered by the first parameter).
#[must_use]
pub fn curves(table: &Table, variable: &str, requirement: Option<&Requirement>, log_x: bool) -> Curves {
    let keys = series_keys(table, variable);
    let limit = requirement.filter(|q| q.variable == variable).map(|q| q.mae_pct);
    let series = keys
        .iter()
        .map(|(instrument, second)| {
            let mut xs: Vec<f64> = Vec::new();
            let rows: Vec<_> = table
                .rows
                .iter()
                .filter(|r| {
                    r.variable == variable && &r.instrument == instrument && r.values.get(1).copied() == *second
                })
                .collect();
            for r in &rows {
                if !xs.contains(&r.values[0]) {
                    xs.push(r.values[0]);
                }
            }
            xs.sort_by(f64::total_cmp);
            let points: Vec<CurvePoint> = xs
                .iter()
                .map(|&x| {
                    let v: Vec<f64> =
                        rows.iter().filter(|r| r.values[0] == x).map(|r| r.mae_pct).filter(|m| m.is_finite()).collect();
                    let mean = if v.is_empty() { f64::NAN } else { v.iter().sum::<f64>() / v.len() as f64 };
                    CurvePoint {
                        x,
                        mean,
                        lo: v.iter().copied().fold(f64::INFINITY, f64::min),
                        hi: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    }
                })
                .filter(|p| p.mean.is_finite())
                .collect();
            let label = match (second, table.parameters.get(1)) {
                (Some(y), Some(name)) => format!("{instrument}, {name} = {}", trim(*y)),
                _ => instrument.clone(),
            };
            let crossing = limit.and_then(|l| first_crossing(&points, l));
            CurveSeries { label, points, crossing }
        })
        .collect();
    let seeds = {
        let mut s: Vec<u64> = table.rows.iter().map(|r| r.seed).collect();
        s.sort_unstable();
        s.dedup();
        s.len()
    };
    Curves {
        title: format!(
            "{}: {variable} MAE against {}",
            table.name,
            table.parameters.first().map_or("", String::as_str)
        ),
        x_label: table.parameters.first().cloned().unwrap_or_default(),
        y_label: format!("{variable} log-space MAE (%)"),
        log_x,
        series,
        requirement: limit.map(|l| (l, format!("requirement: MAE ≤ {} %", trim(l)))),
        caption: vec![
            format!(
                "Line: mean over {seeds} noise seeds; band: lowest to highest seed. Circle: where the mean first meets the requirement (linear between points)."
            ),
            format!("Shoal sweep `{}`, key {}. Metrics after Seegers et al. (2018).", table.name, table.key),
        ],
    }
}

fn trim(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The curves of `variable` against the measured SNR of the image-based correction's long
/// aerosol band (the mean over the seeds at each point), where the table has it: the form of
/// Wang & Gordon's (2018) requirement, error against the pair's SNR. `None` without SNR.
#[must_use]
pub fn curves_by_pair_snr(table: &Table, variable: &str, requirement: Option<&Requirement>) -> Option<Curves> {
    if !table.rows.iter().any(|r| r.snr_pair.is_some_and(|p| p[1].is_finite())) {
        return None;
    }
    let mut c = curves(table, variable, requirement, true);
    let limit = c.requirement.as_ref().map(|r| r.0);
    // The series' keys, in the order `curves` made them.
    let keys = series_keys(table, variable);
    for (s, (instrument, second)) in c.series.iter_mut().zip(&keys) {
        for p in &mut s.points {
            let snr: Vec<f64> = table
                .rows
                .iter()
                .filter(|r| &r.instrument == instrument && r.values.get(1).copied() == *second && r.values[0] == p.x)
                .filter_map(|r| r.snr_pair.map(|p| p[1]))
                .filter(|v| v.is_finite())
                .collect();
            p.x = if snr.is_empty() { f64::NAN } else { snr.iter().sum::<f64>() / snr.len() as f64 };
        }
        s.points.retain(|p| p.x.is_finite() && p.x > 0.0);
        s.points.sort_by(|a, b| a.x.total_cmp(&b.x));
        s.crossing = limit.and_then(|l| first_crossing(&s.points, l));
    }
    c.title = format!("{}: {variable} MAE against the aerosol pair's SNR", table.name);
    c.x_label = "measured SNR, long band of the aerosol pair".into();
    c.caption[0] = "Line: mean over the noise seeds at each swept value, placed at the mean measured SNR of the pair's long band; band: lowest to highest seed. Circle: the SNR above which the mean meets the requirement.".into();
    Some(c)
}

/// The figure of `variable` (PNG and SVG).
pub fn sweep_figure(
    table: &Table,
    variable: &str,
    requirement: Option<&Requirement>,
    log_x: bool,
) -> Result<Figure, StudyError> {
    curve_figure(&format!("sweep_{variable}"), &curves(table, variable, requirement, log_x))
}
