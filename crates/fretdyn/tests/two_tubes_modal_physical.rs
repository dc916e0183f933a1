//! Modal ≡ physical for two tubes (issue [3.4], THEORY §15): two clamped tubes side by side,
//! each in a drilled hole of a rigid support plate, pushed against each other at mid-span
//! through a two-body contact (a plane pair, and the cylinder of radius `R_A + R_B`, on the
//! tube surfaces: both tubes' rotations enter the slip), with friction and shear. The union of
//! the two modal models with every mode kept gives the union of the two physical models'
//! results — contact forces, statuses and displacements — to the tolerance of the one-tube
//! test (`tests/tube_modal_physical.rs`), for penalty, Active Set and Gauss–Seidel: the
//! Delassus operator of the pair couples both tubes' modes alike in both coordinates.

#[path = "common/tube_runs.rs"]
mod tube_runs;
use std::path::Path;
use tube_runs::{lagrange, max_abs, penalty, run};

use fretdyn::case::Case;
use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::obstacle::{Cylinder, Obstacle, Plane};
use fretdyn::contact::tangential::TangentialMethod;
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::model::Model;
use nalgebra::Vector3;

const R: f64 = 9.525e-3;
/// Distance between the two axes: the surfaces 40 µm apart.
const D: f64 = 2.0 * R + 4e-5;

/// One clamped–clamped 1 m tube of 10 elements along x at height `z`, all modes kept, in a
/// drilled hole at x = 0.3 (the contact on its surface of radius `radius`, or at its axis);
/// pushed along `push` z (towards the other tube) at mid-span and
/// shaken at x = 0.7 (`fx` axial).
fn tube_case(z: f64, push: f64, fx: f64, phase_deg: f64, radius: f64) -> Case {
    const SG_TUBE: &str = include_str!("fixtures/sg_tube.toml");
    let text = format!(
        r#"
[time]
dt = 2e-6
duration = 0.02

{SG_TUBE}inner_fluid_density = 1000.0
path = [[0.0, 0.0, {z}], [1.0, 0.0, {z}]]
mesh_size = 0.1
max_frequency_hz = 1e9
rayleigh = {{ alpha = 5.0, beta = 2e-6 }}

[[structure.supports]]
at = [0.0, 0.0, {z}]
type = "clamped"

[[structure.supports]]
at = [1.0, 0.0, {z}]
type = "clamped"

[[structure.points]]
name = "mid"
at = [0.5, 0.0, {z}]

[[structure.points]]
name = "plate"
at = [0.3, 0.0, {z}]

[[structure.points]]
name = "load"
at = [0.7, 0.0, {z}]

[[contacts]]
name = "hole"
point = "plate"
radius = {radius}
obstacle = {{ type = "circle", centre = [0.3, 0.0, {z}], axis = [1.0, 0.0, 0.0], clearance = 3e-5 }}
normal = {{ stiffness = 2e6 }}
friction = {{ mu = 0.3 }}

[[loads]]
point = "mid"
force = [0.0, 0.0, {push}]

[[loads]]
point = "load"
force = [{fx}, 60.0, {shake}]
history = {{ type = "harmonic", frequency_hz = 90.0, phase_deg = {phase_deg} }}
"#,
        shake = 2.0 * push
    );
    Case::from_toml_str(&text, Path::new(".")).unwrap()
}

/// The modal and the physical models of the two tubes `a` (z = 0) and `b` (z = D), with the
/// mid-span contact `obstacle` between them on the surfaces of radii `radii`.
fn models(fx: f64, radii: [f64; 2], obstacle: &Obstacle) -> (Model, Model, Case) {
    let cases = [
        tube_case(0.0, 25.0, fx, 0.0, radii[0]),
        tube_case(D, -25.0, fx, 60.0, radii[1]),
    ];
    let modal = cases
        .iter()
        .zip(["a", "b"])
        .map(|(c, n)| {
            assert_eq!(
                c.model.basis.modes(),
                c.tube.as_ref().unwrap().basis.assembled.mass.nrows(),
                "every mode kept"
            );
            (n.to_string(), c.model.clone())
        })
        .collect();
    let physical = cases
        .iter()
        .zip(["a", "b"])
        .map(|(c, n)| {
            let mut p = c
                .tube
                .as_ref()
                .unwrap()
                .structure
                .physical_model(5.0, 2e-6)
                .unwrap();
            p.contacts = c.model.contacts.clone();
            p.loads = c.model.loads.clone();
            (n.to_string(), p)
        })
        .collect();
    let pair = |mut m: Model| {
        let index = |name: &str| m.basis.points.iter().position(|p| p.name == name).unwrap();
        let c = Contact::between(
            "a-b",
            index("a.mid"),
            index("b.mid"),
            &m.basis.points,
            radii,
            obstacle.clone(),
            NormalLaw::new(3e6, 0.0, "a-b.normal").unwrap(),
            Coulomb::new(0.35, 0.3, "a-b.friction").unwrap(),
        )
        .unwrap();
        m.contacts.push(c);
        m
    };
    let [first, _] = cases;
    (
        pair(Model::union(modal).unwrap()),
        pair(Model::union(physical).unwrap()),
        first,
    )
}

fn plane_pair() -> Obstacle {
    // in relative coordinates x_A − x_B: origin x0_A − x0_B, normal from B to A
    Obstacle::Plane(
        Plane::new(
            Vector3::new(0.0, 0.0, -D),
            Vector3::new(0.0, 0.0, -1.0),
            D - 2.0 * R,
            Some(Vector3::x()),
            "pair",
        )
        .unwrap(),
    )
}

fn cylinder_pair() -> Obstacle {
    Obstacle::Cylinder(Cylinder::new(Vector3::zeros(), Vector3::x(), 2.0 * R, "pair").unwrap())
}

/// Runs both models with `method`: the same statuses, forces to 1e-8 of their peak and every
/// point's displacement to 1e-8 of its peak (the one-tube test's tolerance).
fn compare(modal: &Model, physical: &Model, case: &Case, method: TangentialMethod) {
    let kind = modal.contacts.last().unwrap().obstacle.kind();
    let name = format!("{} ({kind} pair)", method.name());
    let a = run(physical, case, method);
    let b = run(modal, case, method);
    let (ra, rb) = (&a.recorder, &b.recorder);
    let pair = ra.status.ncols() - 1;
    let col: Vec<i8> = ra.status.column(pair).to_vec();
    assert!(
        col.contains(&0) && col.contains(&1) && col.contains(&2),
        "{name}: the pair must open, stick and slip"
    );
    let fscale = max_abs(ra.normal_force.iter().copied());
    assert!(fscale > 1.0);
    let df = max_abs(
        ra.normal_force
            .iter()
            .zip(&rb.normal_force)
            .chain(ra.tangential_force.iter().zip(&rb.tangential_force))
            .map(|(x, y)| x - y),
    );
    assert!(
        df <= 1e-8 * fscale,
        "{name}: forces differ by {df:e} ({fscale:e})"
    );
    assert_eq!(ra.status, rb.status, "{name}: statuses differ");
    for pa in &physical.basis.points {
        let pb = modal
            .basis
            .points
            .iter()
            .find(|p| p.name == pa.name)
            .unwrap();
        let (mut du, mut scale) = (0.0f64, 0.0f64);
        for i in 0..ra.len() {
            let qa: Vec<f64> = ra.q.row(i).to_vec();
            let qb: Vec<f64> = rb.q.row(i).to_vec();
            let ua = fretdyn::structure::modal::recombine(&pa.rows, &qa);
            let ub = fretdyn::structure::modal::recombine(&pb.rows, &qb);
            scale = scale.max(ua.amax());
            du = du.max((ua - ub).amax());
        }
        assert!(du <= 1e-8 * scale, "{name} {}: {du:e} ({scale:e})", pa.name);
    }
    eprintln!("{name}: forces {:.2e} of {fscale:.3e} N", df / fscale);
}

/// On the tube surfaces (both tubes' rotations in the slip), axial shear: 2-D slips, the
/// Lagrange methods (the penalty law's explicit 2-D slip direction parts two runs that differ
/// by round-off, see `tests/tube_modal_physical.rs`).
#[test]
fn two_tubes_on_all_modes_give_the_physical_solution_on_their_surfaces() {
    for obstacle in [plane_pair(), cylinder_pair()] {
        let (modal, physical, case) = models(5.0, [R, R], &obstacle);
        assert_eq!(modal.structures.len(), 2);
        for method in lagrange() {
            compare(&modal, &physical, &case, method);
        }
    }
}

/// At the axes (in the hole too), no axial force: 1-D slips, all three methods.
#[test]
fn two_tubes_on_all_modes_give_the_physical_solution_at_their_axes() {
    for obstacle in [plane_pair(), cylinder_pair()] {
        let (modal, physical, case) = models(0.0, [0.0, 0.0], &obstacle);
        for method in [penalty()].into_iter().chain(lagrange()) {
            compare(&modal, &physical, &case, method);
        }
    }
}
