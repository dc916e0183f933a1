//! Steps per second of a case over consecutive chunks of its run, one line of rates (millions
//! of steps per second): how the speed of a shared machine comes and goes within one run.
//! `scripts/states.sh` runs it beside the same measurement of the C step.
//!
//! cargo run --release --example step_rate -- CASE.toml [CHUNKS]

use std::time::Instant;

use fretdyn::Case;
use fretdyn::integrator::simulation::Simulation;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: step_rate CASE.toml [CHUNKS]")?;
    let chunks: u64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(20);
    let case = Case::from_file(std::path::Path::new(&path))?;
    let mut simulation = Simulation::new(&case.model, &case.settings)?;
    let per_chunk = case.settings.steps / chunks.max(1);
    let mut rates = Vec::new();
    for _ in 0..chunks {
        let start = Instant::now();
        for _ in 0..per_chunk {
            simulation
                .step()
                .map_err(|d| format!("diverged at step {} (t = {} s)", d.step, d.time))?;
        }
        rates.push(per_chunk as f64 / start.elapsed().as_secs_f64() / 1e6);
    }
    let line: Vec<String> = rates.iter().map(|r| format!("{r:.3}")).collect();
    println!("{}", line.join(" "));
    Ok(())
}
