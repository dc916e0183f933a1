//! `fretdyn sweep` as safe as `fretdyn run`: a table tied to the inputs of its rows (a study
//! whose base case changed is refused, not answered with the old rows), one study per folder,
//! a clean stop on SIGTERM that the next sweep continues, bounded `--jobs`; and a signal during
//! a long set-up stops the program at once.

mod common;
use std::path::Path;
use std::process::{Command, Stdio};

use common::{Scratch, examples, fretdyn};

/// V1a with the friction coefficient as a parameter: `n` runs of `duration` s each.
fn write_study(dir: &Path, n: usize, duration: f64) {
    let base = std::fs::read_to_string(examples().join("v1a_oblique_impact.toml"))
        .unwrap()
        .replace("duration = 4e-3", &format!("duration = {duration}"));
    std::fs::write(dir.join("v1a.toml"), base).unwrap();
    let values: Vec<String> = (0..n)
        .map(|k| format!("{}", 0.1 + 0.05 * k as f64))
        .collect();
    std::fs::write(
        dir.join("study.toml"),
        format!(
            "base = \"v1a.toml\"\nseeds = []\n\n[[parameters]]\nkey = \"contacts.*.friction.mu\"\nvalues = [{}]\n\n[percentiles]\nstatistics = [\"wear_work_rate\"]\n",
            values.join(", ")
        ),
    )
    .unwrap();
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The base case edited (μ 0.3 → 0.6 in the case; here its normal stiffness) and the study
/// swept again into the same folder: refused (exit 2), saying which key changed and how to
/// start afresh; it used to print "0 runs (2 already in the table)" and present the old
/// numbers as the new study's. `--fresh` reruns every run.
#[test]
fn a_study_whose_base_case_changed_is_not_answered_with_the_old_rows() {
    let s = Scratch::new("stale");
    write_study(&s.0, 2, 4e-3);
    let out = fretdyn(&["sweep", "study.toml", "-o", "out", "-q"], &s.0);
    assert!(out.status.success(), "{}", stderr(&out));
    let before = std::fs::read_to_string(s.0.join("out/study.csv")).unwrap();
    let base = std::fs::read_to_string(s.0.join("v1a.toml")).unwrap();
    std::fs::write(
        s.0.join("v1a.toml"),
        base.replace("stiffness = 1e6", "stiffness = 4e6"),
    )
    .unwrap();
    let out = fretdyn(&["sweep", "study.toml", "-o", "out", "-q"], &s.0);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    assert!(
        e.contains("2 of its 2 rows were computed from other inputs")
            && e.contains("contacts.0.normal.stiffness: 1000000.0 → 4000000.0")
            && e.contains("--fresh"),
        "{e}"
    );
    assert_eq!(
        std::fs::read_to_string(s.0.join("out/study.csv")).unwrap(),
        before
    );
    let out = fretdyn(&["sweep", "study.toml", "-o", "out", "--fresh"], &s.0);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("2 runs in"));
    let after = std::fs::read_to_string(s.0.join("out/study.csv")).unwrap();
    assert_eq!(after.lines().count(), 3);
    assert_ne!(after, before);
}

/// A sweep stopped by SIGTERM drops the runs under way (no row cut, no row of a run that
/// did not end), writes no percentiles of the incomplete table, says how to continue (exit
/// 1); a second sweep on the folder while the first runs is refused; the next sweep does the
/// runs left and gives the rows of an uninterrupted study.
#[test]
fn a_sweep_stopped_by_a_signal_is_continued_by_the_next() {
    let s = Scratch::new("signal");
    // 8 runs of 2 s simulated (2 million steps each, about a second), one at a time
    write_study(&s.0, 8, 2.0);
    let mut child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args(["sweep", "study.toml", "-o", "out", "-q", "-j", "1"])
        .current_dir(&s.0)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // one row at least, then the signal in the middle of a run
    let table = s.0.join("out/study.csv");
    let start = std::time::Instant::now();
    while std::fs::read_to_string(&table).map_or(0, |t| t.lines().count()) < 2 {
        assert!(child.try_wait().unwrap().is_none(), "the sweep ended first");
        assert!(start.elapsed().as_secs() < 300);
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // a second sweep on the folder
    let out = fretdyn(&["sweep", "study.toml", "-o", "out", "-q"], &s.0);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert!(e.contains("another fretdyn sweep (process"), "{e}");
    std::thread::sleep(std::time::Duration::from_millis(100));
    Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(
        e.contains("interrupted")
            && e.contains("continue it with: fretdyn sweep study.toml -o out"),
        "{e}"
    );
    let text = std::fs::read_to_string(&table).unwrap();
    assert!(text.ends_with('\n'));
    let rows = text.lines().count() - 1;
    assert!((1..8).contains(&rows), "{rows} rows");
    assert!(!s.0.join("out/percentiles.csv").exists());
    // continued
    let out = fretdyn(&["sweep", "study.toml", "-o", "out", "-q"], &s.0);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(s.0.join("out/percentiles.csv").exists());
    let mut done: Vec<String> = std::fs::read_to_string(&table)
        .unwrap()
        .lines()
        .skip(1)
        .map(String::from)
        .collect();
    done.sort_by_key(|l| l.split(',').next().unwrap().parse::<usize>().unwrap());
    let indices: Vec<usize> = done
        .iter()
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(indices, (0..8).collect::<Vec<_>>());
}

/// `-j 5000` started 5000 threads (18 s) for a study of two runs: refused, with the bound.
#[test]
fn too_many_jobs_are_refused() {
    let s = Scratch::new("jobs");
    write_study(&s.0, 2, 4e-3);
    let out = fretdyn(&["sweep", "study.toml", "-o", "out", "-j", "5000"], &s.0);
    let e = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert!(e.contains("--jobs 5000: at most"), "{e}");
    assert!(!s.0.join("out").exists());
}

/// SIGTERM during a long set-up (a 7 000-degree-of-freedom modal analysis of a finely meshed
/// tube, a minute here) stops the program at once: nothing is written yet. It used to be
/// swallowed until the set-up ended.
#[test]
fn a_signal_during_the_set_up_stops_at_once() {
    let s = Scratch::new("setup");
    let case = std::fs::read_to_string(examples().join("tube_multispan.toml"))
        .unwrap()
        .replace("mesh_size = 0.05", "mesh_size = 0.005");
    std::fs::write(s.0.join("big.toml"), case).unwrap();
    for command in [
        &["run", "big.toml", "-o", "out", "-q"][..],
        &["life", "big.toml"],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
            .args(command)
            .current_dir(&s.0)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(1500));
        assert!(
            child.try_wait().unwrap().is_none(),
            "the set-up ended first"
        );
        let sent = std::time::Instant::now();
        Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status()
            .unwrap();
        let out = child.wait_with_output().unwrap();
        let waited = sent.elapsed().as_secs_f64();
        let e = stderr(&out);
        assert!(
            waited < 5.0,
            "{command:?}: stopped {waited:.1} s after the signal"
        );
        assert_eq!(out.status.code(), Some(1), "{e}");
        assert!(e.contains("interrupted during the set-up"), "{e}");
        assert!(!s.0.join("out").exists());
    }
}
