//! THEORY §6, verification case V1: oblique impact of a point mass on a fixed plane, every
//! tangential method against the analytic solution.
//!
//! The library's own acceptance table (`verification::checks`) is run for every case and
//! method; the explicit tests below recompute the key quantities directly from the recorded
//! time histories and the analytic formulas of §6, so that they do not depend on
//! `verification::measure`.

use fretdyn::apps::verification::{Check, V1, V1Measurements, checks, measure, methods};
use fretdyn::contact::tangential::{GaussSeidelSettings, StickVelocity, TangentialMethod};
use fretdyn::integrator::simulation::{RunResults, simulate};

const PENALTY_KT: [f64; 3] = [1e5, 1e6, 1e7];

fn cases() -> [(&'static str, f64); 3] {
    [("V1a", 20.0), ("V1b", 1e-7), ("V1c", 60.0)]
}

fn run(v1: &V1, method: TangentialMethod, stick: StickVelocity) -> RunResults {
    let results = simulate(&v1.model(), &v1.settings(method, stick)).expect("V1 runs");
    assert_eq!(
        results.termination,
        fretdyn::integrator::simulation::Termination::Completed
    );
    results
}

fn run_measured(v1: &V1, method: TangentialMethod) -> (RunResults, V1Measurements) {
    let r = run(v1, method, StickVelocity::HalfStep);
    let m = measure(v1, &r);
    (r, m)
}

fn gauss_seidel() -> TangentialMethod {
    TangentialMethod::GaussSeidel(GaussSeidelSettings::default())
}

/// Velocity of the point mass at the last sample (rows are I/√m: v = q̇/√m).
fn final_velocity(v1: &V1, r: &RunResults) -> [f64; 3] {
    let last = r.recorder.len() - 1;
    let qd = r.recorder.qdot.row(last);
    let s = 1.0 / v1.mass.sqrt();
    [qd[0] * s, qd[1] * s, qd[2] * s]
}

/// (normal, tangential) leaving speeds for the reference orientation (plane z = 0).
fn leaving_speeds(v1: &V1, r: &RunResults) -> (f64, f64) {
    assert_eq!(
        v1.normal,
        nalgebra::Vector3::z(),
        "helper assumes plane z = 0"
    );
    let v = final_velocity(v1, r);
    (v[2], v[0].hypot(v[1]))
}

fn tangential_force_norm(r: &RunResults, i: usize) -> f64 {
    r.recorder.tangential_force[[i, 0, 0]].hypot(r.recorder.tangential_force[[i, 0, 1]])
}

fn assert_all_checks_pass(case: &str, alpha_deg: f64) {
    let v1 = V1::reference(alpha_deg);
    let mut failed: Vec<Check> = Vec::new();
    let mut count = 0;
    for (label, method) in methods(&PENALTY_KT) {
        let (_, m) = run_measured(&v1, method);
        let c = checks(case, &label, method.is_lagrange(), &v1, &m);
        assert!(c.len() >= 5, "{case} {label}: too few checks");
        count += c.len();
        failed.extend(c.into_iter().filter(|c| !c.passed));
    }
    assert!(count > 0);
    assert!(
        failed.is_empty(),
        "{case}: {} of {count} checks failed:\n{}",
        failed.len(),
        failed
            .iter()
            .map(|c| format!(
                "  {} {}: {} = {:e} > {:e}",
                c.case, c.method, c.quantity, c.value, c.limit
            ))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

#[test]
fn v1a_every_acceptance_check_passes_for_every_method() {
    assert_all_checks_pass("V1a", 20.0);
}

#[test]
fn v1b_every_acceptance_check_passes_for_every_method() {
    assert_all_checks_pass("V1b", 1e-7);
}

#[test]
fn v1c_every_acceptance_check_passes_for_every_method() {
    assert_all_checks_pass("V1c", 60.0);
}

/// R_N(t) = m v_n ω sin ωt during the contact, and the mass leaves with normal speed v_n —
/// for every case and method (the normal penalty law does not depend on the tangential one).
#[test]
fn normal_force_and_leaving_normal_speed_match_analytic_for_all_methods() {
    for (case, alpha) in cases() {
        let v1 = V1::reference(alpha);
        let m = v1.mass;
        let omega = (v1.stiffness / m).sqrt();
        let vn = v1.speed * v1.alpha.cos();
        let peak = m * vn * omega;
        let duration = std::f64::consts::PI / omega;
        for (label, method) in methods(&PENALTY_KT) {
            let r = run(&v1, method, StickVelocity::HalfStep);
            let rec = &r.recorder;
            let mut err = 0.0f64;
            let mut closed_samples = 0;
            for i in 0..rec.len() {
                let t = rec.t[i];
                let analytic = if t < duration {
                    peak * (omega * t).sin()
                } else {
                    0.0
                };
                err = err.max((rec.normal_force[[i, 0]] - analytic).abs() / peak);
                if rec.status[[i, 0]] != 0 {
                    closed_samples += 1;
                }
            }
            assert!(err <= 1e-4, "{case} {label}: normal force error {err:e}");
            // the contact lasts π/ω = 3.1416 ms = 3141 or 3142 steps of 1 µs
            let expected = duration / v1.dt;
            assert!(
                (closed_samples as f64 - expected).abs() <= 2.0,
                "{case} {label}: {closed_samples} closed samples, π/(ωΔt) = {expected}"
            );
            let (leaving_vn, _) = leaving_speeds(&v1, &r);
            let e = (leaving_vn - vn).abs() / v1.speed;
            assert!(
                e <= 1e-4,
                "{case} {label}: leaving normal speed {leaving_vn}, analytic {vn}"
            );
        }
    }
}

#[test]
fn v1a_lagrange_methods_stick_at_t_star_then_exactly_zero_tangential_force() {
    let v1 = V1::reference(20.0);
    let omega = (v1.stiffness / v1.mass).sqrt();
    let t_star = (1.0 - v1.alpha.tan() / v1.mu_dynamic).acos() / omega;
    assert!(
        (t_star - 1.78568e-3).abs() <= 1e-8,
        "t* = {t_star} (THEORY §6: 1.78568 ms)"
    );
    assert!((v1.stick_time().unwrap() - t_star).abs() <= 1e-15);
    for (label, method) in methods(&[]) {
        assert!(method.is_lagrange());
        let r = run(&v1, method, StickVelocity::HalfStep);
        let rec = &r.recorder;
        let first_stick = (0..rec.len())
            .find(|&i| rec.status[[i, 0]] == 1)
            .map(|i| rec.t[i]);
        let first_stick = first_stick.unwrap_or_else(|| panic!("{label}: never sticks"));
        assert!(
            (first_stick - t_star).abs() <= 2.0 * v1.dt,
            "{label}: first stick sample at {first_stick:e} s, t* = {t_star:e} s"
        );
        let max_rn = rec.normal_force.iter().fold(0.0f64, |a, &b| a.max(b));
        let mut post = 0.0f64;
        let mut post_samples = 0;
        for i in 0..rec.len() {
            if rec.t[i] >= t_star + 2.0 * v1.dt && rec.status[[i, 0]] != 0 {
                post = post.max(tangential_force_norm(&r, i));
                post_samples += 1;
                assert_eq!(
                    rec.status[[i, 0]],
                    1,
                    "{label}: slips again at {}",
                    rec.t[i]
                );
            }
        }
        assert!(
            post_samples > 1000,
            "{label}: {post_samples} post-stick samples"
        );
        assert!(
            post <= 1e-9 * max_rn,
            "{label}: |R_T| after t*+2Δt = {post:e} N, max R_N = {max_rn} N"
        );
        let (_, vt) = leaving_speeds(&v1, &r);
        assert!(vt <= 1e-9, "{label}: leaving tangential speed {vt:e} m/s");
    }
}

/// THEORY §6: the sticking time 1.08e-7 s is inside the first step; Gauss–Seidel and the
/// penalty law stick from the first closed step.
#[test]
fn v1b_gauss_seidel_and_penalty_stick_from_the_first_closed_step() {
    let v1 = V1::reference(1e-7);
    let t_star = v1.stick_time().expect("V1b sticks");
    assert!(t_star < v1.dt, "t* = {t_star:e}");
    for (label, method) in methods(&PENALTY_KT) {
        if matches!(method, TangentialMethod::ActiveSet(_)) {
            continue;
        }
        let r = run(&v1, method, StickVelocity::HalfStep);
        let rec = &r.recorder;
        let closed: Vec<usize> = (0..rec.len())
            .filter(|&i| rec.status[[i, 0]] != 0)
            .collect();
        assert!(
            closed.len() > 3000,
            "{label}: {} closed samples",
            closed.len()
        );
        assert!(
            (rec.t[closed[0]] - v1.dt).abs() < 1e-12,
            "{label}: first closed at {}",
            rec.t[closed[0]]
        );
        let slipping: Vec<f64> = closed
            .iter()
            .filter(|&&i| rec.status[[i, 0]] != 1)
            .map(|&i| rec.t[i])
            .collect();
        assert!(
            slipping.is_empty(),
            "{label}: {} slip samples, first at {:e} s",
            slipping.len(),
            slipping[0]
        );
    }
}

/// tan 60° > 2 μ_d: slides throughout and leaves with V sin α − 2 μ_d V cos α.
#[test]
fn v1c_slides_throughout_and_leaves_with_analytic_tangential_speed() {
    let v1 = V1::reference(60.0);
    assert!(v1.alpha.tan() > 2.0 * v1.mu_dynamic);
    let expected = v1.speed * v1.alpha.sin() - 2.0 * v1.mu_dynamic * v1.speed * v1.alpha.cos();
    assert!(expected > 0.0);
    for (label, method) in methods(&PENALTY_KT) {
        let r = run(&v1, method, StickVelocity::HalfStep);
        let rec = &r.recorder;
        let sticks = (0..rec.len()).filter(|&i| rec.status[[i, 0]] == 1).count();
        assert_eq!(sticks, 0, "{label}: {sticks} stick samples");
        assert!((0..rec.len()).any(|i| rec.status[[i, 0]] == 2));
        let (_, vt) = leaving_speeds(&v1, &r);
        assert!(
            (vt - expected).abs() / v1.speed <= 1e-4,
            "{label}: leaving tangential speed {vt}, analytic {expected}"
        );
    }
}

/// THEORY §2: the paper's literal full-step stick constraint leaves an alternating spurious
/// tangential force after sticking (±99 N for a ~940 N peak); the half-step one gives 0. The
/// slip phase is the same for both.
#[test]
fn full_step_stick_constraint_leaves_a_spurious_force_half_step_does_not() {
    let v1 = V1::reference(20.0);
    let t_star = v1.stick_time().unwrap();
    let full = run(&v1, gauss_seidel(), StickVelocity::FullStep);
    let half = run(&v1, gauss_seidel(), StickVelocity::HalfStep);
    let m_full = measure(&v1, &full);
    let m_half = measure(&v1, &half);
    assert!(
        m_full.post_stick_force > 0.05,
        "full step: post-stick |R_T|/max R_N = {:e}",
        m_full.post_stick_force
    );
    assert!(
        m_half.post_stick_force <= 1e-9,
        "half step: post-stick |R_T|/max R_N = {:e}",
        m_half.post_stick_force
    );
    for (name, m) in [("full", &m_full), ("half", &m_half)] {
        assert!(
            m.slip_force_error <= 1e-4,
            "{name} step: slip force error {:e}",
            m.slip_force_error
        );
    }
    // The spurious force alternates in sign from step to step (THEORY §2: +λ, −λ, +λ …).
    let rec = &full.recorder;
    let post: Vec<f64> = (0..rec.len())
        .filter(|&i| rec.t[i] >= t_star + 2.0 * v1.dt && rec.status[[i, 0]] != 0)
        .map(|i| rec.tangential_force[[i, 0, 0]])
        .collect();
    assert!(post.len() > 1000);
    let alternating = post.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
    assert!(
        alternating as f64 >= 0.9 * (post.len() - 1) as f64,
        "full step: only {alternating} of {} consecutive post-stick pairs change sign",
        post.len() - 1
    );
}

/// THEORY §6: penalty results depend strongly on K_T, and none of them sticks exactly.
#[test]
fn penalty_post_stick_behaviour_depends_on_kt_and_is_worse_than_lagrange() {
    let v1 = V1::reference(20.0);
    let mut lagrange_vt = Vec::new();
    let mut penalty = Vec::new(); // (label, leaving tangential speed, wear work)
    for (label, method) in methods(&PENALTY_KT) {
        let r = run(&v1, method, StickVelocity::HalfStep);
        let (_, vt) = leaving_speeds(&v1, &r);
        if method.is_lagrange() {
            lagrange_vt.push((label, vt));
        } else {
            penalty.push((label, vt, r.contacts[0].wear_work));
        }
    }
    assert_eq!(penalty.len(), 3);
    for (label, vt) in &lagrange_vt {
        assert!(*vt <= 1e-9, "{label}: leaving tangential speed {vt:e}");
    }
    let rel = |a: f64, b: f64| (a - b).abs() / a.abs().max(b.abs());
    for i in 0..penalty.len() {
        let (li, vi, wi) = &penalty[i];
        assert!(
            *vi > 1e-9,
            "{li}: leaving tangential speed {vi:e}: penalty should not stick exactly"
        );
        for (lj, vj, wj) in &penalty[i + 1..] {
            assert!(
                rel(*vi, *vj) > 0.01 || rel(*wi, *wj) > 0.01,
                "{li} vs {lj}: leaving v_T {vi:e} vs {vj:e}, wear work {wi:e} vs {wj:e} J"
            );
        }
    }
}
