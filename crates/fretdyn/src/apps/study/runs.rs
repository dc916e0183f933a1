//! The runs of a study: the list (every combination × sample × seed, in a stable order),
//! each run's case (the base case with its values and seed) and the fingerprint of its inputs,
//! and one run run to its row of the table.

use std::sync::atomic::AtomicBool;

use super::file::{Combine, Parameter, Study, set_path};
use super::table::{LIFE_COLUMNS, csv_value, row};
use crate::case::fingerprint::{FileHashes, Fingerprint};
use crate::case::{Case, check_case_text};
use crate::error::{Error, Result};
use crate::integrator::simulation::{
    RunResults, Termination, statistics_run, statistics_run_until,
};

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

impl Study {
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
        if let Some(seed) = run.seed {
            set_seeds(value.get_mut("turbulence"), seed);
            // each structure of several its own seeds (independent turbulence), as the case's
            // default seeds are (`case::loads::default_seed`)
            if let Some(toml::Value::Array(structures)) = value.get_mut("structures") {
                for (i, s) in structures.iter_mut().enumerate() {
                    set_seeds(s.get_mut("turbulence"), seed.wrapping_add(1000 * i as u64));
                }
            }
        }
        Ok(value)
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

    /// The fingerprint of one run ([`Fingerprint`]: its case as resolved and the content of
    /// every file it reads), as its row writes it in [`FINGERPRINT_COLUMN`].
    pub fn fingerprint(&self, run: &RunSpec) -> Result<String> {
        Ok(Fingerprint::of(&self.case_value(run)?, &self.base_dir).text())
    }

    /// The fingerprint of every run, in order, each file read once.
    pub(super) fn fingerprints(&self, runs: &[RunSpec]) -> Result<Vec<String>> {
        let mut cache = FileHashes::default();
        runs.iter()
            .map(|r| {
                let value = self.case_value(r)?;
                Ok(Fingerprint::of_cached(&value, &self.base_dir, &mut cache).text())
            })
            .collect()
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
        let life = match &case.life {
            Some(life) => match life_row(&case, life, stop)? {
                Some(cells) => Some(cells),
                None => return Ok(None),
            },
            None => None,
        };
        let connors = case.stability().and_then(|report| report.max_ratio());
        let mut cells = vec![run.index.to_string()];
        cells.extend(run.values.iter().map(csv_value));
        if self.sampling.is_some() {
            cells.push(run.sample.map(|s| s.to_string()).unwrap_or_default());
        }
        cells.push(run.seed.map(|s| s.to_string()).unwrap_or_default());
        Ok(Some(row(cells, &r, life, connors, fingerprint)))
    }
}

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

/// Runs `case` for its statistics (THEORY §5) only: neither the time histories (a recorder of
/// one sample, emptied when full) nor the list of impacts and blocks are kept, so that memory
/// does not grow with the run's length. The statistics are those of
/// [`crate::integrator::simulation::simulate`] (running sums, which do not depend on what is recorded).
pub fn run_statistics(case: &Case) -> Result<RunResults> {
    statistics_run(&case.model, &case.settings, None).map(|(results, _)| results)
}

/// Sets `seed` in every `[[turbulence]]` entry of `loads`.
fn set_seeds(loads: Option<&mut toml::Value>, seed: u64) {
    if let Some(toml::Value::Array(loads)) = loads {
        for l in loads {
            if let Some(t) = l.as_table_mut() {
                t.insert("seed".into(), toml::Value::Integer(seed as i64));
            }
        }
    }
}
