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
use crate::instrument::{AotNodes, Detector, Level0, RadianceCube, Response, SnrRow, Truth, Viewing};
use crate::metrics::ProductMetrics;
use crate::retrieval::{Product, RetrievalSpec};
use crate::scene::Scene;
use crate::toa::SceneOptics;

/// The atmospheric correction stage's product as the cache keeps it: the delivered Rrs cube
/// (exact, the approximation when the config asks for it, or the image-based correction's) and
/// the diagnostics. A run hands on the diagnostics always and the cube only when it keeps its
/// cubes.
#[derive(Debug)]
pub(super) struct Corrected {
    /// The delivered Rrs.
    pub(super) rrs: Arc<Reflectance>,
    /// What the correction found about it.
    pub(super) product: Arc<CorrectionProduct>,
}

/// The atmospheric correction's diagnostics (the Rrs cube itself is [`Cubes::rrs`]).
#[derive(Debug, Clone)]
pub struct CorrectionProduct {
    /// The paper's per-scene approximation terms (none when the image holds no water).
    pub approximation: Option<SceneApproximation>,
    /// Per band: approximation against exact correction.
    pub approximation_vs_exact: Vec<crate::correction::BandDifference>,
    /// Per band: delivered Rrs against the truth ([`crate::correction::compare_with_truth`]).
    pub rrs_vs_truth: Vec<crate::correction::BandDifference>,
    /// Per band: the delivered Rrs against the truth, log-space metrics.
    pub rrs_metrics: Vec<crate::correction::BandRrsMetrics>,
    /// What the image-based correction found (AOT and Ångström per pixel), when it ran.
    pub aerosol: Option<crate::correction::AerosolRetrieval>,
    /// The image-based correction's aerosol family, when it ran.
    pub family: Option<Arc<crate::correction::AerosolFamily>>,
    /// The exact correction's high-glint mask, where it has a threshold and the scene glints.
    pub exact_high_glint: Option<super::HighGlint>,
}

/// The full-resolution cubes of a run: what `shoal simulate` and a study with cubes write, and
/// what a spectrum at a pixel reads. Held only by an engine that keeps cubes
/// ([`super::Engine::keep_cubes`]); a run that does not keep them holds its products, metrics
/// and truth maps, and frees each cube as soon as the next stage has read it.
#[derive(Debug, Clone)]
pub struct Cubes {
    /// Pupil radiance (and the true Rrs).
    pub radiance: Arc<RadianceCube>,
    /// Level-0.
    pub level0: Arc<Level0>,
    /// Level-1.
    pub level1: Arc<Level1>,
    /// The delivered Rrs.
    pub rrs: Arc<Reflectance>,
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
    /// The truth under each pixel (maps; the true Rrs cube is in [`Cubes::radiance`]).
    pub truth: Arc<Truth>,
    /// The full-resolution cubes, when the engine keeps them.
    pub cubes: Option<Cubes>,
    /// Every n-th pixel of the cubes, when the engine keeps views ([`super::Engine::for_app`]).
    pub views: Option<Arc<super::views::CubeViews>>,
    /// Calibration coefficients.
    pub calibration: Arc<Calibration>,
    /// The correction's diagnostics.
    pub correction: Arc<CorrectionProduct>,
    /// SNR per band.
    pub snr: Arc<Vec<SnrRow>>,
    /// Feasibility figures of the design over this scene (f-number, Q, smear, peak signal).
    pub feasibility: Arc<Feasibility>,
    /// Retrieved products and their metrics, one per configured retrieval.
    pub retrievals: Vec<Arc<RetrievalOutput>>,
    /// The pixels the run was asked to keep ([`super::Engine::run_with`]).
    pub probes: Vec<super::probe::Probed>,
    /// The report.
    pub report: RunReport,
}

impl RunOutput {
    /// The true map of `variable` (a key of [`crate::variable`]): the scene's chl, NAP, CDOM or
    /// depth, or what the first retrieval says the truth of its own product is
    /// ([`RetrievalOutput::extra_truths`]: QAA's IOPs); `None` where there is none.
    #[must_use]
    pub fn truth_map(&self, variable: &str) -> Option<&ndarray::Array2<f32>> {
        self.truth.map(variable).or_else(|| {
            let extras = &self.retrievals.first()?.extra_truths;
            extras.iter().find(|(k, _)| k == variable).map(|(_, m)| m)
        })
    }
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
    /// The true maps of the extra products the retrieval says the truth of, by key
    /// ([`crate::retrieval::Prepared::extra_truths`]: QAA's IOPs); scored in `metrics`, kept for
    /// the maps.
    pub extra_truths: Vec<(String, ndarray::Array2<f32>)>,
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
    /// The bands the instrument really has, where they differ from the stated ones.
    pub(super) sensed: Option<Sensed>,
}

/// The scene seen through the bands the instrument really has, where the processor's knowledge
/// of them is wrong (a spectral knowledge error): the radiance is sampled, and the detector
/// and its calibration frames respond, through these.
pub(super) struct Sensed {
    pub(super) response: Arc<Response>,
    pub(super) band_atmosphere: Arc<BandAtmosphere>,
    pub(super) aerosol_map: Option<Arc<AotNodes>>,
    /// The key of its band atmosphere (and AOT nodes): after the stated one's.
    pub(super) band_key: Key,
}

impl SceneSide {
    /// The response, band atmosphere, AOT nodes and key the scene is sampled with: the true
    /// bands' where they differ, else the stated ones.
    pub(super) fn sampled(&self) -> (&Arc<Response>, &Arc<BandAtmosphere>, Option<&AotNodes>, Key) {
        match &self.sensed {
            Some(s) => (&s.response, &s.band_atmosphere, s.aerosol_map.as_deref(), s.band_key),
            None => (&self.response, &self.band_atmosphere, self.aerosol_map.as_deref(), self.band_key),
        }
    }
}

/// Products of the instrument side and the keys later stages build on.
pub(super) struct InstrumentSide {
    /// The pupil radiance, when the run keeps its cubes.
    pub(super) radiance: Option<Arc<RadianceCube>>,
    pub(super) detector: Arc<Detector>,
    pub(super) detector_key: Key,
    pub(super) feasibility: Arc<Feasibility>,
    /// Level-0, until the run lets it go.
    pub(super) level0: Option<Arc<Level0>>,
    pub(super) calibration: Arc<Calibration>,
    /// Level-1, until the run lets it go.
    pub(super) level1: Option<Arc<Level1>>,
    pub(super) level1_key: Key,
}
