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
    pub const ALL: [Self; 19] = [
        Self::Scene,
        Self::Response,
        Self::Geometry,
        Self::Lut,
        Self::Optics,
        Self::BandAtmosphere,
        Self::Radiance,
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
            Self::Radiance | Self::Electrons | Self::Level0 | Self::Level1 | Self::Correction | Self::Retrieval => 4,
            _ => 8,
        }
    }
}

impl Stage {
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

/// Products by stage, most recent first, a few per stage.
#[derive(Default)]
pub struct Cache {
    entries: HashMap<Stage, VecDeque<(Key, Product)>>,
}

impl std::fmt::Debug for Cache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cache").field("stages", &self.entries.len()).finish()
    }
}

impl Cache {
    /// The product under `key`, if kept (and moves it to the front).
    pub fn get<T: Send + Sync + 'static>(&mut self, key: Key) -> Option<Arc<T>> {
        let list = self.entries.get_mut(&key.stage)?;
        let i = list.iter().position(|(k, _)| *k == key)?;
        let entry = list.remove(i)?;
        let product = entry.1.clone().downcast::<T>().ok();
        list.push_front(entry);
        product
    }

    /// Keep `product` under `key`.
    pub fn put<T: Send + Sync + 'static>(&mut self, key: Key, product: Arc<T>) {
        let stage = key.stage;
        let list = self.entries.entry(stage).or_default();
        list.retain(|(k, _)| *k != key);
        list.push_front((key, product));
        list.truncate(stage.capacity());
    }

    /// Products kept, over all stages (at most the sum of [`Stage::capacity`]).
    #[must_use]
    pub fn len(&self) -> usize {
        self.entries.values().map(VecDeque::len).sum()
    }

    /// Drop everything.
    pub fn clear(&mut self) {
        self.entries.clear();
    }
}
