//! `fretdyn stability` (docs/FLOW.md) as a user meets it: the table, stability.json and
//! stability.csv against the closed form of a pinned–pinned tube with a partial flow zone;
//! one-line errors naming the file and the field (exit code 2); the warning of `run` when a
//! mode is above the critical velocity.

use std::f64::consts::PI;
use std::path::Path;
use std::process::Output;

mod common;
use common::{Scratch, fretdyn};

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
            "line 32, column 11: flow.pattern: must be one of",
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

/// A modal basis read from .npz without the abscissae of its points (the basis of
/// `fretdyn modes` written again without its `s_<name>`): the case reads, and its flow zones
/// are refused with an error naming the file and the key to add.
#[test]
fn stability_npz_without_abscissae_names_file_and_key() {
    use fretdyn::structure::basis_file::{read_basis_npz, write_basis_npz};
    let s = Scratch::new("npz");
    std::fs::write(s.0.join("tube.toml"), case(3.0)).unwrap();
    let out = fretdyn(&["modes", "tube.toml", "-o", "m"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let npz = s.0.join("m/basis.npz");
    let file = read_basis_npz(&npz).unwrap();
    assert_eq!(file.abscissae, [Some(0.2)]);
    write_basis_npz(&npz, &file.basis).unwrap();
    assert_eq!(read_basis_npz(&npz).unwrap().abscissae, [None]);
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
    // without [flow], a basis without abscissae is a basis like any other
    let bare = &text[..text.find("[flow]").unwrap()];
    std::fs::write(s.0.join("case.toml"), bare).unwrap();
    let out = fretdyn(&["run", "case.toml", "-o", "out", "-q", "--no-plots"], &s.0);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The pinned tube of [`case`] meshed every 10 mm, with `n` named points evenly spaced from
/// end to end (on nodes), and two zones meeting at 0.46 m: a velocity profile in liquid, then
/// a two-phase mixture. `[flow]` is the last section (`tail` after it, e.g. the diameter and
/// mass per length a point basis needs).
fn dense_tube(n: usize, tail: &str) -> String {
    let mut points = String::new();
    for k in 0..n {
        let x = k as f64 / (n - 1) as f64;
        points.push_str(&format!(
            "[[structure.points]]\nname = \"p{k}\"\nat = [{x:?}, 0.0, 0.0]\n\n"
        ));
    }
    let head = case(1.0);
    let head = &head[..head.find("[[structure.points]]").unwrap()];
    format!(
        "{}\n{points}{}",
        head.replace("mesh_size = 0.025", "mesh_size = 0.01"),
        dense_flow(tail)
    )
}

/// The `[flow]` of [`dense_tube`].
fn dense_flow(tail: &str) -> String {
    format!(
        r#"
[flow]
pattern = "in_line_square"
pitch_ratio = 1.44
velocity_definition = "gap"
{tail}

[[flow.zones]]
name = "inlet"
span = [0.1, 0.46]
density = 750.0
velocity_profile = [[0.1, 1.0], [0.46, 3.0]]

[[flow.zones]]
name = "mixture"
span = [0.46, 0.92]
void_fraction = 0.6
liquid_density = 750.0
gas_density = 30.0
velocity = 4.0
"#
    )
}

fn stability_json(dir: &Path, case: &str, out: &str) -> serde_json::Value {
    let o = fretdyn(&["stability", case, "-o", out], dir);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(dir.join(out).join("stability.json")).unwrap())
        .unwrap()
}

/// `fretdyn modes` writes the abscissa `s_<name>` of every named point of a tube, so that its
/// basis, used as a `.npz` modal structure with the same flow zones, gives the tube's Connors
/// check up to the quadrature: the tube integrates the elements' own shapes (exact), the point
/// basis applies the midpoint rule on its points (docs/FLOW.md), whose error is O(h²). With
/// 101 points (h = 10 mm) the effective velocities agree within 2e-4 (measured: 2.9e-5 to
/// 8.3e-5 over the 6 modes); with 51 points the error is 4 times larger (measured 4.00 to
/// 4.01: the rule's h², the zones meeting on a point); the frequencies, damping, reference
/// zone and critical velocities are the tube's.
#[test]
fn modes_npz_of_a_tube_carries_the_abscissae_for_the_flow_zones() {
    let s = Scratch::new("abscissae");
    let mut errors = Vec::new();
    for n in [101usize, 51] {
        let tube = format!("tube{n}.toml");
        std::fs::write(
            s.0.join(&tube),
            dense_tube(n, "").replace("modes = 4", "modes = 6"),
        )
        .unwrap();
        let out = fretdyn(&["modes", &tube, "-o", &format!("m{n}")], &s.0);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains("s_<point>"), "{stdout}");
        // every point's abscissa is its position along the straight tube
        let file =
            fretdyn::structure::basis_file::read_basis_npz(&s.0.join(format!("m{n}/basis.npz")))
                .unwrap();
        for (p, a) in file.basis.points.iter().zip(&file.abscissae) {
            let a = a.unwrap_or_else(|| panic!("no s_{}", p.name));
            assert!((a - p.coords.x).abs() < 1e-12, "{}: {a}", p.name);
        }
        let reference = stability_json(&s.0, &tube, &format!("st{n}"));
        let tail = format!(
            "diameter = {:?}\nmass_per_length = {:?}",
            reference["diameter"].as_f64().unwrap(),
            reference["mass_per_length"].as_f64().unwrap()
        );
        let npz = format!(
            "[time]\ndt = 1e-6\nduration = 1e-5\n\n[structure]\ntype = \"modal\"\nfile = \"m{n}/basis.npz\"\n{}",
            dense_flow(&tail)
        );
        std::fs::write(s.0.join(format!("npz{n}.toml")), npz).unwrap();
        let points = stability_json(&s.0, &format!("npz{n}.toml"), &format!("sp{n}"));
        let (a, b) = (
            reference["modes"].as_array().unwrap(),
            points["modes"].as_array().unwrap(),
        );
        assert_eq!(a.len(), 6);
        assert_eq!(b.len(), 6);
        let mut e = Vec::new();
        for (x, y) in a.iter().zip(b) {
            let num = |j: &serde_json::Value, k: &str| j[k].as_f64().unwrap();
            for k in [
                "frequency_hz",
                "damping_ratio",
                "critical_velocity",
                "reference_density",
            ] {
                assert!((num(y, k) / num(x, k) - 1.0).abs() < 1e-12, "{k}: {x} {y}");
            }
            assert_eq!(x["reference_zone"], y["reference_zone"]);
            e.push(num(y, "effective_velocity") / num(x, "effective_velocity") - 1.0);
        }
        eprintln!("{n} points: relative differences of U_eff {e:?}");
        errors.push(e);
    }
    for (fine, coarse) in errors[0].iter().zip(&errors[1]) {
        assert!(fine.abs() < 2e-4, "{fine:e}");
        let order = coarse / fine;
        assert!((order - 4.0).abs() < 0.2, "{coarse:e} vs {fine:e}");
    }
}

#[test]
fn run_warns_when_a_mode_is_above_the_critical_velocity() {
    let s = Scratch::new("warn");
    // U_c ≈ 1.6 m/s for the first pair, ≈ 6.3 m/s for the second
    let (slow, fast) = (0.5, 4.0);
    assert!(effective(slow, 1.0) < critical(1.0));
    assert!(effective(fast, 1.0) > critical(1.0) && effective(fast, 2.0) < critical(2.0));
    // one warning per support condition (here only the basis's: a straight tube has no
    // plane, its modes are counted together), naming the worst mode
    for (u, warnings) in [(slow, 0), (fast, 1)] {
        std::fs::write(s.0.join("case.toml"), case(u)).unwrap();
        let out = fretdyn(
            &["run", "case.toml", "-o", "out", "--quiet", "--no-plots"],
            &s.0,
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        let lines: Vec<&str> = stderr.lines().filter(|l| l.contains("Connors")).collect();
        assert_eq!(lines.len(), warnings, "{stderr}");
        for l in &lines {
            assert!(
                l.starts_with(
                    "warning: case.toml: Connors: condition `support_inactive`: all modes: 2 of "
                ),
                "{l}"
            );
            assert!(l.contains("mode 1, ") || l.contains("mode 2, "), "{l}");
        }
        let _ = std::fs::remove_dir_all(s.0.join("out"));
    }
}

/// `fretdyn sweep` over the gap velocity of the pinned tube: `connors_max_ratio` of each run is
/// the largest `U_eff/U_c` by hand (the first pair of modes: its critical velocity is a quarter
/// of the second pair's), and one warning line after the study counts the runs above 1 and
/// gives the largest ratio; a study of a case without `[flow]` has the column empty and no
/// warning.
#[test]
fn sweep_writes_the_largest_connors_ratio_and_warns_once() {
    let s = Scratch::new("sweep");
    std::fs::write(s.0.join("case.toml"), case(1.0)).unwrap();
    let velocities = [0.5, 2.0, 4.0];
    std::fs::write(
        s.0.join("study.toml"),
        format!(
            "base = \"case.toml\"\n\n[[parameters]]\nkey = \"flow.zones.0.velocity\"\nvalues = {velocities:?}\n"
        ),
    )
    .unwrap();
    let out = fretdyn(&["sweep", "study.toml", "-o", "out", "-q"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let table = std::fs::read_to_string(s.0.join("out/study.csv")).unwrap();
    let mut lines = table.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "connors_max_ratio")
        .unwrap();
    let mut rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    rows.sort_by_key(|r| r[0].parse::<usize>().unwrap());
    assert_eq!(rows.len(), 3);
    let expected: Vec<f64> = velocities
        .iter()
        .map(|&u| effective(u, 1.0) / critical(1.0))
        .collect();
    assert!(expected[0] < 1.0 && expected[1] > 1.0 && expected[2] > 1.0);
    for (r, want) in rows.iter().zip(&expected) {
        let got: f64 = r[col].parse().unwrap();
        assert!((got / want - 1.0).abs() < 1e-6, "{got} vs {want}");
    }
    // the first pair has the largest ratio
    for (&u, want) in velocities.iter().zip(&expected) {
        assert!(effective(u, 2.0) / critical(2.0) < *want);
    }
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.contains("Connors")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    let w = warnings[0];
    assert!(w.starts_with("warning: study.toml: 2 of 3 runs "), "{w}");
    let largest: f64 = rows[2][col].parse().unwrap();
    assert!(
        w.contains(&format!("U_eff/U_c = {largest:.4}, run 2)")),
        "{w}"
    );
    assert!(w.contains("connors_max_ratio"), "{w}");

    // no [flow]: the column is there, empty; no warning
    let good = case(1.0);
    std::fs::write(s.0.join("case.toml"), &good[..good.find("[flow]").unwrap()]).unwrap();
    std::fs::write(
        s.0.join("study.toml"),
        "base = \"case.toml\"\n\n[[parameters]]\nkey = \"structure.damping_ratio\"\nvalues = [0.01, 0.02]\n",
    )
    .unwrap();
    let out = fretdyn(&["sweep", "study.toml", "-o", "bare", "-q"], &s.0);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("Connors"), "{stderr}");
    let table = std::fs::read_to_string(s.0.join("bare/study.csv")).unwrap();
    let mut lines = table.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .ends_with(",connors_max_ratio,fingerprint")
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 2);
    for r in rows {
        // the ratio empty, then the row's fingerprint
        let cells: Vec<&str> = r.rsplitn(3, ',').collect();
        assert!(cells[0].starts_with("fp") && cells[1].is_empty(), "{r}");
    }
}
