//! Phase 2 of a step — the detection: the contact points' penetrations, frames and
//! velocities, and the normal penalty forces that follow from them (THEORY §2 step 3, §3,
//! §7, §8); after the step, the full-step velocities.
//!
//! A plane or bars ([`FrameRows`]) is detected with one dot product on the modal
//! displacements (in the common case of four contacts or more, all of them in one pass over
//! the modes, [`Simulation::detect_fixed`]); other obstacles (holes) from the point's 3-D
//! position. Velocities are formed for closed contacts only (and for every contact at an
//! output sample), in the contact's frame.

use nalgebra::{Vector2, Vector3};

use super::contact_kinds::{CommonContacts, ContactKinds};
use super::contact_state::{ContactState, contact_states};
use super::step::Simulation;
use super::workspace::{Tangential, contact_rows};
use crate::contact::frame_rows::FrameRows;
use crate::numerics::Lanes;
use crate::structure::modal::recombine_with;

impl Simulation<'_> {
    /// Step 3: penetrations, frames, velocities (predicted when `predicted`) and normal
    /// forces at time `t`. Returns whether every open contact's values can be accumulated
    /// ([`ContactState::accumulable`]: for an open contact, its penetration squared is at
    /// most a quarter of the bound), checked here where the penetration is at hand.
    #[inline(always)]
    pub(super) fn detect<K: Lanes, O: ContactKinds>(&mut self, t: f64, predicted: bool) -> bool {
        // four contacts or more: their dot products together (with fewer, the pass over `q`
        // for all of them costs more than it saves)
        if O::COMMON && self.work.normal_dots.len() >= 4 {
            return self.detect_fixed::<K>();
        }
        let (w, x) = (&mut self.work, &self.state.modal);
        let velocity = if predicted { &w.cd.qd_star } else { &x.qd };
        let p = x.q.len();
        let penalty = O::penalty(matches!(w.tangential, Tangential::Penalty { .. }));
        w.closed.clear();
        let mut detected = Detected {
            closed: &mut w.closed,
            quarter_bound: 0.25 * w.accumulation_bound,
            open_within: true,
        };
        for (k, (c, state)) in contact_states(self.model, &mut self.state.contacts) {
            state.tangential_force = Vector2::zeros();
            state.held = false;
            match O::rows(&w.frame_rows[k]) {
                Some(rows) => {
                    state.distance = rows.distance::<K>(&x.q, O::is_fixed(c), &c.motion, t);
                    rows.update(state.distance, &mut state.frame);
                }
                None => {
                    let pt = c.point_in(&self.model.basis.points);
                    state.x = pt.coords + recombine_with::<K>(&pt.rows, &x.q);
                    state.frame = c.frame(&state.x, t);
                }
            }
            if !detected.status(k, state) {
                continue;
            }
            let pt = c.point_in(&self.model.basis.points);
            // an open contact's velocity is only needed at output samples
            if !O::is_fixed(c) {
                state.frame.velocity = c.motion.at(t).1;
            }
            match O::rows(&w.frame_rows[k]) {
                Some(frame_rows) => {
                    state.set_velocity::<K>(
                        Kinematics::Rows(frame_rows, O::is_fixed(c)),
                        O::damped(c),
                        velocity,
                        penalty,
                    );
                }
                None => {
                    let rows = if c.at_surface() {
                        let out = &mut w.surface_rows[3 * p * k..3 * p * (k + 1)];
                        c.surface_rows(pt, &state.frame.normal, out);
                        &*out
                    } else {
                        &pt.rows[..]
                    };
                    state.set_velocity::<K>(
                        Kinematics::Point(rows),
                        O::damped(c),
                        velocity,
                        penalty,
                    );
                }
            }
            state.normal_force = c.normal.force(state.frame.penetration, -state.v_normal);
            if penalty {
                // the anchor of the penalty law lives in the obstacle's frame
                let (d, _) = c.motion.at(t);
                let rows = contact_rows(self.model, &w.surface_rows, k);
                state.x_relative = pt.coords + recombine_with::<K>(rows, &x.q) - d;
            }
        }
        detected.open_within
    }

    /// [`Self::detect`] in the common case ([`CommonContacts`]: every obstacle a fixed plane
    /// or fixed bars seen through its frame rows, an undamped normal law, friction by Lagrange
    /// multipliers): every contact's dot product `(n·Φ_c) q` in one pass over `q`
    /// ([`Lanes::padded_dots`], the bits of [`FrameRows::distance`]'s), then each contact's
    /// penetration and normal force from its own — no velocity: without damping the normal
    /// law does not use it, and the Lagrange methods form `L q̇*` themselves.
    #[inline(always)]
    fn detect_fixed<K: Lanes>(&mut self) -> bool {
        let w = &mut self.work;
        w.closed.clear();
        let mut detected = Detected {
            closed: &mut w.closed,
            quarter_bound: 0.25 * w.accumulation_bound,
            open_within: true,
        };
        K::padded_dots(&w.normal_rows, &self.state.modal.q, &mut w.normal_dots);
        let contacts = (self.model.contacts.iter())
            .zip(&w.frame_rows)
            .zip(&w.normal_dots);
        let states = self.state.contacts.iter_mut();
        for (k, (state, ((c, rows), &dot))) in states.zip(contacts).enumerate() {
            let rows = CommonContacts::rows(rows).expect("a common step's contact has rows");
            detected.contact(k, state, c, rows, dot);
        }
        detected.open_within
    }

    /// Full-step velocities of the closed contacts (of all when `all`) relative to their
    /// obstacles: `Φ_c q̇_{n+1} − v̄_{n+1}`, with `v̄` the obstacle's full-step velocity
    /// ([`crate::contact::motion::Motion::full_step_velocity`], the mean of the two step velocities
    /// around `t_{n+1}`, as `q̇_{n+1}` is the mean of the two half-step velocities; THEORY §2),
    /// which also becomes the frame's velocity for the obstacle's power. (The tangential part
    /// of a contact [held](ContactState::held) in stick is read as exactly 0, THEORY §5.)
    #[inline(always)]
    pub(super) fn full_step_velocities<K: Lanes, O: ContactKinds>(&mut self, all: bool) {
        if all {
            for k in 0..self.state.contacts.len() {
                self.full_step_velocity::<K, O>(k);
            }
        } else {
            for i in 0..self.work.closed.len() {
                self.full_step_velocity::<K, O>(self.work.closed[i]);
            }
        }
    }

    /// [`Self::full_step_velocities`] of contact `k`.
    #[inline(always)]
    fn full_step_velocity<K: Lanes, O: ContactKinds>(&mut self, k: usize) {
        let (w, x) = (&mut self.work, &self.state.modal);
        let p = x.q.len();
        let (c, state) = (&self.model.contacts[k], &mut self.state.contacts[k]);
        if !O::is_fixed(c) {
            state.frame.velocity = moving_full_step(&c.motion, self.state.step, self.settings.dt);
        }
        match O::rows(&w.frame_rows[k]) {
            Some(rows) => {
                let kinematics = Kinematics::Rows(rows, O::is_fixed(c));
                state.set_velocity::<K>(kinematics, O::damped(c), &x.qd, true)
            }
            None => {
                let pt = c.point_in(&self.model.basis.points);
                if c.at_surface() && !state.closed {
                    let out = &mut w.surface_rows[3 * p * k..3 * p * (k + 1)];
                    c.surface_rows(pt, &state.frame.normal, out);
                }
                let rows = contact_rows(self.model, &w.surface_rows, k);
                state.set_velocity::<K>(Kinematics::Point(rows), O::damped(c), &x.qd, true);
            }
        }
    }
}

/// What detection ([`Simulation::detect`], [`Simulation::detect_fixed`]) finds, contact by
/// contact.
struct Detected<'a> {
    /// The contacts closed so far, in order.
    closed: &'a mut Vec<usize>,
    /// A quarter of [`Simulation::accumulation_bound`].
    quarter_bound: f64,
    /// Whether every open contact so far can be accumulated ([`ContactState::accumulable`]).
    open_within: bool,
}

impl Detected<'_> {
    /// Contact `k`'s status from its penetration (its frame at hand): an open contact's
    /// normal force is zero and its penetration is checked against the bound, a closed one
    /// joins the closed contacts. Returns whether it is closed.
    #[inline(always)]
    fn status(&mut self, k: usize, state: &mut ContactState) -> bool {
        state.closed = state.frame.penetration > 0.0;
        if !state.closed {
            state.normal_force = 0.0;
            // no forces, no velocity: `accumulable` reduces to this (a NaN fails it)
            let d = state.frame.penetration;
            self.open_within &= d * d <= self.quarter_bound;
            return false;
        }
        self.closed.push(k);
        true
    }

    /// Contact `k` of a fixed plane or bars (`rows`) whose dot product `(n·Φ_c) q` is `dot`:
    /// its distance, penetration, status and normal force ([`Simulation::detect`]'s, for a
    /// contact of the common case).
    #[inline(always)]
    fn contact(
        &mut self,
        k: usize,
        state: &mut ContactState,
        c: &crate::contact::Contact,
        rows: &FrameRows,
        dot: f64,
    ) {
        state.tangential_force = Vector2::zeros();
        state.held = false;
        state.distance = rows.distance_from_dot(dot);
        rows.update(state.distance, &mut state.frame);
        if !self.status(k, state) {
            return;
        }
        // no damping: the velocity is not formed
        state.v_normal = 0.0;
        state.normal_force = c.normal.force(state.frame.penetration, -state.v_normal);
    }
}

/// How a contact's velocity is formed from the modal velocities.
pub(super) enum Kinematics<'a> {
    /// A plane or bars: its frame rows, and whether the obstacle is fixed (then its velocity,
    /// zero, is not subtracted).
    Rows(&'a FrameRows, bool),
    /// Any obstacle: the contact point's 3 × p rows.
    Point(&'a [f64]),
}

impl ContactState {
    /// Sets the velocity relative to the obstacle, in the frame, for modal velocities `qd`
    /// (the frame's velocity is the obstacle's). The normal component is formed only when
    /// the normal law has damping (`damped`), the only use of it (`R_N = K_N δ + C_N δ̇`,
    /// THEORY §3); it is 0 otherwise. The tangential one only when `tangential` (the
    /// predicted tangential velocity serves the penalty law only: the Lagrange methods form
    /// `L q̇*` themselves).
    #[inline(always)]
    pub(super) fn set_velocity<K: Lanes>(
        &mut self,
        kinematics: Kinematics,
        damped: bool,
        qd: &[f64],
        tangential: bool,
    ) {
        match kinematics {
            Kinematics::Rows(rows, fixed) => {
                if tangential {
                    let obstacle = (!fixed).then_some(&self.frame.velocity);
                    self.v_tangential = rows.tangential_velocity::<K>(qd, obstacle);
                }
                self.v_normal = if damped {
                    rows.normal_velocity::<K>(&self.frame, qd, &self.frame.velocity)
                } else {
                    0.0
                };
            }
            Kinematics::Point(rows) => {
                if !(tangential || damped) {
                    return;
                }
                let v = recombine_with::<K>(rows, qd) - self.frame.velocity;
                let f = &self.frame;
                self.v_normal = if damped { f.normal.dot(&v) } else { 0.0 };
                if tangential {
                    self.v_tangential = Vector2::new(f.tangents[0].dot(&v), f.tangents[1].dot(&v));
                }
            }
        }
    }
}

/// [`crate::contact::motion::Motion::full_step_velocity`], out of the loop of the fixed obstacles.
#[inline(never)]
fn moving_full_step(motion: &crate::contact::motion::Motion, step: u64, dt: f64) -> Vector3<f64> {
    motion.full_step_velocity(step, dt)
}
