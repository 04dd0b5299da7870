//! Requirements a study checks: per product variable a largest MAE, a largest |bias| and a
//! smallest share of pixels returned; per band a smallest SNR at the scene's reference radiance.
//! Each check reports the value, pass or fail, and the margin (how far inside the limit —
//! negative when it fails).
//!
//! ```text
//! requirements: Some((
//!     products: [(variable: "chl_mg_m3", mae_pct: Some(20), bias_pct: Some(10), returned_pct: Some(95))],
//!     snr: Some(100),
//! )),
//! ```

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use super::{StudyError, StudyResult};

/// Limits on one variable (`None`: not required).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProductRequirement {
    /// `chl_mg_m3`, `nap_g_m3`, `cdom_per_m` or `depth_m`.
    pub variable: String,
    /// Largest log-space MAE, %.
    #[serde(default)]
    pub mae_pct: Option<f64>,
    /// Largest |log-space bias|, %.
    #[serde(default)]
    pub bias_pct: Option<f64>,
    /// Smallest share of candidate pixels returned, %.
    #[serde(default)]
    pub returned_pct: Option<f64>,
}

/// A study's requirements.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Requirements {
    /// Per variable.
    #[serde(default)]
    pub products: Vec<ProductRequirement>,
    /// Smallest analytic SNR in every band at the scene's reference (median water) radiance.
    #[serde(default)]
    pub snr: Option<f64>,
}

/// One check.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// Instrument label.
    pub instrument: String,
    /// Seed.
    pub seed: u64,
    /// What is checked (`chl_mg_m3 MAE`, `SNR Oa03`).
    pub what: String,
    /// The value.
    pub value: f64,
    /// The limit.
    pub limit: f64,
    /// Met?
    pub pass: bool,
    /// Distance inside the limit (negative: outside), in the value's unit.
    pub margin: f64,
}

impl Requirements {
    /// Every number positive and finite, every variable known.
    pub fn validate(&self) -> Result<(), StudyError> {
        let bad = |field: String, message: String| Err(StudyError::Invalid { field, message });
        for (i, p) in self.products.iter().enumerate() {
            if !["chl_mg_m3", "nap_g_m3", "cdom_per_m", "depth_m"].contains(&p.variable.as_str()) {
                return bad(
                    format!("requirements.products[{i}].variable"),
                    format!("`{}` (allowed: chl_mg_m3, nap_g_m3, cdom_per_m, depth_m)", p.variable),
                );
            }
            for (name, v, range) in [
                ("mae_pct", p.mae_pct, &crate::ranges::REQUIREMENT_MAE_PCT),
                ("bias_pct", p.bias_pct, &crate::ranges::REQUIREMENT_BIAS_PCT),
                ("returned_pct", p.returned_pct, &crate::ranges::REQUIREMENT_RETURNED_PCT),
            ] {
                if let Some(v) = v
                    && let Err(message) = range.check(v)
                {
                    return bad(format!("requirements.products[{i}].{name}"), message);
                }
            }
        }
        if let Some(s) = self.snr
            && let Err(message) = crate::ranges::REQUIREMENT_SNR.check(s)
        {
            return bad("requirements.snr".into(), message);
        }
        Ok(())
    }

    /// Check every run of `result`.
    #[must_use]
    pub fn check(&self, result: &StudyResult) -> Vec<Check> {
        let mut out = Vec::new();
        for run in &result.runs {
            let mut push = |what: String, value: f64, limit: f64, upper: bool| {
                let margin = if upper { limit - value } else { value - limit };
                out.push(Check {
                    instrument: run.label.clone(),
                    seed: run.seed,
                    what,
                    value,
                    limit,
                    pass: margin >= 0.0,
                    margin,
                });
            };
            for p in &self.products {
                let Some(m) = run.retrievals.first().and_then(|r| r.metrics.get(&p.variable)) else { continue };
                if let Some(l) = p.mae_pct {
                    push(format!("{} MAE %", p.variable), m.mae_pct(), l, true);
                }
                if let Some(l) = p.bias_pct {
                    push(format!("{} |bias| %", p.variable), m.bias_pct().abs(), l, true);
                }
                if let Some(l) = p.returned_pct {
                    push(format!("{} returned %", p.variable), m.returned_pct, l, false);
                }
            }
            if let Some(l) = self.snr {
                for row in run.snr.iter() {
                    push(format!("SNR {} ({:.0} nm)", row.band, row.centre_nm), row.snr_analytic, l, false);
                }
            }
        }
        out
    }
}

/// The checks as CSV.
#[must_use]
pub fn checks_csv(checks: &[Check]) -> String {
    let mut s = String::from("instrument,seed,requirement,value,limit,pass,margin\n");
    for c in checks {
        let _ = writeln!(
            s,
            "{},{},{},{:.4},{},{},{:.4}",
            c.instrument,
            c.seed,
            c.what,
            c.value,
            c.limit,
            if c.pass { "pass" } else { "FAIL" },
            c.margin
        );
    }
    s
}
