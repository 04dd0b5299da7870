//! The app's side of the engine thread: it submits the configuration snapshots of the designs
//! with a new generation whenever they change, and keeps, per design, the newest result of the
//! newest generation (a coarser preview never replaces a finer result of the same generation;
//! an older generation's result is shown only until the new one's first preview arrives, and is
//! marked stale meanwhile). When the designs are reordered or one is removed, the results move
//! with their designs ([`EngineLink::remap`]) rather than being computed again.

use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::engine::worker::{EngineHandle, Event, Request, Wake};
use crate::engine::{EngineError, RunConfig, RunOutput};

/// The longest the engine waits, after a preview, for its maps to be on screen before it starts
/// the finer levels (see `EngineHandle::set_preview_pause`). Turning a preview into images takes
/// a few ms beside B at full resolution; run while the finer level took both cores, it took
/// 5–16 ms and the maps came a frame later. A frame and a half: if the app draws no frames
/// (minimised), refinement is late by this much at most.
const PREVIEW_PAUSE: Duration = Duration::from_millis(25);

/// Bytes of a run's views of its cubes (0 without views).
fn views_bytes(output: &RunOutput) -> usize {
    use crate::engine::footprint::Footprint;
    output.views.as_ref().map_or(0, |v| v.bytes())
}

/// A result on display.
#[derive(Debug, Clone)]
pub struct Shown {
    /// Its generation.
    pub generation: u64,
    /// Its decimation.
    pub decimation: usize,
    /// The run.
    pub output: Arc<RunOutput>,
}

/// Progress of the run in flight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Design (0 = A, 1 = B, …).
    pub index: usize,
    /// Decimation.
    pub decimation: usize,
    /// Rows done.
    pub done: u64,
    /// Rows in all.
    pub total: u64,
    /// The stage computing now and its own rows.
    pub stage: Option<crate::control::StageProgress>,
}

/// What one instrument has to show for the configuration now set: panels draw a result only as
/// `Current`; `Earlier` greyed and marked; `Failed` as its reason, never the numbers of before.
#[derive(Debug, Clone, Copy)]
pub enum Standing<'a> {
    /// No result yet.
    Waiting,
    /// The current configuration's result (a preview while its decimation is not the finest).
    Current(&'a Shown),
    /// An earlier configuration's result, kept until the new one's first preview arrives.
    Earlier(&'a Shown),
    /// The current configuration's run failed: why.
    Failed(&'a str),
}

impl<'a> Standing<'a> {
    /// The result, if it belongs to the configuration now set.
    #[must_use]
    pub fn current(self) -> Option<&'a Shown> {
        match self {
            Self::Current(s) => Some(s),
            _ => None,
        }
    }
}

/// The engine link.
#[derive(Debug)]
pub struct EngineLink {
    handle: EngineHandle,
    generation: u64,
    submitted: Vec<Option<RunConfig>>,
    decimations: Vec<usize>,
    submitted_at: Instant,
    /// Per design: the result shown.
    pub shown: Vec<Option<Shown>>,
    /// Per design: the last error of the current generation.
    pub errors: Vec<Option<String>>,
    /// The run in flight, if any.
    pub progress: Option<Progress>,
    /// Per design: has the current generation's finest level finished?
    finished: Vec<bool>,
    /// Per design: its shown result is being run again at the finest level only, to cut its
    /// views to a smaller share (a design was added); it counts as kept until that run comes
    /// back, so a later submission asks for the cut again rather than for a new preview.
    recut: Vec<bool>,
    /// Per design: the engine kept no Rrs to cut its views from ([`Event::Kept`]): it keeps its
    /// larger views until its configuration changes, rather than running again in full.
    recut_declined: Vec<bool>,
    /// The designs moved since the last submission: submit even if the configurations read the
    /// same (the runs in flight report by their old positions).
    moved: bool,
    /// Seconds from the last submission to the first results of every design arriving.
    pub last_latency_s: Option<f64>,
    latency_pending: bool,
    /// The user stopped the current generation's runs (the results shown stay, as far as they
    /// went); cleared by the next submission.
    cancelled: bool,
}

impl EngineLink {
    /// Start the engine thread with `threads` rayon threads; it calls `wake` after each event.
    pub fn new(threads: usize, wake: Wake) -> std::io::Result<Self> {
        let handle = EngineHandle::spawn_with_wake(threads, wake)?;
        handle.set_preview_pause(PREVIEW_PAUSE);
        Ok(Self {
            handle,
            generation: 0,
            submitted: Vec::new(),
            decimations: Vec::new(),
            submitted_at: Instant::now(),
            shown: Vec::new(),
            errors: Vec::new(),
            progress: None,
            finished: Vec::new(),
            recut: Vec::new(),
            recut_declined: Vec::new(),
            moved: false,
            last_latency_s: None,
            latency_pending: false,
            cancelled: false,
        })
    }

    /// Call `hook` with each result on the engine thread, before it reaches [`Self::poll`].
    pub fn set_result_hook(&self, hook: crate::engine::worker::ResultHook) {
        self.handle.set_result_hook(hook);
    }

    /// What instrument `index` has to show for the configuration now set (see [`Standing`]).
    #[must_use]
    pub fn standing(&self, index: usize) -> Standing<'_> {
        if let Some(e) = self.errors.get(index).and_then(Option::as_deref) {
            return Standing::Failed(e);
        }
        match self.shown.get(index).and_then(Option::as_ref) {
            None => Standing::Waiting,
            Some(s) if s.generation == self.generation => Standing::Current(s),
            Some(s) => Standing::Earlier(s),
        }
    }

    /// The current configuration's result of instrument `index`, if it has one.
    #[must_use]
    pub fn current(&self, index: usize) -> Option<&Shown> {
        self.standing(index).current()
    }

    /// The finest decimation of the current request (1: full resolution).
    #[must_use]
    pub fn finest(&self) -> usize {
        self.decimations.last().copied().unwrap_or(1)
    }

    /// Stop the current configuration's runs where they are; what was shown stays, as a
    /// preview. Nothing runs again until the configuration changes or [`Self::refine`].
    pub fn cancel(&mut self) {
        if self.busy() {
            self.cancelled = true;
            self.progress = None;
            // The worker takes the next generation as the newest: the request in flight is stale.
            self.handle.cancel(self.generation + 1);
        }
    }

    /// Did the user stop the current configuration's runs?
    #[must_use]
    pub fn cancelled(&self) -> bool {
        self.cancelled
    }

    /// Run the current configuration again to its finest level (after a cancel).
    pub fn refine(&mut self) {
        self.submitted.clear();
    }

    /// The newest generation submitted.
    #[must_use]
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Submit `configs` at `decimations` if they differ from what is running; true if submitted.
    ///
    /// A design whose configuration and decimations did not change and whose final result is
    /// already shown is not run again: its result is carried over to the new generation (moving
    /// one slider of A re-runs only A).
    pub fn submit_if_changed(&mut self, configs: Vec<RunConfig>, decimations: Vec<usize>) -> bool {
        if !self.moved
            && self.submitted.iter().map(Option::as_ref).eq(configs.iter().map(Some))
            && decimations == self.decimations
        {
            return false;
        }
        self.moved = false;
        let finest = decimations.last().copied().unwrap_or(1);
        let keep: Vec<bool> = (0..configs.len())
            .map(|i| {
                decimations == self.decimations
                    && self.submitted.get(i).and_then(Option::as_ref) == configs.get(i)
                    && (self.finished.get(i).copied().unwrap_or(false) || self.recut.get(i).copied().unwrap_or(false))
                    && self.errors.get(i).is_some_and(Option::is_none)
                    && self
                        .shown
                        .get(i)
                        .and_then(Option::as_ref)
                        .is_some_and(|s| s.generation == self.generation && s.decimation == finest)
            })
            .collect();
        self.generation += 1;
        self.cancelled = false;
        self.submitted = configs.iter().cloned().map(Some).collect();
        self.decimations.clone_from(&decimations);
        let n = configs.len();
        self.errors = vec![None; n];
        self.finished = vec![false; n];
        // Results of designs no longer there are freed off the UI thread.
        for old in self.shown.drain(n.min(self.shown.len())..).flatten() {
            crate::jobs::free_later(old);
        }
        self.shown.resize(n, None);
        for (i, kept) in keep.iter().enumerate() {
            if *kept && let Some(shown) = self.shown[i].as_mut() {
                shown.generation = self.generation;
                self.finished[i] = true;
            }
        }
        // A kept design whose views are larger than its share among the designs now held (a
        // design was added) runs again at the finest level only: restarted from its kept Rrs, it
        // comes back with its views cut to the share, while its maps stay on screen.
        let share = crate::engine::views::view_bytes_per_run(n);
        let finest_only: Vec<bool> = keep
            .iter()
            .zip(&self.shown)
            .enumerate()
            .map(|(i, (kept, shown))| {
                *kept
                    && !self.recut_declined.get(i).copied().unwrap_or(false)
                    && shown.as_ref().is_some_and(|s| views_bytes(&s.output) > share)
            })
            .collect();
        self.recut_declined = (0..n).map(|i| keep[i] && self.recut_declined.get(i).copied().unwrap_or(false)).collect();
        for (i, recut) in finest_only.iter().enumerate() {
            if *recut {
                self.finished[i] = false;
            }
        }
        self.recut.clone_from(&finest_only);
        self.submitted_at = Instant::now();
        self.latency_pending = true;
        let configs = configs
            .into_iter()
            .zip(keep.iter().zip(&finest_only))
            .map(|(c, (kept, recut))| (!kept || *recut).then_some(c))
            .collect();
        self.handle.submit(Request { generation: self.generation, configs, finest_only, decimations })
    }

    /// Take the engine's events; true if anything shown changed.
    pub fn poll(&mut self) -> bool {
        let mut changed = false;
        while let Some(event) = self.handle.poll() {
            match event {
                Event::Progress { index, decimation, done, total, stage, .. } => {
                    self.progress = Some(Progress { index, decimation, done, total, stage });
                }
                Event::Kept { index, .. } => {
                    if index < self.shown.len() {
                        (self.finished[index], self.recut[index], self.recut_declined[index]) = (true, false, true);
                    }
                    if self.finished.iter().all(|f| *f) {
                        self.progress = None;
                    }
                }
                Event::Finished { generation, index, decimation, result } => {
                    let finest = self.decimations.last().copied().unwrap_or(1);
                    let known = index < self.shown.len();
                    if known && decimation == finest && !matches!(result, Err(EngineError::Cancelled)) {
                        self.finished[index] = true;
                        self.recut[index] = false;
                    }
                    match result {
                        Ok(output) if known => {
                            let replace = match &self.shown[index] {
                                None => true,
                                Some(s) => s.generation < generation || s.decimation >= decimation,
                            };
                            if replace {
                                // The run replaced may hold the last handle on full-resolution
                                // cubes: freed off the UI thread.
                                if let Some(old) = self.shown[index].replace(Shown { generation, decimation, output }) {
                                    crate::jobs::free_later(old);
                                }
                                changed = true;
                                if self.latency_pending
                                    && self
                                        .shown
                                        .iter()
                                        .all(|s| s.as_ref().is_some_and(|s| s.generation == self.generation))
                                {
                                    self.last_latency_s = Some(self.submitted_at.elapsed().as_secs_f64());
                                    self.latency_pending = false;
                                }
                            }
                        }
                        Ok(_) => {}
                        Err(EngineError::Cancelled) => {}
                        Err(e) if known => {
                            self.errors[index] = Some(e.to_string());
                            self.finished[index] = true;
                            changed = true;
                        }
                        Err(_) => {}
                    }
                    if self.finished.iter().all(|f| *f) {
                        self.progress = None;
                    }
                }
            }
        }
        changed
    }

    /// The maps of what is shown are on screen: if that is the current generation's preview (a
    /// design whose run failed counts as shown: its error is), the engine (paused for it) goes on
    /// to the finer levels.
    pub fn maps_on_screen(&self) {
        let current = |i: usize| {
            self.errors[i].is_some() || self.shown[i].as_ref().is_some_and(|s| s.generation == self.generation)
        };
        if (0..self.shown.len()).all(current) {
            self.handle.preview_shown(self.generation);
        }
    }

    /// Is the engine still working on the current generation?
    #[must_use]
    pub fn busy(&self) -> bool {
        !self.cancelled && !self.finished.iter().all(|f| *f)
    }

    /// Is design `index`'s shown result from an older generation than the newest?
    #[must_use]
    pub fn stale(&self, index: usize) -> bool {
        self.shown.get(index).and_then(Option::as_ref).is_none_or(|s| s.generation != self.generation)
    }

    /// The designs moved (`moved[old] = Some(new)`, `None`: removed): their results, errors and
    /// submitted configurations go with them, so a design that did not change is not run
    /// again, and the next submission starts a new generation whatever it holds.
    pub fn remap(&mut self, moved: &[Option<usize>]) {
        let n = moved.iter().flatten().map(|k| k + 1).max().unwrap_or(0);
        let mut shown = vec![None; n];
        let mut errors = vec![None; n];
        let mut finished = vec![false; n];
        let mut recut = vec![false; n];
        let mut declined = vec![false; n];
        let mut submitted: Vec<Option<RunConfig>> = vec![None; n];
        for (old, new) in moved.iter().enumerate() {
            let taken = self.shown.get_mut(old).and_then(Option::take);
            match new {
                Some(k) => {
                    shown[*k] = taken;
                    errors[*k] = self.errors.get_mut(old).and_then(Option::take);
                    finished[*k] = self.finished.get(old).copied().unwrap_or(false);
                    recut[*k] = self.recut.get(old).copied().unwrap_or(false);
                    declined[*k] = self.recut_declined.get(old).copied().unwrap_or(false);
                    submitted[*k] = self.submitted.get(old).cloned().flatten();
                }
                None => {
                    if let Some(old) = taken {
                        crate::jobs::free_later(old);
                    }
                }
            }
        }
        (self.shown, self.errors, self.finished, self.recut, self.recut_declined) =
            (shown, errors, finished, recut, declined);
        // A design with no submitted configuration (none was moved into its place) runs anew;
        // the others keep theirs (an undone removal runs the design that came back, only).
        self.submitted = submitted;
        self.progress = None;
        self.moved = true;
    }

    /// Wait (blocking, for tests and the bench) until every design shows the current
    /// generation at `decimation` or finer, or `timeout` passes; true if they do.
    pub fn wait_for(&mut self, decimation: usize, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        loop {
            self.poll();
            let ready = (0..self.shown.len()).all(|i| {
                self.shown[i].as_ref().is_some_and(|s| s.generation == self.generation && s.decimation <= decimation)
                    && !self.recut.get(i).copied().unwrap_or(false)
            }) || self.errors.iter().any(Option::is_some);
            if ready {
                return self.errors.iter().all(Option::is_none);
            }
            if Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }
}

/// The engine's threads: `requested`, or every core the machine offers when 0.
pub(super) fn engine_threads(requested: usize) -> usize {
    if requested > 0 {
        return requested;
    }
    std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
}
