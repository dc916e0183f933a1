//! A time step that resolves impacts too coarsely is flagged (issue 3.1, THEORY §2, §5): before
//! a run when a contact's impacts last fewer than `MIN_STEPS_PER_IMPACT` steps, after it when
//! the energy balance errs by more than `MAX_RELATIVE_ERROR`; each warning gives the time step
//! that fixes it, and that time step does not warn. The impact duration is checked against the
//! closed form of a mass on the penalty spring, and the energy error against a finer run.

use std::f64::consts::PI;
use std::path::Path;

use fretdyn::accumulate::energy::{MAX_RELATIVE_ERROR, energy_time_step, energy_warnings};
use fretdyn::case::Case;
use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::obstacle::{Circle, Obstacle, Plane};
use fretdyn::contact::tangential::{GaussSeidelSettings, StickVelocity, TangentialMethod};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{RunResults, RunSettings, simulate};
use fretdyn::integrator::stability::{
    MIN_STEPS_PER_IMPACT, impact_resolution, impact_resolution_warnings, impact_time_step,
};
use fretdyn::model::Model;
use fretdyn::structure::modal::{ModalBasis, Point};
use nalgebra::Vector3;

const KN: f64 = 1e6;

/// The number written in `text` between `before` and the next " s".
fn number_after(text: &str, before: &str) -> f64 {
    let rest = &text[text
        .find(before)
        .unwrap_or_else(|| panic!("{before:?} in {text}"))
        + before.len()..];
    rest[..rest.find(" s").unwrap()].parse().unwrap()
}

/// Case V1a (THEORY §6): a 1 kg mass thrown at 20° on a plane, K_N = 1e6 N/m, μ = 0.3; an
/// impact lasts `π √(m/K_N)` = 3.14 ms.
fn v1a() -> Model {
    let mut model = Model::new(ModalBasis::point_mass(1.0, "mass", Vector3::zeros()).unwrap());
    model.contacts.push(Contact::new(
        "plane",
        0,
        Obstacle::Plane(
            Plane::new(Vector3::zeros(), Vector3::z(), 0.0, Some(Vector3::x()), "p").unwrap(),
        ),
        NormalLaw::new(KN, 0.0, "n").unwrap(),
        Coulomb::new(0.3, 0.3, "f").unwrap(),
    ));
    let alpha = 20f64.to_radians();
    model.initial.qdot = vec![alpha.sin(), 0.0, -alpha.cos()];
    model
}

fn run(model: &Model, dt: f64) -> RunResults {
    let settings = RunSettings {
        dt,
        steps: (8e-3 / dt).round() as u64,
        method: TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        stick_velocity: StickVelocity::HalfStep,
        output_every: 100,
        monitors: Vec::new(),
        statistics: Default::default(),
    };
    simulate(model, &settings).unwrap()
}

/// The impact's duration is that of the mass on the spring, `π √(m_eff/K_N)`, with the
/// effective mass of the contact point along the normal: `m` for a point mass; for a
/// basis whose two modes move the point along x and y with `a` and `b` (m_eff `1/a²`, `1/b²`),
/// a hole of axis z (normals in the xy plane) takes the most mobile direction, `1/max(a, b)²`,
/// and a plane of normal `(x + y)/√2` the mobility `(a² + b²)/2`; a mode that does not move
/// the point along the normal makes no impact.
#[test]
fn impact_duration_is_that_of_the_effective_mass_on_the_penalty_spring() {
    let mut model = v1a();
    model.basis = ModalBasis::point_mass(2.5, "mass", Vector3::zeros()).unwrap();
    let r = impact_resolution(&model, 1e-5);
    assert_eq!(r.len(), 1);
    assert!((r[0].effective_mass - 2.5).abs() <= 1e-12);
    let duration = PI * (2.5f64 / KN).sqrt();
    assert!((r[0].duration - duration).abs() <= 1e-15);
    assert!((r[0].steps - duration / 1e-5).abs() <= 1e-9);

    let (a, b) = (0.8, 0.3);
    let point = Point {
        name: "p".into(),
        coords: Vector3::zeros(),
        rows: vec![a, 0.0, 0.0, b, 0.0, 0.0],
        rotations: Vec::new(),
    };
    let basis = ModalBasis {
        omega: vec![10.0, 20.0],
        damping_ratio: vec![0.0; 2],
        points: vec![point],
        participation: Vec::new(),
    };
    let mut model = Model::new(basis);
    let contact = |name: &str, obstacle: Obstacle| {
        Contact::new(
            name,
            0,
            obstacle,
            NormalLaw::new(KN, 0.0, "n").unwrap(),
            Coulomb::new(0.3, 0.3, "f").unwrap(),
        )
    };
    let hole = Circle::new(Vector3::zeros(), Vector3::z(), 1e-3, "c").unwrap();
    model.contacts.push(contact("hole", Obstacle::Circle(hole)));
    let diagonal = Vector3::new(1.0, 1.0, 0.0).normalize();
    let plane = Plane::new(Vector3::zeros(), diagonal, 0.0, None, "p").unwrap();
    model
        .contacts
        .push(contact("diagonal", Obstacle::Plane(plane)));
    let floor = Plane::new(Vector3::zeros(), Vector3::z(), 0.0, None, "p").unwrap();
    model
        .contacts
        .push(contact("floor", Obstacle::Plane(floor)));
    let r = impact_resolution(&model, 1e-5);
    assert_eq!(r.len(), 2, "no impact on the floor: {r:?}");
    assert!((r[0].effective_mass - 1.0 / (a * a)).abs() <= 1e-12 / (a * a));
    let diagonal_mass = 2.0 / (a * a + b * b);
    assert!((r[1].effective_mass - diagonal_mass).abs() <= 1e-12 * diagonal_mass);
}

/// Before the run: V1a at 5 steps per impact warns, naming the contact and `time.dt`; at 30
/// it does not; the time step the warning gives resolves the impact with at least 15 steps
/// (and fewer than 16.5: it is the largest one, rounded down to two digits) and does not warn.
#[test]
fn a_coarse_time_step_warns_before_the_run_with_the_one_that_fixes_it() {
    let model = v1a();
    let duration = PI * (1.0f64 / KN).sqrt();
    let warnings = impact_resolution_warnings(&model, duration / 5.0);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let w = &warnings[0];
    assert!(
        w.contains("'plane'") && w.contains("time.dt") && w.contains("5.0 steps"),
        "{w}"
    );
    assert!(!w.contains('\n'), "one line: {w}");
    assert!(impact_resolution_warnings(&model, duration / 30.0).is_empty());
    // at 1.5 steps (above the stable limit 2/ω, π/2 steps) the run is refused: no warning
    assert!(impact_resolution_warnings(&model, duration / 1.5).is_empty());
    assert_eq!(impact_resolution_warnings(&model, duration / 1.6).len(), 1);
    let fixed = impact_time_step(&model).unwrap();
    assert_eq!(number_after(w, "at most "), fixed, "{w}");
    let steps = duration / fixed;
    assert!(
        (MIN_STEPS_PER_IMPACT..1.1 * MIN_STEPS_PER_IMPACT).contains(&steps),
        "{steps} steps per impact at the suggested {fixed} s"
    );
    assert!(impact_resolution_warnings(&model, fixed).is_empty());
}

/// After the run: V1a at 5 steps per impact errs by 8 % of the energy and warns (a run at 300
/// steps errs by `(5/300)²` of that, within a factor 2: the order 2); the time step the
/// warning gives brings the error to about half the threshold (order 2: between 0.25 and 1
/// times the threshold), and does not warn.
#[test]
fn a_coarse_time_step_warns_after_the_run_with_the_one_that_fixes_it() {
    let model = v1a();
    let duration = PI * (1.0f64 / KN).sqrt();
    let coarse = run(&model, duration / 5.0);
    let fine = run(&model, duration / 300.0);
    let (e_coarse, e_fine) = (coarse.energy.relative_error, fine.energy.relative_error);
    assert!(e_coarse > 0.05, "{e_coarse}");
    // order 2: the ratio of the errors is that of the squared time steps, (5/300)²
    let ratio = (e_fine / e_coarse) / (5.0f64 / 300.0).powi(2);
    assert!((0.5..2.0).contains(&ratio), "{e_fine} against {e_coarse}");
    assert!(energy_warnings(&fine.energy, duration / 300.0).is_empty());
    let warnings = energy_warnings(&coarse.energy, duration / 5.0);
    assert_eq!(warnings.len(), 1);
    assert!(
        warnings[0].contains("time.dt") && !warnings[0].contains('\n'),
        "{}",
        warnings[0]
    );
    let fixed = energy_time_step(&coarse.energy, duration / 5.0).unwrap();
    assert_eq!(
        number_after(&warnings[0], "and time.dt = "),
        fixed,
        "{}",
        warnings[0]
    );
    let rerun = run(&model, fixed);
    let error = rerun.energy.relative_error;
    assert!(
        (0.25 * MAX_RELATIVE_ERROR..MAX_RELATIVE_ERROR).contains(&error),
        "at the suggested {fixed} s the error is {error}"
    );
    assert!(energy_warnings(&rerun.energy, fixed).is_empty());
}

/// No shipped example resolves its impacts with fewer than 15 steps: none warns before its
/// run.
#[test]
fn no_shipped_example_warns_on_its_time_step() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if path.extension().is_none_or(|e| e != "toml") || name.starts_with("study_") {
            continue;
        }
        let case = Case::from_file(&path).unwrap();
        let warnings = impact_resolution_warnings(&case.model, case.settings.dt);
        eprintln!(
            "{name}: {:?}",
            impact_resolution(&case.model, case.settings.dt)
                .iter()
                .map(|r| (case.model.contacts[r.contact].name.clone(), r.steps))
                .collect::<Vec<_>>()
        );
        assert!(warnings.is_empty(), "{name}: {warnings:?}");
        checked += 1;
    }
    assert!(checked >= 10, "{checked} examples");
}
