//! The instrument as written in RON (`presets/instruments/`): every parameter of Matthews et al.
//! (2023) Table 1, plus the model kind and its own parameters.

use serde::{Deserialize, Serialize};

use super::InstrumentError;
use super::effects::InstrumentEffect;
use super::focal::{DarkTemperature, DetectorMaterial, FocalPlane, Sampling};
use crate::parse::{FieldError, ParseError};
use crate::spectral::{BandSetSpec, SpectrumSource};

/// Which instrument model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum InstrumentKind {
    /// Band-pass multispectral imager: every band sees the same ground pixel through its SRF.
    Multispectral {
        /// Bands (OLCI, MSI or Gaussian).
        bands: BandSetSpec,
    },
    /// Ideal radiometer for reference runs: the same bands, no noise, no quantisation, no
    /// saturation.
    IdealRadiometer {
        /// Bands.
        bands: BandSetSpec,
    },
    /// Long-slit dispersive spectrograph (CHICO-like): the spectrum is dispersed along one axis
    /// of the detector, one row per spectral sample; Gaussian spectral response.
    Spectrograph {
        /// First band centre, nm.
        start_nm: f64,
        /// Last band centre (at most), nm.
        end_nm: f64,
        /// Spectral sampling (dispersion × pixel pitch), nm per row.
        sampling_nm: f64,
        /// Spectral resolution (FWHM), nm.
        resolution_nm: f64,
        /// Smile: shift of the band centres at the swath edges, nm (quadratic across track).
        #[serde(default)]
        smile_nm: f64,
        /// Keystone: across-track misregistration between the first and last band, pixels.
        #[serde(default)]
        keystone_px: f64,
        /// Adjacent spectral samples summed into one band (spectral binning: the instrument as
        /// flown sets it from a `Binning` effect's `spectral`; 1: none).
        #[serde(default = "one")]
        channels_summed: usize,
    },
    /// Gradient / linear-variable-filter imager (CyanoSat-like): the pass band changes along
    /// track across the focal plane, so each band looks at the ground from a different along-track
    /// angle and sees a point at a different time.
    FilterImager {
        /// Bands, in order along the focal plane.
        bands: BandSetSpec,
        /// Detector rows between successive band centres on the focal plane.
        rows_per_band: usize,
    },
}

fn one() -> usize {
    1
}

fn default_qe() -> SpectrumSource {
    SpectrumSource::Constant(0.7)
}

/// A Level-0 instrument (Table 1 of Matthews et al. 2023 and the model's parameters).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InstrumentSpec {
    /// Short name.
    pub name: String,
    /// What it is.
    #[serde(default)]
    pub description: String,
    /// Model kind and spectral configuration.
    pub kind: InstrumentKind,
    /// Orbit altitude, km (200–1500).
    pub altitude_km: f64,
    /// Orbital heading azimuth, degrees clockwise from north.
    #[serde(default)]
    pub heading_deg: f64,
    /// Aperture diameter, mm (1–2000).
    pub aperture_mm: f64,
    /// Detector pixel pitch, µm (1–100).
    pub pixel_pitch_um: f64,
    /// Focal length, mm (1–10 000).
    pub focal_length_mm: f64,
    /// Detectors across track (1–20 000).
    pub detectors: usize,
    /// Exposure (integration) time, s.
    pub exposure_s: f64,
    /// Lines (exposures) along track (1–100 000). Files written before the rename say
    /// `exposures` ([`crate::schema::RENAMES`]).
    pub lines: usize,
    /// Forward tilt of the line of sight, degrees (−60 to 60).
    #[serde(default)]
    pub forward_tilt_deg: f64,
    /// Across-track pointing of the line of sight (roll), degrees (−60 to 60, positive: right
    /// of the ground track); a fixed shift of the swath away from the sun's glint (as OLCI's
    /// 12.6° west), or where a season's pass sees the site.
    #[serde(default)]
    pub across_track_tilt_deg: f64,
    /// Read noise, electrons rms.
    pub read_noise_e: f64,
    /// Full-well capacity, electrons.
    pub well_depth_e: f64,
    /// Conversion gain, electrons per DN.
    pub gain_e_per_dn: f64,
    /// Bias (offset), DN.
    pub bias_dn: f64,
    /// ADC resolution, bits (1–16).
    pub adc_bits: u32,
    /// Optical transmission of the telescope and filters (0–1).
    pub optical_transmission: f64,
    /// Detector quantum efficiency (0–1) against wavelength. Table 1 gives no curve; the presets
    /// assume a flat 0.7 — supply the detector's own curve (CSV) for a real design.
    #[serde(default = "default_qe")]
    pub quantum_efficiency: SpectrumSource,
    /// Dark current, electrons per second per pixel.
    #[serde(default)]
    pub dark_current_e_s: f64,
    /// Photo-response non-uniformity, relative rms across detectors (fixed pattern).
    #[serde(default)]
    pub prnu: f64,
    /// Dark-signal non-uniformity, electrons rms across detectors (fixed pattern).
    #[serde(default)]
    pub dsnu_e: f64,
    /// The first focal plane's dark-current temperature law, when `dark_current_e_s` is given
    /// at another temperature than the detector runs at.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dark_temperature: Option<DarkTemperature>,
    /// The first focal plane's detector material (the fields above are its numbers).
    #[serde(default, skip_serializing_if = "is_silicon")]
    pub material: DetectorMaterial,
    /// Focal planes beyond the first ([`super::focal`]); a band sits on the first unless one of
    /// these claims it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub focal_planes: Vec<FocalPlane>,
    /// The optics between the entrance pupil and the detector ([`super::effects`]: stray light,
    /// polarisation sensitivity), applied in order; none: an ideal optic.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub effects: Vec<InstrumentEffect>,
}

fn is_silicon(m: &DetectorMaterial) -> bool {
    *m == DetectorMaterial::Silicon
}

/// Orbital ground speed for a circular orbit at `altitude_km`: v = √(GM/(R+h))·R/(R+h).
#[must_use]
pub fn ground_speed_m_s(altitude_km: f64) -> f64 {
    use crate::units::{EARTH_GM_M3_S2, EARTH_RADIUS_M};
    let a = EARTH_RADIUS_M + altitude_km * 1e3;
    (EARTH_GM_M3_S2 / a).sqrt() * EARTH_RADIUS_M / a
}

impl InstrumentSpec {
    /// Parse RON; `origin` names the file in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Self, InstrumentError> {
        crate::parse::from_ron(text, origin)
    }

    /// A built-in instrument by name (`presets/instruments/NAME.ron`).
    pub fn preset(name: &str) -> Result<Self, InstrumentError> {
        crate::parse::preset(name)
    }

    /// Names of the built-in instruments.
    #[must_use]
    pub fn preset_names() -> Vec<String> {
        crate::parse::preset_names::<Self>()
    }

    /// Check every number against its documented range ([`crate::ranges`]); the message names
    /// field, value and range.
    pub fn validate(&self) -> Result<(), InstrumentError> {
        use crate::ranges as r;
        let check = |range: &r::Range, v: f64| {
            range.check(v).map_err(|message| {
                InstrumentError::Invalid(FieldError { field: range.field("instrument.").into(), message })
            })
        };
        let count = |n: usize| n as f64;
        crate::parse::check_name("instrument.name", &self.name).map_err(InstrumentError::Invalid)?;
        check(&r::INSTRUMENT_ALTITUDE_KM, self.altitude_km)?;
        check(&r::INSTRUMENT_HEADING_DEG, self.heading_deg)?;
        check(&r::INSTRUMENT_APERTURE_MM, self.aperture_mm)?;
        check(&r::INSTRUMENT_PIXEL_PITCH_UM, self.pixel_pitch_um)?;
        check(&r::INSTRUMENT_FOCAL_LENGTH_MM, self.focal_length_mm)?;
        check(&r::INSTRUMENT_DETECTORS, count(self.detectors))?;
        check(&r::INSTRUMENT_EXPOSURE_S, self.exposure_s)?;
        check(&r::INSTRUMENT_LINES, count(self.lines))?;
        check(&r::INSTRUMENT_FORWARD_TILT_DEG, self.forward_tilt_deg)?;
        check(&r::INSTRUMENT_ACROSS_TRACK_TILT_DEG, self.across_track_tilt_deg)?;
        check(&r::INSTRUMENT_READ_NOISE_E, self.read_noise_e)?;
        check(&r::INSTRUMENT_WELL_DEPTH_E, self.well_depth_e)?;
        check(&r::INSTRUMENT_GAIN_E_PER_DN, self.gain_e_per_dn)?;
        check(&r::INSTRUMENT_BIAS_DN, self.bias_dn)?;
        check(&r::INSTRUMENT_ADC_BITS, f64::from(self.adc_bits))?;
        // The offset must leave counts for a signal: at or above the largest count the full
        // scale is 0 e⁻ and every pixel saturates.
        let max_dn = f64::from(u32::MAX >> (32 - self.adc_bits));
        if self.bias_dn >= max_dn {
            return Err(InstrumentError::Invalid(FieldError {
                field: r::INSTRUMENT_BIAS_DN.field("instrument.").into(),
                message: format!(
                    "{} is at or above the largest count of a {}-bit ADC ({max_dn}): no signal could be read (allowed: 0 to below {max_dn} DN)",
                    self.bias_dn, self.adc_bits
                ),
            }));
        }
        check(&r::INSTRUMENT_OPTICAL_TRANSMISSION, self.optical_transmission)?;
        check(&r::INSTRUMENT_DARK_CURRENT_E_S, self.dark_current_e_s)?;
        check(&r::INSTRUMENT_PRNU, self.prnu)?;
        check(&r::INSTRUMENT_DSNU_E, self.dsnu_e)?;
        if let Some(t) = &self.dark_temperature {
            t.validate("instrument.dark_temperature")?;
        }
        self.validate_planes()?;
        super::effects::validate(&self.effects)?;
        self.validate_tdi()?;
        // The kind's own fields (a spectrograph's span and sampling, a filter imager's rows).
        self.kind.model().validate()?;
        if let Some(b) = super::effects::binning(&self.effects) {
            super::effects::binning::check_fits(b, self)?;
        }
        // One stated band shift per band.
        if let Some(k) = super::effects::spectral_knowledge(&self.effects)
            && !k.per_band_nm.is_empty()
        {
            k.shifts_nm(self.kind.model().band_set()?.len())?;
        }
        Ok(())
    }

    /// Check the focal planes beyond the first: each number in its range, a pitch that tiles the
    /// first plane's grid, enough detectors for its swath.
    /// TDI integrates along track: not on a spectrograph (whose along-track axis is its
    /// spectrum), and within a filter imager's rows per band.
    fn validate_tdi(&self) -> Result<(), InstrumentError> {
        let Some(tdi) = super::effects::tdi(&self.effects) else { return Ok(()) };
        let refuse = |message: String| {
            Err(InstrumentError::Invalid(FieldError { field: "instrument.effects[].Tdi.stages".into(), message }))
        };
        match &self.kind {
            InstrumentKind::Spectrograph { .. } if tdi.stages > 1 => refuse(format!(
                "{} stages on a spectrograph, whose along-track axis is its spectrum (allowed: 1)",
                tdi.stages
            )),
            InstrumentKind::FilterImager { rows_per_band, .. } if tdi.stages as usize > *rows_per_band => refuse(
                format!("{} stages on {rows_per_band} rows per band (allowed: 1 to {rows_per_band})", tdi.stages),
            ),
            _ => Ok(()),
        }
    }

    fn validate_planes(&self) -> Result<(), InstrumentError> {
        use crate::ranges as r;
        for (i, p) in self.focal_planes.iter().enumerate() {
            let at = format!("instrument.focal_planes[{i}]");
            let fail = |field: &str, message: String| {
                InstrumentError::Invalid(FieldError { field: format!("{at}.{field}"), message })
            };
            let check = |range: &r::Range, v: f64| range.check(v).map_err(|m| fail(range.name(), m));
            crate::parse::check_name(&format!("{at}.name"), &p.name).map_err(InstrumentError::Invalid)?;
            check(&r::PLANE_PIXEL_PITCH_UM, p.pixel_pitch_um)?;
            check(&r::PLANE_DETECTORS, p.detectors as f64)?;
            check(&r::PLANE_READ_NOISE_E, p.read_noise_e)?;
            check(&r::PLANE_WELL_DEPTH_E, p.well_depth_e)?;
            check(&r::PLANE_GAIN_E_PER_DN, p.gain_e_per_dn)?;
            check(&r::PLANE_BIAS_DN, p.bias_dn)?;
            check(&r::PLANE_ADC_BITS, f64::from(p.adc_bits))?;
            check(&r::PLANE_DARK_CURRENT_E_S, p.dark_current_e_s)?;
            check(&r::PLANE_PRNU, p.prnu)?;
            check(&r::PLANE_DSNU_E, p.dsnu_e)?;
            if let Some(t) = p.exposure_s {
                check(&r::PLANE_EXPOSURE_S, t)?;
            }
            if p.bias_dn >= p.dn_max() {
                return Err(fail(
                    "bias_dn",
                    format!(
                        "{} is at or above the largest count of a {}-bit ADC ({}): no signal could be read (allowed: 0 to below {} DN)",
                        p.bias_dn,
                        p.adc_bits,
                        p.dn_max(),
                        p.dn_max()
                    ),
                ));
            }
            if let Some(t) = &p.dark_temperature {
                t.validate(&format!("{at}.dark_temperature"))?;
            }
            let sampling =
                Sampling::of(p.pixel_pitch_um, self.pixel_pitch_um).map_err(|m| fail("pixel_pitch_um", m))?;
            // Its swath must cover the first plane's (a band missing at the edges has no value
            // to retrieve from).
            let swath = p.detectors as f64 * p.pixel_pitch_um;
            let first = self.detectors as f64 * self.pixel_pitch_um;
            if swath < first * (1.0 - 1e-9) {
                let needed = (first / p.pixel_pitch_um).ceil();
                return Err(fail(
                    "detectors",
                    format!(
                        "{} detectors of {} µm span less than the first plane's {} × {} µm (allowed: at least {needed}, so that its swath covers the image's; sampling {sampling:?})",
                        p.detectors, p.pixel_pitch_um, self.detectors, self.pixel_pitch_um
                    ),
                ));
            }
            if self.focal_planes[..i].iter().any(|q| q.name == p.name) {
                return Err(fail("name", format!("`{}` names two focal planes (allowed: one name per plane)", p.name)));
            }
        }
        Ok(())
    }

    /// Dark current of the first focal plane at its operating temperature, e⁻ s⁻¹.
    #[must_use]
    pub fn dark_current_at_operating_e_s(&self) -> f64 {
        self.dark_current_e_s * self.dark_temperature.map_or(1.0, |t| t.factor())
    }

    /// The instrument as flown: with on-board binning folded into its pixels
    /// ([`super::effects::Binning::flown`]), else itself. The engine simulates this one, and its
    /// GSD, SNR and data budget are the design's.
    #[must_use]
    pub fn as_flown(&self) -> std::borrow::Cow<'_, Self> {
        match super::effects::binning(&self.effects) {
            Some(b) => std::borrow::Cow::Owned(b.flown(self)),
            None => std::borrow::Cow::Borrowed(self),
        }
    }

    /// Ground sampling distance at nadir, m: GSD = altitude · pitch / focal length.
    ///
    /// ```
    /// let i = shoal::instrument::InstrumentSpec::preset("nominal").unwrap();
    /// assert!((i.gsd_m() - 18.667).abs() < 1e-3);
    /// ```
    #[must_use]
    pub fn gsd_m(&self) -> f64 {
        self.altitude_km * 1e3 * self.pixel_pitch_um * 1e-6 / (self.focal_length_mm * 1e-3)
    }

    /// Swath width at nadir, m.
    #[must_use]
    pub fn swath_m(&self) -> f64 {
        self.gsd_m() * self.detectors as f64
    }

    /// Focal ratio f/D.
    #[must_use]
    pub fn f_number(&self) -> f64 {
        self.focal_length_mm / self.aperture_mm
    }

    /// Étendue of one pixel, m² sr: A·Ω = (πD²/4)·(p/f)².
    #[must_use]
    pub fn etendue_m2_sr(&self) -> f64 {
        let d = self.aperture_mm * 1e-3;
        let ifov = self.pixel_pitch_um * 1e-6 / (self.focal_length_mm * 1e-3);
        std::f64::consts::PI * d * d / 4.0 * ifov * ifov
    }

    /// What the design is, from its parameters (never from its preset's text, which an edit
    /// leaves behind): "60.0 mm aperture, f/2.75, 5.86 µm pixels, 1024 × 30.0 m (30.7 km swath),
    /// 1.50 ms exposure, 12-bit, 8 bands 443–865 nm".
    ///
    /// ```
    /// let mut i = shoal::instrument::InstrumentSpec::preset("cubesat").unwrap();
    /// i.aperture_mm = 105.8;
    /// assert!(i.summary().starts_with("105.8 mm aperture, f/1.56"), "{}", i.summary());
    /// ```
    #[must_use]
    pub fn summary(&self) -> String {
        let sig = |v: f64| crate::colormap::significant(v, 3);
        let bands = self.kind.model().band_set().map(|b| b.centres_nm()).unwrap_or_default();
        let range = match (bands.iter().copied().reduce(f64::min), bands.iter().copied().reduce(f64::max)) {
            (Some(lo), Some(hi)) => format!(", {} bands {lo:.0}–{hi:.0} nm", bands.len()),
            _ => String::new(),
        };
        format!(
            "{:.1} mm aperture, f/{:.2}, {:.2} µm pixels, {} × {} m ({} km swath), {:.2} ms exposure, {}-bit{range}",
            self.aperture_mm,
            self.f_number(),
            self.pixel_pitch_um,
            self.detectors,
            sig(self.gsd_m()),
            sig(self.swath_m() / 1e3),
            self.exposure_s * 1e3,
            self.adc_bits,
        )
    }

    /// Largest DN the ADC produces, 2^bits − 1.
    #[must_use]
    pub fn dn_max(&self) -> f64 {
        f64::from((1u32 << self.adc_bits.min(16)) - 1)
    }
}

impl crate::parse::Preset for InstrumentSpec {
    const FOLDER: &'static str = "instruments";
    type Error = InstrumentError;
    fn parse_error(origin: &str, message: String) -> InstrumentError {
        InstrumentError::Parse(ParseError { origin: origin.into(), message })
    }
    fn unknown(name: &str, known: &[String]) -> InstrumentError {
        InstrumentError::Invalid(FieldError {
            field: "instrument".into(),
            message: format!("no built-in instrument `{name}` (known: {})", known.join(", ")),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Files written before `exposures` became `lines` still load, with the same value.
    #[test]
    fn an_instrument_file_that_says_exposures_still_loads() {
        let text = crate::assets::preset("instruments/cubesat.ron").expect("the CubeSat preset").text;
        assert!(text.contains("    lines: "), "the preset says `lines`");
        let old = text.replace("    lines: ", "    exposures: ");
        let new_spec: InstrumentSpec = crate::parse::from_ron(text, "cubesat.ron").expect("parses");
        let old_spec: InstrumentSpec = crate::parse::from_ron(&old, "old.ron").expect("the old name parses");
        assert_eq!(old_spec, new_spec);
        assert_eq!(new_spec.lines, 2000);
    }
}
