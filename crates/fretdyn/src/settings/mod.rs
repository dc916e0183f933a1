//! **Settings** — plain data, checked but not parsed here (the case file's sections build them
//! in [`crate::case`]): how a run steps and what it accumulates, how a service life proceeds.
//!
//! - [`run`]: [`RunSettings`] — Δt, steps, the tangential method, output sampling, the
//!   displacement [`Monitor`]s;
//! - [`statistics`]: the statistics window, its blocks and impact definition (THEORY §5, §11);
//! - [`life`]: the `[life]` section of a service life (THEORY §14.5).

pub mod life;
pub mod run;
pub mod statistics;

pub use run::{Monitor, RunSettings};
