//! Run settings recording every step, stick imposed on the half-step velocity (THEORY §2).

use fretdyn::contact::tangential::{StickVelocity, TangentialMethod};
use fretdyn::integrator::simulation::RunSettings;

/// `steps` steps of `dt` with `method`, every step recorded.
pub fn every_step(method: TangentialMethod, dt: f64, steps: u64) -> RunSettings {
    RunSettings {
        dt,
        steps,
        method,
        stick_velocity: StickVelocity::HalfStep,
        output_every: 1,
        monitors: Vec::new(),
        statistics: Default::default(),
    }
}
