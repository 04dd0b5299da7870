//! The engine: the chain as stages with typed products, each cached under a hash of exactly what
//! it reads, so that a change re-runs only the stages downstream of it.
//!
//! ```text
//! Scene ─┐
//! Response ─ Geometry ─┐
//! Lut ── Optics ──── BandAtmosphere ── Radiance ── Electrons ── Level0 ── Level1 ── Correction
//!                                                    Detector ─ Calibration ─┘          Snr
//! ```
//!
//! | stage | reads | product |
//! |---|---|---|
//! | `Scene` | scene file | maps (random fields, images rasterised) |
//! | `Response` | bands, QE, spectral step | photon weights, simulation grids |
//! | `Geometry` | orbit, optics, detectors, decimation, sun | ground points, view angles |
//! | `Lut` | atmosphere, sun, view range | the SOS look-up table |
//! | `Optics` | scene, LUT, grids | water model on the grid, adjacency PSF |
//! | `BandAtmosphere` | optics, geometry | per-column band-effective atmosphere |
//! | `Radiance` | the above, spatial response | pupil band radiance and the truth |
//! | `Detector` | aperture, exposure, transmission, QE, dark, PRNU/DSNU, well, electronics | responsivity |
//! | `Feasibility` | detector, brightest water radiance, line period | f-number, Q, Airy disc, smear, peak/full scale, warnings |
//! | `Electrons` | radiance, photon side of the detector, seed | electrons per pixel |
//! | `Level0` | electrons, read noise, gain, bias, ADC | counts and flags |
//! | `Calibration` | detector, calibration settings, solar spectrum | gain and offset |
//! | `Level1` | Level-0, calibration | calibrated radiance |
//! | `Correction` | Level-1, band atmosphere | Rrs, flags, per-scene approximation |
//! | `Snr` | detector, typical radiance | analytic and measured SNR |
//! | `RetrievalModel` | band atmosphere, retrieval settings, scene SIOP and substrates | SIOP sets and substrates at the bands |
//! | `Retrieval` | Rrs, retrieval model, noise, retrieval settings | products and their metrics |
//!
//! Changing the gain re-runs `Detector`, `Feasibility`, `Level0`, `Calibration`, `Level1`,
//! `Correction`, `Snr` and a configured `Retrieval` (not its model), never the scene, the
//! atmosphere or the photon counts. Effects a scene does not ask for
//! are never computed and the report lists them as skipped. [`worker`] runs the engine on its own
//! thread with its own rayon pool for the app.
//!
//! What a run holds: [`Engine::new`] hands back every cube ([`Cubes`]) and caches them within its
//! byte budget; [`Engine::lean`] (studies) frees each cube once the next stage has read it, makes
//! `Electrons` and `Level0` in one pass row by row (no electrons product), and hands back the truth
//! maps, products, metrics and the pixels asked for ([`Probe`]). A cube nothing else holds (not
//! kept, not cached) is handed to the stage that reads it last: Level-1 takes Level-0's flags, and
//! the correction writes its Rrs over the Level-1 (`correction::Level1Input`).

mod cache;
mod config;
mod correction_stage;
mod effects_stage;
mod fault;
mod files;
pub mod footprint;
mod keys;
mod lut_axes;
pub mod probe;
mod products;
mod report;
pub mod resources;
mod restart;
mod retrieval_stage;
mod run;
mod scene_stages;
pub mod spectrum;
mod stages;
pub mod views;
pub mod worker;

pub use cache::Stage;
pub use config::{DEFAULT_BAND_NODES, DEFAULT_WATER_SINGLE_PRECISION, Fidelity, RunConfig};
pub use fault::{Fault, FaultKind};
pub use lut_axes::lut_axes_covering;
pub use probe::{Probe, Probed};
pub use products::{CorrectionProduct, Cubes, RetrievalOutput, RunOutput};
pub use report::{AerosolSummary, HighGlint, RunReport, StageReport, StageStatus};
pub use run::{APP_LEVELS, Engine, LEAN_CACHE_BYTES};
pub use views::{CubeViews, VIEW_BYTES, ViewOf};

/// An engine failure: the stage and what went wrong (the message names the field).
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum EngineError {
    /// A newer request superseded this run, or the user cancelled it.
    #[error("cancelled")]
    Cancelled,
    /// A stage failed.
    #[error("{stage}: {message}")]
    Failed {
        /// The stage.
        stage: Stage,
        /// What went wrong.
        message: String,
    },
    /// A stage broke: a panic caught at the stage boundary, or an injected fault. Not the
    /// user's input; the pixel is where the stage's per-pixel loop was, when it had one.
    #[error("{stage}: internal error{}: {message}", site.map(|p| format!(" at {p}")).unwrap_or_default())]
    Internal {
        /// The stage.
        stage: Stage,
        /// The pixel the stage was working on.
        site: Option<crate::control::PixelSite>,
        /// What went wrong (the panic's message).
        message: String,
    },
}
