//! Contacts on the tube surface (rotations in the slip velocity), obstacles that move, and a
//! base acceleration, against closed-form solutions and against each other (THEORY §3).

use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::motion::Motion;
use fretdyn::contact::obstacle::{Circle, Obstacle, Plane};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, TangentialMethod,
};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{RunResults, simulate};
use fretdyn::loads::{BaseAcceleration, PointLoad, TimeHistory};
use fretdyn::model::Model;
use fretdyn::structure::modal::{ModalBasis, Point};
use nalgebra::Vector3;
#[path = "common/every_step.rs"]
mod every_step;
use every_step::every_step as settings;

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

/// First sample index whose contact status is `status` from `from` on.
fn first_with_status(r: &RunResults, status: i8, from: usize) -> Option<usize> {
    (from..r.recorder.len()).find(|&i| r.recorder.status[[i, 0]] == status)
}

/// A rigid cylinder (mass m, polar inertia J, radius R) pressed on a plane by a force N and
/// spinning at ω₀ without translating: its surface slides at `R ω₀`. Friction `μN` slows the
/// spin (torque `μ N R`) and drags the centre the other way, so the slip speed falls as
/// `R ω₀ − μ N (1/m + R²/J) t` and the cylinder rolls without slipping from
/// `t* = R ω₀ / (μ N (1/m + R²/J))` on, with `v = −μ N t*/m`, `ω = ω₀ − μ N R t*/J`, and no
/// friction force. Only the rotation rows of the contact point (THEORY §1, "6 × p with
/// rotations") produce this: without `radius` nothing slides at all.
#[test]
fn spinning_cylinder_on_a_plane_rolls_when_friction_has_matched_spin_and_speed() {
    let (m, j, r, mu, n, kn, w0): (f64, f64, f64, f64, f64, f64, f64) =
        (2.0, 1e-4, 0.01, 0.3, 10.0, 1e6, 50.0);
    let s = 1.0 / m.sqrt();
    // modes: 3 translations and the spin about z, all rigid
    let point = Point {
        name: "axis".into(),
        coords: Vector3::zeros(),
        rows: vec![s, 0., 0., 0., 0., s, 0., 0., 0., 0., s, 0.],
        rotations: vec![0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 1.0 / j.sqrt()],
    };
    let basis = ModalBasis {
        omega: vec![0.0; 4],
        damping_ratio: vec![0.0; 4],
        points: vec![point],
        participation: Vec::new(),
    };
    let mut model = Model::new(basis);
    let mut contact = Contact::new(
        "floor",
        0,
        Obstacle::Plane(
            Plane::new(Vector3::zeros(), Vector3::y(), 0.0, Some(Vector3::x()), "p").unwrap(),
        ),
        NormalLaw::new(kn, 0.0, "n").unwrap(),
        Coulomb::new(mu, mu, "f").unwrap(),
    );
    contact.radius = r;
    model.contacts.push(contact);
    model
        .loads
        .push(PointLoad::new(0, Vector3::new(0.0, -n, 0.0), TimeHistory::Constant, "l").unwrap());
    // static penetration N/K_N: the normal force is N from the first step
    model.initial.q = vec![0.0, -n / kn / s, 0.0, 0.0];
    model.initial.qdot = vec![0.0, 0.0, 0.0, w0 * j.sqrt()];
    let f = mu * n;
    let t_star = r * w0 / (f * (1.0 / m + r * r / j));
    let (v_end, w_end) = (-f * t_star / m, w0 - f * r * t_star / j);
    let dt = 1e-5;
    let steps = (1.5 * t_star / dt) as u64;
    for (label, method) in lagrange_methods() {
        let res = simulate(&model, &settings(method, dt, steps)).unwrap();
        let rec = &res.recorder;
        let stick = first_with_status(&res, 1, 1).expect("rolling starts");
        assert!(
            (rec.t[stick] - t_star).abs() <= 2.0 * dt,
            "{label}: rolling from {} s, expected {t_star} s",
            rec.t[stick]
        );
        let peak = n;
        for i in 1..stick {
            let rt = (rec.tangential_force[[i, 0, 0]].powi(2)
                + rec.tangential_force[[i, 0, 1]].powi(2))
            .sqrt();
            assert!(
                (rt - mu * rec.normal_force[[i, 0]]).abs() <= 1e-9 * peak,
                "{label}: sliding force {rt} at sample {i}"
            );
            // the friction force opposes the slip (+x)
            assert!(rec.tangential_force[[i, 0, 0]] < 0.0, "{label}");
        }
        let last = rec.len() - 1;
        for i in stick + 2..=last {
            assert!(
                rec.tangential_force[[i, 0, 0]].abs() <= 1e-9 * peak,
                "{label}: rolling needs no friction, got {} at {i}",
                rec.tangential_force[[i, 0, 0]]
            );
            assert!(rec.slip_velocity[[i, 0, 0]].abs() <= 1e-9, "{label}");
        }
        let v = rec.qdot[[last, 0]] * s;
        let w = rec.qdot[[last, 3]] / j.sqrt();
        // the discrete stick time is within a step of t*: the end state within f Δt / m
        assert!(
            (v - v_end).abs() <= f * dt / m,
            "{label}: v = {v}, expected {v_end}"
        );
        assert!(
            (w - w_end).abs() <= f * r * dt / j,
            "{label}: ω = {w}, expected {w_end}"
        );
        assert!((v + r * w).abs() <= 1e-9, "{label}: rolls without slip");
    }
    // the penalty law rolls too, after a micro-slip bounded by μN/K_T
    let kt = 1e6;
    let res = simulate(
        &model,
        &settings(
            TangentialMethod::Penalty(PenaltySettings {
                stiffness: kt,
                damping: 0.0,
            }),
            dt,
            steps,
        ),
    )
    .unwrap();
    let stick = first_with_status(&res, 1, 1).expect("penalty sticks");
    assert!((res.recorder.t[stick] - t_star).abs() <= 2.0 * dt);
    let last = res.recorder.len() - 1;
    let v = res.recorder.qdot[[last, 0]] * s;
    assert!((v - v_end).abs() <= 1e-3 * v_end.abs(), "penalty: v = {v}");
}

/// A mass m (on `basis`) pressed with N on the wall of a hole (axis x, clearance g,
/// K_N = 1e6 N/m) whose plate moves along x at V, starting on the wall at the static
/// penetration.
struct HoleCase {
    mu_s: f64,
    mu_d: f64,
    n: f64,
    v_plate: f64,
}

impl HoleCase {
    fn model(&self, basis: ModalBasis, m: f64) -> Model {
        let (g, kn) = (2e-4, 1e6);
        let mut model = Model::new(basis);
        let mut hole = Contact::new(
            "plate",
            0,
            Obstacle::Circle(Circle::new(Vector3::zeros(), Vector3::x(), g, "hole").unwrap()),
            NormalLaw::new(kn, 0.0, "n").unwrap(),
            Coulomb::new(self.mu_s, self.mu_d, "f").unwrap(),
        );
        hole.motion = Motion::Velocity(Vector3::new(self.v_plate, 0.0, 0.0));
        model.contacts.push(hole);
        model.loads.push(
            PointLoad::new(
                0,
                Vector3::new(0.0, self.n, 0.0),
                TimeHistory::Constant,
                "l",
            )
            .unwrap(),
        );
        model.initial.q = vec![0.0, (g + self.n / kn) * m.sqrt(), 0.0];
        model
    }
}

/// A mass pressed (force N) on the wall of a hole whose plate moves along the hole's axis at
/// speed V, the mass at rest: it slides with `|R_T| = μ_d R_N` dragged along the axis,
/// accelerates at `μ_d N/m` and sticks at `t* = m V/(μ_d N)`, after which it follows the plate
/// at V exactly (the stick constraint acts on the velocity relative to the obstacle).
#[test]
fn mass_in_a_moving_hole_slides_then_sticks_and_follows_the_plate() {
    let (m, mu_d, n, v_plate) = (1.0f64, 0.3, 10.0, 0.05);
    let s = 1.0 / m.sqrt();
    let case = HoleCase {
        mu_s: 0.4,
        mu_d,
        n,
        v_plate,
    };
    let model = case.model(
        ModalBasis::point_mass(m, "tube", Vector3::zeros()).unwrap(),
        m,
    );
    let t_star = m * v_plate / (mu_d * n);
    let dt = 1e-5;
    let steps = (2.0 * t_star / dt) as u64;
    for (label, method) in lagrange_methods() {
        let res = simulate(&model, &settings(method, dt, steps)).unwrap();
        let rec = &res.recorder;
        let stick = first_with_status(&res, 1, 1).expect("sticks");
        assert!(
            (rec.t[stick] - t_star).abs() <= 2.0 * dt,
            "{label}: sticks at {} s, expected {t_star} s",
            rec.t[stick]
        );
        for i in 1..stick {
            assert_eq!(rec.status[[i, 0]], 2, "{label}: slides before t*");
            // tangents of the hole: [circumferential, axial]; the plate drags the mass along +x
            let rt = rec.tangential_force[[i, 0, 1]];
            assert!(
                (rt - mu_d * rec.normal_force[[i, 0]]).abs() <= 1e-9 * n,
                "{label}: axial force {rt} at {i}"
            );
            assert!(rec.tangential_force[[i, 0, 0]].abs() <= 1e-9 * n);
        }
        for i in stick + 2..rec.len() {
            let x = rec.q[[i, 0]] * s;
            let v = rec.qdot[[i, 0]] * s;
            assert!((v - v_plate).abs() <= 1e-9, "{label}: follows at {v} m/s");
            // from t*, the mass moves with the plate: x − V t is constant
            let offset0 = rec.q[[stick + 1, 0]] * s - v_plate * rec.t[stick + 1];
            assert!((x - v_plate * rec.t[i] - offset0).abs() <= 1e-12);
            assert!(rec.tangential_force[[i, 0, 1]].abs() <= 1e-9 * n);
        }
    }
}

/// A mass held axially by a spring k, pressed on the wall of a hole whose plate moves slowly
/// at V, the mass moving with it: it sticks and follows the plate while the spring force
/// `k V t` stays below `μ_s N`, i.e. until `t_s = μ_s N/(k V)`, then slides with
/// `|R_T| = μ_d R_N`.
#[test]
fn spring_held_mass_follows_a_slow_plate_until_static_friction_is_exceeded() {
    let (m, k, mu_s, mu_d, n, v_plate) = (1.0f64, 400.0, 0.4, 0.3, 10.0, 1e-2);
    let s = 1.0 / m.sqrt();
    let mut basis = ModalBasis::point_mass(m, "tube", Vector3::zeros()).unwrap();
    basis.omega[0] = (k / m).sqrt();
    let case = HoleCase {
        mu_s,
        mu_d,
        n,
        v_plate,
    };
    let mut model = case.model(basis, m);
    model.initial.qdot = vec![v_plate / s, 0.0, 0.0];
    let t_slip = mu_s * n / (k * v_plate);
    let dt = 1e-5;
    let steps = (1.2 * t_slip / dt) as u64;
    for (label, method) in lagrange_methods() {
        let res = simulate(&model, &settings(method, dt, steps)).unwrap();
        let rec = &res.recorder;
        let slip = first_with_status(&res, 2, 1).expect("slides at last");
        assert!(
            (rec.t[slip] - t_slip).abs() <= 2.0 * dt,
            "{label}: slides from {} s, expected {t_slip} s",
            rec.t[slip]
        );
        for i in 1..slip {
            let x = rec.q[[i, 0]] * s;
            assert!(
                (x - v_plate * rec.t[i]).abs() <= 1e-12,
                "{label}: follows the plate"
            );
            // the friction force holds the spring: R_T = k x
            let rt = rec.tangential_force[[i, 0, 1]];
            assert!((rt - k * x).abs() <= 1e-6 * n, "{label}: {rt} vs {}", k * x);
        }
        let end = (slip..rec.len())
            .find(|&i| rec.status[[i, 0]] != 2)
            .unwrap_or(rec.len());
        assert!(end > slip + 10, "{label}: slides for a while");
        for i in slip..end {
            let rt = rec.tangential_force[[i, 0, 1]].abs();
            assert!(
                (rt - mu_d * rec.normal_force[[i, 0]]).abs() <= 1e-9 * n,
                "{label}"
            );
        }
    }
}

/// A base acceleration with obstacles fixed to the base is the same problem, seen from the
/// base, as obstacles that move with the base: a free mass bouncing with friction on a plate
/// that vibrates as `d = A sin ωt` (absolute coordinates, moving obstacle) and the same mass
/// loaded by the base acceleration `−Aω² sin ωt` in front of a fixed plate (coordinates
/// relative to the base) are one problem, discretised differently: the first integrates the
/// plate's position exactly, the second its acceleration by central differences. Their
/// relative displacements must agree to second order in Δt and their contact forces to first
/// order (at a stick onset the force is an impulse over one step), with the same impacts.
#[test]
fn base_acceleration_equals_obstacle_moving_with_the_base() {
    let (m, mu, kn, w): (f64, f64, f64, f64) = (1.0, 0.3, 1e5, 2.0 * std::f64::consts::PI * 20.0);
    let amp = Vector3::new(0.5e-3, 0.0, 1e-3);
    let s = 1.0 / m.sqrt();
    let contact = || {
        Contact::new(
            "plate",
            0,
            Obstacle::Plane(
                Plane::new(
                    Vector3::zeros(),
                    Vector3::z(),
                    1e-4,
                    Some(Vector3::x()),
                    "p",
                )
                .unwrap(),
            ),
            NormalLaw::new(kn, 0.0, "n").unwrap(),
            Coulomb::new(mu, mu, "f").unwrap(),
        )
    };
    let weight = PointLoad::new(
        0,
        Vector3::new(0.0, 0.0, -9.81 * m),
        TimeHistory::Constant,
        "g",
    )
    .unwrap();
    let history = TimeHistory::Harmonic {
        frequency_hz: w / std::f64::consts::TAU,
        phase: 0.0,
    };
    // (a) absolute coordinates: the plate moves; the mass starts with its velocity A ω
    let mut moving = Model::new(ModalBasis::point_mass(m, "mass", Vector3::zeros()).unwrap());
    let mut c = contact();
    c.motion = Motion::Harmonic {
        amplitude: amp,
        frequency_hz: w / std::f64::consts::TAU,
        phase: 0.0,
    };
    moving.contacts.push(c);
    moving.loads.push(weight.clone());
    moving.initial.qdot = (amp * w / s).iter().copied().collect();
    // (b) relative to the base: fixed plate, inertia load −m a(t)
    let mut relative = Model::new(ModalBasis::point_mass(m, "mass", Vector3::zeros()).unwrap());
    relative.contacts.push(contact());
    relative.loads.push(weight);
    relative.base_acceleration =
        Some(BaseAcceleration::new(-amp * w * w, history, "base").unwrap());
    for (label, method) in lagrange_methods() {
        // differences (force, displacement) at Δt and Δt/2
        let mut diffs = Vec::new();
        for dt in [1e-5, 5e-6] {
            let steps = (0.2 / dt) as u64;
            let a = simulate(&moving, &settings(method, dt, steps)).unwrap();
            let b = simulate(&relative, &settings(method, dt, steps)).unwrap();
            let (ra, rb) = (&a.recorder, &b.recorder);
            let peak = ra.normal_force.iter().fold(0.0f64, |x, y| x.max(*y));
            assert!(
                peak > 5.0 * 9.81 * m,
                "{label}: the mass hammers the plate ({peak} N)"
            );
            assert!(a.contacts[0].impacts >= 3, "{label}");
            assert_eq!(a.contacts[0].impacts, b.contacts[0].impacts, "{label}");
            let (mut force, mut displacement) = (0.0f64, 0.0f64);
            for i in 0..ra.len() {
                force = force.max((ra.normal_force[[i, 0]] - rb.normal_force[[i, 0]]).abs());
                for d in 0..2 {
                    force = force.max(
                        (ra.tangential_force[[i, 0, d]] - rb.tangential_force[[i, 0, d]]).abs(),
                    );
                }
                for d in 0..3 {
                    let rel = ra.q[[i, d]] * s - amp[d] * (w * ra.t[i]).sin();
                    displacement = displacement.max((rel - rb.q[[i, d]] * s).abs());
                }
            }
            diffs.push((force / peak, displacement / amp.norm()));
        }
        let [(f1, x1), (f2, x2)] = [diffs[0], diffs[1]];
        assert!(f1 < 1e-2 && x1 < 1e-3, "{label}: {diffs:?}");
        assert!(
            x1 / x2 > 3.5,
            "{label}: displacements converge at order 2: {diffs:?}"
        );
        assert!(
            f1 / f2 > 1.8,
            "{label}: forces converge at order 1: {diffs:?}"
        );
    }
}

/// Undamped spring–mass under a constant base acceleration a₀ from rest: the displacement
/// relative to the base is `−a₀/ω² (1 − cos ωt)` (the participation factor of a point mass is
/// `√m`).
#[test]
fn spring_mass_under_constant_base_acceleration_matches_closed_form() {
    let (m, f, a0): (f64, f64, f64) = (3.0, 5.0, 2.0);
    let w = std::f64::consts::TAU * f;
    let mut basis = ModalBasis::point_mass(m, "mass", Vector3::zeros()).unwrap();
    basis.omega[1] = w;
    let mut model = Model::new(basis);
    model.base_acceleration = Some(
        BaseAcceleration::new(Vector3::new(0.0, a0, 0.0), TimeHistory::Constant, "b").unwrap(),
    );
    let dt = 1e-5;
    let res = simulate(
        &model,
        &settings(
            TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
            dt,
            40_000,
        ),
    )
    .unwrap();
    let amp = a0 / (w * w);
    let rec = &res.recorder;
    let mut worst = 0.0f64;
    for i in 0..rec.len() {
        let y = rec.q[[i, 1]] / m.sqrt();
        worst = worst.max((y + amp * (1.0 - (w * rec.t[i]).cos())).abs());
    }
    // central differences: phase error (ω Δt)²/24 per radian, ~1e-7 over 2 periods
    assert!(
        worst <= 1e-6 * amp,
        "worst error {worst} m for amplitude {amp} m"
    );
    assert!(rec.q.column(0).iter().all(|x| *x == 0.0));
}
