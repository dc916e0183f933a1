//! One window of vibration of a service life: the case simulated on the obstacles worn so
//! far, its statistics only, with where each contact's wear work is done ([`WearMap`]); it
//! gives each wearing contact's wear work rate and its split over the bins.

use std::ops::ControlFlow;

use serde::{Deserialize, Serialize};

use crate::case::Case;
use crate::error::Result;
use crate::integrator::simulation::statistics_run_from;
use crate::integrator::simulation::{Simulation, Snapshot, Termination};
use crate::model::Model;
use crate::wear::WearWork;

/// One window's wear work rate and its split over the bins, per wearing contact.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct Window {
    pub(super) rates: Vec<f64>,
    pub(super) errors: Vec<Option<f64>>,
    pub(super) fractions: Vec<Vec<f64>>,
}

/// How a window ended.
pub(super) enum WindowEnd {
    /// Its rates and their split over the bins.
    Done(Window),
    /// Diverged at this step of the window, at this contact.
    Diverged(u64, Option<String>),
    /// Stopped from outside at the end of a batch: where it stood.
    Stopped(Box<WindowProgress>),
}

/// A window under way: its simulation's state, where its wear work was done so far
/// included, at the end of a batch of steps (a checkpoint inside a long window).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct WindowProgress {
    pub(super) snapshot: Snapshot,
}

/// Runs one window of `model`, tracking where the friction work is done, from its start or
/// from `progress`; `at_batch(progress)` after each batch of steps before the last may stop
/// it (`Break`).
pub(super) fn window(
    case: &Case,
    model: &Model,
    wearing: &[usize],
    bins: usize,
    progress: Option<WindowProgress>,
    at_batch: &mut dyn FnMut(&dyn Fn() -> WindowProgress) -> ControlFlow<()>,
) -> Result<WindowEnd> {
    let sim = match progress {
        None => {
            let mut sim = Simulation::with_recorder(model, &case.settings, 1)?;
            sim.track_wear(bins);
            sim
        }
        Some(p) => Simulation::resume(model, &case.settings, p.snapshot, 1)?,
    };
    let mut stopped = None;
    let (results, map) = statistics_run_from(sim, &mut |sim| {
        let here = || WindowProgress {
            snapshot: sim.snapshot(),
        };
        let flow = at_batch(&here);
        if flow.is_break() {
            stopped = Some(here());
        }
        flow
    })?;
    if let Some(progress) = stopped {
        return Ok(WindowEnd::Stopped(Box::new(progress)));
    }
    let map = map.expect("tracked");
    if let Termination::Diverged { step, contact, .. } = results.termination {
        return Ok(WindowEnd::Diverged(step, contact));
    }
    let mut rates = Vec::with_capacity(wearing.len());
    let mut errors = Vec::with_capacity(wearing.len());
    let mut fractions = Vec::with_capacity(wearing.len());
    for &k in wearing {
        let work = model.wear[k].as_ref().map(|w| w.work).unwrap_or_default();
        rates.push(work.rate(&results.contacts[k]));
        errors.push(work.rate_se(&results.contacts[k]));
        let work = if work == WearWork::Normal {
            map.normal_work(k)
        } else {
            map.work(k)
        };
        let sum: f64 = work.iter().sum();
        fractions.push(if sum > 0.0 {
            work.iter().map(|w| w / sum).collect()
        } else {
            vec![0.0; work.len()]
        });
    }
    Ok(WindowEnd::Done(Window {
        rates,
        errors,
        fractions,
    }))
}
