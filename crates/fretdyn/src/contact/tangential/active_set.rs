//! Active Set method on the tangential problem (THEORY §4.3, paper Algorithm 2).
//!
//! Iterates on statuses, not on λ:
//! 1. initial statuses from the previous step (stick stays stick; slip keeps its direction;
//!    a newly closed contact is guessed sliding along `b_i`, §4.5);
//! 2. slip contacts: `λ_i = μ_d R_N,i d_i`;
//! 3. stick contacts: `H_SS λ_S = b_S − H_SF λ_F` by Cholesky (regularised when singular, §4.6;
//!    a single one by its block's inverse);
//! 4. each contact's status is then tested in turn on its own local problem, the others frozen
//!    (right-hand side `c_i = b_i − Σ_{j≠i} H_ij λ_j`, exact local solve of §4.4), a sliding
//!    contact's λ set to its new direction at once, so that the contacts tested after it see
//!    it (Gauss–Seidel order: 14.5 % fewer iterations on S1 than testing every contact against
//!    the iteration's start):
//!    stick with `|λ_i| > μ_s R_N,i` → slip; slip whose local problem is a stick (for an
//!    isotropic `H_ii` this is exactly the paper's test "the slip velocity `(b − Hλ)_i` has
//!    reversed against `d_i`") → stick; a slip direction is the direction of the exact local
//!    slip solution, which makes `λ_i ∥ w_i` even when `H_ii` is not a multiple of the identity
//!    (the plain update `d ← w/|w|`, or a reversal test made with a wrong direction guess, does
//!    not converge then);
//! 5. stop when no status and no slip direction changes.
//!
//! A status pattern that comes back is a cycle; it and the iteration bound are counted and the
//! step is finished by the stated fallback: a projected Gauss–Seidel from the last λ.

use nalgebra::Vector2;

use super::{ActiveSetSettings, SolverStatistics, gauss_seidel};
use crate::contact::delassus::TangentialProblem;
use crate::contact::friction::{LocalSolve, Slide, local_solve_with};

/// Memory of a contact between steps: its last status and slip direction.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct History {
    /// Whether the contact was closed at the previous step.
    pub closed: bool,
    /// Its status then.
    pub slide: Slide,
    /// Its slip direction then (unit, in its tangent basis).
    pub direction: Vector2<f64>,
}

impl Default for History {
    fn default() -> Self {
        Self {
            closed: false,
            slide: Slide::Stick,
            direction: Vector2::zeros(),
        }
    }
}

/// How one Active Set solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Statuses settled after this many iterations.
    Converged(usize),
    /// A status pattern repeated: solved by the fallback.
    Cycled(usize),
    /// The iteration bound was reached: solved by the fallback.
    IterationLimit(usize),
}

/// Active Set solver with its preallocated work space.
#[derive(Debug, Clone)]
pub struct ActiveSet {
    settings: ActiveSetSettings,
    stick: Vec<bool>,
    direction: Vec<Vector2<f64>>,
    patterns: Vec<u64>,
    work: Vec<f64>,
    index: Vec<usize>,
    /// A sliding contact's local right-hand side at its last status test (for the residual).
    rhs: Vec<Vector2<f64>>,
}

impl ActiveSet {
    /// Work space for up to `contacts` closed contacts.
    pub fn new(settings: ActiveSetSettings, contacts: usize) -> Self {
        let n = 2 * contacts;
        Self {
            settings,
            stick: vec![false; contacts],
            direction: vec![Vector2::zeros(); contacts],
            patterns: Vec::with_capacity(settings.max_iterations + 1),
            work: vec![0.0; n * n + 2 * n],
            index: vec![0; n],
            rhs: vec![Vector2::zeros(); contacts],
        }
    }

    /// Solves the problem; `history[contact]` gives each closed contact's previous status.
    /// Writes λ and the statuses of the slots, and counts into `stats`. A step where a
    /// contact's block may be singular ([`TangentialProblem::may_be_singular`]) runs the local
    /// solves that handle it (THEORY §4.4); the others the same code without their test.
    pub fn solve(
        &mut self,
        problem: &TangentialProblem,
        history: &[History],
        lambda: &mut [Vector2<f64>],
        slide: &mut [Slide],
        stats: &mut SolverStatistics,
    ) -> Outcome {
        if problem.may_be_singular() {
            return self.solve_singular(problem, history, lambda, slide, stats);
        }
        self.solve_with::<false>(problem, history, lambda, slide, stats)
    }

    /// [`Self::solve`] of a step where a block may be singular, apart from the common step's
    /// code.
    #[cold]
    #[inline(never)]
    fn solve_singular(
        &mut self,
        problem: &TangentialProblem,
        history: &[History],
        lambda: &mut [Vector2<f64>],
        slide: &mut [Slide],
        stats: &mut SolverStatistics,
    ) -> Outcome {
        self.solve_with::<true>(problem, history, lambda, slide, stats)
    }

    /// [`Self::solve`], its local solves for singular blocks when `SINGULAR`.
    #[inline(always)]
    fn solve_with<const SINGULAR: bool>(
        &mut self,
        problem: &TangentialProblem,
        history: &[History],
        lambda: &mut [Vector2<f64>],
        slide: &mut [Slide],
        stats: &mut SolverStatistics,
    ) -> Outcome {
        let m = problem.len();
        let lambda = &mut lambda[..m];
        // 1. initial statuses
        for (k, slot) in problem.slots().iter().enumerate() {
            let h = history[slot.contact];
            if h.closed && h.slide == Slide::Stick {
                self.stick[k] = true;
            } else if h.closed && h.direction.norm_squared() > 0.0 {
                self.stick[k] = false;
                self.direction[k] = h.direction;
            } else {
                let b = problem.rhs(k);
                let nb = b.norm();
                self.stick[k] = nb == 0.0;
                self.direction[k] = if nb > 0.0 { b / nb } else { Vector2::zeros() };
            }
        }
        self.patterns.clear();
        self.patterns
            .push(pattern(&self.stick[..m], &self.direction[..m]));

        let mut iterations = 0;
        let outcome = loop {
            iterations += 1;
            // 2. slip contacts on the dynamic circle
            for (k, slot) in problem.slots().iter().enumerate() {
                if !self.stick[k] {
                    lambda[k] = self.direction[k] * slot.s_dynamic;
                }
            }
            // 3. stick contacts by a direct solve
            if problem.solve_stick(&self.stick[..m], lambda, &mut self.work, &mut self.index) {
                stats.singular_delassus += 1;
            }
            // 4. status and direction updates
            let mut status_changed = false;
            let mut direction_changed = false;
            for (k, slot) in problem.slots().iter().enumerate() {
                if self.stick[k] {
                    // |λ_k| > s_static (1 + 1e-12), compared squared
                    let bound = slot.s_static * (1.0 + 1e-12);
                    if lambda[k].norm_squared() > bound * bound {
                        self.stick[k] = false;
                        let (local, _) =
                            local_exact::<SINGULAR>(problem, k, problem.local_rhs(k, lambda));
                        let n = local.norm();
                        self.direction[k] = if n > 0.0 {
                            local / n
                        } else {
                            lambda[k] / lambda[k].norm()
                        };
                        status_changed = true;
                    }
                } else {
                    let c = problem.local_rhs(k, lambda);
                    self.rhs[k] = c;
                    let (local, local_slide) = local_exact::<SINGULAR>(problem, k, c);
                    if local_slide == Slide::Stick {
                        self.stick[k] = true;
                        status_changed = true;
                    } else {
                        // a slip solution has |λ| = s_dynamic (to round-off): its direction
                        // needs no square root
                        let d = if slot.s_dynamic > 0.0 {
                            local / slot.s_dynamic
                        } else {
                            let w = problem.residual_velocity(k, lambda);
                            w / w.norm()
                        };
                        // |d − d_k| > 1e-12, compared squared
                        if (d - self.direction[k]).norm_squared() > 1e-24 {
                            self.direction[k] = d;
                            direction_changed = true;
                            // at once, for the contacts tested after it (Gauss–Seidel order)
                            lambda[k] = d * slot.s_dynamic;
                        }
                    }
                }
            }
            if !status_changed && !direction_changed {
                break Outcome::Converged(iterations);
            }
            if m == 1 && !status_changed && iterations < self.settings.max_iterations {
                // A single sliding contact whose direction changed: the next iteration sets
                // λ = s d and solves the same local problem (its right-hand side is b whatever
                // λ), whose direction is d again to round-off (its Newton started from its own
                // root), far below the 1e-12 of the test. It is counted, not recomputed
                // (THEORY §4.3); λ is the one it would set.
                lambda[0] = self.direction[0] * problem.slots()[0].s_dynamic;
                iterations += 1;
                break Outcome::Converged(iterations);
            }
            if status_changed {
                let pat = pattern(&self.stick[..m], &self.direction[..m]);
                if self.patterns.contains(&pat) {
                    break Outcome::Cycled(iterations);
                }
                self.patterns.push(pat);
            }
            if iterations >= self.settings.max_iterations {
                break Outcome::IterationLimit(iterations);
            }
        };

        stats.as_iterations_total += iterations as u64;
        stats.as_iterations_max = stats.as_iterations_max.max(iterations as u64);
        match outcome {
            Outcome::Converged(_) => {
                for k in 0..m {
                    slide[k] = if self.stick[k] {
                        Slide::Stick
                    } else {
                        Slide::Slip
                    };
                }
            }
            Outcome::Cycled(_) | Outcome::IterationLimit(_) => {
                if matches!(outcome, Outcome::Cycled(_)) {
                    stats.as_cycles += 1;
                } else {
                    stats.as_iteration_limit += 1;
                }
                stats.as_fallbacks += 1;
                let sweeps = gauss_seidel::solve(&self.settings.fallback, problem, lambda, slide);
                stats.gs_sweeps_total += sweeps.count as u64;
                stats.gs_sweeps_max = stats.gs_sweeps_max.max(sweeps.count as u64);
                if !sweeps.converged {
                    stats.gs_nonconverged_steps += 1;
                }
            }
        }
        outcome
    }

    /// After a solve whose outcome was [`Outcome::Converged`]: the natural-map residual of the
    /// λ it returned (THEORY §4.2), bit for bit
    /// [`TangentialProblem::natural_map_residual`], with the sliding contacts' right-hand
    /// sides taken from the last iteration's status tests — which changed no λ, so that they
    /// were formed from the final λ — rather than formed again.
    pub fn residual(
        &self,
        problem: &TangentialProblem,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
    ) -> f64 {
        if problem.may_be_singular() {
            return self.residual_singular(problem, lambda, slide);
        }
        let rhs = |k: usize| (!self.stick[k]).then_some(self.rhs[k]);
        problem.natural_map_residual_given_with::<false>(lambda, slide, rhs)
    }

    /// [`Self::residual`] of a step where a block may be singular.
    #[cold]
    #[inline(never)]
    fn residual_singular(
        &self,
        problem: &TangentialProblem,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
    ) -> f64 {
        let rhs = |k: usize| (!self.stick[k]).then_some(self.rhs[k]);
        problem.natural_map_residual_given_with::<true>(lambda, slide, rhs)
    }
}

/// Contact `k`'s exact local problem with the right-hand side `c` (the others frozen:
/// [`TangentialProblem::local_rhs`]; THEORY §4.4); in line (it runs for every contact at every
/// status iteration).
#[inline(always)]
fn local_exact<const SINGULAR: bool>(
    problem: &TangentialProblem,
    k: usize,
    c: Vector2<f64>,
) -> (Vector2<f64>, Slide) {
    let slot = &problem.slots()[k];
    local_solve_with::<SINGULAR>(
        problem.diagonal_block(k),
        &c,
        slot.s_static,
        slot.s_dynamic,
        LocalSolve::Exact,
        problem.newton_start(k),
    )
}

/// FNV-1a hash of the statuses and of the slip directions (quantised to 1e-9): a cycle is a
/// state that comes back, not just a stick/slip pattern (a slip that reverses goes
/// slip → stick → slip with the opposite direction, which is progress). A hash collision could
/// only make a new state look like a repeated one, which sends the step to the fallback:
/// safe, and counted.
fn pattern(stick: &[bool], direction: &[Vector2<f64>]) -> u64 {
    let mut h: u64 = 0xcbf29ce484222325;
    let mut mix = |v: u64| {
        h ^= v;
        h = h.wrapping_mul(0x100000001b3);
    };
    for (&s, d) in stick.iter().zip(direction) {
        mix(s as u64 + 1);
        if !s {
            // truncated, one instruction (rounding is a libm call in baseline x86-64 code)
            mix((d.x * 1e9) as i64 as u64);
            mix((d.y * 1e9) as i64 as u64);
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::tangential::gauss_seidel::tests::single_sliding_contact;

    /// A single contact sliding on in another direction than the last step's: two
    /// iterations, the second counted but its local solve not recomputed; λ is the Coulomb
    /// slip solution (on the circle, along `w = b − Hλ`) that Gauss–Seidel finds.
    #[test]
    fn a_single_sliding_contact_converges_in_two_counted_iterations() {
        let problem = single_sliding_contact();
        let mut history = [History {
            closed: true,
            slide: Slide::Slip,
            direction: Vector2::new(0.6, 0.8),
        }];
        let mut solver = ActiveSet::new(ActiveSetSettings::default(), 1);
        let (mut lambda, mut slide) = ([Vector2::zeros()], [Slide::Stick]);
        let mut stats = SolverStatistics::default();
        let outcome = solver.solve(&problem, &history, &mut lambda, &mut slide, &mut stats);
        assert_eq!(outcome, Outcome::Converged(2));
        assert_eq!(stats.as_iterations_total, 2);
        assert_eq!(slide, [Slide::Slip]);
        let l = lambda[0];
        assert!((l.norm() - 0.04).abs() <= 4.0 * f64::EPSILON * 0.04);
        let w = problem.rhs(0) - problem.block(0, 0) * l;
        assert!(l.dot(&w) > 0.0);
        assert!((l.x * w.y - l.y * w.x).abs() <= 1e-14 * l.norm() * w.norm());
        let (mut gs, mut gs_slide) = ([Vector2::zeros()], [Slide::Stick]);
        gauss_seidel::solve(
            &ActiveSetSettings::default().fallback,
            &single_sliding_contact(),
            &mut gs,
            &mut gs_slide,
        );
        assert!((gs[0] - l).norm() <= 8.0 * f64::EPSILON * l.norm());
        // the next step starts along that direction: one iteration
        history[0].direction = l / l.norm();
        let mut stats = SolverStatistics::default();
        let again = solver.solve(&problem, &history, &mut lambda, &mut slide, &mut stats);
        assert_eq!(again, Outcome::Converged(1));
    }
}
