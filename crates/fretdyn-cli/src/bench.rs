//! `fretdyn bench`: steps per second of V1 and of the synthetic rattling tube, per method.

use fretdyn::apps::benchmark::{methods, rattling_tube};
use fretdyn::apps::verification::V1;
use fretdyn::case::Case;
use fretdyn::contact::tangential::StickVelocity;
use fretdyn::integrator::simulation::simulate;

use std::path::Path;

use crate::Failure;
use crate::out::outln;
use crate::plot::{Series, panels_plot};

/// Entry point of `fretdyn bench`.
pub fn main(steps: u64, repeat: usize, modes: usize, contacts: usize) -> Result<(), Failure> {
    let methods = methods();
    outln!(
        "machine: {}, {} logical CPUs",
        cpu_model(),
        std::thread::available_parallelism().map_or(1, |n| n.get())
    )?;
    outln!(
        "fretdyn {} (release build: {})",
        env!("CARGO_PKG_VERSION"),
        !cfg!(debug_assertions)
    )?;
    outln!(
        "| case | method | modes | contacts | steps | best wall time (s) | steps/s | closed-contact steps |"
    )?;
    outln!("|---|---|---|---|---|---|---|---|")?;
    for method in methods {
        let v1 = V1::reference(20.0);
        let mut settings = v1.settings(method, StickVelocity::HalfStep);
        settings.steps = 4000;
        settings.output_every = 4000;
        let case = Case::from_parts("V1a", v1.model(), settings);
        // a V1 run lasts under a millisecond: repeat it more to get a stable best time
        bench_case(&case, 20 * repeat)?;
    }
    for method in methods {
        let mut case = rattling_tube(modes, contacts, method, steps);
        case.settings.output_every = steps.max(1);
        bench_case(&case, repeat)?;
    }
    Ok(())
}

/// Modes and contacts of the scaling study.
const SCALING_MODES: [usize; 5] = [10, 25, 50, 100, 200];
const SCALING_CONTACTS: [usize; 5] = [1, 5, 10, 25, 50];

/// `fretdyn bench --scaling DIR`: wall time per step of the synthetic tube over a grid of
/// modes × contacts for each method, with the mean number of closed contacts per step (the
/// cost of the tangential problem grows with those, not with the contacts declared).
pub fn scaling(dir: &Path, steps: u64) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).map_err(|e| Failure::failed(format!("{}: {e}", dir.display())))?;
    outln!("machine: {}, {steps} steps per run, best of 2", cpu_model())?;
    outln!("| method | modes | contacts | mean closed | µs/step | steps/s |")?;
    outln!("|---|---|---|---|---|---|")?;
    let mut csv = String::from("method,modes,contacts,mean_closed,us_per_step,steps_per_s\n");
    // per method, per contact count: (modes, µs/step)
    let mut curves: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
    for method in methods() {
        for &contacts in &SCALING_CONTACTS {
            let (mut xs, mut ys) = (Vec::new(), Vec::new());
            for &modes in &SCALING_MODES {
                let mut case = rattling_tube(modes, contacts, method, steps);
                case.settings.output_every = steps.max(1);
                let mut best = f64::INFINITY;
                let mut closed = 0.0;
                for _ in 0..2 {
                    let r = simulate(&case.model, &case.settings)
                        .map_err(|e| Failure::failed(format!("{}: {e}", case.title)))?;
                    best = best.min(r.wall_time);
                    closed = r
                        .contacts
                        .iter()
                        .map(|c| c.contact_time_fraction)
                        .sum::<f64>();
                }
                let us = 1e6 * best / steps as f64;
                outln!(
                    "| {} | {} | {contacts} | {closed:.2} | {us:.3} | {:.3e} |",
                    method.name(),
                    case.model.basis.modes(),
                    1e6 / us
                )?;
                csv.push_str(&format!(
                    "{},{},{contacts},{closed:.4},{us:.5},{:.1}\n",
                    method.name(),
                    case.model.basis.modes(),
                    1e6 / us
                ));
                xs.push(case.model.basis.modes() as f64);
                ys.push(us);
            }
            curves.push((format!("{}, {contacts} contacts", method.name()), xs, ys));
        }
    }
    let csv_path = dir.join("scaling.csv");
    std::fs::write(&csv_path, csv)
        .map_err(|e| Failure::failed(format!("{}: {e}", csv_path.display())))?;
    let panels: Vec<(String, Vec<Series>)> = methods()
        .iter()
        .map(|m| {
            let series = curves
                .iter()
                .filter(|(label, _, _)| label.starts_with(m.name()))
                .map(|(label, x, y)| Series {
                    label: label.clone(),
                    x,
                    y,
                })
                .collect();
            (m.name().to_string(), series)
        })
        .collect();
    let png = dir.join("scaling.png");
    panels_plot(
        &png,
        "Wall time per step of the synthetic rattling tube",
        "modes",
        "µs per step",
        &panels,
    )
    .map_err(Failure::failed)?;
    outln!("wrote {} and {}", csv_path.display(), png.display())?;
    Ok(())
}

fn bench_case(case: &Case, repeat: usize) -> Result<(), Failure> {
    let mut best = f64::INFINITY;
    let mut closed = 0;
    for _ in 0..repeat.max(1) {
        let r = simulate(&case.model, &case.settings)
            .map_err(|e| Failure::failed(format!("{}: {e}", case.title)))?;
        best = best.min(r.wall_time);
        closed = r.solver.lagrange_steps;
    }
    let s = &case.settings;
    outln!(
        "| {} | {} | {} | {} | {} | {:.4} | {:.3e} | {} |",
        case.title,
        s.method.name(),
        case.model.basis.modes(),
        case.model.contacts.len(),
        s.steps,
        best,
        s.steps as f64 / best,
        if s.method.is_lagrange() {
            closed.to_string()
        } else {
            "—".into()
        }
    )?;
    Ok(())
}

pub(crate) fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}
