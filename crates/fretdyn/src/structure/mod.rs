//! **Stage 2 — the structure.** What enters: a beam/tube description or a modal basis file.
//! What leaves: a [`ModalBasis`](modal::ModalBasis) — natural frequencies, damping ratios and
//! the mode-shape rows of the named points (THEORY §1, §7, §9).
//!
//! - [`modal`]: the modal basis and its operations (recombination, projection);
//! - [`basis_file`]: a basis as `.npz` (read, checked, written);
//! - [`beam`]: Euler–Bernoulli/Timoshenko beam finite elements, assembled;
//! - [`tube`]: a tube line on supports, meshed with [`beam`] elements and reduced on its lowest
//!   modes by [`eigen`];
//! - [`eigen`]: the generalised symmetric eigenproblem `K φ = ω² M φ`;
//! - [`constrained`]: the modes of a tube with chosen supports held (support-active modes);
//! - [`line`]: stations and cells along a tube, where line loads and flow forces meet its modes.

pub mod basis_file;
pub mod beam;
pub mod constrained;
pub mod eigen;
pub mod line;
pub mod modal;
pub mod tube;
