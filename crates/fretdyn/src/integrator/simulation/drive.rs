//! The run loop, one for every kind of run ([`drive`]): batches of steps, and at the end of
//! each what its [`BatchSink`] does there — keep the samples in memory
//! ([`super::run`]), let them go (a study's or a life's runs, [`super::statistics_run`]),
//! or stream them to disk and checkpoint ([`crate::output::stream`]).
//!
//! A batch ends at every multiple of [`Simulation::BATCH`] steps and, when the sink asks for
//! them, at every multiple of [`BatchSink::every_steps`]; the steps between two ends run in
//! one call of [`Simulation::steps`], which stops early when the recorder is full (the sink
//! drains it, [`BatchSink::drain`]) or when the statistics meet their target. The batches do
//! not change the results: a run gives the same bits however it is cut.

use std::ops::ControlFlow;
use std::time::Instant;

use super::results::Termination;
use super::step::Simulation;
use crate::error::Result;

/// Where a batch ended ([`BatchSink::batch_end`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BatchEnd {
    /// Steps done.
    pub step: u64,
    /// Steps in the run.
    pub total: u64,
    /// `step` is a multiple of [`Simulation::BATCH`].
    pub whole: bool,
    /// `step` is a multiple of the sink's [`BatchSink::every_steps`].
    pub by_steps: bool,
}

impl BatchEnd {
    /// Steps remain (the last batch end is followed by the end of the run, where the caller
    /// of [`drive`] finishes it).
    pub fn before_the_end(&self) -> bool {
        self.step < self.total
    }
}

/// What a run does between its batches of steps.
pub trait BatchSink {
    /// Whether the run ends at the step where the statistics meet their target relative
    /// error ([`Simulation::target_met`]); a study's and a life's runs go on to their last
    /// step.
    fn stops_at_target(&self) -> bool {
        true
    }

    /// Steps between batch ends besides those of [`Simulation::BATCH`] (a checkpoint every
    /// so many steps), if any.
    fn every_steps(&self) -> Option<u64> {
        None
    }

    /// The recorder is full after a batch's steps: drain it.
    fn drain(&mut self, sim: &mut Simulation) -> Result<()>;

    /// At the end of a batch (`end`); `Break` stops the run there
    /// ([`Termination::Stopped`]).
    fn batch_end(&mut self, sim: &mut Simulation, end: BatchEnd) -> Result<ControlFlow<()>>;
}

/// A run driven to its end ([`drive`]), to be finished by the caller
/// ([`Simulation::finish`]).
pub struct Driven<'m> {
    /// The simulation where it ended.
    pub sim: Simulation<'m>,
    /// How it ended.
    pub termination: Termination,
    /// Wall-clock time of the step loop, s.
    pub wall_time: f64,
}

/// Runs `sim` to the last step of its settings (or to its target, a divergence or a stop),
/// batch by batch, `sink` at the end of each. Errors are the sink's.
pub fn drive<'m>(mut sim: Simulation<'m>, sink: &mut dyn BatchSink) -> Result<Driven<'m>> {
    let start = Instant::now();
    let total = sim.settings().steps;
    let stops_at_target = sink.stops_at_target();
    let every = sink.every_steps().filter(|&e| e > 0);
    let mut termination = Termination::Completed;
    while sim.steps_done() < total && !(stops_at_target && sim.target_met().is_some()) {
        let n = sim.steps_done();
        let mut chunk = sim.steps_to_batch_end(total);
        if let Some(every) = every {
            chunk = chunk.min(every - n % every);
        }
        if let Err(d) = sim.steps(chunk) {
            termination = d.into_termination(sim.model());
            break;
        }
        if sim.recorder().is_full() {
            sink.drain(&mut sim)?;
        }
        let step = sim.steps_done();
        let end = BatchEnd {
            step,
            total,
            whole: step.is_multiple_of(Simulation::BATCH),
            by_steps: every.is_some_and(|e| step.is_multiple_of(e)),
        };
        if (end.whole || end.by_steps) && sink.batch_end(&mut sim, end)?.is_break() {
            termination = Termination::Stopped { step };
            break;
        }
    }
    Ok(Driven {
        wall_time: start.elapsed().as_secs_f64(),
        sim,
        termination,
    })
}
