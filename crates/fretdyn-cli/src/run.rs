//! `fretdyn run`: one case file, or the built-in demo; `fretdyn run --resume DIR` continues a
//! run that was interrupted; `fretdyn plot DIR` redraws a run's plots.
//!
//! Every run is streamed to its folder ([`fretdyn::output::stream`]): time histories flushed chunk by
//! chunk, impacts as they end, a checkpoint every `checkpoint_seconds` and on Ctrl-C or
//! SIGTERM, so that a killed run leaves readable results and can be resumed, giving the
//! results of an uninterrupted run bit for bit. A run holds a lock on its folder: a second
//! run on the same folder is refused.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use fretdyn::Case;
use fretdyn::RunResults;
use fretdyn::apps::verification::V1;
use fretdyn::integrator::simulation::{Progress, Termination};
use fretdyn::output::stream::ResultsMetadata;
use fretdyn::{StreamObserver, StreamSettings};
use ndarray::{Array3, Ix3};
use ndarray_npy::NpzReader;
use serde_json::json;

use crate::Failure;
use crate::out::{errln, outln};
use crate::plot::{Series, line_plot};
use crate::progress::Bar;

/// The file that records which case a run folder belongs to, for `--resume`.
const RUN_FILE: &str = "run.json";

/// Options of `fretdyn run`.
pub struct Options {
    pub output: Option<PathBuf>,
    pub quiet: bool,
    pub plots: bool,
    /// Wall-clock seconds between checkpoints.
    pub checkpoint_seconds: f64,
}

/// Entry point of `fretdyn run`.
pub fn main(case: Option<&Path>, resume: Option<&Path>, options: &Options) -> Result<(), Failure> {
    match (case, resume) {
        (Some(_), Some(_)) => Err(Failure::input(
            "give either a case file or --resume DIR (the folder knows its case file)",
        )),
        (None, Some(dir)) => resume_run(dir, options),
        (Some(path), None) => {
            let case = load(path)?;
            let dir = options
                .output
                .clone()
                .unwrap_or_else(|| default_dir(&case.title, path));
            let (fingerprint, text) = fingerprint_of(path)?;
            // bad input is refused before anything is written
            check_start(&case, path)?;
            check_disk(&case, path, &dir)?;
            let _lock = crate::folder::lock(&dir, "run")?;
            let absolute = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
            let run_file = json!({ "case_file": absolute, "fingerprint": fingerprint.to_string() });
            std::fs::write(dir.join(RUN_FILE), format!("{run_file:#}\n"))
                .map_err(|e| Failure::failed(format!("{}: {e}", dir.join(RUN_FILE).display())))?;
            run_and_write(
                &case,
                &path.display().to_string(),
                Some(&text),
                &dir,
                options,
                fingerprint,
                false,
            )?;
            Ok(())
        }
        (None, None) => demo(options),
    }
}

fn load(path: &Path) -> Result<Case, Failure> {
    let case = Case::from_file(path).map_err(|e| Failure::input(e.in_file(path)))?;
    for w in &case.warnings {
        errln!("warning: {w}");
    }
    // impacts resolved by too few steps (THEORY §2)
    for w in
        fretdyn::integrator::stability::impact_resolution_warnings(&case.model, case.settings.dt)
    {
        errln!("warning: {}: {w}", path.display());
    }
    if let Some(report) = case.stability_checks() {
        let report = report.map_err(|e| Failure::input(e.in_file(path)))?;
        for (unstable, line) in connors_summary(&report) {
            if unstable {
                errln!(
                    "warning: {}: Connors: {line}; fluid-elastic instability expected, see fretdyn stability",
                    path.display()
                );
            }
        }
    }
    Ok(case)
}

/// One line per support condition of a Connors check: per plane (in-plane, out-of-plane,
/// mixed; all modes together when the structure has no plane) how many modes are above the
/// critical velocity, with the largest ratio, its mode and frequency:
/// "condition `support_inactive`: in-plane: 3 of 12 modes above the critical velocity
/// (largest U_eff/U_c = 2.1, mode 4, 12.3 Hz); out-of-plane: none of 18 modes above", and
/// whether a mode of the condition is above.
pub fn connors_summary(report: &fretdyn::loads::flow::StabilityReport) -> Vec<(bool, String)> {
    use fretdyn::loads::flow::{ModeStability, Plane};
    let mut conditions: Vec<&str> = Vec::new();
    for m in &report.modes {
        if !conditions.contains(&m.condition.as_str()) {
            conditions.push(&m.condition);
        }
    }
    let planes = [
        (Some(Plane::InPlane), "in-plane"),
        (Some(Plane::OutOfPlane), "out-of-plane"),
        (Some(Plane::Mixed), "mixed"),
        (None, "all modes"),
    ];
    conditions
        .iter()
        .map(|condition| {
            let parts: Vec<String> = planes
                .iter()
                .filter_map(|(plane, label)| {
                    let modes: Vec<&ModeStability> = report
                        .modes
                        .iter()
                        .filter(|m| m.condition == *condition && m.plane == *plane)
                        .collect();
                    if modes.is_empty() {
                        return None;
                    }
                    let unstable: Vec<&&ModeStability> =
                        modes.iter().filter(|m| m.unstable()).collect();
                    Some(match unstable.iter().max_by(|a, b| {
                        a.ratio.unwrap_or(0.0).total_cmp(&b.ratio.unwrap_or(0.0))
                    }) {
                        None => format!("{label}: none of {} modes above", modes.len()),
                        Some(w) => format!(
                            "{label}: {} of {} modes above the critical velocity (largest U_eff/U_c = {:.4}, mode {}, {:.4} Hz)",
                            unstable.len(),
                            modes.len(),
                            w.ratio.unwrap_or(f64::NAN),
                            w.mode,
                            w.frequency_hz
                        ),
                    })
                })
                .collect();
            let any = report
                .modes
                .iter()
                .any(|m| m.condition == *condition && m.unstable());
            (any, format!("condition `{condition}`: {}", parts.join("; ")))
        })
        .collect()
}

/// Refuses a case that cannot start, before anything is written: what a run checks as it
/// starts — the stable time step, the energy of the initial state, the memory of the
/// fluid-elastic delays — not the time step only (an initial state whose energy overflows
/// left the output folder and its `run.json` behind). The simulation is set up, then dropped.
pub fn check_start(case: &Case, path: &Path) -> Result<(), Failure> {
    fretdyn::integrator::simulation::Simulation::with_recorder(&case.model, &case.settings, 1)
        .map(drop)
        .map_err(|e| Failure::input(format!("{}: {e}", path.display())))
}

/// The time histories a streamed run writes, bytes: its samples (`steps / output.every + 1`)
/// times [`fretdyn::accumulate::recorder::Recorder::bytes_per_sample`], plus the headers of the files.
fn series_bytes(case: &Case) -> u64 {
    let s = &case.settings;
    let samples = (s.steps / s.output_every.max(1)).saturating_add(1);
    let per_sample = fretdyn::accumulate::recorder::Recorder::bytes_per_sample(
        case.model.basis.modes(),
        case.model.contacts.len(),
    );
    samples.saturating_mul(per_sample).saturating_add(9 * 256)
}

/// Free space for an unprivileged user on the file system of `dir` (or of its first
/// existing parent), bytes; `None` when unknown.
fn free_space(dir: &Path) -> Option<u64> {
    #[cfg(unix)]
    {
        let absolute = std::path::absolute(dir).ok()?;
        let existing = absolute.ancestors().find(|p| p.exists())?;
        let stat = nix::sys::statvfs::statvfs(existing).ok()?;
        Some((stat.blocks_available() as u64).saturating_mul(stat.fragment_size() as u64))
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        None
    }
}

/// Refuses a run whose time histories cannot fit on the disk of its folder, and warns when
/// packing them into `results.npz` and `results.nc` at the end (as much again each, until
/// `series/` is removed) will not fit.
fn check_disk(case: &Case, path: &Path, dir: &Path) -> Result<(), Failure> {
    let Some(free) = free_space(dir) else {
        return Ok(());
    };
    let needed = series_bytes(case);
    let size = human_bytes;
    let verdict = disk_verdict(needed, needed, free);
    if verdict == DiskVerdict::SeriesShort {
        let raise = needed.div_ceil(free.max(1) / 2 + 1).max(2);
        return Err(Failure::input(format!(
            "{}: the run would write {} of time histories in {}, where {} is free: keep fewer samples (multiply output.every by {raise} or more), free some space, or give another output folder (-o DIR)",
            path.display(),
            size(needed),
            dir.display(),
            size(free)
        )));
    }
    if verdict == DiskVerdict::PackingShort {
        errln!(
            "warning: {}: the run will write {} of time histories in {}, where {} is free, and packing them into results.npz and results.nc at the end needs twice as much again: free some space before the end (a run stopped by a full disk continues with fretdyn run --resume {})",
            path.display(),
            size(needed),
            dir.display(),
            size(free),
            dir.display()
        );
    }
    Ok(())
}

/// `bytes` for a person: `1.5 GB` (powers of 1000, as the library's memory check says them).
fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 7] = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1000.0 && unit + 1 < UNITS.len() {
        value /= 1000.0;
        unit += 1;
    }
    match unit {
        0 => format!("{bytes} bytes"),
        _ => format!("{value:.1} {}", UNITS[unit]),
    }
}

/// FNV-1a hash of bytes: the demo's fingerprint of a run (not a security measure).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf29ce484222325, |h, b| {
        (h ^ *b as u64).wrapping_mul(0x100000001b3)
    })
}

/// [`check_disk`] for a resumed run (a run stopped by a full disk is the usual one): refuses
/// it when the time histories still to write do not fit (those already in `series/` stay), and
/// warns, while some are still to write, when packing them at the end will not.
fn check_disk_to_resume(case: &Case, dir: &Path) -> Result<(), Failure> {
    let Some(free) = free_space(dir) else {
        return Ok(());
    };
    let total = series_bytes(case);
    let written = folder_bytes(&dir.join(fretdyn::output::stream::SERIES_DIR));
    let remaining = total.saturating_sub(written);
    let size = human_bytes;
    match disk_verdict(remaining, total, free) {
        DiskVerdict::Fits => Ok(()),
        // every time history written: the packing starts at once, and says itself what
        // stops it
        DiskVerdict::PackingShort if remaining == 0 => Ok(()),
        DiskVerdict::PackingShort => {
            errln!(
                "warning: {}: the run will write {} more of time histories, where {} is free, and packing them into results.npz and results.nc at the end needs {} again: free some space before the end",
                dir.display(),
                size(remaining),
                size(free),
                size(total.saturating_mul(2))
            );
            Ok(())
        }
        DiskVerdict::SeriesShort => Err(Failure::input(format!(
            "{}: the run still has {} of time histories to write, where {} is free: free some space, then resume again (fretdyn run --resume {})",
            dir.display(),
            size(remaining),
            size(free),
            dir.display()
        ))),
    }
}

/// What a disk with `free` bytes allows a run that has `remaining` bytes of time histories
/// still to write, `total` in all (packed twice at the end: `results.npz`, `results.nc`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum DiskVerdict {
    Fits,
    /// The time histories fit, their packing at the end does not.
    PackingShort,
    /// The time histories do not fit.
    SeriesShort,
}

fn disk_verdict(remaining: u64, total: u64, free: u64) -> DiskVerdict {
    if remaining > free {
        DiskVerdict::SeriesShort
    } else if remaining.saturating_add(total.saturating_mul(2)) > free {
        DiskVerdict::PackingShort
    } else {
        DiskVerdict::Fits
    }
}

/// Bytes of the files directly in `dir` (0 when it cannot be read).
fn folder_bytes(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok()?.metadata().ok())
                .filter(|m| m.is_file())
                .map(|m| m.len())
                .sum()
        })
        .unwrap_or(0)
}

/// The fingerprint of the case file (its values and the content of every file it reads: a
/// resumed run must use the inputs it started with, [`fretdyn::case::fingerprint`]), and its
/// text (for `results.nc`).
pub fn fingerprint_of(path: &Path) -> Result<(u64, String), Failure> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Failure::input(format!("{}: {e}", path.display())))?;
    let value: toml::Value =
        toml::from_str(&text).map_err(|e| Failure::input(format!("{}: {e}", path.display())))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let fingerprint = fretdyn::case::fingerprint::Fingerprint::of(&value, base).value();
    Ok((fingerprint, text))
}

fn resume_run(dir: &Path, options: &Options) -> Result<(), Failure> {
    let run_file = dir.join(RUN_FILE);
    let info: serde_json::Value = std::fs::read_to_string(&run_file)
        .map_err(|e| e.to_string())
        .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
        .map_err(|e| {
            Failure::input(format!(
                "{}: {e} (--resume needs a folder written by fretdyn run CASE)",
                run_file.display()
            ))
        })?;
    let path = PathBuf::from(info["case_file"].as_str().unwrap_or_default());
    let _lock = crate::folder::lock(dir, "run")?;
    if !dir.join(fretdyn::output::stream::CHECKPOINT_FILE).exists() {
        return Err(Failure::input(format!(
            "{}: the run stopped before its first checkpoint, there is nothing to resume; start it again: fretdyn run {} -o {}",
            dir.display(),
            path.display(),
            dir.display()
        )));
    }
    let case = load(&path)?;
    let (fingerprint, text) = fingerprint_of(&path)?;
    if info["fingerprint"].as_str() != Some(fingerprint.to_string().as_str()) {
        return Err(Failure::input(format!(
            "{}: the case file or a file it reads changed since the run in {} started; start the run again instead of resuming it",
            path.display(),
            dir.display()
        )));
    }
    check_disk_to_resume(&case, dir)?;
    run_and_write(
        &case,
        &path.display().to_string(),
        Some(&text),
        dir,
        options,
        fingerprint,
        true,
    )?;
    Ok(())
}

/// The folder `fretdyn run` writes in when not told: `fretdyn_results/<case file's stem>`.
pub fn default_dir(title: &str, path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| title.to_string());
    PathBuf::from("fretdyn_results").join(stem)
}

/// Progress bar, Ctrl-C, and `summary.json` (and `contacts.csv`) rewritten at each checkpoint
/// and at the end; the case file's text and the summary for `results.nc`.
struct Observer<'a> {
    bar: Bar,
    case: &'a Case,
    case_text: Option<&'a str>,
    dir: &'a Path,
    /// The text of the last `summary.json` written at the end.
    summary: Option<String>,
}

impl StreamObserver for Observer<'_> {
    fn progress(&mut self, p: Progress) -> ControlFlow<()> {
        let _ = self.bar.observe(p);
        if crate::signals::interrupted() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }

    fn checkpoint(&mut self, partial: &RunResults) {
        // a failure here is reported by the final write
        let _ = write_summary(self.case, partial, self.dir);
    }

    fn finished(&mut self, results: &RunResults) -> fretdyn::Result<()> {
        let path = write_summary(self.case, results, self.dir)?;
        self.summary = std::fs::read_to_string(&path).ok();
        Ok(())
    }

    fn metadata(&self) -> ResultsMetadata {
        ResultsMetadata {
            title: Some(self.case.title.clone()),
            case_toml: self.case_text.map(str::to_string),
            summary_json: self.summary.clone(),
        }
    }
}

/// Writes `summary.json` and the same per-contact statistics as a table, `contacts.csv`
/// (with `contacts_columns.csv`, their units and Code_Aster names); returns the summary's path.
fn write_summary(case: &Case, results: &RunResults, dir: &Path) -> fretdyn::Result<PathBuf> {
    let summary = fretdyn::output::summary::summary(case, results);
    let path = fretdyn::output::summary::write_summary(dir, &summary)?;
    fretdyn::output::contacts_table::write_contacts_csv(dir, &summary)?;
    Ok(path)
}

/// Runs (or resumes) a case streamed into `dir`, writes `summary.json` and the plots, prints
/// a report. A diverged or interrupted run keeps what it wrote, then fails with the step
/// (and contact).
pub fn run_and_write(
    case: &Case,
    source: &str,
    case_text: Option<&str>,
    dir: &Path,
    options: &Options,
    fingerprint: u64,
    resume: bool,
) -> Result<RunResults, Failure> {
    let stream = StreamSettings {
        checkpoint_every_seconds: Some(options.checkpoint_seconds),
        ..StreamSettings::default()
    };
    let _keeping = crate::signals::Keeping::start();
    let mut observer = Observer {
        bar: Bar::new(&case.title, !options.quiet),
        case,
        case_text,
        dir,
        summary: None,
    };
    let results = if resume {
        fretdyn::resume(
            &case.model,
            &case.settings,
            dir,
            &stream,
            fingerprint,
            &mut observer,
        )
    } else {
        fretdyn::run(
            &case.model,
            &case.settings,
            dir,
            &stream,
            fingerprint,
            &mut observer,
        )
    }
    .map_err(|e| {
        observer.bar.finish();
        match e {
            // a failed run (a full disk): what was written up to the last checkpoint stays
            fretdyn::Error::Io { .. } => Failure::failed(format!(
                "{source}: {e}{}",
                if dir.join(fretdyn::output::stream::CHECKPOINT_FILE).exists() {
                    format!(
                        "; once fixed (room on the disk), continue the run with: fretdyn run --resume {}",
                        dir.display()
                    )
                } else {
                    String::new()
                }
            )),
            e => Failure::input(format!("{source}: {e}")),
        }
    })?;
    observer.bar.finish();
    for w in error_warnings(case, &results) {
        errln!("warning: {w}");
    }
    if options.plots {
        crate::results_plots::plot_run(dir)?;
    }
    // a full standard output fails the command, but after a failure of the run itself
    let printed = if options.quiet {
        Ok(())
    } else {
        report(case, &results, dir)
    };
    match &results.termination {
        Termination::Completed | Termination::InProgress { .. } => printed.map(|_| results),
        Termination::Diverged {
            step,
            time,
            contact,
        } => Err(Failure::failed(format!(
            "{source}: the run diverged at step {step} (t = {time:e} s){}; the results up to then are in {}. Reduce time.dt or check the contact stiffnesses",
            contact
                .as_ref()
                .map(|c| format!(" at contact '{c}'"))
                .unwrap_or_default(),
            dir.display()
        ))),
        Termination::Stopped { step } => Err(Failure::failed(format!(
            "{source}: interrupted at step {step}; the results up to then are in {}; continue it with: fretdyn run --resume {}",
            dir.display(),
            dir.display()
        ))),
    }
}

/// Warnings on a run: its energy balance's error above 1 % (THEORY §5, with the time step
/// that would fix it), and on its standard errors (THEORY §5): once if the batches are correlated
/// (too short against the correlation time), one line per contact whose relative standard
/// errors exceed `[statistics] max_relative_error`, naming the statistics, and a target
/// relative error that was not met. Only contacts with at least one impact per batch on
/// average are looked at: with fewer (a single impact, a transient such as V1), the response
/// is not a stationary one whose batch means could be independent, and its errors, still in
/// `summary.json`, say nothing worth a warning.
pub fn error_warnings(case: &Case, r: &RunResults) -> Vec<String> {
    let st = &case.settings.statistics;
    // the energy balance's error (THEORY §5): a time step too coarse
    let mut out = fretdyn::accumulate::energy::energy_warnings(&r.energy, r.dt);
    let stationary = |c: &&fretdyn::accumulate::statistics::ContactStatistics| {
        c.impacts >= c.errors.batches.max(2)
    };
    let correlated: Vec<String> = r
        .contacts
        .iter()
        .filter(stationary)
        .filter(|c| c.errors.batches_correlated)
        .map(|c| {
            format!(
                "{} (r1 = {:.2})",
                c.name,
                c.errors.batch_autocorrelation.unwrap_or(f64::NAN)
            )
        })
        .collect();
    if let Some(c) = r.contacts.first().filter(|_| !correlated.is_empty()) {
        out.push(format!(
            "the batch means are correlated at {}: batches of {} s are too short against the correlation time of the response, and the standard errors are underestimated; set a longer [statistics] block (or fewer batches), or run longer",
            correlated.join(", "),
            number(c.errors.batch_length)
        ));
    }
    for c in r.contacts.iter().filter(stationary) {
        let above = c.relative_errors_above(st.max_relative_error);
        if !above.is_empty() {
            out.push(format!(
                "contact {}: relative standard error above {} % (statistics.max_relative_error): {}; run longer (or set statistics.target_relative_error)",
                c.name,
                number(100.0 * st.max_relative_error),
                above
                    .iter()
                    .map(|(s, e)| format!("{s} {:.1} %", 100.0 * e))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    if let (Some(target), None) = (st.target_relative_error, r.target_met_at)
        && matches!(r.termination, Termination::Completed)
    {
        out.push(format!(
                "the target relative error {} % (statistics.target_relative_error) was not met within time.duration = {} s; the run went to its end",
                number(100.0 * target),
                number(r.steps as f64 * r.dt)
            ));
    }
    out
}

/// `x` as typed (shortest round-trip form).
fn number(x: f64) -> String {
    format!("{x}")
}

/// Reads `t` and `contact_tangential_force` of a finished run.
fn read_friction(dir: &Path) -> Result<(Vec<f64>, Array3<f64>), Failure> {
    let path = dir.join(fretdyn::output::stream::RESULTS_FILE);
    let err = |e: &dyn std::fmt::Display| Failure::failed(format!("{}: {e}", path.display()));
    let file = std::fs::File::open(&path).map_err(|e| err(&e))?;
    let mut npz = NpzReader::new(file).map_err(|e| err(&e))?;
    let t: ndarray::Array1<f64> = npz.by_name("t.npy").map_err(|e| err(&e))?;
    let f = npz
        .by_name::<_, Ix3>("contact_tangential_force.npy")
        .map_err(|e| err(&e))?;
    Ok((t.to_vec(), f))
}

fn report(case: &Case, r: &RunResults, dir: &Path) -> Result<(), Failure> {
    outln!(
        "{}: {} steps of {:e} s ({} method) in {:.3} s, {:.3e} steps/s",
        case.title,
        r.steps,
        r.dt,
        case.settings.method.name(),
        r.wall_time,
        r.steps_per_second()
    )?;
    outln!(
        "  {:<16} {:>8} {:>8} {:>8} {:>8} {:>12} {:>14}",
        "contact",
        "impacts",
        "contact",
        "stick",
        "slip",
        "max R_N (N)",
        "wear rate (W) ± SE"
    )?;
    for c in &r.contacts {
        outln!(
            "  {:<16} {:>8} {:>8.4} {:>8.4} {:>8.4} {:>12} {:>14} ± {}",
            c.name,
            c.impacts,
            c.contact_time_fraction,
            c.stick_time_fraction,
            c.slip_time_fraction,
            significant(c.normal_force_max, 4),
            significant(c.wear_work_rate, 4),
            c.errors
                .wear_work_rate_se
                .map_or("-".to_string(), |e| significant(e, 3))
        )?;
    }
    if let Some(c) = r.contacts.first() {
        outln!(
            "  standard errors by batch means: {} batches of {} s{}",
            c.errors.batches,
            number(c.errors.batch_length),
            r.target_met_at
                .map(|t| format!("; target relative error met at t = {} s", number(t)))
                .unwrap_or_default()
        )?;
    }
    outln!(
        "  energy balance error {:.3e} (relative)",
        r.energy.relative_error
    )?;
    let s = &r.solver;
    if case.settings.method.is_lagrange() {
        outln!(
            "  solver: GS sweeps mean {:.2} max {} non-converged {}; AS iterations mean {:.2} max {} cycles {} fallbacks {}; singular H {}; residual mean {:.1e} max {:.1e}, steps > 1e-8: {}",
            s.gs_sweeps_mean(),
            s.gs_sweeps_max,
            s.gs_nonconverged_steps,
            s.as_iterations_mean(),
            s.as_iterations_max,
            s.as_cycles,
            s.as_fallbacks,
            s.singular_delassus,
            s.residual_mean(),
            s.residual_max,
            s.residual_steps_above_1e_8
        )?;
    }
    outln!("  wrote {}", dir.display())
}

/// The built-in demo: V1a (THEORY §6) with the Active Set, the Gauss–Seidel and the penalty
/// method (K_T = 1e6 N/m, C_T = 2000 N·s/m), and a plot comparing their friction forces.
fn demo(options: &Options) -> Result<(), Failure> {
    let (quiet, plots) = (options.quiet, options.plots);
    let dir = options
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from("fretdyn_results").join("demo_v1a"));
    let v1 = V1::reference(20.0);
    if !quiet {
        outln!(
            "fretdyn demo: V1a, a 1 kg point mass hitting a plane at 1 m/s, 20° from the normal, μ = 0.3 (docs/THEORY.md §6)"
        )?;
    }
    let mut curves = Vec::new();
    for (label, method) in fretdyn::apps::verification::methods(&[1e6]) {
        let slug = label.split_whitespace().next().unwrap_or("run").to_string();
        let case = v1.case(&format!("V1a {label}"), method);
        let sub = dir.join(&slug);
        let fingerprint = fnv1a(case.title.as_bytes());
        let _lock = crate::folder::lock(&sub, "run")?;
        run_and_write(&case, "demo", None, &sub, options, fingerprint, false)?;
        let (t, f) = read_friction(&sub)?;
        let magnitude: Vec<f64> = (0..t.len())
            .map(|i| f[[i, 0, 0]].hypot(f[[i, 0, 1]]))
            .collect();
        curves.push((label, t, magnitude));
    }
    if plots {
        let t = curves[0].1.clone();
        let analytic: Vec<f64> = t.iter().map(|&t| v1.friction_force(t)).collect();
        let mut series: Vec<Series> = curves
            .iter()
            .map(|(l, t, y)| Series {
                label: l.clone(),
                x: t,
                y,
            })
            .collect();
        series.push(Series {
            label: "analytic".into(),
            x: &t,
            y: &analytic,
        });
        let path = dir.join("friction_force.png");
        line_plot(
            &path,
            "V1a: friction force |R_T| against time",
            "t (s)",
            "|R_T| (N)",
            &series,
            true,
        )
        .map_err(Failure::failed)?;
    }
    if !quiet {
        outln!(
            "demo written to {} (one folder per method, and friction_force.png)",
            dir.display()
        )?;
    }
    Ok(())
}

/// `x` to `digits` significant digits as a person reads a figure: plain from 0.001 to a
/// million (`939.7`, `14.62`, `0.004521`), in exponent notation outside (`1.462e-5`).
pub(crate) fn significant(x: f64, digits: usize) -> String {
    let digits = digits.max(1);
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    // the exponent of x once rounded (999.96 to 4 digits is 1000, exponent 3)
    let e = format!("{x:.*e}", digits - 1)
        .split_once('e')
        .and_then(|(_, e)| e.parse::<i32>().ok())
        .unwrap_or(0);
    if (-3..6).contains(&e) {
        let decimals = (digits as i32 - 1 - e).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.*e}", digits - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_read_as_a_person_writes_them() {
        for (x, digits, text) in [
            (939.693, 4, "939.7"),
            (14.6222, 4, "14.62"),
            (4.4512, 3, "4.45"),
            (0.0045213, 4, "0.004521"),
            (1.46222e-5, 4, "1.462e-5"),
            (2.5e7, 4, "2.500e7"),
            (999.96, 4, "1000"),
            (-0.5, 3, "-0.500"),
            (0.0, 4, "0"),
        ] {
            assert_eq!(significant(x, digits), text, "{x}");
        }
    }

    /// The time histories need `remaining` bytes, their packing twice the run's total: a
    /// resumed run (some already written) asks less than a fresh one of the same case.
    #[test]
    fn the_disk_verdict_counts_what_is_left_and_the_packing() {
        let total = 1000;
        // fresh run: the series and two packed copies
        assert_eq!(disk_verdict(total, total, 3000), DiskVerdict::Fits);
        assert_eq!(disk_verdict(total, total, 2999), DiskVerdict::PackingShort);
        assert_eq!(disk_verdict(total, total, 1000), DiskVerdict::PackingShort);
        assert_eq!(disk_verdict(total, total, 999), DiskVerdict::SeriesShort);
        // resumed with 600 bytes written: 400 left
        assert_eq!(disk_verdict(400, total, 2400), DiskVerdict::Fits);
        assert_eq!(disk_verdict(400, total, 2399), DiskVerdict::PackingShort);
        assert_eq!(disk_verdict(400, total, 399), DiskVerdict::SeriesShort);
        // nothing left: only the packing
        assert_eq!(disk_verdict(0, total, 2000), DiskVerdict::Fits);
        assert_eq!(
            disk_verdict(u64::MAX, u64::MAX, u64::MAX - 1),
            DiskVerdict::SeriesShort
        );
    }

    #[test]
    fn folder_bytes_sums_the_files_of_a_folder() {
        let dir = std::env::temp_dir().join(format!("fretdyn_folder_bytes_{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        std::fs::write(dir.join("a.npy"), [0u8; 100]).unwrap();
        std::fs::write(dir.join("b.npy"), [0u8; 28]).unwrap();
        std::fs::write(dir.join("sub").join("c"), [0u8; 7]).unwrap();
        assert_eq!(folder_bytes(&dir), 128);
        assert_eq!(folder_bytes(&dir.join("missing")), 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
