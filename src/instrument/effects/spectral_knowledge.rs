//! Spectral knowledge error: the instrument's bands are not quite where the processor believes
//! them. A band's centre and width are measured before launch (a monochromator scan) to a stated
//! uncertainty, and may move in orbit; a spectrograph's smile is known only approximately.
//!
//! The instrument integrates the scene over the bands it has, L_b = ∫L w_b,true / ∫w_b,true;
//! the processor models every band with the response it believes, w_b: the diffuser radiance
//! its calibration divides by, the Rayleigh and gas terms of the correction, the water model of
//! the retrieval. The Level-1 radiance therefore carries the ratio of the solar irradiance
//! through the two responses (the diffuser sees the sun), and the Level-2 reflectance the
//! mismatch between the scene's spectrum through the true band and the model's through the
//! believed one — largest where the spectrum is steep within a band (Fraunhofer lines, the
//! oxygen A band, the red edge of chlorophyll absorption). Green (1998) derives from this the
//! spectral calibration requirement of imaging spectrometers (a centre known to a few per cent
//! of the FWHM); Thompson et al. (2018) carry a wavelength-calibration uncertainty through the
//! retrieval.
//!
//! The shifts: every band's true centre is the believed one plus `centre_nm`, plus a normal draw
//! of rms `sigma_nm` per band from a generator of the design's own (`draw`), or the values of
//! `per_band_nm` where stated; every band's true SRF is the believed one stretched about its
//! centre by 1 + `width_pct`/100 (its FWHM with it), and a spectrograph's true smile is the
//! stated one times 1 + `smile_pct`/100. The effect acts on the spectral response the scene is
//! sampled with ([`crate::instrument::Response::sensed`]), not on the cube.
//!
//! ## References
//! - Green, R. O. (1998) Spectral calibration requirement for Earth-looking imaging
//!   spectrometers in the solar-reflected spectrum. Appl. Opt. 37, 683–690.
//! - Thompson, D. R., Natraj, V., Green, R. O., Helmlinger, M. C., Gao, B.-C., Eastwood, M. L.
//!   (2018) Optimal estimation for imaging spectrometer atmospheric correction. Remote Sens.
//!   Environ. 216, 355–373.

use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use super::{Effect, InstrumentError, check};
use crate::parse::FieldError;
use crate::ranges as r;

/// What the processor does not know of the bands, as an instrument file states it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpectralKnowledge {
    /// Every band's true centre minus the believed one, nm.
    #[serde(default)]
    pub centre_nm: f64,
    /// Rms of a further shift drawn per band, nm.
    #[serde(default)]
    pub sigma_nm: f64,
    /// Each band's shift, nm, replacing `centre_nm` and the draws (empty: those).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub per_band_nm: Vec<f64>,
    /// The draws' seed: another value, another set of shifts of the same rms.
    #[serde(default)]
    pub draw: u64,
    /// Every band's true width relative to the believed, % (5: 5 % wider).
    #[serde(default)]
    pub width_pct: f64,
    /// A spectrograph's true smile relative to the stated one, % (10: 10 % more).
    #[serde(default)]
    pub smile_pct: f64,
}

impl SpectralKnowledge {
    /// Each of `bands` bands' true centre minus the believed one, nm; an error naming the field
    /// when `per_band_nm` does not hold one value per band.
    pub fn shifts_nm(&self, bands: usize) -> Result<Vec<f64>, InstrumentError> {
        if !self.per_band_nm.is_empty() {
            if self.per_band_nm.len() != bands {
                return Err(InstrumentError::Invalid(FieldError {
                    field: "instrument.effects[].SpectralKnowledge.per_band_nm".into(),
                    message: format!(
                        "{} shifts for {bands} bands (allowed: one per band, or none)",
                        self.per_band_nm.len()
                    ),
                }));
            }
            return Ok(self.per_band_nm.clone());
        }
        Ok((0..bands)
            .map(|b| {
                if self.sigma_nm == 0.0 {
                    return self.centre_nm;
                }
                let seed =
                    self.draw.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (b as u64).wrapping_add(0x2545_F491_4F6C_DD1D);
                let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed);
                let z: f64 = StandardNormal.sample(&mut rng);
                self.centre_nm + self.sigma_nm * z
            })
            .collect())
    }

    /// The factor on every band's width about its centre.
    #[must_use]
    pub fn width_factor(&self) -> f64 {
        1.0 + self.width_pct / 100.0
    }

    /// The factor on a spectrograph's smile.
    #[must_use]
    pub fn smile_factor(&self) -> f64 {
        1.0 + self.smile_pct / 100.0
    }

    /// A short statement for tables ("bands +0.5 nm, 0.3 nm rms, width +2 %").
    #[must_use]
    pub fn describe(&self) -> String {
        let mut parts = Vec::new();
        if !self.per_band_nm.is_empty() {
            let largest = self.per_band_nm.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
            parts.push(format!("bands stated, up to {largest:.2} nm"));
        } else {
            if self.centre_nm != 0.0 {
                parts.push(format!("bands {:+.2} nm", self.centre_nm));
            }
            if self.sigma_nm != 0.0 {
                parts.push(format!("{:.2} nm rms per band", self.sigma_nm));
            }
        }
        if self.width_pct != 0.0 {
            parts.push(format!("width {:+.1} %", self.width_pct));
        }
        if self.smile_pct != 0.0 {
            parts.push(format!("smile {:+.0} %", self.smile_pct));
        }
        format!("spectral knowledge: {}", parts.join(", "))
    }

    /// Does it change nothing (the true bands are the believed ones)?
    #[must_use]
    pub fn is_exact(&self) -> bool {
        self.centre_nm == 0.0
            && self.sigma_nm == 0.0
            && self.per_band_nm.iter().all(|&d| d == 0.0)
            && self.width_pct == 0.0
            && self.smile_pct == 0.0
    }
}

impl Effect for SpectralKnowledge {
    fn name(&self) -> &'static str {
        "SpectralKnowledge"
    }

    fn role(&self) -> super::Role {
        super::Role::FocalPlane
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        check(&r::SPECTRAL_CENTRE_NM, self.centre_nm, &format!("{at}.centre_nm"))?;
        check(&r::SPECTRAL_SIGMA_NM, self.sigma_nm, &format!("{at}.sigma_nm"))?;
        for (i, &d) in self.per_band_nm.iter().enumerate() {
            check(&r::SPECTRAL_CENTRE_NM, d, &format!("{at}.per_band_nm[{i}]"))?;
        }
        check(&r::SPECTRAL_WIDTH_PCT, self.width_pct, &format!("{at}.width_pct"))?;
        check(&r::SPECTRAL_SMILE_PCT, self.smile_pct, &format!("{at}.smile_pct"))
    }

    /// It acts on the spectral response, not on the radiance cube.
    fn on_the_cube(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn knowledge() -> SpectralKnowledge {
        SpectralKnowledge {
            centre_nm: 0.5,
            sigma_nm: 0.0,
            per_band_nm: Vec::new(),
            draw: 0,
            width_pct: 0.0,
            smile_pct: 0.0,
        }
    }

    #[test]
    fn shifts_are_common_drawn_or_stated() {
        assert_eq!(knowledge().shifts_nm(3).unwrap(), vec![0.5; 3]);
        // Drawn: reproducible, another draw another set, the rms near sigma over many bands.
        let drawn = SpectralKnowledge { centre_nm: 0.0, sigma_nm: 0.3, ..knowledge() };
        let a = drawn.shifts_nm(400).unwrap();
        assert_eq!(a, drawn.shifts_nm(400).unwrap());
        assert_ne!(a, SpectralKnowledge { draw: 1, ..drawn.clone() }.shifts_nm(400).unwrap());
        let rms = (a.iter().map(|d| d * d).sum::<f64>() / a.len() as f64).sqrt();
        // 400 draws: the rms's relative standard error is 1/√800 = 3.5 %; 4σ.
        assert!((rms / 0.3 - 1.0).abs() < 0.14, "{rms}");
        // Stated per band: one per band, else an error naming the field.
        let stated = SpectralKnowledge { per_band_nm: vec![0.1, -0.2], ..knowledge() };
        assert_eq!(stated.shifts_nm(2).unwrap(), vec![0.1, -0.2]);
        let err = stated.shifts_nm(3).unwrap_err().to_string();
        assert!(err.contains("per_band_nm") && err.contains("2 shifts for 3 bands"), "{err}");
    }

    #[test]
    fn out_of_range_fields_are_named() {
        let bad = SpectralKnowledge { width_pct: 500.0, ..knowledge() };
        let err = bad.validate("instrument.effects[0].SpectralKnowledge").unwrap_err().to_string();
        assert!(err.contains("effects[0].SpectralKnowledge.width_pct"), "{err}");
        let bad = SpectralKnowledge { per_band_nm: vec![0.0, f64::NAN], ..knowledge() };
        let err = bad.validate("e").unwrap_err().to_string();
        assert!(err.contains("e.per_band_nm[1]"), "{err}");
        assert!(SpectralKnowledge { centre_nm: 0.0, ..knowledge() }.is_exact());
        assert!(!knowledge().is_exact());
    }
}
