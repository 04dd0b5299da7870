//! A run that restarts at its retrievals from the Rrs alone.
//!
//! A change to the retrievals (a mode, a SIOP set, a band choice) changes nothing before the Rrs.
//! The stage cache restarts a run at its first changed stage only while it holds every product
//! before it — for a full-resolution CubeSat the pupil radiance, Level-0 and Level-1 beside the
//! Rrs, ~0.8 GB — and those large cubes are the first the cache lets go when several designs
//! share it (`Cache::put`). So besides the Rrs (the correction stage's product) each
//! run leaves a [`Restart`]: what the run's output carries from the stages between the scene
//! and the retrievals — the truth maps, the calibration, SNR and feasibility figures, the views
//! of the cubes and the report — a few tens of megabytes beside the Rrs. A later run whose
//! configuration differs only in its retrievals finds both and runs the retrievals alone; its
//! output is the one a full run gives, report included (`tests/chain/restart.rs`).
//!
//! Only the app's engine ([`Engine::for_app`]) restarts so. Not taken: by an engine that hands
//! back its cubes (those are not kept) or a lean one, for a run asking for probes (they read the
//! Level-1), or one injecting a fault.

use std::sync::Arc;
use std::time::Instant;

use super::cache::{Key, KeyBuilder, Stage};
use super::footprint::Footprint;
use super::products::{Corrected, RunOutput, SceneSide};
use super::report::{RunReport, StageReport, StageStatus};
use super::run::Engine;
use super::views::CubeViews;
use super::{EngineError, RunConfig};
use crate::calibration::Calibration;
use crate::control::RunControl;
use crate::instrument::feasibility::Feasibility;
use crate::instrument::{SnrRow, Truth};

/// What a run carries from its stages between the scene and the retrievals, kept to restart at
/// the retrievals.
#[derive(Clone)]
pub(super) struct Restart {
    pub(super) truth: Arc<Truth>,
    pub(super) calibration: Arc<Calibration>,
    pub(super) feasibility: Arc<Feasibility>,
    pub(super) snr: Arc<Vec<SnrRow>>,
    /// The typical water radiance per band the retrievals weight their noise by.
    pub(super) typical: Vec<f64>,
    pub(super) views: Option<Arc<CubeViews>>,
    /// The key the Rrs is kept under ([`Stage::Correction`]).
    pub(super) correction_key: Key,
    /// The report as it stood before the retrievals, and how many of its stages were the scene
    /// side's.
    pub(super) report: RunReport,
    pub(super) scene_stages: usize,
}

impl Restart {
    /// Bytes the cache counts for it: the truth maps and the views (the Rrs is counted under its
    /// own key; the rest does not grow with the image).
    fn bytes(&self) -> usize {
        self.truth.bytes() + self.views.as_ref().map_or(0, |v| v.bytes())
    }
}

impl Engine {
    /// The key of `config`'s [`Restart`]: everything but the retrievals (the configuration,
    /// the files it names, the scene side's keys and what the engine hands back), or `None`
    /// where a run may not restart at its retrievals (see the module docs).
    pub(super) fn restart_key(&self, config: &RunConfig, side: &SceneSide) -> Option<Key> {
        // Only the app's engine (views, no cubes) restarts: a lean engine's small cache keeps no
        // full-resolution Rrs, and its runs would build the key and copy the report for nothing.
        let (keeps_views, _) = self.views_setting();
        if self.keeps_cubes() || !keeps_views || config.fault.is_some() {
            return None;
        }
        let mut upstream = config.clone();
        upstream.retrievals.clear();
        let files = super::files::fingerprint(&upstream, config.scene_dir.as_deref());
        let mut key = KeyBuilder::new(Stage::Correction)
            .with("restart at the retrievals")
            .with(&upstream)
            .with(&files)
            .after(side.band_key);
        if let Some(sensed) = &side.sensed {
            key = key.after(sensed.band_key);
        }
        Some(key.finish())
    }

    /// Keep `restart` under `key`, where the cache kept the Rrs it goes with (a lean engine's
    /// small cache does not keep a full-resolution Rrs, and then keeps no restart either).
    pub(super) fn keep_restart(&mut self, key: Key, restart: Restart) {
        if self.cache_get::<Corrected>(restart.correction_key).is_none() {
            return;
        }
        let bytes = restart.bytes();
        self.cache_put(key, Arc::new(restart), bytes);
    }

    /// The run from its kept [`Restart`] and Rrs, if both are still kept: the retrievals alone.
    /// `report` holds the scene side's stages of this run.
    pub(super) fn run_from_rrs(
        &mut self,
        key: Key,
        config: &RunConfig,
        side: &SceneSide,
        report: &RunReport,
        control: &RunControl,
        start: Instant,
    ) -> Option<Result<RunOutput, EngineError>> {
        let mut kept = self.cache_get::<Restart>(key)?;
        let corrected = self.cache_get::<Corrected>(kept.correction_key)?;
        // Views kept under a larger share than this run's (the app holds more designs than when
        // the run was made) are cut to it, here and in the cache, so the larger ones go.
        let (_, view_bytes) = self.views_setting();
        if let Some(cut) = kept.views.as_ref().and_then(|v| v.within(view_bytes)) {
            let smaller = Restart { views: Some(Arc::new(cut)), ..kept.as_ref().clone() };
            let bytes = smaller.bytes();
            kept = Arc::new(smaller);
            self.cache_put(key, kept.clone(), bytes);
        }
        let mut restored = kept.report.clone();
        // This run's scene side, then the stages the kept products stand for, served from them.
        restored.stages.clone_from(&report.stages);
        restored.stages.extend(kept.report.stages[kept.scene_stages..].iter().map(|s| StageReport {
            stage: s.stage,
            status: StageStatus::Cached,
            seconds: 0.0,
        }));
        let retrievals = self.retrieval_stage(
            config,
            side,
            &kept.truth,
            (&corrected.rrs, kept.correction_key),
            &kept.typical,
            control,
            &mut restored,
        );
        let retrievals = match retrievals {
            Ok(r) => r,
            Err(e) => return Some(Err(e)),
        };
        restored.total_seconds = start.elapsed().as_secs_f64();
        Some(Ok(RunOutput {
            config: config.clone(),
            scene: side.scene.clone(),
            response: side.response.clone(),
            viewing: side.viewing.clone(),
            band_atmosphere: side.band_atmosphere.clone(),
            truth: kept.truth.clone(),
            cubes: None,
            views: kept.views.clone(),
            calibration: kept.calibration.clone(),
            correction: corrected.product.clone(),
            snr: kept.snr.clone(),
            feasibility: kept.feasibility.clone(),
            retrievals,
            probes: Vec::new(),
            report: restored,
        }))
    }
}
