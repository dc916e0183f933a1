//! Physical invariants of the discrete model on case V1 (THEORY §2, §5, §6): rotation
//! invariance of the isotropic friction law, energy conservation of the elastic frictionless
//! impact, friction dissipation, and mass/stiffness scaling.

use fretdyn::apps::verification::{V1, measure};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use fretdyn::integrator::simulation::{RunResults, Termination, simulate};
use nalgebra::Vector3;

fn methods() -> Vec<(&'static str, TangentialMethod)> {
    vec![
        (
            "gauss_seidel",
            TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        ),
        (
            "active_set",
            TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        ),
        (
            "penalty",
            TangentialMethod::Penalty(PenaltySettings {
                stiffness: 1e6,
                damping: 2000.0,
            }),
        ),
    ]
}

fn run(v1: &V1, method: TangentialMethod) -> RunResults {
    let r = simulate(&v1.model(), &v1.settings(method, StickVelocity::HalfStep)).expect("V1 runs");
    assert_eq!(r.termination, Termination::Completed);
    r
}

/// Physical velocity of the point mass at sample `i` (rows I/√m: v = q̇/√m).
fn velocity(v1: &V1, r: &RunResults, i: usize) -> Vector3<f64> {
    let qd = r.recorder.qdot.row(i);
    Vector3::new(qd[0], qd[1], qd[2]) / v1.mass.sqrt()
}

/// (normal, tangential) speed of the point at the last sample, for the plane normal of `v1`.
fn leaving_speeds(v1: &V1, r: &RunResults) -> (f64, f64) {
    let n = v1.normal.normalize();
    let v = velocity(v1, r, r.recorder.len() - 1);
    let vn = v.dot(&n);
    (vn, (v - n * vn).norm())
}

fn tangential_force(r: &RunResults, i: usize) -> f64 {
    r.recorder.tangential_force[[i, 0, 0]].hypot(r.recorder.tangential_force[[i, 0, 1]])
}

/// Kinetic energy ½|q̇|² of the last sample (modes are mass-normalised).
fn final_kinetic_energy(r: &RunResults) -> f64 {
    let last = r.recorder.len() - 1;
    0.5 * r.recorder.qdot.row(last).iter().map(|v| v * v).sum::<f64>()
}

/// Friction is isotropic (THEORY §4): a plane with a generic normal and fretdyn's default
/// tangent basis, hit along a generic direction, gives the same scalar history as the
/// reference orientation (plane z = 0, sliding along its first tangent x).
#[test]
fn v1a_is_invariant_under_rotation_of_plane_and_slide_direction() {
    let reference = V1::reference(20.0);
    let rotated = V1 {
        normal: Vector3::new(1.0, 2.0, 3.0).normalize(),
        plane_tangent: None,
        slide_direction: Vector3::new(1.0, 1.0, -0.3),
        ..reference.clone()
    };
    // the incoming tangential velocity is not along a tangent axis of the default basis
    let n = rotated.normal;
    let s = rotated.slide_direction - n * n.dot(&rotated.slide_direction);
    let s = s.normalize();
    let model = rotated.model();
    let frame = model.contacts[0].frame(&Vector3::zeros(), 0.0);
    let (plane_normal, t) = (frame.normal, frame.tangents);
    assert!((plane_normal - n).norm() < 1e-15);
    assert!(
        t[0].dot(&s).abs() < 0.99 && t[1].dot(&s).abs() < 0.99,
        "slide direction {s:?} should not be a tangent axis {t:?}"
    );

    let peak = reference.peak_normal_force();
    for (label, method) in methods() {
        let a = run(&reference, method);
        let b = run(&rotated, method);
        let (ra, rb) = (&a.recorder, &b.recorder);
        assert_eq!(ra.len(), rb.len());
        for i in 0..ra.len() {
            assert_eq!(
                ra.status[[i, 0]],
                rb.status[[i, 0]],
                "{label}: status differs at t = {}",
                ra.t[i]
            );
            let dn = (ra.normal_force[[i, 0]] - rb.normal_force[[i, 0]]).abs() / peak;
            let dt = (tangential_force(&a, i) - tangential_force(&b, i)).abs() / peak;
            assert!(
                dn <= 1e-9 && dt <= 1e-9,
                "{label}: at t = {} R_N {} vs {}, |R_T| {} vs {}",
                ra.t[i],
                ra.normal_force[[i, 0]],
                rb.normal_force[[i, 0]],
                tangential_force(&a, i),
                tangential_force(&b, i)
            );
        }
        let (vna, vta) = leaving_speeds(&reference, &a);
        let (vnb, vtb) = leaving_speeds(&rotated, &b);
        assert!(
            (vna - vnb).abs() <= 1e-9 * reference.speed
                && (vta - vtb).abs() <= 1e-9 * reference.speed,
            "{label}: leaving (v_n, v_t) = ({vna}, {vta}) vs rotated ({vnb}, {vtb})"
        );
        // in the rotated frame the friction force still opposes the slip exactly
        let m = measure(&rotated, &b);
        assert!(
            m.slip_direction_error <= 1e-6,
            "{label}: slip direction error {:e}",
            m.slip_direction_error
        );
        // and the whole velocity stays in the plane spanned by n and the slide direction
        for i in 0..rb.len() {
            let v = velocity(&rotated, &b, i);
            let off = v.dot(&n.cross(&s)).abs();
            assert!(
                off <= 1e-9,
                "{label}: velocity leaves the plane of incidence by {off:e}"
            );
        }
    }
}

fn frictionless(alpha_deg: f64) -> V1 {
    V1 {
        mu_static: 0.0,
        mu_dynamic: 0.0,
        ..V1::reference(alpha_deg)
    }
}

/// THEORY §5: an elastic normal contact with no friction and no damping conserves energy up to
/// the scheme's O(Δt²) error; the mass leaves with its initial kinetic energy ½ m V².
#[test]
fn frictionless_elastic_impact_conserves_energy() {
    let v1 = frictionless(20.0);
    let e0 = 0.5 * v1.mass * v1.speed * v1.speed;
    for (label, method) in methods() {
        let r = run(&v1, method);
        assert!(
            (r.energy.initial - e0).abs() <= 1e-15,
            "{label}: initial energy {}",
            r.energy.initial
        );
        assert!(
            r.energy.relative_error < 1e-6,
            "{label}: energy balance error {:e}",
            r.energy.relative_error
        );
        assert!(
            r.energy.tangential.abs() <= 1e-15,
            "{label}: friction work {}",
            r.energy.tangential
        );
        let last = r.recorder.len() - 1;
        assert_eq!(
            r.recorder.status[[last, 0]],
            0,
            "{label}: still in contact at the end"
        );
        let ke = final_kinetic_energy(&r);
        assert!(
            (ke - e0).abs() <= 1e-6 * e0,
            "{label}: kinetic energy after leaving {ke}, before {e0}"
        );
        // no friction: the tangential velocity is untouched
        let (_, vt) = leaving_speeds(&v1, &r);
        assert!(
            (vt - v1.speed * v1.alpha.sin()).abs() <= 1e-12,
            "{label}: v_T {vt}"
        );
    }
}

/// With friction the mass loses kinetic energy; what it loses is what the energy balance
/// books as dissipated by the tangential forces, and (V1a sticks, THEORY §6) it is exactly the
/// incoming tangential kinetic energy ½ m (V sin α)².
#[test]
fn friction_dissipates_the_tangential_kinetic_energy() {
    let v1 = V1::reference(20.0);
    let e0 = 0.5 * v1.mass * v1.speed * v1.speed;
    let analytic_loss = 0.5 * v1.mass * (v1.speed * v1.alpha.sin()).powi(2);
    for (label, method) in methods() {
        let r = run(&v1, method);
        let dissipated = r.energy.tangential;
        assert!(dissipated > 0.0, "{label}: dissipated {dissipated}");
        let last = r.recorder.len() - 1;
        assert_eq!(
            r.recorder.status[[last, 0]],
            0,
            "{label}: still in contact at the end"
        );
        let ke = final_kinetic_energy(&r);
        let balance = (ke - (e0 - dissipated)).abs();
        assert!(
            balance <= r.energy.relative_error * e0 + 1e-15,
            "{label}: final KE {ke}, E0 − D = {}, reported balance error {:e} (relative)",
            e0 - dissipated,
            r.energy.relative_error
        );
        assert!(
            r.energy.relative_error < 1e-6,
            "{label}: {:e}",
            r.energy.relative_error
        );
        assert!(
            (dissipated - analytic_loss).abs() <= 1e-4 * analytic_loss,
            "{label}: dissipated {dissipated} J, analytic ½ m v_t² = {analytic_loss} J"
        );
        // wear work ∫|R_T·v_T| dt equals the dissipation (R_T opposes v_T throughout)
        let wear = r.contacts[0].wear_work;
        assert!(
            (wear - dissipated).abs() <= 1e-4 * analytic_loss,
            "{label}: wear work {wear} J vs dissipated {dissipated} J"
        );
    }
}

/// m → 4m with K_N → 4 K_N keeps ω: the motion is the same and every force is 4 times
/// larger (penalty: K_T and C_T scaled too).
#[test]
fn mass_and_stiffness_scaling_scales_forces_only() {
    let base = V1::reference(20.0);
    let heavy = V1 {
        mass: 4.0,
        stiffness: 4e6,
        ..base.clone()
    };
    for (label, method) in methods() {
        let scaled = match method {
            TangentialMethod::Penalty(p) => TangentialMethod::Penalty(PenaltySettings {
                stiffness: 4.0 * p.stiffness,
                damping: 4.0 * p.damping,
            }),
            m => m,
        };
        let a = run(&base, method);
        let b = run(&heavy, scaled);
        let (ra, rb) = (&a.recorder, &b.recorder);
        assert_eq!(ra.len(), rb.len());
        let fscale = base.peak_normal_force();
        for i in 0..ra.len() {
            assert_eq!(
                ra.status[[i, 0]],
                rb.status[[i, 0]],
                "{label}: status at {}",
                ra.t[i]
            );
            let va = velocity(&base, &a, i);
            let vb = velocity(&heavy, &b, i);
            assert!(
                (va - vb).norm() <= 1e-9 * base.speed,
                "{label}: velocity at t = {}: {va:?} vs {vb:?}",
                ra.t[i]
            );
            let dn = (4.0 * ra.normal_force[[i, 0]] - rb.normal_force[[i, 0]]).abs();
            assert!(
                dn <= 4e-9 * fscale,
                "{label}: R_N at {} off by {dn:e}",
                ra.t[i]
            );
            for k in 0..2 {
                let fa = ra.tangential_force[[i, 0, k]];
                let fb = rb.tangential_force[[i, 0, k]];
                assert!(
                    (4.0 * fa - fb).abs() <= 4e-9 * fscale,
                    "{label}: R_T[{k}] at {}: 4 × {fa} vs {fb}",
                    ra.t[i]
                );
            }
        }
        assert!(
            (4.0 * a.energy.tangential - b.energy.tangential).abs() <= 1e-9 * b.energy.tangential,
            "{label}: dissipated {} vs {}",
            a.energy.tangential,
            b.energy.tangential
        );
    }
}
