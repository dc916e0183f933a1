//! `fretdyn sweep STUDY.toml`: a parametric or Monte-Carlo study ([`fretdyn::study`]) on every
//! core, one row per finished run in `study.csv`, a progress bar, and a plot of a statistic
//! against a parameter. Killed midway, run again: the finished rows are kept and skipped.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use fretdyn::study::Study;
use indicatif::{ProgressBar, ProgressStyle};

use crate::Failure;
use crate::plot::{Series, panels_plot};

/// Entry point of `fretdyn sweep`.
pub fn main(
    study: &Path,
    output: Option<PathBuf>,
    jobs: usize,
    quiet: bool,
) -> Result<(), Failure> {
    let s = Study::from_file(study).map_err(|e| Failure::input(e.in_file(study)))?;
    // every run's case is built and checked before anything is run or written
    s.check(jobs)
        .map_err(|e| Failure::input(format!("{}; nothing was run", e.in_file(study))))?;
    let dir = output.unwrap_or_else(|| {
        let stem = study
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "study".into());
        PathBuf::from("fretdyn_results").join(stem)
    });
    std::fs::create_dir_all(&dir).map_err(|e| {
        Failure::failed(format!("{}: cannot create the folder: {e}", dir.display()))
    })?;
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
    let done = s
        .execute_checked(&table, jobs, &progress)
        .map_err(|e| Failure::failed(e.in_file(study)))?;
    let wall = start.elapsed().as_secs_f64();
    if let Some(plot) = &s.plot {
        plot_table(&table, &plot.x, &plot.statistic, &dir.join("study.png"))?;
    }
    if !quiet {
        println!(
            "{}: {done} runs in {wall:.2} s ({} already in the table), results in {}",
            study.display(),
            total - done,
            table.display()
        );
    }
    Ok(())
}

/// A line of the plot: its label, x and y values.
type Line = (String, Vec<f64>, Vec<f64>);

/// One panel per contact: `statistic` against the parameter `x`, one line per combination
/// of the other parameters and seed.
fn plot_table(table: &Path, x: &str, statistic: &str, path: &Path) -> Result<(), Failure> {
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
        .filter(|&i| i != xi)
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
    for (contact, col) in &contacts {
        let mut lines: Vec<Line> = Vec::new();
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
                .map(|&i| format!("{}={}", header[i], r[i]))
                .collect::<Vec<_>>()
                .join(" ");
            let (Ok(xv), Ok(yv)) = (r[xi].parse::<f64>(), r[*col].parse::<f64>()) else {
                continue;
            };
            match lines.iter_mut().find(|l| l.0 == label) {
                Some(l) => {
                    l.1.push(xv);
                    l.2.push(yv);
                }
                None => lines.push((label, vec![xv], vec![yv])),
            }
        }
        data.push((contact.clone(), lines));
    }
    let panels: Vec<(String, Vec<Series>)> = data
        .iter()
        .map(|(c, lines)| {
            (
                c.clone(),
                lines
                    .iter()
                    .map(|(label, x, y)| Series {
                        label: if label.is_empty() {
                            statistic.to_string()
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
    panels_plot(
        path,
        &format!("{statistic} against {x}"),
        x,
        statistic,
        &panels,
    )
    .map_err(Failure::failed)
}
