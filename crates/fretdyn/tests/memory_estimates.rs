//! The memory a case's contacts and random turbulence will take, estimated before anything
//! is allocated (`fretdyn::case::memory`, issue [3.1]), against the bytes a run allocates for
//! them, counted by a global allocator on each test's own thread.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    /// Set on the threads whose allocations are counted.
    static COUNTED: Cell<bool> = const { Cell::new(false) };
    /// Bytes allocated by this thread while counted (each test counts its own).
    static BYTES: Cell<u64> = const { Cell::new(0) };
}

fn count(bytes: usize) {
    if COUNTED.with(|c| c.get()) {
        BYTES.with(|b| b.set(b.get() + bytes as u64));
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Bytes allocated by `f` on this thread.
fn bytes_allocated<T>(f: impl FnOnce() -> T) -> (T, u64) {
    BYTES.with(|b| b.set(0));
    COUNTED.with(|c| c.set(true));
    let out = f();
    COUNTED.with(|c| c.set(false));
    (out, BYTES.with(|b| b.get()))
}

/// What a run allocates for its contacts (`Simulation` with one output sample: the tangential
/// problem's matrices and rows, the solvers' work space, the contacts' states and
/// statistics) is within the estimate the case is checked against before it is built
/// (`fretdyn::case::memory::contact_bytes`), and the estimate is no more than twice it; the
/// same for the turbulence generator (`generator_bytes`). Measured as the difference between
/// 8 and 208 contacts (240 and 40 000 tangential unknowns²): what grows with the contacts.
#[test]
fn the_contacts_and_turbulence_memory_estimates_bound_what_a_run_allocates() {
    use fretdyn::apps::benchmark::rattling_tube;
    use fretdyn::case::memory::{contact_bytes, turbulence_bytes};
    use fretdyn::contact::tangential::{
        ActiveSetSettings, GaussSeidelSettings, PenaltySettings, TangentialMethod,
    };
    use fretdyn::integrator::simulation::Simulation;
    use fretdyn::loads::turbulence::{RandomChannels, Spectrum};

    let p = 24;
    for method in [
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e6,
            damping: 0.0,
        }),
    ] {
        let allocated = |m: usize| {
            let case = rattling_tube(p, m, method, 10);
            let (sim, bytes) = bytes_allocated(|| {
                Simulation::with_recorder(&case.model, &case.settings, 1).map(|_| ())
            });
            sim.unwrap();
            (case.model.basis.modes(), bytes as f64)
        };
        let ((p, small), (_, large)) = (allocated(8), allocated(208));
        let measured = large - small;
        let estimated = contact_bytes(p, 208, &method) - contact_bytes(p, 8, &method);
        eprintln!(
            "{}: {measured} bytes allocated, {estimated} estimated",
            method.name()
        );
        assert!(
            measured <= estimated && estimated <= 2.0 * measured,
            "{}: {measured} bytes allocated for 200 more contacts, {estimated} estimated",
            method.name()
        );
    }

    // turbulence: 40 channels of the cross-flow spectrum up to 200 Hz
    let spectrum = Spectrum::cross_flow(3.0, 750.0, 0.019);
    let load = fretdyn::loads::TurbulentLoad {
        spectrum: spectrum.clone(),
        rows: vec![1.0; 40 * p],
        seed: 1,
        f_max: 200.0,
    };
    let (generator, measured) =
        bytes_allocated(|| RandomChannels::new(&spectrum, 40, 1, 200.0, "t").unwrap());
    let estimated = turbulence_bytes(&load, p) - 8.0 * 40.0 * (p as f64 + 1.0);
    eprintln!(
        "turbulence (L = {}): {measured} bytes allocated, {estimated} estimated",
        generator.filter_length()
    );
    let measured = measured as f64;
    assert!(
        measured <= estimated && estimated <= 2.0 * measured,
        "turbulence: {measured} bytes allocated, {estimated} estimated"
    );
}
