//! Cancellation and progress shared between a running chain and whoever watches it (the CLI's
//! progress bar, the app's engine thread). Heavy stages check [`RunControl::cancelled`] between
//! rows and report rows done; nothing here blocks.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Cancellation flag and progress counters of one run.
#[derive(Debug, Default)]
pub struct RunControl {
    cancel: Arc<AtomicBool>,
    /// The newest generation requested and this run's: the run is stale once they differ.
    generation: Option<(Arc<AtomicU64>, u64)>,
    done: AtomicU64,
    total: AtomicU64,
}

impl RunControl {
    /// A control that is not cancelled.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// A control sharing `flag`: setting it cancels the run.
    #[must_use]
    pub fn with_flag(flag: Arc<AtomicBool>) -> Self {
        Self { cancel: flag, ..Self::default() }
    }

    /// A control that counts as cancelled as soon as `latest` moves past `generation` (a newer
    /// request supersedes this run).
    #[must_use]
    pub fn for_generation(latest: Arc<AtomicU64>, generation: u64) -> Self {
        Self { generation: Some((latest, generation)), ..Self::default() }
    }

    /// Ask the run to stop at the next row.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Has the run been asked to stop?
    #[must_use]
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
            || self.generation.as_ref().is_some_and(|(latest, mine)| latest.load(Ordering::Relaxed) != *mine)
    }

    /// Announce `units` more units of work.
    pub fn add_total(&self, units: u64) {
        self.total.fetch_add(units, Ordering::Relaxed);
    }

    /// Record `units` units done.
    pub fn tick(&self, units: u64) {
        self.done.fetch_add(units, Ordering::Relaxed);
    }

    /// (done, total) units so far.
    #[must_use]
    pub fn progress(&self) -> (u64, u64) {
        (self.done.load(Ordering::Relaxed), self.total.load(Ordering::Relaxed))
    }
}
