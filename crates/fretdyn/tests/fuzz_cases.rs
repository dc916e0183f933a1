//! Fuzz test over mutated example case files (issue [2.1]): every mutation of a valid case must
//! either be refused with an input error, or run; no panic, no hang, and a run that succeeds has
//! only finite numbers in its results and in its summary.
//!
//! Each case is one of `examples/*.toml` with 1–3 random mutations of its TOML tree: a number
//! replaced by 0, its negative, a huge or tiny multiple, NaN or ±∞; a string emptied or
//! replaced by another string of the file; a key removed; an array shortened, emptied or with an
//! element repeated (two contacts with the same name, …); a value of another type. The seeds are
//! fixed, so a failure is reproducible: the message gives the seed and the mutated case.
//!
//! Budget: `FRETDYN_FUZZ_CASES` cases (default 2000) and `FRETDYN_FUZZ_SECONDS` of wall time
//! (default 120), whichever ends first; a case that takes more than `FRETDYN_FUZZ_TIMEOUT`
//! seconds (default 60) is a hang. Runs longer than 20 000 steps are only validated, not run
//! (a long run is not a hang).

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use fretdyn::case::Case;
use fretdyn::integrator::simulation::simulate;
use toml::Value;

/// SplitMix64: a seeded stream of pseudo-random numbers (reproducible failures).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn env_or<T: std::str::FromStr>(key: &str, default: T) -> T {
    std::env::var(key)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn examples() -> Vec<(PathBuf, Value)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("examples folder") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            let text = std::fs::read_to_string(&path).expect("example readable");
            let value: Value = toml::from_str(&text).expect("example is TOML");
            // study files are not cases
            if value.get("base").is_none() {
                out.push((path, value));
            }
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// Every path to a value in the tree (tables and arrays included), as index chains.
#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

fn paths(v: &Value, prefix: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    out.push(prefix.clone());
    match v {
        Value::Table(t) => {
            for (k, child) in t {
                prefix.push(Step::Key(k.clone()));
                paths(child, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                prefix.push(Step::Index(i));
                paths(child, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn get_mut<'a>(v: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    let mut cur = v;
    for s in path {
        cur = match (s, cur) {
            (Step::Key(k), Value::Table(t)) => t.get_mut(k)?,
            (Step::Index(i), Value::Array(a)) => a.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(cur)
}

fn strings(v: &Value, out: &mut Vec<String>) {
    match v {
        Value::String(s) => out.push(s.clone()),
        Value::Table(t) => t.values().for_each(|c| strings(c, out)),
        Value::Array(a) => a.iter().for_each(|c| strings(c, out)),
        _ => {}
    }
}

fn mutate_number(x: f64, rng: &mut Rng) -> f64 {
    match rng.below(15) {
        0 => 0.0,
        1 => -x,
        2 => x * 1e3,
        3 => x * 1e-3,
        4 => x * 1e12,
        5 => x * 1e-12,
        6 => f64::NAN,
        7 => f64::INFINITY,
        8 => f64::NEG_INFINITY,
        9 => 1e300,
        10 => -1.0,
        11 => x * 2.0,
        12 => x * 0.5,
        13 => x * 1.1,
        _ => x + 1.0,
    }
}

fn mutate(doc: &mut Value, rng: &mut Rng) -> String {
    let mut all = Vec::new();
    paths(doc, &mut Vec::new(), &mut all);
    let path = all[rng.below(all.len())].clone();
    let mut words = Vec::new();
    strings(doc, &mut words);
    let describe = format!("{path:?}");
    // removing a key or an array element needs the parent
    if rng.below(8) == 0 && !path.is_empty() {
        let (last, parent) = path.split_last().expect("non-empty");
        if let Some(p) = get_mut(doc, parent) {
            match (last, p) {
                (Step::Key(k), Value::Table(t)) => {
                    t.remove(k);
                }
                (Step::Index(i), Value::Array(a)) => {
                    a.remove(*i);
                }
                _ => {}
            }
        }
        return format!("removed {describe}");
    }
    let Some(target) = get_mut(doc, &path) else {
        return "nothing".into();
    };
    let what = match target {
        Value::Integer(i) => {
            let x = mutate_number(*i as f64, rng);
            *target = if rng.below(2) == 0 && x.is_finite() && x.abs() < 9e18 {
                Value::Integer(x as i64)
            } else {
                Value::Float(x)
            };
            "number"
        }
        Value::Float(x) => {
            *target = Value::Float(mutate_number(*x, rng));
            "number"
        }
        Value::String(s) => {
            *s = match rng.below(3) {
                0 => String::new(),
                1 => "nothere".into(),
                _ => words[rng.below(words.len())].clone(),
            };
            "string"
        }
        Value::Boolean(b) => {
            *b = !*b;
            "bool"
        }
        Value::Array(a) => {
            match rng.below(4) {
                0 => a.clear(),
                1 if !a.is_empty() => {
                    let i = rng.below(a.len());
                    a.insert(i, a[i].clone());
                }
                2 if !a.is_empty() => {
                    a.pop();
                }
                _ => a.push(Value::Float(1.0)),
            }
            "array"
        }
        Value::Table(t) => {
            if rng.below(2) == 0 {
                t.insert("unknown_key".into(), Value::Integer(1));
            } else {
                *target = Value::Float(1.0);
            }
            "table"
        }
        Value::Datetime(_) => "datetime",
    };
    format!("{what} at {describe}")
}

/// Every f64 of the summary (JSON null stands for a non-finite number there).
fn non_finite_in_json(v: &serde_json::Value, path: &str, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Null => out.push(path.to_string()),
        serde_json::Value::Number(n) if !n.as_f64().is_some_and(f64::is_finite) => {
            out.push(path.to_string())
        }
        serde_json::Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, c)| non_finite_in_json(c, &format!("{path}[{i}]"), out)),
        serde_json::Value::Object(o) => o
            .iter()
            .for_each(|(k, c)| non_finite_in_json(c, &format!("{path}.{k}"), out)),
        _ => {}
    }
}

/// What happened to one mutated case.
enum Outcome {
    Refused,
    Validated,
    Ran,
    Bad(String),
}

fn check(text: String, base: PathBuf) -> Outcome {
    let case = match Case::from_toml_str(&text, &base) {
        Ok(c) => c,
        Err(e) => {
            let msg = e.to_string();
            if msg.contains('\n') {
                return Outcome::Bad(format!("multi-line error: {msg}"));
            }
            return Outcome::Refused;
        }
    };
    if case.settings.steps > 20_000 {
        return Outcome::Validated;
    }
    let results = match simulate(&case.model, &case.settings) {
        Ok(r) => r,
        Err(_) => return Outcome::Refused,
    };
    let mut bad = Vec::new();
    let rec = &results.recorder;
    let arrays: [(&str, &[f64]); 7] = [
        ("t", rec.t.as_slice().unwrap_or(&[])),
        ("q", rec.q.as_slice().unwrap_or(&[])),
        ("qdot", rec.qdot.as_slice().unwrap_or(&[])),
        ("normal_force", rec.normal_force.as_slice().unwrap_or(&[])),
        (
            "tangential_force",
            rec.tangential_force.as_slice().unwrap_or(&[]),
        ),
        ("slip_velocity", rec.slip_velocity.as_slice().unwrap_or(&[])),
        ("penetration", rec.penetration.as_slice().unwrap_or(&[])),
    ];
    for (name, a) in arrays {
        if a.iter().any(|x| !x.is_finite()) {
            bad.push(format!("results.{name}"));
        }
    }
    if rec.position.iter().any(|x| !x.is_finite()) {
        bad.push("results.position".into());
    }
    let summary = fretdyn::results::output::summary(&case, &results);
    // a model without stiffness (free masses, no contact) has no stability limit: its
    // `stable_dt` is ∞, written as null
    let unbounded = results.stable_dt == f64::INFINITY;
    let mut nulls = Vec::new();
    // the echo of the case may hold the user's own NaN: it is not a result; an obstacle
    // without an outline (a plane) is a null in `contact_geometry`
    for key in ["time", "contacts", "energy_balance", "solver"] {
        if let Some(v) = summary.get(key) {
            non_finite_in_json(v, key, &mut nulls);
        }
    }
    bad.extend(
        nulls
            .into_iter()
            .filter(|p| !(unbounded && p == "time.stable_dt")),
    );
    if bad.is_empty() {
        Outcome::Ran
    } else {
        Outcome::Bad(format!(
            "non-finite values in a run that ended as {:?}: {}",
            results.termination,
            bad.join(", ")
        ))
    }
}

#[test]
fn mutated_example_cases_are_refused_or_run_cleanly() {
    let cases: usize = env_or("FRETDYN_FUZZ_CASES", 2000);
    let budget = Duration::from_secs_f64(env_or("FRETDYN_FUZZ_SECONDS", 120.0));
    let timeout = Duration::from_secs_f64(env_or("FRETDYN_FUZZ_TIMEOUT", 60.0));
    let seed0: u64 = env_or("FRETDYN_FUZZ_SEED", 2026);
    let examples = examples();
    assert!(examples.len() >= 5, "the examples folder holds the cases");
    let start = Instant::now();
    let (mut refused, mut validated, mut ran) = (0, 0, 0);
    let mut failures = Vec::new();
    let mut done = 0;
    for k in 0..cases {
        if start.elapsed() > budget {
            break;
        }
        let seed = seed0.wrapping_add(k as u64);
        let mut rng = Rng(seed);
        let (path, doc) = &examples[rng.below(examples.len())];
        let mut doc = doc.clone();
        let mut what = Vec::new();
        for _ in 0..1 + rng.below(3) {
            what.push(mutate(&mut doc, &mut rng));
        }
        let Ok(text) = toml::to_string(&doc) else {
            continue; // a mutation TOML cannot write (e.g. a table turned into a float at the root)
        };
        let base = path.parent().expect("folder").to_path_buf();
        let (tx, rx) = mpsc::channel();
        let text_for_run = text.clone();
        std::thread::spawn(move || {
            let outcome = std::panic::catch_unwind(move || check(text_for_run, base));
            let _ = tx.send(outcome);
        });
        let label = format!(
            "seed {seed} ({}; {})",
            path.file_name().unwrap().to_string_lossy(),
            what.join("; ")
        );
        match rx.recv_timeout(timeout) {
            Ok(Ok(Outcome::Refused)) => refused += 1,
            Ok(Ok(Outcome::Validated)) => validated += 1,
            Ok(Ok(Outcome::Ran)) => ran += 1,
            Ok(Ok(Outcome::Bad(msg))) => failures.push(format!("{label}: {msg}\n{text}")),
            Ok(Err(_)) => failures.push(format!("{label}: panicked\n{text}")),
            Err(_) => {
                failures.push(format!(
                    "{label}: no answer after {timeout:?} (hang)\n{text}"
                ));
                break; // the thread cannot be stopped: report what we have
            }
        }
        done += 1;
    }
    eprintln!(
        "fuzz: {done} mutated cases in {:.1} s: {refused} refused, {validated} validated only, {ran} ran",
        start.elapsed().as_secs_f64()
    );
    assert!(
        failures.is_empty(),
        "{} of {done} mutated cases failed:\n\n{}",
        failures.len(),
        failures.join("\n\n---\n\n")
    );
    assert!(done >= 20.min(cases), "too few cases in the time budget");
}
