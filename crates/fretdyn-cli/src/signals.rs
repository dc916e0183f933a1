//! Ctrl-C, SIGTERM and SIGHUP (a terminal, `timeout`, a batch scheduler, `docker stop`).
//!
//! While a command has results to keep ([`Keeping`]: a run streaming to its folder, a study
//! appending rows, a service life with its checkpoint), a signal asks it to stop cleanly
//! ([`INTERRUPTED`]): a run and a life stop after a checkpoint, a study drops the runs under
//! way whole; each says how to continue. Before (reading a case, a modal analysis, a
//! turbulence synthesis, building a study's cases: nothing written yet) the program stops at
//! once, whatever it is computing. A second signal while stopping is ignored: the files are
//! being closed.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::EXIT_FAILED;
use crate::out::errln;

/// Set by a signal while a command has results to keep: it stops at its next checkpoint.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Whether the command has results to keep (a signal then sets [`INTERRUPTED`] instead of
/// stopping the program).
static KEEPING: AtomicBool = AtomicBool::new(false);

/// Installs the handler (once, first thing in `main`).
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        if KEEPING.load(Ordering::SeqCst) {
            INTERRUPTED.store(true, Ordering::SeqCst);
        } else {
            errln!("error: interrupted during the set-up, before anything was written");
            std::process::exit(i32::from(EXIT_FAILED));
        }
    });
}

/// While alive, a signal asks the command to stop cleanly ([`INTERRUPTED`]) instead of
/// stopping the program; a signal that came before it stops the program here.
pub struct Keeping(());

impl Keeping {
    pub fn start() -> Self {
        KEEPING.store(true, Ordering::SeqCst);
        Self(())
    }
}

impl Drop for Keeping {
    fn drop(&mut self) {
        KEEPING.store(false, Ordering::SeqCst);
    }
}

/// Whether a signal asked the command to stop.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}
