//! `fretdyn stability` (docs/FLOW.md) as a user meets it: the table, stability.json and
//! stability.csv against the closed form of a pinned–pinned tube with a partial flow zone;
//! one-line errors naming the file and the field (exit code 2); the warning of `run` when a
//! mode is above the critical velocity.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn fretdyn(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("fretdyn runs")
}

struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("fretdyn-stability-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A pinned–pinned tube 1 m long along x (modes sin(nπs/L), pairs in y and z), ζ = 0.02, and
/// one zone over [0.2, 0.7] m at `velocity` (gap) in water-like fluid of 600 kg/m³.
fn case(velocity: f64) -> String {
    format!(
        r#"
[time]
dt = 1e-6
duration = 2e-5

[structure]
type = "tube"
outer_diameter = 0.02
wall_thickness = 0.001
young_modulus = 2.0e11
poisson_ratio = 0.3
density = 8000.0
path = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
mesh_size = 0.025
modes = 4
damping_ratio = 0.02

[[structure.supports]]
at = [0.0, 0.0, 0.0]
type = "dofs"
fixed = ["ux", "uy", "uz", "rx"]

[[structure.supports]]
at = [1.0, 0.0, 0.0]
type = "pinned"

[[structure.points]]
name = "a"
at = [0.2, 0.0, 0.0]

[flow]
pattern = "in_line_square"
pitch_ratio = 1.44
velocity_definition = "gap"

[[flow.zones]]
name = "cross_flow"
span = [0.2, 0.7]
density = 600.0
velocity = {velocity:?}
"#
    )
}

/// `U √(∫_0.2^0.7 sin²(nπs) ds / ½)` by hand.
fn effective(u: f64, n: f64) -> f64 {
    let (a, b, w) = (0.2, 0.7, n * PI);
    let integral = 0.5 * (b - a) - ((2.0 * w * b).sin() - (2.0 * w * a).sin()) / (4.0 * w);
    u * (integral / 0.5).sqrt()
}

/// The Connors critical velocity by hand: m = ρ_t A (no fluids), f = (nπ)² √(EI/m)/2π.
fn critical(n: f64) -> f64 {
    let (ro, ri): (f64, f64) = (0.01, 0.009);
    let m = 8000.0 * PI * (ro * ro - ri * ri);
    let i = 0.25 * PI * (ro.powi(4) - ri.powi(4));
    let f = (n * PI).powi(2) * (2.0e11 * i / m).sqrt() / (2.0 * PI);
    3.0 * f * 0.02 * (m * 2.0 * PI * 0.02 / (600.0 * 0.02 * 0.02)).sqrt()
}

#[test]
fn stability_writes_json_and_csv_matching_the_closed_form() {
    let s = Scratch::new("ok");
    std::fs::write(s.0.join("case.toml"), case(3.0)).unwrap();
    let out = fretdyn(&["stability", "case.toml", "-o", "out"], &s.0);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("Connors check, K = 3"), "{stdout}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.0.join("out/stability.json")).unwrap())
            .unwrap();
    let modes = json["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 4);
    let csv = std::fs::read_to_string(s.0.join("out/stability.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    assert_eq!(rows.len(), 4);
    for (k, n) in [1.0, 1.0, 2.0, 2.0].into_iter().enumerate() {
        let (ue, uc) = (effective(3.0, n), critical(n));
        let j = &modes[k];
        let num = |key: &str| j[key].as_f64().unwrap();
        assert!((num("effective_velocity") / ue - 1.0).abs() < 1e-9, "{j}");
        assert!((num("critical_velocity") / uc - 1.0).abs() < 1e-6, "{j}");
        assert!((num("ratio") / (ue / uc) - 1.0).abs() < 1e-6, "{j}");
        assert_eq!(j["reference_zone"], "cross_flow");
        // the CSV holds the same numbers, to the last bit
        let c = |name: &str| rows[k][col(name)].parse::<f64>().unwrap();
        for key in [
            "frequency_hz",
            "damping_ratio",
            "reference_density",
            "effective_velocity",
            "critical_velocity",
            "ratio",
        ] {
            assert_eq!(c(key), num(key), "{key}");
        }
        assert_eq!(rows[k][col("reference_zone")], "cross_flow");
        assert_eq!(rows[k][col("mode")], (k + 1).to_string());
    }
}

/// Exit code 2, one line on stderr naming the file and the field, nothing written.
fn assert_input_error(out: &Output, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "not one line: {stderr}"
    );
    assert!(stderr.starts_with("error: case.toml: "), "{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "'{n}' not in: {stderr}");
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn stability_bad_input_is_one_line_naming_file_and_field() {
    let s = Scratch::new("bad");
    let good = case(3.0);
    for (from, to, field) in [
        (
            "span = [0.2, 0.7]",
            "span = [0.2, 1.7]",
            "flow.zones[0].span",
        ),
        (
            "density = 600.0",
            "density = -600.0",
            "flow.zones[0].density",
        ),
        (
            "span = [0.2, 0.7]",
            "from = \"a\"\nto = \"apex\"",
            "flow.zones[0].to",
        ),
        (
            "velocity = 3.0",
            "velocity_profile = [[0.2, 1.0], [0.6, 2.0], [0.5, 3.0]]",
            "flow.zones[0].velocity_profile[2]",
        ),
        // a parse error gives the line and column of the key instead
        (
            "pattern = \"in_line_square\"",
            "pattern = \"hexagonal\"",
            "line 32, column 11: unknown variant `hexagonal`",
        ),
    ] {
        let text = good.replace(from, to);
        assert_ne!(text, good);
        std::fs::write(s.0.join("case.toml"), &text).unwrap();
        for command in ["stability", "run"] {
            let out = fretdyn(&[command, "case.toml", "-o", "out"], &s.0);
            assert_input_error(&out, &[field]);
            assert!(!s.0.join("out").exists(), "{command}: output written");
        }
    }
    // no [flow] section
    let bare = &good[..good.find("[flow]").unwrap()];
    std::fs::write(s.0.join("case.toml"), bare).unwrap();
    assert_input_error(
        &fretdyn(&["stability", "case.toml", "-o", "out"], &s.0),
        &["flow", "[flow]"],
    );
}

/// A modal basis read from .npz without the abscissae of its points: the error names the file
/// and the key to add.
#[test]
fn stability_npz_without_abscissae_names_file_and_key() {
    let s = Scratch::new("npz");
    std::fs::write(s.0.join("tube.toml"), case(3.0)).unwrap();
    let out = fretdyn(&["modes", "tube.toml", "-o", "m"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = r#"
[time]
dt = 1e-6
duration = 1e-5

[structure]
type = "modal"
file = "m/basis.npz"

[flow]
pattern = "in_line_square"
pitch_ratio = 1.44
velocity_definition = "gap"
diameter = 0.02
mass_per_length = 0.5

[[flow.zones]]
name = "z"
span = [0.0, 1.0]
density = 600.0
velocity = 1.0
"#;
    std::fs::write(s.0.join("case.toml"), text).unwrap();
    let out = fretdyn(&["stability", "case.toml", "-o", "out"], &s.0);
    assert_input_error(&out, &["flow:", "s_<point>", "basis.npz"]);
}

#[test]
fn run_warns_when_a_mode_is_above_the_critical_velocity() {
    let s = Scratch::new("warn");
    // U_c ≈ 1.6 m/s for the first pair, ≈ 6.3 m/s for the second
    let (slow, fast) = (0.5, 4.0);
    assert!(effective(slow, 1.0) < critical(1.0));
    assert!(effective(fast, 1.0) > critical(1.0) && effective(fast, 2.0) < critical(2.0));
    for (u, warnings) in [(slow, 0), (fast, 2)] {
        std::fs::write(s.0.join("case.toml"), case(u)).unwrap();
        let out = fretdyn(
            &["run", "case.toml", "-o", "out", "--quiet", "--no-plots"],
            &s.0,
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        let lines: Vec<&str> = stderr
            .lines()
            .filter(|l| l.contains("Connors critical velocity"))
            .collect();
        assert_eq!(lines.len(), warnings, "{stderr}");
        for (l, mode) in lines.iter().zip(["mode 1 ", "mode 2 "]) {
            assert!(l.starts_with("warning: case.toml: "), "{l}");
            assert!(l.contains(mode), "{l}");
        }
        let _ = std::fs::remove_dir_all(s.0.join("out"));
    }
}
