//! **Stage 9 — the files of a run.** What enters: a finished or running simulation and its
//! case. What leaves: `results.npz`, `summary.json`, `contacts.csv`, streamed series,
//! checkpoints and `results.nc` (THEORY §5, §11).
//!
//! - [`summary`]: `results.npz` and `summary.json`;
//! - [`contacts_table`]: `contacts.csv`, the per-contact statistics as a table;
//! - [`stream`]: long runs streamed to disk by chunks, checkpoints and resume;
//! - [`checkpoint`]: `checkpoint.bin`, a streamed run's state and the lengths of its files;
//! - `series`: the `.npy` files a streamed run appends to, packed into `results.npz`;
//! - [`layout`]: the names of a run's files and the `.npy` layout shared by the stream and
//!   `results.nc`;
//! - `netcdf` (feature `netcdf`): `results.nc`, the time histories with names and units;
//! - [`variables`]: names, dimensions, units and long names of the time histories.
//!
//! [`summary`] and [`stream`] read what [`crate::accumulate`] holds.

pub mod checkpoint;
pub mod contacts_table;
pub mod layout;
#[cfg(feature = "netcdf")]
pub mod netcdf;
mod series;
pub mod stream;
pub mod summary;
pub mod variables;
