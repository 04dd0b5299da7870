//! The stage cache: products kept under a hash of exactly what they read.

use std::any::Any;
use std::collections::{HashMap, VecDeque};
use std::hash::{DefaultHasher, Hash, Hasher};
use std::sync::Arc;

use serde::Serialize;

/// The stages of the chain, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Stage {
    /// Scene maps.
    Scene,
    /// Spectral response.
    Response,
    /// Viewing geometry.
    Geometry,
    /// Atmosphere LUT.
    Lut,
    /// Scene bound to the grids and the LUT (water model, adjacency).
    Optics,
    /// Band-effective atmosphere per column.
    BandAtmosphere,
    /// Pupil radiance and truth.
    Radiance,
    /// The instrument's optical effects on the pupil radiance (stray light, polarisation).
    Effects,
    /// Detector responsivity and fixed patterns.
    Detector,
    /// Feasibility figures: f-number, Q, Airy disc, smear, peak signal against full scale,
    /// quantisation against read noise (and the plausibility warnings).
    Feasibility,
    /// Electrons per pixel.
    Electrons,
    /// Level-0 counts.
    Level0,
    /// Calibration coefficients.
    Calibration,
    /// Level-1 radiance.
    Level1,
    /// The image-based correction's aerosol family: one LUT per model and AOT node.
    AerosolLuts,
    /// The image-based correction's aerosol family tabulated over the run's geometry.
    AerosolFamily,
    /// Rrs.
    Correction,
    /// SNR table.
    Snr,
    /// A retrieval's model at the instrument's bands (its SIOP sets and substrates integrated
    /// over the band responses): kept while only the Rrs changes.
    RetrievalModel,
    /// A retrieval and its metrics.
    Retrieval,
}

impl Stage {
    /// Every stage, in chain order.
    pub const ALL: [Self; 20] = [
        Self::Scene,
        Self::Response,
        Self::Geometry,
        Self::Lut,
        Self::Optics,
        Self::BandAtmosphere,
        Self::Radiance,
        Self::Effects,
        Self::Detector,
        Self::Feasibility,
        Self::Electrons,
        Self::Level0,
        Self::Calibration,
        Self::Level1,
        Self::AerosolLuts,
        Self::AerosolFamily,
        Self::Correction,
        Self::Snr,
        Self::RetrievalModel,
        Self::Retrieval,
    ];

    /// Products kept per stage: four for the large cubes (instruments A and B of a comparison,
    /// each as a preview and at full resolution), eight for the small ones.
    #[must_use]
    pub fn capacity(self) -> usize {
        match self {
            Self::Radiance
            | Self::Effects
            | Self::Electrons
            | Self::Level0
            | Self::Level1
            | Self::Correction
            | Self::Retrieval => 4,
            _ => 8,
        }
    }
}

impl Stage {
    /// The large cubes a run makes on its way to the Rrs (pupil radiance, the radiance after
    /// the optics, electrons, Level-0, Level-1): what the cache lets go first.
    #[must_use]
    pub const fn is_upstream_cube(self) -> bool {
        matches!(self, Self::Radiance | Self::Effects | Self::Electrons | Self::Level0 | Self::Level1)
    }

    /// The stage's name in messages and progress ("atmosphere LUT", "retrieval").
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Scene => "scene",
            Self::Response => "response",
            Self::Geometry => "geometry",
            Self::Lut => "atmosphere LUT",
            Self::Optics => "optics",
            Self::BandAtmosphere => "band atmosphere",
            Self::Radiance => "radiance",
            Self::Effects => "optical effects",
            Self::Detector => "detector",
            Self::Feasibility => "feasibility",
            Self::Electrons => "electrons",
            Self::Level0 => "level-0",
            Self::Calibration => "calibration",
            Self::Level1 => "level-1",
            Self::AerosolLuts => "aerosol LUTs",
            Self::AerosolFamily => "aerosol family",
            Self::Correction => "correction",
            Self::Snr => "snr",
            Self::RetrievalModel => "retrieval model",
            Self::Retrieval => "retrieval",
        }
    }
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A cache key: the stage it belongs to and the hash of its inputs and upstream keys. The stage
/// travels with the key, so a product is stored and looked up under the stage that built the
/// key and under no other.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Key {
    /// The stage whose product the key names.
    pub stage: Stage,
    hash: u64,
}

/// Builds a key from serialisable inputs (hashed through their exact RON text, which round-trips
/// every f64) and upstream keys.
#[derive(Debug)]
pub struct KeyBuilder(Stage, DefaultHasher);

impl KeyBuilder {
    /// Start a key for `stage`.
    #[must_use]
    pub fn new(stage: Stage) -> Self {
        let mut h = DefaultHasher::new();
        stage.hash(&mut h);
        Self(stage, h)
    }

    /// Add a serialisable input.
    #[must_use]
    pub fn with<T: Serialize + ?Sized>(mut self, value: &T) -> Self {
        match ron::to_string(value) {
            Ok(s) => s.hash(&mut self.1),
            // Unserialisable input: never reuse a product built from it.
            Err(_) => std::time::Instant::now().hash(&mut self.1),
        }
        self
    }

    /// Add an upstream key.
    #[must_use]
    pub fn after(mut self, key: Key) -> Self {
        key.hash(&mut self.1);
        self
    }

    /// The key.
    #[must_use]
    pub fn finish(self) -> Key {
        Key { stage: self.0, hash: self.1.finish() }
    }
}

type Product = Arc<dyn Any + Send + Sync>;

/// One kept product: its key, the product, its bytes ([`super::footprint::Footprint`]) and when
/// it was last used (the cache's own clock).
struct Entry {
    key: Key,
    product: Product,
    bytes: usize,
    used: u64,
}

/// Products by stage, most recent first, a few per stage, and at most `budget` bytes over all
/// stages: past the budget the least recently used products go first (whatever their stage), and
/// a product there is no room for is not kept (it pushes nothing out).
pub struct Cache {
    entries: HashMap<Stage, VecDeque<Entry>>,
    budget: usize,
    held: usize,
    clock: u64,
    /// The clock when the current run began.
    run_start: u64,
    /// Products kept per stage of the large cubes (in place of [`Stage::capacity`]'s 4).
    large_capacity: Option<usize>,
}

impl Default for Cache {
    fn default() -> Self {
        Self::with_budget(usize::MAX)
    }
}

impl std::fmt::Debug for Cache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cache").field("stages", &self.entries.len()).field("bytes", &self.held).finish()
    }
}

impl Cache {
    /// An empty cache that keeps at most `budget` bytes.
    #[must_use]
    pub fn with_budget(budget: usize) -> Self {
        Self { entries: HashMap::new(), budget, held: 0, clock: 0, run_start: 0, large_capacity: None }
    }

    /// The same cache keeping up to `n` products per stage of the large cubes (the app keeps one
    /// per design and decimation; the byte budget still bounds them).
    #[must_use]
    pub fn with_large_capacity(mut self, n: usize) -> Self {
        self.large_capacity = Some(n.max(1));
        self
    }

    fn capacity(&self, stage: Stage) -> usize {
        match self.large_capacity {
            Some(n) if stage.capacity() < Stage::Scene.capacity() => n,
            _ => stage.capacity(),
        }
    }

    /// The product under `key`, if kept (and moves it to the front).
    pub fn get<T: Send + Sync + 'static>(&mut self, key: Key) -> Option<Arc<T>> {
        self.clock += 1;
        let list = self.entries.get_mut(&key.stage)?;
        let i = list.iter().position(|e| e.key == key)?;
        let mut entry = list.remove(i)?;
        entry.used = self.clock;
        let product = entry.product.clone().downcast::<T>().ok();
        list.push_front(entry);
        product
    }

    /// A run starts: the products it uses from now on are not pushed out by its own later ones.
    pub fn begin_run(&mut self) {
        self.clock += 1;
        self.run_start = self.clock;
    }

    /// Keep `product` (of `bytes`) under `key`, then drop what is over the stage's capacity.
    /// Within the budget, room is made by dropping the least recently used products the current
    /// run has not used ([`Self::begin_run`]), the upstream cubes first
    /// ([`Stage::is_upstream_cube`]). A cube may push out only other cubes; a product that is
    /// not one (an Rrs, a run's restart) pushes out the current run's own cubes before any other
    /// product: a design's Rrs lets a retrieval change skip the instrument, and is smaller than
    /// the cubes it was made from. A product there is no such room for is not kept (a run's
    /// pupil radiance, kept for the next noise seed, is not pushed out by the run's own
    /// Level-0).
    pub fn put<T: Send + Sync + 'static>(&mut self, key: Key, product: Arc<T>, bytes: usize) {
        self.clock += 1;
        let stage = key.stage;
        self.remove(key);
        let run_start = self.run_start;
        let cube = stage.is_upstream_cube();
        // In this order: cubes the run has not used, the run's own cubes (not for a cube), then
        // other products the run has not used (not for a cube).
        let unused_cube = |e: &Entry| e.used < run_start && e.key.stage.is_upstream_cube();
        let own_cube = |e: &Entry| !cube && e.key.stage.is_upstream_cube();
        let unused_other = |e: &Entry| !cube && e.used < run_start && !e.key.stage.is_upstream_cube();
        let room = self.budget.saturating_add(self.bytes_where(|e| unused_cube(e) || own_cube(e) || unused_other(e)));
        if self.held + bytes > room {
            return;
        }
        let target = self.budget.saturating_sub(bytes);
        self.evict_to(target, unused_cube);
        self.evict_to(target, own_cube);
        self.evict_to(target, unused_other);
        let keep = self.capacity(stage);
        let list = self.entries.entry(stage).or_default();
        list.push_front(Entry { key, product, bytes, used: self.clock });
        self.held += bytes;
        let dropped: Vec<Entry> = list.drain(keep.min(list.len())..).collect();
        self.held -= dropped.iter().map(|e| e.bytes).sum::<usize>();
    }

    fn remove(&mut self, key: Key) {
        if let Some(list) = self.entries.get_mut(&key.stage)
            && let Some(i) = list.iter().position(|e| e.key == key)
            && let Some(e) = list.remove(i)
        {
            self.held -= e.bytes;
        }
    }

    /// Products kept, over all stages (at most the sum of the stages' capacities).
    #[must_use]
    pub fn len(&self) -> usize {
        self.entries.values().map(VecDeque::len).sum()
    }

    /// Bytes the kept products hold (at most the budget).
    #[must_use]
    pub fn bytes(&self) -> usize {
        self.held
    }

    /// Drop everything.
    pub fn clear(&mut self) {
        self.entries.clear();
        self.held = 0;
    }

    /// Keep at most `budget` bytes from now on: the least recently used products go first,
    /// whichever run used them (called between runs, to make room for a large one).
    pub fn set_budget(&mut self, budget: usize) {
        self.budget = budget;
        self.evict_to(budget, |_| true);
    }

    /// Bytes of the products `may_go` admits.
    fn bytes_where(&self, may_go: impl Fn(&Entry) -> bool) -> usize {
        self.entries.values().flatten().filter(|e| may_go(e)).map(|e| e.bytes).sum()
    }

    /// Drop the products `may_go` admits, the upstream cubes first and least recently used
    /// first among them, until at most `target` bytes are held (or none of them is left).
    fn evict_to(&mut self, target: usize, may_go: impl Fn(&Entry) -> bool) {
        let mut candidates: Vec<(bool, u64, Key)> = self
            .entries
            .values()
            .flatten()
            .filter(|e| e.bytes > 0 && may_go(e))
            .map(|e| (!e.key.stage.is_upstream_cube(), e.used, e.key))
            .collect();
        candidates.sort_unstable_by_key(|e| (e.0, e.1));
        for (_, _, key) in candidates {
            if self.held <= target {
                break;
            }
            self.remove(key);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(stage: Stage, n: u32) -> Key {
        KeyBuilder::new(stage).with(&n).finish()
    }

    #[test]
    fn a_lower_budget_lets_the_least_recently_used_go_and_a_large_capacity_keeps_more() {
        let mut cache = Cache::with_budget(1000).with_large_capacity(6);
        for n in 0..6 {
            cache.begin_run();
            cache.put(key(Stage::Radiance, n), Arc::new(n), 100);
        }
        // Six cubes of one stage: past the default four, within the larger capacity.
        assert_eq!(cache.len(), 6);
        cache.begin_run();
        assert!(cache.get::<u32>(key(Stage::Radiance, 0)).is_some());
        cache.set_budget(250);
        assert_eq!(cache.bytes(), 200);
        // The one just used and the newest stay.
        assert!(cache.get::<u32>(key(Stage::Radiance, 0)).is_some());
        assert!(cache.get::<u32>(key(Stage::Radiance, 5)).is_some());
        assert!(cache.get::<u32>(key(Stage::Radiance, 1)).is_none());
    }

    #[test]
    fn the_budget_drops_the_least_recently_used_bytes_first() {
        let mut cache = Cache::with_budget(100);
        cache.begin_run();
        cache.put(key(Stage::Retrieval, 1), Arc::new(1u8), 60);
        cache.put(key(Stage::Scene, 1), Arc::new(2u8), 30);
        cache.begin_run();
        // The next run uses the retrieval's product: the scene is now the older one, and not used by it.
        assert!(cache.get::<u8>(key(Stage::Retrieval, 1)).is_some());
        cache.put(key(Stage::Correction, 1), Arc::new(3u8), 30);
        assert!(cache.get::<u8>(key(Stage::Scene, 1)).is_none(), "the least recently used goes first");
        assert!(cache.get::<u8>(key(Stage::Retrieval, 1)).is_some());
        assert_eq!(cache.bytes(), 90);
        // A product over the whole budget is not kept, and pushes nothing out.
        cache.put(key(Stage::Level1, 1), Arc::new(4u8), 101);
        assert!(cache.get::<u8>(key(Stage::Level1, 1)).is_none());
        assert_eq!(cache.bytes(), 90);
        // Small products (0 bytes) stay, bounded by their stage's capacity.
        for n in 0..20 {
            cache.put(key(Stage::Response, n), Arc::new(0u8), 0);
        }
        assert_eq!(cache.len(), 2 + Stage::Response.capacity());
    }

    #[test]
    fn cubes_go_first_and_an_rrs_may_push_out_its_own_runs_cubes() {
        let mut cache = Cache::with_budget(100);
        cache.begin_run();
        cache.put(key(Stage::Radiance, 1), Arc::new(1u8), 40);
        cache.put(key(Stage::Correction, 1), Arc::new(1u8), 40);
        // Another run's cube pushes out the older cube, not the newer Rrs.
        cache.begin_run();
        cache.put(key(Stage::Level0, 2), Arc::new(2u8), 40);
        assert!(cache.get::<u8>(key(Stage::Radiance, 1)).is_none());
        assert!(cache.get::<u8>(key(Stage::Correction, 1)).is_some());
        // A run's Rrs with no other room pushes out that run's own cubes, oldest first.
        cache.begin_run();
        cache.put(key(Stage::Radiance, 3), Arc::new(3u8), 30);
        cache.put(key(Stage::Level1, 3), Arc::new(3u8), 20);
        assert!(cache.get::<u8>(key(Stage::Level0, 2)).is_none(), "the other run's cube went for this run's");
        assert_eq!(cache.bytes(), 90);
        cache.put(key(Stage::Correction, 3), Arc::new(3u8), 30);
        assert!(cache.get::<u8>(key(Stage::Correction, 3)).is_some());
        assert!(cache.get::<u8>(key(Stage::Radiance, 3)).is_none(), "its own oldest cube went");
        assert!(cache.get::<u8>(key(Stage::Level1, 3)).is_some());
        assert_eq!(cache.bytes(), 90);
        // A cube never pushes out an Rrs: with only Rrs to push out, it is not kept.
        cache.begin_run();
        cache.put(key(Stage::Radiance, 4), Arc::new(4u8), 80);
        assert!(cache.get::<u8>(key(Stage::Radiance, 4)).is_none());
        assert!(
            cache.get::<u8>(key(Stage::Correction, 1)).is_some()
                && cache.get::<u8>(key(Stage::Correction, 3)).is_some()
        );
    }

    #[test]
    fn a_run_does_not_push_out_what_it_used() {
        let mut cache = Cache::with_budget(100);
        cache.begin_run();
        cache.put(key(Stage::Radiance, 1), Arc::new(1u8), 70);
        // The same run's Level-0 finds no room it may make: not kept, the radiance stays.
        cache.put(key(Stage::Level0, 1), Arc::new(2u8), 40);
        assert!(cache.get::<u8>(key(Stage::Level0, 1)).is_none());
        cache.begin_run();
        assert!(cache.get::<u8>(key(Stage::Radiance, 1)).is_some(), "the next seed reuses the radiance");
        cache.put(key(Stage::Level0, 2), Arc::new(2u8), 40);
        assert!(cache.get::<u8>(key(Stage::Radiance, 1)).is_some());
        assert_eq!(cache.bytes(), 70);
        // A later run that does not use the radiance may push it out.
        cache.begin_run();
        cache.put(key(Stage::Level0, 3), Arc::new(2u8), 40);
        assert!(cache.get::<u8>(key(Stage::Level0, 3)).is_some());
        assert!(cache.get::<u8>(key(Stage::Radiance, 1)).is_none());
    }

    #[test]
    fn replacing_a_product_counts_its_bytes_once() {
        let mut cache = Cache::with_budget(100);
        for _ in 0..5 {
            cache.put(key(Stage::Radiance, 1), Arc::new(1u8), 40);
        }
        assert_eq!((cache.len(), cache.bytes()), (1, 40));
        for n in 0..6 {
            cache.put(key(Stage::Level0, n), Arc::new(1u8), 10);
        }
        // Level-0 keeps 4 (its capacity): 40 + 4 × 10.
        assert_eq!((cache.len(), cache.bytes()), (5, 80));
    }
}
