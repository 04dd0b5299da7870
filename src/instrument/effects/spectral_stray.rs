//! Spectral stray light: light of one band's wavelengths that the spectrograph or the filters
//! scatter into the other bands. Following Zong et al. (2006), the measured band signals are
//!
//! L′ = (I + D)·L,   D_ij = f·k_ij (i ≠ j),   D_jj = −f,   k_ij = e^(−|λ_i − λ_j|/w) / Σ_{i′≠j} e^(−|λ_i′ − λ_j|/w),
//!
//! where column j of D takes the share f of band j's light and spreads it over the other bands,
//! more to the near ones (scale w; a large w spreads it evenly, as a filter's out-of-band
//! leak across the spectrum). Every column of D sums to zero: light is moved, not made, so the
//! sum over bands is kept. The band radiances stand in for the spectrum between them (the
//! spectroradiometer's approximation of Zong et al., exact for a contiguous spectrograph).
//!
//! The processor corrects with its own matrix D̂ (f̂ = f·(1 + e)): L = (I + D̂)⁻¹·L′, as
//! Zong et al. correct an array spectroradiometer and as OLCI's Level-1 corrects its spectral
//! stray light (one matrix, inverted once, applied per pixel).
//!
//! ## References
//! - Zong, Y., Brown, S. W., Johnson, B. C., Lykke, K. R., Ohno, Y. (2006) Simple spectral stray
//!   light correction method for array spectroradiometers. Appl. Opt. 45, 1111–1119.

use ndarray::Array3;
use serde::{Deserialize, Serialize};

use super::{Context, Effect, InstrumentError, Knowledge, check};
use crate::control::RunControl;
use crate::parse::FieldError;
use crate::ranges as r;

/// Spectral stray light as an instrument file states it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpectralStrayLight {
    /// Share of each band's light scattered into the other bands (0.002: 0.2 %).
    pub fraction: f64,
    /// Spectral scale w of the scatter, nm: how far from its band the light lands.
    pub width_nm: f64,
    /// What the Level-1 processor knows of it.
    #[serde(default)]
    pub correction: Knowledge,
}

impl SpectralStrayLight {
    /// I + D for bands at `centres_nm`, with the share `fraction` (row-major, n × n).
    #[must_use]
    pub fn matrix(&self, centres_nm: &[f64], fraction: f64) -> Vec<f64> {
        let n = centres_nm.len();
        let mut m = vec![0.0; n * n];
        for j in 0..n {
            m[j * n + j] = 1.0;
            if n < 2 {
                continue;
            }
            // Each weight relative to the nearest other band's (the shares are the same): a
            // width far below the bands' spacing would otherwise underflow every weight to 0 and
            // make the shares 0/0. The nearest band then takes the whole share.
            let distance = |i: usize| (centres_nm[i] - centres_nm[j]).abs();
            let nearest = (0..n).filter(|&i| i != j).map(distance).fold(f64::INFINITY, f64::min);
            let k = |i: usize| (-(distance(i) - nearest) / self.width_nm).exp();
            let total: f64 = (0..n).filter(|&i| i != j).map(k).sum();
            m[j * n + j] -= fraction;
            for i in (0..n).filter(|&i| i != j) {
                m[i * n + j] += fraction * k(i) / total;
            }
        }
        m
    }

    /// Multiply every pixel's band vector by the n × n `m` (pixels in parallel: each is its own,
    /// so the result does not depend on the threads).
    fn transform(cube: &mut Array3<f32>, m: &[f64], control: &RunControl) -> Result<(), InstrumentError> {
        use rayon::prelude::*;
        let nb = cube.dim().2;
        let Some(values) = cube.as_slice_mut() else {
            return Err(InstrumentError::Invalid(FieldError {
                field: "effects[].SpectralStrayLight".into(),
                message: "the radiance cube is not in standard layout".into(),
            }));
        };
        // Blocks of 256 pixels: enough work per task, and a cancellation check per block.
        values.par_chunks_mut(256 * nb).try_for_each(|block| {
            if control.cancelled() {
                return Err(InstrumentError::Cancelled);
            }
            let mut input = vec![0.0; nb];
            for pixel in block.chunks_exact_mut(nb) {
                for (x, v) in input.iter_mut().zip(pixel.iter()) {
                    *x = f64::from(*v);
                }
                for (i, out) in pixel.iter_mut().enumerate() {
                    *out = m[i * nb..(i + 1) * nb].iter().zip(&input).map(|(a, x)| a * x).sum::<f64>() as f32;
                }
            }
            Ok(())
        })
    }
}

/// The inverse of the n × n row-major `a` by Gauss–Jordan elimination with partial pivoting
/// (`None` if singular; I + D with f < ½ is diagonally dominant by columns, so never).
#[must_use]
pub fn invert(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut a = a.to_vec();
    let mut inv: Vec<f64> = (0..n * n).map(|k| if k / n == k % n { 1.0 } else { 0.0 }).collect();
    for col in 0..n {
        let pivot = (col..n).max_by(|&x, &y| a[x * n + col].abs().total_cmp(&a[y * n + col].abs()))?;
        if a[pivot * n + col].abs() < 1e-300 {
            return None;
        }
        for k in 0..n {
            a.swap(col * n + k, pivot * n + k);
            inv.swap(col * n + k, pivot * n + k);
        }
        let p = a[col * n + col];
        for k in 0..n {
            a[col * n + k] /= p;
            inv[col * n + k] /= p;
        }
        for row in (0..n).filter(|&r| r != col) {
            let f = a[row * n + col];
            if f != 0.0 {
                for k in 0..n {
                    a[row * n + k] -= f * a[col * n + k];
                    inv[row * n + k] -= f * inv[col * n + k];
                }
            }
        }
    }
    Some(inv)
}

impl Effect for SpectralStrayLight {
    fn name(&self) -> &'static str {
        "SpectralStrayLight"
    }

    fn role(&self) -> super::Role {
        super::Role::Optics
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        check(&r::SPECTRAL_STRAY_FRACTION, self.fraction, &format!("{at}.fraction"))?;
        check(&r::SPECTRAL_STRAY_WIDTH_NM, self.width_nm, &format!("{at}.width_nm"))?;
        self.correction.validate(&r::SPECTRAL_STRAY_KNOWLEDGE_ERROR, at)
    }

    fn apply(&self, cube: &mut Array3<f32>, ctx: &Context, control: &RunControl) -> Result<(), InstrumentError> {
        Self::transform(cube, &self.matrix(ctx.centres_nm, self.fraction), control)
    }

    fn correct(&self, cube: &mut Array3<f32>, ctx: &Context, control: &RunControl) -> Result<(), InstrumentError> {
        let factor = self.correction.factor();
        if factor == 0.0 {
            return Ok(());
        }
        let n = ctx.centres_nm.len();
        let believed = self.matrix(ctx.centres_nm, (self.fraction * factor).min(0.99));
        let inverse = invert(&believed, n).ok_or_else(|| {
            InstrumentError::Invalid(FieldError {
                field: "effects[].SpectralStrayLight".into(),
                message: "the processor's stray-light matrix is singular".into(),
            })
        })?;
        Self::transform(cube, &inverse, control)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx(centres: &[f64]) -> Context<'_> {
        Context { spacing_m: (30.0, 30.0), pixel_m: 30.0, centres_nm: centres, stokes: None }
    }

    #[test]
    fn light_is_moved_between_bands_not_made_and_the_near_bands_get_more() {
        let centres = [443.0, 490.0, 560.0, 665.0, 865.0];
        let s = SpectralStrayLight { fraction: 0.01, width_nm: 50.0, correction: Knowledge::default() };
        // A single bright band (560 nm) in dark ones: it keeps 99 %, the rest lands nearer first.
        let mut cube = Array3::<f32>::zeros((1, 1, 5));
        cube[(0, 0, 2)] = 1.0;
        s.apply(&mut cube, &ctx(&centres), &RunControl::new()).unwrap();
        let v: Vec<f64> = cube.iter().map(|&x| f64::from(x)).collect();
        assert!((v[2] - 0.99).abs() < 1e-7, "{v:?}");
        assert!((v.iter().sum::<f64>() - 1.0).abs() < 1e-6, "{v:?}");
        assert!(v[1] > v[0] && v[1] > v[3] && v[3] > v[4], "{v:?}");
        // The weights by the exponential law: 490 nm gets e^(−70/50)/Σ of the other four.
        let k = |d: f64| (-d / 50.0f64).exp();
        let total = k(117.0) + k(70.0) + k(105.0) + k(305.0);
        assert!((v[1] - 0.01 * k(70.0) / total).abs() < 1e-7, "{v:?}");
    }

    #[test]
    fn the_processor_that_knows_the_matrix_gives_the_input_back() {
        let centres: Vec<f64> = (0..21).map(|i| 400.0 + 25.0 * f64::from(i)).collect();
        let s = SpectralStrayLight { fraction: 0.05, width_nm: 80.0, correction: Knowledge::default() };
        let truth = Array3::from_shape_fn((2, 3, 21), |(r, c, b)| (1.0 + r as f32 + c as f32) * (30.0 - b as f32));
        let mut cube = truth.clone();
        s.apply(&mut cube, &ctx(&centres), &RunControl::new()).unwrap();
        let mut back = cube.clone();
        s.correct(&mut back, &ctx(&centres), &RunControl::new()).unwrap();
        for (a, b) in back.iter().zip(truth.iter()) {
            assert!((a - b).abs() <= 8.0 * f32::EPSILON * b.abs(), "{a} vs {b}");
        }
        // A processor 20 % wrong leaves about 20 % of the stray signal (to first order in f).
        let wrong = SpectralStrayLight { correction: Knowledge { corrected: true, error: 0.2 }, ..s.clone() };
        let mut left = cube.clone();
        wrong.correct(&mut left, &ctx(&centres), &RunControl::new()).unwrap();
        let stray = f64::from(cube[(0, 0, 0)] - truth[(0, 0, 0)]);
        let residual = f64::from(left[(0, 0, 0)] - truth[(0, 0, 0)]);
        assert!((residual / stray + 0.2).abs() < 0.02, "residual {residual} of stray {stray}");
    }

    /// A width far below the bands' spacing (Landsat 8's SWIR band is 592 nm from the next:
    /// exp(−592/0.5) underflows to 0) sends each band's share to its nearest neighbour, and
    /// every entry is finite; the columns still sum to 1 (light moved, not made).
    #[test]
    fn a_narrow_width_gives_the_share_to_the_nearest_band() {
        let centres = [443.0, 482.0, 561.0, 655.0, 865.0, 1609.0, 2201.0];
        let s = SpectralStrayLight { fraction: 0.02, width_nm: 0.5, correction: Knowledge::default() };
        let m = s.matrix(&centres, s.fraction);
        let n = centres.len();
        assert!(m.iter().all(|v| v.is_finite()));
        for j in 0..n {
            let column: f64 = (0..n).map(|i| m[i * n + j]).sum();
            assert!((column - 1.0).abs() < 1e-15, "column {j} sums to {column}");
        }
        // 2201 nm gives its 2 % to 1609 nm, the nearest.
        assert!((m[5 * n + 6] - 0.02).abs() < 1e-15 && m[4 * n + 6] == 0.0);
    }

    #[test]
    fn inversion_of_a_known_matrix() {
        let a = [4.0, 7.0, 2.0, 6.0];
        let inv = invert(&a, 2).unwrap();
        let expect = [0.6, -0.7, -0.2, 0.4];
        for (x, y) in inv.iter().zip(expect) {
            assert!((x - y).abs() < 1e-12, "{inv:?}");
        }
        assert!(invert(&[1.0, 2.0, 2.0, 4.0], 2).is_none());
    }
}
