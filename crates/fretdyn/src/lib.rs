//! # fretdyn
//!
//! Nonlinear vibration of a structure reduced on a modal basis that rattles against obstacles
//! with Coulomb friction, by explicit central differences. The normal contact force is a
//! penalty law; the tangential force is a penalty law or Lagrange multipliers solved by an
//! Active Set method or a projected Gauss–Seidel. What it computes is stated in the
//! repository's `docs/THEORY.md`; "THEORY §n" in the doc comments refers to its sections.
//!
//! Data flow, one module per concept:
//! [`case`] (TOML; a [`tube`] is meshed with [`beam`] elements and reduced by [`eigen`]) →
//! [`model`] ([`modal`] basis, [`contact`]s with their [`obstacle`] and
//! [`friction`], [`load`]s and [`turbulence`]) → [`simulation`] ([`central_difference`]
//! steps, normal penalty, [`tangential`] methods on the [`delassus`] problem) → [`recorder`]
//! and [`statistics`] → [`output`] (`results.npz`, `summary.json`) and [`stream`] (long runs
//! streamed to disk, checkpoints, resume).
//!
//! ```no_run
//! let case = fretdyn::case::Case::from_file("examples/v1a_oblique_impact.toml".as_ref())?;
//! let results = fretdyn::simulation::simulate(&case.model, &case.settings)?;
//! println!("wear work rate {} W", results.contacts[0].wear_work_rate);
//! # Ok::<(), fretdyn::Error>(())
//! ```

// Index loops mirror the equations of THEORY.md; `!(x > y)` is deliberate: it is true for NaN.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod beam;
pub mod benchmark;
pub mod case;
pub mod central_difference;
pub mod contact;
pub mod delassus;
pub mod eigen;
pub mod error;
pub mod friction;
pub mod load;
pub mod modal;
pub mod model;
pub mod motion;
pub mod obstacle;
pub mod output;
pub mod recorder;
pub mod simulation;
pub mod spatial_correlation;
pub mod stability;
pub mod statistics;
pub mod stream;
pub mod study;
pub mod tangential;
pub mod tube;
pub mod turbulence;
pub mod verification;

pub use error::{Error, Result};
