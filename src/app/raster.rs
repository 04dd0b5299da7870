//! Product maps for display: colour mapping and downsampling of what `product_map.rs` takes from
//! a run, computed on a raster thread so the UI thread only uploads the finished images.

use std::sync::Arc;

use super::blocks::{Blocks, Prepared, palette_sample};
use super::model::ProductKind;
use super::plot_data::{PlotData, RunValues, combine};
use crate::colormap::Scale;
use crate::engine::RunOutput;
use crate::jobs::Worker;

pub use super::product_map::{MapData, agreement, class_indices, difference, product_map, substrate_classes};

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
    Blocks::of(map, max_side).colorize(palette)
}

/// The palette shared by a set of maps: a robust scale over all valid values (log when they span
/// a decade), ± the 99th percentile of |value| for differences, or classes.
#[must_use]
pub fn shared_palette(maps: &[&MapData], kind: ProductKind, difference: bool) -> Palette {
    let samples: Vec<Vec<f64>> = maps.iter().map(|m| palette_sample(m)).collect();
    let refs: Vec<&[f64]> = samples.iter().map(Vec::as_slice).collect();
    palette_of_samples(&refs, kind, difference)
}

/// [`shared_palette`] from the maps' [`palette_sample`]s (kept with each map, so a redraw after
/// a change of A does not revisit B's pixels).
#[must_use]
pub fn palette_of_samples(samples: &[&[f64]], kind: ProductKind, difference: bool) -> Palette {
    if kind.categorical() {
        return Palette::Classes;
    }
    if difference {
        let mut abs: Vec<f64> = samples.iter().flat_map(|s| s.iter()).map(|v| v.abs()).collect();
        abs.sort_unstable_by(f64::total_cmp);
        let bound = abs.get(abs.len().saturating_sub(1) * 99 / 100).copied().unwrap_or(1.0);
        return Palette::Diverging(if bound > 0.0 { bound } else { 1.0 });
    }
    let concentration = matches!(kind, ProductKind::Chl | ProductKind::Nap | ProductKind::Cdom | ProductKind::Extra(_));
    // Concentrations are scaled over their positive values only.
    let kept: Vec<&[f64]> =
        samples.iter().map(|s| if concentration { &s[s.partition_point(|v| *v <= 0.0)..] } else { *s }).collect();
    let mut scale = Scale::robust_sorted(&kept);
    if concentration && scale.lo > 0.0 {
        scale.log = true;
    }
    Palette::Sequential(scale)
}

/// A request to the raster thread: the runs of the designs and what to show of them.
#[derive(Debug, Clone)]
pub struct Job {
    /// Identifies the request (the app shows the images of the newest key).
    pub key: u64,
    /// The runs of every design, in order (any may be missing).
    pub runs: Vec<Option<Arc<RunOutput>>>,
    /// The designs on the maps beside the truth ([`Layout::TruthAB`](super::model::Layout)).
    pub on_maps: Vec<usize>,
    /// The designs of the difference layout (first − second).
    pub pair: [usize; 2],
    /// The product.
    pub kind: ProductKind,
    /// The band of band products.
    pub band: usize,
    /// The truth beside the designs on the maps, or a pair and its difference.
    pub layout: super::model::Layout,
    /// Longest side of each image.
    pub max_side: usize,
}

impl Job {
    /// The job with its key: what it shows and the results' identities (their addresses: the
    /// raster thread keeps the runs it was last asked for alive, so an address is not reused
    /// while its key may still be compared).
    #[must_use]
    pub fn keyed(mut self) -> Self {
        use std::hash::{DefaultHasher, Hash, Hasher};
        let mut h = DefaultHasher::new();
        self.kind.hash(&mut h);
        self.band.hash(&mut h);
        self.layout.hash(&mut h);
        self.on_maps.hash(&mut h);
        self.pair.hash(&mut h);
        self.max_side.hash(&mut h);
        for r in &self.runs {
            r.as_ref().map(Arc::as_ptr).hash(&mut h);
        }
        self.key = h.finish();
        self
    }
}

/// What a map panel shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The scene's truth (from the run of design `0`).
    Truth(usize),
    /// A design's product.
    Design(usize),
    /// The difference of a pair (first − second; for classes, where they agree).
    Difference(usize, usize),
}

/// One map panel, ready to show.
#[derive(Debug, Clone)]
pub struct PanelImage {
    /// Title ("truth", "A", "B", "A − B (B at A's ground points)").
    pub title: String,
    /// What it shows.
    pub role: Role,
    /// The values (for the value under the cursor).
    pub data: Arc<MapData>,
    /// The coloured image.
    pub image: Image,
    /// The runs it was made from, as (design, the run's address): the app marks a panel whose
    /// runs are no longer the designs' current ones as updating, whatever the link holds meanwhile.
    pub made_from: Vec<(usize, usize)>,
}

/// The address of design `i`'s run in `runs` (0: none), which identifies it while it is alive.
fn address(runs: &[Option<Arc<RunOutput>>], i: usize) -> usize {
    runs.get(i).and_then(Option::as_ref).map_or(0, |r| Arc::as_ptr(r) as usize)
}

impl Role {
    /// The designs whose runs a panel of this role is made from.
    #[must_use]
    pub fn designs(self) -> Vec<usize> {
        match self {
            Self::Truth(i) | Self::Design(i) => vec![i],
            Self::Difference(i, j) => vec![i, j],
        }
    }
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

/// Entries [`ByRun`] keeps per run on display: its map, its truth and one more.
const PER_RUN: usize = 3;

/// Products derived from runs, by run (kept alive here, so pointer equality is identity) and a
/// key, least recently used first: when only A changes, B's products are neither rebuilt nor
/// revisited. Each entry keeps its run (cubes and all) alive, so runs no longer on display are
/// let go ([`ByRun::keep_only`]) and the entries are few per run.
pub struct ByRun<K, V> {
    entries: Vec<(Arc<RunOutput>, K, V)>,
}

impl<K, V> Default for ByRun<K, V> {
    fn default() -> Self {
        Self { entries: Vec::new() }
    }
}

impl<K: PartialEq + Send + 'static, V: Clone + Send + 'static> ByRun<K, V> {
    /// Let go of every run not in `runs` (those no longer on display), and bound the entries.
    fn keep_only(&mut self, runs: &[Option<Arc<RunOutput>>]) {
        let shown = |e: &(Arc<RunOutput>, K, V)| runs.iter().flatten().any(|r| Arc::ptr_eq(r, &e.0));
        let (kept, gone): (Vec<_>, Vec<_>) = std::mem::take(&mut self.entries).into_iter().partition(shown);
        self.entries = kept;
        // Possibly the last handles on runs at full resolution: freed off this thread.
        if !gone.is_empty() {
            crate::jobs::free_later(gone);
        }
    }

    /// The product of `out` under `key`, made by `make` if not kept; at most `capacity` entries.
    fn get(&mut self, out: &Arc<RunOutput>, key: K, capacity: usize, make: impl FnOnce() -> V) -> V {
        if let Some(i) = self.entries.iter().position(|e| Arc::ptr_eq(&e.0, out) && e.1 == key) {
            // Most recently used last: what is shown now stays, old runs leave first.
            let e = self.entries.remove(i);
            let value = e.2.clone();
            self.entries.push(e);
            return value;
        }
        let value = make();
        if self.entries.len() >= capacity.max(1) {
            // Possibly the last handle on a run at full resolution: freed off this thread.
            crate::jobs::free_later(self.entries.remove(0));
        }
        self.entries.push((out.clone(), key, value.clone()));
        value
    }
}

/// Maps prepared for display, by run and (product, band, truth, display size); `None`: the run
/// has no such product.
pub type MapCache = ByRun<(ProductKind, usize, bool, usize), Option<Arc<Prepared>>>;

impl MapCache {
    fn map(
        &mut self,
        out: &Arc<RunOutput>,
        kind: ProductKind,
        band: usize,
        truth: bool,
        (max_side, capacity): (usize, usize),
    ) -> Option<Arc<Prepared>> {
        self.get(out, (kind, band, truth, max_side), capacity, || {
            product_map(out, kind, band, truth).map(|m| Arc::new(Prepared::new(Arc::new(m), max_side)))
        })
    }
}

/// Compute the panels of `job`.
#[must_use]
pub fn panels(job: &Job, cache: &mut MapCache) -> Done {
    use super::model::{Layout, label};
    cache.keep_only(&job.runs);
    let capacity = PER_RUN * job.runs.iter().flatten().count();
    let mut get = |i: usize, truth: bool| {
        let out = job.runs.get(i)?.as_ref()?;
        cache.map(out, job.kind, job.band, truth, (job.max_side, capacity))
    };
    let mut named: Vec<(String, Role, Arc<Prepared>)> = Vec::new();
    let mut diff = None;
    match job.layout {
        Layout::TruthAB => {
            // The truth from the first design on the maps that has a run.
            let truth = job.on_maps.iter().chain(&[0]).find_map(|&i| Some((i, get(i, true)?)));
            if let Some((i, t)) = truth {
                named.push(("truth".into(), Role::Truth(i), t));
            }
            for &i in &job.on_maps {
                if let Some(m) = get(i, false) {
                    named.push((label(i), Role::Design(i), m));
                }
            }
        }
        Layout::AbDifference => {
            let [p, q] = job.pair;
            let (a, b) = (get(p, false), get(q, false));
            if let Some(a) = &a {
                named.push((label(p), Role::Design(p), a.clone()));
            }
            if let Some(b) = &b.as_ref().filter(|_| q != p) {
                named.push((label(q), Role::Design(q), (*b).clone()));
            }
            let runs = (job.runs.get(p).and_then(Option::as_ref), job.runs.get(q).and_then(Option::as_ref));
            if let (Some(a), Some(b), (Some(ra), Some(rb))) = (&a, &b, runs)
                && p != q
            {
                // Classes have no difference: the difference of a class map is where they agree.
                let d = if job.kind.categorical() {
                    agreement(&a.data, ra, &b.data, rb)
                } else {
                    difference(&a.data, ra, &b.data, rb)
                };
                diff = Some((Prepared::new(Arc::new(d), job.max_side), Role::Difference(p, q)));
            }
        }
    }
    let samples: Vec<&[f64]> = named.iter().map(|(_, _, m)| m.sample.as_slice()).collect();
    let palette = palette_of_samples(&samples, job.kind, false);
    let difference_palette = diff.as_ref().map(|(d, _)| {
        if job.kind.categorical() {
            Palette::Agreement
        } else {
            palette_of_samples(&[d.sample.as_slice()], job.kind, true)
        }
    });
    let mut panels: Vec<PanelImage> = named
        .into_iter()
        .map(|(title, role, m)| PanelImage {
            image: m.blocks.colorize(palette),
            made_from: role.designs().into_iter().map(|i| (i, address(&job.runs, i))).collect(),
            title,
            role,
            data: m.data.clone(),
        })
        .collect();
    if let (Some((d, role)), Some(p)) = (diff, difference_palette) {
        let title = crate::study::difference_title(&label(job.pair[0]), &label(job.pair[1]), job.kind.categorical());
        let made_from = role.designs().into_iter().map(|i| (i, address(&job.runs, i))).collect();
        panels.push(PanelImage { title, role, image: d.blocks.colorize(p), data: d.data, made_from });
    }
    Done { key: job.key, panels, palette, difference_palette, plot: Arc::default() }
}

/// Drop the runs `old`, on a thread of their own if one of them is not in `kept` (it may be the
/// last handle on a run at full resolution, whose freeing would stall the thread dropping it).
pub fn let_go(old: Vec<Option<Arc<RunOutput>>>, kept: &[Option<Arc<RunOutput>>]) {
    if old.iter().flatten().any(|r| !kept.iter().flatten().any(|k| Arc::ptr_eq(k, r))) {
        crate::jobs::free_later(old);
    }
}

/// The thread that prepares map panels (and the plots' data) off the UI thread, always on the
/// newest request (a [`Worker`]: asking never blocks, and a request not yet started is replaced
/// by a newer one).
pub type RasterThread = Worker<Job, Done>;

/// Start the raster thread; `wake` is called when an answer is ready (to request a repaint).
pub fn spawn_raster_thread(wake: impl Fn() + Send + 'static) -> std::io::Result<RasterThread> {
    let mut maps = MapCache::default();
    // Each run's share of the plots, by variable.
    let mut values = ByRun::<&'static str, Arc<RunValues>>::default();
    // The last answer and the runs it was made from (kept alive, so their addresses in its key
    // stay theirs): a request asked again — made early by the engine's result hook, then by the
    // frame that takes the result — is answered at once.
    let mut last: Option<(Vec<Option<Arc<RunOutput>>>, Done)> = None;
    Worker::spawn("shoal-raster", wake, move |job: Job| {
        if let Some((_, done)) = last.as_ref().filter(|(_, d)| d.key == job.key) {
            return done.clone();
        }
        let mut done = panels(&job, &mut maps);
        let variable = job.kind.variable().unwrap_or("chl_mg_m3");
        values.keep_only(&job.runs);
        let capacity = 2 * job.runs.len();
        let runs: Vec<Option<Arc<RunValues>>> = job
            .runs
            .iter()
            .map(|r| r.as_ref().map(|o| values.get(o, variable, capacity, || Arc::new(RunValues::of(o, variable)))))
            .collect();
        let refs: Vec<Option<&RunValues>> = runs.iter().map(Option::as_deref).collect();
        done.plot = Arc::new(combine(variable, &refs));
        if let Some((old, _)) = last.replace((job.runs.clone(), done.clone())) {
            let_go(old, &job.runs);
        }
        done
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colormap::viridis;
    use ndarray::Array2;

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
