//! The tangential problem of the Lagrange methods: the Delassus operator `H = L A⁻¹ Lᵀ` over the
//! closed contacts, the right-hand side `b`, and the friction disks (THEORY §2, §4.2).
//!
//! `L` stacks, for each closed contact `k`, the two rows `t_aᵀ Φ_c` (a = 1, 2). With the stick
//! constraint acting on the velocity `L q̇* + θ Δt L q̈` (θ = 1: half-step velocity, the default;
//! θ = ½: the paper's literal full-step velocity),
//!
//! ```text
//!     γ_imp = (v_imp − L q̇*)/(θ Δt),     b = L q̈_free − γ_imp,     H λ = b  (stick)
//! ```
//!
//! and whatever λ is, the tangential velocity the constraint sees is `v_imp + θ Δt (b − H λ)`.
//! All buffers are sized once for every contact being closed: assembling allocates nothing.
//! The rows of a contact whose tangent basis never changes (a fixed plane) are computed once,
//! and so are the blocks of `H` between two such contacts: a step then only gathers them.
//!
//! One concept, the problem of a step, in three files: its assembly and accessors
//! ([`problem`]), its natural-map residual ([`residual`]), and its stick system with the
//! singularity test ([`stick`], on the dense factorisations of [`crate::numerics::dense`]).

mod problem;
mod residual;
mod stick;

pub use problem::{Slot, TangentialProblem};
