//! Plausibility guards: designs the chain will simulate but an engineer should be told about —
//! a detector that saturates at the scene's brightest water radiance, an exposure longer than the
//! line period (along-track smear), and an f-number below 1 (no real telescope). The CLI prints
//! them and writes them into `report.json`; the app shows the same list.
//!
//! ## References
//! - Matthews, M. W. et al. (2023) Sensors 23, 7824, §2.1.2 and Table 1 (exposure, line period,
//!   well depth, gain).
//! - Janesick, J. R. (2007) Photon Transfer: DN → λ. SPIE Press (full well, ADC full scale:
//!   the signal clips at min(well, (2^bits − 1 − bias)·gain) electrons).
//! - Schowengerdt, R. A. (2007) Remote Sensing: Models and Methods for Image Processing, 3rd ed.,
//!   §3.4 (pushbroom smear: the ground moves v·t during an exposure t, i.e. t / t_line pixels).
//! - Smith, W. J. (2008) Modern Optical Engineering, 4th ed., §6.3 (N = f/D; the aplanatic limit
//!   of a lens in air is N = 0.5, practical telescopes stay well above 1).

use serde::Serialize;

use super::{Detector, InstrumentSpec};

/// Which guard a warning comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Guard {
    /// The brightest water pixel fills the well or the ADC.
    Saturation,
    /// The exposure is longer than the line period.
    Smear,
    /// Focal length over aperture below 1.
    FNumber,
}

impl Warning {
    /// A few words for a caption ("smears 5.3 px", "saturates at 191 % of full scale", "f/0.80,
    /// faster than f/1").
    #[must_use]
    pub fn short(&self) -> String {
        match self.guard {
            Guard::Saturation => {
                format!("saturates at {:.0} % of full scale", 100.0 * self.value)
            }
            Guard::Smear => format!("smears {:.1} px", self.value),
            Guard::FNumber => format!("f/{:.2}, faster than f/1", self.value),
        }
    }
}

/// One warning: what, how far, and the limit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Warning {
    /// The guard.
    pub guard: Guard,
    /// The value checked (peak signal as a fraction of full scale; smear in pixels; f-number).
    pub value: f64,
    /// The limit it crossed (1 full scale; 1 pixel; f/1).
    pub limit: f64,
    /// One sentence for people.
    pub message: String,
}

/// Smallest f-number accepted without a warning.
pub const MIN_F_NUMBER: f64 = 1.0;
/// Largest along-track smear accepted without a warning, pixels.
pub const MAX_SMEAR_PX: f64 = 1.0;

/// Full scale of band `b` in electrons: its focal plane's well, or its ADC's top code if that
/// clips first: min(well, (DN_max − bias)·gain).
#[must_use]
pub fn full_scale_e(detector: &Detector, b: usize) -> f64 {
    detector.well_e(b).min((detector.dn_max(b) - detector.bias_dn(b)).max(0.0) * detector.gain_e_per_dn(b))
}

/// The guards for `spec` flown over a scene whose brightest water radiance per band is
/// `brightest_w_m2_sr_nm` (band names in `bands`), with the run's line period.
#[must_use]
pub fn assess(
    spec: &InstrumentSpec,
    detector: &Detector,
    bands: &[String],
    brightest_w_m2_sr_nm: &[f64],
    line_period_s: f64,
) -> Vec<Warning> {
    let mut out = Vec::new();
    let f_number = spec.focal_length_mm / spec.aperture_mm;
    if f_number < MIN_F_NUMBER {
        out.push(Warning {
            guard: Guard::FNumber,
            value: f_number,
            limit: MIN_F_NUMBER,
            message: format!(
                "f-number f/{f_number:.2} (focal length {} mm / aperture {} mm) is below f/1: no real \
                 telescope is that fast, so its signal and SNR are not achievable",
                spec.focal_length_mm, spec.aperture_mm
            ),
        });
    }
    if line_period_s > 0.0 {
        let smear_px = spec.exposure_s / line_period_s;
        if smear_px > MAX_SMEAR_PX {
            out.push(Warning {
                guard: Guard::Smear,
                value: smear_px,
                limit: MAX_SMEAR_PX,
                message: format!(
                    "exposure {:.3} ms is longer than the line period {:.3} ms: the image smears over \
                     {smear_px:.1} pixels along track (the signal and SNR of a longer exposure are \
                     only reached by giving up along-track resolution)",
                    spec.exposure_s * 1e3,
                    line_period_s * 1e3
                ),
            });
        }
    }
    if spec.kind.model().capabilities().real_detector {
        out.extend(saturation(detector, bands, brightest_w_m2_sr_nm));
    }
    out
}

/// The largest signal of band `b` over every detector (PRNU included), electrons, at radiance
/// `radiance_w_m2_sr_nm`: responsivity · L plus the dark signal of one exposure.
#[must_use]
pub fn peak_signal_e(detector: &Detector, b: usize, radiance_w_m2_sr_nm: f64) -> f64 {
    (0..detector.detectors())
        .map(|j| detector.responsivity(j, b) * radiance_w_m2_sr_nm + detector.dark_mean_e(j, b, detector.exposure_s()))
        .fold(0.0f64, f64::max)
}

/// The worst band's peak signal against full scale, over every detector (PRNU included).
fn saturation(detector: &Detector, bands: &[String], brightest: &[f64]) -> Option<Warning> {
    // Each band's peak as a share of its own full scale (focal planes differ).
    let peaks: Vec<f64> = (0..brightest.len().min(detector.n_bands()))
        .map(|b| peak_signal_e(detector, b, brightest[b]) / full_scale_e(detector, b).max(f64::MIN_POSITIVE))
        .collect();
    let over: Vec<usize> = (0..peaks.len()).filter(|&b| peaks[b] >= 1.0).collect();
    let worst = (0..peaks.len()).max_by(|&a, &b| peaks[a].total_cmp(&peaks[b]))?;
    if over.is_empty() {
        return None;
    }
    let name = |b: usize| bands.get(b).cloned().unwrap_or_else(|| format!("band {}", b + 1));
    let listed: Vec<String> = over.iter().take(6).map(|&b| name(b)).collect();
    let more = if over.len() > 6 { format!(" and {} more", over.len() - 6) } else { String::new() };
    Some(Warning {
        guard: Guard::Saturation,
        value: peaks[worst],
        limit: 1.0,
        message: format!(
            "saturates at the scene's brightest water radiance in {} of {} bands ({}{more}): {} needs \
             {:.3e} e⁻ against a full scale of {:.3e} e⁻ ({:.0} % of it)",
            over.len(),
            peaks.len(),
            listed.join(", "),
            name(worst),
            peak_signal_e(detector, worst, brightest[worst]),
            full_scale_e(detector, worst),
            100.0 * peaks[worst]
        ),
    })
}

/// Median band radiance over water pixels (at most ~20 000 of them, evenly strided: the median's
/// sampling error, under 1 %, is far below what an SNR figure needs); the SNR stage's typical
/// radiance. Zero for a band without water pixels.
#[must_use]
pub fn typical_water(radiance: &ndarray::Array3<f32>, surface: &super::SurfaceMap) -> Vec<f64> {
    let (rows, cols, nb) = radiance.dim();
    let Some(rad) = radiance.as_slice() else { return vec![0.0; nb] };
    let stride = (rows * cols / 20_000).max(1);
    let mut per_band: Vec<Vec<f32>> = vec![Vec::new(); nb];
    for (pixel, values) in rad.chunks(nb.max(1)).enumerate().step_by(stride) {
        if surface.is_water_at(pixel) {
            for (list, v) in per_band.iter_mut().zip(values) {
                list.push(*v);
            }
        }
    }
    per_band
        .into_iter()
        .map(|mut v| {
            if v.is_empty() {
                return 0.0;
            }
            let mid = v.len() / 2;
            f64::from(*v.select_nth_unstable_by(mid, f32::total_cmp).1)
        })
        .collect()
}

/// Brightest radiance per band over the water pixels of a (rows, cols, bands) cube.
#[must_use]
pub fn brightest_water(radiance: &ndarray::Array3<f32>, surface: &super::SurfaceMap) -> Vec<f64> {
    let nb = radiance.dim().2;
    let mut out = vec![0.0f32; nb];
    if let Some(rad) = radiance.as_slice() {
        for (pixel, values) in rad.chunks_exact(nb.max(1)).enumerate() {
            if surface.is_water_at(pixel) {
                for (o, &v) in out.iter_mut().zip(values) {
                    *o = o.max(v);
                }
            }
        }
    } else {
        let (rows, cols) = surface.dim();
        for (r, c) in (0..rows).flat_map(|r| (0..cols).map(move |c| (r, c))) {
            if surface.is_water(r, c) {
                for (b, o) in out.iter_mut().enumerate() {
                    *o = o.max(radiance[[r, c, b]]);
                }
            }
        }
    }
    out.into_iter().map(f64::from).collect()
}
