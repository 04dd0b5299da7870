//! What the telescope costs: the NASA MSFC parametric cost model for optical telescope
//! assemblies (OTA).
//!
//! OTA cost (FY2017 US$ M) = 20 · 30^S · D^1.7 · λ^−0.5 · T^−0.25 · e^(−0.028 (Y − 1960)),
//! with S = 1 in space, D the aperture diameter in m, λ the diffraction-limited wavelength in
//! µm, T the operating temperature in K and Y the year of development (Stahl, NTRS 20205010427,
//! 2020: 92 % of the variance of 47 ground and space OTAs, adjusted R²). An OTA is the mirrors or
//! lenses, their structure, baffles and mechanisms; focal planes, electronics and the bus are not
//! in it.
//!
//! The model's space telescopes start at 0.3 m (TRACE and WIRE are the smallest in the database
//! of Stahl et al. 2010, Table 1); every CubeSat and most SmallSat optics are smaller. Outside
//! the stated range a cost is refused unless the budget file says `out_of_range: Extrapolate`,
//! and an extrapolated cost says so wherever it is shown.
//!
//! ## References
//! - Stahl, H. P. (2020) Parametric cost model for ground and space telescopes. NASA Technical
//!   Reports Server 20205010427.
//! - Stahl, H. P., Stephens, K., Henrichs, T., Smart, C., Prince, F. A. (2010) Single-variable
//!   parametric cost models for space telescopes. Opt. Eng. 49(7), 073006.

use serde::{Deserialize, Serialize};

use crate::parse::FieldError;

/// What to do with a design outside the model's data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum OutOfRange {
    /// No cost (a requirement on cost fails with the reason).
    #[default]
    Refuse,
    /// Extrapolate the power law, and say so.
    Extrapolate,
}

/// The cost model's coefficients (Stahl 2020 by default; a user may refit them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CostModel {
    /// Leading coefficient, currency units (20 FY2017 US$ M).
    pub coefficient: f64,
    /// Space factor 30^S (30).
    pub space_factor: f64,
    /// Aperture exponent (1.7).
    pub aperture_exponent: f64,
    /// Wavelength exponent (−0.5).
    pub wavelength_exponent: f64,
    /// Temperature exponent (−0.25).
    pub temperature_exponent: f64,
    /// Cost decrease per year of development (0.028).
    pub year_rate: f64,
    /// Reference year of the time term (1960).
    pub year_origin: f64,
    /// Diffraction-limited wavelength of the optics, µm.
    pub diffraction_limited_um: f64,
    /// Operating temperature of the optics, K.
    pub temperature_k: f64,
    /// Year of development.
    pub year: f64,
    /// Apertures the model's data cover, m (smallest, largest).
    pub valid_aperture_m: (f64, f64),
    /// Outside that range: refuse or extrapolate.
    #[serde(default)]
    pub out_of_range: OutOfRange,
    /// Multiplier to the currency reported (1 keeps FY2017 US$ M; an escalation index
    /// converts to another year).
    #[serde(default = "one")]
    pub currency_factor: f64,
    /// The currency reported (`"FY2017 US$ M"`).
    pub currency: String,
}

fn one() -> f64 {
    1.0
}

/// A design's cost, or why there is none.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cost {
    /// OTA cost in [`CostModel::currency`]; `None` when refused.
    pub ota: Option<f64>,
    /// The aperture lies outside the model's data (and the cost, if any, is extrapolated).
    pub extrapolated: bool,
    /// Why there is no cost, or what the extrapolation is.
    pub note: Option<String>,
}

impl CostModel {
    /// Every coefficient finite and in a range that keeps the power law meaningful.
    pub fn validate(&self) -> Result<(), FieldError> {
        let field = |name: &str, value: f64, lo: f64, hi: f64| {
            if value.is_finite() && value >= lo && value <= hi {
                Ok(())
            } else {
                Err(FieldError {
                    field: format!("budgets.cost.{name}"),
                    message: format!("{value} is out of range (allowed: {lo} to {hi})"),
                })
            }
        };
        field("coefficient", self.coefficient, 1e-9, 1e9)?;
        field("space_factor", self.space_factor, 1e-3, 1e3)?;
        field("aperture_exponent", self.aperture_exponent, 0.0, 4.0)?;
        field("wavelength_exponent", self.wavelength_exponent, -4.0, 4.0)?;
        field("temperature_exponent", self.temperature_exponent, -4.0, 4.0)?;
        field("year_rate", self.year_rate, 0.0, 1.0)?;
        field("year_origin", self.year_origin, 1900.0, 2100.0)?;
        field("diffraction_limited_um", self.diffraction_limited_um, 0.1, 30.0)?;
        field("temperature_k", self.temperature_k, 1.0, 400.0)?;
        field("year", self.year, 1950.0, 2100.0)?;
        field("currency_factor", self.currency_factor, 1e-6, 1e6)?;
        let (lo, hi) = self.valid_aperture_m;
        field("valid_aperture_m.0", lo, 1e-3, 100.0)?;
        field("valid_aperture_m.1", hi, lo, 100.0)?;
        Ok(())
    }

    /// The OTA cost of an aperture of `aperture_m` (see the module formula).
    #[must_use]
    pub fn ota(&self, aperture_m: f64) -> Cost {
        let (lo, hi) = self.valid_aperture_m;
        let outside = !(lo..=hi).contains(&aperture_m);
        let value = self.coefficient
            * self.space_factor
            * aperture_m.powf(self.aperture_exponent)
            * self.diffraction_limited_um.powf(self.wavelength_exponent)
            * self.temperature_k.powf(self.temperature_exponent)
            * (-self.year_rate * (self.year - self.year_origin)).exp()
            * self.currency_factor;
        let range = format!("the cost model's data cover apertures of {lo}–{hi} m");
        match (outside, self.out_of_range) {
            (false, _) => Cost { ota: Some(value), extrapolated: false, note: None },
            (true, OutOfRange::Refuse) => Cost {
                ota: None,
                extrapolated: true,
                note: Some(format!(
                    "no cost: aperture {:.3} m is outside the data ({range}; budgets.cost.out_of_range: Extrapolate \
                     to extrapolate)",
                    aperture_m
                )),
            },
            (true, OutOfRange::Extrapolate) => Cost {
                ota: Some(value),
                extrapolated: true,
                note: Some(format!("extrapolated: aperture {aperture_m:.3} m, {range}")),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stahl() -> CostModel {
        CostModel {
            coefficient: 20.0,
            space_factor: 30.0,
            aperture_exponent: 1.7,
            wavelength_exponent: -0.5,
            temperature_exponent: -0.25,
            year_rate: 0.028,
            year_origin: 1960.0,
            diffraction_limited_um: 0.5,
            temperature_k: 293.0,
            year: 2026.0,
            valid_aperture_m: (0.3, 6.5),
            out_of_range: OutOfRange::Refuse,
            currency_factor: 1.0,
            currency: "FY2017 US$ M".into(),
        }
    }

    #[test]
    fn stahl_2020_by_hand() {
        // 0.5 m, visible, room temperature, developed in 2026:
        // 20 · 30 · 0.5^1.7 · 0.5^−0.5 · 293^−0.25 · e^(−0.028·66)
        // = 600 · 0.307786 · 1.414214 · 0.241704 · 0.157552 = 9.9454 (FY2017 US$ M).
        let c = stahl().ota(0.5);
        assert!(!c.extrapolated);
        assert!((c.ota.unwrap() - 9.9454).abs() < 5e-4, "{c:?}");
        // The aperture law alone: doubling D multiplies the cost by 2^1.7 = 3.2490.
        let ratio = stahl().ota(1.0).ota.unwrap() / c.ota.unwrap();
        assert!((ratio - 3.249_01).abs() < 1e-4);
    }

    #[test]
    fn outside_the_data_is_refused_or_extrapolated_and_said() {
        let refused = stahl().ota(0.06);
        assert!(refused.ota.is_none() && refused.note.as_deref().unwrap().contains("0.3–6.5 m"));
        let model = CostModel { out_of_range: OutOfRange::Extrapolate, ..stahl() };
        let c = model.ota(0.06);
        // 600 · 0.06^1.7 · 1.414214 · 0.241704 · 0.157552 = 0.27054.
        assert!(c.extrapolated && (c.ota.unwrap() - 0.270_54).abs() < 5e-4, "{c:?}");
    }

    #[test]
    fn a_bad_coefficient_names_its_field() {
        let e = CostModel { aperture_exponent: f64::NAN, ..stahl() }.validate().unwrap_err();
        assert_eq!(e.field, "budgets.cost.aperture_exponent");
    }
}
