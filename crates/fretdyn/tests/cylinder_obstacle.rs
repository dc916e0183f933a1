//! The cylinder obstacle (THEORY §15, `contact::obstacle::Cylinder`): a rod of radius
//! `ρ_c = R_A + R_B` around B's axis, seen by the relative point A − B of a two-body contact
//! (tubes side by side). Its frame against the formulas (`δ = ρ_c − |r⊥|`, `n = r⊥/|r⊥|` from
//! B's axis towards A, tangents `[a × n, a]`, the axial offset ignored), and two point masses
//! colliding through it: total momentum kept to round-off through impact, stick and slip,
//! and, while the motion stays on the line of centres (with sliding along the axis), the same
//! run as the equivalent plane contact (point against point along the line of centres).

use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::obstacle::{Cylinder, Obstacle, Plane};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, TangentialMethod,
};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{RunResults, simulate};
use fretdyn::model::Model;
use fretdyn::structure::modal::ModalBasis;
use nalgebra::Vector3;
#[path = "common/every_step.rs"]
mod every_step;
use every_step::every_step;

fn methods() -> [TangentialMethod; 3] {
    [
        TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e6,
            damping: 50.0,
        }),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
    ]
}

#[test]
fn the_frame_is_the_rods_radial_frame_and_ignores_the_axial_offset() {
    let centre = Vector3::new(0.1, -0.2, 0.3);
    let given_axis = Vector3::new(1.0, 2.0, 2.0); // |a| = 3: normalised by the constructor
    let a = given_axis / 3.0;
    let radius = 0.02;
    let rod = Obstacle::Cylinder(Cylinder::new(centre, given_axis, radius, "rod").unwrap());
    // two unit vectors normal to the axis
    let e = Vector3::new(2.0, -1.0, 0.0).normalize();
    let f = a.cross(&e);
    for (k, rho) in [0.005, 0.0199, 0.02, 0.021, 0.3].into_iter().enumerate() {
        let angle = 0.7 * k as f64;
        let radial = e * angle.cos() + f * angle.sin();
        let reference = rod.frame(&(centre + radial * rho));
        for s in [-0.4, 0.0, 1e-3, 2.5] {
            let fr = rod.frame(&(centre + radial * rho + a * s));
            let tol = 1e-15 * (1.0 + s.abs() / rho);
            assert!(
                (fr.penetration - (radius - rho)).abs() < 4.0 * tol * rho.max(radius),
                "δ at ρ = {rho}, s = {s}: {} vs {}",
                fr.penetration,
                radius - rho
            );
            assert!((fr.normal - radial).amax() < 4.0 * tol, "n at ρ = {rho}");
            let [t1, t2] = fr.tangents;
            assert!((t1 - a.cross(&radial)).amax() < 4.0 * tol, "t1 = a × n");
            assert!((t2 - a).amax() < 1e-15, "t2 = a");
            for (u, v) in [(fr.normal, t1), (fr.normal, t2), (t1, t2)] {
                assert!(u.dot(&v).abs() < 4.0 * tol, "orthogonal");
            }
            for u in [fr.normal, t1, t2] {
                assert!((u.norm() - 1.0).abs() < 1e-14, "unit");
            }
            assert_eq!(fr.velocity, Vector3::zeros());
            // the axial offset changes nothing but round-off
            assert!((fr.penetration - reference.penetration).abs() < 4.0 * tol * rho.max(radius));
            assert!((fr.normal - reference.normal).amax() < 4.0 * tol);
        }
    }
    // exactly on the axis: a unit normal across the axis, full penetration
    let on_axis = rod.frame(&(centre + a * 0.7));
    assert!((on_axis.penetration - radius).abs() < 1e-17);
    assert!((on_axis.normal.norm() - 1.0).abs() < 1e-15);
    assert!(on_axis.normal.dot(&a).abs() < 1e-15);
    assert!(rod.is_hole());
    assert_eq!(rod.kind(), "cylinder");
}

#[test]
fn a_rod_without_a_radius_or_an_axis_is_refused_naming_the_field() {
    for (axis, radius, field) in [
        (Vector3::z(), 0.0, "rod.radius"),
        (Vector3::z(), -1e-3, "rod.radius"),
        (Vector3::z(), f64::NAN, "rod.radius"),
        (Vector3::zeros(), 0.02, "rod.axis"),
    ] {
        let e = Cylinder::new(Vector3::zeros(), axis, radius, "rod").unwrap_err();
        let text = e.to_string();
        assert!(text.contains(field), "{text}");
        assert_eq!(text.lines().count(), 1, "{text}");
    }
}

/// Two point masses `a.p`, `b.p` in one model, B's centre at `(d, 0, 0)`, A's at the origin,
/// free (no spring), with velocities `va`, `vb`.
fn two_masses(ma: f64, mb: f64, d: f64, va: Vector3<f64>, vb: Vector3<f64>) -> Model {
    let body = |m: f64, x: Vector3<f64>, v: Vector3<f64>| {
        let mut model = Model::new(ModalBasis::point_mass(m, "p", x).unwrap());
        model
            .set_initial_from_point(0, Vector3::zeros(), v)
            .unwrap();
        model
    };
    Model::union(vec![
        ("a".into(), body(ma, Vector3::zeros(), va)),
        ("b".into(), body(mb, Vector3::new(d, 0.0, 0.0), vb)),
    ])
    .unwrap()
}

/// A rod around B's axis (along z) of radius `rho_c`, in relative coordinates.
fn rod(rho_c: f64) -> Obstacle {
    Obstacle::Cylinder(Cylinder::new(Vector3::zeros(), Vector3::z(), rho_c, "rod").unwrap())
}

fn with_contact(mut model: Model, obstacle: Obstacle, k: f64) -> Model {
    let c = Contact::between(
        "ab",
        0,
        1,
        &model.basis.points,
        [0.0, 0.0],
        obstacle,
        NormalLaw::new(k, 0.0, "ab.normal").unwrap(),
        Coulomb::new(0.4, 0.3, "ab.friction").unwrap(),
    )
    .unwrap();
    model.contacts.push(c);
    model
}

fn run(model: &Model, method: TangentialMethod, dt: f64, steps: u64) -> RunResults {
    let r = simulate(model, &every_step(method, dt, steps)).expect("valid run");
    assert_eq!(
        r.termination,
        fretdyn::integrator::simulation::Termination::Completed
    );
    r
}

/// Total momentum `Σ √m_s q̇_s` (rows of a point mass: `I/√m`).
fn momentum(r: &RunResults, i: usize, ma: f64, mb: f64) -> Vector3<f64> {
    let qd = r.recorder.qdot.row(i);
    Vector3::from_fn(|d, _| ma.sqrt() * qd[d] + mb.sqrt() * qd[3 + d])
}

#[test]
fn an_oblique_collision_through_the_rod_keeps_the_total_momentum() {
    let (ma, mb, d, rho_c) = (2.0, 3.0, 0.05, 0.03);
    // A runs at B obliquely in the plane normal to the axis, and along the axis
    let va = Vector3::new(0.8, 0.5, 0.2);
    let vb = Vector3::new(-0.3, -0.2, -0.1);
    let model = with_contact(two_masses(ma, mb, d, va, vb), rod(rho_c), 1e6);
    for method in methods() {
        let r = run(&model, method, 1e-6, 40_000);
        let rec = &r.recorder;
        let status: Vec<i8> = rec.status.column(0).to_vec();
        assert!(
            status.contains(&0) && status.iter().any(|s| *s > 0),
            "{}: impact",
            method.name()
        );
        let p0 = momentum(&r, 0, ma, mb);
        let scale = p0.norm();
        let mut drift = 0.0f64;
        for i in 0..rec.len() {
            drift = drift.max((momentum(&r, i, ma, mb) - p0).amax());
        }
        // the force enters A's and B's modes with opposite signs: only rounding remains
        assert!(drift < 1e-13 * scale, "{}: {drift:e}", method.name());
        let fmax = rec.normal_force.iter().fold(0.0f64, |m, f| m.max(*f));
        assert!(fmax > 10.0, "{}: {fmax}", method.name());
        // they part: at the end the relative point moves away from B's axis
        let last = rec.len() - 1;
        let (q, qd) = (rec.q.row(last), rec.qdot.row(last));
        let rel = |v: &[f64], k: usize| v[k] / ma.sqrt() - v[3 + k] / mb.sqrt();
        let (q, qd) = (q.to_vec(), qd.to_vec());
        let r = Vector3::new(rel(&q, 0) - d, rel(&q, 1), 0.0);
        let v = Vector3::new(rel(&qd, 0), rel(&qd, 1), 0.0);
        assert!(
            r.norm() > rho_c && r.dot(&v) > 0.0,
            "{}: they part",
            method.name()
        );
    }
}

/// Head on along the line of centres (x), sliding along the axis (z): the rod's normal is
/// the plane's `−x` and its tangents `[a × n, a] = [−y, z]`, the plane's with `t1 = −y`.
/// Both penetrations are `ρ_c − d + (u_A − u_B)·x`, formed from numbers of size `d`: they
/// differ by round-off of order `ε d`, i.e. a relative `ε d / δ` in the force.
#[test]
fn on_the_line_of_centres_the_rod_is_the_plane_between_the_points() {
    let (ma, mb, d, rho_c, k) = (2.0, 3.0, 0.05, 0.03, 1e6);
    let va = Vector3::new(0.6, 0.0, 0.3);
    let vb = Vector3::new(-0.2, 0.0, -0.4);
    let free = two_masses(ma, mb, d, va, vb);
    let plane = Obstacle::Plane(
        Plane::new(
            Vector3::new(-d, 0.0, 0.0),
            Vector3::new(-1.0, 0.0, 0.0),
            d - rho_c,
            Some(Vector3::new(0.0, -1.0, 0.0)),
            "plane",
        )
        .unwrap(),
    );
    let with_rod = with_contact(free.clone(), rod(rho_c), k);
    let with_plane = with_contact(free, plane, k);
    for method in methods() {
        let a = run(&with_rod, method, 1e-6, 35_000);
        let b = run(&with_plane, method, 1e-6, 35_000);
        let (ra, rb) = (&a.recorder, &b.recorder);
        let statuses: Vec<i8> = ra.status.column(0).to_vec();
        assert!(
            statuses.contains(&0) && statuses.contains(&2),
            "{}: impact",
            method.name()
        );
        let fscale = ra.normal_force.iter().fold(0.0f64, |m, f| m.max(*f));
        let peak_penetration = fscale / k;
        let round_off = 64.0 * f64::EPSILON * d / peak_penetration;
        let df = ra
            .normal_force
            .iter()
            .zip(&rb.normal_force)
            .chain(ra.tangential_force.iter().zip(&rb.tangential_force))
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(
            df <= round_off * fscale,
            "{}: forces differ by {df:e} (scale {fscale:e}, round-off {round_off:e})",
            method.name()
        );
        let dq =
            ra.q.iter()
                .zip(&rb.q)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        let qscale = ra.q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(
            dq <= round_off * qscale,
            "{}: q differ by {dq:e}",
            method.name()
        );
        // no motion across the line of centres
        let y =
            ra.q.column(1)
                .iter()
                .chain(ra.q.column(4).iter())
                .fold(0.0f64, |m, x| m.max(x.abs()));
        assert_eq!(y, 0.0, "{}", method.name());
        // the axial sliding met friction
        let ft = ra
            .tangential_force
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(ft > 1.0, "{}: axial friction {ft}", method.name());
    }
}
