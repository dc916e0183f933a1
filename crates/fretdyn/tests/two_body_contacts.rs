//! Two-body contacts (THEORY §15) at library level: a contact between a point of one structure
//! and a point of another is a contact on the relative point `x_A − x_B` whose force acts on
//! A and, opposite, on B. Checked here against identities that do not depend on how the
//! contact is coded:
//!
//! - **symmetry** (Code_Aster's node-to-node validation): a mass on a spring pushed onto a
//!   wall moves exactly as each of two identical masses pushed onto each other, for the
//!   penalty law and both Lagrange methods (Gauss–Seidel with both local solves), through
//!   impacts, stick and slip — to the bit;
//! - **momentum**: two free bodies of unequal masses colliding obliquely with friction keep
//!   `m_A v_A + m_B v_B` to round-off, their relative motion is that of the reduced mass on a
//!   wall (THEORY §6's analytic solution), and the energy balance closes;
//! - **stick**: pressed together and sheared below the static threshold, the Lagrange methods
//!   give no relative slip and no wear work at all; the penalty law a micro-slip.
//!
//! Bodies are point masses (`ModalBasis::point_mass`, rows `I/√m`, so `q̇ = √m v`), given
//! springs through their modal frequencies (`ω² = k/m`).

use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::obstacle::{Obstacle, Plane};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, LocalSolve, PenaltySettings, StickVelocity,
    TangentialMethod,
};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{RunResults, RunSettings, Simulation, Termination, simulate};
use fretdyn::integrator::stability::{impact_resolution, stable_time_step};
use fretdyn::loads::{PointLoad, TimeHistory};
use fretdyn::model::Model;
use fretdyn::structure::modal::ModalBasis;
use fretdyn::testing;
use nalgebra::Vector3;

// ---------------------------------------------------------------------------------------------
// Building blocks
// ---------------------------------------------------------------------------------------------

/// A point mass `m` at `x0`, on springs of circular frequencies `omega = [ω_x, ω_y, ω_z]`
/// (`k = m ω²`; 0: free) with modal damping ratios `xi`.
fn body(mass: f64, x0: Vector3<f64>, omega: [f64; 3], xi: [f64; 3]) -> Model {
    let mut basis = ModalBasis::point_mass(mass, "p", x0).expect("a positive mass");
    basis.omega = omega.to_vec();
    basis.damping_ratio = xi.to_vec();
    Model::new(basis)
}

/// A constant force `f` on point `point`.
fn constant(point: usize, f: Vector3<f64>) -> PointLoad {
    PointLoad::new(point, f, TimeHistory::Constant, "load").expect("a finite force")
}

/// A force `f sin(2π frequency t)` on point `point`.
fn harmonic(point: usize, f: Vector3<f64>, frequency_hz: f64) -> PointLoad {
    let history = TimeHistory::Harmonic {
        frequency_hz,
        phase: 0.0,
    };
    PointLoad::new(point, f, history, "load").expect("a finite force")
}

/// The plane `z = −gap` below `origin`, of normal `+z` (first tangent `x`).
fn plane(origin: Vector3<f64>, gap: f64) -> Obstacle {
    Obstacle::Plane(
        Plane::new(origin, Vector3::z(), gap, Some(Vector3::x()), "plane").expect("a plane"),
    )
}

/// Bodies `a` and `b` as one model (structures `a`, `b`) with the contact `a.p`–`b.p` along
/// `+z` (from B to A) at clearance `gap`.
fn pair(a: Model, b: Model, gap: f64, normal: NormalLaw, friction: Coulomb) -> Model {
    let relative = a.basis.points[0].coords - b.basis.points[0].coords;
    let mut model =
        Model::union(vec![("a".to_string(), a), ("b".to_string(), b)]).expect("two bodies");
    let (ia, ib) = (
        model.basis.point_index("a.p").unwrap(),
        model.basis.point_index("b.p").unwrap(),
    );
    let contact = Contact::between(
        "a_b",
        ia,
        ib,
        &model.basis.points,
        [0.0, 0.0],
        plane(relative, gap),
        normal,
        friction,
    )
    .expect("a valid pair");
    model.contacts.push(contact);
    model
}

fn settings(dt: f64, duration: f64, method: TangentialMethod) -> RunSettings {
    RunSettings {
        dt,
        steps: (duration / dt).round() as u64,
        method,
        stick_velocity: StickVelocity::HalfStep,
        output_every: 1,
        monitors: Vec::new(),
        statistics: Default::default(),
    }
}

fn run(model: &Model, settings: &RunSettings, label: &str) -> RunResults {
    let r = simulate(model, settings).unwrap_or_else(|e| panic!("{label}: {e}"));
    assert_eq!(r.termination, Termination::Completed, "{label}");
    r
}

fn gauss_seidel(local_solve: LocalSolve) -> TangentialMethod {
    TangentialMethod::GaussSeidel(GaussSeidelSettings {
        local_solve,
        ..GaussSeidelSettings::default()
    })
}

/// The Lagrange methods: Active Set, Gauss–Seidel with the exact and the radial local solve.
fn lagrange_methods() -> Vec<(&'static str, TangentialMethod)> {
    vec![
        (
            "active_set",
            TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        ),
        ("gauss_seidel exact", gauss_seidel(LocalSolve::Exact)),
        ("gauss_seidel radial", gauss_seidel(LocalSolve::Radial)),
    ]
}

/// Samples where contact 0 is stuck (status 1) and where it slips (status 2).
fn stick_and_slip_samples(r: &RunResults) -> (usize, usize) {
    let status = r.recorder.status.column(0);
    (
        status.iter().filter(|&&s| s == 1).count(),
        status.iter().filter(|&&s| s == 2).count(),
    )
}

// ---------------------------------------------------------------------------------------------
// 1. Symmetry: mass against a wall ≡ two masses against each other
// ---------------------------------------------------------------------------------------------

/// The mass on its springs: m = 2 kg, k_z = 2e4 N/m (ω = 100 rad/s, ξ = 0.1) toward the wall,
/// k_x = 5e3 N/m (ω = 50 rad/s, ξ = 0.02) along it; pushed by `m γ` (γ = 10 m/s²) onto the
/// wall at g = 0.5 mm (the spring alone would take it to 1 mm: it bounces on the wall less
/// and less, toward resting on it with R_N ≈ 10 N) and by a tangential 4 N at 5 Hz, above
/// μ_s R_N = 3 N at its peaks, below it around its zeros: slip and stick alternate.
struct Symmetry {
    mass: f64,
    omega: [f64; 3],
    xi: [f64; 3],
    gamma: f64,
    gap: f64,
    tangential_load: f64,
    frequency_hz: f64,
    /// The wall's `K_N`, `C_N`.
    normal: NormalLaw,
    friction: Coulomb,
    /// The wall's tangential penalty `K_T`, `C_T`.
    penalty: PenaltySettings,
    dt: f64,
    duration: f64,
}

impl Symmetry {
    fn reference() -> Self {
        Self {
            mass: 2.0,
            omega: [50.0, 0.0, 100.0],
            xi: [0.02, 0.0, 0.1],
            gamma: 10.0,
            gap: 5e-4,
            tangential_load: 4.0,
            frequency_hz: 5.0,
            normal: NormalLaw::new(1e6, 20.0, "normal").unwrap(),
            friction: Coulomb::new(0.3, 0.2, "friction").unwrap(),
            penalty: PenaltySettings {
                stiffness: 1e5,
                damping: 50.0,
            },
            dt: 1e-5,
            duration: 0.4,
        }
    }

    /// A body at `x0` pushed by `sign × (m γ toward the wall, the tangential load)`.
    fn body(&self, x0: Vector3<f64>, sign: f64) -> Model {
        let mut m = body(self.mass, x0, self.omega, self.xi);
        let w = self.mass * self.gamma;
        m.loads.push(constant(0, Vector3::new(0.0, 0.0, -w) * sign));
        m.loads.push(harmonic(
            0,
            Vector3::new(self.tangential_load, 0.0, 0.0) * sign,
            self.frequency_hz,
        ));
        m
    }

    /// The mass on its springs against the fixed wall at `gap` below it.
    fn wall(&self) -> Model {
        let mut m = self.body(Vector3::zeros(), 1.0);
        m.contacts.push(Contact::new(
            "wall",
            0,
            plane(Vector3::zeros(), self.gap),
            self.normal,
            self.friction,
        ));
        m
    }

    /// Two such masses, A pushed by (+γ, +F_T), B by (−γ, −F_T), at 2g from each other, the
    /// contact's `K_N`, `C_N` halved. By symmetry `u_B = −u_A`, so the relative point moves
    /// by `u_A − u_B = 2 u_A`: its penetration is twice the wall's (`2 (−u_z − g)`), its
    /// velocity twice, and `(K_N/2)(2δ) + (C_N/2)(2δ̇)` is the wall's force — on A as on the
    /// single mass. Both bodies share their reference point (x0_A − x0_B = 0, as the wall's
    /// body at the origin): the relative point's coordinates are then exactly twice the
    /// single mass's, not only up to the rounding of an offset.
    fn bodies(&self) -> Model {
        let x0 = Vector3::new(0.25, -1.5, 3.0);
        let halved =
            NormalLaw::new(0.5 * self.normal.stiffness, 0.5 * self.normal.damping, "n").unwrap();
        pair(
            self.body(x0, 1.0),
            self.body(x0, -1.0),
            2.0 * self.gap,
            halved,
            self.friction,
        )
    }

    /// The methods, for the wall and for the pair: the pair's tangential penalty spring and
    /// damper are halved too (its anchor displacement and slip velocity are twice the wall's).
    fn methods(&self) -> Vec<(&'static str, TangentialMethod, TangentialMethod)> {
        let mut v: Vec<_> = lagrange_methods()
            .into_iter()
            .map(|(l, m)| (l, m, m))
            .collect();
        let p = self.penalty;
        let halved = PenaltySettings {
            stiffness: 0.5 * p.stiffness,
            damping: 0.5 * p.damping,
        };
        v.push((
            "penalty",
            TangentialMethod::Penalty(p),
            TangentialMethod::Penalty(halved),
        ));
        v
    }
}

/// The first index at which two sequences differ, if any: exact equality of the values (the
/// bits, but for the sign of a zero: `−0 = 0`, and `−q` of a zero is `−0`).
fn first_difference(x: impl Iterator<Item = f64>, y: impl Iterator<Item = f64>) -> Option<usize> {
    x.zip(y).position(|(u, v)| u != v)
}

/// THEORY §15, Code_Aster's node-to-node validation: the relative motion of two identical
/// bodies hitting each other (±γ, ±F_T, gap 2g, contact stiffness and damping halved) is twice
/// the motion of one body hitting a wall (γ, F_T, gap g) — bit for bit, for the penalty law
/// and the Lagrange methods, through impacts, stick and slip. Everything the pair's contact
/// computes is then the wall's, or twice it (relative quantities), exactly: multiplication by
/// 2 is exact and the rows `Φ_A − Φ_B = [I, −I]/√m` put each term of every dot product of the
/// step in a lane of its own.
#[test]
fn two_bodies_hitting_each_other_move_exactly_as_one_body_hitting_a_wall() {
    // with a damped normal law (the general step) and an undamped one (with the Lagrange
    // methods, the common step of THEORY §9)
    for damping in [20.0, 0.0] {
        let s = Symmetry {
            normal: NormalLaw::new(1e6, damping, "normal").unwrap(),
            ..Symmetry::reference()
        };
        assert_symmetric(&s, &format!("C_N = {damping}"));
    }
}

/// [`two_bodies_hitting_each_other_move_exactly_as_one_body_hitting_a_wall`] for `s`.
fn assert_symmetric(s: &Symmetry, case: &str) {
    let (wall, bodies) = (s.wall(), s.bodies());
    assert_eq!(bodies.structures.len(), 2);
    assert_eq!(bodies.basis.modes(), 6);
    for (method, single_method, pair_method) in s.methods() {
        let label = &format!("{case}, {method}");
        // both run the same step: the common one for an undamped normal law with a Lagrange
        // method, the general one otherwise
        let common = |model: &Model, method| {
            let settings = settings(s.dt, s.dt, method);
            testing::runs_common_step(&Simulation::new(model, &settings).unwrap())
        };
        let expected = s.normal.damping == 0.0 && single_method.is_lagrange();
        assert_eq!(common(&wall, single_method), expected, "{label}");
        assert_eq!(common(&bodies, pair_method), expected, "{label}");
        let one = run(&wall, &settings(s.dt, s.duration, single_method), label);
        let two = run(&bodies, &settings(s.dt, s.duration, pair_method), label);
        // the single body's run has impacts, sticks and slips
        let (stick, slip) = stick_and_slip_samples(&one);
        assert!(
            stick > 1000 && slip > 1000,
            "{label}: {stick} stick and {slip} slip samples"
        );
        assert!(
            one.contacts[0].impacts >= 3,
            "{label}: {:?}",
            one.contacts[0]
        );
        assert_mirrored_motion(label, &two, &one);
        assert_contact_is_the_walls(label, &two, &one);
        assert_energy_is_twice_the_walls(label, &two, &one);
        // the stable time step sees the contact's stiffness on the relative motion of both
        // bodies: K_N/2 × (1/m + 1/m) = K_N/m, the wall's
        let (dt1, dt2) = (
            stable_time_step(&wall, &single_method),
            stable_time_step(&bodies, &pair_method),
        );
        assert!((dt1 - dt2).abs() <= 1e-12 * dt1, "{label}: {dt1} vs {dt2}");
    }
}

/// A moves as the single body, B opposite, and their relative motion halved is the single
/// body's: bit for bit.
fn assert_mirrored_motion(label: &str, two: &RunResults, one: &RunResults) {
    let (r1, r2) = (&one.recorder, &two.recorder);
    assert_eq!(r1.len(), r2.len());
    for (what, x2, x1) in [("q", &r2.q, &r1.q), ("q̇", &r2.qdot, &r1.qdot)] {
        for j in 0..3 {
            let (a, b, single) = (x2.column(j), x2.column(3 + j), x1.column(j));
            let single = || single.iter().copied();
            assert_eq!(
                first_difference(a.iter().copied(), single()),
                None,
                "{label}: {what}_A[{j}] ≠ {what}[{j}]"
            );
            assert_eq!(
                first_difference(b.iter().map(|v| -v), single()),
                None,
                "{label}: {what}_B[{j}] ≠ −{what}[{j}]"
            );
            let half_relative = a.iter().zip(b.iter()).map(|(x, y)| 0.5 * (x - y));
            assert_eq!(
                first_difference(half_relative, single()),
                None,
                "{label}: ({what}_A − {what}_B)/2 ≠ {what}[{j}]"
            );
        }
    }
}

/// The pair's contact forces, statuses, statistics and impacts are the wall's; its relative
/// quantities (penetration, slip velocity, position, speeds, slip work) twice the wall's.
fn assert_contact_is_the_walls(label: &str, two: &RunResults, one: &RunResults) {
    let (r1, r2) = (&one.recorder, &two.recorder);
    let contact = |a: &ndarray::Array2<f64>| a.column(0).to_vec();
    let tangent = |a: &ndarray::Array3<f64>, d: usize| a.slice(ndarray::s![.., 0, d]).to_vec();
    let mut pairs = vec![
        (
            "R_N",
            1.0,
            contact(&r2.normal_force),
            contact(&r1.normal_force),
        ),
        ("δ", 2.0, contact(&r2.penetration), contact(&r1.penetration)),
    ];
    for d in 0..2 {
        pairs.extend([
            (
                "R_T",
                1.0,
                tangent(&r2.tangential_force, d),
                tangent(&r1.tangential_force, d),
            ),
            (
                "v_T",
                2.0,
                tangent(&r2.slip_velocity, d),
                tangent(&r1.slip_velocity, d),
            ),
            (
                "position",
                2.0,
                tangent(&r2.position, d),
                tangent(&r1.position, d),
            ),
        ]);
    }
    for (what, factor, x2, x1) in pairs {
        let x1 = x1.iter().map(|v| factor * v);
        assert_eq!(
            first_difference(x2.iter().copied(), x1),
            None,
            "{label}: the pair's {what} ≠ {factor} × the wall's"
        );
    }
    assert_eq!(r2.status, r1.status, "{label}: statuses");

    // statistics and impacts are the relative motion's: counts, fractions and forces the
    // wall's; speeds, slip work and offsets twice the wall's
    let (a, b) = (&two.contacts[0], &one.contacts[0]);
    assert_eq!(a.name, "a_b");
    for (what, x, y) in [
        ("impacts", a.impacts as f64, b.impacts as f64),
        (
            "contact_time_fraction",
            a.contact_time_fraction,
            b.contact_time_fraction,
        ),
        (
            "stick_time_fraction",
            a.stick_time_fraction,
            b.stick_time_fraction,
        ),
        (
            "slip_time_fraction",
            a.slip_time_fraction,
            b.slip_time_fraction,
        ),
        (
            "normal_force_mean",
            a.normal_force_mean,
            b.normal_force_mean,
        ),
        ("normal_force_max", a.normal_force_max, b.normal_force_max),
        (
            "tangential_force_max",
            a.tangential_force_max,
            b.tangential_force_max,
        ),
        (
            "contact_duration_mean",
            a.contact_duration_mean,
            b.contact_duration_mean,
        ),
        ("wear_work /2", 0.5 * a.wear_work, b.wear_work),
        (
            "normal_wear_work_rate /2",
            0.5 * a.normal_wear_work_rate,
            b.normal_wear_work_rate,
        ),
        (
            "penetration_max /2",
            0.5 * a.penetration_max,
            b.penetration_max,
        ),
        (
            "displacement_rms /2",
            0.5 * a.displacement_rms,
            b.displacement_rms,
        ),
    ] {
        assert!(x == y, "{label}: {what}: {x:e} vs {y:e}");
    }
    assert!(b.wear_work > 0.0 && b.slip_time_fraction > 0.0, "{label}");
    assert_eq!(two.impacts.len(), one.impacts.len(), "{label}");
    for (x, y) in two.impacts.iter().zip(&one.impacts) {
        assert_eq!(
            (x.start, x.duration, x.peak_force, x.impulse),
            (y.start, y.duration, y.peak_force, y.impulse),
            "{label}"
        );
        assert_eq!(
            (0.5 * x.impact_speed, 0.5 * x.rebound_speed),
            (y.impact_speed, y.rebound_speed),
            "{label}"
        );
    }
}

/// Two bodies hold twice the energy of one, and lose twice as much; the balance's relative
/// error is the same (its sums over 6 modes instead of 3: round-off).
fn assert_energy_is_twice_the_walls(label: &str, two: &RunResults, one: &RunResults) {
    let (e2, e1) = (&two.energy, &one.energy);
    let twice = |x: f64, y: f64| (x - 2.0 * y).abs() <= 1e-12 * y.abs();
    for (what, x, y) in [
        ("last", e2.last, e1.last),
        ("external_work", e2.external_work, e1.external_work),
        ("modal_damping", e2.modal_damping, e1.modal_damping),
        ("contact_damping", e2.contact_damping, e1.contact_damping),
        ("tangential", e2.tangential, e1.tangential),
    ] {
        assert!(
            twice(x, y),
            "{label}: energy {what}: pair {x:e}, wall {y:e}"
        );
    }
    assert!(
        (e2.relative_error - e1.relative_error).abs() <= 1e-9 * e1.relative_error,
        "{label}: {e2:?} vs {e1:?}"
    );
    // and it closes: to second order, (ω_c Δt)² = 5e-5 for the impacts' ω_c = √(K_N/m)
    assert!(e1.relative_error < 5e-5, "{label}: {e1:?}");
}

// ---------------------------------------------------------------------------------------------
// 2. Momentum: two free bodies colliding obliquely
// ---------------------------------------------------------------------------------------------

/// Two free point masses, m_A = 1 kg and m_B = 2.5 kg (no spring, no support, no load), whose
/// relative velocity `v_A − v_B` meets their contact plane (normal z, 0.1 mm away) at `V` =
/// 1 m/s, `alpha` from the normal, sliding along 30° in the tangent plane (both tangent
/// components); their centre of mass drifts at `(0.2, −0.1, 0.05)` m/s. K_N = 1e6 N/m,
/// μ = 0.3: the relative motion is THEORY §6's V1 case for the reduced mass
/// `μ_r = m_A m_B / (m_A + m_B)`.
struct Collision {
    masses: [f64; 2],
    speed: f64,
    alpha: f64,
    slide: Vector3<f64>,
    drift: Vector3<f64>,
    gap: f64,
    stiffness: f64,
    mu: f64,
    dt: f64,
    duration: f64,
}

impl Collision {
    fn new(alpha_deg: f64) -> Self {
        let beta = 30f64.to_radians();
        Self {
            masses: [1.0, 2.5],
            speed: 1.0,
            alpha: alpha_deg.to_radians(),
            slide: Vector3::new(beta.cos(), beta.sin(), 0.0),
            drift: Vector3::new(0.2, -0.1, 0.05),
            gap: 1e-4,
            stiffness: 1e6,
            mu: 0.3,
            dt: 1e-6,
            duration: 4e-3,
        }
    }

    fn reduced_mass(&self) -> f64 {
        let [a, b] = self.masses;
        a * b / (a + b)
    }

    /// The relative velocity before the impact, and its normal and tangential parts.
    fn relative_velocity(&self) -> (Vector3<f64>, f64, f64) {
        let (vn, vt) = (self.speed * self.alpha.cos(), self.speed * self.alpha.sin());
        (self.slide * vt - Vector3::z() * vn, vn, vt)
    }

    /// The initial velocities of A and B.
    fn velocities(&self) -> [Vector3<f64>; 2] {
        let [a, b] = self.masses;
        let (v, _, _) = self.relative_velocity();
        [
            self.drift + v * (b / (a + b)),
            self.drift - v * (a / (a + b)),
        ]
    }

    fn model(&self) -> Model {
        let free = |m: f64, x0: Vector3<f64>, v: Vector3<f64>| {
            let mut body = body(m, x0, [0.0; 3], [0.0; 3]);
            body.set_initial_from_point(0, Vector3::zeros(), v)
                .expect("a point mass takes any velocity");
            body
        };
        let [va, vb] = self.velocities();
        pair(
            free(self.masses[0], Vector3::new(0.0, 0.0, 0.01), va),
            free(self.masses[1], Vector3::zeros(), vb),
            self.gap,
            NormalLaw::new(self.stiffness, 0.0, "normal").unwrap(),
            Coulomb::new(self.mu, self.mu, "friction").unwrap(),
        )
    }

    fn methods() -> Vec<(&'static str, TangentialMethod)> {
        let mut v = lagrange_methods();
        v.push((
            "penalty",
            TangentialMethod::Penalty(PenaltySettings {
                stiffness: 1e6,
                damping: 2000.0,
            }),
        ));
        v
    }
}

/// The physical velocities of A and B at sample `i` (rows `I/√m`: `v = q̇/√m`).
fn velocities(r: &RunResults, masses: [f64; 2], i: usize) -> [Vector3<f64>; 2] {
    let qd = r.recorder.qdot.row(i);
    let v = |o: usize, m: f64| Vector3::new(qd[o], qd[o + 1], qd[o + 2]) / m.sqrt();
    [v(0, masses[0]), v(3, masses[1])]
}

/// Total linear momentum `m_A v_A + m_B v_B` at sample `i`.
fn momentum(r: &RunResults, masses: [f64; 2], i: usize) -> Vector3<f64> {
    let [va, vb] = velocities(r, masses, i);
    va * masses[0] + vb * masses[1]
}

fn kinetic_energy(r: &RunResults, masses: [f64; 2], i: usize) -> f64 {
    let [va, vb] = velocities(r, masses, i);
    0.5 * (masses[0] * va.norm_squared() + masses[1] * vb.norm_squared())
}

/// The contact only ever pushes A and B apart with equal and opposite forces: the total
/// momentum is that of the start at every sample, to the round-off of the velocities, through
/// the approach, the impact, the slip, the stick (α = 20°, THEORY §6's V1a) or a slip
/// throughout (α = 60°, V1c), for every method. The contact's modal forces `±R/√m` cancel
/// in `√m_A q̇_A + √m_B q̇_B` up to the rounding of `1/√m`, and each step rounds each
/// velocity a couple of times: after N steps the momentum is off by at most about
/// `2 N ε Σ m|v|` (3e-12 here; measured: about 12 ε Σ m|v|, 5e-15 kg·m/s), where a force
/// missing on one body would change it by the impulse, ~1 kg·m/s.
#[test]
fn two_free_bodies_colliding_obliquely_keep_their_total_momentum() {
    for alpha in [20.0, 60.0] {
        let c = Collision::new(alpha);
        let model = c.model();
        for (label, method) in Collision::methods() {
            let r = run(&model, &settings(c.dt, c.duration, method), label);
            let p0 = momentum(&r, c.masses, 0);
            let [va, vb] = c.velocities();
            assert!((p0 - (va * c.masses[0] + vb * c.masses[1])).norm() <= 1e-15);
            let scale = c.masses[0] * va.norm() + c.masses[1] * vb.norm();
            let drift = (0..r.recorder.len())
                .map(|i| (momentum(&r, c.masses, i) - p0).norm())
                .fold(0.0, f64::max);
            let steps = r.steps as f64;
            assert!(
                drift <= 2.0 * steps * f64::EPSILON * scale,
                "α = {alpha}°, {label}: momentum drifts by {drift:e} kg·m/s ({:.1} ulps of {scale})",
                drift / (f64::EPSILON * scale)
            );
            // it did collide: one impact, and the relative velocity changed
            assert_eq!(r.contacts[0].impacts, 1, "α = {alpha}°, {label}");
            let (stick, slip) = stick_and_slip_samples(&r);
            assert!(slip > 100, "α = {alpha}°, {label}: no slip");
            if alpha == 20.0 && method.is_lagrange() {
                assert!(stick > 100, "α = {alpha}°, {label}: no stick");
            }
        }
    }
}

/// The relative motion of the two bodies is THEORY §6's V1 for the reduced mass μ_r, on which
/// the energy balance of the pair is checked: its initial energy is both bodies' kinetic
/// energy; the friction dissipates the relative tangential kinetic energy ½ μ_r v_t² when the
/// bodies stick (α = 20°), `μ_d ∫R_N (v_t − …)` leaving `v_t − 2 μ v_n` when they slip
/// throughout (α = 60°); what the bodies lose is what the balance books; the wear work is the
/// dissipation. The peak force is `μ_r v_n ω`, `ω = √(K_N/μ_r)`; the stable time step and the
/// impact resolution see μ_r too.
#[test]
fn a_two_body_collision_is_the_reduced_mass_on_a_wall_and_its_energy_balance_closes() {
    for alpha in [20.0, 60.0] {
        let c = Collision::new(alpha);
        let model = c.model();
        let mu_r = c.reduced_mass();
        let omega = (c.stiffness / mu_r).sqrt();
        let (_, vn, vt) = c.relative_velocity();
        // the stable time step of the free pair: 2/ω_max, ω_max² = K_N (1/m_A + 1/m_B)
        let lagrange = TangentialMethod::ActiveSet(ActiveSetSettings::default());
        let stable = stable_time_step(&model, &lagrange);
        assert!(
            (stable - 2.0 / omega).abs() <= 1e-12 * stable,
            "stable Δt {stable:e}, 2/ω = {:e}",
            2.0 / omega
        );
        let resolution = impact_resolution(&model, c.dt);
        assert_eq!(resolution.len(), 1);
        assert!((resolution[0].effective_mass - mu_r).abs() <= 1e-12 * mu_r);

        let e0 = kinetic_energy_of(&c);
        for (label, method) in Collision::methods() {
            let r = run(&model, &settings(c.dt, c.duration, method), label);
            let e = &r.energy;
            assert!(
                (e.initial - e0).abs() <= 1e-14 * e0,
                "α = {alpha}°, {label}: E(0) = {} J, ½ m_A v_A² + ½ m_B v_B² = {e0} J",
                e.initial
            );
            assert!(
                e.relative_error < 1e-6,
                "α = {alpha}°, {label}: energy balance error {:e}",
                e.relative_error
            );
            let last = r.recorder.len() - 1;
            assert_eq!(r.recorder.status[[last, 0]], 0, "{label}: still in contact");
            let lost = e0 - kinetic_energy(&r, c.masses, last);
            assert!(
                (lost - e.tangential).abs() <= e.relative_error * e0 + 1e-15,
                "α = {alpha}°, {label}: the bodies lose {lost} J, the balance books {} J",
                e.tangential
            );
            // the peak normal force of the reduced mass
            let peak = r.contacts[0].normal_force_max;
            let analytic = mu_r * vn * omega;
            assert!(
                (peak - analytic).abs() <= 1e-4 * analytic,
                "α = {alpha}°, {label}: peak R_N {peak} N, μ_r v_n ω = {analytic} N"
            );
            if !method.is_lagrange() {
                continue; // (the penalty law's tangential motion depends on K_T, THEORY §6)
            }
            // the relative velocity after the impact: THEORY §6 for μ_r
            let [va, vb] = velocities(&r, c.masses, last);
            let v = va - vb;
            let leaving_vt = (v - Vector3::z() * v.z).norm();
            let expected_vt = if alpha.to_radians().tan() <= 2.0 * c.mu {
                0.0
            } else {
                vt - 2.0 * c.mu * vn
            };
            assert!(
                (leaving_vt - expected_vt).abs() <= 1e-4 * c.speed,
                "α = {alpha}°, {label}: leaving relative v_T {leaving_vt}, analytic {expected_vt}"
            );
            assert!(
                (v.z - vn).abs() <= 1e-4 * c.speed,
                "α = {alpha}°, {label}: leaving relative v_N {}, analytic {vn}",
                v.z
            );
            // dissipated: the relative tangential kinetic energy lost, ½ μ_r (v_t² − v_t'²)
            let analytic_loss = 0.5 * mu_r * (vt * vt - expected_vt * expected_vt);
            assert!(
                (e.tangential - analytic_loss).abs() <= 1e-4 * analytic_loss,
                "α = {alpha}°, {label}: dissipated {} J, analytic {analytic_loss} J",
                e.tangential
            );
            let wear = r.contacts[0].wear_work;
            assert!(
                (wear - e.tangential).abs() <= 1e-4 * analytic_loss,
                "α = {alpha}°, {label}: wear work {wear} J, dissipated {} J",
                e.tangential
            );
        }
    }
}

/// `½ m_A v_A² + ½ m_B v_B²` of the initial velocities.
fn kinetic_energy_of(c: &Collision) -> f64 {
    let [va, vb] = c.velocities();
    0.5 * (c.masses[0] * va.norm_squared() + c.masses[1] * vb.norm_squared())
}

// ---------------------------------------------------------------------------------------------
// 3. Stick: pressed together and sheared below the threshold
// ---------------------------------------------------------------------------------------------

/// Two free bodies (m_A = 1 kg, m_B = 2.5 kg) pressed onto each other by unequal forces
/// (F_A = 30 N, F_B = 10 N, toward the other: the pair accelerates as a whole) and sheared by
/// unequal opposite forces (3 N on A, −5 N on B, at 20 Hz). Held together, A's share of the
/// common acceleration `(F_A + F_B)/(m_A + m_B)` leaves the contact force
/// `R = (m_A F_B − m_B F_A)/(m_A + m_B)` on A: normal `(m_B F_A,N + m_A F_B,N)/M` = 24.3 N,
/// tangential at most `(m_B F_A,T + m_A F_B,T)/M` = 3.6 N, below μ_s R_N = 7.3 N (μ_s = 0.3,
/// μ_d = 0.2). They start at rest at that normal force's penetration `R_N/K_N` (no normal
/// oscillation that would open the contact), the shear from 0.
struct Pressed {
    masses: [f64; 2],
    normal_forces: [f64; 2],
    shear: [f64; 2],
    frequency_hz: f64,
    stiffness: f64,
    friction: Coulomb,
    dt: f64,
    duration: f64,
}

impl Pressed {
    fn reference() -> Self {
        Self {
            masses: [1.0, 2.5],
            normal_forces: [30.0, 10.0],
            shear: [3.0, 5.0],
            frequency_hz: 20.0,
            stiffness: 1e6,
            friction: Coulomb::new(0.3, 0.2, "friction").unwrap(),
            dt: 1e-5,
            duration: 0.1,
        }
    }

    /// The contact force on A while held together: (normal, largest tangential).
    fn held_forces(&self) -> (f64, f64) {
        let ([ma, mb], total) = (self.masses, self.masses[0] + self.masses[1]);
        let [na, nb] = self.normal_forces;
        let [ta, tb] = self.shear;
        ((mb * na + ma * nb) / total, (mb * ta + ma * tb) / total)
    }

    fn model(&self) -> Model {
        let [ma, mb] = self.masses;
        let [na, nb] = self.normal_forces;
        let [ta, tb] = self.shear;
        let mut a = body(ma, Vector3::zeros(), [0.0; 3], [0.0; 3]);
        a.loads.push(constant(0, Vector3::new(0.0, 0.0, -na)));
        a.loads
            .push(harmonic(0, Vector3::new(ta, 0.0, 0.0), self.frequency_hz));
        let mut b = body(mb, Vector3::zeros(), [0.0; 3], [0.0; 3]);
        b.loads.push(constant(0, Vector3::new(0.0, 0.0, nb)));
        b.loads
            .push(harmonic(0, Vector3::new(-tb, 0.0, 0.0), self.frequency_hz));
        // A starts down by the penetration of the held normal force (q = √m u)
        let (normal, _) = self.held_forces();
        a.initial.q[2] = -(normal / self.stiffness) * ma.sqrt();
        let law = NormalLaw::new(self.stiffness, 0.0, "normal").unwrap();
        pair(a, b, 0.0, law, self.friction)
    }

    /// The relative tangential displacement `u_A,x − u_B,x` at sample `i`.
    fn relative_slip(&self, r: &RunResults, i: usize) -> f64 {
        let q = r.recorder.q.row(i);
        q[0] / self.masses[0].sqrt() - q[3] / self.masses[1].sqrt()
    }
}

/// THEORY §4, §15: below the static threshold the Lagrange methods hold the two bodies
/// together exactly — the contact never slips, its slip velocity is 0 and its wear work 0,
/// not small: nothing — while the relative displacement stays that of the start to round-off.
/// The penalty law, as a contrast, lets the bodies creep on its tangential spring: a
/// micro-slip of about `R_T/K_T` while "sticking", and wear work.
#[test]
fn bodies_pressed_together_and_sheared_below_the_threshold_do_not_slip_with_lagrange() {
    let p = Pressed::reference();
    let model = p.model();
    let (normal, tangential) = p.held_forces();
    assert!(tangential < 0.5 * p.friction.mu_static * normal);
    for (label, method) in lagrange_methods() {
        let r = run(&model, &settings(p.dt, p.duration, method), label);
        let rec = &r.recorder;
        // closed and stuck throughout, at the held forces
        assert!(
            rec.status.iter().all(|&s| s == 1),
            "{label}: {:?}",
            r.contacts[0]
        );
        let (rn, rt) = (&rec.normal_force, &rec.tangential_force);
        let rn_error = rn.iter().map(|f| (f - normal).abs()).fold(0.0, f64::max);
        assert!(
            rn_error <= 1e-9 * normal,
            "{label}: R_N off by {rn_error:e} N"
        );
        let rt_max = rt.iter().map(|f| f.abs()).fold(0.0, f64::max);
        assert!(
            (rt_max - tangential).abs() <= 1e-3 * tangential,
            "{label}: largest R_T {rt_max} N, held {tangential} N"
        );
        // no slip: from the second step on the slip velocity is 0 — the stick constraint has
        // imposed both half-step velocities whose mean it is (THEORY §2, §5) — and so is the
        // friction power. At the first step only the second one was (no Lagrange force acts
        // at t = 0: the initial acceleration has none), and the stick solve's round-off
        // shows: at most ε times the relative velocity one step of the shear alone would give
        let [ma, mb] = p.masses;
        let round_off = f64::EPSILON * (p.shear[0] / ma + p.shear[1] / mb) * p.dt;
        for i in 0..rec.len() {
            for d in 0..2 {
                let v = rec.slip_velocity[[i, 0, d]];
                assert!(
                    v == 0.0 || (i == 1 && v.abs() <= round_off),
                    "{label}: slip velocity {v:e} m/s at sample {i}"
                );
            }
        }
        let s = &r.contacts[0];
        for (what, value, force) in [
            ("wear work ∫|R_T·v_T|", s.wear_work, tangential),
            ("dissipation", r.energy.tangential, tangential),
            ("∫R_N |v_T|", s.normal_wear_work_rate * s.duration, normal),
        ] {
            let bound = force * round_off * p.dt;
            assert!(
                value.abs() <= bound,
                "{label}: {what} {value:e} J, one step of round-off slip {bound:e} J"
            );
        }
        assert_eq!(s.slip_time_fraction, 0.0, "{label}");
        assert_eq!(s.stick_time_fraction, 1.0, "{label}");
        // The relative displacement is not a coordinate: each step rounds u_A and u_B apart
        // (a couple of ε|u| each), so it wanders by round-off, at most 2 N ε max(|u_A| + |u_B|)
        // over N steps (4e-15 m here; measured 2e-18 m), where the penalty law's micro-slip
        // below is 4e-5 m.
        let (slip, scale) = (0..rec.len()).fold((0.0f64, 0.0f64), |(s, u), i| {
            let q = rec.q.row(i);
            let (ua, ub) = (q[0] / ma.sqrt(), q[3] / mb.sqrt());
            (s.max((ua - ub).abs()), u.max(ua.abs() + ub.abs()))
        });
        let bound = 2.0 * r.steps as f64 * f64::EPSILON * scale;
        assert!(
            slip <= bound,
            "{label}: relative slip {slip:e} m > {bound:e} m"
        );
    }

    // the penalty law: the same forces held on a spring K_T, hence a micro-slip R_T/K_T
    let kt = 1e5;
    let penalty = TangentialMethod::Penalty(PenaltySettings {
        stiffness: kt,
        damping: 50.0,
    });
    let r = run(&model, &settings(p.dt, p.duration, penalty), "penalty");
    assert!(
        r.recorder.status.iter().all(|&s| s == 1),
        "{:?}",
        r.contacts[0]
    );
    let slip = (0..r.recorder.len())
        .map(|i| p.relative_slip(&r, i).abs())
        .fold(0.0, f64::max);
    assert!(
        slip > 0.5 * tangential / kt && slip < 2.0 * tangential / kt,
        "penalty: micro-slip {slip:e} m, R_T/K_T = {:e} m",
        tangential / kt
    );
    assert!(r.contacts[0].wear_work > 0.0, "{:?}", r.contacts[0]);
    assert!(r.recorder.slip_velocity.iter().any(|&v| v != 0.0));
}
