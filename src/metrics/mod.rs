//! Validation metrics of a retrieved product against the truth (Seegers et al. 2018).
//!
//! In log space, over pixels where both the retrieval M and the truth O are positive and finite:
//!
//! MAE = 10^(mean |log10 M − log10 O|),  bias = 10^(mean (log10 M − log10 O)),
//!
//! so MAE = 1.14 reads "typically a factor 1.14 (14 %) off" and bias = 0.9 "10 % low on the
//! (geometric) average". Alongside: N (pixels compared), the share of pixels the retrieval
//! returned, linear RMSE, and R² of log10 M against log10 O (the squared Pearson correlation).
//! Pixels with a non-positive or failed retrieval are excluded and counted (`excluded`), never
//! turned into NaN; pixels without truth (land, or no bottom in a deep scene) are not candidates.
//!
//! ## References
//! - Seegers, B. N., Stumpf, R. P., Schaeffer, B. A., Loftin, K. A., Werdell, P. J. (2018)
//!   Performance metrics for the assessment of satellite data products: an ocean color case
//!   study. Opt. Express 26, 7404–7422.

use serde::Serialize;

/// The metrics of one product.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Metrics {
    /// Pixels compared (both positive and finite).
    pub n: usize,
    /// Candidate pixels (with a truth).
    pub candidates: usize,
    /// Candidates whose retrieval failed or was not positive (excluded from the statistics).
    pub excluded: usize,
    /// Share of candidates returned, %.
    pub returned_pct: f64,
    /// 10^mean|log10 M − log10 O| (≥ 1; `mae_pct` = 100·(MAE − 1)).
    pub mae: f64,
    /// 10^mean(log10 M − log10 O).
    pub bias: f64,
    /// Linear root-mean-square error, product units.
    pub rmse: f64,
    /// Mean absolute error mean|M − O|, product units (a depth error in metres).
    pub mean_abs_error: f64,
    /// Mean error mean(M − O), product units (signed: positive when retrieved too high).
    pub mean_error: f64,
    /// Coefficient of determination of log10 M against log10 O (squared Pearson correlation).
    pub r2: f64,
}

impl Metrics {
    /// MAE as a percentage: 14 means "a factor 1.14".
    #[must_use]
    pub fn mae_pct(&self) -> f64 {
        100.0 * (self.mae - 1.0)
    }

    /// Bias as a signed percentage.
    #[must_use]
    pub fn bias_pct(&self) -> f64 {
        100.0 * (self.bias - 1.0)
    }
}

/// The unit of a metrics variable, for people (`depth_m` → "m").
#[must_use]
pub fn unit(variable: &str) -> &'static str {
    // `depth_m_bottom_visible` and `depth_m_over_sand` are depths.
    let key = if variable.starts_with(crate::variable::key::DEPTH) { crate::variable::key::DEPTH } else { variable };
    crate::variable::of(key).map_or("", |v| v.unit)
}

/// The name of a metrics variable, for people (`chl_mg_m3` → "chl-a"); substrate shares and
/// unknown names are returned as they are.
#[must_use]
pub fn name(variable: &str) -> &str {
    match variable {
        "depth_m_bottom_visible" => "depth, bottom visible",
        v => crate::variable::of(v).map_or(v, |v| v.name),
    }
}

/// The name and unit of a metrics variable, for axis titles and table rows: "chl-a (mg m⁻³)".
#[must_use]
pub fn label(variable: &str) -> String {
    match unit(variable) {
        "" => name(variable).to_string(),
        u => format!("{} ({u})", name(variable)),
    }
}

/// Metrics of `retrieved` against `truth`; `None` entries of `retrieved` are failed retrievals,
/// and `None` entries of `truth` are not candidates.
#[must_use]
pub fn compare(retrieved: &[Option<f64>], truth: &[Option<f64>]) -> Metrics {
    let mut sums = Sums::default();
    for (m, o) in retrieved.iter().zip(truth) {
        sums.add(*m, *o);
    }
    sums.metrics()
}

/// The running sums behind [`Metrics`]: [`compare`] adds pixels one by one, [`evaluate`] adds
/// them in blocks of rows on several threads and merges the blocks in order.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Sums {
    n: usize,
    candidates: usize,
    s_abs: f64,
    s_dif: f64,
    s_sq: f64,
    s_lin_abs: f64,
    s_lin: f64,
    sx: f64,
    sy: f64,
    sxx: f64,
    syy: f64,
    sxy: f64,
}

impl Sums {
    /// Add one pixel: retrieval `m` (`None`: failed) against truth `o` (`None`: no truth).
    #[inline]
    pub(crate) fn add(&mut self, m: Option<f64>, o: Option<f64>) {
        let Some(o) = o.filter(|o| o.is_finite() && *o > 0.0) else { return };
        self.candidates += 1;
        let Some(m) = m.filter(|m| m.is_finite() && *m > 0.0) else { return };
        self.n += 1;
        let (lm, lo) = (m.log10(), o.log10());
        self.s_abs += (lm - lo).abs();
        self.s_dif += lm - lo;
        self.s_sq += (m - o) * (m - o);
        self.s_lin_abs += (m - o).abs();
        self.s_lin += m - o;
        self.sx += lo;
        self.sy += lm;
        self.sxx += lo * lo;
        self.syy += lm * lm;
        self.sxy += lo * lm;
    }

    /// Add another block's sums to these.
    pub(crate) fn merge(&mut self, b: &Self) {
        self.n += b.n;
        self.candidates += b.candidates;
        self.s_abs += b.s_abs;
        self.s_dif += b.s_dif;
        self.s_sq += b.s_sq;
        self.s_lin_abs += b.s_lin_abs;
        self.s_lin += b.s_lin;
        self.sx += b.sx;
        self.sy += b.sy;
        self.sxx += b.sxx;
        self.syy += b.syy;
        self.sxy += b.sxy;
    }

    /// The metrics of the pixels added so far.
    pub(crate) fn metrics(&self) -> Metrics {
        let Self { n, candidates, s_abs, s_dif, s_sq, s_lin_abs, s_lin, sx, sy, sxx, syy, sxy } = *self;
        let nf = n as f64;
        let r2 = if n > 1 {
            let cov = sxy - sx * sy / nf;
            let (vx, vy) = (sxx - sx * sx / nf, syy - sy * sy / nf);
            if vx > 0.0 && vy > 0.0 { (cov * cov / (vx * vy)).clamp(0.0, 1.0) } else { 0.0 }
        } else {
            0.0
        };
        Metrics {
            n,
            candidates,
            excluded: candidates - n,
            returned_pct: if candidates > 0 { 100.0 * nf / candidates as f64 } else { 0.0 },
            mae: if n > 0 { 10f64.powf(s_abs / nf) } else { 1.0 },
            bias: if n > 0 { 10f64.powf(s_dif / nf) } else { 1.0 },
            rmse: if n > 0 { (s_sq / nf).sqrt() } else { 0.0 },
            mean_abs_error: if n > 0 { s_lin_abs / nf } else { 0.0 },
            mean_error: if n > 0 { s_lin / nf } else { 0.0 },
            r2,
        }
    }
}

/// The value at index round((n − 1)·`p`) of `v` sorted (nearest rank), NaN when `v` is empty;
/// found in linear time (`select_nth_unstable`: the element a sort would put there, so the same
/// value as sorting), `v` reordered.
pub fn nearest_rank(v: &mut [f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let k = ((v.len() - 1) as f64 * p).round() as usize;
    *v.select_nth_unstable_by(k.min(v.len() - 1), f64::total_cmp).1
}

/// A histogram over fixed bins (log10 or linear edges).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Histogram {
    /// Bin edges (one more than the counts).
    pub edges: Vec<f64>,
    /// Counts per bin (values outside the edges are not counted).
    pub counts: Vec<usize>,
}

/// `bins` logarithmically spaced edges spanning `lo`–`hi` (both > 0).
#[must_use]
pub fn log_edges(lo: f64, hi: f64, bins: usize) -> Vec<f64> {
    let (a, b) = (lo.max(f64::MIN_POSITIVE).log10(), hi.max(lo * 1.0001).log10());
    (0..=bins).map(|i| 10f64.powf(a + (b - a) * i as f64 / bins.max(1) as f64)).collect()
}

/// Bin index of `v` among `edges` (increasing), if inside.
#[must_use]
pub fn bin_of(edges: &[f64], v: f64) -> Option<usize> {
    if !(v.is_finite() && v >= edges[0] && v <= edges[edges.len() - 1]) {
        return None;
    }
    Some(edges.partition_point(|&e| e <= v).saturating_sub(1).min(edges.len() - 2))
}

/// Histogram of the finite values of `values` over `edges`.
#[must_use]
pub fn histogram(values: impl IntoIterator<Item = f64>, edges: &[f64]) -> Histogram {
    let mut counts = vec![0; edges.len().saturating_sub(1)];
    for v in values {
        if let Some(b) = bin_of(edges, v) {
            counts[b] += 1;
        }
    }
    Histogram { edges: edges.to_vec(), counts }
}

/// 2-D histogram (truth on x, retrieval on y) over the same edges on both axes: `counts[y][x]`.
#[must_use]
pub fn histogram_2d(pairs: impl IntoIterator<Item = (f64, f64)>, edges: &[f64]) -> Vec<Vec<usize>> {
    let n = edges.len().saturating_sub(1);
    let mut counts = vec![vec![0; n]; n];
    for (x, y) in pairs {
        if let (Some(i), Some(j)) = (bin_of(edges, x), bin_of(edges, y)) {
            counts[j][i] += 1;
        }
    }
    counts
}

/// The metrics of one variable of a product.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VariableMetrics {
    /// Variable name with its unit (`chl_mg_m3`).
    pub variable: String,
    /// The metrics.
    pub metrics: Metrics,
}

/// A confusion table of dominant substrates: `counts[t][r]` returned water pixels whose true
/// dominant substrate is `classes[t]` and whose retrieved one is `classes[r]`. Classes by name,
/// the truth's first, then any the retrieval knows and the scene does not.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Confusion {
    /// Class names.
    pub classes: Vec<String>,
    /// Counts, (true class, retrieved class).
    pub counts: Vec<Vec<usize>>,
}

impl Confusion {
    /// Share of counted pixels on the diagonal, %.
    #[must_use]
    pub fn accuracy_pct(&self) -> Option<f64> {
        let total: usize = self.counts.iter().flatten().sum();
        let right: usize = (0..self.classes.len()).map(|i| self.counts[i][i]).sum();
        (total > 0).then(|| 100.0 * right as f64 / total as f64)
    }

    /// Of the pixels truly of class `t`, the share retrieved as `t` (the producer's accuracy), %.
    #[must_use]
    pub fn recall_pct(&self, t: usize) -> Option<f64> {
        let row: usize = self.counts.get(t)?.iter().sum();
        (row > 0).then(|| 100.0 * self.counts[t][t] as f64 / row as f64)
    }
}

/// Everything a study reports about one product.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProductMetrics {
    /// Product name (aLMI, SAMBUCA).
    pub product: String,
    /// Per variable.
    pub variables: Vec<VariableMetrics>,
    /// SAMBUCA: % of returned shallow pixels whose dominant substrate is the true dominant one.
    pub substrate_agreement_pct: Option<f64>,
    /// SAMBUCA: true against retrieved dominant substrate over the returned water pixels.
    pub substrate_confusion: Option<Confusion>,
    /// SAMBUCA: depth metrics over the pixels where each substrate truly dominates (where a
    /// substrate the retrieval does not know biases the depth, this shows it).
    pub depth_by_true_substrate: Vec<VariableMetrics>,
    /// aLMI: how many pixels chose each SIOP set.
    pub siop_set_counts: Vec<usize>,
    /// aLMI: how many distinct SIOP sets were chosen.
    pub siop_sets_used: usize,
    /// Water pixels the retrieval did not return (failed).
    pub failed: usize,
    /// SAMBUCA reference mode: water pixels whose kept fit stalled (success reported with the
    /// depth still at its start).
    pub stalled: usize,
}

impl ProductMetrics {
    /// Metrics of `variable`, if the product has it.
    #[must_use]
    pub fn get(&self, variable: &str) -> Option<&Metrics> {
        self.variables.iter().find(|v| v.variable == variable).map(|v| &v.metrics)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_is_the_sorted_value_at_that_rank() {
        let mut v: Vec<f64> = (0..1001).map(|i| f64::from((i * 7919) % 1001) * 0.5).collect();
        let mut sorted = v.clone();
        sorted.sort_by(f64::total_cmp);
        for p in [0.0, 0.05, 0.5, 0.95, 1.0] {
            let want = sorted[((sorted.len() - 1) as f64 * p).round() as usize];
            assert_eq!(nearest_rank(&mut v, p).to_bits(), want.to_bits(), "p = {p}");
        }
        assert!(nearest_rank(&mut [], 0.5).is_nan());
    }

    #[test]
    fn a_confusion_table_gives_accuracy_and_recall() {
        let c = Confusion { classes: vec!["sand".into(), "coral".into()], counts: vec![vec![8, 2], vec![1, 9]] };
        assert_eq!(c.accuracy_pct(), Some(85.0));
        assert_eq!((c.recall_pct(0), c.recall_pct(1)), (Some(80.0), Some(90.0)));
        let empty = Confusion { classes: vec!["sand".into()], counts: vec![vec![0]] };
        assert_eq!((empty.accuracy_pct(), empty.recall_pct(0), empty.recall_pct(5)), (None, None, None));
    }

    #[test]
    fn a_constant_factor_gives_mae_and_bias_of_that_factor() {
        let truth: Vec<Option<f64>> = (1..=100).map(|i| Some(f64::from(i))).collect();
        let high: Vec<Option<f64>> = truth.iter().map(|t| t.map(|v| 1.2 * v)).collect();
        let m = compare(&high, &truth);
        assert!((m.mae - 1.2).abs() < 1e-12 && (m.bias - 1.2).abs() < 1e-12);
        assert!((m.mae_pct() - 20.0).abs() < 1e-9);
        assert!((m.r2 - 1.0).abs() < 1e-12);
        // Half high, half low by the same factor: MAE 1.2, bias 1.
        let mixed: Vec<Option<f64>> =
            truth.iter().enumerate().map(|(i, t)| t.map(|v| if i % 2 == 0 { 1.2 * v } else { v / 1.2 })).collect();
        let m = compare(&mixed, &truth);
        assert!((m.mae - 1.2).abs() < 1e-12 && (m.bias - 1.0).abs() < 1e-12);
    }

    #[test]
    fn failed_and_non_positive_retrievals_are_excluded_and_counted() {
        let truth = vec![Some(1.0), Some(2.0), Some(3.0), None, Some(4.0)];
        let got = vec![Some(1.0), None, Some(-1.0), Some(5.0), Some(f64::NAN)];
        let m = compare(&got, &truth);
        assert_eq!((m.n, m.candidates, m.excluded), (1, 4, 3));
        assert!((m.returned_pct - 25.0).abs() < 1e-12);
        assert!(m.mae.is_finite() && m.rmse.is_finite() && m.r2.is_finite());
        // Errors in product units: retrieved 1.1 and 1.8 against 1 and 2 (the fourth pixel failed):
        // mean |M − O| = (0.1 + 0.2)/2 = 0.15, mean (M − O) = (0.1 − 0.2)/2 = −0.05.
        let m = compare(&[Some(1.1), Some(1.8), None], &[Some(1.0), Some(2.0), Some(3.0)]);
        assert!((m.mean_abs_error - 0.15).abs() < 1e-12 && (m.mean_error + 0.05).abs() < 1e-12, "{m:?}");
        assert_eq!((unit("depth_m"), unit("depth_m_bottom_visible"), unit("chl_mg_m3")), ("m", "m", "mg m⁻³"));
        assert_eq!((label("chl_mg_m3").as_str(), label("sand_fraction").as_str()), ("chl-a (mg m⁻³)", "sand_fraction"));
        // Nothing returned: finite numbers, zero returned.
        let m = compare(&[None, None], &[Some(1.0), Some(2.0)]);
        assert_eq!(m.n, 0);
        assert!(m.mae.is_finite() && m.bias.is_finite());
    }

    #[test]
    fn histograms_bin_inclusively() {
        let e = log_edges(1.0, 100.0, 2);
        assert!((e[1] - 10.0).abs() < 1e-9);
        let h = histogram([1.0, 5.0, 10.0, 99.0, 100.0, 1000.0, f64::NAN], &e);
        assert_eq!(h.counts, vec![2, 3]);
        let h2 = histogram_2d([(2.0, 50.0), (50.0, 50.0)], &e);
        assert_eq!(h2, vec![vec![0, 0], vec![1, 1]]);
    }
}
