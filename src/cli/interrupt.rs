//! Ctrl-C (and SIGTERM) during a command: the first signal cancels the run cleanly — the engine
//! stops at its next row check, a file being written is finished or removed (writes are temp +
//! rename, see `study::write_bytes`; a results folder is staged beside `--out` and removed, see
//! `study::OutputDir`), nothing half-written or `.partial` stays — and the command exits with code
//! 130. A second signal exits at once; the staging folder it leaves is removed by the next run
//! into the same `--out`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

use crate::control::RunControl;

/// Exit code of an interrupted command (128 + SIGINT, the shell convention).
pub const EXIT_INTERRUPTED: u8 = 130;

/// The flag the signal handler sets; installed on first use.
fn flag() -> Arc<AtomicBool> {
    static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        let seen = flag.clone();
        // ctrlc runs the handler on its own thread, not in signal context, so printing is safe.
        let installed = ctrlc::set_handler(move || {
            if seen.swap(true, Ordering::SeqCst) {
                std::process::exit(i32::from(EXIT_INTERRUPTED));
            }
            eprintln!("\ninterrupted: stopping at the next row (again to quit at once)");
        });
        if let Err(e) = installed {
            eprintln!("warning: Ctrl-C will not stop the run cleanly: {e}");
        }
        flag
    })
    .clone()
}

/// A run control that Ctrl-C or SIGTERM cancels.
#[must_use]
pub fn control() -> RunControl {
    RunControl::with_flag(flag())
}
