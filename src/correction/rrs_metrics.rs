//! The corrected Rrs against the truth per band, in log space (Seegers et al. 2018, as
//! ACIX-Aqua reports an atmospheric correction: Pahlevan et al. 2021), and pooled over a band
//! range.

use ndarray::Array3;
use rayon::prelude::*;
use serde::Serialize;

use super::difference::{BandDifference, MEDIAN_SAMPLES};
use super::{Reflectance, RrsFlags};
use crate::instrument::SurfaceMap;

/// One band's corrected Rrs against the truth: log-space metrics (Seegers et al. 2018, as
/// ACIX-Aqua reports Rrs: Pahlevan et al. 2021) over the water pixels.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BandRrsMetrics {
    /// Band name.
    pub band: String,
    /// Band centre, nm.
    pub centre_nm: f64,
    /// The metrics; a flagged or non-positive Rrs is a pixel not returned.
    pub metrics: crate::metrics::Metrics,
}

/// The corrected Rrs's log-space error (Seegers et al. 2018, as ACIX-Aqua reports Rrs:
/// Pahlevan et al. 2021) over every band centred in `lo_nm`–`hi_nm`, pooled from the run's
/// per-band metrics: the pooled mean of |log10 ratio| is the per-band means weighted by their
/// pixels, so MAE = 10^(Σ n_b·log10 MAE_b / Σ n_b), and the bias alike. (MAE %, bias %,
/// returned %, pixels); `None` without such a band or pixel.
#[must_use]
pub fn pooled_rrs_error(bands: &[BandRrsMetrics], lo_nm: f64, hi_nm: f64) -> Option<(f64, f64, f64, usize)> {
    let judged: Vec<&crate::metrics::Metrics> =
        bands.iter().filter(|b| (lo_nm..=hi_nm).contains(&b.centre_nm)).map(|b| &b.metrics).collect();
    let n: usize = judged.iter().map(|m| m.n).sum();
    let candidates: usize = judged.iter().map(|m| m.candidates).sum();
    if n == 0 {
        return None;
    }
    let mean_log = |f: fn(&crate::metrics::Metrics) -> f64| {
        judged.iter().map(|m| m.n as f64 * f(m).log10()).sum::<f64>() / n as f64
    };
    let mae = 10f64.powf(mean_log(|m| m.mae));
    let bias = 10f64.powf(mean_log(|m| m.bias));
    Some((100.0 * (mae - 1.0), 100.0 * (bias - 1.0), 100.0 * n as f64 / candidates.max(1) as f64, n))
}

/// The true Rrs at the pixels the correction's comparisons with the truth read, taken from the
/// true Rrs cube while the run has it: every ⌊n/[`RRS_SAMPLES`]⌋-th of the n water pixels
/// ([`band_rrs_metrics`]) and every ⌊N/[`MEDIAN_SAMPLES`]⌋-th of the image's N pixels
/// ([`compare_with_truth`]). Between [`RRS_SAMPLES`] and [`MEDIAN_SAMPLES`] pixels and twice as
/// many, whatever the image's size: a run that keeps no cubes lets the cube go once it has this
/// (the default study's CubeSat: 19 MB here against 156 MB for the cube).
#[derive(Debug, Clone, PartialEq)]
pub struct TruthRrsSample {
    /// The image's (rows, columns, bands).
    dim: (usize, usize, usize),
    /// The water pixels [`band_rrs_metrics`] reads (row-major indices) and their true Rrs
    /// (pixel, band).
    water: Vec<usize>,
    water_rrs: Vec<f32>,
    /// Every `stride`-th pixel's true Rrs (pixel, band).
    stride: usize,
    strided_rrs: Vec<f32>,
}

impl TruthRrsSample {
    /// The sample of `truth` over the water pixels of `surface`.
    #[must_use]
    pub fn of(truth: &Array3<f32>, surface: &SurfaceMap) -> Self {
        let (rows, cols, nb) = truth.dim();
        // Counted, then walked again: the water pixels' indices are not held (8 bytes a pixel).
        let all = || (0..rows * cols).filter(|&i| surface.is_water(i / cols, i % cols));
        let water: Vec<usize> = all().step_by((all().count() / RRS_SAMPLES).max(1)).collect();
        // A pixel's bands: a slice of the cube where it is laid out row-major (as every stage
        // makes it), copied whole; element by element otherwise.
        let flat = truth.as_slice();
        let take = |out: &mut Vec<f32>, i: usize| match flat {
            Some(f) => out.extend_from_slice(&f[i * nb..(i + 1) * nb]),
            None => out.extend((0..nb).map(|b| truth[[i / cols, i % cols, b]])),
        };
        let mut water_rrs = Vec::with_capacity(water.len() * nb);
        water.iter().for_each(|&i| take(&mut water_rrs, i));
        let stride = (rows * cols / MEDIAN_SAMPLES).max(1);
        let mut strided_rrs = Vec::with_capacity((rows * cols).div_ceil(stride) * nb);
        (0..rows * cols).step_by(stride).for_each(|i| take(&mut strided_rrs, i));
        Self { dim: (rows, cols, nb), water, water_rrs, stride, strided_rrs }
    }

    /// Bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        self.water.len() * std::mem::size_of::<usize>() + 4 * (self.water_rrs.len() + self.strided_rrs.len())
    }
}

/// Per band, `rrs` against the truth over the water pixels: every ⌊n/[`RRS_SAMPLES`]⌋-th of the
/// n water pixels ([`TruthRrsSample`]), so between [`RRS_SAMPLES`] and twice as many once n
/// exceeds it (the log-space MAE is a mean: over 20 000 pixels its standard error is under 1 % of
/// itself, 0.1 points at an MAE of 10 %; all of Lake Hume's 1.5 M pixels took 0.23 s per run),
/// one band per task. A pixel the correction flagged invalid or saturated (its radiance clipped)
/// is one not returned, as in [`super::compare`].
#[must_use]
pub fn band_rrs_metrics(
    rrs: &Reflectance,
    truth: &TruthRrsSample,
    names: &[String],
    centres_nm: &[f64],
) -> Vec<BandRrsMetrics> {
    let (_, cols, nb) = truth.dim;
    (0..nb)
        .into_par_iter()
        .map(|b| {
            let (mut got, mut want) = (Vec::new(), Vec::new());
            for (k, &i) in truth.water.iter().enumerate() {
                let (r, c) = (i / cols, i % cols);
                let ok = rrs.flags[[r, c, b]] & (RrsFlags::INVALID | RrsFlags::SATURATED) == 0;
                got.push(ok.then(|| f64::from(rrs.rrs[[r, c, b]])));
                want.push(Some(f64::from(truth.water_rrs[k * nb + b])));
            }
            BandRrsMetrics {
                band: names.get(b).cloned().unwrap_or_default(),
                centre_nm: centres_nm.get(b).copied().unwrap_or(f64::NAN),
                metrics: crate::metrics::compare(&got, &want),
            }
        })
        .collect()
}

/// `rrs` against the truth band by band, as [`super::compare`] reports two products, over every
/// ⌊N/[`MEDIAN_SAMPLES`]⌋-th of the image's N pixels ([`TruthRrsSample`]): every pixel of an
/// image of fewer than 2 × [`MEDIAN_SAMPLES`], where the two give the same numbers; over a larger
/// one the same median (`compare` takes it from these pixels), and the mean and the largest
/// difference of these pixels rather than of all. `compare`'s own loop over those pixels (its
/// fixed blocks: the threads do not change the sums); empty if `rrs` is not the sample's image.
#[must_use]
pub fn compare_with_truth(rrs: &Reflectance, truth: &TruthRrsSample) -> Vec<BandDifference> {
    let (Ok(values), Ok(flags)) = (super::slice(&rrs.rrs), super::slice(&rrs.flags)) else { return Vec::new() };
    if rrs.rrs.dim() != truth.dim {
        return Vec::new();
    }
    let nb = truth.dim.2.max(1);
    // The k-th pixel compared is pixel k·stride of the image, the k-th of the sample.
    let at = |k: usize| k * truth.stride * nb..(k * truth.stride + 1) * nb;
    let product = |k: usize, v: &mut [f32], f: &mut [u8]| {
        v.copy_from_slice(&values[at(k)]);
        f.copy_from_slice(&flags[at(k)]);
    };
    let reference = |k: usize, v: &mut [f32], f: &mut [u8]| {
        v.copy_from_slice(&truth.strided_rrs[k * nb..(k + 1) * nb]);
        f.fill(0);
    };
    super::difference::compare_both_pixels(&product, &reference, truth.strided_rrs.len() / nb, nb)
}

/// Water pixels per band [`band_rrs_metrics`] judges: at least this many where there are as many,
/// fewer than twice as many.
pub const RRS_SAMPLES: usize = 20_000;

#[cfg(test)]
mod tests {
    use super::*;

    /// A pixel whose radiance clipped (SATURATED) or that the correction left out (INVALID) is
    /// not returned: it does not enter n, only the candidates. Here the saturated pixel's Rrs is
    /// half the truth, which would have moved the MAE.
    #[test]
    fn saturated_and_invalid_pixels_are_not_returned() {
        let truth = Array3::from_elem((1, 4, 1), 0.01f32);
        let mut rrs = Reflectance { rrs: truth.clone(), flags: Array3::zeros((1, 4, 1)) };
        rrs.rrs[[0, 1, 0]] = 0.005;
        rrs.flags[[0, 1, 0]] = RrsFlags::SATURATED;
        rrs.flags[[0, 2, 0]] = RrsFlags::INVALID;
        let sample = TruthRrsSample::of(&truth, &SurfaceMap::all_water((1, 4)));
        let m = band_rrs_metrics(&rrs, &sample, &["b".into()], &[443.0]);
        let m = &m[0].metrics;
        assert_eq!((m.n, m.candidates), (2, 4));
        assert!((m.mae - 1.0).abs() < 1e-12 && (m.bias - 1.0).abs() < 1e-12, "{m:?}");
    }

    /// A product and a truth of `rows × cols × 3` with land, flags and a few non-positive truths.
    fn pair(rows: usize, cols: usize) -> (Reflectance, Array3<f32>, SurfaceMap) {
        let value = |i: usize| 0.001 + 1e-5 * ((i * 7919) % 1013) as f32;
        let mut truth = Array3::from_shape_fn((rows, cols, 3), |(r, c, b)| value(r * 31 + c * 7 + b));
        truth[[3, 4, 0]] = 0.0;
        let mut a = Reflectance {
            rrs: Array3::from_shape_fn((rows, cols, 3), |(r, c, b)| value(r * 17 + c * 13 + b * 5)),
            flags: Array3::zeros((rows, cols, 3)),
        };
        a.flags[[5, 6, 1]] = RrsFlags::INVALID;
        a.rrs[[7, 2, 2]] = f32::NAN;
        use crate::instrument::SurfaceClass::{Land, Water};
        let codes = ndarray::Array2::from_shape_fn((rows, cols), |(r, c)| {
            (if (r * 3 + c) % 11 == 0 { Land } else { Water }) as u8
        });
        let surface = SurfaceMap::from_codes(codes);
        (a, truth, surface)
    }

    /// The sample gives the metrics the truth cube gives: the same water pixels, every
    /// ⌊n/RRS_SAMPLES⌋-th, read from the cube directly here.
    #[test]
    fn the_sample_gives_the_metrics_of_the_cube() {
        let (a, truth, surface) = pair(300, 170);
        let sample = TruthRrsSample::of(&truth, &surface);
        let names: Vec<String> = ["a", "b", "c"].map(String::from).into();
        let got = band_rrs_metrics(&a, &sample, &names, &[443.0, 490.0, 560.0]);
        let water: Vec<(usize, usize)> =
            (0..300).flat_map(|r| (0..170).map(move |c| (r, c))).filter(|&(r, c)| surface.is_water(r, c)).collect();
        assert!(water.len() > RRS_SAMPLES, "the test samples: {} water pixels", water.len());
        for b in 0..3 {
            let picked = water.iter().step_by((water.len() / RRS_SAMPLES).max(1));
            let ok = |r: usize, c: usize| a.flags[[r, c, b]] & (RrsFlags::INVALID | RrsFlags::SATURATED) == 0;
            let from_cube: (Vec<_>, Vec<_>) = picked
                .map(|&(r, c)| (ok(r, c).then(|| f64::from(a.rrs[[r, c, b]])), Some(f64::from(truth[[r, c, b]]))))
                .unzip();
            assert_eq!(got[b].metrics, crate::metrics::compare(&from_cube.0, &from_cube.1), "band {b}");
        }
    }

    /// Under 2 × MEDIAN_SAMPLES pixels the comparison reads every pixel and gives `compare`'s
    /// numbers bit for bit; over it, `compare`'s median (from the same pixels) and the count, sum
    /// and largest difference of those pixels.
    #[test]
    fn the_comparison_with_the_sample_is_compare_over_its_pixels() {
        let (a, truth, surface) = pair(97, 113);
        let whole = super::super::compare(&a, &truth, None);
        assert_eq!(compare_with_truth(&a, &TruthRrsSample::of(&truth, &surface)), whole);
        assert_eq!(whole[1].n, 97 * 113 - 1, "the flagged value is left out");
        let (rows, cols) = (700, 600);
        let (a, truth, surface) = pair(rows, cols);
        let sample = TruthRrsSample::of(&truth, &surface);
        let stride = rows * cols / MEDIAN_SAMPLES;
        assert_eq!(stride, 2);
        let got = compare_with_truth(&a, &sample);
        let whole = super::super::compare(&a, &truth, None);
        for b in 0..3 {
            assert_eq!(got[b].median_abs_rel, whole[b].median_abs_rel, "band {b}");
            let strided = |r: usize, c: usize| (r * cols + c).is_multiple_of(stride);
            let valid =
                |r: usize, c: usize| a.flags[[r, c, b]] == 0 && truth[[r, c, b]] > 0.0 && a.rrs[[r, c, b]].is_finite();
            let n = (0..rows)
                .flat_map(|r| (0..cols).map(move |c| (r, c)))
                .filter(|&(r, c)| strided(r, c) && valid(r, c))
                .count();
            assert_eq!(got[b].n, n, "band {b}");
            assert!((got[b].mean_rel - whole[b].mean_rel).abs() < 0.05 * whole[b].mean_rel.abs().max(0.01), "band {b}");
            assert!(got[b].max_abs_rel <= whole[b].max_abs_rel, "band {b}");
        }
        // The threads do not change the numbers.
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| compare_with_truth(&a, &sample))
        };
        assert_eq!(on(1), on(3));
        // A sample of about MEDIAN_SAMPLES pixels of 3 bands, not the cube's 420 000.
        assert!(
            sample.bytes() < 4 * 3 * (MEDIAN_SAMPLES + 2 * RRS_SAMPLES) + 8 * 2 * RRS_SAMPLES,
            "{}",
            sample.bytes()
        );
    }
}
