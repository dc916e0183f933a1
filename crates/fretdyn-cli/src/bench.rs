//! `fretdyn bench`: steps per second of V1 and of the synthetic rattling tube, per method.

use fretdyn::benchmark::rattling_tube;
use fretdyn::case::Case;
use fretdyn::simulation::simulate;
use fretdyn::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use fretdyn::verification::V1;

use crate::Failure;

/// Entry point of `fretdyn bench`.
pub fn main(steps: u64, repeat: usize, modes: usize, contacts: usize) -> Result<(), Failure> {
    let methods = [
        TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e6,
            damping: 2000.0,
        }),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
    ];
    println!(
        "machine: {}, {} logical CPUs",
        cpu_model(),
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    println!(
        "fretdyn {} (release build: {})",
        env!("CARGO_PKG_VERSION"),
        !cfg!(debug_assertions)
    );
    println!(
        "| case | method | modes | contacts | steps | best wall time (s) | steps/s | closed-contact steps |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for method in methods {
        let v1 = V1::reference(20.0);
        let mut settings = v1.settings(method, StickVelocity::HalfStep);
        settings.steps = 4000;
        settings.output_every = 4000;
        let case = Case::from_parts("V1a", v1.model(), settings);
        // a V1 run lasts under a millisecond: repeat it more to get a stable best time
        bench_case(&case, 20 * repeat)?;
    }
    for method in methods {
        let mut case = rattling_tube(modes, contacts, method, steps);
        case.settings.output_every = steps.max(1);
        bench_case(&case, repeat)?;
    }
    Ok(())
}

fn bench_case(case: &Case, repeat: usize) -> Result<(), Failure> {
    let mut best = f64::INFINITY;
    let mut closed = 0;
    for _ in 0..repeat.max(1) {
        let r = simulate(&case.model, &case.settings)
            .map_err(|e| Failure::failed(format!("{}: {e}", case.title)))?;
        best = best.min(r.wall_time);
        closed = r.solver.lagrange_steps;
    }
    let s = &case.settings;
    println!(
        "| {} | {} | {} | {} | {} | {:.4} | {:.3e} | {} |",
        case.title,
        s.method.name(),
        case.model.basis.modes(),
        case.model.contacts.len(),
        s.steps,
        best,
        s.steps as f64 / best,
        if s.method.is_lagrange() {
            closed.to_string()
        } else {
            "—".into()
        }
    );
    Ok(())
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}
