//! The native part of the Python package `fretdyn` (module `fretdyn._native`): cases from a
//! TOML file, TOML text or JSON (Python dicts), changed by key paths and given back as JSON,
//! runs with the GIL released and Ctrl-C honoured, results as numpy arrays with their impacts
//! and blocks, the names, dimensions and units of the results, the Connors stability check of
//! a case with flow zones, and the rows of studies (from a file or a dict) for local or Dask
//! execution. The Python-facing API is `python/fretdyn/__init__.py`.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

mod apps;
mod dict_case;
use dict_case::Document;

pyo3::create_exception!(
    fretdyn,
    FretdynError,
    pyo3::exceptions::PyValueError,
    "Bad input or a failed run; the message names the file, the field and the fix, as the CLI's."
);

fn err(e: fretdyn::Error) -> PyErr {
    FretdynError::new_err(e.to_string())
}

/// A case: model and settings, ready to run, and the folder its file names are relative to.
#[pyclass(module = "fretdyn._native", frozen)]
struct Case {
    inner: fretdyn::Case,
    base_dir: PathBuf,
}

/// `dir` made absolute (from the current folder), so that a case reads the same files
/// whatever folder it is run from later.
fn absolute(dir: &Path) -> PathBuf {
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf())
}

impl Case {
    /// The name of the point `point` gives of each contact (empty for none).
    fn contact_point_names(
        &self,
        point: impl Fn(&fretdyn::contact::Contact) -> Option<usize>,
    ) -> Vec<String> {
        let points = &self.inner.model.basis.points;
        let contacts = &self.inner.model.contacts;
        contacts
            .iter()
            .map(|c| {
                point(c)
                    .and_then(|i| points.get(i))
                    .map_or_else(String::new, |p| p.name.clone())
            })
            .collect()
    }
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

    /// Names of the structure points of the contacts, in the order of the contacts.
    #[getter]
    fn contact_points(&self) -> Vec<String> {
        self.contact_point_names(|c| Some(c.point))
    }

    /// Point B of each two-body contact (THEORY §15), empty for a contact with an obstacle,
    /// in the order of the contacts.
    #[getter]
    fn contact_other_points(&self) -> Vec<String> {
        self.contact_point_names(fretdyn::contact::Contact::other)
    }

    /// Names of the structures of a model of several (empty for a model of one).
    #[getter]
    fn structures(&self) -> Vec<String> {
        let model = &self.inner.model;
        model.structures.iter().map(|s| s.name.clone()).collect()
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

    /// Folder the case's relative file names are resolved from (absolute).
    #[getter]
    fn base_dir(&self) -> PathBuf {
        self.base_dir.clone()
    }

    /// The case as JSON with the structure of a case file (its TOML as read, or as changed by
    /// `case_with`), the title included, file names made absolute.
    fn to_json(&self) -> String {
        let mut value = self.inner.echo.clone();
        fretdyn::case::absolute_file_names(&mut value, &self.base_dir);
        if let (serde_json::Value::Object(map), false) = (&mut value, self.inner.title.is_empty()) {
            map.entry("title")
                .or_insert_with(|| serde_json::Value::String(self.inner.title.clone()));
        }
        value.to_string()
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
    fretdyn::Case::from_file(&path)
        .map(|inner| Case {
            inner,
            base_dir: absolute(path.parent().unwrap_or(Path::new("."))),
        })
        .map_err(|e| FretdynError::new_err(e.in_file(&path)))
}

/// A case from TOML text; relative file names are resolved from `base_dir`.
#[pyfunction]
#[pyo3(signature = (text, base_dir = PathBuf::from(".")))]
fn case_from_toml(text: &str, base_dir: PathBuf) -> PyResult<Case> {
    fretdyn::Case::from_toml_str(text, &base_dir)
        .map(|inner| Case {
            inner,
            base_dir: absolute(&base_dir),
        })
        .map_err(err)
}

/// The JSON object of a case or a study given as a Python dict.
fn json_object(json: &str, what: &str) -> PyResult<serde_json::Map<String, serde_json::Value>> {
    let value: serde_json::Value = serde_json::from_str(json)
        .map_err(|e| FretdynError::new_err(format!("the {what} is not valid JSON: {e}")))?;
    match value {
        serde_json::Value::Object(root) => Ok(root),
        _ => Err(FretdynError::new_err(format!(
            "a {what} is a dict with the keys of a {what} file"
        ))),
    }
}

/// An error of the parser of the TOML text `doc` was written to, named by the key path of
/// the dict (the other errors name their field already).
fn dict_error(doc: &Document, e: fretdyn::Error) -> PyErr {
    let (path, message) = dict_error_at(doc, e);
    FretdynError::new_err(match path {
        Some(path) => format!("{path}: {message}"),
        None => message,
    })
}

/// The key path of the dict an error of the case read from `doc` is at (a parse error's,
/// found from its line; a check's field), and the rest of its message; no path for an error
/// at none.
fn dict_error_at(doc: &Document, e: fretdyn::Error) -> (Option<String>, String) {
    match e {
        // the key as the case's TOML writes it is the dict's key path
        fretdyn::Error::Parse {
            key: Some(key),
            message,
            ..
        } => (Some(key), message),
        fretdyn::Error::Parse { line, message, .. } => (doc.path_at(line, &message), message),
        fretdyn::Error::Invalid { field, message } => (Some(field), message),
        other => (None, other.to_string()),
    }
}

/// The case of a dict with the structure of a case file; an error is the key path it is at
/// (if any) and the rest of its message.
fn case_from_map_at(
    root: &serde_json::Map<String, serde_json::Value>,
    base_dir: &Path,
) -> Result<Case, (Option<String>, String)> {
    let doc = Document::from_json(root).map_err(|e| (None, e))?;
    fretdyn::Case::from_toml_str(&doc.text, base_dir)
        .map(|inner| Case {
            inner,
            base_dir: absolute(base_dir),
        })
        .map_err(|e| dict_error_at(&doc, e))
}

/// The case of a dict with the structure of a case file.
fn case_from_map(
    root: &serde_json::Map<String, serde_json::Value>,
    base_dir: &Path,
) -> PyResult<Case> {
    case_from_map_at(root, base_dir).map_err(|(path, message)| {
        FretdynError::new_err(match path {
            Some(path) => format!("{path}: {message}"),
            None => message,
        })
    })
}

/// Whether a part of a key path given to `case_with` (`*` for any element) stands for a part
/// of the path an error is at.
fn same_part(given: &fretdyn::case::key_path::Part, at: &fretdyn::case::key_path::Part) -> bool {
    use fretdyn::case::key_path::Part;
    match (given, at) {
        (Part::Every, Part::Index(_) | Part::Every) => true,
        (Part::Index(i), Part::Key(k)) | (Part::Key(k), Part::Index(i)) => *k == i.to_string(),
        _ => given == at,
    }
}

/// The message of an error of `case_with` at the key path `at` (in the notation of the dict,
/// `contacts[1]`), named by the key path the user gave for it, exactly as given: the last of
/// `changes` whose path goes through `at` (`at` is that path, or a part of it, or one element
/// of its `*`). `contacts.1.obstacle.gap: no such element; …` when `at` is the key path given
/// in another notation; `tim.dt: tim: unknown field …` when it is a part of it. An error
/// below a key path given (in the value set there) or at none keeps its path.
fn named_by_change(
    changes: &[(&str, fretdyn::case::key_path::KeyPath)],
    at: Option<&str>,
    message: &str,
) -> String {
    use fretdyn::case::key_path::{KeyPath, abbreviated};
    let Some(at) = at else {
        return message.to_string();
    };
    let plain = format!("{}: {message}", abbreviated(at));
    let Ok(path) = KeyPath::parse(at) else {
        return plain;
    };
    let given = changes.iter().rev().find(|(_, key)| {
        path.parts.len() <= key.parts.len()
            && key
                .parts
                .iter()
                .zip(&path.parts)
                .all(|(g, a)| same_part(g, a))
    });
    match given {
        Some((text, _)) if *text == at => plain,
        Some((text, key))
            if key.parts.len() == path.parts.len()
                && !key.parts.contains(&fretdyn::case::key_path::Part::Every) =>
        {
            format!("{}: {message}", abbreviated(text))
        }
        Some((text, _)) => format!("{}: {}: {message}", abbreviated(text), abbreviated(at)),
        None => plain,
    }
}

/// A case from JSON text with the structure of a case file (how Python dicts come in). It is
/// read by the case file's parser, through TOML text whose lines are mapped back to the keys
/// of the dict: errors name the key path (`time.dt`, `contacts[0].normal.stiffness`).
#[pyfunction]
#[pyo3(signature = (json, base_dir = PathBuf::from(".")))]
fn case_from_json(json: &str, base_dir: PathBuf) -> PyResult<Case> {
    case_from_map(&json_object(json, "case")?, &base_dir)
}

/// A new case: `case` with the values of `changes`, JSON `[[key path, value], …]` applied in
/// order. A key path is that of a study parameter (`fretdyn::case::key_path`:
/// `contacts[0].obstacle.clearance`, `contacts.*.friction.mu`; at most
/// `key_path::MAX_PARTS` parts); missing keys of tables are added, then the case's parser
/// checks them. Errors start with the key path exactly as given (its start and its length
/// when it is long), then where it fails when that is a part of it
/// (`contacts[1].obstacle.gap: contacts[1]: no such element; …`).
#[pyfunction]
fn case_with(case: &Case, changes: &str) -> PyResult<Case> {
    use fretdyn::case::key_path::{KeyPath, Missing, abbreviated};
    let changes: Vec<(String, serde_json::Value)> = serde_json::from_str(changes)
        .map_err(|e| FretdynError::new_err(format!("the changes are not valid JSON: {e}")))?;
    let mut value: toml::Value = toml::Value::try_from(&case.inner.echo)
        .map_err(|e| FretdynError::new_err(format!("the case cannot be changed: {e}")))?;
    let mut paths = Vec::with_capacity(changes.len());
    for (key, new) in &changes {
        let shown = abbreviated(key);
        let new = match new {
            serde_json::Value::Null => {
                return Err(FretdynError::new_err(format!(
                    "{shown}: None is not a value of a case (leave the key out)"
                )));
            }
            v => toml::Value::try_from(v)
                .map_err(|e| FretdynError::new_err(format!("{shown}: {e}")))?,
        };
        // a text that is no key path, or too deep, names itself
        let path = KeyPath::parse(key).map_err(|e| FretdynError::new_err(e.to_string()))?;
        path.set(&mut value, &new, Missing::Create).map_err(|e| {
            let message = e.to_string();
            let at = e.at().unwrap_or_default();
            let rest = message.strip_prefix(&format!("{}: ", abbreviated(at)));
            FretdynError::new_err(match rest {
                Some(rest) => named_by_change(&[(key.as_str(), path.clone())], Some(at), rest),
                None => message,
            })
        })?;
        paths.push((key.as_str(), path));
    }
    let json = serde_json::to_value(&value)
        .map_err(|e| FretdynError::new_err(format!("the case cannot be changed: {e}")))?;
    let serde_json::Value::Object(mut root) = json else {
        return Err(FretdynError::new_err("a case is a table"));
    };
    if !case.inner.title.is_empty() {
        root.entry("title")
            .or_insert_with(|| serde_json::Value::String(case.inner.title.clone()));
    }
    case_from_map_at(&root, &case.base_dir).map_err(|(at, message)| {
        FretdynError::new_err(named_by_change(&paths, at.as_deref(), &message))
    })
}

/// Runs a case with the GIL released; Ctrl-C stops it (KeyboardInterrupt). Returns a dict of
/// numpy arrays (the keys of `results.npz`), `summary_json`, the text of `summary.json`, and
/// `impacts` and `blocks`, the columns of `impacts.csv` and `blocks.csv` (dicts of numpy
/// arrays, in the files' order; `name` a list of str).
/// A run whose time histories do not fit in memory twice (the run's, then numpy's copy) is
/// refused before it starts (FretdynError naming `output.every`), not left to abort the
/// interpreter.
#[pyfunction]
fn run<'py>(py: Python<'py>, case: &Case) -> PyResult<Bound<'py, PyDict>> {
    let c = &case.inner;
    let s = &c.settings;
    let samples = (s.steps / s.output_every.max(1)).saturating_add(1);
    fretdyn::accumulate::recorder::Recorder::check_memory(
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
    let summary = fretdyn::output::summary::summary(c, &results);
    out.set_item("summary_json", summary.to_string())?;
    let names: Vec<String> = c.model.contacts.iter().map(|k| k.name.clone()).collect();
    out.set_item("impacts", impacts(py, &results.impacts, &names)?)?;
    out.set_item("blocks", blocks(py, &results.blocks, &names)?)?;
    if matches!(
        results.termination,
        fretdyn::integrator::simulation::Termination::Stopped { .. }
    ) {
        return Err(PyKeyboardInterrupt::new_err("the run was interrupted"));
    }
    Ok(out)
}

/// The columns of `impacts.csv` (`fretdyn::output::stream`) of `impacts`.
fn impacts<'py>(
    py: Python<'py>,
    impacts: &[fretdyn::accumulate::statistics::Impact],
    names: &[String],
) -> PyResult<Bound<'py, PyDict>> {
    use fretdyn::accumulate::statistics::Impact;
    let out = PyDict::new(py);
    let contact: Vec<i64> = impacts.iter().map(|i| i.contact as i64).collect();
    out.set_item("contact", PyArray1::from_vec(py, contact))?;
    let name: Vec<&str> = impacts
        .iter()
        .map(|i| names.get(i.contact).map_or("", String::as_str))
        .collect();
    out.set_item("name", name)?;
    type Column = fn(&Impact) -> f64;
    let columns: [(&str, Column); 8] = [
        ("start", |i| i.start),
        ("duration", |i| i.duration),
        ("contact_time", |i| i.contact_time),
        ("peak_time", |i| i.peak_time),
        ("peak_force", |i| i.peak_force),
        ("impulse", |i| i.impulse),
        ("impact_speed", |i| i.impact_speed),
        ("rebound_speed", |i| i.rebound_speed),
    ];
    for (key, value) in columns {
        out.set_item(
            key,
            PyArray1::from_vec(py, impacts.iter().map(value).collect()),
        )?;
    }
    let rebounds: Vec<i64> = impacts.iter().map(|i| i64::from(i.rebounds)).collect();
    out.set_item("rebounds", PyArray1::from_vec(py, rebounds))?;
    out.set_item(
        "angle_deg",
        PyArray1::from_vec(py, impacts.iter().map(|i| i.angle_deg).collect()),
    )?;
    Ok(out)
}

/// The columns of `blocks.csv` (`fretdyn::output::stream`) of `blocks`.
fn blocks<'py>(
    py: Python<'py>,
    blocks: &[fretdyn::accumulate::statistics::BlockStatistics],
    names: &[String],
) -> PyResult<Bound<'py, PyDict>> {
    use fretdyn::accumulate::statistics::{Kind, Value, block_columns};
    let out = PyDict::new(py);
    let block: Vec<i64> = blocks.iter().map(|b| b.block as i64).collect();
    out.set_item("block", PyArray1::from_vec(py, block))?;
    out.set_item(
        "t_start",
        PyArray1::from_vec(py, blocks.iter().map(|b| b.t_start).collect()),
    )?;
    out.set_item(
        "t_end",
        PyArray1::from_vec(py, blocks.iter().map(|b| b.t_end).collect()),
    )?;
    let name: Vec<&str> = blocks
        .iter()
        .map(|b| {
            names
                .get(b.contact)
                .map_or(b.statistics.name.as_str(), String::as_str)
        })
        .collect();
    out.set_item("name", name)?;
    for column in block_columns() {
        let values = blocks.iter().map(|b| (column.value)(&b.statistics));
        match column.kind {
            Kind::Count => {
                let counts = values
                    .map(|v| match v {
                        Value::Count(n) => n as i64,
                        Value::Real(x) => x as i64,
                    })
                    .collect();
                out.set_item(column.key, PyArray1::from_vec(py, counts))?;
            }
            Kind::Real => {
                let reals = values.map(Value::as_f64).collect();
                out.set_item(column.key, PyArray1::from_vec(py, reals))?;
            }
        }
    }
    Ok(out)
}

/// The one table of per-contact statistics (`fretdyn::accumulate::statistics::columns`,
/// from which `summary.json`, `contacts.csv`, `study.csv` and `blocks.csv` are derived): a
/// dict per statistic, in the order of `contacts.csv`, with `key`, `unit` (`1` for a number
/// without one), `long_name`, `meaning`, `code_aster` (empty when Code_Aster has none),
/// `count` (an integer), `se_key` (`<key>_se`, or None without a standard error by batch
/// means), `study` and `blocks` (a column of `study.csv`, of `blocks.csv`).
#[pyfunction]
fn statistics_columns(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    use fretdyn::accumulate::statistics::{Kind, STATISTICS};
    let out = PyList::empty(py);
    for s in STATISTICS {
        let d = PyDict::new(py);
        d.set_item("key", s.key)?;
        d.set_item("unit", s.unit)?;
        d.set_item("long_name", s.long_name)?;
        d.set_item("meaning", s.meaning)?;
        d.set_item("code_aster", s.code_aster)?;
        d.set_item("count", s.kind == Kind::Count)?;
        d.set_item("se_key", s.batched.map(|b| b.se_key))?;
        d.set_item("study", s.study)?;
        d.set_item("blocks", s.blocks)?;
        out.append(d)?;
    }
    Ok(out)
}

/// A variable of `fretdyn::output::variables` as a dict: `name`, `dims`, `units` (None for
/// names), `long_name`, `flag_meanings`.
fn variable_dict<'py>(
    py: Python<'py>,
    v: &fretdyn::output::variables::Variable,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", v.name)?;
    d.set_item("dims", v.dims.to_vec())?;
    d.set_item("units", v.units)?;
    d.set_item("long_name", v.long_name)?;
    d.set_item("flag_meanings", v.flag_meanings.to_vec())?;
    Ok(d)
}

/// The one table of names, dimensions, units and long names (`fretdyn::output::variables`,
/// which `results.nc` is written from): the time histories of a run of a modal model
/// (`modal`) or of one in physical coordinates, in the order of `results.npz`, each a dict
/// with `key` (of `results.npz`), `name`, `dims`, `units`, `long_name`, `flag_meanings` and
/// `coordinates` (its auxiliary coordinates, CF); and the coordinates besides `time` (the
/// same keys but `key` and `coordinates`), those of a model of several structures or with
/// two-body contacts last.
#[pyfunction]
#[pyo3(signature = (modal = true))]
fn variables<'py>(
    py: Python<'py>,
    modal: bool,
) -> PyResult<(Bound<'py, PyList>, Bound<'py, PyList>)> {
    use fretdyn::output::variables::{
        COORDINATES, NEIGHBOUR_COORDINATES, auxiliary_coordinates, time_histories,
    };
    let histories = PyList::empty(py);
    for h in time_histories(modal) {
        let d = variable_dict(py, &h.variable)?;
        d.set_item("key", h.key)?;
        d.set_item("coordinates", auxiliary_coordinates(h.variable.dims))?;
        histories.append(d)?;
    }
    let coordinates = PyList::empty(py);
    for c in COORDINATES.iter().chain(&NEIGHBOUR_COORDINATES) {
        coordinates.append(variable_dict(py, &c.variable)?)?;
    }
    Ok((histories, coordinates))
}

/// The values of the coordinates of a case's results besides `time` (`fretdyn::results::
/// variables::COORDINATES`, as `results.nc` has them): a dict name → numpy array (int32 mode
/// numbers, float64 numbers in the shape of their dimensions) or list of str (names), with
/// `structure`, `mode_structure`, `point_structure` and `contact_other_point` for a model
/// of several structures or with two-body contacts; and whether the case's model is modal
/// (else in physical coordinates).
#[pyfunction]
fn coordinates<'py>(py: Python<'py>, case: &Case) -> PyResult<(Bound<'py, PyDict>, bool)> {
    use fretdyn::output::variables::{Labels, Values};
    let labels = Labels::of(&case.inner.model);
    let out = PyDict::new(py);
    for c in &labels.coordinates() {
        let v = &c.variable;
        let shape: Vec<usize> = v
            .dims
            .iter()
            .map(|d| labels.dimension_len(d).unwrap_or(0))
            .collect();
        match labels.values(c.source) {
            Values::Text(names) => out.set_item(v.name, names)?,
            Values::Int(numbers) => {
                out.set_item(v.name, PyArray1::from_vec(py, numbers).reshape(shape)?)?
            }
            Values::Float(numbers) => {
                out.set_item(v.name, PyArray1::from_vec(py, numbers).reshape(shape)?)?
            }
        }
    }
    Ok((out, labels.modal()))
}

/// The Connors fluid-elastic stability check of every mode of a case with a `[flow]` section
/// (docs/FLOW.md; `fretdyn stability`): the basis's modes (condition `support_inactive`),
/// then those of each support condition of `[stability]`. A dict of numpy arrays, one per
/// column of `stability.csv` (`mode`, `frequency_hz`, `damping_ratio`, `reference_density`,
/// `effective_velocity`, `critical_velocity`, `ratio`: NaN where undefined, inf for an
/// undamped mode in a flow; `out_of_plane_share`: NaN when the structure has no plane),
/// `reference_zone`, `condition` and `plane` (`in_plane`, `out_of_plane`, `mixed`, or ""
/// without a plane) as lists of str, and the scalars `connors_constant`, `diameter`,
/// `mass_per_length`. A case without `[flow]` is a FretdynError with the CLI's message.
#[pyfunction]
fn stability<'py>(py: Python<'py>, case: &Case) -> PyResult<Bound<'py, PyDict>> {
    let Some(report) = case.inner.stability_checks() else {
        return Err(FretdynError::new_err(
            "flow: the case has no [flow] section: add one with its [[flow.zones]] (docs/FLOW.md)",
        ));
    };
    let report = report.map_err(err)?;
    let out = PyDict::new(py);
    let modes = &report.modes;
    let mode: Vec<i64> = modes.iter().map(|m| m.mode as i64).collect();
    out.set_item("mode", PyArray1::from_vec(py, mode))?;
    type Column = fn(&fretdyn::loads::flow::ModeStability) -> f64;
    let columns: [(&str, Column); 7] = [
        ("frequency_hz", |m| m.frequency_hz),
        ("damping_ratio", |m| m.damping_ratio),
        ("reference_density", |m| m.reference_density),
        ("effective_velocity", |m| m.effective_velocity),
        ("critical_velocity", |m| m.critical_velocity),
        ("ratio", |m| m.ratio.unwrap_or(f64::NAN)),
        ("out_of_plane_share", |m| {
            m.out_of_plane_share.unwrap_or(f64::NAN)
        }),
    ];
    for (key, value) in columns {
        out.set_item(
            key,
            PyArray1::from_vec(py, modes.iter().map(value).collect()),
        )?;
    }
    let zones: Vec<String> = modes.iter().map(|m| m.reference_zone.clone()).collect();
    out.set_item("reference_zone", zones)?;
    let conditions: Vec<String> = modes.iter().map(|m| m.condition.clone()).collect();
    out.set_item("condition", conditions)?;
    let planes: Vec<&str> = modes
        .iter()
        .map(|m| m.plane.map_or("", |p| p.name()))
        .collect();
    out.set_item("plane", planes)?;
    out.set_item("connors_constant", report.connors_constant)?;
    out.set_item("diameter", report.diameter)?;
    out.set_item("mass_per_length", report.mass_per_length)?;
    Ok(out)
}

/// Where a study comes from: the path of a study file, or `(json, base_dir)`, a dict with the
/// structure of a study file as JSON whose `base` is the path of a case file (relative to
/// `base_dir`) or a case as a dict (its file names relative to `base_dir`). A tuple of str
/// pickles: Dask sends it to the workers, which build the study again.
#[derive(FromPyObject)]
enum StudySource {
    File(PathBuf),
    Dict(String, PathBuf),
}

impl StudySource {
    /// An error about the study: a file's is prefixed by its name, as the CLI's.
    fn error(&self, e: fretdyn::Error) -> PyErr {
        match self {
            StudySource::File(path) => FretdynError::new_err(e.in_file(path)),
            StudySource::Dict(..) => err(e),
        }
    }

    fn study(&self) -> PyResult<fretdyn::Study> {
        use fretdyn::Study;
        match self {
            StudySource::File(path) => Study::from_file(path).map_err(|e| self.error(e)),
            StudySource::Dict(json, base_dir) => {
                let mut root = json_object(json, "study")?;
                let base = match root.get("base") {
                    Some(serde_json::Value::Object(_)) => {
                        let case = root.remove("base").unwrap_or_default();
                        let value = toml::Value::try_from(&case)
                            .map_err(|e| FretdynError::new_err(format!("base: {e}")))?;
                        Some((value, absolute(base_dir)))
                    }
                    _ => None,
                };
                let doc = Document::from_json(&root).map_err(FretdynError::new_err)?;
                Study::from_toml_str(&doc.text, base_dir, base).map_err(|e| dict_error(&doc, e))
            }
        }
    }
}

/// Number of runs of a study.
#[pyfunction]
fn study_runs(study: StudySource) -> PyResult<usize> {
    Ok(study.study()?.runs().len())
}

/// Header line of a study's table.
#[pyfunction]
fn study_header(study: StudySource) -> PyResult<String> {
    let s = study.study()?;
    Ok(s.header(&s.contact_names()))
}

/// Runs run `index` of a study (GIL released) and returns its table row.
#[pyfunction]
fn study_row(py: Python<'_>, study: StudySource, index: usize) -> PyResult<String> {
    let s = study.study()?;
    let runs = s.runs();
    let run = runs
        .get(index)
        .ok_or_else(|| FretdynError::new_err(format!("the study has {} runs", runs.len())))?;
    py.detach(|| s.run_row(run)).map_err(err)
}

/// Runs a study on this machine, `jobs` runs at a time (0: one per core), into the table
/// `table` (finished runs already in it are skipped, if they are of the study's inputs now:
/// a stale table is refused; `fresh` replaces it); returns the number of runs done.
#[pyfunction]
#[pyo3(signature = (study, table, jobs = 0, fresh = false))]
fn study_local(
    py: Python<'_>,
    study: StudySource,
    table: PathBuf,
    jobs: usize,
    fresh: bool,
) -> PyResult<usize> {
    let s = study.study()?;
    let options = fretdyn::apps::study::StudyOptions {
        jobs,
        fresh,
        stop: None,
    };
    py.detach(|| {
        s.check(jobs)?;
        s.run_checked(&table, &options, &|_, _| {})
    })
    .map(|outcome| outcome.done)
    .map_err(err)
}

/// The table of a study open for appending, locked while it is open (a second study on it
/// is refused): its rows are checked against the study's inputs when it is opened (a stale
/// table is refused; `fresh` replaces it), and each row appended is checked to be a pending
/// run's of the same inputs (a Dask worker with other files is refused).
#[pyclass(module = "fretdyn._native")]
struct StudyTable {
    inner: Option<fretdyn::apps::study::StudyTable>,
}

#[pymethods]
impl StudyTable {
    /// The runs without a row.
    fn pending(&self) -> PyResult<Vec<usize>> {
        Ok(self.open()?.pending())
    }

    /// Appends a row made by `study_row`.
    fn append(&mut self, row: &str) -> PyResult<()> {
        self.inner
            .as_mut()
            .ok_or_else(|| FretdynError::new_err("the study table is closed"))?
            .append(row)
            .map_err(err)
    }

    /// Lets the lock go.
    fn close(&mut self) {
        self.inner = None;
    }
}

impl StudyTable {
    fn open(&self) -> PyResult<&fretdyn::apps::study::StudyTable> {
        self.inner
            .as_ref()
            .ok_or_else(|| FretdynError::new_err("the study table is closed"))
    }
}

/// Opens (creates) the table `table` of a study for appending rows made elsewhere (Dask).
#[pyfunction]
#[pyo3(signature = (study, table, fresh = false))]
fn open_study_table(
    py: Python<'_>,
    study: StudySource,
    table: PathBuf,
    fresh: bool,
) -> PyResult<StudyTable> {
    let s = study.study()?;
    let t = py.detach(|| s.open_table(&table, fresh)).map_err(err)?;
    Ok(StudyTable { inner: Some(t) })
}

/// The percentiles of a study's `[percentiles]` (or its defaults for a probabilistic study)
/// from its table, as the JSON of `percentiles.json`; written into `output` (a folder) too
/// when given. `None` when the study asks for no percentiles.
#[pyfunction]
#[pyo3(signature = (study, table, output = None))]
fn study_percentiles(
    py: Python<'_>,
    study: StudySource,
    table: PathBuf,
    output: Option<PathBuf>,
) -> PyResult<Option<String>> {
    let s = study.study()?;
    let report = py
        .detach(|| s.percentiles(&table))
        .map_err(|e| study.error(e))?;
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
    m.add_function(wrap_pyfunction!(case_with, m)?)?;
    m.add_function(wrap_pyfunction!(variables, m)?)?;
    m.add_function(wrap_pyfunction!(statistics_columns, m)?)?;
    m.add_function(wrap_pyfunction!(coordinates, m)?)?;
    m.add("RESULTS_COMMENT", fretdyn::output::variables::COMMENT)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(stability, m)?)?;
    m.add_function(wrap_pyfunction!(apps::life, m)?)?;
    m.add_function(wrap_pyfunction!(apps::life_depth_se, m)?)?;
    m.add_function(wrap_pyfunction!(apps::modes, m)?)?;
    m.add_function(wrap_pyfunction!(study_runs, m)?)?;
    m.add_function(wrap_pyfunction!(study_header, m)?)?;
    m.add_function(wrap_pyfunction!(study_row, m)?)?;
    m.add_function(wrap_pyfunction!(study_local, m)?)?;
    m.add_class::<StudyTable>()?;
    m.add_function(wrap_pyfunction!(open_study_table, m)?)?;
    m.add_function(wrap_pyfunction!(study_percentiles, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
