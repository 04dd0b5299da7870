//! What a season says, as plain data: the printed summary of `shoal season` and the review
//! pack's season section are both made from a [`SeasonSummary`], which `shoal season` writes
//! beside its tables (`season.json`) so that `shoal report … --season DIR` can carry it.

use serde::{Deserialize, Serialize};

use super::looks::Verdict;
use super::run::{LookError, SeasonResult};
use super::stats;

/// The file `shoal season` writes its summary to.
pub const SUMMARY_JSON: &str = "season.json";

/// One product variable's error over a design's valid looks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProductSeason {
    /// Retrieval.
    pub product: String,
    /// Variable.
    pub variable: String,
    /// Looks that returned it.
    pub looks: usize,
    /// Log-space MAE over the looks, %: median, 10th and 90th percentile, worst.
    pub mae_median_pct: f64,
    /// 10th percentile.
    pub mae_p10_pct: f64,
    /// 90th percentile.
    pub mae_p90_pct: f64,
    /// Worst look.
    pub mae_worst_pct: f64,
    /// Share of the water returned, %: median and least over the looks (clouds, their shadows
    /// and glint take their share).
    pub returned_median_pct: f64,
    /// Least.
    pub returned_least_pct: f64,
}

/// One design over the season.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DesignSummary {
    /// Label in the study.
    pub label: String,
    /// Altitude, km.
    pub altitude_km: f64,
    /// Half the across-track field of view, degrees.
    pub half_fov_deg: f64,
    /// Passes over the site.
    pub passes: usize,
    /// Looks by verdict: valid, sun low, view oblique, glint, cloud.
    pub by_verdict: [usize; 5],
    /// Valid looks per calendar month, ("YYYY-MM", count).
    pub valid_per_month: Vec<(String, usize)>,
    /// Gap between valid looks, days: median and 90th percentile (`None`: fewer than two).
    pub gap_median_d: Option<f64>,
    /// 90th percentile.
    pub gap_p90_d: Option<f64>,
    /// Share of days within the revisit requirement's wait, %, and whether it passes.
    pub revisit: Option<(f64, bool)>,
    /// Orbit phases the spread below is taken over (0 on an element set, whose phase is known).
    pub phases: usize,
    /// Over the orbit phases: valid looks min, median, max.
    pub phase_valid: Option<(f64, f64, f64)>,
    /// Over the orbit phases: revisit share min, median, max, %.
    pub phase_revisit_pct: Option<(f64, f64, f64)>,
    /// Chain runs made, and how many failed.
    pub runs: usize,
    /// Failed runs.
    pub failed: usize,
    /// Up to three failure messages.
    pub failures: Vec<String>,
    /// Each product variable's error over the looks run.
    pub products: Vec<ProductSeason>,
}

/// A season's answer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeasonSummary {
    /// Season name.
    pub name: String,
    /// What it asks.
    pub description: String,
    /// The study its looks run.
    pub study: String,
    /// The site, degrees north and east.
    pub site: (f64, f64),
    /// First and last day.
    pub from: String,
    /// Last day.
    pub to: String,
    /// The orbit, in words.
    pub orbit: String,
    /// Largest roll towards the site, degrees.
    pub max_roll_deg: f64,
    /// Fore/aft glint tilt, degrees.
    pub glint_tilt_deg: f64,
    /// Where the cloud fractions come from ("no clouds" without).
    pub clouds: String,
    /// Decimation of each look's chain run.
    pub decimation: usize,
    /// The revisit requirement: (days, % of days).
    pub revisit: Option<(f64, f64)>,
    /// Per design.
    pub designs: Vec<DesignSummary>,
}

/// The variables every design's runs returned, as (product, variable), in first-seen order.
#[must_use]
pub fn variables(result: &SeasonResult) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    for e in result.designs.iter().flat_map(|d| &d.runs).flat_map(|r| &r.errors) {
        if !out.iter().any(|(p, v)| *p == e.product && *v == e.variable) {
            out.push((e.product.clone(), e.variable.clone()));
        }
    }
    out
}

fn spread(values: &[f64]) -> Option<(f64, f64, f64)> {
    Some((stats::percentile(values, 0.0)?, stats::percentile(values, 50.0)?, stats::percentile(values, 100.0)?))
}

/// One product's error over a design's looks: the MAE percentiles over the looks that returned
/// some of it (a look whose water was all screened out, masked or failed has no error: its
/// metrics' MAE of 0 % would pull the median down), the share returned over every look run.
/// `None` when no look returned it.
fn product_season(product: &str, variable: &str, errs: &[&LookError]) -> Option<ProductSeason> {
    let mae: Vec<f64> = errs.iter().filter_map(|e| e.returned_mae_pct()).collect();
    let returned: Vec<f64> = errs.iter().map(|e| e.returned_pct).collect();
    let p = |q: f64| stats::percentile(&mae, q);
    Some(ProductSeason {
        product: product.to_string(),
        variable: variable.to_string(),
        looks: mae.len(),
        mae_median_pct: p(50.0)?,
        mae_p10_pct: p(10.0)?,
        mae_p90_pct: p(90.0)?,
        mae_worst_pct: p(100.0)?,
        returned_median_pct: stats::percentile(&returned, 50.0)?,
        returned_least_pct: stats::percentile(&returned, 0.0)?,
    })
}

impl SeasonSummary {
    /// The summary of `result`.
    #[must_use]
    pub fn of(result: &SeasonResult) -> Self {
        let s = &result.spec;
        let vars = variables(result);
        let designs = result
            .designs
            .iter()
            .map(|d| {
                let count = |v: Verdict| d.looks.iter().filter(|l| l.verdict == v).count();
                let (gap_median_d, gap_p90_d) = d.gap_percentiles();
                let valid: Vec<f64> = d.phases.iter().map(|p| p.valid as f64).collect();
                let revisit: Vec<f64> = d.phases.iter().filter_map(|p| p.revisit_pct).collect();
                let products = vars
                    .iter()
                    .filter_map(|(product, variable)| {
                        product_season(product, variable, &d.errors_of(product, variable))
                    })
                    .collect();
                DesignSummary {
                    label: d.label.clone(),
                    altitude_km: d.altitude_km,
                    half_fov_deg: d.half_fov_deg,
                    passes: d.looks.len(),
                    by_verdict: [
                        count(Verdict::Valid),
                        count(Verdict::SunLow),
                        count(Verdict::ViewOblique),
                        count(Verdict::Glint),
                        count(Verdict::Cloud),
                    ],
                    valid_per_month: result
                        .per_month(d, Some(Verdict::Valid))
                        .iter()
                        .map(|((y, m), n)| (format!("{y}-{m:02}"), *n))
                        .collect(),
                    gap_median_d,
                    gap_p90_d,
                    revisit: result.revisit(d),
                    phases: d.phases.len(),
                    phase_valid: spread(&valid),
                    phase_revisit_pct: spread(&revisit),
                    runs: d.runs.len(),
                    failed: d.runs.iter().filter(|r| r.failure.is_some()).count(),
                    failures: d.runs.iter().filter_map(|r| r.failure.clone()).take(3).collect(),
                    products,
                }
            })
            .collect();
        Self {
            name: s.name.clone(),
            description: s.description.clone(),
            study: result.study.clone(),
            site: s.site,
            from: s.from.clone(),
            to: s.to.clone(),
            orbit: match &s.orbit.tle {
                Some((line1, _)) => {
                    format!("two-line elements of {} (SGP4)", line1.get(2..7).unwrap_or("?").trim())
                }
                None => format!("descending node {:.2} h", s.orbit.descending_node_h),
            },
            max_roll_deg: s.max_roll_deg,
            glint_tilt_deg: s.glint_tilt_deg,
            clouds: s.clouds.as_ref().map_or_else(|| "no clouds".to_string(), |c| format!("clouds from {}", c.source)),
            decimation: s.decimation,
            revisit: s.revisit.map(|q| (q.days, q.pct)),
            designs,
        }
    }

    /// The printed summary: per design, looks by verdict, valid looks per month, gaps, the
    /// revisit requirement, and each product's error over the valid looks run; `seconds` is the
    /// season's run time (`None` for a merge, whose runs were timed on their machines).
    #[must_use]
    pub fn text(&self, seconds: Option<f64>) -> String {
        let mut t = format!(
            "{}: study {}, site {:.2}°, {:.2}°, {} to {}, {}, roll up to {}°, glint tilt {}°, {}{}\n",
            self.name,
            self.study,
            self.site.0,
            self.site.1,
            self.from,
            self.to,
            self.orbit,
            self.max_roll_deg,
            self.glint_tilt_deg,
            self.clouds,
            seconds.map_or_else(String::new, |s| format!(" in {s:.1} s")),
        );
        for d in &self.designs {
            let [valid, sun, view, glint, cloud] = d.by_verdict;
            t += &format!(
                "\n{} ({} km, half field of view {:.2}°): {} passes; valid {valid}, sun low {sun}, view oblique {view}, \
                 glint {glint}, cloud {cloud}\n",
                d.label, d.altitude_km, d.half_fov_deg, d.passes
            );
            let row: Vec<String> = d.valid_per_month.iter().map(|(m, n)| format!("{m} {n}")).collect();
            t += &format!("  valid looks per month: {}\n", row.join(", "));
            t += &format!(
                "  gap between valid looks: median {} d, 90th percentile {} d\n",
                fmt(d.gap_median_d, 1),
                fmt(d.gap_p90_d, 1)
            );
            if let (Some((days, pct)), Some((share, ok))) = (self.revisit, d.revisit) {
                t += &format!(
                    "  revisit: a valid look within {days} d on {share:.1} % of days (required {pct} %): {}\n",
                    if ok { "pass" } else { "FAIL" }
                );
            }
            if let Some(v) = d.phase_valid {
                let phases =
                    |(a, b, c): (f64, f64, f64), digits: usize| format!("{a:.digits$}–{b:.digits$}–{c:.digits$}");
                t += &format!(
                    "  over {} orbit phases (min–median–max): valid looks {}{}\n",
                    d.phases,
                    phases(v, 0),
                    d.phase_revisit_pct.map_or_else(String::new, |r| format!(", revisit {} % of days", phases(r, 1)))
                );
            }
            t += &format!(
                "  chain runs: {} of the valid looks{}\n",
                d.runs,
                if d.failed > 0 { format!(", {} failed", d.failed) } else { String::new() }
            );
            for p in &d.products {
                t += &format!(
                    "  {} {} MAE %: median {:.1}, 10th–90th percentile {:.1}–{:.1}, worst {:.1} ({} looks); returned % \
                     median {:.1}, least {:.1}\n",
                    p.product,
                    p.variable,
                    p.mae_median_pct,
                    p.mae_p10_pct,
                    p.mae_p90_pct,
                    p.mae_worst_pct,
                    p.looks,
                    p.returned_median_pct,
                    p.returned_least_pct
                );
            }
            for f in &d.failures {
                t += &format!("  a run failed: {f}\n");
            }
        }
        t
    }
}

fn fmt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "–".to_string(), |v| format!("{v:.digits$}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(mae_pct: f64, returned_pct: f64) -> LookError {
        LookError { product: "aLMI".into(), variable: "chl_mg_m3".into(), mae_pct, bias_pct: 0.0, returned_pct }
    }

    /// A look that returned no water has no error: it does not enter the MAE percentiles (its
    /// metrics' MAE of 0 % would have made the median 20 % here), but it is the least returned.
    #[test]
    fn a_look_that_returned_nothing_has_no_error() {
        let errs = [error(20.0, 90.0), error(0.0, 0.0), error(0.0, 0.0), error(30.0, 80.0)];
        let refs: Vec<&LookError> = errs.iter().collect();
        let p = product_season("aLMI", "chl_mg_m3", &refs).unwrap();
        assert_eq!(p.looks, 2);
        assert!((p.mae_median_pct - 25.0).abs() < 1e-12 && p.mae_p10_pct >= 20.0, "{p:?}");
        assert_eq!(p.returned_least_pct, 0.0);
        let none = [error(0.0, 0.0)];
        assert!(product_season("aLMI", "chl_mg_m3", &none.iter().collect::<Vec<_>>()).is_none());
    }
}
