//! Criterion benchmarks of the time-step loop: V1 (3 modes, 1 contact) and the synthetic
//! rattling tube (50 modes, 8 contacts), each with the three tangential methods.
//! Run: cargo bench -p fretdyn-bench --bench step

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
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

criterion_group!(benches, v1, tube);
criterion_main!(benches);
