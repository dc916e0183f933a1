//! Files: `results.npz` (time histories, opened by `numpy.load`) and `summary.json`
//! (THEORY §5).
//!
//! Results are written to a temporary name and renamed (`files::write_atomically`), so a failed
//! write never leaves a truncated file under the final name.

use std::io::BufWriter;
use std::path::{Path, PathBuf};

use ndarray_npy::NpzWriter;
use serde_json::json;

use crate::error::Result;
use crate::files::write_atomically;
use crate::integrator::simulation::RunResults;

/// Writes `results.npz` in `dir` with the arrays of [`crate::accumulate::recorder::Recorder`]:
/// `t`, `q`, `qdot`, `contact_normal_force`, `contact_tangential_force`,
/// `contact_slip_velocity`, `contact_penetration`, `contact_status`, `contact_position`
/// (contact names are in `summary.json`, in the same order). A streamed run
/// ([`crate::output::stream`]) writes the same keys.
pub fn write_results_npz(dir: &Path, results: &RunResults) -> Result<PathBuf> {
    let r = &results.recorder;
    let path = dir.join("results.npz");
    write_atomically(&path, |file| {
        let mut npz = NpzWriter::new(BufWriter::new(file));
        let e = |err: ndarray_npy::WriteNpzError| std::io::Error::other(err.to_string());
        npz.add_array("t", &r.t).map_err(e)?;
        npz.add_array("q", &r.q).map_err(e)?;
        npz.add_array("qdot", &r.qdot).map_err(e)?;
        npz.add_array("contact_normal_force", &r.normal_force)
            .map_err(e)?;
        npz.add_array("contact_tangential_force", &r.tangential_force)
            .map_err(e)?;
        npz.add_array("contact_slip_velocity", &r.slip_velocity)
            .map_err(e)?;
        npz.add_array("contact_penetration", &r.penetration)
            .map_err(e)?;
        npz.add_array("contact_status", &r.status).map_err(e)?;
        npz.add_array("contact_position", &r.position).map_err(e)?;
        npz.finish().map_err(e)?;
        Ok(())
    })?;
    Ok(path)
}

/// The JSON summary of a run: the case echoed, per-contact statistics with their standard
/// errors (`<statistic>_se`, `batches`, `batch_length`, `batch_autocorrelation`,
/// `batches_correlated`), the standard errors' settings and whether a target was met,
/// energy balance, solver statistics, steps, wall time and steps/s; the displacement
/// `monitors` when the case has some.
pub fn summary(case: &crate::case::Case, results: &RunResults) -> serde_json::Value {
    let s = &results.solver;
    let st = &case.settings.statistics;
    let mut standard_errors = json!({
        "method": "batch means",
        "batch_length": results.contacts.first().map_or(0.0, |c| c.errors.batch_length),
        "batches": results.contacts.first().map_or(0, |c| c.errors.batches),
        "batches_correlated": results.contacts.iter().any(|c| c.errors.batches_correlated),
        "max_relative_error": st.max_relative_error,
    });
    if let Some(target) = st.target_relative_error {
        standard_errors["target_relative_error"] = json!(target);
        standard_errors["target_met"] = json!(results.target_met_at.is_some());
        if let Some(t) = results.target_met_at {
            standard_errors["target_met_at"] = json!(t);
        }
    }
    let mut summary = json!({
        "fretdyn_version": env!("CARGO_PKG_VERSION"),
        "title": case.title,
        "warnings": case.warnings,
        "termination": results.termination,
        "time": {
            "dt": results.dt,
            "stable_dt": results.stable_dt,
            "steps": results.steps,
            "simulated_time": results.steps as f64 * results.dt,
            "samples": results.steps / case.settings.output_every + 1,
        },
        "contacts": contacts_with_wear(case, results),
        "standard_errors": standard_errors,
        "contact_geometry": case.model.contacts.iter().map(|c| json!({
            "name": c.name,
            "obstacle": c.obstacle.kind(),
            "outline": c.obstacle.outline(),
        })).collect::<Vec<_>>(),
        "energy_balance": results.energy,
        "solver": {
            "counters": s,
            "gauss_seidel_sweeps_mean": s.gs_sweeps_mean(),
            "active_set_iterations_mean": s.as_iterations_mean(),
            "natural_map_residual_mean": s.residual_mean(),
        },
        "performance": {
            "wall_time_s": results.wall_time,
            "steps_per_second": results.steps_per_second(),
        },
        "case": case.echo,
    });
    if !case.model.structures.is_empty() {
        summary["structures"] = structures(&case.model);
    }
    if !results.monitors.is_empty() {
        summary["monitors"] = json!(results.monitors);
    }
    summary
}

/// The structures of a model of several (THEORY §15): each one's name and its modes, points
/// and contacts (their names; its contacts are those with obstacles or between two of its
/// own points, those between two structures are no one's).
fn structures(model: &crate::model::Model) -> serde_json::Value {
    let points = &model.basis.points;
    json!(
        model
            .structures
            .iter()
            .map(|s| json!({
                "name": s.name,
                "modes": s.modes.len(),
                "points": points[s.points.clone()].iter().map(|p| &p.name).collect::<Vec<_>>(),
                "contacts": model.contacts[s.contacts.clone()]
                    .iter()
                    .map(|c| &c.name)
                    .collect::<Vec<_>>(),
            }))
            .collect::<Vec<_>>()
    )
}

/// The per-contact statistics; a contact with `wear` (docs/WEAR.md) also gets
/// `tube_volume_rate` and `support_volume_rate`, m³/s, its laws at the run's wear work rate
/// (friction or normal, as its `work` says) and service time 0 (THEORY §14); a two-body
/// contact also `tube_body` and `support_body`, the names of its points A and B. In a model of
/// several structures or with two-body contacts, every contact also has its `point` and
/// `other_point` (point B of a two-body contact, empty for an obstacle). A preloaded contact
/// has `preload_interference` (m) and `preload_force` (N), its plane's interference and its
/// normal force at rest (THEORY §16.1). One of a flat bar's points across its width (`width` on a
/// contact) has its `axial_offset` `s_j` (m, along the tube's axis towards its last node) and its
/// `width_share` `ω_j`.
fn contacts_with_wear(case: &crate::case::Case, results: &RunResults) -> serde_json::Value {
    let mut contacts = json!(results.contacts);
    let model = &case.model;
    let points = &model.basis.points;
    let pairs = crate::output::variables::neighbours(model);
    if let Some(list) = contacts.as_array_mut() {
        for (k, (entry, stats)) in list.iter_mut().zip(&results.contacts).enumerate() {
            let Some(map) = entry.as_object_mut() else {
                continue;
            };
            if pairs {
                // the contact's points: A, and B of a two-body contact (empty for an obstacle)
                let c = &model.contacts[k];
                let name = |i: Option<usize>| {
                    i.and_then(|i| points.get(i))
                        .map_or_else(String::new, |p| p.name.clone())
                };
                map.insert("point".into(), json!(name(Some(c.point))));
                map.insert("other_point".into(), json!(name(c.other())));
            }
            // a preloaded plane (THEORY §16.1): the interference it was pressed by and its
            // normal force at rest
            if let Some((interference, force)) = model.contacts[k].preload.and_then(|p| p.applied) {
                map.insert("preload_interference".into(), json!(interference));
                map.insert("preload_force".into(), json!(force));
            }
            if let Some(a) = model.contacts[k].across {
                // one of a flat bar's points across its width: where (which edge)
                map.insert("axial_offset".into(), json!(a.offset));
                map.insert("width_share".into(), json!(a.weight));
            }
            if let Some(w) = model.contact_wear(k) {
                let (tube, support) = w.volume_rates(w.work.rate(stats), 0.0);
                map.insert("tube_volume_rate".into(), json!(tube));
                map.insert("support_volume_rate".into(), json!(support));
                // a two-body contact: whose wear the two rates are (points A and B)
                let contact = &case.model.contacts[k];
                if let Some([a, b]) = crate::wear::pair_bodies(contact, &case.model.basis.points) {
                    map.insert("tube_body".into(), json!(a));
                    map.insert("support_body".into(), json!(b));
                }
            }
        }
    }
    contacts
}

/// Writes `summary.json` in `dir`.
pub fn write_summary(dir: &Path, summary: &serde_json::Value) -> Result<PathBuf> {
    let path = dir.join("summary.json");
    write_atomically(&path, |mut file| {
        serde_json::to_writer_pretty(&mut file, summary).map_err(std::io::Error::other)?;
        use std::io::Write;
        file.write_all(b"\n")
    })?;
    Ok(path)
}
