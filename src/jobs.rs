//! Background work, in one place:
//! - [`Mailbox`], the single slot where the newest request wins (the engine thread takes its
//!   runs from one);
//! - [`Worker`], a named thread answering requests from a mailbox (the app's map colouring and
//!   plot data, library listing and exports);
//! - [`Task`], a one-off cancellable job streaming its results from its own pool (the app's
//!   sweeps and cost measurements);
//! - [`pool`], the one way Shoal builds a rayon pool (named threads, a bounded size);
//! - [`free_later`], dropping a large value on a thread of its own.
//!
//! A mailbox is the right shape for interactive work: the producer (the UI thread) never blocks
//! and never sleeps — `put` replaces whatever request is waiting, which is by construction older
//! than the new one and no longer wanted — and the consumer blocks in `take` until there is
//! work or the mailbox is closed.

use std::sync::mpsc::{Receiver, sync_channel};
use std::sync::{Arc, Condvar, Mutex, PoisonError};

use crate::control::RunControl;

/// One waiting request at most; a newer one replaces it.
#[derive(Debug)]
pub struct Mailbox<T> {
    slot: Mutex<Slot<T>>,
    ready: Condvar,
}

#[derive(Debug)]
struct Slot<T> {
    waiting: Option<T>,
    closed: bool,
}

/// What became of a `put`.
#[derive(Debug, PartialEq, Eq)]
pub enum Put<T> {
    /// Waiting for the consumer; nothing was waiting before.
    Queued,
    /// Waiting; it replaced this older request, which will never be taken.
    Replaced(T),
    /// The mailbox is closed (its consumer has stopped): the request is handed back.
    Closed(T),
}

impl<T> Default for Mailbox<T> {
    fn default() -> Self {
        Self { slot: Mutex::new(Slot { waiting: None, closed: false }), ready: Condvar::new() }
    }
}

impl<T> Mailbox<T> {
    /// An empty, open mailbox.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Slot<T>> {
        // A panic elsewhere while holding the lock leaves the slot consistent (an Option and a
        // flag): go on with it.
        self.slot.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Leave `value` for the consumer, replacing any request still waiting. Never blocks.
    pub fn put(&self, value: T) -> Put<T> {
        let mut slot = self.lock();
        if slot.closed {
            return Put::Closed(value);
        }
        let old = slot.waiting.replace(value);
        drop(slot);
        self.ready.notify_one();
        old.map_or(Put::Queued, Put::Replaced)
    }

    /// Leave `value` only if no request is waiting (one waiting is newer or more wanted: it
    /// stays); false if it was not left. Never blocks.
    pub fn offer(&self, value: T) -> bool {
        let mut slot = self.lock();
        if slot.closed || slot.waiting.is_some() {
            return false;
        }
        slot.waiting = Some(value);
        drop(slot);
        self.ready.notify_one();
        true
    }

    /// The waiting request, waiting for one if there is none; `None` once the mailbox is closed
    /// (a request left when it closed is dropped: nobody wants it any more).
    pub fn take(&self) -> Option<T> {
        let mut slot = self.lock();
        loop {
            if slot.closed {
                return None;
            }
            if let Some(v) = slot.waiting.take() {
                return Some(v);
            }
            slot = self.ready.wait(slot).unwrap_or_else(PoisonError::into_inner);
        }
    }

    /// The waiting request, if any (never blocks).
    pub fn try_take(&self) -> Option<T> {
        self.lock().waiting.take()
    }

    /// Close: `take` returns `None` from now on and `put` hands requests back.
    pub fn close(&self) {
        self.lock().closed = true;
        self.ready.notify_all();
    }

    /// Closed?
    #[must_use]
    pub fn is_closed(&self) -> bool {
        self.lock().closed
    }
}

/// A named thread that answers requests taken from a [`Mailbox`]: the newest request wins,
/// asking never blocks, and every answer goes back through a short queue the owner polls (the
/// app, once per frame). `wake` runs after each answer (the app asks egui for a repaint).
/// Dropping the worker closes its mailbox; the thread ends after the request in hand.
#[derive(Debug)]
pub struct Worker<Req, Out> {
    inbox: Arc<Mailbox<Req>>,
    answers: Receiver<Out>,
}

impl<Req: Send + 'static, Out: Send + 'static> Worker<Req, Out> {
    /// Start thread `name` running `work` on each request.
    pub fn spawn(
        name: &str,
        wake: impl Fn() + Send + 'static,
        mut work: impl FnMut(Req) -> Out + Send + 'static,
    ) -> std::io::Result<Self> {
        let inbox = Arc::new(Mailbox::<Req>::new());
        // Answers are taken every frame: a short queue is enough, and a full one only makes the
        // worker wait for the next frame.
        let (tx, answers) = sync_channel::<Out>(4);
        let rx = inbox.clone();
        std::thread::Builder::new().name(name.into()).spawn(move || {
            while let Some(request) = rx.take() {
                if tx.send(work(request)).is_err() {
                    break;
                }
                wake();
            }
            rx.close();
        })?;
        Ok(Self { inbox, answers })
    }

    /// Ask, replacing a request not yet started. Never blocks.
    pub fn request(&self, request: Req) -> Put<Req> {
        self.inbox.put(request)
    }

    /// A handle that offers this worker work from another thread (never replacing a request of
    /// the owner's); its answers come back to the owner.
    #[must_use]
    pub fn requester(&self) -> Requester<Req> {
        Requester(self.inbox.clone())
    }

    /// The oldest answer not yet taken.
    pub fn poll(&self) -> Option<Out> {
        self.answers.try_recv().ok()
    }

    /// The oldest answer not yet taken, waiting until `deadline` for one when none is there: for
    /// an owner that has just asked and would rather draw the answer in this frame than one
    /// refresh later. The wait is bounded, so a slow answer costs the frame its deadline at most.
    pub fn poll_until(&self, deadline: std::time::Instant) -> Option<Out> {
        self.answers.recv_timeout(deadline.saturating_duration_since(std::time::Instant::now())).ok()
    }

    /// The newest answer, dropping older ones not yet taken.
    pub fn latest(&self) -> Option<Out> {
        let mut last = None;
        while let Some(a) = self.poll() {
            last = Some(a);
        }
        last
    }
}

/// Offers a [`Worker`] work from another thread ([`Worker::requester`]): the owner's own
/// requests come first.
#[derive(Debug)]
pub struct Requester<Req>(Arc<Mailbox<Req>>);

impl<Req> Requester<Req> {
    /// Ask, unless a request is waiting (the owner's, which is never replaced from here); true if
    /// asked. Never blocks.
    pub fn offer(&self, request: Req) -> bool {
        self.0.offer(request)
    }
}

impl<Req, Out> Drop for Worker<Req, Out> {
    fn drop(&mut self) {
        self.inbox.close();
    }
}

/// What a [`Task`] sends: items as they are made, then how it ended.
#[derive(Debug)]
pub enum TaskNews<T> {
    /// One result.
    Item(T),
    /// The task ended: `Ok` when it finished, else why not.
    Done(Result<(), String>),
}

/// A one-off streaming job (a sweep, a cost measurement): its own named thread and its own rayon
/// pool of all cores but one (at least one), so it neither queues behind the engine's runs nor
/// takes every core from them. Results stream back as they are made; dropping the task cancels
/// it (the work sees it through its [`RunControl`]).
#[derive(Debug)]
pub struct Task<T> {
    news: Receiver<TaskNews<T>>,
    control: Arc<RunControl>,
}

impl<T: Send + 'static> Task<T> {
    /// Start `work` on thread `name`; it sends each result through its second argument. `wake`
    /// runs after each message.
    pub fn spawn(
        name: &'static str,
        wake: impl Fn() + Send + Sync + 'static,
        work: impl FnOnce(&RunControl, &dyn Fn(T)) -> Result<(), String> + Send + 'static,
    ) -> Result<Self, String> {
        let (tx, news) = sync_channel::<TaskNews<T>>(64);
        let control = Arc::new(RunControl::new());
        let c = control.clone();
        let cores = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
        let pool = pool(cores.saturating_sub(1).max(1), name).map_err(|e| e.to_string())?;
        std::thread::Builder::new()
            .name(name.into())
            .spawn(move || {
                let send = |item: T| {
                    let _ = tx.send(TaskNews::Item(item));
                    wake();
                };
                let result = pool.install(|| work(&c, &send));
                let _ = tx.send(TaskNews::Done(result));
                wake();
            })
            .map_err(|e| format!("cannot start {name}: {e}"))?;
        Ok(Self { news, control })
    }

    /// The next message, if any.
    pub fn poll(&self) -> Option<TaskNews<T>> {
        self.news.try_recv().ok()
    }
}

impl<T> Drop for Task<T> {
    fn drop(&mut self) {
        self.control.cancel();
    }
}

/// A rayon pool of `threads` threads (0: one per available core) named `name-0`, `name-1`, …
/// Every pool in Shoal is built here, so each job's threads are bounded and show in a profiler
/// under the job's name.
pub fn pool(threads: usize, name: &'static str) -> std::io::Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(move |i| format!("{name}-{i}"))
        .build()
        .map_err(|e| std::io::Error::other(format!("cannot start the {name} threads: {e}")))
}

/// Drop `value` on a short-lived thread of its own: for the last handle on a run at full
/// resolution (its cubes are a gigabyte), whose freeing took 50 ms of a slider's preview when
/// done on the thread that had replaced it. If no thread can be started, the closure (and the
/// value with it) is dropped here instead.
pub fn free_later<T: Send + 'static>(value: T) {
    let _ = std::thread::Builder::new().name("shoal-free".into()).spawn(move || drop(value));
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;

    #[test]
    fn the_newest_request_wins_and_put_never_blocks() {
        let m = Mailbox::new();
        assert_eq!(m.put(1), Put::Queued);
        assert_eq!(m.put(2), Put::Replaced(1));
        assert_eq!(m.put(3), Put::Replaced(2));
        assert_eq!(m.take(), Some(3));
        assert_eq!(m.try_take(), None);
    }

    #[test]
    fn an_offer_never_replaces_a_waiting_request() {
        let m = Mailbox::new();
        assert!(m.offer(1));
        assert!(!m.offer(2), "an offer replaced an offer");
        assert_eq!(m.put(3), Put::Replaced(1));
        assert!(!m.offer(4), "an offer replaced a request");
        assert_eq!(m.take(), Some(3));
        assert!(m.offer(5));
        m.close();
        assert!(!m.offer(6));
    }

    #[test]
    fn take_waits_for_work_and_ends_when_closed() {
        let m = Arc::new(Mailbox::new());
        let consumer = {
            let m = m.clone();
            std::thread::Builder::new()
                .name("mailbox-test".into())
                .spawn(move || {
                    let mut got = Vec::new();
                    while let Some(v) = m.take() {
                        got.push(v);
                    }
                    got
                })
                .unwrap()
        };
        std::thread::sleep(Duration::from_millis(20));
        assert_eq!(m.put(7), Put::Queued);
        // Wait until the consumer has it, then close.
        while m.lock().waiting.is_some() {
            std::thread::yield_now();
        }
        m.close();
        assert_eq!(consumer.join().unwrap(), vec![7]);
        assert_eq!(m.put(8), Put::Closed(8), "a closed mailbox hands the request back");
        assert!(m.is_closed());
    }

    #[test]
    fn a_worker_answers_on_its_named_thread_and_stops_when_dropped() {
        let woken = Arc::new(std::sync::atomic::AtomicUsize::new(0));
        let w = {
            let woken = woken.clone();
            Worker::spawn(
                "worker-test",
                move || {
                    woken.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                },
                |x: u32| (x * 2, std::thread::current().name().map(str::to_string)),
            )
            .unwrap()
        };
        assert_eq!(w.request(21), Put::Queued);
        let answer = loop {
            if let Some(a) = w.poll() {
                break a;
            }
            std::thread::sleep(Duration::from_millis(1));
        };
        assert_eq!(answer, (42, Some("worker-test".into())));
        assert!(woken.load(std::sync::atomic::Ordering::SeqCst) >= 1, "the owner was woken");
        let inbox = w.inbox.clone();
        drop(w);
        assert!(inbox.is_closed(), "dropping the worker closes its mailbox");
    }

    #[test]
    fn pools_have_the_size_and_names_asked_for() {
        let p = pool(2, "shoal-test").unwrap();
        assert_eq!(p.current_num_threads(), 2);
        let name = p.install(|| std::thread::current().name().map(str::to_string));
        assert!(name.is_some_and(|n| n.starts_with("shoal-test-")));
    }
}
