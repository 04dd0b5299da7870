//! One exposure's shot noise: the electrons a pixel collects, drawn (see [`super`]).

use rand_distr::{Distribution, Poisson, StandardNormal};

use crate::instrument::effects::nonlinearity::Curve;

/// Shot noise: a Poisson draw of mean `mean` electrons (normal approximation above 1000).
#[inline(always)]
pub(super) fn shot<R: rand::Rng + ?Sized>(mean: f64, rng: &mut R) -> f64 {
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
pub(super) enum Shot {
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
    /// The draw of the electrons of all `binned` pixels together.
    pub(super) shot: Shot,
    /// Pixels averaged into the value (m² for a finer focal plane, 1 otherwise).
    pub(super) binned: f64,
    /// An ideal detector does not clip at the well.
    pub(super) ideal: bool,
    pub(super) well_e: f64,
    /// Mean electrons of a frame (per pixel).
    pub(super) mean_e: f64,
    /// The pixel's response curve (the readout applies it: [`super::readout::value`]).
    pub(super) curve: Curve,
}

impl Exposure {
    /// Electrons of one frame: the same value as [`super::Detector::expose`] with the same generator.
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
        let e = if self.binned > 1.0 { e / self.binned } else { e };
        if self.ideal { e } else { e.min(self.well_e) }
    }
}

/// Round half up to a whole number, negative values to 0. (`f64::round` is a libm call on the
/// baseline x86-64 target; the truncating conversion is one instruction.)
#[inline]
pub(super) fn round_non_negative(x: f64) -> f64 {
    if x > 0.0 { (x + 0.5) as i64 as f64 } else { 0.0 }
}
