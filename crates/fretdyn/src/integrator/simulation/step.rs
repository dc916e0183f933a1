//! A run in progress ([`Simulation`]): its [`State`] (what a checkpoint holds), its
//! [`Workspace`] (rebuilt from the model) and its output samples; and its step, which runs
//! the phases in order, each in its own file as an `impl Simulation` block (the same code
//! path as one file; THEORY §2, steps 1–7):
//! 1. `loads`: the external force (loads, turbulence, fluid-elastic force) with the predictor;
//! 2. `detection`: contact positions, frames, velocities, normal forces;
//! 3. `forces` (with `penalty`, the penalty tangential law): the modal force with the contact
//!    forces, and the free acceleration;
//! 4. `lagrange`: the Lagrange tangential solve (Gauss–Seidel or Active Set);
//! 5. `bookkeeping`: energy and powers, output samples, statistics, results.
//!
//! Everything the steps touch is allocated before the first step.

use nalgebra::Vector2;

use super::contact_kinds::{AnyContacts, CommonContacts, ContactKinds};
use super::results::Divergence;
use super::state::{Snapshot, State};
use super::workspace::{Workspace, accumulation_bound, modal_force};
use crate::accumulate::energy::EnergyBalance;
use crate::accumulate::recorder::Recorder;
use crate::accumulate::statistics::ContactStatisticsState;
use crate::accumulate::wear_map::WearMap;
use crate::contact::friction::Slide;
use crate::contact::tangential::SolverStatistics;
use crate::error::{Error, Result};
use crate::integrator::stability::stable_time_step;
use crate::model::Model;
use crate::numerics::{Lanes, Portable};
use crate::settings::RunSettings;
use crate::settings::run::round_down;

/// A run in progress: create it with [`Simulation::new`] (or [`Simulation::resume`]), advance
/// it with [`Simulation::steps`], drain its [`Recorder`] and finished impacts as it goes, end
/// it with [`Simulation::finish`]. [`super::drive`] does all of it, batch by batch.
pub struct Simulation<'m> {
    pub(super) model: &'m Model,
    pub(super) settings: &'m RunSettings,
    /// What the steps carry from one to the next (a checkpoint's content).
    pub(super) state: State,
    /// What the steps rebuild from the model.
    pub(super) work: Workspace<'m>,
    /// The output samples not yet drained.
    pub(super) recorder: Recorder,
}

impl<'m> Simulation<'m> {
    /// Checks the model and the settings (Δt against the stability limit), allocates
    /// everything the steps need, with room for every output sample of the run, and computes
    /// the state at t = 0 (the first sample).
    /// A run whose time histories would not fit in memory is refused before anything is
    /// allocated ([`Recorder::check_memory`]).
    pub fn new(model: &'m Model, settings: &'m RunSettings) -> Result<Self> {
        settings.validate()?;
        let samples = settings.steps / settings.output_every + 1;
        Recorder::check_memory(samples, model.basis.modes(), model.contacts.len(), 1)?;
        Self::with_recorder(model, settings, samples as usize)
    }

    /// As [`Self::new`], with room for `samples` output samples only: the caller drains the
    /// recorder ([`Recorder::clear`]) before it is full, so that memory does not grow with the
    /// length of the run.
    pub fn with_recorder(
        model: &'m Model,
        settings: &'m RunSettings,
        samples: usize,
    ) -> Result<Self> {
        let stable_dt = Self::check(model, settings)?;
        let work = Workspace::new(model, settings, stable_dt)?;
        let state = work.initial_state(model, settings);
        let mut sim = Self::assemble(model, settings, state, work, samples);
        sim.start();
        // an initial state so large that its energy overflows cannot give a finite run
        let initial = sim.state.energy.initial;
        if !(initial.is_finite() && initial.abs() < sim.work.accumulation_bound) {
            return Err(Error::invalid(
                "initial",
                format!(
                    "the initial displacement and velocity give an energy of {initial:e} J, too \
                     large to compute with: check their units (m, m/s)"
                ),
            ));
        }
        Ok(sim)
    }

    /// Continues a run from a [`Snapshot`] taken by [`Self::snapshot`] on the same model and
    /// settings; the recorder (room for `samples`) starts empty, at the step after it.
    pub fn resume(
        model: &'m Model,
        settings: &'m RunSettings,
        snapshot: Snapshot,
        samples: usize,
    ) -> Result<Self> {
        let stable_dt = Self::check(model, settings)?;
        let mut work = Workspace::new(model, settings, stable_dt)?;
        snapshot.state.check_fits(model, settings)?;
        let restored = match (&mut work.fluid, &snapshot.fluid) {
            (None, None) => true,
            (Some(f), Some(h)) => f.restore(h),
            _ => false,
        };
        if !restored {
            return Err(Error::invalid(
                "checkpoint",
                "its fluid-elastic delay does not match the case: was the case file changed \
                 since the run started?",
            ));
        }
        Ok(Self::assemble(
            model,
            settings,
            snapshot.state,
            work,
            samples,
        ))
    }

    fn assemble(
        model: &'m Model,
        settings: &'m RunSettings,
        state: State,
        work: Workspace<'m>,
        samples: usize,
    ) -> Self {
        let recorder = Recorder::new(samples.max(1), model.basis.modes(), model.contacts.len());
        Self {
            model,
            settings,
            state,
            work,
            recorder,
        }
    }

    /// The state after the steps done, for [`Self::resume`].
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            state: self.state.clone(),
            fluid: self.work.fluid.as_ref().map(|f| f.history()),
        }
    }

    /// The state after the steps done.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// Tracks where each contact's friction work is done, from now on, `angular_bins` around
    /// each hole ([`WearMap`]; for the service life, THEORY §14.4). Part of the [`State`]:
    /// a snapshot carries it.
    pub fn track_wear(&mut self, angular_bins: usize) {
        self.state.wear_map = Some(WearMap::new(self.model, angular_bins));
    }

    /// Where the friction work was done, when tracked ([`Self::track_wear`]).
    pub fn wear_map(&self) -> Option<&WearMap> {
        self.state.wear_map.as_ref()
    }

    /// The model simulated.
    pub fn model(&self) -> &'m Model {
        self.model
    }

    /// The settings of the run.
    pub fn settings(&self) -> &'m RunSettings {
        self.settings
    }

    /// Steps done.
    pub fn steps_done(&self) -> u64 {
        self.state.step
    }

    /// Steps between the run loop's looks at the progress, the clock and the finished rows
    /// ([`Self::steps_to_batch_end`]).
    pub const BATCH: u64 = 1024;

    /// Steps from here to the next multiple of [`Self::BATCH`], or to `total` when it comes
    /// first: what the run loop asks of [`Self::steps`] at a time.
    pub fn steps_to_batch_end(&self, total: u64) -> u64 {
        let n = self.state.step;
        total.saturating_sub(n).min(Self::BATCH - n % Self::BATCH)
    }

    /// Time reached, s.
    pub fn time(&self) -> f64 {
        self.state.step as f64 * self.settings.dt
    }

    /// Stability limit of the time step, s.
    pub fn stable_dt(&self) -> f64 {
        self.work.stable_dt
    }

    /// The output samples not yet drained.
    pub fn recorder(&self) -> &Recorder {
        &self.recorder
    }

    /// The output samples, to drain ([`Recorder::clear`]).
    pub fn recorder_mut(&mut self) -> &mut Recorder {
        &mut self.recorder
    }

    /// End time of the step at which the target relative error of the statistics was met
    /// (`[statistics] target_relative_error`): the run stops there.
    #[inline]
    pub fn target_met(&self) -> Option<f64> {
        self.state.statistics.target_met()
    }

    /// Statistics in progress, whose finished impacts and blocks may be drained.
    pub(crate) fn statistics_mut(&mut self) -> &mut ContactStatisticsState {
        &mut self.state.statistics
    }

    /// Solver counters so far.
    pub fn solver_statistics(&self) -> &SolverStatistics {
        &self.state.solver
    }

    /// Energy balance so far.
    pub fn energy(&self) -> &EnergyBalance {
        &self.state.energy
    }

    /// Checks the model and the settings, Δt against the stability limit; returns that
    /// limit. [`Self::new`] does it; a front end calls it to refuse bad input before it
    /// creates any output.
    pub fn check(model: &Model, settings: &RunSettings) -> Result<f64> {
        model.validate()?;
        settings.validate()?;
        let stable_dt = stable_time_step(model, &settings.method);
        if settings.dt >= stable_dt {
            return Err(Error::UnstableTimeStep {
                dt: settings.dt,
                limit: stable_dt,
                suggest: round_down(0.9 * stable_dt),
            });
        }
        Ok(stable_dt)
    }

    /// t = 0: contacts at the initial state, initial acceleration, first sample.
    fn start(&mut self) {
        self.external_force::<Portable>(0, 0.0);
        self.fluid_elastic_force::<Portable>(0, false);
        let _ = self.detect::<Portable, AnyContacts>(0.0, false);
        self.contact_forces::<Portable, AnyContacts>();
        let w = &mut self.work;
        w.cd.start(
            &mut self.state.modal,
            modal_force(&w.closed, &w.external, &w.force),
        );
        self.full_step_velocities::<Portable, AnyContacts>(true);
        for c in &mut self.state.contacts {
            // the velocities were the initial (full-step) ones already
            if c.closed && c.tangential_force == Vector2::zeros() {
                c.slide = if c.tangential_velocity().norm() > 0.0 {
                    Slide::Slip
                } else {
                    Slide::Stick
                };
            }
        }
        let modal = (self.work.cd).energy_and_powers(&self.state.modal, &self.work.external);
        let (e, powers) = self.energy_and_powers::<Portable, AnyContacts>(modal);
        self.state.energy = EnergyBalance::start(e, powers);
        self.state.statistics.start(
            self.state
                .contacts
                .iter()
                .map(|c| (c.frame.penetration, c.closed)),
        );
        if self.work.window_opens == 0 {
            self.open_statistics_window();
        }
        // the initial state is the input's: the steps check what they add
        let _ = self.sample();
    }

    /// One step n → n+1: the state, the statistics and, every `output_every` steps, an
    /// output sample.
    ///
    /// A step whose values cannot all be kept stops the run with a [`Divergence`], and
    /// nothing of it is kept: the statistics, the energy balance and the samples cover the
    /// steps before it, and are finite. It is checked before anything is accumulated
    /// ([`Self::accumulation_bound`]): every contact's forces, penetration and velocity,
    /// which bound the products the statistics form from them (THEORY §5; the divergence
    /// names the first such contact), the energy and the powers of the balance (the
    /// structure's state; no contact named), and at a sample step every value of the sample.
    ///
    /// On a processor with AVX2 and FMA (x86-64, detected at run time) the step runs as code
    /// compiled for them: the same operations in the same order on wider vectors, so the
    /// results are bit for bit those of the portable code ([`Self::use_portable_kernels`]).
    ///
    /// In the common case (every obstacle a fixed plane or fixed bars, an undamped normal law,
    /// friction by Lagrange multipliers) the phases that visit the contacts run as the same
    /// code compiled for that case only (`contact_kinds`, [`Self::runs_common_step`]): the
    /// same results bit for bit ([`Self::use_general_step`]).
    pub fn step(&mut self) -> std::result::Result<(), Divergence> {
        self.steps(1).map(|_| ())
    }

    /// Up to `n` steps ([`Self::step`]): fewer when the recorder is full after a step (to be
    /// drained, [`Recorder::is_full`]) or when the statistics meet their target in one of
    /// them ([`Self::target_met`]: the run stops there). Returns the steps done; on a
    /// divergence, the steps before it are kept. The same results as `n` calls of
    /// [`Self::step`], for less work per step (the code is chosen once).
    pub fn steps(&mut self, n: u64) -> std::result::Result<u64, Divergence> {
        #[cfg(target_arch = "x86_64")]
        if self.work.wide {
            // SAFETY: `wide` is set only when the processor has AVX2 and FMA (checked at run
            // time when the workspace is built).
            return unsafe {
                if self.work.common_contacts {
                    self.steps_avx2::<CommonContacts>(n)
                } else {
                    self.steps_avx2::<AnyContacts>(n)
                }
            };
        }
        if self.work.common_contacts {
            self.steps_with::<Portable, CommonContacts>(n)
        } else {
            self.steps_with::<Portable, AnyContacts>(n)
        }
    }

    /// Runs the steps with the portable (SSE2 on x86-64) code even when the processor has
    /// AVX2: for comparisons and tests.
    pub(crate) fn use_portable_kernels(&mut self) {
        self.work.wide = false;
    }

    /// Runs the steps with the code compiled for any contact even when the case is the
    /// common one (`contact_kinds`): for comparisons and tests.
    pub(crate) fn use_general_step(&mut self) {
        self.work.common_contacts = false;
    }

    /// Whether the steps run the code compiled for the common case: every obstacle a fixed
    /// plane or fixed bars, an undamped normal law, friction by Lagrange multipliers (the same
    /// results as the general code, bit for bit, faster).
    pub(crate) fn runs_common_step(&self) -> bool {
        self.work.common_contacts
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn steps_avx2<O: ContactKinds>(
        &mut self,
        n: u64,
    ) -> std::result::Result<u64, Divergence> {
        // each version of the step its own copy of the kernels, inlined
        self.steps_with::<crate::numerics::Avx2<O>, O>(n)
    }

    /// [`Self::steps`] with the reduction kernels `K` ([`crate::kernels`]), for the contacts
    /// `O`.
    #[inline(always)]
    fn steps_with<K: Lanes, O: ContactKinds>(
        &mut self,
        n: u64,
    ) -> std::result::Result<u64, Divergence> {
        let until_target = self.state.statistics.target_met().is_none();
        for done in 1..=n {
            self.try_step::<K, O>()
                .inspect_err(|_| self.state.step -= 1)?;
            if self.recorder.is_full()
                || (until_target && self.state.statistics.target_met().is_some())
            {
                return Ok(done);
            }
        }
        Ok(n)
    }

    /// The step; on `Err`, nothing of it was accumulated or sampled.
    #[inline(always)]
    fn try_step<K: Lanes, O: ContactKinds>(&mut self) -> std::result::Result<(), Divergence> {
        self.state.step += 1;
        let t = self.state.step as f64 * self.settings.dt;
        self.predict_with_first_load::<K>(self.state.step, t);
        self.other_loads::<K>(self.state.step, t);
        if self.work.fluid.is_some() {
            self.fluid_elastic_force::<K>(self.state.step, true);
        }
        let open_within = self.detect::<K, O>(t, true);
        self.free_acceleration::<K, O>();
        self.lagrange::<K>();
        let modal = (self.work.cd).correct_with::<K>(&mut self.state.modal, &self.work.external);
        self.full_step_velocities::<K, O>(false);

        let dt = self.settings.dt;
        let bound = self.work.accumulation_bound;
        let step = self.state.step;
        let diverged = move |contact: Option<usize>| Divergence {
            step,
            time: t,
            contact,
        };
        // the open contacts were checked by detection, the closed ones are checked here
        let (closed, contacts) = (&self.work.closed, &self.state.contacts);
        if !(open_within && closed.iter().all(|&k| contacts[k].accumulable(bound))) {
            let first = contacts.iter().position(|c| !c.accumulable(bound));
            return Err(diverged(first));
        }
        let (e, powers) = self.energy_and_powers::<K, O>(modal);
        let magnitude = e.abs() + powers.iter().map(|p| p.abs()).sum::<f64>();
        if magnitude > bound || magnitude.is_nan() {
            return Err(diverged(None));
        }
        let sample = self.state.step == self.state.next_sample;
        if sample {
            self.full_step_velocities::<K, O>(true);
            if let Some(k) = self.sample() {
                self.recorder.discard_last();
                return Err(diverged(Some(k)));
            }
        }
        self.state.energy.step(e, powers, dt);
        let model = self.model;
        let values = (self.state.contacts.iter())
            .zip(&model.contacts)
            .zip(&self.work.frame_rows)
            .map(|((s, c), rows)| s.statistics_step(c, O::rows(rows), t));
        (self.state.statistics).step(&self.settings.statistics, t, dt, values);
        if self.state.step == self.work.window_opens {
            self.open_statistics_window();
        }
        if self.state.wear_map.is_some() {
            self.track_wear_step(t);
        }
        if sample {
            self.state.next_sample =
                (self.state.next_sample).saturating_add(self.settings.output_every);
        }
        Ok(())
    }

    /// Largest value a step may add to a running sum of the statistics or of the energy
    /// balance (a force, a square, a power, a penetration): `f64::MAX / (8 (N + 1) max(1, Δt))`
    /// for `N` steps, so that no sum of the run can overflow — a step above it has diverged.
    /// (About 2e298 for a billion steps: no physical value comes near it.)
    pub fn accumulation_bound(settings: &RunSettings) -> f64 {
        accumulation_bound(settings)
    }
}
