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

use crate::instrument::Truth;
use crate::retrieval::{Product, ProductFlags};

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
    match variable {
        "chl_mg_m3" => "mg m⁻³",
        "nap_g_m3" => "g m⁻³",
        "cdom_per_m" => "m⁻¹",
        v if v.starts_with("depth_m") => "m",
        _ => "",
    }
}

/// The name of a metrics variable, for people (`chl_mg_m3` → "chl-a"); substrate shares and
/// unknown names are returned as they are.
#[must_use]
pub fn name(variable: &str) -> &str {
    match variable {
        "chl_mg_m3" => "chl-a",
        "nap_g_m3" => "NAP",
        "cdom_per_m" => "CDOM",
        "depth_m" => "depth",
        "depth_m_bottom_visible" => "depth where the bottom is visible",
        v => v,
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
    let mut n = 0usize;
    let mut candidates = 0usize;
    let (mut s_abs, mut s_dif, mut s_sq, mut s_lin_abs, mut s_lin) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (m, o) in retrieved.iter().zip(truth) {
        let Some(o) = o.filter(|o| o.is_finite() && *o > 0.0) else { continue };
        candidates += 1;
        let Some(m) = m.filter(|m| m.is_finite() && *m > 0.0) else { continue };
        n += 1;
        let (lm, lo) = (m.log10(), o.log10());
        s_abs += (lm - lo).abs();
        s_dif += lm - lo;
        s_sq += (m - o) * (m - o);
        s_lin_abs += (m - o).abs();
        s_lin += m - o;
        sx += lo;
        sy += lm;
        sxx += lo * lo;
        syy += lm * lm;
        sxy += lo * lm;
    }
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

/// Score `product` against the `truth` under the same pixels.
#[must_use]
pub fn evaluate(product: &Product, truth: &Truth) -> ProductMetrics {
    let (rows, cols) = product.flags.dim();
    let water: Vec<(usize, usize)> =
        (0..rows).flat_map(|r| (0..cols).map(move |c| (r, c))).filter(|&(r, c)| truth.land[[r, c]] == 0).collect();
    let got = |map: &ndarray::Array2<f32>, keep: &dyn Fn(usize, usize) -> bool| -> Vec<Option<f64>> {
        water
            .iter()
            .filter(|&&(r, c)| keep(r, c))
            .map(|&(r, c)| product.returned(r, c).then(|| f64::from(map[[r, c]])))
            .collect()
    };
    let want = |map: &ndarray::Array2<f32>, keep: &dyn Fn(usize, usize) -> bool| -> Vec<Option<f64>> {
        water.iter().filter(|&&(r, c)| keep(r, c)).map(|&(r, c)| Some(f64::from(map[[r, c]]))).collect()
    };
    let all = |_: usize, _: usize| true;
    let mut variables = vec![
        VariableMetrics {
            variable: "chl_mg_m3".into(),
            metrics: compare(&got(&product.chl_mg_m3, &all), &want(&truth.chl_mg_m3, &all)),
        },
        VariableMetrics {
            variable: "nap_g_m3".into(),
            metrics: compare(&got(&product.nap_g_m3, &all), &want(&truth.nap_g_m3, &all)),
        },
        VariableMetrics {
            variable: "cdom_per_m".into(),
            metrics: compare(&got(&product.cdom_per_m, &all), &want(&truth.cdom_per_m, &all)),
        },
    ];
    let mut substrate_agreement_pct = None;
    let mut substrate_confusion = None;
    let mut depth_by_true_substrate = Vec::new();
    if let (Some(depth), Some(true_depth)) = (&product.depth_m, &truth.depth_m) {
        if let Some(tf) = &truth.substrate_fractions {
            let n = tf.dim().2;
            let dominant =
                |r: usize, c: usize| (0..n).max_by(|&i, &j| tf[[r, c, i]].total_cmp(&tf[[r, c, j]])).unwrap_or(0);
            for (s, name) in truth.substrate_names.iter().enumerate().take(n) {
                let here = |r: usize, c: usize| dominant(r, c) == s;
                depth_by_true_substrate.push(VariableMetrics {
                    variable: format!("depth_m_over_{name}"),
                    metrics: compare(&got(depth, &here), &want(true_depth, &here)),
                });
            }
        }
        variables.push(VariableMetrics {
            variable: "depth_m".into(),
            metrics: compare(&got(depth, &all), &want(true_depth, &all)),
        });
        let visible = |r: usize, c: usize| product.flags[[r, c]] & ProductFlags::BOTTOM_VISIBLE != 0;
        variables.push(VariableMetrics {
            variable: "depth_m_bottom_visible".into(),
            metrics: compare(&got(depth, &visible), &want(true_depth, &visible)),
        });
        if let (Some(f), Some(tf)) = (&product.substrate_fractions, &truth.substrate_fractions) {
            // Compared by name: the retrieval's library need not be the scene's.
            let dominant = |a: &ndarray::Array3<f32>, names: &[String], r: usize, c: usize| -> Option<String> {
                (0..names.len().min(a.dim().2))
                    .max_by(|&i, &j| a[[r, c, i]].total_cmp(&a[[r, c, j]]))
                    .map(|i| names[i].clone())
            };
            let returned: Vec<&(usize, usize)> = water.iter().filter(|&&(r, c)| product.returned(r, c)).collect();
            let mut classes = truth.substrate_names.clone();
            for n in &product.substrate_names {
                if !classes.contains(n) {
                    classes.push(n.clone());
                }
            }
            let mut counts = vec![vec![0usize; classes.len()]; classes.len()];
            let index = |name: Option<String>| name.and_then(|n| classes.iter().position(|c| *c == n));
            for &&(r, c) in &returned {
                let t = index(dominant(tf, &truth.substrate_names, r, c));
                let g = index(dominant(f, &product.substrate_names, r, c));
                if let (Some(t), Some(g)) = (t, g) {
                    counts[t][g] += 1;
                }
            }
            let confusion = Confusion { classes, counts };
            // Agreement over every returned pixel (a pixel without a dominant class disagrees).
            if !returned.is_empty() {
                let right: usize = (0..confusion.classes.len()).map(|i| confusion.counts[i][i]).sum();
                substrate_agreement_pct = Some(100.0 * right as f64 / returned.len() as f64);
            }
            substrate_confusion = Some(confusion);
        }
    }
    let mut siop_set_counts = vec![0; product.siop_set_names.len()];
    if product.siop_set.is_none() && siop_set_counts.len() == 1 {
        // One set (SAMBUCA): every returned pixel used it.
        siop_set_counts[0] = water.iter().filter(|&&(r, c)| product.returned(r, c)).count();
    }
    if let Some(sets) = &product.siop_set {
        for &(r, c) in &water {
            if let Ok(i) = usize::try_from(sets[[r, c]])
                && product.returned(r, c)
                && i < siop_set_counts.len()
            {
                siop_set_counts[i] += 1;
            }
        }
    }
    ProductMetrics {
        product: product.name.clone(),
        variables,
        substrate_agreement_pct,
        substrate_confusion,
        depth_by_true_substrate,
        siop_sets_used: siop_set_counts.iter().filter(|&&n| n > 0).count(),
        siop_set_counts,
        failed: water.iter().filter(|&&(r, c)| product.flags[[r, c]] & ProductFlags::FAILED != 0).count(),
        stalled: water.iter().filter(|&&(r, c)| product.flags[[r, c]] & ProductFlags::STALLED != 0).count(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
