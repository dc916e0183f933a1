//! The `fretdyn` command: run case files, verify against the analytic solutions, benchmark.

mod bench;
mod modes;
mod out;
mod plot;
mod progress;
mod results_plots;
mod run;
mod sweep;
mod verify;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};

use crate::out::{errln, outln};

/// Nonlinear vibration of structures on a modal basis rattling against obstacles with Coulomb
/// friction (explicit central differences; penalty, Active Set or projected Gauss–Seidel).
#[derive(Debug, Parser)]
#[command(name = "fretdyn", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run a case file; without one, run the built-in demo (V1a with the three methods).
    /// Results are streamed to the output folder; Ctrl-C or SIGTERM (timeout, a batch
    /// scheduler, docker stop) stops after a checkpoint.
    Run {
        /// Case file (TOML). See examples/ for the reference of every key.
        #[arg(value_parser = path)]
        case: Option<PathBuf>,
        /// Continue the interrupted (Ctrl-C, SIGTERM, killed, out of disk) run in this folder
        /// from its last checkpoint; the results are those of an uninterrupted run.
        #[arg(long, value_name = "DIR", value_parser = path)]
        resume: Option<PathBuf>,
        /// Wall-clock seconds between checkpoints.
        #[arg(long, default_value_t = 60.0, value_name = "SECONDS")]
        checkpoint_every: f64,
        /// Output folder [default: fretdyn_results/<case name>].
        #[arg(short, long, value_parser = path)]
        output: Option<PathBuf>,
        /// No progress bar and no report on stdout.
        #[arg(short, long)]
        quiet: bool,
        /// Do not write PNG plots.
        #[arg(long)]
        no_plots: bool,
    },
    /// Run a parametric / Monte-Carlo study (a base case, parameters as a grid or a list,
    /// seeds) on every core: one row per finished run in DIR/study.csv; run again after a
    /// crash, the finished runs are skipped.
    Sweep {
        /// Study file (TOML), see examples/study_clearance.toml.
        #[arg(value_parser = path)]
        study: PathBuf,
        /// Output folder [default: fretdyn_results/<study name>].
        #[arg(short, long, value_parser = path)]
        output: Option<PathBuf>,
        /// Runs at a time [default: one per core].
        #[arg(short, long, default_value_t = 0)]
        jobs: usize,
        /// No progress bar and no report.
        #[arg(short, long)]
        quiet: bool,
    },
    /// Draw the plots of a run folder again (forces, displacements, orbits in the holes,
    /// peak-force histograms, wear work rates).
    Plot {
        /// Folder written by `fretdyn run`.
        #[arg(value_parser = path)]
        dir: PathBuf,
    },
    /// Run V1a, V1b, V1c (docs/THEORY.md §6) with every method, compare with the analytic solution,
    /// write the figures; exit code 1 if a check fails.
    Verify {
        /// Output folder for figures and verification.json.
        #[arg(short, long, default_value = "fretdyn_results/verify", value_parser = path)]
        output: PathBuf,
        /// Print only failures and the final line.
        #[arg(short, long)]
        quiet: bool,
    },
    /// Print the modal basis of a case (frequency table), write it as .npz and, for a tube,
    /// a picture of its first mode shapes.
    Modes {
        /// Case file (TOML).
        #[arg(value_parser = path)]
        case: PathBuf,
        /// Output folder [default: fretdyn_results/<case name>_modes].
        #[arg(short, long, value_parser = path)]
        output: Option<PathBuf>,
        /// Mode shapes drawn.
        #[arg(long, default_value_t = 4)]
        shown: usize,
    },
    /// Measure steps per second on V1 and on a synthetic 50-mode, 8-contact tube.
    Bench {
        /// Steps per run of the synthetic tube (V1 runs its 4000 steps, 20 × repeat times).
        #[arg(long, default_value_t = 200_000)]
        steps: u64,
        /// Repetitions; the best is reported.
        #[arg(long, default_value_t = 3)]
        repeat: usize,
        /// Modes of the synthetic tube.
        #[arg(long, default_value_t = 50)]
        modes: usize,
        /// Contacts of the synthetic tube.
        #[arg(long, default_value_t = 8)]
        contacts: usize,
        /// Instead: the cost of a step over 10–200 modes × 1–50 contacts, per method, as a
        /// table, `scaling.csv` and `scaling.png` in this folder.
        #[arg(long, value_name = "DIR", value_parser = path)]
        scaling: Option<PathBuf>,
    },
}

/// Exit code of input errors (bad case file, bad option).
pub const EXIT_INPUT: u8 = 2;
/// Exit code of a run that failed (diverged, verification check failed).
pub const EXIT_FAILED: u8 = 1;

/// A file or folder argument: anything but an empty string.
fn path(value: &str) -> Result<PathBuf, String> {
    if value.is_empty() {
        Err("an empty path: give a file or folder name".into())
    } else {
        Ok(PathBuf::from(value))
    }
}

/// A command-line error in one line with a hint to the help (exit code 2); the help and the
/// version as clap prints them.
fn command_line_error(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        let _ = e.print();
        return ExitCode::from(e.exit_code().clamp(0, 255) as u8);
    }
    let text = e.render().to_string();
    let first = text
        .lines()
        .next()
        .unwrap_or_default()
        .trim_start_matches("error: ")
        .trim();
    // the help of the subcommand given, if one was
    let command = std::env::args()
        .skip(1)
        .find(|a| Cli::command().find_subcommand(a).is_some())
        .map_or_else(|| "fretdyn".to_string(), |sub| format!("fretdyn {sub}"));
    errln!("error: {first} (see '{command} --help')");
    ExitCode::from(EXIT_INPUT)
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return command_line_error(e),
    };
    let outcome = match cli.command {
        Command::Run {
            case,
            resume,
            checkpoint_every,
            output,
            quiet,
            no_plots,
        } => {
            // Ctrl-C, SIGTERM, SIGHUP: stop at the next progress report, after a checkpoint (a
            // second signal while stopping is ignored: the files are being closed)
            let _ = ctrlc::set_handler(|| {
                run::INTERRUPTED.store(true, std::sync::atomic::Ordering::Relaxed)
            });
            let options = run::Options {
                output,
                quiet,
                plots: !no_plots,
                checkpoint_seconds: checkpoint_every,
            };
            if !(checkpoint_every.is_finite() && checkpoint_every > 0.0) {
                Err(Failure::input(format!(
                    "--checkpoint-every: must be a positive number of seconds (got {checkpoint_every})"
                )))
            } else {
                run::main(case.as_deref(), resume.as_deref(), &options)
            }
        }
        Command::Sweep {
            study,
            output,
            jobs,
            quiet,
        } => sweep::main(&study, output, jobs, quiet),
        Command::Plot { dir } => results_plots::plot_run(&dir).and_then(|files| {
            files
                .iter()
                .try_for_each(|f| outln!("wrote {}", f.display()))
        }),
        Command::Verify { output, quiet } => verify::main(&output, quiet),
        Command::Modes {
            case,
            output,
            shown,
        } => modes::main(&case, output, shown),
        Command::Bench {
            steps,
            repeat,
            modes,
            contacts,
            scaling,
        } => match scaling {
            Some(dir) => bench::scaling(&dir, steps.min(20_000)),
            None => bench::main(steps, repeat, modes, contacts),
        },
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            errln!("error: {}", failure.message);
            ExitCode::from(failure.code)
        }
    }
}

/// A failure to report: a one-line message and the exit code.
#[derive(Debug)]
pub struct Failure {
    pub message: String,
    pub code: u8,
}

impl Failure {
    /// An input error (exit code 2).
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: EXIT_INPUT,
        }
    }

    /// A failed run or check (exit code 1).
    pub fn failed(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: EXIT_FAILED,
        }
    }
}
