//! Product maps for display: the values of a product from a run (or its truth), the A − B
//! difference on A's pixels, colour mapping and downsampling — computed on a raster thread so
//! the UI thread only uploads the finished images.

use std::sync::Arc;

use ndarray::Array2;

use super::model::ProductKind;
use super::plot_data::{PlotData, plot_data};
use crate::colormap::{Scale, categorical, diverging, viridis};
use crate::engine::RunOutput;
use crate::instrument::{Detector, DetectorMode};
use crate::jobs::Worker;

/// A map's values and where they are valid.
#[derive(Debug, Clone, PartialEq)]
pub struct MapData {
    /// Values (row, column).
    pub values: Array2<f32>,
    /// Valid pixels.
    pub valid: Array2<bool>,
}

/// The product `kind` (band `band`) of `out`; `truth` takes the scene's truth instead of the
/// retrieval where there is one. `None` when the run has no such product.
#[must_use]
pub fn product_map(out: &RunOutput, kind: ProductKind, band: usize, truth: bool) -> Option<MapData> {
    let r = &out.radiance;
    let water = r.truth.land.mapv(|l| l == 0);
    let ret = out.retrievals.first();
    let returned = |p: &crate::retrieval::Product| Array2::from_shape_fn(p.flags.dim(), |(i, j)| p.returned(i, j));
    let product_or_truth =
        |t: &Array2<f32>, pick: fn(&crate::retrieval::Product) -> Option<&Array2<f32>>| -> Option<MapData> {
            if truth {
                return Some(MapData { values: t.clone(), valid: water.clone() });
            }
            let p = &ret?.product;
            let map = pick(p)?;
            let ok = returned(p);
            Some(MapData {
                valid: Array2::from_shape_fn(map.dim(), |(i, j)| ok[[i, j]] && map[[i, j]] > 0.0),
                values: map.clone(),
            })
        };
    let nb = r.radiance.dim().2;
    let band = band.min(nb.saturating_sub(1));
    match kind {
        ProductKind::Chl => product_or_truth(&r.truth.chl_mg_m3, |p| Some(&p.chl_mg_m3)),
        ProductKind::Nap => product_or_truth(&r.truth.nap_g_m3, |p| Some(&p.nap_g_m3)),
        ProductKind::Cdom => product_or_truth(&r.truth.cdom_per_m, |p| Some(&p.cdom_per_m)),
        ProductKind::Depth => product_or_truth(r.truth.depth_m.as_ref()?, |p| p.depth_m.as_ref()),
        ProductKind::Substrate => {
            let (f, names) = if truth {
                (r.truth.substrate_fractions.as_ref()?, &r.truth.substrate_names)
            } else {
                let p = &ret?.product;
                (p.substrate_fractions.as_ref()?, &p.substrate_names)
            };
            // The truth and the retrieval may list substrates in different orders: every map is
            // coloured by its class's place in one list (`substrate_classes`), so one colour is
            // one substrate in every panel and in the legend.
            let class_of = class_indices(names, &substrate_classes(out));
            let dominant = Array2::from_shape_fn((f.dim().0, f.dim().1), |(i, j)| {
                let k = (0..f.dim().2).max_by(|&a, &b| f[[i, j, a]].total_cmp(&f[[i, j, b]])).unwrap_or(0);
                class_of.get(k).copied().unwrap_or(0.0)
            });
            let valid = if truth { water } else { returned(&ret?.product) };
            Some(MapData { values: dominant, valid })
        }
        ProductKind::SiopSet => {
            if truth {
                return None;
            }
            let p = &ret?.product;
            let s = p.siop_set.as_ref()?;
            Some(MapData {
                values: s.mapv(f32::from),
                valid: Array2::from_shape_fn(s.dim(), |(i, j)| s[[i, j]] >= 0 && p.returned(i, j)),
            })
        }
        ProductKind::Rrs => {
            let cube = if truth { &r.truth.rrs_above } else { &out.correction.rrs.rrs };
            let values = cube.index_axis(ndarray::Axis(2), band).to_owned();
            let flags = &out.correction.rrs.flags;
            let valid =
                Array2::from_shape_fn(values.dim(), |(i, j)| water[[i, j]] && (truth || flags[[i, j, band]] == 0));
            Some(MapData { values, valid })
        }
        ProductKind::Level1 => {
            let cube = if truth { &r.radiance } else { &out.level1.radiance };
            let values = cube.index_axis(ndarray::Axis(2), band).to_owned();
            Some(MapData { valid: values.mapv(|v| v.is_finite() && v > 0.0), values })
        }
        ProductKind::Snr => {
            // Analytic SNR at each pixel's own radiance (detector noise model, noise on).
            let detector =
                Detector::new(&out.config.instrument, &out.response, DetectorMode::default(), out.config.seed);
            let l = r.radiance.index_axis(ndarray::Axis(2), band);
            let values = Array2::from_shape_fn(l.dim(), |(i, j)| {
                let d = out.viewing.detector_index[j];
                crate::instrument::analytic_snr(&detector, d, band, f64::from(l[[i, j]])) as f32
            });
            Some(MapData { valid: values.mapv(|v| v.is_finite() && v > 0.0), values })
        }
    }
}

/// A − B on A's pixels: B is sampled at the pixel nearest each of A's ground points.
#[must_use]
pub fn difference(a: &MapData, a_out: &RunOutput, b: &MapData, b_out: &RunOutput) -> MapData {
    let (rows, cols) = a.values.dim();
    let mut values = Array2::zeros((rows, cols));
    let mut valid = Array2::from_elem((rows, cols), false);
    for r in 0..rows {
        for c in 0..cols {
            let (x, y) = a_out.viewing.ground_m(0, r, c);
            if let Some((rb, cb)) = b_out.viewing.nearest_pixel(x, y, b_out.config.instrument.heading_deg)
                && rb < b.values.dim().0
                && cb < b.values.dim().1
                && a.valid[[r, c]]
                && b.valid[[rb, cb]]
            {
                values[[r, c]] = a.values[[r, c]] - b.values[[rb, cb]];
                valid[[r, c]] = true;
            }
        }
    }
    MapData { values, valid }
}

/// The substrate classes of a run's maps, in legend order: the scene's substrates, then any the
/// retrieval unmixes that the scene does not have.
#[must_use]
pub fn substrate_classes(out: &RunOutput) -> Vec<String> {
    let mut classes = out.radiance.truth.substrate_names.clone();
    for r in &out.retrievals {
        for n in &r.product.substrate_names {
            if !classes.contains(n) {
                classes.push(n.clone());
            }
        }
    }
    classes
}

/// The legend position of each of `names` in `classes` (past the end when absent).
#[must_use]
pub fn class_indices(names: &[String], classes: &[String]) -> Vec<f32> {
    names.iter().map(|n| classes.iter().position(|c| c == n).unwrap_or(classes.len()) as f32).collect()
}

/// Where two class maps agree (0) or not (1), A's pixels against B's nearest ground point.
#[must_use]
pub fn agreement(a: &MapData, a_out: &RunOutput, b: &MapData, b_out: &RunOutput) -> MapData {
    let mut d = difference(a, a_out, b, b_out);
    d.values.mapv_inplace(|v| if v == 0.0 { 0.0 } else { 1.0 });
    d
}

/// How a map is coloured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Palette {
    /// Viridis on a scale.
    Sequential(Scale),
    /// Blue–white–red symmetric about zero, ± this bound.
    Diverging(f64),
    /// Class colours.
    Classes,
    /// Two classes of A against B: the same (0) or different (1).
    Agreement,
}

/// An RGBA image ready to upload.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Width, px.
    pub width: usize,
    /// Height, px.
    pub height: usize,
    /// Unmultiplied RGBA.
    pub rgba: Vec<u8>,
}

/// Colour `map` with `palette`, block-averaged down to at most `max_side` pixels on its long side,
/// the first row at the bottom (flight direction up). Invalid pixels are transparent grey.
#[must_use]
pub fn colorize(map: &MapData, palette: Palette, max_side: usize) -> Image {
    let (rows, cols) = map.values.dim();
    let step = rows.max(cols).div_ceil(max_side.max(1)).max(1);
    let (h, w) = (rows.div_ceil(step).max(1), cols.div_ceil(step).max(1));
    let mut rgba = vec![0u8; w * h * 4];
    for y in 0..h {
        for x in 0..w {
            let (mut sum, mut n, mut first) = (0.0, 0usize, None);
            for r in y * step..((y + 1) * step).min(rows) {
                for c in x * step..((x + 1) * step).min(cols) {
                    if map.valid[[r, c]] {
                        let v = f64::from(map.values[[r, c]]);
                        first.get_or_insert(v);
                        sum += match palette {
                            Palette::Sequential(s) => s.position(v),
                            _ => v,
                        };
                        n += 1;
                    }
                }
            }
            let i = ((h - 1 - y) * w + x) * 4;
            let colour = if n == 0 {
                super::theme::NOT_RETURNED
            } else {
                let c = match palette {
                    Palette::Sequential(_) => viridis(sum / n as f64),
                    Palette::Diverging(bound) => diverging((sum / n as f64) / bound.max(f64::MIN_POSITIVE)),
                    Palette::Classes => categorical(first.unwrap_or(0.0).max(0.0) as usize),
                    // Any disagreement in the block shows (a mean above 0).
                    Palette::Agreement => super::theme::AGREEMENT[usize::from(sum > 0.0)],
                };
                [c[0], c[1], c[2], 255]
            };
            rgba[i..i + 4].copy_from_slice(&colour);
        }
    }
    Image { width: w, height: h, rgba }
}

/// The palette shared by a set of maps: a robust scale over all valid values (log when they span
/// a decade), ± the 99th percentile of |value| for differences, or classes.
#[must_use]
pub fn shared_palette(maps: &[&MapData], kind: ProductKind, difference: bool) -> Palette {
    if kind.categorical() {
        return Palette::Classes;
    }
    let mut values: Vec<f64> = Vec::new();
    for m in maps {
        let step = (m.values.len() / 50_000).max(1);
        values.extend(
            m.values.iter().zip(m.valid.iter()).step_by(step).filter(|(_, ok)| **ok).map(|(v, _)| f64::from(*v)),
        );
    }
    if difference {
        let mut abs: Vec<f64> = values.iter().map(|v| v.abs()).filter(|v| v.is_finite()).collect();
        abs.sort_by(f64::total_cmp);
        let bound = abs.get(abs.len().saturating_sub(1) * 99 / 100).copied().unwrap_or(1.0);
        return Palette::Diverging(if bound > 0.0 { bound } else { 1.0 });
    }
    let mut scale = Scale::robust(
        values
            .iter()
            .copied()
            .filter(|v| *v > 0.0 || !matches!(kind, ProductKind::Chl | ProductKind::Nap | ProductKind::Cdom)),
    );
    if matches!(kind, ProductKind::Chl | ProductKind::Nap | ProductKind::Cdom) && scale.lo > 0.0 {
        scale.log = true;
    }
    Palette::Sequential(scale)
}

/// A request to the raster thread: the runs of A and B and what to show of them.
#[derive(Debug, Clone)]
pub struct Job {
    /// Identifies the request (the app shows the images of the newest key).
    pub key: u64,
    /// The runs of A and B (either may be missing).
    pub runs: [Option<Arc<RunOutput>>; 2],
    /// The product.
    pub kind: ProductKind,
    /// The band of band products.
    pub band: usize,
    /// Truth | A | B, or A | B | A − B.
    pub layout: super::model::Layout,
    /// Longest side of each image.
    pub max_side: usize,
}

/// One map panel, ready to show.
#[derive(Debug, Clone)]
pub struct PanelImage {
    /// Title ("truth", "A", "B", "A − B").
    pub title: String,
    /// The values (for the value under the cursor).
    pub data: Arc<MapData>,
    /// The coloured image.
    pub image: Image,
}

/// The raster thread's answer.
#[derive(Debug, Clone)]
pub struct Done {
    /// The request's key.
    pub key: u64,
    /// The panels, in display order.
    pub panels: Vec<PanelImage>,
    /// The palette they share (for the colour bar).
    pub palette: Palette,
    /// The differences' palette, when the layout has one.
    pub difference_palette: Option<Palette>,
    /// The histogram and scatter data of the product's variable.
    pub plot: Arc<PlotData>,
}

/// One cached map: its run, product, band, truth flag and the map (`None`: the run has none).
type CachedMap = (Arc<RunOutput>, ProductKind, usize, bool, Option<Arc<MapData>>);

/// Product maps already extracted, by run (kept alive here, so pointer equality is identity),
/// product, band and truth, least recently used first: when only A changes, B's map is not
/// rebuilt.
#[derive(Default)]
pub struct MapCache {
    entries: Vec<CachedMap>,
}

impl MapCache {
    /// Maps kept: A, A's truth, B and one more. Few, because each entry keeps its run (cubes
    /// and all) alive.
    const CAPACITY: usize = 4;

    fn get(&mut self, out: &Arc<RunOutput>, kind: ProductKind, band: usize, truth: bool) -> Option<Arc<MapData>> {
        if let Some(i) =
            self.entries.iter().position(|e| Arc::ptr_eq(&e.0, out) && e.1 == kind && e.2 == band && e.3 == truth)
        {
            // Most recently used last: what is shown now stays, old runs leave first.
            let e = self.entries.remove(i);
            let map = e.4.clone();
            self.entries.push(e);
            return map;
        }
        let map = product_map(out, kind, band, truth).map(Arc::new);
        if self.entries.len() == Self::CAPACITY {
            self.entries.remove(0);
        }
        self.entries.push((out.clone(), kind, band, truth, map.clone()));
        map
    }
}

/// Compute the panels of `job`.
#[must_use]
pub fn panels(job: &Job, cache: &mut MapCache) -> Done {
    use super::model::Layout;
    let mut get = |i: usize, truth: bool| job.runs[i].as_ref().and_then(|o| cache.get(o, job.kind, job.band, truth));
    let (a, b) = (get(0, false), get(1, false));
    let mut named: Vec<(String, Arc<MapData>)> = Vec::new();
    let mut diff = None;
    match job.layout {
        Layout::TruthAB => {
            if let Some(t) = get(0, true) {
                named.push(("truth".into(), t));
            }
            if let Some(a) = &a {
                named.push(("A".into(), a.clone()));
            }
            if let Some(b) = &b {
                named.push(("B".into(), b.clone()));
            }
        }
        Layout::AbDifference => {
            if let Some(a) = &a {
                named.push(("A".into(), a.clone()));
            }
            if let Some(b) = &b {
                named.push(("B".into(), b.clone()));
            }
            if let (Some(a), Some(b), Some(ra), Some(rb)) = (&a, &b, &job.runs[0], &job.runs[1]) {
                // Classes have no difference: A − B of a class map is where they agree.
                diff = Some(Arc::new(if job.kind.categorical() {
                    agreement(a, ra, b, rb)
                } else {
                    difference(a, ra, b, rb)
                }));
            }
        }
    }
    let refs: Vec<&MapData> = named.iter().map(|(_, m)| m.as_ref()).collect();
    let palette = shared_palette(&refs, job.kind, false);
    let difference_palette = diff.as_ref().map(|d| {
        if job.kind.categorical() { Palette::Agreement } else { shared_palette(&[d.as_ref()], job.kind, true) }
    });
    let mut panels: Vec<PanelImage> = named
        .into_iter()
        .map(|(title, data)| PanelImage { image: colorize(&data, palette, job.max_side), title, data })
        .collect();
    if let (Some(d), Some(p)) = (diff, difference_palette) {
        panels.push(PanelImage { title: "A − B".into(), image: colorize(&d, p, job.max_side), data: d });
    }
    Done { key: job.key, panels, palette, difference_palette, plot: Arc::default() }
}

/// A's and B's runs.
type Runs = [Option<Arc<RunOutput>>; 2];

/// The thread that prepares map panels (and the plots' data) off the UI thread, always on the
/// newest request (a [`Worker`]: asking never blocks, and a request not yet started is replaced
/// by a newer one).
pub type RasterThread = Worker<Job, Done>;

/// Start the raster thread; `wake` is called when an answer is ready (to request a repaint).
pub fn spawn_raster_thread(wake: impl Fn() + Send + 'static) -> std::io::Result<RasterThread> {
    let mut cache = MapCache::default();
    // The plot data depend on the runs and the variable only, not on the band or layout. The
    // cache holds the runs themselves, so their identity cannot be reused by a newer run.
    let mut last_plot: Option<(Runs, &'static str, Arc<PlotData>)> = None;
    Worker::spawn("shoal-raster", wake, move |job: Job| {
        let mut done = panels(&job, &mut cache);
        let variable = job.kind.variable().unwrap_or("chl_mg_m3");
        let same = |a: &Option<Arc<RunOutput>>, b: &Option<Arc<RunOutput>>| match (a, b) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        };
        done.plot = match &last_plot {
            Some((runs, v, plot)) if *v == variable && runs.iter().zip(&job.runs).all(|(a, b)| same(a, b)) => {
                plot.clone()
            }
            _ => {
                let plot = Arc::new(plot_data(&job.runs, variable));
                last_plot = Some((job.runs.clone(), variable, plot.clone()));
                plot
            }
        };
        done
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_substrate_is_one_colour_whatever_order_a_product_lists_it_in() {
        // The scene lists sand, seagrass, coral; a retrieval unmixing coral and sand (and mud,
        // which the scene lacks) must colour its coral as the truth's coral.
        let classes: Vec<String> = ["sand", "seagrass", "coral", "mud"].map(String::from).to_vec();
        let product: Vec<String> = ["coral", "sand", "mud"].map(String::from).to_vec();
        assert_eq!(class_indices(&product, &classes), vec![2.0, 0.0, 3.0]);
        assert_eq!(class_indices(&["kelp".to_string()], &classes), vec![4.0], "unknown: past the legend");
    }

    #[test]
    fn colorize_downsamples_and_flips() {
        let values = Array2::from_shape_fn((4, 2), |(r, _)| r as f32);
        let valid = Array2::from_elem((4, 2), true);
        let img = colorize(&MapData { values, valid }, Palette::Sequential(Scale { lo: 0.0, hi: 3.0, log: false }), 2);
        assert_eq!((img.width, img.height), (1, 2));
        // Bottom image row holds rows 0–1 (mean 0.5 of 3), top holds rows 2–3.
        let bottom = &img.rgba[4..8];
        let top = &img.rgba[0..4];
        assert_eq!(&bottom[..3], &viridis(0.5 / 3.0));
        assert_eq!(&top[..3], &viridis(2.5 / 3.0));
    }
}
