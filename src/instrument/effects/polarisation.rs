//! Polarisation sensitivity: an instrument whose response depends on the linear polarisation
//! of the light it measures reads, per band (Meister et al. 2005, eq. 1, with the radiometric
//! gain M₁₁ calibrated out),
//!
//! L_m = L + m₁₂·Q′ + m₁₃·U′,
//!
//! where Q′ and U′ are the Stokes parameters in the instrument's frame (reference axis along
//! track) and m₁₂ = s·cos 2ψ, m₁₃ = s·sin 2ψ: s is the polarisation sensitivity
//! √(m₁₂² + m₁₃²), the figure missions specify (PACE OCI below 1 %; a fully polarised input seen
//! at its best and worst orientation reads 1 ± s), and ψ the orientation of the instrument's
//! most transmitted polarisation from the along-track axis.
//!
//! Over water the polarised light at the top of the atmosphere is the path radiance's
//! (molecular scattering; the atmosphere's Q and U come from the vector radiative transfer,
//! [`crate::atmosphere::stokes`]); the water-leaving radiance and glint are taken as
//! unpolarised here, as l2gen's polcor takes them. The processor (l2gen's polcor) subtracts
//! ŝ·(Q′ cos 2ψ + U′ sin 2ψ) with its knowledge of s, ŝ = s·(1 + e), and the same Q′, U′
//! (l2gen computes them from its Rayleigh tables; Shoal's processor uses the path's own).
//!
//! ## References
//! - Meister, G. et al. (2005) Appl. Opt. 44, 5524–5535.
//! - Gordon, H. R., Du, T., Zhang, T. (1997) Atmospheric correction of ocean color sensors:
//!   analysis of the effects of residual instrument polarization sensitivity. Appl. Opt. 36,
//!   6938–6948.

use ndarray::Array3;
use serde::{Deserialize, Serialize};

use super::{Context, Effect, InstrumentError, Knowledge, Needs, check};
use crate::control::RunControl;
use crate::parse::FieldError;
use crate::ranges as r;

/// Polarisation sensitivity as an instrument file states it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Polarisation {
    /// Polarisation sensitivity √(m₁₂² + m₁₃²) of every band (0.01: 1 %).
    pub sensitivity: f64,
    /// Per band, when the bands differ (overrides `sensitivity`; one value per band).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub per_band: Vec<f64>,
    /// Orientation ψ of the most transmitted polarisation from the along-track axis, degrees.
    #[serde(default)]
    pub axis_deg: f64,
    /// What the Level-1 processor knows of it.
    #[serde(default)]
    pub correction: Knowledge,
}

impl Polarisation {
    /// (m₁₂, m₁₃) of band `b`, scaled by `factor`.
    #[must_use]
    pub fn m12_m13(&self, b: usize, factor: f64) -> (f64, f64) {
        let s = factor * self.per_band.get(b).copied().unwrap_or(self.sensitivity);
        let (sin, cos) = (2.0 * self.axis_deg.to_radians()).sin_cos();
        (s * cos, s * sin)
    }

    /// L + factor·(m₁₂Q′ + m₁₃U′) (a negative factor: the processor's subtraction).
    fn add(&self, cube: &mut Array3<f32>, ctx: &Context, factor: f64) -> Result<(), InstrumentError> {
        let stokes = ctx.stokes.ok_or_else(|| {
            InstrumentError::Invalid(FieldError {
                field: "effects[].Polarisation".into(),
                message: "needs the atmosphere's Q and U, which this run did not compute".into(),
            })
        })?;
        let (_, cols, nb) = cube.dim();
        if !self.per_band.is_empty() && self.per_band.len() != nb {
            return Err(InstrumentError::Invalid(FieldError {
                field: "effects[].Polarisation.per_band".into(),
                message: format!("{} values for {nb} bands (give one per band, or none)", self.per_band.len()),
            }));
        }
        let m: Vec<(f64, f64)> = (0..nb).map(|b| self.m12_m13(b, factor)).collect();
        for mut row in cube.outer_iter_mut() {
            for c in 0..cols {
                for (b, &(m12, m13)) in m.iter().enumerate() {
                    let (q, u) = stokes.qu(c, b);
                    row[(c, b)] = (f64::from(row[(c, b)]) + m12 * q + m13 * u) as f32;
                }
            }
        }
        Ok(())
    }
}

impl Effect for Polarisation {
    fn name(&self) -> &'static str {
        "Polarisation"
    }

    fn role(&self) -> super::Role {
        super::Role::Optics
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        check(&r::POLARISATION_SENSITIVITY, self.sensitivity, &format!("{at}.sensitivity"))?;
        for (i, &s) in self.per_band.iter().enumerate() {
            check(&r::POLARISATION_SENSITIVITY, s, &format!("{at}.per_band[{i}]"))?;
        }
        check(&r::POLARISATION_AXIS_DEG, self.axis_deg, &format!("{at}.axis_deg"))?;
        self.correction.validate(&r::POLARISATION_KNOWLEDGE_ERROR, at)
    }

    fn needs(&self) -> Needs {
        Needs { stokes: true }
    }

    fn apply(&self, cube: &mut Array3<f32>, ctx: &Context, _control: &RunControl) -> Result<(), InstrumentError> {
        self.add(cube, ctx, 1.0)
    }

    fn correct(&self, cube: &mut Array3<f32>, ctx: &Context, _control: &RunControl) -> Result<(), InstrumentError> {
        let factor = self.correction.factor();
        if factor == 0.0 { Ok(()) } else { self.add(cube, ctx, -factor) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::effects::StokesColumns;

    fn ctx<'a>(stokes: &'a StokesColumns, centres: &'a [f64]) -> Context<'a> {
        Context { spacing_m: (30.0, 30.0), pixel_m: 30.0, centres_nm: centres, stokes: Some(stokes) }
    }

    #[test]
    fn a_fully_polarised_input_reads_one_plus_the_diattenuation() {
        // One column, two bands: band 0 polarised along track (Q = I), band 1 at 45° (U = I).
        let stokes = StokesColumns::from_parts(2, vec![1.0, 0.0], vec![0.0, 1.0]);
        let centres = [443.0, 865.0];
        let control = RunControl::new();
        for (axis_deg, expect) in [(0.0, [1.02f32, 1.0]), (45.0, [1.0, 1.02]), (90.0, [0.98, 1.0])] {
            let p = Polarisation { sensitivity: 0.02, per_band: vec![], axis_deg, correction: Knowledge::default() };
            let mut cube = Array3::<f32>::from_elem((3, 1, 2), 1.0);
            p.apply(&mut cube, &ctx(&stokes, &centres), &control).unwrap();
            for b in 0..2 {
                assert!(
                    (cube[(1, 0, b)] - expect[b]).abs() <= f32::EPSILON,
                    "axis {axis_deg}, band {b}: {}",
                    cube[(1, 0, b)]
                );
            }
            // The processor that knows s gives the input back to rounding; one that believes
            // it 10 % larger leaves −0.1·s·(the polarised part).
            let mut exact = cube.clone();
            p.correct(&mut exact, &ctx(&stokes, &centres), &control).unwrap();
            assert!(exact.iter().all(|&v| (v - 1.0).abs() <= 2.0 * f32::EPSILON), "{exact:?}");
            let wrong = Polarisation { correction: Knowledge { corrected: true, error: 0.1 }, ..p.clone() };
            let mut left = cube.clone();
            wrong.correct(&mut left, &ctx(&stokes, &centres), &control).unwrap();
            for b in 0..2 {
                let residual = f64::from(left[(0, 0, b)]) - 1.0;
                let polarised = f64::from(expect[b]) - 1.0;
                assert!((residual + 0.1 * polarised).abs() < 1e-6, "{residual} vs {}", -0.1 * polarised);
            }
        }
    }

    #[test]
    fn per_band_values_must_match_the_bands() {
        let stokes = StokesColumns::from_parts(2, vec![1.0, 0.0], vec![0.0, 1.0]);
        let p = Polarisation {
            sensitivity: 0.0,
            per_band: vec![0.01, 0.02, 0.03],
            axis_deg: 0.0,
            correction: Knowledge::default(),
        };
        let mut cube = Array3::<f32>::from_elem((1, 1, 2), 1.0);
        let e = p.apply(&mut cube, &ctx(&stokes, &[443.0, 865.0]), &RunControl::new()).unwrap_err();
        assert!(e.to_string().contains("per_band"), "{e}");
        // One value for two bands is refused too (it would have set band 0 alone).
        let one = Polarisation { per_band: vec![0.01], ..p.clone() };
        let e = one.apply(&mut cube, &ctx(&stokes, &[443.0, 865.0]), &RunControl::new()).unwrap_err();
        assert!(e.to_string().contains("1 values for 2 bands"), "{e}");
        // The worst band is the list's where there is one: `sensitivity` then applies to none.
        let listed = Polarisation { sensitivity: 0.02, per_band: vec![0.005, 0.004], ..p.clone() };
        let effects = [super::super::InstrumentEffect::Polarisation(listed)];
        assert_eq!(super::super::polarisation_sensitivity(&effects), Some(0.005));
        assert!(p.validate("instrument.effects[0].Polarisation").is_ok());
        let bad = Polarisation { sensitivity: 0.5, ..p };
        let e = bad.validate("instrument.effects[0].Polarisation").unwrap_err().to_string();
        assert!(e.contains("sensitivity") && e.contains("0.2"), "{e}");
    }
}
