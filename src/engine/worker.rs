//! The engine on its own thread, for the app: requests in through a single-slot
//! [`crate::jobs::Mailbox`] (the newest wins; submitting never blocks), events out
//! through a bounded channel, with generation numbers so that stale work is abandoned and stale
//! results dropped.
//!
//! The app owns the configuration and sends a snapshot with a new generation number each time it
//! changes. The worker always runs the newest request it has: a newer one cancels the current
//! run at its next row. Each request runs at each of its decimation factors in turn (a preview,
//! then full resolution), through the same stage cache. The worker owns a rayon pool of its own,
//! so the UI thread keeps a core.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, TryRecvError, sync_channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration;

use super::{Engine, EngineError, RunConfig, RunOutput};
use crate::control::RunControl;
use crate::jobs::{Mailbox, Put};

/// A request: configuration snapshots (instrument A, instrument B, …) and the decimations to run
/// them at, coarsest first. Each decimation runs every configuration before the next finer one.
#[derive(Debug, Clone)]
pub struct Request {
    /// Generation number (increasing).
    pub generation: u64,
    /// The configurations; `None` at an index the caller already holds a final result for
    /// (unchanged since its previous request): nothing is run or reported for it.
    pub configs: Vec<Option<RunConfig>>,
    /// Per configuration (missing: false): restart it at the finest decimation only, after the
    /// others there. The app asks so for a design whose final result is shown but whose views
    /// are larger than its share of the request's designs: where the cache still holds its Rrs
    /// the run restarts from it and hands back the views cut to the share
    /// ([`super::views::CubeViews::within`]); where it does not, the design is not run
    /// ([`Event::Kept`]). Its maps stay on screen meanwhile.
    pub finest_only: Vec<bool>,
    /// Decimation factors, e.g. `[4, 1]` for a preview then full resolution.
    pub decimations: Vec<usize>,
}

/// What the worker reports.
#[derive(Debug, Clone)]
pub enum Event {
    /// Progress of a run: units done of total (rows of the heavy stages).
    Progress {
        /// Generation.
        generation: u64,
        /// Which configuration of the request.
        index: usize,
        /// Decimation of the run in progress.
        decimation: usize,
        /// Units done.
        done: u64,
        /// Units in all (grows as stages start).
        total: u64,
        /// The stage computing now and its own rows.
        stage: Option<crate::control::StageProgress>,
    },
    /// A design asked at the finest level only ([`Request::finest_only`]) was not run: the
    /// engine keeps no Rrs to restart it from, and running it again in full would cost more than
    /// its larger views do. Its result on screen stays as it is.
    Kept {
        /// Generation.
        generation: u64,
        /// Which configuration of the request.
        index: usize,
    },
    /// A run finished (or failed).
    Finished {
        /// Generation.
        generation: u64,
        /// Which configuration of the request.
        index: usize,
        /// Decimation of the run.
        decimation: usize,
        /// The output, or the error message.
        result: Result<Arc<RunOutput>, EngineError>,
    },
}

/// Called by the worker after it sends an event.
pub type Wake = Arc<dyn Fn() + Send + Sync>;

/// Called by the worker with each result (generation, design, decimation, output) just before it
/// sends it: an owner can start work on the result on its own threads without waiting for its
/// next poll (the app starts colouring the result's maps while its UI thread waits for the
/// display's next refresh).
pub type ResultHook = Arc<dyn Fn(u64, usize, usize, &Arc<RunOutput>) + Send + Sync>;

/// Where the owner's [`ResultHook`] is kept, shared by the handle and the worker.
#[derive(Default)]
struct HookSlot(Mutex<Option<ResultHook>>);

impl std::fmt::Debug for HookSlot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("HookSlot")
    }
}

impl HookSlot {
    fn call(&self, generation: u64, index: usize, decimation: usize, output: &Arc<RunOutput>) {
        if let Some(hook) = self.0.lock().unwrap_or_else(PoisonError::into_inner).as_ref() {
            hook(generation, index, decimation, output);
        }
    }
}

/// What became of the runs and results since the worker started (for tests and diagnostics):
/// a stale result (a run that finished after a newer request was submitted, dropped by
/// [`EngineHandle::poll`]) is told apart from a cancelled run (stopped before it finished,
/// never reported) and from a request superseded before it started.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WorkerStats {
    /// `Finished` events the worker sent (current or stale when they arrive).
    pub results_sent: u64,
    /// Runs stopped by cancellation (a newer generation); these send no `Finished` event.
    pub runs_cancelled: u64,
    /// Requests superseded before any of their runs started (replaced in the mailbox, or found
    /// stale when taken from it).
    pub requests_skipped: u64,
    /// `Finished` events of an older generation that `poll`/`wait` dropped.
    pub stale_results_dropped: u64,
}

/// How much work and memory the worker has used (for the soak test and diagnostics).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WorkerLoad {
    /// Rows (progress units) the cancelled runs completed after their cancel: work already
    /// started when a newer request arrived (see [`RunControl::done_after_cancel`]).
    pub rows_after_cancel: u64,
    /// The most products the engine's stage cache held after any run (bounded by the sum of
    /// the stages' capacities).
    pub max_cached_products: u64,
}

/// The counters behind [`WorkerStats`], shared by the worker and the handle.
#[derive(Debug, Default)]
struct Counters {
    results_sent: AtomicU64,
    runs_cancelled: AtomicU64,
    requests_skipped: AtomicU64,
    stale_results_dropped: AtomicU64,
    rows_after_cancel: AtomicU64,
    max_cached_products: AtomicU64,
}

/// The app's handle on the engine thread.
#[derive(Debug)]
pub struct EngineHandle {
    requests: Arc<Mailbox<Request>>,
    events: Receiver<Event>,
    latest: Arc<AtomicU64>,
    counters: Arc<Counters>,
    pause: Arc<PreviewPause>,
    hook: Arc<HookSlot>,
    thread: Option<JoinHandle<()>>,
}

/// The pause between a request's preview and its finer levels, for an owner that draws the
/// preview: the engine waits until the owner says the preview is on screen
/// ([`EngineHandle::preview_shown`]), a newer request arrives, or `limit` passes, whichever is
/// first. Without it the finer run starts at once and takes every core while the owner is
/// turning the preview into images, which then come a frame or two later. Off (zero) unless set.
#[derive(Debug, Default)]
struct PreviewPause {
    /// The longest wait, µs (0: no pause).
    limit_us: AtomicU64,
    /// The newest generation whose preview the owner has on screen.
    shown: AtomicU64,
}

impl EngineHandle {
    /// Start the worker with a rayon pool of `threads` threads.
    pub fn spawn(threads: usize) -> std::io::Result<Self> {
        Self::spawn_with_wake(threads, Arc::new(|| {}))
    }

    /// As [`EngineHandle::spawn`], calling `wake` after every event it sends (the app passes
    /// "request a repaint", so a result is drawn the moment it arrives, not at the next poll).
    pub fn spawn_with_wake(threads: usize, wake: Wake) -> std::io::Result<Self> {
        let requests = Arc::new(Mailbox::new());
        let worker_requests = requests.clone();
        let (event_tx, event_rx) = sync_channel::<Event>(64);
        let latest = Arc::new(AtomicU64::new(0));
        let worker_latest = latest.clone();
        let counters = Arc::new(Counters::default());
        let worker_counters = counters.clone();
        let pause = Arc::new(PreviewPause::default());
        let worker_pause = pause.clone();
        let hook = Arc::new(HookSlot::default());
        let worker_hook = hook.clone();
        let pool = crate::jobs::pool(threads.max(1), "shoal-engine")?;
        let thread = std::thread::Builder::new().name("shoal-engine".into()).spawn(move || {
            let link = Link {
                events: &event_tx,
                latest: &worker_latest,
                counters: &worker_counters,
                wake: &wake,
                hook: &worker_hook,
            };
            worker(&worker_requests, &link, &worker_pause, &pool);
            // However the worker ended, later submissions are refused rather than left waiting.
            worker_requests.close();
        })?;
        Ok(Self { requests, events: event_rx, latest, counters, pause, hook, thread: Some(thread) })
    }

    /// Call `hook` with each result before it is sent (see [`ResultHook`]); replaces any hook set.
    pub fn set_result_hook(&self, hook: ResultHook) {
        *self.hook.0.lock().unwrap_or_else(PoisonError::into_inner) = Some(hook);
    }

    /// Pause up to `limit` between a request's coarsest level and its finer ones, until
    /// [`EngineHandle::preview_shown`] (zero: no pause, the default).
    pub fn set_preview_pause(&self, limit: Duration) {
        self.pause.limit_us.store(u64::try_from(limit.as_micros()).unwrap_or(u64::MAX), Ordering::SeqCst);
    }

    /// The preview of `generation` is on screen: a paused engine goes on to the finer levels.
    pub fn preview_shown(&self, generation: u64) {
        self.pause.shown.fetch_max(generation, Ordering::SeqCst);
        if let Some(t) = &self.thread {
            t.thread().unpark();
        }
    }

    /// Submit a configuration snapshot; any run of an older generation is cancelled. Returns
    /// false if the worker has stopped.
    pub fn submit(&self, request: Request) -> bool {
        self.latest.fetch_max(request.generation, Ordering::SeqCst);
        match self.requests.put(request) {
            Put::Queued => true,
            Put::Replaced(_) => {
                self.counters.requests_skipped.fetch_add(1, Ordering::SeqCst);
                true
            }
            Put::Closed(_) => false,
        }
    }

    /// Stop the run in flight and the rest of its request (the results already sent stay the
    /// caller's): the worker takes `generation` (newer than any submitted) as the newest, so
    /// the request in flight is stale; the caller's next [`Self::submit`] must carry
    /// `generation` or a newer one.
    pub fn cancel(&self, generation: u64) {
        self.latest.fetch_max(generation, Ordering::SeqCst);
    }

    /// The newest generation submitted.
    #[must_use]
    pub fn latest_generation(&self) -> u64 {
        self.latest.load(Ordering::SeqCst)
    }

    /// What became of the runs and results so far (see [`WorkerStats`]).
    #[must_use]
    pub fn stats(&self) -> WorkerStats {
        let c = &self.counters;
        WorkerStats {
            results_sent: c.results_sent.load(Ordering::SeqCst),
            runs_cancelled: c.runs_cancelled.load(Ordering::SeqCst),
            requests_skipped: c.requests_skipped.load(Ordering::SeqCst),
            stale_results_dropped: c.stale_results_dropped.load(Ordering::SeqCst),
        }
    }

    /// Work done after cancels and the cache's high-water mark (see [`WorkerLoad`]).
    #[must_use]
    pub fn load(&self) -> WorkerLoad {
        let c = &self.counters;
        WorkerLoad {
            rows_after_cancel: c.rows_after_cancel.load(Ordering::SeqCst),
            max_cached_products: c.max_cached_products.load(Ordering::SeqCst),
        }
    }

    /// `event` if it belongs to the newest generation; otherwise `None`, counting a dropped
    /// stale result.
    fn current(&self, event: Event) -> Option<Event> {
        let (generation, finished) = match &event {
            Event::Progress { generation, .. } => (*generation, false),
            Event::Finished { generation, .. } | Event::Kept { generation, .. } => (*generation, true),
        };
        if generation == self.latest_generation() {
            return Some(event);
        }
        if finished {
            self.counters.stale_results_dropped.fetch_add(1, Ordering::SeqCst);
        }
        None
    }

    /// Next event, if any (never blocks). Results of stale generations are dropped here.
    pub fn poll(&self) -> Option<Event> {
        loop {
            match self.events.try_recv() {
                Ok(event) => {
                    if let Some(e) = self.current(event) {
                        return Some(e);
                    }
                }
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => return None,
            }
        }
    }

    /// Wait up to `timeout` for the next current event.
    pub fn wait(&self, timeout: Duration) -> Option<Event> {
        let deadline = std::time::Instant::now() + timeout;
        loop {
            if let Some(e) = self.poll() {
                return Some(e);
            }
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            if left.is_zero() {
                return None;
            }
            match self.events.recv_timeout(left.min(Duration::from_millis(5))) {
                Ok(event) => {
                    if let Some(e) = self.current(event) {
                        return Some(e);
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => return None,
            }
        }
    }
}

impl Drop for EngineHandle {
    fn drop(&mut self) {
        // Cancel the current run and close the mailbox; the worker then exits.
        self.latest.fetch_add(1, Ordering::SeqCst);
        self.requests.close();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The worker's ends of the handle.
struct Link<'a> {
    events: &'a SyncSender<Event>,
    latest: &'a Arc<AtomicU64>,
    counters: &'a Counters,
    wake: &'a Wake,
    hook: &'a HookSlot,
}

/// Wait, after `generation`'s preview, until it is on screen, a newer generation arrives or the
/// pause's limit passes.
fn pause_after_preview(pause: &PreviewPause, latest: &AtomicU64, generation: u64) {
    let limit = Duration::from_micros(pause.limit_us.load(Ordering::SeqCst));
    let start = std::time::Instant::now();
    while pause.shown.load(Ordering::SeqCst) < generation && latest.load(Ordering::SeqCst) == generation {
        let Some(left) = limit.checked_sub(start.elapsed()).filter(|d| !d.is_zero()) else { return };
        // Parked: `preview_shown` and `submit` (through the generation check after at most 2 ms)
        // end the wait early.
        std::thread::park_timeout(left.min(Duration::from_millis(2)));
    }
}

/// The designs the app holds at most.
pub const MAX_DESIGNS: usize = 8;

/// The most the app engine's cache keeps: what lets a change restart mid-chain (an instrument
/// change needs the cubes before it, ~0.8 GB up to the Rrs for a full-resolution CubeSat, so the
/// default study's two designs keep theirs; a retrieval change needs only each design's Rrs, which
/// outlasts the cubes).
pub const APP_CACHE_MAX_BYTES: usize = 2 << 30;

/// The most a run's working set and the app engine's cache hold together: before a run whose
/// working set would take the cache past it, the cache lets its least recently used products go
/// (the 101-band spectrograph's or a 10 m imager's full-resolution run, ~2.5 GiB and more,
/// empties it: a later change reruns the other designs from the start).
pub const APP_RUN_ENVELOPE_BYTES: usize = 5 << 29;

/// The app engine's cache: a quarter of the memory budget (`SHOAL_MEMORY_BUDGET`, default 60 %
/// of the machine's memory), at most [`APP_CACHE_MAX_BYTES`]. The runs themselves hand back
/// products and bounded views, not cubes ([`Engine::for_app`]); a rerun of a design whose
/// cubes the cache let go recomputes them.
pub fn app_cache_bytes() -> usize {
    const SHARE: f64 = 0.25;
    // A budget that cannot be read (a malformed variable: the CLI refuses it) gets the most.
    crate::budget::MachineBudget::from_env()
        .map_or(APP_CACHE_MAX_BYTES, |b| ((b.memory_bytes * SHARE) as usize).min(APP_CACHE_MAX_BYTES))
}

fn worker(requests: &Mailbox<Request>, link: &Link<'_>, pause: &PreviewPause, pool: &rayon::ThreadPool) {
    let Link { events, latest, counters, wake, hook } = *link;
    let cache_bytes = app_cache_bytes();
    let mut engine = Engine::for_app(cache_bytes, MAX_DESIGNS);
    // The mailbox holds only the newest request: an older one was replaced (and counted) there.
    while let Some(request) = requests.take() {
        // Each design's share of the views: the more designs, the smaller each one's maps.
        engine.set_view_bytes(super::views::view_bytes_per_run(request.configs.len()));
        // A configuration that failed is not run at finer levels; the others go on (one
        // broken instrument does not hide the other's results).
        let mut failed = vec![false; request.configs.len()];
        let mut started = false;
        'decimations: for (level, &decimation) in request.decimations.iter().enumerate() {
            if level == 1 && started {
                pause_after_preview(pause, latest, request.generation);
            }
            // The designs asked at the finest level only come after the others there: a new
            // design's result is not kept waiting behind the cuts of the ones on screen.
            let finest = level + 1 == request.decimations.len();
            let only_finest = |i: &usize| request.finest_only.get(*i).copied().unwrap_or(false);
            let order: Vec<usize> = (0..request.configs.len())
                .filter(|i| !only_finest(i))
                .chain((0..request.configs.len()).filter(|i| finest && only_finest(i)))
                .collect();
            for index in order {
                let Some(base) = &request.configs[index] else { continue };
                if failed[index] {
                    continue;
                }
                if latest.load(Ordering::SeqCst) != request.generation {
                    if !started {
                        counters.requests_skipped.fetch_add(1, Ordering::SeqCst);
                    }
                    break 'decimations;
                }
                started = true;
                let mut config = base.clone();
                config.fidelity.decimation = decimation;
                // Room for a large run: the run's working set and the cache together stay within
                // [`APP_RUN_ENVELOPE_BYTES`] (the spectrograph's or a 10 m imager's run empties the
                // cache; a CubeSat's leaves it 1.9 GiB).
                // A design asked at the finest level only restarts from what the cache keeps, or
                // is not run: the cache is left as it is for it.
                let only_restart = only_finest(&index);
                if !only_restart {
                    let working = super::resources::run_demand_keeping(&config, false).bytes() as usize;
                    engine.set_cache_budget(cache_bytes.min(APP_RUN_ENVELOPE_BYTES.saturating_sub(working)));
                }
                let control = Arc::new(RunControl::for_generation(latest.clone(), request.generation));
                let generation = request.generation;
                let report = |c: &RunControl| {
                    let (d, t) = c.progress();
                    let stage = c.stage_progress();
                    if events
                        .try_send(Event::Progress { generation, index, decimation, done: d, total: t, stage })
                        .is_ok()
                    {
                        wake();
                    }
                };
                let result = crate::control::observed(&control, Duration::from_millis(50), report, || {
                    pool.install(|| {
                        if only_restart {
                            engine.run_restart_only(&config, &control)
                        } else {
                            engine.run(&config, &control).map(Some)
                        }
                    })
                });
                counters.max_cached_products.fetch_max(engine.cached_products() as u64, Ordering::SeqCst);
                if matches!(result, Err(EngineError::Cancelled)) {
                    counters.rows_after_cancel.fetch_add(control.done_after_cancel(), Ordering::SeqCst);
                    counters.runs_cancelled.fetch_add(1, Ordering::SeqCst);
                    break 'decimations;
                }
                failed[index] = result.is_err();
                let event = match result {
                    Ok(None) => Event::Kept { generation, index },
                    Ok(Some(output)) => Event::Finished { generation, index, decimation, result: Ok(Arc::new(output)) },
                    Err(e) => Event::Finished { generation, index, decimation, result: Err(e) },
                };
                // Not for a result the owner will drop as stale (a newer request, or a cancel).
                if let Event::Finished { result: Ok(output), .. } = &event
                    && latest.load(Ordering::SeqCst) == generation
                {
                    hook.call(generation, index, decimation, output);
                }
                // Counted before it is sent, so a reader that has the event sees it counted.
                counters.results_sent.fetch_add(1, Ordering::SeqCst);
                if events.send(event).is_err() {
                    return;
                }
                wake();
            }
        }
    }
}
