//! The preset library's listing as the left panel shows it, kept in memory: the combo boxes draw
//! from it every frame and never read the disk. It is read again on a worker thread every few
//! seconds (a preset copied into the library by hand appears without a restart), and at once,
//! synchronously, after the app itself saves or is pointed at another library — both user
//! actions, not frames.

use std::time::{Duration, Instant};

use crate::jobs::Worker;
use crate::library::{Entry, Library, PresetKind};

/// How often the library folder is listed again in the background.
const RESCAN: Duration = Duration::from_secs(3);

/// Instruments, scenes and studies, as [`Library::list`] gives them.
type Lists = [Vec<Entry>; 3];

fn read(library: &Library) -> Lists {
    [library.list(PresetKind::Instrument), library.list(PresetKind::Scene), library.list(PresetKind::Study)]
}

const fn slot(kind: PresetKind) -> usize {
    match kind {
        PresetKind::Instrument => 0,
        PresetKind::Scene => 1,
        PresetKind::Study => 2,
    }
}

/// The cached listing and the `shoal-library` [`Worker`] that re-reads it.
pub struct Listing {
    lists: Lists,
    /// Started at the first background read.
    worker: Option<Worker<(u64, Library), (u64, Lists)>>,
    /// Counts synchronous reads: a background answer begun before the last one is older than
    /// what is shown and is dropped.
    generation: u64,
    read_at: Instant,
}

impl Listing {
    /// The listing of `library`, read now.
    pub fn new(library: &Library) -> Self {
        Self { lists: read(library), worker: None, generation: 0, read_at: Instant::now() }
    }

    /// Read `library` again now (after a save, or a change of library).
    pub fn reread(&mut self, library: &Library) {
        self.lists = read(library);
        self.generation += 1;
        self.read_at = Instant::now();
    }

    /// Once a frame: take a finished background read, and ask for one when the last is old.
    /// `wake` asks for a frame when a read is done.
    pub fn poll(&mut self, library: &Library, wake: impl Fn() + Send + 'static) {
        if let Some(w) = &self.worker
            && let Some((generation, lists)) = w.latest()
            && generation == self.generation
        {
            self.lists = lists;
        }
        if self.read_at.elapsed() < RESCAN {
            return;
        }
        self.read_at = Instant::now();
        if self.worker.is_none() {
            // Without a thread the listing stays as it is until the next save.
            self.worker = Worker::spawn("shoal-library", wake, |(g, library): (u64, Library)| (g, read(&library))).ok();
        }
        if let Some(w) = &self.worker {
            let _ = w.request((self.generation, library.clone()));
        }
    }

    /// The entries of `kind`.
    #[must_use]
    pub fn get(&self, kind: PresetKind) -> &[Entry] {
        &self.lists[slot(kind)]
    }
}
