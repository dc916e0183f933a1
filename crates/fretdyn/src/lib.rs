//! # fretdyn
//!
//! Nonlinear vibration of a structure reduced on a modal basis that rattles against obstacles
//! with Coulomb friction, by explicit central differences. The normal contact force is a
//! penalty law; the tangential force is a penalty law or Lagrange multipliers solved by an
//! Active Set method or a projected Gauss–Seidel. What it computes is stated in the
//! repository's `docs/THEORY.md`; "THEORY §n" in the doc comments refers to its sections.
//!
//! The modules follow the data flow; read them in this order (`docs/ARCHITECTURE.md` has the
//! picture and where to add a new obstacle, load, friction law or statistic):
//!
//! 1. [`case`] — the input: a TOML case file, its schema by section, and the build of the
//!    structure, loads, contacts and settings from it;
//! 2. [`structure`] — the modal basis: read from `.npz`, or a tube meshed with beam elements
//!    and reduced by an eigen solve (THEORY §1, §7, §9);
//! 3. [`loads`] — time histories, point and line loads, base acceleration, turbulence and its
//!    spatial correlation (THEORY §8, §10);
//! 4. [`contact`] — obstacles and their motion, the normal penalty law, friction laws, the
//!    Delassus problem and the tangential methods (THEORY §3, §4, §7, §8);
//! 5. [`model`] — everything the integrator needs, assembled: basis, contacts, loads, initial
//!    state;
//! 6. [`integrator`] — central differences, the stability limit and the step loop
//!    (THEORY §2–§4);
//! 7. [`results`] — recorder, statistics and energy balance, `results.npz`, `summary.json`,
//!    streamed runs and checkpoints (THEORY §5, §11);
//! 8. [`wear`] — after the run: wear laws and scar geometries, from the wear work rate to the
//!    depth of the scars (THEORY §14, `docs/WEAR.md`).
//!
//! The [`apps`] (parameter studies, verification cases, the benchmark) run cases and add no
//! physics. [`Error`] is the one error type of the crate.
//!
//! The main entry points are re-exported here: [`Case`], [`simulate`], [`RunSettings`],
//! [`RunResults`], [`Model`].
//!
//! ```no_run
//! let case = fretdyn::Case::from_file("examples/v1a_oblique_impact.toml".as_ref())?;
//! let results = fretdyn::simulate(&case.model, &case.settings)?;
//! println!("wear work rate {} W", results.contacts[0].wear_work_rate);
//! # Ok::<(), fretdyn::Error>(())
//! ```

// Index loops mirror the equations of THEORY.md; `!(x > y)` is deliberate: it is true for NaN.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

// The stages, in the order of the data flow (not alphabetical: keep it so).
pub mod structure;

pub mod loads;

pub mod contact;

pub mod wear;

pub mod model;

pub mod settings;

pub mod accumulate;

pub mod integrator;

pub mod case;

pub mod output;

pub mod apps;

pub mod error;
pub mod files;
pub(crate) mod numerics;

// The README's Rust example is compiled with the doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
struct ReadmeDoctests;

pub use case::Case;
pub use error::{Error, Result};
pub use integrator::simulation::{RunResults, RunSettings, simulate};
pub use model::Model;
