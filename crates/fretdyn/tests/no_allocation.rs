//! The time-step loop allocates nothing, random turbulence included: a run of 10× more steps
//! makes exactly as many heap allocations (all of them in the set-up and in the results), counted by a global allocator
//! on each test's own thread only (the test harness allocates on its main thread meanwhile,
//! and the tests run in parallel).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use fretdyn::apps::benchmark::rattling_tube;
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, TangentialMethod,
};
use fretdyn::integrator::simulation::simulate;

struct Counting;

thread_local! {
    /// Set on the threads whose allocations are counted.
    static COUNTED: Cell<bool> = const { Cell::new(false) };
    /// The allocations of this thread (each test counts its own: they run in parallel).
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    if COUNTED.with(|c| c.get()) {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
    }
}

fn allocations() -> usize {
    ALLOCATIONS.with(|a| a.get())
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_of_run(
    method: TangentialMethod,
    steps: u64,
    (turbulence, fluid): (bool, bool),
) -> (usize, u64) {
    let mut case = rattling_tube(10, 4, method, steps);
    case.settings.output_every = 100;
    if fluid {
        // a delayed fluid stiffness (37.3 steps: the ring buffer wraps many times) and a
        // dense and a diagonal one without delay, a fluid damping
        use fretdyn::loads::fluid_elastic::{DelayedStiffness, FluidElastic, ModalMatrix};
        let p = case.model.basis.modes();
        let small = |k: usize| ((k % 5) as f64 - 2.0) * 0.5;
        case.model.fluid_elastic = Some(FluidElastic {
            delayed: vec![
                DelayedStiffness {
                    name: "a".into(),
                    delay: 37.3 * case.settings.dt,
                    stiffness: ModalMatrix::Dense((0..p * p).map(small).collect()),
                },
                DelayedStiffness {
                    name: "b".into(),
                    delay: 0.0,
                    stiffness: ModalMatrix::Diagonal((0..p).map(small).collect()),
                },
            ],
            damping: vec![ModalMatrix::Dense((0..p * p).map(small).collect())],
        });
    }
    if turbulence {
        // 3 random channels on the modes, sampled at 80 kHz: 20 000 steps cross several
        // blocks of the generator
        let p = case.model.basis.modes();
        case.model.turbulence.push(fretdyn::loads::TurbulentLoad {
            spectrum: fretdyn::loads::turbulence::Spectrum::Table {
                frequency_hz: vec![5e3, 1e4],
                psd: vec![1.0, 1.0],
            },
            rows: (0..3 * p).map(|i| 0.1 * ((i % 7) as f64 - 3.0)).collect(),
            seed: 1,
            f_max: 1e4,
        });
        let load = &case.model.turbulence[0];
        let g =
            fretdyn::loads::turbulence::RandomChannels::new(&load.spectrum, 3, 1, load.f_max, "t")
                .unwrap();
        let samples = 20_000.0 * case.settings.dt * g.sample_rate();
        assert!(
            samples > 2.0 * g.block_length() as f64,
            "{samples} samples, blocks of {}",
            g.block_length()
        );
    }
    let before = allocations();
    let r = simulate(&case.model, &case.settings).expect("valid case");
    (allocations() - before, r.solver.lagrange_steps)
}

#[test]
fn the_step_loop_does_not_allocate() {
    COUNTED.with(|c| c.set(true));
    for method in [
        TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e6,
            damping: 10.0,
        }),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
    ] {
        for (turbulence, fluid) in [(false, false), (true, false), (false, true)] {
            let (short, _) = allocations_of_run(method, 2_000, (turbulence, fluid));
            let (long, contact_steps) = allocations_of_run(method, 20_000, (turbulence, fluid));
            assert!(
                method.is_lagrange() == (contact_steps > 1000),
                "{}: the run must exercise the contact solver ({contact_steps} steps)",
                method.name()
            );
            assert!(short > 0, "the counter sees the set-up's allocations");
            assert_eq!(
                short,
                long,
                "{} (turbulence {turbulence}, fluid-elastic {fluid}): {short} allocations for 2 000 steps, {long} for 20 000",
                method.name()
            );
        }
    }
}

/// Closing a block (a batch of the standard errors, THEORY §5) allocates nothing in the
/// step loop: 200 blocks of 100 steps, and a target relative error checked at each of
/// them (too small to be met), counted over the steps only.
#[test]
fn closing_blocks_does_not_allocate() {
    use fretdyn::integrator::simulation::Simulation;
    COUNTED.with(|c| c.set(true));
    let method = TangentialMethod::ActiveSet(ActiveSetSettings::default());
    for target in [None, Some(1e-9)] {
        let mut case = rattling_tube(10, 4, method, 20_000);
        case.settings.output_every = 100;
        case.settings.statistics.block = Some(100.0 * case.settings.dt);
        case.settings.statistics.target_relative_error = target;
        let mut sim = Simulation::new(&case.model, &case.settings).expect("valid case");
        let before = allocations();
        while sim.steps_done() < case.settings.steps {
            sim.step().expect("no divergence");
        }
        let during = allocations() - before;
        assert_eq!(sim.target_met(), None);
        let r = sim.finish(0.0, fretdyn::integrator::simulation::Termination::Completed);
        assert_eq!(r.blocks.len(), 200 * 4, "200 blocks of 4 contacts");
        assert_eq!(r.contacts[0].errors.batches, 200);
        assert_eq!(during, 0, "target {target:?}: allocations in the step loop");
    }
}
