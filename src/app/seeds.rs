//! The seed spread of the metrics in the app: every design as shown, rerun over several
//! detector-noise seeds on a helper thread, so the table can say how far one noise draw's MAE is from another's
//! (`study::spread_of_runs`, the same reduction `shoal study` writes to seed_spread.csv).
//!
//! The spread belongs to the designs it was measured for: after any edit it is marked stale and
//! no longer shown beside the metrics.

use std::sync::Arc;

use crate::engine::{Engine, RetrievalOutput, RunConfig};
use crate::jobs::{Task, TaskNews};
use crate::study::{SeedSpread, spread_of_runs};

/// One finished run: instrument index (0 = A) and its retrievals.
type SeedRun = (usize, Vec<Arc<RetrievalOutput>>);

/// The seed-spread job and its result.
pub struct SeedSpreadJob {
    /// Seeds per instrument (2–20).
    pub seeds: u64,
    /// Decimation of the runs (1 = full resolution).
    pub decimation: usize,
    task: Option<Task<SeedRun>>,
    runs: Vec<SeedRun>,
    /// The configurations measured (seed left at the first), to tell a stale spread.
    measured: Option<Vec<RunConfig>>,
    spread: Vec<SeedSpread>,
    /// What the job is doing or did.
    pub status: String,
    total: usize,
}

impl Default for SeedSpreadJob {
    fn default() -> Self {
        Self {
            seeds: 5,
            decimation: 4,
            task: None,
            runs: Vec::new(),
            measured: None,
            spread: Vec::new(),
            status: String::new(),
            total: 0,
        }
    }
}

/// Configurations compared without their noise seed (the job varies it).
fn unseeded(configs: &[RunConfig]) -> Vec<RunConfig> {
    configs
        .iter()
        .map(|c| {
            let mut c = c.clone();
            c.seed = 0;
            c
        })
        .collect()
}

impl SeedSpreadJob {
    /// Is the job running?
    #[must_use]
    pub fn busy(&self) -> bool {
        self.task.is_some()
    }

    /// Runs finished of the job in flight (or of the last job), and how many it has.
    #[must_use]
    pub fn progress(&self) -> (usize, usize) {
        (self.runs.len(), self.total)
    }

    /// Rerun `configs` (the designs) over seeds 1..=`self.seeds` at 1/`self.decimation`.
    pub fn start(&mut self, ctx: &egui::Context, configs: &[RunConfig]) {
        let seeds = self.seeds.clamp(2, 20);
        let decimation = self.decimation.clamp(1, 64);
        let jobs: Vec<(usize, RunConfig)> = configs
            .iter()
            .enumerate()
            .flat_map(|(i, c)| {
                (1..=seeds).map(move |seed| {
                    let mut c = c.clone();
                    c.seed = seed;
                    c.fidelity.decimation = decimation;
                    (i, c)
                })
            })
            .collect();
        self.runs.clear();
        self.spread.clear();
        self.total = jobs.len();
        self.measured = Some(unseeded(configs));
        self.status = format!("running {} runs at 1/{decimation}", jobs.len());
        let wake = ctx.clone();
        let task = Task::spawn(
            "shoal-seeds",
            move || wake.request_repaint(),
            move |control, send| {
                let mut engine = Engine::new();
                for (i, config) in &jobs {
                    let out = engine.run(config, control).map_err(|e| e.to_string())?;
                    send((*i, out.retrievals.clone()));
                }
                Ok(())
            },
        );
        match task {
            Ok(t) => self.task = Some(t),
            Err(e) => self.status = e,
        }
    }

    /// Stop the runs in flight (dropping the task cancels it) and forget their partial results.
    pub fn cancel(&mut self) {
        self.task = None;
        self.runs.clear();
        self.measured = None;
        self.status = "cancelled".into();
    }

    /// Take what the helper thread sent; the spread is computed when the last run is in.
    pub fn poll(&mut self) {
        let Some(task) = &self.task else { return };
        let mut finished = None;
        while let Some(news) = task.poll() {
            match news {
                TaskNews::Item(run) => self.runs.push(run),
                TaskNews::Done(r) => finished = Some(r),
            }
        }
        if let Some(r) = finished {
            self.task = None;
            match r {
                Ok(()) => {
                    let labels: Vec<String> = self.runs.iter().map(|(i, _)| super::model::label(*i)).collect();
                    self.spread =
                        spread_of_runs(self.runs.iter().zip(&labels).map(|((_, r), l)| (l.as_str(), r.as_slice())));
                    self.status = format!("{} seeds at 1/{}", self.seeds.clamp(2, 20), self.decimation);
                }
                Err(e) => self.status = e,
            }
        }
    }

    /// Was the spread measured for these designs (the seed aside)?
    #[must_use]
    pub fn fresh(&self, configs: &[RunConfig]) -> bool {
        self.measured.as_ref().is_some_and(|m| *m == unseeded(configs))
    }

    /// The spread, if it was measured for `configs` (checked once per frame, not per cell).
    #[must_use]
    pub fn spread_for(&self, configs: &[RunConfig]) -> Option<&[SeedSpread]> {
        self.fresh(configs).then_some(self.spread.as_slice())
    }

    /// Is there a spread measured for other designs than `configs`?
    #[must_use]
    pub fn stale(&self, configs: &[RunConfig]) -> bool {
        !self.spread.is_empty() && !self.fresh(configs)
    }
}
