//! The `fretdyn` command: run case files, verify against the analytic solutions, benchmark.

// The doc comments of the commands and their arguments are clap's `--help` text, written for
// the terminal: `<case name>` and `[flow]` there are words, not HTML or links.
#![allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]

mod bench;
mod folder;
mod life;
mod modes;
mod out;
mod plot;
mod progress;
mod results_plots;
mod run;
mod signals;
mod stability;
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
    /// seeds) on every core: one row per finished run in DIR/study.csv. Run again after a
    /// crash or Ctrl-C/SIGTERM (which drop the runs under way), the finished runs are
    /// skipped — only if the study and its inputs (base case, files it reads) are unchanged:
    /// a table of other inputs is refused (see --fresh).
    Sweep {
        /// Study file (TOML), see examples/study_clearance.toml.
        #[arg(value_parser = path)]
        study: PathBuf,
        /// Output folder [default: fretdyn_results/<study name>].
        #[arg(short, long, value_parser = path)]
        output: Option<PathBuf>,
        /// Runs at a time [default: one per core].
        #[arg(short, long, default_value_t = 0, hide_default_value = true)]
        jobs: usize,
        /// Start afresh: replace the table (and the percentiles and plots) of an earlier
        /// study in the folder instead of continuing it.
        #[arg(long)]
        fresh: bool,
        /// No progress bar and no report.
        #[arg(short, long)]
        quiet: bool,
    },
    /// Draw the figures of a folder fretdyn wrote again: a run's (forces, displacements,
    /// orbits in the holes, peak-force histograms, wear work rates), a study's (study.png,
    /// percentiles.png), a life's (life.png), a modes folder's (mode_shapes.png) or `bench
    /// --scaling`'s (scaling.png); the kind of folder is told by the files in it.
    Plot {
        /// Folder written by `fretdyn run`, `sweep`, `life`, `modes` or `bench --scaling`.
        #[arg(value_parser = path)]
        dir: PathBuf,
        /// The y axis of a study's study.png: log when the values span two decades or more
        /// (auto), or always linear or log.
        #[arg(long, value_enum, default_value_t = YAxis::Auto)]
        y_scale: YAxis,
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
    /// Connors fluid-elastic stability check of every mode of a case with a [flow] section
    /// (docs/FLOW.md), and of the modes of each support condition of its [stability]:
    /// frequency, damping, effective and critical velocities, their ratio, the mode's plane;
    /// printed and written as stability.json and stability.csv.
    Stability {
        /// Case file (TOML) with [flow] and [[flow.zones]].
        #[arg(value_parser = path)]
        case: PathBuf,
        /// Output folder [default: fretdyn_results/<case name>_stability].
        #[arg(short, long, value_parser = path)]
        output: Option<PathBuf>,
    },
    /// Service life of a case with a [life] section and contacts with wear (docs/WEAR.md):
    /// windows of vibration, scar growth, the scars fed back into the obstacles, to the
    /// target time; writes life.csv, life.json, scars.csv and life.png. Checkpointed after
    /// every life step (and inside long windows): Ctrl-C or SIGTERM stops after a
    /// checkpoint, and --resume DIR continues it.
    Life {
        /// Case file (TOML) with [life] and contacts with `wear`.
        #[arg(value_parser = path, required_unless_present = "resume")]
        case: Option<PathBuf>,
        /// Continue the interrupted (Ctrl-C, SIGTERM, killed) life in this folder from its
        /// last checkpoint; the results are those of an uninterrupted life.
        #[arg(long, value_name = "DIR", value_parser = path, conflicts_with = "case")]
        resume: Option<PathBuf>,
        /// Wall-clock seconds between checkpoints inside a window of vibration (one is
        /// written after every life step too).
        #[arg(long, default_value_t = 60.0, value_name = "SECONDS")]
        checkpoint_every: f64,
        /// Output folder [default: fretdyn_results/<case name>/life, beside what `fretdyn run`
        /// of the case writes].
        #[arg(short, long, value_parser = path)]
        output: Option<PathBuf>,
        /// Do not draw life.png.
        #[arg(long)]
        no_plots: bool,
        /// Also run the life with max_depth_change halved N times (at most 10: each halving
        /// about doubles the life steps) and write the depth at the end against it
        /// (convergence.csv, convergence.png).
        #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=life::MAX_HALVINGS as i64))]
        halvings: u32,
    },
    /// Print a shell completion script to standard output, e.g.
    /// `fretdyn completions bash > ~/.local/share/bash-completion/completions/fretdyn`
    /// (zsh: to a folder of $fpath as `_fretdyn`; fish: ~/.config/fish/completions/fretdyn.fish).
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Measure steps per second on V1 and on a synthetic 50-mode, 8-contact tube.
    Bench {
        /// Steps per run of the synthetic tube [default: 200000] (V1 runs its 4000 steps, 20 ×
        /// repeat times).
        #[arg(long)]
        steps: Option<u64>,
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
        /// Instead: time two case files against each other in this process, alternately
        /// (the order swapped every round), and report the median and quartiles of the
        /// per-round ratio of steps/s B/A — what resolves a few per cent on a shared machine
        /// (e.g. one friction method against another; --steps overrides both cases' steps).
        #[arg(long, num_args = 2, value_names = ["A", "B"], value_parser = path,
              conflicts_with = "scaling")]
        pair: Option<Vec<PathBuf>>,
        /// With --pair: rounds (each runs A and B once).
        #[arg(long, default_value_t = 100, requires = "pair")]
        rounds: usize,
    },
}

/// The y axis of a study's figure (`fretdyn plot --y-scale`).
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum YAxis {
    Auto,
    Linear,
    Log,
}

impl From<YAxis> for plot::YScale {
    fn from(a: YAxis) -> Self {
        match a {
            YAxis::Auto => plot::YScale::Auto,
            YAxis::Linear => plot::YScale::Linear,
            YAxis::Log => plot::YScale::Log,
        }
    }
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
    let mut lines = text.lines();
    let mut first = lines
        .next()
        .unwrap_or_default()
        .trim_start_matches("error: ")
        .trim()
        .to_string();
    // the indented lines right after it belong to it: the missing arguments of "the following
    // required arguments were not provided:", the "[possible values: …]" of an invalid value
    let listed: Vec<&str> = lines
        .take_while(|l| l.starts_with(' '))
        .map(str::trim)
        .collect();
    if !listed.is_empty() {
        first = format!("{first} {}", listed.join(", "));
    }
    // the help of the subcommand given, if one was
    let command = std::env::args()
        .skip(1)
        .find(|a| Cli::command().find_subcommand(a).is_some())
        .map_or_else(|| "fretdyn".to_string(), |sub| format!("fretdyn {sub}"));
    errln!("error: {first} (see '{command} --help')");
    ExitCode::from(EXIT_INPUT)
}

fn main() -> ExitCode {
    signals::install();
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
            fresh,
            quiet,
        } => sweep::main(&study, output, jobs, fresh, quiet),
        Command::Plot { dir, y_scale } => results_plots::plot_folder(&dir, y_scale.into())
            .and_then(|files| {
                files
                    .iter()
                    .try_for_each(|f| outln!("wrote {}", f.display()))
            }),
        Command::Verify { output, quiet } => verify::main(&output, quiet),
        Command::Completions { shell } => {
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "fretdyn", &mut script);
            outln!("{}", String::from_utf8_lossy(&script).trim_end())
        }
        Command::Modes {
            case,
            output,
            shown,
        } => modes::main(&case, output, shown),
        Command::Stability { case, output } => stability::main(&case, output),
        Command::Life {
            case,
            resume,
            checkpoint_every,
            output,
            no_plots,
            halvings,
        } => {
            if !(checkpoint_every.is_finite() && checkpoint_every > 0.0) {
                Err(Failure::input(format!(
                    "--checkpoint-every: must be a positive number of seconds (got {checkpoint_every})"
                )))
            } else {
                life::main(&life::Options {
                    case,
                    resume,
                    output,
                    plots: !no_plots,
                    halvings,
                    checkpoint_seconds: checkpoint_every,
                })
            }
        }
        Command::Bench {
            steps,
            repeat,
            modes,
            contacts,
            scaling,
            pair,
            rounds,
        } => match (pair.as_deref(), scaling) {
            // (clap takes exactly two values for --pair)
            (Some([a, b]), _) => bench::pair(a, b, rounds, steps),
            (_, Some(dir)) => bench::scaling(&dir, steps.unwrap_or(20_000).min(20_000)),
            (_, None) => bench::main(steps.unwrap_or(200_000), repeat, modes, contacts),
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
