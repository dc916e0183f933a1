//! `fretdyn run`: one case file, or the built-in demo.

use std::path::{Path, PathBuf};

use fretdyn::case::Case;
use fretdyn::simulation::{RunResults, Termination, run};
use fretdyn::verification::V1;

use crate::Failure;
use crate::plot::{Series, line_plot, panels_plot};
use crate::progress::Bar;

/// Entry point of `fretdyn run`.
pub fn main(
    case: Option<&Path>,
    output: Option<PathBuf>,
    quiet: bool,
    plots: bool,
) -> Result<(), Failure> {
    match case {
        Some(path) => {
            let case = Case::from_file(path)
                .map_err(|e| Failure::input(format!("{}: {e}", path.display())))?;
            for w in &case.warnings {
                eprintln!("warning: {w}");
            }
            let dir = output.unwrap_or_else(|| default_dir(&case.title, path));
            run_and_write(&case, &path.display().to_string(), &dir, quiet, plots)?;
            Ok(())
        }
        None => demo(output, quiet, plots),
    }
}

fn default_dir(title: &str, path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| title.to_string());
    PathBuf::from("fretdyn_results").join(stem)
}

/// Runs a case, writes `results.npz`, `summary.json` and plots in `dir`, prints a report.
/// A diverged run still writes what it computed, then fails with the step and contact.
pub fn run_and_write(
    case: &Case,
    source: &str,
    dir: &Path,
    quiet: bool,
    plots: bool,
) -> Result<RunResults, Failure> {
    let mut bar = Bar::new(&case.title, !quiet);
    let results = run(&case.model, &case.settings, |p| bar.observe(p))
        .map_err(|e| Failure::input(format!("{source}: {e}")))?;
    bar.finish();
    write_outputs(dir, case, &results, plots)?;
    if !quiet {
        report(case, &results, dir);
    }
    match &results.termination {
        Termination::Completed => Ok(results),
        Termination::Diverged {
            step,
            time,
            contact,
        } => Err(Failure::failed(format!(
            "{source}: the run diverged at step {step} (t = {time:e} s){}; the results up to then are in {}. Reduce time.dt or check the contact stiffnesses",
            contact
                .as_ref()
                .map(|c| format!(" at contact '{c}'"))
                .unwrap_or_default(),
            dir.display()
        ))),
        Termination::Stopped { step } => Err(Failure::failed(format!(
            "{source}: stopped at step {step}; the results up to then are in {}",
            dir.display()
        ))),
    }
}

/// Writes every output of a run into `dir`.
pub fn write_outputs(
    dir: &Path,
    case: &Case,
    results: &RunResults,
    plots: bool,
) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::failed(format!("{}: cannot create the folder: {e}", dir.display()))
    })?;
    let io = |e: fretdyn::Error| Failure::failed(e.to_string());
    fretdyn::output::write_results_npz(dir, results).map_err(io)?;
    let summary = fretdyn::output::summary(case, results);
    fretdyn::output::write_summary(dir, &summary).map_err(io)?;
    if plots && !case.model.contacts.is_empty() {
        plot_contact_forces(&dir.join("contact_forces.png"), case, results)
            .map_err(Failure::failed)?;
    }
    Ok(())
}

/// Contact forces against time, one panel per contact.
fn plot_contact_forces(path: &Path, case: &Case, results: &RunResults) -> Result<(), String> {
    let r = &results.recorder;
    let t: Vec<f64> = r.t.to_vec();
    let columns: Vec<[Vec<f64>; 3]> = (0..case.model.contacts.len())
        .map(|k| {
            [
                r.normal_force.column(k).to_vec(),
                r.tangential_force.slice(ndarray::s![.., k, 0]).to_vec(),
                r.tangential_force.slice(ndarray::s![.., k, 1]).to_vec(),
            ]
        })
        .collect();
    let panels: Vec<(String, Vec<Series>)> = case
        .model
        .contacts
        .iter()
        .zip(&columns)
        .map(|(c, [n, t1, t2])| {
            (
                c.name.clone(),
                vec![
                    Series {
                        label: "normal R_N".into(),
                        x: &t,
                        y: n,
                    },
                    Series {
                        label: "tangential R_T,1".into(),
                        x: &t,
                        y: t1,
                    },
                    Series {
                        label: "tangential R_T,2".into(),
                        x: &t,
                        y: t2,
                    },
                ],
            )
        })
        .collect();
    panels_plot(
        path,
        &format!(
            "{} — contact forces ({})",
            case.title,
            case.settings.method.name()
        ),
        "t (s)",
        "force (N)",
        &panels,
    )
}

fn report(case: &Case, r: &RunResults, dir: &Path) {
    println!(
        "{}: {} steps of {:e} s ({} method) in {:.3} s, {:.3e} steps/s",
        case.title,
        r.steps,
        r.dt,
        case.settings.method.name(),
        r.wall_time,
        r.steps_per_second()
    );
    println!(
        "  {:<16} {:>8} {:>8} {:>8} {:>8} {:>12} {:>14}",
        "contact", "impacts", "contact", "stick", "slip", "max R_N (N)", "wear rate (W)"
    );
    for c in &r.contacts {
        println!(
            "  {:<16} {:>8} {:>8.4} {:>8.4} {:>8.4} {:>12.5e} {:>14.5e}",
            c.name,
            c.impacts,
            c.contact_time_fraction,
            c.stick_time_fraction,
            c.slip_time_fraction,
            c.normal_force_max,
            c.wear_work_rate
        );
    }
    println!(
        "  energy balance error {:.3e} (relative)",
        r.energy.relative_error
    );
    let s = &r.solver;
    if case.settings.method.is_lagrange() {
        println!(
            "  solver: GS sweeps mean {:.2} max {} non-converged {}; AS iterations mean {:.2} max {} cycles {} fallbacks {}; singular H {}; residual mean {:.1e} max {:.1e}, steps > 1e-8: {}",
            s.gs_sweeps_mean(),
            s.gs_sweeps_max,
            s.gs_nonconverged_steps,
            s.as_iterations_mean(),
            s.as_iterations_max,
            s.as_cycles,
            s.as_fallbacks,
            s.singular_delassus,
            s.residual_mean(),
            s.residual_max,
            s.residual_steps_above_1e_8
        );
    }
    println!("  wrote {}", dir.display());
}

/// The built-in demo: V1a (THEORY §6) with the Active Set, the Gauss–Seidel and the penalty
/// method (K_T = 1e6 N/m, C_T = 2000 N·s/m), and a plot comparing their friction forces.
fn demo(output: Option<PathBuf>, quiet: bool, plots: bool) -> Result<(), Failure> {
    let dir = output.unwrap_or_else(|| PathBuf::from("fretdyn_results").join("demo_v1a"));
    let v1 = V1::reference(20.0);
    if !quiet {
        println!(
            "fretdyn demo: V1a, a 1 kg point mass hitting a plane at 1 m/s, 20° from the normal, μ = 0.3 (THEORY §6)"
        );
    }
    let mut curves = Vec::new();
    for (label, method) in fretdyn::verification::methods(&[1e6]) {
        let slug = label.split_whitespace().next().unwrap_or("run").to_string();
        let case = v1.case(&format!("V1a {label}"), method);
        let results = run_and_write(&case, "demo", &dir.join(&slug), quiet, plots)?;
        let r = &results.recorder;
        let magnitude: Vec<f64> = (0..r.len())
            .map(|i| r.tangential_force[[i, 0, 0]].hypot(r.tangential_force[[i, 0, 1]]))
            .collect();
        curves.push((label, r.t.to_vec(), magnitude));
    }
    if plots {
        let t = curves[0].1.clone();
        let analytic: Vec<f64> = t.iter().map(|&t| v1.friction_force(t)).collect();
        let mut series: Vec<Series> = curves
            .iter()
            .map(|(l, t, y)| Series {
                label: l.clone(),
                x: t,
                y,
            })
            .collect();
        series.push(Series {
            label: "analytic".into(),
            x: &t,
            y: &analytic,
        });
        let path = dir.join("friction_force.png");
        line_plot(
            &path,
            "V1a: friction force |R_T| against time",
            "t (s)",
            "|R_T| (N)",
            &series,
            true,
        )
        .map_err(Failure::failed)?;
    }
    if !quiet {
        println!(
            "demo written to {} (one folder per method, and friction_force.png)",
            dir.display()
        );
    }
    Ok(())
}
