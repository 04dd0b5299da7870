//! Scoring a retrieved product against the truth, pixel by pixel, in one pass over the scene.
//!
//! Every statistic of [`ProductMetrics`] is a sum or a count over the water pixels, so the scene
//! is cut into fixed blocks of rows, each block's sums are taken on whichever thread is free, and
//! the blocks are merged in row order. The blocks do not depend on the number of threads, so the
//! result does not either (the determinism tests run 1 and 2 threads). The sums are those of
//! [`crate::metrics::compare`], added in another order: the metrics agree with a one-pixel-at-a-time pass
//! to the last few bits of a double.
//! (It lives with the retrievals, not in `metrics`: it reads their products, and `metrics` sits
//! above the correction, which uses its statistics.)

use ndarray::Array2;
use rayon::prelude::*;

use super::{Product, ProductFlags};
use crate::instrument::Truth;
use crate::metrics::{Confusion, ProductMetrics, Sums, VariableMetrics};

/// Rows per block (about 50 k pixels at full resolution: enough work to hide the hand-over).
const ROWS_PER_BLOCK: usize = 32;

/// One block's sums and counts.
#[derive(Debug, Clone)]
struct Block {
    /// chl, NAP, CDOM over every water pixel.
    constituents: [Sums; 3],
    /// Depth over every water pixel, and where the retrieval says the bottom is visible.
    depth: Sums,
    depth_visible: Sums,
    /// Depth over the pixels where each substrate truly dominates.
    depth_by_true_substrate: Vec<Sums>,
    /// (true class, retrieved class) counts over the returned water pixels.
    confusion: Vec<Vec<usize>>,
    /// Returned water pixels.
    returned: usize,
    /// Returned water pixels per SIOP set.
    siop_set_counts: Vec<usize>,
    failed: usize,
    stalled: usize,
}

/// What the pass needs to know once, before it starts.
struct Plan<'a> {
    product: &'a Product,
    truth: &'a Truth,
    /// Product and true depth, when both exist.
    depth: Option<(&'a Array2<f32>, &'a Array2<f32>)>,
    /// Substrates whose depth metrics are reported (the truth's, at most its fraction layers).
    true_substrates: usize,
    /// The confusion table's classes; `None` unless both have substrate fractions.
    classes: Option<Classes>,
    siop_sets: usize,
}

/// The confusion table's classes (the truth's substrate names, then any only the retrieval
/// knows: compared by name, as the retrieval's library need not be the scene's).
struct Classes {
    names: Vec<String>,
    /// The class of each true substrate.
    of_true: Vec<Option<usize>>,
    /// The class of each retrieved substrate.
    of_retrieved: Vec<Option<usize>>,
}

/// The substrate with the largest fraction at (r, c) among the first `n` (the last of equals,
/// as `Iterator::max_by` picks).
#[must_use]
pub fn dominant(fractions: &ndarray::Array3<f32>, n: usize, r: usize, c: usize) -> Option<usize> {
    (0..n.min(fractions.dim().2)).max_by(|&i, &j| fractions[[r, c, i]].total_cmp(&fractions[[r, c, j]]))
}

impl Plan<'_> {
    fn empty_block(&self) -> Block {
        let n_classes = self.classes.as_ref().map_or(0, |c| c.names.len());
        Block {
            constituents: [Sums::default(); 3],
            depth: Sums::default(),
            depth_visible: Sums::default(),
            depth_by_true_substrate: vec![Sums::default(); self.true_substrates],
            confusion: vec![vec![0; n_classes]; n_classes],
            returned: 0,
            siop_set_counts: vec![0; self.siop_sets],
            failed: 0,
            stalled: 0,
        }
    }

    /// The sums of rows `rows`.
    fn block(&self, rows: std::ops::Range<usize>) -> Block {
        let (product, truth) = (self.product, self.truth);
        let cols = product.flags.dim().1;
        let mut b = self.empty_block();
        // A variable the product lacks (an external retrieval's choice) adds nothing.
        let maps = [
            (product.chl_mg_m3.as_ref(), &truth.chl_mg_m3),
            (product.nap_g_m3.as_ref(), &truth.nap_g_m3),
            (product.cdom_per_m.as_ref(), &truth.cdom_per_m),
        ];
        for r in rows {
            for c in 0..cols {
                if !truth.surface.is_water(r, c) {
                    continue;
                }
                let flags = product.flags[[r, c]];
                let returned = product.returned(r, c);
                let got = |map: &Array2<f32>| returned.then(|| f64::from(map[[r, c]]));
                for (sums, (m, o)) in b.constituents.iter_mut().zip(maps) {
                    if let Some(m) = m {
                        sums.add(got(m), Some(f64::from(o[[r, c]])));
                    }
                }
                if let Some((depth, true_depth)) = self.depth {
                    let (m, o) = (got(depth), Some(f64::from(true_depth[[r, c]])));
                    b.depth.add(m, o);
                    if flags & ProductFlags::BOTTOM_VISIBLE != 0 {
                        b.depth_visible.add(m, o);
                    }
                    if let Some(tf) = &truth.substrate_fractions
                        && self.true_substrates > 0
                    {
                        let s = dominant(tf, tf.dim().2, r, c).unwrap_or(0);
                        if let Some(sums) = b.depth_by_true_substrate.get_mut(s) {
                            sums.add(m, o);
                        }
                    }
                }
                b.failed += usize::from(flags & ProductFlags::FAILED != 0);
                b.stalled += usize::from(flags & ProductFlags::STALLED != 0);
                if !returned {
                    continue;
                }
                b.returned += 1;
                if let (Some(classes), Some(f), Some(tf)) =
                    (&self.classes, &product.substrate_fractions, &truth.substrate_fractions)
                {
                    let t = dominant(tf, truth.substrate_names.len(), r, c).and_then(|i| classes.of_true[i]);
                    let g = dominant(f, product.substrate_names.len(), r, c).and_then(|i| classes.of_retrieved[i]);
                    if let (Some(t), Some(g)) = (t, g) {
                        b.confusion[t][g] += 1;
                    }
                }
                if let Some(sets) = &product.siop_set
                    && let Ok(i) = usize::try_from(sets[[r, c]])
                    && let Some(n) = b.siop_set_counts.get_mut(i)
                {
                    *n += 1;
                }
            }
        }
        b
    }
}

impl Block {
    /// Add `other`'s sums and counts to these.
    fn merge(mut self, other: &Self) -> Self {
        for (a, b) in self.constituents.iter_mut().zip(&other.constituents) {
            a.merge(b);
        }
        self.depth.merge(&other.depth);
        self.depth_visible.merge(&other.depth_visible);
        for (a, b) in self.depth_by_true_substrate.iter_mut().zip(&other.depth_by_true_substrate) {
            a.merge(b);
        }
        for (a, b) in self.confusion.iter_mut().flatten().zip(other.confusion.iter().flatten()) {
            *a += b;
        }
        self.returned += other.returned;
        for (a, b) in self.siop_set_counts.iter_mut().zip(&other.siop_set_counts) {
            *a += b;
        }
        self.failed += other.failed;
        self.stalled += other.stalled;
        self
    }
}

/// Score `product` against the `truth` under the same pixels: the water pixels (not land), a
/// retrieval counted where it returned.
#[must_use]
pub fn evaluate(product: &Product, truth: &Truth) -> ProductMetrics {
    let rows = product.flags.dim().0;
    let depth = product.depth_m.as_ref().zip(truth.depth_m.as_ref());
    let classes = (product.substrate_fractions.is_some() && truth.substrate_fractions.is_some()).then(|| {
        let mut names = truth.substrate_names.clone();
        for n in &product.substrate_names {
            if !names.contains(n) {
                names.push(n.clone());
            }
        }
        let class_of =
            |of: &[String]| -> Vec<Option<usize>> { of.iter().map(|n| names.iter().position(|c| c == n)).collect() };
        let (of_true, of_retrieved) = (class_of(&truth.substrate_names), class_of(&product.substrate_names));
        Classes { names, of_true, of_retrieved }
    });
    let true_substrates = match (&depth, &truth.substrate_fractions) {
        (Some(_), Some(tf)) => truth.substrate_names.len().min(tf.dim().2),
        _ => 0,
    };
    let plan = Plan { product, truth, depth, true_substrates, classes, siop_sets: product.siop_set_names.len() };
    // One block a task (rayon would otherwise hand a thread runs of several blocks, and the
    // last run leave the other thread waiting).
    let blocks: Vec<Block> = (0..rows.div_ceil(ROWS_PER_BLOCK))
        .into_par_iter()
        .with_max_len(1)
        .map(|i| plan.block(i * ROWS_PER_BLOCK..((i + 1) * ROWS_PER_BLOCK).min(rows)))
        .collect();
    let all = blocks.iter().fold(plan.empty_block(), Block::merge);

    let names = ["chl_mg_m3", "nap_g_m3", "cdom_per_m"];
    let mut variables: Vec<VariableMetrics> = names
        .iter()
        .zip(&all.constituents)
        .filter(|(v, _)| product.map(v).is_some())
        .map(|(v, s)| VariableMetrics { variable: (*v).into(), metrics: s.metrics() })
        .collect();
    let mut depth_by_true_substrate = Vec::new();
    let (mut substrate_agreement_pct, mut substrate_confusion) = (None, None);
    if depth.is_some() {
        depth_by_true_substrate = truth
            .substrate_names
            .iter()
            .zip(&all.depth_by_true_substrate)
            .map(|(name, s)| VariableMetrics { variable: format!("depth_m_over_{name}"), metrics: s.metrics() })
            .collect();
        variables.push(VariableMetrics { variable: "depth_m".into(), metrics: all.depth.metrics() });
        variables
            .push(VariableMetrics { variable: "depth_m_bottom_visible".into(), metrics: all.depth_visible.metrics() });
        if let Some(classes) = plan.classes {
            let confusion = Confusion { classes: classes.names, counts: all.confusion };
            // Agreement over every returned pixel (a pixel without a dominant class disagrees).
            if all.returned > 0 {
                let right: usize = (0..confusion.classes.len()).map(|i| confusion.counts[i][i]).sum();
                substrate_agreement_pct = Some(100.0 * right as f64 / all.returned as f64);
            }
            substrate_confusion = Some(confusion);
        }
    }
    let mut siop_set_counts = all.siop_set_counts;
    if product.siop_set.is_none() && siop_set_counts.len() == 1 {
        // One set (SAMBUCA): every returned pixel used it.
        siop_set_counts[0] = all.returned;
    }
    ProductMetrics {
        product: product.name.clone(),
        variables,
        substrate_agreement_pct,
        substrate_confusion,
        depth_by_true_substrate,
        siop_sets_used: siop_set_counts.iter().filter(|&&n| n > 0).count(),
        siop_set_counts,
        failed: all.failed,
        stalled: all.stalled,
    }
}

#[cfg(test)]
mod tests {
    use ndarray::{Array2, Array3};

    use super::*;
    use crate::metrics::{Metrics, compare};

    /// A 100 × 7 scene (four blocks of rows, the last one short): land in one column, failures,
    /// three true substrates, a retrieval that knows two of them and one the scene lacks.
    fn scene() -> (Product, Truth) {
        let (rows, cols) = (100, 7);
        let wobble = |r: usize, c: usize, k: f32| 1.0 + 0.3 * ((r * 7 + c) as f32 * k).sin();
        let truth_map = |k: f32| Array2::from_shape_fn((rows, cols), |(r, c)| 0.5 + (r + c) as f32 * 0.05 * k);
        let truth = Truth {
            chl_mg_m3: truth_map(1.0),
            nap_g_m3: truth_map(2.0),
            cdom_per_m: truth_map(0.1),
            depth_m: Some(truth_map(3.0)),
            substrate_fractions: Some(Array3::from_shape_fn((rows, cols, 3), |(r, c, s)| {
                ((r * 3 + c * 5 + s * 11) % 7) as f32
            })),
            substrate_names: vec!["sand".into(), "coral".into(), "seagrass".into()],
            surface: crate::instrument::SurfaceMap::from_codes(Array2::from_shape_fn((rows, cols), |(_, c)| {
                u8::from(c == 6)
            })),
            aot550: None,
        };
        let flags = Array2::from_shape_fn((rows, cols), |(r, c)| match (r * cols + c) % 13 {
            0 => ProductFlags::FAILED,
            3 => ProductFlags::RETURNED | ProductFlags::STALLED,
            k if k % 2 == 0 => ProductFlags::RETURNED | ProductFlags::BOTTOM_VISIBLE,
            _ => ProductFlags::RETURNED,
        });
        let retrieved =
            |t: &Array2<f32>, k: f32| Array2::from_shape_fn((rows, cols), |(r, c)| t[[r, c]] * wobble(r, c, k));
        let product = Product {
            name: "test".into(),
            chl_mg_m3: Some(retrieved(&truth.chl_mg_m3, 0.7)),
            cdom_per_m: Some(retrieved(&truth.cdom_per_m, 1.3)),
            nap_g_m3: Some(retrieved(&truth.nap_g_m3, 0.2)),
            depth_m: Some(retrieved(truth.depth_m.as_ref().unwrap(), 0.9)),
            substrate_names: vec!["coral".into(), "mud".into()],
            substrate_fractions: Some(Array3::from_shape_fn((rows, cols, 2), |(r, c, s)| ((r + c * 2 + s) % 3) as f32)),
            siop_set_names: vec!["a".into(), "b".into(), "c".into()],
            siop_set: Some(Array2::from_shape_fn((rows, cols), |(r, c)| ((r + c) % 4) as i16 - 1)),
            cost: Array2::zeros((rows, cols)),
            sdi: None,
            iterations: None,
            extras: Vec::new(),
            flags,
        };
        (product, truth)
    }

    /// The metrics of `variable` over the water pixels `keep` selects, one pixel at a time.
    fn one_by_one(
        p: &Product,
        t: &Truth,
        m: &Array2<f32>,
        o: &Array2<f32>,
        keep: impl Fn(usize, usize) -> bool,
    ) -> Metrics {
        let (mut got, mut want) = (Vec::new(), Vec::new());
        for ((r, c), &land) in t.surface.codes().indexed_iter() {
            if land == 0 && keep(r, c) {
                got.push(p.returned(r, c).then(|| f64::from(m[[r, c]])));
                want.push(Some(f64::from(o[[r, c]])));
            }
        }
        compare(&got, &want)
    }

    fn assert_close(a: &Metrics, b: &Metrics) {
        assert_eq!((a.n, a.candidates, a.excluded), (b.n, b.candidates, b.excluded));
        // The same sums added in another order: equal to a few units in the last place.
        for (x, y) in [(a.mae, b.mae), (a.bias, b.bias), (a.rmse, b.rmse), (a.r2, b.r2), (a.mean_error, b.mean_error)] {
            assert!((x - y).abs() <= 1e-12 * y.abs().max(1.0), "{x} vs {y}");
        }
    }

    #[test]
    fn the_block_pass_agrees_with_a_pixel_by_pixel_pass() {
        let (p, t) = scene();
        let m = evaluate(&p, &t);
        let all = |_: usize, _: usize| true;
        assert_close(
            m.get("chl_mg_m3").unwrap(),
            &one_by_one(&p, &t, p.chl_mg_m3.as_ref().unwrap(), &t.chl_mg_m3, all),
        );
        assert_close(m.get("nap_g_m3").unwrap(), &one_by_one(&p, &t, p.nap_g_m3.as_ref().unwrap(), &t.nap_g_m3, all));
        let (d, td) = (p.depth_m.as_ref().unwrap(), t.depth_m.as_ref().unwrap());
        let visible = |r: usize, c: usize| p.flags[[r, c]] & ProductFlags::BOTTOM_VISIBLE != 0;
        assert_close(m.get("depth_m_bottom_visible").unwrap(), &one_by_one(&p, &t, d, td, visible));
        let tf = t.substrate_fractions.as_ref().unwrap();
        assert_eq!(m.depth_by_true_substrate.len(), 3);
        for (s, v) in m.depth_by_true_substrate.iter().enumerate() {
            let here = |r: usize, c: usize| dominant(tf, 3, r, c) == Some(s);
            assert_close(&v.metrics, &one_by_one(&p, &t, d, td, here));
        }
        // Counts: 6 water columns × 100 rows; FAILED where (r·7 + c) mod 13 = 0.
        let water: Vec<(usize, usize)> = (0..100).flat_map(|r| (0..6).map(move |c| (r, c))).collect();
        let failed = water.iter().filter(|&&(r, c)| (r * 7 + c) % 13 == 0).count();
        assert_eq!((m.failed, m.get("chl_mg_m3").unwrap().excluded), (failed, failed));
        assert_eq!(m.stalled, water.iter().filter(|&&(r, c)| (r * 7 + c) % 13 == 3).count());
        let sets = |i: i16| water.iter().filter(|&&(r, c)| p.returned(r, c) && ((r + c) % 4) as i16 - 1 == i).count();
        assert_eq!(m.siop_set_counts, vec![sets(0), sets(1), sets(2)]);
        // The confusion table has the truth's classes, then "mud"; its total is the returned water.
        let confusion = m.substrate_confusion.as_ref().unwrap();
        assert_eq!(confusion.classes, ["sand", "coral", "seagrass", "mud"]);
        let pf = p.substrate_fractions.as_ref().unwrap();
        let mut counts = vec![vec![0; 4]; 4];
        for &(r, c) in water.iter().filter(|&&(r, c)| p.returned(r, c)) {
            let t = dominant(tf, 3, r, c).unwrap();
            let g = [1, 3][dominant(pf, 2, r, c).unwrap()];
            counts[t][g] += 1;
        }
        assert_eq!(confusion.counts, counts);
        let right = counts[1][1] as f64;
        let returned = water.iter().filter(|&&(r, c)| p.returned(r, c)).count() as f64;
        assert_eq!(m.substrate_agreement_pct, Some(100.0 * right / returned));
    }

    #[test]
    fn the_metrics_do_not_depend_on_the_number_of_threads() {
        let (p, t) = scene();
        let on =
            |n: usize| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap().install(|| evaluate(&p, &t));
        assert_eq!(on(1), on(2));
        assert_eq!(on(1), on(3));
    }
}
