//! Fuzz test of the commands as a user runs them (issue [3.1]): mutated example case and study
//! files given to the `fretdyn` binary — `run`, `life`, `stability`, `modes` and `sweep` —
//! each in its own process, so that what a user would meet is caught as such: a panic (exit
//! code 101, "panicked" on stderr), an abort (SIGABRT: a failed allocation, a stack overflow),
//! any other signal, a hang (a watchdog kills the command), an exit code other than 0 (done),
//! 1 (a run that failed: diverged, a life cut short) or 2 (bad input), an error of more than
//! one line, or a non-finite number in an output.
//!
//! Inputs (fixed seeds; one command per seed): an example of `examples/` with 1–3 random
//! mutations of its TOML tree (`crates/fretdyn/tests/fuzz/mutate.rs`, the mutations of the
//! library's fuzz test `fuzz_cases.rs`):
//! - `run` on any example case; `modes` on any example case;
//! - `life` on `tube_multispan_life.toml`, or on another example case given a `[life]`
//!   section and a `wear` table on each contact whose obstacle has a scar geometry (a plane or
//!   bars: a flat bar; a drilled hole) before the mutations, which may hit them too;
//!   one life in four with `--halvings 1`;
//! - `stability` on the flow cases (`tube_fluid_elastic.toml`, `ubend_flow.toml`);
//! - `sweep` on an example study, its base case copied beside it into the command's scratch
//!   folder, the mutations on the study or on the base.
//!
//! Bounded time, decided before a command is spawned, whatever the mutation did to the
//! durations: a case runs at most [`CASE_STEPS`] steps (a life: over all its windows, with
//! `[life] max_steps` at most [`LIFE_STEPS`]), a study [`STUDY_STEPS`] over all its runs (at
//! most [`SAMPLES`] samples, [`SEEDS`] seeds, [`VALUES`] values of its first parameter and one
//! of the others — a mutated value is kept first —, lives of [`STUDY_LIFE_STEPS`] life
//! steps): a run that would take more has `time.duration` shortened, and `[statistics]`
//! `t_start`, `t_end` and `block` with it (in the base case and in the study's parameters of
//! those keys). The library reads the input as the binary will (`Case::from_toml_str`,
//! `Simulation::check`, `Study::from_toml_str` and `Study::check`): an input it refuses is
//! still given to the binary, which must refuse it the same way (exit code 2, its one-line
//! error holding the library's message); an input whose cost cannot be bounded so is not run
//! (counted as "not run").
//!
//! Checks on the outputs of every command that exits (0, 1 or 2): every number finite —
//! `summary.json` as the library's fuzz test checks it (null stands for a non-finite number;
//! the echo of the case is not looked at), every array of `results.npz` (`results.nc` holds
//! the same arrays bit for bit: `tests/results_nc.rs`) and of `basis.npz`, every cell of every CSV (`life.csv`, `scars.csv`, `contacts.csv`,
//! `impacts.csv`, `blocks.csv`, `study.csv`, `percentiles.csv`, `stability.csv`, …) and the nulls
//! of `life.json`, `stability.json` and `percentiles.json` at the places only where they mean
//! "none". Allowed: an empty cell (a value the run cannot give, e.g. a standard error of fewer
//! than 2 batches), `inf` where it is documented — `study.csv`'s `time_to_criterion*` columns
//! (a criterion not reached) and `connors_max_ratio`, their percentiles, and the `ratio` of a
//! mode with `U_c = 0` (undamped, or rigid-body) in `stability.csv` — and the parameter columns of `study.csv` and
//! `percentiles.csv`, which echo the input. A command that exits 0 has written its results.
//!
//! Budget: `FRETDYN_FUZZ_COMMANDS` commands (default 800) and `FRETDYN_FUZZ_SECONDS` of wall
//! time (default 180), whichever ends first, two commands at a time; a command that runs
//! longer than `FRETDYN_FUZZ_TIMEOUT` seconds (default 60) is killed and reported as a hang.
//! The seeds are `FRETDYN_FUZZ_SEED` (default 2026) + 0, 1, 2, …: a failure names its seed,
//! its command, its mutations and its files, and is run again alone with
//! `FRETDYN_FUZZ_SEED=<seed> FRETDYN_FUZZ_COMMANDS=1`.

mod common;
#[path = "../../fretdyn/tests/fuzz/mutate.rs"]
mod mutate;

use std::collections::BTreeMap;
use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use fretdyn::apps::study::Study;
use fretdyn::case::Case;
use fretdyn::integrator::simulation::Simulation;
use toml::Value;

use common::Scratch;
use mutate::{Rng, env_or, mutate, non_finite_in_json, summary_non_finite};

/// Steps a spawned `run`, `life`, `modes` or `stability` may cost (a life: its windows
/// together; the set-up of a case synthesises its turbulence over its duration): about a
/// second of a 30-mode tube.
const CASE_STEPS: f64 = 20_000.0;
/// Steps of all the runs of a spawned `sweep` together.
const STUDY_STEPS: f64 = 40_000.0;
/// Most life steps of a `life` (`[life] max_steps`).
const LIFE_STEPS: i64 = 3;
/// Most life steps of each life of a study.
const STUDY_LIFE_STEPS: i64 = 2;
/// Most samples of a probabilistic study.
const SAMPLES: i64 = 2;
/// Most seeds of a study.
const SEEDS: usize = 2;
/// Most values of a study's first parameter (one for each of the others, in a grid).
const VALUES: usize = 2;
/// The keys of a case that are times of its run, shortened together.
const TIME_KEYS: [&str; 4] = [
    "time.duration",
    "statistics.t_start",
    "statistics.t_end",
    "statistics.block",
];
/// Commands at a time (the machine of CI has 2 cores).
const WORKERS: usize = 2;

/// A command of `fretdyn`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Kind {
    Run,
    Life,
    Stability,
    Modes,
    Sweep,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Run => "run",
            Kind::Life => "life",
            Kind::Stability => "stability",
            Kind::Modes => "modes",
            Kind::Sweep => "sweep",
        }
    }

    /// What the command writes when it exits 0.
    fn results(self) -> &'static [&'static str] {
        match self {
            Kind::Run => &["results.npz", "summary.json"],
            Kind::Life => &["life.csv", "life.json", "scars.csv"],
            Kind::Stability => &["stability.csv", "stability.json"],
            Kind::Modes => &["basis.npz"],
            Kind::Sweep => &["study.csv"],
        }
    }
}

/// The example files: cases and studies, by file name.
struct Examples {
    cases: Vec<(String, Value)>,
    studies: Vec<(String, Value)>,
}

impl Examples {
    fn load() -> Self {
        let mut cases = Vec::new();
        let mut studies = Vec::new();
        for (path, value) in mutate::example_files() {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if mutate::is_study(&value) {
                studies.push((name, value));
            } else {
                cases.push((name, value));
            }
        }
        Self { cases, studies }
    }

    fn case(&self, name: &str) -> Option<&(String, Value)> {
        self.cases.iter().find(|(n, _)| n == name)
    }

    /// A case drawn among those that pass `filter`.
    fn pick(&self, rng: &mut Rng, filter: impl Fn(&Value) -> bool) -> (String, Value) {
        let some: Vec<&(String, Value)> = self.cases.iter().filter(|(_, v)| filter(v)).collect();
        some[rng.below(some.len())].clone()
    }
}

/// What the library says of an input as the binary will get it.
#[derive(Debug, Clone)]
enum Verdict {
    /// Refused with this message: the binary must refuse it too (exit 2, the message).
    Refused(String),
    /// Read (the binary may still refuse it for what only it checks).
    Accepted,
    /// Its cost could not be bounded: not run.
    Unbounded,
}

/// One command to run.
struct Job {
    seed: u64,
    kind: Kind,
    args: Vec<String>,
    /// The files written in the command's folder: name and text.
    files: Vec<(String, String)>,
    /// The mutated file and its mutations.
    mutated: String,
    what: Vec<String>,
    /// What was changed to bound the cost.
    bounded: Vec<String>,
    verdict: Verdict,
    /// A model without stiffness: the summary's `time.stable_dt` is ∞ (null).
    unbounded_dt: bool,
}

impl Job {
    fn label(&self) -> String {
        let mut s = format!(
            "seed {}: fretdyn {} ({}: {})",
            self.seed,
            self.args.join(" "),
            self.mutated,
            self.what.join("; ")
        );
        if !self.bounded.is_empty() {
            s.push_str(&format!("; bounded: {}", self.bounded.join(", ")));
        }
        s
    }

    fn write(&self, dir: &Path) {
        for (name, text) in &self.files {
            std::fs::write(dir.join(name), text).expect("scratch file");
        }
    }

    fn set_file(&mut self, name: &str, text: String) {
        match self.files.iter_mut().find(|(n, _)| n == name) {
            Some(f) => f.1 = text,
            None => self.files.push((name.to_string(), text)),
        }
    }
}

/// A number of the tree (an integer or a float).
fn number(v: Option<&Value>) -> Option<f64> {
    match v? {
        Value::Integer(i) => Some(*i as f64),
        Value::Float(x) => Some(*x),
        _ => None,
    }
}

/// The value at a dotted path of tables.
fn at<'a>(doc: &'a Value, path: &str) -> Option<&'a Value> {
    path.split('.').try_fold(doc, |v, k| v.get(k))
}

fn at_mut<'a>(doc: &'a mut Value, path: &str) -> Option<&'a mut Value> {
    path.split('.').try_fold(doc, |v, k| v.get_mut(k))
}

/// The steps of a case as TOML (`time.duration / time.dt`), when both are positive numbers.
fn steps_of(doc: &Value) -> Option<f64> {
    let (dt, duration) = (
        number(at(doc, "time.dt"))?,
        number(at(doc, "time.duration"))?,
    );
    let steps = duration / dt;
    (dt > 0.0 && duration > 0.0 && steps.is_finite()).then_some(steps)
}

/// The windows of a life of a case as TOML: its `[life] max_steps` (1 without a life).
fn windows_of(doc: &Value) -> f64 {
    match doc.get("life") {
        Some(Value::Table(life)) => number(life.get("max_steps")).unwrap_or(1000.0).max(1.0),
        _ => 1.0,
    }
}

/// `[life] max_steps` at most `cap` (given when missing; a value the case refuses is kept).
fn cap_life(doc: &mut Value, cap: i64, bounded: &mut Vec<String>) {
    if let Some(Value::Table(life)) = doc.get_mut("life") {
        match life.get("max_steps").cloned() {
            None => {
                life.insert("max_steps".into(), Value::Integer(cap));
                bounded.push(format!("life.max_steps = {cap}"));
            }
            Some(Value::Integer(n)) if n > cap => {
                life.insert("max_steps".into(), Value::Integer(cap));
                bounded.push(format!("life.max_steps {n} → {cap}"));
            }
            _ => {}
        }
    }
}

/// Multiplies the times of the run ([`TIME_KEYS`]) of a case as TOML by `f`.
fn scale_times(doc: &mut Value, f: f64) {
    for key in TIME_KEYS {
        if let Some(v) = at_mut(doc, key)
            && let Some(x) = number(Some(v))
        {
            *v = Value::Float(x * f);
        }
    }
}

/// A study's parameter key as dotted parts (`time[duration]` → `time.duration`).
fn dotted(key: &str) -> String {
    key.replace('[', ".").replace(']', "")
}

/// Multiplies the values of a study's parameters that are times of the run by `f`.
fn scale_study_times(study: &mut Value, f: f64) {
    let Some(Value::Array(parameters)) = study.get_mut("parameters") else {
        return;
    };
    for p in parameters {
        let is_time = p
            .get("key")
            .and_then(Value::as_str)
            .is_some_and(|k| TIME_KEYS.contains(&dotted(k).as_str()));
        if let (true, Some(Value::Array(values))) = (is_time, p.get_mut("values")) {
            for v in values {
                if let Some(x) = number(Some(v)) {
                    *v = Value::Float(x * f);
                }
            }
        }
    }
}

/// `cap` elements of `a` in their order: those `novel` picks first (a mutated value is kept),
/// then the first ones.
fn keep(len: usize, novel: impl Fn(usize) -> bool, cap: usize) -> Vec<usize> {
    let mut chosen: Vec<usize> = (0..len).filter(|&i| novel(i)).take(cap).collect();
    for i in 0..len {
        if chosen.len() >= cap {
            break;
        }
        if !chosen.contains(&i) {
            chosen.push(i);
        }
    }
    chosen.sort_unstable();
    chosen
}

fn select(a: &[Value], indices: &[usize]) -> Vec<Value> {
    indices.iter().map(|&i| a[i].clone()).collect()
}

/// Fewer runs in a study: at most [`SAMPLES`] samples, [`SEEDS`] seeds, [`VALUES`] values of
/// its first parameter with values and one of each other in a grid ([`VALUES`] of each in a
/// list of equal lengths); values not in `original` (mutated) are kept first. A value the
/// study refuses (a count out of range, lists of unequal lengths) is kept.
fn cap_study(study: &mut Value, original: &Value, bounded: &mut Vec<String>) {
    let Value::Table(t) = study else { return };
    if let Some(Value::Integer(n)) = t.get("samples")
        && *n > SAMPLES
        && *n <= fretdyn::apps::study::MAX_SAMPLES
    {
        bounded.push(format!("samples {n} → {SAMPLES}"));
        t.insert("samples".into(), Value::Integer(SAMPLES));
    }
    let old_seeds: Vec<Value> = match original.get("seeds") {
        Some(Value::Array(a)) => a.clone(),
        _ => Vec::new(),
    };
    if let Some(Value::Array(seeds)) = t.get_mut("seeds")
        && seeds.len() > SEEDS
    {
        let chosen = keep(seeds.len(), |i| !old_seeds.contains(&seeds[i]), SEEDS);
        bounded.push(format!("seeds: {} of {}", chosen.len(), seeds.len()));
        *seeds = select(seeds, &chosen);
    }
    let old_values: Vec<Value> = match original.get("parameters") {
        Some(Value::Array(ps)) => ps
            .iter()
            .filter_map(|p| p.get("values").and_then(Value::as_array))
            .flatten()
            .cloned()
            .collect(),
        _ => Vec::new(),
    };
    let list = t.get("combine").and_then(Value::as_str) == Some("list");
    let Some(Value::Array(parameters)) = t.get_mut("parameters") else {
        return;
    };
    let mut lists: Vec<&mut Vec<Value>> = parameters
        .iter_mut()
        .filter_map(|p| match p.get_mut("values") {
            Some(Value::Array(values)) => Some(values),
            _ => None,
        })
        .collect();
    if list {
        let len = lists.first().map_or(0, |l| l.len());
        if len > VALUES && lists.iter().all(|l| l.len() == len) {
            let chosen = keep(
                len,
                |i| lists.iter().any(|l| !old_values.contains(&l[i])),
                VALUES,
            );
            bounded.push(format!("values: {} of {len} (list)", chosen.len()));
            for l in &mut lists {
                **l = select(l, &chosen);
            }
        }
    } else {
        for (k, l) in lists.iter_mut().enumerate() {
            let cap = if k == 0 { VALUES } else { 1 };
            if l.len() > cap {
                let chosen = keep(l.len(), |i| !old_values.contains(&l[i]), cap);
                bounded.push(format!("values list {k}: {cap} of {}", l.len()));
                **l = select(l, &chosen);
            }
        }
    }
}

/// Gives a case a service life: a `wear` table on each contact whose obstacle has a scar
/// geometry (a plane or bars: a flat bar; a circle: a drilled hole), the tube's radius in
/// the scar when the contact has none, and a `[life]` section. `None`: no such contact.
fn add_life(doc: &mut Value) -> Option<String> {
    let law = |k: f64| {
        let mut t = toml::Table::new();
        t.insert("law".into(), Value::String("archard".into()));
        t.insert("coefficient".into(), Value::Float(k));
        Value::Table(t)
    };
    let mut worn = Vec::new();
    if let Some(Value::Array(contacts)) = doc.get_mut("contacts") {
        for (k, c) in contacts.iter_mut().enumerate() {
            let Value::Table(c) = c else { continue };
            let kind = c
                .get("obstacle")
                .and_then(|o| o.get("type"))
                .and_then(Value::as_str)
                .unwrap_or("");
            let mut scar = toml::Table::new();
            match kind {
                "plane" | "bi_plane" => {
                    scar.insert("type".into(), Value::String("flat_bar".into()));
                    scar.insert("width".into(), Value::Float(0.02));
                }
                "circle" => {
                    scar.insert("type".into(), Value::String("drilled_hole".into()));
                    scar.insert("thickness".into(), Value::Float(0.02));
                    scar.insert("shape".into(), Value::String("crescent".into()));
                }
                _ => continue,
            }
            if !c.contains_key("radius") {
                scar.insert("tube_radius".into(), Value::Float(0.0095));
            }
            let mut wear = toml::Table::new();
            wear.insert("tube".into(), law(2e-15));
            wear.insert("support".into(), law(1e-15));
            wear.insert("scar".into(), Value::Table(scar));
            c.insert("wear".into(), Value::Table(wear));
            worn.push(k);
        }
    }
    if worn.is_empty() {
        return None;
    }
    let mut life = toml::Table::new();
    life.insert("target_years".into(), Value::Float(10.0));
    life.insert("max_depth_change".into(), Value::Float(0.2));
    life.insert("criterion_depth".into(), Value::Float(2e-4));
    doc.as_table_mut()?
        .insert("life".into(), Value::Table(life));
    Some(format!("[life] and wear on contacts {worn:?}"))
}

/// The command of `seed` and its inputs, without the library: `None` when the mutated tree
/// cannot be written as TOML (a table turned into a number at the root).
fn plan(seed: u64, examples: &Examples) -> Option<Job> {
    let mut rng = Rng(seed);
    let kind = match rng.below(20) {
        0..=5 => Kind::Run,
        6..=9 => Kind::Life,
        10..=11 => Kind::Stability,
        12..=13 => Kind::Modes,
        _ => Kind::Sweep,
    };
    let mut bounded = Vec::new();
    if kind == Kind::Sweep {
        let (study_name, study) = examples.studies[rng.below(examples.studies.len())].clone();
        let base_name = study.get("base")?.as_str()?.to_string();
        let (_, mut base) = examples.case(&base_name)?.clone();
        let original = study.clone();
        let mut study = study;
        let on_base = rng.below(2) == 0;
        let mut what = Vec::new();
        for _ in 0..1 + rng.below(3) {
            what.push(mutate(
                if on_base { &mut base } else { &mut study },
                &mut rng,
            ));
        }
        cap_study(&mut study, &original, &mut bounded);
        cap_life(&mut base, STUDY_LIFE_STEPS, &mut bounded);
        let files = vec![
            (study_name.clone(), toml::to_string(&study).ok()?),
            (base_name.clone(), toml::to_string(&base).ok()?),
        ];
        return Some(Job {
            seed,
            kind,
            args: ["sweep", &study_name, "-o", "out"]
                .map(String::from)
                .to_vec(),
            files,
            mutated: if on_base { base_name } else { study_name },
            what,
            bounded,
            verdict: Verdict::Accepted,
            unbounded_dt: false,
        });
    }
    let (name, mut doc) = match kind {
        Kind::Stability => examples.pick(&mut rng, |v| v.get("flow").is_some()),
        Kind::Life if rng.below(2) == 0 => examples.pick(&mut rng, |v| v.get("life").is_some()),
        Kind::Life => examples.pick(&mut rng, |v| {
            v.get("life").is_none() && v.get("contacts").is_some()
        }),
        _ => examples.pick(&mut rng, |_| true),
    };
    let mut what = Vec::new();
    if kind == Kind::Life && doc.get("life").is_none() {
        what.push(add_life(&mut doc)?);
    }
    for _ in 0..1 + rng.below(3) {
        what.push(mutate(&mut doc, &mut rng));
    }
    let mut args = vec![
        kind.name().to_string(),
        name.clone(),
        "-o".into(),
        "out".into(),
    ];
    let mut windows = 1.0;
    if kind == Kind::Life {
        cap_life(&mut doc, LIFE_STEPS, &mut bounded);
        windows = windows_of(&doc);
        if rng.below(4) == 0 {
            args.extend(["--halvings".into(), "1".into()]);
            // the life again with max_depth_change halved: up to max_steps windows more
            windows *= 2.0;
        }
    }
    if let Some(steps) = steps_of(&doc)
        && steps * windows > CASE_STEPS
    {
        let f = CASE_STEPS / (steps * windows);
        scale_times(&mut doc, f);
        bounded.push(format!("times × {f:.3e}"));
    }
    Some(Job {
        seed,
        kind,
        files: vec![(name.clone(), toml::to_string(&doc).ok()?)],
        mutated: name,
        what,
        bounded,
        args,
        verdict: Verdict::Accepted,
        unbounded_dt: false,
    })
}

/// What the library says of the job's inputs (written in `dir`), as the command will read
/// them; a study whose runs would take too long is shortened here (its files rewritten).
fn judge(job: &mut Job, dir: &Path) {
    let halvings = if job.args.iter().any(|a| a == "--halvings") {
        2.0
    } else {
        1.0
    };
    if job.kind != Kind::Sweep {
        let text = &job.files[0].1;
        let case = match Case::from_toml_str(text, dir) {
            Ok(case) => case,
            Err(e) => {
                job.verdict = refused(&e, dir);
                return;
            }
        };
        let windows = match (job.kind, &case.life) {
            (Kind::Life, Some(life)) => life.max_steps as f64 * halvings,
            _ => 1.0,
        };
        let cost = case.settings.steps as f64 * windows;
        job.verdict = if cost > 1.5 * CASE_STEPS {
            Verdict::Unbounded
        } else {
            match job.kind {
                Kind::Life if case.life.is_none() => {
                    Verdict::Refused("life: the case has no [life] section".into())
                }
                Kind::Stability if case.flow.is_none() => {
                    Verdict::Refused("flow: the case has no [flow] section".into())
                }
                Kind::Run => match Simulation::check(&case.model, &case.settings) {
                    Ok(stable_dt) => {
                        job.unbounded_dt = stable_dt == f64::INFINITY;
                        Verdict::Accepted
                    }
                    Err(e) => refused(&e, dir),
                },
                _ => Verdict::Accepted,
            }
        };
        return;
    }
    let study_name = job.files[0].0.clone();
    let read = |job: &Job| Study::from_toml_str(&job.files[0].1, dir, None);
    let study = match read(job) {
        Ok(s) => s,
        Err(e) => {
            job.verdict = refused(&e, dir);
            return;
        }
    };
    // the steps of all its runs, from the runs' cases as TOML
    let cost = |s: &Study| -> f64 {
        s.runs()
            .iter()
            .filter_map(|r| s.case_value(r).ok())
            .filter_map(|v| Some(steps_of(&v)? * windows_of(&v)))
            .sum()
    };
    let total = cost(&study);
    let study = if total > STUDY_STEPS {
        let f = STUDY_STEPS / total;
        let mut value: Value = toml::from_str(&job.files[0].1).expect("written by the test");
        scale_study_times(&mut value, f);
        let base_name = job.files[1].0.clone();
        let mut base: Value = toml::from_str(&job.files[1].1).expect("written by the test");
        scale_times(&mut base, f);
        job.set_file(&study_name, toml::to_string(&value).expect("TOML"));
        job.set_file(&base_name, toml::to_string(&base).expect("TOML"));
        job.bounded.push(format!("times × {f:.3e}"));
        job.write(dir);
        match read(job) {
            Ok(s) => s,
            Err(e) => {
                job.verdict = refused(&e, dir);
                return;
            }
        }
    } else {
        study
    };
    job.verdict = match study.check(0) {
        Err(e) => refused(&e, dir),
        Ok(_) => {
            let total = cost(&study);
            if total > 1.5 * STUDY_STEPS {
                Verdict::Unbounded
            } else {
                Verdict::Accepted
            }
        }
    };
}

/// The library's refusal as the command, run in `dir`, words it: file names relative to it.
fn refused(e: &fretdyn::Error, dir: &Path) -> Verdict {
    Verdict::Refused(e.to_string().replace(&format!("{}/", dir.display()), ""))
}

/// How a command ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum End {
    /// The mutated tree could not be written as TOML.
    Unwritable,
    /// Its cost could not be bounded.
    NotRun,
    /// Exit code.
    Code(i32),
    /// Killed by a signal.
    Signal(i32),
    /// Killed by the watchdog.
    Hang,
    /// The test itself panicked (in the library's reading of the input).
    TestPanic,
}

/// What one seed gave.
struct Report {
    seed: u64,
    kind: Option<Kind>,
    end: End,
    refused_by_library: bool,
    seconds: f64,
    /// The command's error line, if any.
    error: String,
    failure: Option<String>,
}

/// Runs `fretdyn args` in `dir` with its standard output and error in files there; `None`
/// when it ran past `timeout` (killed).
fn spawn(args: &[String], dir: &Path, timeout: Duration) -> Option<ExitStatus> {
    let file = |name: &str| std::fs::File::create(dir.join(name)).expect("scratch file");
    let mut child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(file("stdout.txt"))
        .stderr(file("stderr.txt"))
        .spawn()
        .expect("fretdyn starts");
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            return Some(status);
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// `message` with the figures that change from one moment to the next masked: the memory
/// available (`more than half of the 24.5 GB of memory available`) is read by the library's
/// check and by the command a moment apart.
fn steady(message: &str) -> String {
    const AVAILABLE: &str = " GB of memory available";
    let mut out = String::new();
    let mut rest = message;
    while let Some(i) = rest.find(AVAILABLE) {
        let figure = rest[..i].trim_end_matches(|c: char| c.is_ascii_digit() || c == '.');
        out.push_str(figure);
        out.push('…');
        out.push_str(AVAILABLE);
        rest = &rest[i + AVAILABLE.len()..];
    }
    out.push_str(rest);
    out
}

/// What the standard error says that it should not.
fn stderr_problems(stderr: &str, code: i32, verdict: &Verdict, problems: &mut Vec<String>) {
    for marker in [
        "panicked",
        "RUST_BACKTRACE",
        "fatal runtime error",
        "memory allocation",
    ] {
        if stderr.contains(marker) {
            problems.push(format!("'{marker}' on stderr"));
        }
    }
    // warnings, then at most one error, each on one line
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    let errors: Vec<&&str> = lines.iter().filter(|l| l.starts_with("error: ")).collect();
    if let Some(l) = lines
        .iter()
        .find(|l| !l.starts_with("warning: ") && !l.starts_with("error: "))
    {
        problems.push(format!(
            "a line on stderr that is neither a warning nor an error (a message of several lines?): {l}"
        ));
    }
    match code {
        0 if !errors.is_empty() => problems.push("exit code 0 with an error".into()),
        1 | 2 if errors.len() != 1 || !lines.last().is_some_and(|l| l.starts_with("error: ")) => {
            problems.push(format!(
                "exit code {code}: {} error lines, not one at the end",
                errors.len()
            ))
        }
        _ => {}
    }
    if let Verdict::Refused(message) = verdict {
        if code != 2 {
            problems.push(format!(
                "the library refuses the input ({message}), the command exits {code}"
            ));
        } else if !errors
            .iter()
            .any(|l| steady(l).contains(steady(message).as_str()))
        {
            problems.push(format!(
                "the command's error is not the library's ({message})"
            ));
        }
    }
}

/// Cells of a CSV file that are not finite numbers where they must be.
fn csv_problems(path: &Path, name: &str, problems: &mut Vec<String>) {
    let mut reader = match csv::ReaderBuilder::new().from_path(path) {
        Ok(r) => r,
        Err(e) => return problems.push(format!("{name}: {e}")),
    };
    let header: Vec<String> = match reader.headers() {
        Ok(h) => h.iter().map(String::from).collect(),
        Err(e) => return problems.push(format!("{name}: {e}")),
    };
    let col = |c: &str| header.iter().position(|h| h == c);
    // documented infinities: a criterion never reached, the ratio of an undamped mode
    let inf_column = |c: &str| {
        c.ends_with(".time_to_criterion")
            || c.ends_with(".time_to_criterion_fixed_gap")
            || c == "connors_max_ratio"
    };
    // the columns that echo the input: a study's parameters, a percentile's group
    let echo: Vec<usize> = match name {
        "study.csv" => {
            let end = col("sample").or(col("seed")).unwrap_or(0);
            (1..end).collect()
        }
        "percentiles.csv" => (0..col("column").unwrap_or(0)).collect(),
        _ => Vec::new(),
    };
    let mut bad = Vec::new();
    for (row, record) in reader.records().enumerate() {
        let record = match record {
            Ok(r) => r,
            Err(e) => {
                problems.push(format!("{name}: {e}"));
                return;
            }
        };
        for (i, cell) in record.iter().enumerate() {
            let Ok(x) = cell.trim().parse::<f64>() else {
                continue;
            };
            if x.is_finite() || echo.contains(&i) {
                continue;
            }
            let column = header.get(i).map_or("?", String::as_str);
            let allowed = x == f64::INFINITY
                && match name {
                    "study.csv" => inf_column(column),
                    "percentiles.csv" => {
                        ["estimate", "ci_low", "ci_high"].contains(&column)
                            && col("column")
                                .and_then(|c| record.get(c))
                                .is_some_and(inf_column)
                    }
                    // U_c = 0: an undamped or a rigid-body mode (docs/FLOW.md)
                    "stability.csv" => {
                        column == "ratio"
                            && col("critical_velocity")
                                .and_then(|c| record.get(c))
                                .and_then(|u| u.parse::<f64>().ok())
                                == Some(0.0)
                    }
                    _ => false,
                };
            if !allowed {
                bad.push(format!("row {} {column} = {cell}", row + 1));
            }
        }
    }
    if !bad.is_empty() {
        let n = bad.len();
        bad.truncate(5);
        problems.push(format!("{name}: {n} non-finite cells: {}", bad.join(", ")));
    }
}

/// Arrays of a `.npz` with a non-finite number.
fn npz_problems(path: &Path, name: &str, problems: &mut Vec<String>) {
    let file = std::fs::File::open(path).expect("open");
    let mut npz = match ndarray_npy::NpzReader::new(file) {
        Ok(n) => n,
        Err(e) => return problems.push(format!("{name}: {e}")),
    };
    let names = match npz.names() {
        Ok(n) => n,
        Err(e) => return problems.push(format!("{name}: {e}")),
    };
    for key in names {
        match npz.by_name::<ndarray::OwnedRepr<f64>, ndarray::IxDyn>(&key) {
            Ok(a) => {
                let n = a.iter().filter(|x| !x.is_finite()).count();
                if n > 0 {
                    problems.push(format!("{name}: {key}: {n} non-finite values"));
                }
            }
            // integers (contact_status) are finite
            Err(_)
                if npz
                    .by_name::<ndarray::OwnedRepr<i8>, ndarray::IxDyn>(&key)
                    .is_ok() => {}
            Err(e) => problems.push(format!("{name}: {key}: {e}")),
        }
    }
}

/// The nulls of a JSON output that stand for a non-finite number: all but those at the
/// places where null means "none".
fn json_problems(path: &Path, name: &str, unbounded_dt: bool, problems: &mut Vec<String>) {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let value: serde_json::Value = match serde_json::from_str(&text) {
        Ok(v) => v,
        Err(e) => return problems.push(format!("{name}: not JSON ({e})")),
    };
    let nulls = if name == "summary.json" {
        summary_non_finite(&value, unbounded_dt)
    } else {
        let mut nulls = Vec::new();
        non_finite_in_json(&value, "", &mut nulls);
        // the last part of the path, without an index
        let field = |p: &str| {
            p.trim_end_matches(|c: char| c == ']' || c.is_ascii_digit() || c == '[')
                .rsplit('.')
                .next()
                .unwrap_or("")
                .to_string()
        };
        let none: &[&str] = match name {
            // no criterion; a criterion not reached; a standard error of fewer than 2
            // batches; a divergence at no contact
            "life.json" => &[
                "criterion_depth",
                "time_to_criterion",
                "time_to_criterion_fixed_gap",
                "wear_work_rate_se",
                "contact",
            ],
            // U_eff = U_c = 0, or ∞ for an undamped mode (JSON has no infinity); no plane
            // (a straight tube)
            "stability.json" => &["ratio", "plane", "out_of_plane_share"],
            // what the samples cannot give (empty cells of percentiles.csv), or ∞
            "percentiles.json" => &[
                "estimate",
                "ci_low",
                "ci_high",
                "ci_coverage",
                "bootstrap_se",
            ],
            _ => &[],
        };
        nulls
            .into_iter()
            .filter(|p| !none.contains(&field(p).as_str()))
            .collect()
    };
    if !nulls.is_empty() {
        let n = nulls.len();
        let shown: Vec<String> = nulls.into_iter().take(5).collect();
        problems.push(format!(
            "{name}: {n} non-finite numbers (null): {}",
            shown.join(", ")
        ));
    }
}

/// Every output under `dir`, checked by its kind.
fn output_problems(dir: &Path, unbounded_dt: bool, problems: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            output_problems(&path, unbounded_dt, problems);
            continue;
        }
        match path.extension().and_then(|e| e.to_str()) {
            Some("json") => json_problems(&path, &name, unbounded_dt, problems),
            Some("csv") => csv_problems(&path, &name, problems),
            Some("npz") => npz_problems(&path, &name, problems),
            Some("npy") => match ndarray_npy::read_npy::<_, ndarray::ArrayD<f64>>(&path) {
                Ok(a) if a.iter().any(|x| !x.is_finite()) => {
                    problems.push(format!("{name}: non-finite values"))
                }
                _ => {}
            },
            _ => {}
        }
    }
}

/// Plans, judges, runs and checks the command of `seed` in `dir`.
fn one(seed: u64, examples: &Examples, dir: &Path, timeout: Duration) -> (Option<Job>, Report) {
    let start = Instant::now();
    let mut report = Report {
        seed,
        kind: None,
        end: End::Unwritable,
        refused_by_library: false,
        seconds: 0.0,
        error: String::new(),
        failure: None,
    };
    let Some(mut job) = plan(seed, examples) else {
        return (None, report);
    };
    report.kind = Some(job.kind);
    std::fs::create_dir_all(dir).expect("scratch folder");
    job.write(dir);
    let judged = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| judge(&mut job, dir)));
    if let Err(e) = judged {
        let message = e
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default();
        report.end = End::TestPanic;
        report.failure = Some(format!(
            "the library panicked reading the input in the test: {message}"
        ));
        return (Some(job), report);
    }
    report.refused_by_library = matches!(job.verdict, Verdict::Refused(_));
    if let Verdict::Unbounded = job.verdict {
        report.end = End::NotRun;
        return (Some(job), report);
    }
    let status = spawn(&job.args, dir, timeout);
    report.seconds = start.elapsed().as_secs_f64();
    let stderr = std::fs::read_to_string(dir.join("stderr.txt")).unwrap_or_default();
    report.error = stderr
        .lines()
        .filter(|l| l.starts_with("error: "))
        .collect::<Vec<_>>()
        .join(" / ");
    let mut problems = Vec::new();
    match status {
        None => {
            report.end = End::Hang;
            problems.push(format!(
                "no exit after {} s (a hang): killed",
                timeout.as_secs_f64()
            ));
        }
        Some(status) => match (status.code(), status.signal()) {
            (Some(code), _) => {
                report.end = End::Code(code);
                if !(0..=2).contains(&code) {
                    problems.push(format!(
                        "exit code {code}{}",
                        if code == 101 { " (a panic)" } else { "" }
                    ));
                }
                stderr_problems(&stderr, code, &job.verdict, &mut problems);
                let out = dir.join("out");
                output_problems(&out, job.unbounded_dt, &mut problems);
                if code == 0 {
                    for file in job.kind.results() {
                        if !out.join(file).exists() {
                            problems.push(format!("exit code 0 without {file}"));
                        }
                    }
                }
            }
            (None, signal) => {
                let signal = signal.unwrap_or(0);
                report.end = End::Signal(signal);
                problems.push(format!(
                    "killed by signal {signal}{}",
                    match signal {
                        6 => " (SIGABRT: an abort — a failed allocation, a stack overflow)",
                        9 => " (SIGKILL: out of memory?)",
                        11 => " (SIGSEGV)",
                        _ => "",
                    }
                ));
            }
        },
    }
    if !problems.is_empty() {
        let tail: Vec<&str> = stderr.lines().rev().take(12).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        report.failure = Some(format!(
            "{}\nstderr (end):\n{}",
            problems.join("\n"),
            tail.join("\n")
        ));
    }
    (Some(job), report)
}

/// The failure of a seed, with what reproduces it.
fn describe(job: Option<&Job>, report: &Report) -> String {
    let mut s = match job {
        Some(job) => job.label(),
        None => format!("seed {}", report.seed),
    };
    if let Some(Verdict::Refused(m)) = job.map(|j| &j.verdict) {
        s.push_str(&format!("\nthe library refuses it: {m}"));
    }
    s.push_str(&format!(
        "\n{}\nreproduce: FRETDYN_FUZZ_SEED={} FRETDYN_FUZZ_COMMANDS=1 cargo test --release --locked -p fretdyn-cli --test fuzz_commands",
        report.failure.as_deref().unwrap_or(""),
        report.seed
    ));
    if let Some(job) = job {
        for (name, text) in &job.files {
            s.push_str(&format!("\n--- {name} ---\n{text}"));
        }
    }
    s
}

/// What a worker is doing: the seed and since when, and whether inside the test's own process
/// (the library reading the input: a hang there cannot be killed).
#[derive(Clone, Copy)]
struct Busy {
    seed: u64,
    since: Instant,
}

/// The report of every command, with the description of its failure if it failed.
type Reports = Vec<(Report, Option<String>)>;

#[test]
fn mutated_inputs_to_the_commands_end_cleanly() {
    let count: usize = env_or("FRETDYN_FUZZ_COMMANDS", 800);
    let budget = Duration::from_secs_f64(env_or("FRETDYN_FUZZ_SECONDS", 180.0));
    let timeout = Duration::from_secs_f64(env_or("FRETDYN_FUZZ_TIMEOUT", 60.0));
    let seed0: u64 = env_or("FRETDYN_FUZZ_SEED", 2026);
    let verbose = env_or("FRETDYN_FUZZ_VERBOSE", 0) > 0;
    let examples = Arc::new(Examples::load());
    assert!(examples.cases.len() >= 5 && examples.studies.len() >= 3);
    let scratch = Arc::new(Scratch::new("commands"));
    let start = Instant::now();
    let next = Arc::new(AtomicUsize::new(0));
    let stop = Arc::new(AtomicBool::new(false));
    let reports: Arc<Mutex<Reports>> = Arc::default();
    let busy: Arc<Mutex<Vec<Option<Busy>>>> = Arc::new(Mutex::new(vec![None; WORKERS]));
    let workers: Vec<_> = (0..WORKERS)
        .map(|w| {
            let (examples, scratch, next, stop, reports, busy) = (
                examples.clone(),
                scratch.clone(),
                next.clone(),
                stop.clone(),
                reports.clone(),
                busy.clone(),
            );
            std::thread::spawn(move || {
                loop {
                    if stop.load(Ordering::Relaxed) || start.elapsed() > budget {
                        break;
                    }
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= count {
                        break;
                    }
                    let seed = seed0.wrapping_add(k as u64);
                    busy.lock().unwrap()[w] = Some(Busy {
                        seed,
                        since: Instant::now(),
                    });
                    let dir = scratch.0.join(format!("seed-{seed}"));
                    let (job, report) = one(seed, &examples, &dir, timeout);
                    if verbose && let Some(job) = &job {
                        eprintln!(
                            "{} → {:?} {:?} {}",
                            job.label(),
                            report.end,
                            job.verdict,
                            report.error
                        );
                    }
                    let failure = report
                        .failure
                        .is_some()
                        .then(|| describe(job.as_ref(), &report));
                    busy.lock().unwrap()[w] = None;
                    let _ = std::fs::remove_dir_all(&dir);
                    reports.lock().unwrap().push((report, failure));
                }
            })
        })
        .collect();
    // the watchdog of what runs in this process (the library reading an input): the spawned
    // commands have their own
    let mut stuck = None;
    while !workers.iter().all(|w| w.is_finished()) {
        std::thread::sleep(Duration::from_millis(100));
        let late = busy
            .lock()
            .unwrap()
            .iter()
            .flatten()
            .find(|b| b.since.elapsed() > timeout + Duration::from_secs(30))
            .copied();
        if let Some(b) = late {
            stop.store(true, Ordering::Relaxed);
            stuck = Some(b.seed);
            break;
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    let reports = std::mem::take(&mut *reports.lock().unwrap());
    // per command: spawned, refused by the library, exit codes, not run
    let mut table: BTreeMap<Kind, BTreeMap<End, usize>> = BTreeMap::new();
    let mut refused: BTreeMap<Kind, usize> = BTreeMap::new();
    let mut seconds: BTreeMap<Kind, f64> = BTreeMap::new();
    let mut unwritable = 0;
    let mut failures = Vec::new();
    for (r, failure) in &reports {
        match r.kind {
            Some(kind) => {
                *table.entry(kind).or_default().entry(r.end).or_default() += 1;
                *refused.entry(kind).or_default() += usize::from(r.refused_by_library);
                *seconds.entry(kind).or_default() += r.seconds;
            }
            None => unwritable += 1,
        }
        if let Some(f) = failure {
            failures.push(f.clone());
        }
    }
    eprintln!(
        "fuzz_commands: {} seeds in {elapsed:.1} s ({unwritable} mutations not writable as TOML)",
        reports.len()
    );
    for (kind, ends) in &table {
        let n: usize = ends.values().sum();
        let ends: Vec<String> = ends
            .iter()
            .map(|(e, n)| match e {
                End::Code(c) => format!("exit {c}: {n}"),
                other => format!("{other:?}: {n}"),
            })
            .collect();
        eprintln!(
            "  {:<9} {n:>4} commands ({} refused by the library), {}; {:.1} s of commands",
            kind.name(),
            refused[kind],
            ends.join(", "),
            seconds[kind]
        );
    }
    if let Some(seed) = stuck {
        failures.push(format!(
            "seed {seed}: no answer after {} s in the test's own process (the library reading the input hangs, or a command could not be killed); reproduce: FRETDYN_FUZZ_SEED={seed} FRETDYN_FUZZ_COMMANDS=1",
            timeout.as_secs_f64() + 30.0
        ));
    }
    assert!(
        failures.is_empty(),
        "{} of {} mutated commands failed:\n\n{}",
        failures.len(),
        reports.len(),
        failures.join("\n\n---\n\n")
    );
    assert!(
        reports.len() >= 20.min(count),
        "too few commands in the time budget"
    );
    // the scratch folder goes with the last reference
    drop(scratch);
}
