//! The time-step loop: central differences on the modes, contacts on the physical basis at the
//! contact points only, tangential forces by the chosen method (THEORY §2, steps 1–7).
//!
//! Everything the loop touches is allocated before the first step.
//!
//! A step ([`Simulation::step`], in this file) runs its phases in order, each in its own file
//! as an `impl Simulation` block (the same code path as one file):
//! 1. `detection`: external force, contact positions, frames, velocities, normal forces;
//! 2. `normal`: the modal force with the contact forces (and the penalty tangential law);
//! 3. `tangential`: the Lagrange tangential solve (Gauss–Seidel or Active Set);
//! 4. `bookkeeping`: energy and powers, output samples, statistics values, results.
//!
//! `settings` holds [`RunSettings`]; `run` the run as a whole ([`simulate`], [`run`],
//! [`RunResults`], [`Termination`], [`Snapshot`]).

mod bookkeeping;
mod contact_kinds;
mod detection;
mod normal;
mod run;

mod tangential;

pub use crate::settings::RunSettings;
pub use run::{
    Divergence, Progress, RunResults, Termination, run, simulate, statistics_run,
    statistics_run_from, statistics_run_until,
};

use crate::settings::run::round_down;
use bookkeeping::{contact_step, step_values};
use contact_kinds::{AnyContacts, CommonContacts, ContactKinds};
use tangential::{LagrangeSolver, Tangential};

use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::accumulate::energy::{EnergyBalance, EnergyRaw};
use crate::accumulate::recorder::Recorder;
use crate::accumulate::statistics::ContactStatisticsState;
use crate::accumulate::wear_map::WearMap;
use crate::contact::frame_rows::FrameRows;
use crate::contact::friction::Slide;
use crate::contact::obstacle::ContactFrame;
use crate::contact::tangential::active_set::{ActiveSet, History};
use crate::contact::tangential::penalty::PenaltyContact;
use crate::contact::tangential::{SolverStatistics, TangentialMethod};
use crate::error::{Error, Result};
use crate::integrator::central_difference::CentralDifference;
use crate::integrator::stability::stable_time_step;
use crate::kernels::{Lanes, PaddedRows, Portable};
use crate::loads::fluid_elastic::{DelayHistory, FluidElasticForce};
use crate::loads::stepped::SteppedHistory;
use crate::model::Model;
use crate::structure::modal::project_add;

/// Everything that the steps after step `step` depend on: a run restored from it continues
/// bit for bit as the run it was taken from ([`Simulation::snapshot`],
/// [`Simulation::resume`]). The loads are pure functions of time and need nothing here.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Steps done.
    pub step: u64,
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    contacts: Vec<ContactState>,
    penalty: Vec<PenaltyContact>,
    history: Vec<History>,
    previous_lambda: Vec<Vector2<f64>>,
    statistics: ContactStatisticsState,
    solver: SolverStatistics,
    energy: EnergyRaw,
    /// The past displacements of the fluid-elastic delays.
    #[serde(default)]
    fluid: Option<DelayHistory>,
}

impl Snapshot {
    /// The end time of the step at which the run met its target relative error, if it did
    /// (the run ended there).
    pub fn target_met(&self) -> Option<f64> {
        self.statistics.target_met()
    }
}

impl Snapshot {
    /// Binary encoding (CBOR: exact for every `f64`).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut bytes = Vec::new();
        ciborium::into_writer(self, &mut bytes).expect("a snapshot always serializes");
        bytes
    }

    /// Decodes [`Self::to_bytes`]; `None` when the bytes are not a snapshot.
    pub fn from_bytes(bytes: &[u8]) -> Option<Self> {
        ciborium::from_reader(bytes).ok()
    }
}

/// Per-contact state within a step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct ContactState {
    frame: ContactFrame,
    /// Physical position of the point: updated at every step for a hole, at output samples
    /// only for a plane or bars (whose detection needs [`Self::distance`] only).
    x: Vector3<f64>,
    /// Plane or bars ([`FrameRows`]): the signed distance `s = (x − d(t) − x₀)·n`.
    distance: f64,
    /// Position of the contact point (on the surface for a tube contact) relative to the
    /// moving obstacle: the penalty law's anchor lives in this frame.
    x_relative: Vector3<f64>,
    /// Velocity of the point relative to the obstacle along the frame's normal (predicted
    /// during the step, full-step after; see [`Simulation::full_step_velocities`]); formed
    /// only when the normal law has damping, 0 otherwise.
    v_normal: f64,
    /// Its tangential velocity relative to the obstacle, tangent basis.
    v_tangential: Vector2<f64>,
    normal_force: f64,
    /// Tangential force of the obstacle on the structure, tangent basis.
    tangential_force: Vector2<f64>,
    closed: bool,
    slide: Slide,
    /// Lagrange methods: the stick constraint held this contact's full-step velocity to the
    /// obstacle's — it sticks at this step and, with the half-step constraint, stuck at the
    /// previous one too, so both half-step velocities whose mean is `q̇_{n+1}` were imposed
    /// (THEORY §2). Its slip velocity is then zero by construction and is reported as exactly
    /// 0, without the round-off of `Φ_c q̇_{n+1}` (THEORY §5: in stick `v_T = 0`). Set within
    /// each step, so not part of a snapshot.
    #[serde(skip)]
    held: bool,
}

impl ContactState {
    /// Contact force on the structure, global axes: `R_N n + T R_T`.
    fn force(&self) -> Vector3<f64> {
        let t = &self.frame.tangents;
        self.frame.normal * self.normal_force
            + t[0] * self.tangential_force.x
            + t[1] * self.tangential_force.y
    }

    /// Tangential velocity relative to the obstacle, tangent basis; exactly 0 when
    /// [held](Self::held) in stick.
    fn tangential_velocity(&self) -> Vector2<f64> {
        if self.held {
            return Vector2::zeros();
        }
        self.v_tangential
    }

    /// True when `R_N² + |R_T|² + δ² + |v|²` (`v` of a closed contact only: an open one's is
    /// not used) is at most `bound/4` (false for a non-finite value). Then every increment
    /// the statistics form from the contact's values is at most `bound`
    /// ([`Simulation::accumulation_bound`]): the squares of the forces and of the
    /// penetration, the friction powers `|R_T·v_T| ≤ (|R_T|² + |v|²)/2` and
    /// `R_N |v_T| ≤ (R_N² + |v|²)/2` (THEORY §5), and the point's offset, which is the
    /// penetration give or take the obstacle's clearance.
    #[inline]
    fn accumulable(&self, bound: f64) -> bool {
        let v2 = if self.closed {
            self.v_normal * self.v_normal + self.v_tangential.norm_squared()
        } else {
            0.0
        };
        self.normal_force * self.normal_force
            + self.tangential_force.norm_squared()
            + self.frame.penetration * self.frame.penetration
            + v2
            <= 0.25 * bound
    }

    fn status_code(&self) -> i8 {
        match (self.closed, self.slide) {
            (false, _) => 0,
            (true, Slide::Stick) => 1,
            (true, Slide::Slip) => 2,
        }
    }
}

/// A run in progress: create it with [`Simulation::new`] (or [`Simulation::resume`]), advance
/// it with [`Simulation::step`], drain its [`Recorder`] and finished impacts as it goes, end
/// it with [`Simulation::finish`]. [`run`] does all of it for a run held in memory.
pub struct Simulation<'m> {
    model: &'m Model,
    settings: &'m RunSettings,
    cd: CentralDifference,
    contacts: Vec<ContactState>,
    /// The contacts closed at this step, in order (set by detection): the phases after it
    /// visit these only.
    closed: Vec<usize>,
    tangential: Tangential,
    /// Rows (3 × p) of the contact points on the tube surface, one block per contact (used
    /// only by contacts with a radius), updated with the normal at each step (once for a
    /// plane).
    surface_rows: Vec<f64>,
    /// Per contact: the frame rows of a plane or bars, `None` for a hole.
    frame_rows: Vec<Option<FrameRows>>,
    /// The common step's detection ([`contact_kinds::CommonContacts`]): every contact's
    /// normal row `n·Φ_c` ([`FrameRows::row`]), laid out for one pass over `q` that forms
    /// all their dot products ([`Lanes::padded_dots`]). Empty for the general step.
    normal_rows: PaddedRows,
    /// Work space of that detection: `normal_rows q`, one value per contact.
    normal_dots: Vec<f64>,
    /// The fluid-elastic force with its past displacements, when the model has one.
    fluid: Option<FluidElasticForce>,
    /// Modal loads `Φ_lᵀ F_l`, one row of p per load.
    load_rows: Vec<f64>,
    /// The time history of each row of `load_rows`, in order.
    load_histories: Vec<SteppedHistory<'m>>,
    /// Signal generators of the turbulent loads, one per load.
    turbulence: Vec<crate::loads::turbulence::RandomChannels>,
    /// Work space: the turbulence signals at the current time.
    signals: Vec<f64>,
    external: Vec<f64>,
    force: Vec<f64>,
    names: Vec<String>,
    statistics: ContactStatisticsState,
    /// The last step before the statistics window, at whose end the window opens
    /// ([`Self::open_statistics_window`]; `u64::MAX`: never).
    window_opens: u64,
    solver_stats: SolverStatistics,
    stable_dt: f64,
    energy: EnergyBalance,
    recorder: Recorder,
    step: u64,
    /// The step of the next output sample (a multiple of `output_every`).
    next_sample: u64,
    /// [`Self::accumulation_bound`] of the settings.
    accumulation_bound: f64,
    /// Run the steps as code compiled for AVX2 and FMA ([`Self::step`]).
    wide: bool,
    /// Run the contact phases compiled for the common case ([`contact_kinds`]).
    common_contacts: bool,
    /// Where the friction work is done, when tracked ([`Self::track_wear`]).
    wear_map: Option<WearMap>,
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
        let mut sim = Self::allocate(model, settings, stable_dt, samples.max(1))?;
        sim.start();
        // an initial state so large that its energy overflows cannot give a finite run
        if !(sim.energy.initial.is_finite() && sim.energy.initial.abs() < sim.accumulation_bound) {
            return Err(Error::invalid(
                "initial",
                format!(
                    "the initial displacement and velocity give an energy of {:e} J, too large \
                     to compute with: check their units (m, m/s)",
                    sim.energy.initial
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
        let mut sim = Self::allocate(model, settings, stable_dt, samples.max(1))?;
        let p = model.basis.modes();
        let nc = model.contacts.len();
        let mismatch = |what: &str| {
            Error::invalid(
                "checkpoint",
                format!(
                    "its {what} does not match the case: was the case file changed since the run started?"
                ),
            )
        };
        if snapshot.q.len() != p || snapshot.qd.len() != p || snapshot.qdd.len() != p {
            return Err(mismatch("number of modes"));
        }
        if snapshot.contacts.len() != nc
            || snapshot.history.len() != nc
            || snapshot.previous_lambda.len() != nc
            || !snapshot.statistics.has_contacts(nc)
        {
            return Err(mismatch("number of contacts"));
        }
        sim.step = snapshot.step;
        sim.next_sample =
            (snapshot.step / settings.output_every + 1).saturating_mul(settings.output_every);
        sim.cd.q.copy_from_slice(&snapshot.q);
        sim.cd.qd.copy_from_slice(&snapshot.qd);
        sim.cd.qdd.copy_from_slice(&snapshot.qdd);
        sim.contacts = snapshot.contacts;
        match &mut sim.tangential {
            Tangential::Penalty { contacts, .. } => {
                if snapshot.penalty.len() != nc {
                    return Err(mismatch("tangential method"));
                }
                *contacts = snapshot.penalty;
            }
            Tangential::Lagrange {
                history,
                previous_lambda,
                ..
            } => {
                if !snapshot.penalty.is_empty() {
                    return Err(mismatch("tangential method"));
                }
                *history = snapshot.history;
                *previous_lambda = snapshot.previous_lambda;
            }
        }
        sim.statistics = snapshot.statistics;
        sim.solver_stats = snapshot.solver;
        sim.energy = EnergyBalance::from_raw(&snapshot.energy);
        let restored = match (&mut sim.fluid, &snapshot.fluid) {
            (None, None) => true,
            (Some(f), Some(h)) => f.restore(h),
            _ => false,
        };
        if !restored {
            return Err(mismatch("fluid-elastic delay"));
        }
        Ok(sim)
    }

    /// The state after the steps done, for [`Self::resume`].
    pub fn snapshot(&self) -> Snapshot {
        let nc = self.contacts.len();
        let (penalty, history, previous_lambda) = match &self.tangential {
            Tangential::Penalty { contacts, .. } => (
                contacts.clone(),
                vec![History::default(); nc],
                vec![Vector2::zeros(); nc],
            ),
            Tangential::Lagrange {
                history,
                previous_lambda,
                ..
            } => (Vec::new(), history.clone(), previous_lambda.clone()),
        };
        Snapshot {
            step: self.step,
            q: self.cd.q.clone(),
            qd: self.cd.qd.clone(),
            qdd: self.cd.qdd.clone(),
            contacts: self.contacts.clone(),
            penalty,
            history,
            previous_lambda,
            statistics: self.statistics.clone(),
            solver: self.solver_stats.clone(),
            energy: self.energy.raw(),
            fluid: self.fluid.as_ref().map(|f| f.history()),
        }
    }

    /// Tracks where each contact's friction work is done, from now on, `angular_bins` around
    /// each hole ([`WearMap`]; for the service life, THEORY §14.4). Not carried by
    /// checkpoints.
    pub fn track_wear(&mut self, angular_bins: usize) {
        self.wear_map = Some(WearMap::new(self.model, angular_bins));
    }

    /// Where the friction work was done, when tracked ([`Self::track_wear`]).
    pub fn wear_map(&self) -> Option<&WearMap> {
        self.wear_map.as_ref()
    }

    /// Tracks the wear work from now on into `map`, the [`Self::wear_map`] of the same model
    /// at the snapshot this simulation was resumed from: a checkpoint of a service life's
    /// window carries the map beside the [`Snapshot`].
    pub fn track_wear_from(&mut self, map: WearMap) {
        self.wear_map = Some(map);
    }

    /// The model simulated.
    pub fn model(&self) -> &'m Model {
        self.model
    }

    /// Steps done.
    pub fn steps_done(&self) -> u64 {
        self.step
    }

    /// Steps between the run loops' looks at the progress, the clock and the finished rows
    /// ([`Self::steps_to_batch_end`]).
    pub const BATCH: u64 = 1024;

    /// Steps from here to the next multiple of [`Self::BATCH`], or to `total` when it comes
    /// first: what a run loop asks of [`Self::steps`] at a time.
    pub fn steps_to_batch_end(&self, total: u64) -> u64 {
        let n = self.step;
        total.saturating_sub(n).min(Self::BATCH - n % Self::BATCH)
    }

    /// Time reached, s.
    pub fn time(&self) -> f64 {
        self.step as f64 * self.settings.dt
    }

    /// Stability limit of the time step, s.
    pub fn stable_dt(&self) -> f64 {
        self.stable_dt
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
        self.statistics.target_met()
    }

    /// Statistics in progress, whose finished impacts and blocks may be drained.
    pub(crate) fn statistics_mut(&mut self) -> &mut ContactStatisticsState {
        &mut self.statistics
    }

    /// Solver counters so far.
    pub fn solver_statistics(&self) -> &SolverStatistics {
        &self.solver_stats
    }

    /// Energy balance so far.
    pub fn energy(&self) -> &EnergyBalance {
        &self.energy
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

    fn allocate(
        model: &'m Model,
        settings: &'m RunSettings,
        stable_dt: f64,
        samples: usize,
    ) -> Result<Self> {
        let p = model.basis.modes();
        let nc = model.contacts.len();
        let mut cd = CentralDifference::new(model, settings.dt);
        cd.q.copy_from_slice(&model.initial.q);
        cd.qd.copy_from_slice(&model.initial.qdot);
        let fluid = match &model.fluid_elastic {
            Some(fe) => {
                let (needed, available) = (
                    FluidElasticForce::ring_bytes(fe, settings.dt, p),
                    crate::structure::beam::available_memory(),
                );
                if needed > 0.5 * available {
                    return Err(Error::invalid(
                        "flow",
                        format!(
                            "the fluid-elastic delay of {:e} s is {:.0} time steps: the past displacements would need {}, more than half of the {} of memory available; check the velocity (τ = μ D / U) or the time step",
                            fe.longest_delay(),
                            fe.longest_delay() / settings.dt,
                            crate::structure::beam::gigabytes(needed),
                            crate::structure::beam::gigabytes(available)
                        ),
                    ));
                }
                Some(FluidElasticForce::new(fe, settings.dt, &model.initial.q))
            }
            None => None,
        };
        let mut load_rows = vec![0.0; p * model.loads.len()];
        for (l, load) in model.loads.iter().enumerate() {
            project_add(
                &model.basis.points[load.point].rows,
                &load.force,
                &mut load_rows[l * p..(l + 1) * p],
            );
        }
        for load in &model.modal_loads {
            load_rows.extend_from_slice(&load.row);
        }
        if let Some(base) = &model.base_acceleration {
            load_rows.extend(base.modal_row(&model.basis.participation));
        }
        let turbulence = model
            .turbulence
            .iter()
            .enumerate()
            .map(|(k, l)| {
                crate::loads::turbulence::RandomChannels::new(
                    &l.spectrum,
                    l.channels(p),
                    l.seed,
                    l.f_max,
                    &format!("turbulence[{k}]"),
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let channels = model
            .turbulence
            .iter()
            .map(|l| l.channels(p))
            .max()
            .unwrap_or(0);
        let tangential = match settings.method {
            TangentialMethod::Penalty(s) => Tangential::Penalty {
                settings: s,
                contacts: vec![PenaltyContact::default(); nc],
            },
            TangentialMethod::GaussSeidel(s) => {
                Tangential::lagrange(model, &cd, settings, LagrangeSolver::GaussSeidel(s))
            }
            TangentialMethod::ActiveSet(s) => Tangential::lagrange(
                model,
                &cd,
                settings,
                LagrangeSolver::ActiveSet(Box::new(ActiveSet::new(s, nc))),
            ),
        };
        let blank = ContactState {
            frame: ContactFrame {
                penetration: 0.0,
                normal: Vector3::zeros(),
                tangents: [Vector3::zeros(); 2],
                velocity: Vector3::zeros(),
            },
            x: Vector3::zeros(),
            distance: 0.0,
            x_relative: Vector3::zeros(),
            v_normal: 0.0,
            v_tangential: Vector2::zeros(),
            normal_force: 0.0,
            tangential_force: Vector2::zeros(),
            closed: false,
            slide: Slide::Stick,
            held: false,
        };
        let frame_rows: Vec<Option<FrameRows>> = model
            .contacts
            .iter()
            .map(|c| FrameRows::new(c, &model.basis.points[c.point]))
            .collect();
        let mut surface_rows = vec![0.0; 3 * p * nc];
        let mut contacts = vec![blank; nc];
        for (k, (c, rows)) in model.contacts.iter().zip(&frame_rows).enumerate() {
            if let Some(rows) = rows {
                contacts[k].frame = rows.frame(0.0);
                if c.at_surface() {
                    // a plane: the normal, and so the surface rows, never change
                    c.surface_rows(
                        &model.basis.points[c.point],
                        &contacts[k].frame.normal,
                        &mut surface_rows[3 * p * k..3 * p * (k + 1)],
                    );
                }
            }
        }
        let common_contacts =
            contact_kinds::is_common(&model.contacts, &frame_rows, &settings.method);
        let normal_rows = if common_contacts {
            let rows: Vec<&[f64]> = frame_rows.iter().flatten().map(|r| r.row(0)).collect();
            PaddedRows::new(p, rows.into_iter())
        } else {
            PaddedRows::default()
        };
        Ok(Self {
            model,
            settings,
            cd,
            contacts,
            closed: Vec::with_capacity(nc),
            tangential,
            surface_rows,
            frame_rows,
            normal_dots: vec![0.0; normal_rows.rows()],
            normal_rows,
            fluid,
            load_rows,
            load_histories: (model.loads.iter().map(|l| &l.history))
                .chain(model.modal_loads.iter().map(|l| &l.history))
                .chain(model.base_acceleration.iter().map(|b| &b.history))
                .map(|h| SteppedHistory::new(h, settings.dt))
                .collect(),
            turbulence,
            signals: vec![0.0; channels],
            external: vec![0.0; p],
            force: vec![0.0; p],
            names: model.contacts.iter().map(|c| c.name.clone()).collect(),
            statistics: ContactStatisticsState::new(
                nc,
                &settings.statistics,
                settings.steps,
                settings.dt,
            ),
            window_opens: settings
                .statistics
                .first_window_step(settings.steps, settings.dt)
                .map_or(u64::MAX, |first| first - 1),
            wear_map: None,
            solver_stats: SolverStatistics::default(),
            stable_dt,
            energy: EnergyBalance::default(),
            recorder: Recorder::new(samples, p, nc),
            step: 0,
            next_sample: settings.output_every,
            accumulation_bound: Self::accumulation_bound(settings),
            wide: wide_vectors(),
            common_contacts,
        })
    }

    /// t = 0: contacts at the initial state, initial acceleration, first sample.
    fn start(&mut self) {
        self.external_force::<Portable>(0, 0.0);
        self.fluid_elastic_force::<Portable>(0, false);
        let _ = self.detect::<Portable, AnyContacts>(0.0, false);
        self.contact_forces::<Portable, AnyContacts>();
        self.cd.start(normal::modal_force(
            &self.closed,
            &self.external,
            &self.force,
        ));
        self.full_step_velocities::<Portable, AnyContacts>(true);
        for c in &mut self.contacts {
            // the velocities were the initial (full-step) ones already
            if c.closed && c.tangential_force == Vector2::zeros() {
                c.slide = if c.tangential_velocity().norm() > 0.0 {
                    Slide::Slip
                } else {
                    Slide::Stick
                };
            }
        }
        let (e, powers) = self
            .energy_and_powers::<Portable, AnyContacts>(self.cd.energy_and_powers(&self.external));
        self.energy = EnergyBalance::start(e, powers);
        self.statistics.start(
            self.contacts
                .iter()
                .map(|c| (c.frame.penetration, c.closed)),
        );
        if self.window_opens == 0 {
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
        if self.wide {
            // SAFETY: `wide` is set only when the processor has AVX2 and FMA (checked at run
            // time in `allocate`).
            return unsafe {
                if self.common_contacts {
                    self.steps_avx2::<CommonContacts>(n)
                } else {
                    self.steps_avx2::<AnyContacts>(n)
                }
            };
        }
        if self.common_contacts {
            self.steps_with::<Portable, CommonContacts>(n)
        } else {
            self.steps_with::<Portable, AnyContacts>(n)
        }
    }

    /// Runs the steps with the portable (SSE2 on x86-64) code even when the processor has
    /// AVX2: for comparisons and tests.
    pub(crate) fn use_portable_kernels(&mut self) {
        self.wide = false;
    }

    /// Runs the steps with the code compiled for any contact even when the case is the
    /// common one (`contact_kinds`): for comparisons and tests.
    pub(crate) fn use_general_step(&mut self) {
        self.common_contacts = false;
    }

    /// Whether the steps run the code compiled for the common case: every obstacle a fixed
    /// plane or fixed bars, an undamped normal law, friction by Lagrange multipliers (the same
    /// results as the general code, bit for bit, faster).
    pub(crate) fn runs_common_step(&self) -> bool {
        self.common_contacts
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn steps_avx2<O: ContactKinds>(
        &mut self,
        n: u64,
    ) -> std::result::Result<u64, Divergence> {
        // each version of the step its own copy of the kernels, inlined
        self.steps_with::<crate::kernels::Avx2<O>, O>(n)
    }

    /// [`Self::steps`] with the reduction kernels `K` ([`crate::kernels`]), for the contacts
    /// `O`.
    #[inline(always)]
    fn steps_with<K: Lanes, O: ContactKinds>(
        &mut self,
        n: u64,
    ) -> std::result::Result<u64, Divergence> {
        let until_target = self.statistics.target_met().is_none();
        for done in 1..=n {
            self.try_step::<K, O>().inspect_err(|_| self.step -= 1)?;
            if self.recorder.is_full() || (until_target && self.statistics.target_met().is_some()) {
                return Ok(done);
            }
        }
        Ok(n)
    }

    /// The step; on `Err`, nothing of it was accumulated or sampled.
    #[inline(always)]
    fn try_step<K: Lanes, O: ContactKinds>(&mut self) -> std::result::Result<(), Divergence> {
        self.step += 1;
        let t = self.step as f64 * self.settings.dt;
        self.predict_with_first_load::<K>(self.step, t);
        self.other_loads::<K>(self.step, t);
        if self.fluid.is_some() {
            self.fluid_elastic_force::<K>(self.step, true);
        }
        let open_within = self.detect::<K, O>(t, true);
        self.free_acceleration::<K, O>();
        self.lagrange::<K>();
        let modal = self.cd.correct_with::<K>(&self.external);
        self.full_step_velocities::<K, O>(false);

        let dt = self.settings.dt;
        let bound = self.accumulation_bound;
        let step = self.step;
        let diverged = move |contact: Option<usize>| Divergence {
            step,
            time: t,
            contact,
        };
        // the open contacts were checked by detection, the closed ones are checked here
        let closed = &self.closed;
        if !(open_within && closed.iter().all(|&k| self.contacts[k].accumulable(bound))) {
            let first = self.contacts.iter().position(|c| !c.accumulable(bound));
            return Err(diverged(first));
        }
        let (e, powers) = self.energy_and_powers::<K, O>(modal);
        let magnitude = e.abs() + powers.iter().map(|p| p.abs()).sum::<f64>();
        if magnitude > bound || magnitude.is_nan() {
            return Err(diverged(None));
        }
        let sample = self.step == self.next_sample;
        if sample {
            self.full_step_velocities::<K, O>(true);
            if let Some(k) = self.sample() {
                self.recorder.discard_last();
                return Err(diverged(Some(k)));
            }
        }
        self.energy.step(e, powers, dt);
        let model = self.model;
        let values = self
            .contacts
            .iter()
            .zip(&model.contacts)
            .zip(&self.frame_rows)
            .map(|((s, c), rows)| contact_step(s, c, O::rows(rows), t));
        self.statistics
            .step(&self.settings.statistics, t, dt, values);
        if self.step == self.window_opens {
            self.open_statistics_window();
        }
        if let Some(map) = &mut self.wear_map {
            track_wear(
                map,
                &self.contacts,
                model,
                &self.frame_rows,
                t,
                dt,
                self.settings,
            );
        }
        if sample {
            self.next_sample = self.next_sample.saturating_add(self.settings.output_every);
        }
        Ok(())
    }

    /// Largest value a step may add to a running sum of the statistics or of the energy
    /// balance (a force, a square, a power, a penetration): `f64::MAX / (8 (N + 1) max(1, Δt))`
    /// for `N` steps, so that no sum of the run can overflow — a step above it has diverged.
    /// (About 2e298 for a billion steps: no physical value comes near it.)
    pub fn accumulation_bound(settings: &RunSettings) -> f64 {
        f64::MAX / (8.0 * (settings.steps as f64 + 1.0) * settings.dt.max(1.0))
    }
}

/// Rows (3 × p) through which contact `k` sees the modal coordinates: the point's, or the
/// surface point's ([`crate::contact::Contact::surface_rows`], updated with the normal by
/// `detect`). A free function, so that it borrows two fields only.
#[inline]
fn contact_rows<'a>(model: &'a Model, surface_rows: &'a [f64], k: usize) -> &'a [f64] {
    let c = &model.contacts[k];
    if c.at_surface() {
        let p = model.basis.modes();
        &surface_rows[3 * p * k..3 * p * (k + 1)]
    } else {
        &model.basis.points[c.point].rows
    }
}

/// The model's contacts with their states, by index: the loop of the contact phases.
#[inline]
fn contact_states<'a>(
    model: &'a Model,
    states: &'a mut [ContactState],
) -> impl Iterator<Item = (usize, (&'a crate::contact::Contact, &'a mut ContactState))> {
    model.contacts.iter().zip(states).enumerate()
}

/// Adds the step's friction work of the closed contacts to `map`, when the step is in the
/// statistics window.
#[inline(never)]
fn track_wear(
    map: &mut WearMap,
    states: &[ContactState],
    model: &Model,
    frame_rows: &[Option<FrameRows>],
    t: f64,
    dt: f64,
    settings: &RunSettings,
) {
    if !settings.statistics.step_in_window(t, dt) {
        return;
    }
    for (k, ((s, c), rows)) in states
        .iter()
        .zip(&model.contacts)
        .zip(frame_rows)
        .enumerate()
    {
        if s.closed {
            map.add(k, &step_values(s, c, rows.as_ref(), t), dt);
        }
    }
}

/// Whether the processor runs AVX2 and FMA code ([`Simulation::step`]).
fn wide_vectors() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
