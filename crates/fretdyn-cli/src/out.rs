//! The standard output without panics (`println!` panics when it cannot write): a closed
//! pipe (`fretdyn verify | head -1`) silences the rest of the report and the command goes on
//! to its end and its exit code, as with `> /dev/null`; any other error (`> /dev/full`) stops
//! the command with a one-line error and exit code 1. Messages on the standard error ignore
//! its errors: there is nowhere else to report them.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::Failure;

/// Set when the reader of the standard output went away: what follows is dropped.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// Writes one line on the standard output (the [`outln!`] macro).
pub fn line(args: std::fmt::Arguments) -> Result<(), Failure> {
    if CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut out = std::io::stdout().lock();
    match out.write_fmt(args).and_then(|_| out.write_all(b"\n")) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
            CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => Err(Failure::failed(format!(
            "cannot write to the standard output: {e}"
        ))),
    }
}

/// Writes one line on the standard error, ignoring errors (the [`errln!`] macro).
pub fn error_line(args: std::fmt::Arguments) {
    let mut err = std::io::stderr().lock();
    let _ = err.write_fmt(args).and_then(|_| err.write_all(b"\n"));
}

/// `println!` that returns `Result<(), Failure>` instead of panicking ([`line()`]).
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::out::line(format_args!($($arg)*))
    };
}

/// `eprintln!` that never panics ([`error_line`]).
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::out::error_line(format_args!($($arg)*))
    };
}

pub(crate) use errln;
pub(crate) use outln;
