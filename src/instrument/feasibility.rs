//! Feasibility figures of a design flown over a scene: the numbers a phase-0 reviewer checks
//! before believing any SNR — how fast the optics are, whether the optics or the pixel sets the
//! resolution, how far a ground point moves during an exposure, how close the brightest water
//! comes to full scale, and whether the ADC step or the read noise sets the noise floor. The
//! engine computes them as the `Feasibility` stage; the plausibility warnings
//! ([`super::plausibility`]) are the subset that crosses a hard limit.
//!
//! ## Formulas
//! - f-number N = f / D (Smith 2008, §6.3).
//! - Airy disc diameter to the first dark ring, 2.44·λ·N (Hecht 2017, §10.2.5, eq. 10.59: first
//!   zero at radius 1.22·λ·f/D in the focal plane).
//! - Optical Q = λ·N / p, the ratio of the optics' sampling frequency to the detector's (Fiete
//!   1999): Q = 2 samples the diffraction-limited optics at Nyquist; Q < 1 leaves aliasing
//!   (detector-limited); most Earth-observation imagers fly 0.5 < Q < 2.
//! - Along-track smear, pixels = exposure / line period (Schowengerdt 2007, §3.4).
//! - Peak signal as a fraction of full scale min(well, (2^bits − 1 − bias)·gain) at the scene's
//!   brightest water radiance ([`super::plausibility::full_scale_e`]; Janesick 2007).
//! - Quantisation noise of an ideal ADC, gain/√12 electrons rms (uniform error over one DN step;
//!   Janesick 2007, ch. 6), against the read noise.
//!
//! ## References
//! - Fiete, R. D. (1999) Image quality and λFN/p for remote sensing systems. Opt. Eng. 38,
//!   1229–1240.
//! - Hecht, E. (2017) Optics, 5th ed. Pearson.
//! - Janesick, J. R. (2007) Photon Transfer: DN → λ. SPIE Press.
//! - Schowengerdt, R. A. (2007) Remote Sensing: Models and Methods for Image Processing, 3rd ed.
//! - Smith, W. J. (2008) Modern Optical Engineering, 4th ed. McGraw-Hill.

use serde::Serialize;

use super::plausibility::{Warning, assess, full_scale_e, peak_signal_e};
use super::{Detector, InstrumentSpec};

/// Q below which the pixel, not the optics, sets the resolution (aliasing; Fiete 1999).
pub const Q_DETECTOR_LIMITED: f64 = 0.5;
/// Q above which the optics blur over two pixels or more (resolution the pixels cannot use).
pub const Q_OPTICS_LIMITED: f64 = 2.0;
/// Peak signal share of full scale above which a brighter scene than this one saturates.
pub const SATURATION_HEADROOM: f64 = 0.8;

/// One band's figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BandFeasibility {
    /// Band name.
    pub band: String,
    /// Band centre, nm.
    pub centre_nm: f64,
    /// Airy disc diameter to the first dark ring, µm in the focal plane.
    pub airy_diameter_um: f64,
    /// Optical Q = λ·N / p.
    pub q: f64,
    /// Peak signal at the scene's brightest water radiance over full scale (worst detector).
    pub peak_fraction_of_full_scale: f64,
}

/// The figures of one design over one scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Feasibility {
    /// f-number N = f / D.
    pub f_number: f64,
    /// Along-track smear over one exposure, pixels.
    pub smear_px: f64,
    /// Quantisation noise gain/√12, electrons rms.
    pub quantisation_noise_e: f64,
    /// Read noise, electrons rms.
    pub read_noise_e: f64,
    /// Per band.
    pub bands: Vec<BandFeasibility>,
    /// The plausibility guards crossed (saturation, smear over a pixel, f-number below 1).
    pub warnings: Vec<Warning>,
}

impl Feasibility {
    /// The figures of `spec` with its `detector`, bands `names` centred at `centres_nm`, over a
    /// scene whose brightest water radiance per band is `brightest_w_m2_sr_nm`, at the run's
    /// line period.
    #[must_use]
    pub fn assess(
        spec: &InstrumentSpec,
        detector: &Detector,
        names: &[String],
        centres_nm: &[f64],
        brightest_w_m2_sr_nm: &[f64],
        line_period_s: f64,
    ) -> Self {
        let f_number = spec.focal_length_mm / spec.aperture_mm;
        let bands = names
            .iter()
            .zip(centres_nm)
            .enumerate()
            .map(|(b, (name, &centre_nm))| {
                let lambda_um = centre_nm * 1e-3;
                let peak_e = peak_signal_e(detector, b, brightest_w_m2_sr_nm.get(b).copied().unwrap_or(0.0));
                BandFeasibility {
                    band: name.clone(),
                    centre_nm,
                    airy_diameter_um: 2.44 * lambda_um * f_number,
                    q: lambda_um * f_number / spec.pixel_pitch_um,
                    peak_fraction_of_full_scale: {
                        let full = full_scale_e(detector, b);
                        if full > 0.0 { peak_e / full } else { f64::INFINITY }
                    },
                }
            })
            .collect();
        Self {
            f_number,
            smear_px: if line_period_s > 0.0 { spec.exposure_s / line_period_s } else { 0.0 },
            quantisation_noise_e: spec.gain_e_per_dn / 12f64.sqrt(),
            read_noise_e: spec.read_noise_e,
            bands,
            warnings: assess(spec, detector, names, brightest_w_m2_sr_nm, line_period_s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::instrument::{DetectorMode, Response};

    fn cubesat() -> (InstrumentSpec, Detector, Vec<String>, Vec<f64>) {
        let spec = InstrumentSpec::preset("cubesat").unwrap();
        let response = Response::new(&spec, 1.0).unwrap();
        let detector = Detector::new(&spec, &response, DetectorMode::default(), 1);
        let names = response.bands.bands.iter().map(|b| b.name.clone()).collect();
        (spec, detector, names, response.bands.centres_nm())
    }

    #[test]
    fn table_1_cubesat_figures_by_hand() {
        // Table 1 CubeSat: f = 165 mm, D = 60 mm (N = 2.75), p = 5.86 µm, gain 3 e⁻/DN, read 15 e⁻.
        let (spec, detector, names, centres) = cubesat();
        let dark = vec![0.0; names.len()];
        let f = Feasibility::assess(&spec, &detector, &names, &centres, &dark, 2.0 * spec.exposure_s);
        assert!((f.f_number - spec.focal_length_mm / spec.aperture_mm).abs() < 1e-12);
        assert!((f.smear_px - 0.5).abs() < 1e-12, "half the line period: half a pixel");
        assert!((f.quantisation_noise_e - spec.gain_e_per_dn / 12f64.sqrt()).abs() < 1e-12);
        for b in &f.bands {
            // Q = λN/p, and the Airy diameter is 2.44 Q pixels.
            let q = b.centre_nm * 1e-3 * f.f_number / spec.pixel_pitch_um;
            assert!((b.q - q).abs() < 1e-12, "{b:?}");
            assert!((b.airy_diameter_um / spec.pixel_pitch_um - 2.44 * q).abs() < 1e-9, "{b:?}");
            // No light: the peak is the dark signal, far below full scale.
            assert!(b.peak_fraction_of_full_scale < 0.05, "{b:?}");
        }
        // At 665 nm and f/2.75 over 5.86 µm pixels, Q = 0.665·2.75/5.86 = 0.312 (to the band
        // centre's 1e-2): detector-limited, as such CubeSats are.
        let red = f.bands.iter().min_by(|a, b| (a.centre_nm - 665.0).abs().total_cmp(&(b.centre_nm - 665.0).abs()));
        assert!(red.is_some_and(|b| (b.q - 0.312).abs() < 1e-2 && b.q < Q_DETECTOR_LIMITED), "{red:?}");
        assert!(f.warnings.is_empty(), "{:?}", f.warnings);
    }

    #[test]
    fn the_peak_share_grows_with_radiance_and_saturation_is_warned() {
        let (spec, detector, names, centres) = cubesat();
        let nb = names.len();
        let some = Feasibility::assess(&spec, &detector, &names, &centres, &vec![10.0; nb], 1.0);
        let more = Feasibility::assess(&spec, &detector, &names, &centres, &vec![20.0; nb], 1.0);
        for (a, b) in some.bands.iter().zip(&more.bands) {
            assert!(b.peak_fraction_of_full_scale > 1.9 * a.peak_fraction_of_full_scale - 1e-9, "{a:?} {b:?}");
        }
        let blinding = Feasibility::assess(&spec, &detector, &names, &centres, &vec![1e6; nb], 1.0);
        assert!(blinding.bands.iter().all(|b| b.peak_fraction_of_full_scale > 1.0));
        assert!(blinding.warnings.iter().any(|w| w.guard == super::super::plausibility::Guard::Saturation));
    }
}
