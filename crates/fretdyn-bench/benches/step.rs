//! Criterion benchmarks of the time-step loop: V1 (3 modes, 1 contact) and the synthetic
//! rattling tube (50 modes, 8 contacts), each with the three tangential methods, and case S1
//! of the shared perf folder (30 modes, 5 contacts: the case `fretdyn bench --against-c` times
//! against a plain C step) with GS radial, GS exact and the Active Set; and one contact's
//! local solve, exact against radial.
//! Run: cargo bench -p fretdyn-bench --bench step

use std::cell::Cell;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fretdyn::Case;
use fretdyn::apps::benchmark::{methods, rattling_tube};
use fretdyn::apps::verification::V1;
use fretdyn::contact::friction::{DiagonalBlock, LocalSolve, local_solve_block};
use fretdyn::contact::tangential::StickVelocity;
use fretdyn::simulate;
use nalgebra::{Matrix2, Vector2};

fn v1(c: &mut Criterion) {
    let mut group = c.benchmark_group("v1a_4000_steps");
    group.throughput(Throughput::Elements(4000));
    let v1 = V1::reference(20.0);
    let model = v1.model();
    for method in methods() {
        let mut settings = v1.settings(method, StickVelocity::HalfStep);
        settings.output_every = 4000;
        group.bench_function(method.name(), |b| {
            b.iter(|| simulate(&model, &settings).expect("V1 runs"))
        });
    }
    group.finish();
}

fn tube(c: &mut Criterion) {
    let steps = 20_000;
    let mut group = c.benchmark_group("tube_50_modes_8_contacts_20000_steps");
    group.throughput(Throughput::Elements(steps));
    group.sample_size(10);
    for method in methods() {
        let mut case = rattling_tube(50, 8, method, steps);
        case.settings.output_every = steps;
        group.bench_function(method.name(), |b| {
            b.iter(|| simulate(&case.model, &case.settings).expect("tube runs"))
        });
    }
    group.finish();
}

/// S1 from `../shared/perf/fretdyn_cases/s1/s1_{method}_2000.toml` (next to the repository),
/// a full in-memory run of 2000 steps; skipped with a note where the folder is absent.
fn s1(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/perf/fretdyn_cases/s1");
    let mut group = c.benchmark_group("s1");
    group.sample_size(20);
    for method in ["gs_radial", "gs_exact", "active_set"] {
        let path = dir.join(format!("s1_{method}_2000.toml"));
        if !path.is_file() {
            eprintln!("note: {} absent: s1/{method} skipped", path.display());
            continue;
        }
        let mut case = match Case::from_file(&path) {
            Ok(case) => case,
            Err(e) => {
                eprintln!("note: {}: s1/{method} skipped", e.in_file(&path));
                continue;
            }
        };
        // two output samples: t = 0 and the last step
        case.settings.output_every = case.settings.steps.max(1);
        group.throughput(Throughput::Elements(case.settings.steps));
        group.bench_function(method, |b| {
            b.iter(|| simulate(&case.model, &case.settings).expect("S1 runs"))
        });
    }
    group.finish();
}

/// One contact's local solve (THEORY §4.4) on a block of S1 (anisotropic: eigenvalues 0.23
/// and 0.31), 1 000 sliding right-hand sides round the circle, each solve's input depending
/// on the previous answer as in a sweep (so the figure is the latency of the solve, which is
/// what a sweep pays): the exact slip solve against the radial projection.
fn local_solve(c: &mut Criterion) {
    let h = Matrix2::new(0.237_883_319, 0.017_070_369, 0.017_070_369, 0.302_367_152);
    let s = 0.036_523_133;
    let rhs: Vec<Vector2<f64>> = (0..1000)
        .map(|i| {
            let a = i as f64 * 0.006_283;
            Vector2::new(30.0 * a.cos(), 30.0 * a.sin())
        })
        .collect();
    let mut group = c.benchmark_group("local_solve_1000_slips");
    group.throughput(Throughput::Elements(rhs.len() as u64));
    for mode in [LocalSolve::Radial, LocalSolve::Exact] {
        let block = DiagonalBlock::new(h);
        group.bench_function(format!("{mode:?}").to_lowercase(), |b| {
            b.iter(|| {
                let mut previous = Vector2::zeros();
                for c in &rhs {
                    // a cold start, as the first sweep of a step
                    let newton = Cell::new(f64::NAN);
                    let c = c + previous * 1e-300;
                    previous = local_solve_block(&block, &c, s, s, mode, &newton).0;
                }
                previous
            })
        });
    }
    group.finish();
}

criterion_group!(benches, v1, tube, s1, local_solve);
criterion_main!(benches);
