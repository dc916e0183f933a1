//! What a run produces and how it ended: [`RunResults`], [`Termination`], [`Divergence`],
//! and the [`Progress`] reported while it goes on.

use serde::Serialize;

use crate::accumulate::energy::EnergyBalance;
use crate::accumulate::monitor::MonitorStatistics;
use crate::accumulate::recorder::Recorder;
use crate::accumulate::statistics::{BlockStatistics, ContactStatistics, Impact};
use crate::contact::tangential::SolverStatistics;
use crate::model::Model;

/// Progress report passed to the observer of a run ([`super::run`], [`super::drive`]).
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
    /// The displacement monitors over the window's output samples
    /// ([`crate::accumulate::monitor`]).
    pub monitors: Vec<MonitorStatistics>,
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
