//! Memory of a run's time histories: a run held in memory that would not fit is refused
//! before anything is allocated (not an abort that takes a Python interpreter with it), and a
//! study keeps only the statistics, so that its memory does not grow with the runs' length.
//! Bytes are counted by a global allocator on the test's own thread.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use fretdyn::accumulate::recorder::Recorder;
use fretdyn::apps::study::{Combine, Study};
use fretdyn::case::Case;
use fretdyn::integrator::simulation::simulate;

struct Counting;

/// Bytes allocated on the counted thread.
static BYTES: AtomicU64 = AtomicU64::new(0);

thread_local! {
    static COUNTED: Cell<bool> = const { Cell::new(false) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTED.with(|c| c.get()) {
            BYTES.fetch_add(layout.size() as u64, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if COUNTED.with(|c| c.get()) {
            BYTES.fetch_add(layout.size() as u64, Ordering::Relaxed);
        }
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTED.with(|c| c.get()) {
            BYTES.fetch_add(new_size as u64, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Bytes allocated by `f` on this thread.
fn bytes_allocated<T>(f: impl FnOnce() -> T) -> (T, u64) {
    BYTES.store(0, Ordering::Relaxed);
    COUNTED.with(|c| c.set(true));
    let out = f();
    COUNTED.with(|c| c.set(false));
    (out, BYTES.load(Ordering::Relaxed))
}

const V1A: &str = include_str!("../../../examples/v1a_oblique_impact.toml");

fn examples() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples"))
}

/// V1a (3 modes, 1 contact: 8 + 16·3 + 65 = 121 bytes per sample) for `duration` seconds of
/// 1e-6 s steps, every step kept.
fn v1a(duration: &str) -> String {
    let text = V1A.replace("duration = 4e-3", &format!("duration = {duration}"));
    assert!(text.contains(duration));
    text
}

#[test]
fn a_history_larger_than_the_memory_is_refused_and_a_study_keeps_none() {
    assert_eq!(Recorder::bytes_per_sample(3, 1), 121);

    // 1e10 steps: 1.2 TB of time histories, more than any machine this runs on
    let case = Case::from_toml_str(&v1a("1e4"), examples()).unwrap();
    assert_eq!(case.settings.steps, 10_000_000_000);
    let (result, bytes) = bytes_allocated(|| simulate(&case.model, &case.settings));
    let message = result.unwrap_err().to_string();
    for needle in ["output.every", "1.2 TB", "fretdyn run"] {
        assert!(message.contains(needle), "'{needle}' not in: {message}");
    }
    assert!(bytes < 1 << 20, "{bytes} bytes allocated for a refused run");
    // a few samples, even twice (the Python package copies them into numpy arrays), fit
    assert!(Recorder::check_memory(1000, 3, 1, 2).is_ok());

    // a study run of 2e6 steps: the in-memory run allocates its 242 MB of histories, the
    // study's run only the statistics, which are the same
    let base: toml::Value = toml::from_str(&v1a("2.0")).unwrap();
    let study = Study {
        base,
        base_dir: examples().to_path_buf(),
        combine: Combine::Grid,
        parameters: Vec::new(),
        seeds: Vec::new(),
        plot: None,
        sampling: None,
        percentiles: None,
    };
    let run = &study.runs()[0];
    let case = study.case(run).unwrap();
    let history = 2_000_001 * 121;
    let (full, bytes_full) = bytes_allocated(|| simulate(&case.model, &case.settings).unwrap());
    assert!(bytes_full >= history, "{bytes_full}");
    let (row, bytes_row) = bytes_allocated(|| study.run_row(run).unwrap());
    assert!(
        bytes_row < history / 100,
        "the study's run allocated {bytes_row} bytes for {history} bytes of histories"
    );
    let (stats, _) = bytes_allocated(|| fretdyn::apps::study::run_statistics(&case).unwrap());
    assert_eq!(stats.contacts, full.contacts);
    assert_eq!(stats.solver, full.solver);
    assert_eq!(stats.energy, full.energy);
    assert_eq!(stats.steps, full.steps);
    // the row has the run's statistics: one impact
    let header = study.header(&study.contact_names());
    let column = header
        .split(',')
        .position(|c| c == "plane.impacts_per_second")
        .unwrap();
    let value: f64 = row.split(',').nth(column).unwrap().parse().unwrap();
    assert_eq!(value, full.contacts[0].impacts_per_second);
}
