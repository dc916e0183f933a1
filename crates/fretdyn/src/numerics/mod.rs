//! The numerics below the physics, crate-private, one concept per file: the reduction kernels
//! of the time step ([`Lanes`], summed in four lanes: [`lanes`]) in plain Rust ([`Portable`])
//! and on AVX2 ([`Avx2`], whose intrinsics are [`avx2_intrinsics`]); the rows laid out for
//! them ([`PaddedRows`]); the small kernels of the step ([`running_max`], [`running_min`],
//! [`map3`]); the dense factorisations of the Delassus matrix ([`dense`]); and the one random
//! generator ([`rng`]). Nothing here knows of modes, contacts or loads.

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx2_intrinsics;
pub(crate) mod dense;
mod elementwise;
mod extrema;
mod lanes;
mod padded;
mod portable;
pub(crate) mod rng;

#[cfg(target_arch = "x86_64")]
pub(crate) use avx2::Avx2;
pub(crate) use elementwise::map3;
pub(crate) use extrema::{running_max, running_min};
pub(crate) use lanes::Lanes;
pub(crate) use padded::PaddedRows;
pub(crate) use portable::{Portable, energy_sums};
