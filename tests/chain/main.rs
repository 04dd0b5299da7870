//! The chain from scene to Rrs: closure, noise statistics, saturation, SNR trade-off,
//! incremental re-runs, determinism, bad input, and `shoal simulate`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod adjacency;
mod aerosol_map;
mod bad_input;
mod band_nodes;
mod binning;
mod cli;
mod closure;
mod clouds;
mod coherence;
#[path = "../common/mod.rs"]
mod common;
mod design;
mod determinism;
mod effects;
mod external;
mod external_hostile;
mod focal_plane;
mod function;
mod glint;
mod image_correction;
mod in_place;
mod incremental;
mod memory;
mod netcdf;
mod nir_iteration;
mod noise;
mod path_sharing;
mod plausibility;
mod qaa;
mod rasters;
mod report;
mod reproduction;
mod restart;
mod retrieval;
mod season;
mod season_shards;
mod soak;
mod spatial;
mod spectral_knowledge;
mod spectrum;
mod study;
mod sweep;
mod term_columns;
mod user_data;
mod worker;

use shoal::control::RunControl;
use shoal::engine::{Engine, RunConfig, RunOutput};
use shoal::instrument::InstrumentSpec;
use shoal::scene::SceneSpec;

/// Lake Hume's bloom on a 12 × 8 km patch (same maps and atmosphere as the preset).
pub fn small_lake() -> SceneSpec {
    let mut s = SceneSpec::preset("lake_hume_bloom").unwrap();
    s.width = 600;
    s.height = 400;
    s
}

/// Heron Island's reef, unchanged (it is small).
pub fn reef() -> SceneSpec {
    SceneSpec::preset("heron_island_reef").unwrap()
}

/// A Table 1 instrument cut to `detectors` × `lines`.
pub fn small(name: &str, detectors: usize, lines: usize) -> InstrumentSpec {
    let mut i = InstrumentSpec::preset(name).unwrap();
    i.detectors = detectors;
    i.lines = lines;
    i
}

/// Run `config` in a fresh engine.
pub fn run(config: &RunConfig) -> RunOutput {
    Engine::new().run(config, &RunControl::new()).unwrap()
}

/// `config` run on one thread and on two (determinism tests compare the two).
pub fn on_one_and_two_threads(config: &RunConfig) -> (RunOutput, RunOutput) {
    let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
    (pool(1).install(|| run(config)), pool(2).install(|| run(config)))
}
