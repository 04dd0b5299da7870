//! The products of the chain's stages, as they travel between stages and out of a run: the
//! correction's and the retrievals' products, the whole run's output, and the groups of products
//! (with their keys) that one group of stages hands to the next. Data only; the stages that make
//! them are in `stages.rs` and `retrieval_stage.rs`.

use std::sync::Arc;

use super::RunConfig;
use super::cache::Key;
use super::report::RunReport;
use crate::calibration::{Calibration, Level1};
use crate::correction::{Reflectance, SceneApproximation};
use crate::instrument::feasibility::Feasibility;
use crate::instrument::sample::BandAtmosphere;
use crate::instrument::{AotNodes, Detector, Level0, RadianceCube, Response, SnrRow, Viewing};
use crate::metrics::ProductMetrics;
use crate::retrieval::{Product, RetrievalSpec};
use crate::scene::Scene;
use crate::toa::SceneOptics;

/// The atmospheric correction stage's product.
#[derive(Debug, Clone)]
pub struct CorrectionProduct {
    /// The delivered Rrs (exact, or the approximation when the config asks for it).
    pub rrs: Reflectance,
    /// The paper's per-scene approximation terms.
    pub approximation: SceneApproximation,
    /// Per band: approximation against exact correction.
    pub approximation_vs_exact: Vec<crate::correction::BandDifference>,
    /// Per band: delivered Rrs against the truth.
    pub rrs_vs_truth: Vec<crate::correction::BandDifference>,
    /// Per band: the delivered Rrs against the truth, log-space metrics.
    pub rrs_metrics: Vec<crate::correction::BandRrsMetrics>,
    /// What the image-based correction found (AOT and Ångström per pixel), when it ran.
    pub aerosol: Option<crate::correction::AerosolRetrieval>,
    /// The image-based correction's aerosol family, when it ran.
    pub family: Option<Arc<crate::correction::AerosolFamily>>,
}

/// Everything a run produced (shared with the cache: cheap to clone).
#[derive(Debug, Clone)]
pub struct RunOutput {
    /// The configuration it ran.
    pub config: RunConfig,
    /// The scene.
    pub scene: Arc<Scene>,
    /// The instrument's spectral response.
    pub response: Arc<Response>,
    /// The viewing geometry.
    pub viewing: Arc<Viewing>,
    /// The band-effective atmosphere of each column (what the exact correction used).
    pub band_atmosphere: Arc<BandAtmosphere>,
    /// Pupil radiance and truth.
    pub radiance: Arc<RadianceCube>,
    /// Level-0.
    pub level0: Arc<Level0>,
    /// Calibration coefficients.
    pub calibration: Arc<Calibration>,
    /// Level-1.
    pub level1: Arc<Level1>,
    /// Rrs and the correction's diagnostics.
    pub correction: Arc<CorrectionProduct>,
    /// SNR per band.
    pub snr: Arc<Vec<SnrRow>>,
    /// Feasibility figures of the design over this scene (f-number, Q, smear, peak signal).
    pub feasibility: Arc<Feasibility>,
    /// Retrieved products and their metrics, one per configured retrieval.
    pub retrievals: Vec<Arc<RetrievalOutput>>,
    /// The report.
    pub report: RunReport,
}

/// One retrieval's product and its metrics.
#[derive(Debug, Clone)]
pub struct RetrievalOutput {
    /// What ran.
    pub spec: RetrievalSpec,
    /// The product maps.
    pub product: Product,
    /// The metrics against the truth.
    pub metrics: ProductMetrics,
    /// The band responses the retrieval integrated over.
    pub bands: Vec<crate::retrieval::BandResponse>,
    /// The noise-equivalent ΔRrs per band it weighted with, sr⁻¹.
    pub nedr: Vec<f64>,
    /// Why the retrieval returned nothing, when its program failed (an external retrieval:
    /// the rest of the run is kept, and this says what went wrong).
    pub failure: Option<String>,
}

/// Products of the scene side of the chain and their keys.
pub(super) struct SceneSide {
    pub(super) scene: Arc<Scene>,
    pub(super) response: Arc<Response>,
    pub(super) response_key: Key,
    pub(super) viewing: Arc<Viewing>,
    /// The viewing geometry's key (after the response and the scene).
    pub(super) geometry_key: Key,
    pub(super) optics: Arc<Vec<SceneOptics>>,
    pub(super) band_atmosphere: Arc<BandAtmosphere>,
    /// The band terms at AOT nodes, where the scene's AOT is a map.
    pub(super) aerosol_map: Option<Arc<AotNodes>>,
    /// The band atmosphere's key (and the AOT nodes', where there are any).
    pub(super) band_key: Key,
}

/// Products of the instrument side and the keys later stages build on.
pub(super) struct InstrumentSide {
    pub(super) detector: Arc<Detector>,
    pub(super) detector_key: Key,
    pub(super) feasibility: Arc<Feasibility>,
    pub(super) level0: Arc<Level0>,
    pub(super) calibration: Arc<Calibration>,
    pub(super) level1: Arc<Level1>,
    pub(super) level1_key: Key,
}
