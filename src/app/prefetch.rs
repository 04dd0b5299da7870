//! A result's maps coloured as soon as the engine has it, not when the UI thread next polls.
//!
//! The UI thread takes the engine's results once per frame. A preview that finishes just after a
//! frame began waited for the next one (up to a refresh, 16.7 ms), and its maps were then
//! coloured on the raster thread, which often took longer than the frame's short wait for them
//! (`tick`), so they came a refresh later still. Here the engine thread, through its
//! [`ResultHook`], asks the raster thread for the maps the UI will ask for once it takes the
//! result: the same job, with the same key ([`super::maps::job_for`]). The UI's own request,
//! made when it takes the result, is then answered at once from the raster thread's last answer.
//!
//! The hook asks only for what the UI will show: a result of the generation on display that
//! replaces the design's shown one by the link's rule (newer, or finer). Any other result, or a
//! state changed in between, makes a key the UI never asks for; that answer is dropped, and the
//! UI's request is coloured as before.

use std::sync::{Arc, Mutex, PoisonError};

use super::link::EngineLink;
use super::raster::Job;
use crate::engine::RunOutput;
use crate::engine::worker::ResultHook;
use crate::jobs::Requester;

/// The maps on display as the UI thread last saw them.
#[derive(Debug)]
struct View {
    /// The generation whose results are on display.
    generation: u64,
    /// The raster job for the results on display.
    job: Job,
    /// Per design: (generation, decimation) of the result shown.
    shown: Vec<Option<(u64, usize)>>,
}

/// What the UI would ask the raster thread for, where the engine's result hook reads it.
#[derive(Debug, Default)]
pub struct Prefetch {
    view: Mutex<Option<View>>,
}

impl Prefetch {
    /// Record `job`, the raster job for what is on display, and the link's results (the UI
    /// thread, each frame; nothing is rewritten while they stay the same).
    pub fn update(&self, job: Job, link: &EngineLink) {
        let generation = link.generation();
        let shown: Vec<_> = link.shown.iter().map(|s| s.as_ref().map(|s| (s.generation, s.decimation))).collect();
        let mut guard = self.view.lock().unwrap_or_else(PoisonError::into_inner);
        if guard.as_ref().is_some_and(|v| v.generation == generation && v.job.key == job.key && v.shown == shown) {
            return;
        }
        let kept = job.runs.clone();
        let old = guard.replace(View { generation, job, shown });
        drop(guard);
        // The view replaced may hold the last handle on a run no longer shown (a design was
        // removed): freed off the UI thread.
        if let Some(old) = old {
            super::raster::let_go(old.job.runs, &kept);
        }
    }

    /// The job the UI will ask for once it takes `output` (design `index`, `generation`, at
    /// `decimation`), if it will show it.
    fn job_with(&self, generation: u64, index: usize, decimation: usize, output: &Arc<RunOutput>) -> Option<Job> {
        let mut guard = self.view.lock().unwrap_or_else(PoisonError::into_inner);
        let view = guard.as_mut()?;
        let replaces = match view.shown.get(index)? {
            None => true,
            Some((g, d)) => *g < generation || *d >= decimation,
        };
        if generation != view.generation || !replaces || index >= view.job.runs.len() {
            return None;
        }
        // Kept, so that a second result before the next frame (B after A) builds on this one.
        view.shown[index] = Some((generation, decimation));
        view.job.runs[index] = Some(output.clone());
        view.job = view.job.clone().keyed();
        Some(view.job.clone())
    }

    /// The engine's result hook: `ask` (the raster thread) for the maps of each result the UI
    /// will show.
    pub fn hook(self: &Arc<Self>, ask: impl Fn(Job) + Send + Sync + 'static) -> ResultHook {
        let this = self.clone();
        Arc::new(move |generation, index, decimation, output| {
            if let Some(job) = this.job_with(generation, index, decimation, output) {
                ask(job);
            }
        })
    }
}

/// The hook offering `raster` the job (never replacing a request of the UI's waiting there).
pub fn asking(raster: Requester<Job>) -> impl Fn(Job) + Send + Sync + 'static {
    move |job| {
        raster.offer(job);
    }
}

#[cfg(test)]
mod tests {
    use std::time::{Duration, Instant};

    use super::super::model::AppState;
    use super::*;

    /// The keys the hook asked for, in order, once the link shows both designs' results of the
    /// current generation.
    fn run_with_hook(state: &AppState) -> (Arc<Prefetch>, EngineLink, Vec<u64>) {
        let asked = Arc::new(Mutex::new(Vec::new()));
        let prefetch = Arc::new(Prefetch::default());
        let mut link = EngineLink::new(2, Arc::new(|| {})).expect("an engine thread");
        let sink = asked.clone();
        link.set_result_hook(prefetch.hook(move |job| sink.lock().unwrap().push(job.key)));
        assert!(link.submit_if_changed(state.configs(), state.decimations()));
        // Once, before any result: the UI's view of generation 1 with nothing shown yet.
        prefetch.update(super::super::maps::job_for(state, &link), &link);
        let start = Instant::now();
        while !link.shown.iter().all(|s| s.as_ref().is_some_and(|s| s.generation == link.generation())) {
            link.poll();
            assert!(link.errors.iter().all(Option::is_none), "engine error: {:?}", link.errors);
            assert!(start.elapsed() < Duration::from_secs(300), "no result in 5 minutes");
            std::thread::sleep(Duration::from_millis(5));
        }
        let keys = asked.lock().unwrap().clone();
        (prefetch, link, keys)
    }

    #[test]
    fn the_hook_asks_for_the_job_the_ui_asks_for_once_it_takes_the_results() {
        let state = AppState { decimations: vec![32], ..AppState::default() };
        let (prefetch, link, keys) = run_with_hook(&state);
        // One ask per result (A, then B, the second building on the first), and the last is the
        // job the UI now asks for: its request is answered from the raster thread's last answer.
        assert_eq!(keys.len(), 2, "{keys:?}");
        assert_eq!(keys[1], super::super::maps::job_for(&state, &link).key);
        assert_ne!(keys[0], keys[1]);
        // A result the UI will not show asks for nothing: one of an older generation, and a
        // coarser one of the same generation beside the result shown.
        let shown = link.shown[0].clone().unwrap();
        let generation = link.generation();
        assert!(prefetch.job_with(generation - 1, 0, 32, &shown.output).is_none());
        assert!(prefetch.job_with(generation, 0, 64, &shown.output).is_none());
        assert!(prefetch.job_with(generation, 5, 32, &shown.output).is_none());
    }
}
