//! **Applications** built on the stages, apart from the physics: they run cases, they add no
//! equation.
//!
//! - [`study`]: parameter studies — one case file, a grid of values, one run per point;
//!   parameters drawn from distributions ([`sampling`]) and percentiles across the draws
//!   ([`percentiles`]);
//! - [`verification`]: the verification cases against closed forms (THEORY §6,
//!   `docs/VERIFICATION.md`);
//! - [`benchmark`]: the step-speed benchmark case (`docs/PERFORMANCE.md`);
//! - [`life`]: the service life — wear depth over years with the scars fed back (THEORY §14.5).

pub mod benchmark;
pub mod life;
pub mod percentiles;
pub mod sampling;
pub mod study;
pub mod verification;
