//! Hardening of the physics and the statistics (issue 2.1), each against something
//! independent of the code: closed forms, exact discrete kinematics, invariants.
//!
//! 1. An impact that starts on the first step of the statistics window (a contact closed on
//!    the very first step, as in case V1, or exactly at a window start `t_start > 0`) has its
//!    row, its duration and its peak like any other (THEORY §5, §6).
//! 2. A contact stuck on a moving obstacle slips by exactly 0 and wears nothing with the
//!    Lagrange methods; the slip is the central difference of the position relative to the
//!    obstacle; a contact sliding on a moving obstacle dissipates `μ R_N |v_rel|` (THEORY §2,
//!    §5).
//! 3. A diverged run keeps only finite values, and says at which step, time and contact it
//!    stopped.

use std::f64::consts::{PI, TAU};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use fretdyn::accumulate::statistics::StatisticsSettings;
use fretdyn::case::Case;
use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::motion::Motion;
use fretdyn::contact::obstacle::{Obstacle, Plane};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{RunResults, RunSettings, Termination, simulate};
use fretdyn::loads::{PointLoad, TimeHistory};
use fretdyn::model::Model;
use fretdyn::output::stream::{self, ProgressOnly, StreamSettings};
use fretdyn::structure::modal::ModalBasis;
use nalgebra::Vector3;

fn lagrange_methods() -> [(&'static str, TangentialMethod); 2] {
    [
        (
            "gauss_seidel",
            TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        ),
        (
            "active_set",
            TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        ),
    ]
}

fn all_methods() -> [(&'static str, TangentialMethod); 3] {
    let [gs, a] = lagrange_methods();
    [
        gs,
        a,
        (
            "penalty",
            TangentialMethod::Penalty(PenaltySettings {
                stiffness: 1e6,
                damping: 2000.0,
            }),
        ),
    ]
}

fn settings(
    method: TangentialMethod,
    dt: f64,
    steps: u64,
    stats: StatisticsSettings,
) -> RunSettings {
    RunSettings {
        dt,
        steps,
        method,
        stick_velocity: StickVelocity::HalfStep,
        output_every: 1,
        monitors: Vec::new(),
        statistics: stats,
    }
}

fn scratch_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "fretdyn-hardening-physics-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn streamed(case: &Case, dir: &Path) -> RunResults {
    stream::run(
        &case.model,
        &case.settings,
        dir,
        &StreamSettings::default(),
        1,
        &mut ProgressOnly(|_| ControlFlow::Continue(())),
    )
    .unwrap()
}

/// Data rows of `impacts.csv` (the header excluded).
fn impact_rows(dir: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(dir.join(stream::IMPACTS_FILE)).unwrap();
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

// ---------------------------------------------------------------------------------------
// 1. Impacts that start on the window's first step

/// Case V1a as shipped (examples/v1a_oblique_impact.toml): the mass starts on the plane
/// (gap 0) moving into it, so the contact closes on the very first step. Its one impact
/// lasts `π/ω` (THEORY §6, `ω = √(K_N/m)`), peaks at `m v_n ω`, and is in the impacts table,
/// the duration statistics and the peak-force histogram, with every method, streamed (the
/// CLI's path) and in memory.
#[test]
fn v1a_impact_on_the_first_step_has_its_row_duration_and_peak() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/v1a_oblique_impact.toml");
    let base = Case::from_file(&path).unwrap();
    let (m, kn, v, alpha) = (1.0f64, 1e6f64, 1.0f64, 20f64.to_radians());
    let omega = (kn / m).sqrt();
    let duration = PI / omega;
    let peak = m * v * alpha.cos() * omega;
    // central differences: frequency error (ωΔt)²/24, sampled peak and linearly interpolated
    // zero crossings O((ωΔt)²): 1e-6 at ωΔt = 1e-3
    let wdt2 = (omega * base.settings.dt).powi(2);
    for (label, method) in all_methods() {
        let mut case = Case::from_file(&path).unwrap();
        case.settings.method = method;
        let dir = scratch_dir(&format!("v1a-{label}"));
        let streamed = streamed(&case, &dir);
        let memory = simulate(&case.model, &case.settings).unwrap();
        for (how, r) in [("streamed", &streamed), ("in memory", &memory)] {
            assert_eq!(r.termination, Termination::Completed);
            let c = &r.contacts[0];
            assert_eq!(c.impacts, 1, "{label} {how}: impacts counted");
            assert!(
                (c.contact_duration_mean - duration).abs() <= wdt2 * duration,
                "{label} {how}: duration {} s, π/ω = {duration} s",
                c.contact_duration_mean
            );
            assert_eq!(c.contact_duration_min, c.contact_duration_mean, "{label}");
            assert_eq!(c.contact_duration_max, c.contact_duration_mean, "{label}");
            let counted: u64 = c.peak_force_histogram.iter().map(|b| b.count).sum();
            assert_eq!(
                counted, 1,
                "{label} {how}: histogram {:?}",
                c.peak_force_histogram
            );
            let bin = &c.peak_force_histogram[0];
            assert!(bin.from <= peak && peak < bin.to, "{label} {how}: {bin:?}");
        }
        // the table: one row in the file of the streamed run, one impact in memory
        let rows = impact_rows(&dir);
        assert_eq!(rows.len(), 1, "{label}: impacts.csv {rows:?}");
        assert_eq!(memory.impacts.len(), 1, "{label}");
        let imp = &memory.impacts[0];
        assert_eq!(imp.start, 0.0, "{label}: starts at t = 0");
        assert!(
            (imp.duration - duration).abs() <= wdt2 * duration,
            "{label}: {}",
            imp.duration
        );
        assert!(
            (imp.peak_force - peak).abs() <= wdt2 * peak,
            "{label}: peak {} N, m v_n ω = {peak} N",
            imp.peak_force
        );
        let csv = |k: usize| rows[0][k].parse::<f64>().unwrap();
        // contact,name,start,duration,contact_time,peak_time,peak_force,...
        assert_eq!(csv(2), imp.start, "{label}");
        assert_eq!(csv(3), imp.duration, "{label}");
        assert_eq!(csv(6), imp.peak_force, "{label}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// A free unit mass falling at 1 m/s on a plane, with every number a power of 2 so that the
/// motion before the contact is exact: it reaches the plane exactly at `t_0 = 1024 Δt`, and
/// the statistics window starts exactly there. The impact starts at `t_0` (its first closed
/// step is the window's first) and is counted, tabled and measured once; with the window
/// starting in the middle of the impact, it starts with the window (THEORY §11).
#[test]
fn impact_starting_exactly_at_the_window_start_is_counted_once_with_its_row() {
    let (kn, v) = (1e6f64, 1.0f64);
    let dt = 2f64.powi(-20);
    let t0 = 1024.0 * dt;
    let omega = kn.sqrt();
    let duration = PI / omega;
    let mut model = Model::new(ModalBasis::point_mass(1.0, "mass", Vector3::zeros()).unwrap());
    model.contacts.push(Contact::new(
        "plane",
        0,
        Obstacle::Plane(
            Plane::new(Vector3::zeros(), Vector3::z(), 0.0, Some(Vector3::x()), "p").unwrap(),
        ),
        NormalLaw::new(kn, 0.0, "n").unwrap(),
        Coulomb::new(0.3, 0.3, "f").unwrap(),
    ));
    model.initial.q = vec![0.0, 0.0, v * t0];
    model.initial.qdot = vec![0.0, 0.0, -v];
    let steps = 1024 + 2 * (duration / dt) as u64;
    let wdt2 = (omega * dt).powi(2);
    for (label, method) in all_methods() {
        let stats = StatisticsSettings {
            t_start: t0,
            ..Default::default()
        };
        let r = simulate(&model, &settings(method, dt, steps, stats)).unwrap();
        let c = &r.contacts[0];
        assert_eq!(c.impacts, 1, "{label}");
        assert_eq!(r.impacts.len(), 1, "{label}: the impact's row");
        let imp = &r.impacts[0];
        assert_eq!(imp.start, t0, "{label}: starts at the window's start");
        assert!(
            (imp.duration - duration).abs() <= wdt2 * duration,
            "{label}: {} vs π/ω = {duration}",
            imp.duration
        );
        assert!(
            (imp.peak_force - v * omega).abs() <= wdt2 * v * omega,
            "{label}"
        );
        assert!(
            (imp.impact_speed - v).abs() <= 1e-12,
            "{label}: {}",
            imp.impact_speed
        );
        assert_eq!(c.contact_duration_mean, imp.duration, "{label}");
        let counted: u64 = c.peak_force_histogram.iter().map(|b| b.count).sum();
        assert_eq!(counted, 1, "{label}");

        // a window that starts during the impact: the impact starts with the window (issue
        // 3.1, THEORY §11), at the start of its first step (within Δt/2 of t_start), lasts to
        // the opening at t0 + π/ω, and its impact speed is the approach speed there,
        // v cos(ω (t − t0)) = 0 at the deepest point (to ω v Δt/2)
        let t_start = t0 + 0.5 * duration;
        let stats = StatisticsSettings {
            t_start,
            ..Default::default()
        };
        let r = simulate(&model, &settings(method, dt, steps, stats)).unwrap();
        assert_eq!(r.contacts[0].impacts, 1, "{label}");
        assert_eq!(r.impacts.len(), 1, "{label}: {:?}", r.impacts);
        let imp = &r.impacts[0];
        assert!((imp.start - t_start).abs() <= 0.5 * dt, "{label}: {imp:?}");
        assert!(
            (imp.start + imp.duration - (t0 + duration)).abs() <= wdt2 * duration,
            "{label}: {imp:?}"
        );
        assert!(imp.impact_speed.abs() <= omega * v * dt, "{label}: {imp:?}");
        assert_eq!(
            r.contacts[0]
                .peak_force_histogram
                .iter()
                .map(|b| b.count)
                .sum::<u64>(),
            1,
            "{label}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// 2. Slip on moving obstacles

/// A unit mass pressed with `N = 10 N` on a plane (`K_N = 1e6 N/m`, μ = 0.3, at the static
/// penetration) that moves along its tangent `x` with `motion`; the mass starts with
/// `velocity` along x.
fn pressed_on_a_moving_plane(motion: Motion, velocity: f64) -> Model {
    let (n, kn) = (10.0, 1e6);
    let mut model = Model::new(ModalBasis::point_mass(1.0, "mass", Vector3::zeros()).unwrap());
    let mut c = Contact::new(
        "plane",
        0,
        Obstacle::Plane(
            Plane::new(Vector3::zeros(), Vector3::z(), 0.0, Some(Vector3::x()), "p").unwrap(),
        ),
        NormalLaw::new(kn, 0.0, "n").unwrap(),
        Coulomb::new(0.3, 0.3, "f").unwrap(),
    );
    c.motion = motion;
    model.contacts.push(c);
    model
        .loads
        .push(PointLoad::new(0, Vector3::new(0.0, 0.0, -n), TimeHistory::Constant, "l").unwrap());
    model.initial.q = vec![0.0, 0.0, -n / kn];
    model.initial.qdot = vec![velocity, 0.0, 0.0];
    model
}

fn harmonic_x(amplitude: f64, frequency_hz: f64) -> Motion {
    Motion::Harmonic {
        amplitude: Vector3::new(amplitude, 0.0, 0.0),
        frequency_hz,
        phase: 0.0,
    }
}

/// The plane oscillates tangentially as `A sin ωt` (A = 0.5 mm, 10 Hz): the mass follows it
/// with `m A ω² = 2.0 N < μ_s N = 3 N`, so it sticks throughout. With the Lagrange methods the
/// slip velocity is exactly 0 on every step that is stuck on both half-steps (from the
/// second on: the first half-step velocity is the initial state's), the wear work rate is
/// exactly 0, and the mass keeps its place on the plane (relative position constant to
/// round-off), at two time steps. (Before: a slip of order Δt² against `ḋ(t_{n+1})` and a wear
/// rate of 1.3e-7 W at Δt = 1e-4 s, 3.2e-8 W at 5e-5 s.)
#[test]
fn stuck_on_a_moving_plane_slips_and_wears_exactly_nothing() {
    let (a, f) = (5e-4, 10.0);
    let w = TAU * f;
    let model = pressed_on_a_moving_plane(harmonic_x(a, f), a * w);
    for dt in [1e-4, 5e-5] {
        let steps = (0.5 / dt) as u64;
        let stats = StatisticsSettings {
            t_start: 2.0 * dt,
            ..Default::default()
        };
        for (label, method) in lagrange_methods() {
            let r = simulate(&model, &settings(method, dt, steps, stats)).unwrap();
            let rec = &r.recorder;
            let c = &r.contacts[0];
            assert_eq!(c.stick_time_fraction, 1.0, "{label} Δt = {dt}");
            assert_eq!(c.wear_work_rate, 0.0, "{label} Δt = {dt}");
            assert_eq!(c.normal_wear_work_rate, 0.0, "{label} Δt = {dt}");
            let x0 = rec.position[[2, 0, 1]];
            for i in 2..rec.len() {
                assert_eq!(rec.status[[i, 0]], 1, "{label}: sticks at sample {i}");
                assert_eq!(rec.slip_velocity[[i, 0, 0]], 0.0, "{label} Δt = {dt}: {i}");
                assert_eq!(rec.slip_velocity[[i, 0, 1]], 0.0, "{label}");
                let drift = (rec.position[[i, 0, 1]] - x0).abs();
                assert!(
                    drift <= 1e-12 * a,
                    "{label} Δt = {dt}: drift {drift} m at {i}"
                );
            }
        }
    }
}

/// The full-step slip velocity is measured consistently with the scheme: `q̇_{n+1}` is the
/// central difference `(q_{n+2} − q_n)/(2Δt)` of the positions, so the slip velocity relative
/// to the obstacle must be the central difference of the recorded position relative to the
/// obstacle, on every step, sliding or stuck (here a stick–slip on a plane oscillating with
/// `m A ω² = 3.9 N > μ N = 3 N`). Measured against `ḋ(t_{n+1})` it differed by `O(Δt²)`
/// (`A ω³ Δt²/6`, 7e-6 of `A ω` at Δt = 1e-4 s).
#[test]
fn slip_on_a_moving_plane_is_the_central_difference_of_the_relative_position() {
    let (a, f) = (1e-3, 10.0);
    let w = TAU * f;
    let model = pressed_on_a_moving_plane(harmonic_x(a, f), a * w);
    for dt in [1e-4, 5e-5] {
        let steps = (0.3 / dt) as u64;
        for (label, method) in lagrange_methods() {
            let r = simulate(&model, &settings(method, dt, steps, Default::default())).unwrap();
            let rec = &r.recorder;
            let (mut stick, mut slip, mut worst) = (0, 0, 0.0f64);
            for i in 1..rec.len() - 1 {
                let central = (rec.position[[i + 1, 0, 1]] - rec.position[[i - 1, 0, 1]])
                    / (rec.t[i + 1] - rec.t[i - 1]);
                worst = worst.max((rec.slip_velocity[[i, 0, 0]] - central).abs());
                match rec.status[[i, 0]] {
                    1 => stick += 1,
                    2 => slip += 1,
                    s => panic!("{label}: status {s} at {i}"),
                }
            }
            assert!(
                stick > 100 && slip > 100,
                "{label}: {stick} stuck, {slip} sliding"
            );
            // round-off of positions ~1e-3 m differenced over Δt: ~1e-15/Δt m/s
            assert!(
                worst <= 1e-10 * a * w,
                "{label} Δt = {dt}: slip − central difference up to {worst} m/s"
            );
        }
    }
}

/// A mass at rest pressed (N = 10 N) on a plane moving at V = 0.05 m/s along x: it slides,
/// dragged by `μ N` (μ = 0.3), accelerates at `μN/m` and sticks at `t* = mV/(μN)`. The friction
/// power while it slides is `μ R_N |v_rel| = μ N (V − μN t/m)` (the first step has no friction
/// yet: `t − Δt/2`), and the friction work up to the stick is the relative kinetic energy
/// `½ m V²` the plane's frame loses.
#[test]
fn sliding_on_a_plane_moving_at_constant_velocity_dissipates_mu_rn_vrel() {
    let (m, n, mu, v) = (1.0f64, 10.0f64, 0.3f64, 0.05f64);
    let acc = mu * n / m;
    let t_star = v / acc;
    let model = pressed_on_a_moving_plane(Motion::Velocity(Vector3::new(v, 0.0, 0.0)), 0.0);
    for dt in [1e-5, 5e-6] {
        let steps = (2.0 * t_star / dt) as u64;
        for (label, method) in lagrange_methods() {
            let r = simulate(&model, &settings(method, dt, steps, Default::default())).unwrap();
            let rec = &r.recorder;
            let stick = (1..rec.len()).find(|&i| rec.status[[i, 0]] == 1).unwrap();
            assert!(
                (rec.t[stick] - t_star).abs() <= 2.0 * dt,
                "{label}: {}",
                rec.t[stick]
            );
            for i in 1..stick {
                assert_eq!(rec.status[[i, 0]], 2, "{label}");
                let (rt, vt) = (
                    rec.tangential_force[[i, 0, 0]],
                    rec.slip_velocity[[i, 0, 0]],
                );
                let power = (rt * vt).abs();
                let expected = mu * rec.normal_force[[i, 0]] * (v - acc * (rec.t[i] - 0.5 * dt));
                assert!(
                    (power - expected).abs() <= 1e-9 * mu * n * v,
                    "{label} Δt = {dt}: power {power} W vs μ R_N |v_rel| = {expected} W at {i}"
                );
                assert!(
                    rt > 0.0 && vt < 0.0,
                    "{label}: the plane drags the mass along +x"
                );
            }
            let c = &r.contacts[0];
            let work = 0.5 * m * v * v;
            // rectangle rule on a linearly falling power: within μ N V Δt of the integral
            assert!(
                (c.wear_work - work).abs() <= mu * n * v * dt,
                "{label} Δt = {dt}: friction work {} J vs ½ m V² = {work} J",
                c.wear_work
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// 3. Divergence

/// A unit mass pressed on a plane by a load that grows ×10^1.5 every `period` (a table of 200
/// rows up to 1e298 N), at a rate `r = ln 10^1.5/period`. Pressed normally, slowly
/// (`r = 3.5e4/s` below `ω = √K_N = 1e5 rad/s`, quasi-static), the normal force `R_N ≈ F` is
/// the first value that cannot be kept — its square overflows the statistics before the
/// energy `F²/(2K_N)` or the load's power `F² r/K_N` do; pushed obliquely and fast
/// (`r = 3.5e5/s`, `ω = 1e3 rad/s`), the mass cannot follow and the load's power `F²/r`
/// goes first. The run
/// stops at the first step whose values cannot all be kept, says its step and time, names the
/// contact when it is a contact's value, and everything kept — samples, statistics, energy
/// balance, summary.json, the streamed series — is finite. (Before: summary.json had `null`
/// for normal_force_rms, normal_wear_work_rate, the external work and the balance error.)
#[test]
fn diverged_run_keeps_only_finite_values_and_names_step_time_and_contact() {
    for (force, stiffness, period, culprit) in [
        ("[0.0, 0.0, -1.0]", "1e10", 1e-4, Some("plane")),
        ("[1.0, 0.3, -1.0]", "1e6", 1e-5, None),
    ] {
        diverging(force, stiffness, period, culprit);
    }
}

fn diverging(force: &str, stiffness: &str, period: f64, culprit: Option<&str>) {
    let rows: Vec<String> = (0..200)
        .map(|k| {
            format!(
                "[{:e}, {:e}]",
                k as f64 * period,
                10f64.powf(1.5 * k as f64)
            )
        })
        .collect();
    let text = format!(
        r#"
title = "diverging"
[time]
dt = 1e-6
duration = {duration:e}
[structure]
type = "point_mass"
mass = 1.0
point = "mass"
[[contacts]]
name = "plane"
point = "mass"
obstacle = {{ type = "plane", origin = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], gap = 1e-4, tangent = [1.0, 0.0, 0.0] }}
normal = {{ stiffness = {stiffness} }}
friction = {{ mu = 0.3 }}
[[loads]]
point = "mass"
force = {force}
history = {{ type = "table", table = [{}] }}
[output]
every = 1
"#,
        rows.join(", "),
        duration = 200.0 * period,
    );
    for (label, method) in all_methods() {
        let mut case = Case::from_toml_str(&text, Path::new(".")).unwrap();
        case.settings.method = method;
        let label = format!("{label}, force {force}");
        let dir = scratch_dir(&format!(
            "diverge-{stiffness}-{}",
            case.settings.method.name()
        ));
        let streamed = streamed(&case, &dir);
        let memory = simulate(&case.model, &case.settings).unwrap();
        for (how, r) in [("streamed", &streamed), ("in memory", &memory)] {
            let Termination::Diverged {
                step,
                time,
                contact,
            } = &r.termination
            else {
                panic!("{label} {how}: {:?}", r.termination)
            };
            assert_eq!(contact.as_deref(), culprit, "{label} {how}");
            assert_eq!(*time, *step as f64 * case.settings.dt, "{label} {how}");
            assert_eq!(r.steps, step - 1, "{label} {how}: the steps kept");
            let summary = fretdyn::output::summary::summary(&case, r);
            let mut nulls = Vec::new();
            find_nulls(&summary, "summary", &mut nulls);
            // the one null allowed: no contact to name
            nulls.retain(|p| culprit.is_some() || p != "summary.termination.contact");
            assert!(nulls.is_empty(), "{label} {how}: not finite: {nulls:?}");
            assert_eq!(summary["termination"]["status"], "diverged");
            assert_eq!(summary["termination"]["step"], *step);
            if let Some(name) = culprit {
                assert_eq!(summary["termination"]["contact"], name);
            }
        }
        // what is kept of the samples: all finite, up to the step before
        let rec = &memory.recorder;
        assert_eq!(rec.len() as u64, memory.steps + 1, "{label}");
        for (key, data) in [
            ("q", rec.q.as_slice().unwrap()),
            ("qdot", rec.qdot.as_slice().unwrap()),
            ("normal_force", rec.normal_force.as_slice().unwrap()),
            ("tangential_force", rec.tangential_force.as_slice().unwrap()),
            ("slip_velocity", rec.slip_velocity.as_slice().unwrap()),
            ("penetration", rec.penetration.as_slice().unwrap()),
            ("position", rec.position.as_slice().unwrap()),
        ] {
            assert!(data.iter().all(|x| x.is_finite()), "{label}: {key}");
        }
        let results = dir.join(stream::RESULTS_FILE);
        let mut npz = ndarray_npy::NpzReader::new(std::fs::File::open(results).unwrap()).unwrap();
        for name in npz.names().unwrap() {
            if name.starts_with("contact_status") {
                continue;
            }
            let a: ndarray::ArrayD<f64> = npz.by_name(&name).unwrap();
            assert_eq!(a.shape()[0] as u64, memory.steps + 1, "{label}: {name}");
            assert!(a.iter().all(|x| x.is_finite()), "{label}: {name}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// JSON paths of the `null`s (non-finite numbers) in the results of `v` (not in the echoed
/// case and the obstacles' outlines, where null means "none").
fn find_nulls(v: &serde_json::Value, path: &str, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Null => out.push(path.to_string()),
        serde_json::Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| find_nulls(x, &format!("{path}[{i}]"), out)),
        serde_json::Value::Object(o) => o
            .iter()
            .filter(|(k, _)| !matches!(k.as_str(), "case" | "contact_geometry"))
            .for_each(|(k, x)| find_nulls(x, &format!("{path}.{k}"), out)),
        _ => {}
    }
}
