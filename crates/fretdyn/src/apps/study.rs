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
//!
//! A probabilistic study draws parameters from distributions
//! ([`sampling`](crate::apps::sampling), `docs/STUDIES.md`):
//!
//! ```toml
//! base = "tube_multispan.toml"
//! samples = 200                      # draws; every grid point gets all of them
//! seed = 1                           # the draws depend on (seed, sample, parameter) only
//!
//! [[parameters]]
//! key = "contacts.*.obstacle.clearance"
//! independent = true                 # one draw per contact, a column each
//! distribution = { type = "uniform", low = 1e-4, high = 3e-4 }
//!
//! [percentiles]                      # optional: P50, P95, P99 and their errors
//! statistics = ["wear_work_rate"]
//! ```
//!
//! The runs are: every combination of the `values` parameters (grid or list) × every sample ×
//! every seed, in that order; percentiles ([`percentiles`](crate::apps::percentiles)) pool the
//! samples and seeds of a combination.

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use serde::Deserialize;

use super::percentiles::{PercentileReport, PercentileRequest, percentiles_of_table};
use super::sampling::{Distribution, Stream};
use crate::case::key_path::{KeyPath, KeyPathError, Missing, Part};
use crate::case::{Case, check_case_text, parse_error};
use crate::error::{Error, Result};
use crate::integrator::simulation::{RunResults, RunSettings, Simulation, Termination};
use crate::model::Model;
use crate::results::wear_map::WearMap;

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

/// One parameter of a study: a dotted path in the case file and its values, or the
/// distribution its values are drawn from.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Dotted path: `time.dt`, `contacts.0.friction.mu`, `contacts.*.obstacle.clearance`
    /// (`*`: every element of an array).
    pub key: String,
    /// Values (numbers, strings or booleans, as in the case file); empty for a drawn
    /// parameter.
    pub values: Vec<toml::Value>,
    /// Distribution of a drawn parameter (then `values` is empty).
    pub distribution: Option<Distribution>,
    /// A drawn parameter with `*` in its key: one draw per element (else one draw for all).
    pub independent: bool,
}

impl Parameter {
    /// A parameter taking `values` in turn.
    pub fn with_values(key: impl Into<String>, values: Vec<toml::Value>) -> Self {
        Self {
            key: key.into(),
            values,
            distribution: None,
            independent: false,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawParameter {
    key: String,
    values: Option<Vec<toml::Value>>,
    distribution: Option<toml::Value>,
    independent: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPercentiles {
    statistics: Option<Vec<String>>,
    levels: Option<Vec<toml::Value>>,
    confidence: Option<f64>,
    bootstrap: Option<i64>,
}

/// What `[percentiles]` asks for (`docs/STUDIES.md`).
#[derive(Debug, Clone, PartialEq)]
pub struct PercentileSpec {
    /// Statistics: a per-contact statistic (`wear_work_rate`: every contact's column) or any
    /// column name of the table.
    pub statistics: Vec<String>,
    /// Levels, percent (default 50, 95, 99).
    pub levels: Vec<f64>,
    /// Confidence of the intervals (default 0.95).
    pub confidence: f64,
    /// Bootstrap resamples (default 1000).
    pub bootstrap: usize,
}

/// Statistic of `[percentiles]` when the section is not given.
pub const DEFAULT_PERCENTILE_STATISTIC: &str = "wear_work_rate";

/// A column of the table that a parameter sets: its key (concrete for an independent draw),
/// its parameter and, for an independent draw, its element.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// Dotted path set by the column (the header's name).
    pub key: String,
    /// Index of its parameter.
    pub parameter: usize,
    /// Element of an independent draw (its index in the expansion of the key's `*`).
    pub element: Option<usize>,
}

/// The draws of a probabilistic study.
#[derive(Debug, Clone, PartialEq)]
pub struct Sampling {
    /// Number of samples.
    pub samples: usize,
    /// Seed of the draws.
    pub seed: u64,
    /// The table's parameter columns.
    pub columns: Vec<Column>,
}

/// Most samples a study may ask for (its runs are listed in memory).
pub const MAX_SAMPLES: i64 = 100_000;

impl Sampling {
    /// The value of `column` in sample `sample` (`None` for a `values` column): drawn from
    /// [`Stream::new`]`(seed, [sample, parameter, element])` (`element` only for an
    /// independent draw), a pure function of these indices.
    pub fn value(
        &self,
        parameters: &[Parameter],
        sample: usize,
        column: &Column,
    ) -> Option<toml::Value> {
        parameters[column.parameter].distribution.as_ref().map(|d| {
            let mut indices = vec![sample as u64, column.parameter as u64];
            indices.extend(column.element.map(|e| e as u64));
            d.draw(&mut Stream::new(self.seed, &indices))
        })
    }
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
    base: Option<String>,
    #[serde(default)]
    combine: Combine,
    #[serde(default)]
    seeds: Vec<u64>,
    #[serde(default)]
    parameters: Vec<RawParameter>,
    plot: Option<PlotSpec>,
    samples: Option<i64>,
    seed: Option<u64>,
    percentiles: Option<RawPercentiles>,
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
    /// The draws of a probabilistic study (`samples = N`).
    pub sampling: Option<Sampling>,
    /// Percentiles to report (`[percentiles]`, or its defaults with `samples`).
    pub percentiles: Option<PercentileSpec>,
}

/// One run of a study: its index, its parameter values, sample and seed.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    /// Index in the study (stable: the same study gives the same indices).
    pub index: usize,
    /// Value of each parameter column ([`Study::columns`]).
    pub values: Vec<toml::Value>,
    /// Sample, if the study draws parameters.
    pub sample: Option<usize>,
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
        Self::from_toml_str(&text, path.parent().unwrap_or(Path::new(".")), None)
    }

    /// A study from the text of a study file; `dir` resolves its `base`. With `base_case`
    /// (a case as TOML and the folder its file names are relative to), that is the base case
    /// and the study gives no `base`.
    pub fn from_toml_str(
        text: &str,
        dir: &Path,
        base_case: Option<(toml::Value, PathBuf)>,
    ) -> Result<Self> {
        let value: toml::Value = toml::from_str(text).map_err(|e| parse_error(text, &e))?;
        if value.get("base").is_none() && value.get("structure").is_some() {
            return Err(Error::invalid(
                "base",
                "this is a case file, not a study file (base = \"case.toml\" and [[parameters]]): run it with `fretdyn run <file>`",
            ));
        }
        let file: StudyFile = toml::from_str(text).map_err(|e| parse_error(text, &e))?;
        let (base, base_dir) = match (base_case, &file.base) {
            (Some(_), Some(_)) => {
                return Err(Error::invalid(
                    "base",
                    "the base case is given twice: remove base from the study",
                ));
            }
            (Some((base, base_dir)), None) => (base, base_dir),
            (None, None) => {
                return Err(Error::invalid(
                    "base",
                    "missing: give base = \"case.toml\", the case file the study varies",
                ));
            }
            (None, Some(name)) => {
                let base_path = dir.join(name);
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
                let base_dir = base_path.parent().unwrap_or(Path::new(".")).to_path_buf();
                (base, base_dir)
            }
        };
        let parameters = file
            .parameters
            .into_iter()
            .enumerate()
            .map(|(k, p)| parameter(k, p))
            .collect::<Result<Vec<_>>>()?;
        let drawn = parameters.iter().position(|p| p.distribution.is_some());
        let sampling = match (file.samples, drawn) {
            (Some(n), _) if !(1..=MAX_SAMPLES).contains(&n) => {
                return Err(Error::invalid(
                    "samples",
                    format!(
                        "must be between 1 and {MAX_SAMPLES}, got {n}: the number of draws of the distributions"
                    ),
                ));
            }
            (Some(n), Some(_)) => Some(Sampling {
                samples: n as usize,
                seed: file.seed.unwrap_or(0),
                columns: columns(&base, &parameters)?,
            }),
            (Some(_), None) => {
                return Err(Error::invalid(
                    "samples",
                    "no parameter has a distribution: give one distribution = { type = …, … } in [[parameters]], or remove samples",
                ));
            }
            (None, Some(k)) => {
                return Err(Error::invalid(
                    "samples",
                    format!(
                        "missing: parameters[{k}] has a distribution: give samples = N (the number of draws) at the top of the study file"
                    ),
                ));
            }
            (None, None) => {
                if file.seed.is_some() {
                    return Err(Error::invalid(
                        "seed",
                        "is the seed of the draws and no parameter has a distribution: remove it (seeds = [...] sets the turbulence's seeds)",
                    ));
                }
                None
            }
        };
        let percentiles = match (file.percentiles, &sampling) {
            (Some(raw), _) => Some(percentile_spec(raw)?),
            (None, Some(_)) => Some(PercentileSpec {
                statistics: vec![DEFAULT_PERCENTILE_STATISTIC.to_string()],
                levels: vec![50.0, 95.0, 99.0],
                confidence: 0.95,
                bootstrap: 1000,
            }),
            (None, None) => None,
        };
        let study = Self {
            base,
            base_dir,
            combine: file.combine,
            parameters,
            seeds: file.seeds,
            plot: file.plot,
            sampling,
            percentiles,
        };
        study.validate()?;
        Ok(study)
    }

    fn validate(&self) -> Result<()> {
        for (k, p) in self.parameters.iter().enumerate() {
            // the path must exist in the base case
            let probe_value = match (&p.values.first(), &p.distribution) {
                (Some(v), _) => (*v).clone(),
                (None, Some(d)) => d.draw(&mut Stream::new(0, &[])),
                (None, None) => toml::Value::Integer(0),
            };
            let mut probe = self.base.clone();
            set_path(&mut probe, &p.key, &probe_value)
                .map_err(|e| Error::invalid(format!("parameters[{k}].key"), e.to_string()))?;
        }
        if let Some(spec) = &self.percentiles {
            let header = self.header(&self.contact_names());
            let columns: Vec<&str> = header.split(',').collect();
            for (i, s) in spec.statistics.iter().enumerate() {
                if self.percentile_columns(s, &columns).is_empty() {
                    return Err(Error::invalid(
                        format!("percentiles.statistics[{i}]"),
                        format!(
                            "'{s}' is neither a per-contact statistic nor a column of the table: use one of {TABLE_STATISTICS:?} or a column name"
                        ),
                    ));
                }
            }
        }
        if self.combine == Combine::List {
            let lens: BTreeSet<usize> = self
                .parameters
                .iter()
                .filter(|p| p.distribution.is_none())
                .map(|p| p.values.len())
                .collect();
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
            if !self.parameters.iter().any(|p| p.key == plot.x)
                && !self.columns().iter().any(|c| c.key == plot.x)
            {
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

    /// The table's parameter columns: one per parameter, or one per element for an
    /// independent draw.
    pub fn columns(&self) -> Vec<Column> {
        match &self.sampling {
            Some(s) => s.columns.clone(),
            None => self
                .parameters
                .iter()
                .enumerate()
                .map(|(k, p)| Column {
                    key: p.key.clone(),
                    parameter: k,
                    element: None,
                })
                .collect(),
        }
    }

    /// Columns of the table `statistic` of `[percentiles]` designates: `<contact>.<statistic>`
    /// for every contact, or the column of that name.
    fn percentile_columns(&self, statistic: &str, header: &[&str]) -> Vec<String> {
        let per_contact: Vec<String> = self
            .contact_names()
            .iter()
            .map(|c| format!("{c}.{statistic}"))
            .filter(|c| header.contains(&c.as_str()))
            .collect();
        if !per_contact.is_empty() {
            per_contact
        } else if header.contains(&statistic) {
            vec![statistic.to_string()]
        } else {
            Vec::new()
        }
    }

    /// The percentiles of `[percentiles]` (module [`percentiles`](super::percentiles)) from
    /// the table at `table`, grouped by the values of the `values` parameters; `None` when the
    /// study asks for none.
    pub fn percentiles(&self, table: &Path) -> Result<Option<PercentileReport>> {
        let Some(spec) = &self.percentiles else {
            return Ok(None);
        };
        let header = self.header(&self.contact_names());
        let names: Vec<&str> = header.split(',').collect();
        let columns = spec
            .statistics
            .iter()
            .flat_map(|s| self.percentile_columns(s, &names))
            .collect();
        let group_by = self
            .columns()
            .iter()
            .filter(|c| self.parameters[c.parameter].distribution.is_none())
            .map(|c| c.key.clone())
            .collect();
        let request = PercentileRequest {
            columns,
            levels: spec.levels.clone(),
            group_by,
            confidence: spec.confidence,
            bootstrap: spec.bootstrap,
            seed: self.sampling.as_ref().map_or(0, |s| s.seed),
        };
        percentiles_of_table(table, &request).map(Some)
    }

    /// Every run of the study, in a stable order: every combination of the `values`
    /// parameters, then every sample, then every seed.
    pub fn runs(&self) -> Vec<RunSpec> {
        let fixed: Vec<&Parameter> = self
            .parameters
            .iter()
            .filter(|p| p.distribution.is_none())
            .collect();
        let combos: Vec<Vec<toml::Value>> = match self.combine {
            Combine::List => {
                let n = fixed.first().map_or(1, |p| p.values.len());
                (0..n)
                    .map(|i| fixed.iter().map(|p| p.values[i].clone()).collect())
                    .collect()
            }
            Combine::Grid => fixed.iter().fold(vec![vec![]], |acc, p| {
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
        let samples: Vec<Option<usize>> = match &self.sampling {
            Some(s) => (0..s.samples).map(Some).collect(),
            None => vec![None],
        };
        let columns = self.columns();
        // position of each `values` parameter among the combination's values
        let fixed_at: Vec<Option<usize>> = {
            let mut k = 0;
            self.parameters
                .iter()
                .map(|p| {
                    p.distribution.is_none().then(|| {
                        k += 1;
                        k - 1
                    })
                })
                .collect()
        };
        let row = |combo: &[toml::Value], sample: Option<usize>| -> Vec<toml::Value> {
            columns
                .iter()
                .map(|col| match fixed_at[col.parameter] {
                    Some(i) => combo[i].clone(),
                    None => self
                        .sampling
                        .as_ref()
                        .zip(sample)
                        .and_then(|(s, k)| s.value(&self.parameters, k, col))
                        .unwrap_or(toml::Value::Integer(0)),
                })
                .collect()
        };
        let mut runs = Vec::new();
        for combo in &combos {
            for &sample in &samples {
                let values = row(combo, sample);
                for &seed in &seeds {
                    runs.push(RunSpec {
                        index: runs.len(),
                        values: values.clone(),
                        sample,
                        seed,
                    });
                }
            }
        }
        runs
    }

    /// The case of one run.
    pub fn case(&self, run: &RunSpec) -> Result<Case> {
        let mut value = self.base.clone();
        for (c, v) in self.columns().iter().zip(&run.values) {
            set_path(&mut value, &c.key, v)
                .map_err(|e| Error::invalid(c.key.clone(), e.to_string()))?;
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
        for (c, v) in self.columns().iter().zip(&run.values) {
            let mut value = self.base.clone();
            let alone = set_path(&mut value, &c.key, v)
                .ok()
                .and_then(|_| toml::to_string(&value).ok())
                .is_some_and(|text| check_case_text(&text).is_err());
            if alone {
                let k = c.parameter;
                let field = if self.parameters[k].distribution.is_some() {
                    "distribution"
                } else {
                    "values"
                };
                return Error::invalid(
                    format!("parameters[{k}].{field}"),
                    format!("{} = {v} does not fit the case: {message}", c.key),
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

    /// Header of the table: run, each parameter column ([`Self::columns`]), `sample` (in a
    /// probabilistic study), seed, status, steps/s, then `<contact>.<statistic>` for every
    /// contact of the base case, then [`CONNORS_COLUMN`].
    pub fn header(&self, contacts: &[String]) -> String {
        let mut cols = vec!["run".to_string()];
        cols.extend(self.columns().into_iter().map(|c| c.key));
        if self.sampling.is_some() {
            cols.push("sample".into());
        }
        cols.extend(["seed", "status", "steps_per_second"].map(String::from));
        for c in contacts {
            for s in TABLE_STATISTICS {
                cols.push(format!("{c}.{s}"));
            }
            for s in table_errors() {
                cols.push(format!("{c}.{s}_se"));
            }
        }
        if self.has_life() {
            cols.push("life_end".into());
            for c in contacts {
                for s in LIFE_COLUMNS {
                    cols.push(format!("{c}.{s}"));
                }
            }
        }
        cols.push(CONNORS_COLUMN.to_string());
        cols.join(",")
    }

    /// Whether the base case has a `[life]` section: each run is then a service life
    /// ([`crate::apps::life`]) and its row has the [`LIFE_COLUMNS`].
    pub fn has_life(&self) -> bool {
        self.base.get("life").is_some()
    }

    /// `key = value, …` of a run's parameters and its seed, for messages.
    pub fn describe(&self, run: &RunSpec) -> String {
        let mut parts: Vec<String> = self
            .columns()
            .iter()
            .zip(&run.values)
            .map(|(c, v)| format!("{} = {v}", c.key))
            .collect();
        if let Some(sample) = run.sample {
            parts.push(format!("sample {sample}"));
        }
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
        if self.sampling.is_some() {
            cols.push(run.sample.map(|s| s.to_string()).unwrap_or_default());
        }
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
        if let Some(life) = &case.life {
            cols.extend(life_row(&case, life)?);
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

/// Per-contact columns of a study whose base case has a `[life]` section (THEORY §14.5): the
/// tube's depth at the end of the life (m; at the target time, or where it stopped), the time
/// to the criterion (years; `inf` when not reached), and the same by the fixed-gap
/// extrapolation. Empty for a contact without `wear`.
pub const LIFE_COLUMNS: [&str; 4] = [
    "depth_at_target",
    "time_to_criterion",
    "depth_at_target_fixed_gap",
    "time_to_criterion_fixed_gap",
];

/// The life columns of one run: how it ended, then [`LIFE_COLUMNS`] per contact.
fn life_row(case: &Case, life: &crate::apps::life::LifeSettings) -> Result<Vec<String>> {
    use crate::apps::life::{LifeEnd, YEAR, service_life};
    let r = service_life(case, life, |_| {})?;
    let end = match r.end {
        LifeEnd::Completed => "completed",
        LifeEnd::Perforated { .. } => "perforated",
        LifeEnd::ScarLimit { .. } => "scar_limit",
        LifeEnd::Diverged { .. } => "diverged",
        LifeEnd::StepLimit => "step_limit",
    };
    let mut cols = vec![end.to_string()];
    let last = r.steps.last().map(|s| &s.contacts);
    let years = |t: Option<f64>| t.map_or("inf".to_string(), |t| (t / YEAR).to_string());
    for c in &case.model.contacts {
        match (r.contacts.iter().position(|n| n == &c.name), last) {
            (Some(i), Some(last)) => cols.extend([
                last[i].tube_depth.to_string(),
                years(r.time_to_criterion[i]),
                last[i].tube_depth_fixed_gap.to_string(),
                years(r.time_to_criterion_fixed_gap[i]),
            ]),
            _ => cols.extend(std::iter::repeat_n(String::new(), LIFE_COLUMNS.len())),
        }
    }
    Ok(cols)
}

/// The percentiles of the study file at `study` from the table at `table` (a table written by
/// `fretdyn sweep`, or by `fretdyn.sweep` on a Dask cluster): [`Study::percentiles`].
pub fn percentiles_from_table(study: &Path, table: &Path) -> Result<Option<PercentileReport>> {
    Study::from_file(study)?.percentiles(table)
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
    statistics_run(&case.model, &case.settings, None).map(|(results, _)| results)
}

/// [`run_statistics`] of `model` with `settings`; with `wear_bins`, also where each contact's
/// wear work was done ([`WearMap`] with that many bins around a hole, THEORY §14.3).
pub fn statistics_run(
    model: &Model,
    settings: &RunSettings,
    wear_bins: Option<usize>,
) -> Result<(RunResults, Option<WearMap>)> {
    let start = Instant::now();
    let mut sim = Simulation::with_recorder(model, settings, 1)?;
    if let Some(bins) = wear_bins {
        sim.track_wear(bins);
    }
    let total = settings.steps;
    let mut termination = Termination::Completed;
    while sim.steps_done() < total {
        // to the end of the batch, where the finished impacts and blocks are let go
        if let Err(d) = sim.steps(sim.steps_to_batch_end(total)) {
            termination = d.into_termination(model);
            break;
        }
        if sim.recorder().is_full() {
            sim.recorder_mut().clear();
        }
        if sim.steps_done() % Simulation::BATCH == 0 {
            let statistics = sim.statistics_mut();
            statistics.impacts.clear();
            statistics.blocks.clear();
        }
    }
    let map = sim.wear_map().cloned();
    Ok((sim.finish(start.elapsed().as_secs_f64(), termination), map))
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

/// Sets `key` (a [`KeyPath`]: dotted, `*` for every element of an array, numbers or `[i]` for
/// one element) in a TOML value; the path must exist.
fn set_path(
    root: &mut toml::Value,
    key: &str,
    value: &toml::Value,
) -> std::result::Result<(), KeyPathError> {
    KeyPath::parse(key)?.set(root, value, Missing::Refuse)
}

/// Checks a `[[parameters]]` entry (number `k`).
fn parameter(k: usize, raw: RawParameter) -> Result<Parameter> {
    let field = format!("parameters[{k}]");
    let distribution = match (&raw.values, &raw.distribution) {
        (Some(_), Some(_)) => {
            return Err(Error::invalid(
                field,
                "gives both values and distribution: keep one (values = [...] for a grid or list, distribution = { type = …, … } for draws)",
            ));
        }
        (None, None) => {
            return Err(Error::invalid(
                format!("{field}.values"),
                "missing: give values = [...] or distribution = { type = …, … }",
            ));
        }
        (Some(v), None) if v.is_empty() => {
            return Err(Error::invalid(
                format!("{field}.values"),
                "give at least one value",
            ));
        }
        (Some(_), None) => None,
        (None, Some(d)) => Some(Distribution::from_toml(
            d,
            &format!("{field}.distribution"),
        )?),
    };
    let independent = raw.independent.unwrap_or(false);
    if independent && distribution.is_none() {
        return Err(Error::invalid(
            format!("{field}.independent"),
            "applies to a drawn parameter (distribution = …): remove it, or give a distribution",
        ));
    }
    let every = KeyPath::parse(&raw.key)
        .map_err(|e| Error::invalid(format!("{field}.key"), e.to_string()))?
        .parts
        .contains(&Part::Every);
    if independent && !every {
        return Err(Error::invalid(
            format!("{field}.independent"),
            format!(
                "'{}' has no '*': independent = true draws each element of a '*' separately (e.g. contacts.*.obstacle.clearance)",
                raw.key
            ),
        ));
    }
    Ok(Parameter {
        key: raw.key,
        values: raw.values.unwrap_or_default(),
        distribution,
        independent,
    })
}

/// Checks `[percentiles]`.
fn percentile_spec(raw: RawPercentiles) -> Result<PercentileSpec> {
    let statistics = raw
        .statistics
        .unwrap_or_else(|| vec![DEFAULT_PERCENTILE_STATISTIC.to_string()]);
    if statistics.is_empty() {
        return Err(Error::invalid(
            "percentiles.statistics",
            "give at least one statistic, e.g. [\"wear_work_rate\"]",
        ));
    }
    let levels = match raw.levels {
        None => vec![50.0, 95.0, 99.0],
        Some(levels) if levels.is_empty() => {
            return Err(Error::invalid(
                "percentiles.levels",
                "give at least one level, percent: [50, 95, 99]",
            ));
        }
        Some(levels) => levels
            .iter()
            .enumerate()
            .map(
                |(i, v)| match v.as_float().or_else(|| v.as_integer().map(|i| i as f64)) {
                    Some(x) if x > 0.0 && x < 100.0 => Ok(x),
                    _ => Err(Error::invalid(
                        format!("percentiles.levels[{i}]"),
                        format!("must be a percent strictly between 0 and 100, got {v}"),
                    )),
                },
            )
            .collect::<Result<_>>()?,
    };
    let confidence = raw.confidence.unwrap_or(0.95);
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(Error::invalid(
            "percentiles.confidence",
            format!("must be strictly between 0 and 1 (0.95 for 95 %), got {confidence}"),
        ));
    }
    let bootstrap = match raw.bootstrap {
        None => 1000,
        Some(b) if b >= 2 => b as usize,
        Some(b) => {
            return Err(Error::invalid(
                "percentiles.bootstrap",
                format!("must be at least 2 resamples (1000 is usual), got {b}"),
            ));
        }
    };
    Ok(PercentileSpec {
        statistics,
        levels,
        confidence,
        bootstrap,
    })
}

/// The parameter columns of a probabilistic study: an independent draw's key expanded into one
/// concrete key per element of the base case (`contacts.*.x` → `contacts.0.x`, …).
fn columns(base: &toml::Value, parameters: &[Parameter]) -> Result<Vec<Column>> {
    let mut out = Vec::new();
    for (k, p) in parameters.iter().enumerate() {
        if p.independent {
            let keys = KeyPath::parse(&p.key)
                .and_then(|path| path.expand(base))
                .map_err(|e| Error::invalid(format!("parameters[{k}].key"), e.to_string()))?;
            out.extend(keys.into_iter().enumerate().map(|(e, key)| Column {
                key,
                parameter: k,
                element: Some(e),
            }));
        } else {
            out.push(Column {
                key: p.key.clone(),
                parameter: k,
                element: None,
            });
        }
    }
    Ok(out)
}
