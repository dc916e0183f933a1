//! `fretdyn bench`: steps per second of V1 and of the synthetic rattling tube, per method.

use fretdyn::Case;
use fretdyn::apps::benchmark::{methods, rattling_tube};
use fretdyn::apps::verification::V1;
use fretdyn::contact::tangential::{StickVelocity, TangentialMethod};
use fretdyn::integrator::simulation::Termination;
use fretdyn::simulate;

use std::path::Path;
use std::time::Instant;

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
    let mut csv = String::from(SCALING_HEADER);
    csv.push('\n');
    for method in methods() {
        for &contacts in &SCALING_CONTACTS {
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
            }
        }
    }
    let csv_path = dir.join(SCALING_FILE);
    std::fs::write(&csv_path, csv)
        .map_err(|e| Failure::failed(format!("{}: {e}", csv_path.display())))?;
    let png = draw_scaling(dir).map_err(Failure::failed)?;
    outln!("wrote {} and {}", csv_path.display(), png.display())?;
    Ok(())
}

/// The table `fretdyn bench --scaling` writes, and its header.
pub const SCALING_FILE: &str = "scaling.csv";
const SCALING_HEADER: &str = "method,modes,contacts,mean_closed,us_per_step,steps_per_s";

/// `scaling.png` of a folder with a `scaling.csv` (`bench --scaling`, or `fretdyn plot`
/// again): µs per step against the modes, one panel per method, a curve per contact count, in
/// the table's order. Returns the figure's path.
pub fn draw_scaling(dir: &Path) -> Result<std::path::PathBuf, String> {
    let path = dir.join(SCALING_FILE);
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    if lines.next() != Some(SCALING_HEADER) {
        return Err(format!(
            "{}: not a table of fretdyn bench --scaling (its header is {SCALING_HEADER})",
            path.display()
        ));
    }
    // (method, contacts) → (modes, µs per step), in the table's order
    let mut curves: Vec<(String, String, Vec<f64>, Vec<f64>)> = Vec::new();
    for (i, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        let bad = || {
            format!(
                "{} line {}: {line:?} is not a row of the table",
                path.display(),
                i + 2
            )
        };
        let [method, modes, contacts, _, us, _] = f[..] else {
            return Err(bad());
        };
        let (Ok(modes), Ok(us)) = (modes.parse::<f64>(), us.parse::<f64>()) else {
            return Err(bad());
        };
        match curves.iter_mut().find(|c| c.0 == method && c.1 == contacts) {
            Some(c) => {
                c.2.push(modes);
                c.3.push(us * 1e-6);
            }
            None => curves.push((method.into(), contacts.into(), vec![modes], vec![us * 1e-6])),
        }
    }
    let mut methods: Vec<&str> = Vec::new();
    for c in &curves {
        if !methods.contains(&c.0.as_str()) {
            methods.push(&c.0);
        }
    }
    let panels: Vec<(String, Vec<Series>)> = methods
        .iter()
        .map(|m| {
            let series = curves
                .iter()
                .filter(|c| c.0 == *m)
                .map(|c| Series {
                    label: if c.1 == "1" {
                        "1 contact".to_string()
                    } else {
                        format!("{} contacts", c.1)
                    },
                    x: &c.2,
                    y: &c.3,
                })
                .collect();
            (m.to_string(), series)
        })
        .collect();
    let png = dir.join("scaling.png");
    panels_plot(
        &png,
        "Wall time per step of the synthetic rattling tube",
        "modes",
        "time per step (s)",
        &panels,
    )?;
    Ok(png)
}

/// `fretdyn bench --pair A B`: the two cases run in this process alternately, the order
/// swapped every round, `rounds` times (`steps` each instead of their own when given, only
/// their first and last samples recorded). Reports each case's time-loop steps/s (median and
/// best) and the median and quartiles of the per-round ratio B/A. On a shared machine whose
/// speed drifts over seconds, separate processes of one build differ by ±10 % and more;
/// rounds alternated in one process see the same drift and resolve a few per cent.
pub fn pair(a: &Path, b: &Path, rounds: usize, steps: Option<u64>) -> Result<(), Failure> {
    let load = |path: &Path| -> Result<Case, Failure> {
        let mut case = Case::from_file(path).map_err(|e| Failure::input(e.in_file(path)))?;
        if let Some(steps) = steps {
            case.settings.steps = steps;
        }
        case.settings.output_every = case.settings.steps.max(1);
        Ok(case)
    };
    let cases = [load(a)?, load(b)?];
    let paths = [a, b];
    let rounds = rounds.max(1);
    outln!(
        "machine: {}, {} logical CPUs; fretdyn {} (release build: {})",
        cpu_model(),
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        env!("CARGO_PKG_VERSION"),
        !cfg!(debug_assertions)
    )?;
    outln!("{rounds} rounds in this process, alternated (A, B), (B, A), …; time-loop steps/s\n")?;
    let started = Instant::now();
    let mut speeds = [Vec::with_capacity(rounds), Vec::with_capacity(rounds)];
    for round in 0..rounds {
        let order = if round % 2 == 0 { [0, 1] } else { [1, 0] };
        for k in order {
            let r = simulate(&cases[k].model, &cases[k].settings)
                .map_err(|e| Failure::failed(format!("{}: {e}", paths[k].display())))?;
            if r.termination != Termination::Completed {
                return Err(Failure::failed(format!(
                    "{}: the run did not complete ({:?}): nothing to time",
                    paths[k].display(),
                    r.termination
                )));
            }
            speeds[k].push(r.steps_per_second());
        }
    }
    outln!("| case | file | method | steps | steps/s (median) | steps/s (best) |")?;
    outln!("|---|---|---|---|---|---|")?;
    let best = |k: usize| speeds[k].iter().copied().fold(0.0, f64::max);
    for (k, label) in ["A", "B"].iter().enumerate() {
        let [_, median, _] = quartiles(&speeds[k]);
        outln!(
            "| {label} | {} | {} | {} | {median:.4e} | {:.4e} |",
            paths[k].display(),
            method_label(&cases[k].settings.method),
            cases[k].settings.steps,
            best(k)
        )?;
    }
    let ratios: Vec<f64> = speeds[1]
        .iter()
        .zip(&speeds[0])
        .map(|(b, a)| b / a)
        .collect();
    let [q1, median, q3] = quartiles(&ratios);
    outln!(
        "\nratio B/A of steps/s: median {median:.4} (quartiles {q1:.4}–{q3:.4}), best/best {:.4}; {:.0} s",
        best(1) / best(0),
        started.elapsed().as_secs_f64()
    )?;
    Ok(())
}

/// The method's name, with the local solve of Gauss–Seidel (`gauss_seidel (exact)`).
fn method_label(method: &TangentialMethod) -> String {
    match method {
        TangentialMethod::GaussSeidel(s) => {
            format!("{} ({})", method.name(), s.local_solve.name())
        }
        _ => method.name().to_string(),
    }
}

/// First quartile, median and third quartile (linear interpolation between the order
/// statistics, as numpy's default); NaN for no values.
fn quartiles(values: &[f64]) -> [f64; 3] {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let at = |q: f64| {
        if v.is_empty() {
            return f64::NAN;
        }
        let x = q * (v.len() - 1) as f64;
        let (i, f) = (x.floor() as usize, x.fract());
        if i + 1 < v.len() {
            v[i] + f * (v[i + 1] - v[i])
        } else {
            v[i]
        }
    };
    [at(0.25), at(0.5), at(0.75)]
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

fn cpu_model() -> String {
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

#[cfg(test)]
mod tests {
    use super::quartiles;

    /// numpy's `percentile(v, [25, 50, 75])` of the same values.
    #[test]
    fn quartiles_interpolate_as_numpy() {
        assert_eq!(quartiles(&[4.0, 1.0, 3.0, 2.0]), [1.75, 2.5, 3.25]);
        assert_eq!(quartiles(&[5.0, 1.0, 3.0]), [2.0, 3.0, 4.0]);
        assert_eq!(quartiles(&[7.0]), [7.0, 7.0, 7.0]);
        assert!(quartiles(&[]).iter().all(|q| q.is_nan()));
    }
}
