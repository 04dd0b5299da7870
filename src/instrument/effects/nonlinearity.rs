//! Detector non-linearity: the signal chain's response departs from a straight line as the
//! sense node fills (Janesick 2007, ch. 3: the photon-transfer non-linearity of the source
//! follower and the node capacitance). The measured electrons are a polynomial of the
//! collected ones,
//!
//! e′ = e·(1 + a₂·x + a₃·x²),   x = e / W,
//!
//! with W the full well, so a₂ + a₃ is the relative departure at full well (the integral
//! non-linearity a data sheet quotes; −0.01: 1 % low at full well). The Sentinel-2 MSI Level-1
//! processor corrects its VNIR detectors with a cubic of this kind, per pixel (Gascon et al.
//! 2017, §2.2.1). Each column may depart from its band's curve by a stated relative spread
//! (a per-pixel polynomial, as MSI's).
//!
//! The calibration linearises every value before it derives and applies its coefficients, with
//! the curve it believes: the true one times (1 + error) ([`super::Knowledge`]). With the curve
//! known exactly the chain closes (the inversion is exact to 10⁻¹² e⁻); a wrong curve leaves a
//! signal-dependent error that the diffuser's one level cannot remove.
//!
//! ## References
//! - Janesick, J. R. (2007) Photon Transfer: DN → λ. SPIE Press, ch. 3.
//! - Gascon, F. et al. (2017) Copernicus Sentinel-2A calibration and products validation
//!   status. Remote Sens. 9, 584.

use serde::{Deserialize, Serialize};

use super::{Effect, InstrumentError, Knowledge, check};
use crate::parse::FieldError;
use crate::ranges as r;

/// Non-linearity as an instrument file states it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NonLinearity {
    /// a₂: the quadratic term, relative at full well.
    pub quadratic: f64,
    /// a₃: the cubic term, relative at full well.
    #[serde(default)]
    pub cubic: f64,
    /// (a₂, a₃) of each band, in band order, replacing the two above (empty: every band the same).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub per_band: Vec<(f64, f64)>,
    /// Relative rms by which a column's curve departs from its band's (0: every column the same).
    #[serde(default)]
    pub column_spread: f64,
    /// What the calibration knows of the curve (its error scales both terms).
    #[serde(default)]
    pub correction: Knowledge,
}

/// One curve e′ = e·(1 + a₂x + a₃x²), x = e/W.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Curve {
    /// a₂.
    pub quadratic: f64,
    /// a₃.
    pub cubic: f64,
    /// 1/W, e⁻¹.
    pub per_well_e: f64,
}

impl Curve {
    /// The straight line.
    pub const LINEAR: Self = Self { quadratic: 0.0, cubic: 0.0, per_well_e: 0.0 };

    /// Is it the straight line?
    #[must_use]
    pub fn is_linear(&self) -> bool {
        self.quadratic == 0.0 && self.cubic == 0.0
    }

    /// The curve with both terms times `factor` (a column's departure, the processor's belief).
    #[must_use]
    pub fn scaled(self, factor: f64) -> Self {
        Self { quadratic: self.quadratic * factor, cubic: self.cubic * factor, ..self }
    }

    /// e′ of `e` collected electrons.
    #[inline(always)]
    #[must_use]
    pub fn apply(&self, e: f64) -> f64 {
        let x = e * self.per_well_e;
        e * (1.0 + x * (self.quadratic + x * self.cubic))
    }

    /// de′/de at `e`.
    #[inline]
    #[must_use]
    pub fn slope(&self, e: f64) -> f64 {
        let x = e * self.per_well_e;
        1.0 + x * (2.0 * self.quadratic + 3.0 * x * self.cubic)
    }

    /// The collected electrons that read `measured` (Newton's method from e = e′; the curve is
    /// monotone on the range validation allows, and 8 steps bring a 20 % departure to 10⁻¹²).
    #[must_use]
    pub fn invert(&self, measured: f64) -> f64 {
        if self.is_linear() || !measured.is_finite() {
            return measured;
        }
        let mut e = measured;
        for _ in 0..8 {
            let step = (self.apply(e) - measured) / self.slope(e).max(0.05);
            e -= step;
            if step.abs() <= 1e-13 * measured.abs().max(1.0) {
                break;
            }
        }
        e
    }
}

impl NonLinearity {
    /// Band `b`'s curve for a well of `well_e` (per-band values when stated).
    #[must_use]
    pub fn curve(&self, b: usize, well_e: f64) -> Curve {
        let (quadratic, cubic) = self.per_band.get(b).copied().unwrap_or((self.quadratic, self.cubic));
        Curve { quadratic, cubic, per_well_e: if well_e > 0.0 { 1.0 / well_e } else { 0.0 } }
    }

    /// Check the curve of `bands` bands against the bands (a per-band list must have one entry
    /// per band).
    pub fn check_bands(&self, bands: usize) -> Result<(), InstrumentError> {
        if !self.per_band.is_empty() && self.per_band.len() != bands {
            return Err(InstrumentError::Invalid(FieldError {
                field: "instrument.effects[].NonLinearity.per_band".into(),
                message: format!("{} values for {bands} bands (allowed: one per band, or none)", self.per_band.len()),
            }));
        }
        Ok(())
    }
}

/// A curve must rise over the whole well (and a little past it, where clipped values sit):
/// its slope 1 + 2a₂x + 3a₃x² stays above 0.5 on 0 ≤ x ≤ 1.2.
fn rises(quadratic: f64, cubic: f64) -> bool {
    (0..=120).all(|i| {
        let x = f64::from(i) / 100.0;
        1.0 + x * (2.0 * quadratic + 3.0 * x * cubic) > 0.5
    })
}

impl Effect for NonLinearity {
    fn name(&self) -> &'static str {
        "NonLinearity"
    }

    fn role(&self) -> super::Role {
        super::Role::Detector
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        let terms = std::iter::once((self.quadratic, self.cubic, at.to_string()))
            .chain(self.per_band.iter().enumerate().map(|(i, &(q, c))| (q, c, format!("{at}.per_band[{i}]"))));
        for (q, c, field) in terms {
            check(&r::NONLINEARITY_QUADRATIC, q, &format!("{field}.quadratic"))?;
            check(&r::NONLINEARITY_CUBIC, c, &format!("{field}.cubic"))?;
            if !rises(q, c) {
                // Named by the term that pulls the slope down more at the well's end (x = 1.2).
                let term = if 3.0 * c * 1.2 < 2.0 * q { "cubic" } else { "quadratic" };
                return Err(InstrumentError::Invalid(FieldError {
                    field: format!("{field}.{term}"),
                    message: format!(
                        "a₂ = {q}, a₃ = {c} make the response fall within the well (allowed: \
                         1 + 2a₂x + 3a₃x² above 0.5 for x = e/W up to 1.2)"
                    ),
                }));
            }
        }
        check(&r::NONLINEARITY_COLUMN_SPREAD, self.column_spread, &format!("{at}.column_spread"))?;
        self.correction.validate(&r::NONLINEARITY_KNOWLEDGE_ERROR, at)
    }

    fn on_the_cube(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inverse_undoes_the_curve() {
        let curve = Curve { quadratic: -0.03, cubic: 0.01, per_well_e: 1.0 / 20_000.0 };
        for e in [0.0, 1.0, 150.0, 5_000.0, 19_999.0, 24_000.0] {
            let back = curve.invert(curve.apply(e));
            assert!((back - e).abs() <= 1e-9, "{e} → {back}");
        }
        // At full well the departure is a₂ + a₃ = −2 %.
        assert!((curve.apply(20_000.0) / 20_000.0 - 0.98).abs() < 1e-12);
        assert_eq!(Curve::LINEAR.apply(1234.5), 1234.5);
    }

    #[test]
    fn a_falling_curve_is_refused_by_name() {
        let n = NonLinearity {
            quadratic: -0.2,
            cubic: -0.2,
            per_band: vec![],
            column_spread: 0.0,
            correction: Knowledge::default(),
        };
        let e = n.validate("instrument.effects[0].NonLinearity").unwrap_err().to_string();
        assert!(e.contains("NonLinearity.cubic") && e.contains("0.5"), "{e}");
        let ok = NonLinearity { quadratic: -0.02, cubic: 0.005, ..n };
        assert!(ok.validate("instrument.effects[0].NonLinearity").is_ok());
        let two = NonLinearity { per_band: vec![(0.0, 0.0); 2], ..ok };
        assert!(two.check_bands(3).unwrap_err().to_string().contains("per_band"));
    }
}
