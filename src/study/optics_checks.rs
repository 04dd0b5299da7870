//! The optics requirements of a design ([`Requirements`]: MTF at Nyquist, polarisation
//! sensitivity, stray light past a bright edge), judged from the design's stated effects
//! (`instrument::effects`; an ideal optic where it states none).

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
        out
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
}
