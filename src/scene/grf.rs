//! Gaussian random fields by spectral synthesis: white Gaussian noise shaped in the Fourier
//! domain by the square root of the power spectrum of a Gaussian covariance
//! C(r) = exp(−r²/(2ℓ²)), whose 2-D spectrum is S(k) ∝ exp(−k²ℓ²/2), then transformed back.
//! The field is periodic over the raster; it is rescaled to zero mean and unit standard
//! deviation exactly, so a map's statistics are the ones its spec states.
//!
//! ## References
//! - Lang, A. & Potthoff, J. (2011) Fast simulation of Gaussian random fields. Monte Carlo
//!   Methods Appl. 17, 195–214.
//! - Rasmussen, C. E. & Williams, C. K. I. (2006) Gaussian Processes for Machine Learning, MIT
//!   Press, §4.2 (squared-exponential covariance and its spectral density).

use rand::SeedableRng;
use rand::rngs::Xoshiro256PlusPlus;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex32;

/// A zero-mean, unit-variance field of `width` × `height` cells of `cell_m` metres with
/// correlation length `correlation_m`, row-major (row 0 = south edge). Deterministic in `seed`.
#[must_use]
pub fn gaussian_random_field(width: usize, height: usize, cell_m: f64, correlation_m: f64, seed: u64) -> Vec<f32> {
    synthesise(width, height, cell_m, correlation_m, seed, true)
}

/// [`gaussian_random_field`]; `skip_zero_rows`: leave the rows of zero amplitude out of the
/// first pass of the inverse FFT (the tests compare the two).
fn synthesise(
    width: usize,
    height: usize,
    cell_m: f64,
    correlation_m: f64,
    seed: u64,
    skip_zero_rows: bool,
) -> Vec<f32> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let n = width * height;
    let mut data: Vec<Complex32> = (0..n)
        .map(|_| {
            let re: f64 = StandardNormal.sample(&mut rng);
            let im: f64 = StandardNormal.sample(&mut rng);
            Complex32::new(re as f32, im as f32)
        })
        .collect();
    // Shape by √S(k); k in rad/m on the FFT's frequency layout.
    let freq = |i: usize, len: usize| -> f64 {
        let j = if i <= len / 2 { i as f64 } else { i as f64 - len as f64 };
        2.0 * std::f64::consts::PI * j / (len as f64 * cell_m)
    };
    let l2 = correlation_m * correlation_m;
    // Every amplitude of such a row is below e^−110 (0 as an f32, below): most rows of a large
    // field, whose exponentials were most of its synthesis time.
    let zero_row = |row: usize| {
        let ky = freq(row, height);
        -(ky * ky) * l2 / 4.0 < -110.0
    };
    data.par_chunks_exact_mut(width.max(1)).enumerate().for_each(|(row, cells)| {
        if zero_row(row) {
            cells.iter_mut().for_each(|cell| *cell *= 0.0);
            return;
        }
        let ky = freq(row, height);
        for (col, cell) in cells.iter_mut().enumerate() {
            let kx = freq(col, width);
            // √exp(−k²ℓ²/2). Below e^−110 the amplitude is 0 as an f32 (whose smallest value is
            // 1.4·10⁻⁴⁵ ≈ e^−103.3). The exponent is clamped there before exp, which keeps libm
            // off its slow underflow path (most of a large field's cells took it: the compiler
            // evaluates exp on both sides of the select, so a branch alone did not avoid it).
            let exponent = -(kx * kx + ky * ky) * l2 / 4.0;
            let amplitude = exponent.max(-110.0).exp() as f32;
            let amplitude = if exponent < -110.0 { 0.0 } else { amplitude };
            *cell *= amplitude;
        }
    });
    let mut field = inverse_fft_2d_real(data, width, height, |row| skip_zero_rows && zero_row(row));
    // The sums in order, one after the other (a parallel sum would add in another order and
    // change the field's last bits with the thread count); the rescaling in parallel.
    let mean = field.iter().map(|v| f64::from(*v)).sum::<f64>() / n as f64;
    let var = field.iter().map(|v| (f64::from(*v) - mean).powi(2)).sum::<f64>() / n as f64;
    let std = var.sqrt().max(f64::MIN_POSITIVE);
    field.par_iter_mut().for_each(|v| *v = ((f64::from(*v) - mean) / std) as f32);
    field
}

/// The real part of the 2-D inverse FFT (rows, then columns) of `data`, unnormalised (the
/// caller rescales). Rows are transformed in parallel; the columns too, as rows of the
/// transpose (each transform is the same as one at a time, so the field does not depend on the
/// thread count). At most two complex arrays are held at once (16 bytes a cell).
///
/// Rows for which `zero_row` holds are all zeros (of either sign) and are left as they are:
/// their transform is zeros too, and a zero's sign cannot change a sum with a non-zero term, so
/// the columns' transforms are the same bits but for the sign of exact zeros (and the field's
/// rescaling takes those to the same value).
fn inverse_fft_2d_real(
    mut data: Vec<Complex32>,
    width: usize,
    height: usize,
    zero_row: impl Fn(usize) -> bool + Sync,
) -> Vec<f32> {
    if width == 0 || height == 0 {
        return data.iter().map(|c| c.re).collect();
    }
    let mut planner = FftPlanner::<f32>::new();
    let mut rows = |data: &mut [Complex32], len: usize, skip: &(dyn Fn(usize) -> bool + Sync)| {
        let fft = planner.plan_fft_inverse(len);
        data.par_chunks_exact_mut(len).enumerate().for_each_init(
            || vec![Complex32::new(0.0, 0.0); fft.get_inplace_scratch_len()],
            |scratch, (i, line)| {
                if !skip(i) {
                    fft.process_with_scratch(line, scratch);
                }
            },
        );
    };
    rows(&mut data, width, &zero_row);
    let mut transposed = vec![Complex32::new(0.0, 0.0); data.len()];
    transpose_into(&data, width, height, &mut transposed);
    drop(data);
    rows(&mut transposed, height, &|_| false);
    let mut real = vec![0.0f32; transposed.len()];
    transpose_into_with(&transposed, height, width, &mut real, |c| c.re);
    real
}

/// Write the transpose of the row-major `width` × `height` array `data` into `out`, in
/// cache-sized tiles.
fn transpose_into(data: &[Complex32], width: usize, height: usize, out: &mut [Complex32]) {
    transpose_into_with(data, width, height, out, |c| c);
}

/// [`transpose_into`], writing `f` of each value.
fn transpose_into_with<T: Send>(
    data: &[Complex32],
    width: usize,
    height: usize,
    out: &mut [T],
    f: impl Fn(Complex32) -> T + Sync,
) {
    const TILE: usize = 32;
    // Each output row block (TILE input columns) is written by one task.
    out.par_chunks_mut(TILE * height).enumerate().for_each(|(block, out_rows)| {
        let c0 = block * TILE;
        let c1 = (c0 + TILE).min(width);
        for r0 in (0..height).step_by(TILE) {
            for r in r0..(r0 + TILE).min(height) {
                for c in c0..c1 {
                    out_rows[(c - c0) * height + r] = f(data[r * width + c]);
                }
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaving_out_the_rows_of_zero_amplitude_changes_no_bit() {
        // A large field (most rows zero), a small one with a short correlation (few or none)
        // and one of odd sizes.
        for (w, h, cell, l, seed) in
            [(600, 400, 20.0, 1500.0, 2023), (500, 400, 10.0, 50.0, 3), (257, 129, 30.0, 5000.0, 9)]
        {
            let skipped = synthesise(w, h, cell, l, seed, true);
            let full = synthesise(w, h, cell, l, seed, false);
            assert!(skipped.iter().zip(&full).all(|(a, b)| a.to_bits() == b.to_bits()), "{w} × {h}");
        }
    }

    #[test]
    fn unit_statistics_and_determinism() {
        let a = gaussian_random_field(128, 96, 10.0, 100.0, 7);
        let b = gaussian_random_field(128, 96, 10.0, 100.0, 7);
        assert_eq!(a, b);
        let mean = a.iter().map(|v| f64::from(*v)).sum::<f64>() / a.len() as f64;
        let var = a.iter().map(|v| (f64::from(*v) - mean).powi(2)).sum::<f64>() / a.len() as f64;
        assert!(mean.abs() < 1e-6 && (var - 1.0).abs() < 1e-4);
        assert_ne!(a, gaussian_random_field(128, 96, 10.0, 100.0, 8));
    }

    #[test]
    fn correlation_length_sets_the_correlation() {
        // For C(r) = exp(−r²/2ℓ²): neighbours one ℓ apart correlate at e^{−1/2} ≈ 0.61 and
        // three ℓ apart at ≈ 0.01. Estimated over a large field (±0.1 sampling spread).
        let (w, h, cell, l) = (256, 256, 10.0, 50.0);
        let f = gaussian_random_field(w, h, cell, l, 3);
        let corr = |lag: usize| {
            let mut s = 0.0;
            let mut n = 0.0;
            for r in 0..h {
                for c in 0..w - lag {
                    s += f64::from(f[r * w + c]) * f64::from(f[r * w + c + lag]);
                    n += 1.0;
                }
            }
            s / n
        };
        let one = corr((l / cell) as usize);
        let three = corr((3.0 * l / cell) as usize);
        assert!((one - (-0.5f64).exp()).abs() < 0.1, "{one}");
        assert!(three.abs() < 0.1, "{three}");
    }
}
