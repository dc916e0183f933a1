//! **Stage 7 — the results.** What enters: the state of each step (sampled histories, contact
//! forces, energies). What leaves: `results.npz`, `summary.json`, streamed series and
//! checkpoints (THEORY §5, §11).
//!
//! - [`recorder`]: the sampled time histories kept in memory;
//! - [`statistics`]: per-contact wear work rate, impacts, slip, blocks (THEORY §5, §11);
//! - [`energy`]: the discrete energy balance (THEORY §5);
//! - [`output`]: `results.npz` and `summary.json`;
//! - [`contacts_table`]: `contacts.csv`, the per-contact statistics as a table;
//! - [`stream`]: long runs streamed to disk by chunks, checkpoints and resume;
//! - `netcdf` (feature `netcdf`): `results.nc`, the time histories with names and units;
//! - [`wear_map`]: where each contact's friction work is done, for the service life;
//! - [`variables`]: names, dimensions, units and long names of the time histories.
//!
//! The step loop ([`crate::integrator`]) writes into [`recorder`], [`statistics`] and [`energy`];
//! [`output`] and [`stream`] read the finished or running simulation.

pub mod contacts_table;
pub mod energy;
#[cfg(feature = "netcdf")]
pub mod netcdf;
pub mod output;
pub mod recorder;
pub mod statistics;
pub mod stream;
pub mod variables;
pub mod wear_map;
