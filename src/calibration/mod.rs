//! Calibration, Level-0 → Level-1 (Matthews et al. 2023, §2.1.2 and Appendix A).
//!
//! The instrument views a Lambertian diffuser lit by the extraterrestrial sun: its radiance in
//! band b is L_d,b = ρ_d·E0_b·cos θ_d/π, with E0_b the band's response-weighted solar irradiance
//! at the scene's Sun–Earth distance and θ_d the sun's incidence on the diffuser. As in the
//! paper, 100 exposures at the nominal exposure time and 100 at zero exposure time are simulated
//! through the full detector model (noise, full well, ADC). Per detector and band:
//!
//! offset = mean DN(dark),  gain = (mean DN(diffuser) − offset)/L_d,b,  L1 = (DN − offset)/gain.
//!
//! A diffuser lit at normal incidence would saturate most instruments, as a real on-board diffuser
//! would: unless `sun_incidence_deg` is given, the incidence is chosen so that the brightest
//! band of the brightest detector reaches 60 % of the smaller of the full well and the ADC range.
//! Systematic errors can be injected to study them: a diffuser reflectance known `diffuser_bias_pct`
//! too high (Level-1 reads low by that factor), and a responsivity that drifted by
//! `gain_drift_pct` between calibration and the scene (Level-1 reads high by that factor).
//! Zero-second dark frames do not see the dark current the scene exposures collect: with dark
//! current, Level-1 carries the paper's own offset error unless `dark_exposure_s` is set to
//! the nominal exposure.
//!
//! ## References
//! - Matthews, M. W. et al. (2023) Sensors 23, 7824, Appendix A.

use ndarray::Array3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::control::RunControl;
use crate::instrument::detector::{Detector, Exposure, Stream, pixel_rng};
use crate::instrument::{Flags, Level0, Response, Viewing};
use crate::parse::FieldError;

mod focal;

pub use focal::{Defects, FocalKnowledge, Linearisation};

/// Errors from the calibration stage; each names the field and what is allowed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum CalibrationError {
    /// A setting or an input with an invalid value.
    #[error(transparent)]
    Invalid(#[from] FieldError),
    /// The run was cancelled (a newer request superseded it).
    #[error("cancelled")]
    Cancelled,
}

impl crate::control::Cancellable for CalibrationError {
    fn cancelled() -> Self {
        Self::Cancelled
    }

    fn is_cancelled(&self) -> bool {
        matches!(self, Self::Cancelled)
    }
}

/// Calibration settings and injected systematic errors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CalibrationSpec {
    /// Diffuser exposures at the nominal exposure time (Appendix A: 100).
    pub light_frames: usize,
    /// Dark exposures (Appendix A: 100).
    pub dark_frames: usize,
    /// Exposure time of the dark frames, s (Appendix A: 0).
    pub dark_exposure_s: f64,
    /// Diffuser reflectance (Spectralon-like: 0.99).
    pub diffuser_reflectance: f64,
    /// Sun incidence angle on the diffuser, degrees; `None`: chosen to fill 60 % of the range.
    pub sun_incidence_deg: Option<f64>,
    /// Error of the assumed diffuser reflectance, % (positive: assumed too bright).
    pub diffuser_bias_pct: f64,
    /// Responsivity drift between calibration and the scene, %.
    pub gain_drift_pct: f64,
    /// Perfect calibration: the detector's exact responsivity and offset, no frames (a "perfect
    /// stage" switch for error budgets).
    pub perfect: bool,
}

impl Default for CalibrationSpec {
    fn default() -> Self {
        Self {
            light_frames: 100,
            dark_frames: 100,
            dark_exposure_s: 0.0,
            diffuser_reflectance: 0.99,
            sun_incidence_deg: None,
            diffuser_bias_pct: 0.0,
            gain_drift_pct: 0.0,
            perfect: false,
        }
    }
}

impl CalibrationSpec {
    /// Check every number against [`crate::ranges`]; the message names field, value and range.
    pub fn validate(&self) -> Result<(), CalibrationError> {
        use crate::ranges as r;
        let check = |range: &r::Range, v: f64| {
            range
                .check(v)
                .map_err(|message| CalibrationError::Invalid(FieldError { field: range.path.into(), message }))
        };
        check(&r::CALIBRATION_LIGHT_FRAMES, self.light_frames as f64)?;
        check(&r::CALIBRATION_DARK_FRAMES, self.dark_frames as f64)?;
        check(&r::CALIBRATION_DARK_EXPOSURE_S, self.dark_exposure_s)?;
        check(&r::CALIBRATION_DIFFUSER_REFLECTANCE, self.diffuser_reflectance)?;
        if let Some(a) = self.sun_incidence_deg {
            check(&r::CALIBRATION_SUN_INCIDENCE_DEG, a)?;
        }
        check(&r::CALIBRATION_DIFFUSER_BIAS_PCT, self.diffuser_bias_pct)?;
        check(&r::CALIBRATION_GAIN_DRIFT_PCT, self.gain_drift_pct)
    }
}

/// Per-detector, per-band calibration coefficients.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    n_bands: usize,
    /// Offset, DN, per detector × band.
    pub offset_dn: Vec<f64>,
    /// DN per unit band radiance (W m⁻² sr⁻¹ nm⁻¹), per detector × band.
    pub gain_dn_per_radiance: Vec<f64>,
    /// True diffuser radiance per detector × band.
    pub diffuser_radiance: Vec<f64>,
    /// Sun incidence on the diffuser used, degrees.
    pub sun_incidence_deg: f64,
    /// Diffuser frames that saturated (any band): a calibration that cannot be trusted.
    pub saturated_frames: usize,
    /// The response curves every value is linearised with (`None`: the detector is taken as
    /// linear).
    pub linearise: Option<Linearisation>,
    /// The dead elements found (`None`: none).
    pub defects: Option<Defects>,
}

/// Response-weighted extraterrestrial irradiance of every detector × band (smile included),
/// from `e0[g]` = E0 on group g's grid, W m⁻² nm⁻¹.
#[must_use]
pub fn band_e0(response: &Response, detectors: usize, e0: &[Vec<f64>]) -> Vec<f64> {
    let nb = response.n_bands();
    let mut out = vec![0.0; detectors * nb];
    for j in 0..detectors {
        for (gi, g) in response.groups.iter().enumerate() {
            for (k, &b) in g.bands.iter().enumerate() {
                let (first, w) = response.weights(gi, k, j);
                let den: f64 = w.iter().sum();
                let num: f64 = w.iter().zip(&e0[gi][first..first + w.len()]).map(|(a, e)| a * e).sum();
                out[j * nb + b] = if den > 0.0 { num / den } else { 0.0 };
            }
        }
    }
    out
}

impl Calibration {
    /// Simulate the calibration frames of `detector` and derive the coefficients of the
    /// detectors in `used` (a preview calibrates only the detectors it reads; the others keep
    /// zero gain), with what the processor `knowledge` of the focal-plane effects (the
    /// response curve it linearises with, whether it fills dead elements). `e0_band` from
    /// [`band_e0`]: through the bands the detector has, and through those the processor believes
    /// (the same unless the instrument states a spectral knowledge error). The frames see the
    /// first; the gain divides by the diffuser radiance of the second, so a band's error leaves
    /// Level-1 scaled by their ratio.
    pub fn derive(
        spec: &CalibrationSpec,
        (detector, knowledge): (&Detector, FocalKnowledge),
        (e0_band, believed_e0_band): (&[f64], &[f64]),
        used: &[usize],
        seed: u64,
    ) -> Result<Self, CalibrationError> {
        spec.validate()?;
        let nb = detector.n_bands();
        let nd = e0_band.len() / nb.max(1);
        // Diffuser radiance at normal incidence, then the incidence that fills 60 % of the range.
        let normal: Vec<f64> = e0_band.iter().map(|e| spec.diffuser_reflectance * e / std::f64::consts::PI).collect();
        // What the processor believes of each band's diffuser radiance, relative to the truth.
        let believed: Vec<f64> =
            e0_band.iter().zip(believed_e0_band).map(|(t, b)| if *t > 0.0 { b / t } else { 1.0 }).collect();
        // Each band's range in electrons (its focal plane's well or ADC top, the smaller), and
        // the incidence at which the band closest to its top fills 60 % of it.
        let range_e = |b: usize| {
            detector.well_e(b).min((detector.dn_max(b) - detector.bias_dn(b)).max(1.0) * detector.gain_e_per_dn(b))
        };
        let fill = (0..nd * nb)
            .map(|i| detector.responsivity(i / nb, i % nb) * normal[i] / range_e(i % nb))
            .fold(0.0, f64::max);
        let cos_inc = match spec.sun_incidence_deg {
            Some(a) => a.to_radians().cos(),
            None if fill > 0.0 => (0.6 / fill).min(1.0),
            None => 1.0,
        };
        let diffuser_radiance: Vec<f64> = normal.iter().map(|l| l * cos_inc).collect();
        let assumed = 1.0 + spec.diffuser_bias_pct / 100.0;
        let drift = 1.0 + spec.gain_drift_pct / 100.0;
        let t = detector.exposure_s();
        let linearise = Linearisation::of(detector, nd, knowledge.curve_factor, spec.perfect);
        let lin = |j: usize, b: usize, v: f64| linearise.as_ref().map_or(v, |l| l.value(j, b, v));
        let per_detector: Vec<(usize, Vec<f64>, Vec<f64>, usize)> = used
            .par_iter()
            .filter(|&&j| j < nd)
            .map(|&j| {
                let mut offset = vec![0.0; nb];
                let mut gain = vec![0.0; nb];
                if spec.perfect {
                    for b in 0..nb {
                        offset[b] = detector.bias_dn(b) + detector.dark_mean_e(j, b, t) / detector.gain_e_per_dn(b);
                        gain[b] =
                            detector.responsivity(j, b) / detector.gain_e_per_dn(b) / drift / believed[j * nb + b];
                    }
                    return (j, offset, gain, 0);
                }
                // Every frame sees the same radiance: the exposures are set up once per band.
                let lit: Vec<_> = (0..nb).map(|b| detector.exposure(j, b, diffuser_radiance[j * nb + b], t)).collect();
                let dark: Vec<_> = (0..nb).map(|b| detector.exposure(j, b, 0.0, spec.dark_exposure_s)).collect();
                let frames = |exposures: &[Exposure], n: usize, streams: (Stream, Stream)| {
                    frame_means(detector, j, exposures, n, (seed, streams.0, streams.1))
                };
                let (light, saturated) =
                    frames(&lit, spec.light_frames, (Stream::CalibrationLightSum, Stream::CalibrationLight));
                let (dark, _) = frames(&dark, spec.dark_frames, (Stream::CalibrationDarkSum, Stream::CalibrationDark));
                for b in 0..nb {
                    // The frames' means linearised (the curve of the mean: see `frames_mean`).
                    let (light, dark) = (lin(j, b, light[b]), lin(j, b, dark[b]));
                    offset[b] = dark;
                    gain[b] = (light - dark) / (diffuser_radiance[j * nb + b] * believed[j * nb + b] * assumed) / drift;
                }
                (j, offset, gain, saturated)
            })
            .collect();
        let mut offset_dn = vec![0.0; nd * nb];
        let mut gain_dn_per_radiance = vec![0.0; nd * nb];
        for (j, offset, gain, _) in &per_detector {
            offset_dn[j * nb..(j + 1) * nb].copy_from_slice(offset);
            gain_dn_per_radiance[j * nb..(j + 1) * nb].copy_from_slice(gain);
        }
        let defects = Defects::find(&gain_dn_per_radiance, nb, used, knowledge.fill_dead);
        Ok(Self {
            n_bands: nb,
            offset_dn,
            gain_dn_per_radiance,
            diffuser_radiance,
            sun_incidence_deg: cos_inc.acos().to_degrees(),
            saturated_frames: per_detector.iter().map(|p| p.3).sum(),
            linearise,
            defects,
        })
    }

    /// Level-1 band radiance of a Level-0 value from detector `j`, band `b`.
    #[must_use]
    pub fn radiance(&self, j: usize, b: usize, value: f64) -> f64 {
        let i = j * self.n_bands + b;
        let value = self.linearise.as_ref().map_or(value, |l| l.value(j, b, value));
        radiance_of(value, self.offset_dn[i], self.gain_dn_per_radiance[i])
    }
}

/// The mean Level-0 value of `frames` frames of each band's exposure of detector `j`, and the
/// frames in which a band saturated. Each band's mean is drawn at once where
/// [`Detector::frames_mean`] shows that to be the same in distribution (no frame can clip, the
/// ADC's rounding is dithered by the read noise); the other bands are read out frame by frame
/// (for example dark frames whose bias sits within a few σ of zero, which clip). `streams`:
/// (run seed, stream of the drawn means, stream of the frames).
fn frame_means(
    detector: &Detector,
    j: usize,
    exposures: &[Exposure],
    frames: usize,
    (seed, at_once, by_frame): (u64, Stream, Stream),
) -> (Vec<f64>, usize) {
    let mut rng = pixel_rng(seed, at_once, 0, j);
    let drawn: Vec<Option<f64>> =
        exposures.iter().enumerate().map(|(b, e)| detector.frames_mean(b, e, frames, &mut rng)).collect();
    let left: Vec<usize> = (0..exposures.len()).filter(|&b| drawn[b].is_none()).collect();
    let mut sums = vec![0.0; exposures.len()];
    let mut saturated = 0;
    if !left.is_empty() {
        let mut frame_saturated = vec![false; frames];
        let rng_of = |f| pixel_rng(seed, by_frame, f, j);
        detector.read_out_frames(j, exposures, &left, frames, rng_of, |f, b, r| {
            frame_saturated[f] |= r.flags & Flags::SATURATED != 0;
            sums[b] += detector.level0_value(&r);
        });
        saturated = frame_saturated.iter().filter(|&&s| s).count();
    }
    let means = drawn.iter().zip(&sums).map(|(d, s)| d.unwrap_or(s / frames as f64)).collect();
    (means, saturated)
}

/// L1 = (DN − offset)/gain (Appendix A); 0 for a detector without a usable gain.
#[inline(always)]
fn radiance_of(value: f64, offset_dn: f64, gain: f64) -> f64 {
    if gain > 0.0 { (value - offset_dn) / gain } else { 0.0 }
}

/// Level-1: calibrated band radiance at the entrance pupil.
#[derive(Debug, Clone, PartialEq)]
pub struct Level1 {
    /// Band radiance, W m⁻² sr⁻¹ nm⁻¹, (row, column, band).
    pub radiance: Array3<f32>,
    /// Level-0 flags carried over.
    pub flags: Array3<u8>,
}

/// Apply `calibration` to every pixel of `level0`.
pub fn calibrate(
    level0: &Level0,
    calibration: &Calibration,
    viewing: &Viewing,
    control: &RunControl,
) -> Result<Level1, CalibrationError> {
    let out = calibrated_radiance(level0, calibration, viewing, control)?;
    finish(out, level0.flags.clone(), calibration, viewing)
}

/// [`calibrate`], handing `level0`'s flags on to the Level-1 rather than copying them (the
/// counts are let go once read).
pub fn calibrate_owned(
    level0: Level0,
    calibration: &Calibration,
    viewing: &Viewing,
    control: &RunControl,
) -> Result<Level1, CalibrationError> {
    let out = calibrated_radiance(&level0, calibration, viewing, control)?;
    let Level0 { flags, dn, analog, .. } = level0;
    drop((dn, analog));
    finish(out, flags, calibration, viewing)
}

fn not_standard() -> CalibrationError {
    CalibrationError::Invalid(FieldError { field: "Level-0 cube".into(), message: "not in standard layout".into() })
}

/// The calibrated radiance of every pixel of `level0`, (row, column, band) in one vector.
fn calibrated_radiance(
    level0: &Level0,
    calibration: &Calibration,
    viewing: &Viewing,
    control: &RunControl,
) -> Result<Vec<f32>, CalibrationError> {
    let (rows, cols, nb) = level0.dn.dim();
    let mut out = vec![0.0f32; rows * cols * nb];
    // The values calibration reads: the analogue ones when quantisation is off, else the DN.
    let analog = level0.analog.as_ref().map(|a| a.as_slice().ok_or_else(not_standard)).transpose()?;
    let dn = level0.dn.as_slice().ok_or_else(not_standard)?;
    control.fill_rows(out.as_mut_slice(), rows, cols * nb, |at, row| {
        let r = at.index();
        for c in 0..cols {
            at.column(c);
            // [`Calibration::radiance`] over the column's bands, on slices (no index checks in
            // the band loop, so neighbouring bands are computed together).
            let j = viewing.detector_index[c] * nb;
            let (offset, gain) = (&calibration.offset_dn[j..j + nb], &calibration.gain_dn_per_radiance[j..j + nb]);
            let at_pixel = (r * cols + c) * nb..(r * cols + c + 1) * nb;
            let out = &mut row[c * nb..(c + 1) * nb];
            let radiance = |value: f64, b: usize| radiance_of(value, offset[b], gain[b]) as f32;
            if let Some(lin) = &calibration.linearise {
                let j = viewing.detector_index[c];
                for (b, o) in out.iter_mut().enumerate() {
                    let value =
                        analog.map_or_else(|| f64::from(dn[at_pixel.start + b]), |a| f64::from(a[at_pixel.start + b]));
                    *o = radiance(lin.value(j, b, value), b);
                }
                continue;
            }
            match analog {
                Some(a) => {
                    for (b, (o, &v)) in out.iter_mut().zip(&a[at_pixel]).enumerate() {
                        *o = radiance(f64::from(v), b);
                    }
                }
                None => {
                    for (b, (o, &v)) in out.iter_mut().zip(&dn[at_pixel]).enumerate() {
                        *o = radiance(f64::from(v), b);
                    }
                }
            }
        }
        Ok::<_, CalibrationError>(())
    })?;
    Ok(out)
}

/// The Level-1 of the calibrated radiance `out` with the Level-0 `flags` (its shape), the
/// detector's known defects repaired.
fn finish(
    mut out: Vec<f32>,
    mut flags: Array3<u8>,
    calibration: &Calibration,
    viewing: &Viewing,
) -> Result<Level1, CalibrationError> {
    let (rows, cols, nb) = flags.dim();
    if let Some(defects) = &calibration.defects {
        let flag_rows = flags.as_slice_mut().ok_or_else(not_standard)?;
        out.par_chunks_mut((cols * nb).max(1)).zip(flag_rows.par_chunks_mut((cols * nb).max(1))).for_each(
            |(row, flags)| {
                defects.repair_row(row, flags, &viewing.detector_index);
            },
        );
    }
    Ok(Level1 {
        radiance: Array3::from_shape_vec((rows, cols, nb), out)
            .map_err(|e| CalibrationError::Invalid(FieldError { field: "cube".into(), message: e.to_string() }))?,
        flags,
    })
}
