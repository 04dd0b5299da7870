//! The sweep's curves: MAE of one variable against the first parameter, one series per
//! instrument (and per value of the second parameter), seeds' spread as a band, the requirement
//! and where it is first met.

use crate::study::{CurvePoint, CurveSeries, Curves, Figure, StudyError, curve_figure, first_crossing};

use super::Requirement;
use super::table::Table;

/// One series of a variable: an instrument, a retrieval, a value of the second parameter.
#[derive(Debug, Clone, PartialEq)]
struct SeriesKey {
    instrument: String,
    product: String,
    second: Option<f64>,
}

impl SeriesKey {
    fn holds(&self, r: &super::table::Row) -> bool {
        r.instrument == self.instrument && r.product == self.product && r.values.get(1).copied() == self.second
    }
}

/// The series of `variable` in `table`, in the order of their first row, and whether the
/// variable comes from more than one retrieval (an external algorithm beside aLMI: each is its
/// own series, named).
fn series_keys(table: &Table, variable: &str) -> (Vec<SeriesKey>, bool) {
    let mut keys: Vec<SeriesKey> = Vec::new();
    for r in table.rows.iter().filter(|r| r.variable == variable) {
        let key = SeriesKey {
            instrument: r.instrument.clone(),
            product: r.product.clone(),
            second: r.values.get(1).copied(),
        };
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    let several = keys.iter().any(|k| k.product != keys[0].product);
    (keys, several)
}

/// The curves of `variable` in `table` (points ordered by the first parameter).
#[must_use]
pub fn curves(table: &Table, variable: &str, requirement: Option<&Requirement>, log_x: bool) -> Curves {
    let (keys, several) = series_keys(table, variable);
    let limit = requirement.filter(|q| q.variable == variable).map(|q| q.mae_pct);
    let series = keys
        .iter()
        .map(|key| {
            let mut xs: Vec<f64> = Vec::new();
            let rows: Vec<_> = table.rows.iter().filter(|r| r.variable == variable && key.holds(r)).collect();
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
            let series = if several { format!("{} {}", key.instrument, key.product) } else { key.instrument.clone() };
            let label = match (key.second, table.parameters.get(1)) {
                (Some(y), Some(name)) => format!("{series}, {name} = {}", trim(y)),
                _ => series,
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
    let (keys, _) = series_keys(table, variable);
    for (s, key) in c.series.iter_mut().zip(&keys) {
        for p in &mut s.points {
            let snr: Vec<f64> = table
                .rows
                .iter()
                .filter(|r| r.variable == variable && key.holds(r) && r.values[0] == p.x)
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
