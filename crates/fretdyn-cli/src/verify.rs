//! `fretdyn verify`: V1a, V1b, V1c (THEORY §6) with every method against the analytic
//! solution, the figures of the paper's Figure 2, and the literal full-step variant.

use std::path::Path;

use fretdyn::apps::verification::{Check, V1, V1Measurements, checks, measure, methods};
use fretdyn::contact::tangential::{GaussSeidelSettings, StickVelocity, TangentialMethod};
use fretdyn::{RunResults, simulate};
use serde_json::json;

use crate::Failure;
use crate::out::outln;
use crate::plot::{Series, line_plot};

/// Penalty stiffnesses compared (THEORY §6), N/m.
const PENALTY_STIFFNESSES: [f64; 3] = [1e5, 1e6, 1e7];

struct Run {
    case: &'static str,
    label: String,
    results: RunResults,
    measurements: V1Measurements,
}

/// Entry point of `fretdyn verify`.
pub fn main(dir: &Path, quiet: bool) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::failed(format!("{}: cannot create the folder: {e}", dir.display()))
    })?;
    let mut all_checks: Vec<Check> = Vec::new();
    let mut runs: Vec<Run> = Vec::new();
    for (case, alpha) in [("V1a", 20.0), ("V1b", 1e-7), ("V1c", 60.0)] {
        let v1 = V1::reference(alpha);
        for (label, method) in methods(&PENALTY_STIFFNESSES) {
            let results = simulate(&v1.model(), &v1.settings(method, StickVelocity::HalfStep))
                .map_err(|e| Failure::failed(format!("{case} {label}: {e}")))?;
            let m = measure(&v1, &results);
            all_checks.extend(checks(case, &label, method.is_lagrange(), &v1, &m));
            runs.push(Run {
                case,
                label,
                results,
                measurements: m,
            });
        }
    }
    // Energy: frictionless elastic impact.
    let mut frictionless = V1::reference(20.0);
    frictionless.mu_static = 0.0;
    frictionless.mu_dynamic = 0.0;
    for (label, method) in methods(&[1e6]) {
        let r = simulate(
            &frictionless.model(),
            &frictionless.settings(method, StickVelocity::HalfStep),
        )
        .map_err(|e| Failure::failed(format!("energy {label}: {e}")))?;
        all_checks.push(Check::new(
            "V1 μ=0",
            &label,
            "energy balance error (relative)",
            r.energy.relative_error,
            1e-6,
        ));
    }
    // The paper's literal full-step constraint, for the record (not a check of fretdyn).
    let v1a = V1::reference(20.0);
    let gs = TangentialMethod::GaussSeidel(GaussSeidelSettings::default());
    let full = simulate(&v1a.model(), &v1a.settings(gs, StickVelocity::FullStep))
        .map_err(|e| Failure::failed(format!("V1a full-step: {e}")))?;
    let full_m = measure(&v1a, &full);

    print_table(&all_checks, quiet)?;
    if !quiet {
        outln!(
            "paper's literal full-step constraint (V1a, Gauss–Seidel): max |R_T| after t*+2Δt = {:.4} × max R_N ({:.1} N), leaving tangential speed {:.3e} m/s",
            full_m.post_stick_force,
            full_m.post_stick_force * max_normal(&full),
            full_m.leaving_tangential_speed
        )?;
        for run in runs
            .iter()
            .filter(|r| r.case == "V1a" && r.label.starts_with("penalty"))
        {
            outln!(
                "V1a {}: wear work {:.4e} J (analytic {:.4e} J), leaving tangential speed {:.3e} m/s",
                run.label,
                run.results.contacts[0].wear_work,
                analytic_wear_work(&v1a),
                run.measurements.leaving_tangential_speed
            )?;
        }
    }
    figures(dir, &runs, &full).map_err(Failure::failed)?;
    let report = json!({
        "checks": all_checks,
        "runs": runs.iter().map(|r| json!({
            "case": r.case,
            "method": r.label,
            "measurements": r.measurements,
            "wear_work": r.results.contacts[0].wear_work,
            "solver": r.results.solver,
        })).collect::<Vec<_>>(),
        "full_step_variant_v1a_gauss_seidel": full_m,
    });
    let path = dir.join("verification.json");
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&report).unwrap_or_default() + "\n",
    )
    .map_err(|e| Failure::failed(format!("{}: {e}", path.display())))?;
    let failed = all_checks.iter().filter(|c| !c.passed).count();
    outln!(
        "verify: {} passed, {} failed; figures and verification.json in {}",
        all_checks.len() - failed,
        failed,
        dir.display()
    )?;
    if failed > 0 {
        return Err(Failure::failed(format!(
            "{failed} verification check(s) failed (see the table above)"
        )));
    }
    Ok(())
}

/// Friction work of V1a's slip phase, `∫ μ_d R_N |v_T| dt` from 0 to t*: the tangential kinetic
/// energy `½ m v_t²` is all dissipated by friction before the stick.
fn analytic_wear_work(v1: &V1) -> f64 {
    0.5 * v1.mass * v1.tangential_speed().powi(2)
}

fn max_normal(r: &RunResults) -> f64 {
    r.recorder.normal_force.iter().copied().fold(0.0, f64::max)
}

fn print_table(checks: &[Check], quiet: bool) -> Result<(), Failure> {
    if !quiet {
        outln!(
            "{:<7} {:<18} {:<42} {:>12} {:>10}  ok",
            "case",
            "method",
            "quantity",
            "value",
            "limit"
        )?;
    }
    for c in checks {
        if !quiet || !c.passed {
            outln!(
                "{:<7} {:<18} {:<42} {:>12.3e} {:>10.1e}  {}",
                c.case,
                c.method,
                c.quantity,
                c.value,
                c.limit,
                if c.passed { "yes" } else { "NO" }
            )?;
        }
    }
    Ok(())
}

fn magnitude(r: &RunResults) -> Vec<f64> {
    let f = &r.recorder.tangential_force;
    (0..r.recorder.len())
        .map(|i| f[[i, 0, 0]].hypot(f[[i, 0, 1]]))
        .collect()
}

fn figures(dir: &Path, runs: &[Run], full: &RunResults) -> Result<(), String> {
    for (case, file, title, t_end) in [
        (
            "V1a",
            "fig2a_v1a_friction_force.png",
            "V1a (α = 20°): friction force against time",
            3.3e-3,
        ),
        (
            "V1b",
            "fig2b_v1b_friction_force.png",
            "V1b (α = 1e-7°): friction force, first 10 µs",
            10e-6,
        ),
    ] {
        let v1 = V1::reference(if case == "V1a" { 20.0 } else { 1e-7 });
        let selected: Vec<(&Run, Vec<f64>, usize)> = runs
            .iter()
            .filter(|r| r.case == case)
            .map(|r| {
                let n = r
                    .results
                    .recorder
                    .t
                    .iter()
                    .take_while(|&&t| t <= t_end)
                    .count();
                (r, magnitude(&r.results), n)
            })
            .collect();
        let t = &selected[0].0.results.recorder.t.as_slice().unwrap_or(&[])[..selected[0].2];
        let analytic: Vec<f64> = t.iter().map(|&t| v1.friction_force(t)).collect();
        let mut series: Vec<Series> = selected
            .iter()
            .map(|(r, y, n)| Series {
                label: r.label.clone(),
                x: &r.results.recorder.t.as_slice().unwrap_or(&[])[..*n],
                y: &y[..*n],
            })
            .collect();
        series.push(Series {
            label: "analytic".into(),
            x: t,
            y: &analytic,
        });
        line_plot(&dir.join(file), title, "t (s)", "|R_T| (N)", &series, true)?;
    }
    // Half-step (default) against the paper's literal full-step constraint.
    let half = &runs
        .iter()
        .find(|r| r.case == "V1a" && r.label == "gauss_seidel")
        .ok_or("no V1a Gauss–Seidel run")?
        .results;
    let comp = |r: &RunResults| -> Vec<f64> {
        r.recorder
            .tangential_force
            .slice(ndarray::s![.., 0, 0])
            .to_vec()
    };
    let (yh, yf) = (comp(half), comp(full));
    line_plot(
        &dir.join("full_step_variant.png"),
        "V1a Gauss–Seidel: stick on the half-step velocity (default) vs the paper's full-step",
        "t (s)",
        "R_T,1 (N)",
        &[
            Series {
                label: "full-step constraint (paper, literal)".into(),
                x: full.recorder.t.as_slice().unwrap_or(&[]),
                y: &yf,
            },
            Series {
                label: "half-step constraint (fretdyn default)".into(),
                x: half.recorder.t.as_slice().unwrap_or(&[]),
                y: &yh,
            },
        ],
        false,
    )?;
    // Penalty K_T dependence after the stick.
    let v1a = V1::reference(20.0);
    let ts = v1a.stick_time().unwrap_or(0.0);
    let penalty: Vec<(&Run, Vec<f64>)> = runs
        .iter()
        .filter(|r| r.case == "V1a" && r.label.starts_with("penalty"))
        .map(|r| (r, comp(&r.results)))
        .collect();
    let window = |r: &RunResults| -> (usize, usize) {
        let t = &r.recorder.t;
        let a = t.iter().take_while(|&&x| x < ts + 2.0 * v1a.dt).count();
        let b = t
            .iter()
            .take_while(|&&x| x <= v1a.contact_duration())
            .count();
        (a, b)
    };
    let series: Vec<Series> = penalty
        .iter()
        .map(|(r, y)| {
            let (a, b) = window(&r.results);
            Series {
                label: r.label.clone(),
                x: &r.results.recorder.t.as_slice().unwrap_or(&[])[a..b],
                y: &y[a..b],
            }
        })
        .collect();
    line_plot(
        &dir.join("penalty_kt_dependence.png"),
        "V1a penalty method: tangential force after the stick (t > t* + 2Δt), C_T = 2000 N·s/m",
        "t (s)",
        "R_T,1 (N)",
        &series,
        false,
    )
}
