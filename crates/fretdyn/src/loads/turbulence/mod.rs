//! Random turbulence loads: a one-sided power spectral density of a force per unit length
//! ([`Spectrum`]) and `r` independent stationary Gaussian signals with that spectrum that are a
//! pure function of time ([`RandomChannels`]). Their spatial correlation along the tube is
//! [`crate::loads::spatial_correlation`]. `docs/LOADS.md`, section "Random turbulence", states the
//! models, their sources and the measured accuracy.
//!
//! The nodal turbulent force is
//!
//! ```text
//! F_i(t) = Σ_j L_ij ξ_j(t),      L Lᵀ ≈ C,   C_ik = ∫∫ N_i(s) N_k(s') exp(−|s − s'| / λ) ds ds'
//! ```
//!
//! with `ξ_j` the unit-less channels of [`RandomChannels`] (one-sided PSD `S(f)`), so that the
//! cross-PSD of the nodal forces is `S(f) C_ik` (`N_i` the shape function of node `i`).
//!
//! - [`spectrum`]: the spectra `S(f)` — a table, or the cross-flow model of Code_Aster;
//! - [`generator`]: the signals with a spectrum, by filtering a white noise drawn from the
//!   crate's one random generator ([`crate::numerics::rng`]).

mod generator;
mod spectrum;

pub use generator::{DEFAULT_OVERSAMPLING, GeneratorSettings, RandomChannels, generator_bytes};
pub use spectrum::Spectrum;
