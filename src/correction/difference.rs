//! Two Rrs products compared band by band over the pixels valid in both: what the
//! correction's diagnostics report (the approximation against the exact correction, the delivered
//! Rrs against the truth).

use ndarray::Array3;
use rayon::prelude::*;
use serde::Serialize;

use super::{Reflectance, slice};

/// Per-band comparison of two Rrs products over pixels valid in both (water, unflagged,
/// positive): median relative difference and mean relative difference (bias), both of `a`
/// against `b`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BandDifference {
    /// Band index.
    pub band: usize,
    /// Pixels compared.
    pub n: usize,
    /// Median |a − b|/b.
    pub median_abs_rel: f64,
    /// Mean (a − b)/b.
    pub mean_rel: f64,
    /// Largest |a − b|/b.
    pub max_abs_rel: f64,
}

/// A pixel's bands made on the fly: `f(pixel, values, flags)`.
pub type PixelBands<'a> = &'a (dyn Fn(usize, &mut [f32], &mut [u8]) + Sync);

/// Where the values compared come from: a cube, or each pixel's bands computed on the fly
/// (`f(pixel, values, flags)`), so that a product made only to be compared need not be held whole.
enum Source<'a> {
    Cube(&'a [f32], &'a [u8]),
    Pixels(PixelBands<'a>),
}

/// Compare `a` with the reference `b`, band by band.
#[must_use]
pub fn compare(a: &Reflectance, b: &Array3<f32>, b_flags: Option<&Array3<u8>>) -> Vec<BandDifference> {
    let (Ok(ar), Ok(af)) = (slice(&a.rrs), slice(&a.flags)) else { return Vec::new() };
    let Some(reference) = Reference::of(b, b_flags) else { return Vec::new() };
    compare_source(Source::Cube(ar, af), a.rrs.dim().2, reference)
}

/// [`compare`] with both `a` and the reference `b` made pixel by pixel (`pixels` of `nb` bands,
/// row-major): neither product is held whole.
#[must_use]
pub fn compare_both_pixels(a: PixelBands<'_>, b: PixelBands<'_>, pixels: usize, nb: usize) -> Vec<BandDifference> {
    compare_source(Source::Pixels(a), nb, Reference::Pixels(b, pixels))
}

/// The reference a comparison is against: a cube with its flags if any, or `pixels` pixels made
/// on the fly (with flags).
enum Reference<'a> {
    Cube(&'a [f32], Option<&'a [u8]>),
    Pixels(PixelBands<'a>, usize),
}

impl<'a> Reference<'a> {
    fn of(b: &'a Array3<f32>, b_flags: Option<&'a Array3<u8>>) -> Option<Self> {
        Some(Self::Cube(slice(b).ok()?, b_flags.and_then(|f| slice(f).ok())))
    }
}

fn compare_source(source: Source<'_>, nb: usize, reference: Reference<'_>) -> Vec<BandDifference> {
    let nb = nb.max(1);
    let pixels = match reference {
        Reference::Cube(br, _) => br.len() / nb,
        Reference::Pixels(_, pixels) => pixels,
    };
    // Count, sum and maximum over every pixel; the median from at most ~200 000 evenly strided
    // pixels per band (its sampling error is far below the differences it reports).
    let stride = (pixels / MEDIAN_SAMPLES).max(1);
    #[derive(Clone)]
    struct Acc {
        n: Vec<usize>,
        sum: Vec<f64>,
        max: Vec<f64>,
        sample: Vec<Vec<f64>>,
        /// A pixel's bands and flags as a [`Source::Pixels`] makes them (not combined), and as a
        /// [`Reference::Pixels`] does.
        values: Vec<f32>,
        flags: Vec<u8>,
        ref_values: Vec<f32>,
        ref_flags: Vec<u8>,
    }
    let scratch = usize::from(matches!(source, Source::Pixels(_))) * nb;
    let ref_scratch = usize::from(matches!(reference, Reference::Pixels(..))) * nb;
    let empty = || Acc {
        n: vec![0; nb],
        sum: vec![0.0; nb],
        max: vec![0.0; nb],
        sample: vec![Vec::new(); nb],
        values: vec![0.0; scratch],
        flags: vec![0; scratch],
        ref_values: vec![0.0; ref_scratch],
        ref_flags: vec![0; ref_scratch],
    };
    // Fixed blocks of pixels, summed in block order: the sums (of f64, whose rounding depends
    // on the order) are the same whatever the threads and however rayon splits the work (a
    // `fold` over the pixels split them where threads stole work, so the bias moved in its last
    // digits from run to run).
    let blocks: Vec<Acc> = (0..pixels.div_ceil(BLOCK_PIXELS))
        .into_par_iter()
        .map(|k| {
            let mut acc = empty();
            for p in k * BLOCK_PIXELS..((k + 1) * BLOCK_PIXELS).min(pixels) {
                // One pixel's bands as slices (no per-value bounds checks), and whether it is a
                // median sample decided once per pixel: the modulo per value was half the stage.
                let span = p * nb..(p + 1) * nb;
                let (a, a_flags) = match &source {
                    Source::Cube(ar, af) => (&ar[span.clone()], &af[span.clone()]),
                    Source::Pixels(f) => {
                        f(p, &mut acc.values, &mut acc.flags);
                        (&acc.values[..], &acc.flags[..])
                    }
                };
                let (b, b_flags) = match &reference {
                    Reference::Cube(br, bf) => (&br[span.clone()], bf.map(|f| &f[span])),
                    Reference::Pixels(f, _) => {
                        f(p, &mut acc.ref_values, &mut acc.ref_flags);
                        (&acc.ref_values[..], Some(&acc.ref_flags[..]))
                    }
                };
                let sampled = p % stride == 0;
                for band in 0..nb {
                    let fb = b_flags.map_or(0, |f| f[band]);
                    let (x, y) = (f64::from(a[band]), f64::from(b[band]));
                    if a_flags[band] == 0 && fb == 0 && y > 0.0 && x.is_finite() {
                        let rel = (x - y) / y;
                        acc.n[band] += 1;
                        acc.sum[band] += rel;
                        acc.max[band] = acc.max[band].max(rel.abs());
                        if sampled {
                            acc.sample[band].push(rel.abs());
                        }
                    }
                }
            }
            acc
        })
        .collect();
    // Band by band, each band's blocks merged in block order (so the same sums as one fold over
    // the blocks), the bands side by side: merged in one fold, then copied again for the
    // medians, the samples were 0.1 s of one core per run while the other waited (perf).
    (0..nb)
        .into_par_iter()
        .map(|band| {
            let n: usize = blocks.iter().map(|b| b.n[band]).sum();
            let sum = blocks.iter().fold(0.0, |s, b| s + b.sum[band]);
            let max_abs_rel = blocks.iter().fold(0.0f64, |m, b| m.max(b.max[band]));
            let mut sample = Vec::with_capacity(blocks.iter().map(|b| b.sample[band].len()).sum());
            blocks.iter().for_each(|b| sample.extend_from_slice(&b.sample[band]));
            let m = sample.len();
            BandDifference {
                band,
                n,
                median_abs_rel: if m > 0 { *sample.select_nth_unstable_by(m / 2, f64::total_cmp).1 } else { 0.0 },
                mean_rel: if n > 0 { sum / n as f64 } else { 0.0 },
                max_abs_rel,
            }
        })
        .collect()
}

/// Pixels per block of [`compare`]'s sums.
const BLOCK_PIXELS: usize = 4096;

/// Pixels per band the median of [`compare`] is taken from, at most.
pub(super) const MEDIAN_SAMPLES: usize = 200_000;

#[cfg(test)]
mod tests {
    use super::*;

    /// A 97 × 113 × 3 truth and a product unlike it (10 961 pixels: three blocks of 4 096).
    fn truth_and_product() -> (Array3<f32>, Array3<f32>) {
        let (rows, cols, nb) = (97, 113, 3);
        let value = |i: usize| 0.001 + 1e-5 * ((i * 7919) % 1013) as f32;
        let truth = Array3::from_shape_fn((rows, cols, nb), |(r, c, b)| value(r * 31 + c * 7 + b));
        let rrs = Array3::from_shape_fn((rows, cols, nb), |(r, c, b)| value(r * 17 + c * 13 + b * 5));
        (truth, rrs)
    }

    /// The sums are taken in fixed blocks: one thread and three give the same bits.
    #[test]
    fn the_comparison_does_not_depend_on_the_threads() {
        let (truth, rrs) = truth_and_product();
        let (rows, cols, _) = truth.dim();
        let mut flags = Array3::zeros(truth.dim());
        flags[[5, 6, 1]] = 1;
        let a = Reflectance { rrs, flags };
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| compare(&a, &truth, None))
        };
        let (one, three) = (on(1), on(3));
        assert_eq!(one, three);
        assert_eq!(one[1].n, rows * cols - 1, "the flagged value is left out");
        assert!(one.iter().all(|d| d.mean_rel.is_finite() && d.median_abs_rel > 0.0));
    }

    /// Merged band by band from blocks of 4 096 pixels (here three), each band's count, maximum and
    /// median are those of the whole image's pixels taken one by one, and its mean agrees to the
    /// rounding of 10⁴ additions (the blocks' sums are added in block order, not pixel by pixel).
    #[test]
    fn the_blocks_merge_to_the_whole_images_statistics() {
        let (truth, rrs) = truth_and_product();
        let (rows, cols, _) = truth.dim();
        let mut flags = Array3::zeros(truth.dim());
        flags[[50, 60, 2]] = 1;
        let got = compare(&Reflectance { rrs: rrs.clone(), flags: flags.clone() }, &truth, None);
        for (b, d) in got.iter().enumerate() {
            let mut rel: Vec<f64> = (0..rows * cols)
                .filter(|&p| flags[[p / cols, p % cols, b]] == 0)
                .map(|p| {
                    let (x, y) = (f64::from(rrs[[p / cols, p % cols, b]]), f64::from(truth[[p / cols, p % cols, b]]));
                    (x - y) / y
                })
                .collect();
            assert_eq!(d.n, rel.len());
            let mean = rel.iter().sum::<f64>() / rel.len() as f64;
            assert!((d.mean_rel - mean).abs() <= 1e-12 * mean.abs().max(1e-3), "band {b}: {} vs {mean}", d.mean_rel);
            rel.iter_mut().for_each(|v| *v = v.abs());
            assert_eq!(d.max_abs_rel, rel.iter().copied().fold(0.0, f64::max));
            rel.sort_by(f64::total_cmp);
            assert_eq!(d.median_abs_rel, rel[rel.len() / 2], "band {b}");
        }
    }
}
