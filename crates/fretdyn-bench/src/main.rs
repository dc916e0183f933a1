//! `fretdyn-bench --against-c DIR`: fretdyn's step timed side by side with the plain C step of
//! the shared perf folder ([`against_c`], docs/PERFORMANCE.md). A developer's yardstick (the C
//! step is not in this repository), kept out of the users' `fretdyn` binary, whose
//! `fretdyn bench` measures steps per second on the user's machine.

mod against_c;

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;

/// Time fretdyn's step against the plain C one of DIR/step_ref.c (built with gcc) on case S1
/// and on a grid of 10–200 modes × 1–50 contacts, after checking that the two agree after
/// 2000 steps. Takes minutes; prints a markdown report.
#[derive(Debug, Parser)]
#[command(name = "fretdyn-bench", version)]
struct Args {
    /// The perf folder, e.g. ../shared/perf (`step_ref.c`, `s1_case.bin`, `grid/`,
    /// `fretdyn_cases/`).
    #[arg(long, value_name = "DIR", value_parser = path)]
    against_c: PathBuf,
    /// The steps of every timed run of both programs, instead of 200000 on S1 and 50000 on
    /// the grid (for a quick check; not with --write).
    #[arg(long)]
    steps: Option<u64>,
    /// Interleaved pairs (C, fretdyn) per timed case; medians are reported. At least 5 with
    /// --write.
    #[arg(long, default_value_t = 5)]
    reps: usize,
    /// Only case S1 (seconds) or only the grid (minutes).
    #[arg(long, value_enum)]
    only: Option<against_c::Part>,
    /// Also put the report in this markdown file, between the lines
    /// `<!-- against-c:begin -->` and `<!-- against-c:end -->` (appended with them when they
    /// are absent).
    #[arg(long, value_name = "FILE", value_parser = path)]
    write: Option<PathBuf>,
}

/// A non-empty path.
fn path(value: &str) -> Result<PathBuf, String> {
    match value {
        "" => Err("an empty path: give a file or folder name".into()),
        _ => Ok(PathBuf::from(value)),
    }
}

/// Why the command stopped: its exit code (2: the input, 1: the measurement) and a one-line
/// message.
#[derive(Debug)]
pub struct Failure(u8, String);

impl Failure {
    /// An input error (exit code 2).
    pub fn input(message: impl Into<String>) -> Self {
        Self(2, message.into())
    }

    /// A failure of the measurement itself (exit code 1).
    pub fn failed(message: impl Into<String>) -> Self {
        Self(1, message.into())
    }
}

/// One line on the standard output (the [`outln!`] macro); a closed pipe is not an error.
pub fn out_line(args: std::fmt::Arguments) -> Result<(), Failure> {
    match writeln!(std::io::stdout().lock(), "{args}") {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Failure::failed(format!(
            "cannot write to the standard output: {e}"
        ))),
        _ => Ok(()),
    }
}

/// `println!` that returns `Result<(), Failure>` ([`out_line`]).
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::out_line(format_args!($($arg)*))
    };
}

/// `eprintln!` that ignores errors of the standard error.
macro_rules! errln {
    ($($arg:tt)*) => {{
        let _ = writeln!(std::io::stderr().lock(), $($arg)*);
    }};
}

pub(crate) use errln;
pub(crate) use outln;

/// The processor's model name (Linux), for the report's header.
pub fn cpu_model() -> String {
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let model = info.lines().find_map(|l| {
        l.strip_prefix("model name")
            .and_then(|rest| rest.split(':').nth(1))
    });
    model.map_or_else(|| "unknown CPU".into(), |m| m.trim().to_string())
}

fn main() -> ExitCode {
    let args = match Args::try_parse() {
        Ok(args) => args,
        Err(e) if !e.use_stderr() => e.exit(),
        // a command-line error in one line (exit code 2)
        Err(e) => {
            let text = e.render().to_string();
            let words: Vec<&str> = (text.lines())
                .take_while(|l| !l.trim().is_empty())
                .map(|l| l.trim().trim_start_matches("error: "))
                .collect();
            errln!("error: {} (see 'fretdyn-bench --help')", words.join(" "));
            return ExitCode::from(2);
        }
    };
    let options = against_c::Options {
        dir: args.against_c,
        reps: args.reps,
        only: args.only,
        steps: args.steps,
        write: args.write,
    };
    match against_c::main(&options) {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure(code, message)) => {
            errln!("error: {message}");
            ExitCode::from(code)
        }
    }
}
