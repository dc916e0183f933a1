//! Phase 1 of a step — the loads and the kinematics: the external modal force at `t`, the
//! contact points' positions, frames and velocities, and the normal penalty forces that
//! follow from them (THEORY §2 step 3, §3, §7, §8); after the step, the full-step
//! velocities.

use nalgebra::{Vector2, Vector3};

use super::{Simulation, Tangential, contact_rows, contact_states};
use crate::structure::modal::recombine;

impl Simulation<'_> {
    pub(super) fn external_force(&mut self, t: f64) {
        let p = self.external.len();
        self.external.iter_mut().for_each(|f| *f = 0.0);
        let histories = self.model.loads.iter().map(|l| &l.history);
        let modal = self.model.modal_loads.iter().map(|l| &l.history);
        let base = self.model.base_acceleration.iter().map(|b| &b.history);
        for (l, history) in histories.chain(modal).chain(base).enumerate() {
            let s = history.value(t);
            for (f, g) in self
                .external
                .iter_mut()
                .zip(&self.load_rows[l * p..(l + 1) * p])
            {
                *f += s * g;
            }
        }
        for (load, generator) in self.model.turbulence.iter().zip(&mut self.turbulence) {
            let r = generator.channels();
            let xi = &mut self.signals[..r];
            generator.values(t, xi);
            for (j, x) in xi.iter().enumerate() {
                for (f, g) in self.external.iter_mut().zip(&load.rows[j * p..(j + 1) * p]) {
                    *f += x * g;
                }
            }
        }
    }

    /// Step 3: positions, velocities (predicted when `predicted`), frames and normal forces
    /// at time `t`.
    pub(super) fn detect(&mut self, t: f64, predicted: bool) {
        let velocity = if predicted {
            &self.cd.qd_star
        } else {
            &self.cd.qd
        };
        let p = self.cd.q.len();
        for (k, (c, state)) in contact_states(self.model, &mut self.contacts) {
            let pt = &self.model.basis.points[c.point];
            state.x = pt.coords + recombine(&pt.rows, &self.cd.q);
            state.frame = c.frame(&state.x, t);
            state.closed = state.frame.penetration > 0.0;
            state.tangential_force = Vector2::zeros();
            state.held = false;
            if state.closed {
                // an open contact's velocity is only needed at output samples
                let rows = if c.at_surface() {
                    let out = &mut self.surface_rows[3 * p * k..3 * p * (k + 1)];
                    c.surface_rows(pt, &state.frame.normal, out);
                    &*out
                } else {
                    &pt.rows[..]
                };
                state.v = recombine(rows, velocity) - state.frame.velocity;
                let rate = -state.frame.normal.dot(&state.v);
                state.normal_force = c.normal.force(state.frame.penetration, rate);
                if matches!(self.tangential, Tangential::Penalty { .. }) {
                    let (d, _) = c.motion.at(t);
                    state.x_relative = pt.coords + recombine(rows, &self.cd.q) - d;
                }
            } else {
                state.normal_force = 0.0;
            }
        }
    }

    /// Full-step velocities of the closed contacts (of all when `all`) relative to their
    /// obstacles: `Φ_c q̇_{n+1} − v̄_{n+1}`, with `v̄` the obstacle's full-step velocity
    /// ([`crate::contact::motion::Motion::full_step_velocity`], the mean of the two step velocities
    /// around `t_{n+1}`, as `q̇_{n+1}` is the mean of the two half-step velocities; THEORY §2),
    /// which also becomes the frame's velocity for the obstacle's power. (The tangential part
    /// of a contact [held](ContactState::held) in stick is read as exactly 0, THEORY §5.)
    pub(super) fn full_step_velocities(&mut self, all: bool) {
        let p = self.cd.q.len();
        for (k, (c, state)) in contact_states(self.model, &mut self.contacts) {
            if state.closed || all {
                let pt = &self.model.basis.points[c.point];
                if c.at_surface() && !state.closed {
                    let out = &mut self.surface_rows[3 * p * k..3 * p * (k + 1)];
                    c.surface_rows(pt, &state.frame.normal, out);
                }
                let rows = contact_rows(self.model, &self.surface_rows, k);
                if !c.motion.is_fixed() {
                    state.frame.velocity = moving_full_step(&c.motion, self.step, self.settings.dt);
                }
                state.v = recombine(rows, &self.cd.qd) - state.frame.velocity;
            }
        }
    }
}

/// [`crate::contact::motion::Motion::full_step_velocity`], out of the loop of the fixed obstacles.
#[inline(never)]
fn moving_full_step(motion: &crate::contact::motion::Motion, step: u64, dt: f64) -> Vector3<f64> {
    motion.full_step_velocity(step, dt)
}
