//! Projected (block) Gauss–Seidel on the tangential problem (THEORY §4.4, paper Algorithm 3).
//!
//! Sweep over the closed contacts; for each, solve its 2 × 2 block problem exactly with the
//! others frozen, `λ_i ← local(H_ii, b_i − Σ_{j≠i} H_ij λ_j)`, until
//! `‖λ^{k+1} − λ^k‖ ≤ tol ‖λ^{k+1}‖` or `max_sweeps`. Statuses play no role in the iteration;
//! they are read off the last local solves.

use nalgebra::Vector2;

use super::GaussSeidelSettings;
use crate::delassus::TangentialProblem;
use crate::friction::{Slide, local_solve};

/// Result of one solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sweeps {
    /// Sweeps performed.
    pub count: usize,
    /// Whether the tolerance was met.
    pub converged: bool,
}

/// Solves the tangential problem from the λ given (warm start) and writes the statuses.
pub fn solve(
    settings: &GaussSeidelSettings,
    problem: &TangentialProblem,
    lambda: &mut [Vector2<f64>],
    slide: &mut [Slide],
) -> Sweeps {
    let m = problem.len();
    for sweep in 1..=settings.max_sweeps {
        let mut diff2 = 0.0;
        let mut norm2 = 0.0;
        for (k, slot) in problem.slots().iter().enumerate() {
            let c = problem.local_rhs(k, &lambda[..m]);
            let (new, st) = local_solve(
                &problem.block(k, k),
                &c,
                slot.s_static,
                slot.s_dynamic,
                settings.local_solve,
            );
            diff2 += (new - lambda[k]).norm_squared();
            norm2 += new.norm_squared();
            lambda[k] = new;
            slide[k] = st;
        }
        if diff2 <= settings.tolerance * settings.tolerance * norm2 || diff2 == 0.0 {
            return Sweeps {
                count: sweep,
                converged: true,
            };
        }
    }
    Sweeps {
        count: settings.max_sweeps,
        converged: false,
    }
}
