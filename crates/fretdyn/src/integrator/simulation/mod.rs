//! The time-step loop: central differences on the modes, contacts on the physical basis at the
//! contact points only, tangential forces by the chosen method (THEORY §2, steps 1–7).
//!
//! Everything the loop touches is allocated before the first step.

use std::ops::ControlFlow;
use std::time::Instant;

use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::contact::delassus::{Slot, TangentialProblem};
use crate::contact::friction::Slide;
use crate::contact::obstacle::ContactFrame;
use crate::contact::tangential::active_set::{ActiveSet, History};
use crate::contact::tangential::penalty::PenaltyContact;
use crate::contact::tangential::{SolverStatistics, StickVelocity, TangentialMethod, gauss_seidel};
use crate::error::{Error, Result};
use crate::integrator::central_difference::CentralDifference;
use crate::integrator::stability::stable_time_step;
use crate::model::Model;
use crate::results::recorder::{ContactSample, Recorder};
use crate::results::statistics::{
    BlockStatistics, ContactStatistics, ContactStatisticsState, EnergyBalance, EnergyRaw, Impact,
    StatisticsSettings, StepValues,
};
use crate::structure::modal::{dot, project_add, recombine};

/// Numerical settings of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSettings {
    /// Time step Δt, s.
    pub dt: f64,
    /// Number of steps.
    pub steps: u64,
    /// Tangential method.
    pub method: TangentialMethod,
    /// Velocity the stick constraint acts on (Lagrange methods).
    pub stick_velocity: StickVelocity,
    /// Keep every `output_every`-th step in the recorded time histories (statistics use all).
    pub output_every: u64,
    /// Window, blocks and impact definition of the statistics.
    pub statistics: StatisticsSettings,
}

impl RunSettings {
    /// Checks the numbers (not the stability limit, which needs the model).
    pub fn validate(&self) -> Result<()> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::invalid(
                "time.dt",
                format!("must be a positive time step in s (got {})", self.dt),
            ));
        }
        if self.output_every == 0 {
            return Err(Error::invalid(
                "output.every",
                "must be at least 1 (1 keeps every step)",
            ));
        }
        self.statistics.validate("statistics")?;
        match &self.method {
            TangentialMethod::Penalty(p) => {
                if !(p.stiffness.is_finite() && p.stiffness > 0.0) {
                    return Err(Error::invalid(
                        "tangential.penalty.stiffness",
                        format!("must be a positive K_T in N/m (got {})", p.stiffness),
                    ));
                }
                if !(p.damping.is_finite() && p.damping >= 0.0) {
                    return Err(Error::invalid(
                        "tangential.penalty.damping",
                        format!("must be a C_T ≥ 0 in N·s/m (got {})", p.damping),
                    ));
                }
            }
            TangentialMethod::GaussSeidel(g) => check_gs(g, "tangential.gauss_seidel")?,
            TangentialMethod::ActiveSet(a) => {
                if a.max_iterations == 0 {
                    return Err(Error::invalid(
                        "tangential.active_set.max_iterations",
                        "must be at least 1",
                    ));
                }
                check_gs(&a.fallback, "tangential.gauss_seidel")?;
            }
        }
        Ok(())
    }
}

fn check_gs(g: &crate::contact::tangential::GaussSeidelSettings, field: &str) -> Result<()> {
    if !(g.tolerance.is_finite() && g.tolerance > 0.0) {
        return Err(Error::invalid(
            format!("{field}.tolerance"),
            format!(
                "must be a positive relative tolerance, e.g. 1e-12 (got {})",
                g.tolerance
            ),
        ));
    }
    if !(g.residual_tolerance.is_finite() && g.residual_tolerance > 0.0) {
        return Err(Error::invalid(
            format!("{field}.residual_tolerance"),
            format!(
                "must be a positive bound on the relative natural-map residual, e.g. 1e-8 \
                 (got {})",
                g.residual_tolerance
            ),
        ));
    }
    if g.max_sweeps == 0 {
        return Err(Error::invalid(
            format!("{field}.max_sweeps"),
            "must be at least 1",
        ));
    }
    Ok(())
}

/// `x` rounded down to 3 significant digits, for the time step suggested to the user.
fn round_down(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let exponent = x.log10().floor() as i32 - 2;
    let digits = (x / 10f64.powi(exponent)).floor();
    // through the decimal text, so that it prints as typed (1.8e-3, not 1.8000000000000002e-3)
    format!("{digits}e{exponent}").parse().unwrap_or(x)
}

/// Progress report passed to the observer of [`run`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// Steps done.
    pub step: u64,
    /// Steps in the run.
    pub total: u64,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum Termination {
    /// Every step was done.
    Completed,
    /// The state became non-finite at `step`; results up to the previous sample are kept.
    Diverged {
        step: u64,
        time: f64,
        /// The contact whose force was non-finite first, if any.
        contact: Option<String>,
    },
    /// The observer asked to stop.
    Stopped { step: u64 },
    /// Still running (statistics of a checkpoint).
    InProgress { step: u64 },
}

/// Everything a run produces.
#[derive(Debug, Clone)]
pub struct RunResults {
    /// Output time histories.
    pub recorder: Recorder,
    /// Per-contact statistics over every step of the window (THEORY §5).
    pub contacts: Vec<ContactStatistics>,
    /// Finished impacts of the window, in the order they ended (not drained by a streaming
    /// driver).
    pub impacts: Vec<Impact>,
    /// Per-block statistics, block by block, contact by contact (when blocks are set).
    pub blocks: Vec<BlockStatistics>,
    /// Tangential solver counters.
    pub solver: SolverStatistics,
    /// Energy balance.
    pub energy: EnergyBalance,
    /// Steps done.
    pub steps: u64,
    /// Time step, s.
    pub dt: f64,
    /// Stability limit of the time step, s.
    pub stable_dt: f64,
    /// Wall-clock time of the step loop, s.
    pub wall_time: f64,
    /// How the run ended.
    pub termination: Termination,
}

impl RunResults {
    /// Steps per second of wall time.
    pub fn steps_per_second(&self) -> f64 {
        if self.wall_time > 0.0 {
            self.steps as f64 / self.wall_time
        } else {
            0.0
        }
    }
}

/// Runs `model` with `settings` without progress reporting.
pub fn simulate(model: &Model, settings: &RunSettings) -> Result<RunResults> {
    run(model, settings, |_| ControlFlow::Continue(()))
}

/// Runs `model` with `settings`. `observer` is called every 1024 steps and at the end; it may
/// stop the run by returning `ControlFlow::Break`.
///
/// Errors are input errors (including a Δt above the stable limit). A run that diverges or is
/// stopped returns `Ok` with its [`Termination`] and the results written so far.
pub fn run(
    model: &Model,
    settings: &RunSettings,
    mut observer: impl FnMut(Progress) -> ControlFlow<()>,
) -> Result<RunResults> {
    let start = Instant::now();
    let mut sim = Simulation::new(model, settings)?;
    let total = settings.steps;
    let mut termination = Termination::Completed;
    while sim.steps_done() < total {
        if let Err(d) = sim.step() {
            termination = d.into_termination(model);
            break;
        }
        let n = sim.steps_done();
        if n % 1024 == 0 && n < total && observer(Progress { step: n, total }).is_break() {
            termination = Termination::Stopped { step: n };
            break;
        }
    }
    let wall_time = start.elapsed().as_secs_f64();
    let _ = observer(Progress {
        step: sim.steps_done(),
        total,
    });
    Ok(sim.finish(wall_time, termination))
}

/// A step whose state became non-finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Divergence {
    /// The step, counted from 1.
    pub step: u64,
    /// Its end time, s.
    pub time: f64,
    /// The contact whose force was non-finite first, if any.
    pub contact: Option<usize>,
}

impl Divergence {
    /// The [`Termination`] it causes.
    pub fn into_termination(self, model: &Model) -> Termination {
        Termination::Diverged {
            step: self.step,
            time: self.time,
            contact: self.contact.map(|c| model.contacts[c].name.clone()),
        }
    }
}

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
    /// Physical position of the point.
    x: Vector3<f64>,
    /// Position of the contact point (on the surface for a tube contact) relative to the
    /// moving obstacle: the penalty law's anchor lives in this frame.
    x_relative: Vector3<f64>,
    /// Point velocity relative to the obstacle (predicted during the step, full-step after;
    /// see [`Simulation::full_step_velocities`]).
    v: Vector3<f64>,
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
        Vector2::new(
            self.frame.tangents[0].dot(&self.v),
            self.frame.tangents[1].dot(&self.v),
        )
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
            self.v.norm_squared()
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

/// Method-specific state (one per run, so the size difference of the variants is irrelevant).
#[allow(clippy::large_enum_variant)]
enum Tangential {
    Penalty {
        settings: crate::contact::tangential::PenaltySettings,
        contacts: Vec<PenaltyContact>,
    },
    Lagrange {
        problem: TangentialProblem,
        solver: LagrangeSolver,
        theta_dt: f64,
        lambda: Vec<Vector2<f64>>,
        slide: Vec<Slide>,
        /// Per contact: previous step's status, direction and λ (warm start).
        history: Vec<History>,
        previous_lambda: Vec<Vector2<f64>>,
        /// Work space of the singularity check.
        work: Vec<f64>,
    },
}

enum LagrangeSolver {
    GaussSeidel(crate::contact::tangential::GaussSeidelSettings),
    ActiveSet(Box<ActiveSet>),
}

/// A run in progress: create it with [`Simulation::new`] (or [`Simulation::resume`]), advance
/// it with [`Simulation::step`], drain its [`Recorder`] and finished impacts as it goes, end
/// it with [`Simulation::finish`]. [`run`] does all of it for a run held in memory.
pub struct Simulation<'m> {
    model: &'m Model,
    settings: &'m RunSettings,
    cd: CentralDifference,
    contacts: Vec<ContactState>,
    tangential: Tangential,
    /// Rows (3 × p) of the contact points on the tube surface, one block per contact (used
    /// only by contacts with a radius), updated with the normal at each step.
    surface_rows: Vec<f64>,
    /// Modal loads `Φ_lᵀ F_l`, one row of p per load.
    load_rows: Vec<f64>,
    /// Signal generators of the turbulent loads, one per load.
    turbulence: Vec<crate::loads::turbulence::RandomChannels>,
    /// Work space: the turbulence signals at the current time.
    signals: Vec<f64>,
    external: Vec<f64>,
    force: Vec<f64>,
    names: Vec<String>,
    statistics: ContactStatisticsState,
    solver_stats: SolverStatistics,
    stable_dt: f64,
    energy: EnergyBalance,
    recorder: Recorder,
    step: u64,
    /// [`Self::accumulation_bound`] of the settings.
    accumulation_bound: f64,
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
        }
    }

    /// Steps done.
    pub fn steps_done(&self) -> u64 {
        self.step
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

    /// Statistics in progress, whose finished impacts and blocks may be drained.
    pub fn statistics_mut(&mut self) -> &mut ContactStatisticsState {
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
            x_relative: Vector3::zeros(),
            v: Vector3::zeros(),
            normal_force: 0.0,
            tangential_force: Vector2::zeros(),
            closed: false,
            slide: Slide::Stick,
            held: false,
        };
        Ok(Self {
            model,
            settings,
            cd,
            contacts: vec![blank; nc],
            tangential,
            surface_rows: vec![0.0; 3 * p * nc],
            load_rows,
            turbulence,
            signals: vec![0.0; channels],
            external: vec![0.0; p],
            force: vec![0.0; p],
            names: model.contacts.iter().map(|c| c.name.clone()).collect(),
            statistics: ContactStatisticsState::new(nc, &settings.statistics),
            solver_stats: SolverStatistics::default(),
            stable_dt,
            energy: EnergyBalance::default(),
            recorder: Recorder::new(samples, p, nc),
            step: 0,
            accumulation_bound: Self::accumulation_bound(settings),
        })
    }

    /// t = 0: contacts at the initial state, initial acceleration, first sample.
    fn start(&mut self) {
        self.external_force(0.0);
        self.detect(0.0, false);
        self.contact_forces();
        self.cd.start(&self.force);
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
        let (e, powers) = self.energy_and_powers();
        self.energy = EnergyBalance::start(e, powers);
        self.statistics.start(
            self.contacts
                .iter()
                .map(|c| (c.frame.penetration, c.closed)),
        );
        self.full_step_velocities(true);
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
    pub fn step(&mut self) -> std::result::Result<(), Divergence> {
        self.try_step().inspect_err(|_| self.step -= 1)
    }

    /// The step; on `Err`, nothing of it was accumulated or sampled.
    fn try_step(&mut self) -> std::result::Result<(), Divergence> {
        self.step += 1;
        let t = self.step as f64 * self.settings.dt;
        self.cd.predict();
        self.external_force(t);
        self.detect(t, true);
        self.contact_forces();
        self.cd.free_acceleration(&self.force);
        self.lagrange();
        self.cd.correct();
        self.full_step_velocities(false);

        let dt = self.settings.dt;
        let bound = self.accumulation_bound;
        let step = self.step;
        let diverged = move |contact: Option<usize>| Divergence {
            step,
            time: t,
            contact,
        };
        if let Some(k) = self.contacts.iter().position(|c| !c.accumulable(bound)) {
            return Err(diverged(Some(k)));
        }
        let (e, powers) = self.energy_and_powers();
        let magnitude = e.abs() + powers.iter().map(|p| p.abs()).sum::<f64>();
        if magnitude > bound || magnitude.is_nan() {
            return Err(diverged(None));
        }
        if self.step % self.settings.output_every == 0 {
            self.full_step_velocities(true);
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
            .map(|(s, c)| step_values(s, c, t));
        self.statistics
            .step(&self.settings.statistics, &self.names, t, dt, values);
        Ok(())
    }

    /// Largest value a step may add to a running sum of the statistics or of the energy
    /// balance (a force, a square, a power, a penetration): `f64::MAX / (8 (N + 1) max(1, Δt))`
    /// for `N` steps, so that no sum of the run can overflow — a step above it has diverged.
    /// (About 2e298 for a billion steps: no physical value comes near it.)
    pub fn accumulation_bound(settings: &RunSettings) -> f64 {
        f64::MAX / (8.0 * (settings.steps as f64 + 1.0) * settings.dt.max(1.0))
    }

    fn external_force(&mut self, t: f64) {
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
    fn detect(&mut self, t: f64, predicted: bool) {
        let velocity = if predicted {
            &self.cd.qd_star
        } else {
            &self.cd.qd
        };
        let p = self.cd.q.len();
        for (k, (c, state)) in self
            .model
            .contacts
            .iter()
            .zip(&mut self.contacts)
            .enumerate()
        {
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

    /// Step 4 (and the penalty tangential forces): modal force `f = f_ext + Σ Φ_cᵀ R_c`.
    fn contact_forces(&mut self) {
        self.force.copy_from_slice(&self.external);
        for (k, (c, state)) in self
            .model
            .contacts
            .iter()
            .zip(&mut self.contacts)
            .enumerate()
        {
            if let Tangential::Penalty { settings, contacts } = &mut self.tangential {
                if state.closed {
                    let vt = state.tangential_velocity();
                    state.tangential_force = contacts[k].force(
                        settings,
                        &c.friction,
                        &state.frame.tangents,
                        &state.x_relative,
                        vt,
                        state.normal_force,
                    );
                    state.slide = contacts[k].slide;
                } else {
                    contacts[k].open();
                }
            }
            if state.closed {
                let f = state.force();
                project_add(
                    contact_rows(self.model, &self.surface_rows, k),
                    &f,
                    &mut self.force,
                );
            }
        }
    }

    /// Step 6 for the Lagrange methods.
    fn lagrange(&mut self) {
        let Tangential::Lagrange {
            problem,
            solver,
            theta_dt,
            lambda,
            slide,
            history,
            previous_lambda,
            work,
        } = &mut self.tangential
        else {
            return;
        };
        problem.clear();
        for (k, (c, state)) in self.model.contacts.iter().zip(&self.contacts).enumerate() {
            if state.closed {
                let cd = &self.cd;
                problem.push_with(
                    Slot {
                        contact: k,
                        s_static: c.friction.mu_static * state.normal_force,
                        s_dynamic: c.friction.mu_dynamic * state.normal_force,
                    },
                    &state.frame.tangents,
                    contact_rows(self.model, &self.surface_rows, k),
                    |l, out| cd.apply_a_inv(l, out),
                );
            }
        }
        if problem.is_empty() {
            history.iter_mut().for_each(|h| h.closed = false);
            return;
        }
        let (contacts, model, dt) = (&self.contacts, self.model, self.settings.dt);
        let half_step = self.settings.stick_velocity == StickVelocity::HalfStep;
        let step = self.step;
        problem.assemble(&self.cd.qdd, &self.cd.qd_star, *theta_dt, |slot| {
            let f = &contacts[slot.contact].frame;
            let motion = &model.contacts[slot.contact].motion;
            // the half-step velocity moves the point from t_{n+1} to t_{n+2}: the obstacle's
            // velocity over that step, so that a sticking point keeps its place on the
            // obstacle exactly; the full-step one is the mean of two such steps
            // (Motion::full_step_velocity, the velocity the slip is measured against)
            let v = if motion.is_fixed() {
                f.velocity
            } else if half_step {
                motion.step_velocity(step, dt)
            } else {
                motion.full_step_velocity(step, dt)
            };
            Vector2::new(f.tangents[0].dot(&v), f.tangents[1].dot(&v))
        });
        let m = problem.len();
        for (k, slot) in problem.slots().iter().enumerate() {
            let warm = match solver {
                LagrangeSolver::GaussSeidel(s) => s.warm_start,
                LagrangeSolver::ActiveSet(_) => false,
            };
            lambda[k] = if warm && history[slot.contact].closed {
                previous_lambda[slot.contact]
            } else {
                Vector2::zeros()
            };
        }
        self.solver_stats.lagrange_steps += 1;
        let mut residual = None;
        match solver {
            LagrangeSolver::GaussSeidel(s) => {
                // Gauss–Seidel tolerates a singular H (the modal forces are unique, λ is
                // not); it is counted all the same (THEORY §4.6).
                if problem.is_singular(work) {
                    self.solver_stats.singular_delassus += 1;
                }
                let sweeps = gauss_seidel::solve(s, problem, &mut lambda[..m], &mut slide[..m]);
                self.solver_stats.gs_sweeps_total += sweeps.count as u64;
                self.solver_stats.gs_sweeps_max =
                    self.solver_stats.gs_sweeps_max.max(sweeps.count as u64);
                if !sweeps.converged {
                    self.solver_stats.gs_nonconverged_steps += 1;
                }
                residual = sweeps.residual;
            }
            LagrangeSolver::ActiveSet(a) => {
                a.solve(
                    problem,
                    history,
                    &mut lambda[..m],
                    &mut slide[..m],
                    &mut self.solver_stats,
                );
            }
        }
        let residual =
            residual.unwrap_or_else(|| problem.natural_map_residual(&lambda[..m], &slide[..m]));
        self.solver_stats.add_residual(residual);
        problem.apply(&lambda[..m], &mut self.cd.qdd);
        for (k, slot) in problem.slots().iter().enumerate() {
            // held: both half-step velocities of q̇_{n+1} imposed (only this step's with the
            // full-step constraint)
            let before = &history[slot.contact];
            self.contacts[slot.contact].held = slide[k] == Slide::Stick
                && (!half_step || (before.closed && before.slide == Slide::Stick));
        }
        history.iter_mut().for_each(|h| h.closed = false);
        for (k, slot) in problem.slots().iter().enumerate() {
            let state = &mut self.contacts[slot.contact];
            state.tangential_force = -lambda[k];
            state.slide = slide[k];
            let n = lambda[k].norm();
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

    /// Full-step velocities of the closed contacts (of all when `all`) relative to their
    /// obstacles: `Φ_c q̇_{n+1} − v̄_{n+1}`, with `v̄` the obstacle's full-step velocity
    /// ([`crate::contact::motion::Motion::full_step_velocity`], the mean of the two step velocities
    /// around `t_{n+1}`, as `q̇_{n+1}` is the mean of the two half-step velocities; THEORY §2),
    /// which also becomes the frame's velocity for the obstacle's power. (The tangential part
    /// of a contact [held](ContactState::held) in stick is read as exactly 0, THEORY §5.)
    fn full_step_velocities(&mut self, all: bool) {
        let p = self.cd.q.len();
        for (k, (c, state)) in self
            .model
            .contacts
            .iter()
            .zip(&mut self.contacts)
            .enumerate()
        {
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

    /// Energy `E` and the powers `[external (loads and moving obstacles), modal damping,
    /// contact damping, tangential]`.
    fn energy_and_powers(&self) -> (f64, [f64; 4]) {
        let mut e = self.cd.energy();
        let mut contact_damping = 0.0;
        let mut tangential = 0.0;
        let mut obstacle = 0.0;
        for (c, s) in self.model.contacts.iter().zip(&self.contacts) {
            if s.closed {
                let d = s.frame.penetration;
                e += 0.5 * c.normal.stiffness * d * d;
                let rate = -s.frame.normal.dot(&s.v);
                contact_damping += (s.normal_force - c.normal.stiffness * d) * rate;
                tangential -= s.tangential_force.dot(&s.tangential_velocity());
                // a moving obstacle works on the structure at the rate R·v_obstacle
                obstacle += s.force().dot(&s.frame.velocity);
            }
        }
        let external = dot(&self.external, &self.cd.qd) + obstacle;
        (
            e,
            [
                external,
                self.cd.damping_power(),
                contact_damping,
                tangential,
            ],
        )
    }

    /// Records the output sample of the current step; returns the first contact whose slip
    /// velocity or position is not finite (the modal state and the forces are checked by
    /// [`Self::step`] already).
    fn sample(&mut self) -> Option<usize> {
        let t = self.step as f64 * self.settings.dt;
        if !self.recorder.push_state(t, &self.cd.q, &self.cd.qd) {
            return None;
        }
        let mut non_finite = None;
        for (k, (s, c)) in self.contacts.iter().zip(&self.model.contacts).enumerate() {
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
            energy: self.energy.clone(),
            steps: self.step,
            dt: self.settings.dt,
            stable_dt: self.stable_dt,
            wall_time,
            termination: Termination::InProgress { step: self.step },
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
        RunResults {
            contacts,
            impacts: std::mem::take(&mut self.statistics.impacts),
            blocks: std::mem::take(&mut self.statistics.blocks),
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

/// [`crate::contact::motion::Motion::full_step_velocity`], out of the loop of the fixed obstacles.
#[inline(never)]
fn moving_full_step(motion: &crate::contact::motion::Motion, step: u64, dt: f64) -> Vector3<f64> {
    motion.full_step_velocity(step, dt)
}

/// One contact's values of the step ending at `t`, for the statistics (THEORY §5).
#[inline]
fn step_values(s: &ContactState, c: &crate::contact::Contact, t: f64) -> StepValues {
    let local = c.local(&s.x, t);
    let (radial, direction) = if c.obstacle.is_hole() {
        let r = local.norm();
        let unit = if r > 0.0 {
            [local.x / r, local.y / r]
        } else {
            [1.0, 0.0]
        };
        (r, unit)
    } else {
        (local.x, [1.0, 0.0])
    };
    let (slip_speed, friction_power) = if s.closed {
        let vt = s.tangential_velocity();
        (vt.norm(), s.tangential_force.dot(&vt).abs())
    } else {
        (0.0, 0.0)
    };
    StepValues {
        t,
        closed: s.closed,
        stick: s.slide == Slide::Stick,
        normal: s.normal_force,
        tangential: s.tangential_force.norm(),
        slip_speed,
        friction_power,
        penetration: s.frame.penetration,
        radial,
        direction,
    }
}

impl Tangential {
    fn lagrange(
        model: &Model,
        cd: &CentralDifference,
        settings: &RunSettings,
        solver: LagrangeSolver,
    ) -> Self {
        let nc = model.contacts.len();
        let mut problem = TangentialProblem::new(model.basis.modes(), nc);
        for (k, c) in model.contacts.iter().enumerate() {
            if let Some(t) = c.fixed_tangents() {
                let point = &model.basis.points[c.point];
                let mut rows = point.rows.clone();
                if c.at_surface() {
                    // a plane: the normal never changes
                    c.surface_rows(point, &c.frame(&point.coords, 0.0).normal, &mut rows);
                }
                problem.fix_rows(k, &t, &rows, |l, out| cd.apply_a_inv(l, out));
            }
        }
        Tangential::Lagrange {
            problem,
            solver,
            theta_dt: settings.stick_velocity.theta() * settings.dt,
            lambda: vec![Vector2::zeros(); nc],
            slide: vec![Slide::Stick; nc],
            history: vec![History::default(); nc],
            previous_lambda: vec![Vector2::zeros(); nc],
            work: vec![0.0; 4 * nc * nc + 8 * nc],
        }
    }
}
