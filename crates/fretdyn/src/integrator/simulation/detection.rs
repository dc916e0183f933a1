//! Phase 1 of a step — the loads and the kinematics: the external modal force at `t`, the
//! contact points' penetrations, frames and velocities, and the normal penalty forces that
//! follow from them (THEORY §2 step 3, §3, §7, §8); after the step, the full-step
//! velocities.
//!
//! A plane or bars ([`FrameRows`]) is detected with one dot product on the modal
//! displacements (in the common case of four contacts or more, all of them in one pass over
//! the modes, [`Simulation::detect_fixed`]); other obstacles (holes) from the point's 3-D
//! position. Velocities are formed for closed contacts only (and for every contact at an
//! output sample), in the contact's frame.

use nalgebra::{Vector2, Vector3};

use super::contact_kinds::{CommonContacts, ContactKinds};
use super::{ContactState, Simulation, Tangential, contact_rows, contact_states};
use crate::contact::frame_rows::FrameRows;
use crate::numerics::Lanes;
use crate::structure::modal::recombine_with;

impl Simulation<'_> {
    /// The external modal force of step `n`, at `t = n Δt`: `Σ_l s_l(t) Φ_lᵀ F_l` over the
    /// loads' rows (the histories' sines rotated from step to step, THEORY §10), plus the
    /// turbulence (THEORY §10). The step forms the first load's with the predictor instead
    /// ([`Self::predict_with_first_load`]).
    #[inline(always)]
    pub(super) fn external_force<K: Lanes>(&mut self, n: u64, t: f64) {
        let p = self.external.len();
        // the first load sets the force, the others add to it
        match self.load_histories.first_mut() {
            Some(first) => K::scale(&mut self.external, first.value(n, t), &self.load_rows[..p]),
            None => self.external.fill(0.0),
        }
        self.other_loads::<K>(n, t);
    }

    /// Steps 1–2 (the predictor) of step `n` and, in the same pass over the modes, the first
    /// load's force: the start of [`Self::external_force`] (the same bits), which
    /// [`Self::other_loads`] completes.
    #[inline(always)]
    pub(super) fn predict_with_first_load<K: Lanes>(&mut self, n: u64, t: f64) {
        let p = self.external.len();
        match self.load_histories.first_mut() {
            Some(first) => {
                let s = first.value(n, t);
                self.cd
                    .predict_and_scale_with::<K>(&mut self.external, s, &self.load_rows[..p]);
            }
            None => {
                self.cd.predict_with::<K>();
                self.external.fill(0.0);
            }
        }
    }

    /// The loads after the first and the turbulence, added to the external force.
    #[inline(always)]
    pub(super) fn other_loads<K: Lanes>(&mut self, n: u64, t: f64) {
        let p = self.external.len();
        // (one load, the common case, skips the set-up of the loop: its rows' count is a
        // division)
        if self.load_histories.len() > 1 {
            for (history, row) in self.load_histories[1..]
                .iter_mut()
                .zip(self.load_rows[p..].chunks_exact(p.max(1)))
            {
                K::axpy(&mut self.external, history.value(n, t), row);
            }
        }
        if self.turbulence.is_empty() {
            return;
        }
        for (load, generator) in self.model.turbulence.iter().zip(&mut self.turbulence) {
            let r = generator.channels();
            let xi = &mut self.signals[..r];
            generator.values(t, xi);
            for (x, row) in xi.iter().zip(load.rows.chunks_exact(p.max(1))) {
                K::axpy(&mut self.external, *x, row);
            }
        }
    }

    /// The fluid-elastic force of step `n` added to the external force (THEORY §13): the
    /// displacement of the step is stored for the delays; the velocity is extrapolated from
    /// the previous step's (`started`), or is the initial one.
    #[inline(always)]
    pub(super) fn fluid_elastic_force<K: Lanes>(&mut self, n: u64, started: bool) {
        let (Some(fluid), Some(fe)) = (&mut self.fluid, &self.model.fluid_elastic) else {
            return;
        };
        fluid.record(n, &self.cd.q);
        let h = if started { self.settings.dt } else { 0.0 };
        fluid.apply::<K>(fe, n, (&self.cd.qd, &self.cd.qdd, h), &mut self.external);
    }

    /// Step 3: penetrations, frames, velocities (predicted when `predicted`) and normal
    /// forces at time `t`. Returns whether every open contact's values can be accumulated
    /// ([`ContactState::accumulable`]: for an open contact, its penetration squared is at
    /// most a quarter of the bound), checked here where the penetration is at hand.
    #[inline(always)]
    pub(super) fn detect<K: Lanes, O: ContactKinds>(&mut self, t: f64, predicted: bool) -> bool {
        // four contacts or more: their dot products together (with fewer, the pass over `q`
        // for all of them costs more than it saves)
        if O::COMMON && self.normal_dots.len() >= 4 {
            return self.detect_fixed::<K>();
        }
        let velocity = if predicted {
            &self.cd.qd_star
        } else {
            &self.cd.qd
        };
        let p = self.cd.q.len();
        let penalty = O::penalty(matches!(self.tangential, Tangential::Penalty { .. }));
        self.closed.clear();
        let mut detected = Detected {
            closed: &mut self.closed,
            quarter_bound: 0.25 * self.accumulation_bound,
            open_within: true,
        };
        for (k, (c, state)) in contact_states(self.model, &mut self.contacts) {
            state.tangential_force = Vector2::zeros();
            state.held = false;
            match O::rows(&self.frame_rows[k]) {
                Some(rows) => {
                    state.distance = rows.distance::<K>(&self.cd.q, O::is_fixed(c), &c.motion, t);
                    rows.update(state.distance, &mut state.frame);
                }
                None => {
                    let pt = &self.model.basis.points[c.point];
                    state.x = pt.coords + recombine_with::<K>(&pt.rows, &self.cd.q);
                    state.frame = c.frame(&state.x, t);
                }
            }
            if !detected.status(k, state) {
                continue;
            }
            let pt = &self.model.basis.points[c.point];
            // an open contact's velocity is only needed at output samples
            if !O::is_fixed(c) {
                state.frame.velocity = c.motion.at(t).1;
            }
            match O::rows(&self.frame_rows[k]) {
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
                        let out = &mut self.surface_rows[3 * p * k..3 * p * (k + 1)];
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
                let rows = contact_rows(self.model, &self.surface_rows, k);
                state.x_relative = pt.coords + recombine_with::<K>(rows, &self.cd.q) - d;
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
        self.closed.clear();
        let mut detected = Detected {
            closed: &mut self.closed,
            quarter_bound: 0.25 * self.accumulation_bound,
            open_within: true,
        };
        K::padded_dots(&self.normal_rows, &self.cd.q, &mut self.normal_dots);
        let contacts = (self.model.contacts.iter())
            .zip(&self.frame_rows)
            .zip(&self.normal_dots);
        for (k, (state, ((c, rows), &dot))) in self.contacts.iter_mut().zip(contacts).enumerate() {
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
            for k in 0..self.contacts.len() {
                self.full_step_velocity::<K, O>(k);
            }
        } else {
            for i in 0..self.closed.len() {
                self.full_step_velocity::<K, O>(self.closed[i]);
            }
        }
    }

    /// [`Self::full_step_velocities`] of contact `k`.
    #[inline(always)]
    fn full_step_velocity<K: Lanes, O: ContactKinds>(&mut self, k: usize) {
        let p = self.cd.q.len();
        let (c, state) = (&self.model.contacts[k], &mut self.contacts[k]);
        if !O::is_fixed(c) {
            state.frame.velocity = moving_full_step(&c.motion, self.step, self.settings.dt);
        }
        match O::rows(&self.frame_rows[k]) {
            Some(rows) => {
                let kinematics = Kinematics::Rows(rows, O::is_fixed(c));
                state.set_velocity::<K>(kinematics, O::damped(c), &self.cd.qd, true)
            }
            None => {
                let pt = &self.model.basis.points[c.point];
                if c.at_surface() && !state.closed {
                    let out = &mut self.surface_rows[3 * p * k..3 * p * (k + 1)];
                    c.surface_rows(pt, &state.frame.normal, out);
                }
                let rows = contact_rows(self.model, &self.surface_rows, k);
                state.set_velocity::<K>(Kinematics::Point(rows), O::damped(c), &self.cd.qd, true);
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
