//! The histogram and scatter data of the product on display, computed on the raster thread
//! beside the maps, once per (results, variable): a frame only draws them.
//!
//! Histograms count every water pixel (the truth) and every returned pixel (each design) over one
//! shared set of log10 bins spanning the central 99 % of the values (the rest in the end bins);
//! the scatter plots a strided sample of at most [`SCATTER_POINTS`] pixels per design
//! (enough to show the cloud; egui draws each point every frame). Each run's share
//! ([`RunValues`]) is computed once and kept, so moving a slider of A does not revisit B's
//! full-resolution pixels.

use std::sync::Arc;

use crate::colormap::kth_smallest;
use crate::engine::RunOutput;

/// Bins of the histograms.
pub const BINS: usize = 30;
/// Scatter points per instrument, at most.
pub const SCATTER_POINTS: usize = 4000;

/// What the histogram and scatter plots draw. The histograms are drawn as shares of each run's
/// water pixels ([`PlotData::percent`]): A at a 1/24 preview beside B at full resolution has
/// ~600 times fewer pixels, and as counts its bars would not show.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlotData {
    /// The variable (`chl_mg_m3`).
    pub variable: String,
    /// Bin edges in log10 of the value, `BINS + 1` of them (empty when there is nothing to bin).
    pub edges_log10: Vec<f64>,
    /// Truth counts per bin (every water pixel of the first run with a truth value).
    pub truth: Vec<usize>,
    /// Each design's counts per bin (returned pixels), in the designs' order.
    pub counts: Vec<Vec<usize>>,
    /// Each design's water pixels with a positive truth: what its counts are shares of (a
    /// preview and a full-resolution run have very different numbers of pixels).
    pub pixels: Vec<usize>,
    /// The water pixels of the run the truth histogram comes from.
    pub truth_pixels: usize,
    /// Each design's (log10 truth, log10 retrieved) samples.
    pub scatter: Vec<Vec<[f64; 2]>>,
}

impl PlotData {
    /// `count` as a percentage of `pixels` (0 when there are none).
    #[must_use]
    pub fn percent(count: usize, pixels: usize) -> f64 {
        if pixels == 0 { 0.0 } else { 100.0 * count as f64 / pixels as f64 }
    }
}

/// Water pixels with a positive truth and, for the retrieval, a returned positive value:
/// (truth, retrieved or `None`) per pixel, visiting every `step`-th pixel.
fn values(out: &RunOutput, variable: &str, step: usize) -> Vec<(f64, Option<f64>)> {
    let truth = &out.truth;
    let Some(t) = out.truth_map(variable) else { return Vec::new() };
    let product = out.retrievals.first().map(|r| &r.product);
    let got = product.and_then(|p| p.map(variable));
    let cols = t.ncols().max(1);
    (0..t.len())
        .step_by(step.max(1))
        .map(|k| (k / cols, k % cols))
        .filter(|&(i, j)| truth.is_water(i, j) && t[[i, j]] > 0.0)
        .map(|(i, j)| {
            let retrieved = match (product, got) {
                (Some(p), Some(g)) if p.returned(i, j) && g[[i, j]] > 0.0 => Some(f64::from(g[[i, j]])),
                _ => None,
            };
            (f64::from(t[[i, j]]), retrieved)
        })
        .collect()
}

/// One run's share of the plots of a variable, computed once per run (a redraw after a change
/// of A reuses B's): the log10 truth of every water pixel with a positive truth and the log10
/// retrieval of every returned positive pixel, each sorted (so quantiles and bin counts of
/// several runs come from binary searches), and the scatter sample.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunValues {
    /// log10 truth, ascending.
    pub truth_log10: Vec<f64>,
    /// log10 retrieved, ascending.
    pub retrieved_log10: Vec<f64>,
    /// (log10 truth, log10 retrieved) of a strided sample of at most [`SCATTER_POINTS`] pixels.
    pub scatter: Vec<[f64; 2]>,
}

impl RunValues {
    /// The values of `variable` in `out`.
    #[must_use]
    pub fn of(out: &RunOutput, variable: &str) -> Self {
        let all = values(out, variable, 1);
        let mut truth_log10: Vec<f64> = all.iter().map(|(t, _)| t.log10()).collect();
        let mut retrieved_log10: Vec<f64> = all.iter().filter_map(|(_, g)| g.map(f64::log10)).collect();
        truth_log10.sort_unstable_by(f64::total_cmp);
        retrieved_log10.sort_unstable_by(f64::total_cmp);
        let n = out.truth.surface.codes().len();
        let scatter = values(out, variable, n / SCATTER_POINTS + 1)
            .into_iter()
            .filter_map(|(t, g)| g.map(|g| [t.log10(), g.log10()]))
            .collect();
        Self { truth_log10, retrieved_log10, scatter }
    }
}

/// The histogram's log10 range: the 0.5th to 99.5th percentile of the truth and retrieved values
/// of all runs, so that a few wild retrievals (1e-8 mg m⁻³) do not squeeze the distribution into
/// two bins; values outside fall into the end bins. The full range when the percentiles
/// coincide.
fn bin_range(sorted: &[&[f64]]) -> (f64, f64) {
    let n: usize = sorted.iter().map(|s| s.len()).sum();
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let at = |q: f64| kth_smallest(sorted, ((n - 1) as f64 * q).round() as usize).unwrap_or(f64::NAN);
    let (lo, hi) = (at(0.005), at(0.995));
    if hi > lo { (lo, hi) } else { (at(0.0), at(1.0)) }
}

/// The plot data of `variable` for the designs' runs.
#[must_use]
pub fn plot_data(runs: &[Option<Arc<RunOutput>>], variable: &str) -> PlotData {
    let values: Vec<Option<RunValues>> = runs.iter().map(|r| r.as_ref().map(|o| RunValues::of(o, variable))).collect();
    combine(variable, &values.iter().map(Option::as_ref).collect::<Vec<_>>())
}

/// The plot data of `variable` from the designs' [`RunValues`]: bins shared by all, counted by
/// binary search in the sorted values (the bin of a value is monotone in it).
#[must_use]
pub fn combine(variable: &str, runs: &[Option<&RunValues>]) -> PlotData {
    let n = runs.len();
    let mut out = PlotData {
        variable: variable.to_string(),
        counts: vec![Vec::new(); n],
        pixels: vec![0; n],
        scatter: vec![Vec::new(); n],
        ..PlotData::default()
    };
    for (k, r) in runs.iter().enumerate() {
        if let Some(r) = r {
            out.scatter[k].clone_from(&r.scatter);
            out.pixels[k] = r.truth_log10.len();
        }
    }
    let sorted: Vec<&[f64]> =
        runs.iter().flatten().flat_map(|r| [r.truth_log10.as_slice(), r.retrieved_log10.as_slice()]).collect();
    let (lo, hi) = bin_range(&sorted);
    if !(lo.is_finite() && hi > lo) {
        return out;
    }
    let width = (hi - lo) / BINS as f64;
    out.edges_log10 = (0..=BINS).map(|b| lo + width * b as f64).collect();
    // Clamped: values beyond the range count in the end bins.
    let bin = |x: f64| (((x - lo) / width).max(0.0) as usize).min(BINS - 1);
    let counts = |v: &[f64]| -> Vec<usize> {
        let ends: Vec<usize> = (1..=BINS).map(|b| v.partition_point(|x| bin(*x) < b)).collect();
        ends.iter().scan(0, |start, &end| Some(end - std::mem::replace(start, end))).collect()
    };
    // The truth of the first run that has one.
    if let Some(r) = runs.iter().flatten().find(|r| !r.truth_log10.is_empty()) {
        out.truth = counts(&r.truth_log10);
        out.truth_pixels = r.truth_log10.len();
    } else {
        out.truth = vec![0; BINS];
    }
    for (k, r) in runs.iter().enumerate() {
        out.counts[k] = r.map_or_else(|| vec![0; BINS], |r| counts(&r.retrieved_log10));
    }
    out
}
