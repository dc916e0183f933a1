//! The plots of a run folder, drawn from its files only (`results.npz` — or `series/` of a run
//! not finished —, `summary.json`, `impacts.csv`), so that `fretdyn run` and
//! `fretdyn plot DIR` draw the same pictures:
//! - `contact_forces.png`: normal and tangential force magnitude against time, per contact;
//! - `contact_displacement.png`: the point's displacement at each contact against time (radial
//!   offset from the hole's centre, or distance to the plane);
//! - `orbits.png`: the orbit of the tube centre inside each hole, with the hole's outline;
//! - `peak_forces.png`: histogram of the impacts' peak forces (5 bins a decade, on one
//!   logarithmic force axis for every contact), per contact;
//! - `wear.png`: wear work rate per contact (friction power and `R_N|v_T|` definitions).

use std::path::{Path, PathBuf};

use fretdyn::apps::percentiles::{PercentileReport, PercentileRow};
use ndarray::{Array1, Array2, Array3, Ix1, Ix2, Ix3};
use ndarray_npy::{NpzReader, ReadNpyExt};
use serde_json::Value;

use crate::Failure;
use crate::plot::{
    Bar, Bin, Layout, Mark, Panel, Series, YScale, bar_panels, histogram_panels, panels_plot,
    stacked, xy_panels,
};

/// What a contact's displacement is measured from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Obstacle {
    /// A hole: the radial offset from its centre.
    Hole,
    /// A plane whose face is at `gap` from the plane through its origin.
    Plane { gap: f64 },
    /// Two bars at ±`gap` from their mid-plane.
    Bars { gap: f64 },
    /// Unknown (a summary without the case): the coordinate as written.
    Other,
}

/// The obstacle of contact `k`, from `summary.json`'s geometry and the case echoed in it
/// (`gap` absent: 0, the case's default).
fn obstacle_of(summary: &Value, geometry: &[Value], k: usize) -> Obstacle {
    if geometry.get(k).is_some_and(|g| !g["outline"].is_null()) {
        return Obstacle::Hole;
    }
    let name = geometry.get(k).map(|g| &g["name"]);
    let contacts = summary["case"]["contacts"].as_array();
    let echoed = contacts
        .and_then(|c| c.iter().find(|c| Some(&c["name"]) == name))
        .or_else(|| contacts.and_then(|c| c.get(k)))
        .map_or(&Value::Null, |c| &c["obstacle"]);
    let gap = echoed["gap"].as_f64().unwrap_or(0.0);
    match geometry.get(k).and_then(|g| g["obstacle"].as_str()) {
        Some("plane") => Obstacle::Plane { gap },
        Some("bi_plane") => Obstacle::Bars { gap },
        _ => Obstacle::Other,
    }
}

/// The time histories the plots need.
struct Histories {
    t: Array1<f64>,
    normal: Array2<f64>,
    tangential: Array3<f64>,
    position: Array3<f64>,
}

fn read_histories(dir: &Path) -> Result<Histories, String> {
    let npz = dir.join(fretdyn::output::stream::RESULTS_FILE);
    if npz.exists() {
        let file = std::fs::File::open(&npz).map_err(|e| format!("{}: {e}", npz.display()))?;
        let mut z = NpzReader::new(file).map_err(|e| format!("{}: {e}", npz.display()))?;
        let err = |k: &str, e: ndarray_npy::ReadNpzError| format!("{}: {k}: {e}", npz.display());
        Ok(Histories {
            t: z.by_name::<_, Ix1>("t.npy").map_err(|e| err("t", e))?,
            normal: z
                .by_name::<_, Ix2>("contact_normal_force.npy")
                .map_err(|e| err("contact_normal_force", e))?,
            tangential: z
                .by_name::<_, Ix3>("contact_tangential_force.npy")
                .map_err(|e| err("contact_tangential_force", e))?,
            position: z
                .by_name::<_, Ix3>("contact_position.npy")
                .map_err(|e| err("contact_position", e))?,
        })
    } else {
        // a run stopped before its end: the streamed series
        let series = dir.join(fretdyn::output::stream::SERIES_DIR);
        fn npy<A: ReadNpyExt>(dir: &Path, key: &str) -> Result<A, String> {
            let p = dir.join(format!("{key}.npy"));
            let f = std::fs::File::open(&p).map_err(|e| format!("{}: {e}", p.display()))?;
            A::read_npy(f).map_err(|e| format!("{}: {e}", p.display()))
        }
        Ok(Histories {
            t: npy(&series, "t")?,
            normal: npy(&series, "contact_normal_force")?,
            tangential: npy(&series, "contact_tangential_force")?,
            position: npy(&series, "contact_position")?,
        })
    }
}

/// Peak forces of the impacts, per contact index, from `impacts.csv`.
fn read_peaks(dir: &Path, contacts: usize) -> Vec<Vec<f64>> {
    let mut peaks = vec![Vec::new(); contacts];
    if let Ok(text) = std::fs::read_to_string(dir.join(fretdyn::output::stream::IMPACTS_FILE)) {
        for line in text.lines().skip(1) {
            let cols: Vec<&str> = line.split(',').collect();
            if let (Some(Ok(k)), Some(Ok(p))) = (
                cols.first().map(|c| c.parse::<usize>()),
                cols.get(6).map(|c| c.parse::<f64>()),
            ) && k < contacts
            {
                peaks[k].push(p);
            }
        }
    }
    peaks
}

/// Checks what the plots read of `summary.json`: an object with `contacts`, a list of objects
/// with a `name` each, and `contact_geometry`, a list of as many objects.
fn check_summary(summary: &Value) -> Result<(), String> {
    if !summary.is_object() {
        return Err("not a JSON object".into());
    }
    let contacts = summary["contacts"]
        .as_array()
        .ok_or("'contacts' is missing or not a list")?;
    for (k, c) in contacts.iter().enumerate() {
        if !c["name"].is_string() {
            return Err(format!("'contacts[{k}].name' is missing or not a string"));
        }
    }
    let geometry = summary["contact_geometry"]
        .as_array()
        .ok_or("'contact_geometry' is missing or not a list")?;
    if geometry.len() != contacts.len() || !geometry.iter().all(Value::is_object) {
        return Err(format!(
            "'contact_geometry' must list one object per contact ({})",
            contacts.len()
        ));
    }
    Ok(())
}

/// Draws every plot of the run in `dir`; returns the files written.
pub fn plot_run(dir: &Path) -> Result<Vec<PathBuf>, Failure> {
    let summary_path = dir.join("summary.json");
    let summary: Value = std::fs::read_to_string(&summary_path)
        .map_err(|e| e.to_string())
        .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
        .map_err(|e| {
            Failure::input(format!(
                "{}: {e} (is {} a folder written by fretdyn run?)",
                summary_path.display(),
                dir.display()
            ))
        })?;
    check_summary(&summary).map_err(|e| {
        Failure::input(format!(
            "{}: {e}; it is not a summary written by fretdyn run: run the case again",
            summary_path.display()
        ))
    })?;
    let h = read_histories(dir).map_err(Failure::input)?;
    let title = summary["title"].as_str().unwrap_or("fretdyn").to_string();
    let stats = summary["contacts"].as_array().cloned().unwrap_or_default();
    let geometry = summary["contact_geometry"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    let names: Vec<String> = stats
        .iter()
        .map(|c| c["name"].as_str().unwrap_or("?").to_string())
        .collect();
    let nc = names.len().min(h.normal.ncols());
    let mut written = Vec::new();
    if nc == 0 {
        return Ok(written);
    }
    let fail = Failure::failed;
    let t = h.t.to_vec();

    // time histories of the forces
    let columns: Vec<(Vec<f64>, Vec<f64>)> = (0..nc)
        .map(|k| {
            let n = h.normal.column(k).to_vec();
            let tg = (0..h.t.len())
                .map(|i| h.tangential[[i, k, 0]].hypot(h.tangential[[i, k, 1]]))
                .collect();
            (n, tg)
        })
        .collect();
    let panels: Vec<(String, Vec<Series>)> = (0..nc)
        .map(|k| {
            (
                names[k].clone(),
                vec![
                    Series {
                        label: "normal R_N".into(),
                        x: &t,
                        y: &columns[k].0,
                    },
                    Series {
                        label: "tangential |R_T|".into(),
                        x: &t,
                        y: &columns[k].1,
                    },
                ],
            )
        })
        .collect();
    let path = dir.join("contact_forces.png");
    panels_plot(
        &path,
        &format!("{title} — contact forces"),
        "t (s)",
        "force (N)",
        &panels,
    )
    .map_err(fail)?;
    written.push(path);

    // displacement at the contacts: for a plane, the distance from its face (at `gap` from
    // the plane through `origin`, contact below 0); for bars, the position from their
    // mid-plane with the faces at ±gap
    let is_hole = |k: usize| geometry.get(k).is_some_and(|g| !g["outline"].is_null());
    let obstacles: Vec<Obstacle> = (0..nc)
        .map(|k| obstacle_of(&summary, &geometry, k))
        .collect();
    let displacement: Vec<Vec<f64>> = (0..nc)
        .map(|k| {
            (0..h.t.len())
                .map(|i| {
                    let (x, y) = (h.position[[i, k, 0]], h.position[[i, k, 1]]);
                    match obstacles[k] {
                        Obstacle::Hole => x.hypot(y),
                        Obstacle::Plane { gap } => x + gap,
                        Obstacle::Bars { .. } | Obstacle::Other => x,
                    }
                })
                .collect()
        })
        .collect();
    let panels: Vec<Panel> = (0..nc)
        .map(|k| {
            let (label, marks) = match obstacles[k] {
                Obstacle::Hole => ("radial offset from the hole's centre", vec![]),
                Obstacle::Plane { .. } => (
                    "distance from the obstacle's face (contact below 0)",
                    vec![Mark::Level {
                        label: "face (at gap)".into(),
                        y: 0.0,
                    }],
                ),
                Obstacle::Bars { gap } => (
                    "position from the bars' mid-plane",
                    vec![
                        Mark::Level {
                            label: "faces (±gap)".into(),
                            y: gap,
                        },
                        Mark::Level {
                            label: "faces (±gap)".into(),
                            y: -gap,
                        },
                    ],
                ),
                Obstacle::Other => ("distance from the plane", vec![]),
            };
            Panel {
                title: names[k].clone(),
                series: vec![Series {
                    label: label.into(),
                    x: &t,
                    y: &displacement[k],
                }],
                errors: Vec::new(),
                marks,
            }
        })
        .collect();
    let path = dir.join("contact_displacement.png");
    stacked(
        &path,
        &format!("{title} — displacement at the contacts"),
        "t (s)",
        "displacement (m)",
        &panels,
        &Layout {
            y_scale: YScale::Linear,
            ..Layout::default()
        },
    )
    .map_err(fail)?;
    written.push(path);

    // orbits in the holes
    let holes: Vec<usize> = (0..nc).filter(|&k| is_hole(k)).collect();
    if !holes.is_empty() {
        let orbits: Vec<(Vec<f64>, Vec<f64>)> = holes
            .iter()
            .map(|&k| {
                let coord = |i: usize| h.position.slice(ndarray::s![.., k, i]).to_vec();
                (coord(0), coord(1))
            })
            .collect();
        let outlines: Vec<(Vec<f64>, Vec<f64>)> = holes
            .iter()
            .map(|&k| {
                let pts = geometry[k]["outline"]
                    .as_array()
                    .cloned()
                    .unwrap_or_default();
                let coord = |i: usize| -> Vec<f64> {
                    pts.iter().map(|p| p[i].as_f64().unwrap_or(0.0)).collect()
                };
                (coord(0), coord(1))
            })
            .collect();
        let panels: Vec<(String, Vec<Series>)> = holes
            .iter()
            .enumerate()
            .map(|(j, &k)| {
                (
                    names[k].clone(),
                    vec![
                        Series {
                            label: "tube centre".into(),
                            x: &orbits[j].0,
                            y: &orbits[j].1,
                        },
                        Series {
                            label: "hole (clearance)".into(),
                            x: &outlines[j].0,
                            y: &outlines[j].1,
                        },
                    ],
                )
            })
            .collect();
        let path = dir.join("orbits.png");
        xy_panels(
            &path,
            &format!("{title} — orbit of the tube centre in the holes"),
            "e1 (m)",
            "e2 (m)",
            &panels,
        )
        .map_err(fail)?;
        written.push(path);
    }

    // histograms of the peak forces, 5 bins per decade
    let peaks = read_peaks(dir, nc);
    if peaks.iter().any(|p| !p.is_empty()) {
        let panels: Vec<(String, Vec<Bin>)> = (0..nc)
            .filter(|&k| !peaks[k].is_empty())
            .map(|k| {
                (
                    match peaks[k].len() {
                        1 => format!("{} (1 impact)", names[k]),
                        n => format!("{} ({n} impacts)", names[k]),
                    },
                    histogram(&peaks[k], 5),
                )
            })
            .collect();
        let path = dir.join("peak_forces.png");
        histogram_panels(
            &path,
            &format!("{title} — peak force of the impacts"),
            "peak force R_N (N)",
            "impacts",
            &panels,
        )
        .map_err(fail)?;
        written.push(path);
    }

    // wear work rate per contact
    let rate = |k: usize, key: &str| stats[k][key].as_f64().unwrap_or(0.0);
    let panels = vec![
        (
            "friction power (1/T)∫|R_T·v_T| dt".to_string(),
            (0..nc)
                .map(|k| Bar {
                    label: names[k].clone(),
                    value: rate(k, "wear_work_rate"),
                    error: rate(k, "wear_work_rate_se"),
                })
                .collect(),
        ),
        (
            "normal-force definition (1/T)∫R_N|v_T| dt".to_string(),
            (0..nc)
                .map(|k| Bar {
                    label: names[k].clone(),
                    value: rate(k, "normal_wear_work_rate"),
                    error: rate(k, "normal_wear_work_rate_se"),
                })
                .collect(),
        ),
    ];
    let path = dir.join("wear.png");
    bar_panels(
        &path,
        &format!("{title} — wear work rate per contact (± standard error)"),
        "wear work rate (W)",
        &panels,
    )
    .map_err(fail)?;
    written.push(path);
    Ok(written)
}

/// Logarithmic histogram, `per_decade` bins per decade (edges 10^(i/per_decade)), from the
/// first to the last bin holding a value.
fn histogram(values: &[f64], per_decade: usize) -> Vec<Bin> {
    let per = per_decade as f64;
    let logs: Vec<f64> = values
        .iter()
        .filter(|v| **v > 0.0 && v.is_finite())
        .map(|v| v.log10() * per)
        .collect();
    if logs.is_empty() {
        return Vec::new();
    }
    let lo = logs.iter().copied().fold(f64::INFINITY, f64::min).floor() as i64;
    let hi = logs
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max)
        .floor() as i64;
    let mut counts = vec![0usize; (hi - lo + 1) as usize];
    for l in &logs {
        counts[(l.floor() as i64 - lo) as usize] += 1;
    }
    counts
        .iter()
        .enumerate()
        .map(|(i, &count)| {
            let edge = |j: i64| 10f64.powf(j as f64 / per);
            Bin {
                lo: edge(lo + i as i64),
                hi: edge(lo + i as i64 + 1),
                count,
            }
        })
        .collect()
}

/// The kinds of folder fretdyn writes, by the file that tells them apart.
const FOLDER_KINDS: [(&str, &str); 5] = [
    ("summary.json", "a run"),
    ("study.csv", "a study (sweep)"),
    ("life.json", "a life"),
    (crate::modes::SHAPES_FILE, "a modes folder"),
    (crate::bench::SCALING_FILE, "bench --scaling"),
];

/// Draws again every figure of a folder fretdyn wrote — a run, a study (`study.png` and
/// `percentiles.png`), a life, a modes folder or `bench --scaling`'s —, its kind told by the files in it; returns
/// the files written. `y_scale`: the y axis of a study's `study.png`.
pub fn plot_folder(dir: &Path, y_scale: YScale) -> Result<Vec<PathBuf>, Failure> {
    if !dir.is_dir() {
        return Err(Failure::input(format!(
            "{}: no such folder (give a folder written by fretdyn run, sweep, life, modes or bench --scaling)",
            dir.display()
        )));
    }
    let has = |name: &str| dir.join(name).is_file();
    if has("summary.json") {
        return plot_run(dir);
    }
    let mut written = Vec::new();
    if has("study.csv") {
        written.extend(plot_study(dir, y_scale)?);
    }
    if has("life.json") && has("life.csv") {
        written.push(crate::life::draw_folder(dir).map_err(Failure::failed)?);
    }
    if has(crate::modes::SHAPES_FILE) {
        written.push(crate::modes::draw_folder(dir).map_err(Failure::failed)?);
    }
    if has(crate::bench::SCALING_FILE) {
        written.push(crate::bench::draw_scaling(dir).map_err(Failure::input)?);
    }
    if written.is_empty() && !FOLDER_KINDS.iter().any(|(f, _)| has(f)) {
        let kinds: Vec<String> = FOLDER_KINDS
            .iter()
            .map(|(f, k)| format!("{k}: {f}"))
            .collect();
        return Err(Failure::input(format!(
            "{}: nothing fretdyn wrote is in this folder ({}); a modes folder written before {} was added: run fretdyn modes again",
            dir.display(),
            kinds.join(", "),
            crate::modes::SHAPES_FILE
        )));
    }
    Ok(written)
}

/// `study.png` and `percentiles.png` of a study folder, as `fretdyn sweep` drew them (from
/// its `figures.json`; a folder without one: the first parameter of the table on x and the
/// wear work rate, when the table has it).
fn plot_study(dir: &Path, y_scale: YScale) -> Result<Vec<PathBuf>, Failure> {
    use crate::sweep::{FIGURES_FILE, plot_percentiles, plot_table};
    let table = dir.join("study.csv");
    // a folder of a fretdyn before FIGURES_FILE: Null, the study.png of its first parameter
    let figures: Value = std::fs::read_to_string(dir.join(FIGURES_FILE))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or(Value::Null);
    let text = std::fs::read_to_string(&table)
        .map_err(|e| Failure::input(format!("{}: {e}", table.display())))?;
    let header: Vec<String> = text
        .lines()
        .next()
        .unwrap_or_default()
        .split(',')
        .map(str::to_string)
        .collect();
    let status = header.iter().position(|h| h == "status");
    let Some(status) = status.filter(|&s| s > 1) else {
        return Err(Failure::input(format!(
            "{}: not a study table of fretdyn sweep (no parameter and status columns)",
            table.display()
        )));
    };
    let per_contact =
        |statistic: &str| header.iter().any(|h| h.ends_with(&format!(".{statistic}")));
    let mut written = Vec::new();
    let study = &figures["study"];
    let (x, statistic, labels) = if !figures.is_null() {
        // sweep drew study.png only when the study has a [plot]
        if !study.is_object() {
            (String::new(), String::new(), Vec::new())
        } else {
            (
                study["x"].as_str().unwrap_or_default().to_string(),
                study["statistic"].as_str().unwrap_or_default().to_string(),
                study["labels"]
                    .as_array()
                    .map(|a| {
                        a.iter()
                            .filter_map(|v| v.as_str().map(str::to_string))
                            .collect()
                    })
                    .unwrap_or_default(),
            )
        }
    } else {
        (
            header[1].clone(),
            "wear_work_rate".to_string(),
            header[1..status].to_vec(),
        )
    };
    if !statistic.is_empty() && per_contact(&statistic) && header.contains(&x) {
        let path = dir.join("study.png");
        plot_table(&table, &x, &statistic, &labels, y_scale, &path)?;
        written.push(path);
    }
    let json = dir.join("percentiles.json");
    if json.is_file() {
        let report = read_percentiles(&json).map_err(Failure::input)?;
        let statistic = figures["percentiles"]["statistic"]
            .as_str()
            .map(str::to_string)
            .or_else(|| {
                report
                    .rows
                    .first()
                    .and_then(|r| r.column.rsplit_once('.').map(|(_, s)| s.to_string()))
            });
        if let Some(statistic) = statistic {
            let path = dir.join("percentiles.png");
            plot_percentiles(&table, &report, &statistic, &path)?;
            written.push(path);
        }
    }
    Ok(written)
}

/// A study's percentiles read back from its `percentiles.json` (a `null` estimate: NaN).
fn read_percentiles(path: &Path) -> Result<PercentileReport, String> {
    let json: Value = std::fs::read_to_string(path)
        .map_err(|e| e.to_string())
        .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let rows = json["rows"]
        .as_array()
        .ok_or_else(|| format!("{}: no 'rows' list", path.display()))?;
    Ok(PercentileReport {
        confidence: json["confidence"].as_f64().unwrap_or(0.95),
        bootstrap_resamples: json["bootstrap_resamples"].as_u64().unwrap_or(0) as usize,
        seed: json["seed"].as_u64().unwrap_or(0),
        rows: rows
            .iter()
            .map(|r| PercentileRow {
                group: r["group"]
                    .as_object()
                    .map(|g| {
                        g.iter()
                            .map(|(k, v)| (k.clone(), v.as_str().unwrap_or_default().to_string()))
                            .collect()
                    })
                    .unwrap_or_default(),
                column: r["column"].as_str().unwrap_or_default().to_string(),
                level: r["level"].as_f64().unwrap_or(f64::NAN),
                n: r["n"].as_u64().unwrap_or(0) as usize,
                excluded: r["excluded"].as_u64().unwrap_or(0) as usize,
                estimate: r["estimate"].as_f64().unwrap_or(f64::NAN),
                ci_low: r["ci_low"].as_f64(),
                ci_high: r["ci_high"].as_f64(),
                ci_coverage: r["ci_coverage"].as_f64().unwrap_or(f64::NAN),
                bootstrap_se: r["bootstrap_se"].as_f64().unwrap_or(f64::NAN),
            })
            .collect(),
    })
}
