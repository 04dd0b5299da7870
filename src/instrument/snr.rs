//! Signal-to-noise ratio per band: the analytic value from the detector model, and the value
//! measured on simulated Level-0 frames of a uniform patch, side by side.
//!
//! Analytic (Janesick 2007, eq. 2.14 with the quantisation term of §4.4):
//! SNR = S / √(S + D + σ_read² + gain²/12), S = K·L photo-electrons, D dark electrons, each
//! band with its focal plane's numbers (for m × m binned pixels the variance is
//! (S + D + σ_read²)/m² + gain²/12: see [`super::focal`]).
//! Measured: `frames` exposures of a uniform radiance and as many dark exposures through the
//! full detector model (shot, dark, read noise, full well, ADC); per detector, the temporal
//! mean of light minus dark DN over the temporal standard deviation of the light DN; the
//! detectors' mean. With 128 frames each detector's estimate has a 6 % standard error; the mean
//! over 256 detectors has 0.4 %.
//!
//! ## References
//! - Janesick, J. R. (2007) Photon Transfer: DN → λ. SPIE Press.

use rayon::prelude::*;
use serde::Serialize;

use super::detector::{Detector, Flags, Stream, pixel_rng};

/// One row of `snr.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SnrRow {
    /// Band name.
    pub band: String,
    /// Band centre, nm.
    pub centre_nm: f64,
    /// The radiance the SNR refers to (the scene's median water radiance), W m⁻² sr⁻¹ nm⁻¹.
    pub radiance: f64,
    /// Analytic SNR at the central detector.
    pub snr_analytic: f64,
    /// SNR measured on a simulated uniform patch.
    pub snr_measured: f64,
    /// The reference radiance's signal (photo and dark electrons, at the brightest detector)
    /// over the full scale (the well or the ADC's top count, the smaller;
    /// [`super::plausibility::full_scale_e`]): at 1 or more the band saturates at its own
    /// reference radiance and its SNR is no figure of merit (the verdict fails it).
    pub full_scale_fraction: f64,
}

impl SnrRow {
    /// Does the band saturate at its reference radiance?
    #[must_use]
    pub fn saturated(&self) -> bool {
        self.full_scale_fraction >= 1.0
    }
}

/// Analytic SNR of detector `j`, band `b` at band radiance `radiance` (infinite without noise).
#[must_use]
pub fn analytic_snr(detector: &Detector, j: usize, b: usize, radiance: f64) -> f64 {
    let signal = detector.responsivity(j, b) * radiance;
    let dark = detector.dark_mean_e(j, b, nominal_exposure(detector));
    let var = detector.variance_e2(b, signal, dark);
    if var > 0.0 { signal / var.sqrt() } else { f64::INFINITY }
}

fn nominal_exposure(detector: &Detector) -> f64 {
    detector.exposure_s()
}

/// SNR of every band measured on `frames` simulated exposures of the uniform band radiances
/// `radiance` by each of `detectors` (light and dark frames, temporal statistics per detector,
/// mean over detectors). Infinite when the detector has no noise.
///
/// Two converter limits are reported, not hidden behind a zero variance: a patch that
/// saturates in any frame carries no information about the radiance (SNR 0), and a noisy signal
/// that the ADC rounds to one constant value has the uniform quantiser's error, 1/√12 DN rms
/// (Widrow & Kollár 2008, *Quantization Noise*, ch. 4), in place of its zero sample variance.
#[must_use]
pub fn measured_snr(detector: &Detector, radiance: &[f64], detectors: &[usize], frames: usize, seed: u64) -> Vec<f64> {
    let t = nominal_exposure(detector);
    let nb = detector.n_bands();
    let per_detector: Vec<Vec<f64>> = detectors
        .par_iter()
        .map(|&j| {
            // Running sums per band: light Σx, Σx², dark Σx.
            let (mut s1, mut s2, mut d1) = (vec![0.0; nb], vec![0.0; nb], vec![0.0; nb]);
            let mut saturated = vec![false; nb];
            // Every frame sees the same radiance: the exposures are set up once per band.
            let lit: Vec<_> = (0..nb).map(|b| detector.exposure(j, b, radiance[b], t)).collect();
            let dark: Vec<_> = (0..nb).map(|b| detector.exposure(j, b, 0.0, t)).collect();
            // Frame f's light frame draws from generator 2f, its dark frame from 2f + 1.
            let bands: Vec<usize> = (0..nb).collect();
            let light_rng = |f: usize| pixel_rng(seed, Stream::SnrPatch, 2 * f, j);
            detector.read_out_frames(j, &lit, &bands, frames, light_rng, |_, b, out| {
                saturated[b] |= out.flags & Flags::SATURATED != 0;
                let v = detector.level0_value(&out);
                s1[b] += v;
                s2[b] += v * v;
            });
            let dark_rng = |f: usize| pixel_rng(seed, Stream::SnrPatch, 2 * f + 1, j);
            detector.read_out_frames(j, &dark, &bands, frames, dark_rng, |_, b, out| {
                d1[b] += detector.level0_value(&out);
            });
            let n = frames as f64;
            (0..nb)
                .map(|b| {
                    let mean = s1[b] / n;
                    let var = (s2[b] - n * mean * mean) / (n - 1.0).max(1.0);
                    // Below the dark level on average: no measurable signal (0, not negative).
                    let signal = (mean - d1[b] / n).max(0.0);
                    let noisy = detector.mode().noise;
                    if noisy && saturated[b] {
                        0.0
                    } else if var > 0.0 {
                        signal / var.sqrt()
                    } else if noisy && detector.mode().quantise {
                        signal * 12f64.sqrt()
                    } else {
                        f64::INFINITY
                    }
                })
                .collect()
        })
        .collect();
    (0..nb)
        .map(|b| {
            let v: Vec<f64> = per_detector.iter().map(|d| d[b]).collect();
            if v.is_empty() {
                0.0
            } else if v.iter().any(|x| x.is_infinite()) {
                f64::INFINITY
            } else {
                v.iter().sum::<f64>() / v.len() as f64
            }
        })
        .collect()
}
