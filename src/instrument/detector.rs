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

/// Shot noise: a Poisson draw of mean `mean` electrons (normal approximation above 1000).
fn shot<R: rand::Rng + ?Sized>(mean: f64, rng: &mut R) -> f64 {
    if !(mean > 0.0) {
        return 0.0;
    }
    if mean < 1000.0 {
        return Poisson::new(mean).map_or(mean, |p| p.sample(rng));
    }
    let z: f64 = StandardNormal.sample(rng);
    round_non_negative(mean + mean.sqrt() * z)
}

/// Shot noise set up for one mean (see [`shot`]).
#[derive(Debug, Clone, Copy)]
enum Shot {
    /// No draw: noise off, or no signal.
    Fixed(f64),
    /// An exact Poisson draw (mean below 1000).
    Poisson(Poisson<f64>),
    /// The normal approximation.
    Normal { mean: f64, sd: f64 },
}

/// One detector and band's exposure to a constant radiance, from [`Detector::exposure`].
#[derive(Debug, Clone, Copy)]
pub struct Exposure {
    shot: Shot,
    /// An ideal detector does not clip at the well.
    ideal: bool,
    well_e: f64,
    /// Mean electrons of a frame.
    mean_e: f64,
}

impl Exposure {
    /// Electrons of one frame: the same value as [`Detector::expose`] with the same generator.
    #[inline]
    pub fn draw<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> f64 {
        let e = match &self.shot {
            Shot::Fixed(v) => *v,
            Shot::Poisson(p) => p.sample(rng),
            Shot::Normal { mean, sd } => {
                let z: f64 = StandardNormal.sample(rng);
                round_non_negative(mean + sd * z)
            }
        };
        if self.ideal { e } else { e.min(self.well_e) }
    }
}

/// Round half up to a whole number, negative values to 0. (`f64::round` is a libm call on the
/// baseline x86-64 target; the truncating conversion is one instruction.)
#[inline]
fn round_non_negative(x: f64) -> f64 {
    if x > 0.0 { (x + 0.5) as i64 as f64 } else { 0.0 }
}

/// A standard normal draw.
#[must_use]
pub fn normal<R: rand::Rng + ?Sized>(rng: &mut R) -> f64 {
    StandardNormal.sample(rng)
}

/// The detector of one instrument: per-(detector, band) responsivity and dark signal, and the
/// readout electronics.
#[derive(Debug, Clone, PartialEq)]
pub struct Detector {
    n_bands: usize,
    /// Mean electrons per unit band radiance (W m⁻² sr⁻¹ nm⁻¹) at the nominal exposure, with
    /// PRNU, per detector × band.
    responsivity: Vec<f64>,
    /// Mean dark electrons at the nominal exposure (dark current and DSNU), per detector × band.
    dark_e: Vec<f64>,
    /// Dark current, e⁻/s (for exposures other than the nominal one).
    dark_current_e_s: f64,
    exposure_s: f64,
    well_e: f64,
    read_noise_e: f64,
    gain_e_per_dn: f64,
    dn_per_e: f64,
    bias_dn: f64,
    dn_max: f64,
    ideal: bool,
    mode: DetectorMode,
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
    #[must_use]
    pub fn new(spec: &InstrumentSpec, response: &Response, mode: DetectorMode, seed: u64) -> Self {
        let ideal = spec.is_ideal();
        let mode = if ideal { DetectorMode::IDEAL } else { mode };
        let nb = response.n_bands();
        let nd = spec.detectors;
        let geometric = spec.exposure_s * spec.optical_transmission * spec.etendue_m2_sr();
        let mut responsivity = vec![0.0; nd * nb];
        let mut dark_e = vec![0.0; nd * nb];
        for j in 0..nd {
            let mut rng = pixel_rng(seed, Stream::FixedPattern, 0, j);
            for (gi, g) in response.groups.iter().enumerate() {
                for (k, &b) in g.bands.iter().enumerate() {
                    let photons: f64 = response.weights(gi, k, j).1.iter().sum();
                    let (z1, z2) = (normal(&mut rng), normal(&mut rng));
                    let prnu = if ideal { 1.0 } else { (1.0 + spec.prnu * z1).max(0.0) };
                    responsivity[j * nb + b] = geometric * photons * prnu;
                    let dsnu = if ideal { 0.0 } else { spec.dsnu_e * z2 };
                    dark_e[j * nb + b] = (spec.dark_current_e_s * spec.exposure_s + dsnu).max(0.0);
                }
            }
        }
        Self {
            n_bands: nb,
            responsivity,
            dark_e,
            dark_current_e_s: spec.dark_current_e_s,
            exposure_s: spec.exposure_s,
            // In f32 precision: the electrons cube is stored as f32 (level0.rs), and a pixel
            // clipped at the well must still compare ≥ the well when read out and be flagged.
            well_e: f64::from(spec.well_depth_e as f32),
            read_noise_e: spec.read_noise_e,
            gain_e_per_dn: spec.gain_e_per_dn,
            dn_per_e: 1.0 / spec.gain_e_per_dn,
            bias_dn: spec.bias_dn,
            dn_max: spec.dn_max(),
            ideal,
            mode,
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

    /// Mean dark electrons of detector `j`, band `b` for an exposure of `exposure_s`.
    #[must_use]
    pub fn dark_mean_e(&self, j: usize, b: usize, exposure_s: f64) -> f64 {
        let fixed = self.dark_e[j * self.n_bands + b] - self.dark_current_e_s * self.exposure_s;
        (self.dark_current_e_s * exposure_s + fixed * exposure_s / self.exposure_s).max(0.0)
    }

    /// Nominal exposure time, s.
    #[must_use]
    pub fn exposure_s(&self) -> f64 {
        self.exposure_s
    }

    /// Full-well capacity, e⁻.
    #[must_use]
    pub fn well_e(&self) -> f64 {
        self.well_e
    }

    /// Conversion gain, e⁻/DN.
    #[must_use]
    pub fn gain_e_per_dn(&self) -> f64 {
        self.gain_e_per_dn
    }

    /// Read noise, e⁻ rms.
    #[must_use]
    pub fn read_noise_e(&self) -> f64 {
        self.read_noise_e
    }

    /// Bias, DN.
    #[must_use]
    pub fn bias_dn(&self) -> f64 {
        self.bias_dn
    }

    /// Largest DN.
    #[must_use]
    pub fn dn_max(&self) -> f64 {
        self.dn_max
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
        let mean = self.mean_e(j, b, radiance, exposure_s);
        let e = if self.mode.noise { shot(mean, rng) } else { mean };
        if self.ideal { e } else { e.min(self.well_e) }
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
        let shot = if !self.mode.noise {
            Shot::Fixed(mean)
        } else if !(mean > 0.0) {
            Shot::Fixed(0.0)
        } else if mean < 1000.0 {
            Poisson::new(mean).map_or(Shot::Fixed(mean), Shot::Poisson)
        } else {
            Shot::Normal { mean, sd: mean.sqrt() }
        };
        Exposure { shot, ideal: self.ideal, well_e: self.well_e, mean_e: mean }
    }

    /// Read out `electrons`: read noise, gain, bias and the ADC.
    #[inline(always)]
    pub fn read_out<R: rand::Rng + ?Sized>(&self, electrons: f64, rng: &mut R) -> Readout {
        let z = if self.mode.noise { normal(rng) } else { 0.0 };
        self.read_out_with(electrons, z)
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
    pub fn frames_mean<R: rand::Rng + ?Sized>(&self, exposure: &Exposure, frames: usize, rng: &mut R) -> Option<f64> {
        /// A frame clips with probability below 10⁻⁹ beyond this many σ.
        const MARGIN_SIGMA: f64 = 6.0;
        if frames == 0 {
            return None;
        }
        if !self.mode.noise {
            // Every frame is the same value.
            return Some(self.level0_value(&self.read_out_with(exposure.draw(rng), 0.0)));
        }
        let mu = exposure.mean_e.max(0.0);
        let sd_dn = (mu + self.read_noise_e * self.read_noise_e).sqrt() * self.dn_per_e;
        let mean_dn = mu * self.dn_per_e + self.bias_dn;
        if !self.ideal && mu + MARGIN_SIGMA * mu.sqrt() >= self.well_e {
            return None;
        }
        if self.mode.quantise {
            let clear = mean_dn - MARGIN_SIGMA * sd_dn > 0.0 && mean_dn + MARGIN_SIGMA * sd_dn < self.dn_max - 0.5;
            if self.read_noise_e * self.dn_per_e < 1.0 || !clear {
                return None;
            }
        } else if !self.ideal && mean_dn + MARGIN_SIGMA * sd_dn >= self.dn_max {
            return None;
        }
        let n = frames as f64;
        let electrons = match &exposure.shot {
            Shot::Fixed(v) => n * v,
            Shot::Poisson(_) => Poisson::new(n * mu).map_or(n * mu, |p| p.sample(rng)),
            Shot::Normal { mean, sd } => n * mean + sd * n.sqrt() * normal(rng),
        };
        let read_e = self.read_noise_e * n.sqrt() * normal(rng);
        let mut value = (electrons + read_e) / n * self.dn_per_e + self.bias_dn;
        if self.mode.quantise {
            value += (1.0 / (12.0 * n)).sqrt() * normal(rng);
        }
        Some(value)
    }

    /// [`Self::read_out`] with its standard normal read-noise draw `z` given (ignored when noise
    /// is off). The arithmetic is [`readout::value`], shared with Level-0's vector lanes.
    #[inline(always)]
    fn read_out_with(&self, electrons: f64, z: f64) -> Readout {
        readout::value(readout::Adc::of(self), electrons, z)
    }

    /// The value Level-1 calibrates: the DN, or the analogue value when quantisation is off.
    #[must_use]
    pub fn level0_value(&self, r: &Readout) -> f64 {
        if self.mode.quantise { f64::from(r.dn) } else { f64::from(r.analog_dn) }
    }

    /// Noise variance in electrons² of a pixel with `signal_e` photo-electrons and `dark_e`
    /// dark electrons: shot + read + quantisation (Janesick 2007, eq. 2.14 and §4.4).
    #[must_use]
    pub fn variance_e2(&self, signal_e: f64, dark_e: f64) -> f64 {
        if !self.mode.noise {
            return 0.0;
        }
        let quant = if self.mode.quantise { self.gain_e_per_dn * self.gain_e_per_dn / 12.0 } else { 0.0 };
        signal_e + dark_e + self.read_noise_e * self.read_noise_e + quant
    }
}

mod readout;
#[cfg(test)]
mod tests;
