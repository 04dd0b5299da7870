//! The preset library's listing as the left panel shows it, kept in memory: the combo boxes draw
//! from it every frame and never read the disk. It is read again on its own thread every few
//! seconds (a preset copied into the library by hand appears without a restart), and at once,
//! synchronously, after the app itself saves or is pointed at another library — both user
//! actions, not frames.

use std::sync::mpsc::{Receiver, TryRecvError, sync_channel};
use std::time::{Duration, Instant};

use crate::library::{Entry, Kind, Library};

/// How often the library folder is listed again in the background.
const RESCAN: Duration = Duration::from_secs(3);

/// Instruments, scenes and studies, as [`Library::list`] gives them.
type Lists = [Vec<Entry>; 3];

fn read(library: &Library) -> Lists {
    [library.list(Kind::Instrument), library.list(Kind::Scene), library.list(Kind::Study)]
}

const fn slot(kind: Kind) -> usize {
    match kind {
        Kind::Instrument => 0,
        Kind::Scene => 1,
        Kind::Study => 2,
    }
}

/// The cached listing and the background re-read in flight, if any.
pub struct Listing {
    lists: Lists,
    pending: Option<Receiver<Lists>>,
    read_at: Instant,
}

impl Listing {
    /// The listing of `library`, read now.
    pub fn new(library: &Library) -> Self {
        Self { lists: read(library), pending: None, read_at: Instant::now() }
    }

    /// Read `library` again now (after a save, or a change of library).
    pub fn reread(&mut self, library: &Library) {
        *self = Self::new(library);
    }

    /// Once a frame: take a finished background read, and start one when the last is old.
    /// `wake` asks for a frame when the read is done.
    pub fn poll(&mut self, library: &Library, wake: impl Fn() + Send + 'static) {
        if let Some(rx) = &self.pending {
            match rx.try_recv() {
                Ok(lists) => {
                    self.lists = lists;
                    self.pending = None;
                }
                Err(TryRecvError::Empty) => return,
                Err(TryRecvError::Disconnected) => self.pending = None,
            }
        }
        if self.read_at.elapsed() < RESCAN {
            return;
        }
        self.read_at = Instant::now();
        let (tx, rx) = sync_channel(1);
        let library = library.clone();
        let spawned = std::thread::Builder::new().name("shoal-library".into()).spawn(move || {
            let _ = tx.send(read(&library));
            wake();
        });
        // Without a thread the listing stays as it is until the next save.
        self.pending = spawned.is_ok().then_some(rx);
    }

    /// The entries of `kind`.
    #[must_use]
    pub fn get(&self, kind: Kind) -> &[Entry] {
        &self.lists[slot(kind)]
    }
}
