//! Coulomb friction with static and dynamic coefficients, and the exact solution of one
//! contact's local tangential problem (THEORY §4, §4.4).
//!
//! Sign convention: the tangential multiplier `λ` of a contact is minus the tangential force of
//! the obstacle on the structure in the contact's tangent basis, `R_T = −λ`. Sliding means
//! `λ = μ_d R_N v/|v|` (the force opposes the slip velocity), sticking `|λ| ≤ μ_s R_N`, `v = 0`.
//!
//! - [`coulomb`]: the coefficients and the stick/slip status;
//! - [`block`]: a contact's 2 × 2 diagonal block of the Delassus operator, prepared for its
//!   local solves (inverse, eigen-decomposition, singularity: THEORY §4.4);
//! - [`local_solve`]: the stick/slip solve of one contact with the others frozen;
//! - [`disk_boundary`]: its exact slip solution on the dynamic circle (a secular equation
//!   solved by Newton).

mod block;
mod coulomb;
mod disk_boundary;
mod local_solve;

pub use block::{DiagonalBlock, SINGULAR_RATIO, inverse2, solve2};
pub use coulomb::{Coulomb, LocalSolve, Slide};
pub(crate) use local_solve::local_solve_with;
pub use local_solve::{local_solve, local_solve_block};
