//! The step compiled for AVX2 and FMA ([`Simulation::step`] picks it at run time) does the
//! same operations in the same order as the portable code, on wider vectors: the results must
//! be the same bit for bit. (On a processor without AVX2 both runs take the portable code and
//! the test compares it with itself.)

use fretdyn::apps::benchmark::{methods, rattling_tube};
use fretdyn::integrator::simulation::Simulation;

#[test]
fn avx2_and_portable_steps_give_the_same_bits() {
    for method in methods() {
        // 23 modes: the vector loops have a remainder; 6 contacts rattling with friction
        let case = rattling_tube(23, 6, method, 20_000);
        let run = |portable: bool| {
            let mut sim = Simulation::new(&case.model, &case.settings).expect("valid case");
            if portable {
                fretdyn::testing::use_portable_kernels(&mut sim);
            }
            while sim.steps_done() < case.settings.steps {
                sim.step().expect("the run does not diverge");
            }
            sim.finish(0.0, fretdyn::integrator::simulation::Termination::Completed)
        };
        let (wide, portable) = (run(false), run(true));
        let name = method.name();
        assert!(
            wide.solver.lagrange_steps > 1000 || !method.is_lagrange(),
            "{name}: the run should have closed contacts: {:?}",
            wide.solver
        );
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        let r = (&wide.recorder, &portable.recorder);
        assert_eq!(
            bits(r.0.q.as_slice().unwrap()),
            bits(r.1.q.as_slice().unwrap()),
            "{name}: q"
        );
        assert_eq!(
            bits(r.0.qdot.as_slice().unwrap()),
            bits(r.1.qdot.as_slice().unwrap()),
            "{name}: q̇"
        );
        assert_eq!(wide.contacts, portable.contacts, "{name}: statistics");
        assert_eq!(wide.energy, portable.energy, "{name}: energy balance");
        assert_eq!(wide.solver, portable.solver, "{name}: solver counters");
    }
}
