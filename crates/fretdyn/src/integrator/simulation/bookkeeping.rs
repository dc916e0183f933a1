//! Phase 5 of a step — the bookkeeping: energy and powers for the balance, the output
//! sample, the window's opening, the wear work's map, and the results (THEORY §5).

use super::contact_kinds::ContactKinds;
use super::results::{RunResults, Termination};
use super::step::Simulation;
use super::workspace::contact_rows;
use crate::accumulate::monitor::MonitorStatistics;
use crate::accumulate::recorder::{ContactSample, Recorder};
use crate::numerics::Lanes;
use crate::structure::modal::recombine;

impl Simulation<'_> {
    /// Energy `E` and the powers `[external (loads and moving obstacles), modal damping,
    /// contact damping, tangential, fluid-elastic]`.
    /// `modal`: the structure's energy, modal damping power and external power
    /// ([`crate::integrator::central_difference::CentralDifference::energy_and_powers`]).
    #[inline(always)]
    pub(super) fn energy_and_powers<K: Lanes, O: ContactKinds>(
        &self,
        modal: (f64, f64, f64),
    ) -> (f64, [f64; 5]) {
        let (mut e, modal_damping, mut external) = modal;
        // the external force holds the fluid-elastic one: its power apart
        let fluid = match &self.work.fluid {
            Some(f) => K::dot(&f.force, &self.state.modal.qd),
            None => 0.0,
        };
        external -= fluid;
        let mut contact_damping = 0.0;
        let mut tangential = 0.0;
        let mut obstacle = 0.0;
        for &k in &self.work.closed {
            let (c, s) = (&self.model.contacts[k], &self.state.contacts[k]);
            let d = s.frame.penetration;
            e += 0.5 * c.normal.stiffness * d * d;
            if O::damped(c) {
                // (R_N − K_N δ) δ̇: zero without damping
                contact_damping += (s.normal_force - c.normal.stiffness * d) * -s.v_normal;
            }
            tangential -= s.tangential_force.dot(&s.tangential_velocity());
            if !O::is_fixed(c) {
                // a moving obstacle works on the structure at the rate R·v_obstacle
                obstacle += s.force().dot(&s.frame.velocity);
            }
        }
        (
            e,
            [
                external + obstacle,
                modal_damping,
                contact_damping,
                tangential,
                fluid,
            ],
        )
    }

    /// Records the output sample of the current step; returns the first contact whose slip
    /// velocity or position is not finite (the modal state and the forces are checked by
    /// [`Self::step`] already).
    pub(super) fn sample(&mut self) -> Option<usize> {
        let t = self.state.step as f64 * self.settings.dt;
        let x = &self.state.modal;
        if !self.recorder.push_state(t, &x.q, &x.qd) {
            return None;
        }
        let mut non_finite = None;
        let states = self.state.contacts.iter_mut();
        for (k, (s, c)) in states.zip(&self.model.contacts).enumerate() {
            if self.work.frame_rows[k].is_some() {
                // a plane's or bars' 3-D position is formed for the samples only
                let pt = c.point_in(&self.model.basis.points);
                s.x = pt.coords + recombine(&pt.rows, &x.q);
            }
            let vt = s.tangential_velocity();
            let local = c.local(&s.x, t);
            // a sum is non-finite when a term is (or when it overflows: no value to keep)
            if !(vt.x + vt.y + local.x + local.y).is_finite() && non_finite.is_none() {
                non_finite = Some(k);
            }
            self.recorder.contact(
                k,
                &ContactSample {
                    normal_force: s.normal_force,
                    tangential_force: [s.tangential_force.x, s.tangential_force.y],
                    slip_velocity: [vt.x, vt.y],
                    penetration: s.frame.penetration,
                    status: s.status_code(),
                    position: [local.x, local.y],
                },
            );
        }
        if non_finite.is_none() && self.settings.statistics.step_in_window(t, self.settings.dt) {
            self.monitor_sample();
        }
        non_finite
    }

    /// Adds the displacements `u = d·(Φ_x q)` of the monitors at the current step to their
    /// sums ([`crate::accumulate::monitor`]).
    fn monitor_sample(&mut self) {
        let (points, q) = (&self.model.basis.points, &self.state.modal.q);
        let monitors = self.settings.monitors.iter();
        for (m, sums) in monitors.zip(&mut self.state.monitors) {
            sums.add(m.direction.dot(&recombine(&points[m.point].rows, q)));
        }
    }

    /// Opens the statistics window at the end of the current step (THEORY §11): an impact
    /// under way starts there, with the normal approach speed `−n·(Φ_c q̇ − ḋ)` of its
    /// contact at that time as its impact speed (the full-step velocities, those of the step
    /// or at t = 0 the initial ones; the obstacle's full-step velocity, set for the closed
    /// contacts).
    #[cold]
    #[inline(never)]
    pub(super) fn open_statistics_window(&mut self) {
        let t = self.state.step as f64 * self.settings.dt;
        let (model, surface_rows, qd) = (self.model, &self.work.surface_rows, &self.state.modal.qd);
        let speeds = self.state.contacts.iter().enumerate().map(|(k, s)| {
            if !s.closed {
                return 0.0;
            }
            let rows = contact_rows(model, surface_rows, k);
            -s.frame
                .normal
                .dot(&(recombine(rows, qd) - s.frame.velocity))
        });
        self.state.statistics.open_window(t, speeds);
    }

    /// Adds the step ending at `t` to the wear map ([`Self::track_wear`]): the friction work
    /// of the closed contacts, when the step is in the statistics window.
    #[inline(never)]
    pub(super) fn track_wear_step(&mut self, t: f64) {
        let dt = self.settings.dt;
        let Some(map) = &mut self.state.wear_map else {
            return;
        };
        if !self.settings.statistics.step_in_window(t, dt) {
            return;
        }
        let contacts = self.state.contacts.iter().zip(&self.model.contacts);
        for (k, ((s, c), rows)) in contacts.zip(&self.work.frame_rows).enumerate() {
            if s.closed {
                map.add(k, &s.values(c, rows.as_ref(), t), dt);
            }
        }
    }

    /// The statistics so far, without ending the run (its recorder is empty).
    pub fn partial_results(&self, wall_time: f64) -> RunResults {
        let state = &self.state;
        let mut statistics = state.statistics.clone();
        let contacts = statistics.finish(
            &self.settings.statistics,
            &self.work.names,
            self.settings.dt,
        );
        RunResults {
            recorder: Recorder::new(0, state.modal.q.len(), state.contacts.len()),
            contacts,
            impacts: Vec::new(),
            blocks: Vec::new(),
            solver: state.solver.clone(),
            energy: {
                let mut energy = state.energy.clone();
                energy.settle();
                energy
            },
            steps: state.step,
            dt: self.settings.dt,
            stable_dt: self.work.stable_dt,
            wall_time,
            termination: Termination::InProgress { step: state.step },
            target_met_at: state.statistics.target_met(),
            monitors: self.monitor_statistics(),
        }
    }

    /// Ends the run: window statistics, last partial block, the samples and impacts not
    /// drained. `wall_time` is the caller's measure of the time spent stepping.
    pub fn finish(mut self, wall_time: f64, termination: Termination) -> RunResults {
        self.recorder.truncate();
        let monitors = self.monitor_statistics();
        let dt = self.settings.dt;
        let mut state = self.state;
        let names = &self.work.names;
        let steps = state.step;
        let stable_dt = self.work.stable_dt;
        let contacts = (state.statistics).finish(&self.settings.statistics, names, dt);
        state.energy.settle();
        let mut blocks = std::mem::take(&mut state.statistics.blocks);
        crate::accumulate::statistics::name_blocks(&mut blocks, names);
        RunResults {
            target_met_at: state.statistics.target_met(),
            contacts,
            impacts: std::mem::take(&mut state.statistics.impacts),
            blocks,
            recorder: self.recorder,
            solver: state.solver,
            energy: state.energy,
            steps,
            dt,
            stable_dt,
            wall_time,
            termination,
            monitors,
        }
    }

    /// The monitors' statistics so far.
    fn monitor_statistics(&self) -> Vec<MonitorStatistics> {
        let monitors = self.settings.monitors.iter();
        monitors
            .zip(&self.state.monitors)
            .map(|(m, sums)| sums.finish(m))
            .collect()
    }
}
