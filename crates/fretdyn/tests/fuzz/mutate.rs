//! What the two fuzz tests share (`#[path = "…/fuzz/mutate.rs"] mod mutate;`): the example
//! files as TOML trees, a seeded random stream, the mutations of a TOML tree, and the check
//! of a `summary.json` for non-finite numbers. `crates/fretdyn/tests/fuzz_cases.rs` runs the
//! mutated cases through the library, `crates/fretdyn-cli/tests/fuzz_commands.rs` through the
//! `fretdyn` commands.
//!
//! A mutation is one of: a number replaced by 0, its negative, a huge or tiny multiple, NaN
//! or ±∞; a string emptied or replaced by another string of the file; a key removed; an array
//! shortened, emptied or with an element repeated (two contacts with the same name, …); a
//! value of another type.
#![allow(dead_code)] // each test uses a part

use std::path::{Path, PathBuf};

use toml::Value;

/// SplitMix64: a seeded stream of pseudo-random numbers (reproducible failures).
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// The environment variable `key` parsed, or `default`.
pub fn env_or<T: std::str::FromStr>(key: &str, default: T) -> T {
    std::env::var(key)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Every `examples/*.toml` (case and study files) as a TOML tree, sorted by path.
pub fn example_files() -> Vec<(PathBuf, Value)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("examples folder") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            let text = std::fs::read_to_string(&path).expect("example readable");
            let value: Value = toml::from_str(&text).expect("example is TOML");
            out.push((path, value));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// Whether a TOML tree is a study file (a base case and parameters), not a case.
pub fn is_study(value: &Value) -> bool {
    value.get("base").is_some()
}

/// Every path to a value in the tree (tables and arrays included), as index chains.
#[derive(Clone, Debug)]
pub enum Step {
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

/// One random mutation of `doc`; returns what it did.
pub fn mutate(doc: &mut Value, rng: &mut Rng) -> String {
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

/// Every f64 of a JSON tree that is not finite (JSON null stands for a non-finite number in
/// the files fretdyn writes), by its path.
pub fn non_finite_in_json(v: &serde_json::Value, path: &str, out: &mut Vec<String>) {
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

/// The non-finite numbers of a run's summary (`summary.json`), by their path. Not results,
/// so not looked at: the echo of the case (it may hold the user's own NaN) and an obstacle
/// without an outline (a plane is a null in `contact_geometry`); `time.stable_dt` is ∞ (null)
/// for a model without stiffness (free masses, no contact: `unbounded`), which has no
/// stability limit.
pub fn summary_non_finite(summary: &serde_json::Value, unbounded: bool) -> Vec<String> {
    let mut nulls = Vec::new();
    for key in ["time", "contacts", "energy_balance", "solver"] {
        if let Some(v) = summary.get(key) {
            non_finite_in_json(v, key, &mut nulls);
        }
    }
    nulls
        .into_iter()
        .filter(|p| !(unbounded && p == "time.stable_dt"))
        .collect()
}
