//! The optics and focal-plane requirements of a design ([`Requirements`]: MTF at Nyquist,
//! polarisation sensitivity, stray light past a bright edge, band-to-band registration and
//! residual non-linearity), judged from the design's stated effects (`instrument::effects`; an
//! ideal optic and focal plane where it states none).

use serde::{Deserialize, Serialize};

use super::requirements::{Check, Requirements};
use crate::instrument::InstrumentSpec;
use crate::instrument::effects;
use crate::instrument::spatial::nyquist_table;

/// The stray signal `distance_m` into the dark half of a half-bright, half-dark field, relative
/// to the bright half, in a band at `centre_nm` (Metop-3MI's convention).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrayLightRequirement {
    /// Largest ratio, %.
    pub ratio_pct_max: f64,
    /// Distance from the edge, m.
    #[serde(default = "default_stray_distance_m")]
    pub distance_m: f64,
    /// Band centre, nm.
    #[serde(default = "default_stray_centre_nm")]
    pub centre_nm: f64,
}

fn default_stray_distance_m() -> f64 {
    1000.0
}

fn default_stray_centre_nm() -> f64 {
    443.0
}

impl StrayLightRequirement {
    /// What its check is called (and the design search's constraint).
    #[must_use]
    pub fn what(&self) -> String {
        format!("stray light {:.0} m past an edge at {:.0} nm, %", self.distance_m, self.centre_nm)
    }
}

/// The optics checks' names (and the design search's constraints).
pub const MTF_MIN_WHAT: &str = "MTF at Nyquist, worst band";
/// See [`MTF_MIN_WHAT`].
pub const MTF_MAX_WHAT: &str = "MTF at Nyquist, sharpest band";
/// See [`MTF_MIN_WHAT`].
pub const POLARISATION_WHAT: &str = "polarisation sensitivity, %";
/// See [`MTF_MIN_WHAT`].
pub const REGISTRATION_WHAT: &str = "band-to-band registration in Level-1, px rms";
/// See [`MTF_MIN_WHAT`].
pub const NONLINEARITY_WHAT: &str = "non-linearity left at full well, %";

/// The rms band-to-band shift Level-1 keeps: the design's shifts times what the processor's
/// co-registration leaves of them (|error| when it corrects, all of them when it does not); 0
/// without misregistration.
#[must_use]
pub fn registration_px(spec: &InstrumentSpec) -> f64 {
    effects::misregistration(&spec.effects).map_or(0.0, |m| {
        let shifts = m.shifts_px(spec.kind.model().band_count().max(1));
        let rms = (shifts.iter().map(|(a, c)| 0.5 * (a * a + c * c)).sum::<f64>() / shifts.len() as f64).sqrt();
        let left = if m.correction.corrected { m.correction.error.abs() } else { 1.0 };
        rms * left
    })
}

/// The largest departure from a straight line at full well the calibration leaves, %: the
/// curve's |a₂ + a₃| (its largest band's, the per-band list's where there is one; columns
/// spread about it by `column_spread`) times
/// |error| when it linearises, whole when not; 0 without non-linearity.
#[must_use]
pub fn nonlinearity_left_pct(spec: &InstrumentSpec) -> f64 {
    effects::non_linearity(&spec.effects).map_or(0.0, |n| {
        // A per-band list sets every band (the stated curve then applies to none).
        let worst = if n.per_band.is_empty() {
            (n.quadratic + n.cubic).abs()
        } else {
            n.per_band.iter().map(|&(q, c)| (q + c).abs()).fold(0.0, f64::max)
        };
        let left = if n.correction.corrected { n.correction.error.abs() } else { 1.0 };
        100.0 * worst * left
    })
}

impl Requirements {
    /// Check `spec`'s optics: the worst and sharpest band's MTF at Nyquist (both axes, each
    /// band on its focal plane), the largest polarisation sensitivity and the stray-light ratio
    /// at the stated distance and wavelength (0 where the design states no such effect).
    #[must_use]
    pub fn check_optics(&self, label: &str, seed: u64, spec: &InstrumentSpec) -> Vec<Check> {
        let mut out = Vec::new();
        let check = |what: String, value: Option<f64>, limit: f64, at_most: bool| {
            Check::of_design(label, seed, what, value, limit, at_most)
        };
        if self.mtf_nyquist_min.is_some() || self.mtf_nyquist_max.is_some() {
            // A band set that does not build has no MTF: the checks fail without a value.
            let table = nyquist_table(spec).ok();
            let values = || table.iter().flatten().flat_map(|r| [r.along, r.across]);
            let worst = table.as_ref().map(|_| values().fold(f64::INFINITY, f64::min));
            let sharpest = table.as_ref().map(|_| values().fold(0.0, f64::max));
            if let Some(l) = self.mtf_nyquist_min {
                out.push(check(MTF_MIN_WHAT.into(), worst, l, false));
            }
            if let Some(l) = self.mtf_nyquist_max {
                out.push(check(MTF_MAX_WHAT.into(), sharpest, l, true));
            }
        }
        if let Some(l) = self.polarisation_pct_max {
            let v = effects::polarisation_sensitivity(&spec.effects).unwrap_or(0.0);
            out.push(check(POLARISATION_WHAT.into(), Some(100.0 * v), l, true));
        }
        if let Some(s) = &self.stray_light {
            let v = effects::edge_ratio(&spec.effects, s.distance_m, s.centre_nm).unwrap_or(0.0);
            out.push(check(s.what(), Some(100.0 * v), s.ratio_pct_max, true));
        }
        if let Some(l) = self.registration_px_max {
            out.push(check(REGISTRATION_WHAT.into(), Some(registration_px(spec)), l, true));
        }
        if let Some(l) = self.nonlinearity_pct_max {
            out.push(check(NONLINEARITY_WHAT.into(), Some(nonlinearity_left_pct(spec)), l, true));
        }
        out
    }

    /// The focal-plane limits in range: registration above 0 up to 10 px, non-linearity above 0
    /// up to 50 %.
    pub(super) fn validate_focal_plane(&self) -> Result<(), super::StudyError> {
        for (field, value, hi, unit) in [
            ("requirements.registration_px_max", self.registration_px_max, 10.0, "px"),
            ("requirements.nonlinearity_pct_max", self.nonlinearity_pct_max, 50.0, "%"),
        ] {
            if let Some(v) = value
                && !(v.is_finite() && v > 0.0 && v <= hi)
            {
                return Err(super::StudyError::Invalid(crate::parse::FieldError {
                    field: field.into(),
                    message: format!("{v} (allowed: above 0 up to {hi} {unit})"),
                }));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::InstrumentEffect;
    use crate::instrument::effects::{Knowledge, MtfBudget, Polarisation};

    #[test]
    fn optics_checks_judge_the_designs_stated_effects() {
        let req = Requirements {
            mtf_nyquist_min: Some(0.2),
            mtf_nyquist_max: Some(0.6),
            polarisation_pct_max: Some(1.0),
            stray_light: Some(StrayLightRequirement { ratio_pct_max: 0.1, distance_m: 1000.0, centre_nm: 443.0 }),
            ..Requirements::default()
        };
        let mut spec = InstrumentSpec::preset("cubesat").unwrap();
        // An ideal optic: MTF of diffraction, pixel and smear; no polarisation, no stray light.
        let ideal = req.check_optics("A", 1, &spec);
        assert_eq!(ideal.len(), 4);
        assert!(ideal.iter().all(|c| c.pass), "{ideal:?}");
        assert_eq!(ideal[2].value, Some(0.0));
        // 2 % polarisation sensitivity fails a 1 % limit by 1 point; 8 µm diffusion drags the
        // MTF below 0.2.
        spec.effects.push(InstrumentEffect::Polarisation(Polarisation {
            sensitivity: 0.02,
            per_band: Vec::new(),
            axis_deg: 0.0,
            correction: Knowledge::default(),
        }));
        spec.effects.push(InstrumentEffect::SpatialResponse(MtfBudget { diffusion_um: 8.0, ..MtfBudget::default() }));
        let checks = req.check_optics("A", 1, &spec);
        let by = |what: &str| checks.iter().find(|c| c.what == what).unwrap();
        let p = by(POLARISATION_WHAT);
        assert!(!p.pass && (p.margin.unwrap() + 1.0).abs() < 1e-9, "{p:?}");
        let m = by(MTF_MIN_WHAT);
        assert!(!m.pass && m.value.unwrap() < 0.2, "{m:?}");
    }

    #[test]
    fn focal_plane_checks_judge_what_the_processor_leaves() {
        let req = Requirements {
            registration_px_max: Some(0.05),
            nonlinearity_pct_max: Some(0.5),
            ..Requirements::default()
        };
        let mut spec = InstrumentSpec::preset("cubesat").unwrap();
        assert!(req.check_optics("A", 1, &spec).iter().all(|c| c.pass && c.value == Some(0.0)));
        // Shifts of 0.3 px along and 0.4 across in every band (rms 0.354 px), co-registered to
        // 20 %: 0.0707 px left, over 0.05. A 2 % curve linearised 10 % wrong: 0.2 % left.
        spec.effects = ron::from_str(
            "[Misregistration((sigma_px: 0.0, per_band: [(0.3, 0.4)], correction: (corrected: true, error: 0.2))), \
             NonLinearity((quadratic: -0.025, cubic: 0.005, correction: (corrected: true, error: -0.1)))]",
        )
        .unwrap();
        spec.kind = ron::from_str("Multispectral(bands: Gaussian([(centre_nm: 560.0, fwhm_nm: 20.0)]))").unwrap();
        let checks = req.check_optics("A", 1, &spec);
        let by = |what: &str| checks.iter().find(|c| c.what == what).unwrap();
        let r = by(REGISTRATION_WHAT);
        assert!(!r.pass && (r.value.unwrap() - 0.2 * 0.125f64.sqrt()).abs() < 1e-12, "{r:?}");
        let n = by(NONLINEARITY_WHAT);
        assert!(n.pass && (n.value.unwrap() - 0.2).abs() < 1e-12, "{n:?}");
    }
}
