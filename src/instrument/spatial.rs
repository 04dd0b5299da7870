//! The instrument's spatial response, used only when a scene asks for `SpatialResponse`.
//!
//! The system point-spread function on the ground is the convolution of the optics, the detector
//! footprint and the motion during the exposure (Schowengerdt 2007, §3.4.3):
//!
//! - optics: the diffraction-limited Airy pattern of a circular aperture D, approximated by a
//!   Gaussian of σ = 0.42·λ·N in the focal plane (Zhang, Zerubia & Olivo-Marin 2007), i.e.
//!   σ_ground = 0.42·λ·H/D at altitude H;
//! - detector: a box one GSD wide in both directions;
//! - smear: a box v·t_exp long along track (ground speed × exposure time).
//!
//! The pixel's band radiance is the PSF-weighted mean of the scene radiance. Shoal evaluates it
//! with a product quadrature: sample points every GSD/`samples_per_gsd` along and across track,
//! each weighted by the 1-D PSF integrated over its sub-cell; tails holding less than 0.5 % at
//! either end are dropped and the weights renormalised, so a uniform scene keeps its radiance
//! exactly. Diffraction depends on λ, so each band has its own weights on shared points.
//!
//! ## References
//! - Schowengerdt, R. A. (2007) Remote Sensing: Models and Methods for Image Processing, 3rd ed.
//! - Zhang, B., Zerubia, J., Olivo-Marin, J.-C. (2007) Gaussian approximations of fluorescence
//!   microscope point-spread function models. Appl. Opt. 46, 1819–1829 (σ ≈ 0.21 λ/NA).

use super::spec::{InstrumentSpec, ground_speed_m_s};

/// Quadrature of the system PSF: sample offsets and per-band weights.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialKernel {
    /// Sample offsets from the pixel centre (along track, across track), m.
    pub offsets_m: Vec<(f64, f64)>,
    /// Per band: the weight of each offset (summing to 1).
    pub weights: Vec<Vec<f64>>,
}

/// Fraction of the PSF dropped at each tail of each axis.
const TAIL: f64 = 0.005;

impl SpatialKernel {
    /// A point sample at the pixel centre (no spatial response).
    #[must_use]
    pub fn point(n_bands: usize) -> Self {
        Self { offsets_m: vec![(0.0, 0.0)], weights: vec![vec![1.0]; n_bands] }
    }

    /// The PSF quadrature of `spec` for bands centred at `centres_nm`.
    #[must_use]
    pub fn new(spec: &InstrumentSpec, centres_nm: &[f64], samples_per_gsd: usize) -> Self {
        let gsd = spec.gsd_m();
        let h = gsd / samples_per_gsd.max(1) as f64;
        let smear = ground_speed_m_s(spec.altitude_km) * spec.exposure_s;
        let altitude = spec.altitude_km * 1e3;
        let aperture = spec.aperture_mm * 1e-3;
        let sigmas: Vec<f64> = centres_nm.iter().map(|&w| 0.42 * w * 1e-9 * altitude / aperture).collect();
        let max_sigma = sigmas.iter().copied().fold(0.0, f64::max);
        // Per band, 1-D weights on the shared positions; then keep the union of significant ones.
        let along: Vec<Vec<f64>> = sigmas.iter().map(|&s| axis_weights(&[gsd, smear], s, h, max_sigma)).collect();
        let across: Vec<Vec<f64>> = sigmas.iter().map(|&s| axis_weights(&[gsd], s, h, max_sigma)).collect();
        let keep = |all: &[Vec<f64>]| -> (usize, usize) {
            let n = all[0].len();
            let mut lo = n;
            let mut hi = 0;
            for w in all {
                let (a, b) = trim(w);
                lo = lo.min(a);
                hi = hi.max(b);
            }
            (lo, hi)
        };
        let (a0, a1) = keep(&along);
        let (c0, c1) = keep(&across);
        let centre = |n: usize| (n / 2) as f64;
        let na = along[0].len();
        let nc = across[0].len();
        let mut offsets_m = Vec::new();
        for i in a0..=a1 {
            for k in c0..=c1 {
                offsets_m.push(((i as f64 - centre(na)) * h, (k as f64 - centre(nc)) * h));
            }
        }
        let weights = along
            .iter()
            .zip(&across)
            .map(|(wa, wc)| {
                let mut w = Vec::with_capacity(offsets_m.len());
                for i in a0..=a1 {
                    for k in c0..=c1 {
                        w.push(wa[i] * wc[k]);
                    }
                }
                let total: f64 = w.iter().sum();
                w.iter().map(|v| v / total).collect()
            })
            .collect();
        Self { offsets_m, weights }
    }

    /// Number of sample points per pixel.
    #[must_use]
    pub fn len(&self) -> usize {
        self.offsets_m.len()
    }

    /// Is this empty? (Never, for a built kernel.)
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.offsets_m.is_empty()
    }
}

/// Weights of sub-cells of width `h` centred on 0, ±h, ±2h, … for the 1-D PSF
/// box(widths[0]) ⊗ box(widths[1]) ⊗ … ⊗ Gauss(σ), by numerical convolution on a fine grid.
/// `max_sigma` fixes the half-width so that every band shares the positions.
fn axis_weights(widths: &[f64], sigma: f64, h: f64, max_sigma: f64) -> Vec<f64> {
    let half = widths.iter().map(|w| 0.5 * w).sum::<f64>() + 4.0 * max_sigma;
    let k_max = (half / h + 0.5).ceil() as i64;
    let fine = h / 64.0;
    let n_fine = ((2.0 * (k_max as f64 + 0.5) * h) / fine).round() as usize;
    let x0 = -(k_max as f64 + 0.5) * h;
    let xs: Vec<f64> = (0..n_fine).map(|i| x0 + (i as f64 + 0.5) * fine).collect();
    // Start from the first box, convolve with the rest and the Gaussian.
    let mut psf: Vec<f64> = xs.iter().map(|&x| if x.abs() <= 0.5 * widths[0] { 1.0 } else { 0.0 }).collect();
    let convolve = |f: &[f64], kernel: &dyn Fn(f64) -> f64, reach: f64| -> Vec<f64> {
        let r = (reach / fine).ceil() as i64;
        let taps: Vec<f64> = (-r..=r).map(|i| kernel(i as f64 * fine)).collect();
        let sum: f64 = taps.iter().sum();
        if !(sum > 0.0) {
            return f.to_vec();
        }
        (0..f.len() as i64)
            .map(|i| {
                let mut acc = 0.0;
                for (t, w) in taps.iter().enumerate() {
                    let j = i + t as i64 - r;
                    if j >= 0 && (j as usize) < f.len() {
                        acc += w * f[j as usize];
                    }
                }
                acc / sum
            })
            .collect()
    };
    for &w in &widths[1..] {
        if w > fine {
            psf = convolve(&psf, &|x: f64| if x.abs() <= 0.5 * w { 1.0 } else { 0.0 }, 0.5 * w);
        }
    }
    if sigma > fine {
        psf = convolve(&psf, &|x: f64| (-0.5 * (x / sigma).powi(2)).exp(), 4.0 * sigma);
    }
    let n_cells = (2 * k_max + 1) as usize;
    let mut cells = vec![0.0; n_cells];
    for (x, p) in xs.iter().zip(&psf) {
        let c = (((x - x0) / h).floor() as usize).min(n_cells - 1);
        cells[c] += p;
    }
    let total: f64 = cells.iter().sum();
    cells.iter().map(|c| c / total).collect()
}

/// Indices of the first and last cells kept after dropping `TAIL` at each end.
fn trim(w: &[f64]) -> (usize, usize) {
    let mut acc = 0.0;
    let mut lo = 0;
    for (i, v) in w.iter().enumerate() {
        acc += v;
        if acc > TAIL {
            lo = i;
            break;
        }
    }
    acc = 0.0;
    let mut hi = w.len() - 1;
    for (i, v) in w.iter().enumerate().rev() {
        acc += v;
        if acc > TAIL {
            hi = i;
            break;
        }
    }
    (lo, hi.max(lo))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_alone_is_trapezoid_rule() {
        // A GSD box sampled at GSD/2: weights ¼, ½, ¼.
        let w = axis_weights(&[20.0], 0.0, 10.0, 0.0);
        let mid = w.len() / 2;
        assert!((w[mid] - 0.5).abs() < 0.02, "{w:?}");
        assert!((w[mid - 1] - 0.25).abs() < 0.02);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn kernel_is_normalised_and_centred() {
        let spec = InstrumentSpec::preset("cubesat").unwrap();
        let k = SpatialKernel::new(&spec, &[400.0, 865.0], 2);
        for w in &k.weights {
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            let mean_along: f64 = w.iter().zip(&k.offsets_m).map(|(w, o)| w * o.0).sum();
            assert!(mean_along.abs() < 1e-9);
        }
        // The smear makes the kernel longer along track than across.
        let span = |f: fn(&(f64, f64)) -> f64| k.offsets_m.iter().map(f).fold(0.0, f64::max);
        assert!(span(|o| o.0) >= span(|o| o.1));
    }
}
