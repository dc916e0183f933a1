//! Contacts whose Delassus block `H_ii` is singular (issue 3.1, THEORY §4.4, §4.6): no mode
//! can move the contact point along a tangent direction `d`, so the friction force along `d`
//! does no work on the structure and the stick condition `v_T = v_imp` cannot be met along
//! `d` when the obstacle moves along it (`c·d ≠ 0`): the contact slides at the Coulomb bound,
//! whatever the Lagrange method. Checked against the closed form, and against the penalty law.
//!
//! The structure: a point mass `m` whose two modes move it along `x` and `z` only (its `y`
//! row is zero), pressed with `N` on a plane of normal `z` (tangents `x`, `y`) from its static
//! penetration `N/K_N`, so that `R_N = N` exactly at every step.
//!
//! 1. The plane moves along `y` at `V`: the mass cannot follow; the friction force is
//!    `μ_d N` along `+y` (it drags the mass the way the plane goes), the slip velocity is
//!    `−V` along `y`, the wear work rate `μ_d N V`.
//! 2. The plane moves along `x` at `V`, the mass moving with it and held by a spring `k`
//!    along `x`: `c·d = 0` (nothing moves along `y`) and the contact sticks exactly (zero
//!    slip, zero wear), its force `k V t` along `x` and exactly 0 along `y` (the minimum-norm
//!    multiplier), until `k V t` reaches `μ_s N`.
//! 3. A zero block (a mass that only moves along the normal): it sticks with no force while
//!    the plane is at rest, and slides at `μ_d N` as soon as the plane moves (the Active Set
//!    starts that step from a stick, which its stick solve must refuse).

use fretdyn::accumulate::statistics::StatisticsSettings;
use fretdyn::contact::friction::{Coulomb, LocalSolve};
use fretdyn::contact::motion::Motion;
use fretdyn::contact::obstacle::{Obstacle, Plane};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{RunSettings, simulate};
use fretdyn::loads::{PointLoad, TimeHistory};
use fretdyn::model::Model;
use fretdyn::structure::modal::{ModalBasis, Point};
use nalgebra::Vector3;

const M: f64 = 2.0;
const KN: f64 = 1e6;
const N: f64 = 10.0;
const MU_S: f64 = 0.4;
const MU_D: f64 = 0.3;

/// The three Lagrange solvers: Active Set, Gauss–Seidel with the exact and the radial local
/// solve.
fn lagrange_methods() -> [(&'static str, TangentialMethod); 3] {
    [
        (
            "active_set",
            TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        ),
        (
            "gauss_seidel exact",
            TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        ),
        (
            "gauss_seidel radial",
            TangentialMethod::GaussSeidel(GaussSeidelSettings {
                local_solve: LocalSolve::Radial,
                ..GaussSeidelSettings::default()
            }),
        ),
    ]
}

fn settings(method: TangentialMethod, dt: f64, steps: u64, t_start: f64) -> RunSettings {
    RunSettings {
        dt,
        steps,
        method,
        stick_velocity: StickVelocity::HalfStep,
        output_every: 1,
        monitors: Vec::new(),
        statistics: StatisticsSettings {
            t_start,
            ..Default::default()
        },
    }
}

/// The mass (modes along x and z only; `omega_x` the frequency of a spring along x) pressed
/// with `N` on a plane of normal z that moves with `motion`, from its static penetration,
/// with the initial velocity `vx` along x.
fn pressed_mass(omega_x: f64, motion: Motion, vx: f64) -> Model {
    let s = 1.0 / M.sqrt();
    let point = Point {
        name: "mass".into(),
        coords: Vector3::zeros(),
        // rows x, y, z over the two modes: nothing moves the point along y
        rows: vec![s, 0.0, 0.0, 0.0, 0.0, s],
        rotations: Vec::new(),
    };
    let mut model = Model::new(ModalBasis {
        omega: vec![omega_x, 0.0],
        damping_ratio: vec![0.0; 2],
        points: vec![point],
        participation: Vec::new(),
    });
    let mut contact = Contact::new(
        "plane",
        0,
        Obstacle::Plane(
            Plane::new(Vector3::zeros(), Vector3::z(), 0.0, Some(Vector3::x()), "p").unwrap(),
        ),
        NormalLaw::new(KN, 0.0, "n").unwrap(),
        Coulomb::new(MU_S, MU_D, "f").unwrap(),
    );
    contact.motion = motion;
    model.contacts.push(contact);
    model
        .loads
        .push(PointLoad::new(0, Vector3::new(0.0, 0.0, -N), TimeHistory::Constant, "l").unwrap());
    // δ = −z = N/K_N: R_N = N, in equilibrium with the load
    model.initial.q = vec![0.0, -N / KN / s];
    model.initial.qdot = vec![vx / s, 0.0];
    model
}

/// Case 1: the plane slides along y, which no mode can follow: every Lagrange method slides at
/// `μ_d N` along the plane's motion from the first step, with the slip velocity `−V` and
/// the wear work rate `μ_d N V` (the penalty law, after its elastic stick of
/// `(μ_s N − C_T V)/(K_T V)`, gives the same).
#[test]
fn an_obstacle_moving_along_a_direction_no_mode_follows_drags_at_the_coulomb_bound() {
    let v = 0.02;
    let model = pressed_mass(0.0, Motion::Velocity(Vector3::new(0.0, v, 0.0)), 0.0);
    let dt = 1e-5;
    let steps = 10_000;
    let expected = MU_D * N * v;
    for (label, method) in lagrange_methods() {
        let r = simulate(&model, &settings(method, dt, steps, 0.0)).unwrap();
        let c = &r.contacts[0];
        assert!(
            (c.wear_work_rate - expected).abs() <= 1e-9 * expected,
            "{label}: wear work rate {} W, μ_d N V = {expected} W",
            c.wear_work_rate
        );
        assert_eq!(c.slip_time_fraction, 1.0, "{label}: slides all along");
        assert_eq!(c.contact_time_fraction, 1.0, "{label}");
        let rec = &r.recorder;
        for i in 1..rec.len() {
            assert!(
                (rec.normal_force[[i, 0]] - N).abs() <= 1e-9 * N,
                "{label}: R_N = {} at {i}",
                rec.normal_force[[i, 0]]
            );
            assert_eq!(rec.status[[i, 0]], 2, "{label}: slides at sample {i}");
            // the friction force on the mass drags it along +y, at the Coulomb bound
            let (rx, ry) = (
                rec.tangential_force[[i, 0, 0]],
                rec.tangential_force[[i, 0, 1]],
            );
            assert!(rx.abs() <= 1e-12 * N, "{label}: R_T,x = {rx} at {i}");
            assert!(
                (ry - MU_D * N).abs() <= 1e-9 * N,
                "{label}: R_T,y = {ry} at {i}, μ_d N = {}",
                MU_D * N
            );
            assert!(
                (rec.slip_velocity[[i, 0, 1]] + v).abs() <= 1e-12,
                "{label}: slip {} at {i}",
                rec.slip_velocity[[i, 0, 1]]
            );
        }
        // Coulomb's law holds: the step's natural-map residual is round-off
        assert!(
            r.solver.residual_max <= 1e-12,
            "{label}: residual {}",
            r.solver.residual_max
        );
        assert_eq!(r.solver.gs_nonconverged_steps, 0, "{label}");
        assert_eq!(r.solver.as_fallbacks, 0, "{label}");
    }
    // the penalty law: stick of (μ_s N − C_T V)/(K_T V), then μ_d N along +y
    let (kt, ct) = (1e5, 100.0);
    let t_stick = (MU_S * N - ct * v) / (kt * v);
    let t_start = 2.0 * t_stick;
    assert!(t_start < 0.5 * steps as f64 * dt);
    let penalty = TangentialMethod::Penalty(PenaltySettings {
        stiffness: kt,
        damping: ct,
    });
    let r = simulate(&model, &settings(penalty, dt, steps, t_start)).unwrap();
    let c = &r.contacts[0];
    assert!(
        (c.wear_work_rate - expected).abs() <= 1e-9 * expected,
        "penalty: wear work rate {} W, μ_d N V = {expected} W",
        c.wear_work_rate
    );
    assert_eq!(c.slip_time_fraction, 1.0, "penalty");
}

/// Case 2: the plane moves along x, which the modes follow, the mass with it, held by a spring:
/// nothing asks for a velocity along the singular direction y (`c·d = 0`), so the contact
/// sticks exactly — zero slip, zero wear — with the friction force `k x = k V t` along x (the
/// spring's) and exactly 0 along y, until `k V t_s = μ_s N`; then it slides at `μ_d N`.
#[test]
fn a_contact_with_a_singular_block_sticks_exactly_when_nothing_moves_along_its_null_direction() {
    let (k, v) = (400.0, 1e-2);
    let omega = (k / M).sqrt();
    let model = pressed_mass(omega, Motion::Velocity(Vector3::new(v, 0.0, 0.0)), v);
    let t_slip = MU_S * N / (k * v);
    let dt = 1e-5;
    let window = 0.9 * t_slip;
    let steps = (window / dt) as u64;
    for (label, method) in lagrange_methods() {
        let r = simulate(&model, &settings(method, dt, steps, 0.0)).unwrap();
        let c = &r.contacts[0];
        assert_eq!(
            c.wear_work_rate, 0.0,
            "{label}: a stuck contact wears nothing"
        );
        assert_eq!(c.stick_time_fraction, 1.0, "{label}");
        let rec = &r.recorder;
        for i in 1..rec.len() {
            assert_eq!(rec.status[[i, 0]], 1, "{label}: sticks at sample {i}");
            assert_eq!(rec.slip_velocity[[i, 0, 0]], 0.0, "{label}: no slip");
            assert_eq!(rec.slip_velocity[[i, 0, 1]], 0.0, "{label}: no slip");
            // the minimum-norm multiplier: nothing along the direction no mode moves
            assert_eq!(rec.tangential_force[[i, 0, 1]], 0.0, "{label} at {i}");
            // the spring's force, k x with x = V t: the mass follows the plane
            let x = rec.q[[i, 0]] / M.sqrt();
            assert!((x - v * rec.t[i]).abs() <= 1e-12, "{label}: x = {x}");
            let rx = rec.tangential_force[[i, 0, 0]];
            assert!(
                (rx - k * x).abs() <= 1e-6 * N,
                "{label}: R_T,x = {rx}, k x = {}",
                k * x
            );
        }
    }
}

/// Case 3, a zero block: the mass moves along the normal z only. While the plane is at rest the
/// contact sticks with no friction force; from `t_1` the plane slides along x at `V` (a table
/// motion) and the contact slides at `μ_d N` along +x, with the wear work rate `μ_d N V`:
/// nothing can follow the plane. The Active Set starts the first moving step from the stick
/// of the step before.
#[test]
fn a_zero_block_sticks_on_a_plane_at_rest_and_slides_as_soon_as_it_moves() {
    let (v, t1, t2) = (0.02, 0.02, 0.1);
    let s = 1.0 / M.sqrt();
    let point = Point {
        name: "mass".into(),
        coords: Vector3::zeros(),
        rows: vec![0.0, 0.0, s],
        rotations: Vec::new(),
    };
    let mut model = Model::new(ModalBasis {
        omega: vec![0.0],
        damping_ratio: vec![0.0],
        points: vec![point],
        participation: Vec::new(),
    });
    let mut contact = Contact::new(
        "plane",
        0,
        Obstacle::Plane(
            Plane::new(Vector3::zeros(), Vector3::z(), 0.0, Some(Vector3::x()), "p").unwrap(),
        ),
        NormalLaw::new(KN, 0.0, "n").unwrap(),
        Coulomb::new(MU_S, MU_D, "f").unwrap(),
    );
    contact.motion = Motion::Table {
        // moving on past the run's end
        times: vec![0.0, t1, 2.0 * t2],
        displacements: vec![
            Vector3::zeros(),
            Vector3::zeros(),
            Vector3::new(v * (2.0 * t2 - t1), 0.0, 0.0),
        ],
    };
    model.contacts.push(contact);
    model
        .loads
        .push(PointLoad::new(0, Vector3::new(0.0, 0.0, -N), TimeHistory::Constant, "l").unwrap());
    model.initial.q = vec![-N / KN / s];
    let dt = 1e-5;
    let steps = (t2 / dt).round() as u64;
    let expected = MU_D * N * v;
    for (label, method) in lagrange_methods() {
        // the window after t1 (and a step for the table's corner)
        let r = simulate(&model, &settings(method, dt, steps, t1 + 2.0 * dt)).unwrap();
        let c = &r.contacts[0];
        assert!(
            (c.wear_work_rate - expected).abs() <= 1e-9 * expected,
            "{label}: wear work rate {} W, μ_d N V = {expected} W",
            c.wear_work_rate
        );
        assert_eq!(c.slip_time_fraction, 1.0, "{label}");
        let rec = &r.recorder;
        for i in 1..rec.len() {
            let (rx, ry) = (
                rec.tangential_force[[i, 0, 0]],
                rec.tangential_force[[i, 0, 1]],
            );
            assert_eq!(ry, 0.0, "{label} at {i}");
            // the stick constraint of the step ending at t acts on the half step from t
            // to t + Δt: the plane moves during it from the step ending at t1 on
            if rec.t[i] < t1 - 0.5 * dt {
                assert_eq!(rec.status[[i, 0]], 1, "{label}: sticks at {}", rec.t[i]);
                assert_eq!(rx, 0.0, "{label}: no force at rest");
            } else {
                assert_eq!(rec.status[[i, 0]], 2, "{label}: slides at {}", rec.t[i]);
                assert!((rx - MU_D * N).abs() <= 1e-9 * N, "{label}: R_T,x = {rx}");
            }
        }
        assert!(
            r.solver.residual_max <= 1e-12,
            "{label}: {}",
            r.solver.residual_max
        );
        assert_eq!(r.solver.as_fallbacks, 0, "{label}");
        // the steps before the one ending at t1: no wear
        let before = (t1 / dt).round() as u64 - 1;
        let r = simulate(&model, &settings(method, dt, before, 0.0)).unwrap();
        assert_eq!(r.contacts[0].wear_work_rate, 0.0, "{label}");
        assert_eq!(r.contacts[0].stick_time_fraction, 1.0, "{label}");
    }
}
