//! What the calibration does about the focal-plane effects
//! ([`crate::instrument::effects`]): it linearises every value with the response curve it
//! believes before deriving or applying its coefficients, and it finds the dead elements (a
//! gain below a tenth of the band's median) to fill them from their neighbours or flag them.

use crate::instrument::Flags;
use crate::instrument::detector::Detector;
use crate::instrument::effects::nonlinearity::Curve;
use crate::instrument::effects::{self, InstrumentEffect};

/// What the processor knows of the focal-plane effects (the instrument file's `correction` and
/// `interpolate_dead`): the calibration's input, kept apart from the detector, which is the
/// same whatever the processor believes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FocalKnowledge {
    /// The calibration's factor on the true response curve (0: it does not linearise).
    pub curve_factor: f64,
    /// It fills dead elements from their neighbours (else it flags them).
    pub fill_dead: bool,
}

impl FocalKnowledge {
    /// What an instrument's `effects` say the processor knows.
    #[must_use]
    pub fn of(list: &[InstrumentEffect]) -> Self {
        Self {
            curve_factor: effects::non_linearity(list).map_or(0.0, |n| n.correction.factor()),
            fill_dead: effects::fixed_patterns(list).is_none_or(|p| p.interpolate_dead),
        }
    }
}

/// An element whose gain is below this share of its band's median gain is dead.
const DEAD_GAIN_SHARE: f64 = 0.1;

/// The calibration's linearisation: each element's believed curve and each band's converter.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearisation {
    n_bands: usize,
    /// Per detector × band (`None`: linear).
    curves: Vec<Option<Curve>>,
    /// Per band: e⁻/DN and bias, DN (the processor knows its converters).
    gain_e_per_dn: Vec<f64>,
    bias_dn: Vec<f64>,
}

impl Linearisation {
    /// The curves the calibration believes for `detector`'s detectors `0..nd`: the true ones
    /// times `factor` (the true ones when `exact`: the perfect calibration); `None` when it
    /// linearises nothing.
    #[must_use]
    pub fn of(detector: &Detector, nd: usize, factor: f64, exact: bool) -> Option<Self> {
        let nb = detector.n_bands();
        let curves: Vec<Option<Curve>> = (0..nd * nb)
            .map(|i| {
                let (j, b) = (i / nb, i % nb);
                let factor = if exact { 1.0 } else { factor };
                Some(detector.curve(j, b)).filter(|c| !c.is_linear() && factor != 0.0).map(|c| c.scaled(factor))
            })
            .collect();
        curves.iter().any(Option::is_some).then(|| Self {
            n_bands: nb,
            curves,
            gain_e_per_dn: (0..nb).map(|b| detector.gain_e_per_dn(b)).collect(),
            bias_dn: (0..nb).map(|b| detector.bias_dn(b)).collect(),
        })
    }

    /// Level-0 `value` of element (`j`, `b`) as a linear detector would have read it:
    /// e′ = (value − bias)·gain, e = f⁻¹(e′), value′ = e/gain + bias.
    #[inline]
    #[must_use]
    pub fn value(&self, j: usize, b: usize, value: f64) -> f64 {
        match self.curves.get(j * self.n_bands + b) {
            Some(Some(curve)) => {
                let (g, bias) = (self.gain_e_per_dn[b], self.bias_dn[b]);
                curve.invert((value - bias) * g) / g + bias
            }
            _ => value,
        }
    }
}

/// The dead elements the calibration found, and what it does with them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Defects {
    n_bands: usize,
    /// Per detector × band.
    dead: Vec<bool>,
    /// Fill from the neighbours (else flag).
    pub fill: bool,
}

impl Defects {
    /// The elements among `used` whose gain (per detector × band) is below a tenth of their
    /// band's median over `used`; `None` when there are none.
    #[must_use]
    pub fn find(gain: &[f64], nb: usize, used: &[usize], fill: bool) -> Option<Self> {
        let mut dead = vec![false; gain.len()];
        for b in 0..nb {
            let mut g: Vec<f64> = used.iter().filter_map(|&j| gain.get(j * nb + b).copied()).collect();
            if g.is_empty() {
                continue;
            }
            g.sort_by(f64::total_cmp);
            let median = g[g.len() / 2];
            for &j in used {
                if let Some(&v) = gain.get(j * nb + b) {
                    dead[j * nb + b] = !(v > DEAD_GAIN_SHARE * median);
                }
            }
        }
        dead.iter().any(|&d| d).then_some(Self { n_bands: nb, dead, fill })
    }

    /// Is element (`j`, `b`) dead?
    #[must_use]
    pub fn is_dead(&self, j: usize, b: usize) -> bool {
        self.dead.get(j * self.n_bands + b).copied().unwrap_or(false)
    }

    /// Fill or flag the dead elements of one Level-1 row (`radiance` and `flags`, column after
    /// column of `nb` bands; column c read by detector `detector_index[c]`): each dead value
    /// becomes the mean of the nearest working column on each side (the one there is at an
    /// edge), or 0 flagged [`Flags::DEFECTIVE`] when the processor does not fill, or when no
    /// column of the band works.
    pub fn repair_row(&self, radiance: &mut [f32], flags: &mut [u8], detector_index: &[usize]) {
        let nb = self.n_bands;
        let cols = detector_index.len();
        let dead = |c: usize, b: usize| self.is_dead(detector_index[c], b);
        for b in 0..nb {
            for c in (0..cols).filter(|&c| dead(c, b)) {
                let left = (0..c).rev().find(|&k| !dead(k, b));
                let right = (c + 1..cols).find(|&k| !dead(k, b));
                let value = |k: usize| radiance[k * nb + b];
                let filled = match (left, right) {
                    (Some(l), Some(r)) => Some(0.5 * (value(l) + value(r))),
                    (Some(k), None) | (None, Some(k)) => Some(value(k)),
                    (None, None) => None,
                };
                match filled.filter(|_| self.fill) {
                    Some(v) => radiance[c * nb + b] = v,
                    None => {
                        radiance[c * nb + b] = 0.0;
                        flags[c * nb + b] |= Flags::DEFECTIVE;
                    }
                }
            }
        }
    }
}
