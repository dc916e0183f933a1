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
use std::sync::atomic::{AtomicBool, Ordering};

use serde::Deserialize;

use super::percentiles::{PercentileReport, PercentileRequest, percentiles_of_table};
use super::sampling::{Distribution, Stream};
use crate::case::fingerprint::{FileHashes, Fingerprint, canonical, differences};
use crate::case::key_path::{KeyPath, KeyPathError, Missing, Part};
use crate::case::{Case, check_case_text, named_file, parse_error};
use crate::error::{Error, Result};
use crate::files::Lock;
use crate::integrator::simulation::{RunResults, Simulation, Termination};
pub use crate::integrator::simulation::{statistics_run, statistics_run_until};

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

/// Most bootstrap resamples of `[percentiles]` (each sorts the samples of every group and
/// column once).
pub const MAX_BOOTSTRAP: i64 = 100_000;

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

/// Statistics written per contact in the table, as `<contact>.<statistic>`: those of the
/// table of statistics marked for `study.csv`.
pub const TABLE_STATISTICS: [&str; crate::accumulate::statistics::STUDY] =
    crate::accumulate::statistics::STUDY_STATISTICS;

/// The statistics of [`TABLE_STATISTICS`] with a standard error by batch means, written
/// as `<contact>.<statistic>_se` after a contact's statistics (empty with fewer than 2
/// batches).
pub fn table_errors() -> impl Iterator<Item = &'static str> {
    TABLE_STATISTICS
        .into_iter()
        .filter(|s| crate::accumulate::statistics::BATCHED_STATISTICS.contains(s))
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
                let base_path = named_file(dir, name, "base", "the study file")?;
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
    /// study asks for none. The table must hold every run of the study, each from the inputs
    /// the study gives it now ([`Self::check_table_complete`]): an incomplete or stale table is
    /// refused.
    pub fn percentiles(&self, table: &Path) -> Result<Option<PercentileReport>> {
        let Some(spec) = &self.percentiles else {
            return Ok(None);
        };
        self.check_table_complete(table)?;
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

    /// The case of one run, as TOML: the base case with the run's values and seed set.
    pub fn case_value(&self, run: &RunSpec) -> Result<toml::Value> {
        let mut value = self.base.clone();
        for (c, v) in self.columns().iter().zip(&run.values) {
            set_path(&mut value, &c.key, v)
                .map_err(|e| Error::invalid(c.key.clone(), e.to_string()))?;
        }
        if let Some(seed) = run.seed
            && let Some(toml::Value::Array(loads)) = value.get_mut("turbulence")
        {
            for l in loads {
                if let Some(t) = l.as_table_mut() {
                    t.insert("seed".into(), toml::Value::Integer(seed as i64));
                }
            }
        }
        Ok(value)
    }

    /// The fingerprint of one run ([`Fingerprint`]: its case as resolved and the content of
    /// every file it reads), as its row writes it in [`FINGERPRINT_COLUMN`].
    pub fn fingerprint(&self, run: &RunSpec) -> Result<String> {
        Ok(Fingerprint::of(&self.case_value(run)?, &self.base_dir).text())
    }

    /// The fingerprint of every run, in order, each file read once.
    fn fingerprints(&self, runs: &[RunSpec]) -> Result<Vec<String>> {
        let mut cache = FileHashes::default();
        runs.iter()
            .map(|r| {
                let value = self.case_value(r)?;
                Ok(Fingerprint::of_cached(&value, &self.base_dir, &mut cache).text())
            })
            .collect()
    }

    /// The case of one run.
    pub fn case(&self, run: &RunSpec) -> Result<Case> {
        let value = self.case_value(run)?;
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
        cols.push(FINGERPRINT_COLUMN.to_string());
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
                            super::check_names_for_tables(&case.model, "a study")?;
                            // and a service life, what it checks before its first window
                            if let Some(life) = &case.life {
                                super::life::check_life(&case, life)?;
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

    /// Runs one run and formats its row. Only the statistics are kept
    /// ([`run_statistics`]): memory does not grow with the length of the run.
    pub fn run_row(&self, run: &RunSpec) -> Result<String> {
        self.run_row_until(run, None)
            .map(|row| row.expect("a run without a stop signal runs to its end"))
    }

    /// [`Self::run_row`], stopped at the next batch of steps (or life step) once `stop` is
    /// set: `None` then (a stopped run has no row).
    pub fn run_row_until(
        &self,
        run: &RunSpec,
        stop: Option<&AtomicBool>,
    ) -> Result<Option<String>> {
        let fingerprint = self.fingerprint(run)?;
        let case = self.case(run)?;
        let r = statistics_run_until(&case.model, &case.settings, None, stop)?.0;
        if matches!(r.termination, Termination::Stopped { .. }) {
            return Ok(None);
        }
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
            match life_row(&case, life, stop)? {
                Some(life) => cols.extend(life),
                None => return Ok(None),
            }
        }
        cols.push(
            case.stability()
                .and_then(|report| report.max_ratio())
                .map(|x| x.to_string())
                .unwrap_or_default(),
        );
        cols.push(fingerprint);
        Ok(Some(cols.join(",")))
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

/// Column of the study table that ties each row to the inputs it was computed from: the
/// fingerprint of its run's case as resolved and of the files it reads
/// ([`Fingerprint::text`]). A row is reused only when it is the fingerprint the study gives
/// its run now.
pub const FINGERPRINT_COLUMN: &str = "fingerprint";

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

/// The life columns of one run: how it ended, then [`LIFE_COLUMNS`] per contact; `None`
/// when `stop` stopped it.
fn life_row(
    case: &Case,
    life: &crate::apps::life::LifeSettings,
    stop: Option<&AtomicBool>,
) -> Result<Option<Vec<String>>> {
    use crate::apps::life::{LifeControl, LifeEnd, YEAR, service_life_with};
    let mut control = LifeControl {
        stop,
        ..LifeControl::default()
    };
    let r = service_life_with(case, life, &mut control, |_| {})?;
    if matches!(r.end, LifeEnd::Stopped { .. }) {
        return Ok(None);
    }
    let mut cols = vec![r.end.name().to_string()];
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
    Ok(Some(cols))
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

fn csv_value(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.replace(',', "_"),
        other => other.to_string(),
    }
}

/// A complete row of a study table: its run, its parameter cells and its fingerprint.
#[derive(Debug)]
struct TableRow {
    index: usize,
    values: Vec<String>,
    fingerprint: String,
}

/// The complete rows of the table at `table` (none when it is missing or empty; a last line
/// without its end of line is cut, not complete); checks its header.
fn read_rows(table: &Path, header: &str) -> Result<Vec<TableRow>> {
    let Ok(text) = std::fs::read_to_string(table) else {
        return Ok(Vec::new());
    };
    let mut lines = text.lines();
    match lines.next() {
        None => return Ok(Vec::new()),
        Some(h) if h == header => {}
        Some(h) => {
            let why = if h.split(',').all(|c| c != FINGERPRINT_COLUMN) {
                "it was written without the fingerprints of its runs' inputs (by fretdyn before 0.1.0 of 2026-11-28), so its rows cannot be tied to this study"
            } else {
                "its columns are those of another study"
            };
            return Err(Error::invalid(
                "table",
                format!(
                    "{} has another header: {why}; start afresh with --fresh (Python: fresh=True; the table is replaced), or write to another table (-o DIR)",
                    table.display()
                ),
            ));
        }
    }
    let columns = header.split(',').count();
    let parameters = header
        .split(',')
        .position(|c| c == "seed")
        .map_or(0, |seed| seed.saturating_sub(1));
    let complete = if text.ends_with('\n') {
        text.lines().count()
    } else {
        text.lines().count().saturating_sub(1)
    };
    Ok(lines
        .take(complete.saturating_sub(1))
        .filter_map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            if cells.len() != columns {
                return None;
            }
            Some(TableRow {
                index: cells[0].parse().ok()?,
                values: cells[1..1 + parameters]
                    .iter()
                    .map(|c| c.to_string())
                    .collect(),
                fingerprint: cells[columns - 1].to_string(),
            })
        })
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
        Some(b) if (2..=MAX_BOOTSTRAP).contains(&b) => b as usize,
        Some(b) => {
            return Err(Error::invalid(
                "percentiles.bootstrap",
                format!(
                    "must be between 2 and {MAX_BOOTSTRAP} resamples (1000 is usual: the standard error's own error falls as 1/√(2B), 2 % at 1000), got {b}"
                ),
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
