//! Budgets of a design: what it costs, where it fits, what it weighs and draws, and what it
//! downlinks. Each is a parametric model with cited sources; the coefficients live in a RON file
//! a user can replace (`presets/budgets/`, `budgets:` in a study).
//!
//! | budget | module | source |
//! |---|---|---|
//! | telescope cost | [`cost`] | NASA MSFC OTA cost model (Stahl 2020) |
//! | envelope, form factor, mass, power | [`envelope`] | telephoto length; CubeSat Design Specification; SMAD §9.5 analogy scaling |
//! | data rate and volume | [`data`] | pushbroom readout; SMAD §13.2 |
//!
//! The numbers are phase-0 estimates: a cost-estimating relation's scatter is tens of per cent
//! (Stahl 2020 explains 92 % of the variance in log space), and mass and power are only as good
//! as the reference they are scaled from. They rank designs against each other; they do not
//! replace a costing.

pub mod cost;
pub mod data;
pub mod envelope;

use serde::{Deserialize, Serialize};

pub use cost::{Cost, CostModel, OutOfRange};
pub use data::{DataBudget, Operations, PlaneReadout};
pub use envelope::{Envelope, FormFactor, Packaging, Reference};

use super::InstrumentSpec;
use crate::parse::{FieldError, ParseError};

/// The models and their coefficients, as written in RON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BudgetModels {
    /// Short name.
    pub name: String,
    /// Where the coefficients come from and what they assume.
    #[serde(default)]
    pub description: String,
    /// The telescope cost model.
    pub cost: CostModel,
    /// How the optics are packaged.
    pub packaging: Packaging,
    /// The boxes a design may fly in, any order.
    pub form_factors: Vec<FormFactor>,
    /// The instrument mass and power are scaled from (none: not estimated).
    #[serde(default)]
    pub reference: Option<Reference>,
    /// Operations and downlink.
    pub operations: Operations,
}

/// Errors reading budget models.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum BudgetError {
    /// A field out of range.
    #[error(transparent)]
    Invalid(#[from] FieldError),
    /// A file that does not parse.
    #[error(transparent)]
    Parse(#[from] ParseError),
}

/// The budgets of one design.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignBudget {
    /// Telescope cost.
    pub cost: Cost,
    /// The currency of [`Cost::ota`].
    pub currency: String,
    /// Envelope, fit, mass and power.
    pub envelope: Envelope,
    /// Data rate and volume.
    pub data: DataBudget,
}

impl DesignBudget {
    /// The budgets as (name, value) rows for tables: the review pack, `shoal study`, the app.
    #[must_use]
    pub fn rows(&self) -> Vec<(String, String)> {
        let cost = match (self.cost.ota, self.cost.extrapolated) {
            (Some(c), false) => format!("{c:.2} {}", self.currency),
            (Some(c), true) => format!("{c:.2} {} (extrapolated)", self.currency),
            (None, _) => "– (outside the model)".into(),
        };
        let e = &self.envelope;
        let d = &self.data;
        vec![
            ("telescope cost (OTA)".into(), cost),
            ("optics length × cross-section".into(), format!("{:.0} × {:.0} mm", e.length_mm, e.cross_section_mm)),
            ("smallest box it fits".into(), e.fits.clone().unwrap_or_else(|| "none of the listed".into())),
            (
                "mass, power (scaled)".into(),
                match (e.mass_kg, e.power_w) {
                    (Some(m), Some(p)) => format!("{m:.2} kg, {p:.1} W"),
                    _ => "– (no reference)".into(),
                },
            ),
            ("data rate while imaging".into(), format!("{:.1} Mbit/s", d.rate_mbit_s)),
            (
                "data a day / downlink a day".into(),
                format!("{:.1} / {:.1} Gbit ({:.0} %)", d.daily_gbit, d.downlink_gbit_day, 100.0 * d.downlink_share()),
            ),
        ]
    }
}

impl BudgetModels {
    /// The built-in models by name (`presets/budgets/NAME.ron`).
    pub fn preset(name: &str) -> Result<Self, BudgetError> {
        crate::parse::preset(name)
    }

    /// The built-in default.
    pub fn default_models() -> Result<Self, BudgetError> {
        Self::preset("default")
    }

    /// Every coefficient in range, every box with positive sides and a unique name.
    pub fn validate(&self) -> Result<(), BudgetError> {
        crate::parse::check_name("budgets.name", &self.name)?;
        self.cost.validate()?;
        self.packaging.validate()?;
        self.operations.validate()?;
        if let Some(r) = &self.reference {
            r.validate()?;
        }
        if self.form_factors.len() > 64 {
            return Err(FieldError {
                field: "budgets.form_factors".into(),
                message: format!("{} boxes (allowed: 0 to 64)", self.form_factors.len()),
            }
            .into());
        }
        for (i, f) in self.form_factors.iter().enumerate() {
            crate::parse::check_name(&format!("budgets.form_factors[{i}].name"), &f.name)?;
            let (a, b, c) = f.sides_mm;
            for (k, s) in [a, b, c].into_iter().enumerate() {
                envelope::check(&format!("budgets.form_factors[{i}].sides_mm.{k}"), s, 1.0, 100_000.0)?;
            }
            if self.form_factors[..i].iter().any(|g| g.name == f.name) {
                return Err(FieldError {
                    field: format!("budgets.form_factors[{i}].name"),
                    message: format!("`{}` is named twice", f.name),
                }
                .into());
            }
        }
        Ok(())
    }

    /// Is `name` one of the form factors?
    #[must_use]
    pub fn has_form_factor(&self, name: &str) -> bool {
        self.form_factors.iter().any(|f| f.name == name)
    }

    /// How much of the box `name` a design of `envelope` needs ([`Packaging::fit_ratio`]: at
    /// most 1 when it fits); `None` for a box the models do not have.
    #[must_use]
    pub fn fit_ratio(&self, envelope: &Envelope, name: &str) -> Option<f64> {
        let b = self.form_factors.iter().find(|f| f.name == name)?;
        Some(self.packaging.fit_ratio(envelope.length_mm, envelope.cross_section_mm, b))
    }

    /// The budgets of `spec`, whose band `b` sits on focal plane `plane_of_band[b]` (0: the
    /// first, `i`: `focal_planes[i − 1]`).
    #[must_use]
    pub fn assess(&self, spec: &InstrumentSpec, plane_of_band: &[usize]) -> DesignBudget {
        let t0 = spec.gsd_m() / super::ground_speed_m_s(spec.altitude_km);
        let mut planes =
            vec![PlaneReadout { bands: 0, detectors: spec.detectors, bits: spec.adc_bits, line_period_s: t0 }];
        planes.extend(spec.focal_planes.iter().map(|p| PlaneReadout {
            bands: 0,
            detectors: p.detectors,
            bits: p.adc_bits,
            line_period_s: t0 * p.pixel_pitch_um / spec.pixel_pitch_um,
        }));
        for &p in plane_of_band {
            if let Some(plane) = planes.get_mut(p) {
                plane.bands += 1;
            }
        }
        DesignBudget {
            cost: self.cost.ota(spec.aperture_mm * 1e-3),
            currency: self.cost.currency.clone(),
            envelope: envelope::envelope(
                &self.packaging,
                &self.form_factors,
                self.reference.as_ref(),
                spec.aperture_mm,
                spec.focal_length_mm,
            ),
            data: self.operations.budget_with(&planes, spec.lines, super::effects::compression(&spec.effects)),
        }
    }
}

impl crate::parse::Preset for BudgetModels {
    const FOLDER: &'static str = "budgets";
    type Error = BudgetError;
    fn parse_error(origin: &str, message: String) -> BudgetError {
        BudgetError::Parse(ParseError { origin: origin.into(), message })
    }
    fn unknown(name: &str, known: &[String]) -> BudgetError {
        BudgetError::Invalid(FieldError {
            field: "budgets".into(),
            message: format!("no built-in budget models `{name}` (known: {})", known.join(", ")),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_models_load_and_validate() {
        for name in crate::parse::preset_names::<BudgetModels>() {
            let m = BudgetModels::preset(&name).unwrap();
            m.validate().unwrap();
        }
    }

    #[test]
    fn the_cubesat_preset_by_hand() {
        let m = BudgetModels::preset("cubesat_class").unwrap();
        let spec = InstrumentSpec::preset("cubesat").unwrap();
        let b = m.assess(&spec, &[0; 8]);
        // Extrapolated below the model's 0.3 m: 600 · 0.06^1.7 · 0.5^−0.5 · 293^−0.25 ·
        // e^(−0.028·66) = 0.27054 (FY2017 US$ M).
        assert!(b.cost.extrapolated);
        assert!((b.cost.ota.unwrap() - 0.270_54).abs() < 5e-4, "{:?}", b.cost);
        // 1024 × 8 × 16 bits every line period (GSD 5.86e-6·560e3/0.165 = 19.89 m over
        // v_ground at 560 km).
        let t = spec.gsd_m() / crate::instrument::ground_speed_m_s(560.0);
        assert!((b.data.rate_mbit_s - 1024.0 * 8.0 * 16.0 / t * 1e-6).abs() < 1e-9);
    }

    #[test]
    fn a_duplicate_box_is_named() {
        let mut m = BudgetModels::default_models().unwrap();
        m.form_factors.push(m.form_factors[0].clone());
        let e = m.validate().unwrap_err().to_string();
        assert!(e.contains("budgets.form_factors[") && e.contains("named twice"), "{e}");
    }
}
