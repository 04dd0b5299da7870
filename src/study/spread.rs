//! The spread of the metrics over a study's noise seeds: one seed is one draw of the detector
//! noise, so a design decision should rest on the mean and on how far the seeds scatter around
//! it, not on one draw.

use serde::Serialize;

use std::sync::Arc;

use super::StudyResult;
use crate::engine::RetrievalOutput;

/// One (instrument, product, variable) over the seeds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeedSpread {
    /// Instrument label.
    pub instrument: String,
    /// Product (aLMI, SAMBUCA).
    pub product: String,
    /// Variable (`chl_mg_m3`).
    pub variable: String,
    /// Seeds with a value (a seed whose product returned no pixel has none).
    pub seeds: usize,
    /// Mean log-space MAE over the seeds, %.
    pub mae_pct_mean: f64,
    /// Sample standard deviation of the MAE over the seeds, % (0 for one seed).
    pub mae_pct_std: f64,
    /// Smallest and largest MAE over the seeds, %.
    pub mae_pct_range: (f64, f64),
    /// Mean log-space bias over the seeds, %.
    pub bias_pct_mean: f64,
}

impl SeedSpread {
    /// "37.0 ± 0.4 %" (the ± only when there are two seeds or more; "–" when no seed returned a
    /// pixel).
    #[must_use]
    pub fn mae_text(&self) -> String {
        if self.seeds == 0 {
            "– (nothing returned)".into()
        } else if self.seeds > 1 {
            format!("{:.1} ± {:.1} %", self.mae_pct_mean, self.mae_pct_std)
        } else {
            format!("{:.1} %", self.mae_pct_mean)
        }
    }
}

/// The spread of every (instrument, product, variable) of `result` over its seeds, in the order
/// they first appear.
#[must_use]
pub fn seed_spread(result: &StudyResult) -> Vec<SeedSpread> {
    spread_of_runs(result.runs.iter().map(|r| (r.label.as_str(), r.retrievals.as_slice())))
}

/// The spread over any set of runs, each given as (instrument label, its retrievals); runs of
/// one label are that instrument's seeds (the app measures its own seeds this way).
#[must_use]
pub fn spread_of_runs<'a>(runs: impl IntoIterator<Item = (&'a str, &'a [Arc<RetrievalOutput>])>) -> Vec<SeedSpread> {
    let mut keys: Vec<(String, String, String)> = Vec::new();
    let mut values: Vec<Vec<(f64, f64)>> = Vec::new();
    for (label, retrievals) in runs {
        for ret in retrievals {
            for v in &ret.metrics.variables {
                let key = (label.to_string(), ret.metrics.product.clone(), v.variable.clone());
                let i = keys.iter().position(|k| *k == key).unwrap_or_else(|| {
                    keys.push(key);
                    values.push(Vec::new());
                    keys.len() - 1
                });
                if v.metrics.n > 0 && v.metrics.mae_pct().is_finite() {
                    values[i].push((v.metrics.mae_pct(), v.metrics.bias_pct()));
                }
            }
        }
    }
    keys.into_iter()
        .zip(values)
        .map(|((instrument, product, variable), v)| {
            let n = v.len();
            let mean =
                |f: fn(&(f64, f64)) -> f64| if n == 0 { f64::NAN } else { v.iter().map(f).sum::<f64>() / n as f64 };
            let mae_mean = mean(|p| p.0);
            let std = if n > 1 {
                (v.iter().map(|p| (p.0 - mae_mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
            } else {
                0.0
            };
            let range = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.0), b.max(p.0)));
            SeedSpread {
                instrument,
                product,
                variable,
                seeds: n,
                mae_pct_mean: mae_mean,
                mae_pct_std: std,
                mae_pct_range: if n == 0 { (f64::NAN, f64::NAN) } else { range },
                bias_pct_mean: mean(|p| p.1),
            }
        })
        .collect()
}

/// The spread as CSV: instrument, product, variable, seeds, MAE mean, std, min, max, bias mean.
#[must_use]
pub fn seed_spread_csv(rows: &[SeedSpread]) -> String {
    let mut csv = crate::csvtext::Csv::new(&[
        "instrument",
        "product",
        "variable",
        "seeds",
        "mae_pct_mean",
        "mae_pct_std",
        "mae_pct_min",
        "mae_pct_max",
        "bias_pct_mean",
    ]);
    // No seed returned a pixel: the statistics are empty fields, not NaN.
    let value = |v: f64| if v.is_finite() { v.to_string() } else { String::new() };
    for r in rows {
        csv.row([
            r.instrument.clone(),
            r.product.clone(),
            r.variable.clone(),
            r.seeds.to_string(),
            value(r.mae_pct_mean),
            value(r.mae_pct_std),
            value(r.mae_pct_range.0),
            value(r.mae_pct_range.1),
            value(r.bias_pct_mean),
        ]);
    }
    csv.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_variable_with_nothing_returned_writes_empty_fields_not_nan() {
        let none = SeedSpread {
            instrument: "cubesat".into(),
            product: "QAA v6".into(),
            variable: "nap_g_m3".into(),
            seeds: 0,
            mae_pct_mean: f64::NAN,
            mae_pct_std: 0.0,
            mae_pct_range: (f64::NAN, f64::NAN),
            bias_pct_mean: f64::NAN,
        };
        let csv = seed_spread_csv(std::slice::from_ref(&none));
        assert_eq!(csv.lines().nth(1), Some("cubesat,QAA v6,nap_g_m3,0,,0,,,"));
        assert!(!csv.contains("NaN"));
        assert_eq!(none.mae_text(), "– (nothing returned)");
    }
}
