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
use crate::contact::friction::{LocalSolve, Slide, local_solve_with};

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
///
/// A single closed contact, the common case of a rattling structure, is solved in line
/// (`solve_single_radial`, `solve_single_exact`); several by the sweeps (`solve_by_sweeps`).
/// A step where a contact's block may be singular ([`TangentialProblem::may_be_singular`])
/// is solved by the sweeps whose local solves and residual handle it (THEORY §4.4); the
/// others by the same code without those tests.
#[inline(always)]
pub fn solve(
    settings: &GaussSeidelSettings,
    problem: &TangentialProblem,
    lambda: &mut [Vector2<f64>],
    slide: &mut [Slide],
) -> Sweeps {
    if problem.may_be_singular() {
        return solve_by_sweeps::<true>(settings, problem, lambda, slide);
    }
    let m = problem.len();
    if m == 1
        && settings.local_solve == LocalSolve::Radial
        && settings.max_sweeps >= 2
        && let Some(sweeps) = solve_single_radial(settings, problem, lambda, slide)
    {
        return sweeps;
    }
    if m == 1
        && settings.local_solve == LocalSolve::Exact
        && settings.max_sweeps >= 2
        && let Some(sweeps) = solve_single_exact(settings, problem, lambda, slide)
    {
        return sweeps;
    }
    solve_by_sweeps::<false>(settings, problem, lambda, slide)
}

/// The sweeps of [`solve`] (module documentation); `SINGULAR` when a block may be singular.
#[inline(never)]
fn solve_by_sweeps<const SINGULAR: bool>(
    settings: &GaussSeidelSettings,
    problem: &TangentialProblem,
    lambda: &mut [Vector2<f64>],
    slide: &mut [Slide],
) -> Sweeps {
    let m = problem.len();
    let mut residual = None;
    for sweep in 1..=settings.max_sweeps {
        let mut diff2 = 0.0;
        let mut norm2 = 0.0;
        for (k, slot) in problem.slots().iter().enumerate() {
            let c = problem.local_rhs(k, &lambda[..m]);
            let (new, st) = local_solve_with::<SINGULAR>(
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
            let r = problem
                .natural_map_residual_after_sweep_with::<SINGULAR>(&lambda[..m], &slide[..m]);
            residual = Some(r);
            if r <= settings.residual_tolerance || settings.local_solve == LocalSolve::Radial {
                return Sweeps {
                    count: sweep,
                    converged: true,
                    residual,
                };
            }
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
/// sweep's λ is not finite: [`solve`] then sweeps ([`solve_by_sweeps`]).
#[inline]
fn solve_single_radial(
    settings: &GaussSeidelSettings,
    problem: &TangentialProblem,
    lambda: &mut [Vector2<f64>],
    slide: &mut [Slide],
) -> Option<Sweeps> {
    let (new, st, count) = single_sweep(settings, problem, lambda[0], LocalSolve::Radial)?;
    lambda[0] = new;
    slide[0] = st;
    Some(Sweeps {
        count,
        converged: true,
        residual: Some(problem.single_residual_after_sweep(new, st)),
    })
}

/// [`solve_single_radial`] with the exact local solve: the first sweep gives the solution (to
/// the Newton's round-off), and a second sweep, when the first one's change does not pass the
/// test, would solve the same local problem with its Newton started from the first one's root
/// and return the same λ to round-off — a few ulps of `|λ|`, a change that passes a tolerance
/// of 1e-14 or more. It is counted, not recomputed (THEORY §4.4). `None` (λ and statuses as
/// given) when the tolerance is below that, the first sweep's λ is not finite or misses the
/// residual tolerance: [`solve`] then sweeps ([`solve_by_sweeps`]).
#[inline]
fn solve_single_exact(
    settings: &GaussSeidelSettings,
    problem: &TangentialProblem,
    lambda: &mut [Vector2<f64>],
    slide: &mut [Slide],
) -> Option<Sweeps> {
    if settings.tolerance < 1e-14 {
        return None;
    }
    let (new, st, count) = single_sweep(settings, problem, lambda[0], LocalSolve::Exact)?;
    let residual = problem.single_residual_after_sweep(new, st);
    if !(residual <= settings.residual_tolerance) {
        return None;
    }
    lambda[0] = new;
    slide[0] = st;
    Some(Sweeps {
        count,
        converged: true,
        residual: Some(residual),
    })
}

/// The first sweep of a single contact from `given`, recorded: its λ, its status and the
/// sweeps counted (1 when its change passes the test, else 2: the second one's change is
/// known); `None` when its λ is not finite.
#[inline(always)]
fn single_sweep(
    settings: &GaussSeidelSettings,
    problem: &TangentialProblem,
    given: Vector2<f64>,
    local_solve: LocalSolve,
) -> Option<(Vector2<f64>, Slide, usize)> {
    let slot = &problem.slots()[0];
    // local_rhs(0, λ) of a single contact: b_0, nothing subtracted
    let c = problem.rhs(0);
    // regular: a singular block is solved by the sweeps (`solve`)
    let (new, st) = local_solve_with::<false>(
        problem.diagonal_block(0),
        &c,
        slot.s_static,
        slot.s_dynamic,
        local_solve,
        problem.newton_start(0),
    );
    let change = new - given;
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
    Some((new, st, count))
}

#[cfg(test)]
pub(crate) mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::contact::delassus::Slot;
    use crate::contact::friction::local_solve_block;

    /// One closed contact on 4 modes whose `H_ii` is anisotropic (ratio ~10), sliding: `b` well
    /// outside the static disk.
    pub(crate) fn single_sliding_contact() -> TangentialProblem {
        let p = 4;
        let a_inv = [0.5, 1.5, 2.0, 0.25];
        let mut problem = TangentialProblem::new(p, 1);
        let tangents = [Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 0.6, 0.8)];
        let rows = [
            1.0, 0.2, -0.3, 0.1, // x
            0.1, 0.3, 0.0, 0.2, // y
            0.0, -0.1, 0.25, 0.05, // z
        ];
        problem.fix_rows(0, &tangents, &rows, |l, out| {
            for i in 0..l.len() {
                out[i] = a_inv[i] * l[i];
            }
        });
        problem.clear();
        let slot = Slot {
            contact: 0,
            s_static: 0.05,
            s_dynamic: 0.04,
        };
        problem.push(slot, &[Vector3::zeros(); 2], &[], &[]);
        problem.assemble(&[0.1, -0.2, 0.3, 0.4], &[1.0, 2.0, -1.0, 0.5], 1e-3, |_| {
            Vector2::zeros()
        });
        let h = problem.block(0, 0);
        let ratio = h.symmetric_eigenvalues().max() / h.symmetric_eigenvalues().min();
        assert!(ratio > 5.0, "H_ii not anisotropic enough: {h}");
        problem
    }

    fn exact(tolerance: f64) -> GaussSeidelSettings {
        GaussSeidelSettings {
            tolerance,
            local_solve: LocalSolve::Exact,
            ..GaussSeidelSettings::default()
        }
    }

    /// A single contact with the exact solve: the sweep that is counted but not recomputed
    /// is the one whose change, computed here as the loop computes it (the same local
    /// problem, its Newton from the first sweep's root), is round-off — the step returns the
    /// first sweep's λ, a few ulps from the second's — and λ is a Coulomb slip solution: on
    /// the circle, along the slip velocity `w = b − Hλ`.
    #[test]
    fn a_single_exact_contact_skips_only_a_sweep_of_round_off() {
        let problem = single_sliding_contact();
        let settings = exact(1e-12);
        let (mut lambda, mut slide) = ([Vector2::zeros()], [Slide::Stick]);
        let sweeps = solve(&settings, &problem, &mut lambda, &mut slide);
        assert_eq!((sweeps.count, sweeps.converged), (2, true));
        assert_eq!(slide, [Slide::Slip]);
        // the two sweeps, computed
        let fresh = single_sliding_contact();
        let (b, newton) = (fresh.rhs(0), fresh.newton_start(0));
        let solve_b = || {
            local_solve_block(
                fresh.diagonal_block(0),
                &b,
                0.05,
                0.04,
                LocalSolve::Exact,
                newton,
            )
        };
        let (first, _) = solve_b();
        let (second, second_slide) = solve_b();
        assert_eq!(lambda[0], first);
        assert_eq!(second_slide, Slide::Slip);
        assert!((second - first).norm() <= 4.0 * f64::EPSILON * first.norm());
        let l = lambda[0];
        assert!((l.norm() - 0.04).abs() <= 4.0 * f64::EPSILON * 0.04);
        let w = b - problem.block(0, 0) * l;
        assert!(l.dot(&w) > 0.0);
        assert!((l.x * w.y - l.y * w.x).abs() <= 1e-14 * l.norm() * w.norm());
        assert!(sweeps.residual.unwrap() <= 1e-14);
        // from its own solution: one sweep
        let again = solve(&settings, &problem, &mut lambda, &mut slide);
        assert_eq!(again.count, 1);
    }
}
