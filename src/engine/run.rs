//! One run of the chain through the stage cache.

use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::time::Instant;

use super::cache::{Cache, Key, Stage};
use super::footprint::Footprint;
use super::probe::{Probe, Probed};
use super::products::{Cubes, RunOutput};
use super::report::{RunReport, StageReport, StageStatus};
use super::views::CubeViews;
use super::{EngineError, Fault, FaultKind, RunConfig};
use crate::control::{PixelSite, RunControl};

/// The engine: a stage cache and execution counters.
#[derive(Debug)]
pub struct Engine {
    cache: Cache,
    executions: HashMap<Stage, u64>,
    /// The fault the current run injects, if any.
    fault: Option<Fault>,
    /// Whether a run hands back its full-resolution cubes ([`RunOutput::cubes`]).
    keep_cubes: bool,
    /// Whether a run hands back every n-th pixel of its cubes ([`RunOutput::views`]).
    keep_views: bool,
    /// The most a run's views may hold, bytes.
    view_bytes: usize,
}

impl Default for Engine {
    fn default() -> Self {
        Self {
            cache: Cache::default(),
            executions: HashMap::new(),
            fault: None,
            keep_cubes: true,
            keep_views: false,
            view_bytes: super::views::VIEW_BYTES,
        }
    }
}

/// The cache budget of [`Engine::lean`]: the scene's maps, the atmosphere, the small products and
/// a run's retrieval products, not a cube of a full-resolution image (a 1024 × 2000 × 19 f32
/// cube is 156 MB; its Level-0 counts and flags 117 MB).
pub const LEAN_CACHE_BYTES: usize = 64 << 20;

/// The decimations the app's cache keeps a large product of per design: its default levels are
/// a coarse preview, a finer one and full resolution (`app::model`), and one more for a user's.
pub const APP_LEVELS: usize = 4;

/// Stages whose per-pixel loops report the pixel they fail at (an injected panic fires there).
const PIXEL_STAGES: [Stage; 6] =
    [Stage::Radiance, Stage::Electrons, Stage::Level0, Stage::Level1, Stage::Correction, Stage::Retrieval];

impl Engine {
    /// An engine with an empty, unbounded cache whose runs keep their cubes (what the app's
    /// incremental reruns and `shoal simulate` want).
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// An engine for runs that keep products, not cubes (studies, sweeps, searches): each cube
    /// is freed as soon as the next stage has read it, and the cache keeps at most
    /// [`LEAN_CACHE_BYTES`].
    #[must_use]
    pub fn lean() -> Self {
        Self { keep_cubes: false, ..Self::default() }.with_cache_budget(LEAN_CACHE_BYTES)
    }

    /// An engine for the app: runs keep products and views of their cubes at a bounded size
    /// ([`super::views::VIEW_BYTES`], or less: [`Self::set_view_bytes`]), not the cubes; the
    /// cache keeps at most `cache_bytes` and up to `designs` cubes per stage at each of
    /// [`APP_LEVELS`] decimations. A change restarts
    /// mid-chain where the cache still holds every product before it; a change to the
    /// retrievals alone restarts from the run's kept Rrs ([`super::restart`]).
    #[must_use]
    pub fn for_app(cache_bytes: usize, designs: usize) -> Self {
        let mut engine = Self { keep_cubes: false, keep_views: true, ..Self::default() };
        engine.cache = Cache::with_budget(cache_bytes).with_large_capacity(APP_LEVELS * designs.max(1));
        engine
    }

    /// Views of the cubes kept under `bytes` per run instead of [`super::views::VIEW_BYTES`]
    /// (tests use it to see a stride above 1 on a small image).
    #[must_use]
    pub fn with_view_bytes(mut self, bytes: usize) -> Self {
        self.view_bytes = bytes;
        self
    }

    /// Keep the views of later runs under `bytes` per run (the app: its designs' share of
    /// [`super::views::ALL_VIEW_BYTES`]).
    pub fn set_view_bytes(&mut self, bytes: usize) {
        self.view_bytes = bytes;
    }

    /// The same engine, its cache emptied and bounded to `bytes` (products past it are dropped,
    /// least recently used first).
    #[must_use]
    pub fn with_cache_budget(mut self, bytes: usize) -> Self {
        self.cache = Cache::with_budget(bytes);
        self
    }

    /// Bound the cache to `bytes` from now on, letting the least recently used products go.
    pub fn set_cache_budget(&mut self, bytes: usize) {
        self.cache.set_budget(bytes);
    }

    /// Whether runs hand back views of their cubes, and their most bytes.
    pub(super) fn views_setting(&self) -> (bool, usize) {
        (self.keep_views, self.view_bytes)
    }

    /// The product kept under `key`, if any.
    pub(super) fn cache_get<T: Send + Sync + 'static>(&mut self, key: Key) -> Option<Arc<T>> {
        self.cache.get(key)
    }

    /// Keep `product` (of `bytes`) under `key`, within the cache's budget.
    pub(super) fn cache_put<T: Send + Sync + 'static>(&mut self, key: Key, product: Arc<T>, bytes: usize) {
        self.cache.put(key, product, bytes);
    }

    /// Whether runs hand back their full-resolution cubes.
    #[must_use]
    pub fn keeps_cubes(&self) -> bool {
        self.keep_cubes
    }

    /// Set whether runs hand back their full-resolution cubes ([`RunOutput::cubes`]).
    pub fn keep_cubes(&mut self, keep: bool) {
        self.keep_cubes = keep;
    }

    /// Bytes the cache holds now.
    #[must_use]
    pub fn cached_bytes(&self) -> usize {
        self.cache.bytes()
    }

    /// How many times `stage` has been computed (not served from the cache) by this engine.
    #[must_use]
    pub fn executions(&self, stage: Stage) -> u64 {
        self.executions.get(&stage).copied().unwrap_or(0)
    }

    /// Products the cache holds now (bounded by the sum of [`Stage::capacity`]).
    #[must_use]
    pub fn cached_products(&self) -> usize {
        self.cache.len()
    }

    /// Forget every cached product.
    pub fn clear(&mut self) {
        self.cache.clear();
    }

    /// Serve the product of `key`'s stage from the cache, or compute it with `f` (timed, counted, and
    /// guarded: a panic inside a stage becomes an error naming the stage).
    pub(super) fn stage<T, F>(
        &mut self,
        key: Key,
        report: &mut RunReport,
        control: &RunControl,
        f: F,
    ) -> Result<Arc<T>, EngineError>
    where
        T: Footprint + Send + Sync + 'static,
        F: FnOnce() -> Result<T, EngineError>,
    {
        if control.cancelled() {
            return Err(EngineError::Cancelled);
        }
        let stage = key.stage;
        if let Some(product) = self.cache.get::<T>(key) {
            report.stages.push(StageReport { stage, status: StageStatus::Cached, seconds: 0.0 });
            return Ok(product);
        }
        let start = Instant::now();
        control.begin_stage(stage.name());
        let fault = self.fault.filter(|f| f.stage == stage);
        if let Some(f) = fault {
            match f.kind {
                FaultKind::Error => {
                    let site = Some(PixelSite { row: f.row, column: Some(f.column) });
                    return Err(EngineError::Internal { stage, site, message: "injected error".into() });
                }
                FaultKind::Panic => control.arm_panic(f.row, f.column),
            }
        }
        let pixel_loops = PIXEL_STAGES.contains(&stage);
        let guarded = catch_unwind(AssertUnwindSafe(|| {
            assert!(fault.is_none() || pixel_loops, "injected fault on entry to {stage}");
            f()
        }));
        control.disarm();
        let product = match guarded {
            Ok(result) => Arc::new(result?),
            Err(panic) => {
                let message = panic
                    .downcast_ref::<&str>()
                    .map(|s| (*s).to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "unknown panic".into());
                return Err(EngineError::Internal { stage, site: control.take_site(), message });
            }
        };
        *self.executions.entry(stage).or_default() += 1;
        report.stages.push(StageReport { stage, status: StageStatus::Ran, seconds: start.elapsed().as_secs_f64() });
        let bytes = product.bytes();
        self.cache.put(key, product.clone(), bytes);
        Ok(product)
    }

    /// Run the chain for `config`, reusing every stage whose inputs did not change. Checks
    /// `control` between stages and between rows of the heavy ones.
    pub fn run(&mut self, config: &RunConfig, control: &RunControl) -> Result<RunOutput, EngineError> {
        self.run_with(config, control, &[])
    }

    /// A run's start: its clock, the configuration as flown (on-board binning folded into its
    /// pixels: what every stage simulates and the output reports), its report and its scene side.
    fn begin<'c>(
        &mut self,
        config: &'c RunConfig,
        control: &RunControl,
    ) -> Result<(Instant, std::borrow::Cow<'c, RunConfig>, RunReport, super::products::SceneSide), EngineError> {
        let start = Instant::now();
        self.cache.begin_run();
        self.fault = config.fault;
        config.validate_keeping(self.keep_cubes)?;
        let flown = config.flown();
        let mut report = report_for(&flown);
        let side = self.scene_side(&flown, control, &mut report)?;
        Ok((start, flown, report, side))
    }

    /// The run of `config` from its kept Rrs and [`super::restart`]'s record alone, or `None`
    /// where this engine keeps none for it (nothing before the retrievals is computed: what the
    /// app asks for a design on screen whose views it cuts to a smaller share).
    pub fn run_restart_only(
        &mut self,
        config: &RunConfig,
        control: &RunControl,
    ) -> Result<Option<RunOutput>, EngineError> {
        let (start, flown, report, side) = self.begin(config, control)?;
        let Some(key) = self.restart_key(&flown, &side) else { return Ok(None) };
        self.run_from_rrs(key, &flown, &side, &report, control, start).transpose()
    }

    /// [`Self::run`], keeping the Level-1 radiance and the corrected Rrs of the pixels `probes`
    /// name ([`RunOutput::probes`]), whether or not the run keeps its cubes.
    pub fn run_with(
        &mut self,
        config: &RunConfig,
        control: &RunControl,
        probes: &[Probe],
    ) -> Result<RunOutput, EngineError> {
        let (start, flown, mut report, side) = self.begin(config, control)?;
        let config: &RunConfig = &flown;
        // A run that differs from a kept one only in its retrievals restarts at them.
        let restart_key = self.restart_key(config, &side);
        let scene_stages = report.stages.len();
        if let Some(key) = restart_key.filter(|_| probes.is_empty())
            && let Some(output) = self.run_from_rrs(key, config, &side, &report, control, start)
        {
            return output;
        }
        let (mut radiance, radiance_key) = self.radiance_stage(config, &side, control, &mut report)?;
        let truth = radiance.truth.clone();
        let typical = radiance.typical_water_w_m2_sr_nm.clone();
        // Three reads of the radiance product, each on one thread, run side by side:
        // - the probes' pixels (the typical water pixel: a selection over the chl map);
        // - the paper's per-scene approximation, which reads the pupil radiance at a few hundred
        //   pixels: taken now, so that the pupil radiance cube can go once the detector has seen
        //   it;
        // - the pixels the correction compares with the truth: a run that keeps no cubes then
        //   lets the true Rrs cube go before the detector reads out (unless the cache keeps the
        //   radiance product: then it is the cache's to hold).
        let ((mut probed, approximation), truth_rrs) = rayon::join(
            || {
                rayon::join(
                    || probes.iter().map(|p| Probed::locate(*p, &truth, &side.viewing)).collect::<Vec<Probed>>(),
                    || {
                        crate::correction::SceneApproximation::new(
                            &radiance.radiance,
                            &radiance.truth_rrs,
                            &side.band_atmosphere,
                            &truth.surface,
                            config.correction.approx_points,
                            config.seed,
                        )
                    },
                )
            },
            || crate::correction::TruthRrsSample::of(&radiance.truth_rrs, &truth.surface),
        );
        let approximation = approximation.map_err(super::stages::failed(Stage::Correction))?;
        let mut views = self.keep_views.then(|| {
            let (rows, cols, bands) = radiance.radiance.dim();
            CubeViews::of_radiance(&radiance, super::views::stride_for(rows, cols, bands, self.view_bytes))
        });
        if !self.keep_cubes
            && let Some(product) = Arc::get_mut(&mut radiance)
        {
            product.truth_rrs = Arc::default();
        }
        let mut inst = self.instrument_side(config, &side, radiance, radiance_key, control, &mut report)?;
        let kept_radiance = inst.radiance.take();
        // Each cube is let go once read (the cache may still keep it, within its budget).
        let kept_level0 = inst.level0.take();
        if let Some(level1) = &inst.level1 {
            probed.iter_mut().for_each(|p| p.read_level1(level1));
            if let Some(v) = &mut views {
                v.keep_level1(level1);
            }
        }
        // The Level-1 goes to the correction, which writes the Rrs over it where nothing else
        // holds it (a run that keeps no cubes, whose cache let it go).
        let level1 = if self.keep_cubes { inst.level1.clone() } else { inst.level1.take() };
        let (corrected, correction_key) = self.correction_stage(
            config,
            &side,
            (&truth, &truth_rrs, radiance_key),
            approximation,
            (level1, inst.level1_key),
            control,
            &mut report,
        )?;
        drop(truth_rrs);
        probed.iter_mut().for_each(|p| p.read_rrs(&corrected.rrs));
        if let Some(v) = &mut views {
            v.keep_rrs(&corrected.rrs);
        }
        let kept_level1 = inst.level1.take().filter(|_| self.keep_cubes);
        let (snr, typical) = self.snr_stage(config, &side, typical, &inst, control, &mut report)?;
        let before_retrievals = restart_key.map(|_| (report.clone(), typical.clone()));
        let retrievals = self.retrieval_stage(
            config,
            &side,
            &truth,
            (&corrected.rrs, correction_key),
            &typical,
            control,
            &mut report,
        )?;
        let cubes = match (kept_radiance, kept_level0, kept_level1) {
            (Some(radiance), Some(level0), Some(level1)) => {
                Some(Cubes { radiance, level0, level1, rrs: corrected.rrs.clone() })
            }
            _ => None,
        };
        let views = views.map(Arc::new);
        if let (Some(key), Some((report, typical))) = (restart_key, before_retrievals) {
            let restart = super::restart::Restart {
                truth: truth.clone(),
                calibration: inst.calibration.clone(),
                feasibility: inst.feasibility.clone(),
                snr: snr.clone(),
                typical,
                views: views.clone(),
                correction_key,
                report,
                scene_stages,
            };
            self.keep_restart(key, restart);
        }
        report.total_seconds = start.elapsed().as_secs_f64();
        Ok(RunOutput {
            config: config.clone(),
            scene: side.scene,
            response: side.response,
            viewing: side.viewing.clone(),
            band_atmosphere: side.band_atmosphere.clone(),
            truth,
            cubes,
            views,
            calibration: inst.calibration,
            correction: corrected.product.clone(),
            snr,
            feasibility: inst.feasibility,
            retrievals,
            probes: probed,
            report,
        })
    }
}

/// A run's report before its stages: what it runs.
fn report_for(config: &RunConfig) -> RunReport {
    RunReport {
        scene: config.scene.name.clone(),
        instrument: config.instrument.name.clone(),
        decimation: config.fidelity.decimation,
        ..RunReport::default()
    }
}
