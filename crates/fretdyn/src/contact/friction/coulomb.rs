//! Coulomb's law with static and dynamic coefficients, and the status it gives a contact
//! (THEORY §4): stick inside the static disk, slip on the dynamic circle; the two ways the
//! Gauss–Seidel block update may solve it (THEORY §4.4).

use crate::error::{Error, Result};

/// Friction coefficients, `μ_s ≥ μ_d ≥ 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coulomb {
    /// Static coefficient: sticking holds while `|R_T| ≤ μ_s R_N`.
    pub mu_static: f64,
    /// Dynamic coefficient: sliding force `|R_T| = μ_d R_N`.
    pub mu_dynamic: f64,
}

impl Coulomb {
    /// Validated constructor; `field` prefixes error messages.
    pub fn new(mu_static: f64, mu_dynamic: f64, field: &str) -> Result<Self> {
        if !(mu_dynamic.is_finite() && mu_dynamic >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.mu_dynamic"),
                format!("must be a friction coefficient ≥ 0 (got {mu_dynamic})"),
            ));
        }
        if !(mu_static.is_finite() && mu_static >= mu_dynamic) {
            return Err(Error::invalid(
                format!("{field}.mu_static"),
                format!(
                    "must be ≥ mu_dynamic = {mu_dynamic} (got {mu_static}): static friction is at least the dynamic one"
                ),
            ));
        }
        Ok(Self {
            mu_static,
            mu_dynamic,
        })
    }
}

/// Stick or slip, as decided by a local solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Slide {
    /// Inside the static disk: the tangential velocity is zero.
    Stick,
    /// On the dynamic circle: the force opposes the slip.
    Slip,
}

/// How the Gauss–Seidel block update treats a 2-component block (THEORY §4.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LocalSolve {
    /// Exact solution of the block problem: `λ = s w/|w|` with `w = c − H_ii λ`.
    Exact,
    /// The paper's radial projection of the unconstrained block solution onto the disk.
    Radial,
}

impl LocalSolve {
    /// Its name in case files and summaries: `exact`, `radial`.
    pub fn name(self) -> &'static str {
        match self {
            LocalSolve::Exact => "exact",
            LocalSolve::Radial => "radial",
        }
    }
}
