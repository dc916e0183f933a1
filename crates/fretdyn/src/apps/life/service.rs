//! The service life (THEORY §14.5): windows of vibration on the obstacles worn so far, life
//! steps as long as every contact's depth limit allows, until the target time, a tube through
//! its wall, or a scar at the limit of its geometry.

use std::ops::ControlFlow;
use std::sync::atomic::Ordering;
use std::time::Instant;

use super::checkpoint::{LifeCheckpoint, LifeControl, LifeState};
use super::results::{ContactLife, LifeEnd, LifeResults, LifeStep, ScarProfile};
use super::step::{deepest, obstacle_wear};
use super::track::Track;
use super::window::{WindowEnd, window};
use crate::case::Case;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::settings::life::LifeSettings;
use crate::wear::pair_bodies;

/// Contact `k` of `current` on its unworn obstacle in `model` worn by the clearance `added`
/// per bin of its wear map (THEORY §14.4); for a two-body contact the obstacle is the pair's
/// relative one, which recedes by the approach of both bodies' scars.
fn wear_obstacle(
    current: &mut Model,
    model: &Model,
    k: usize,
    added: &[f64],
    field: &str,
) -> Result<()> {
    current.contacts[k].obstacle = model.contacts[k]
        .obstacle
        .worn(&obstacle_wear(added), field)?;
    Ok(())
}

/// `model` with the scars at the end of the life `results` (of this model) fed back: each
/// wearing contact's obstacle worn by its final scar profile's `clearance_increase`
/// (THEORY §14.4) — the model the life's next window would simulate (with feedback).
pub fn worn_model(model: &Model, results: &LifeResults) -> Result<Model> {
    let mut worn = model.clone();
    for scar in &results.scars {
        let k = model
            .contacts
            .iter()
            .position(|c| c.name == scar.contact)
            .ok_or_else(|| {
                Error::invalid(
                    "life",
                    format!(
                        "the life's contact '{}' is not in the model: give the model the life was computed on",
                        scar.contact
                    ),
                )
            })?;
        let field = format!("contacts[{k}].wear");
        wear_obstacle(&mut worn, model, k, &scar.clearance_increase, &field)?;
    }
    Ok(worn)
}

/// The service life of `case` with its `[life]` settings (THEORY §14.5). `observer` sees
/// each step as it is done.
pub fn service_life(
    case: &Case,
    life: &LifeSettings,
    observer: impl FnMut(&LifeStep),
) -> Result<LifeResults> {
    service_life_with(case, life, &mut LifeControl::default(), observer)
}

/// Most halvings of `max_depth_change` a convergence check runs (`fretdyn life --halvings`,
/// Python's `halvings`): each about doubles the life steps of the one before.
pub const MAX_HALVINGS: u32 = 10;

/// Whether contact `k` of `model` has a wear law.
fn wears(model: &Model, k: usize) -> bool {
    model.wear.get(k).is_some_and(|w| w.is_some())
}

/// What [`service_life_with`] checks before it computes anything: the `[life]` settings, and
/// a contact with a wear law. A front end calls it before it writes anything.
pub fn check_life(case: &Case, life: &LifeSettings) -> Result<()> {
    life.validate("life")?;
    crate::apps::check_names_for_tables(&case.model, "a service life")?;
    if !(0..case.model.contacts.len()).any(|k| wears(&case.model, k)) {
        return Err(Error::invalid(
            "life",
            "no contact has a wear law: give `wear = { tube = …, support = …, scar = … }` in the [[contacts]] that wear (docs/WEAR.md)",
        ));
    }
    Ok(())
}

/// [`service_life`] driven by `control`: checkpoints, a life continued from one, a stop
/// signal ([`LifeEnd::Stopped`], after a checkpoint).
pub fn service_life_with(
    case: &Case,
    life: &LifeSettings,
    control: &mut LifeControl,
    mut observer: impl FnMut(&LifeStep),
) -> Result<LifeResults> {
    check_life(case, life)?;
    let start = Instant::now();
    let model = &case.model;
    let mut tracks: Vec<Track> = (0..model.contacts.len())
        .filter(|&k| wears(model, k))
        .map(|k| Track::new(model, k, life.angular_bins))
        .collect();
    let wearing: Vec<usize> = tracks.iter().map(|c| c.k).collect();
    let stop_requested = || control.stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let mut state = match control.resume.take() {
        None => {
            let zero = ContactLife {
                wear_work_rate: 0.0,
                wear_work_rate_se: None,
                tube_volume: 0.0,
                support_volume: 0.0,
                tube_depth: 0.0,
                support_depth: 0.0,
                clearance_increase: 0.0,
                tube_depth_fixed_gap: 0.0,
            };
            let steps = vec![LifeStep {
                time: 0.0,
                contacts: vec![zero; tracks.len()],
            }];
            observer(&steps[0]);
            LifeState {
                t: 0.0,
                windows: 0,
                steps,
                first: None,
                tracks: tracks.iter().map(Track::state).collect(),
                wall_time: 0.0,
                window: None,
            }
        }
        Some(checkpoint) => {
            if checkpoint.fingerprint != control.fingerprint {
                return Err(Error::invalid(
                    "checkpoint",
                    "it was written for other inputs (the case, a file it reads or the [life] settings changed since the life started): start the life again instead of resuming it",
                ));
            }
            let state = checkpoint.state;
            if state.tracks.len() != tracks.len()
                || state
                    .tracks
                    .iter()
                    .zip(&tracks)
                    .any(|(s, t)| s.worn.tube.len() != t.worn.tube.len())
            {
                return Err(Error::invalid(
                    "checkpoint",
                    "its wearing contacts do not match the case: start the life again",
                ));
            }
            state
        }
    };
    // the obstacles worn so far (the model is a function of the volumes)
    let mut current = model.clone();
    for (c, s) in tracks.iter_mut().zip(&state.tracks) {
        c.restore(s);
        if life.feedback && state.steps.len() > 1 {
            let added = c.worn.depths(c.wear, &c.field)?.added;
            wear_obstacle(&mut current, model, c.k, &added, &c.field)?;
        }
    }
    let mut last_checkpoint = Instant::now();
    let save = |state: &LifeState, start: &Instant| -> Result<()> {
        match control.checkpoint {
            Some(path) => {
                let mut s = state.clone();
                s.wall_time += start.elapsed().as_secs_f64();
                LifeCheckpoint::write(path, control.fingerprint, &s)
            }
            None => Ok(()),
        }
    };
    let mut end = LifeEnd::StepLimit;
    while state.steps.len() <= life.max_steps {
        let t = state.t;
        if t >= life.target {
            break;
        }
        if stop_requested() {
            save(&state, &start)?;
            end = LifeEnd::Stopped { time: t };
            break;
        }
        // the window on the obstacles worn so far (only the first one without feedback)
        let w = match &state.first {
            Some(f) if !life.feedback => f.clone(),
            _ => {
                let progress = state.window.take();
                let mut failed = None;
                let outcome = window(
                    case,
                    &current,
                    &wearing,
                    life.angular_bins,
                    progress,
                    &mut |here| {
                        if stop_requested() {
                            return ControlFlow::Break(());
                        }
                        let every = control.checkpoint_every_seconds;
                        if control.checkpoint.is_some()
                            && last_checkpoint.elapsed().as_secs_f64() >= every
                        {
                            let mut s = state.clone();
                            s.window = Some(here());
                            if let Err(e) = save(&s, &start) {
                                failed = Some(e);
                                return ControlFlow::Break(());
                            }
                            last_checkpoint = Instant::now();
                        }
                        ControlFlow::Continue(())
                    },
                )?;
                if let Some(e) = failed {
                    return Err(e);
                }
                match outcome {
                    WindowEnd::Done(w) => {
                        state.windows += 1;
                        w
                    }
                    WindowEnd::Diverged(step, contact) => {
                        end = LifeEnd::Diverged {
                            window: state.windows,
                            time: t,
                            step,
                            contact,
                        };
                        state.windows += 1;
                        break;
                    }
                    WindowEnd::Stopped(progress) => {
                        state.window = Some(*progress);
                        save(&state, &start)?;
                        end = LifeEnd::Stopped { time: t };
                        break;
                    }
                }
            }
        };
        let w0 = state.first.get_or_insert_with(|| w.clone()).clone();
        // the longest step every contact allows, and the contact that sets it
        let mut dt = life.target - t;
        let mut limiting = 0;
        let mut beyond = None;
        for (i, c) in tracks.iter().enumerate() {
            match c.longest_step(w.rates[i], &w.fractions[i], t, dt, life)? {
                Ok(h) if h < dt => (dt, limiting) = (h, i),
                Ok(_) => {}
                Err(e) => {
                    beyond = Some((i, e));
                    break;
                }
            }
        }
        if let Some((i, e)) = beyond {
            // no step is short enough: the scar is at the limit of its geometry
            end = LifeEnd::ScarLimit {
                contact: tracks[i].name.clone(),
                time: t,
                message: e.to_string(),
            };
            break;
        }
        let t1 = if life.target - t - dt <= 1e-12 * life.target {
            life.target
        } else {
            t + dt
        };
        if !(t1 > t) {
            // a step below the resolution of the service time: a scar at the limit of its
            // geometry if the shortest step there is beyond it
            let c = &tracks[limiting];
            let (rate, fractions) = (w.rates[limiting], &w.fractions[limiting]);
            end = match c.advance(&c.worn, rate, fractions, t, t.next_up()) {
                Err(e) => LifeEnd::ScarLimit {
                    contact: c.name.clone(),
                    time: t,
                    message: e.to_string(),
                },
                Ok(_) => LifeEnd::StepTooShort {
                    contact: c.name.clone(),
                    time: t,
                    step: dt,
                    depth: deepest(&c.worn.depths(c.wear, &c.field)?.tube),
                },
            };
            break;
        }
        // every contact's next state, or the first scar beyond its geometry
        let mut next = Vec::with_capacity(tracks.len());
        for (i, c) in tracks.iter().enumerate() {
            let a = c.advance(&c.worn, w.rates[i], &w.fractions[i], t, t1);
            let f = c.advance(&c.fixed, w0.rates[i], &w0.fractions[i], t, t1);
            match (a, f) {
                (Ok(a), Ok(f)) => next.push((a, f)),
                (Err(e), _) | (_, Err(e)) => {
                    end = LifeEnd::ScarLimit {
                        contact: c.name.clone(),
                        time: t,
                        message: e.to_string(),
                    };
                    break;
                }
            }
        }
        if next.len() < tracks.len() {
            break;
        }
        let mut contacts = Vec::with_capacity(tracks.len());
        for (i, (c, (a, f))) in tracks.iter_mut().zip(next).enumerate() {
            let (rate, fractions) = (w.rates[i], &w.fractions[i]);
            let tube = deepest(&a.depths.tube);
            let tube_fixed = deepest(&f.depths.tube);
            if let Some(level) = life.criterion {
                if c.criterion.is_none() && tube >= level {
                    c.criterion = Some(c.reaches(&c.worn, rate, fractions, t, t1, level)?);
                }
                if c.criterion_fixed.is_none() && tube_fixed >= level {
                    let (r0, f0) = (w0.rates[i], &w0.fractions[i]);
                    c.criterion_fixed = Some(c.reaches(&c.fixed, r0, f0, t, t1, level)?);
                }
            }
            if let Some(wall) = life.wall
                && tube >= wall
            {
                c.perforation = Some(c.reaches(&c.worn, rate, fractions, t, t1, wall)?);
            }
            contacts.push(ContactLife {
                wear_work_rate: rate,
                wear_work_rate_se: w.errors[i],
                tube_volume: a.worn.tube.iter().sum(),
                support_volume: a.worn.support.iter().sum(),
                tube_depth: tube,
                support_depth: a.depths.support_max,
                clearance_increase: deepest(&a.depths.added),
                tube_depth_fixed_gap: tube_fixed,
            });
            if life.feedback {
                wear_obstacle(&mut current, model, c.k, &a.depths.added, &c.field)?;
            }
            (c.worn, c.fixed) = (a.worn, f.worn);
        }
        state.t = t1;
        state.steps.push(LifeStep { time: t1, contacts });
        state.tracks = tracks.iter().map(Track::state).collect();
        observer(state.steps.last().expect("pushed"));
        // the first tube through its wall ends the life
        if let Some((name, time)) = tracks
            .iter()
            .filter_map(|c| c.perforation.map(|p| (&c.name, p)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
        {
            end = LifeEnd::Perforated {
                contact: name.clone(),
                time,
            };
            break;
        }
        save(&state, &start)?;
        last_checkpoint = Instant::now();
    }
    if state.t >= life.target && matches!(end, LifeEnd::StepLimit) {
        end = LifeEnd::Completed;
    }
    let mut scars = Vec::with_capacity(tracks.len());
    for c in &tracks {
        let d = c.worn.depths(c.wear, &c.field)?;
        scars.push(ScarProfile {
            contact: c.name.clone(),
            kind: match d.added.len() {
                1 => "plane",
                2 => "bars",
                _ => "hole",
            },
            clearance_increase: d.added,
            tube_depth: d.tube,
            support_depth: d.support,
        });
    }
    Ok(LifeResults {
        contacts: tracks.iter().map(|c| c.name.clone()).collect(),
        clearances: tracks.iter().map(|c| c.clearance).collect(),
        bodies: tracks
            .iter()
            .map(|c| {
                pair_bodies(&model.contacts[c.k], &model.basis.points)
                    .map(|b| b.map(str::to_string))
            })
            .collect(),
        steps: state.steps,
        time_to_criterion: tracks.iter().map(|c| c.criterion).collect(),
        time_to_criterion_fixed_gap: tracks.iter().map(|c| c.criterion_fixed).collect(),
        scars,
        end,
        windows: state.windows,
        wall_time: state.wall_time + start.elapsed().as_secs_f64(),
    })
}
