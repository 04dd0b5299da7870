//! The focal-plane effects a [`super::Detector`] carries: its response curve
//! ([`NonLinearity`]) and the fixed patterns the calibration does not remove ([`FixedPatterns`]).
//!
//! Dead and hot elements change the detector itself (no responsivity; more dark signal) and so
//! reach the calibration frames as they reach the scene. The drifts of gain and dark signal
//! happen after the calibration: only the scene's exposures see them.

use rand::RngExt;

use super::{PlaneElectronics, Stream, normal, pixel_rng};
use crate::instrument::effects::nonlinearity::Curve;
use crate::instrument::effects::{self, FixedPatterns, NonLinearity};
use crate::instrument::spec::InstrumentSpec;

/// What of one draw the line key of [`pixel_rng`] selects.
#[derive(Clone, Copy)]
#[repr(usize)]
enum Draw {
    ColumnCurve = 1,
    GainDrift = 2,
    OffsetDrift = 3,
    Dead = 4,
    Hot = 5,
}

/// The focal-plane effects of one detector, per element (detector `j`, band `b`: `j·nb + b`).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct FocalEffects {
    n_bands: usize,
    /// Each band's curve (empty: linear).
    curves: Vec<Curve>,
    /// Each element's factor on its band's curve (empty: 1).
    column_factor: Vec<f64>,
    /// Each element's gain in the scene over its gain at calibration (empty: 1).
    gain_drift: Vec<f64>,
    /// Each element's dark signal in the scene over its dark signal at calibration, e⁻ (empty: 0).
    offset_drift_e: Vec<f64>,
    /// Elements with no response.
    pub(super) dead: Vec<bool>,
    /// Extra dark current per element, e⁻ s⁻¹ (empty: none).
    pub(super) hot_e_s: Vec<f64>,
}

/// `n` values of `f` from the generator of (`draw`, detector `j`), in band order.
fn draws(
    seed: u64,
    draw: Draw,
    j: usize,
    n: usize,
    mut f: impl FnMut(&mut rand::rngs::Xoshiro256PlusPlus) -> f64,
) -> Vec<f64> {
    let mut rng = pixel_rng(seed, Stream::FocalPlane, draw as usize, j);
    (0..n).map(|_| f(&mut rng)).collect()
}

impl FocalEffects {
    /// The effects `spec` states for `nd` detectors × `nb` bands on `planes` (`None`: it states
    /// none, and the detector is exactly as before they existed).
    pub(super) fn of(
        spec: &InstrumentSpec,
        nd: usize,
        planes: &[PlaneElectronics],
        plane_of_band: &[usize],
        seed: u64,
    ) -> Option<Self> {
        let nl: Option<&NonLinearity> = effects::non_linearity(&spec.effects);
        let fp: Option<&FixedPatterns> = effects::fixed_patterns(&spec.effects);
        if nl.is_none() && fp.is_none() {
            return None;
        }
        let nb = plane_of_band.len();
        let every = |draw: Draw, f: &dyn Fn(&mut rand::rngs::Xoshiro256PlusPlus) -> f64| -> Vec<f64> {
            (0..nd).flat_map(|j| draws(seed, draw, j, nb, f)).collect()
        };
        let curves =
            nl.map_or_else(Vec::new, |n| (0..nb).map(|b| n.curve(b, planes[plane_of_band[b]].well_e)).collect());
        let column_factor = match nl {
            Some(n) if n.column_spread > 0.0 => every(Draw::ColumnCurve, &|rng| 1.0 + n.column_spread * normal(rng)),
            _ => Vec::new(),
        };
        let fp = fp.cloned().unwrap_or_default();
        let gain_drift = if fp.gain_drift > 0.0 {
            every(Draw::GainDrift, &|rng| (1.0 + fp.gain_drift * normal(rng)).max(0.0))
        } else {
            Vec::new()
        };
        let offset_drift_e = if fp.offset_drift_e > 0.0 {
            every(Draw::OffsetDrift, &|rng| fp.offset_drift_e * normal(rng))
        } else {
            Vec::new()
        };
        let dead = if fp.dead_fraction > 0.0 {
            every(Draw::Dead, &|rng| f64::from(u8::from(rng.random::<f64>() < fp.dead_fraction)))
                .into_iter()
                .map(|d| d > 0.0)
                .collect()
        } else {
            Vec::new()
        };
        let hot_e_s = if fp.hot_fraction > 0.0 && fp.hot_dark_current_e_s > 0.0 {
            let hot = fp.hot_dark_current_e_s;
            every(Draw::Hot, &|rng| if rng.random::<f64>() < fp.hot_fraction { hot } else { 0.0 })
        } else {
            Vec::new()
        };
        Some(Self { n_bands: nb, curves, column_factor, gain_drift, offset_drift_e, dead, hot_e_s })
    }

    /// Element (j, b)'s response curve.
    #[inline]
    pub(super) fn curve(&self, j: usize, b: usize) -> Curve {
        match self.curves.get(b) {
            None => Curve::LINEAR,
            Some(c) => self.column_factor.get(j * self.n_bands + b).map_or(*c, |&f| c.scaled(f)),
        }
    }

    /// Does the curve differ between the columns of a band?
    pub(super) fn curve_varies_by_column(&self) -> bool {
        !self.column_factor.is_empty()
    }

    /// Mean electrons of element (j, b) in the scene from `signal_e` photo-electrons and
    /// `dark_e` dark electrons at calibration time: the drifts since.
    #[inline]
    pub(super) fn in_the_scene(&self, j: usize, b: usize, signal_e: f64, dark_e: f64) -> f64 {
        let i = j * self.n_bands + b;
        let gain = self.gain_drift.get(i).copied().unwrap_or(1.0);
        let offset = self.offset_drift_e.get(i).copied().unwrap_or(0.0);
        signal_e * gain + (dark_e + offset).max(0.0)
    }

    /// Is element (j, b) dead?
    pub(super) fn is_dead(&self, j: usize, b: usize) -> bool {
        self.dead.get(j * self.n_bands + b).copied().unwrap_or(false)
    }
}

impl super::Detector {
    /// Element (detector `j`, band `b`)'s response curve (linear unless the instrument states a
    /// non-linearity).
    #[must_use]
    pub fn curve(&self, j: usize, b: usize) -> Curve {
        self.focal.as_ref().map_or(Curve::LINEAR, |f| f.curve(j, b))
    }

    /// Is element (`j`, `b`) dead (no response)?
    #[must_use]
    pub fn is_dead(&self, j: usize, b: usize) -> bool {
        self.focal.as_ref().is_some_and(|f| f.is_dead(j, b))
    }

    /// Does a band's response curve differ between its columns?
    #[must_use]
    pub fn curve_varies_by_column(&self) -> bool {
        self.focal.as_ref().is_some_and(|f| f.curve_varies_by_column())
    }
}
