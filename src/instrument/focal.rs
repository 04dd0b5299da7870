//! Focal planes: an instrument's bands may sit on more than one detector — a silicon VNIR array
//! and an InGaAs or HgCdTe (MCT) SWIR array, or arrays of different pixel sizes — each with its
//! own pitch, count, quantum efficiency, dark current and readout.
//!
//! The instrument's own detector fields (`pixel_pitch_um`, `read_noise_e`, …) describe its first
//! focal plane; `focal_planes` lists the others, and a band sits on the first plane unless one
//! of them claims it. Every plane images through the same telescope, so a plane's ground
//! sampling is its pitch over the common focal length, and the image is simulated on the first
//! plane's grid:
//! - a plane whose pitch is k times the first's (k = 2, 3, …) reads one pixel per k × k block:
//!   its bands' radiance is averaged over the block, and the block's pixels share one exposure
//!   and readout (what nearest-neighbour resampling of the coarse band to the first plane's
//!   grid gives, as in Sentinel-2's 20 m and 60 m bands);
//! - a plane whose pitch is the first's divided by m (m = 2, 3, …) has m × m pixels in each
//!   pixel of the grid, averaged (binned) on the ground: its shot noise is that of m² pixels'
//!   electrons over m², and its read noise σ/m; the values are quantised once, after averaging
//!   (a rounding error of 1/12 DN² where averaging m² rounded values would give 1/(12 m²)).
//!
//! Dark current at the detector's temperature follows one of two laws ([`DarkLaw`]).
//!
//! ## References
//! - Janesick, J. R. (2001) Scientific Charge-Coupled Devices. SPIE Press, §7.2 (silicon dark
//!   current doubles every 5–7 °C near room temperature).
//! - Widenhorn, R., Blouke, M. M., Weber, A., Rest, A., Bodegom, E. (2002) Temperature
//!   dependence of dark current in a CCD. Proc. SPIE 4669, 193–201 (Arrhenius law,
//!   I ∝ exp(−E_a/kT)).
//! - Rogalski, A. (2011) Infrared Detectors, 2nd ed. CRC Press, ch. 13 (InGaAs) and 14 (HgCdTe):
//!   diffusion-limited dark current with activation energy near the band gap.

use serde::{Deserialize, Serialize};

use super::InstrumentError;
use crate::parse::FieldError;
use crate::spectral::SpectrumSource;

/// Boltzmann constant, eV K⁻¹ (CODATA 2018, exact).
const BOLTZMANN_EV_K: f64 = 8.617_333_262e-5;
/// 0 °C in kelvin.
const ZERO_C_K: f64 = 273.15;

/// How dark current changes with the detector's temperature.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum DarkLaw {
    /// Doubles every `delta_c` °C: I(T) = I_ref · 2^((T − T_ref)/ΔT) (silicon near room
    /// temperature, ΔT = 5–7 °C; Janesick 2001, §7.2).
    Doubling {
        /// Temperature rise that doubles the dark current, °C (0.5–50).
        delta_c: f64,
    },
    /// Arrhenius: I(T) = I_ref · exp(−(E_a/k)(1/T − 1/T_ref)) (Widenhorn et al. 2002); E_a near
    /// the band gap for diffusion-limited InGaAs and HgCdTe (Rogalski 2011).
    Arrhenius {
        /// Activation energy, eV (0.05–2).
        activation_ev: f64,
    },
}

/// The temperature the dark current was specified at and the one the detector runs at.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DarkTemperature {
    /// Temperature at which `dark_current_e_s` is specified, °C.
    pub reference_c: f64,
    /// Operating temperature, °C.
    pub operating_c: f64,
    /// The law between them.
    pub law: DarkLaw,
}

impl DarkTemperature {
    /// The factor dark current is multiplied by from the reference to the operating temperature.
    #[must_use]
    pub fn factor(&self) -> f64 {
        match self.law {
            DarkLaw::Doubling { delta_c } => 2f64.powf((self.operating_c - self.reference_c) / delta_c),
            DarkLaw::Arrhenius { activation_ev } => {
                let (t, t_ref) = (self.operating_c + ZERO_C_K, self.reference_c + ZERO_C_K);
                (-(activation_ev / BOLTZMANN_EV_K) * (1.0 / t - 1.0 / t_ref)).exp()
            }
        }
    }

    /// Check the temperatures and the law's parameter; `at` is the field path up to here.
    pub fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        use crate::ranges as r;
        let check = |range: &r::Range, v: f64| {
            range.check(v).map_err(|message| {
                let suffix = range.path.strip_prefix("instrument.dark_temperature.").unwrap_or(range.path);
                InstrumentError::Invalid(FieldError { field: format!("{at}.{suffix}"), message })
            })
        };
        check(&r::DARK_REFERENCE_C, self.reference_c)?;
        check(&r::DARK_OPERATING_C, self.operating_c)?;
        match self.law {
            DarkLaw::Doubling { delta_c } => check(&r::DARK_DOUBLING_DELTA_C, delta_c),
            DarkLaw::Arrhenius { activation_ev } => check(&r::DARK_ACTIVATION_EV, activation_ev),
        }
    }
}

/// The detector material: what the editor and the review pack call the plane (the physics is in
/// its numbers: QE curve, dark current, noise).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum DetectorMaterial {
    /// Silicon CCD or CMOS (to about 1000 nm).
    #[default]
    Silicon,
    /// Standard InGaAs (about 900–1700 nm).
    InGaAs,
    /// Extended-wavelength InGaAs (to about 2500 nm).
    ExtendedInGaAs,
    /// Mercury cadmium telluride (HgCdTe), cut-off at 2.5 µm or beyond.
    Mct,
}

impl DetectorMaterial {
    /// The name in text.
    #[must_use]
    pub const fn label(self) -> &'static str {
        match self {
            Self::Silicon => "silicon",
            Self::InGaAs => "InGaAs",
            Self::ExtendedInGaAs => "extended InGaAs",
            Self::Mct => "HgCdTe (MCT)",
        }
    }
}

/// Which bands a plane holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum BandSelection {
    /// Bands by name (`"B11"`, `"Oa21"`, or a Gaussian band's name).
    Names(Vec<String>),
    /// Every band whose centre lies in `from_nm`–`to_nm`.
    Centres {
        /// Shortest centre, nm.
        from_nm: f64,
        /// Longest centre, nm.
        to_nm: f64,
    },
}

impl BandSelection {
    /// Does the band named `name` centred at `centre_nm` belong here?
    #[must_use]
    pub fn holds(&self, name: &str, centre_nm: f64) -> bool {
        match self {
            Self::Names(names) => names.iter().any(|n| n == name),
            Self::Centres { from_nm, to_nm } => (*from_nm..=*to_nm).contains(&centre_nm),
        }
    }
}

fn default_qe() -> SpectrumSource {
    SpectrumSource::Constant(0.7)
}

/// A focal plane beyond the instrument's first.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FocalPlane {
    /// Short name (`"SWIR"`).
    pub name: String,
    /// Detector material.
    #[serde(default)]
    pub material: DetectorMaterial,
    /// The bands it holds.
    pub bands: BandSelection,
    /// Pixel pitch, µm: the first plane's times or divided by a whole number.
    pub pixel_pitch_um: f64,
    /// Detectors across track: enough for the first plane's swath.
    pub detectors: usize,
    /// Quantum efficiency (0–1) against wavelength.
    #[serde(default = "default_qe")]
    pub quantum_efficiency: SpectrumSource,
    /// Dark current, e⁻ s⁻¹ per pixel (at `dark_temperature.reference_c` when given).
    #[serde(default)]
    pub dark_current_e_s: f64,
    /// The dark current's temperature law, when it is specified at another temperature.
    #[serde(default)]
    pub dark_temperature: Option<DarkTemperature>,
    /// Read noise, e⁻ rms.
    pub read_noise_e: f64,
    /// Full-well capacity, e⁻.
    pub well_depth_e: f64,
    /// Conversion gain, e⁻ per DN.
    pub gain_e_per_dn: f64,
    /// Bias, DN.
    pub bias_dn: f64,
    /// ADC resolution, bits (1–16).
    pub adc_bits: u32,
    /// Photo-response non-uniformity, relative rms.
    #[serde(default)]
    pub prnu: f64,
    /// Dark-signal non-uniformity, e⁻ rms.
    #[serde(default)]
    pub dsnu_e: f64,
    /// Integration time of this plane's pixels, s. By default the instrument's `exposure_s`
    /// times the pitch ratio: the same share of its own line period (a pushbroom pixel twice as
    /// large crosses its footprint in twice the time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exposure_s: Option<f64>,
}

/// How a plane's pixels map onto the first plane's grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sampling {
    /// One pixel per grid pixel.
    Same,
    /// One pixel per k × k block of grid pixels.
    Coarse(usize),
    /// m × m pixels binned into each grid pixel.
    Fine(usize),
}

impl Sampling {
    /// Grid pixels per plane pixel along a side (k for `Coarse(k)`, 1 otherwise).
    #[must_use]
    pub fn block(self) -> usize {
        if let Self::Coarse(k) = self { k } else { 1 }
    }

    /// Plane pixels binned into a grid pixel (m² for `Fine(m)`, 1 otherwise).
    #[must_use]
    pub fn binned(self) -> usize {
        if let Self::Fine(m) = self { m * m } else { 1 }
    }

    /// The sampling of a plane of `pitch_um` on a grid of `first_pitch_um`, or why not.
    pub fn of(pitch_um: f64, first_pitch_um: f64) -> Result<Self, String> {
        let whole = |x: f64| {
            let n = x.round();
            ((x - n).abs() < 1e-6 * x.max(1.0) && n >= 1.0).then_some(n as usize)
        };
        let ratio = pitch_um / first_pitch_um;
        match (whole(ratio), whole(1.0 / ratio)) {
            (Some(1), _) => Ok(Self::Same),
            (Some(k), _) if k <= 16 => Ok(Self::Coarse(k)),
            (_, Some(m)) if m <= 8 => Ok(Self::Fine(m)),
            _ => Err(format!(
                "{pitch_um} µm is {ratio:.4} times the first plane's {first_pitch_um} µm (allowed: a whole multiple \
                 up to 16×, or a whole fraction down to 1/8, so that its pixels tile the image's grid)"
            )),
        }
    }
}

impl FocalPlane {
    /// Integration time, s, on an instrument whose first plane has `first_pitch_um` and
    /// integrates `first_exposure_s`.
    #[must_use]
    pub fn exposure_on(&self, first_pitch_um: f64, first_exposure_s: f64) -> f64 {
        self.exposure_s.unwrap_or(first_exposure_s * self.pixel_pitch_um / first_pitch_um)
    }

    /// Dark current at the operating temperature, e⁻ s⁻¹.
    #[must_use]
    pub fn dark_current_at_operating_e_s(&self) -> f64 {
        self.dark_current_e_s * self.dark_temperature.map_or(1.0, |t| t.factor())
    }

    /// Largest DN of the ADC, 2^bits − 1.
    #[must_use]
    pub fn dn_max(&self) -> f64 {
        f64::from((1u32 << self.adc_bits.min(16)) - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dark_current_laws() {
        let doubling =
            DarkTemperature { reference_c: 20.0, operating_c: 34.0, law: DarkLaw::Doubling { delta_c: 7.0 } };
        assert!((doubling.factor() - 4.0).abs() < 1e-12);
        // Arrhenius with E_a = 0.75 eV from 20 °C to 0 °C: exp(−(0.75/k)(1/273.15 − 1/293.15)).
        let cold =
            DarkTemperature { reference_c: 20.0, operating_c: 0.0, law: DarkLaw::Arrhenius { activation_ev: 0.75 } };
        let expected = (-(0.75 / BOLTZMANN_EV_K) * (1.0 / 273.15 - 1.0 / 293.15)).exp();
        assert!((cold.factor() - expected).abs() < 1e-15 && cold.factor() < 0.15, "{}", cold.factor());
        let same =
            DarkTemperature { reference_c: 5.0, operating_c: 5.0, law: DarkLaw::Arrhenius { activation_ev: 1.1 } };
        assert_eq!(same.factor(), 1.0);
    }

    #[test]
    fn planes_tile_the_grid_or_are_refused() {
        assert_eq!(Sampling::of(15.0, 15.0), Ok(Sampling::Same));
        assert_eq!(Sampling::of(45.0, 15.0), Ok(Sampling::Coarse(3)));
        assert_eq!(Sampling::of(7.5, 15.0), Ok(Sampling::Fine(2)));
        let e = Sampling::of(20.0, 15.0).unwrap_err();
        assert!(e.contains("1.3333") && e.contains("whole multiple"), "{e}");
        assert_eq!((Sampling::Coarse(3).block(), Sampling::Fine(2).binned()), (3, 4));
    }
}
