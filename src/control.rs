//! Cancellation and progress shared between a running chain and whoever watches it (the CLI's
//! progress bar, the app's engine thread). Heavy stages check [`RunControl::cancelled`] between
//! rows and report rows done; nothing here blocks.
//!
//! It also knows where a stage was working: per-pixel loops hold a [`RowGuard`] for the row
//! they are on, and a guard dropped by a panic records its row and column, so that a failure
//! is reported with the pixel it happened at. Tests arm an injected panic at one pixel
//! ([`RunControl::arm_panic`]) to prove that path.
//!
//! Every per-pixel stage runs its rows through one executor, [`RunControl::fill_rows`] (rows of
//! output buffers) or [`RunControl::map_rows`] (a value per row): rows in parallel, each checking
//! for cancellation first, holding its guard, and counting one unit of progress when done. A
//! stage writes only what one pixel needs.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use rayon::prelude::*;

/// A stage's error for "the run was cancelled", so the executor can stop a stage in its own terms.
pub trait Cancellable {
    /// The cancellation error.
    fn cancelled() -> Self;
    /// Is this error the cancellation (not a failure to report)?
    fn is_cancelled(&self) -> bool;
}

/// Output buffers the executor splits into rows: one `&mut [T]`, or a tuple of them (row `r` of
/// each, together). An empty buffer (an optional output that is off) gives empty rows.
pub trait RowSplit<'a> {
    /// One row of every buffer.
    type Row: Send;
    /// The buffers as `rows` rows of `stride` elements each.
    fn split(self, rows: usize, stride: usize) -> Vec<Self::Row>;
}

impl<'a, T: Send> RowSplit<'a> for &'a mut [T] {
    type Row = &'a mut [T];
    fn split(self, rows: usize, stride: usize) -> Vec<Self::Row> {
        if self.is_empty() {
            return (0..rows).map(|_| <&mut [T]>::default()).collect();
        }
        self.chunks_mut(stride.max(1)).collect()
    }
}

/// A buffer split into `rows` equal rows whatever the stride the others are split at (a map of
/// one value per pixel beside a cube of one per pixel and band).
pub struct OwnRows<'a, T>(pub &'a mut [T]);

impl<'a, T: Send> RowSplit<'a> for OwnRows<'a, T> {
    type Row = &'a mut [T];
    fn split(self, rows: usize, _stride: usize) -> Vec<Self::Row> {
        let stride = self.0.len() / rows.max(1);
        self.0.split(rows, stride)
    }
}

impl<'a, A: RowSplit<'a>, B: RowSplit<'a>> RowSplit<'a> for (A, B) {
    type Row = (A::Row, B::Row);
    fn split(self, rows: usize, stride: usize) -> Vec<Self::Row> {
        self.0.split(rows, stride).into_iter().zip(self.1.split(rows, stride)).collect()
    }
}

impl<'a, A: RowSplit<'a>, B: RowSplit<'a>, C: RowSplit<'a>> RowSplit<'a> for (A, B, C) {
    type Row = (A::Row, B::Row, C::Row);
    fn split(self, rows: usize, stride: usize) -> Vec<Self::Row> {
        let ab = (self.0, self.1).split(rows, stride);
        ab.into_iter().zip(self.2.split(rows, stride)).map(|((a, b), c)| (a, b, c)).collect()
    }
}

/// A pixel of the simulated image (row, column), as reported with a failure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelSite {
    /// Row (line) of the simulated image.
    pub row: usize,
    /// Column (detector) of the simulated image, when the loop had reached one.
    pub column: Option<usize>,
}

impl std::fmt::Display for PixelSite {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.column {
            Some(c) => write!(f, "row {}, column {c}", self.row),
            None => write!(f, "row {}", self.row),
        }
    }
}

const UNARMED: usize = usize::MAX;

/// Most rows one rayon task of [`RunControl::fill_rows`] and [`RunControl::map_rows`] runs in a
/// row. Left to itself rayon cuts a range into a few pieces per thread and splits a piece only
/// when another thread steals it, so the last piece, run from start to end by one thread, could
/// hold many rows while the other thread had nothing left to take: on the default study's
/// correction that left one of two cores idle for 0.1 s at the end of the stage (perf timeline).
/// A row is 0.1 ms or more of work and a task costs about a microsecond, so one row a task
/// costs nothing measurable. The rows' results do not depend on how they are split.
const ROW_TASK_LEN: usize = 1;

/// Where a run is: the stage computing now and how far its rows have gone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageProgress {
    /// The stage (`retrieval`, `radiance`, …).
    pub name: &'static str,
    /// Stages computed so far in this run, this one included (cached ones are not counted).
    pub ordinal: u32,
    /// Rows of this stage done.
    pub done: u64,
    /// Rows of this stage in all (0 until its per-pixel loop starts, or if it has none).
    pub total: u64,
    /// Seconds since the stage started.
    pub seconds: f64,
}

impl StageProgress {
    /// Seconds left in this stage at its pace so far, once the pace is known (at least 5 % of
    /// its rows and half a second done); `None` before.
    #[must_use]
    pub fn seconds_left(&self) -> Option<f64> {
        let f = if self.total > 0 { self.done as f64 / self.total as f64 } else { return None };
        (f >= 0.05 && self.seconds >= 0.5 && f < 1.0).then(|| self.seconds * (1.0 - f) / f)
    }
}

/// The stage a run is in (see [`RunControl::begin_stage`]).
#[derive(Debug, Clone, Copy)]
struct StageMark {
    name: &'static str,
    ordinal: u32,
    start: std::time::Instant,
    done: u64,
    total: u64,
}

/// Cancellation flag and progress counters of one run.
#[derive(Debug)]
pub struct RunControl {
    cancel: Arc<AtomicBool>,
    /// The newest generation requested and this run's: the run is stale once they differ.
    generation: Option<(Arc<AtomicU64>, u64)>,
    done: AtomicU64,
    total: AtomicU64,
    /// Units ticked while the run was already cancelled (work a cancel did not stop in time).
    after_cancel: AtomicU64,
    /// Injected panic: (row, column), `UNARMED` when none.
    armed: (AtomicUsize, AtomicUsize),
    /// Where the first panicking row guard was.
    site: Mutex<Option<PixelSite>>,
    /// The stage computing now.
    stage: Mutex<Option<StageMark>>,
}

impl Default for RunControl {
    fn default() -> Self {
        Self {
            cancel: Arc::default(),
            generation: None,
            done: AtomicU64::default(),
            total: AtomicU64::default(),
            after_cancel: AtomicU64::default(),
            armed: (AtomicUsize::new(UNARMED), AtomicUsize::new(UNARMED)),
            site: Mutex::new(None),
            stage: Mutex::new(None),
        }
    }
}

/// The row a per-pixel loop is working on; see the module documentation.
#[derive(Debug)]
pub struct RowGuard<'a> {
    control: &'a RunControl,
    row: usize,
    column: Option<usize>,
    /// The column at which an injected panic fires on this row.
    armed_column: Option<usize>,
}

impl RowGuard<'_> {
    /// The row.
    #[must_use]
    pub const fn index(&self) -> usize {
        self.row
    }

    /// The loop moves to `column`. Panics there if a test armed a panic at this pixel.
    #[inline]
    pub fn column(&mut self, column: usize) {
        self.column = Some(column);
        if self.armed_column == Some(column) {
            panic!("injected fault at row {}, column {column}", self.row);
        }
    }
}

impl Drop for RowGuard<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            let mut site = self.control.site.lock().unwrap_or_else(PoisonError::into_inner);
            site.get_or_insert(PixelSite { row: self.row, column: self.column });
        }
    }
}

/// Run `work` while an observer thread calls `report(control)` every `interval` — the one way a
/// run's progress is watched (a progress bar, the app's engine events). The observer is parked,
/// not asleep: the end of `work` wakes it at once, so a fast (cached) run is not held up by the
/// interval, and it reports once more before it stops.
pub fn observed<T>(
    control: &RunControl,
    interval: std::time::Duration,
    report: impl Fn(&RunControl) + Send,
    work: impl FnOnce() -> T,
) -> T {
    let done = &AtomicBool::new(false);
    std::thread::scope(|s| {
        let observer = s.spawn(move || {
            while !done.load(Ordering::Acquire) {
                report(control);
                std::thread::park_timeout(interval);
            }
            report(control);
        });
        let result = work();
        done.store(true, Ordering::Release);
        observer.thread().unpark();
        result
    })
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
        if self.cancelled() {
            self.after_cancel.fetch_add(units, Ordering::Relaxed);
        }
    }

    /// Units (rows) completed after the run was cancelled: the rows a cancel could not stop
    /// because they had already started (at most one per worker thread and stage).
    #[must_use]
    pub fn done_after_cancel(&self) -> u64 {
        self.after_cancel.load(Ordering::Relaxed)
    }

    /// (done, total) units so far.
    #[must_use]
    pub fn progress(&self) -> (u64, u64) {
        (self.done.load(Ordering::Relaxed), self.total.load(Ordering::Relaxed))
    }

    /// A stage called `name` starts computing (the engine calls this for each stage it does not
    /// serve from its cache); [`Self::stage_progress`] then counts its rows alone.
    pub fn begin_stage(&self, name: &'static str) {
        let (done, total) = self.progress();
        let mut stage = self.stage.lock().unwrap_or_else(PoisonError::into_inner);
        let ordinal = stage.map_or(1, |s| s.ordinal + 1);
        *stage = Some(StageMark { name, ordinal, start: std::time::Instant::now(), done, total });
    }

    /// The stage computing now and its rows, if a stage has begun.
    #[must_use]
    pub fn stage_progress(&self) -> Option<StageProgress> {
        let mark = (*self.stage.lock().unwrap_or_else(PoisonError::into_inner))?;
        let (done, total) = self.progress();
        Some(StageProgress {
            name: mark.name,
            ordinal: mark.ordinal,
            done: done.saturating_sub(mark.done),
            total: total.saturating_sub(mark.total),
            seconds: mark.start.elapsed().as_secs_f64(),
        })
    }

    /// Fill `outputs` (see [`RowSplit`]) row by row: `f(guard, row)` writes row `guard.index()`
    /// of every buffer, `stride` elements each. Rows run in parallel, at most [`ROW_TASK_LEN`]
    /// rows to a task; each checks for cancellation first and counts one unit of progress (`rows`
    /// are added to the total).
    pub fn fill_rows<'a, O, E>(
        &self,
        outputs: O,
        rows: usize,
        stride: usize,
        f: impl Fn(&mut RowGuard<'_>, O::Row) -> Result<(), E> + Sync + Send,
    ) -> Result<(), E>
    where
        O: RowSplit<'a>,
        E: Cancellable + Send,
    {
        self.add_total(rows as u64);
        outputs.split(rows, stride).into_par_iter().with_max_len(ROW_TASK_LEN).enumerate().try_for_each(|(r, row)| {
            if self.cancelled() {
                return Err(E::cancelled());
            }
            let mut guard = self.row(r);
            f(&mut guard, row)?;
            self.tick(1);
            Ok(())
        })
    }

    /// `f(guard)` for every row `0..rows`, in parallel, collected in row order; cancellation
    /// and progress as [`Self::fill_rows`].
    pub fn map_rows<T, E>(
        &self,
        rows: usize,
        f: impl Fn(&mut RowGuard<'_>) -> Result<T, E> + Sync + Send,
    ) -> Result<Vec<T>, E>
    where
        T: Send,
        E: Cancellable + Send,
    {
        self.add_total(rows as u64);
        (0..rows)
            .into_par_iter()
            .with_max_len(ROW_TASK_LEN)
            .map(|r| {
                if self.cancelled() {
                    return Err(E::cancelled());
                }
                let mut guard = self.row(r);
                let value = f(&mut guard)?;
                self.tick(1);
                Ok(value)
            })
            .collect()
    }

    /// Enter `row` of a per-pixel loop (see [`RowGuard`]).
    #[inline]
    #[must_use]
    pub fn row(&self, row: usize) -> RowGuard<'_> {
        let armed_column = (self.armed.0.load(Ordering::Relaxed) == row).then(|| self.armed.1.load(Ordering::Relaxed));
        RowGuard { control: self, row, column: None, armed_column }
    }

    /// Make the per-pixel loop that next reaches (`row`, `column`) panic (fault injection for
    /// tests of the failure path; the engine arms it for one stage only).
    pub fn arm_panic(&self, row: usize, column: usize) {
        self.armed.1.store(column, Ordering::Relaxed);
        self.armed.0.store(row, Ordering::Relaxed);
    }

    /// Disarm an injected panic.
    pub fn disarm(&self) {
        self.armed.0.store(UNARMED, Ordering::Relaxed);
    }

    /// Where a per-pixel loop panicked, if one did (and forget it).
    pub fn take_site(&self) -> Option<PixelSite> {
        self.site.lock().unwrap_or_else(PoisonError::into_inner).take()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_observer_reports_during_and_after_the_work_and_never_holds_it_up() {
        let control = RunControl::new();
        let reports = AtomicUsize::new(0);
        let start = std::time::Instant::now();
        // A long interval and instant work: the end wakes the observer, which reports once more.
        let out = observed(
            &control,
            std::time::Duration::from_secs(30),
            |_| {
                reports.fetch_add(1, Ordering::SeqCst);
            },
            || 7,
        );
        assert_eq!(out, 7);
        assert!(start.elapsed() < std::time::Duration::from_secs(5), "{:?}", start.elapsed());
        assert!(reports.load(Ordering::SeqCst) >= 1);
        // Work that ticks: the last report sees all of it.
        let last = AtomicU64::new(0);
        observed(
            &control,
            std::time::Duration::from_millis(1),
            |c| last.store(c.progress().0, Ordering::SeqCst),
            || {
                control.add_total(10);
                for _ in 0..10 {
                    control.tick(1);
                    std::thread::sleep(std::time::Duration::from_millis(2));
                }
            },
        );
        assert_eq!(last.load(Ordering::SeqCst), 10);
    }
}
