//! `fretdyn life` (docs/WEAR.md) as a user meets it: a mass sliding on a bar at a constant
//! wear rate, its life.csv against the closed form, scars.csv, life.png, the convergence
//! runs of `--halvings`; one-line errors naming the file and the field (exit code 2).

mod common;
use common::{Scratch, fretdyn};

/// A mass pressed on a bar (10 N) sliding under it at 1 cm/s, μ = 0.3: `W = 0.03 W`.
const CASE: &str = r#"
title = "sliding mass"
[time]
dt = 1e-4
duration = 1.5
[structure]
type = "modal"
frequencies_hz = [5.0, 5.0, 0.0]
damping_ratio = 0.7
[[structure.points]]
name = "mass"
coords = [0.0, 0.0, 0.0]
rows = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
[[loads]]
point = "mass"
force = [0.0, 0.0, -10.0]
[[contacts]]
name = "bar"
point = "mass"
obstacle = { type = "plane", origin = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], gap = 0.0, tangent = [1.0, 0.0, 0.0] }
motion = { type = "velocity", velocity = [0.01, 0.0, 0.0] }
normal = { stiffness = 1e6, damping = 2000.0 }
friction = { mu = 0.3 }
wear = { tube = { law = "archard", coefficient = 2e-15 }, support = { law = "archard", coefficient = 1e-15 }, scar = { type = "flat_bar", width = 0.02, tube_radius = 0.0095 } }
[statistics]
t_start = 1.0
[life]
target_years = 10.0
max_depth_change = 0.2
criterion_depth = 2e-4
"#;

/// Circular segment of height `u` in a circle of radius `r`.
fn segment(r: f64, u: f64) -> f64 {
    r * r * ((r - u) / r).acos() - (r - u) * (2.0 * r * u - u * u).sqrt()
}

#[test]
fn a_life_writes_its_depths_against_time_and_converges_under_halvings() {
    let s = Scratch::new("ok");
    std::fs::write(s.0.join("case.toml"), CASE).unwrap();
    let out = fretdyn(&["life", "case.toml", "-o", "out", "--halvings", "1"], &s.0);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("bar: tube depth"), "{stdout}");
    let csv = std::fs::read_to_string(s.0.join("out/life.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header[0], "time_years");
    let at = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    assert!(rows.len() > 3);
    let year = 365.25 * 86400.0;
    let w = 0.3 * 10.0 * 0.01;
    for r in &rows[1..] {
        // w A_R(d) = K W t on the tube
        let d = r[at("bar.tube_depth")];
        let v = 2e-15 * w * r[0] * year;
        assert!((0.02 * segment(0.0095, d) - v).abs() < 1e-6 * v, "{d}");
        assert!(r[at("bar.wear_work_rate_se")] >= 0.0);
    }
    assert!((rows[rows.len() - 1][0] - 10.0).abs() < 1e-9);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(s.0.join("out/life.json")).unwrap()).unwrap();
    assert_eq!(json["results"]["end"]["status"], "completed");
    assert!(json["results"]["time_to_criterion"][0].as_f64().unwrap() > 0.0);
    let scars = std::fs::read_to_string(s.0.join("out/scars.csv")).unwrap();
    assert!(
        scars
            .starts_with("contact,kind,bin,angle_deg,clearance_increase,tube_depth\nbar,plane,0,,")
    );
    assert!(std::fs::metadata(s.0.join("out/life.png")).unwrap().len() > 10_000);
    let conv = std::fs::read_to_string(s.0.join("out/convergence.csv")).unwrap();
    assert_eq!(conv.lines().count(), 3, "{conv}");
    // a constant rate: the depth at the end does not depend on the life step
    let ends: Vec<f64> = conv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap().parse().unwrap())
        .collect();
    assert!((ends[0] - ends[1]).abs() < 1e-6 * ends[0]);
    assert!(
        std::fs::metadata(s.0.join("out/convergence.png"))
            .unwrap()
            .len()
            > 10_000
    );
}

#[test]
fn life_errors_are_one_line_naming_the_file_and_the_field() {
    let s = Scratch::new("errors");
    for (text, needle) in [
        (
            CASE.replace("target_years = 10.0", "target_years = 0.0"),
            "life.target_years",
        ),
        (
            CASE.replace(
                "[life]\ntarget_years = 10.0\nmax_depth_change = 0.2\ncriterion_depth = 2e-4\n",
                "",
            ),
            "life: the case has no [life] section",
        ),
        (
            CASE.replace(
                "type = \"flat_bar\"",
                "type = \"drilled_hole\", thickness = 0.02, shape = \"crescent\"",
            )
            .replace(", width = 0.02", ""),
            "contacts[0].wear.scar.type",
        ),
    ] {
        std::fs::write(s.0.join("bad.toml"), text).unwrap();
        let out = fretdyn(&["life", "bad.toml", "-o", "out"], &s.0);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.starts_with("error: bad.toml: "), "{stderr}");
        assert!(stderr.contains(needle), "'{needle}' not in {stderr}");
    }
}
