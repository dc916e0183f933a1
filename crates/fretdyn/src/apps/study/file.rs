//! The study file (`docs/STUDIES.md`): its parameters (values, or a distribution to draw
//! from), how they combine, the seeds, the draws of a probabilistic study, `[percentiles]`
//! and `[plot]` — read, checked against the base case, and turned into each run's case.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::table::{self, TABLE_STATISTICS};
use crate::apps::sampling::{Distribution, Stream};
use crate::case::key_path::{KeyPath, KeyPathError, Missing, Part};
use crate::case::{check_case_text, named_file, parse_error};
use crate::error::{Error, Result};

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
        if value.get("base").is_none()
            && (value.get("structure").is_some() || value.get("structures").is_some())
        {
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
    pub(super) fn percentile_columns(&self, statistic: &str, header: &[&str]) -> Vec<String> {
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

    /// Names of the base case's contacts, as the case gives them (`contact<k>` when unnamed),
    /// read from the TOML: the header needs no model built. In a case of several structures,
    /// each structure's own first (`tube_a.plate1`), then the top-level ones, as the model
    /// orders them ([`crate::model::Model::union`]).
    pub fn contact_names(&self) -> Vec<String> {
        fn names(contacts: Option<&toml::Value>, prefix: &str) -> Vec<String> {
            match contacts {
                Some(toml::Value::Array(contacts)) => contacts
                    .iter()
                    .enumerate()
                    .map(|(k, c)| {
                        let name = c
                            .get("name")
                            .and_then(|n| n.as_str())
                            .map_or_else(|| format!("contact{k}"), String::from);
                        format!("{prefix}{name}")
                    })
                    .collect(),
                _ => Vec::new(),
            }
        }
        let mut out = Vec::new();
        if let Some(toml::Value::Array(structures)) = self.base.get("structures") {
            for s in structures {
                let name = s.get("name").and_then(|n| n.as_str()).unwrap_or_default();
                out.extend(names(s.get("contacts"), &format!("{name}.")));
            }
        }
        out.extend(names(self.base.get("contacts"), ""));
        out
    }

    /// The names of the base case's displacement monitors (`[[output.monitors]]`: its `name`,
    /// or its `point`).
    pub fn monitor_names(&self) -> Vec<String> {
        let monitors = self.base.get("output").and_then(|o| o.get("monitors"));
        let Some(toml::Value::Array(monitors)) = monitors else {
            return Vec::new();
        };
        monitors
            .iter()
            .map(|m| {
                let name = m.get("name").or_else(|| m.get("point"));
                name.and_then(|n| n.as_str())
                    .unwrap_or_default()
                    .to_string()
            })
            .collect()
    }

    /// Header of the table: run, each parameter column ([`Self::columns`]), `sample` (in a
    /// probabilistic study), seed, status, steps/s, then `<contact>.<statistic>` for every
    /// contact of the base case, `<monitor>.<column>` for every monitor, then
    /// [`CONNORS_COLUMN`].
    pub fn header(&self, contacts: &[String]) -> String {
        table::header(
            self.columns().into_iter().map(|c| c.key),
            self.sampling.is_some(),
            self.has_life(),
            contacts,
            &self.monitor_names(),
        )
    }

    /// Whether the base case has a `[life]` section: each run is then a service life
    /// ([`crate::apps::life`]) and its row has the [`LIFE_COLUMNS`].
    pub fn has_life(&self) -> bool {
        self.base.get("life").is_some()
    }
}

/// Sets `key` (a [`KeyPath`]: dotted, `*` for every element of an array, numbers or `[i]` for
/// one element) in a TOML value; the path must exist.
pub(super) fn set_path(
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
