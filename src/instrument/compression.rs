//! On-board compression of Level-0: a predictive coder in the manner of CCSDS 123.0-B-2
//! (lossless and near-lossless multispectral compression), its rate, and the error it leaves.
//!
//! Each count is predicted from counts already coded (reconstructed, as the decoder sees them):
//!
//! x̂(c, b) = W + P − WP,   W = x̃(c − 1, b),  P = x̃(c, b − 1),  WP = x̃(c − 1, b − 1),
//!
//! the left neighbour carried by the band-to-band step of its own pixel (P alone in the first
//! column, W alone in the first band, nothing for the row's first count), clipped to the ADC's
//! range. Rows are coded independently (a pushbroom line is a coding unit), so they run in
//! parallel. The residual d = x − x̂ is quantised with the step 2m + 1 of CCSDS 123.0-B-2's
//! near-lossless mode, q = sign(d)·⌊(|d| + m)/(2m + 1)⌋, and the count is reconstructed as
//! x̃ = x̂ + q·(2m + 1) (clipped to the range): |x − x̃| ≤ m, and m = 0 is lossless.
//!
//! The rate is the zero-order entropy of the mapped residuals (2q for q ≥ 0, −2q − 1 else) over
//! the image, with residuals beyond 4094 sent raw after an escape: a lower bound on what an
//! adaptive entropy coder reaches on them. The compression ratio is the ADC's bits over it.
//! With a rate target, the coder takes the smallest m (at least the stated bound) whose rate
//! on a sample of rows meets it, by bisection (the rate falls as m grows).
//!
//! ## References
//! - CCSDS (2019) Low-Complexity Lossless and Near-Lossless Multispectral and Hyperspectral
//!   Image Compression. CCSDS 123.0-B-2, Blue Book (predictor, quantiser, mapped residuals).
//! - Shannon, C. E. (1948) A mathematical theory of communication. Bell Syst. Tech. J. 27,
//!   379–423 (the entropy bound).

use ndarray::Array3;
use rayon::prelude::*;
use serde::Serialize;

use super::InstrumentError;
use super::detector::Detector;
use super::effects::compression::Compression;
use super::level0::Level0;
use crate::control::RunControl;
use crate::parse::FieldError;

/// Mapped residuals with a bin of their own; larger ones share the escape bin.
const BINS: usize = 4096;

/// Rows the rate search codes at least (every k-th row of larger images).
const SEARCH_ROWS: usize = 64;

/// What the coder did to one image.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CompressionReport {
    /// The error bound used, DN.
    pub max_error_dn: u32,
    /// The largest reconstruction error, DN.
    pub largest_error_dn: u32,
    /// Rate, bits per sample (zero-order entropy of the residuals).
    pub bits_per_sample: f64,
    /// The ADC's bits over the rate.
    pub ratio: f64,
}

/// Residual statistics of coded rows.
#[derive(Clone)]
struct Tally {
    counts: Vec<u64>,
    escapes: u64,
    largest_error: u32,
}

impl Tally {
    fn new() -> Self {
        Self { counts: vec![0; BINS], escapes: 0, largest_error: 0 }
    }

    fn merge(mut self, other: Self) -> Self {
        self.counts.iter_mut().zip(&other.counts).for_each(|(a, b)| *a += b);
        self.escapes += other.escapes;
        self.largest_error = self.largest_error.max(other.largest_error);
        self
    }

    /// Zero-order entropy per sample, with `raw_bits` more for each escaped residual.
    fn bits_per_sample(&self, raw_bits: f64) -> f64 {
        let n: u64 = self.counts.iter().sum();
        if n == 0 {
            return 0.0;
        }
        let n = n as f64;
        let entropy: f64 = self.counts.iter().filter(|&&c| c > 0).map(|&c| c as f64 / n).map(|p| -p * p.log2()).sum();
        entropy + self.escapes as f64 / n * raw_bits
    }
}

/// Code one row (`row`: column after column of `nb` bands; `top[b]`: band b's largest count)
/// with error bound `m` into `tally`; the reconstructed counts replace the row's when `write`.
fn code_row(row: &mut [u16], nb: usize, top: &[u16], m: u32, write: bool, tally: &mut Tally) {
    let step = 2 * i64::from(m) + 1;
    let mut rec = vec![0u16; row.len()];
    for i in 0..row.len() {
        let (c, b) = (i / nb, i % nb);
        let hi = i64::from(top[b]);
        let predicted = match (c > 0, b > 0) {
            (true, true) => {
                let (w, p, wp) = (rec[i - nb], rec[i - 1], rec[i - nb - 1]);
                (i64::from(w) + i64::from(p) - i64::from(wp)).clamp(0, hi)
            }
            (true, false) => i64::from(rec[i - nb]),
            (false, true) => i64::from(rec[i - 1]).min(hi),
            (false, false) => 0,
        };
        let x = i64::from(row[i]);
        let d = x - predicted;
        let q = d.signum() * ((d.abs() + i64::from(m)) / step);
        let back = (predicted + q * step).clamp(0, hi);
        rec[i] = back as u16;
        tally.largest_error = tally.largest_error.max((x - back).unsigned_abs() as u32);
        let mapped = if q >= 0 { 2 * q } else { -2 * q - 1 } as u64;
        if mapped >= (BINS - 1) as u64 {
            tally.counts[BINS - 1] += 1;
            tally.escapes += 1;
        } else {
            tally.counts[mapped as usize] += 1;
        }
    }
    if write {
        row.copy_from_slice(&rec);
    }
}

/// How the counts lie: `stride` counts a row, `nb` bands a pixel, `top[b]` band b's largest.
#[derive(Clone, Copy)]
struct Layout<'a> {
    stride: usize,
    nb: usize,
    top: &'a [u16],
}

/// Code every `every`-th row of `dn` (row-major, as `layout` says) with bound `m`.
fn code(dn: &mut [u16], layout: Layout<'_>, m: u32, every: usize, write: bool, control: &RunControl) -> Tally {
    dn.par_chunks_mut(layout.stride)
        .step_by(every)
        .fold(Tally::new, |mut tally, row| {
            if !control.cancelled() {
                code_row(row, layout.nb, layout.top, m, write, &mut tally);
            }
            tally
        })
        .reduce(Tally::new, Tally::merge)
}

/// Compress `level0`'s counts as `settings` say, each band with its focal plane's ADC. The
/// ideal-ADC closure setting (quantisation off) has no counts to compress: `None`.
pub fn compress_level0(
    level0: &mut Level0,
    detector: &Detector,
    settings: &Compression,
    control: &RunControl,
) -> Result<Option<CompressionReport>, InstrumentError> {
    if level0.analog.is_some() {
        return Ok(None);
    }
    let bits: Vec<u32> = (0..detector.n_bands()).map(|b| (detector.dn_max(b) + 1.0).log2().round() as u32).collect();
    let report = compress(&mut level0.dn, &bits, settings, control)?;
    level0.compression = Some(report);
    Ok(Some(report))
}

/// Compress the counts `dn` (row, column, band; band b's ADC of `bits[b]` bits) as `settings`
/// say, in place: the counts become what the ground decodes.
pub fn compress(
    dn: &mut Array3<u16>,
    bits: &[u32],
    settings: &Compression,
    control: &RunControl,
) -> Result<CompressionReport, InstrumentError> {
    let (rows, cols, nb) = dn.dim();
    if bits.len() != nb {
        return Err(InstrumentError::Invalid(FieldError {
            field: "Level-0".into(),
            message: format!("{nb} bands against {} ADCs", bits.len()),
        }));
    }
    let top: Vec<u16> = bits.iter().map(|&b| ((1u32 << b.min(16)) - 1) as u16).collect();
    let raw_bits = bits.iter().map(|&b| f64::from(b)).sum::<f64>() / nb.max(1) as f64;
    let stride = cols * nb;
    let data = dn.as_slice_mut().ok_or_else(|| {
        InstrumentError::Invalid(FieldError { field: "Level-0".into(), message: "not contiguous".into() })
    })?;
    let layout = Layout { stride, nb, top: &top };
    let mut m = settings.max_error_dn;
    if settings.bits_per_sample > 0.0 && stride > 0 {
        // Bisection on a sample of rows: the smallest bound whose rate meets the target.
        let every = (rows / SEARCH_ROWS).max(1);
        let rate = |m: u32, data: &mut [u16]| code(data, layout, m, every, false, control).bits_per_sample(raw_bits);
        let widest = u32::from(top.iter().copied().max().unwrap_or(0)) / 2;
        if rate(m, data) > settings.bits_per_sample {
            let (mut lo, mut hi) = (m, m.max(1));
            while hi < widest && rate(hi, data) > settings.bits_per_sample {
                (lo, hi) = (hi, (2 * hi).min(widest));
            }
            while hi - lo > 1 {
                let mid = lo + (hi - lo) / 2;
                if rate(mid, data) > settings.bits_per_sample { lo = mid } else { hi = mid }
            }
            m = hi;
        }
    }
    let tally = code(data, layout, m, 1, true, control);
    if control.cancelled() {
        return Err(InstrumentError::Cancelled);
    }
    let bits_per_sample = tally.bits_per_sample(raw_bits);
    Ok(CompressionReport {
        max_error_dn: m,
        largest_error_dn: tally.largest_error,
        bits_per_sample,
        ratio: if bits_per_sample > 0.0 { raw_bits / bits_per_sample } else { f64::INFINITY },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth 12-bit image with a little noise (a generator of its own, reproducible).
    fn image(rows: usize, cols: usize, nb: usize) -> Array3<u16> {
        let mut state = 12345u64;
        Array3::from_shape_fn((rows, cols, nb), |(r, c, b)| {
            state = crate::instrument::detector::mix64(state);
            let noise = (state % 7) as f64 - 3.0;
            (1000.0 + 300.0 * ((r + c) as f64 / 20.0).sin() + 40.0 * b as f64 + noise) as u16
        })
    }

    #[test]
    fn lossless_is_exact_and_near_lossless_keeps_its_bound() {
        let original = image(40, 50, 6);
        let control = RunControl::new();
        let mut lossless = original.clone();
        let report = compress(&mut lossless, &[12; 6], &Compression::default(), &control).unwrap();
        assert_eq!(lossless, original);
        assert_eq!(report.largest_error_dn, 0);
        // Noise uniform over 7 values dominates the residuals: about log2(7·√2-ish) bits, far
        // below the 12 raw bits.
        assert!(report.ratio > 2.0 && report.bits_per_sample < 6.0, "{report:?}");
        for m in [1, 3, 10] {
            let mut lossy = original.clone();
            let r = compress(&mut lossy, &[12; 6], &Compression { max_error_dn: m, bits_per_sample: 0.0 }, &control)
                .unwrap();
            let worst = lossy.iter().zip(&original).map(|(a, b)| a.abs_diff(*b)).max().unwrap();
            assert!(u32::from(worst) <= m && r.largest_error_dn == u32::from(worst), "m {m}: {worst}");
            // The error is spread over ±m: its rms is close to that of a uniform quantiser,
            // √((2m + 1)² − 1)/√12 (within 25 %: the residuals are not uniform within a step).
            let n = original.len() as f64;
            let rms =
                (lossy.iter().zip(&original).map(|(a, b)| f64::from(*a) - f64::from(*b)).map(|e| e * e).sum::<f64>()
                    / n)
                    .sqrt();
            let uniform = ((f64::from(2 * m + 1).powi(2) - 1.0) / 12.0).sqrt();
            assert!((rms / uniform - 1.0).abs() < 0.25, "m {m}: rms {rms} against {uniform}");
            assert!(r.bits_per_sample < report.bits_per_sample, "m {m}: {} bits", r.bits_per_sample);
        }
    }

    #[test]
    fn a_rate_target_takes_the_smallest_bound_that_meets_it() {
        let original = image(128, 64, 4);
        let control = RunControl::new();
        let target = 2.0;
        let mut coded = original.clone();
        let r = compress(&mut coded, &[12; 4], &Compression { max_error_dn: 0, bits_per_sample: target }, &control)
            .unwrap();
        assert!(r.max_error_dn >= 1 && r.bits_per_sample <= target + 0.05, "{r:?}");
        // One less and the rate is above the target (on the whole image; the search sampled
        // every second row, so allow its 0.05 bit).
        let mut finer = original.clone();
        let below = Compression { max_error_dn: r.max_error_dn - 1, bits_per_sample: 0.0 };
        let f = compress(&mut finer, &[12; 4], &below, &control).unwrap();
        assert!(f.bits_per_sample > target - 0.05, "{f:?}");
    }
}
