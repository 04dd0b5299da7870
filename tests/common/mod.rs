//! What the integration crates share (`#[path = "../common/mod.rs"] mod common;` in each
//! `main.rs`): how a `src/ranges.rs` path is reached in a run configuration.
//!
//! Each crate uses a part of it; the rest is unused there.
#![allow(dead_code)]

use shoal::retrieval::RetrievalSpec;

/// The built-in instrument in which the `ranges` path exists: a spectrograph's or filter
/// imager's `kind` fields need that kind; everything else is on the Table 1 CubeSat.
#[must_use]
pub fn instrument_for(path: &str) -> &'static str {
    if path.contains("Spectrograph") {
        "hyperspectral"
    } else if path.contains("FilterImager") {
        "filter_imager"
    } else {
        "cubesat"
    }
}

/// Both retrievals with their defaults, aLMI first and SAMBUCA second, so every
/// `retrievals[i]` path of the ranges table exists ([`sweep_path`] picks the index).
#[must_use]
pub fn both_retrievals() -> Vec<RetrievalSpec> {
    vec![ron::from_str("Almi()").unwrap(), ron::from_str("Sambuca()").unwrap()]
}

/// A ranges-table path as `sweep::apply` walks it: `[i]` becomes the index of the retrieval
/// the path names in [`both_retrievals`].
#[must_use]
pub fn sweep_path(path: &str) -> String {
    let index = if path.contains("Sambuca") { ".1" } else { ".0" };
    path.replace("[i]", index)
}
