//! `fretdyn life CASE.toml`: the service life of a case with a `[life]` section and contacts
//! with `wear` (THEORY §14.5, docs/WEAR.md) — windows of vibration, scar growth, the scars
//! fed back into the obstacles, until the target time. Writes `life.csv` (one row per life
//! step), `life.json` (the whole result), `scars.csv` (final scar profiles) and `life.png`.
//! The library computes ([`fretdyn::service_life`]); this prints and writes.

use crate::run::significant;
use std::path::{Path, PathBuf};

use fretdyn::Case;
use fretdyn::apps::life::{
    CHECKPOINT_FILE, LifeCheckpoint, LifeControl, LifeEnd, LifeResults, LifeStep, Unresumable,
    YEAR, convergence_csv, end_depths, service_life_with,
};
use fretdyn::error::number;

use crate::Failure;
pub use fretdyn::apps::life::MAX_HALVINGS;

use crate::out::{errln, outln};
use crate::plot::{self, Layout, Mark, Panel, Series, YScale};

/// Options of `fretdyn life`.
pub struct Options {
    pub case: Option<PathBuf>,
    pub resume: Option<PathBuf>,
    pub output: Option<PathBuf>,
    pub plots: bool,
    pub halvings: u32,
    /// Wall-clock seconds between checkpoints inside a window.
    pub checkpoint_seconds: f64,
}

/// Entry point of `fretdyn life`.
pub fn main(o: &Options) -> Result<(), Failure> {
    let (path, dir) = match (&o.case, &o.resume) {
        (Some(path), None) => {
            let dir = o.output.clone().unwrap_or_else(|| default_dir(path));
            (path.clone(), dir)
        }
        (None, Some(dir)) => (recorded_case(dir)?, dir.clone()),
        _ => {
            return Err(Failure::input(
                "give either a case file or --resume DIR (the folder knows its case file)",
            ));
        }
    };
    let case = Case::from_file(&path).map_err(|e| Failure::input(e.in_file(&path)))?;
    for w in &case.warnings {
        errln!("warning: {w}");
    }
    let Some(life) = case.life.clone() else {
        return Err(Failure::input(format!(
            "{}: life: the case has no [life] section: add one with target_years (docs/WEAR.md)",
            path.display()
        )));
    };
    let (fingerprint, _) = crate::run::fingerprint_of(&path)?;
    // a case that cannot have a life, or cannot start its first window, is refused before
    // anything is written
    fretdyn::apps::life::check_life(&case, &life).map_err(|e| Failure::input(e.in_file(&path)))?;
    crate::run::check_start(&case, &path)?;
    let _lock = crate::folder::lock(&dir, "life")?;
    let checkpoint = dir.join(CHECKPOINT_FILE);
    let resume = match &o.resume {
        Some(_) => Some(read_checkpoint(&dir, &path, fingerprint)?),
        None => {
            fretdyn::apps::life::start_afresh(&dir, fingerprint, Some(&path))
                .map_err(|e| Failure::failed(e.to_string()))?;
            None
        }
    };
    let window = case.settings.steps as f64 * case.settings.dt;
    outln!(
        "{}: service life to {} years, windows of {} s, depth change ≤ {} per step{}",
        case.title,
        number(life.target / YEAR),
        number(window),
        number(life.max_depth_change),
        if life.feedback {
            ""
        } else {
            " (fixed gap: no feedback)"
        }
    )?;
    if let Some(r) = &resume {
        outln!(
            "  resumed from its checkpoint at {:.4} years",
            r.time() / YEAR
        )?;
    }
    let _keeping = crate::signals::Keeping::start();
    let mut control = LifeControl {
        checkpoint: Some(&checkpoint),
        checkpoint_every_seconds: o.checkpoint_seconds,
        fingerprint,
        resume,
        stop: Some(&crate::signals::INTERRUPTED),
    };
    // the wearing contacts, in the order of the life's rows: a column each, headed by its name
    let names: Vec<&str> = (case.model.contacts.iter().zip(&case.model.wear))
        .filter(|(_, w)| w.is_some())
        .map(|(c, _)| c.name.as_str())
        .collect();
    let width = names
        .iter()
        .map(|n| n.chars().count())
        .max()
        .unwrap_or(0)
        .max(9);
    let mut printed = outln!(
        "  {:>10}  tube depth (µm): {}",
        "years",
        names
            .iter()
            .map(|n| format!("{n:>width$}"))
            .collect::<Vec<_>>()
            .join(" ")
    );
    let results = service_life_with(&case, &life, &mut control, |step: &LifeStep| {
        if printed.is_ok() && step.time > 0.0 {
            let depths: Vec<String> = step
                .contacts
                .iter()
                .map(|c| format!("{:>width$}", significant(c.tube_depth * 1e6, 4)))
                .collect();
            printed = outln!(
                "  {:>10.4}                   {}",
                step.time / YEAR,
                depths.join(" ")
            );
        }
    })
    .map_err(|e| match e {
        fretdyn::Error::Io { .. } => Failure::failed(format!(
            "{}: {e}; once fixed (room on the disk), continue the life with: fretdyn life --resume {}",
            path.display(),
            dir.display()
        )),
        e => Failure::input(e.in_file(&path)),
    })?;
    printed?;
    fretdyn::apps::life::write_life(&dir, &case.title, &results, life.criterion).map_err(|e| {
        if checkpoint.exists() {
            Failure::failed(format!(
                "{e}; the life is kept in its checkpoint: once there is room on the disk, write its results with: fretdyn life --resume {}",
                dir.display()
            ))
        } else {
            Failure::failed(e.to_string())
        }
    })?;
    if o.plots {
        draw_folder(&dir).map_err(Failure::failed)?;
    }
    for (k, name) in results.contacts.iter().enumerate() {
        let last = &results.steps[results.steps.len() - 1].contacts[k];
        let reach = |t: Option<f64>| {
            t.map_or_else(
                || "not reached".into(),
                |t| format!("{:.3} years", t / YEAR),
            )
        };
        let um = |depth: f64| significant(depth * 1e6, 4);
        outln!(
            "{name}: tube depth {} µm (fixed gap {} µm), support {} µm; criterion {} (fixed gap {})",
            um(last.tube_depth),
            um(last.tube_depth_fixed_gap),
            um(last.support_depth),
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
    if !matches!(results.end, LifeEnd::Stopped { .. }) {
        // the life is over: nothing to resume
        let _ = std::fs::remove_file(&checkpoint);
    }
    let source = path.display();
    let end = match &results.end {
        LifeEnd::Completed => Ok(()),
        LifeEnd::Perforated { contact, time } => outln!(
            "the tube at '{contact}' is worn through its wall at {}: the life stops there",
            when(*time)
        ),
        LifeEnd::StepLimit => Err(Failure::failed(format!(
            "{source}: life: the target was not reached in max_steps = {} life steps (at {}): raise life.max_steps or life.max_depth_change (results so far written)",
            life.max_steps,
            when(results.steps.last().map_or(0.0, |s| s.time))
        ))),
        LifeEnd::ScarLimit {
            contact,
            time,
            message,
        } => Err(Failure::failed(format!(
            "{source}: life: at {} the scar of contact '{contact}' reached the limit of its geometry ({message}); results so far written",
            when(*time)
        ))),
        LifeEnd::StepTooShort {
            contact,
            time,
            step,
            depth,
        } => Err(Failure::failed(format!(
            "{source}: life: at {}, tube depth {depth:.4e} m, the life step that keeps the depth change of contact '{contact}' within life.max_depth_change is {step:.3e} s, below what the service time resolves there (t + Δt = t): the depth grows too fast there to be followed to {} years; raise life.max_depth_change or life.depth_resolution, or shorten life.target_years (results so far written)",
            when(*time),
            number(life.target / YEAR)
        ))),
        LifeEnd::Diverged {
            window,
            time,
            step,
            contact,
        } => Err(Failure::failed(format!(
            "{source}: life: window {window} (at {}) diverged at step {step}{}; results so far written",
            when(*time),
            contact
                .as_ref()
                .map(|c| format!(", contact '{c}'"))
                .unwrap_or_default()
        ))),
        LifeEnd::Stopped { time } => Err(Failure::failed(format!(
            "{source}: life: interrupted at {}; the results up to then are in {}; continue it with: fretdyn life --resume {}",
            when(*time),
            dir.display(),
            dir.display()
        ))),
    };
    end?;
    if o.halvings > 0 {
        convergence(&case, &life, &results, o.halvings, &dir, o.plots)
            .map_err(|e| Failure::input(e.in_file(&path)))??;
    }
    Ok(())
}

/// The folder a life writes in when not told: `life/` inside the folder `fretdyn run` of the
/// same case writes in (`fretdyn_results/<case name>/life`), so that a case's run and life sit
/// together, neither overwrites the other, and a case named `*_life.toml` does not get a
/// doubled `_life_life` suffix.
pub fn default_dir(case: &Path) -> PathBuf {
    crate::run::default_dir("case", case).join("life")
}

/// The case file of the life in `dir` (`life_run.json`), for `--resume`.
fn recorded_case(dir: &Path) -> Result<PathBuf, Failure> {
    fretdyn::apps::life::recorded_case_file(dir)
        .map(Option::unwrap_or_default)
        .map_err(|e| {
            Failure::input(format!(
                "{e} (--resume needs a folder written by fretdyn life CASE)"
            ))
        })
}

/// The checkpoint to resume the life in `dir` from: refused when the case (or a file it
/// reads) changed since the life started, or when there is none.
fn read_checkpoint(dir: &Path, path: &Path, fingerprint: u64) -> Result<LifeCheckpoint, Failure> {
    fretdyn::apps::life::resume_checkpoint(dir, fingerprint).map_err(|why| {
        Failure::input(match why {
            Unresumable::Changed => format!(
                "{}: the case file or a file it reads changed since the life in {} started; start the life again instead of resuming it: fretdyn life {} -o {}",
                path.display(),
                dir.display(),
                path.display(),
                dir.display()
            ),
            Unresumable::NoCheckpoint => format!(
                "{}: no checkpoint to resume: the life there is over (life.json says how it ended) or stopped before its first checkpoint; start it again: fretdyn life {} -o {}",
                dir.display(),
                path.display(),
                dir.display()
            ),
            Unresumable::OtherInputs(checkpoint) => format!(
                "{}: written for other inputs than {} has now; start the life again: fretdyn life {} -o {}",
                checkpoint.display(),
                path.display(),
                path.display(),
                dir.display()
            ),
            Unresumable::Unreadable(e) => e.to_string(),
        })
    })
}

/// A service time in a message: in years, or in seconds when below a hundredth of a year.
fn when(t: f64) -> String {
    if t == 0.0 || t >= 0.01 * YEAR {
        format!("{:.4} years", t / YEAR)
    } else {
        format!("{t:.4e} s")
    }
}

/// The life again with `max_depth_change` halved `halvings` times: the tube's depth at the
/// end of each (`convergence.csv`, `convergence.png`), the convergence check of THEORY §14.5.
/// Each row says how its life ended and when: a life cut short (a step limit, a divergence, a
/// scar at its limit) is marked, not taken for one that reached the target, and fails the
/// command once the table is written. Ctrl-C or SIGTERM stops the refinements (no table).
fn convergence(
    case: &Case,
    life: &fretdyn::LifeSettings,
    first: &LifeResults,
    halvings: u32,
    dir: &Path,
    plots: bool,
) -> fretdyn::Result<Result<(), Failure>> {
    let mut fractions = vec![life.max_depth_change];
    let mut lives: Vec<LifeResults> = vec![first.clone()];
    for h in 1..=halvings.min(MAX_HALVINGS) {
        let mut refined = life.clone();
        refined.max_depth_change = life.max_depth_change / f64::from(1u32 << h);
        let mut control = LifeControl {
            stop: Some(&crate::signals::INTERRUPTED),
            ..LifeControl::default()
        };
        let r = service_life_with(case, &refined, &mut control, |_| {})?;
        if let LifeEnd::Stopped { time } = r.end {
            return Ok(Err(Failure::failed(format!(
                "life: interrupted in the life with max_depth_change = {} at {:.4} years; the life itself is in {}, the convergence check was not written (run it again with --halvings)",
                refined.max_depth_change,
                time / YEAR,
                dir.display()
            ))));
        }
        if let Err(e) = outln!(
            "max_depth_change = {}: {} life steps, {}, tube depth at the end (µm) {}",
            refined.max_depth_change,
            r.steps.len() - 1,
            r.end.name(),
            end_depths(&r)
                .iter()
                .map(|d| significant(d * 1e6, 4))
                .collect::<Vec<_>>()
                .join(" ")
        ) {
            return Ok(Err(e));
        }
        fractions.push(refined.max_depth_change);
        lives.push(r);
    }
    let rows: Vec<(f64, &LifeResults)> = fractions.iter().copied().zip(&lives).collect();
    let csv = convergence_csv(&first.contacts, &rows);
    let p = dir.join("convergence.csv");
    if let Err(e) = fretdyn::files::write_text_atomically(&p, &csv) {
        return Ok(Err(Failure::failed(e.to_string())));
    }
    if plots {
        // x: the number of halvings, so that the refinements are evenly spaced; only the
        // lives that reached their end
        let finished: Vec<usize> = (0..lives.len())
            .filter(|&k| lives[k].end.is_finished())
            .collect();
        let x: Vec<f64> = finished.iter().map(|&k| k as f64).collect();
        let columns: Vec<Vec<f64>> = (0..first.contacts.len())
            .map(|c| finished.iter().map(|&k| end_depths(&lives[k])[c]).collect())
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
    let short: Vec<String> = fractions
        .iter()
        .zip(&lives)
        .filter(|(_, r)| !r.end.is_finished())
        .map(|(f, r)| format!("max_depth_change = {f} ({})", r.end.name()))
        .collect();
    if !short.is_empty() {
        return Ok(Err(Failure::failed(format!(
            "life: the convergence check is incomplete: {} did not reach the target (marked in {}); their depths are not those at the target",
            short.join(", "),
            p.display()
        ))));
    }
    if let [.., before, after] = &lives[..]
        && let Some(w) = unconverged(&first.contacts, &end_depths(before), &end_depths(after))
    {
        errln!("warning: {w}");
    }
    Ok(Ok(()))
}

/// Largest relative change of the deepest scar's depth at the last halving of `--halvings`
/// that still counts as converged: one window's wear work rate has a standard error of
/// 5–16 % at the loaded plates of `examples/tube_multispan_life.toml` (docs/WEAR.md), and a
/// depth goes as the volume to the power 2/3 or less, so that a smaller change is noise.
pub const CONVERGED_CHANGE: f64 = 0.05;

/// The warning when the last halving changed the depth of the deepest scar (in `after`,
/// the finer life) by more than [`CONVERGED_CHANGE`]; lightly worn contacts are left out:
/// their depths move by ±10 % with the windows' noise, whatever the life step.
fn unconverged(names: &[String], before: &[f64], after: &[f64]) -> Option<String> {
    let (k, deepest) = after
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let change = (deepest - before[k]) / deepest;
    (deepest > 0.0 && change.abs() > CONVERGED_CHANGE).then(|| {
        format!(
            "life: the last halving of max_depth_change changed the depth of the deepest scar ('{}') by {:+.1} % ({} to {} µm), more than {} %: the life is not converged; lower life.max_depth_change",
            names[k],
            100.0 * change,
            significant(before[k] * 1e6, 4),
            significant(deepest * 1e6, 4),
            100.0 * CONVERGED_CHANGE
        )
    })
}

/// A life's table as `life.csv` gives it, per contact: the tube depth with the scars fed back
/// and at fixed gap, the wear work rate of each window and its standard error.
pub struct LifeTable {
    pub years: Vec<f64>,
    pub contacts: Vec<String>,
    pub depth: Vec<Vec<f64>>,
    pub fixed: Vec<Vec<f64>>,
    pub rate: Vec<Vec<f64>>,
    pub rate_se: Vec<Vec<f64>>,
}

impl LifeTable {
    /// Reads `life.csv` (an empty standard error: 0).
    pub fn read(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
        if header.first() != Some(&"time_years") {
            return Err(format!(
                "{}: not a life table of fretdyn life (no time_years column)",
                path.display()
            ));
        }
        let contacts: Vec<String> = header
            .iter()
            .filter_map(|h| h.strip_suffix(".tube_depth").map(str::to_string))
            .collect();
        let rows: Vec<Vec<f64>> = lines
            .filter(|l| !l.trim().is_empty())
            .map(|l| l.split(',').map(|c| c.parse().unwrap_or(0.0)).collect())
            .collect();
        let column = |name: &str| -> Result<Vec<f64>, String> {
            let i = header
                .iter()
                .position(|h| *h == name)
                .ok_or_else(|| format!("{}: no column {name}", path.display()))?;
            Ok(rows
                .iter()
                .map(|r| r.get(i).copied().unwrap_or(0.0))
                .collect())
        };
        let per = |col: &str| -> Result<Vec<Vec<f64>>, String> {
            contacts
                .iter()
                .map(|c| column(&format!("{c}.{col}")))
                .collect()
        };
        Ok(Self {
            years: column("time_years")?,
            depth: per("tube_depth")?,
            fixed: per("tube_depth_fixed_gap")?,
            rate: per("wear_work_rate")?,
            rate_se: per("wear_work_rate_se")?,
            contacts,
        })
    }

    /// The first-order standard error of each depth of contact `k`, with the scars fed back
    /// and at fixed gap ([`fretdyn::apps::life::depth_standard_errors`]).
    pub fn depth_se(&self, k: usize) -> (Vec<f64>, Vec<f64>) {
        fretdyn::apps::life::depth_standard_errors(
            &self.depth[k],
            &self.fixed[k],
            &self.rate[k],
            &self.rate_se[k],
        )
    }
}

/// `life.png` of the life in `dir`, from its `life.csv` and `life.json`: two panels (the
/// tube depth of every contact against service time with the scars fed back, and at fixed
/// gap) on the same y limits, each depth with a band of ± its standard error
/// ([`LifeTable::depth_se`]) and the plugging criterion of `life.json` as a line.
pub fn draw_folder(dir: &Path) -> Result<PathBuf, String> {
    let table = LifeTable::read(&dir.join("life.csv"))?;
    let json_path = dir.join("life.json");
    let json: serde_json::Value = std::fs::read_to_string(&json_path)
        .map_err(|e| e.to_string())
        .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
        .map_err(|e| format!("{}: {e}", json_path.display()))?;
    let criterion = json["criterion_depth"].as_f64();
    let title = json["title"].as_str().map_or_else(
        || {
            dir.file_name()
                .map_or("life".into(), |n| n.to_string_lossy().into_owned())
        },
        str::to_string,
    );
    let path = dir.join("life.png");
    draw(&path, &title, &table, criterion)?;
    Ok(path)
}

fn draw(path: &Path, title: &str, t: &LifeTable, criterion: Option<f64>) -> Result<(), String> {
    let errors: Vec<(Vec<f64>, Vec<f64>)> = (0..t.contacts.len()).map(|k| t.depth_se(k)).collect();
    // the criterion as a line when the depths come near it (within 3×, else it would flatten
    // them), else in the title
    let deepest = t
        .depth
        .iter()
        .chain(&t.fixed)
        .flatten()
        .copied()
        .fold(0.0, f64::max);
    let (marks, beyond): (Vec<Mark>, String) = match criterion {
        Some(c) if deepest >= c / 3.0 => (
            vec![Mark::Level {
                label: "plugging criterion".into(),
                y: c,
            }],
            String::new(),
        ),
        Some(c) => {
            let (unit, factor) = plot::unit_for("depth (m)", c);
            (
                Vec::new(),
                format!(
                    ", plugging criterion {} {unit}, far above",
                    plot::significant(c / factor, 3)
                ),
            )
        }
        None => (Vec::new(), String::new()),
    };
    fn panel<'a>(
        caption: &str,
        t: &'a LifeTable,
        columns: &'a [Vec<f64>],
        errors: Vec<Vec<f64>>,
        marks: &[Mark],
    ) -> Panel<'a> {
        Panel {
            title: caption.to_string(),
            series: t
                .contacts
                .iter()
                .zip(columns)
                .map(|(name, y)| Series {
                    label: name.clone(),
                    x: &t.years,
                    y,
                })
                .collect(),
            errors,
            marks: marks.to_vec(),
        }
    }
    let (coupled, fixed): (Vec<Vec<f64>>, Vec<Vec<f64>>) = errors.into_iter().unzip();
    let panels = vec![
        panel(
            "scars fed back into the obstacles",
            t,
            &t.depth,
            coupled,
            &marks,
        ),
        panel(
            "fixed gap (the first window's rates)",
            t,
            &t.fixed,
            fixed,
            &marks,
        ),
    ];
    plot::stacked(
        path,
        &format!("{title}: tube wear depth (± standard error{beyond})"),
        "service time (years)",
        "depth (m)",
        &panels,
        &Layout {
            same_y_unit: true,
            same_y_limits: true,
            y_scale: YScale::Linear,
            bands: true,
            ..Layout::default()
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_last_halving_warns_when_the_deepest_scar_moved_by_more_than_the_tolerance() {
        let names = ["a".to_string(), "b".to_string()];
        // the deepest scar ('b') 19.19 → 21.34 µm: +10.1 %; 'a' moved by 20 % but is shallow
        let w = unconverged(&names, &[5e-6, 19.19e-6], &[6e-6, 21.34e-6]).unwrap();
        assert!(w.contains("'b'") && w.contains("+10.1 %"), "{w}");
        assert!(w.contains("19.19 to 21.34 µm"), "{w}");
        // 21.34 → 21.90 µm: +2.6 %, converged, whatever the shallow scar did
        assert_eq!(
            unconverged(&names, &[5e-6, 21.34e-6], &[7e-6, 21.90e-6]),
            None
        );
        // a decrease counts as much as an increase
        assert!(unconverged(&names, &[0.0, 21.0e-6], &[0.0, 19.0e-6]).is_some());
        // no wear at all: nothing to say
        assert_eq!(unconverged(&names, &[0.0, 0.0], &[0.0, 0.0]), None);
    }
}
