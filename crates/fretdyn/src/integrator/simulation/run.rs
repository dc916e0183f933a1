//! A run as a whole: progress, termination, results, the in-memory driver ([`simulate`],
//! [`run`]), divergence and the snapshot a checkpoint holds.

use std::ops::ControlFlow;

use serde::Serialize;

use super::{RunSettings, Simulation};
use crate::accumulate::energy::EnergyBalance;
use crate::accumulate::recorder::Recorder;
use crate::accumulate::statistics::{BlockStatistics, ContactStatistics, Impact};
use crate::accumulate::wear_map::WearMap;
use crate::contact::tangential::SolverStatistics;
use crate::error::Result;
use crate::model::Model;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

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
    /// End time of the step at which the target relative error was met
    /// (`[statistics] target_relative_error`), where the run stopped.
    pub target_met_at: Option<f64>,
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
    let mut sim = Simulation::new(model, settings)?;
    // the time loop only, as a streamed run measures it
    let start = Instant::now();
    let total = settings.steps;
    let mut termination = Termination::Completed;
    while sim.steps_done() < total && sim.target_met().is_none() {
        // to the end of the batch, where the observer is called
        if let Err(d) = sim.steps(sim.steps_to_batch_end(total)) {
            termination = d.into_termination(model);
            break;
        }
        let n = sim.steps_done();
        if n % Simulation::BATCH == 0
            && n < total
            && observer(Progress { step: n, total }).is_break()
        {
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

/// A run of `model` with `settings` for its statistics only ([`crate::apps::study::run_statistics`]); with `wear_bins`, also where each contact's
/// wear work was done ([`WearMap`] with that many bins around a hole, THEORY §14.3).
pub fn statistics_run(
    model: &Model,
    settings: &RunSettings,
    wear_bins: Option<usize>,
) -> Result<(RunResults, Option<WearMap>)> {
    statistics_run_until(model, settings, wear_bins, None)
}

/// [`statistics_run`] that stops at the end of a batch of steps once `stop` is set
/// ([`Termination::Stopped`]).
pub fn statistics_run_until(
    model: &Model,
    settings: &RunSettings,
    wear_bins: Option<usize>,
    stop: Option<&AtomicBool>,
) -> Result<(RunResults, Option<WearMap>)> {
    let mut sim = Simulation::with_recorder(model, settings, 1)?;
    if let Some(bins) = wear_bins {
        sim.track_wear(bins);
    }
    statistics_run_from(sim, settings, &mut |sim| {
        if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            ControlFlow::Break(sim.steps_done())
        } else {
            ControlFlow::Continue(())
        }
    })
}

/// The loop of [`statistics_run`] from a simulation made (or resumed) by the caller:
/// `at_batch(sim)` after every batch of steps before the last; `Break(step)` stops the run
/// there ([`Termination::Stopped`]).
pub fn statistics_run_from(
    mut sim: Simulation,
    settings: &RunSettings,
    at_batch: &mut dyn FnMut(&Simulation) -> ControlFlow<u64>,
) -> Result<(RunResults, Option<WearMap>)> {
    let start = Instant::now();
    let model = sim.model();
    let total = settings.steps;
    let mut termination = Termination::Completed;
    while sim.steps_done() < total {
        // to the end of the batch, where the finished impacts and blocks are let go
        if let Err(d) = sim.steps(sim.steps_to_batch_end(total)) {
            termination = d.into_termination(model);
            break;
        }
        if sim.recorder().is_full() {
            sim.recorder_mut().clear();
        }
        if sim.steps_done().is_multiple_of(Simulation::BATCH) {
            let statistics = sim.statistics_mut();
            statistics.impacts.clear();
            statistics.blocks.clear();
            if sim.steps_done() < total
                && let ControlFlow::Break(step) = at_batch(&sim)
            {
                termination = Termination::Stopped { step };
                break;
            }
        }
    }
    let map = sim.wear_map().cloned();
    Ok((sim.finish(start.elapsed().as_secs_f64(), termination), map))
}
