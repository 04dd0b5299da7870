//! The detector and its electronics: band radiance → photo-electrons → digital numbers.
//!
//! Signal chain for detector j, band b (Janesick 2007, ch. 2–3; Matthews et al. 2023 §2.1.2):
//!
//! - mean photo-electrons S = K_{j,b}·L_b·t/t₀ with K = t₀·τ·A·Ω·∫SRF·QE·λ/(hc) dλ
//!   (see [`super::response`]) times the fixed photo-response non-uniformity (1 + PRNU·z_{j,b});
//! - mean dark electrons D = i_dark·t + DSNU·z'_{j,b}·t/t₀ (never negative);
//! - shot noise: electrons ~ Poisson(S + D), exact below 1000 e⁻ and the normal approximation
//!   N(μ, μ) rounded to whole electrons above (its skewness 1/√μ is under 3 %);
//! - full-well clipping at the well depth;
//! - read noise: Gaussian, σ_read electrons, added at readout;
//! - ADC: DN = round(e/gain + bias), clipped to 0 … 2^bits − 1; quantisation noise gain²/12 e⁻².
//!
//! Noise is deterministic per pixel: every pixel's draws come from its own generator seeded by
//! (run seed, stage, line, detector), so the result does not depend on threads or on the order
//! of work, and a decimated preview sees exactly the noise of the same pixels at full resolution.
//!
//! ## References
//! - Janesick, J. R. (2007) Photon Transfer: DN → λ. SPIE Press.
//! - Matthews, M. W. et al. (2023) Sensors 23, 7824, §2.1.2 and Table 1.

use rand::SeedableRng;
use rand::rngs::Xoshiro256PlusPlus;
use rand_distr::{Distribution, Poisson, StandardNormal};

use exposure::{Shot, shot};
use serde::{Deserialize, Serialize};

use super::response::Response;
use super::spec::InstrumentSpec;

/// Noise and quantisation switches (the "perfect stage" switches of an error budget).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DetectorMode {
    /// Shot, dark and read noise on (off: every pixel gets its mean).
    pub noise: bool,
    /// ADC quantisation and clipping on (off: Level-1 is computed from the analogue value).
    pub quantise: bool,
}

impl Default for DetectorMode {
    fn default() -> Self {
        Self { noise: true, quantise: true }
    }
}

impl DetectorMode {
    /// No noise, no quantisation: the closure setting.
    pub const IDEAL: Self = Self { noise: false, quantise: false };
}

/// Level-0 per-pixel, per-band flags.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Flags;

impl Flags {
    /// The well filled or the ADC reached 2^bits − 1.
    pub const SATURATED: u8 = 1;
    /// The ADC read 0 (signal below the converter's range).
    pub const ZERO: u8 = 2;
    /// A dead detector element the calibration found and did not fill (Level-1 only).
    pub const DEFECTIVE: u8 = 4;
}

/// Stream tags that keep the noise of different stages independent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u64)]
pub enum Stream {
    /// Shot and dark noise of scene exposures.
    Exposure = 1,
    /// Read noise of scene exposures.
    Readout = 2,
    /// Calibration diffuser frames.
    CalibrationLight = 3,
    /// Calibration dark frames.
    CalibrationDark = 4,
    /// Fixed patterns (PRNU, DSNU).
    FixedPattern = 5,
    /// SNR patch frames.
    SnrPatch = 6,
    /// Calibration diffuser frames drawn as their sum ([`Detector::frames_mean`]).
    CalibrationLightSum = 7,
    /// Calibration dark frames drawn as their sum.
    CalibrationDarkSum = 8,
    /// The focal-plane effects' patterns (non-linearity per column, drifts, dead and hot
    /// elements: [`patterns`]).
    FocalPlane = 9,
}

/// SplitMix64 finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mixer.
#[must_use]
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The generator of one pixel: seeded by (run seed, stream, line, detector).
#[must_use]
pub fn pixel_rng(seed: u64, stream: Stream, line: usize, detector: usize) -> Xoshiro256PlusPlus {
    let key =
        mix64(mix64(mix64(seed ^ (stream as u64).wrapping_mul(0xA24B_AED4_963E_E407)) ^ line as u64) ^ detector as u64);
    Xoshiro256PlusPlus::seed_from_u64(key)
}

/// A standard normal draw.
#[must_use]
pub fn normal<R: rand::Rng + ?Sized>(rng: &mut R) -> f64 {
    StandardNormal.sample(rng)
}

/// The detector of one instrument: per-(detector, band) responsivity and dark signal, and each
/// focal plane's readout electronics ([`plane::PlaneElectronics`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Detector {
    n_bands: usize,
    /// Mean electrons per unit band radiance (W m⁻² sr⁻¹ nm⁻¹) at the nominal exposure, with
    /// PRNU, per detector × band.
    responsivity: Vec<f64>,
    /// Mean dark electrons at the nominal exposure (dark current and DSNU), per detector × band.
    dark_e: Vec<f64>,
    /// Each band's focal plane (an index into `planes`).
    plane_of_band: Vec<usize>,
    /// The focal planes: the instrument's first, then its `focal_planes`.
    planes: Vec<PlaneElectronics>,
    exposure_s: f64,
    ideal: bool,
    mode: DetectorMode,
    /// Non-linearity and fixed patterns, when the instrument states them.
    focal: Option<Box<patterns::FocalEffects>>,
}

/// One pixel read out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Readout {
    /// Digital number.
    pub dn: u16,
    /// The analogue value before quantisation, DN.
    pub analog_dn: f32,
    /// [`Flags`].
    pub flags: u8,
}

impl Detector {
    /// The detector of `spec` with `response`, fixed patterns drawn from `seed`.
    ///
    /// The first focal plane's PRNU and DSNU come from each detector's generator in band order
    /// (as they did before focal planes existed, so a one-plane instrument's patterns are
    /// unchanged); a further plane's from a generator of its own per (plane, band, native
    /// detector), so the grid pixels of one coarse pixel share its pattern.
    #[must_use]
    pub fn new(spec: &InstrumentSpec, response: &Response, mode: DetectorMode, seed: u64) -> Self {
        let ideal = !spec.kind.model().capabilities().real_detector;
        let mode = if ideal { DetectorMode::IDEAL } else { mode };
        let nb = response.n_bands();
        let nd = spec.detectors;
        let planes = PlaneElectronics::of(spec);
        let plane_of_band: Vec<usize> =
            (0..nb).map(|b| response.plane_of_band.get(b).copied().unwrap_or(0).min(planes.len() - 1)).collect();
        let mut responsivity = vec![0.0; nd * nb];
        let mut dark_e = vec![0.0; nd * nb];
        // Σw of each band of each smile class: the detectors of a class share one weight slice
        // (`Response::weights`), so each sum is taken once, not once per detector.
        let photon_sums: Vec<Vec<Vec<f64>>> = response
            .groups
            .iter()
            .map(|g| g.weights.iter().map(|class| class.iter().map(|(_, w)| w.iter().sum()).collect()).collect())
            .collect();
        for j in 0..nd {
            let mut rng = pixel_rng(seed, Stream::FixedPattern, 0, j);
            for (gi, g) in response.groups.iter().enumerate() {
                for (k, &b) in g.bands.iter().enumerate() {
                    let p = plane_of_band[b];
                    let plane = &planes[p];
                    let photons = photon_sums[gi][response.smile_class_of(gi, j)][k];
                    let (z1, z2) = if p == 0 {
                        (normal(&mut rng), normal(&mut rng))
                    } else {
                        let mut own = pixel_rng(seed, Stream::FixedPattern, (p << 16) | b, j / plane.block());
                        (normal(&mut own), normal(&mut own))
                    };
                    let prnu = if ideal { 1.0 } else { (1.0 + plane.prnu * z1).max(0.0) };
                    // The plane's own integration time (a ratio of the instrument's, at which every
                    // stage calls the detector).
                    let t = spec.exposure_s * plane.exposure_ratio;
                    let geometric = t * spec.optical_transmission * plane.etendue_m2_sr;
                    responsivity[j * nb + b] = geometric * photons * prnu;
                    let dsnu = if ideal { 0.0 } else { plane.dsnu_e * z2 };
                    dark_e[j * nb + b] = (plane.dark_current_e_s * t + dsnu).max(0.0);
                }
            }
        }
        // Dead elements respond to nothing; hot ones collect more dark current (both seen by the
        // calibration frames as by the scene).
        let focal = if ideal { None } else { patterns::FocalEffects::of(spec, nd, &planes, &plane_of_band, seed) };
        if let Some(f) = &focal {
            for (i, r) in responsivity.iter_mut().enumerate() {
                if f.dead.get(i).copied().unwrap_or(false) {
                    *r = 0.0;
                }
            }
            for (i, (d, hot)) in dark_e.iter_mut().zip(&f.hot_e_s).enumerate() {
                *d += hot * spec.exposure_s * planes[plane_of_band[i % nb]].exposure_ratio;
            }
        }
        let focal = focal.map(Box::new);
        Self {
            n_bands: nb,
            responsivity,
            dark_e,
            plane_of_band,
            planes,
            exposure_s: spec.exposure_s,
            ideal,
            mode,
            focal,
        }
    }

    /// Noise and quantisation switches in effect (the ideal radiometer has neither).
    #[must_use]
    pub fn mode(&self) -> DetectorMode {
        self.mode
    }

    /// Number of bands.
    #[must_use]
    pub fn n_bands(&self) -> usize {
        self.n_bands
    }

    /// Detectors across track.
    #[must_use]
    pub fn detectors(&self) -> usize {
        self.responsivity.len() / self.n_bands.max(1)
    }

    /// Mean electrons per unit band radiance at the nominal exposure, detector `j`, band `b`.
    #[must_use]
    pub fn responsivity(&self, j: usize, b: usize) -> f64 {
        self.responsivity[j * self.n_bands + b]
    }

    /// Band `b`'s focal plane.
    #[must_use]
    pub fn plane(&self, b: usize) -> &PlaneElectronics {
        &self.planes[self.plane_of_band[b]]
    }

    /// Band `b`'s focal-plane index (0: the instrument's first).
    #[must_use]
    pub fn plane_index(&self, b: usize) -> usize {
        self.plane_of_band[b]
    }

    /// The focal planes.
    #[must_use]
    pub fn planes(&self) -> &[PlaneElectronics] {
        &self.planes
    }

    /// Mean dark electrons of detector `j`, band `b` for an exposure of `exposure_s`.
    #[must_use]
    pub fn dark_mean_e(&self, j: usize, b: usize, exposure_s: f64) -> f64 {
        // `exposure_s` is on the instrument's clock; the plane integrates its share of it.
        let plane = self.plane(b);
        let own = exposure_s * plane.exposure_ratio;
        let fixed = self.dark_e[j * self.n_bands + b] - plane.dark_current_e_s * self.exposure_s * plane.exposure_ratio;
        (plane.dark_current_e_s * own + fixed * exposure_s / self.exposure_s).max(0.0)
    }

    /// Nominal exposure time, s.
    #[must_use]
    pub fn exposure_s(&self) -> f64 {
        self.exposure_s
    }

    /// Full-well capacity of band `b`'s pixels, e⁻.
    #[must_use]
    pub fn well_e(&self, b: usize) -> f64 {
        self.plane(b).well_e
    }

    /// Conversion gain of band `b`'s readout, e⁻/DN.
    #[must_use]
    pub fn gain_e_per_dn(&self, b: usize) -> f64 {
        self.plane(b).gain_e_per_dn
    }

    /// Read noise of band `b`'s value, e⁻ rms (÷ m for m × m binned pixels).
    #[must_use]
    pub fn read_noise_e(&self, b: usize) -> f64 {
        self.plane(b).read_noise_e
    }

    /// Bias of band `b`'s readout, DN.
    #[must_use]
    pub fn bias_dn(&self, b: usize) -> f64 {
        self.plane(b).bias_dn
    }

    /// Largest DN of band `b`'s ADC.
    #[must_use]
    pub fn dn_max(&self, b: usize) -> f64 {
        self.plane(b).dn_max
    }

    /// Electrons collected by detector `j`, band `b` from band radiance `radiance` during
    /// `exposure_s` (shot noise when on; clipped at the well unless ideal).
    pub fn expose<R: rand::Rng + ?Sized>(
        &self,
        j: usize,
        b: usize,
        radiance: f64,
        exposure_s: f64,
        rng: &mut R,
    ) -> f64 {
        let mean = match &self.focal {
            None => self.mean_e(j, b, radiance, exposure_s),
            Some(f) => {
                // The gain and dark signal drifted since the calibration.
                let dark = self.dark_mean_e(j, b, exposure_s);
                f.in_the_scene(j, b, self.mean_e(j, b, radiance, exposure_s) - dark, dark)
            }
        };
        let plane = self.plane(b);
        let q = plane.binned();
        // m × m binned pixels: the shot noise of their summed electrons, averaged.
        let e = match (self.mode.noise, q > 1.0) {
            (false, _) => mean,
            (true, false) => shot(mean, rng),
            (true, true) => shot(mean * q, rng) / q,
        };
        if self.ideal { e } else { e.min(plane.well_e) }
    }

    /// Mean electrons of detector `j`, band `b` for `radiance` over `exposure_s`.
    #[inline]
    fn mean_e(&self, j: usize, b: usize, radiance: f64, exposure_s: f64) -> f64 {
        if exposure_s == self.exposure_s {
            let i = j * self.n_bands + b;
            self.responsivity[i] * radiance.max(0.0) + self.dark_e[i]
        } else {
            self.responsivity(j, b) * radiance.max(0.0) * exposure_s / self.exposure_s
                + self.dark_mean_e(j, b, exposure_s)
        }
    }

    /// [`Self::expose`] prepared for repeated frames of one constant radiance (calibration
    /// frames, the SNR patch): the mean and the shot-noise distribution are set up once, and
    /// each [`Exposure::draw`] returns what `expose` would with the same generator.
    #[must_use]
    pub fn exposure(&self, j: usize, b: usize, radiance: f64, exposure_s: f64) -> Exposure {
        let mean = self.mean_e(j, b, radiance, exposure_s);
        let plane = self.plane(b);
        let q = plane.binned();
        let summed = mean * q;
        let shot = if !self.mode.noise {
            Shot::Fixed(summed)
        } else if !(mean > 0.0) {
            Shot::Fixed(0.0)
        } else if summed < 1000.0 {
            Poisson::new(summed).map_or(Shot::Fixed(summed), Shot::Poisson)
        } else {
            Shot::Normal { mean: summed, sd: summed.sqrt() }
        };
        Exposure { shot, binned: q, ideal: self.ideal, well_e: plane.well_e, mean_e: mean, curve: self.curve(j, b) }
    }

    /// Read out band `b`'s `electrons`: read noise, gain, bias and the ADC, through detector 0's
    /// response curve (one detector's own: [`Self::exposure`] carries it, Level-0 reads it per
    /// element).
    #[inline(always)]
    pub fn read_out<R: rand::Rng + ?Sized>(&self, b: usize, electrons: f64, rng: &mut R) -> Readout {
        let z = if self.mode.noise { normal(rng) } else { 0.0 };
        self.read_out_with(b, electrons, z)
    }

    /// The mean Level-0 value of `frames` frames of `exposure`, drawn at once: the sum of the
    /// frames' shot noise, read noise and rounding as one draw each, or `None` where a frame
    /// could clip or the ADC's rounding is not dithered (then only frame by frame is right).
    ///
    /// In distribution this is the mean of the frames [`Self::read_out`] would give:
    /// - shot noise: a sum of Poisson draws is a Poisson draw of the summed mean; a sum of the
    ///   normal approximation's draws is normal with the summed variance (its per-frame rounding
    ///   to whole electrons, dithered by σ ≥ 31 e⁻, adds 1/12 e⁻² per frame and is left out);
    /// - read noise: a sum of normal draws, N(0, n·σ²);
    /// - the ADC's rounding: with a read noise of at least 1 DN, each frame's rounding error is
    ///   uniform on ±½ DN and independent of the signal to within exp(−2π²σ²) ≈ 3·10⁻⁹
    ///   (Widrow & Kollár 2008, *Quantization Noise*, §5.2 and §7: the characteristic function
    ///   of the input at 2π, bounded by the Gaussian read noise's alone), so the mean is unbiased
    ///   and the n rounding errors add a normal of variance n/12 DN² (central limit);
    /// - clipping (the well, the ADC's range, zero): refused unless the mean is 6 σ inside, where
    ///   a frame clips with probability below 10⁻⁹ and the clipped tail moves the mean by less
    ///   than 2·10⁻¹⁰ σ (σ·(φ(z) − z·Q(z)) at z = 6).
    ///
    /// The calibration averages 100 light and 100 dark frames per detector and band: frame by
    /// frame that was the slowest part of a preview after a gain change.
    pub fn frames_mean<R: rand::Rng + ?Sized>(
        &self,
        b: usize,
        exposure: &Exposure,
        frames: usize,
        rng: &mut R,
    ) -> Option<f64> {
        /// A frame clips with probability below 10⁻⁹ beyond this many σ.
        const MARGIN_SIGMA: f64 = 6.0;
        if frames == 0 {
            return None;
        }
        if !self.mode.noise {
            // Every frame is the same value, read through the exposure's own detector's
            // response curve. A value that clips is read frame by frame, which counts the
            // saturated frames.
            let adc = readout::Adc::of(self, 0, b).with_curve(exposure.curve);
            let r = readout::value(adc, exposure.draw(rng), 0.0);
            return (r.flags & Flags::SATURATED == 0).then(|| self.level0_value(&r));
        }
        let plane = self.plane(b);
        let q = exposure.binned;
        let mu = exposure.mean_e.max(0.0);
        let sd_dn = (mu / q + plane.read_noise_e * plane.read_noise_e).sqrt() * plane.dn_per_e;
        let mean_dn = mu * plane.dn_per_e + plane.bias_dn;
        if !self.ideal && mu + MARGIN_SIGMA * (mu / q).sqrt() >= plane.well_e {
            return None;
        }
        if self.mode.quantise {
            let clear = mean_dn - MARGIN_SIGMA * sd_dn > 0.0 && mean_dn + MARGIN_SIGMA * sd_dn < plane.dn_max - 0.5;
            if plane.read_noise_e * plane.dn_per_e < 1.0 || !clear {
                return None;
            }
        } else if !self.ideal && mean_dn + MARGIN_SIGMA * sd_dn >= plane.dn_max {
            return None;
        }
        let n = frames as f64;
        // The frames' summed electrons (of all binned pixels), then per pixel.
        let summed = match &exposure.shot {
            Shot::Fixed(v) => n * v,
            Shot::Poisson(_) => Poisson::new(n * q * mu).map_or(n * q * mu, |p| p.sample(rng)),
            Shot::Normal { mean, sd } => n * mean + sd * n.sqrt() * normal(rng),
        };
        // The frames' mean electrons through the response curve: the curve of the mean, not the
        // mean of the curve, which differs by ½·f″·σ² ≈ a₂·μ/W e⁻ (under 0.02 e⁻ for a 1 %
        // curve: far below the mean's own noise).
        let electrons = exposure.curve.apply(summed / q / n) * n;
        let read_e = plane.read_noise_e * n.sqrt() * normal(rng);
        let mut value = (electrons + read_e) / n * plane.dn_per_e + plane.bias_dn;
        if self.mode.quantise {
            value += (1.0 / (12.0 * n)).sqrt() * normal(rng);
        }
        Some(value)
    }

    /// [`Self::read_out`] with its standard normal read-noise draw `z` given (ignored when noise
    /// is off). The arithmetic is [`readout::value`], shared with Level-0's vector lanes.
    #[inline(always)]
    fn read_out_with(&self, b: usize, electrons: f64, z: f64) -> Readout {
        readout::value(readout::Adc::of(self, 0, b), electrons, z)
    }

    /// The value Level-1 calibrates: the DN, or the analogue value when quantisation is off.
    #[must_use]
    pub fn level0_value(&self, r: &Readout) -> f64 {
        if self.mode.quantise { f64::from(r.dn) } else { f64::from(r.analog_dn) }
    }

    /// Noise variance in electrons² of band `b`'s value with `signal_e` photo-electrons and
    /// `dark_e` dark electrons per pixel: shot + read + quantisation (Janesick 2007, eq. 2.14 and
    /// §4.4); for m × m binned pixels the shot noise of their mean, the read noise σ/m, and one
    /// rounding of the mean.
    #[must_use]
    pub fn variance_e2(&self, b: usize, signal_e: f64, dark_e: f64) -> f64 {
        if !self.mode.noise {
            return 0.0;
        }
        let plane = self.plane(b);
        let quant = if self.mode.quantise { plane.gain_e_per_dn * plane.gain_e_per_dn / 12.0 } else { 0.0 };
        (signal_e + dark_e) / plane.binned() + plane.read_noise_e * plane.read_noise_e + quant
    }
}

mod exposure;
mod patterns;
mod plane;
mod readout;

pub use exposure::Exposure;

pub use plane::PlaneElectronics;
#[cfg(test)]
mod tests;
