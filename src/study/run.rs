//! Running a study: every instrument and seed through one engine (the scene, its maps and the
//! atmosphere are computed once and shared through the stage cache).

use std::sync::Arc;

use ndarray::{Array2, Array3};

use super::{ResolvedStudy, StudyError};
use crate::control::RunControl;
use crate::engine::{Engine, EngineError, RetrievalOutput, RunOutput, RunReport};
use crate::instrument::SnrRow;

/// The truth under each pixel of a run (the small 2-D maps; the cubes stay with the run).
#[derive(Debug, Clone, PartialEq)]
pub struct Truth {
    /// Chlorophyll-a, mg m⁻³.
    pub chl_mg_m3: Array2<f32>,
    /// NAP, g m⁻³.
    pub nap_g_m3: Array2<f32>,
    /// CDOM, m⁻¹.
    pub cdom_per_m: Array2<f32>,
    /// Depth, m (shallow scenes).
    pub depth_m: Option<Array2<f32>>,
    /// Substrate fractions (shallow scenes).
    pub substrate_fractions: Option<Array3<f32>>,
    /// Substrate names.
    pub substrate_names: Vec<String>,
    /// Land mask.
    pub land: Array2<u8>,
}

/// One run of a study, kept for its tables and figures.
#[derive(Debug, Clone)]
pub struct StudyRun {
    /// Instrument label.
    pub label: String,
    /// Noise seed.
    pub seed: u64,
    /// The run's report.
    pub report: RunReport,
    /// SNR table.
    pub snr: Arc<Vec<SnrRow>>,
    /// Retrieval products and metrics.
    pub retrievals: Vec<Arc<RetrievalOutput>>,
    /// The truth maps.
    pub truth: Truth,
}

/// All runs of a study.
#[derive(Debug, Clone)]
pub struct StudyResult {
    /// The study.
    pub study: ResolvedStudy,
    /// The runs, in instrument then seed order.
    pub runs: Vec<StudyRun>,
}

/// Run every configuration of `study`; `on_run` sees each full run output (to write its cubes)
/// before it is reduced to what the tables and figures need.
pub fn run_study(
    study: &ResolvedStudy,
    control: &RunControl,
    mut on_run: impl FnMut(usize, &RunOutput) -> Result<(), StudyError>,
) -> Result<StudyResult, StudyError> {
    let mut engine = Engine::new();
    let mut runs = Vec::with_capacity(study.runs.len());
    for (i, (label, seed, config)) in study.runs.iter().enumerate() {
        let out = engine.run(config, control).map_err(|e| match e {
            EngineError::Cancelled => StudyError::Cancelled,
            internal @ EngineError::Internal { .. } => {
                StudyError::Internal { instrument: label.clone(), message: internal.to_string() }
            }
            other => StudyError::Run { instrument: label.clone(), message: other.to_string() },
        })?;
        on_run(i, &out)?;
        let r = &out.radiance;
        runs.push(StudyRun {
            label: label.clone(),
            seed: *seed,
            report: out.report.clone(),
            snr: out.snr.clone(),
            retrievals: out.retrievals.clone(),
            truth: Truth {
                chl_mg_m3: r.chl_mg_m3.clone(),
                nap_g_m3: r.nap_g_m3.clone(),
                cdom_per_m: r.cdom_per_m.clone(),
                depth_m: r.depth_m.clone(),
                substrate_fractions: r.substrate_fractions.clone(),
                substrate_names: out.scene.substrates.iter().map(|(n, _)| n.clone()).collect(),
                land: r.land.clone(),
            },
        });
    }
    Ok(StudyResult { study: study.clone(), runs })
}
