//! One run of the chain through the stage cache.

use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::time::Instant;

use super::cache::{Cache, Key, Stage};
use super::products::RunOutput;
use super::report::{RunReport, StageReport, StageStatus};
use super::{EngineError, Fault, FaultKind, RunConfig};
use crate::control::{PixelSite, RunControl};

/// The engine: a stage cache and execution counters.
#[derive(Debug, Default)]
pub struct Engine {
    cache: Cache,
    executions: HashMap<Stage, u64>,
    /// The fault the current run injects, if any.
    fault: Option<Fault>,
}

/// Stages whose per-pixel loops report the pixel they fail at (an injected panic fires there).
const PIXEL_STAGES: [Stage; 6] =
    [Stage::Radiance, Stage::Electrons, Stage::Level0, Stage::Level1, Stage::Correction, Stage::Retrieval];

impl Engine {
    /// An engine with an empty cache.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
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
        T: Send + Sync + 'static,
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
        self.cache.put(key, product.clone());
        Ok(product)
    }

    /// Run the chain for `config`, reusing every stage whose inputs did not change. Checks
    /// `control` between stages and between rows of the heavy ones.
    pub fn run(&mut self, config: &RunConfig, control: &RunControl) -> Result<RunOutput, EngineError> {
        let start = Instant::now();
        self.fault = config.fault;
        config.validate()?;
        let mut report = RunReport {
            scene: config.scene.name.clone(),
            instrument: config.instrument.name.clone(),
            decimation: config.fidelity.decimation,
            ..RunReport::default()
        };
        let side = self.scene_side(config, control, &mut report)?;
        let (radiance, radiance_key) = self.radiance_stage(config, &side, control, &mut report)?;
        let inst = self.instrument_side(config, &side, &radiance, radiance_key, control, &mut report)?;
        let (correction, correction_key) =
            self.correction_stage(config, &side, &radiance, radiance_key, &inst, control, &mut report)?;
        let (snr, typical) = self.snr_stage(config, &side, &radiance, &inst, control, &mut report)?;
        let retrievals = self.retrieval_stage(
            config,
            &side,
            &radiance,
            (&correction, correction_key),
            &typical,
            control,
            &mut report,
        )?;
        report.total_seconds = start.elapsed().as_secs_f64();
        Ok(RunOutput {
            config: config.clone(),
            scene: side.scene,
            response: side.response,
            viewing: side.viewing.clone(),
            band_atmosphere: side.band_atmosphere.clone(),
            radiance,
            level0: inst.level0,
            calibration: inst.calibration,
            level1: inst.level1,
            correction,
            snr,
            feasibility: inst.feasibility,
            retrievals,
            report,
        })
    }
}
