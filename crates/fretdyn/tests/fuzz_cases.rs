//! Fuzz test over mutated example case files (issue [2.1]): every mutation of a valid case must
//! either be refused with an input error, or run; no panic, no hang, and a run that succeeds has
//! only finite numbers in its results and in its summary.
//!
//! Each case is one of `examples/*.toml` with 1–3 random mutations of its TOML tree
//! (`tests/fuzz/mutate.rs`, shared with the command-line fuzz test
//! `crates/fretdyn-cli/tests/fuzz_commands.rs`, which runs `run`, `life`, `stability`, `modes`
//! and `sweep` as a user does): a number
//! replaced by 0, its negative, a huge or tiny multiple, NaN or ±∞; a string emptied or
//! replaced by another string of the file; a key removed; an array shortened, emptied or with an
//! element repeated (two contacts with the same name, …); a value of another type. The seeds are
//! fixed, so a failure is reproducible: the message gives the seed and the mutated case.
//!
//! Budget: `FRETDYN_FUZZ_CASES` cases (default 2000) and `FRETDYN_FUZZ_SECONDS` of wall time
//! (default 120), whichever ends first; a case that takes more than `FRETDYN_FUZZ_TIMEOUT`
//! seconds (default 60) is a hang. Runs longer than 20 000 steps are only validated, not run
//! (a long run is not a hang).

use std::path::PathBuf;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use fretdyn::case::Case;
use fretdyn::integrator::simulation::simulate;
use toml::Value;

#[path = "fuzz/mutate.rs"]
mod mutate;
use mutate::{Rng, env_or, mutate, summary_non_finite};

/// The example case files (study files are not cases).
fn examples() -> Vec<(PathBuf, Value)> {
    mutate::example_files()
        .into_iter()
        .filter(|(_, value)| !mutate::is_study(value))
        .collect()
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
    let summary = fretdyn::output::summary::summary(&case, &results);
    // a model without stiffness (free masses, no contact) has no stability limit: its
    // `stable_dt` is ∞, written as null
    let unbounded = results.stable_dt == f64::INFINITY;
    bad.extend(summary_non_finite(&summary, unbounded));
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
