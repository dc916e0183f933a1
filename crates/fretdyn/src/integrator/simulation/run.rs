//! A run as a whole, on [`drive`]: in memory ([`simulate`], [`run`]: every sample kept) or for
//! its statistics only ([`statistics_run`] and its variants: the samples, impacts and blocks
//! let go batch by batch, for studies and service lives).

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};

use super::drive::{BatchEnd, BatchSink, Driven, drive};
use super::results::{Progress, RunResults};
use super::step::Simulation;
use crate::accumulate::wear_map::WearMap;
use crate::error::Result;
use crate::model::Model;
use crate::settings::RunSettings;

/// Runs `model` with `settings` without progress reporting.
pub fn simulate(model: &Model, settings: &RunSettings) -> Result<RunResults> {
    run(model, settings, |_| ControlFlow::Continue(()))
}

/// Runs `model` with `settings`. `observer` is called every 1024 steps and at the end; it may
/// stop the run by returning `ControlFlow::Break`.
///
/// Errors are input errors (including a Δt above the stable limit). A run that diverges or is
/// stopped returns `Ok` with its [`Termination`](super::Termination) and the results written
/// so far.
pub fn run(
    model: &Model,
    settings: &RunSettings,
    mut observer: impl FnMut(Progress) -> ControlFlow<()>,
) -> Result<RunResults> {
    let sim = Simulation::new(model, settings)?;
    let Driven {
        sim,
        termination,
        wall_time,
    } = drive(sim, &mut InMemory(&mut observer))?;
    let _ = observer(Progress {
        step: sim.steps_done(),
        total: settings.steps,
    });
    Ok(sim.finish(wall_time, termination))
}

/// A run held in memory: its recorder has room for every sample, the observer hears of the
/// progress.
struct InMemory<F>(F);

impl<F: FnMut(Progress) -> ControlFlow<()>> BatchSink for InMemory<F> {
    fn drain(&mut self, _sim: &mut Simulation) -> Result<()> {
        // full only after the last sample: every sample is kept
        Ok(())
    }

    fn batch_end(&mut self, _sim: &mut Simulation, end: BatchEnd) -> Result<ControlFlow<()>> {
        Ok(if end.before_the_end() {
            (self.0)(Progress {
                step: end.step,
                total: end.total,
            })
        } else {
            ControlFlow::Continue(())
        })
    }
}

/// A run of `model` with `settings` for its statistics only ([`crate::apps::study`]); with
/// `wear_bins`, also where each contact's wear work was done ([`WearMap`] with that many bins
/// around a hole, THEORY §14.3).
pub fn statistics_run(
    model: &Model,
    settings: &RunSettings,
    wear_bins: Option<usize>,
) -> Result<(RunResults, Option<WearMap>)> {
    statistics_run_until(model, settings, wear_bins, None)
}

/// [`statistics_run`] that stops at the end of a batch of steps once `stop` is set
/// ([`Termination::Stopped`](super::Termination::Stopped)).
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
    statistics_run_from(sim, &mut |_| {
        if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })
}

/// [`statistics_run`] from a simulation made (or resumed) by the caller: `at_batch(sim)`
/// after every batch of steps before the last; `Break` stops the run there
/// ([`Termination::Stopped`](super::Termination::Stopped)). It runs to its last step even
/// when the statistics meet their target.
pub fn statistics_run_from(
    sim: Simulation,
    at_batch: &mut dyn FnMut(&Simulation) -> ControlFlow<()>,
) -> Result<(RunResults, Option<WearMap>)> {
    let Driven {
        sim,
        termination,
        wall_time,
    } = drive(sim, &mut StatisticsOnly(at_batch))?;
    let map = sim.wear_map().cloned();
    Ok((sim.finish(wall_time, termination), map))
}

/// A run kept for its statistics: the samples, the finished impacts and the blocks are let
/// go as they come.
struct StatisticsOnly<'a>(&'a mut dyn FnMut(&Simulation) -> ControlFlow<()>);

impl BatchSink for StatisticsOnly<'_> {
    fn stops_at_target(&self) -> bool {
        false
    }

    fn drain(&mut self, sim: &mut Simulation) -> Result<()> {
        sim.recorder_mut().clear();
        Ok(())
    }

    fn batch_end(&mut self, sim: &mut Simulation, end: BatchEnd) -> Result<ControlFlow<()>> {
        if !end.whole {
            return Ok(ControlFlow::Continue(()));
        }
        let statistics = sim.statistics_mut();
        statistics.impacts.clear();
        statistics.blocks.clear();
        Ok(if end.before_the_end() {
            (self.0)(sim)
        } else {
            ControlFlow::Continue(())
        })
    }
}
