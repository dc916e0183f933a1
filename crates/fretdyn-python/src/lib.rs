//! The native part of the Python package `fretdyn` (module `fretdyn._native`): cases from a
//! TOML file, TOML text or JSON (Python dicts), runs with the GIL released and Ctrl-C honoured,
//! results as numpy arrays, the Connors stability check of a case with flow zones, and the
//! rows of studies for local or Dask execution. The
//! Python-facing API is `python/fretdyn/__init__.py`.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::PyDict;

mod dict_case;
use dict_case::Document;

pyo3::create_exception!(
    _native,
    FretdynError,
    pyo3::exceptions::PyValueError,
    "Bad input or a failed run; the message names the file, the field and the fix, as the CLI's."
);

fn err(e: fretdyn::Error) -> PyErr {
    FretdynError::new_err(e.to_string())
}

/// A case: model and settings, ready to run.
#[pyclass(module = "fretdyn._native", frozen)]
struct Case {
    inner: fretdyn::case::Case,
}

#[pymethods]
impl Case {
    /// Title of the case.
    #[getter]
    fn title(&self) -> String {
        self.inner.title.clone()
    }

    /// Time step, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.settings.dt
    }

    /// Number of steps.
    #[getter]
    fn steps(&self) -> u64 {
        self.inner.settings.steps
    }

    /// Number of modes of the basis.
    #[getter]
    fn modes(&self) -> usize {
        self.inner.model.basis.modes()
    }

    /// Names of the contacts, in the order of the results' contact axis.
    #[getter]
    fn contact_names(&self) -> Vec<String> {
        self.inner
            .model
            .contacts
            .iter()
            .map(|c| c.name.clone())
            .collect()
    }

    /// Natural frequencies of the basis, Hz.
    #[getter]
    fn frequencies_hz(&self) -> Vec<f64> {
        self.inner
            .model
            .basis
            .omega
            .iter()
            .map(|w| w / std::f64::consts::TAU)
            .collect()
    }

    fn __repr__(&self) -> String {
        format!(
            "Case({:?}, {} modes, {} contacts, {} steps of {:e} s)",
            self.inner.title,
            self.modes(),
            self.inner.model.contacts.len(),
            self.steps(),
            self.dt()
        )
    }
}

/// Reads a case file.
#[pyfunction]
fn load_case(path: PathBuf) -> PyResult<Case> {
    fretdyn::case::Case::from_file(&path)
        .map(|inner| Case { inner })
        .map_err(|e| FretdynError::new_err(e.in_file(&path)))
}

/// A case from TOML text; relative file names are resolved from `base_dir`.
#[pyfunction]
#[pyo3(signature = (text, base_dir = PathBuf::from(".")))]
fn case_from_toml(text: &str, base_dir: PathBuf) -> PyResult<Case> {
    fretdyn::case::Case::from_toml_str(text, &base_dir)
        .map(|inner| Case { inner })
        .map_err(err)
}

/// A case from JSON text with the structure of a case file (how Python dicts come in). It is
/// read by the case file's parser, through TOML text whose lines are mapped back to the keys
/// of the dict: errors name the key path (`time.dt`, `contacts[0].normal.stiffness`).
#[pyfunction]
#[pyo3(signature = (json, base_dir = PathBuf::from(".")))]
fn case_from_json(json: &str, base_dir: PathBuf) -> PyResult<Case> {
    let value: serde_json::Value = serde_json::from_str(json)
        .map_err(|e| FretdynError::new_err(format!("the case is not valid JSON: {e}")))?;
    let serde_json::Value::Object(root) = value else {
        return Err(FretdynError::new_err(
            "a case is a dict with the keys of a case file (time, structure, contacts, …)",
        ));
    };
    let doc = Document::from_json(&root).map_err(FretdynError::new_err)?;
    fretdyn::case::Case::from_toml_str(&doc.text, &base_dir)
        .map(|inner| Case { inner })
        .map_err(|e| match e {
            fretdyn::Error::Parse { line, message, .. } => {
                FretdynError::new_err(match doc.path_at(line, &message) {
                    Some(path) => format!("{path}: {message}"),
                    None => message,
                })
            }
            other => err(other),
        })
}

/// Runs a case with the GIL released; Ctrl-C stops it (KeyboardInterrupt). Returns a dict of
/// numpy arrays (the keys of `results.npz`) and `summary_json`, the text of `summary.json`.
/// A run whose time histories do not fit in memory twice (the run's, then numpy's copy) is
/// refused before it starts (FretdynError naming `output.every`), not left to abort the
/// interpreter.
#[pyfunction]
fn run<'py>(py: Python<'py>, case: &Case) -> PyResult<Bound<'py, PyDict>> {
    let c = &case.inner;
    let s = &c.settings;
    let samples = (s.steps / s.output_every.max(1)).saturating_add(1);
    fretdyn::results::recorder::Recorder::check_memory(
        samples,
        c.model.basis.modes(),
        c.model.contacts.len(),
        2,
    )
    .map_err(err)?;
    let mut interrupted = None;
    let results = py
        .detach(|| {
            fretdyn::integrator::simulation::run(&c.model, &c.settings, |_| {
                // back in the interpreter for a moment, every 1024 steps, for Ctrl-C
                match Python::attach(|py| py.check_signals()) {
                    Ok(()) => ControlFlow::Continue(()),
                    Err(e) => {
                        interrupted = Some(e);
                        ControlFlow::Break(())
                    }
                }
            })
        })
        .map_err(err)?;
    if let Some(e) = interrupted {
        return Err(e);
    }
    let out = PyDict::new(py);
    let r = &results.recorder;
    let f64_arrays: [(&str, Vec<f64>, Vec<usize>); 8] = [
        ("t", r.t.to_vec(), r.t.shape().to_vec()),
        ("q", r.q.iter().copied().collect(), r.q.shape().to_vec()),
        (
            "qdot",
            r.qdot.iter().copied().collect(),
            r.qdot.shape().to_vec(),
        ),
        (
            "contact_normal_force",
            r.normal_force.iter().copied().collect(),
            r.normal_force.shape().to_vec(),
        ),
        (
            "contact_tangential_force",
            r.tangential_force.iter().copied().collect(),
            r.tangential_force.shape().to_vec(),
        ),
        (
            "contact_slip_velocity",
            r.slip_velocity.iter().copied().collect(),
            r.slip_velocity.shape().to_vec(),
        ),
        (
            "contact_penetration",
            r.penetration.iter().copied().collect(),
            r.penetration.shape().to_vec(),
        ),
        (
            "contact_position",
            r.position.iter().copied().collect(),
            r.position.shape().to_vec(),
        ),
    ];
    for (key, data, shape) in f64_arrays {
        out.set_item(key, PyArray1::from_vec(py, data).reshape(shape)?)?;
    }
    let status: Vec<i8> = r.status.iter().copied().collect();
    out.set_item(
        "contact_status",
        PyArray1::from_vec(py, status).reshape(r.status.shape().to_vec())?,
    )?;
    let summary = fretdyn::results::output::summary(c, &results);
    out.set_item("summary_json", summary.to_string())?;
    if matches!(
        results.termination,
        fretdyn::integrator::simulation::Termination::Stopped { .. }
    ) {
        return Err(PyKeyboardInterrupt::new_err("the run was interrupted"));
    }
    Ok(out)
}

/// The Connors fluid-elastic stability check of every mode of a case with a `[flow]` section
/// (docs/FLOW.md; `fretdyn stability`): a dict of numpy arrays, one per column of
/// `stability.csv` (`mode`, `frequency_hz`, `damping_ratio`, `reference_density`,
/// `effective_velocity`, `critical_velocity`, `ratio`: NaN where undefined, inf for an
/// undamped mode in a flow), `reference_zone` (list of str) and the scalars
/// `connors_constant`, `diameter`, `mass_per_length`. A case without `[flow]` is a
/// FretdynError with the CLI's message.
#[pyfunction]
fn stability<'py>(py: Python<'py>, case: &Case) -> PyResult<Bound<'py, PyDict>> {
    let Some(report) = case.inner.stability() else {
        return Err(FretdynError::new_err(
            "flow: the case has no [flow] section: add one with its [[flow.zones]] (docs/FLOW.md)",
        ));
    };
    let out = PyDict::new(py);
    let modes = &report.modes;
    let mode: Vec<i64> = modes.iter().map(|m| m.mode as i64).collect();
    out.set_item("mode", PyArray1::from_vec(py, mode))?;
    type Column = fn(&fretdyn::loads::flow::ModeStability) -> f64;
    let columns: [(&str, Column); 6] = [
        ("frequency_hz", |m| m.frequency_hz),
        ("damping_ratio", |m| m.damping_ratio),
        ("reference_density", |m| m.reference_density),
        ("effective_velocity", |m| m.effective_velocity),
        ("critical_velocity", |m| m.critical_velocity),
        ("ratio", |m| m.ratio.unwrap_or(f64::NAN)),
    ];
    for (key, value) in columns {
        out.set_item(
            key,
            PyArray1::from_vec(py, modes.iter().map(value).collect()),
        )?;
    }
    let zones: Vec<String> = modes.iter().map(|m| m.reference_zone.clone()).collect();
    out.set_item("reference_zone", zones)?;
    out.set_item("connors_constant", report.connors_constant)?;
    out.set_item("diameter", report.diameter)?;
    out.set_item("mass_per_length", report.mass_per_length)?;
    Ok(out)
}

fn study(path: &Path) -> PyResult<fretdyn::apps::study::Study> {
    fretdyn::apps::study::Study::from_file(path).map_err(|e| FretdynError::new_err(e.in_file(path)))
}

/// Number of runs of a study.
#[pyfunction]
fn study_runs(path: PathBuf) -> PyResult<usize> {
    Ok(study(&path)?.runs().len())
}

/// Header line of a study's table.
#[pyfunction]
fn study_header(path: PathBuf) -> PyResult<String> {
    let s = study(&path)?;
    Ok(s.header(&s.contact_names()))
}

/// Runs run `index` of a study (GIL released) and returns its table row.
#[pyfunction]
fn study_row(py: Python<'_>, path: PathBuf, index: usize) -> PyResult<String> {
    let s = study(&path)?;
    let runs = s.runs();
    let run = runs
        .get(index)
        .ok_or_else(|| FretdynError::new_err(format!("the study has {} runs", runs.len())))?;
    py.detach(|| s.run_row(run)).map_err(err)
}

/// Runs a study on this machine, `jobs` runs at a time (0: one per core), into the table
/// `table` (finished runs already in it are skipped); returns the number of runs done.
#[pyfunction]
#[pyo3(signature = (path, table, jobs = 0))]
fn study_local(py: Python<'_>, path: PathBuf, table: PathBuf, jobs: usize) -> PyResult<usize> {
    let s = study(&path)?;
    py.detach(|| s.execute(&table, jobs, &|_, _| {}))
        .map_err(err)
}

/// The percentiles of a study's `[percentiles]` (or its defaults for a probabilistic study)
/// from its table, as the JSON of `percentiles.json`; written into `output` (a folder) too
/// when given. `None` when the study asks for no percentiles.
#[pyfunction]
#[pyo3(signature = (path, table, output = None))]
fn study_percentiles(
    py: Python<'_>,
    path: PathBuf,
    table: PathBuf,
    output: Option<PathBuf>,
) -> PyResult<Option<String>> {
    let s = study(&path)?;
    let report = py
        .detach(|| s.percentiles(&table))
        .map_err(|e| FretdynError::new_err(e.in_file(&path)))?;
    if let (Some(r), Some(dir)) = (&report, &output) {
        r.write(dir).map_err(err)?;
    }
    Ok(report.map(|r| r.to_json()))
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("FretdynError", m.py().get_type::<FretdynError>())?;
    m.add_class::<Case>()?;
    m.add_function(wrap_pyfunction!(load_case, m)?)?;
    m.add_function(wrap_pyfunction!(case_from_toml, m)?)?;
    m.add_function(wrap_pyfunction!(case_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(stability, m)?)?;
    m.add_function(wrap_pyfunction!(study_runs, m)?)?;
    m.add_function(wrap_pyfunction!(study_header, m)?)?;
    m.add_function(wrap_pyfunction!(study_row, m)?)?;
    m.add_function(wrap_pyfunction!(study_local, m)?)?;
    m.add_function(wrap_pyfunction!(study_percentiles, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
