//! [`Simulation::steps`] runs up to `n` steps with the code chosen once; it must give the
//! results of `n` calls of [`Simulation::step`], bit for bit, and stop early where the caller
//! has work to do: a full recorder (to be drained), a divergence (the steps before it kept).

use fretdyn::apps::benchmark::{methods, rattling_tube};
use fretdyn::integrator::simulation::{RunResults, Simulation, Termination};

/// Runs `case` to its end with a recorder of 7 samples, in batches of `batch` steps
/// (`None`: [`Simulation::step`] one by one); returns the samples of `q` drained from the
/// recorder, in order, and the results.
fn run(case: &fretdyn::Case, batch: Option<u64>) -> (Vec<u64>, RunResults) {
    let mut sim = Simulation::with_recorder(&case.model, &case.settings, 7).expect("valid case");
    let mut samples = Vec::new();
    let total = case.settings.steps;
    while sim.steps_done() < total {
        let before = sim.steps_done();
        match batch {
            None => sim.step().expect("no divergence"),
            Some(n) => {
                let n = n.min(total - before);
                let done = sim.steps(n).expect("no divergence");
                assert_eq!(sim.steps_done(), before + done);
                assert!(done >= 1 && done <= n);
                // a batch stops short only at a full recorder
                assert!(done == n || sim.recorder().is_full(), "{done} of {n}");
            }
        }
        if sim.recorder().is_full() {
            let r = sim.recorder();
            samples.extend(r.q.iter().take(r.len() * r.q.ncols()).map(|v| v.to_bits()));
            sim.recorder_mut().clear();
        }
    }
    (samples, sim.finish(0.0, Termination::Completed))
}

#[test]
fn steps_in_batches_are_the_steps_one_by_one() {
    for method in methods() {
        let case = rattling_tube(23, 6, method, 6_000);
        let (one, r1) = run(&case, None);
        for batch in [1, 37, 1000] {
            let (many, rn) = run(&case, Some(batch));
            let name = method.name();
            assert!(
                one.len() > 10 * 23,
                "{name}: the recorder was drained several times"
            );
            assert_eq!(one, many, "{name}, batches of {batch}: the samples of q");
            assert_eq!(r1.contacts, rn.contacts, "{name}: statistics");
            assert_eq!(r1.energy, rn.energy, "{name}: energy balance");
            assert_eq!(r1.solver, rn.solver, "{name}: solver counters");
            assert_eq!(r1.steps, rn.steps);
        }
    }
}

#[test]
fn a_batch_stops_at_a_divergence_and_keeps_the_steps_before_it() {
    let gs = methods()[2];
    let mut case = rattling_tube(10, 3, gs, 100_000);
    // loads 1e150 times the tube's: the state overflows the bound of the sums after some steps
    for load in &mut case.model.loads {
        load.force *= 1e150;
    }
    let mut one = Simulation::new(&case.model, &case.settings).unwrap();
    let diverged = loop {
        if let Err(d) = one.step() {
            break d;
        }
    };
    let mut batched = Simulation::new(&case.model, &case.settings).unwrap();
    let d = batched.steps(case.settings.steps).expect_err("it diverges");
    println!("diverged at step {}", d.step);
    assert!(d.step > 1, "a divergence after some steps");
    assert_eq!(d, diverged);
    assert_eq!(
        batched.steps_done(),
        d.step - 1,
        "the steps before it are kept"
    );
    assert_eq!(batched.steps_done(), one.steps_done());
}
