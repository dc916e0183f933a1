//! **Stage 7 — what the step writes.** What enters: the state of each step (sampled histories,
//! contact forces, energies). What leaves: the recorder, the per-contact statistics and the
//! energy balance that a run's results are made of (THEORY §5, §11). Nothing here writes a
//! file: [`crate::output`] does.
//!
//! - [`recorder`]: the sampled time histories kept in memory;
//! - [`statistics`]: per-contact wear work rate, impacts, slip, blocks (THEORY §5, §11);
//! - [`energy`]: the discrete energy balance (THEORY §5);
//! - [`wear_map`]: where each contact's friction work is done, for the service life;
//! - [`monitor`]: the displacement of points along directions, at the output samples.
//!
//! The step loop ([`crate::integrator`]) writes into all five.

pub mod energy;
pub mod monitor;
pub mod recorder;
pub mod statistics;
pub mod wear_map;
