//! `fretdyn-bench --against-c DIR`: fretdyn's step timed side by side with a plain C99
//! implementation of the same algorithm (`DIR/step_ref.c`, the yardstick of issue [2.3]),
//! following `DIR/side_by_side.sh`:
//!
//! 1. the C program is built with `gcc -std=c99 -O3 -march=native` in a temporary folder;
//! 2. agreement after 2 000 steps of Gauss–Seidel with the radial projection (the C
//!    algorithm, docs/THEORY.md §2–§4) on S1 and on every grid case: `Σ|q|` after the last step,
//!    the friction dissipation `Σ_steps Σ_closed |R_T·v_T| Δt` (fretdyn: `Σ wear_work`, THEORY
//!    §5) and the Gauss–Seidel sweeps; on S1 they must agree to 1e-12 relative, or the timings
//!    compare different computations;
//! 3. REPS interleaved pairs (C, fretdyn, C, fretdyn, …) of each program's time-loop steps/s;
//!    the median of the per-pair ratios fretdyn/C (above 1: fretdyn is faster);
//! 4. on the grid, the least-squares slope of µs/step against the number of modes, per
//!    contact count.
//!
//! fretdyn runs in this process ([`simulate`], keeping two output samples); C runs as a
//! subprocess and reports its own `steps_per_s`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use fretdyn::Case;
use fretdyn::integrator::simulation::Termination;
use fretdyn::simulate;

use crate::{Failure, cpu_model, errln, outln};
use std::io::Write as _;

/// The part of the comparison to run (`--only`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Part {
    /// Case S1 (30 modes, 5 contacts) with the four fretdyn methods.
    S1,
    /// The 16 cases of 10–200 modes × 1–50 contacts, GS radial against C and C `--preH`.
    Grid,
}

/// Options of `fretdyn-bench --against-c`.
#[derive(Debug, Clone)]
pub struct Options {
    /// The perf folder (`step_ref.c`, `s1_case.bin`, `grid/`, `fretdyn_cases/`).
    pub dir: PathBuf,
    /// Interleaved pairs per timed case.
    pub reps: usize,
    /// Only S1 or only the grid; both when `None`.
    pub only: Option<Part>,
    /// Steps of every timed run instead of [`S1_STEPS`] / [`GRID_STEPS`].
    pub steps: Option<u64>,
    /// A markdown file whose section between [`BEGIN`] and [`END`] receives the report.
    pub write: Option<PathBuf>,
}

/// Steps of the agreement runs: the checksums agree to round-off up to ~30 000 steps, past
/// which the rattling is chaotic (DIR/README.md).
pub const AGREEMENT_STEPS: u64 = 2000;
/// Timed steps of S1 (the generated `s1_*_200000.toml` cases).
pub const S1_STEPS: u64 = 200_000;
/// Timed steps of a grid case (the `.bin` headers and `p*_c*_gs_radial_50000.toml`).
pub const GRID_STEPS: u64 = 50_000;
/// Largest relative difference of the S1 checksums for the two programs to agree.
pub const AGREEMENT_TOLERANCE: f64 = 1e-12;
/// Pairs needed for a table worth writing to the docs.
pub const MIN_REPS_TO_WRITE: usize = 5;
/// fretdyn's methods timed on S1 (the file names of `fretdyn_cases/s1/`).
const S1_METHODS: [&str; 4] = ["gs_radial", "gs_exact", "active_set", "penalty"];
/// Modes and contacts of the grid (`grid/p{P}_c{C}.bin`).
const GRID_MODES: [u32; 4] = [10, 30, 100, 200];
const GRID_CONTACTS: [u32; 4] = [1, 5, 20, 50];

/// Marker lines of the section `--write` replaces.
pub const BEGIN: &str = "<!-- against-c:begin -->";
pub const END: &str = "<!-- against-c:end -->";

/// Entry point of `fretdyn-bench --against-c DIR`.
pub fn main(options: &Options) -> Result<(), Failure> {
    check_options(options)?;
    let files = Files::check(&options.dir, options.only)?;
    let s1_steps = options.steps.unwrap_or(S1_STEPS);
    let grid_steps = options.steps.unwrap_or(GRID_STEPS);
    // every case is read before minutes of measurement, so that a bad one stops it at once
    let s1_cases = (files.s1_timing.iter())
        .map(|path| load(path, s1_steps))
        .collect::<Result<Vec<_>, _>>()?;
    let grid_cases = (files.grid.iter())
        .map(|g| load(&g.case, grid_steps))
        .collect::<Result<Vec<_>, _>>()?;
    let build = build_c(&options.dir)?;
    let c = &build.exe;
    let started = now_utc();
    let runs = |part| options.only.is_none_or(|only| only == part);

    let mut report = Report::default();
    // 1. agreement
    if runs(Part::S1) {
        errln!("against-c: agreement on S1, {AGREEMENT_STEPS} steps");
        let s1 = agreement("S1", c, &files.s1_bin, &files.s1_agreement)?;
        if !s1.agrees() {
            errln!(
                "against-c: DISAGREEMENT on S1 after {AGREEMENT_STEPS} steps: {}; the timings \
                 that follow compare different computations",
                s1.describe()
            );
        }
        report.agreement.push(s1);
    }
    if runs(Part::Grid) {
        for g in &files.grid {
            errln!(
                "against-c: agreement on {}, {AGREEMENT_STEPS} steps",
                g.name
            );
            report
                .agreement
                .push(agreement(&g.name, c, &g.bin, &g.case)?);
        }
    }
    // 2. timing
    let reps = options.reps;
    if runs(Part::S1) {
        let steps = s1_steps;
        for ((method, path), case) in S1_METHODS.iter().zip(&files.s1_timing).zip(&s1_cases) {
            let (mut cs, mut fs) = (Vec::new(), Vec::new());
            for rep in 1..=reps {
                errln!("against-c: S1 {method}, pair {rep}/{reps} ({steps} steps)");
                cs.push(run_c(c, &files.s1_bin, steps, false)?.steps_per_s);
                fs.push(run_fretdyn(case, path)?.steps_per_s);
            }
            report
                .s1
                .push(Timing::new(method.to_string(), steps, &cs, &fs));
        }
    }
    if runs(Part::Grid) {
        let steps = grid_steps;
        for (g, case) in files.grid.iter().zip(&grid_cases) {
            let (mut cs, mut fs, mut ps) = (Vec::new(), Vec::new(), Vec::new());
            for rep in 1..=reps {
                errln!(
                    "against-c: grid {}, C / fretdyn / C --preH {rep}/{reps} ({steps} steps)",
                    g.name
                );
                cs.push(run_c(c, &g.bin, steps, false)?.steps_per_s);
                fs.push(run_fretdyn(case, &g.case)?.steps_per_s);
                ps.push(run_c(c, &g.bin, steps, true)?.steps_per_s);
            }
            report.grid.push(GridTiming {
                modes: g.modes,
                contacts: g.contacts,
                default: Timing::new(g.name.clone(), steps, &cs, &fs),
                pre_h: Timing::new(g.name.clone(), steps, &ps, &fs),
            });
        }
    }

    let header = Header {
        machine: format!(
            "{}, {} logical CPUs",
            cpu_model(),
            std::thread::available_parallelism().map_or(1, |n| n.get())
        ),
        date: started,
        command: command_line(),
        gcc: build.gcc_version.clone(),
        reps,
        s1_steps: runs(Part::S1).then_some(s1_steps),
        grid_steps: runs(Part::Grid).then_some(grid_steps),
    };
    let markdown = report.markdown(&header);
    outln!("{markdown}")?;

    // a disagreement on S1 fails the command (exit code 1) and is not written to the docs
    if let Some(s1) = report
        .agreement
        .iter()
        .find(|a| a.case == "S1" && !a.agrees())
    {
        let unwritten = (options.write.as_ref())
            .map(|f| format!("; {} not written", f.display()))
            .unwrap_or_default();
        return Err(Failure::failed(format!(
            "fretdyn and C disagree on S1 after {AGREEMENT_STEPS} steps ({}): the timings \
             compare different computations{unwritten}",
            s1.describe()
        )));
    }
    if let Some(file) = &options.write {
        write_section(file, &markdown)?;
        errln!("against-c: wrote the section of {}", file.display());
    }
    Ok(())
}

/// The options that can be checked before minutes of measurement.
fn check_options(options: &Options) -> Result<(), Failure> {
    if options.reps == 0 {
        return Err(Failure::input(
            "--reps 0: give the number of interleaved pairs, at least 1 (5 for --write)",
        ));
    }
    if options.steps == Some(0) {
        return Err(Failure::input(
            "--steps 0: give the steps of every timed run (or leave it out: 200000 on S1, \
             50000 on the grid)",
        ));
    }
    if let Some(file) = &options.write {
        if options.reps < MIN_REPS_TO_WRITE {
            return Err(Failure::input(format!(
                "--write {}: the table of the docs needs --reps {MIN_REPS_TO_WRITE} or more (got {})",
                file.display(),
                options.reps
            )));
        }
        if options.steps.is_some() {
            return Err(Failure::input(format!(
                "--write {}: the table of the docs is measured on the full runs \
                 ({S1_STEPS} steps on S1, {GRID_STEPS} on the grid): leave out --steps",
                file.display()
            )));
        }
        if !file.is_file() {
            return Err(Failure::input(format!(
                "--write {}: no such file; give an existing markdown file (e.g. docs/dev/PERFORMANCE_LOG.md)",
                file.display()
            )));
        }
        // its markers are checked now rather than after the measurement
        let text = std::fs::read_to_string(file)
            .map_err(|e| Failure::input(format!("--write {}: {e}", file.display())))?;
        replace_section(&text, "")
            .map_err(|e| Failure::input(format!("--write {}: {e}", file.display())))?;
    }
    Ok(())
}

/// The files of the perf folder the comparison reads.
struct Files {
    s1_bin: PathBuf,
    s1_agreement: PathBuf,
    /// One per entry of [`S1_METHODS`].
    s1_timing: Vec<PathBuf>,
    grid: Vec<GridFiles>,
}

struct GridFiles {
    name: String,
    modes: u32,
    contacts: u32,
    bin: PathBuf,
    case: PathBuf,
}

impl Files {
    /// The paths, each checked to exist: a one-line error names the first missing one.
    fn check(dir: &Path, only: Option<Part>) -> Result<Self, Failure> {
        let hint = "pass the perf folder of the shared material, e.g. --against-c ../shared/perf";
        if !dir.is_dir() {
            return Err(Failure::input(format!(
                "--against-c {}: no such folder; {hint}",
                dir.display()
            )));
        }
        let need = |rel: String| -> Result<PathBuf, Failure> {
            let path = dir.join(&rel);
            if path.is_file() {
                Ok(path)
            } else {
                Err(Failure::input(format!(
                    "--against-c {}: {} is missing; {hint}",
                    dir.display(),
                    path.display()
                )))
            }
        };
        need("step_ref.c".into())?;
        let cases = "fretdyn_cases";
        let s1 = only != Some(Part::Grid);
        let grid = only != Some(Part::S1);
        let mut files = Files {
            s1_bin: dir.join("s1_case.bin"),
            s1_agreement: PathBuf::new(),
            s1_timing: Vec::new(),
            grid: Vec::new(),
        };
        if s1 {
            files.s1_bin = need("s1_case.bin".into())?;
            files.s1_agreement = need(format!("{cases}/s1/s1_gs_radial_{AGREEMENT_STEPS}.toml"))?;
            for method in S1_METHODS {
                files
                    .s1_timing
                    .push(need(format!("{cases}/s1/s1_{method}_{S1_STEPS}.toml"))?);
            }
        }
        if grid {
            for modes in GRID_MODES {
                for contacts in GRID_CONTACTS {
                    let name = format!("p{modes}_c{contacts}");
                    files.grid.push(GridFiles {
                        bin: need(format!("grid/{name}.bin"))?,
                        case: need(format!("{cases}/grid/{name}_gs_radial_{GRID_STEPS}.toml"))?,
                        name,
                        modes,
                        contacts,
                    });
                }
            }
        }
        Ok(files)
    }
}

/// The C program, built in a temporary folder removed on drop.
struct CBuild {
    dir: PathBuf,
    exe: PathBuf,
    gcc_version: String,
}

impl Drop for CBuild {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// `gcc -std=c99 -O3 -march=native -Wall -o TMP/step_ref DIR/step_ref.c -lm`.
fn build_c(dir: &Path) -> Result<CBuild, Failure> {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let tmp =
        std::env::temp_dir().join(format!("fretdyn-against-c-{}-{nanos}", std::process::id()));
    std::fs::create_dir_all(&tmp)
        .map_err(|e| Failure::failed(format!("{}: {e}", tmp.display())))?;
    let mut build = CBuild {
        exe: tmp.join("step_ref"),
        dir: tmp,
        gcc_version: String::new(),
    };
    let source = dir.join("step_ref.c");
    errln!("against-c: building {} with gcc", source.display());
    let out = Command::new("gcc")
        .args(["-std=c99", "-O3", "-march=native", "-Wall", "-o"])
        .arg(&build.exe)
        .arg(&source)
        .arg("-lm")
        .output()
        .map_err(|e| {
            Failure::failed(format!(
                "cannot run gcc ({e}): --against-c builds {} with gcc; install gcc \
                 (e.g. apt-get install gcc) or put it on the PATH",
                source.display()
            ))
        })?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let first = stderr
            .lines()
            .find(|l| l.contains("error"))
            .or(stderr.lines().next());
        return Err(Failure::failed(format!(
            "gcc failed to build {} ({}): {}",
            source.display(),
            out.status,
            first.unwrap_or("no message")
        )));
    }
    build.gcc_version = Command::new("gcc")
        .arg("-dumpfullversion")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    Ok(build)
}

/// What `step_ref` prints (its `key value` lines).
#[derive(Debug, Clone, PartialEq)]
struct COutput {
    steps_per_s: f64,
    closed_any_fraction: f64,
    avg_pgs_sweeps: f64,
    sum_abs_q: f64,
    dissipation: f64,
}

impl COutput {
    /// Parses the report of `step_ref`; `None` names the first key missing or unreadable.
    fn parse(text: &str) -> Result<Self, &'static str> {
        let field = |key: &'static str| -> Result<f64, &'static str> {
            text.lines()
                .find_map(|l| {
                    let mut words = l.split_whitespace();
                    (words.next() == Some(key)).then(|| words.next())?
                })
                .and_then(|v| v.parse().ok())
                .ok_or(key)
        };
        Ok(Self {
            steps_per_s: field("steps_per_s")?,
            closed_any_fraction: field("closed_any_fraction")?,
            avg_pgs_sweeps: field("avg_pgs_sweeps")?,
            sum_abs_q: field("checksum_sum_abs_q")?,
            dissipation: field("checksum_friction_dissipation")?,
        })
    }

    /// Total Gauss–Seidel sweeps of a run of `steps`, from the mean per closed step, as
    /// side_by_side.sh computes it: round(avg × round(closed fraction × steps)).
    fn sweeps(&self, steps: u64) -> u64 {
        let closed_steps = (self.closed_any_fraction * steps as f64).round();
        (self.avg_pgs_sweeps * closed_steps).round() as u64
    }
}

/// `step_ref BIN STEPS [--preH]`.
fn run_c(exe: &Path, bin: &Path, steps: u64, pre_h: bool) -> Result<COutput, Failure> {
    let mut cmd = Command::new(exe);
    cmd.arg(bin).arg(steps.to_string());
    if pre_h {
        cmd.arg("--preH");
    }
    let out = cmd
        .output()
        .map_err(|e| Failure::failed(format!("cannot run {}: {e}", exe.display())))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        return Err(Failure::failed(format!(
            "step_ref {} {steps} failed ({}): {}",
            bin.display(),
            out.status,
            stderr.lines().next().unwrap_or("no message")
        )));
    }
    COutput::parse(&stdout).map_err(|key| {
        Failure::failed(format!(
            "step_ref {} {steps}: no readable `{key}` line in its output",
            bin.display()
        ))
    })
}

/// The same numbers from a fretdyn run.
#[derive(Debug, Clone, PartialEq)]
struct FretdynOutput {
    steps_per_s: f64,
    sweeps: u64,
    sum_abs_q: f64,
    dissipation: f64,
}

/// Loads a case file with its steps set to `steps` and two output samples (t = 0 and the last
/// step).
fn load(path: &Path, steps: u64) -> Result<Case, Failure> {
    let mut case = Case::from_file(path).map_err(|e| Failure::input(e.in_file(path)))?;
    case.settings.steps = steps;
    case.settings.output_every = steps;
    Ok(case)
}

/// Runs `case` in memory: the checksums of the C program from its results (as
/// `fretdyn_cases/checksums.py` reads them from a run folder) and its time-loop steps/s.
fn run_fretdyn(case: &Case, path: &Path) -> Result<FretdynOutput, Failure> {
    let r = simulate(&case.model, &case.settings).map_err(|e| Failure::input(e.in_file(path)))?;
    if r.termination != Termination::Completed {
        return Err(Failure::failed(format!(
            "{}: the fretdyn run did not complete: {:?}",
            path.display(),
            r.termination
        )));
    }
    let q = &r.recorder.q;
    let last = r.recorder.len().checked_sub(1).ok_or_else(|| {
        Failure::failed(format!("{}: the run recorded no sample", path.display()))
    })?;
    // the last sample must be the state after the last step
    let t_end = r.steps as f64 * r.dt;
    if (r.recorder.t[last] - t_end).abs() > 1e-12 * t_end.max(1.0) {
        return Err(Failure::failed(format!(
            "{}: the last output sample is at t = {} s, not at the end of the run ({t_end} s)",
            path.display(),
            r.recorder.t[last]
        )));
    }
    Ok(FretdynOutput {
        steps_per_s: r.steps_per_second(),
        sweeps: r.solver.gs_sweeps_total,
        sum_abs_q: q.row(last).iter().map(|v| v.abs()).sum(),
        dissipation: r.contacts.iter().map(|c| c.wear_work).sum(),
    })
}

/// Checksums of both programs after [`AGREEMENT_STEPS`].
#[derive(Debug, Clone, PartialEq)]
struct Agreement {
    case: String,
    c: COutput,
    c_sweeps: u64,
    fretdyn: FretdynOutput,
}

impl Agreement {
    fn q_rel(&self) -> f64 {
        relative(self.fretdyn.sum_abs_q, self.c.sum_abs_q)
    }

    fn dissipation_rel(&self) -> f64 {
        relative(self.fretdyn.dissipation, self.c.dissipation)
    }

    /// Both checksums within [`AGREEMENT_TOLERANCE`] and the same sweeps.
    fn agrees(&self) -> bool {
        self.q_rel() <= AGREEMENT_TOLERANCE
            && self.dissipation_rel() <= AGREEMENT_TOLERANCE
            && self.c_sweeps == self.fretdyn.sweeps
    }

    fn describe(&self) -> String {
        format!(
            "Σ|q| relative difference {:.1e}, dissipation {:.1e} (tolerance {AGREEMENT_TOLERANCE:.0e}), \
             PGS sweeps C {} fretdyn {}",
            self.q_rel(),
            self.dissipation_rel(),
            self.c_sweeps,
            self.fretdyn.sweeps
        )
    }
}

fn agreement(name: &str, c: &Path, bin: &Path, case_path: &Path) -> Result<Agreement, Failure> {
    let case = load(case_path, AGREEMENT_STEPS)?;
    let c_out = run_c(c, bin, AGREEMENT_STEPS, false)?;
    let fretdyn = run_fretdyn(&case, case_path)?;
    Ok(Agreement {
        case: name.to_string(),
        c_sweeps: c_out.sweeps(AGREEMENT_STEPS),
        c: c_out,
        fretdyn,
    })
}

/// |a − b| / |b|.
fn relative(a: f64, b: f64) -> f64 {
    if a == b { 0.0 } else { (a - b).abs() / b.abs() }
}

/// Median, min and max of a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Spread {
    median: f64,
    min: f64,
    max: f64,
}

impl Spread {
    fn of(values: &[f64]) -> Self {
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = match n {
            0 => f64::NAN,
            _ if n % 2 == 1 => v[n / 2],
            _ => 0.5 * (v[n / 2 - 1] + v[n / 2]),
        };
        Self {
            median,
            min: v.first().copied().unwrap_or(f64::NAN),
            max: v.last().copied().unwrap_or(f64::NAN),
        }
    }
}

/// Interleaved pairs of one case: steps/s of each side and the per-pair ratios fretdyn/C.
#[derive(Debug, Clone, PartialEq)]
struct Timing {
    label: String,
    steps: u64,
    pairs: usize,
    c: Spread,
    fretdyn: Spread,
    ratio: Spread,
    /// µs per step, median over the pairs.
    c_us: f64,
    fretdyn_us: f64,
}

impl Timing {
    /// fretdyn's fastest run over C's fastest.
    fn best_ratio(&self) -> f64 {
        self.fretdyn.max / self.c.max
    }

    fn new(label: String, steps: u64, c: &[f64], fretdyn: &[f64]) -> Self {
        let ratios: Vec<f64> = fretdyn.iter().zip(c).map(|(f, c)| f / c).collect();
        let us = |v: &[f64]| Spread::of(&v.iter().map(|s| 1e6 / s).collect::<Vec<_>>()).median;
        Self {
            label,
            steps,
            pairs: ratios.len(),
            c: Spread::of(c),
            fretdyn: Spread::of(fretdyn),
            ratio: Spread::of(&ratios),
            c_us: us(c),
            fretdyn_us: us(fretdyn),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
struct GridTiming {
    modes: u32,
    contacts: u32,
    /// Against C rebuilding H every step.
    default: Timing,
    /// Against C with H precomputed (`--preH`).
    pre_h: Timing,
}

/// Least-squares slope of `y` on `x`: Σ(x − x̄)(y − ȳ) / Σ(x − x̄)².
fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// What the report says about the measurement itself.
struct Header {
    machine: String,
    date: String,
    command: String,
    gcc: String,
    reps: usize,
    s1_steps: Option<u64>,
    grid_steps: Option<u64>,
}

#[derive(Default)]
struct Report {
    agreement: Vec<Agreement>,
    s1: Vec<Timing>,
    grid: Vec<GridTiming>,
}

impl Report {
    /// The markdown of the report (no trailing newline).
    fn markdown(&self, h: &Header) -> String {
        let mut m = String::new();
        let _ = self.write_markdown(h, &mut m);
        m.trim_end().to_string()
    }

    fn write_markdown(&self, h: &Header, m: &mut String) -> std::fmt::Result {
        writeln!(m, "### fretdyn against a plain C step (`step_ref.c`)")?;
        writeln!(m)?;
        writeln!(m, "- machine: {}", h.machine)?;
        writeln!(m, "- date: {}", h.date)?;
        writeln!(m, "- command: `{}`", h.command)?;
        writeln!(
            m,
            "- fretdyn {} (release build: {}), in process (`simulate`, time-loop steps/s); \
             C: `gcc {} -std=c99 -O3 -march=native`, its own `steps_per_s`",
            env!("CARGO_PKG_VERSION"),
            !cfg!(debug_assertions),
            if h.gcc.is_empty() { "?" } else { &h.gcc }
        )?;
        let mut steps = Vec::new();
        if let Some(s) = h.s1_steps {
            steps.push(format!("S1 {s}"));
        }
        if let Some(s) = h.grid_steps {
            steps.push(format!("grid {s}"));
        }
        writeln!(
            m,
            "- steps per timed run: {}; agreement after {AGREEMENT_STEPS} steps",
            steps.join(", ")
        )?;
        writeln!(
            m,
            "- reps: {} per case, interleaved: C, fretdyn, C, fretdyn, … (grid: C, fretdyn, \
             C --preH, …); ratio = fretdyn/C steps/s (above 1: fretdyn faster), median of the \
             per-pair ratios (min–max); best/best = fretdyn's fastest run over C's fastest (on a \
             shared machine whose speed comes and goes, the ratio when both ran undisturbed)",
            h.reps
        )?;
        writeln!(m)?;

        if !self.agreement.is_empty() {
            writeln!(
                m,
                "#### Agreement after {AGREEMENT_STEPS} steps (GS radial: the C algorithm)"
            )?;
            writeln!(m)?;
            writeln!(
                m,
                "| case | sum\\|q\\| C | sum\\|q\\| fretdyn | rel. diff. | dissipation C (J) \
                 | dissipation fretdyn (J) | rel. diff. | PGS sweeps C | PGS sweeps fretdyn |"
            )?;
            writeln!(m, "|---|---|---|---|---|---|---|---|---|")?;
            for a in &self.agreement {
                writeln!(
                    m,
                    "| {} | {:.16e} | {:.16e} | {:.1e} | {:.16e} | {:.16e} | {:.1e} | {} | {} |",
                    a.case,
                    a.c.sum_abs_q,
                    a.fretdyn.sum_abs_q,
                    a.q_rel(),
                    a.c.dissipation,
                    a.fretdyn.dissipation,
                    a.dissipation_rel(),
                    a.c_sweeps,
                    a.fretdyn.sweeps
                )?;
            }
            writeln!(m)?;
            if let Some(s1) = self.agreement.iter().find(|a| a.case == "S1") {
                if s1.agrees() {
                    writeln!(
                        m,
                        "S1: **fretdyn and C agree** after {AGREEMENT_STEPS} steps (relative \
                         differences ≤ {AGREEMENT_TOLERANCE:.0e}, the same PGS sweeps)."
                    )?;
                } else {
                    writeln!(
                        m,
                        "S1: **DISAGREEMENT: fretdyn and C do not compute the same thing** \
                         ({}); the timings below compare different computations.",
                        s1.describe()
                    )?;
                }
                writeln!(m)?;
            }
        }

        if !self.s1.is_empty() {
            writeln!(
                m,
                "#### S1 (30 modes, 5 contacts): fretdyn's methods against C's GS radial"
            )?;
            writeln!(m)?;
            writeln!(
                m,
                "| fretdyn method | steps | pairs | C steps/s (median) | fretdyn steps/s (median) \
                 | ratio fretdyn/C (median) | min | max | best/best |"
            )?;
            writeln!(m, "|---|---|---|---|---|---|---|---|---|")?;
            for t in &self.s1 {
                writeln!(
                    m,
                    "| {} | {} | {} | {:.4e} | {:.4e} | {:.3} | {:.3} | {:.3} | {:.3} |",
                    t.label,
                    t.steps,
                    t.pairs,
                    t.c.median,
                    t.fretdyn.median,
                    t.ratio.median,
                    t.ratio.min,
                    t.ratio.max,
                    t.best_ratio()
                )?;
            }
            writeln!(m)?;
        }

        if !self.grid.is_empty() {
            writeln!(
                m,
                "#### Grid: fretdyn GS radial against C (H rebuilt every step) and C `--preH` \
                 (H precomputed)"
            )?;
            writeln!(m)?;
            writeln!(
                m,
                "| case | modes | contacts | C steps/s | C --preH steps/s | fretdyn steps/s \
                 | fretdyn/C (min–max) | fretdyn/C --preH (min–max) | best/best, best/best --preH |"
            )?;
            writeln!(m, "|---|---|---|---|---|---|---|---|---|")?;
            for g in &self.grid {
                writeln!(
                    m,
                    "| {} | {} | {} | {:.4e} | {:.4e} | {:.4e} | {:.3} ({:.3}–{:.3}) | {:.3} ({:.3}–{:.3}) | {:.3}, {:.3} |",
                    g.default.label,
                    g.modes,
                    g.contacts,
                    g.default.c.median,
                    g.pre_h.c.median,
                    g.default.fretdyn.median,
                    g.default.ratio.median,
                    g.default.ratio.min,
                    g.default.ratio.max,
                    g.pre_h.ratio.median,
                    g.pre_h.ratio.min,
                    g.pre_h.ratio.max,
                    g.default.best_ratio(),
                    g.pre_h.best_ratio()
                )?;
            }
            writeln!(m)?;
            writeln!(
                m,
                "#### Cost per mode: least-squares slope of µs/step (medians) against the modes \
                 (p = 10, 30, 100, 200)"
            )?;
            writeln!(m)?;
            writeln!(
                m,
                "| contacts | fretdyn µs/(mode·step) | C µs/(mode·step) | C --preH µs/(mode·step) \
                 | fretdyn/C | fretdyn/C --preH |"
            )?;
            writeln!(m, "|---|---|---|---|---|---|")?;
            for contacts in GRID_CONTACTS {
                let row: Vec<&GridTiming> = self
                    .grid
                    .iter()
                    .filter(|g| g.contacts == contacts)
                    .collect();
                if row.len() < 2 {
                    continue;
                }
                let x: Vec<f64> = row.iter().map(|g| f64::from(g.modes)).collect();
                let fit = |f: fn(&GridTiming) -> f64| {
                    slope(&x, &row.iter().map(|g| f(g)).collect::<Vec<_>>())
                };
                let f = fit(|g| g.default.fretdyn_us);
                let c = fit(|g| g.default.c_us);
                let p = fit(|g| g.pre_h.c_us);
                writeln!(
                    m,
                    "| {contacts} | {f:.4} | {c:.4} | {p:.4} | {:.3} | {:.3} |",
                    f / c,
                    f / p
                )?;
            }
            writeln!(m)?;
        }
        Ok(())
    }
}

/// `doc` with the section between [`BEGIN`] and [`END`] replaced by `section` (the markers
/// kept), or with the markers and the section appended when it has neither.
pub fn replace_section(doc: &str, section: &str) -> Result<String, String> {
    let block = format!("{BEGIN}\n{}\n{END}", section.trim_end());
    match (doc.find(BEGIN), doc.find(END)) {
        (None, None) => {
            let mut out = doc.to_string();
            if !out.is_empty() && !out.ends_with('\n') {
                out.push('\n');
            }
            if !out.is_empty() {
                out.push('\n');
            }
            out.push_str(&block);
            out.push('\n');
            Ok(out)
        }
        (Some(b), Some(e)) if b < e => {
            if doc[e + END.len()..].contains(BEGIN) || doc[b + BEGIN.len()..e].contains(BEGIN) {
                return Err(format!(
                    "it has more than one `{BEGIN}`: keep one pair of markers"
                ));
            }
            Ok(format!("{}{block}{}", &doc[..b], &doc[e + END.len()..]))
        }
        (Some(_), None) => Err(format!("it has `{BEGIN}` but no `{END}` after it: add it")),
        (None, Some(_)) => Err(format!("it has `{END}` but no `{BEGIN}` before it: add it")),
        (Some(_), Some(_)) => Err(format!("`{END}` comes before `{BEGIN}`: swap them")),
    }
}

fn write_section(file: &Path, markdown: &str) -> Result<(), Failure> {
    let io = |e: std::io::Error| Failure::failed(format!("--write {}: {e}", file.display()));
    let text = std::fs::read_to_string(file).map_err(io)?;
    let new = replace_section(&text, markdown)
        .map_err(|e| Failure::input(format!("--write {}: {e}", file.display())))?;
    std::fs::write(file, new).map_err(io)
}

/// The command line as typed, program name shortened to `fretdyn-bench`.
fn command_line() -> String {
    let mut words = vec!["fretdyn-bench".to_string()];
    for a in std::env::args().skip(1) {
        if a.is_empty() || a.contains(char::is_whitespace) {
            words.push(format!("'{a}'"));
        } else {
            words.push(a);
        }
    }
    words.join(" ")
}

/// The current date and time, `YYYY-MM-DD HH:MM UTC`.
fn now_utc() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, mo, d) = civil_from_days((secs / 86_400) as i64);
    let s = secs % 86_400;
    format!(
        "{y:04}-{mo:02}-{d:02} {:02}:{:02} UTC",
        s / 3600,
        s % 3600 / 60
    )
}

/// The proleptic Gregorian (year, month, day) of a count of days since 1970-01-01
/// (H. Hinnant's `civil_from_days`: 400-year eras of 146 097 days, years from March).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn section_is_replaced_between_the_markers() {
        let doc = format!("# Perf\n\nbefore\n{BEGIN}\nold table\n| a |\n{END}\nafter\n");
        let new = replace_section(&doc, "new table\n").unwrap();
        assert_eq!(
            new,
            format!("# Perf\n\nbefore\n{BEGIN}\nnew table\n{END}\nafter\n")
        );
        // replacing again gives the same document: the markers survive
        assert_eq!(replace_section(&new, "new table").unwrap(), new);
    }

    #[test]
    fn section_is_appended_without_markers() {
        let new = replace_section("# Perf\ntext", "table").unwrap();
        assert_eq!(new, format!("# Perf\ntext\n\n{BEGIN}\ntable\n{END}\n"));
        // and is replaced, not appended again, the next time
        let again = replace_section(&new, "table 2").unwrap();
        assert_eq!(again, format!("# Perf\ntext\n\n{BEGIN}\ntable 2\n{END}\n"));
        assert_eq!(
            replace_section("", "t").unwrap(),
            format!("{BEGIN}\nt\n{END}\n")
        );
    }

    #[test]
    fn broken_markers_are_refused() {
        for doc in [
            format!("{BEGIN}\nx\n"),
            format!("x\n{END}\n"),
            format!("{END}\nx\n{BEGIN}\n"),
            format!("{BEGIN}\n{BEGIN}\nx\n{END}\n"),
            format!("{BEGIN}\nx\n{END}\n{BEGIN}\n{END}\n"),
        ] {
            assert!(replace_section(&doc, "t").is_err(), "{doc}");
        }
    }

    #[test]
    fn section_is_written_to_a_file() {
        let path =
            std::env::temp_dir().join(format!("fretdyn-against-c-{}.md", std::process::id()));
        std::fs::write(&path, format!("# Perf\n{BEGIN}\nold\n{END}\ntail\n")).unwrap();
        write_section(&path, "| new |").unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        assert_eq!(text, format!("# Perf\n{BEGIN}\n| new |\n{END}\ntail\n"));
    }

    #[test]
    fn c_output_is_parsed_and_sweeps_recovered() {
        // 804 closed steps of 2000 with 1868 sweeps: the mean printed with 6 digits
        let text = "case s1_case.bin p=30 c=5 dt=7.95715452e-05 steps=2000 H=per-step\n\
                    steps_per_s 4.77896e+06\nelapsed_s 0.000418501\n\
                    closed_any_fraction 0.402000\n\
                    closed_fraction_per_contact 0.0000 0.0620 0.1100 0.2050 0.1435\n\
                    avg_pgs_sweeps 2.32338\nmax_pgs_sweeps 4\nnonconverged_steps 0\n\
                    checksum_sum_abs_q 0.0066284754112514192\n\
                    checksum_friction_dissipation 0.012126715963961573\n";
        let c = COutput::parse(text).unwrap();
        assert_eq!(c.steps_per_s, 4.77896e6);
        // 17 significant digits, as printed (%.17g): read back exactly
        assert_eq!(c.sum_abs_q.to_string(), "0.006628475411251419");
        assert_eq!(c.dissipation, 0.012126715963961573);
        assert_eq!(c.sweeps(2000), 1868);
        assert_eq!(
            COutput::parse("steps_per_s 1\n"),
            Err("closed_any_fraction")
        );
    }

    #[test]
    fn spread_and_slope() {
        let s = Spread::of(&[3.0, 1.0, 2.0]);
        assert_eq!((s.median, s.min, s.max), (2.0, 1.0, 3.0));
        assert_eq!(Spread::of(&[4.0, 1.0, 2.0, 3.0]).median, 2.5);
        // pairs (C, fretdyn) = (2, 3), (4, 3): per-pair ratios 1.5 and 0.75, bests 3 over 4
        let t = Timing::new("x".into(), 1, &[2.0, 4.0], &[3.0, 3.0]);
        assert_eq!((t.ratio.median, t.best_ratio()), (1.125, 0.75));
        // an exact line: y = 0.25 x + 3
        let x = [10.0, 30.0, 100.0, 200.0];
        let y = x.map(|v| 0.25 * v + 3.0);
        assert!((slope(&x, &y) - 0.25).abs() < 1e-15);
    }

    #[test]
    fn civil_dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        // 2000-02-29 is day 11 016 (30 years of 365 days + 7 leap days + 59 days of 2000)
        assert_eq!(civil_from_days(30 * 365 + 7 + 59), (2000, 2, 29));
        assert_eq!(civil_from_days(30 * 365 + 7 + 60), (2000, 3, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
    }
}
