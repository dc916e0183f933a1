//! Phase 4 of a step — the bookkeeping: energy and powers for the balance, the output
//! sample, the per-contact values for the statistics, and the results (THEORY §5).

use super::contact_kinds::ContactKinds;
use super::{ContactState, RunResults, Simulation, Termination};
use crate::accumulate::recorder::{ContactSample, Recorder};
use crate::accumulate::statistics::{ContactStep, StepValues};
use crate::contact::frame_rows::FrameRows;
use crate::contact::friction::Slide;
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
        let fluid = match &self.fluid {
            Some(f) => K::dot(&f.force, &self.cd.qd),
            None => 0.0,
        };
        external -= fluid;
        let mut contact_damping = 0.0;
        let mut tangential = 0.0;
        let mut obstacle = 0.0;
        for &k in &self.closed {
            let (c, s) = (&self.model.contacts[k], &self.contacts[k]);
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
        let t = self.step as f64 * self.settings.dt;
        if !self.recorder.push_state(t, &self.cd.q, &self.cd.qd) {
            return None;
        }
        let mut non_finite = None;
        for (k, (s, c)) in self
            .contacts
            .iter_mut()
            .zip(&self.model.contacts)
            .enumerate()
        {
            if self.frame_rows[k].is_some() {
                // a plane's or bars' 3-D position is formed for the samples only
                let pt = &self.model.basis.points[c.point];
                s.x = pt.coords + recombine(&pt.rows, &self.cd.q);
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
        non_finite
    }

    /// Opens the statistics window at the end of the current step (THEORY §11): an impact
    /// under way starts there, with the normal approach speed `−n·(Φ_c q̇ − ḋ)` of its
    /// contact at that time as its impact speed (the full-step velocities, those of the step
    /// or at t = 0 the initial ones; the obstacle's full-step velocity, set for the closed
    /// contacts).
    #[cold]
    #[inline(never)]
    pub(super) fn open_statistics_window(&mut self) {
        let t = self.step as f64 * self.settings.dt;
        let (model, surface_rows, qd) = (self.model, &self.surface_rows, &self.cd.qd);
        let speeds = self.contacts.iter().enumerate().map(|(k, s)| {
            if !s.closed {
                return 0.0;
            }
            let rows = super::contact_rows(model, surface_rows, k);
            -s.frame
                .normal
                .dot(&(recombine(rows, qd) - s.frame.velocity))
        });
        self.statistics.open_window(t, speeds);
    }

    /// The statistics so far, without ending the run (its recorder is empty).
    pub fn partial_results(&self, wall_time: f64) -> RunResults {
        let mut statistics = self.statistics.clone();
        let contacts = statistics.finish(&self.settings.statistics, &self.names, self.settings.dt);
        RunResults {
            recorder: Recorder::new(0, self.cd.q.len(), self.contacts.len()),
            contacts,
            impacts: Vec::new(),
            blocks: Vec::new(),
            solver: self.solver_stats.clone(),
            energy: {
                let mut energy = self.energy.clone();
                energy.settle();
                energy
            },
            steps: self.step,
            dt: self.settings.dt,
            stable_dt: self.stable_dt,
            wall_time,
            termination: Termination::InProgress { step: self.step },
            target_met_at: self.statistics.target_met(),
        }
    }

    /// Ends the run: window statistics, last partial block, the samples and impacts not
    /// drained. `wall_time` is the caller's measure of the time spent stepping.
    pub fn finish(mut self, wall_time: f64, termination: Termination) -> RunResults {
        self.recorder.truncate();
        let dt = self.settings.dt;
        let steps = self.step;
        let stable_dt = self.stable_dt;
        let contacts = self
            .statistics
            .finish(&self.settings.statistics, &self.names, dt);
        self.energy.settle();
        let mut blocks = std::mem::take(&mut self.statistics.blocks);
        crate::accumulate::statistics::name_blocks(&mut blocks, &self.names);
        RunResults {
            target_met_at: self.statistics.target_met(),
            contacts,
            impacts: std::mem::take(&mut self.statistics.impacts),
            blocks,
            recorder: self.recorder,
            solver: self.solver_stats,
            energy: self.energy,
            steps,
            dt,
            stable_dt,
            wall_time,
            termination,
        }
    }
}

/// One contact's step ending at `t` for the statistics (THEORY §5): an open contact's offset
/// and penetration, or a closed one's [`step_values`].
#[inline(always)]
pub(super) fn contact_step(
    s: &ContactState,
    c: &crate::contact::Contact,
    rows: Option<&FrameRows>,
    t: f64,
) -> ContactStep {
    if s.closed {
        ContactStep::Closed(step_values(s, c, rows, t))
    } else {
        ContactStep::Open {
            radial: offset(s, c, rows, t).0,
            penetration: s.frame.penetration,
        }
    }
}

/// The offset of contact `s` and its direction ([`StepValues::radial`],
/// [`StepValues::direction`]).
#[inline(always)]
fn offset(
    s: &ContactState,
    c: &crate::contact::Contact,
    rows: Option<&FrameRows>,
    t: f64,
) -> (f64, [f64; 2]) {
    if rows.is_some() {
        // a plane or bars: the distance from the (mid-)plane, THEORY §5
        (s.distance, [1.0, 0.0])
    } else if c.obstacle.is_hole() {
        let local = c.local(&s.x, t);
        let r = local.norm();
        let unit = if r > 0.0 {
            [local.x / r, local.y / r]
        } else {
            [1.0, 0.0]
        };
        (r, unit)
    } else {
        (c.local(&s.x, t).x, [1.0, 0.0])
    }
}

/// One contact's values of the step ending at `t`, for the statistics (THEORY §5).
#[inline(always)]
pub(super) fn step_values(
    s: &ContactState,
    c: &crate::contact::Contact,
    rows: Option<&FrameRows>,
    t: f64,
) -> StepValues {
    let (radial, direction) = offset(s, c, rows, t);
    let (slip_speed, friction_power, tangential) = if s.closed {
        let vt = s.tangential_velocity();
        (
            vt.norm(),
            s.tangential_force.dot(&vt).abs(),
            s.tangential_force.norm(),
        )
    } else {
        (0.0, 0.0, 0.0)
    };
    StepValues {
        t,
        closed: s.closed,
        stick: s.slide == Slide::Stick,
        normal: s.normal_force,
        tangential,
        slip_speed,
        friction_power,
        penetration: s.frame.penetration,
        radial,
        direction,
    }
}
