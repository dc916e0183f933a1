//! A study run into its table: every run checked before any starts, the table opened and
//! locked (a table of other inputs refused, a row cut by a crash dropped, the rows already
//! there kept: a study continues where it stopped), the pending runs run in parallel (rayon),
//! one row appended per finished run, and a run stopped from outside dropped whole.

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use super::file::Study;
use super::runs::RunSpec;
use super::table::{TableRow, csv_value, read_rows};
use crate::case::fingerprint::{Fingerprint, canonical, differences};
use crate::error::{Error, Result};
use crate::files::Lock;
use crate::integrator::simulation::Simulation;

impl Study {
    /// Builds the case of every run and checks it as a run does as it starts (the stability
    /// limit of Δt, the energy of the initial state, the memory of the fluid-elastic delays:
    /// the simulation is set up, then dropped; a service life's settings and wearing
    /// contacts), `jobs` at a time (0: one per core), so that a
    /// value that makes a case invalid is found before any run starts. The error is that of
    /// the first such run, as [`Error::StudyRun`] naming it and its values. Returns the cases'
    /// warnings (an implausible value, an impact resolved by too few steps…), each once with
    /// the number of runs that give it, in the order of the runs.
    pub fn check(&self, jobs: usize) -> Result<Vec<(String, usize)>> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs)
            .build()
            .map_err(|e| Error::invalid("jobs", e.to_string()))?;
        use rayon::prelude::*;
        let runs = self.runs();
        let checked: Vec<Result<Vec<String>>> = pool.install(|| {
            runs.par_iter()
                .map(|run| {
                    self.case(run)
                        .and_then(|case| {
                            // what a run checks as it starts, not the time step only: its
                            // initial state's energy, the memory of its fluid-elastic delays
                            drop(Simulation::with_recorder(&case.model, &case.settings, 1)?);
                            crate::apps::check_names_for_tables(&case.model, "a study")?;
                            // and a service life, what it checks before its first window
                            if let Some(life) = &case.life {
                                crate::apps::life::check_life(&case, life)?;
                            }
                            Ok(case.warnings)
                        })
                        .map_err(|e| Error::StudyRun {
                            index: run.index,
                            point: self.describe(run),
                            source: Box::new(e),
                        })
                })
                .collect()
        });
        let mut warnings: Vec<(String, usize)> = Vec::new();
        for run in checked {
            for w in run? {
                match warnings.iter_mut().find(|(text, _)| *text == w) {
                    Some((_, n)) => *n += 1,
                    None => warnings.push((w, 1)),
                }
            }
        }
        Ok(warnings)
    }

    /// Runs every run not already in the table at `table` (created with its header if
    /// missing), `jobs` at a time (0: one per core), appending one row per run as it
    /// finishes; `progress(done, total)` after each. Returns the number of runs done now.
    /// Every run is checked first ([`Self::check`]): a bad value runs nothing. A table whose
    /// rows were computed from other inputs is refused ([`Self::open_table`]).
    pub fn execute(
        &self,
        table: &Path,
        jobs: usize,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<usize> {
        self.check(jobs)?;
        self.execute_checked(table, jobs, progress)
    }

    /// [`Self::execute`] after [`Self::check`] passed: the runs are not checked again.
    pub fn execute_checked(
        &self,
        table: &Path,
        jobs: usize,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<usize> {
        let options = StudyOptions {
            jobs,
            ..StudyOptions::default()
        };
        Ok(self.run_checked(table, &options, progress)?.done)
    }

    /// Runs the runs not already in the table at `table` with `options`, after
    /// [`Self::check`] passed: the table is opened and locked ([`Self::open_table`]), the
    /// pending runs run `options.jobs` at a time, one row appended per finished run,
    /// `progress(done, total)` after each. When `options.stop` is set, no run starts and the
    /// runs under way stop at their next batch of steps and are dropped whole (no row): the
    /// table holds finished runs only, and running the study again continues it.
    pub fn run_checked(
        &self,
        table: &Path,
        options: &StudyOptions,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<StudyOutcome> {
        let mut table = self.open_table(table, options.fresh)?;
        self.run_on(&mut table, options, progress)
    }

    /// The pending runs of `table` (opened by [`Self::open_table`]) with `options`, as
    /// [`Self::run_checked`] runs them.
    pub fn run_on(
        &self,
        table: &mut StudyTable,
        options: &StudyOptions,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<StudyOutcome> {
        let pending = table.pending();
        let already = table.done();
        let table = Mutex::new(table);
        let total = pending.len();
        let runs = self.runs();
        let finished = std::sync::atomic::AtomicUsize::new(0);
        let stopped = std::sync::atomic::AtomicBool::new(false);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(options.jobs)
            .build()
            .map_err(|e| Error::invalid("jobs", e.to_string()))?;
        let stop = options.stop;
        let stop_requested = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
        use rayon::prelude::*;
        pool.install(|| {
            pending.par_iter().try_for_each(|&index| -> Result<()> {
                if stop_requested() {
                    stopped.store(true, Ordering::Relaxed);
                    return Ok(());
                }
                let Some(row) = self.run_row_until(&runs[index], stop)? else {
                    stopped.store(true, Ordering::Relaxed);
                    return Ok(());
                };
                table
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .append(&row)?;
                let n = finished.fetch_add(1, Ordering::Relaxed) + 1;
                progress(n, total);
                Ok(())
            })
        })?;
        Ok(StudyOutcome {
            done: finished.load(Ordering::Relaxed),
            already,
            pending: total,
            stopped: stopped.load(Ordering::Relaxed),
        })
    }

    /// Opens the table of this study at `table` for writing, locked for as long as the
    /// returned [`StudyTable`] lives (a second study writing it is refused, naming the
    /// process that holds it). A missing or empty table is created with its header, and the
    /// record of the inputs beside it ([`record_path`]). An existing one is checked row by
    /// row: each complete row's [`FINGERPRINT_COLUMN`] must be the fingerprint this study
    /// gives its run now, and no run may appear twice; otherwise the table is refused with
    /// what changed (the base case's keys, the files it reads, the runs' values) and how to
    /// start afresh — its rows are never reused. With `fresh`, an existing table (and its
    /// record) is replaced. A row cut by a crash is dropped (its run is done again).
    pub fn open_table(&self, table: &Path, fresh: bool) -> Result<StudyTable> {
        let lock_path = lock_path(table);
        let lock = match Lock::try_new(&lock_path, "a study")? {
            Ok(lock) => lock,
            Err(holder) => {
                return Err(Error::invalid(
                    "table",
                    format!(
                        "{}: {holder} is writing this table; wait for it to end, or write to another table (-o DIR)",
                        table.display(),
                    ),
                ));
            }
        };
        let runs = self.runs();
        let expected = self.fingerprints(&runs)?;
        let header = self.header(&self.contact_names());
        if fresh {
            for path in [table.to_path_buf(), record_path(table)] {
                match std::fs::remove_file(&path) {
                    Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                        return Err(Error::io(&path, e));
                    }
                    _ => {}
                }
            }
        }
        let done = self.checked_rows(table, &header, &expected, &runs)?;
        // a row cut by a crash is dropped (its run is done again)
        if let Ok(text) = std::fs::read(table)
            && !text.is_empty()
            && !text.ends_with(b"\n")
        {
            let keep = text.iter().rposition(|b| *b == b'\n').map_or(0, |i| i + 1);
            let f = std::fs::OpenOptions::new()
                .write(true)
                .open(table)
                .map_err(|e| Error::io(table, e))?;
            f.set_len(keep as u64).map_err(|e| Error::io(table, e))?;
        }
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(table)
            .map_err(|e| Error::io(table, e))?;
        if file.metadata().map(|m| m.len()).unwrap_or(0) == 0 {
            crate::files::write_text_atomically(&record_path(table), &self.record())?;
            writeln!(file, "{header}")
                .and_then(|_| file.flush())
                .map_err(|e| Error::io(table, e))?;
        }
        Ok(StudyTable {
            path: table.to_path_buf(),
            file,
            _lock: lock,
            expected,
            done,
            columns: header.split(',').count(),
        })
    }

    /// The runs with a row in the table at `table` (none when it is missing or empty),
    /// after checking each complete row against `expected` (the fingerprint of each run): a
    /// table with a row of other inputs, or a run twice, is refused ([`Self::open_table`]).
    fn checked_rows(
        &self,
        table: &Path,
        header: &str,
        expected: &[String],
        runs: &[RunSpec],
    ) -> Result<BTreeSet<usize>> {
        let rows = read_rows(table, header)?;
        let mut done = BTreeSet::new();
        let mut stale = Vec::new();
        for row in &rows {
            let fits = expected
                .get(row.index)
                .is_some_and(|f| *f == row.fingerprint);
            if !fits {
                stale.push(row);
            } else if !done.insert(row.index) {
                return Err(Error::invalid(
                    "table",
                    format!(
                        "{}: run {} is in the table twice (two studies wrote it at once): its percentiles would count it twice; start afresh with --fresh (Python: fresh=True), or write to another table",
                        table.display(),
                        row.index
                    ),
                ));
            }
        }
        if !stale.is_empty() {
            return Err(Error::invalid(
                "table",
                format!(
                    "{}: {} of its {} rows were computed from other inputs than this study gives now ({}); they are not reused: start afresh with --fresh (Python: fresh=True; the table is replaced), or write to another table (-o DIR)",
                    table.display(),
                    stale.len(),
                    rows.len(),
                    self.what_changed(table, &stale, runs)
                ),
            ));
        }
        Ok(done)
    }

    /// Checks that the table at `table` holds a row for every run of this study, each of the
    /// inputs this study gives it now: the percentiles of an incomplete or stale table would
    /// look complete and be wrong.
    pub fn check_table_complete(&self, table: &Path) -> Result<()> {
        if !table.exists() {
            return Err(Error::io(
                table,
                std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    "no such file: run the study first",
                ),
            ));
        }
        let runs = self.runs();
        let expected = self.fingerprints(&runs)?;
        let done =
            self.checked_rows(table, &self.header(&self.contact_names()), &expected, &runs)?;
        if done.len() < runs.len() {
            return Err(Error::invalid(
                "table",
                format!(
                    "{}: {} of the study's {} runs have a row: the percentiles of an incomplete study would look complete; run the study to its end first (fretdyn sweep, or fretdyn.sweep with the same table)",
                    table.display(),
                    done.len(),
                    runs.len()
                ),
            ));
        }
        Ok(())
    }

    /// The record of the inputs written beside a new table ([`record_path`]): the fretdyn
    /// version, the base case as resolved (canonical TOML) and the hash of each file it reads
    /// — what [`Self::open_table`] compares with to say what changed.
    fn record(&self) -> String {
        let f = Fingerprint::of(&self.base, &self.base_dir);
        let files: serde_json::Map<String, serde_json::Value> = f
            .files
            .iter()
            .map(|(name, h)| {
                (
                    name.clone(),
                    h.map_or(serde_json::Value::Null, |h| format!("{h:016x}").into()),
                )
            })
            .collect();
        let json = serde_json::json!({
            "fretdyn": env!("CARGO_PKG_VERSION"),
            "base": canonical(&self.base),
            "files": files,
        });
        format!("{json:#}\n")
    }

    /// What makes `stale` rows differ from this study's runs, for the message of
    /// [`Self::open_table`]: the base case's keys and files against the record beside the
    /// table, and the parameter values of the rows against the runs of the same index.
    fn what_changed(&self, table: &Path, stale: &[&TableRow], runs: &[RunSpec]) -> String {
        let mut causes = Vec::new();
        let record: Option<serde_json::Value> = std::fs::read_to_string(record_path(table))
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok());
        match &record {
            Some(record) => {
                let old_base: Option<toml::Value> =
                    record["base"].as_str().and_then(|t| toml::from_str(t).ok());
                if let Some(old) = old_base {
                    let keys = differences(&old, &self.base, 3);
                    if !keys.is_empty() {
                        causes.push(format!("the base case changed: {}", keys.join(", ")));
                    }
                }
                let now = Fingerprint::of(&self.base, &self.base_dir);
                let changed: Vec<&str> = now
                    .files
                    .iter()
                    .filter(|(name, h)| {
                        let was = record["files"][name.as_str()].as_str();
                        was != h.map(|h| format!("{h:016x}")).as_deref()
                    })
                    .map(|(name, _)| name.as_str())
                    .collect();
                if !changed.is_empty() {
                    causes.push(format!("the content of {} changed", changed.join(", ")));
                }
            }
            None => causes.push(format!(
                "{} is missing: the inputs of its rows are unknown",
                record_path(table).display()
            )),
        }
        let columns = self.columns();
        for row in stale.iter().take(3) {
            match runs.get(row.index) {
                None => causes.push(format!(
                    "the table has run {}, the study now has {} runs",
                    row.index,
                    runs.len()
                )),
                Some(run) => {
                    let moved: Vec<String> = columns
                        .iter()
                        .zip(&run.values)
                        .zip(&row.values)
                        .filter(|((_, v), cell)| csv_value(v) != **cell)
                        .map(|((c, v), cell)| {
                            format!("{} = {cell} in the table, {} now", c.key, csv_value(v))
                        })
                        .collect();
                    if !moved.is_empty() {
                        causes.push(format!("run {}: {}", row.index, moved.join(", ")));
                    }
                }
            }
        }
        if causes.is_empty() {
            causes.push("a file the runs read, or the values of a run, changed".into());
        }
        causes.join("; ")
    }
}

/// Options of [`Study::run_checked`].
#[derive(Debug, Default, Clone, Copy)]
pub struct StudyOptions<'a> {
    /// Runs at a time (0: one per core).
    pub jobs: usize,
    /// Replace an existing table (and its record) instead of continuing it.
    pub fresh: bool,
    /// Set from outside (a signal): no run starts, the runs under way are dropped.
    pub stop: Option<&'a AtomicBool>,
}

/// What [`Study::run_checked`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StudyOutcome {
    /// Runs finished now (rows appended).
    pub done: usize,
    /// Runs already in the table.
    pub already: usize,
    /// Runs that were to be done.
    pub pending: usize,
    /// Stopped by `stop` before every pending run was done.
    pub stopped: bool,
}

/// The record of the inputs of the table at `table`: `study.csv` → `study.csv.inputs.json`.
pub fn record_path(table: &Path) -> PathBuf {
    sibling(table, ".inputs.json", "")
}

/// The lock of the table at `table`: `study.csv` → `.study.csv.lock`, beside it.
fn lock_path(table: &Path) -> PathBuf {
    sibling(table, ".lock", ".")
}

fn sibling(table: &Path, suffix: &str, prefix: &str) -> PathBuf {
    let name = table.file_name().unwrap_or_default().to_string_lossy();
    table.with_file_name(format!("{prefix}{name}{suffix}"))
}

/// The table of a study, open for appending and locked ([`Study::open_table`]).
#[derive(Debug)]
pub struct StudyTable {
    path: PathBuf,
    file: std::fs::File,
    _lock: Lock,
    /// Each run's fingerprint, by index.
    expected: Vec<String>,
    /// Runs with a row.
    done: BTreeSet<usize>,
    /// Columns of a row.
    columns: usize,
}

impl StudyTable {
    /// The runs without a row, in order.
    pub fn pending(&self) -> Vec<usize> {
        (0..self.expected.len())
            .filter(|i| !self.done.contains(i))
            .collect()
    }

    /// Runs with a row.
    pub fn done(&self) -> usize {
        self.done.len()
    }

    /// Appends a run's row (as [`Study::run_row`] formats it), after checking that it is a
    /// pending run's, with the fingerprint of its inputs here: a row computed elsewhere
    /// (a Dask worker) from other files than this machine's is refused, as is a run twice.
    pub fn append(&mut self, row: &str) -> Result<()> {
        let cells: Vec<&str> = row.split(',').collect();
        let index = cells.first().and_then(|c| c.parse::<usize>().ok());
        let fingerprint = cells.last().copied().unwrap_or_default();
        let refuse = |why: String| {
            Err(Error::invalid(
                "table",
                format!("{}: a row is refused: {why}", self.path.display()),
            ))
        };
        let Some(index) = index.filter(|_| cells.len() == self.columns) else {
            return refuse(format!(
                "it is not a row of this study ({} columns, {} expected)",
                cells.len(),
                self.columns
            ));
        };
        match self.expected.get(index) {
            None => {
                return refuse(format!(
                    "run {index} is not one of the study's {} runs",
                    self.expected.len()
                ));
            }
            Some(f) if f != fingerprint => {
                return refuse(format!(
                    "run {index} was computed from other inputs ({fingerprint}) than this study gives it here ({f}): the base case or a file it reads differs where it ran (the workers need the same files)"
                ));
            }
            Some(_) if self.done.contains(&index) => {
                return refuse(format!("run {index} has a row already"));
            }
            Some(_) => {}
        }
        writeln!(self.file, "{row}")
            .and_then(|_| self.file.flush())
            .map_err(|e| Error::io(&self.path, e))?;
        self.done.insert(index);
        if self.done.len() == self.expected.len() {
            self.sort_rows()?;
        }
        Ok(())
    }

    /// Puts the rows in the order of the runs once every run has its row: they are appended
    /// as the runs finish, in the order the threads (or Dask's workers) finish them, and a
    /// table read by a person, or compared between two sweeps, should not depend on that.
    /// Each row keeps its bytes; the file is replaced atomically (a crash leaves the table
    /// in one order or the other, whole), and reopened for appending.
    fn sort_rows(&mut self) -> Result<()> {
        let text = std::fs::read_to_string(&self.path).map_err(|e| Error::io(&self.path, e))?;
        let mut lines = text.lines();
        let Some(header) = lines.next() else {
            return Ok(());
        };
        let run = |line: &str| {
            line.split(',')
                .next()
                .and_then(|c| c.parse::<usize>().ok())
                .unwrap_or(usize::MAX)
        };
        let mut rows: Vec<&str> = lines.filter(|l| !l.is_empty()).collect();
        if rows.is_sorted_by_key(|l| run(l)) {
            return Ok(());
        }
        rows.sort_by_key(|l| run(l));
        let mut sorted = String::with_capacity(text.len());
        for line in std::iter::once(header).chain(rows) {
            sorted.push_str(line);
            sorted.push('\n');
        }
        crate::files::write_text_atomically(&self.path, &sorted)?;
        self.file = std::fs::OpenOptions::new()
            .append(true)
            .open(&self.path)
            .map_err(|e| Error::io(&self.path, e))?;
        Ok(())
    }
}
