//! # fretdyn
//!
//! Nonlinear vibration of a structure reduced on a modal basis that rattles against obstacles
//! with Coulomb friction, by explicit central differences. The normal contact force is a
//! penalty law; the tangential force is a penalty law or Lagrange multipliers solved by an
//! Active Set method or a projected Gauss–Seidel. What it computes is stated in the
//! repository's `docs/THEORY.md`; "THEORY §n" in the doc comments refers to its sections.
//!
//! ## The public API
//!
//! What a user calls is re-exported here, at the root (and all of it in [`prelude`]):
//!
//! | item | what it does |
//! | --- | --- |
//! | [`Case`] | a case file read and built: [`Case::from_file`], [`Case::from_toml_str`]; holds the [`Model`] and the [`RunSettings`] |
//! | [`simulate`] | runs a model in memory and returns its [`RunResults`] (statistics, time histories) |
//! | [`run`], [`resume`] | runs a model streaming its time histories into a folder, with checkpoints ([`StreamSettings`], [`StreamObserver`]); continues a stopped run bit for bit |
//! | [`Study`] | a parameter study or Monte-Carlo sample: a study file, its runs, its table |
//! | [`service_life`] | the service life of a case by its `[life]` settings ([`LifeSettings`], [`LifeResults`]; THEORY §14.5) |
//! | [`Error`], [`Result`] | the one error type of the crate, which names the case key at fault |
//!
//! ```no_run
//! use fretdyn::prelude::*;
//!
//! let case = Case::from_file("examples/v1a_oblique_impact.toml".as_ref())?;
//! let results = simulate(&case.model, &case.settings)?;
//! println!("wear work rate {} W", results.contacts[0].wear_work_rate);
//! # Ok::<(), fretdyn::Error>(())
//! ```
//!
//! The modules below hold the rest (typed settings, the structure, loads and obstacles built
//! by hand, the output files); they follow the data flow, low layers first, and a module
//! imports only lower ones (`docs/ARCHITECTURE.md` has the picture and where to add a new
//! obstacle, load, friction law or statistic):
//!
//! 1. [`structure`] — the modal basis: read from `.npz`, or a tube meshed with beam elements
//!    and reduced by an eigen solve (THEORY §1, §7, §9);
//! 2. [`loads`] — time histories, point and line loads, base acceleration, turbulence and its
//!    spatial correlation (THEORY §8, §10);
//! 3. [`contact`] — obstacles and their motion, the normal penalty law, friction laws and the
//!    tangential methods (THEORY §3, §4, §7, §8; the Delassus problem and the Lagrange
//!    solvers are crate-private);
//! 4. [`wear`] — wear laws and scar geometries, from the wear work rate to the depth of the
//!    scars (THEORY §14, `docs/WEAR.md`);
//! 5. [`model`] — everything the integrator needs, assembled: basis, contacts, loads, initial
//!    state;
//! 6. [`settings`] — plain typed settings of a run, its statistics and a service life;
//! 7. [`accumulate`] — what the step writes: recorder, energy balance, statistics
//!    (THEORY §5, §11);
//! 8. [`integrator`] — central differences, the stability limit and the step loop
//!    (THEORY §2–§4);
//! 9. [`case`] — the input: a TOML case file, its schema by section, and the build of the
//!    structure, loads, contacts and settings from it;
//! 10. [`output`] — the files of a run: `results.npz`, `summary.json`, `contacts.csv`,
//!     streamed runs and checkpoints;
//! 11. [`apps`] — parameter studies, service lives, verification cases: they run cases and
//!     add no physics.
//!
//! With the cargo feature `testing` (the crate's own tests and benches turn it on) the module
//! `testing` (hooks that switch the step's code paths) and the solver internals (`contact::delassus`, `contact::tangential::{active_set,
//! gauss_seidel, penalty}`) are public too; they are not part of the API.

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

pub mod prelude;

// Hooks for the crate's own tests and benches (`--features testing`), not part of the API.
// Without the feature they are compiled but private (`allow(dead_code)` keeps the crate-private
// hooks they call alive too).
#[cfg(feature = "testing")]
pub mod testing;
#[cfg(not(feature = "testing"))]
#[allow(dead_code)]
mod testing;

// The README's Rust example is compiled with the doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
struct ReadmeDoctests;

// The path users take (the crate doc's table; all of it in `prelude`).
pub use apps::life::{LifeResults, LifeSettings, service_life};
pub use apps::study::Study;
pub use case::Case;
pub use error::{Error, Result};
pub use integrator::simulation::{RunResults, RunSettings, simulate};
pub use model::Model;
pub use output::stream::{StreamObserver, StreamSettings, resume, run};
