//! Preloaded contacts (THEORY §16.1): a tube pressed on anti-vibration bars starts at rest in
//! its static equilibrium.
//!
//! **The closed form.** A simply supported Euler–Bernoulli beam of length `L`, bending
//! stiffness `E I`, loaded by a point force `P` at `x = a` (`b = L − a`) deflects at `x ≤ a`
//! by `w(x) = P α(x, a)`, `α(x, a) = b x (L² − b² − x²) / (6 E I L)` (Maxwell's influence
//! coefficient, symmetric), and under the load by `α(a, a) = a² b² / (3 E I L)`. A plane of
//! contact stiffness `k` pressed into the beam at `x = a` by the interference `δ` pushes with
//! `F = k (δ − w(a))` (the penetration is what is left of the interference once the beam has
//! moved away by `w(a) = F α(a, a)`): `F = δ / (1/k + a² b² / (3 E I L))`. With several
//! planes, `(A + diag(1/k_i)) F = δ` with `A_ij = α(a_i, a_j)`; a force `F` at rest asks for
//! the interference `δ = F (1/k + α(a, a))`.
//!
//! The tube's finite elements are Euler–Bernoulli cubics, exact at the nodes for point loads
//! at nodes, and every mode is kept, so the modal model's static flexibility is the beam's:
//! the comparison is to round-off (1e-9 asked).

use std::path::Path;

use fretdyn::case::Case;
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, TangentialMethod,
};
use fretdyn::integrator::simulation::{RunResults, RunSettings, simulate};
use fretdyn::model::static_equilibrium;

const OUTER: f64 = 19.05e-3;
const WALL: f64 = 1.09e-3;
const YOUNG: f64 = 2.0e11;
const LENGTH: f64 = 1.0;

/// `E I` of the tube.
fn bending_stiffness() -> f64 {
    let inner = OUTER - 2.0 * WALL;
    YOUNG * std::f64::consts::PI / 64.0 * (OUTER.powi(4) - inner.powi(4))
}

/// Maxwell's influence coefficient of the simply supported beam: deflection at `x` under a
/// unit force at `a`.
fn influence(x: f64, a: f64) -> f64 {
    let (x, a) = if x <= a { (x, a) } else { (a, x) };
    let b = LENGTH - a;
    b * x * (LENGTH * LENGTH - b * b - x * x) / (6.0 * bending_stiffness() * LENGTH)
}

/// A 1 m steam-generator tube simply supported at both ends (torsion held at the left one),
/// every mode kept, points `a` (0.4 m) and `b` (0.7 m) on its axis, and `contacts`.
fn case_text(contacts: &str, duration: f64) -> String {
    format!(
        r#"
[time]
dt = 2e-6
duration = {duration}

[structure]
type = "tube"
outer_diameter = {OUTER}
wall_thickness = {WALL}
young_modulus = {YOUNG}
poisson_ratio = 0.3
density = 8200.0
inner_fluid_density = 1000.0
path = [[0.0, 0.0, 0.0], [{LENGTH}, 0.0, 0.0]]
mesh_size = 0.1
max_frequency_hz = 1e9
damping_ratio = 0.0

[[structure.supports]]
at = [0.0, 0.0, 0.0]
type = "dofs"
fixed = ["ux", "uy", "uz", "rx"]

[[structure.supports]]
at = [{LENGTH}, 0.0, 0.0]
type = "pinned"

[[structure.points]]
name = "a"
at = [0.4, 0.0, 0.0]

[[structure.points]]
name = "b"
at = [0.7, 0.0, 0.0]
{contacts}
"#
    )
}

/// A plane below point `point` (normal +y, pushing up) or above it (normal −y), stiffness `k`,
/// preloaded by `preload` (`interference = …` or `force = …`).
fn bar(name: &str, point: &str, x: f64, up: bool, k: f64, preload: &str) -> String {
    let n = if up { 1.0 } else { -1.0 };
    format!(
        r#"
[[contacts]]
name = "{name}"
point = "{point}"
obstacle = {{ type = "plane", origin = [{x}, 0.0, 0.0], normal = [0.0, {n}, 0.0], tangent = [1.0, 0.0, 0.0] }}
normal = {{ stiffness = {k} }}
friction = {{ mu = 0.3 }}
preload = {{ {preload} }}
"#
    )
}

fn case(contacts: &str, duration: f64) -> Case {
    Case::from_toml_str(&case_text(contacts, duration), Path::new(".")).expect("valid case")
}

fn methods() -> [TangentialMethod; 3] {
    [
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e6,
            damping: 0.0,
        }),
    ]
}

fn run(case: &Case, method: TangentialMethod) -> RunResults {
    let settings = RunSettings {
        method,
        output_every: 1,
        ..case.settings.clone()
    };
    simulate(&case.model, &settings).expect("valid run")
}

/// `(interference, force)` the case applied to contact `k`.
fn applied(case: &Case, k: usize) -> (f64, f64) {
    case.model.contacts[k]
        .preload
        .and_then(|p| p.applied)
        .expect("a preload applied")
}

fn relative(got: f64, expected: f64) -> f64 {
    (got - expected).abs() / expected.abs()
}

#[test]
fn one_bar_with_an_interference_presses_with_the_closed_form_force() {
    let (a, k, delta) = (0.4, 1e6, 1e-4);
    let case = case(
        &bar("avb", "a", a, true, k, &format!("interference = {delta}")),
        2e-5,
    );
    let expected = delta / (1.0 / k + influence(a, a));
    let (interference, force) = applied(&case, 0);
    assert_eq!(interference, delta);
    assert!(relative(force, expected) <= 1e-9, "{force} vs {expected}");
    // the run's contact force at t = 0 is the static one
    let r = run(&case, methods()[0]);
    let at_start = r.recorder.normal_force[[0, 0]];
    assert!(
        relative(at_start, expected) <= 1e-9,
        "{at_start} vs {expected}"
    );
    // the tube is lifted by F α(a, a) at the bar
    let lift = expected * influence(a, a);
    let q0 = case.model.initial.q.clone();
    let rows = &case.model.basis.points[case.model.contacts[0].point].rows;
    let p = q0.len();
    let y: f64 = rows[p..2 * p].iter().zip(&q0).map(|(r, q)| r * q).sum();
    assert!(relative(y, lift) <= 1e-9, "{y} vs {lift}");
}

#[test]
fn two_bars_share_the_load_as_maxwell_says() {
    // both bars closed needs m12/m22 < δ1/δ2 < m11/m12 (1.00 and 1.31 here)
    let (a1, a2, k1, k2, d1, d2) = (0.4, 0.7, 1e6, 2e6, 1.15e-4, 1e-4);
    let contacts = bar("a1", "a", a1, true, k1, &format!("interference = {d1}"))
        + &bar("a2", "b", a2, true, k2, &format!("interference = {d2}"));
    let case = case(&contacts, 2e-5);
    // (A + diag(1/k)) F = δ, 2 × 2 by Cramer
    let (m11, m12, m22) = (
        influence(a1, a1) + 1.0 / k1,
        influence(a1, a2),
        influence(a2, a2) + 1.0 / k2,
    );
    let det = m11 * m22 - m12 * m12;
    let f1 = (d1 * m22 - m12 * d2) / det;
    let f2 = (m11 * d2 - m12 * d1) / det;
    assert!(f1 > 0.0 && f2 > 0.0, "both bars closed: {f1}, {f2}");
    let r = run(&case, methods()[1]);
    for (k, expected) in [f1, f2].into_iter().enumerate() {
        let (_, force) = applied(&case, k);
        assert!(
            relative(force, expected) <= 1e-9,
            "{k}: {force} vs {expected}"
        );
        let at_start = r.recorder.normal_force[[0, k]];
        assert!(relative(at_start, expected) <= 1e-9, "{k}: {at_start}");
    }
}

#[test]
fn a_force_at_rest_finds_the_closed_form_interference() {
    let (a1, a2, k1, k2, f1, f2) = (0.4, 0.7, 1e6, 2e6, 4.0, 2.5);
    // one bar: δ = F (1/k + α(a, a))
    let one = case(
        &bar("a1", "a", a1, true, k1, &format!("force = {f1}")),
        2e-5,
    );
    let (interference, force) = applied(&one, 0);
    let expected = f1 * (1.0 / k1 + influence(a1, a1));
    assert!(relative(interference, expected) <= 1e-9, "{interference}");
    assert!(relative(force, f1) <= 1e-12, "{force}");
    // two bars, one with a force and one with an interference: δ_1 = (A F + F/k)_1 with
    // F_2 from its own row, (α22 + 1/k2) F2 = δ2 − α21 F1 (δ2 more than the lift α21 F1 of
    // the first bar, 0.12 mm, for the second to stay closed)
    let d2 = 2e-4;
    let two = case(
        &(bar("a1", "a", a1, true, k1, &format!("force = {f1}"))
            + &bar("a2", "b", a2, true, k2, &format!("interference = {d2}"))),
        2e-5,
    );
    let g2 = (d2 - influence(a2, a1) * f1) / (influence(a2, a2) + 1.0 / k2);
    assert!(g2 > 0.0, "the second bar closed: {g2}");
    let d1 = f1 * (influence(a1, a1) + 1.0 / k1) + influence(a1, a2) * g2;
    let (i1, force1) = applied(&two, 0);
    let (_, force2) = applied(&two, 1);
    assert!(relative(i1, d1) <= 1e-9, "{i1} vs {d1}");
    assert!(relative(force1, f1) <= 1e-9, "{force1}");
    assert!(relative(force2, g2) <= 1e-9, "{force2} vs {g2}");
    // both by force
    let both = case(
        &(bar("a1", "a", a1, true, k1, &format!("force = {f1}"))
            + &bar("a2", "b", a2, true, k2, &format!("force = {f2}"))),
        2e-5,
    );
    let r = run(&both, methods()[0]);
    for (k, (f, kk, a)) in [(f1, k1, a1), (f2, k2, a2)].into_iter().enumerate() {
        let (i, force) = applied(&both, k);
        let other = if k == 0 { (f2, a2) } else { (f1, a1) };
        let expected = f * (influence(a, a) + 1.0 / kk) + influence(a, other.1) * other.0;
        assert!(relative(i, expected) <= 1e-9, "{k}: {i} vs {expected}");
        assert!(relative(force, f) <= 1e-9, "{k}: {force}");
        assert!(relative(r.recorder.normal_force[[0, k]], f) <= 1e-9);
    }
    // the library's solve of the pressed model finds the same state again
    let again = static_equilibrium(&both.model, None).expect("equilibrium");
    assert!(relative(again.forces[0], f1) <= 1e-9);
}

/// Two bars preloaded on a tube and no load: each method keeps it at rest for 5000 steps.
#[test]
fn nothing_moves_without_loads() {
    let contacts = bar("a1", "a", 0.4, true, 1e6, "interference = 1e-4")
        + &bar("a2", "b", 0.7, true, 2e6, "force = 25.0")
        + &bar("a3", "b", 0.7, false, 2e6, "force = 10.0");
    let case = case(&contacts, 1e-2);
    let q0 = case.model.initial.q.clone();
    let qmax = q0.iter().fold(0.0f64, |m, q| m.max(q.abs()));
    for method in methods() {
        let name = method.name();
        let r = run(&case, method);
        assert_eq!(r.steps, 5000);
        let mut drift = 0.0f64;
        for row in r.recorder.q.rows() {
            for (q, q0) in row.iter().zip(&q0) {
                drift = drift.max((q - q0).abs());
            }
        }
        let f0 = r.recorder.normal_force.row(0).to_owned();
        let mut force_drift = 0.0f64;
        for row in r.recorder.normal_force.rows() {
            for (f, f0) in row.iter().zip(&f0) {
                force_drift = force_drift.max((f - f0).abs() / f0);
            }
        }
        let slip = r
            .recorder
            .slip_velocity
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        eprintln!(
            "{name}: modal drift {drift:.3e} of {qmax:.3e}, force drift {force_drift:.3e}, slip {slip:.3e}"
        );
        assert!(drift <= 1e-10 * qmax, "{name}: {drift:.3e}");
        assert!(force_drift <= 1e-10, "{name}: {force_drift:.3e}");
    }
}

/// A point pinched between two bars pressed with `F` each (their forces cancel: the tube stays
/// straight) and sheared along the tube's other lateral direction `z` by `T`, ramped from 0
/// over 1 ms then constant (a shear already there at t = 0 moves the point during the first
/// half step, before the first tangential solve: 6.7e-9 m, measured).
fn pinched(shear: f64) -> Case {
    let contacts = bar("below", "a", 0.4, true, 1e6, "force = 100.0")
        + &bar("above", "a", 0.4, false, 1e6, "force = 100.0")
        + &format!(
            "\n[[loads]]\npoint = \"a\"\nforce = [0.0, 0.0, {shear}]\nhistory = {{ type = \"table\", table = [[0.0, 0.0], [1e-3, 1.0], [1.0, 1.0]] }}\n"
        );
    case(&contacts, 4e-3)
}

/// The largest `|z|` of point `a` over the run, m.
fn largest_z(case: &Case, r: &RunResults) -> f64 {
    let point = &case.model.basis.points[case.model.contacts[0].point];
    let p = case.model.basis.modes();
    r.recorder
        .q
        .rows()
        .into_iter()
        .map(|q| {
            point.rows[2 * p..]
                .iter()
                .zip(q)
                .map(|(a, b)| a * b)
                .sum::<f64>()
                .abs()
        })
        .fold(0.0, f64::max)
}

/// Below `2 μ F` the pinched point sticks exactly with the Lagrange methods (its friction
/// carries the whole shear: nothing moves); above, it slides.
#[test]
fn a_pinched_point_sheared_below_twice_mu_f_sticks() {
    let limit = 2.0 * 0.3 * 100.0;
    let free = limit * influence(0.4, 0.4); // the free deflection under the limit load, m
    for method in [methods()[1], methods()[0]] {
        let name = method.name();
        let case = pinched(0.9 * limit);
        assert_eq!(
            case.model
                .initial
                .q
                .iter()
                .fold(0.0f64, |m, q| m.max(q.abs())),
            0.0
        );
        let r = run(&case, method);
        let z = largest_z(&case, &r);
        let slip = r
            .recorder
            .slip_velocity
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let statuses: Vec<usize> = (0..3)
            .map(|s| r.recorder.status.iter().filter(|x| **x == s).count())
            .collect();
        // the friction of the two bars along z carries the shear at every step
        let last = r.recorder.t.len() - 1;
        let carried: f64 = (0..2)
            .map(|k| {
                let t2 = if k == 0 { -1.0 } else { 1.0 }; // t2 = n × x: −z below, +z above
                t2 * r.recorder.tangential_force[[last, k, 1]]
            })
            .sum();
        eprintln!(
            "{name}: |z| ≤ {z:.3e} m (free {free:.3e}), slip ≤ {slip:.3e} m/s, statuses open/stick/slip {statuses:?}, carried {carried:.9} N, solver {:?}",
            r.solver
        );
        assert!(z <= 1e-12 * free, "{name}: {z:.3e}");
        assert!(relative(-carried, 0.9 * limit) <= 1e-9, "{name}: {carried}");
        // above the limit it slides: the point moves by more than the stuck round-off
        let r = run(&pinched(1.1 * limit), method);
        let z = largest_z(&pinched(1.1 * limit), &r);
        assert!(z > 1e-3 * free, "{name}: slides by {z:.3e}");
    }
}

/// Bad input: one clear error naming the key.
#[test]
fn bad_preloads_are_refused_by_key() {
    let plane = |preload: &str| bar("avb", "a", 0.4, true, 1e6, preload);
    for (contacts, field, words) in [
        (plane("force = -1.0"), "contacts[0].preload.force", "≥ 0"),
        (
            plane("interference = -1e-4"),
            "contacts[0].preload.interference",
            "obstacle.gap",
        ),
        (
            plane("force = 1.0, interference = 1e-4"),
            "contacts[0].preload",
            "not both",
        ),
        (plane(""), "contacts[0].preload", "either"),
        (
            plane("force = 1.0")
                .replace("type = \"plane\"", "type = \"bi_plane\", gap = 1e-4"),
            "contacts[0].preload",
            "two plane contacts",
        ),
        (
            "\n[[contacts]]\npoint = \"a\"\nobstacle = { type = \"circle\", centre = [0.4, 0.0, 0.0], axis = [1.0, 0.0, 0.0], clearance = 1e-4 }\nnormal = { stiffness = 1e6 }\nfriction = { mu = 0.3 }\npreload = { force = 1.0 }\n".to_string(),
            "contacts[0].preload",
            "plane obstacles",
        ),
        (
            // a bar with a width is one face: a force would not say how it spreads
            plane("force = 1.0").replace("friction =", "width = 0.02\nfriction ="),
            "contacts[0].preload.force",
            "interference",
        ),
    ] {
        let err = Case::from_toml_str(&case_text(&contacts, 1e-5), Path::new("."))
            .expect_err("refused");
        assert_eq!(err.field(), Some(field), "{err}");
        assert!(err.to_string().contains(words), "{err}");
    }
    let err = Case::from_toml_str(
        &case_text(&plane("force = 1.0, spring = 2.0"), 1e-5),
        Path::new("."),
    )
    .expect_err("unknown key");
    assert!(err.to_string().contains("spring"), "{err}");
}

/// A study's parameter `contacts[0].preload.force` (the key path studies set) changes the
/// force at rest.
#[test]
fn a_study_key_path_sets_the_force_at_rest() {
    use fretdyn::case::key_path::{KeyPath, Missing};
    let text = case_text(&bar("avb", "a", 0.4, true, 1e6, "force = 10.0"), 1e-5);
    let mut root: toml::Value = toml::from_str(&text).expect("toml");
    KeyPath::parse("contacts[0].preload.force")
        .expect("path")
        .set(&mut root, &toml::Value::Float(40.0), Missing::Refuse)
        .expect("set");
    let case = Case::from_toml_str(&toml::to_string(&root).expect("toml"), Path::new("."))
        .expect("valid case");
    assert!(relative(applied(&case, 0).1, 40.0) <= 1e-9);
}

/// A two-body plane preloaded (THEORY §15): two point masses on springs `k_A`, `k_B` pressed
/// together through a contact of stiffness `k` are three springs in series,
/// `F = δ / (1/k + 1/k_A + 1/k_B)`; a force at rest `F` asks for `δ = F (1/k + 1/k_A + 1/k_B)`.
#[test]
fn a_two_body_plane_takes_a_preload_as_springs_in_series() {
    use fretdyn::contact::friction::Coulomb;
    use fretdyn::contact::obstacle::{Obstacle, Plane};
    use fretdyn::contact::preload::{Preload, PreloadInput};
    use fretdyn::contact::{Contact, NormalLaw};
    use fretdyn::model::Model;
    use fretdyn::model::preload::apply_preloads;
    use fretdyn::structure::modal::ModalBasis;
    use nalgebra::Vector3;
    let (ma, mb, ka, kb, k) = (2.0, 3.0, 4e5, 9e5, 1e6);
    let body = |m: f64, kx: f64, x: f64| {
        let mut basis = ModalBasis::point_mass(m, "p", Vector3::new(x, 0.0, 0.0)).expect("mass");
        basis.omega = vec![(kx / m).sqrt(), 1e3, 1e3];
        basis.damping_ratio = vec![0.0; 3];
        Model::new(basis)
    };
    let series = 1.0 / k + 1.0 / ka + 1.0 / kb;
    for input in [PreloadInput::Interference(1e-4), PreloadInput::Force(30.0)] {
        let mut model = Model::union(vec![
            ("a".to_string(), body(ma, ka, 0.0)),
            ("b".to_string(), body(mb, kb, -0.1)),
        ])
        .expect("two bodies");
        // in relative coordinates x_A − x_B: the plane through the rest position, normal
        // from B to A
        let plane =
            Plane::new(Vector3::new(0.1, 0.0, 0.0), Vector3::x(), 0.0, None, "o").expect("plane");
        let mut contact = Contact::between(
            "ab",
            0,
            1,
            &model.basis.points,
            [0.0, 0.0],
            Obstacle::Plane(plane),
            NormalLaw::new(k, 0.0, "n").expect("law"),
            Coulomb::new(0.3, 0.3, "f").expect("friction"),
        )
        .expect("pair");
        contact.preload = Some(Preload::new(input, "p").expect("preload"));
        model.contacts.push(contact);
        let state = apply_preloads(&mut model)
            .expect("equilibrium")
            .expect("a preload");
        let (interference, force) = model.contacts[0].preload.and_then(|p| p.applied).unwrap();
        let (d, f) = match input {
            PreloadInput::Interference(d) => (d, d / series),
            PreloadInput::Force(f) => (f * series, f),
        };
        assert!(relative(interference, d) <= 1e-12, "{interference} vs {d}");
        assert!(relative(force, f) <= 1e-12, "{force} vs {f}");
        // A pushed along +x by F/k_A, B along −x by F/k_B (q = √m u)
        assert!(relative(state.q[0] / ma.sqrt(), f / ka) <= 1e-12);
        assert!(relative(state.q[3] / mb.sqrt(), -f / kb) <= 1e-12);
        assert_eq!(model.initial.q, state.q);
        // applied once: a second call changes nothing
        assert!(apply_preloads(&mut model).expect("nothing to do").is_none());
    }
}
