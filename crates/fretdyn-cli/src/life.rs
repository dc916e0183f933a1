//! `fretdyn life CASE.toml`: the service life of a case with a `[life]` section and contacts
//! with `wear` (THEORY §14.5, docs/WEAR.md) — windows of vibration, scar growth, the scars
//! fed back into the obstacles, until the target time. Writes `life.csv` (one row per life
//! step), `life.json` (the whole result), `scars.csv` (final scar profiles) and `life.png`.
//! The library computes ([`fretdyn::apps::life::service_life`]); this prints and writes.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use fretdyn::apps::life::{LifeEnd, LifeResults, LifeStep, YEAR, service_life};
use fretdyn::case::Case;

use crate::Failure;
use crate::out::{errln, outln};
use crate::plot::{self, Series};

/// Entry point of `fretdyn life`.
pub fn main(
    path: &Path,
    output: Option<PathBuf>,
    plots: bool,
    halvings: u32,
) -> Result<(), Failure> {
    let case = Case::from_file(path).map_err(|e| Failure::input(e.in_file(path)))?;
    for w in &case.warnings {
        errln!("warning: {w}");
    }
    let Some(life) = case.life.clone() else {
        return Err(Failure::input(format!(
            "{}: life: the case has no [life] section: add one with target_years (docs/WEAR.md)",
            path.display()
        )));
    };
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "case".into());
    let dir =
        output.unwrap_or_else(|| PathBuf::from("fretdyn_results").join(format!("{stem}_life")));
    std::fs::create_dir_all(&dir).map_err(|e| {
        Failure::failed(format!("{}: cannot create the folder: {e}", dir.display()))
    })?;
    outln!(
        "{}: service life to {} years, windows of {} s, depth change ≤ {} per step{}",
        case.title,
        life.target / YEAR,
        case.settings.steps as f64 * case.settings.dt,
        life.max_depth_change,
        if life.feedback {
            ""
        } else {
            " (fixed gap: no feedback)"
        }
    )?;
    let mut printed = Ok(());
    let results = service_life(&case, &life, |step: &LifeStep| {
        if printed.is_ok() && step.time > 0.0 {
            let depths: Vec<String> = step
                .contacts
                .iter()
                .map(|c| format!("{:.3e}", c.tube_depth))
                .collect();
            printed = outln!(
                "  {:>10.4} years  tube depth (m) {}",
                step.time / YEAR,
                depths.join(" ")
            );
        }
    })
    .map_err(|e| Failure::input(e.in_file(path)))?;
    printed?;
    write(&dir, &results, life.criterion)?;
    if plots {
        draw(&dir.join("life.png"), &case.title, &results, life.criterion)
            .map_err(|e| Failure::failed(format!("{}: {e}", dir.join("life.png").display())))?;
    }
    for (k, name) in results.contacts.iter().enumerate() {
        let last = &results.steps[results.steps.len() - 1].contacts[k];
        let reach = |t: Option<f64>| {
            t.map_or_else(
                || "not reached".into(),
                |t| format!("{:.3} years", t / YEAR),
            )
        };
        outln!(
            "{name}: tube depth {:.4e} m (fixed gap {:.4e} m), support {:.4e} m; criterion {} (fixed gap {})",
            last.tube_depth,
            last.tube_depth_fixed_gap,
            last.support_depth,
            reach(results.time_to_criterion[k]),
            reach(results.time_to_criterion_fixed_gap[k])
        )?;
    }
    outln!(
        "{} life steps, {} windows, {:.1} s; wrote {}",
        results.steps.len() - 1,
        results.windows,
        results.wall_time,
        dir.display()
    )?;
    if halvings > 0 {
        convergence(&case, &life, &results, halvings, &dir, plots)
            .map_err(|e| Failure::input(e.in_file(path)))??;
    }
    match &results.end {
        LifeEnd::Completed => Ok(()),
        LifeEnd::Perforated { contact, time } => outln!(
            "the tube at '{contact}' is worn through its wall at {:.4} years: the life stops there",
            time / YEAR
        ),
        LifeEnd::StepLimit => Err(Failure::failed(format!(
            "{}: life: the target was not reached in max_steps = {} life steps: raise life.max_steps or life.max_depth_change (results so far written)",
            path.display(),
            life.max_steps
        ))),
        LifeEnd::ScarLimit {
            contact,
            time,
            message,
        } => Err(Failure::failed(format!(
            "{}: life: at {:.4} years the scar of contact '{contact}' reached the limit of its geometry ({message}); results so far written",
            path.display(),
            time / YEAR
        ))),
        LifeEnd::Diverged {
            window,
            time,
            step,
            contact,
        } => Err(Failure::failed(format!(
            "{}: life: window {window} (at {:.4} years) diverged at step {step}{}; results so far written",
            path.display(),
            time / YEAR,
            contact
                .as_ref()
                .map(|c| format!(", contact '{c}'"))
                .unwrap_or_default()
        ))),
    }
}

/// The life again with `max_depth_change` halved `halvings` times: the tube's depth at the
/// end of each (`convergence.csv`, `convergence.png`), the convergence check of THEORY §14.5.
fn convergence(
    case: &Case,
    life: &fretdyn::apps::life::LifeSettings,
    first: &LifeResults,
    halvings: u32,
    dir: &Path,
    plots: bool,
) -> fretdyn::Result<Result<(), Failure>> {
    let mut fractions = vec![life.max_depth_change];
    let mut depths: Vec<Vec<f64>> = vec![end_depths(first)];
    let mut steps = vec![first.steps.len() - 1];
    for h in 1..=halvings {
        let mut refined = life.clone();
        refined.max_depth_change = life.max_depth_change / f64::from(1u32 << h);
        let r = service_life(case, &refined, |_| {})?;
        if let Err(e) = outln!(
            "max_depth_change = {}: {} life steps, tube depth at the end (m) {}",
            refined.max_depth_change,
            r.steps.len() - 1,
            end_depths(&r)
                .iter()
                .map(|d| format!("{d:.4e}"))
                .collect::<Vec<_>>()
                .join(" ")
        ) {
            return Ok(Err(e));
        }
        fractions.push(refined.max_depth_change);
        depths.push(end_depths(&r));
        steps.push(r.steps.len() - 1);
    }
    let mut csv = String::from("max_depth_change,life_steps");
    for name in &first.contacts {
        let _ = write!(csv, ",{name}.tube_depth");
    }
    csv.push('\n');
    for ((f, n), d) in fractions.iter().zip(&steps).zip(&depths) {
        let _ = write!(csv, "{f:e},{n}");
        for x in d {
            let _ = write!(csv, ",{x:e}");
        }
        csv.push('\n');
    }
    let p = dir.join("convergence.csv");
    if let Err(e) = std::fs::write(&p, csv) {
        return Ok(Err(Failure::failed(format!("{}: {e}", p.display()))));
    }
    if plots {
        // x: the number of halvings, so that the refinements are evenly spaced
        let x: Vec<f64> = (0..fractions.len()).map(|k| k as f64).collect();
        let columns: Vec<Vec<f64>> = (0..first.contacts.len())
            .map(|c| depths.iter().map(|d| d[c]).collect())
            .collect();
        let series: Vec<Series> = first
            .contacts
            .iter()
            .zip(&columns)
            .map(|(name, y)| Series {
                label: name.clone(),
                x: &x,
                y,
            })
            .collect();
        let png = dir.join("convergence.png");
        if let Err(e) = plot::line_plot(
            &png,
            &format!("{}: depth at the end against the life step", case.title),
            &format!("k: max_depth_change = {} / 2^k", life.max_depth_change),
            "tube depth (m)",
            &series,
            false,
        ) {
            return Ok(Err(Failure::failed(format!("{}: {e}", png.display()))));
        }
    }
    Ok(Ok(()))
}

/// Each contact's tube depth at the end of a life.
fn end_depths(r: &LifeResults) -> Vec<f64> {
    r.steps
        .last()
        .map(|s| s.contacts.iter().map(|c| c.tube_depth).collect())
        .unwrap_or_default()
}

fn write(dir: &Path, r: &LifeResults, criterion: Option<f64>) -> Result<(), Failure> {
    let put = |name: &str, text: String| {
        let p = dir.join(name);
        std::fs::write(&p, text).map_err(|e| Failure::failed(format!("{}: {e}", p.display())))
    };
    let mut csv = String::from("time_years");
    for name in &r.contacts {
        for col in [
            "wear_work_rate",
            "wear_work_rate_se",
            "tube_volume",
            "support_volume",
            "tube_depth",
            "support_depth",
            "clearance_increase",
            "tube_depth_fixed_gap",
        ] {
            let _ = write!(csv, ",{name}.{col}");
        }
    }
    csv.push('\n');
    for s in &r.steps {
        let _ = write!(csv, "{:e}", s.time / YEAR);
        for c in &s.contacts {
            let se = c
                .wear_work_rate_se
                .map(|x| format!("{x:e}"))
                .unwrap_or_default();
            let _ = write!(
                csv,
                ",{:e},{se},{:e},{:e},{:e},{:e},{:e},{:e}",
                c.wear_work_rate,
                c.tube_volume,
                c.support_volume,
                c.tube_depth,
                c.support_depth,
                c.clearance_increase,
                c.tube_depth_fixed_gap
            );
        }
        csv.push('\n');
    }
    put("life.csv", csv)?;
    let mut scars = String::from("contact,kind,bin,angle_deg,clearance_increase,tube_depth\n");
    for s in &r.scars {
        let n = s.clearance_increase.len();
        for (b, (a, t)) in s.clearance_increase.iter().zip(&s.tube_depth).enumerate() {
            let angle = if s.kind == "hole" {
                format!("{}", (b as f64 + 0.5) * 360.0 / n as f64)
            } else {
                String::new()
            };
            let _ = writeln!(scars, "{},{},{b},{angle},{a:e},{t:e}", s.contact, s.kind);
        }
    }
    put("scars.csv", scars)?;
    let json = serde_json::json!({
        "criterion_depth": criterion,
        "results": r,
    });
    put(
        "life.json",
        serde_json::to_string_pretty(&json).unwrap_or_default() + "\n",
    )
}

/// Two panels, the tube depth of every contact against service time with the scars fed back
/// and at fixed gap; the criterion drawn when the depths come near it (within 3×).
fn draw(path: &Path, title: &str, r: &LifeResults, criterion: Option<f64>) -> Result<(), String> {
    let years: Vec<f64> = r.steps.iter().map(|s| s.time / YEAR).collect();
    let column = |k: usize, fixed: bool| -> Vec<f64> {
        r.steps
            .iter()
            .map(|s| {
                let c = &s.contacts[k];
                if fixed {
                    c.tube_depth_fixed_gap
                } else {
                    c.tube_depth
                }
            })
            .collect()
    };
    let coupled: Vec<Vec<f64>> = (0..r.contacts.len()).map(|k| column(k, false)).collect();
    let fixed: Vec<Vec<f64>> = (0..r.contacts.len()).map(|k| column(k, true)).collect();
    let deepest = coupled
        .iter()
        .chain(&fixed)
        .flatten()
        .copied()
        .fold(0.0, f64::max);
    let level: Vec<f64> = match criterion {
        Some(c) if deepest >= c / 3.0 => vec![c; years.len()],
        _ => Vec::new(),
    };
    fn panel<'a>(
        label: &str,
        names: &[String],
        years: &'a [f64],
        columns: &'a [Vec<f64>],
        level: &'a [f64],
    ) -> (String, Vec<Series<'a>>) {
        let mut series: Vec<Series> = names
            .iter()
            .zip(columns)
            .map(|(name, y)| Series {
                label: name.clone(),
                x: years,
                y,
            })
            .collect();
        if !level.is_empty() {
            series.push(Series {
                label: "criterion".into(),
                x: years,
                y: level,
            });
        }
        (label.to_string(), series)
    }
    let panels = vec![
        panel(
            "scars fed back into the obstacles",
            &r.contacts,
            &years,
            &coupled,
            &level,
        ),
        panel(
            "fixed gap (the first window's rates)",
            &r.contacts,
            &years,
            &fixed,
            &level,
        ),
    ];
    plot::panels_plot(
        path,
        &format!("{title}: tube wear depth"),
        "service time (years)",
        "depth (m)",
        &panels,
    )
}
