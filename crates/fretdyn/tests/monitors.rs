//! Displacement monitors (`[[output.monitors]]`, `accumulate/monitor.rs`, THEORY §5): the
//! displacement `u = d·(Φ_x q)` of a point along a direction, summarised over the window's
//! output samples — checked against the same recombination done here from the recorded modal
//! displacements (to round-off), against the closed form of a free undamped oscillation
//! `u = A cos ωt` (amplitude `A`, RMS `A/√2`), and through the summary and a study's table.

use std::path::Path;

use fretdyn::Case;
use fretdyn::integrator::simulation::simulate;

/// Two modes, 5 Hz and 13 Hz, undamped, at a point whose x follows mode 1 and z both; the
/// first mode displaced by `a` at rest; a plane far away (no contact).
fn case(a: f64, monitors: &str, extra: &str) -> Case {
    let text = format!(
        r#"
title = "monitors"
[time]
dt = 1e-4
duration = 10.0
[structure]
type = "modal"
frequencies_hz = [5.0, 13.0]
damping_ratio = 0.0
[[structure.points]]
name = "p"
coords = [0.0, 0.0, 0.0]
rows = [[1.0, 0.0], [0.0, 0.0], [0.6, 0.8]]
[initial]
q = [{a}, 0.0]
[[contacts]]
name = "far"
point = "p"
obstacle = {{ type = "plane", origin = [0.0, 0.0, -1.0], normal = [0.0, 0.0, 1.0], gap = 0.0 }}
normal = {{ stiffness = 1e3 }}
friction = {{ mu = 0.3 }}
[tangential]
method = "gauss_seidel"
[output]
every = 7
{monitors}
{extra}
"#
    );
    Case::from_toml_str(&text, Path::new(".")).expect("the case is valid")
}

const MONITORS: &str = r#"
[[output.monitors]]
name = "x"
point = "p"
direction = [2.0, 0.0, 0.0]

[[output.monitors]]
point = "p"
direction = [1.0, 0.0, 1.0]
"#;

#[test]
fn monitors_are_the_recombined_displacement_at_the_samples() {
    let c = case(1e-3, MONITORS, "[statistics]\nt_start = 1.0");
    let r = simulate(&c.model, &c.settings).unwrap();
    let (q, t) = (&r.recorder.q, &r.recorder.t);
    let dt = c.settings.dt;
    let s2 = std::f64::consts::FRAC_1_SQRT_2;
    // the same displacements, recombined here from the recorded q: x = q1, z = 0.6 q1 + 0.8 q2
    for (m, d) in r.monitors.iter().zip([[1.0, 0.0], [s2 * 1.6, s2 * 0.8]]) {
        let u: Vec<f64> = (0..t.len())
            .filter(|&i| t[i] - 0.5 * dt >= 1.0)
            .map(|i| d[0] * q[[i, 0]] + d[1] * q[[i, 1]])
            .collect();
        let n = u.len() as f64;
        let max = u.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let min = u.iter().cloned().fold(f64::INFINITY, f64::min);
        let rms = (u.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
        // the same sums, formed in another order: equal to round-off
        let close = |a: Option<f64>, b: f64| (a.unwrap() - b).abs() <= 1e-14 * rms;
        assert_eq!(m.samples, u.len() as u64, "{}", m.name);
        assert!(close(m.max, max), "{}: max {:?} vs {max}", m.name, m.max);
        assert!(close(m.min, min), "{}: min {:?} vs {min}", m.name, m.min);
        assert!(close(m.amplitude, max.max(-min)), "{}", m.name);
        assert!(close(m.rms, rms), "{}: rms {:?} vs {rms}", m.name, m.rms);
    }
    assert_eq!(
        r.monitors[1].name, "p",
        "a monitor without a name takes its point's"
    );
    assert_eq!(
        r.monitors[0].direction,
        [1.0, 0.0, 0.0],
        "directions are made unit"
    );
}

#[test]
fn a_free_oscillation_has_its_closed_form_amplitude_and_rms() {
    // u = A cos ωt, ω = 2π·5 Hz; 10 s = 50 periods, sampled every 7 steps (0.7 ms, 286 per
    // period): the largest sample is within 1 − cos(π·0.7e-3·5) = 6e-5 of A (the scheme is
    // undamped: no decay), the RMS over 50 periods within 1/(4π·50) of A/√2 (the window's
    // end cuts a period), the mean within 1/(2π·50) A
    let a = 2e-3;
    let c = case(a, MONITORS, "");
    let r = simulate(&c.model, &c.settings).unwrap();
    let x = &r.monitors[0];
    let amplitude = x.amplitude.unwrap();
    assert!(
        amplitude <= a * (1.0 + 1e-12) && amplitude > a * (1.0 - 6.1e-5),
        "{amplitude}"
    );
    let rms = x.rms.unwrap();
    let exact = a * std::f64::consts::FRAC_1_SQRT_2;
    assert!(
        (rms - exact).abs() < exact / (4.0 * std::f64::consts::PI * 50.0),
        "{rms} vs {exact}"
    );
    assert!(x.mean.unwrap().abs() < a / (2.0 * std::f64::consts::PI * 50.0));
    assert!((x.std.unwrap() - rms).abs() < 1e-2 * rms);
}

#[test]
fn monitors_reach_the_summary() {
    let c = case(1e-3, MONITORS, "");
    let r = simulate(&c.model, &c.settings).unwrap();
    let s = fretdyn::output::summary::summary(&c, &r);
    let m = &s["monitors"];
    assert_eq!(m[0]["name"], "x");
    assert_eq!(m[1]["point"], "p");
    assert_eq!(m[0]["amplitude"].as_f64(), r.monitors[0].amplitude);
    let none = case(1e-3, "", "");
    let r = simulate(&none.model, &none.settings).unwrap();
    let s = fretdyn::output::summary::summary(&none, &r);
    assert!(s.get("monitors").is_none(), "no monitor, no key");
}

#[test]
fn bad_monitors_are_refused_with_the_field() {
    for (monitors, field) in [
        (
            "[[output.monitors]]\npoint = \"q\"\ndirection = [1.0, 0.0, 0.0]",
            "output.monitors[0].point",
        ),
        (
            "[[output.monitors]]\npoint = \"p\"\ndirection = [0.0, 0.0, 0.0]",
            "output.monitors[0].direction",
        ),
        (
            "[[output.monitors]]\npoint = \"p\"\ndirection = [1.0, 0.0, 0.0]\n\
             [[output.monitors]]\npoint = \"p\"\ndirection = [0.0, 1.0, 0.0]",
            "output.monitors[1].name",
        ),
    ] {
        let text = format!(
            "title = \"bad\"\n[time]\ndt = 1e-4\nduration = 0.01\n[structure]\ntype = \"modal\"\n\
             frequencies_hz = [5.0]\ndamping_ratio = 0.0\n[[structure.points]]\nname = \"p\"\n\
             coords = [0.0, 0.0, 0.0]\nrows = [[1.0], [0.0], [0.0]]\n{monitors}\n"
        );
        let Err(e) = Case::from_toml_str(&text, Path::new(".")) else {
            panic!("{field}: accepted");
        };
        let e = e.to_string();
        assert!(e.contains(field), "{e}");
    }
}

#[test]
fn a_study_table_has_the_monitors_columns() {
    use fretdyn::apps::study::Study;
    let dir = std::env::temp_dir().join(format!("fretdyn-monitors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let base = "title = \"m\"\n[time]\ndt = 1e-4\nduration = 1.0\n[structure]\ntype = \"modal\"\n\
         frequencies_hz = [5.0]\ndamping_ratio = 0.0\n[[structure.points]]\nname = \"p\"\n\
         coords = [0.0, 0.0, 0.0]\nrows = [[1.0], [0.0], [0.0]]\n[initial]\nq = [1e-3]\n\
         [[contacts]]\nname = \"far\"\npoint = \"p\"\n\
         obstacle = { type = \"plane\", origin = [-1.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0], gap = 0.0 }\n\
         normal = { stiffness = 1e3 }\nfriction = { mu = 0.3 }\n[tangential]\nmethod = \"gauss_seidel\"\n\
         [[output.monitors]]\nname = \"x\"\npoint = \"p\"\ndirection = [1.0, 0.0, 0.0]\n";
    std::fs::write(dir.join("base.toml"), base).unwrap();
    let path = dir.join("study.toml");
    std::fs::write(
        &path,
        "base = \"base.toml\"\n[[parameters]]\nkey = \"initial.q.0\"\nvalues = [1e-3, 2e-3]\n",
    )
    .unwrap();
    let study = Study::from_file(&path).unwrap();
    let table = dir.join("study.csv");
    study.execute(&table, 1, &|_, _| {}).unwrap();
    let text = std::fs::read_to_string(&table).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "x.displacement_amplitude")
        .expect("the monitor's column");
    assert_eq!(header[col + 1], "x.displacement_rms");
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), header.len());
        let q0: f64 = cells[1].parse().unwrap();
        let amplitude: f64 = cells[col].parse().unwrap();
        // a free oscillation of amplitude q0 (1 s = 5 periods, every step sampled)
        assert!((amplitude - q0).abs() < 1e-6 * q0, "{amplitude} vs {q0}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
