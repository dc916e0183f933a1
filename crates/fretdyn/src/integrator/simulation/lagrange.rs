//! Phase 4 of a step — the Lagrange tangential solve: the Delassus problem on the closed
//! contacts, solved by projected Gauss–Seidel or Active Set, applied to the acceleration
//! (THEORY §2 step 6, §4.2–§4.6).

use nalgebra::Vector2;

use super::step::Simulation;
use super::workspace::{LagrangeSolver, Tangential, contact_rows};
use crate::contact::delassus::Slot;
use crate::contact::friction::Slide;
use crate::contact::tangential::active_set::{History, Outcome};
use crate::contact::tangential::{StickVelocity, gauss_seidel};
use crate::numerics::Lanes;

impl Simulation<'_> {
    /// Step 6 for the Lagrange methods.
    #[inline(always)]
    pub(super) fn lagrange<K: Lanes>(&mut self) {
        let Tangential::Lagrange {
            problem,
            solver,
            theta_dt,
            lambda,
            slide,
            work,
        } = &mut self.work.tangential
        else {
            return;
        };
        let (history, previous_lambda) = (&mut self.state.history, &mut self.state.previous_lambda);
        problem.clear();
        for &k in &self.work.closed {
            let (c, state) = (&self.model.contacts[k], &self.state.contacts[k]);
            let cd = &self.work.cd;
            problem.push_with(
                Slot {
                    contact: k,
                    s_static: c.friction.mu_static * state.normal_force,
                    s_dynamic: c.friction.mu_dynamic * state.normal_force,
                },
                &state.frame.tangents,
                contact_rows(self.model, &self.work.surface_rows, k),
                |l, out| cd.apply_a_inv(l, out),
            );
        }
        if problem.is_empty() {
            history.iter_mut().for_each(|h| h.closed = false);
            return;
        }
        let (contacts, model, dt) = (&self.state.contacts, self.model, self.settings.dt);
        let half_step = self.settings.stick_velocity == StickVelocity::HalfStep;
        let step = self.state.step;
        let (qdd, qd_star) = (&self.state.modal.qdd, &self.work.cd.qd_star);
        problem.assemble_with::<K>(qdd, qd_star, *theta_dt, |slot| {
            let f = &contacts[slot.contact].frame;
            let motion = &model.contacts[slot.contact].motion;
            // the half-step velocity moves the point from t_{n+1} to t_{n+2}: the obstacle's
            // velocity over that step, so that a sticking point keeps its place on the
            // obstacle exactly; the full-step one is the mean of two such steps
            // (Motion::full_step_velocity, the velocity the slip is measured against)
            if motion.is_fixed() {
                return Vector2::zeros();
            }
            let v = if half_step {
                motion.step_velocity(step, dt)
            } else {
                motion.full_step_velocity(step, dt)
            };
            Vector2::new(f.tangents[0].dot(&v), f.tangents[1].dot(&v))
        });
        let m = problem.len();
        let warm = match solver {
            LagrangeSolver::GaussSeidel(s) => s.warm_start,
            LagrangeSolver::ActiveSet(_) => false,
        };
        for (k, slot) in problem.slots().iter().enumerate() {
            let before = &history[slot.contact];
            lambda[k] = if warm && before.closed {
                previous_lambda[slot.contact]
            } else {
                Vector2::zeros()
            };
            // held: both half-step velocities of q̇_{n+1} imposed (only this step's with the
            // full-step constraint) — the previous step's part here, this step's stick below
            self.state.contacts[slot.contact].held =
                !half_step || (before.closed && before.slide == Slide::Stick);
        }
        let stats = &mut self.state.solver;
        stats.lagrange_steps += 1;
        let mut residual = None;
        match solver {
            LagrangeSolver::GaussSeidel(s) => {
                // Gauss–Seidel tolerates a singular H (the modal forces are unique, λ is
                // not); it is counted all the same (THEORY §4.6).
                if problem.is_singular(work) {
                    stats.singular_delassus += 1;
                }
                let sweeps = gauss_seidel::solve(s, problem, &mut lambda[..m], &mut slide[..m]);
                stats.gs_sweeps_total += sweeps.count as u64;
                stats.gs_sweeps_max = stats.gs_sweeps_max.max(sweeps.count as u64);
                if !sweeps.converged {
                    stats.gs_nonconverged_steps += 1;
                }
                residual = sweeps.residual;
            }
            LagrangeSolver::ActiveSet(a) => {
                let outcome = a.solve(problem, history, &mut lambda[..m], &mut slide[..m], stats);
                if matches!(outcome, Outcome::Converged(_)) {
                    residual = Some(a.residual(problem, &lambda[..m], &slide[..m]));
                }
            }
        }
        let residual =
            residual.unwrap_or_else(|| problem.natural_map_residual(&lambda[..m], &slide[..m]));
        stats.add_residual(residual);
        problem.apply::<K>(&lambda[..m], &mut self.state.modal.qdd);
        history.iter_mut().for_each(|h| h.closed = false);
        let active_set = matches!(solver, LagrangeSolver::ActiveSet(_));
        for (k, slot) in problem.slots().iter().enumerate() {
            let state = &mut self.state.contacts[slot.contact];
            state.tangential_force = -lambda[k];
            state.slide = slide[k];
            state.held &= slide[k] == Slide::Stick;
            // the slip direction serves the Active Set's first guess only
            let n = if active_set { lambda[k].norm() } else { 0.0 };
            history[slot.contact] = History {
                closed: true,
                slide: slide[k],
                direction: if n > 0.0 {
                    lambda[k] / n
                } else {
                    Vector2::zeros()
                },
            };
            previous_lambda[slot.contact] = lambda[k];
        }
    }
}
