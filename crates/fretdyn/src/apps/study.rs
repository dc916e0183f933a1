//! Parametric and Monte-Carlo studies: a base case, parameters to vary (as a grid or a list)
//! and seeds; every run independent, run in parallel on the cores of the machine (rayon),
//! one row per finished run appended to a CSV table, so that a study killed midway keeps its
//! finished rows and, run again, skips them.
//!
//! A study file (`examples/study_clearance.toml`):
//!
//! ```toml
//! base = "tube_multispan.toml"       # the case, relative to the study file
//! combine = "grid"                   # every combination ("grid") or row by row ("list")
//! seeds = [1, 2]                     # optional: each run once per seed (turbulence[*].seed)
//!
//! [[parameters]]
//! key = "contacts.*.obstacle.clearance"   # dotted path in the case; * = every element
//! values = [1e-4, 2e-4]
//!
//! [plot]                             # optional: what `fretdyn sweep` plots
//! x = "contacts.*.obstacle.clearance"
//! statistic = "wear_work_rate"
//! ```

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use serde::Deserialize;

use crate::case::{Case, check_case_text, parse_error};
use crate::error::{Error, Result};
use crate::integrator::simulation::{RunResults, Simulation, Termination};

/// How the parameters' values are combined into runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Combine {
    /// Every combination of the values (the runs are the Cartesian product).
    #[default]
    Grid,
    /// The k-th run takes the k-th value of every parameter (all lists of one length).
    List,
}

/// One parameter of a study: a dotted path in the case file and its values.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Parameter {
    /// Dotted path: `time.dt`, `contacts.0.friction.mu`, `contacts.*.obstacle.clearance`
    /// (`*`: every element of an array).
    pub key: String,
    /// Values (numbers, strings or booleans, as in the case file).
    pub values: Vec<toml::Value>,
}

/// What `fretdyn sweep` plots.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlotSpec {
    /// Parameter on the x axis.
    pub x: String,
    /// Per-contact statistic on the y axis (a column of the table without its contact prefix).
    pub statistic: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StudyFile {
    base: String,
    #[serde(default)]
    combine: Combine,
    #[serde(default)]
    seeds: Vec<u64>,
    #[serde(default)]
    parameters: Vec<Parameter>,
    plot: Option<PlotSpec>,
}

/// A study: the base case as TOML, the parameters, the seeds.
#[derive(Debug, Clone)]
pub struct Study {
    /// The base case, parsed but not built.
    pub base: toml::Value,
    /// Folder the base case's relative paths are resolved from.
    pub base_dir: PathBuf,
    /// How the values are combined.
    pub combine: Combine,
    /// Parameters.
    pub parameters: Vec<Parameter>,
    /// Seeds (empty: one run per combination, with the case's own seeds).
    pub seeds: Vec<u64>,
    /// What to plot.
    pub plot: Option<PlotSpec>,
}

/// One run of a study: its index, its parameter values and seed.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    /// Index in the study (stable: the same study gives the same indices).
    pub index: usize,
    /// Value of each parameter.
    pub values: Vec<toml::Value>,
    /// Seed, if the study has seeds.
    pub seed: Option<u64>,
}

/// Statistics written per contact in the table, as `<contact>.<statistic>`.
pub const TABLE_STATISTICS: [&str; 10] = [
    "impacts_per_second",
    "contact_time_fraction",
    "stick_time_fraction",
    "slip_time_fraction",
    "normal_force_mean",
    "normal_force_rms",
    "normal_force_max",
    "tangential_force_rms",
    "wear_work_rate",
    "normal_wear_work_rate",
];

/// The statistics of [`TABLE_STATISTICS`] with a standard error by batch means, written
/// as `<contact>.<statistic>_se` after a contact's statistics (empty with fewer than 2
/// batches).
pub fn table_errors() -> impl Iterator<Item = &'static str> {
    TABLE_STATISTICS
        .into_iter()
        .filter(|s| crate::results::statistics::BATCHED_STATISTICS.contains(s))
}

impl Study {
    /// Reads a study file.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let value: toml::Value = toml::from_str(&text).map_err(|e| parse_error(&text, &e))?;
        if value.get("base").is_none() && value.get("structure").is_some() {
            return Err(Error::invalid(
                "base",
                "this is a case file, not a study file (base = \"case.toml\" and [[parameters]]): run it with `fretdyn run <file>`",
            ));
        }
        let file: StudyFile = toml::from_str(&text).map_err(|e| parse_error(&text, &e))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let base_path = dir.join(&file.base);
        let base_text =
            std::fs::read_to_string(&base_path).map_err(|e| Error::io(&base_path, e))?;
        // the base case's own mistakes are reported with their line in it
        check_case_text(&base_text)
            .map_err(|e| Error::invalid("base", format!("{}: {e}", base_path.display())))?;
        let base: toml::Value = toml::from_str(&base_text).map_err(|e| {
            Error::invalid(
                "base",
                format!("{}: {}", base_path.display(), parse_error(&base_text, &e)),
            )
        })?;
        let study = Self {
            base,
            base_dir: base_path.parent().unwrap_or(Path::new(".")).to_path_buf(),
            combine: file.combine,
            parameters: file.parameters,
            seeds: file.seeds,
            plot: file.plot,
        };
        study.validate()?;
        Ok(study)
    }

    fn validate(&self) -> Result<()> {
        for (k, p) in self.parameters.iter().enumerate() {
            if p.values.is_empty() {
                return Err(Error::invalid(
                    format!("parameters[{k}].values"),
                    "give at least one value",
                ));
            }
            // the path must exist in the base case
            let mut probe = self.base.clone();
            set_path(&mut probe, &p.key, &p.values[0])
                .map_err(|m| Error::invalid(format!("parameters[{k}].key"), m))?;
        }
        if self.combine == Combine::List {
            let lens: BTreeSet<usize> = self.parameters.iter().map(|p| p.values.len()).collect();
            if lens.len() > 1 {
                return Err(Error::invalid(
                    "combine",
                    format!(
                        "\"list\" needs lists of one length (got lengths {lens:?}); use \"grid\" for every combination"
                    ),
                ));
            }
        }
        if let Some(plot) = &self.plot {
            if !self.parameters.iter().any(|p| p.key == plot.x) {
                return Err(Error::invalid(
                    "plot.x",
                    format!("'{}' is not one of the parameters' keys", plot.x),
                ));
            }
            if !TABLE_STATISTICS.contains(&plot.statistic.as_str()) {
                return Err(Error::invalid(
                    "plot.statistic",
                    format!("must be one of {TABLE_STATISTICS:?}"),
                ));
            }
        }
        Ok(())
    }

    /// Every run of the study, in a stable order.
    pub fn runs(&self) -> Vec<RunSpec> {
        let combos: Vec<Vec<toml::Value>> = match self.combine {
            Combine::List => {
                let n = self.parameters.first().map_or(1, |p| p.values.len());
                (0..n)
                    .map(|i| {
                        self.parameters
                            .iter()
                            .map(|p| p.values[i].clone())
                            .collect()
                    })
                    .collect()
            }
            Combine::Grid => self.parameters.iter().fold(vec![vec![]], |acc, p| {
                acc.iter()
                    .flat_map(|prefix| {
                        p.values.iter().map(move |v| {
                            let mut c = prefix.clone();
                            c.push(v.clone());
                            c
                        })
                    })
                    .collect()
            }),
        };
        let seeds: Vec<Option<u64>> = if self.seeds.is_empty() {
            vec![None]
        } else {
            self.seeds.iter().copied().map(Some).collect()
        };
        combos
            .iter()
            .flat_map(|values| seeds.iter().map(move |seed| (values.clone(), *seed)))
            .enumerate()
            .map(|(index, (values, seed))| RunSpec {
                index,
                values,
                seed,
            })
            .collect()
    }

    /// The case of one run.
    pub fn case(&self, run: &RunSpec) -> Result<Case> {
        let mut value = self.base.clone();
        for (p, v) in self.parameters.iter().zip(&run.values) {
            set_path(&mut value, &p.key, v).map_err(|m| Error::invalid(p.key.clone(), m))?;
        }
        if let Some(seed) = run.seed {
            if let Some(toml::Value::Array(loads)) = value.get_mut("turbulence") {
                for l in loads {
                    if let Some(t) = l.as_table_mut() {
                        t.insert("seed".into(), toml::Value::Integer(seed as i64));
                    }
                }
            }
        }
        let text = toml::to_string(&value)
            .map_err(|e| Error::invalid("study", format!("cannot write the case: {e}")))?;
        Case::from_toml_str(&text, &self.base_dir).map_err(|e| match e {
            // the base reads (checked by `from_file`): a value does not fit its key
            Error::Parse { message, .. } => self.misfit(run, message),
            other => other,
        })
    }

    /// The parameter whose value of `run` makes the case unreadable (a string where a number
    /// is expected, an unknown method…): the first that does alone.
    fn misfit(&self, run: &RunSpec, message: String) -> Error {
        for (k, (p, v)) in self.parameters.iter().zip(&run.values).enumerate() {
            let mut value = self.base.clone();
            let alone = set_path(&mut value, &p.key, v)
                .ok()
                .and_then(|_| toml::to_string(&value).ok())
                .is_some_and(|text| check_case_text(&text).is_err());
            if alone {
                return Error::invalid(
                    format!("parameters[{k}].values"),
                    format!("{} = {v} does not fit the case: {message}", p.key),
                );
            }
        }
        Error::invalid(
            "parameters",
            format!("these values do not fit the case: {message}"),
        )
    }

    /// Names of the base case's contacts, as the case gives them (`contact<k>` when unnamed),
    /// read from the TOML: the header needs no model built.
    pub fn contact_names(&self) -> Vec<String> {
        match self.base.get("contacts") {
            Some(toml::Value::Array(contacts)) => contacts
                .iter()
                .enumerate()
                .map(|(k, c)| {
                    c.get("name")
                        .and_then(|n| n.as_str())
                        .map_or_else(|| format!("contact{k}"), String::from)
                })
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Header of the table: run, each parameter, seed, status, steps/s, then
    /// `<contact>.<statistic>` for every contact of the base case, then
    /// [`CONNORS_COLUMN`].
    pub fn header(&self, contacts: &[String]) -> String {
        let mut cols = vec!["run".to_string()];
        cols.extend(self.parameters.iter().map(|p| p.key.clone()));
        cols.extend(["seed", "status", "steps_per_second"].map(String::from));
        for c in contacts {
            for s in TABLE_STATISTICS {
                cols.push(format!("{c}.{s}"));
            }
            for s in table_errors() {
                cols.push(format!("{c}.{s}_se"));
            }
        }
        cols.push(CONNORS_COLUMN.to_string());
        cols.join(",")
    }

    /// `key = value, …` of a run's parameters and its seed, for messages.
    pub fn describe(&self, run: &RunSpec) -> String {
        let mut parts: Vec<String> = self
            .parameters
            .iter()
            .zip(&run.values)
            .map(|(p, v)| format!("{} = {v}", p.key))
            .collect();
        if let Some(seed) = run.seed {
            parts.push(format!("seed = {seed}"));
        }
        if parts.is_empty() {
            "the base case".into()
        } else {
            parts.join(", ")
        }
    }

    /// Builds the case of every run and checks it as a run would (the stability limit of
    /// Δt included), `jobs` at a time (0: one per core), so that a value that makes a case
    /// invalid is found before any run starts. The error is that of the first such run, as
    /// [`Error::StudyRun`] naming it and its values.
    pub fn check(&self, jobs: usize) -> Result<()> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs)
            .build()
            .map_err(|e| Error::invalid("jobs", e.to_string()))?;
        use rayon::prelude::*;
        let runs = self.runs();
        let first = pool.install(|| {
            runs.par_iter().find_map_first(|run| {
                self.case(run)
                    .and_then(|case| Simulation::check(&case.model, &case.settings))
                    .err()
                    .map(|e| Error::StudyRun {
                        index: run.index,
                        point: self.describe(run),
                        source: Box::new(e),
                    })
            })
        });
        first.map_or(Ok(()), Err)
    }

    /// Runs every run not already in the table at `table` (created with its header if
    /// missing), `jobs` at a time (0: one per core), appending one row per run as it
    /// finishes; `progress(done, total)` after each. Returns the number of runs done now.
    /// Every run is checked first ([`Self::check`]): a bad value runs nothing.
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
        let runs = self.runs();
        let header = self.header(&self.contact_names());
        let done = read_done(table, &header)?;
        // a row cut by a crash is dropped (its run is done again)
        if let Ok(text) = std::fs::read(table) {
            if !text.is_empty() && !text.ends_with(b"\n") {
                let keep = text.iter().rposition(|b| *b == b'\n').map_or(0, |i| i + 1);
                let f = std::fs::OpenOptions::new()
                    .write(true)
                    .open(table)
                    .map_err(|e| Error::io(table, e))?;
                f.set_len(keep as u64).map_err(|e| Error::io(table, e))?;
            }
        }
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(table)
            .map_err(|e| Error::io(table, e))?;
        if done.is_empty() && file.metadata().map(|m| m.len()).unwrap_or(0) == 0 {
            writeln!(file, "{header}").map_err(|e| Error::io(table, e))?;
        }
        let pending: Vec<&RunSpec> = runs.iter().filter(|r| !done.contains(&r.index)).collect();
        let total = pending.len();
        let file = Mutex::new(file);
        let finished = std::sync::atomic::AtomicUsize::new(0);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs)
            .build()
            .map_err(|e| Error::invalid("jobs", e.to_string()))?;
        use rayon::prelude::*;
        pool.install(|| {
            pending.par_iter().try_for_each(|run| -> Result<()> {
                let row = self.run_row(run)?;
                let mut f = file.lock().unwrap_or_else(|e| e.into_inner());
                writeln!(f, "{row}")
                    .and_then(|_| f.flush())
                    .map_err(|e| Error::io(table, e))?;
                drop(f);
                let n = finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(n, total);
                Ok(())
            })
        })?;
        Ok(total)
    }

    /// Runs one run and formats its row. Only the statistics are kept
    /// ([`run_statistics`]): memory does not grow with the length of the run.
    pub fn run_row(&self, run: &RunSpec) -> Result<String> {
        let case = self.case(run)?;
        let r = run_statistics(&case)?;
        let mut cols = vec![run.index.to_string()];
        cols.extend(run.values.iter().map(csv_value));
        cols.push(run.seed.map(|s| s.to_string()).unwrap_or_default());
        cols.push(
            match r.termination {
                Termination::Completed => "completed",
                Termination::Diverged { .. } => "diverged",
                Termination::Stopped { .. } | Termination::InProgress { .. } => "stopped",
            }
            .to_string(),
        );
        cols.push(r.steps_per_second().to_string());
        for c in &r.contacts {
            let v = serde_json::to_value(c).unwrap_or_default();
            for s in TABLE_STATISTICS {
                cols.push(v[s].as_f64().map(|x| x.to_string()).unwrap_or_default());
            }
            for s in table_errors() {
                let se = &v[format!("{s}_se")];
                cols.push(se.as_f64().map(|x| x.to_string()).unwrap_or_default());
            }
        }
        cols.push(
            case.stability()
                .and_then(|report| report.max_ratio())
                .map(|x| x.to_string())
                .unwrap_or_default(),
        );
        Ok(cols.join(","))
    }
}

/// Column of the study table with the largest Connors ratio `U_eff/U_c` over the modes of
/// the run's case (docs/FLOW.md; `inf` for an undamped mode in a flow; empty without
/// `[flow]`).
pub const CONNORS_COLUMN: &str = "connors_max_ratio";

/// The runs of a study table whose case has a mode above its Connors critical velocity.
#[derive(Debug, Clone, PartialEq)]
pub struct ConnorsExceedance {
    /// Runs with `connors_max_ratio > 1`.
    pub runs: usize,
    /// Runs in the table.
    pub of: usize,
    /// The largest ratio, and the index of its run.
    pub largest: (f64, usize),
}

/// Reads the [`CONNORS_COLUMN`] of a study table (complete rows only): `None` when no run
/// has a ratio above 1 (or the table has no such column).
pub fn connors_exceedance(table: &Path) -> Result<Option<ConnorsExceedance>> {
    let text = std::fs::read_to_string(table).map_err(|e| Error::io(table, e))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let Some(col) = header.iter().position(|h| *h == CONNORS_COLUMN) else {
        return Ok(None);
    };
    let rows: Vec<Vec<&str>> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|r| r.len() == header.len())
        .collect();
    let mut found: Option<ConnorsExceedance> = None;
    for r in &rows {
        let (Ok(ratio), Ok(run)) = (r[col].parse::<f64>(), r[0].parse::<usize>()) else {
            continue;
        };
        if ratio > 1.0 {
            let f = found.get_or_insert(ConnorsExceedance {
                runs: 0,
                of: rows.len(),
                largest: (ratio, run),
            });
            f.runs += 1;
            if ratio > f.largest.0 {
                f.largest = (ratio, run);
            }
        }
    }
    Ok(found)
}

/// Runs `case` for its statistics (THEORY §5) only: neither the time histories (a recorder of
/// one sample, emptied when full) nor the list of impacts and blocks are kept, so that memory
/// does not grow with the run's length. The statistics are those of
/// [`crate::integrator::simulation::simulate`] (running sums, which do not depend on what is recorded).
pub fn run_statistics(case: &Case) -> Result<RunResults> {
    let start = Instant::now();
    let mut sim = Simulation::with_recorder(&case.model, &case.settings, 1)?;
    let total = case.settings.steps;
    let mut termination = Termination::Completed;
    while sim.steps_done() < total {
        if let Err(d) = sim.step() {
            termination = d.into_termination(&case.model);
            break;
        }
        if sim.recorder().is_full() {
            sim.recorder_mut().clear();
        }
        if sim.steps_done() % 1024 == 0 {
            let statistics = sim.statistics_mut();
            statistics.impacts.clear();
            statistics.blocks.clear();
        }
    }
    Ok(sim.finish(start.elapsed().as_secs_f64(), termination))
}

fn csv_value(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.replace(',', "_"),
        other => other.to_string(),
    }
}

/// Indices of the runs already in the table (rows with every column); checks its header.
fn read_done(table: &Path, header: &str) -> Result<BTreeSet<usize>> {
    let Ok(text) = std::fs::read_to_string(table) else {
        return Ok(BTreeSet::new());
    };
    let mut lines = text.lines();
    match lines.next() {
        None => return Ok(BTreeSet::new()),
        Some(h) if h == header => {}
        Some(_) => {
            return Err(Error::invalid(
                "table",
                format!(
                    "{} has another header: it belongs to another study; give another output",
                    table.display()
                ),
            ));
        }
    }
    let columns = header.split(',').count();
    let complete = if text.ends_with('\n') {
        text.lines().count()
    } else {
        text.lines().count().saturating_sub(1)
    };
    Ok(lines
        .take(complete.saturating_sub(1))
        .filter(|l| l.split(',').count() == columns)
        .filter_map(|l| l.split(',').next()?.parse().ok())
        .collect())
}

/// Sets `key` (dotted, `*` for every element of an array, numbers for one element) in a TOML
/// value; the path must exist.
fn set_path(
    root: &mut toml::Value,
    key: &str,
    value: &toml::Value,
) -> std::result::Result<(), String> {
    fn go(
        v: &mut toml::Value,
        parts: &[&str],
        value: &toml::Value,
        key: &str,
    ) -> std::result::Result<(), String> {
        let Some((head, rest)) = parts.split_first() else {
            *v = value.clone();
            return Ok(());
        };
        let missing = || format!("'{key}': '{head}' is not in the base case");
        match v {
            toml::Value::Array(items) if *head == "*" => {
                if items.is_empty() {
                    return Err(missing());
                }
                items
                    .iter_mut()
                    .try_for_each(|item| go(item, rest, value, key))
            }
            toml::Value::Array(items) => {
                let i: usize = head.parse().map_err(|_| missing())?;
                go(items.get_mut(i).ok_or_else(missing)?, rest, value, key)
            }
            toml::Value::Table(t) => go(t.get_mut(*head).ok_or_else(missing)?, rest, value, key),
            _ => Err(missing()),
        }
    }
    let parts: Vec<&str> = key.split('.').collect();
    go(root, &parts, value, key)
}
