//! Physics and command-line tests: against reference codes (SAMBUCA, OSOAA, 6SV), physical
//! limits, determinism and bad input. One test crate, so that CI links one binary.

// Test helpers outside `#[test]` functions may panic on broken fixtures: that is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod aerosol;
mod almi_reference;
mod atmosphere_limits;
mod cli;
mod missions;
mod osoaa;
mod qaa;
mod sambuca;
mod sambuca_reference;
mod sambuca_starts;
mod sixs_swir;
mod user_aerosol;
mod water_limits;

/// Path of a file under `tests/data/`.
pub fn data(path: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(path)
}
