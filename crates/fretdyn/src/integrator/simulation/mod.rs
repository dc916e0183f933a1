//! A run: central differences on the modes, contacts on the physical basis at the contact
//! points only, tangential forces by the chosen method (THEORY §2, steps 1–7).
//!
//! - [`Simulation`] (`step`): a run in progress, its [`State`] (`state`, `contact_state`:
//!   what a checkpoint holds, serialised as it is) and its workspace (`workspace`: what is
//!   rebuilt from the model), and the step; the step's phases, each an `impl Simulation`
//!   block in its own file: `loads`, `detection`, `forces` with `penalty`, `lagrange`,
//!   `bookkeeping`; `contact_kinds`, the contacts the step is compiled for;
//! - [`drive`] (`drive`): the run loop, one for every kind of run, with its [`BatchSink`];
//! - `run`: runs in memory ([`simulate`], [`run`]) and for their statistics
//!   ([`statistics_run`]); `results`: what a run produces ([`RunResults`], [`Termination`]).

mod bookkeeping;
mod contact_kinds;
mod contact_state;
mod detection;
mod drive;
mod forces;
mod lagrange;
mod loads;
mod penalty;
mod results;
mod run;
mod state;
mod step;
mod workspace;

pub use crate::settings::RunSettings;
pub use drive::{BatchEnd, BatchSink, Driven, drive};
pub use results::{Divergence, Progress, RunResults, Termination};
pub use run::{run, simulate, statistics_run, statistics_run_from, statistics_run_until};
pub use state::{Snapshot, State};
pub use step::Simulation;
