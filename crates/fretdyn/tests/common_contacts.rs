//! The phases of the step that visit the contacts are compiled twice: for any contact, and for
//! the common case — every obstacle a fixed plane or fixed bars, an undamped normal law,
//! friction by Lagrange multipliers — in which the other paths are not compiled
//! ([`fretdyn::testing::runs_common_step`]). The two run the same operations in the same order: the
//! results must be the same bit for bit, for every Lagrange method, with planes and with bars,
//! with the AVX2 code and the portable one. The selection itself is checked: a case outside the
//! common one runs the general code.

use fretdyn::Case;
use fretdyn::apps::benchmark::rattling_tube;
use fretdyn::contact::NormalLaw;
use fretdyn::contact::motion::Motion;
use fretdyn::contact::obstacle::{BiPlane, Circle, Obstacle};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, LocalSolve, PenaltySettings, TangentialMethod,
};
use fretdyn::integrator::simulation::{RunResults, Simulation, Termination};
use fretdyn::testing;
use nalgebra::Vector3;

fn lagrange_methods() -> [TangentialMethod; 3] {
    let exact = GaussSeidelSettings {
        local_solve: LocalSolve::Exact,
        ..GaussSeidelSettings::default()
    };
    [
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        TangentialMethod::GaussSeidel(exact),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
    ]
}

/// Runs `case` with the common code or the general one, AVX2 (when the processor has it) or
/// portable; returns the results and whether the common code ran.
fn run(case: &Case, general: bool, portable: bool) -> (RunResults, bool) {
    let mut sim = Simulation::new(&case.model, &case.settings).expect("valid case");
    if general {
        testing::use_general_step(&mut sim);
    }
    if portable {
        testing::use_portable_kernels(&mut sim);
    }
    let common = testing::runs_common_step(&sim);
    while sim.steps_done() < case.settings.steps {
        sim.step().expect("the run does not diverge");
    }
    (sim.finish(0.0, Termination::Completed), common)
}

fn assert_same_bits(a: &RunResults, b: &RunResults, what: &str) {
    // the first value whose bits differ, if any
    let first = |x: &[f64], y: &[f64]| {
        assert_eq!(x.len(), y.len(), "{what}: lengths");
        x.iter()
            .zip(y)
            .position(|(u, v)| u.to_bits() != v.to_bits())
    };
    let (ra, rb) = (&a.recorder, &b.recorder);
    let q = first(ra.q.as_slice().unwrap(), rb.q.as_slice().unwrap());
    assert_eq!(q, None, "{what}: q differs (first index)");
    let qd = first(ra.qdot.as_slice().unwrap(), rb.qdot.as_slice().unwrap());
    assert_eq!(qd, None, "{what}: q̇ differs (first index)");
    assert_eq!(a.contacts, b.contacts, "{what}: statistics");
    assert_eq!(a.impacts, b.impacts, "{what}: impacts");
    assert_eq!(a.energy, b.energy, "{what}: energy balance");
    assert_eq!(a.solver, b.solver, "{what}: solver counters");
}

/// The origin of a support of [`rattling_tube`] (a plane).
fn plane_origin(obstacle: &Obstacle) -> Vector3<f64> {
    match obstacle {
        Obstacle::Plane(p) => p.origin(),
        _ => panic!("the rattling tube's supports are planes"),
    }
}

/// Bars (two-sided) in place of every other plane: the bars' normal flips with the side.
fn with_bars(mut case: Case) -> Case {
    for (j, c) in case.model.contacts.iter_mut().enumerate() {
        if j % 2 == 1 {
            let origin = plane_origin(&c.obstacle);
            c.obstacle = Obstacle::BiPlane(
                BiPlane::new(origin, Vector3::z(), 1e-4, Some(Vector3::x()), "bars")
                    .expect("valid bars"),
            );
        }
    }
    case
}

#[test]
fn common_contacts_step_is_the_general_one() {
    // 23 modes: the vector loops have a remainder; 3 or 6 supports rattling with friction
    // (detection forms 3 contacts' dot products one by one, 6 contacts' four at a time and
    // the last two one by one)
    for (method, supports) in lagrange_methods()
        .into_iter()
        .flat_map(|m| [(m, 3), (m, 6)])
    {
        for bars in [false, true] {
            let mut case = rattling_tube(23, supports, method, 20_000);
            if bars {
                case = with_bars(case);
            }
            let what = format!("{} ({supports} supports, bars: {bars})", method.name());
            for portable in [false, true] {
                let (common, ran_common) = run(&case, false, portable);
                let (general, ran_general) = run(&case, true, portable);
                assert!(
                    ran_common && !ran_general,
                    "{what}: the common code should run"
                );
                assert!(
                    common.solver.lagrange_steps > 1000,
                    "{what}: the run should have closed contacts: {:?}",
                    common.solver
                );
                assert!(
                    common.impacts.len() > 10,
                    "{what}: the supports should be struck"
                );
                assert_same_bits(&common, &general, &format!("{what}, portable: {portable}"));
            }
        }
    }
}

#[test]
fn cases_outside_the_common_one_run_the_general_code() {
    let gs = TangentialMethod::GaussSeidel(GaussSeidelSettings::default());
    let common = |case: &Case| {
        testing::runs_common_step(
            &Simulation::new(&case.model, &case.settings).expect("valid case"),
        )
    };
    assert!(common(&rattling_tube(10, 3, gs, 10)));
    assert!(common(&with_bars(rattling_tube(10, 3, gs, 10))));
    let penalty = TangentialMethod::Penalty(PenaltySettings {
        stiffness: 1e6,
        damping: 0.0,
    });
    assert!(!common(&rattling_tube(10, 3, penalty, 10)), "penalty law");
    let mut damped = rattling_tube(10, 3, gs, 10);
    damped.model.contacts[1].normal = NormalLaw::new(1e6, 10.0, "n").unwrap();
    assert!(!common(&damped), "normal damping");
    let mut moving = rattling_tube(10, 3, gs, 10);
    moving.model.contacts[2].motion = Motion::Velocity(Vector3::new(1e-3, 0.0, 0.0));
    assert!(!common(&moving), "a moving obstacle");
    let mut hole = rattling_tube(10, 3, gs, 10);
    hole.model.contacts[0].obstacle = Obstacle::Circle(
        Circle::new(
            plane_origin(&hole.model.contacts[0].obstacle),
            Vector3::x(),
            1e-4,
            "hole",
        )
        .unwrap(),
    );
    assert!(!common(&hole), "a hole");
}
