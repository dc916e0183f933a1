//! `fretdyn-bench --against-c DIR`: fretdyn and the plain C step of the shared perf folder
//! (`step_ref.c`, an independent implementation of the same algorithm) compute the same
//! thing on case S1, and the report has its rows. Skipped, with a note, where the perf folder
//! or gcc is absent.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn fretdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fretdyn-bench"))
        .args(args)
        .output()
        .expect("fretdyn runs")
}

/// The shared perf folder next to the repository (`../shared/perf` from the workspace root).
fn perf_dir() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/perf");
    if !dir.join("step_ref.c").is_file() {
        eprintln!("note: {} absent: test skipped", dir.display());
        return None;
    }
    if Command::new("gcc").arg("--version").output().is_err() {
        eprintln!("note: no gcc: test skipped");
        return None;
    }
    Some(dir)
}

/// The cells of the markdown table row that starts with `| {first} |`.
fn row<'a>(text: &'a str, first: &str) -> Vec<&'a str> {
    let start = format!("| {first} |");
    let line = text
        .lines()
        .find(|l| l.starts_with(&start))
        .unwrap_or_else(|| panic!("no row {first} in\n{text}"));
    line.trim_matches('|').split('|').map(str::trim).collect()
}

#[test]
fn s1_agrees_with_the_c_program_and_is_timed() {
    let Some(dir) = perf_dir() else { return };
    let out = fretdyn(&[
        "--against-c",
        dir.to_str().unwrap(),
        "--only",
        "s1",
        "--reps",
        "1",
        "--steps",
        "2000",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}\n{stdout}");
    assert!(stdout.contains("**fretdyn and C agree**"), "{stdout}");

    // the agreement, recomputed here from the two programs' numbers
    let s1 = row(&stdout, "S1");
    let num = |i: usize| -> f64 { s1[i].parse().unwrap_or_else(|_| panic!("{}", s1[i])) };
    let (q_c, q_f, d_c, d_f) = (num(1), num(2), num(4), num(5));
    assert!(q_c > 0.0 && d_c > 0.0, "{s1:?}");
    assert!(
        (q_f - q_c).abs() <= 1e-12 * q_c,
        "sum|q|: C {q_c} fretdyn {q_f}"
    );
    assert!(
        (d_f - d_c).abs() <= 1e-12 * d_c,
        "dissipation: C {d_c} fretdyn {d_f}"
    );
    let sweeps: u64 = s1[7].parse().unwrap();
    assert!(sweeps > 0);
    assert_eq!(s1[7], s1[8], "PGS sweeps C and fretdyn");

    // one timing row per fretdyn method; with one pair the ratio is fretdyn/C of that pair
    for method in ["gs_radial", "gs_exact", "active_set", "penalty"] {
        let r = row(&stdout, method);
        assert_eq!((r[1], r[2]), ("2000", "1"), "{r:?}");
        let c: f64 = r[3].parse().unwrap();
        let f: f64 = r[4].parse().unwrap();
        let ratio: f64 = r[5].parse().unwrap();
        assert!(c > 0.0 && f > 0.0, "{r:?}");
        assert!((ratio - f / c).abs() <= 1e-3 + 1e-3 * ratio, "{r:?}");
    }
    assert!(stdout.contains("- machine: "), "{stdout}");
    assert!(
        stdout.contains("--only s1 --reps 1 --steps 2000"),
        "{stdout}"
    );
    assert!(stderr.contains("pair 1/1"), "progress on stderr: {stderr}");
}

#[test]
fn a_different_computation_is_flagged_and_fails() {
    let Some(dir) = perf_dir() else { return };
    // a copy of the S1 files whose fretdyn case has μ = 0.31 instead of the C program's 0.3
    let copy = std::env::temp_dir().join(format!("fretdyn-against-c-mu-{}", std::process::id()));
    let s1 = copy.join("fretdyn_cases/s1");
    std::fs::create_dir_all(&s1).unwrap();
    for f in ["step_ref.c", "s1_case.bin"] {
        std::fs::copy(dir.join(f), copy.join(f)).unwrap();
    }
    let cases = dir.join("fretdyn_cases/s1");
    for entry in std::fs::read_dir(&cases).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name == "basis_s1.npz" || name.ends_with("_200000.toml") {
            std::fs::copy(cases.join(&name), s1.join(&name)).unwrap();
        }
    }
    let text = std::fs::read_to_string(cases.join("s1_gs_radial_2000.toml")).unwrap();
    assert!(text.contains("mu = 0.3 }"));
    std::fs::write(
        s1.join("s1_gs_radial_2000.toml"),
        text.replace("mu = 0.3 }", "mu = 0.31 }"),
    )
    .unwrap();

    let out = fretdyn(&[
        "--against-c",
        copy.to_str().unwrap(),
        "--only",
        "s1",
        "--reps",
        "1",
        "--steps",
        "100",
    ]);
    let _ = std::fs::remove_dir_all(&copy);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stdout.contains("**DISAGREEMENT"), "{stdout}");
    assert!(stderr.contains("DISAGREEMENT on S1"), "{stderr}");
    assert!(
        stderr
            .trim_end()
            .lines()
            .last()
            .unwrap()
            .starts_with("error: fretdyn and C disagree")
    );
}

#[test]
fn missing_folder_is_a_one_line_input_error() {
    let out = fretdyn(&["--against-c", "no/such/perf", "--only", "s1"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("no/such/perf") && stderr.contains("../shared/perf"),
        "{stderr}"
    );
    assert!(out.stdout.is_empty());
}

#[test]
fn write_needs_five_reps_and_reps_needs_against_c() {
    let out = fretdyn(&["--against-c", "perf", "--reps", "3", "--write", "PERF.md"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--reps 5"), "{stderr}");

    let out = fretdyn(&["--reps", "3"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--against-c"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
}
