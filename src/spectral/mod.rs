//! Spectral foundation: wavelength grids, tabulated spectra, band sets and the
//! `band_from_fine` averaging matrix.
//!
//! Two spectral "spaces" run through Shoal: `_fine` quantities live on a [`WavelengthGrid`]
//! (350–1000 nm, 1 nm by default; coarser steps trade accuracy for time) and `_band`
//! quantities live on a sensor's [`BandSet`]. The only way from one to the other is
//! [`BandAverager`] (`band_from_fine`), built once per grid and band set.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | λ, `wavelength_nm` | vacuum wavelength | nm |
//! | SRF | spectral response function (relative) | – |
//! | FWHM | full width at half maximum | nm |
//!
//! ## References
//! - ESA (2016) Sentinel-3 OLCI spectral response functions, `S3A_OL_SRF_20160713_mean_rsr`.
//! - ESA (2024) Sentinel-2 Spectral Response Functions, COPE-GSEG-EOPG-TN-15-0007 v4.0.

mod averager;
mod bands;
mod grid;
mod source;
mod spectrum;
mod table;

pub use averager::BandAverager;
pub use bands::{Band, BandSet, BandSetSpec, GaussianBand, Platform};
pub use grid::WavelengthGrid;
pub use source::SpectrumSource;
pub use spectrum::{Extrapolation, Spectrum};
pub use table::Table;

/// Errors from the spectral layer. Every variant names what was wrong and what is allowed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum SpectralError {
    /// A wavelength grid setting out of range.
    #[error("wavelength grid: {field} = {value} is out of range ({allowed})")]
    Grid {
        /// The offending setting.
        field: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, in words.
        allowed: String,
    },
    /// A malformed table.
    #[error("{origin}: line {line}: {message}")]
    Table {
        /// File or asset name.
        origin: String,
        /// 1-based line number (0 when not tied to a line).
        line: usize,
        /// What was wrong.
        message: String,
    },
    /// A column that the table does not have.
    #[error("{origin}: no column `{column}` (columns: {known})")]
    UnknownColumn {
        /// File or asset name.
        origin: String,
        /// The requested column.
        column: String,
        /// The columns there are.
        known: String,
    },
    /// An asset path that is not embedded.
    #[error("no embedded asset `{name}` (known: {known})")]
    UnknownAsset {
        /// The requested path.
        name: String,
        /// The embedded paths.
        known: String,
    },
    /// A file that could not be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// The path.
        path: String,
        /// The OS error.
        message: String,
    },
    /// A spectrum that does not cover the wavelengths asked of it.
    #[error(
        "spectrum `{name}` covers {min_nm}–{max_nm} nm but {wavelength_nm} nm was requested \
         (extend the data or use a grid inside its range)"
    )]
    OutOfRange {
        /// The spectrum's name.
        name: String,
        /// Requested wavelength.
        wavelength_nm: f64,
        /// Data minimum.
        min_nm: f64,
        /// Data maximum.
        max_nm: f64,
    },
    /// A spectrum that is not usable (unsorted, too short, non-finite).
    #[error("spectrum `{name}`: {message}")]
    BadSpectrum {
        /// The spectrum's name.
        name: String,
        /// What was wrong.
        message: String,
    },
    /// A band set that cannot be built.
    #[error("band set: {0}")]
    Bands(String),
}
