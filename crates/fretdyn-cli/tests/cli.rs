//! The `fretdyn` command as a user meets it: outputs of a run, and one-line errors with a
//! non-zero exit code and no output for bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::{Scratch, examples, fretdyn, kill_past_checkpoint};

const V1A: &str = include_str!("../../../examples/v1a_oblique_impact.toml");

#[test]
fn run_writes_npz_summary_and_plot() {
    let s = Scratch::new("run");
    let case = examples().join("v1a_oblique_impact.toml");
    let out = fretdyn(
        &["run", case.to_str().unwrap(), "-o", "out", "--quiet"],
        &s.0,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dir = s.0.join("out");
    for f in ["results.npz", "summary.json", "contact_forces.png"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    let mut npz =
        ndarray_npy::NpzReader::new(std::fs::File::open(dir.join("results.npz")).unwrap()).unwrap();
    let t: ndarray::Array1<f64> = npz.by_name("t").unwrap();
    let rn: ndarray::Array2<f64> = npz.by_name("contact_normal_force").unwrap();
    let rt: ndarray::Array3<f64> = npz.by_name("contact_tangential_force").unwrap();
    let st: ndarray::Array2<i8> = npz.by_name("contact_status").unwrap();
    assert_eq!(t.len(), 4001);
    assert_eq!(rn.shape(), [4001, 1]);
    assert_eq!(rt.shape(), [4001, 1, 2]);
    assert!(st.iter().all(|s| (0..=2).contains(s)));
    // the peak normal force is m v_n ω (THEORY §6)
    let peak = rn.iter().copied().fold(0.0, f64::max);
    let expected = 20f64.to_radians().cos() * 1000.0;
    assert!((peak - expected).abs() < 1e-3 * expected, "{peak}");

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["termination"]["status"], "completed");
    assert_eq!(summary["time"]["steps"], 4000);
    let c = &summary["contacts"][0];
    assert_eq!(c["name"], "plane");
    assert_eq!(c["impacts"], 1);
    // all the tangential kinetic energy ½ m (V sin α)² is dissipated by friction before the stick
    let wear = c["wear_work"].as_f64().unwrap();
    let analytic = 0.5 * 20f64.to_radians().sin().powi(2);
    assert!(
        (wear - analytic).abs() < 1e-4 * analytic,
        "{wear} vs {analytic}"
    );
    assert!(
        summary["energy_balance"]["relative_error"]
            .as_f64()
            .unwrap()
            < 1e-6
    );
    assert!(summary["performance"]["steps_per_second"].as_f64().unwrap() > 0.0);
    assert_eq!(summary["case"]["tangential"]["method"], "gauss_seidel");
}

#[test]
fn demo_runs_three_methods() {
    let s = Scratch::new("demo");
    let out = fretdyn(&["run", "-o", "demo"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("demo written to demo"), "{stdout}");
    for m in ["active_set", "gauss_seidel", "penalty"] {
        assert!(
            s.0.join("demo").join(m).join("results.npz").is_file(),
            "{m}"
        );
    }
    assert!(s.0.join("demo/friction_force.png").is_file());
}

/// Writes `case` to a file, runs it, and checks: exit code 2, one line on stderr naming the
/// file and containing every `needles`, nothing written.
fn assert_input_error(name: &str, case: &str, needles: &[&str]) {
    let s = Scratch::new(name);
    std::fs::write(s.0.join("case.toml"), case).unwrap();
    let out = fretdyn(&["run", "case.toml", "-o", "out"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{name}: {stderr}");
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "{name}: not one line: {stderr}"
    );
    assert!(stderr.starts_with("error: case.toml: "), "{name}: {stderr}");
    for n in needles {
        assert!(stderr.contains(n), "{name}: '{n}' not in: {stderr}");
    }
    assert!(
        !s.0.join("out").exists(),
        "{name}: output written for a bad input"
    );
    assert!(!stderr.contains("panicked"), "{name}: {stderr}");
}

#[test]
fn time_step_above_the_stable_limit() {
    // ω = 1000 rad/s: the limit is 2 ms
    let case = V1A.replace("dt = 1e-6 ", "dt = 3e-3 ");
    assert_input_error(
        "dt",
        &case,
        &["time.dt", "stable limit 2e-3", "set time.dt ≤ 1.8e-3"],
    );
}

#[test]
fn negative_mass() {
    let case = V1A.replace("mass = 1.0 ", "mass = -1.0 ");
    assert_input_error("mass", &case, &["structure.mass", "positive"]);
}

#[test]
fn negative_contact_stiffness() {
    let case = V1A.replace("stiffness = 1e6,", "stiffness = -1e6,");
    assert_input_error("kn", &case, &["contacts[0].normal.stiffness", "positive"]);
}

#[test]
fn non_finite_mode_shape() {
    let case = include_str!("../../../examples/v1a_modal_inline.toml")
        .replace("[0.0, 1.0, 0.0],", "[0.0, nan, 0.0],");
    assert_input_error(
        "nan",
        &case,
        &["structure.points.mass.rows", "not finite", "y", "mode 1"],
    );
}

#[test]
fn unknown_key() {
    let case = V1A.replace("duration = 4e-3", "duration = 4e-3\nstep = 2");
    assert_input_error(
        "key",
        &case,
        &["line 18", "time.step: unknown key", "dt, duration"],
    );
}

#[test]
fn unknown_method() {
    let case = V1A.replace("method = \"gauss_seidel\"", "method = \"newton\"");
    assert_input_error(
        "method",
        &case,
        &["newton", "gauss_seidel", "active_set", "penalty"],
    );
}

#[test]
fn missing_modal_file() {
    let case =
        "[time]\ndt = 1e-6\nduration = 1e-3\n[structure]\ntype = \"modal\"\nfile = \"basis.npz\"\n";
    assert_input_error("npz", case, &["basis.npz", "No such file"]);
}

#[test]
fn missing_case_file() {
    let s = Scratch::new("nofile");
    let out = fretdyn(&["run", "nothere.toml"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr.contains("nothere.toml") && stderr.contains("No such file"),
        "{stderr}"
    );
    assert!(!s.0.join("fretdyn_results").exists());
}

/// A run that blows up stops with the step where it happened and keeps what it computed.
#[test]
fn divergence_stops_with_the_step_and_keeps_results() {
    let s = Scratch::new("diverge");
    let case = V1A.replace(
        "[output]",
        // a force growing to 1e307 N (a load that large is refused: the history is not)
        "[[loads]]\npoint = \"mass\"\nforce = [0.0, 1.0, 0.0]\nhistory = { type = \"table\", table = [[0.0, 0.0], [2e-3, 1e307]] }\n\n[output]",
    );
    std::fs::write(s.0.join("case.toml"), case).unwrap();
    let out = fretdyn(&["run", "case.toml", "-o", "out", "--quiet"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("diverged at step"), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.0.join("out/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["termination"]["status"], "diverged");
    let step = summary["termination"]["step"].as_u64().unwrap();
    assert!(step > 0 && step < 4000, "{summary}");
    let mut npz =
        ndarray_npy::NpzReader::new(std::fs::File::open(s.0.join("out/results.npz")).unwrap())
            .unwrap();
    let q: ndarray::Array2<f64> = npz.by_name("q").unwrap();
    assert!(q.nrows() as u64 <= step && q.nrows() > 0);
    assert!(
        q.iter().all(|v| v.is_finite()),
        "only finite samples are kept"
    );
}

#[test]
fn verify_passes() {
    let s = Scratch::new("verify");
    let out = fretdyn(&["verify", "-o", "v", "--quiet"], &s.0);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    assert!(stdout.contains(" 0 failed"), "{stdout}");
    for f in [
        "fig2a_v1a_friction_force.png",
        "fig2b_v1b_friction_force.png",
        "full_step_variant.png",
        "penalty_kt_dependence.png",
        "verification.json",
    ] {
        assert!(s.0.join("v").join(f).is_file(), "{f}");
    }
}

#[test]
fn modes_prints_the_table_and_writes_basis_and_picture() {
    let s = Scratch::new("modes");
    let case = examples().join("tube_clamped_one_support.toml");
    let out = fretdyn(&["modes", case.to_str().unwrap(), "-o", "m"], &s.0);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // first clamped–clamped bending mode of the water-filled tube: β₁L = 4.730,
    // f = β² √(EI/m)/2π with m = tube + inner water + added mass = 1.0128 kg/m (78.94 Hz)
    assert!(stdout.contains("    1      78.93"), "{stdout}");
    assert!(stdout.contains("114 free DOFs"), "{stdout}");
    for f in ["basis.npz", "mode_shapes.png"] {
        assert!(s.0.join("m").join(f).is_file(), "{f}");
    }
    let back = fretdyn::structure::basis_file::read_basis_npz(&s.0.join("m/basis.npz")).unwrap();
    assert_eq!(back.basis.modes(), 12);
    assert_eq!(back.basis.points.len(), 2);
}

/// Step of the last checkpoint in a run folder, if there is one.
fn checkpoint_step(dir: &Path) -> Option<u64> {
    fretdyn::output::checkpoint::checkpoint_step(dir).ok()
}

fn npz_f64(dir: &Path, key: &str) -> ndarray::ArrayD<f64> {
    let mut npz =
        ndarray_npy::NpzReader::new(std::fs::File::open(dir.join("results.npz")).unwrap()).unwrap();
    npz.by_name(key).unwrap()
}

/// The tube in its 5 plates under turbulence, 10 simulated seconds: run to the end; run again
/// and `kill -9` it past half time; what it wrote is readable; `run --resume` finishes it with
/// the results of the uninterrupted run, bit for bit. The same after Ctrl-C.
#[test]
fn turbulence_tube_killed_at_half_time_resumes_bit_for_bit() {
    let s = Scratch::new("resume");
    let case = examples().join("tube_turbulence.toml");
    let case = case.to_str().unwrap();
    let out = fretdyn(&["run", case, "-o", "full", "-q", "--no-plots"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let full = s.0.join("full");

    let mut child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args([
            "run",
            case,
            "-o",
            "killed",
            "-q",
            "--no-plots",
            "--checkpoint-every",
            "0.2",
        ])
        .current_dir(&s.0)
        .spawn()
        .unwrap();
    let killed = s.0.join("killed");
    let start = std::time::Instant::now();
    kill_past_checkpoint(&mut child, &killed, 500_000);
    // readable up to the last flush: every series has the rows its header says
    let t: ndarray::Array1<f64> = ndarray_npy::ReadNpyExt::read_npy(
        std::fs::File::open(killed.join("series/t.npy")).unwrap(),
    )
    .unwrap();
    assert!(t.len() > 1000 && t.iter().all(|v| v.is_finite()));
    assert!(!killed.join("results.npz").exists());

    let out = fretdyn(&["run", "--resume", "killed", "-q", "--no-plots"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for key in [
        "t",
        "q",
        "qdot",
        "contact_normal_force",
        "contact_tangential_force",
        "contact_slip_velocity",
        "contact_penetration",
        "contact_position",
    ] {
        let (a, b) = (npz_f64(&full, key), npz_f64(&killed, key));
        assert_eq!(a.shape(), b.shape(), "{key}");
        // bit for bit
        assert!(
            a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{key} differs"
        );
    }
    for file in ["impacts.csv", "blocks.csv"] {
        let (a, b) = (
            std::fs::read_to_string(full.join(file)).unwrap(),
            std::fs::read_to_string(killed.join(file)).unwrap(),
        );
        assert!(a.lines().count() > 20, "{file} has content");
        assert_eq!(a, b, "{file}");
    }
    let summary = |d: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(d.join("summary.json")).unwrap()).unwrap()
    };
    let (a, b) = (summary(&full), summary(&killed));
    for key in [
        "contacts",
        "energy_balance",
        "solver",
        "termination",
        "time",
    ] {
        assert_eq!(a[key], b[key], "{key}");
    }
    // resuming a finished run is refused
    let out = fretdyn(&["run", "--resume", "killed", "-q", "--no-plots"], &s.0);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nothing to resume"));

    // Ctrl-C (SIGINT) and SIGTERM (timeout, batch schedulers, docker stop) alike: a stop after
    // a checkpoint that says how to continue and leaves results.npz; resumed, the results are
    // those of the uninterrupted run, bit for bit
    for (signal, folder) in [("-INT", "interrupted"), ("-TERM", "terminated")] {
        let child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
            .args([
                "run",
                case,
                "-o",
                folder,
                "-q",
                "--no-plots",
                "--checkpoint-every",
                "0.2",
            ])
            .current_dir(&s.0)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let stopped = s.0.join(folder);
        while checkpoint_step(&stopped).is_none_or(|n| n < 200_000) {
            assert!(start.elapsed().as_secs() < 1800, "no checkpoint");
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status()
            .unwrap();
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{signal}: {stderr}");
        assert!(
            stderr.contains("interrupted at step") && stderr.contains("--resume"),
            "{signal}: {stderr}"
        );
        assert_eq!(summary(&stopped)["termination"]["status"], "stopped");
        let stopped_at = checkpoint_step(&stopped).unwrap();
        assert!((200_000..1_000_000).contains(&stopped_at), "{stopped_at}");
        let n = npz_f64(&stopped, "t").len();
        assert!(n > 1 && n < npz_f64(&full, "t").len());
        let out = fretdyn(&["run", "--resume", folder, "-q", "--no-plots"], &s.0);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        for key in ["t", "q", "qdot", "contact_normal_force", "contact_position"] {
            let (x, y) = (npz_f64(&full, key), npz_f64(&stopped, key));
            assert_eq!(x.shape(), y.shape(), "{key}");
            assert!(
                x.iter().zip(&y).all(|(a, b)| a.to_bits() == b.to_bits()),
                "{signal}: {key} differs"
            );
        }
        assert_eq!(summary(&stopped)["contacts"], a["contacts"]);
        assert_eq!(
            std::fs::read_to_string(full.join("impacts.csv")).unwrap(),
            std::fs::read_to_string(stopped.join("impacts.csv")).unwrap()
        );
    }
}

/// Checks a refusal: exit code `code`, one line on stderr starting with "error: " and
/// containing every needle, no panic.
fn assert_one_line_error(out: &Output, code: i32, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{stderr}");
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "not one line: {stderr}"
    );
    assert!(stderr.starts_with("error: "), "{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "'{n}' not in: {stderr}");
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// The turbulence tube, run for `duration` simulated seconds (10 s: about a million steps).
fn long_case(dir: &Path, duration: f64) -> PathBuf {
    let text = std::fs::read_to_string(examples().join("tube_turbulence.toml"))
        .unwrap()
        .replace("duration = 10.0", &format!("duration = {duration:?}"));
    assert!(text.contains(&format!("duration = {duration:?}")));
    let path = dir.join("long.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Waits until `path` exists.
fn wait_for(path: &Path, child: &mut std::process::Child) {
    let start = std::time::Instant::now();
    while !path.exists() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before {} was written",
            path.display()
        );
        assert!(
            start.elapsed().as_secs() < 120,
            "{} not written",
            path.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

/// A closed standard output (`| head -1`) neither panics nor stops the command's work; a
/// full one (`> /dev/full`) is a one-line error with exit code 1.
#[test]
fn closed_or_full_stdout_is_not_a_panic() {
    let s = Scratch::new("stdout");
    let tube = examples().join("tube_clamped_one_support.toml");
    let tube = tube.to_str().unwrap();
    // the reader is gone before the first line
    for args in [
        vec!["modes", tube, "-o", "m"],
        vec!["verify", "-o", "v"],
        vec!["run", "-o", "demo"],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
            .args(&args)
            .current_dir(&s.0)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
        assert!(stderr.is_empty(), "{args:?}: {stderr}");
    }
    // and the command did its work
    for f in [
        "m/basis.npz",
        "m/mode_shapes.png",
        "v/verification.json",
        "demo/friction_force.png",
    ] {
        assert!(s.0.join(f).is_file(), "{f}");
    }
    // as a shell does it: the first line, then the pipe closes
    let out = Command::new("bash")
        .args([
            "-c",
            "set -o pipefail; \"$0\" modes \"$1\" -o m2 | head -1",
            env!("CARGO_BIN_EXE_fretdyn"),
            tube,
        ])
        .current_dir(&s.0)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 1);
    assert!(!stderr.contains("panicked"), "{stderr}");

    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let case = examples().join("v1a_oblique_impact.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args(["run", case.to_str().unwrap(), "-o", "r", "--no-plots"])
        .current_dir(&s.0)
        .stdout(full)
        .output()
        .unwrap();
    assert_one_line_error(&out, 1, &["standard output", "No space left on device"]);
    assert!(s.0.join("r/results.npz").is_file());
}

/// A run killed before its first checkpoint cannot be resumed: say so, and how to start it
/// again.
#[test]
fn resume_before_the_first_checkpoint_says_to_start_again() {
    let s = Scratch::new("nocheckpoint");
    let case = long_case(&s.0, 100.0);
    let mut child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args([
            "run",
            case.to_str().unwrap(),
            "-o",
            "out",
            "-q",
            "--checkpoint-every",
            "100000",
        ])
        .current_dir(&s.0)
        .spawn()
        .unwrap();
    wait_for(&s.0.join("out/series/t.npy"), &mut child);
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!s.0.join("out/checkpoint.bin").exists());
    let out = fretdyn(&["run", "--resume", "out"], &s.0);
    assert_one_line_error(
        &out,
        2,
        &[
            "out",
            "before its first checkpoint",
            "nothing to resume",
            "fretdyn run",
            "long.toml",
        ],
    );
}

/// Two runs on one folder: the second is refused, naming the folder; the first goes on.
#[test]
fn a_second_run_on_the_same_folder_is_refused() {
    let s = Scratch::new("lock");
    let case = long_case(&s.0, 100.0);
    let mut child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args([
            "run",
            case.to_str().unwrap(),
            "-o",
            "out",
            "-q",
            "--no-plots",
        ])
        .current_dir(&s.0)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    wait_for(&s.0.join("out/series/t.npy"), &mut child);
    let v1a = examples().join("v1a_oblique_impact.toml");
    let out = fretdyn(&["run", v1a.to_str().unwrap(), "-o", "out", "-q"], &s.0);
    assert_one_line_error(&out, 2, &["out", "another fretdyn run", "-o"]);
    let out = fretdyn(&["run", "--resume", "out", "-q"], &s.0);
    assert_one_line_error(&out, 2, &["out", "another fretdyn run"]);
    // the first is untouched: it stops on Ctrl-C as usual, with its own case
    assert!(child.try_wait().unwrap().is_none(), "the first run ended");
    Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("interrupted at step"), "{stderr}");
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.0.join("out/run.json")).unwrap()).unwrap();
    assert!(run["case_file"].as_str().unwrap().ends_with("long.toml"));
    // once it ended, the folder is free again
    let out = fretdyn(&["run", v1a.to_str().unwrap(), "-o", "out", "-q"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Command-line errors are one line with a hint to the help, exit code 2.
#[test]
fn command_line_errors_are_one_line() {
    let s = Scratch::new("clap");
    let v1a = examples().join("v1a_oblique_impact.toml");
    let v1a = v1a.to_str().unwrap();
    let out = fretdyn(&["run", v1a, "--bogus"], &s.0);
    assert_one_line_error(&out, 2, &["--bogus", "fretdyn run --help"]);
    let out = fretdyn(&["run", v1a, "-o", ""], &s.0);
    assert_one_line_error(&out, 2, &["--output", "empty", "fretdyn run --help"]);
    let out = fretdyn(&["bench", "--steps", "many"], &s.0);
    assert_one_line_error(&out, 2, &["--steps", "many", "fretdyn bench --help"]);
    let out = fretdyn(&["rnu"], &s.0);
    assert_one_line_error(&out, 2, &["rnu", "fretdyn --help"]);
    assert!(
        std::fs::read_dir(&s.0).unwrap().next().is_none(),
        "nothing written"
    );
    // the help is still the help
    let out = fretdyn(&["run", "--help"], &s.0);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("--resume"));
}

/// `fretdyn plot` on a summary.json that is JSON but not a summary: refused, naming the file.
#[test]
fn plot_refuses_a_malformed_summary() {
    let s = Scratch::new("plotsummary");
    let v1a = examples().join("v1a_oblique_impact.toml");
    let out = fretdyn(
        &[
            "run",
            v1a.to_str().unwrap(),
            "-o",
            "out",
            "-q",
            "--no-plots",
        ],
        &s.0,
    );
    assert!(out.status.success());
    for bad in [
        "{}",
        "[1, 2]",
        "{\"contacts\": 5}",
        "{\"contacts\": [{\"name\": 1}], \"contact_geometry\": [{}]}",
        "{\"contacts\": [{\"name\": \"plane\"}]}",
    ] {
        std::fs::write(s.0.join("out/summary.json"), bad).unwrap();
        let out = fretdyn(&["plot", "out"], &s.0);
        assert_one_line_error(&out, 2, &["summary.json"]);
        assert!(!s.0.join("out/contact_forces.png").exists(), "{bad}");
    }
}

/// A case whose time histories cannot fit on the disk is refused before it starts (not after
/// hours), with the figure and the fix; nothing is written.
#[test]
fn a_run_larger_than_the_disk_is_refused() {
    let s = Scratch::new("disk");
    // 9e11 steps of 121 bytes (t, q, q̇ of 3 modes, 65 bytes of one contact): 109 TB
    let case = V1A.replace("duration = 4e-3", "duration = 9e5");
    std::fs::write(s.0.join("case.toml"), case).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args(["run", "case.toml", "-o", "out", "-q"])
        .current_dir(&s.0)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed().as_secs() > 60 {
            child.kill().unwrap();
            panic!("the run was not refused");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    assert_one_line_error(&out, 2, &["case.toml", "108.9 TB", "free", "output.every"]);
    assert!(!s.0.join("out").exists());
}

/// The packing of results.npz fails (here: a file-size limit, as `ulimit -f`; the same path
/// as a full disk): the run fails (exit 1) with one line and the way to continue; `--resume`
/// then packs it, with the results of an uninterrupted run.
#[test]
fn a_run_that_fails_while_packing_is_finished_by_resume() {
    let s = Scratch::new("pack");
    let v1a = examples().join("v1a_oblique_impact.toml");
    let v1a = v1a.to_str().unwrap();
    let out = fretdyn(&["run", v1a, "-o", "full", "-q", "--no-plots"], &s.0);
    assert!(out.status.success());
    // 4001 samples: each series file is under 100 kB, results.npz is about 490 kB
    let out = Command::new("bash")
        .args([
            "-c",
            "ulimit -f 300; trap '' XFSZ; exec \"$0\" run \"$1\" -o out -q --no-plots",
            env!("CARGO_BIN_EXE_fretdyn"),
            v1a,
        ])
        .current_dir(&s.0)
        .output()
        .unwrap();
    assert_one_line_error(&out, 1, &["results.npz", "fretdyn run --resume out"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("ZipWriter"));
    assert!(!s.0.join("out/results.npz").exists());
    resumed_equals(&s.0, "out", &s.0.join("full"));
}

/// `--resume DIR` succeeds, and DIR then holds the results of the run in `full`.
fn resumed_equals(cwd: &Path, dir: &str, full: &Path) {
    let out = fretdyn(&["run", "--resume", dir, "-q", "--no-plots"], cwd);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dir = cwd.join(dir);
    for key in [
        "t",
        "q",
        "qdot",
        "contact_normal_force",
        "contact_tangential_force",
    ] {
        let (a, b) = (npz_f64(full, key), npz_f64(&dir, key));
        assert_eq!(a.shape(), b.shape(), "{key}");
        assert!(
            a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{key} differs"
        );
    }
    assert!(!dir.join("series").exists());
    let summary = |d: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(d.join("summary.json")).unwrap()).unwrap()
    };
    let (a, b) = (summary(full), summary(&dir));
    assert_eq!(b["termination"]["status"], "completed");
    for key in ["contacts", "energy_balance", "time"] {
        assert_eq!(a[key], b[key], "{key}");
    }
    for table in ["impacts.csv", "contacts.csv"] {
        assert_eq!(
            std::fs::read_to_string(full.join(table)).unwrap(),
            std::fs::read_to_string(dir.join(table)).unwrap(),
            "{table}"
        );
    }
    // and then it is complete
    let out = fretdyn(&["run", "--resume", dir.to_str().unwrap(), "-q"], cwd);
    assert_one_line_error(&out, 2, &["nothing to resume"]);
}

/// A real full disk (a small tmpfs; needs the right to mount, skipped without it): a warning
/// before the run that packing will not fit, a one-line failure (exit 1) while packing, and
/// `--resume` finishes the run once there is room.
#[test]
fn a_full_disk_while_packing_is_resumed_once_there_is_room() {
    let s = Scratch::new("tmpfs");
    let v1a = examples().join("v1a_oblique_impact.toml");
    let v1a = v1a.to_str().unwrap();
    let out = fretdyn(&["run", v1a, "-o", "full", "-q", "--no-plots"], &s.0);
    assert!(out.status.success());
    let disk = s.0.join("disk");
    std::fs::create_dir_all(&disk).unwrap();
    // the series (about 490 kB) fit, not twice
    let mounted = Command::new("mount")
        .args([
            "-t",
            "tmpfs",
            "-o",
            "size=800k",
            "tmpfs",
            disk.to_str().unwrap(),
        ])
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !mounted {
        eprintln!("skipped: cannot mount a tmpfs here");
        return;
    }
    struct Unmount(PathBuf);
    impl Drop for Unmount {
        fn drop(&mut self) {
            let _ = Command::new("umount").arg(&self.0).status();
        }
    }
    let _unmount = Unmount(disk.clone());
    let out = fretdyn(&["run", v1a, "-o", "disk/out", "-q", "--no-plots"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 2, "a warning and an error: {stderr}");
    assert!(
        lines[0].starts_with("warning: ") && lines[0].contains("results.npz"),
        "{stderr}"
    );
    assert!(lines[1].starts_with("error: "), "{stderr}");
    for needle in ["No space left on device", "fretdyn run --resume disk/out"] {
        assert!(lines[1].contains(needle), "{needle}: {stderr}");
    }
    assert!(
        !stderr.contains("ZipWriter") && !stderr.contains("Os {"),
        "{stderr}"
    );
    // still no room: the same failure, and the run is still resumable
    let out = fretdyn(&["run", "--resume", "disk/out", "-q", "--no-plots"], &s.0);
    assert_one_line_error(&out, 1, &["No space left on device", "--resume"]);
    let remount = Command::new("mount")
        .args(["-o", "remount,size=4m", disk.to_str().unwrap()])
        .status()
        .unwrap();
    assert!(remount.success());
    resumed_equals(&s.0, "disk/out", &s.0.join("full"));
}

// ---------------------------------------------------------------------------------------------
// Bad input: refused with the field as the user wrote it, exit code 2, no hang
// ---------------------------------------------------------------------------------------------

const TUBE: &str = include_str!("../../../examples/tube_clamped_one_support.toml");

/// Runs `fretdyn args` in `cwd`; fails the test if it has not finished after `seconds`.
fn fretdyn_within(args: &[&str], cwd: &Path, seconds: u64) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args(args)
        .current_dir(cwd)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("fretdyn runs");
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed().as_secs() >= seconds {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("fretdyn {args:?} did not finish in {seconds} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Writes `files` (the first is the case), runs it, and checks: done within a minute, exit
/// code 2, one line on stderr naming the case file and containing every `needles`, nothing
/// written.
fn assert_refused(name: &str, files: &[(&str, &str)], needles: &[&str]) {
    let s = Scratch::new(name);
    for (file, text) in files {
        std::fs::write(s.0.join(file), text).unwrap();
    }
    let out = fretdyn_within(&["run", files[0].0, "-o", "out"], &s.0, 60);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{name}: {stderr}");
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "{name}: not one line: {stderr}"
    );
    assert!(
        stderr.starts_with(&format!("error: {}: ", files[0].0)),
        "{name}: {stderr}"
    );
    for n in needles {
        assert!(stderr.contains(n), "{name}: '{n}' not in: {stderr}");
    }
    assert!(!s.0.join("out").exists(), "{name}: output written");
}

#[test]
fn a_duration_shorter_than_one_step_is_refused() {
    let case = V1A.replace("duration = 4e-3", "duration = 1e-7");
    assert_refused(
        "short",
        &[("case.toml", &case)],
        &["time.duration", "shorter than one step", "duration ≥ dt"],
    );
}

#[test]
fn two_contacts_with_the_same_name_are_refused() {
    let (start, end) = (
        V1A.find("[[contacts]]").unwrap(),
        V1A.find("[tangential]").unwrap(),
    );
    let case = format!("{}{}{}", &V1A[..end], &V1A[start..end], &V1A[end..]);
    assert_refused(
        "names",
        &[("case.toml", &case)],
        &["contacts[1].name", "'plane'", "unique"],
    );
}

#[test]
fn a_statistics_window_after_the_run_is_refused() {
    let case = format!("{V1A}\n[statistics]\nt_start = 5e-3\n");
    assert_refused(
        "t_start",
        &[("case.toml", &case)],
        &[
            "statistics.t_start",
            "time.duration = 0.004",
            "t_start < duration",
        ],
    );
}

/// It ran forever: 1e294 empty blocks per step.
#[test]
fn a_statistics_block_shorter_than_a_step_is_refused() {
    let case = format!("{V1A}\n[statistics]\nblock = 1e-300\n");
    assert_refused(
        "block",
        &[("case.toml", &case)],
        &["statistics.block", "1e-300 s", "block ≥ dt"],
    );
}

/// It ran forever: the eigen solver of the stability limit on an infinite stiffness term.
#[test]
fn a_mass_that_makes_the_stable_time_step_infinite_is_refused() {
    let case = V1A.replace("mass = 1.0 ", "mass = 1e-320 ");
    assert_refused(
        "tiny_mass",
        &[("case.toml", &case)],
        &["contacts[0].normal", "1e-320 kg", "units"],
    );
}

#[test]
fn friction_and_initial_errors_name_the_key_written() {
    let case = V1A.replace("friction = { mu = 0.3 }", "friction = { mu = -0.3 }");
    assert_refused(
        "mu",
        &[("case.toml", &case)],
        &["contacts[0].friction.mu:", "-0.3"],
    );
    let line = V1A.lines().find(|l| l.starts_with("velocity = ")).unwrap();
    let case = V1A.replace(line, "velocity = [nan, 0.0, -1.0]");
    assert_refused(
        "velocity",
        &[("case.toml", &case)],
        &["initial.velocity:", "NaN"],
    );
}

#[test]
fn tube_errors_name_the_key_written() {
    let case = TUBE.replace(
        "damping_ratio = 0.01",
        "rayleigh = { alpha = -500, beta = 0 }",
    );
    assert_refused(
        "rayleigh",
        &[("tube.toml", &case)],
        &["structure.rayleigh.alpha", "-500"],
    );
    let case = TUBE.replace(
        "friction = { mu = 0.3 }",
        "friction = { mu = 0.3 }\nradius = 9.525",
    );
    assert_refused(
        "radius",
        &[("tube.toml", &case)],
        &["contacts[0].radius", "outer radius 0.009525 m"],
    );
    let case = TUBE.replace("modes = 12", "modes = 100000");
    assert_refused(
        "modes",
        &[("tube.toml", &case)],
        &["structure.modes", "114 free DOFs", "modes ≤ 114"],
    );
}

/// It aborted with "memory allocation failed".
#[test]
fn a_tube_too_large_for_memory_is_refused_with_the_figure() {
    let case = TUBE.replace(
        "path = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]",
        "path = [[0.0, 0.0, 0.0], [1e9, 0.0, 0.0]]",
    );
    assert_refused(
        "path",
        &[("tube.toml", &case)],
        &[
            "structure.mesh_size",
            "GB",
            "use mesh_size ≥",
            "units of path",
        ],
    );
}

#[test]
fn a_bad_row_of_a_load_table_names_the_file_and_its_line() {
    let case = V1A.replace(
        "[tangential]\n",
        "[[loads]]\npoint = \"mass\"\nforce = [0.0, 1.0, 0.0]\nhistory = { type = \"table\", file = \"load.csv\" }\n\n[tangential]\n",
    );
    assert_refused(
        "load_csv",
        &[
            ("case.toml", &case),
            ("load.csv", "t,value\n0,0\n1e-3,1\n5e-4,2\n"),
        ],
        &[
            "loads[0].history.file",
            "load.csv line 4:",
            "strictly increasing",
        ],
    );
}

#[test]
fn a_missing_file_is_named_once() {
    let s = Scratch::new("once");
    for command in ["run", "sweep", "modes"] {
        let out = fretdyn(&[command, "nothere.toml"], &s.0);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{command}: {stderr}");
        assert_eq!(
            stderr.matches("nothere.toml").count(),
            1,
            "{command}: {stderr}"
        );
        assert!(stderr.contains("No such file"), "{command}: {stderr}");
    }
}

#[test]
fn a_study_file_given_to_run_says_to_use_sweep() {
    let s = Scratch::new("study_run");
    std::fs::write(s.0.join("case.toml"), V1A).unwrap();
    std::fs::write(
        s.0.join("study.toml"),
        "base = \"case.toml\"\n\n[[parameters]]\nkey = \"time.dt\"\nvalues = [1e-6]\n",
    )
    .unwrap();
    let out = fretdyn(&["run", "study.toml", "-o", "out"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("study file") && stderr.contains("fretdyn sweep"),
        "{stderr}"
    );
    assert!(!stderr.contains("unknown field"), "{stderr}");
}

/// A case that cannot start — an initial state whose energy overflows, found by the commands'
/// fuzz test — and a life without a wearing contact are refused by `run`, `life` and `sweep`
/// before anything is written (exit code 2, one line, no output folder): `run` and `life` left
/// their folder (`run.json`, `life_run.json`) behind, and `sweep` passed its check, then failed
/// at its first run with exit code 1, as if a run had failed.
#[test]
fn a_case_that_cannot_start_is_refused_before_anything_is_written() {
    let bad = V1A.replace(
        "velocity = [0.3420201433256687, 0.0, -0.9396926207859084]",
        "velocity = [0.3420201433256687, 1e300, -0.9396926207859084]",
    );
    let wear = "friction = { mu = 0.3 }
wear = { tube = { law = \"archard\", coefficient = 2e-15 }, support = { law = \"archard\", coefficient = 1e-15 }, scar = { type = \"flat_bar\", width = 0.02, tube_radius = 0.0095 } }";
    let life = "\n[life]\ntarget_years = 1.0\n";
    let s = Scratch::new("cannot_start");
    for (name, text, args, needles) in [
        (
            "run.toml",
            bad.clone(),
            vec!["run", "run.toml", "-o", "out"],
            vec!["run.toml: initial:", "energy of inf J"],
        ),
        (
            "life.toml",
            format!("{}{life}", bad.replace("friction = { mu = 0.3 }", wear)),
            vec!["life", "life.toml", "-o", "out"],
            vec!["life.toml: initial:", "energy of inf J"],
        ),
        (
            "unworn.toml",
            format!("{V1A}{life}"),
            vec!["life", "unworn.toml", "-o", "out"],
            vec!["unworn.toml: life: no contact has a wear law"],
        ),
        (
            "case.toml",
            bad.clone(),
            vec!["sweep", "study.toml", "-o", "out"],
            vec!["study.toml: run 0 (", "initial:", "nothing was run"],
        ),
    ] {
        std::fs::write(s.0.join(name), text).unwrap();
        std::fs::write(
            s.0.join("study.toml"),
            "base = \"case.toml\"\n\n[[parameters]]\nkey = \"contacts.*.friction.mu\"\nvalues = [0.1, 0.2]\n",
        )
        .unwrap();
        let out = fretdyn(&args, &s.0);
        // the warning on the implausible velocity, then the error in one line
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        let error = stderr.trim_end().lines().last().unwrap_or_default();
        assert!(error.starts_with("error: "), "{stderr}");
        assert!(
            stderr
                .lines()
                .rev()
                .skip(1)
                .all(|l| l.starts_with("warning: ")),
            "{stderr}"
        );
        for n in &needles {
            assert!(error.contains(n), "'{n}' not in: {stderr}");
        }
        assert!(!s.0.join("out").exists(), "{args:?}: output written");
    }
}

/// A value that makes one run invalid: exit 2 before any run, naming the run, its values and
/// the field; nothing written.
#[test]
fn a_bad_study_value_is_refused_before_any_run() {
    let s = Scratch::new("study_value");
    std::fs::write(s.0.join("case.toml"), V1A).unwrap();
    for (values, needles) in [
        (
            "[0.1, -0.3, 0.2]",
            vec![
                "run 1 (contacts.*.friction.mu = -0.3)",
                "contacts[0].friction.mu:",
                "nothing was run",
            ],
        ),
        (
            "[0.1, \"high\"]",
            vec!["run 1 (", "parameters[0].values", "\"high\""],
        ),
    ] {
        std::fs::write(
            s.0.join("study.toml"),
            format!(
                "base = \"case.toml\"\n\n[[parameters]]\nkey = \"contacts.*.friction.mu\"\nvalues = {values}\n"
            ),
        )
        .unwrap();
        let out = fretdyn(&["sweep", "study.toml", "-o", "out", "-q"], &s.0);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.starts_with("error: study.toml: "), "{stderr}");
        for n in needles {
            assert!(stderr.contains(n), "'{n}' not in: {stderr}");
        }
        assert!(!s.0.join("out").exists(), "a run was made");
    }
}

#[test]
fn study_syntax_errors_give_their_line_and_column() {
    let s = Scratch::new("study_syntax");
    std::fs::write(s.0.join("case.toml"), V1A).unwrap();
    std::fs::write(
        s.0.join("study.toml"),
        "base = \"case.toml\"\n\n[[parameters]]\nkey = \"time.dt\"\nvalues = [1e-6 2e-6]\n",
    )
    .unwrap();
    let out = fretdyn(&["sweep", "study.toml", "-o", "out"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.starts_with("error: study.toml: line 5, column 16: "),
        "{stderr}"
    );
}

/// A short run of the multi-span tube: summary.json carries the standard errors of every
/// rate, the batches and their check; the too-large relative errors of so short a run are
/// warned about on stderr, one line per contact naming the statistics (a contact with fewer
/// impacts than batches, a transient, is not); a target relative
/// error is reported as met or not; a block longer than the window is refused naming the
/// field.
#[test]
fn a_run_reports_its_standard_errors_and_warns_when_they_are_large() {
    let s = Scratch::new("errors");
    let text = std::fs::read_to_string(examples().join("tube_multispan.toml"))
        .unwrap()
        .replace("duration = 2.0", "duration = 0.2");
    std::fs::write(s.0.join("short.toml"), &text).unwrap();
    let out = fretdyn(
        &["run", "short.toml", "-o", "out", "--quiet", "--no-plots"],
        &s.0,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.0.join("out/summary.json")).unwrap())
            .unwrap();
    let errors = &summary["standard_errors"];
    assert_eq!(errors["batches"], 20);
    assert!((errors["batch_length"].as_f64().unwrap() - 0.01).abs() < 1e-12);
    assert!(errors.get("target_met").is_none(), "no target, no key");
    let mut some_warned = false;
    for c in summary["contacts"].as_array().unwrap() {
        assert_eq!(c["batches"], 20);
        for key in fretdyn::accumulate::statistics::BATCHED_STATISTICS {
            let se = c[format!("{key}_se")].as_f64();
            assert!(se.is_some_and(|e| e >= 0.0), "{key}_se of {}", c["name"]);
        }
        assert!(c["batches_correlated"].is_boolean());
        let name = c["name"].as_str().unwrap();
        let rse = c["wear_work_rate_se"].as_f64().unwrap() / c["wear_work_rate"].as_f64().unwrap();
        let warned = stderr.lines().any(|l| {
            l.starts_with(&format!("warning: contact {name}:")) && l.contains("wear_work_rate")
        });
        // only a contact with at least an impact per batch is a stationary response
        let stationary = c["impacts"].as_u64().unwrap() >= 20;
        assert_eq!(
            warned,
            stationary && rse > 0.05,
            "{name}: relative error {rse}: {stderr}"
        );
        some_warned |= warned;
    }
    assert!(some_warned, "0.2 s is too short: {stderr}");
    // a target too small to be met within the duration
    std::fs::write(
        s.0.join("target.toml"),
        format!("{text}\n[statistics]\ntarget_relative_error = 0.001\n"),
    )
    .unwrap();
    let out = fretdyn(
        &["run", "target.toml", "-o", "t", "--quiet", "--no-plots"],
        &s.0,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("was not met"), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.0.join("t/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["standard_errors"]["target_met"], false);
    assert_eq!(summary["standard_errors"]["target_relative_error"], 0.001);
    // a block longer than the window
    std::fs::write(
        s.0.join("bad.toml"),
        format!("{text}\n[statistics]\nblock = 0.5\n"),
    )
    .unwrap();
    let out = fretdyn(&["run", "bad.toml", "-o", "b", "--quiet"], &s.0);
    assert_one_line_error(
        &out,
        2,
        &[
            "bad.toml",
            "statistics.block",
            "longer than the statistics window",
        ],
    );
}

/// A probabilistic study: the sweep writes the drawn values in its table and the percentiles
/// (CSV and JSON) beside it; run again, nothing is redone and the percentiles are the same.
/// Bad input (samples = 0, an unknown distribution) is one line naming the file and the field,
/// exit 2, nothing run.
#[test]
fn a_probabilistic_sweep_writes_its_percentiles() {
    let s = Scratch::new("study_probabilistic");
    std::fs::write(s.0.join("case.toml"), V1A).unwrap();
    let study = "base = \"case.toml\"\nsamples = 5\nseed = 4\n\n[[parameters]]\nkey = \"contacts.*.friction.mu\"\ndistribution = { type = \"uniform\", low = 0.1, high = 0.5 }\n\n[percentiles]\nstatistics = [\"tangential_force_rms\"]\n";
    std::fs::write(s.0.join("study.toml"), study).unwrap();
    let out = fretdyn(&["sweep", "study.toml", "-o", "out", "-q"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = std::fs::read_to_string(s.0.join("out/study.csv")).unwrap();
    assert!(table.starts_with("run,contacts.*.friction.mu,sample,seed,status,"));
    assert_eq!(table.lines().count(), 6);
    let csv = std::fs::read_to_string(s.0.join("out/percentiles.csv")).unwrap();
    assert!(
        csv.starts_with(
            "column,level,n,excluded,estimate,ci_low,ci_high,ci_coverage,bootstrap_se\n"
        ),
        "{csv}"
    );
    // P50, P95, P99 of the one contact, 5 samples each
    assert_eq!(csv.lines().count(), 4, "{csv}");
    assert!(csv.contains("plane.tangential_force_rms,95,5,0,"), "{csv}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.0.join("out/percentiles.json")).unwrap())
            .unwrap();
    assert_eq!(json["rows"].as_array().unwrap().len(), 3);
    let out = fretdyn(&["sweep", "study.toml", "-o", "out", "-q"], &s.0);
    assert!(out.status.success());
    assert_eq!(
        std::fs::read_to_string(s.0.join("out/percentiles.csv")).unwrap(),
        csv
    );

    for (text, needles) in [
        (
            study.replace("samples = 5", "samples = 0"),
            vec!["samples:", "between 1 and 100000"],
        ),
        (
            study.replace("\"uniform\", low = 0.1, high = 0.5", "\"weibull\""),
            vec!["parameters[0].distribution.type", "\"weibull\""],
        ),
    ] {
        std::fs::write(s.0.join("bad.toml"), text).unwrap();
        let out = fretdyn(&["sweep", "bad.toml", "-o", "bad", "-q"], &s.0);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.starts_with("error: bad.toml: "), "{stderr}");
        for n in needles {
            assert!(stderr.contains(n), "'{n}' not in: {stderr}");
        }
        assert!(!s.0.join("bad").exists(), "a run was made");
    }
}

/// `fretdyn completions SHELL`: a bash script that bash parses and that completes every
/// subcommand; an unknown shell is a one-line error listing the shells (exit 2).
#[test]
fn completions_are_a_script_for_the_shell() {
    let s = Scratch::new("completions");
    let out = fretdyn(&["completions", "bash"], &s.0);
    assert!(out.status.success());
    let script = String::from_utf8_lossy(&out.stdout).to_string();
    for sub in [
        "run",
        "sweep",
        "life",
        "stability",
        "modes",
        "verify",
        "bench",
    ] {
        assert!(
            script.contains(&format!("fretdyn,{sub})")),
            "{sub} not completed"
        );
    }
    std::fs::write(s.0.join("fretdyn.bash"), &script).unwrap();
    let parsed = std::process::Command::new("bash")
        .args(["-n", "fretdyn.bash"])
        .current_dir(&s.0)
        .status();
    if let Ok(status) = parsed {
        assert!(status.success(), "bash cannot parse the script");
    }
    let out = fretdyn(&["completions", "tcsh"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("bash") && stderr.contains("zsh"),
        "{stderr}"
    );
}

/// `bench --pair A B`: both cases run with the steps asked, and the ratio is B's steps/s over
/// A's — a case whose step costs ~20 times more (a U-bend in cross-flow, its turbulence and
/// fluid-elastic forces) against a single-contact one, in both orders.
#[test]
fn bench_pair_reports_b_over_a() {
    let ex = examples();
    let ratio = |a: &str, b: &str| -> f64 {
        let out = fretdyn(
            &["bench", "--pair", a, b, "--rounds", "3", "--steps", "1000"],
            &ex,
        );
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        for (label, file) in [("A", a), ("B", b)] {
            let row = format!("| {label} | {file} | gauss_seidel (exact) | 1000 |");
            assert!(text.contains(&row), "no row {row} in\n{text}");
        }
        let line = text
            .lines()
            .find(|l| l.starts_with("ratio B/A of steps/s: median "))
            .unwrap_or_else(|| panic!("no ratio in\n{text}"));
        line["ratio B/A of steps/s: median ".len()..]
            .split_whitespace()
            .next()
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no number in {line}"))
    };
    let cheap = "v1a_modal_inline.toml";
    let costly = "ubend_flow.toml";
    assert!(ratio(cheap, costly) < 0.5);
    assert!(ratio(costly, cheap) > 2.0);
}

// ---------------------------------------------------------------------------------------------
// Issue [3.1]: schema errors in plain words, plausibility warnings, results.nc on a full disk
// ---------------------------------------------------------------------------------------------

/// The catalogue's schema errors on the command line: one line naming the file and the key
/// as written, in plain words (they were serde's: `invalid value: integer `-1`, expected
/// u64`, `invalid type: integer `1`, expected a boolean`), exit code 2.
#[test]
fn schema_errors_name_the_file_and_the_key_in_plain_words() {
    let serde = [
        "invalid type",
        "invalid value",
        "expected usize",
        "expected u64",
        "expected f64",
        "expected a boolean",
        "integer `",
        "floating point `",
        "unknown field",
        "unknown variant",
    ];
    for (name, from, to, needles) in [
        (
            "every",
            "every = 1 ",
            "every = -1 ",
            &["output.every: must be a whole number ≥ 1", "got -1"][..],
        ),
        (
            "warm_start",
            "warm_start = true",
            "warm_start = 1",
            &["tangential.gauss_seidel.warm_start: must be true or false, got 1"],
        ),
        (
            "max_sweeps",
            "max_sweeps = 1000",
            "max_sweeps = -1",
            &[
                "tangential.gauss_seidel.max_sweeps: must be a whole number ≥ 1",
                "got -1",
            ],
        ),
        (
            "mu",
            "friction = { mu = 0.3 }",
            "friction = { mu = \"0.3\" }",
            &["contacts[0].friction.mu: must be a number", "got \"0.3\""],
        ),
        (
            "position",
            "position = [0.0, 0.0, 0.0]",
            "position = [0.0, 0.0]",
            &[
                "structure.position: must be a list of 3 values",
                "got [0.0, 0.0]",
            ],
        ),
    ] {
        let case = V1A.replace(from, to);
        assert_ne!(case, V1A);
        let s = Scratch::new(&format!("words_{name}"));
        std::fs::write(s.0.join("case.toml"), &case).unwrap();
        let out = fretdyn(&["run", "case.toml", "-o", "out"], &s.0);
        assert_one_line_error(&out, 2, needles);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.starts_with("error: case.toml: line "), "{stderr}");
        for w in serde {
            assert!(!stderr.contains(w), "{name}: serde's '{w}' in: {stderr}");
        }
        assert!(!s.0.join("out").exists(), "{name}: output written");
    }
}

/// A value no structure has (μ = 1e6) is one warning line naming the file, the key, the
/// value and the plausible range; the run goes on.
#[test]
fn an_implausible_value_is_a_one_line_warning_naming_the_file_and_the_key() {
    let s = Scratch::new("implausible");
    std::fs::write(
        s.0.join("case.toml"),
        V1A.replace("friction = { mu = 0.3 }", "friction = { mu = 1e6 }"),
    )
    .unwrap();
    let out = fretdyn(&["run", "case.toml", "-o", "out", "-q", "--no-plots"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.contains("friction")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(
        warnings[0].starts_with("warning: case.toml: contacts[0].friction.mu = 1e6 ")
            && warnings[0].contains("0 to 2"),
        "{stderr}"
    );
}

/// A turbulence band limit above 1/(2Δt) ran for hours: refused at once, with the limit.
#[test]
fn a_turbulence_band_limit_above_nyquist_is_refused_at_once() {
    let text = std::fs::read_to_string(examples().join("tube_turbulence.toml")).unwrap();
    let case = text.replace("f_max = 250.0", "f_max = 1e9");
    assert_ne!(case, text);
    assert_refused(
        "f_max",
        &[("turbulence.toml", &case)],
        &["turbulence[0].f_max", "Nyquist", "set f_max ≤ 50000 Hz"],
    );
}

/// A real full disk while writing results.nc (a small tmpfs; needs the right to mount,
/// skipped without it): the netCDF library's "NetCDF: HDF error" is said as the disk being
/// full, with what stays written and `--resume`, which finishes the run once there is room.
#[test]
fn a_full_disk_while_writing_results_nc_says_so_and_is_resumed() {
    let s = Scratch::new("tmpfs_nc");
    let v1a = examples().join("v1a_oblique_impact.toml");
    let v1a = v1a.to_str().unwrap();
    let out = fretdyn(&["run", v1a, "-o", "full", "-q", "--no-plots"], &s.0);
    assert!(out.status.success());
    let disk = s.0.join("disk");
    std::fs::create_dir_all(&disk).unwrap();
    // the series (about 490 kB) and results.npz (as much) fit, results.nc does not
    let mounted = Command::new("mount")
        .args([
            "-t",
            "tmpfs",
            "-o",
            "size=1100k",
            "tmpfs",
            disk.to_str().unwrap(),
        ])
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !mounted {
        eprintln!("skipped: cannot mount a tmpfs here");
        return;
    }
    struct Unmount(PathBuf);
    impl Drop for Unmount {
        fn drop(&mut self) {
            let _ = Command::new("umount").arg(&self.0).status();
        }
    }
    let _unmount = Unmount(disk.clone());
    let out = fretdyn(&["run", v1a, "-o", "disk/out", "-q", "--no-plots"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let error = stderr
        .lines()
        .find(|l| l.starts_with("error: "))
        .unwrap_or_else(|| panic!("no error in: {stderr}"));
    for needle in [
        "results.nc: No space left on device",
        "results.npz and the time histories in series/ stay written",
        "fretdyn run --resume disk/out",
    ] {
        assert!(error.contains(needle), "{needle}: {stderr}");
    }
    assert!(!stderr.contains("HDF error"), "{stderr}");
    assert!(s.0.join("disk/out/results.npz").exists());
    assert!(!s.0.join("disk/out/results.nc").exists());
    let remount = Command::new("mount")
        .args(["-o", "remount,size=4m", disk.to_str().unwrap()])
        .status()
        .unwrap();
    assert!(remount.success());
    resumed_equals(&s.0, "disk/out", &s.0.join("full"));
    assert!(s.0.join("disk/out/results.nc").exists());
}
