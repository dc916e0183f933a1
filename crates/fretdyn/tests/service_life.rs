//! Service life (THEORY §14.5): the depth against time of a contact whose wear rate does not
//! depend on the gap against the closed forms of the wear law and the scar, the life-step
//! limit, the time to the criterion, the scar fed back into the obstacle.

use std::f64::consts::PI;
use std::path::Path;

use fretdyn::apps::life::{LifeEnd, LifeSettings, YEAR, service_life};
use fretdyn::case::Case;

/// A point mass pressed on a bar (10 N) that slides under it at 1 cm/s: once the transient has
/// died out (heavily damped springs, window from 1 s) the mass stands still and the bar slides,
/// `W = μ N v` exactly, whatever the gap: the bar's recession only moves the mass down.
fn sliding_mass(wear: &str, life: &str) -> String {
    const BODY: &str = include_str!("fixtures/sliding_mass.toml");
    format!(
        r#"
title = "mass sliding on a bar"
{BODY}wear = {wear}
[tangential]
method = "gauss_seidel"
[statistics]
t_start = 1.0
[life]
{life}
"#
    )
}

const W: f64 = 0.3 * 10.0 * 0.01;
const R: f64 = 0.0095;
const WIDTH: f64 = 0.02;

/// Circular segment of height `u` in a circle of radius `r` (the flat cut of a tube).
fn segment(r: f64, u: f64) -> f64 {
    r * r * ((r - u) / r).acos() - (r - u) * (2.0 * r * u - u * u).sqrt()
}

/// The depth whose segment area is `a`, by bisection.
fn depth_of_area(r: f64, a: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, r);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if segment(r, mid) < a {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

fn case(wear: &str, life: &str) -> (Case, LifeSettings) {
    let c = Case::from_toml_str(&sliding_mass(wear, life), Path::new(".")).unwrap();
    let l = c.life.clone().unwrap();
    (c, l)
}

const ARCHARD: &str = r#"{ tube = { law = "archard", coefficient = 2e-15 }, support = { law = "archard", coefficient = 1e-15 }, scar = { type = "flat_bar", width = 0.02, tube_radius = 0.0095 } }"#;

#[test]
fn constant_wear_rate_gives_the_closed_form_depth_against_time() {
    let (case, life) = case(
        ARCHARD,
        "target_years = 40.0\nmax_depth_change = 0.2\ncriterion_depth = 4e-4",
    );
    let r = service_life(&case, &life, |_| {}).unwrap();
    assert_eq!(r.end, LifeEnd::Completed);
    assert!(r.steps.len() > 5, "{} steps", r.steps.len());
    let mut worst = 0.0f64;
    for s in &r.steps[1..] {
        let c = &s.contacts[0];
        // the transient of each window has died out to ~1e-8 by the window's start
        assert!(
            (c.wear_work_rate - W).abs() < 1e-7 * W,
            "W = {}",
            c.wear_work_rate
        );
        // V = K W t, V = w A_R(d) on the tube and on the bar (a groove of the tube's radius)
        let tube = depth_of_area(R, 2e-15 * W * s.time / WIDTH);
        let bar = depth_of_area(R, 1e-15 * W * s.time / WIDTH);
        worst = worst.max((c.tube_depth - tube).abs() / tube);
        worst = worst.max((c.support_depth - bar).abs() / bar);
        // the approach: the overlap holding both volumes
        let approach = depth_of_area(R, 3e-15 * W * s.time / WIDTH);
        worst = worst.max((c.clearance_increase - approach).abs() / approach);
        // no change of dynamics with the gap: the fixed-gap extrapolation is the same
        assert!((c.tube_depth_fixed_gap - c.tube_depth).abs() <= 1e-6 * tube);
    }
    assert!(worst < 1e-6, "depth off by {worst:e}");
    // the criterion: w A_R(d_c) = K W t_c
    let tc = WIDTH * segment(R, 4e-4) / (2e-15 * W);
    let found = r.time_to_criterion[0].unwrap();
    assert!((found - tc).abs() < 1e-6 * tc, "{found} s, expected {tc} s");
    assert!(tc < 40.0 * YEAR);
}

#[test]
fn a_life_step_never_grows_the_depth_by_more_than_the_set_fraction() {
    for f in [0.2, 0.05] {
        let (case, life) = case(
            ARCHARD,
            &format!("target_years = 40.0\nmax_depth_change = {f}"),
        );
        let r = service_life(&case, &life, |_| {}).unwrap();
        for pair in r.steps.windows(2) {
            let (a, b) = (&pair[0].contacts[0], &pair[1].contacts[0]);
            let limit = f * (r.clearances[0] + a.clearance_increase).max(life.depth_resolution);
            let grown = b.clearance_increase - a.clearance_increase;
            assert!(grown <= limit * (1.0 + 1e-9), "{grown:e} > {limit:e}");
        }
        // the steps are as long as allowed: all but the last use most of the limit
        let n = r.steps.len();
        assert!(n > 3);
        let last = r.steps[n - 1].time;
        assert!((last - 40.0 * YEAR).abs() < 1e-9 * last);
    }
}

#[test]
fn the_decaying_law_gives_its_closed_form_over_the_life() {
    // V(t) = A W^B [s t + (1 − s)(1 − e^{−N t})/N]
    let (a, b, s, n) = (2e-15, 1.2, 0.05, 1.0 / YEAR);
    let wear = format!(
        r#"{{ tube = {{ law = "decaying", a = {a:e}, b = {b}, s = {s}, n = {n:e} }}, support = {{ law = "archard", coefficient = 1e-15 }}, scar = {{ type = "flat_bar", width = 0.02, tube_radius = 0.0095 }} }}"#
    );
    let (case, life) = case(&wear, "target_years = 20.0\nmax_depth_change = 0.3");
    let r = service_life(&case, &life, |_| {}).unwrap();
    for st in &r.steps[1..] {
        let t = st.time;
        let v = a * W.powf(b) * (s * t + (1.0 - s) * (1.0 - (-n * t).exp()) / n);
        let c = &st.contacts[0];
        assert!(
            (c.tube_volume - v).abs() < 1e-8 * v,
            "{} vs {v}",
            c.tube_volume
        );
        let d = depth_of_area(R, v / WIDTH);
        assert!((c.tube_depth - d).abs() < 1e-6 * d);
    }
}

#[test]
fn bars_wear_on_the_side_that_is_rubbed_and_the_worn_side_recedes() {
    // the same mass between two bars 0 and 1 mm away: pressed on the lower one only
    let text = sliding_mass(ARCHARD, "target_years = 10.0\nmax_depth_change = 0.2").replace(
        r#"{ type = "plane", origin = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], gap = 0.0, tangent = [1.0, 0.0, 0.0] }"#,
        r#"{ type = "bi_plane", origin = [0.0, 0.0, 5e-4], normal = [0.0, 0.0, 1.0], gap = 5e-4, tangent = [1.0, 0.0, 0.0] }"#,
    );
    let case = Case::from_toml_str(&text, Path::new(".")).unwrap();
    let life = case.life.clone().unwrap();
    let r = service_life(&case, &life, |_| {}).unwrap();
    let scar = &r.scars[0];
    assert_eq!(scar.kind, "bars");
    // the mass is below the mid-plane: the −n side (bin 1) wears, the +n side not at all
    assert_eq!(scar.clearance_increase[0], 0.0);
    let last = &r.steps[r.steps.len() - 1].contacts[0];
    let tube = depth_of_area(R, 2e-15 * W * 10.0 * YEAR / WIDTH);
    assert!((scar.tube_depth[1] - tube).abs() < 1e-6 * tube);
    assert!((last.tube_depth - tube).abs() < 1e-6 * tube);
    assert!((last.wear_work_rate - W).abs() < 1e-7 * W);
}

#[test]
fn life_input_errors_name_the_field() {
    let bad = |life: &str, wear: &str, needle: &str| {
        let e = Case::from_toml_str(&sliding_mass(wear, life), Path::new("."))
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{e}");
    };
    bad("target_years = -1.0", ARCHARD, "life.target_years");
    bad(
        "target_years = 1.0\nmax_depth_change = 2.0",
        ARCHARD,
        "life.max_depth_change",
    );
    bad(
        "target_years = 1.0\ncriterion_wall_fraction = 0.4",
        ARCHARD,
        "life.criterion_wall_fraction",
    );
    bad(
        "target_years = 1.0\nangular_bins = 2",
        ARCHARD,
        "life.angular_bins",
    );
    // a case whose contacts do not wear
    let text =
        sliding_mass(ARCHARD, "target_years = 1.0").replace(&format!("wear = {ARCHARD}\n"), "");
    let case = Case::from_toml_str(&text, Path::new(".")).unwrap();
    let e = service_life(&case, case.life.as_ref().unwrap(), |_| {}).unwrap_err();
    assert!(
        e.to_string().starts_with("life: no contact has a wear law"),
        "{e}"
    );
    let _ = PI;
}

/// A probabilistic study whose base case has `[life]`: each sample is a service life, its row
/// carries the depth at the target and the time to the criterion; with the friction
/// coefficient drawn, each row's depth is the closed form at its own `W = μ N v`.
#[test]
fn a_probabilistic_study_of_service_lives_gives_each_sample_s_closed_form_depth() {
    use fretdyn::apps::study::Study;
    let dir = std::env::temp_dir().join(format!("fretdyn_life_study_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("case.toml"),
        sliding_mass(
            ARCHARD,
            "target_years = 40.0\nmax_depth_change = 0.2\ncriterion_depth = 4e-4",
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("study.toml"),
        "base = \"case.toml\"\nsamples = 4\nseed = 7\n\n[[parameters]]\nkey = \"contacts.*.friction.mu\"\ndistribution = { type = \"uniform\", low = 0.2, high = 0.4 }\n\n[percentiles]\nstatistics = [\"depth_at_target\", \"time_to_criterion\"]\n",
    )
    .unwrap();
    let study = Study::from_file(&dir.join("study.toml")).unwrap();
    assert!(study.has_life());
    let header = study.header(&study.contact_names());
    let cols: Vec<&str> = header.split(',').collect();
    let at = |name: &str| cols.iter().position(|c| *c == name).unwrap();
    for run in study.runs() {
        let row = study.run_row(&run).unwrap();
        let v: Vec<&str> = row.split(',').collect();
        assert_eq!(v.len(), cols.len());
        assert_eq!(v[at("life_end")], "completed");
        let mu: f64 = v[at("contacts.*.friction.mu")].parse().unwrap();
        let w = mu * 10.0 * 0.01;
        let depth: f64 = v[at("bar.depth_at_target")].parse().unwrap();
        let expected = depth_of_area(R, 2e-15 * w * 40.0 * YEAR / WIDTH);
        assert!(
            (depth - expected).abs() < 1e-6 * expected,
            "μ = {mu}: {depth} vs {expected}"
        );
        let years: f64 = v[at("bar.time_to_criterion")].parse().unwrap();
        let tc = WIDTH * segment(R, 4e-4) / (2e-15 * w) / YEAR;
        assert!((years - tc).abs() < 1e-6 * tc);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A fast-wearing contact (an Archard coefficient of 1e-3, a contact at rest on its bar: the
/// life steps are milliseconds against 40 years) runs: its scar grows step by step until
/// the tube is worn through its diameter, the limit of the flat scar's geometry. It used to
/// stop at t = 0 with "the scar reached the limit of its geometry", its first life step
/// being shorter than 1e-12 × the target.
#[test]
fn a_fast_wearing_contact_runs_to_the_limit_of_its_scar() {
    let fast = ARCHARD.replace("coefficient = 2e-15", "coefficient = 1e-3");
    let (case, life) = case(&fast, "target_years = 40.0");
    let r = service_life(&case, &life, |_| {}).unwrap();
    assert!(r.steps.len() > 20, "{} life steps", r.steps.len());
    let LifeEnd::ScarLimit { time, message, .. } = &r.end else {
        panic!("{:?}", r.end)
    };
    assert!(*time > 0.0 && message.contains("worn through"), "{message}");
    // the depth went up to the tube's diameter, the flat scar's largest depth
    let last = &r.steps[r.steps.len() - 1].contacts[0];
    assert!(last.tube_depth > 0.99 * 2.0 * R, "{}", last.tube_depth);
    // and every step kept within its limit, the first ones at the depth resolution
    for pair in r.steps.windows(2) {
        let (a, b) = (&pair[0].contacts[0], &pair[1].contacts[0]);
        let limit = 0.1 * (r.clearances[0] + a.clearance_increase).max(life.depth_resolution);
        assert!(b.clearance_increase - a.clearance_increase <= limit * (1.0 + 1e-9));
    }
}

/// Each way a life ends early has its own end: life steps too small for `max_steps`
/// (`max_depth_change = 1e-10`) end at the step limit, not at "the limit of the scar's
/// geometry" (what every one of them used to say).
#[test]
fn a_life_that_needs_too_many_steps_ends_at_the_step_limit() {
    let (case, life) = case(
        ARCHARD,
        "target_years = 40.0\nmax_depth_change = 1e-10\nmax_steps = 4",
    );
    let r = service_life(&case, &life, |_| {}).unwrap();
    assert_eq!(r.end, LifeEnd::StepLimit);
    assert_eq!(r.steps.len(), 5);
    assert!(r.steps[4].time > r.steps[3].time && r.steps[4].time < YEAR);
    assert!(!r.end.is_finished());
}

/// A life stopped from outside (the signal of `fretdyn life`) at any moment — between life
/// steps or inside a window — and continued from its checkpoint gives the uninterrupted
/// life, bit for bit; a checkpoint of other inputs is refused.
#[test]
fn a_life_stopped_anywhere_and_resumed_is_the_uninterrupted_life() {
    use fretdyn::apps::life::{LifeCheckpoint, LifeControl, service_life_with};
    use std::sync::atomic::{AtomicBool, Ordering};
    // long windows (3 s of 1e-4 s steps: 30 batches each), so that a stop lands inside one
    let text = sliding_mass(ARCHARD, "target_years = 40.0\nmax_depth_change = 0.2")
        .replace("duration = 1.5", "duration = 3.0");
    let case = Case::from_toml_str(&text, Path::new(".")).unwrap();
    let life = case.life.clone().unwrap();
    let whole = service_life(&case, &life, |_| {}).unwrap();
    assert_eq!(whole.end, LifeEnd::Completed);

    let dir = std::env::temp_dir().join(format!("fretdyn_life_resume_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("life_checkpoint.bin");
    let mut resume = None;
    let mut stops = 0;
    let (mut inside, mut between) = (0, 0);
    let resumed = loop {
        let stop = AtomicBool::new(false);
        let mut control = LifeControl {
            checkpoint: Some(&path),
            // a checkpoint at every batch of steps: the stop lands after any of them
            checkpoint_every_seconds: 0.0,
            fingerprint: 42,
            resume: resume.take(),
            stop: Some(&stop),
        };
        let mut seen = 0;
        let r = std::thread::scope(|s| {
            // stop after a few ms, at a different point each time
            if stops < 6 {
                let stop = &stop;
                s.spawn(move || {
                    std::thread::sleep(std::time::Duration::from_millis(7 + 13 * stops));
                    stop.store(true, Ordering::Relaxed);
                });
            }
            service_life_with(&case, &life, &mut control, |_| seen += 1).unwrap()
        });
        match r.end {
            LifeEnd::Stopped { time } => {
                stops += 1;
                let c = LifeCheckpoint::read(&path).unwrap();
                assert_eq!(c.time(), time);
                if c.inside_window() {
                    inside += 1;
                } else {
                    between += 1;
                }
                resume = Some(c);
            }
            _ => break r,
        }
    };
    assert!(stops >= 3, "{stops} stops");
    assert!(
        inside >= 1,
        "no stop inside a window ({between} between steps)"
    );
    assert_eq!(resumed.end, whole.end);
    assert_eq!(resumed.steps, whole.steps);
    assert_eq!(resumed.scars, whole.scars);
    assert_eq!(resumed.time_to_criterion, whole.time_to_criterion);
    assert_eq!(resumed.windows, whole.windows);

    // a checkpoint for other inputs
    let mut control = LifeControl {
        fingerprint: 43,
        resume: Some(LifeCheckpoint::read(&path).unwrap()),
        ..LifeControl::default()
    };
    let e = service_life_with(&case, &life, &mut control, |_| {}).unwrap_err();
    assert!(e.to_string().contains("other inputs"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
