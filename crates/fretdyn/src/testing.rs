//! Hooks for the crate's own tests and benches, behind the cargo feature `testing`: not part
//! of the API (a user's run never needs them).

use crate::integrator::simulation::Simulation;

/// Runs the steps of `sim` with the portable (SSE2 on x86-64) code even when the processor
/// has AVX2: the results must be the same bit for bit.
pub fn use_portable_kernels(sim: &mut Simulation) {
    sim.use_portable_kernels();
}

/// Runs the steps of `sim` with the code compiled for any contact even when the case is the
/// common one: the results must be the same bit for bit.
pub fn use_general_step(sim: &mut Simulation) {
    sim.use_general_step();
}

/// Whether `sim` runs the code compiled for the common case (every obstacle a fixed plane or
/// fixed bars, an undamped normal law, friction by Lagrange multipliers).
pub fn runs_common_step(sim: &Simulation) -> bool {
    sim.runs_common_step()
}
