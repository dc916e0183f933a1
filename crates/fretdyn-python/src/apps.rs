//! The service life and the modal basis of a case for Python (`fretdyn.life`, `fretdyn.modes`),
//! computed by the library as `fretdyn life` and `fretdyn modes` compute them: the life with
//! the GIL released and Ctrl-C honoured (the life stops after a checkpoint, as the CLI's), its
//! checkpoint and `life.json` in an output folder for a later `resume`; the basis as numpy
//! arrays. The tables and the messages of how a life ended are built in Python
//! (`python/fretdyn/_life.py`).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use fretdyn::apps::life::{
    CHECKPOINT_FILE, LifeCheckpoint, LifeControl, LifeResults, LifeSettings, MAX_HALVINGS,
    Unresumable,
};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::{Case, FretdynError, err};

/// Runs `work` on a thread of its own while this thread waits with the GIL released and looks
/// for Ctrl-C every 50 ms: on Ctrl-C (or any pending signal's exception) `work`'s stop flag
/// is set, `work` is waited for (it stops at its next batch of steps) and the exception comes
/// back beside its result.
fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&AtomicBool) -> T + Send,
) -> (T, Option<PyErr>) {
    let stop = AtomicBool::new(false);
    let mut interrupted = None;
    let out = std::thread::scope(|s| {
        let handle = s.spawn(|| work(&stop));
        while !handle.is_finished() {
            py.detach(|| std::thread::sleep(Duration::from_millis(50)));
            if interrupted.is_none()
                && let Err(e) = py.check_signals()
            {
                interrupted = Some(e);
                stop.store(true, Ordering::Relaxed);
            }
        }
        handle.join()
    });
    match out {
        Ok(out) => (out, interrupted),
        Err(panic) => std::panic::resume_unwind(panic),
    }
}

/// The fingerprint of a case's inputs (its TOML as read, the `[life]` settings included, and
/// the files it reads), as `fretdyn life` takes it of its case file.
fn fingerprint(case: &Case) -> PyResult<u64> {
    let value = toml::Value::try_from(&case.inner.echo)
        .map_err(|e| FretdynError::new_err(format!("the case cannot be fingerprinted: {e}")))?;
    Ok(fretdyn::case::fingerprint::Fingerprint::of(&value, &case.base_dir).value())
}

/// Creates the output folder `dir` and takes its lock ([`fretdyn::files::FOLDER_LOCK_FILE`]),
/// or says who holds it.
fn lock_folder(dir: &Path) -> PyResult<fretdyn::files::Lock> {
    std::fs::create_dir_all(dir).map_err(|e| {
        FretdynError::new_err(format!("{}: cannot create the folder: {e}", dir.display()))
    })?;
    match fretdyn::files::Lock::try_new(
        &dir.join(fretdyn::files::FOLDER_LOCK_FILE),
        "fretdyn.life (Python)",
    ) {
        Ok(Ok(lock)) => Ok(lock),
        Ok(Err(holder)) => Err(FretdynError::new_err(format!(
            "{}: {holder} is writing in this folder; wait for it to end, or give another output folder (output=...)",
            dir.display()
        ))),
        Err(e) => Err(err(e)),
    }
}

/// The checkpoint to continue the life in `dir` from: refused when the inputs changed since
/// the life started there, or when there is none (the CLI's checks, in Python's words).
fn read_checkpoint(dir: &Path, fingerprint: u64) -> PyResult<LifeCheckpoint> {
    let again = format!(
        "start the life again: fretdyn.life(case, output={:?})",
        dir.display().to_string()
    );
    fretdyn::apps::life::resume_checkpoint(dir, fingerprint).map_err(|why| match why {
        Unresumable::Changed => FretdynError::new_err(format!(
            "{}: the case or a file it reads changed since the life in this folder started (or no life was started there); {again}",
            dir.display()
        )),
        Unresumable::NoCheckpoint => FretdynError::new_err(format!(
            "{}: no checkpoint to resume: the life there is over (life.json says how it ended) or stopped before its first checkpoint; {again}",
            dir.display()
        )),
        Unresumable::OtherInputs(checkpoint) => FretdynError::new_err(format!(
            "{}: written for other inputs than the case has now; {again}",
            checkpoint.display()
        )),
        Unresumable::Unreadable(e) => err(e),
    })
}

/// The files of a life beside `life.json`, as `fretdyn life` writes them: `life.csv`,
/// `scars.csv` and, with `refined` lives (`max_depth_change` halved: `(fraction, results)`),
/// `convergence.csv` (the life itself first, at `max_depth_change`).
fn life_files(
    results: &LifeResults,
    max_depth_change: f64,
    refined: &[(f64, LifeResults)],
) -> Vec<(String, String)> {
    let mut files = vec![
        (
            "life.csv".to_string(),
            fretdyn::apps::life::life_csv(results),
        ),
        (
            "scars.csv".to_string(),
            fretdyn::apps::life::scars_csv(results),
        ),
    ];
    if !refined.is_empty() {
        let lives: Vec<(f64, &LifeResults)> = std::iter::once((max_depth_change, results))
            .chain(refined.iter().map(|(f, r)| (*f, r)))
            .collect();
        files.push((
            "convergence.csv".to_string(),
            fretdyn::apps::life::convergence_csv(&results.contacts, &lives),
        ));
    }
    files
}

/// The first-order standard error of one contact's tube depth after each life step, with the
/// scars fed back and at fixed gap, from its columns of `life.csv` (an unknown error: NaN):
/// `fretdyn::apps::life::depth_standard_errors`, as `fretdyn life` draws it in `life.png`.
#[pyfunction]
pub(crate) fn life_depth_se(
    depth: Vec<f64>,
    fixed_gap: Vec<f64>,
    rate: Vec<f64>,
    rate_se: Vec<f64>,
) -> PyResult<(Vec<f64>, Vec<f64>)> {
    let n = depth.len();
    if fixed_gap.len() != n || rate.len() != n || rate_se.len() != n {
        return Err(FretdynError::new_err(
            "life_depth_se: the four columns must have one length",
        ));
    }
    Ok(fretdyn::apps::life::depth_standard_errors(
        &depth, &fixed_gap, &rate, &rate_se,
    ))
}

/// The service life of a case with a `[life]` section (THEORY §14.5; `fretdyn life`), with
/// the GIL released; Ctrl-C stops it after a checkpoint (KeyboardInterrupt, once the results
/// so far are written). Returns the JSON of `life.json` (`criterion_depth`, `results`), and
/// when the life reached its end, the lives with `max_depth_change` halved 1…`halvings`
/// times: `(max_depth_change, JSON of their results)` each (the convergence check of
/// `--halvings`), and the text of the life's tables (`life.csv`, `scars.csv`,
/// `convergence.csv` with halvings: `(name, text)` each, the CLI's bytes). With `output` (a
/// folder): the life's checkpoint (after every life step and every `checkpoint_every` s
/// inside a window), `life_run.json`, `life.json`, `life.csv`, `scars.csv` (and
/// `convergence.csv`) are written there, as `fretdyn life` writes them, and `resume` continues the life stopped there (one the CLI started too: the same
/// fingerprint); `case_file`, the file the case was read from unchanged, is recorded for
/// `fretdyn life --resume`.
#[pyfunction]
#[pyo3(signature = (case, halvings = 0, output = None, resume = false, checkpoint_every = 60.0, case_file = None))]
pub(crate) fn life(
    py: Python<'_>,
    case: &Case,
    halvings: u32,
    output: Option<PathBuf>,
    resume: bool,
    checkpoint_every: f64,
    case_file: Option<PathBuf>,
) -> PyResult<LifeOutput> {
    let c = &case.inner;
    let Some(settings) = c.life.clone() else {
        return Err(FretdynError::new_err(
            "life: the case has no [life] section: add one with target_years (docs/WEAR.md)",
        ));
    };
    if halvings > MAX_HALVINGS {
        return Err(FretdynError::new_err(format!(
            "halvings: at most {MAX_HALVINGS} (each about doubles the life steps), got {halvings}"
        )));
    }
    if !(checkpoint_every.is_finite() && checkpoint_every > 0.0) {
        // the CLI's message for --checkpoint-every
        return Err(FretdynError::new_err(format!(
            "checkpoint_every: must be a positive number of seconds (got {checkpoint_every})"
        )));
    }
    // a case that cannot have a life, or cannot start its first window, is refused before
    // anything is written
    fretdyn::apps::life::check_life(c, &settings).map_err(err)?;
    fretdyn::integrator::simulation::Simulation::with_recorder(&c.model, &c.settings, 1)
        .map(drop)
        .map_err(err)?;
    let fingerprint = fingerprint(case)?;
    let checkpoint_path = output.as_ref().map(|d| d.join(CHECKPOINT_FILE));
    // held until the life is written: another life (or `fretdyn run`/`sweep`/`life`) in the
    // same folder is refused, as the CLI refuses it
    let _lock = output.as_deref().map(lock_folder).transpose()?;
    let resumed = match (&output, resume) {
        (Some(dir), true) => Some(read_checkpoint(dir, fingerprint)?),
        (Some(dir), false) => {
            fretdyn::apps::life::start_afresh(dir, fingerprint, case_file.as_deref())
                .map_err(err)?;
            None
        }
        (None, true) => {
            return Err(FretdynError::new_err(
                "resume: give the folder of the life to continue: fretdyn.life(case, output=DIR, resume=True)",
            ));
        }
        (None, false) => None,
    };
    let (results, interrupted) = interruptible(py, |stop| {
        let mut control = LifeControl {
            checkpoint: checkpoint_path.as_deref(),
            checkpoint_every_seconds: checkpoint_every,
            fingerprint,
            resume: resumed,
            stop: Some(stop),
        };
        fretdyn::apps::life::service_life_with(c, &settings, &mut control, |_| {})
    });
    let results = results.map_err(err)?;
    let json = fretdyn::apps::life::life_json(&c.title, &results, settings.criterion);
    if let Some(dir) = &output {
        fretdyn::apps::life::write_life(dir, &c.title, &results, settings.criterion)
            .map_err(err)?;
        if !matches!(results.end, fretdyn::apps::life::LifeEnd::Stopped { .. }) {
            // the life is over: nothing to resume
            let _ = std::fs::remove_file(dir.join(CHECKPOINT_FILE));
        }
    }
    if let Some(e) = interrupted {
        return Err(e);
    }
    let mut refined = Vec::new();
    if results.end.is_finished() {
        for h in 1..=halvings {
            let finer = LifeSettings {
                max_depth_change: settings.max_depth_change / f64::from(1u32 << h),
                ..settings.clone()
            };
            let (r, interrupted) = interruptible(py, |stop| {
                let mut control = LifeControl {
                    stop: Some(stop),
                    ..LifeControl::default()
                };
                fretdyn::apps::life::service_life_with(c, &finer, &mut control, |_| {})
            });
            if let Some(e) = interrupted {
                return Err(e);
            }
            refined.push((finer.max_depth_change, r.map_err(err)?));
        }
    }
    let files = life_files(&results, settings.max_depth_change, &refined);
    if let Some(dir) = &output {
        for (name, text) in files.iter().filter(|(name, _)| name == "convergence.csv") {
            fretdyn::files::write_text_atomically(&dir.join(name), text).map_err(err)?;
        }
    }
    let refined = refined
        .iter()
        .map(|(f, r)| (*f, serde_json::to_string(r).unwrap_or_default()))
        .collect();
    Ok((json, refined, files))
}

/// What [`life`] returns to Python: the JSON of `life.json`, the refined lives
/// `(max_depth_change, JSON of their results)` and the tables `(file name, text)`.
type LifeOutput = (String, Vec<(f64, String)>, Vec<(String, String)>);

/// The modal basis of a case (`fretdyn modes`): a dict with `frequencies_hz`,
/// `damping_ratio` (numpy arrays, one value per mode), `points` (names), `rows` (numpy
/// array points × 3 × modes: the translation of each point in each mode, mass-normalised),
/// `coords` (points × 3, m), `abscissae` (per point, m, NaN where unknown), `participation`
/// (3 × modes, Γ = ΦᵀMr, kg^0.5, or None when the basis does not know it) and, for a tube
/// (`type = "tube"`), `tube`: a dict with `s` (the abscissa of each node along the tube, m),
/// `nodes` (nodes × 3, m), `shapes` (modes × nodes × 3: the translations u_x, u_y, u_z of
/// every node, 0 at a restrained one), `supports` (the abscissae of the nodes with a
/// restrained translation, m) and `orthonormality_error` (max |ΦᵀMΦ − I|). With `output`
/// (a folder, made if needed), the basis is written there as `basis.npz`, as `fretdyn modes`
/// writes it (keys `frequencies_hz`, `damping_ratio`, `rows_<point>`, `coords_<point>`,
/// `s_<point>`).
#[pyfunction]
#[pyo3(signature = (case, output = None))]
pub(crate) fn modes<'py>(
    py: Python<'py>,
    case: &Case,
    output: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    use fretdyn::structure::beam::Dof;
    let c = &case.inner;
    let basis = &c.model.basis;
    if let Some(dir) = &output {
        std::fs::create_dir_all(dir).map_err(|e| {
            FretdynError::new_err(format!("{}: cannot create the folder: {e}", dir.display()))
        })?;
        fretdyn::structure::basis_file::write_basis_npz_with_abscissae(
            &dir.join("basis.npz"),
            basis,
            &c.point_abscissae,
        )
        .map_err(err)?;
    }
    let p = basis.modes();
    let out = PyDict::new(py);
    let hz: Vec<f64> = basis
        .omega
        .iter()
        .map(|w| w / std::f64::consts::TAU)
        .collect();
    out.set_item("frequencies_hz", PyArray1::from_vec(py, hz))?;
    out.set_item(
        "damping_ratio",
        PyArray1::from_vec(py, basis.damping_ratio.clone()),
    )?;
    let names: Vec<&str> = basis.points.iter().map(|pt| pt.name.as_str()).collect();
    out.set_item("points", names)?;
    let n = basis.points.len();
    let rows: Vec<f64> = basis
        .points
        .iter()
        .flat_map(|pt| pt.rows.iter().copied())
        .collect();
    out.set_item("rows", PyArray1::from_vec(py, rows).reshape([n, 3, p])?)?;
    let coords: Vec<f64> = basis
        .points
        .iter()
        .flat_map(|pt| pt.coords.iter().copied())
        .collect();
    out.set_item("coords", PyArray1::from_vec(py, coords).reshape([n, 3])?)?;
    let abscissae: Vec<f64> = (0..n)
        .map(|k| {
            c.point_abscissae
                .get(k)
                .copied()
                .flatten()
                .unwrap_or(f64::NAN)
        })
        .collect();
    out.set_item("abscissae", PyArray1::from_vec(py, abscissae))?;
    if basis.participation.len() == 3 * p {
        let gamma = PyArray1::from_vec(py, basis.participation.clone()).reshape([3, p])?;
        out.set_item("participation", gamma)?;
    } else {
        out.set_item("participation", py.None())?;
    }
    if let Some(tube) = &c.tube {
        let mesh = &tube.structure.beam.mesh;
        let a = &tube.basis.assembled;
        let shapes = &tube.basis.modes.shapes;
        let nodes = mesh.nodes.len();
        // the abscissa along the path: the nodes are numbered along the tube
        let mut s = vec![0.0; nodes];
        for k in 1..nodes {
            s[k] = s[k - 1] + (mesh.nodes[k] - mesh.nodes[k - 1]).norm();
        }
        let dofs = [Dof::Ux, Dof::Uy, Dof::Uz];
        let m = shapes.ncols().min(p);
        let mut u = Vec::with_capacity(m * nodes * 3);
        for mode in 0..m {
            for node in 0..nodes {
                for d in dofs {
                    u.push(a.reduced_index(node, d).map_or(0.0, |i| shapes[(i, mode)]));
                }
            }
        }
        let supports: Vec<f64> = (0..nodes)
            .filter(|&k| dofs.iter().any(|&d| a.reduced_index(k, d).is_none()))
            .map(|k| s[k])
            .collect();
        let positions: Vec<f64> = mesh.nodes.iter().flat_map(|x| x.iter().copied()).collect();
        let t = PyDict::new(py);
        t.set_item("s", PyArray1::from_vec(py, s))?;
        t.set_item(
            "nodes",
            PyArray1::from_vec(py, positions).reshape([nodes, 3])?,
        )?;
        t.set_item("shapes", PyArray1::from_vec(py, u).reshape([m, nodes, 3])?)?;
        t.set_item("supports", PyArray1::from_vec(py, supports))?;
        t.set_item(
            "orthonormality_error",
            fretdyn::structure::eigen::orthonormality_error(&a.mass, shapes),
        )?;
        out.set_item("tube", t)?;
    } else {
        out.set_item("tube", py.None())?;
    }
    Ok(out)
}
