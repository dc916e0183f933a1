//! The obstacles of THEORY §3 beyond the plane: a drilled hole (point–circle) and a pair of
//! flat bars (bi-plane), against analytic solutions and an equivalent model.

use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::obstacle::{BiPlane, Circle, Obstacle, Plane, Polygon};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{RunSettings, simulate};
use fretdyn::model::Model;
use fretdyn::structure::modal::ModalBasis;
use nalgebra::{Vector2, Vector3};

fn settings(method: TangentialMethod, dt: f64, steps: u64, every: u64) -> RunSettings {
    RunSettings {
        dt,
        steps,
        method,
        stick_velocity: StickVelocity::HalfStep,
        output_every: every,
        monitors: Vec::new(),
        statistics: Default::default(),
    }
}

/// A mass sliding round the inside of a hole of radius R (no other force): the wall holds it
/// on the circle with `N = m v²/R`, friction slows it, `m dv/dt = −μ N`, so
/// `v(t) = v₀ / (1 + μ v₀ t / R)`. The contact stays closed and slides all the time; its
/// tangential velocity is circumferential, and the friction force opposes it.
#[test]
fn mass_sliding_round_a_hole_slows_down_as_coulomb_says() {
    let (m, r, v0, mu, kn) = (1.0, 0.1, 1.0, 0.1, 1e8);
    // start at the equilibrium penetration m v0²/(R K_N), moving along the circumference
    let delta = m * v0 * v0 / (r * kn);
    let mut model = Model::new(ModalBasis::point_mass(m, "mass", Vector3::zeros()).unwrap());
    model.contacts.push(Contact::new(
        "hole",
        0,
        Obstacle::Circle(Circle::new(Vector3::zeros(), Vector3::z(), r, "hole").unwrap()),
        NormalLaw::new(kn, 2.0 * (kn * m).sqrt(), "n").unwrap(),
        Coulomb::new(mu, mu, "f").unwrap(),
    ));
    model.initial.q = vec![(r + delta) * m.sqrt(), 0.0, 0.0];
    model.initial.qdot = vec![0.0, v0 * m.sqrt(), 0.0];
    let (dt, duration) = (2e-6, 0.5);
    let steps = (duration / dt) as u64;
    for method in [
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e6,
            damping: 100.0,
        }),
    ] {
        let res = simulate(&model, &settings(method, dt, steps, 1000)).unwrap();
        let rec = &res.recorder;
        let mut worst = 0.0f64;
        for i in 1..rec.len() {
            let t = rec.t[i];
            let v = (rec.qdot[[i, 0]].powi(2) + rec.qdot[[i, 1]].powi(2)).sqrt() / m.sqrt();
            let exact = v0 / (1.0 + mu * v0 * t / r);
            worst = worst.max((v - exact).abs() / exact);
            assert_eq!(
                rec.status[[i, 0]],
                2,
                "{}: slides all the time",
                method.name()
            );
            // friction opposes the (circumferential) slip
            let (ft, vt) = (
                rec.tangential_force[[i, 0, 0]],
                rec.slip_velocity[[i, 0, 0]],
            );
            assert!(ft * vt < 0.0 && rec.slip_velocity[[i, 0, 1]].abs() < 1e-9 * v0);
        }
        assert!(worst < 2e-4, "{}: speed off by {worst:e}", method.name());
        let c = &res.contacts[0];
        assert_eq!(c.impacts, 1);
        // the wear work is the kinetic energy lost
        let v_end = v0 / (1.0 + mu * v0 * duration / r);
        let lost = 0.5 * m * (v0 * v0 - v_end * v_end);
        assert!(
            (c.wear_work - lost).abs() < 1e-3 * lost,
            "{}: {} vs {lost}",
            method.name(),
            c.wear_work
        );
    }
}

/// A bi-plane is the pair of planes it stands for: a mass bouncing between two bars at ±g
/// with a sliding velocity moves exactly as with two plane contacts.
#[test]
fn bi_plane_equals_two_planes() {
    let g = 1e-3;
    let base = || {
        let mut m = Model::new(ModalBasis::point_mass(1.0, "mass", Vector3::zeros()).unwrap());
        m.initial.qdot = vec![0.3, 0.8, 0.1];
        m
    };
    let law = NormalLaw::new(1e6, 0.0, "n").unwrap();
    let friction = Coulomb::new(0.3, 0.25, "f").unwrap();
    let contact = |name: &str, obstacle| Contact::new(name, 0, obstacle, law, friction);
    let mut bars = base();
    bars.contacts.push(contact(
        "bars",
        Obstacle::BiPlane(
            BiPlane::new(Vector3::zeros(), Vector3::y(), g, Some(Vector3::x()), "b").unwrap(),
        ),
    ));
    let mut planes = base();
    for (name, n) in [("below", Vector3::y()), ("above", -Vector3::y())] {
        planes.contacts.push(contact(
            name,
            Obstacle::Plane(Plane::new(Vector3::zeros(), n, g, Some(Vector3::x()), "p").unwrap()),
        ));
    }
    for method in [
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e6,
            damping: 10.0,
        }),
    ] {
        let s = settings(method, 1e-6, 30_000, 1);
        let a = simulate(&bars, &s).unwrap();
        let b = simulate(&planes, &s).unwrap();
        assert!(a.contacts[0].impacts >= 4, "{:?}", a.contacts[0]);
        assert_eq!(
            a.contacts[0].impacts,
            b.contacts[0].impacts + b.contacts[1].impacts
        );
        for i in 0..a.recorder.len() {
            for k in 0..3 {
                let (x, y) = (a.recorder.q[[i, k]], b.recorder.q[[i, k]]);
                assert!(
                    (x - y).abs() <= 1e-12,
                    "{}: step {i}: {x} vs {y}",
                    method.name()
                );
            }
            let rn = b.recorder.normal_force[[i, 0]] + b.recorder.normal_force[[i, 1]];
            assert!((a.recorder.normal_force[[i, 0]] - rn).abs() <= 1e-9);
        }
        let w = a.contacts[0].wear_work;
        let wb = b.contacts[0].wear_work + b.contacts[1].wear_work;
        assert!((w - wb).abs() <= 1e-9 * w, "{w} vs {wb}");
    }
}

#[test]
fn obstacle_input_errors() {
    assert!(
        Circle::new(Vector3::zeros(), Vector3::zeros(), 1e-4, "c")
            .unwrap_err()
            .to_string()
            .contains("c.axis")
    );
    assert!(
        Circle::new(Vector3::zeros(), Vector3::z(), -1e-4, "c")
            .unwrap_err()
            .to_string()
            .contains("c.clearance")
    );
    assert!(
        BiPlane::new(Vector3::zeros(), Vector3::y(), f64::NAN, None, "b")
            .unwrap_err()
            .to_string()
            .contains("b.gap")
    );
}

/// Redundant constraints (THEORY §4.6): a mass pressed on two coincident planes, each of
/// stiffness K_N, is the same mass on one plane of stiffness 2 K_N — the friction disks add up
/// — although H is singular at every closed step. Every method runs to the end with bounded
/// forces; the Lagrange methods give the single plane's motion and count the singular steps.
#[test]
fn two_coincident_planes_are_one_plane_of_double_stiffness() {
    use fretdyn::integrator::simulation::Termination;
    use fretdyn::loads::{PointLoad, TimeHistory};
    let model = |planes: &[(f64, &str)]| {
        let mut m = Model::new(ModalBasis::point_mass(1.0, "mass", Vector3::zeros()).unwrap());
        for (kn, name) in planes {
            m.contacts.push(Contact::new(
                *name,
                0,
                Obstacle::Plane(
                    Plane::new(Vector3::zeros(), Vector3::z(), 0.0, Some(Vector3::x()), "p")
                        .unwrap(),
                ),
                NormalLaw::new(*kn, 0.0, "n").unwrap(),
                Coulomb::new(0.3, 0.3, "f").unwrap(),
            ));
        }
        // pressed down by 50 N, pushed sideways by 20 N at 5 Hz: friction capacity 15 N,
        // so it sticks and slips in turn
        m.loads.push(
            PointLoad::new(0, Vector3::new(0.0, 0.0, -50.0), TimeHistory::Constant, "g").unwrap(),
        );
        m.loads.push(
            PointLoad::new(
                0,
                Vector3::new(20.0, 5.0, 0.0),
                TimeHistory::Harmonic {
                    frequency_hz: 5.0,
                    phase: 0.0,
                },
                "push",
            )
            .unwrap(),
        );
        m.initial.qdot = vec![0.2, 0.1, 0.0];
        m
    };
    let double = model(&[(1e6, "a"), (1e6, "b")]);
    let single = model(&[(2e6, "ab")]);
    for method in [
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e6,
            damping: 100.0,
        }),
    ] {
        let s = settings(method, 1e-5, 40_000, 10);
        let a = simulate(&double, &s).unwrap();
        assert_eq!(a.termination, Termination::Completed, "{}", method.name());
        let rec = &a.recorder;
        assert!(
            rec.tangential_force
                .iter()
                .all(|f| f.is_finite() && f.abs() < 100.0)
        );
        assert!(rec.normal_force.iter().all(|f| f.is_finite() && *f < 200.0));
        if !method.is_lagrange() {
            continue;
        }
        assert!(
            a.solver.singular_delassus > 1000,
            "{}: {:?}",
            method.name(),
            a.solver
        );
        let statuses: Vec<i8> = rec.status.column(0).to_vec();
        assert!(
            statuses.contains(&1) && statuses.contains(&2),
            "sticks and slips"
        );
        let b = simulate(&single, &s).unwrap();
        assert_eq!(b.solver.singular_delassus, 0);
        let scale = b.recorder.q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..rec.len() {
            for k in 0..3 {
                let d = (rec.q[[i, k]] - b.recorder.q[[i, k]]).abs();
                assert!(d <= 1e-9 * scale, "{}: sample {i}: {d:e}", method.name());
            }
            for j in 0..2 {
                let sum = rec.tangential_force[[i, 0, j]] + rec.tangential_force[[i, 1, j]];
                let d = (sum - b.recorder.tangential_force[[i, 0, j]]).abs();
                assert!(
                    d <= 1e-6,
                    "{}: sample {i}: friction {sum} vs {}",
                    method.name(),
                    b.recorder.tangential_force[[i, 0, j]]
                );
            }
        }
    }
}

/// A flat land of a polygonal hole is a plane: a mass thrown obliquely (circumferential and
/// axial velocity) at the land x = g of a square hole moves exactly as against the plane
/// x = g — same forces, same trajectory — because on a land the polygon's frame is the
/// plane's (THEORY §3).
#[test]
fn flat_land_of_a_polygonal_hole_is_a_plane() {
    let g = 2e-4;
    let model = |obstacle: Obstacle| {
        let mut m = Model::new(ModalBasis::point_mass(1.0, "mass", Vector3::zeros()).unwrap());
        m.contacts.push(Contact::new(
            "c",
            0,
            obstacle,
            NormalLaw::new(1e6, 0.0, "n").unwrap(),
            Coulomb::new(0.3, 0.3, "f").unwrap(),
        ));
        m.initial.qdot = vec![0.5, 0.1, 0.2];
        m
    };
    let square = Polygon::new(
        Vector3::zeros(),
        Vector3::z(),
        Some(Vector3::x()),
        vec![
            Vector2::new(g, -g),
            Vector2::new(g, g),
            Vector2::new(-g, g),
            Vector2::new(-g, -g),
        ],
        "square",
    )
    .unwrap();
    // the polygon's tangents on that land are [n × a, a] = [y, z]
    let plane = Plane::new(Vector3::zeros(), -Vector3::x(), g, Some(Vector3::y()), "p").unwrap();
    assert_eq!(plane.tangents()[1], -Vector3::z());
    let a = model(Obstacle::Polygon(square));
    let b = model(Obstacle::Plane(plane));
    for method in [
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
    ] {
        let ra = simulate(&a, &settings(method, 1e-6, 3000, 1)).unwrap();
        let rb = simulate(&b, &settings(method, 1e-6, 3000, 1)).unwrap();
        assert_eq!(ra.contacts[0].impacts, 1);
        let (x, y) = (&ra.recorder, &rb.recorder);
        assert!(x.status.iter().any(|s| *s == 1) && x.status.iter().any(|s| *s == 2));
        // equal but for round-off (the polygon projects on its edge, the plane takes a dot)
        let close = |u: f64, v: f64, scale: f64| (u - v).abs() <= 1e-12 * scale;
        for (u, v) in x.q.iter().zip(&y.q) {
            assert!(close(*u, *v, g), "{}: q {u} vs {v}", method.name());
        }
        let peak = x.normal_force.iter().fold(0.0f64, |a, f| a.max(*f));
        for i in 0..x.len() {
            assert!(close(x.normal_force[[i, 0]], y.normal_force[[i, 0]], peak));
            let (xt, yt) = (&x.tangential_force, &y.tangential_force);
            assert!(close(xt[[i, 0, 0]], yt[[i, 0, 0]], peak));
            assert!(close(xt[[i, 0, 1]], -yt[[i, 0, 1]], peak));
        }
    }
}

/// A regular polygon of many sides is nearly a circle: the mass sliding round the inside of
/// an N-gon given by (angle, radius) pairs slows down as in the drilled hole of the same
/// radius (analytic `v₀/(1 + μ v₀ t/R)`, see the first test) but for the bumps at the
/// corners, which shrink as N grows: measured 0.66 % slower at N = 720, under 0.1 % at 2880.
#[test]
fn many_sided_polygon_hole_tends_to_the_drilled_hole() {
    let (m, r, v0, mu, kn) = (1.0f64, 0.1, 1.0, 0.1, 1e8);
    let speed_error = |sides: usize| {
        let pairs: Vec<(f64, f64)> = (0..sides)
            .map(|k| (std::f64::consts::TAU * k as f64 / sides as f64, r))
            .collect();
        let hole = Polygon::new(
            Vector3::zeros(),
            Vector3::z(),
            Some(Vector3::x()),
            Polygon::polar(&pairs),
            "hole",
        )
        .unwrap();
        let mut model = Model::new(ModalBasis::point_mass(m, "mass", Vector3::zeros()).unwrap());
        model.contacts.push(Contact::new(
            "hole",
            0,
            Obstacle::Polygon(hole),
            NormalLaw::new(kn, 0.0, "n").unwrap(),
            Coulomb::new(mu, mu, "f").unwrap(),
        ));
        let delta = m * v0 * v0 / (r * kn);
        model.initial.q = vec![(r + delta) * m.sqrt(), 0.0, 0.0];
        model.initial.qdot = vec![0.0, v0 * m.sqrt(), 0.0];
        let (dt, duration) = (2e-6, 0.5);
        let res = simulate(
            &model,
            &settings(
                TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
                dt,
                (duration / dt) as u64,
                1000,
            ),
        )
        .unwrap();
        let rec = &res.recorder;
        let i = rec.len() - 1;
        let v = (rec.qdot[[i, 0]].powi(2) + rec.qdot[[i, 1]].powi(2)).sqrt() / m.sqrt();
        let exact = v0 / (1.0 + mu * v0 * rec.t[i] / r);
        (v - exact).abs() / exact
    };
    let (coarse, fine) = (speed_error(720), speed_error(2880));
    assert!(coarse < 1e-2 && fine < 1e-3, "{coarse:e}, {fine:e}");
    assert!(fine < coarse / 3.0, "{coarse:e}, {fine:e}");
}

#[test]
fn polygonal_hole_refuses_a_centre_outside_and_too_few_vertices() {
    let v = |pts: &[(f64, f64)]| pts.iter().map(|p| Vector2::new(p.0, p.1)).collect();
    let outside = Polygon::new(
        Vector3::zeros(),
        Vector3::z(),
        None,
        v(&[(1.0, 1.0), (2.0, 1.0), (2.0, 2.0)]),
        "h",
    );
    assert!(outside.unwrap_err().to_string().contains("inside"));
    let two = Polygon::new(
        Vector3::zeros(),
        Vector3::z(),
        None,
        v(&[(1.0, 0.0), (-1.0, 0.0)]),
        "h",
    );
    assert!(two.unwrap_err().to_string().contains("at least 3"));
}
