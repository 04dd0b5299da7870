//! Requirements a study checks: per product variable a largest MAE, a largest |bias| and a
//! smallest share of pixels returned; per band a smallest SNR at the scene's reference radiance.
//! Each check reports the value, pass or fail, and the margin (how far inside the limit —
//! negative when it fails). A product with no pixel returned has no MAE or bias: those checks
//! have no value and fail (an empty product is never a pass). The app, its exported figure and
//! `shoal study` all judge through [`Requirements::check_run`], so they cannot disagree.
//!
//! ```text
//! requirements: Some((
//!     products: [(variable: "chl_mg_m3", mae_pct: Some(20), bias_pct: Some(10), returned_pct: Some(95))],
//!     snr: Some(100),
//!     substrate_pct: Some(70),
//! )),
//! ```

use serde::{Deserialize, Serialize};

use super::{StudyError, StudyResult};
use crate::instrument::budgets::{BudgetModels, DesignBudget};
use crate::instrument::{InstrumentSpec, SnrRow};
use crate::metrics::ProductMetrics;
use crate::parse::FieldError;

use super::optics_checks::StrayLightRequirement;

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
    /// Smallest share of returned water pixels whose dominant substrate is the truth's, % (for a
    /// retrieval that unmixes substrates; checked as the variable `substrate`).
    #[serde(default)]
    pub substrate_pct: Option<f64>,
    /// Largest log-space MAE of the corrected Rrs against the truth in every band of a range
    /// (as ACIX-Aqua states atmospheric-correction performance: Pahlevan et al. 2021).
    #[serde(default)]
    pub rrs: Option<RrsRequirement>,
    /// Largest telescope cost, in the budget models' currency ([`BudgetModels`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cost_max: Option<f64>,
    /// The box the instrument must fit (a form factor of the budget models: `"6U"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fits: Option<String>,
    /// Largest volume of a day's images after compression, Gbit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data_volume_gbit_day: Option<f64>,
    /// Largest nadir ground sampling distance, m (altitude · pitch / focal length).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gsd_m_max: Option<f64>,
    /// Largest along-track smear over one exposure, pixels (exposure / line period;
    /// Schowengerdt 2007, §3.4): what bounds the exposure a design may use.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub smear_px_max: Option<f64>,
    /// Smallest system MTF at Nyquist of any band, along or across track, from the design's MTF
    /// budget (an ideal optic's where it states none; `instrument::effects::mtf`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mtf_nyquist_min: Option<f64>,
    /// Largest system MTF at Nyquist of any band (against aliasing: Sentinel-2 MSI allows 0.30).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mtf_nyquist_max: Option<f64>,
    /// Largest polarisation sensitivity of any band, % (PACE OCI: 1 %).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarisation_pct_max: Option<f64>,
    /// Largest stray-light ratio at a distance from a bright edge (3MI's half-bright field).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stray_light: Option<StrayLightRequirement>,
    /// Largest rms band-to-band misregistration left in Level-1 after co-registration, pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub registration_px_max: Option<f64>,
    /// Largest non-linearity at full well left after the calibration's linearisation, %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nonlinearity_pct_max: Option<f64>,
}

/// The corrected Rrs's error per band, in the bands centred from `from_nm` to `to_nm`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RrsRequirement {
    /// Largest log-space MAE, %.
    pub mae_pct: f64,
    /// First band centre judged, nm.
    #[serde(default = "default_rrs_from_nm")]
    pub from_nm: f64,
    /// Last band centre judged, nm.
    #[serde(default = "default_rrs_to_nm")]
    pub to_nm: f64,
}

fn default_rrs_from_nm() -> f64 {
    400.0
}

fn default_rrs_to_nm() -> f64 {
    560.0
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
    /// The product variable checked (`None`: an SNR check).
    pub variable: Option<String>,
    /// The value; `None` when there is none to judge (no pixel returned), which fails.
    pub value: Option<f64>,
    /// The limit.
    pub limit: f64,
    /// Met?
    pub pass: bool,
    /// Distance inside the limit (negative: outside), in the value's unit; `None` with the value.
    pub margin: Option<f64>,
}

impl Check {
    /// A check of the design (no product variable): `value` at most `limit` when `at_most`, at
    /// least `limit` otherwise; no value fails.
    #[must_use]
    pub fn of_design(label: &str, seed: u64, what: String, value: Option<f64>, limit: f64, at_most: bool) -> Self {
        let margin = value.map(|v| if at_most { limit - v } else { v - limit });
        Self {
            instrument: label.into(),
            seed,
            what,
            variable: None,
            value,
            limit,
            pass: margin.is_some_and(|m| m >= 0.0),
            margin,
        }
    }

    /// The value for a table: `"–"` when there is none.
    #[must_use]
    pub fn value_text(&self, decimals: usize) -> String {
        self.value.map_or_else(|| "–".into(), |v| format!("{v:.decimals$}"))
    }

    /// One line a reviewer can read: "chl-a MAE % 12.3 vs limit 20: pass (margin +7.7)" (the
    /// variable by its name for people, [`crate::metrics::name`]).
    #[must_use]
    pub fn describe(&self) -> String {
        let verdict = if self.pass { "pass" } else { "FAIL" };
        let what = match &self.variable {
            Some(v) => self.what.replacen(v.as_str(), crate::metrics::name(v), 1),
            None => self.what.clone(),
        };
        match (self.value, self.margin) {
            (Some(v), Some(m)) => format!("{what} {v:.1} vs limit {}: {verdict} (margin {m:+.1})", self.limit),
            _ => format!("{what} (limit {}): {verdict}, no pixel returned", self.limit),
        }
    }
}

/// The verdict of a set of checks: `None` when nothing was checked.
#[must_use]
pub fn verdict<'a>(checks: impl IntoIterator<Item = &'a Check>) -> Option<bool> {
    checks.into_iter().fold(None, |acc, c| Some(acc.unwrap_or(true) && c.pass))
}

impl Requirements {
    /// Every number positive and finite, every variable known.
    pub fn validate(&self) -> Result<(), StudyError> {
        let bad = |field: String, message: String| Err(StudyError::Invalid(FieldError { field, message }));
        for (i, p) in self.products.iter().enumerate() {
            if crate::variable::of(&p.variable).is_none() {
                return bad(
                    format!("requirements.products[{i}].variable"),
                    format!("`{}` (allowed: {})", p.variable, crate::variable::KEYS.join(", ")),
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
        if let Some(s) = self.substrate_pct
            && let Err(message) = crate::ranges::REQUIREMENT_SUBSTRATE_PCT.check(s)
        {
            return bad("requirements.substrate_pct".into(), message);
        }
        if let Some(r) = &self.rrs {
            if let Err(message) = crate::ranges::REQUIREMENT_RRS_MAE_PCT.check(r.mae_pct) {
                return bad("requirements.rrs.mae_pct".into(), message);
            }
            if !(350.0..=2500.0).contains(&r.from_nm) || !(r.from_nm..=2500.0).contains(&r.to_nm) {
                return bad(
                    "requirements.rrs.from_nm, to_nm".into(),
                    format!("{} to {} nm (allowed: 350 ≤ from_nm ≤ to_nm ≤ 2500)", r.from_nm, r.to_nm),
                );
            }
        }
        Ok(())
    }

    /// The design requirements against the study's budget models: a cost limit positive, a box
    /// among the models' form factors, a data volume positive.
    pub fn validate_design(&self, models: &BudgetModels) -> Result<(), StudyError> {
        let bad = |field: &str, message: String| Err(StudyError::Invalid(FieldError { field: field.into(), message }));
        if let Some(c) = self.cost_max
            && !(c.is_finite() && c > 0.0 && c <= 1e6)
        {
            return bad("requirements.cost_max", format!("{c} (allowed: above 0 up to 1e6 {})", models.cost.currency));
        }
        if let Some(v) = self.data_volume_gbit_day
            && !(v.is_finite() && v > 0.0 && v <= 1e6)
        {
            return bad("requirements.data_volume_gbit_day", format!("{v} (allowed: above 0 up to 1e6 Gbit)"));
        }
        if let Some(v) = self.gsd_m_max
            && !(v.is_finite() && v > 0.0 && v <= 1e5)
        {
            return bad("requirements.gsd_m_max", format!("{v} (allowed: above 0 up to 100 000 m)"));
        }
        if let Some(v) = self.smear_px_max
            && !(v.is_finite() && v > 0.0 && v <= 100.0)
        {
            return bad("requirements.smear_px_max", format!("{v} (allowed: above 0 up to 100 pixels)"));
        }
        for (field, v) in [
            ("requirements.mtf_nyquist_min", self.mtf_nyquist_min),
            ("requirements.mtf_nyquist_max", self.mtf_nyquist_max),
        ] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0 && v < 1.0)
            {
                return bad(field, format!("{v} (allowed: above 0, below 1)"));
            }
        }
        if let Some(v) = self.polarisation_pct_max
            && !(v.is_finite() && v > 0.0 && v <= 20.0)
        {
            return bad("requirements.polarisation_pct_max", format!("{v} (allowed: above 0 up to 20 %)"));
        }
        self.validate_focal_plane()?;
        if let Some(s) = &self.stray_light {
            if !(s.ratio_pct_max.is_finite() && s.ratio_pct_max > 0.0 && s.ratio_pct_max <= 100.0) {
                return bad(
                    "requirements.stray_light.ratio_pct_max",
                    format!("{} (allowed: above 0 up to 100 %)", s.ratio_pct_max),
                );
            }
            if !(s.distance_m.is_finite() && s.distance_m > 0.0 && s.distance_m <= 1e5) {
                return bad(
                    "requirements.stray_light.distance_m",
                    format!("{} (allowed: above 0 up to 100 000 m)", s.distance_m),
                );
            }
            if !(350.0..=2500.0).contains(&s.centre_nm) {
                return bad("requirements.stray_light.centre_nm", format!("{} (allowed: 350 to 2500 nm)", s.centre_nm));
            }
        }
        if let Some(f) = &self.fits
            && !models.has_form_factor(f)
        {
            let names: Vec<&str> = models.form_factors.iter().map(|f| f.name.as_str()).collect();
            return bad(
                "requirements.fits",
                format!("`{f}` is not a box of budgets `{}` (allowed: {})", models.name, names.join(", ")),
            );
        }
        Ok(())
    }

    /// Does the study ask anything of the design's budgets?
    #[must_use]
    pub fn has_design(&self) -> bool {
        self.cost_max.is_some()
            || self.fits.is_some()
            || self.data_volume_gbit_day.is_some()
            || self.smear_px_max.is_some()
            || self.gsd_m_max.is_some()
            || self.mtf_nyquist_min.is_some()
            || self.mtf_nyquist_max.is_some()
            || self.polarisation_pct_max.is_some()
            || self.stray_light.is_some()
            || self.registration_px_max.is_some()
            || self.nonlinearity_pct_max.is_some()
    }

    /// Check a design `spec` and its budgets: cost (a refused cost fails, with the reason), the
    /// box, the daily data volume, its nadir GSD and its along-track smear (exposure over the
    /// line period GSD / ground speed, as the feasibility stage computes it).
    #[must_use]
    pub fn check_design(
        &self,
        label: &str,
        seed: u64,
        spec: &InstrumentSpec,
        budget: &DesignBudget,
        models: &BudgetModels,
    ) -> Vec<Check> {
        let mut out = Vec::new();
        let check =
            |what: String, value: Option<f64>, limit: f64| Check::of_design(label, seed, what, value, limit, true);
        if let Some(l) = self.cost_max {
            let note = if budget.cost.extrapolated { ", extrapolated" } else { "" };
            out.push(check(format!("cost {}{note}", budget.currency), budget.cost.ota, l));
        }
        if let Some(name) = &self.fits {
            // The share of the box's room the tightest dimension takes: 1 or less fits.
            out.push(check(format!("fits {name}: size / room"), models.fit_ratio(&budget.envelope, name), 1.0));
        }
        if let Some(l) = self.data_volume_gbit_day {
            out.push(check("data a day, Gbit".into(), Some(budget.data.daily_gbit), l));
        }
        if let Some(l) = self.gsd_m_max {
            out.push(check("GSD, m".into(), Some(spec.gsd_m()), l));
        }
        if let Some(l) = self.smear_px_max {
            let line_period_s = spec.gsd_m() / crate::instrument::ground_speed_m_s(spec.altitude_km);
            out.push(check("smear, px".into(), Some(spec.exposure_s / line_period_s), l));
        }
        out.extend(self.check_optics(label, seed, spec));
        out
    }

    /// The limits of one variable (`depth_m_bottom_visible` is judged as `depth_m`).
    #[must_use]
    pub fn for_variable(&self, variable: &str) -> Option<&ProductRequirement> {
        let variable = if variable == "depth_m_bottom_visible" { "depth_m" } else { variable };
        self.products.iter().find(|p| p.variable == variable)
    }

    /// Check every run of `result`: its first retrieval as the tables show it, then each further
    /// retrieval's products, named `"<product>: <check>"` (an external algorithm beside aLMI is
    /// judged against the same limits).
    #[must_use]
    pub fn check(&self, result: &StudyResult) -> Vec<Check> {
        result
            .runs
            .iter()
            .flat_map(|run| {
                let metrics = run.retrievals.first().map(|r| &r.metrics);
                let mut checks = self.check_run(&run.label, run.seed, metrics, &run.snr, &run.rrs_metrics);
                for other in run.retrievals.iter().skip(1) {
                    let m = &other.metrics;
                    checks.extend(self.check_run(&run.label, run.seed, Some(m), &[], &[]).into_iter().map(|mut c| {
                        c.what = format!("{}: {}", m.product, c.what);
                        c
                    }));
                }
                let spec = result.study.runs.iter().find(|r| r.0 == run.label).map(|r| &r.2.instrument);
                if let Some(spec) = spec {
                    let spec = spec.as_flown();
                    checks.extend(self.check_design(&run.label, run.seed, &spec, &run.budget, &result.study.budgets));
                }
                checks
            })
            .collect()
    }

    /// Check one run: every product limit against `metrics` (a required variable the retrieval
    /// does not make is skipped: it has no candidate pixels to judge), and the SNR floor against
    /// every band of `snr`.
    #[must_use]
    pub fn check_run(
        &self,
        label: &str,
        seed: u64,
        metrics: Option<&ProductMetrics>,
        snr: &[SnrRow],
        rrs: &[crate::correction::BandRrsMetrics],
    ) -> Vec<Check> {
        let mut out = Vec::new();
        let mut push = |variable: Option<&str>, what: String, value: Option<f64>, limit: f64, upper: bool| {
            let margin = value.map(|v| if upper { limit - v } else { v - limit });
            out.push(Check {
                instrument: label.into(),
                seed,
                what,
                variable: variable.map(Into::into),
                value,
                limit,
                pass: margin.is_some_and(|m| m >= 0.0),
                margin,
            });
        };
        for p in &self.products {
            let Some(m) = metrics.and_then(|m| m.get(&p.variable)) else { continue };
            // With nothing returned the MAE and bias are undefined (metrics reports 0 %).
            let returned = m.n > 0;
            if let Some(l) = p.mae_pct {
                push(Some(&p.variable), format!("{} MAE %", p.variable), returned.then(|| m.mae_pct()), l, true);
            }
            if let Some(l) = p.bias_pct {
                push(
                    Some(&p.variable),
                    format!("{} |bias| %", p.variable),
                    returned.then(|| m.bias_pct().abs()),
                    l,
                    true,
                );
            }
            if let Some(l) = p.returned_pct {
                push(Some(&p.variable), format!("{} returned %", p.variable), Some(m.returned_pct), l, false);
            }
        }
        if let (Some(l), Some(a)) = (self.substrate_pct, metrics.and_then(|m| m.substrate_agreement_pct)) {
            push(Some("substrate"), "substrate right %".into(), Some(a), l, false);
        }
        if let Some(req) = &self.rrs {
            for band in rrs.iter().filter(|b| (req.from_nm..=req.to_nm).contains(&b.centre_nm)) {
                let m = &band.metrics;
                let what = format!("Rrs {} ({:.0} nm) MAE %", band.band, band.centre_nm);
                push(None, what, (m.n > 0).then(|| m.mae_pct()), req.mae_pct, true);
            }
        }
        if let Some(l) = self.snr {
            for row in snr {
                // A band that saturates at its reference radiance measures nothing there: its
                // analytic SNR (which knows no well) is not its figure of merit; it fails at 0.
                let (what, value) = if row.saturated() {
                    (
                        format!(
                            "SNR {} ({:.0} nm), saturated ({:.0} % of full scale)",
                            row.band,
                            row.centre_nm,
                            100.0 * row.full_scale_fraction
                        ),
                        0.0,
                    )
                } else {
                    (format!("SNR {} ({:.0} nm)", row.band, row.centre_nm), row.snr_analytic)
                };
                push(None, what, Some(value), l, false);
            }
        }
        out
    }
}

/// The checks as CSV; a pass of an instrument in `warned` (one with a plausibility warning:
/// saturation, smear, no buildable f-number) reads "pass?", as in the app and the pack.
#[must_use]
pub fn checks_csv(checks: &[Check], warned: &[&str]) -> String {
    let mut csv = crate::csvtext::Csv::new(&["instrument", "seed", "requirement", "value", "limit", "pass", "margin"]);
    for c in checks {
        csv.row([
            c.instrument.clone(),
            c.seed.to_string(),
            c.what.clone(),
            c.value.map_or_else(String::new, |v| format!("{v:.4}")),
            c.limit.to_string(),
            (match (c.pass, warned.contains(&c.instrument.as_str())) {
                (true, false) => "pass",
                (true, true) => "pass?",
                (false, _) => "FAIL",
            })
            .to_string(),
            c.margin.map_or_else(String::new, |m| format!("{m:.4}")),
        ]);
    }
    csv.finish()
}

#[cfg(test)]
mod tests;
