//! The histogram and scatter data of the product on display, computed on the raster thread
//! beside the maps, once per (results, variable): a frame only draws them.
//!
//! Histograms count every water pixel (the truth) and every returned pixel (A, B) over one
//! shared set of log10 bins spanning the central 99 % of the values (the rest in the end bins); the scatter plots a strided sample of at most [`SCATTER_POINTS`]
//! pixels per instrument (enough to show the cloud; egui draws each point every frame).

use std::sync::Arc;

use crate::engine::RunOutput;

/// Bins of the histograms.
pub const BINS: usize = 30;
/// Scatter points per instrument, at most.
pub const SCATTER_POINTS: usize = 4000;

/// What the histogram and scatter plots draw.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlotData {
    /// The variable (`chl_mg_m3`).
    pub variable: String,
    /// Bin edges in log10 of the value, `BINS + 1` of them (empty when there is nothing to bin).
    pub edges_log10: Vec<f64>,
    /// Truth counts per bin (every water pixel of the first run with a truth value).
    pub truth: Vec<usize>,
    /// A's and B's counts per bin (returned pixels).
    pub counts: [Vec<usize>; 2],
    /// A's and B's (log10 truth, log10 retrieved) samples.
    pub scatter: [Vec<[f64; 2]>; 2],
}

/// Water pixels with a positive truth and, for the retrieval, a returned positive value:
/// (truth, retrieved or `None`) per pixel, visiting every `step`-th pixel.
fn values(out: &RunOutput, variable: &str, step: usize) -> Vec<(f64, Option<f64>)> {
    let truth = &out.radiance.truth;
    let Some(t) = truth.map(variable) else { return Vec::new() };
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

/// The histogram's log10 range: the 0.5th to 99.5th percentile of the truth and retrieved values
/// (from a strided sample of at most 20 000), so that a few wild retrievals (1e-8 mg m⁻³) do not
/// squeeze the distribution into two bins; values outside fall into the end bins. The full range
/// when the percentiles coincide.
fn bin_range(all: &[Vec<(f64, Option<f64>)>]) -> (f64, f64) {
    let values = || all.iter().flatten().flat_map(|(t, g)| std::iter::once(*t).chain(*g)).map(f64::log10);
    let n = values().count();
    let mut sample: Vec<f64> = values().step_by(n / 20_000 + 1).collect();
    if sample.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    sample.sort_by(f64::total_cmp);
    let at = |q: f64| sample[((sample.len() - 1) as f64 * q).round() as usize];
    let (lo, hi) = (at(0.005), at(0.995));
    if hi > lo { (lo, hi) } else { values().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v))) }
}

/// The plot data of `variable` for A's and B's runs.
#[must_use]
pub fn plot_data(runs: &[Option<Arc<RunOutput>>; 2], variable: &str) -> PlotData {
    let all: Vec<Vec<(f64, Option<f64>)>> =
        runs.iter().map(|r| r.as_ref().map(|o| values(o, variable, 1)).unwrap_or_default()).collect();
    let (lo, hi) = bin_range(&all);
    let mut out = PlotData { variable: variable.to_string(), ..PlotData::default() };
    for (k, r) in runs.iter().enumerate() {
        if let Some(o) = r {
            let n = o.radiance.truth.land.len();
            out.scatter[k] = values(o, variable, n / SCATTER_POINTS + 1)
                .into_iter()
                .filter_map(|(t, g)| g.map(|g| [t.log10(), g.log10()]))
                .collect();
        }
    }
    if !(lo.is_finite() && hi > lo) {
        return out;
    }
    let width = (hi - lo) / BINS as f64;
    out.edges_log10 = (0..=BINS).map(|b| lo + width * b as f64).collect();
    // Clamped: values beyond the range count in the end bins.
    let bin = |v: f64| (((v.log10() - lo) / width).max(0.0) as usize).min(BINS - 1);
    let first_with_truth = all.iter().position(|v| !v.is_empty());
    out.truth = vec![0; BINS];
    if let Some(f) = first_with_truth {
        for (t, _) in &all[f] {
            out.truth[bin(*t)] += 1;
        }
    }
    for (k, v) in all.iter().enumerate() {
        out.counts[k] = vec![0; BINS];
        for g in v.iter().filter_map(|(_, g)| *g) {
            out.counts[k][bin(g)] += 1;
        }
    }
    out
}
