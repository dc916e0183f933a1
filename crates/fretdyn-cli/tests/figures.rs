//! What each figure of the `fretdyn` command promises, read back from the record it writes
//! beside the PNG with `FRETDYN_FIGURE_RECORD` set (title lines, panels with their axes and
//! ticks, legend entries, reference lines, error bars, bands, bars), checked against the files
//! it was drawn from; and the figures committed under docs/figures against what the code
//! draws today.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

mod common;
use common::{Scratch, examples};

/// Runs `fretdyn` in `cwd` with the figures' records written.
fn fretdyn(args: &[&str], cwd: &Path) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args(args)
        .current_dir(cwd)
        .env("FRETDYN_FIGURE_RECORD", "1")
        .output()
        .expect("fretdyn runs");
    assert!(
        out.status.success(),
        "fretdyn {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The record of the figure `png`.
fn record(png: &Path) -> Value {
    let path = PathBuf::from(format!("{}.json", png.display()));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn panels(r: &Value) -> &Vec<Value> {
    r["panels"].as_array().unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The width in pixels of `text` at `size` px in the font the figures embed, measured here
/// with plotters (independently of the figure code's own measure).
fn width(text: &str, size: u32) -> u32 {
    use plotters::style::{FontStyle, IntoFont};
    static FONT: &[u8] = include_bytes!("../../../assets/DejaVuSans.ttf");
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    ("sans-serif", size).into_font().box_size(text).unwrap().0
}

/// The unit in an axis title `quantity (unit)`.
fn unit_of(title: &str) -> &str {
    title
        .rsplit_once(" (")
        .and_then(|(_, u)| u.strip_suffix(')'))
        .unwrap_or("")
}

/// The short tube_fluid_elastic case (0.4 s) in `dir`, run into `dir/out`.
fn run_tube_fluid_elastic(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(examples().join("tube_fluid_elastic.toml"))
        .unwrap()
        .replace("duration = 3.0", "duration = 0.4")
        .replace("t_start = 1.0", "t_start = 0.1");
    std::fs::write(dir.join("tfe.toml"), text).unwrap();
    fretdyn(&["run", "tfe.toml", "-o", "out", "-q"], dir);
    dir.join("out")
}

/// A title longer than the canvas (tube_fluid_elastic's) is wrapped: every line fits the
/// canvas (measured with the embedded font) and the lines together are the whole title; the
/// panels' captions fit their panels.
#[test]
fn long_titles_fit_the_canvas() {
    let s = Scratch::new("titles");
    let dir = run_tube_fluid_elastic(&s.0);
    let case = "Straight tube in 5 support plates, a cross flow over the middle spans (fluid-elastic forces)";
    for (file, what) in [
        ("orbits.png", "orbit of the tube centre in the holes"),
        ("contact_displacement.png", "displacement at the contacts"),
        ("peak_forces.png", "peak force of the impacts"),
        ("wear.png", "wear work rate per contact (± standard error)"),
        ("contact_forces.png", "contact forces"),
    ] {
        let r = record(&dir.join(file));
        let canvas = f(&r["size"][0]) as u32;
        let lines = r["title"].as_array().unwrap();
        let mut words = Vec::new();
        for line in lines {
            let text = line["text"].as_str().unwrap();
            let size = line["font"].as_u64().unwrap() as u32;
            assert!(
                width(text, size) + 2 * 12 <= canvas,
                "{file}: '{text}' is {} px on a {canvas} px canvas",
                width(text, size)
            );
            words.push(text.to_string());
        }
        assert_eq!(words.join(" "), format!("{case} — {what}"), "{file}");
        for p in panels(&r) {
            let caption = p["caption"].as_str().unwrap();
            assert!(p["caption_width"].as_u64().unwrap() <= p["width"].as_u64().unwrap());
            assert!(!caption.is_empty(), "{file}");
        }
    }
}

/// A study table in `dir` with two contacts whose wear work rates differ by a factor 1000
/// (µW at one, mW at the other) and span decades along the parameter, and the record of
/// what its figures are drawn from.
fn synthetic_study(dir: &Path) {
    let mut csv = String::from(
        "run,flow.zones.0.velocity,seed,status,a.wear_work_rate,a.wear_work_rate_se,b.wear_work_rate,b.wear_work_rate_se,fingerprint\n",
    );
    for (i, v) in [0.5, 1.0, 2.0, 4.0].iter().enumerate() {
        let rate = 1e-6 * 10f64.powi(i as i32); // 1 µW … 1 mW
        csv.push_str(&format!(
            "{i},{v},0,completed,{rate:e},{:e},{:e},{:e},x\n",
            0.1 * rate,
            1e3 * rate,
            100.0 * rate
        ));
    }
    std::fs::write(dir.join("study.csv"), csv).unwrap();
    std::fs::write(
        dir.join("figures.json"),
        r#"{"study": {"x": "flow.zones.0.velocity", "statistic": "wear_work_rate", "labels": ["flow.zones.0.velocity", "seed"]}}"#,
    )
    .unwrap();
}

/// study.png: the x axis is the study's key with its unit (no "zone 0"); the panels, which
/// are compared, share one unit; values spanning decades are on a log axis, and
/// `--y-scale linear` draws them linear with one SI prefix.
#[test]
fn study_figure_names_its_key_and_shares_a_unit() {
    let s = Scratch::new("study");
    synthetic_study(&s.0);
    fretdyn(&["plot", "."], &s.0);
    let r = record(&s.0.join("study.png"));
    for p in panels(&r) {
        assert_eq!(p["x"]["title"], "flow.zones.0.velocity (m/s)");
        assert!(p["y"]["log"].as_bool().unwrap(), "{}", p["y"]);
        // ± standard error: one bar a point
        assert_eq!(p["error_bars"].as_array().unwrap().len(), 4);
    }
    assert!(
        !r["title"][0]["text"].as_str().unwrap().contains("zone 0"),
        "{}",
        r["title"]
    );
    fretdyn(&["plot", ".", "--y-scale", "linear"], &s.0);
    let r = record(&s.0.join("study.png"));
    let titles: Vec<&str> = panels(&r)
        .iter()
        .map(|p| p["y"]["title"].as_str().unwrap())
        .collect();
    assert_eq!(titles.len(), 2);
    assert!(titles.iter().all(|t| *t == titles[0]), "{titles:?}");
    // the largest value is 1 W ± 0.1 W: W, not a prefix per panel
    assert_eq!(unit_of(titles[0]), "W");
    assert!(panels(&r).iter().all(|p| !p["y"]["log"].as_bool().unwrap()));
}

/// percentiles.png: each percentile's 95 % interval drawn as a horizontal bar at its level
/// between the bounds of percentiles.json; the legend's values in the axis' unit.
#[test]
fn percentiles_draw_their_intervals_in_the_axis_unit() {
    let s = Scratch::new("percentiles");
    let mut csv = String::from("run,sample,seed,status,a.wear_work_rate,fingerprint\n");
    for i in 0..40 {
        csv.push_str(&format!(
            "{i},{i},{i},completed,{:e},x\n",
            1e-3 * (1.0 + i as f64 / 10.0)
        ));
    }
    std::fs::write(s.0.join("study.csv"), csv).unwrap();
    let row = |level: f64, estimate: f64, lo: f64, hi: f64| {
        serde_json::json!({"group": {}, "column": "a.wear_work_rate", "level": level, "n": 40,
            "excluded": 0, "estimate": estimate, "ci_low": lo, "ci_high": hi,
            "ci_coverage": 0.96, "bootstrap_se": 1e-4})
    };
    let report = serde_json::json!({"confidence": 0.95, "bootstrap_resamples": 1000, "seed": 1,
        "rows": [row(50.0, 2.95e-3, 2.6e-3, 3.3e-3), row(95.0, 4.7e-3, 4.5e-3, 4.9e-3)]});
    std::fs::write(s.0.join("percentiles.json"), report.to_string()).unwrap();
    fretdyn(&["plot", "."], &s.0);
    let r = record(&s.0.join("percentiles.png"));
    assert!(
        r["title"][0]["text"]
            .as_str()
            .unwrap()
            .contains("95 % intervals")
    );
    let p = &panels(&r)[0];
    let unit = unit_of(p["x"]["title"].as_str().unwrap()).to_string();
    assert_eq!(unit, "mW");
    let bars = p["error_bars"].as_array().unwrap();
    for (level, lo, hi, estimate) in [
        (0.5, 2.6e-3, 3.3e-3, "2.950"),
        (0.95, 4.5e-3, 4.9e-3, "4.700"),
    ] {
        let bar = bars
            .iter()
            .find(|b| !b["vertical"].as_bool().unwrap() && f(&b["at"]) == level)
            .unwrap_or_else(|| panic!("no interval at {level}: {bars:?}"));
        assert_eq!((f(&bar["from"]), f(&bar["to"])), (lo, hi));
        let name = format!("P{}", level * 100.0);
        let key = p["keys"]
            .as_array()
            .unwrap()
            .iter()
            .map(|k| k.as_str().unwrap())
            .find(|k| k.starts_with(&name))
            .unwrap();
        // the value and both bounds in the axis' unit
        assert!(key.contains(&format!("{estimate} {unit}")), "{key}");
        assert_eq!(key.matches(&format!(" {unit}")).count(), 3, "{key}");
        // a line of its own, not a series whose markers another series' would hide
        assert!(
            p["lines"]
                .as_array()
                .unwrap()
                .iter()
                .any(|l| l["label"] == key),
            "{key}"
        );
        assert!(
            !p["series"]
                .as_array()
                .unwrap()
                .iter()
                .any(|s| s["label"] == key)
        );
    }
}

/// wear.png of V1b: both panels in one unit; the friction power, round-off (4e-16 W beside
/// 1e-7 W), reads 0 without an error bar; the other bar is summary.json's value ± its error.
#[test]
fn wear_bars_share_a_unit_and_round_off_reads_zero() {
    let s = Scratch::new("wear");
    let case = examples().join("v1b_grazing_impact.toml");
    fretdyn(&["run", case.to_str().unwrap(), "-o", "out", "-q"], &s.0);
    let summary = json(&s.0.join("out/summary.json"));
    let c = &summary["contacts"][0];
    let r = record(&s.0.join("out/wear.png"));
    let ps = panels(&r);
    assert_eq!(ps[0]["y"]["title"], ps[1]["y"]["title"]);
    assert_eq!(ps[0]["y"]["range"], ps[1]["y"]["range"]);
    let friction = &ps[0]["bars"][0];
    assert!(f(&c["wear_work_rate"]) > 0.0);
    assert!(f(&c["wear_work_rate"]) < 1e-8 * f(&c["normal_wear_work_rate"]));
    assert_eq!((f(&friction["value"]), f(&friction["error"])), (0.0, 0.0));
    assert!(ps[0]["error_bars"].as_array().unwrap().is_empty());
    let normal = &ps[1]["bars"][0];
    assert_eq!(f(&normal["value"]), f(&c["normal_wear_work_rate"]));
    assert_eq!(f(&normal["error"]), f(&c["normal_wear_work_rate_se"]));
    assert_eq!(ps[1]["error_bars"].as_array().unwrap().len(), 1);
}

/// peak_forces.png with a single impact: its bar is a small part of the axis, between ticks.
#[test]
fn a_single_impact_is_a_bar_among_ticks() {
    let s = Scratch::new("peaks");
    let case = examples().join("v1b_grazing_impact.toml");
    fretdyn(&["run", case.to_str().unwrap(), "-o", "out", "-q"], &s.0);
    let impacts = std::fs::read_to_string(s.0.join("out/impacts.csv")).unwrap();
    assert_eq!(impacts.lines().count(), 2, "one impact expected");
    let r = record(&s.0.join("out/peak_forces.png"));
    let p = &panels(&r)[0];
    assert!(
        p["caption"].as_str().unwrap().ends_with("(1 impact)"),
        "{}",
        p["caption"]
    );
    let (a, b) = (f(&p["x"]["range"][0]), f(&p["x"]["range"][1]));
    let bars = p["bars"].as_array().unwrap();
    assert_eq!(bars.len(), 1);
    let (from, to) = (f(&bars[0]["from"]), f(&bars[0]["to"]));
    assert!(to - from <= 0.25 * (b - a), "bar {from}..{to} on {a}..{b}");
    let ticks: Vec<f64> = p["x"]["ticks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| f(&t[0]))
        .filter(|t| (a..=b).contains(t))
        .collect();
    assert!(ticks.len() >= 3, "{ticks:?}");
    assert!(
        ticks.iter().any(|t| *t <= from) && ticks.iter().any(|t| *t >= to),
        "{ticks:?}"
    );
}

/// life.png: the plugging criterion of life.json as a line, a band of ± the depth's standard
/// error from life.csv's rate errors (the steps' relative errors in quadrature), the two
/// panels on the same y limits.
#[test]
fn life_figure_has_the_criterion_the_band_and_shared_limits() {
    let s = Scratch::new("life");
    let mut csv = String::from("time_years");
    let cols = [
        "wear_work_rate",
        "wear_work_rate_se",
        "tube_volume",
        "support_volume",
        "tube_depth",
        "support_depth",
        "clearance_increase",
        "tube_depth_fixed_gap",
    ];
    for c in ["p1", "p2"] {
        for col in cols {
            csv.push_str(&format!(",{c}.{col}"));
        }
    }
    csv.push('\n');
    let years = [0.0, 1.0, 2.0, 4.0];
    let depth = |k: usize, i: usize| 1e-5 * (k + 1) as f64 * years[i];
    for (i, year) in years.iter().enumerate() {
        csv.push_str(&format!("{year:e}"));
        for k in 0..2 {
            let rate = 1e-3 * (k + 1) as f64;
            csv.push_str(&format!(
                ",{rate:e},{:e},0,0,{:e},0,0,{:e}",
                0.1 * rate,
                depth(k, i),
                0.8 * depth(k, i)
            ));
        }
        csv.push('\n');
    }
    std::fs::write(s.0.join("life.csv"), csv).unwrap();
    std::fs::write(
        s.0.join("life.json"),
        r#"{"title": "two plates", "criterion_depth": 6e-5, "results": {}}"#,
    )
    .unwrap();
    fretdyn(&["plot", "."], &s.0);
    let r = record(&s.0.join("life.png"));
    let ps = panels(&r);
    assert_eq!(ps.len(), 2);
    assert_eq!(ps[0]["y"]["range"], ps[1]["y"]["range"]);
    assert_eq!(ps[0]["y"]["title"], ps[1]["y"]["title"]);
    for p in ps {
        let line = &p["lines"][0];
        assert_eq!(line["label"], "plugging criterion");
        assert_eq!(
            (f(&line["at"]), line["vertical"].as_bool()),
            (6e-5, Some(false))
        );
        assert_eq!(p["bands"].as_array().unwrap().len(), 2, "{}", p["bands"]);
        assert!(p["x"]["title"].as_str().unwrap().contains("(years)"));
    }
    // the band's top: depth + SE, the steps' errors (10 % of each step) in quadrature
    let se = |k: usize| -> f64 {
        (1..4)
            .map(|i| (0.1 * (depth(k, i) - depth(k, i - 1))).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let top = f(&ps[0]["y"]["range"][1]);
    assert!(top >= depth(1, 3) + se(1), "{top}");
    assert!(top < depth(1, 3) + 2.0 * se(1) + 0.1 * depth(1, 3), "{top}");
}

/// mode_shapes.png: normalised translations (y label says so, each mode's largest is 1),
/// the supports and contacts marked where they are, no legend entry without a line.
#[test]
fn mode_shapes_are_normalised_with_supports_marked() {
    let s = Scratch::new("modes");
    let case = examples().join("tube_fluid_elastic.toml");
    fretdyn(&["modes", case.to_str().unwrap(), "-o", "m"], &s.0);
    let r = record(&s.0.join("m/mode_shapes.png"));
    // redrawn by fretdyn plot alike
    let first = std::fs::read(s.0.join("m/mode_shapes.png")).unwrap();
    fretdyn(&["plot", "m"], &s.0);
    assert!(std::fs::read(s.0.join("m/mode_shapes.png")).unwrap() == first);
    for p in panels(&r) {
        assert!(p["y"]["title"].as_str().unwrap().contains("normalised"));
        let series = p["series"].as_array().unwrap();
        let largest = series
            .iter()
            .map(|s| f(&s["min_y"]).abs().max(f(&s["max_y"]).abs()))
            .fold(0.0, f64::max);
        assert!((largest - 1.0).abs() < 1e-12, "{largest}");
        for key in p["keys"].as_array().unwrap() {
            let key = key.as_str().unwrap();
            let drawn = series.iter().find(|s| s["label"] == key);
            let line = p["lines"]
                .as_array()
                .unwrap()
                .iter()
                .any(|l| l["label"] == key);
            match drawn {
                Some(s) => assert!(f(&s["max_y"]) - f(&s["min_y"]) > 1e-3, "{key}: flat"),
                None => assert!(line, "{key}: a legend entry without a line"),
            }
        }
        let at = |label: &str| -> Vec<f64> {
            p["lines"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|l| l["label"].as_str().unwrap().starts_with(label))
                .map(|l| f(&l["at"]))
                .collect()
        };
        let near = |a: Vec<f64>, b: &[f64]| {
            let mut a = a;
            a.sort_by(f64::total_cmp);
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
        };
        assert!(near(at("supports"), &[0.0, 6.0]), "{:?}", at("supports"));
        assert!(
            near(at("contacts"), &[1.0, 2.0, 3.0, 4.0, 5.0]),
            "{:?}",
            at("contacts")
        );
    }
}

/// contact_displacement.png of a plane with a gap: the distance from its face (at `gap` from
/// the plane through `origin`), with the face drawn at 0.
#[test]
fn plane_displacement_is_measured_from_the_face() {
    let s = Scratch::new("plane");
    let gap = 5e-4;
    let text = std::fs::read_to_string(examples().join("v1b_grazing_impact.toml"))
        .unwrap()
        .replace(
            "obstacle = { type = \"plane\",",
            &format!("obstacle = {{ type = \"plane\", gap = {gap},"),
        );
    assert!(text.contains("gap = "));
    std::fs::write(s.0.join("case.toml"), text).unwrap();
    fretdyn(&["run", "case.toml", "-o", "out", "-q"], &s.0);
    let mut npz =
        ndarray_npy::NpzReader::new(std::fs::File::open(s.0.join("out/results.npz")).unwrap())
            .unwrap();
    let position: ndarray::Array3<f64> = npz.by_name("contact_position").unwrap();
    let along: Vec<f64> = position.slice(ndarray::s![.., 0, 0]).to_vec();
    let lowest = along.iter().copied().fold(f64::INFINITY, f64::min);
    let highest = along.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let r = record(&s.0.join("out/contact_displacement.png"));
    let p = &panels(&r)[0];
    let series = &p["series"][0];
    assert!(series["label"].as_str().unwrap().contains("face"));
    assert!((f(&series["min_y"]) - (lowest + gap)).abs() < 1e-15);
    assert!((f(&series["max_y"]) - (highest + gap)).abs() < 1e-15);
    // it starts free at the gap, and goes into the face
    assert!(f(&series["max_y"]) >= gap && f(&series["min_y"]) < 0.0);
    let face = &p["lines"][0];
    assert_eq!(
        (f(&face["at"]), face["vertical"].as_bool()),
        (0.0, Some(false))
    );
}

/// `fretdyn plot` on a folder with nothing fretdyn wrote: a one-line error naming it.
#[test]
fn plot_names_a_folder_it_cannot_draw() {
    let s = Scratch::new("plotnothing");
    std::fs::create_dir_all(s.0.join("empty")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args(["plot", "empty"])
        .current_dir(&s.0)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: empty: nothing fretdyn wrote"),
        "{err}"
    );
}

/// `fretdyn plot` of a `bench --scaling` folder draws scaling.png from scaling.csv: a panel
/// per method in the table's order, a curve per contact count, the table's µs per step in
/// seconds on the axis; a table that is not one is refused naming its line.
#[test]
fn scaling_figure_is_drawn_again_from_its_table() {
    let s = Scratch::new("scaling");
    let dir = s.0.join("scaling");
    std::fs::create_dir_all(&dir).unwrap();
    let header = "method,modes,contacts,mean_closed,us_per_step,steps_per_s";
    let rows = [
        ("penalty", 10, 1, 0.25),
        ("penalty", 50, 1, 0.5),
        ("penalty", 10, 5, 0.75),
        ("penalty", 50, 5, 1.5),
        ("gauss_seidel", 10, 1, 0.5),
        ("gauss_seidel", 50, 1, 2.0),
    ];
    let mut csv = format!("{header}\n");
    for (m, modes, contacts, us) in rows {
        csv.push_str(&format!("{m},{modes},{contacts},0.1,{us},{}\n", 1e6 / us));
    }
    std::fs::write(dir.join("scaling.csv"), &csv).unwrap();
    fretdyn(&["plot", "scaling"], &s.0);
    let r = record(&dir.join("scaling.png"));
    let p = panels(&r);
    let captions: Vec<&str> = p.iter().map(|q| q["caption"].as_str().unwrap()).collect();
    assert_eq!(captions, ["penalty", "gauss_seidel"]);
    assert_eq!(p[0]["keys"], serde_json::json!(["1 contact", "5 contacts"]));
    assert_eq!(p[1]["keys"], serde_json::json!(["1 contact"]));
    let series = p[0]["series"].as_array().unwrap();
    assert_eq!(f(&series[1]["max_y"]), 1.5e-6);
    assert_eq!(f(&series[1]["min_y"]), 0.75e-6);
    assert_eq!(series[1]["points"], 2);
    assert_eq!(p[0]["y"]["title"], "time per step (µs)");
    // a row that is not one: refused, naming the file and the line
    std::fs::write(
        dir.join("scaling.csv"),
        format!("{csv}penalty,ten,1,0.1,0.2,5e6\n"),
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args(["plot", "scaling"])
        .current_dir(&s.0)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("scaling.csv line 8"), "{err}");
}

/// The figures committed under docs/figures are what the code draws today: the cheap ones
/// (scripts/regenerate_figures.sh --cheap, about a minute) drawn again and compared byte for
/// byte (plotters' PNGs are deterministic); the costly ones are listed in the script's header.
#[test]
fn committed_figures_are_what_the_code_draws() {
    let s = Scratch::new("committed");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let into = s.0.join("figures");
    let out = Command::new("bash")
        .arg(root.join("scripts/regenerate_figures.sh"))
        .args(["--cheap", "--into", into.to_str().unwrap()])
        .env("FRETDYN", env!("CARGO_BIN_EXE_fretdyn"))
        .env("SCRATCH", s.0.join("scratch"))
        .env_remove("FRETDYN_FIGURE_RECORD")
        .current_dir(&root)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut compared = 0;
    let mut stale = Vec::new();
    let mut stack = vec![into.clone()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            let name = p.strip_prefix(&into).unwrap();
            let committed = std::fs::read(root.join("docs/figures").join(name))
                .unwrap_or_else(|e| panic!("docs/figures/{}: {e}", name.display()));
            compared += 1;
            if committed != std::fs::read(&p).unwrap() {
                stale.push(name.display().to_string());
            }
        }
    }
    assert_eq!(compared, 6);
    assert!(
        stale.is_empty(),
        "docs/figures differ from what the code draws: {stale:?}; run scripts/regenerate_figures.sh"
    );
}
