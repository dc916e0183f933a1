//! Projected (block) Gauss–Seidel on the tangential problem (THEORY §4.4, paper Algorithm 3).
//!
//! Sweep over the closed contacts; for each, solve its 2 × 2 block problem exactly with the
//! others frozen, `λ_i ← local(H_ii, b_i − Σ_{j≠i} H_ij λ_j)`, until
//! `‖λ^{k+1} − λ^k‖ ≤ tol ‖λ^{k+1}‖` and the natural-map residual (THEORY §4.2) is at most
//! `residual_tolerance`, or `max_sweeps`. The residual test catches the slow crawl of
//! Gauss–Seidel on a near-singular `H`, where the change per sweep is tiny far from the
//! solution (with the exact local solve; the paper's radial one is stopped by the change
//! test alone). Statuses play no role in the iteration; they are read off the last local solves.

use nalgebra::Vector2;

use super::GaussSeidelSettings;
use crate::contact::delassus::TangentialProblem;
use crate::contact::friction::{LocalSolve, Slide, local_solve_block};

/// Result of one solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweeps {
    /// Sweeps performed.
    pub count: usize,
    /// Whether both tolerances were met.
    pub converged: bool,
    /// Natural-map residual of the returned λ when it was evaluated (the change test passed).
    pub residual: Option<f64>,
}

/// Solves the tangential problem from the λ given (warm start) and writes the statuses.
pub fn solve(
    settings: &GaussSeidelSettings,
    problem: &TangentialProblem,
    lambda: &mut [Vector2<f64>],
    slide: &mut [Slide],
) -> Sweeps {
    let m = problem.len();
    if m == 1 && settings.local_solve == LocalSolve::Radial && settings.max_sweeps >= 2 {
        if let Some(sweeps) = solve_single_radial(settings, problem, lambda, slide) {
            return sweeps;
        }
    }
    let mut residual = None;
    for sweep in 1..=settings.max_sweeps {
        let mut diff2 = 0.0;
        let mut norm2 = 0.0;
        for (k, slot) in problem.slots().iter().enumerate() {
            let c = problem.local_rhs(k, &lambda[..m]);
            let (new, st) = local_solve_block(
                problem.diagonal_block(k),
                &c,
                slot.s_static,
                slot.s_dynamic,
                settings.local_solve,
                problem.newton_start(k),
            );
            let change = new - lambda[k];
            problem.record_sweep(k, c, change);
            diff2 += change.norm_squared();
            norm2 += new.norm_squared();
            lambda[k] = new;
            slide[k] = st;
        }
        if diff2 <= settings.tolerance * settings.tolerance * norm2 || diff2 == 0.0 {
            // The radial local solve does not satisfy Coulomb's law when H_ii is not
            // isotropic: its fixed point is not a zero of the residual, so only the change
            // test applies to it.
            let r = problem.natural_map_residual_after_sweep(&lambda[..m], &slide[..m]);
            residual = Some(r);
            if r <= settings.residual_tolerance || settings.local_solve == LocalSolve::Radial {
                return Sweeps {
                    count: sweep,
                    converged: true,
                    residual,
                };
            }
        } else if m == 1
            && settings.local_solve == LocalSolve::Radial
            && sweep < settings.max_sweeps
            && norm2.is_finite()
        {
            // A single contact: the next sweep solves the same local problem (no other λ
            // changed its right-hand side), and the radial solve returns the same λ, a
            // change of exactly 0 that passes the test. It is counted, not recomputed
            // (THEORY §4.4).
            let [c, _] = problem.recorded_sweep(0);
            problem.record_sweep(0, c, Vector2::zeros());
            return Sweeps {
                count: sweep + 1,
                converged: true,
                residual: Some(problem.natural_map_residual_after_sweep(&lambda[..m], &slide[..m])),
            };
        } else {
            residual = None;
        }
    }
    Sweeps {
        count: settings.max_sweeps,
        converged: false,
        residual,
    }
}

/// [`solve`] of a single closed contact with the radial local solve, the common case of a
/// rattling structure, without the loops: its local problem's right-hand side is `b` whatever
/// the λ (no other contact), so the first sweep gives the solution and a second sweep, when
/// the first one's change does not pass the test, would return the same λ with a change of
/// exactly 0 (counted, not recomputed: THEORY §4.4). The same operations as the loop of
/// [`solve`], so the same bits and counts. `None` (λ and statuses as given) when the first
/// sweep's λ is not finite: [`solve`] then runs its loop.
#[inline]
fn solve_single_radial(
    settings: &GaussSeidelSettings,
    problem: &TangentialProblem,
    lambda: &mut [Vector2<f64>],
    slide: &mut [Slide],
) -> Option<Sweeps> {
    let slot = &problem.slots()[0];
    // local_rhs(0, λ) of a single contact: b_0, nothing subtracted
    let c = problem.rhs(0);
    let (new, st) = local_solve_block(
        problem.diagonal_block(0),
        &c,
        slot.s_static,
        slot.s_dynamic,
        LocalSolve::Radial,
        problem.newton_start(0),
    );
    let change = new - lambda[0];
    let (diff2, norm2) = (change.norm_squared(), new.norm_squared());
    let count = if diff2 <= settings.tolerance * settings.tolerance * norm2 || diff2 == 0.0 {
        problem.record_sweep(0, c, change);
        1
    } else if norm2.is_finite() {
        problem.record_sweep(0, c, Vector2::zeros());
        2
    } else {
        return None;
    };
    lambda[0] = new;
    slide[0] = st;
    Some(Sweeps {
        count,
        converged: true,
        residual: Some(problem.natural_map_residual_after_sweep(&lambda[..1], &slide[..1])),
    })
}
