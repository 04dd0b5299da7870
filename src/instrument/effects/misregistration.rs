//! Band-to-band misregistration: each band looks at a ground grid shifted from the others by a
//! fraction of a pixel (filters on separate rows of the focal plane seeing the ground at
//! different times, a keystone, the platform's motion between band exposures).
//!
//! Band b's image is the scene's moved by (Δr_b, Δc_b) pixels along and across track,
//! L′_b(r, c) = L_b(r − Δr_b, c − Δc_b), resampled by cubic convolution (Keys 1981, a = −½; the
//! resampler of Level-1 processors, Schowengerdt 2007, §7.5; edges held). Unlike bilinear
//! resampling, which averages neighbours and so lowers the noise by a fifth at a 0.1 px shift,
//! it keeps the noise within 4 % there. The shifts are either stated per band or drawn, each component normal with the stated
//! rms `sigma_px` (the convention of the Φsat-2 simulator's band-to-band shifts), from a
//! generator of the design's own (`draw`): the same design misregisters the same way in every
//! run and preview. Shifts are in pixels of the instrument's grid; a decimated preview moves by
//! the same ground distance.
//!
//! The Level-1 processor co-registers each band with the shift it believes, (1 + error)·Δ,
//! resampling it back: known exactly, the bands line up again, left with the smoothing of two
//! resamplings; known to 10 %, a tenth of each shift remains.
//!
//! ## References
//! - Keys, R. G. (1981) Cubic convolution interpolation for digital image processing. IEEE
//!   Trans. Acoust. Speech Signal Process. 29, 1153–1160.
//! - Schowengerdt, R. A. (2007) Remote Sensing: Models and Methods for Image Processing, 3rd
//!   ed., Academic Press, §7.5 (resampling).

use ndarray::Array3;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{Context, Effect, InstrumentError, Knowledge, check};
use crate::control::RunControl;
use crate::parse::FieldError;
use crate::ranges as r;

/// Band-to-band misregistration as an instrument file states it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Misregistration {
    /// Rms of each band's shift along and across track, pixels (drawn per band).
    pub sigma_px: f64,
    /// Each band's (along, across) shift in pixels, replacing the draws (empty: drawn).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub per_band: Vec<(f64, f64)>,
    /// The draws' seed: another value, another set of shifts of the same rms.
    #[serde(default)]
    pub draw: u64,
    /// What the processor's co-registration knows of the shifts.
    #[serde(default)]
    pub correction: Knowledge,
}

impl Misregistration {
    /// Each of `bands` bands' (along, across) shift, pixels.
    #[must_use]
    pub fn shifts_px(&self, bands: usize) -> Vec<(f64, f64)> {
        if !self.per_band.is_empty() {
            return self.per_band.clone();
        }
        (0..bands)
            .map(|b| {
                let seed =
                    self.draw.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (b as u64).wrapping_add(0xD1B5_4A32_D192_ED03);
                let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed);
                let (a, c): (f64, f64) = (StandardNormal.sample(&mut rng), StandardNormal.sample(&mut rng));
                (self.sigma_px * a, self.sigma_px * c)
            })
            .collect()
    }

    /// Move every band by `factor` × its shift (in the cube's pixels: `ctx` scales for a
    /// decimated preview).
    fn shift(&self, cube: &mut Array3<f32>, ctx: &Context, factor: f64) -> Result<(), InstrumentError> {
        let (rows, cols, nb) = cube.dim();
        let shifts = self.shifts_px(nb);
        if shifts.len() != nb {
            return Err(InstrumentError::Invalid(FieldError {
                field: "instrument.effects[].Misregistration.per_band".into(),
                message: format!("{} shifts for {nb} bands (allowed: one per band, or none)", shifts.len()),
            }));
        }
        let scale = (ctx.pixel_m / ctx.spacing_m.0, ctx.pixel_m / ctx.spacing_m.1);
        let source = cube.clone();
        let data = cube.as_slice_mut().ok_or_else(|| {
            InstrumentError::Invalid(FieldError { field: "cube".into(), message: "not contiguous".into() })
        })?;
        // Each band's shift is the same over the image: its taps and weights along each axis
        // once per band (`Taps`), then 4 × 4 taps per value, edges held.
        let taps: Vec<(Taps, Taps)> = shifts
            .iter()
            .map(|&(along, across)| (Taps::of(factor * along * scale.0), Taps::of(factor * across * scale.1)))
            .collect();
        data.par_chunks_mut(cols * nb).enumerate().for_each(|(r, row)| {
            for (b, (down, across)) in taps.iter().enumerate() {
                let rows_at = down.indices(r, rows);
                for c in 0..cols {
                    let cols_at = across.indices(c, cols);
                    let mut value = 0.0;
                    for (&ri, &wy) in rows_at.iter().zip(&down.weights) {
                        let line: f64 = cols_at
                            .iter()
                            .zip(&across.weights)
                            .map(|(&ci, &wx)| wx * f64::from(source[(ri, ci, b)]))
                            .sum();
                        value += wy * line;
                    }
                    row[c * nb + b] = value as f32;
                }
            }
        });
        Ok(())
    }
}

/// Cubic convolution's four taps for a shift of `d` pixels along one axis: output pixel i reads
/// i − d, i.e. input pixels ⌊i − d⌋ − 1 … ⌊i − d⌋ + 2 with Keys's (1981) weights, a = −½.
#[derive(Debug, Clone, Copy)]
struct Taps {
    /// ⌊−d⌋: the first tap's offset from the output pixel, plus 1.
    offset: i64,
    weights: [f64; 4],
}

impl Taps {
    fn of(d: f64) -> Self {
        let x = -d;
        let offset = x.floor();
        let t = x - offset;
        Self { offset: offset as i64, weights: [keys(t + 1.0), keys(t), keys(1.0 - t), keys(2.0 - t)] }
    }

    /// The four input indices output `i` of `n` reads (held at the edges).
    fn indices(&self, i: usize, n: usize) -> [usize; 4] {
        let last = n as i64 - 1;
        std::array::from_fn(|k| (i as i64 + self.offset + k as i64 - 1).clamp(0, last) as usize)
    }
}

/// Keys's (1981) cubic convolution kernel with a = −½: it reproduces quadratics exactly, and its
/// four weights sum to 1 at any phase.
fn keys(s: f64) -> f64 {
    const A: f64 = -0.5;
    let s = s.abs();
    if s <= 1.0 {
        ((A + 2.0) * s - (A + 3.0)) * s * s + 1.0
    } else if s < 2.0 {
        ((A * s - 5.0 * A) * s + 8.0 * A) * s - 4.0 * A
    } else {
        0.0
    }
}

impl Effect for Misregistration {
    fn name(&self) -> &'static str {
        "Misregistration"
    }

    fn role(&self) -> super::Role {
        super::Role::FocalPlane
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        check(&r::MISREGISTRATION_SIGMA_PX, self.sigma_px, &format!("{at}.sigma_px"))?;
        for (i, &(a, c)) in self.per_band.iter().enumerate() {
            check(&r::MISREGISTRATION_SIGMA_PX, a.abs(), &format!("{at}.per_band[{i}].0"))?;
            check(&r::MISREGISTRATION_SIGMA_PX, c.abs(), &format!("{at}.per_band[{i}].1"))?;
        }
        self.correction.validate(&r::MISREGISTRATION_KNOWLEDGE_ERROR, at)
    }

    fn apply(&self, cube: &mut Array3<f32>, ctx: &Context, _control: &RunControl) -> Result<(), InstrumentError> {
        self.shift(cube, ctx, 1.0)
    }

    fn correct(&self, cube: &mut Array3<f32>, ctx: &Context, _control: &RunControl) -> Result<(), InstrumentError> {
        let factor = self.correction.factor();
        if factor == 0.0 { Ok(()) } else { self.shift(cube, ctx, -factor) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx(centres: &[f64]) -> Context<'_> {
        Context { spacing_m: (30.0, 30.0), pixel_m: 30.0, centres_nm: centres, stokes: None }
    }

    /// Where a rising edge of a row sits, in columns: its dark share summed over the row, less
    /// a half (the step between columns 9 and 10 sits at 9.5). Linear resampling keeps a
    /// row's sum, so this moves by exactly the shift (a half-way crossing would not, on a step
    /// sharper than a pixel).
    fn crossing(row: &[f32]) -> f64 {
        let (lo, hi) = (f64::from(row[0]), f64::from(row[row.len() - 1]));
        row.iter().map(|&v| (hi - f64::from(v)) / (hi - lo)).sum::<f64>() - 0.5
    }

    #[test]
    fn a_sharp_edge_moves_by_the_shift_and_the_processor_moves_it_back() {
        // A vertical edge (dark left, bright right) in two bands; band 1 moves 0.3 px across
        // and 0.6 px along (the along-track shift leaves a vertical edge in place).
        let (rows, cols) = (8, 20);
        let cube = Array3::from_shape_fn((rows, cols, 2), |(_, c, _)| if c < 10 { 1.0f32 } else { 3.0 });
        let centres = [490.0, 560.0];
        let m = Misregistration {
            sigma_px: 0.0,
            per_band: vec![(0.0, 0.0), (0.6, 0.3)],
            draw: 0,
            correction: Knowledge::default(),
        };
        let mut moved = cube.clone();
        m.apply(&mut moved, &ctx(&centres), &RunControl::new()).unwrap();
        let edge = |c: &Array3<f32>, b: usize| crossing(&c.slice(ndarray::s![4, .., b]).to_vec());
        assert!((edge(&moved, 0) - edge(&cube, 0)).abs() < 1e-6);
        assert!((edge(&moved, 1) - edge(&cube, 1) - 0.3).abs() < 1e-6, "{}", edge(&moved, 1));
        // Co-registered with the exact shift: the edge is back where it was.
        let mut back = moved.clone();
        m.correct(&mut back, &ctx(&centres), &RunControl::new()).unwrap();
        assert!((edge(&back, 1) - edge(&cube, 1)).abs() < 1e-6, "{}", edge(&back, 1));
        // Believed 10 % too large: a tenth of the shift, the other way.
        let wrong = Misregistration { correction: Knowledge { corrected: true, error: 0.1 }, ..m.clone() };
        let mut left = moved.clone();
        wrong.correct(&mut left, &ctx(&centres), &RunControl::new()).unwrap();
        assert!((edge(&left, 1) - edge(&cube, 1) + 0.03).abs() < 1e-5, "{}", edge(&left, 1));
    }

    #[test]
    fn cubic_weights_sum_to_one_and_keep_the_noise() {
        for d in [0.0, 0.1, 0.3, 0.5, -0.7, 2.25] {
            let t = Taps::of(d);
            assert!((t.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{d}: {t:?}");
            // The first moment moves a ramp by exactly the shift.
            let moment: f64 = t.weights.iter().enumerate().map(|(k, w)| w * (t.offset + k as i64 - 1) as f64).sum();
            assert!((moment + d).abs() < 1e-12, "{d}: {moment}");
        }
        // White noise's variance through one axis at 0.1 px: Σw² = 0.960 (bilinear: 0.82).
        let w = Taps::of(0.1).weights;
        let kept: f64 = w.iter().map(|w| w * w).sum();
        assert!((kept - 0.960).abs() < 1e-3, "{kept}");
        assert_eq!(Taps::of(0.0).weights, [0.0, 1.0, 0.0, 0.0]);
    }

    #[test]
    fn drawn_shifts_have_the_stated_rms_and_are_the_designs_own() {
        let m = Misregistration { sigma_px: 0.2, per_band: vec![], draw: 7, correction: Knowledge::default() };
        let s = m.shifts_px(4000);
        let rms = (s.iter().map(|(a, c)| a * a + c * c).sum::<f64>() / (2.0 * s.len() as f64)).sqrt();
        // 8000 normal draws: the sample rms within 3 % of σ (3.5 standard errors of 0.8 %).
        assert!((rms / 0.2 - 1.0).abs() < 0.03, "{rms}");
        assert_eq!(s, m.shifts_px(4000));
        assert_ne!(s, Misregistration { draw: 8, ..m }.shifts_px(4000));
    }
}
