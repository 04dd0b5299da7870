//! Convolution of band images with a kernel far larger than a pixel, by FFT.
//!
//! The image is padded by the kernel's half-size on every side with its mirror image (the scene
//! beyond the simulated edge is taken to continue as it looks inside: the half-sample symmetric
//! extension of image processing), placed in a transform of a 5-smooth size at least that of
//! the padded image, multiplied by the kernel's spectrum and transformed back. The transform is
//! as large as the padded image, so the circular wrap reaches only the padding: inside the image
//! the result is the linear convolution, exact to rounding (tested against the direct sum).
//!
//! ## References
//! - Press, W. H., Teukolsky, S. A., Vetterling, W. T., Flannery, B. P. (2007) Numerical Recipes,
//!   3rd ed., §13.1 (convolution by FFT and the wrap-around it must be padded against).

use std::sync::Arc;

use ndarray::{Array2, ArrayView2};
use rustfft::num_complex::Complex64;
use rustfft::{Fft, FftPlanner};

/// A kernel's spectrum on the transform grid of one image size.
pub struct KernelSpectrum {
    image: (usize, usize),
    half: (usize, usize),
    n: (usize, usize),
    spectrum: Vec<Complex64>,
    row_fft: (Arc<dyn Fft<f64>>, Arc<dyn Fft<f64>>),
    col_fft: (Arc<dyn Fft<f64>>, Arc<dyn Fft<f64>>),
}

/// The smallest 2^a·3^b·5^c at least `n` (sizes rustfft transforms fast).
#[must_use]
pub fn fast_size(n: usize) -> usize {
    (n.max(1)..)
        .find(|&m| {
            let mut k = m;
            for p in [2, 3, 5] {
                while k % p == 0 {
                    k /= p;
                }
            }
            k == 1
        })
        .unwrap_or(n)
}

/// Index `i` of the half-sample symmetric extension of `0..n` (−1 → 0, n → n − 1).
fn reflect(i: isize, n: usize) -> usize {
    let period = 2 * n as isize;
    let m = i.rem_euclid(period);
    if m < n as isize { m as usize } else { (period - 1 - m) as usize }
}

impl KernelSpectrum {
    /// The spectrum of `kernel` (odd sizes, centred) for images of `image` = (rows, columns).
    #[must_use]
    pub fn new(kernel: &Array2<f64>, image: (usize, usize)) -> Self {
        let (kr, kc) = kernel.dim();
        let half = (kr / 2, kc / 2);
        let n = (fast_size(image.0 + 2 * half.0), fast_size(image.1 + 2 * half.1));
        let mut planner = FftPlanner::new();
        let row_fft = (planner.plan_fft_forward(n.1), planner.plan_fft_inverse(n.1));
        let col_fft = (planner.plan_fft_forward(n.0), planner.plan_fft_inverse(n.0));
        let mut spectrum = vec![Complex64::default(); n.0 * n.1];
        for ((i, j), &k) in kernel.indexed_iter() {
            let r = (i as isize - half.0 as isize).rem_euclid(n.0 as isize) as usize;
            let c = (j as isize - half.1 as isize).rem_euclid(n.1 as isize) as usize;
            spectrum[r * n.1 + c] = Complex64::new(k, 0.0);
        }
        let mut out = Self { image, half, n, spectrum: Vec::new(), row_fft, col_fft };
        out.transform(&mut spectrum, true);
        out.spectrum = spectrum;
        out
    }

    /// 2-D transform in place: every row, then every column (through a transpose).
    fn transform(&self, data: &mut [Complex64], forward: bool) {
        let (nr, nc) = self.n;
        let (rows, cols) =
            if forward { (&self.row_fft.0, &self.col_fft.0) } else { (&self.row_fft.1, &self.col_fft.1) };
        rows.process(data);
        let mut t = vec![Complex64::default(); nr * nc];
        for r in 0..nr {
            for c in 0..nc {
                t[c * nr + r] = data[r * nc + c];
            }
        }
        cols.process(&mut t);
        for c in 0..nc {
            for r in 0..nr {
                data[r * nc + c] = t[c * nr + r];
            }
        }
    }

    /// `band` ⊗ kernel, the image mirrored beyond its edges; the image's shape must be the one
    /// this spectrum was made for.
    #[must_use]
    pub fn convolve(&self, band: ArrayView2<f32>) -> Array2<f64> {
        assert_eq!(band.dim(), self.image, "the kernel spectrum was made for another image size");
        let (rows, cols) = self.image;
        let (hr, hc) = self.half;
        let (nr, nc) = self.n;
        let mut data = vec![Complex64::default(); nr * nc];
        for pr in 0..rows + 2 * hr {
            let r = reflect(pr as isize - hr as isize, rows);
            for pc in 0..cols + 2 * hc {
                let c = reflect(pc as isize - hc as isize, cols);
                data[pr * nc + pc] = Complex64::new(f64::from(band[(r, c)]), 0.0);
            }
        }
        self.transform(&mut data, true);
        for (d, k) in data.iter_mut().zip(&self.spectrum) {
            *d *= k;
        }
        self.transform(&mut data, false);
        let scale = 1.0 / (nr * nc) as f64;
        Array2::from_shape_fn((rows, cols), |(r, c)| data[(r + hr) * nc + (c + hc)].re * scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fft_convolution_is_the_direct_sum_with_mirrored_edges() {
        let (rows, cols) = (7, 11);
        let band = Array2::from_shape_fn((rows, cols), |(r, c)| ((r * 13 + c * 7) % 5) as f32 + 0.5);
        let kernel = Array2::from_shape_fn((5, 9), |(i, j)| 1.0 / (1.0 + (i * i + j) as f64));
        let fast = KernelSpectrum::new(&kernel, (rows, cols)).convolve(band.view());
        for r in 0..rows {
            for c in 0..cols {
                let mut direct = 0.0;
                for ((i, j), k) in kernel.indexed_iter() {
                    let rr = reflect(r as isize + 2 - i as isize, rows);
                    let cc = reflect(c as isize + 4 - j as isize, cols);
                    direct += k * f64::from(band[(rr, cc)]);
                }
                assert!((fast[(r, c)] - direct).abs() < 1e-12 * direct.abs().max(1.0), "({r}, {c})");
            }
        }
    }

    #[test]
    fn sizes_and_reflection() {
        assert_eq!(fast_size(7), 8);
        assert_eq!(fast_size(121), 125);
        assert_eq!((reflect(-1, 4), reflect(-2, 4), reflect(4, 4), reflect(9, 4)), (0, 1, 3, 1));
    }
}
