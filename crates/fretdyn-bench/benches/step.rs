//! Criterion benchmarks of the time-step loop: V1 (3 modes, 1 contact) and the synthetic
//! rattling tube (50 modes, 8 contacts), each with the three tangential methods, and case S1
//! of the shared perf folder (30 modes, 5 contacts: the case `fretdyn bench --against-c` times
//! against a plain C step) with GS radial, GS exact and the Active Set.
//! Run: cargo bench -p fretdyn-bench --bench step

use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fretdyn::Case;
use fretdyn::apps::benchmark::{methods, rattling_tube};
use fretdyn::apps::verification::V1;
use fretdyn::contact::tangential::StickVelocity;
use fretdyn::integrator::simulation::simulate;

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

criterion_group!(benches, v1, tube, s1);
criterion_main!(benches);
