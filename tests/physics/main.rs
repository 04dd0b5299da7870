//! Physics tests against reference codes and physical limits. One test crate (modules below)
//! so that CI links one binary.

mod sambuca;
mod water_limits;

/// Path of a file under `tests/data/`.
pub fn data(path: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(path)
}
