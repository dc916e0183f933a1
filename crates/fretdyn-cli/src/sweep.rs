//! `fretdyn sweep STUDY.toml`: a parametric or Monte-Carlo study ([`fretdyn::apps::study`]) on every
//! core, one row per finished run in `study.csv`, a progress bar, a plot of a statistic
//! against a parameter, and for a probabilistic study the percentiles across its samples
//! (`percentiles.csv`, `percentiles.json`, docs/STUDIES.md). Killed midway, run again: the
//! finished rows are kept and skipped.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use fretdyn::Study;
use fretdyn::apps::percentiles::{PercentileReport, PercentileRow};
use fretdyn::apps::study::{CONNORS_COLUMN, StudyOptions, connors_exceedance};
use indicatif::{ProgressBar, ProgressStyle};

use crate::Failure;
use crate::out::{errln, outln};
use crate::plot::{Layout, Mark, Panel, Series, YScale, stacked, unit_for};

/// Most runs at a time (`-j`) on a machine of `cores` cores: four per core, and at least
/// 64 (each is a thread with its own simulation; more only cost their start).
pub fn max_jobs(cores: usize) -> usize {
    (4 * cores).max(64)
}

/// What a study writes in its folder beside its table, from the table: removed before runs
/// are added (so that a stopped study never leaves the figures of an earlier table) and
/// written again at its end.
const DERIVED: [&str; 5] = [
    "percentiles.csv",
    "percentiles.json",
    "percentiles.png",
    "study.png",
    FIGURES_FILE,
];

/// What a study's figures are drawn from (`study.png`: the parameter on x, the statistic,
/// the columns labelling the lines; `percentiles.png`: the statistic), written beside its
/// table so that `fretdyn plot DIR` draws them again.
pub const FIGURES_FILE: &str = "figures.json";

/// Entry point of `fretdyn sweep`.
pub fn main(
    study: &Path,
    output: Option<PathBuf>,
    jobs: usize,
    fresh: bool,
    quiet: bool,
) -> Result<(), Failure> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if jobs > max_jobs(cores) {
        return Err(Failure::input(format!(
            "--jobs {jobs}: at most {} runs at a time on this machine of {cores} cores (0, the default, runs one per core)",
            max_jobs(cores)
        )));
    }
    let s = Study::from_file(study).map_err(|e| Failure::input(e.in_file(study)))?;
    // every run's case is built and checked before anything is run or written
    let warnings = s
        .check(jobs)
        .map_err(|e| Failure::input(format!("{}; nothing was run", e.in_file(study))))?;
    let runs = s.runs().len();
    for (w, n) in &warnings {
        let which = if *n == runs {
            "every run".to_string()
        } else {
            format!("{n} of {runs} runs")
        };
        errln!("warning: {} ({which}): {w}", study.display());
    }
    let dir = output.unwrap_or_else(|| {
        let stem = study
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "study".into());
        PathBuf::from("fretdyn_results").join(stem)
    });
    let _lock = crate::folder::lock(&dir, "sweep")?;
    let table = dir.join("study.csv");
    let total = s.runs().len();
    let bar = Mutex::new(None::<ProgressBar>);
    let start = std::time::Instant::now();
    let progress = |done: usize, pending: usize| {
        if quiet {
            return;
        }
        let mut b = bar.lock().unwrap_or_else(|e| e.into_inner());
        let bar = b.get_or_insert_with(|| {
            let bar = ProgressBar::new(pending as u64);
            bar.set_style(
                ProgressStyle::with_template("{prefix} [{bar:40}] {pos}/{len} runs, {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> "),
            );
            bar.set_prefix("sweep");
            bar
        });
        bar.set_position(done as u64);
        let per_run = start.elapsed().as_secs_f64() / done.max(1) as f64;
        bar.set_message(format!("{:.0} s left", per_run * (pending - done) as f64));
        if done == pending {
            bar.finish_and_clear();
        }
    };
    let keeping = crate::signals::Keeping::start();
    let options = StudyOptions {
        jobs,
        fresh,
        stop: Some(&crate::signals::INTERRUPTED),
    };
    let mut table_file = s
        .open_table(&table, options.fresh)
        .map_err(|e| Failure::input(e.in_file(study)))?;
    if !table_file.pending().is_empty() {
        for name in DERIVED {
            let _ = std::fs::remove_file(dir.join(name));
        }
    }
    let outcome = s
        .run_on(&mut table_file, &options, &progress)
        .map_err(|e| Failure::failed(e.in_file(study)))?;
    drop(table_file);
    drop(keeping);
    if let Some(b) = bar.lock().unwrap_or_else(|e| e.into_inner()).take() {
        b.finish_and_clear();
    }
    let wall = start.elapsed().as_secs_f64();
    if outcome.stopped {
        return Err(Failure::failed(format!(
            "{}: interrupted: {} runs done now, {} of {total} in {} (the runs under way were dropped; no percentiles or plots of an incomplete study); continue it with: fretdyn sweep {} -o {}",
            study.display(),
            outcome.done,
            outcome.already + outcome.done,
            table.display(),
            study.display(),
            dir.display()
        )));
    }
    let done = outcome.done;
    // one line for the whole study, not one per mode per run (docs/FLOW.md)
    if let Some(e) = connors_exceedance(&table).map_err(|e| Failure::failed(e.to_string()))? {
        errln!(
            "warning: {}: {} of {} runs have a mode above its Connors critical velocity (largest U_eff/U_c = {:.4}, run {}): fluid-elastic instability expected, see the column {CONNORS_COLUMN} of {}",
            study.display(),
            e.runs,
            e.of,
            e.largest.0,
            e.largest.1,
            table.display()
        );
    }
    // what the figures are drawn from, for `fretdyn plot DIR`
    let mut figures = serde_json::json!({});
    if let Some(plot) = &s.plot {
        // the lines are labelled by the values parameters and the seed, not by the draws
        let labels: Vec<String> = s
            .columns()
            .into_iter()
            .filter(|c| s.parameters[c.parameter].distribution.is_none())
            .map(|c| c.key)
            .chain(["seed".to_string()])
            .collect();
        plot_table(
            &table,
            &plot.x,
            &plot.statistic,
            &labels,
            YScale::Auto,
            &dir.join("study.png"),
        )?;
        figures["study"] = serde_json::json!({
            "x": plot.x,
            "statistic": plot.statistic,
            "labels": labels,
        });
    }
    // percentiles across the samples, from the table (docs/STUDIES.md)
    let report = s
        .percentiles(&table)
        .map_err(|e| Failure::failed(e.in_file(study)))?;
    if let Some(report) = &report {
        report
            .write(&dir)
            .map_err(|e| Failure::failed(e.to_string()))?;
        if let Some(statistic) = s.percentiles.as_ref().and_then(|p| p.statistics.first()) {
            plot_percentiles(&table, report, statistic, &dir.join("percentiles.png"))?;
            figures["percentiles"] = serde_json::json!({ "statistic": statistic });
        }
    }
    if figures.as_object().is_some_and(|f| !f.is_empty()) {
        let p = dir.join(FIGURES_FILE);
        fretdyn::files::write_text_atomically(&p, &format!("{figures:#}\n"))
            .map_err(|e| Failure::failed(e.to_string()))?;
    }
    if !quiet {
        outln!(
            "{}: {done} runs in {wall:.2} s ({} already in the table), results in {}",
            study.display(),
            total - done,
            table.display()
        )?;
        if let Some(report) = &report {
            outln!(
                "percentiles ({} rows, {:.0} % distribution-free intervals, bootstrap standard errors) in {}",
                report.rows.len(),
                100.0 * report.confidence,
                dir.join("percentiles.csv").display()
            )?;
        }
    }
    Ok(())
}

/// A line of the plot: its label, x and y values.
type Line = (String, Vec<f64>, Vec<f64>);

/// One panel per contact: `statistic` against the parameter `x`, one line per combination
/// of the other `labels` columns (the `values` parameters and the seed).
pub fn plot_table(
    table: &Path,
    x: &str,
    statistic: &str,
    labels: &[String],
    y_scale: YScale,
    path: &Path,
) -> Result<(), Failure> {
    let text = std::fs::read_to_string(table)
        .map_err(|e| Failure::failed(format!("{}: {e}", table.display())))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let rows: Vec<Vec<&str>> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|r| r.len() == header.len())
        .collect();
    let xi = header.iter().position(|h| *h == x).unwrap_or(1);
    let status = header.iter().position(|h| *h == "status").unwrap_or(0);
    // the other parameters and the seed label the lines
    // (only those that vary)
    let others: Vec<usize> = (1..status)
        .filter(|&i| i != xi && labels.iter().any(|l| l == header[i]))
        .filter(|&i| rows.iter().any(|r| r[i] != rows[0][i]))
        .collect();
    let contacts: Vec<(String, usize)> = header
        .iter()
        .enumerate()
        .filter_map(|(i, h)| {
            h.strip_suffix(&format!(".{statistic}"))
                .map(|c| (c.to_string(), i))
        })
        .collect();
    let mut data: Vec<(String, Vec<Line>)> = Vec::new();
    // the standard errors of the points, line by line, panel by panel (± bars)
    let mut errors: Vec<Vec<Vec<f64>>> = Vec::new();
    for (contact, col) in &contacts {
        let se_col = header
            .iter()
            .position(|h| *h == format!("{contact}.{statistic}_se"));
        let mut lines: Vec<Line> = Vec::new();
        let mut line_errors: Vec<Vec<f64>> = Vec::new();
        let mut sorted = rows.clone();
        sorted.sort_by(|a, b| {
            let (p, q) = (a[xi].parse::<f64>(), b[xi].parse::<f64>());
            match (p, q) {
                (Ok(p), Ok(q)) => p.total_cmp(&q),
                _ => a[xi].cmp(b[xi]),
            }
        });
        for r in &sorted {
            let label = others
                .iter()
                .map(|&i| parameter_value(header[i], r[i]))
                .collect::<Vec<_>>()
                .join(", ");
            let (Ok(xv), Ok(yv)) = (r[xi].parse::<f64>(), r[*col].parse::<f64>()) else {
                continue;
            };
            let ev = se_col.and_then(|i| r[i].parse::<f64>().ok()).unwrap_or(0.0);
            match lines.iter().position(|l| l.0 == label) {
                Some(i) => {
                    lines[i].1.push(xv);
                    lines[i].2.push(yv);
                    line_errors[i].push(ev);
                }
                None => {
                    lines.push((label, vec![xv], vec![yv]));
                    line_errors.push(vec![ev]);
                }
            }
        }
        data.push((contact.clone(), lines));
        errors.push(line_errors);
    }
    let y_label = statistic_label(statistic);
    let panels: Vec<(String, Vec<Series>)> = data
        .iter()
        .map(|(c, lines)| {
            (
                c.clone(),
                lines
                    .iter()
                    .map(|(label, x, y)| Series {
                        label: if label.is_empty() {
                            y_label.clone()
                        } else {
                            label.clone()
                        },
                        x,
                        y,
                    })
                    .collect(),
            )
        })
        .collect();
    let (y_name, _) = statistic_name(statistic);
    let panels: Vec<Panel> = panels
        .into_iter()
        .zip(errors)
        .map(|((title, series), errors)| Panel {
            title,
            series,
            errors,
            marks: Vec::new(),
        })
        .collect();
    // the contacts' panels are compared: one unit; a log axis when the values span decades
    stacked(
        path,
        &format!("{} against {x} (± standard error)", capitalised(&y_name)),
        &parameter_label(x),
        &y_label,
        &panels,
        &Layout {
            same_y_unit: true,
            y_scale,
            ..Layout::default()
        },
    )
    .map_err(Failure::failed)
}

/// One panel per column of `statistic` (per contact): the empirical distribution function of
/// the completed runs' values (one line per group of the report), and each percentile of the
/// report as a vertical segment up to its level, labelled with its interval.
pub fn plot_percentiles(
    table: &Path,
    report: &PercentileReport,
    statistic: &str,
    path: &Path,
) -> Result<(), Failure> {
    let text = std::fs::read_to_string(table)
        .map_err(|e| Failure::failed(format!("{}: {e}", table.display())))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let rows: Vec<Vec<&str>> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|r| r.len() == header.len())
        .collect();
    let at = |name: &str| header.iter().position(|h| *h == name);
    let Some(status) = at("status") else {
        return Ok(());
    };
    let mut columns: Vec<&str> = Vec::new();
    for r in &report.rows {
        let per_contact = r.column.ends_with(&format!(".{statistic}")) || r.column == statistic;
        if per_contact && !columns.contains(&r.column.as_str()) {
            columns.push(&r.column);
        }
    }
    // (x, y) of every line, kept alive for the borrowed series, and the percentiles' marks
    let mut data: Vec<(String, Vec<Line>, Vec<&PercentileRow>)> = Vec::new();
    for column in &columns {
        let Some(col) = at(column) else { continue };
        let mut lines = Vec::new();
        let mut marks = Vec::new();
        let mut groups: Vec<&Vec<(String, String)>> = Vec::new();
        for r in report.rows.iter().filter(|r| r.column == *column) {
            if !groups.contains(&&r.group) {
                groups.push(&r.group);
            }
        }
        for group in groups {
            let mut x: Vec<f64> = rows
                .iter()
                .filter(|r| r[status] == "completed")
                .filter(|r| group.iter().all(|(k, v)| at(k).is_some_and(|i| r[i] == v)))
                .filter_map(|r| r[col].parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .collect();
            x.sort_by(f64::total_cmp);
            let n = x.len() as f64;
            let y: Vec<f64> = (1..=x.len()).map(|i| i as f64 / n).collect();
            lines.push((group_prefix(group, x.len()), x, y));
            marks.extend(
                report
                    .rows
                    .iter()
                    .filter(|r| r.column == *column && &r.group == group && r.estimate.is_finite()),
            );
        }
        let contact = column
            .strip_suffix(&format!(".{statistic}"))
            .unwrap_or(column);
        data.push((contact.to_string(), lines, marks));
    }
    // the values in the legend in the x axis' unit: one prefix for every panel
    let x_label = statistic_label(statistic);
    let magnitude = data
        .iter()
        .flat_map(|(_, lines, marks)| {
            lines
                .iter()
                .flat_map(|l| l.1.iter().copied())
                .chain(marks.iter().flat_map(|r| {
                    [Some(r.estimate), r.ci_low, r.ci_high]
                        .into_iter()
                        .flatten()
                }))
        })
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let (unit, factor) = unit_for(&x_label, magnitude);
    let value = |x: f64| {
        let v = format!("{:.3}", x / factor);
        if unit.is_empty() {
            v
        } else {
            format!("{v} {unit}")
        }
    };
    let groups = |marks: &[&PercentileRow]| {
        let mut g: Vec<&Vec<(String, String)>> = marks.iter().map(|r| &r.group).collect();
        g.dedup();
        g.len()
    };
    let panels: Vec<Panel> = data
        .iter()
        .map(|(c, lines, marks)| {
            let several = groups(marks) > 1;
            Panel {
                title: c.clone(),
                series: lines
                    .iter()
                    .map(|(label, x, y)| Series {
                        label: label.clone(),
                        x,
                        y,
                    })
                    .collect(),
                errors: Vec::new(),
                marks: marks
                    .iter()
                    .map(|r| {
                        let prefix = if several {
                            format!("{}: ", group_label(&r.group))
                        } else {
                            String::new()
                        };
                        let bound = |b: Option<f64>| b.map_or("–".to_string(), value);
                        Mark::Percentile {
                            label: format!(
                                "{prefix}P{} = {} [{}, {}]",
                                r.level,
                                value(r.estimate),
                                bound(r.ci_low),
                                bound(r.ci_high)
                            ),
                            x: r.estimate,
                            level: r.level / 100.0,
                            low: r.ci_low,
                            high: r.ci_high,
                        }
                    })
                    .collect(),
            }
        })
        .collect();
    let (name, _) = statistic_name(statistic);
    stacked(
        path,
        &format!(
            "Distribution of the {name} over the samples, percentiles with their {:.0} % intervals",
            100.0 * report.confidence
        ),
        &x_label,
        "fraction of the runs ≤ x",
        &panels,
        &Layout {
            y_scale: YScale::Linear,
            x_magnitude: Some(magnitude),
            ..Layout::default()
        },
    )
    .map_err(Failure::failed)
}

/// The legend words of a group of runs: `clearance = 0.0002 m, mu = 0.3`.
fn group_label(group: &[(String, String)]) -> String {
    group
        .iter()
        .map(|(k, v)| parameter_value(k, v))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The label of a group's distribution function: `<group>: 40 runs`.
fn group_prefix(group: &[(String, String)], runs: usize) -> String {
    if group.is_empty() {
        format!("{runs} runs")
    } else {
        format!("{}: {runs} runs", group_label(group))
    }
}

fn capitalised(s: &str) -> String {
    let mut chars = s.chars();
    chars
        .next()
        .map(|c| c.to_uppercase().chain(chars).collect())
        .unwrap_or_default()
}

/// Axis label `quantity (unit)` from a name and a unit (none: the name alone).
fn with_unit(name: String, unit: &str) -> String {
    if unit.is_empty() {
        name
    } else {
        format!("{name} ({unit})")
    }
}

/// A readable name of a parameter key of a study (a dotted path in the case: a number picks
/// an array element, `*` every element), and its unit in base SI ("" when dimensionless or not
/// a number): `contacts.*.obstacle.clearance` → (`clearance, every contact`, `m`),
/// `contacts[0].normal.stiffness` → (`normal stiffness, contact 0`, `N/m`).
fn parameter_name(key: &str) -> (String, &'static str) {
    let normalised = key.replace('[', ".").replace(']', "");
    let segments: Vec<&str> = normalised.split('.').filter(|s| !s.is_empty()).collect();
    let is_index = |s: &str| s == "*" || s.parse::<usize>().is_ok();
    // where the parameter applies: the innermost array element
    let place = segments.windows(2).rev().find_map(|w| {
        is_index(w[1]).then(|| {
            let singular = w[0].strip_suffix('s').unwrap_or(w[0]).replace('_', " ");
            if w[1] == "*" {
                format!("every {singular}")
            } else {
                format!("{singular} {}", w[1])
            }
        })
    });
    let names: Vec<&str> = segments.iter().copied().filter(|s| !is_index(s)).collect();
    let last = names.last().copied().unwrap_or(key);
    let parent = names.len().checked_sub(2).map(|i| names[i]).unwrap_or("");
    let unit = match last {
        "clearance" | "radius" | "gap" | "mesh_size" | "outer_diameter" | "wall_thickness"
        | "leg_length" | "correlation_length" | "x" => "m",
        "dt" | "duration" | "t_start" | "t_end" | "block" | "rest_duration" => "s",
        "stiffness" | "force_per_length" => "N/m",
        "damping" if parent != "structure" => "N·s/m",
        "young_modulus" => "Pa",
        "density" | "inner_fluid_density" | "outer_fluid_density" => "kg/m³",
        "f_max" | "max_frequency_hz" => "Hz",
        "force" => "N",
        "acceleration" => "m/s²",
        "velocity" | "mean_velocity" | "gap_velocity" => "m/s",
        "lift_slope" | "mu" | "mu_static" | "mu_dynamic" => "",
        _ => "",
    };
    let word = match last {
        "mu" => "friction coefficient".to_string(),
        "mu_static" => "static friction coefficient".to_string(),
        "mu_dynamic" => "dynamic friction coefficient".to_string(),
        "dt" => "time step".to_string(),
        "f_max" => "maximum frequency".to_string(),
        other => other.replace('_', " "),
    };
    // a generic word takes its section's name: normal stiffness, tangential method
    let qualified = match parent {
        "normal" | "penalty" | "tangential" | "gauss_seidel" | "active_set" => {
            format!("{} {word}", parent.replace('_', " "))
        }
        _ => word,
    };
    let name = match place {
        Some(place) => format!("{qualified}, {place}"),
        None => qualified,
    };
    (name, unit)
}

/// Axis label of a parameter key: the key as the study writes it (a path in the case, whose
/// indices are the user's own) and its unit.
fn parameter_label(key: &str) -> String {
    let (_, unit) = parameter_name(key);
    with_unit(key.to_string(), unit)
}

/// `name = value unit` for the legend (the name without where it applies).
fn parameter_value(key: &str, value: &str) -> String {
    let (name, unit) = parameter_name(key);
    let name = name.split(", ").next().unwrap_or(&name).to_string();
    if unit.is_empty() || value.parse::<f64>().is_err() {
        format!("{name} = {value}")
    } else {
        format!("{name} = {value} {unit}")
    }
}

/// Readable name and unit of a statistic of the study table: a per-contact statistic's from
/// the table of statistics ([`fretdyn::accumulate::statistics::STATISTICS`]), a life
/// column's from [`known_life_column`]; another: its key with spaces, no unit.
fn statistic_name(statistic: &str) -> (String, &'static str) {
    match known_statistic(statistic) {
        Some((name, unit)) => (name.to_string(), unit),
        None => (statistic.replace('_', " "), ""),
    }
}

fn known_statistic(statistic: &str) -> Option<(&'static str, &'static str)> {
    fretdyn::accumulate::statistics::statistic(statistic)
        .map(|s| (s.long_name, s.label_unit()))
        .or_else(|| known_life_column(statistic))
}

/// Readable name and unit of a life column of the study table
/// ([`fretdyn::apps::study::LIFE_COLUMNS`]).
fn known_life_column(column: &str) -> Option<(&'static str, &'static str)> {
    Some(match column {
        "depth_at_target" => ("tube depth at the target time", "m"),
        "depth_at_target_fixed_gap" => ("tube depth at the target time, fixed gap", "m"),
        "time_to_criterion" => ("time to the plugging criterion", "years"),
        "time_to_criterion_fixed_gap" => ("time to the plugging criterion, fixed gap", "years"),
        _ => return None,
    })
}

/// Axis label of a statistic: its readable name and unit.
fn statistic_label(statistic: &str) -> String {
    let (name, unit) = statistic_name(statistic);
    with_unit(name, unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn study_axes_are_readable_with_their_unit() {
        // the x axis: the key as the study writes it, never an internal index, and its unit
        assert_eq!(
            parameter_label("contacts.*.obstacle.clearance"),
            "contacts.*.obstacle.clearance (m)"
        );
        assert_eq!(
            parameter_label("flow.zones.0.velocity"),
            "flow.zones.0.velocity (m/s)"
        );
        assert_eq!(
            parameter_label("contacts.2.normal.stiffness"),
            "contacts.2.normal.stiffness (N/m)"
        );
        assert_eq!(
            parameter_label("contacts.*.friction.mu"),
            "contacts.*.friction.mu"
        );
        assert_eq!(parameter_label("time.duration"), "time.duration (s)");
        assert_eq!(parameter_name("time.dt").0, "time step");
        assert_eq!(parameter_name("flow.zones.0.velocity").1, "m/s");
        assert_eq!(
            parameter_value("tangential.method", "gauss_seidel"),
            "tangential method = gauss_seidel"
        );
        assert_eq!(
            parameter_value("contacts.*.obstacle.clearance", "0.0002"),
            "clearance = 0.0002 m"
        );
        assert_eq!(statistic_label("wear_work_rate"), "wear work rate (W)");
        assert_eq!(
            statistic_label("normal_force_max"),
            "maximum normal force (N)"
        );
        // a life study's percentiles: their axis has a unit
        assert_eq!(
            statistic_label("depth_at_target"),
            "tube depth at the target time (m)"
        );
        assert_eq!(
            statistic_label("time_to_criterion_fixed_gap"),
            "time to the plugging criterion, fixed gap (years)"
        );
        for s in fretdyn::apps::study::LIFE_COLUMNS {
            assert!(
                known_statistic(s).is_some_and(|(_, u)| !u.is_empty()),
                "{s}"
            );
        }
        // every statistic of the table has a readable name, and a unit but for a fraction
        for s in fretdyn::apps::study::TABLE_STATISTICS {
            assert!(known_statistic(s).is_some(), "{s}");
        }
        assert_eq!(statistic_label("impacts_per_second"), "impact rate (1/s)");
        assert_eq!(
            statistic_label("contact_time_fraction"),
            "fraction of the time in contact"
        );
    }
}
