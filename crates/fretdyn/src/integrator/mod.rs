//! **Stage 6 — the integrator.** What enters: a [`Model`](crate::model::Model) and
//! [`RunSettings`](simulation::RunSettings). What leaves: a run, step by step, into the
//! recorder and statistics of [`crate::accumulate`] (THEORY §2–§4).
//!
//! - [`central_difference`]: the explicit central-difference update of the modal coordinates
//!   (THEORY §2);
//! - [`stability`]: the stable time step `Δt ≤ 2/ω_max` with the contact stiffnesses (THEORY §2);
//! - [`simulation`]: a run — its state (what a checkpoint holds) and workspace, the step's
//!   phases (loads, detection, forces, tangential solve, bookkeeping), the one run loop
//!   [`drive`](simulation::drive) and the in-memory run [`simulate`](simulation::simulate).

pub mod central_difference;
pub mod simulation;
pub mod stability;
