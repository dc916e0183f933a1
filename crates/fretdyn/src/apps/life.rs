//! Service life (THEORY §14.5): the wear depth of each contact over years, with the scar fed
//! back into the obstacle's geometry.
//!
//! The vibration is simulated over a representative window (the case's `[time]` and
//! `[statistics]` window), from the case's initial state, on the obstacles worn so far. Each
//! contact's wear work rate `W` of the window and where it was done ([`WearMap`]) drive its
//! wear laws over a life step `[t, t + Δt]` at constant `W`: the tube's and the support's
//! volumes grow by `ΔV = ∫ V̇(W, τ) dτ`, spread over the bins of the map in the proportions of
//! the window's work; the scar geometry turns each volume into a depth ([`crate::wear`]). The
//! obstacle then recedes by the tube's plus the support's depth in the direction the scar
//! faces ([`crate::contact::scar`]) and the next window is simulated, until the target time.
//!
//! The life step is the longest (up to the target) over which no contact's depth (tube plus
//! support, where it is deepest) grows by more than `max_depth_change × max(g₀ + D, d_res)`,
//! `g₀` the contact's clearance at rest, `D` its depth so far and `d_res` the depth
//! resolution; it is found by bisection, the depth being monotone in `Δt`. Halving
//! `max_depth_change` shows the convergence (docs/WEAR.md).
//!
//! The same windows give the fixed-gap extrapolation (the first window's rates kept for the
//! whole life, as a post-processing of one run does) beside the coupled result.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use std::ops::ControlFlow;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::accumulate::wear_map::WearMap;
use crate::case::Case;
use crate::contact::scar::{AngularProfile, ObstacleWear};
use crate::error::{Error, Result};
use crate::integrator::simulation::statistics_run_from;
use crate::integrator::simulation::{Simulation, Snapshot, Termination};
use crate::model::Model;
pub use crate::settings::life::{DEFAULT_MAX_DEPTH_CHANGE, LifeSettings, MAX_ANGULAR_BINS, YEAR};
use crate::wear::{ContactWear, HoleScar, Scar, WearWork};

/// One contact at the end of a life step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactLife {
    /// Wear work rate of the window that drove the step (the law's work: friction or
    /// normal), W.
    pub wear_work_rate: f64,
    /// Its standard error by batch means (THEORY §11), W; `None` without batches.
    pub wear_work_rate_se: Option<f64>,
    /// Wear volume of the tube so far, m³.
    pub tube_volume: f64,
    /// Wear volume of the support so far, m³.
    pub support_volume: f64,
    /// Depth of the tube's scar (the deepest, for bars: the deeper side), m.
    pub tube_depth: f64,
    /// Depth of the support's scar, m.
    pub support_depth: f64,
    /// The clearance the scars add where they are deepest ([`Scar::approach`] of the two
    /// volumes: how far tube and support came together), m.
    pub clearance_increase: f64,
    /// The tube's depth by the fixed-gap extrapolation of the first window, m.
    pub tube_depth_fixed_gap: f64,
}

/// The state after one life step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LifeStep {
    /// Service time at the end of the step, s.
    pub time: f64,
    /// Per contact (the contacts with `wear`, in the case's order).
    pub contacts: Vec<ContactLife>,
}

/// How a service-life computation ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum LifeEnd {
    /// The target time was reached.
    Completed,
    /// A window diverged: the life stops at the service time it started from.
    Diverged {
        /// The window (from 0).
        window: usize,
        /// Service time, s.
        time: f64,
        /// Step of the window and the contact where it diverged.
        step: u64,
        /// The contact, if one was named.
        contact: Option<String>,
    },
    /// `max_steps` life steps did not reach the target.
    StepLimit,
    /// A tube's depth reached its wall thickness: the life stops there (a result, not an
    /// error: the depth against time up to then is the answer).
    Perforated {
        /// The contact.
        contact: String,
        /// Service time at which the depth reached the wall, s.
        time: f64,
    },
    /// A scar reached the limit of its geometry (e.g. a tube's depth its radius): the life
    /// stops at the service time it reached.
    ScarLimit {
        /// The contact.
        contact: String,
        /// Service time, s.
        time: f64,
        /// What the geometry says.
        message: String,
    },
    /// The life step the depth limit allows is below the resolution of the service time in
    /// floating point (`t + Δt = t`): the wear is too fast, or the target too far, for the
    /// life step's limit (`max_depth_change`, `depth_resolution`).
    StepTooShort {
        /// The contact whose depth limits the step.
        contact: String,
        /// Service time, s.
        time: f64,
        /// The life step, s.
        step: f64,
        /// The contact's tube depth then, m.
        depth: f64,
    },
    /// Stopped from outside (a signal) at this service time: continued from its checkpoint
    /// by [`service_life_with`] and [`LifeControl::resume`].
    Stopped {
        /// Service time reached, s.
        time: f64,
    },
}

impl LifeEnd {
    /// The name of the end in a table (`life_end` of a study, `convergence.csv`).
    pub fn name(&self) -> &'static str {
        match self {
            LifeEnd::Completed => "completed",
            LifeEnd::Perforated { .. } => "perforated",
            LifeEnd::ScarLimit { .. } => "scar_limit",
            LifeEnd::Diverged { .. } => "diverged",
            LifeEnd::StepLimit => "step_limit",
            LifeEnd::StepTooShort { .. } => "step_too_short",
            LifeEnd::Stopped { .. } => "stopped",
        }
    }

    /// Whether the life reached its end: the target time, or a tube through its wall (the
    /// depth against time up to then is the answer). Any other end is a life cut short.
    pub fn is_finished(&self) -> bool {
        matches!(self, LifeEnd::Completed | LifeEnd::Perforated { .. })
    }
}

/// A scar's final state, for the scar profiles.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScarProfile {
    /// The contact.
    pub contact: String,
    /// `plane`, `bars` (values for the `+n`, `−n` sides) or `hole` (values per angular bin,
    /// bin `k` centred on `(k + ½) 360°/N` in the hole's axes).
    pub kind: &'static str,
    /// Added clearance (the approach of tube and support, [`Scar::approach`]) per bin, m.
    pub clearance_increase: Vec<f64>,
    /// Tube depth per bin, m.
    pub tube_depth: Vec<f64>,
}

/// The result of [`service_life`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LifeResults {
    /// Names of the wearing contacts.
    pub contacts: Vec<String>,
    /// Clearance at rest of each wearing contact, m.
    pub clearances: Vec<f64>,
    /// The state at t = 0 and after every life step.
    pub steps: Vec<LifeStep>,
    /// Time at which each contact's tube depth reaches the criterion, s (`None`: not reached).
    pub time_to_criterion: Vec<Option<f64>>,
    /// Same, by the fixed-gap extrapolation.
    pub time_to_criterion_fixed_gap: Vec<Option<f64>>,
    /// Final scar profiles.
    pub scars: Vec<ScarProfile>,
    /// How it ended.
    pub end: LifeEnd,
    /// Windows simulated.
    pub windows: usize,
    /// Wall-clock time, s.
    pub wall_time: f64,
}

/// Cumulative wear of one contact, per bin of its [`WearMap`].
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Worn {
    /// Tube volume per bin, m³.
    tube: Vec<f64>,
    /// Support volume per bin, m³.
    support: Vec<f64>,
}

/// The depths of a contact's scar(s) from its volumes.
struct Depths {
    /// Tube depth per bin (what faces each direction), m.
    tube: Vec<f64>,
    /// Added clearance per bin, m.
    added: Vec<f64>,
    /// Support depth where deepest, m.
    support_max: f64,
}

impl Worn {
    fn new(bins: usize) -> Self {
        Self {
            tube: vec![0.0; bins],
            support: vec![0.0; bins],
        }
    }

    /// Depths from the volumes (THEORY §14.4): a plane's or a side's scar from its own
    /// volumes; around a hole, the scar's depth from the whole volume, spread over the bins
    /// in proportion to each bin's volume (the deepest bin takes the full depth), or all
    /// around for a uniform scar.
    fn depths(&self, wear: &ContactWear, field: &str) -> Result<Depths> {
        let n = self.tube.len();
        if n <= 2 {
            let mut d = Depths {
                tube: vec![0.0; n],
                added: vec![0.0; n],
                support_max: 0.0,
            };
            for b in 0..n {
                let (vt, vs) = (self.tube[b], self.support[b]);
                let t = wear.scar.tube_depth(vt).map_err(|e| at(e, field))?;
                let s = wear.scar.support_depth(vs).map_err(|e| at(e, field))?;
                d.tube[b] = t;
                d.added[b] = wear.scar.approach(vt, vs).map_err(|e| at(e, field))?;
                d.support_max = d.support_max.max(s);
            }
            return Ok(d);
        }
        let (vt, vs): (f64, f64) = (self.tube.iter().sum(), self.support.iter().sum());
        let t = wear.scar.tube_depth(vt).map_err(|e| at(e, field))?;
        let s = wear.scar.support_depth(vs).map_err(|e| at(e, field))?;
        let approach = wear.scar.approach(vt, vs).map_err(|e| at(e, field))?;
        let uniform = matches!(
            wear.scar,
            Scar::DrilledHole {
                shape: HoleScar::Uniform,
                ..
            }
        );
        let total: Vec<f64> = self
            .tube
            .iter()
            .zip(&self.support)
            .map(|(a, b)| a + b)
            .collect();
        let shape: Vec<f64> = match wear.scar {
            _ if uniform => vec![1.0; n],
            Scar::DrilledHole {
                tube_radius,
                clearance,
                ..
            } => spread(
                &crescent_footprint(tube_radius, clearance, approach, n),
                &total,
            ),
            _ => spread(&[1.0], &total),
        };
        Ok(Depths {
            tube: shape.iter().map(|f| f * t).collect(),
            added: shape.iter().map(|f| f * approach).collect(),
            support_max: s,
        })
    }
}

/// The crescent a tube of radius `r` leaves when it is pushed `a` beyond a hole of clearance
/// `c` (THEORY §14.4), over `n` bins: the thickness of the lens at the angle `φ` from its
/// middle, `t(φ) = d cos φ + √(r² − d² sin²φ) − (r + c)` (≥ 0), `d = c + a`, relative to its
/// depth `a`; index `j` is `φ = ±j 2π/n`, `j ∈ [0, n/2]` (it is even in `φ`).
fn crescent_footprint(r: f64, c: f64, a: f64, n: usize) -> Vec<f64> {
    if a <= 0.0 {
        let mut one = vec![0.0; n / 2 + 1];
        one[0] = 1.0;
        return one;
    }
    let d = c + a;
    (0..=n / 2)
        .map(|j| {
            let phi = std::f64::consts::TAU * j as f64 / n as f64;
            let (s, co) = phi.sin_cos();
            let inner = r * r - d * d * s * s;
            if inner < 0.0 {
                return 0.0;
            }
            ((d * co + inner.sqrt() - (r + c)) / a).max(0.0)
        })
        .collect()
}

/// The shape of a scar around a hole: each bin's volume spread by `footprint` (index `j`: `±j`
/// bins away, periodic, `j ≤ n/2`), normalised to 1 where deepest (0 everywhere without
/// volume).
fn spread(footprint: &[f64], volumes: &[f64]) -> Vec<f64> {
    let n = volumes.len();
    let mut shape = vec![0.0; n];
    for (b, v) in volumes.iter().enumerate().filter(|(_, v)| **v > 0.0) {
        for (j, f) in footprint.iter().enumerate().filter(|(_, f)| **f > 0.0) {
            shape[(b + j) % n] += v * f;
            if j > 0 && 2 * j != n {
                shape[(b + n - j) % n] += v * f;
            }
        }
    }
    let max = shape.iter().copied().fold(0.0, f64::max);
    if max > 0.0 {
        shape.iter_mut().for_each(|x| *x /= max);
    }
    shape
}

/// `e` of a contact's wear (its field `wear.…`) named in the case: `contacts[k].wear.…`
/// with `field` = `contacts[k].wear`.
fn at(e: Error, field: &str) -> Error {
    match e {
        Error::Invalid { field: f, message } => {
            let f = f.strip_prefix("wear.").unwrap_or(&f);
            Error::invalid(format!("{field}.{f}"), message)
        }
        other => other,
    }
}

/// The obstacle's wear for the added clearance per bin.
fn obstacle_wear(added: &[f64]) -> ObstacleWear {
    match added.len() {
        1 => ObstacleWear::Uniform(added[0]),
        2 => ObstacleWear::Sides {
            positive: added[0],
            negative: added[1],
        },
        // the bins' depths are finite and ≥ 0 by construction
        _ => {
            ObstacleWear::Angular(AngularProfile::new(added.to_vec()).unwrap_or_else(|| {
                AngularProfile::new(vec![0.0; added.len()]).expect("zero profile")
            }))
        }
    }
}

/// One window's wear work rate and its split over the bins, per wearing contact.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Window {
    rates: Vec<f64>,
    errors: Vec<Option<f64>>,
    fractions: Vec<Vec<f64>>,
}

/// How a window ended.
enum WindowEnd {
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
struct WindowProgress {
    snapshot: Snapshot,
}

/// Runs one window of `model`, tracking where the friction work is done, from its start or
/// from `progress`; `at_batch(progress)` after each batch of steps before the last may stop
/// it (`Break`).
fn window(
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

/// The volumes after `[t0, t1]` at the window's rates.
fn advanced(
    worn: &Worn,
    wear: &ContactWear,
    rate: f64,
    fractions: &[f64],
    t0: f64,
    t1: f64,
) -> Worn {
    let dvt = wear.tube.volume_increment(rate, t0, t1);
    let dvs = wear.support.volume_increment(rate, t0, t1);
    Worn {
        tube: worn
            .tube
            .iter()
            .zip(fractions)
            .map(|(v, f)| v + f * dvt)
            .collect(),
        support: worn
            .support
            .iter()
            .zip(fractions)
            .map(|(v, f)| v + f * dvs)
            .collect(),
    }
}

fn deepest(d: &[f64]) -> f64 {
    d.iter().copied().fold(0.0, f64::max)
}

/// One wearing contact through the life: what it is, and its volumes with and without
/// feedback.
struct Track<'a> {
    /// Index of the contact in the model.
    k: usize,
    name: String,
    /// `contacts[k].wear`, for messages.
    field: String,
    wear: &'a ContactWear,
    /// Clearance at rest `g₀`, m.
    clearance: f64,
    /// Volumes with the scars fed back.
    worn: Worn,
    /// Volumes of the fixed-gap extrapolation.
    fixed: Worn,
    /// When the tube's depth reached the criterion (with feedback, at fixed gap) and its wall.
    criterion: Option<f64>,
    criterion_fixed: Option<f64>,
    perforation: Option<f64>,
}

/// A volume state advanced over a life step, with its depths.
struct Advanced {
    worn: Worn,
    depths: Depths,
}

impl<'a> Track<'a> {
    fn new(model: &'a Model, k: usize, bins: usize) -> Self {
        let c = &model.contacts[k];
        let x = model.basis.points[c.point].coords;
        let worn = Worn::new(WearMap::new(model, bins).work(k).len());
        Self {
            k,
            name: c.name.clone(),
            field: format!("contacts[{k}].wear"),
            wear: model.wear[k].as_ref().expect("a wearing contact"),
            clearance: (-c.frame(&x, 0.0).penetration).max(0.0),
            fixed: worn.clone(),
            worn,
            criterion: None,
            criterion_fixed: None,
            perforation: None,
        }
    }

    /// What the track has accumulated, for a checkpoint.
    fn state(&self) -> TrackState {
        TrackState {
            worn: self.worn.clone(),
            fixed: self.fixed.clone(),
            criterion: self.criterion,
            criterion_fixed: self.criterion_fixed,
            perforation: self.perforation,
        }
    }

    /// Takes up what a checkpoint's track had accumulated.
    fn restore(&mut self, s: &TrackState) {
        self.worn = s.worn.clone();
        self.fixed = s.fixed.clone();
        self.criterion = s.criterion;
        self.criterion_fixed = s.criterion_fixed;
        self.perforation = s.perforation;
    }

    fn advance(
        &self,
        from: &Worn,
        rate: f64,
        fractions: &[f64],
        t0: f64,
        t1: f64,
    ) -> Result<Advanced> {
        let worn = advanced(from, self.wear, rate, fractions, t0, t1);
        let depths = worn.depths(self.wear, &self.field)?;
        Ok(Advanced { worn, depths })
    }

    /// The longest step from `t` (at most `dt`) over which the added clearance grows by no
    /// more than the settings allow (§14.5); beyond the scar's geometry counts as too much.
    /// Found by bisection on `[0, dt]`; a step below `1e-9 dt` (a fast wear against a long
    /// life), which that bisection cannot resolve, by halving `dt` down to it, then
    /// bisection between it and its double. `Err` (inside): no step is short enough — the
    /// scar is at the limit of its geometry (the error of its smallest step).
    fn longest_step(
        &self,
        rate: f64,
        fractions: &[f64],
        t: f64,
        dt: f64,
        life: &LifeSettings,
    ) -> Result<std::result::Result<f64, Error>> {
        let now = deepest(&self.worn.depths(self.wear, &self.field)?.added);
        let limit = life.max_depth_change * (self.clearance + now).max(life.depth_resolution);
        let growth = |h: f64| {
            self.advance(&self.worn, rate, fractions, t, t + h)
                .map(|a| deepest(&a.depths.added) - now)
        };
        let grown = |h: f64| growth(h).unwrap_or(f64::INFINITY);
        if grown(dt) <= limit {
            return Ok(Ok(dt));
        }
        let (mut lo, mut hi) = (0.0, dt);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if grown(mid) > limit {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        if lo > 1e-9 * dt {
            return Ok(Ok(lo));
        }
        // halvings down to a step within the limit, then bisection in [h, 2h]
        let mut h = hi;
        loop {
            h *= 0.5;
            match growth(h) {
                Ok(g) if g <= limit => break,
                Err(e) if h <= f64::MIN_POSITIVE => return Ok(Err(e)),
                _ if h <= f64::MIN_POSITIVE => {
                    return Ok(Err(Error::invalid(
                        format!("{}.tube", self.field),
                        format!(
                            "the depth grows by more than {limit:e} m in any life step: is the wear rate finite?"
                        ),
                    )));
                }
                _ => {}
            }
        }
        let (mut lo, mut hi) = (h, 2.0 * h);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if grown(mid) > limit {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Ok(Ok(lo))
    }

    /// The time in `[t0, t1]` at which the tube's depth from `from` reaches `level`.
    fn reaches(
        &self,
        from: &Worn,
        rate: f64,
        fractions: &[f64],
        t0: f64,
        t1: f64,
        level: f64,
    ) -> Result<f64> {
        crossing(t0, t1, level, |h| {
            self.advance(from, rate, fractions, t0, h)
                .map(|a| deepest(&a.depths.tube))
        })
    }
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

/// The file that records which inputs a life's folder belongs to, for a resume.
pub const LIFE_RUN_FILE: &str = "life_run.json";

/// The checkpoint of a life in its folder ([`LifeCheckpoint`]).
pub const CHECKPOINT_FILE: &str = "life_checkpoint.bin";

/// What a life writes in its folder (removed when a new life starts there, so that a folder
/// never mixes two lives).
pub const OUTPUTS: [&str; 6] = [
    "life.csv",
    "life.json",
    "scars.csv",
    "life.png",
    "convergence.csv",
    "convergence.png",
];

/// The text of `life.json`, as `fretdyn life` and Python's `fretdyn.life` write it: the case
/// `title`, the plugging `criterion_depth` (m, or null) and the `results`.
pub fn life_json(title: &str, results: &LifeResults, criterion: Option<f64>) -> String {
    let json = serde_json::json!({
        "title": title,
        "criterion_depth": criterion,
        "results": results,
    });
    serde_json::to_string_pretty(&json).unwrap_or_default() + "\n"
}

/// Whether contact `k` of `model` has a wear law.
fn wears(model: &Model, k: usize) -> bool {
    model.wear.get(k).is_some_and(|w| w.is_some())
}

/// What [`service_life_with`] checks before it computes anything: the `[life]` settings, and
/// a contact with a wear law. A front end calls it before it writes anything.
pub fn check_life(case: &Case, life: &LifeSettings) -> Result<()> {
    life.validate("life")?;
    super::check_names_for_tables(&case.model, "a service life")?;
    if !(0..case.model.contacts.len()).any(|k| wears(&case.model, k)) {
        return Err(Error::invalid(
            "life",
            "no contact has a wear law: give `wear = { tube = …, support = …, scar = … }` in the [[contacts]] that wear (docs/WEAR.md)",
        ));
    }
    Ok(())
}

/// How a service life is driven from outside: where its checkpoint goes, a life to
/// continue, and a stop signal.
#[derive(Default)]
pub struct LifeControl<'a> {
    /// The checkpoint file, written after every life step and, inside a window, every
    /// `checkpoint_every_seconds` of wall-clock time and when the life is stopped
    /// ([`LifeCheckpoint`]); `None`: no checkpoint.
    pub checkpoint: Option<&'a Path>,
    /// Wall-clock seconds between checkpoints inside a window (0: at every batch of steps).
    pub checkpoint_every_seconds: f64,
    /// The fingerprint of the inputs (the case as resolved, the files it reads, the life's
    /// settings): a checkpoint is resumed only by the inputs it was written for.
    pub fingerprint: u64,
    /// A life to continue, read by [`LifeCheckpoint::read`]: the results are those of an
    /// uninterrupted life, bit for bit (but the wall-clock time).
    pub resume: Option<LifeCheckpoint>,
    /// Set from outside (a signal): the life stops at the next batch of steps of its window
    /// or the next life step, after a checkpoint ([`LifeEnd::Stopped`]).
    pub stop: Option<&'a AtomicBool>,
}

/// The state of a service life between two batches of steps, as its checkpoint holds it.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct LifeState {
    /// Service time reached, s.
    t: f64,
    /// Windows simulated (finished).
    windows: usize,
    /// The state at t = 0 and after every life step so far.
    steps: Vec<LifeStep>,
    /// The first window's rates (the fixed-gap extrapolation).
    first: Option<Window>,
    /// Each wearing contact's volumes and the times found so far.
    tracks: Vec<TrackState>,
    /// Wall-clock time of the sessions before this one, s.
    wall_time: f64,
    /// The window under way, if the checkpoint was taken inside one.
    window: Option<WindowProgress>,
}

/// What a wearing contact has accumulated (the part of [`Track`] that changes).
#[derive(Debug, Clone, Serialize, Deserialize)]
struct TrackState {
    worn: Worn,
    fixed: Worn,
    criterion: Option<f64>,
    criterion_fixed: Option<f64>,
    perforation: Option<f64>,
}

/// A service life's checkpoint (`life_checkpoint.bin`): these bytes, then the format
/// version (u32 little-endian), the length of fretdyn's version (u8) and the version, the
/// fingerprint of the inputs (u64 little-endian), then the state in CBOR (exact for every
/// `f64`). A checkpoint of another format or version, or of other inputs, is refused.
#[derive(Debug, Clone)]
pub struct LifeCheckpoint {
    fingerprint: u64,
    state: LifeState,
}

/// First bytes of a service life's checkpoint.
pub const LIFE_CHECKPOINT_MAGIC: &[u8; 8] = b"FRETDYNL";
/// Format version of a service life's checkpoint (1: the window's wear map beside its
/// simulation's hand-kept snapshot).
pub const LIFE_CHECKPOINT_FORMAT: u32 = 2;

impl LifeCheckpoint {
    /// Reads the checkpoint at `path`; the error says why it cannot be resumed.
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let bad = |why: String| Error::invalid("checkpoint", format!("{}: {why}", path.display()));
        let again = "start the life again";
        let rest = bytes
            .strip_prefix(LIFE_CHECKPOINT_MAGIC)
            .ok_or_else(|| bad(format!("not a service life's checkpoint: {again}")))?;
        let truncated = || bad(format!("truncated: {again}"));
        let format = u32::from_le_bytes(
            rest.get(..4)
                .and_then(|b| b.try_into().ok())
                .ok_or_else(truncated)?,
        );
        let len = *rest.get(4).ok_or_else(truncated)? as usize;
        let version = String::from_utf8_lossy(rest.get(5..5 + len).ok_or_else(truncated)?);
        let ours = env!("CARGO_PKG_VERSION");
        if format != LIFE_CHECKPOINT_FORMAT || version != ours {
            return Err(bad(format!(
                "written by fretdyn {version} (format {format}), this is fretdyn {ours} (format {LIFE_CHECKPOINT_FORMAT}): resume it with fretdyn {version}, or {again}"
            )));
        }
        let fingerprint = u64::from_le_bytes(
            rest.get(5 + len..13 + len)
                .and_then(|b| b.try_into().ok())
                .ok_or_else(truncated)?,
        );
        let state: LifeState = ciborium::from_reader(&rest[13 + len..])
            .map_err(|e| bad(format!("damaged ({e}): {again}")))?;
        Ok(Self { fingerprint, state })
    }

    /// The service time the checkpoint reached, s.
    pub fn time(&self) -> f64 {
        self.state.t
    }

    /// The fingerprint of the inputs it was written for.
    pub fn fingerprint(&self) -> u64 {
        self.fingerprint
    }

    /// Whether it was taken inside a window of vibration (else between two life steps).
    pub fn inside_window(&self) -> bool {
        self.state.window.is_some()
    }

    fn write(path: &Path, fingerprint: u64, state: &LifeState) -> Result<()> {
        let version = env!("CARGO_PKG_VERSION").as_bytes();
        let mut bytes = Vec::with_capacity(4096);
        bytes.extend_from_slice(LIFE_CHECKPOINT_MAGIC);
        bytes.extend_from_slice(&LIFE_CHECKPOINT_FORMAT.to_le_bytes());
        bytes.push(version.len() as u8);
        bytes.extend_from_slice(version);
        bytes.extend_from_slice(&fingerprint.to_le_bytes());
        ciborium::into_writer(state, &mut bytes)
            .map_err(|e| Error::io(path, std::io::Error::other(e)))?;
        crate::files::write_atomically(path, |mut f| {
            use std::io::Write;
            f.write_all(&bytes)?;
            f.sync_data()
        })
    }
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
            current.contacts[c.k].obstacle = model.contacts[c.k]
                .obstacle
                .worn(&obstacle_wear(&added), &c.field)?;
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
                current.contacts[c.k].obstacle = model.contacts[c.k]
                    .obstacle
                    .worn(&obstacle_wear(&a.depths.added), &c.field)?;
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
        });
    }
    Ok(LifeResults {
        contacts: tracks.iter().map(|c| c.name.clone()).collect(),
        clearances: tracks.iter().map(|c| c.clearance).collect(),
        steps: state.steps,
        time_to_criterion: tracks.iter().map(|c| c.criterion).collect(),
        time_to_criterion_fixed_gap: tracks.iter().map(|c| c.criterion_fixed).collect(),
        scars,
        end,
        windows: state.windows,
        wall_time: state.wall_time + start.elapsed().as_secs_f64(),
    })
}

/// The time in `[t0, t1]` at which `depth(t)` (increasing) reaches `c`, by bisection.
fn crossing(t0: f64, t1: f64, c: f64, depth: impl Fn(f64) -> Result<f64>) -> Result<f64> {
    let (mut lo, mut hi) = (t0, t1);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if depth(mid)? >= c {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crescent's footprint is the lens between the tube's circle and the hole's: 1 at its
    /// middle, and it ends where the two circles cross, `cos θ_h = (d² + R_h² − r²)/(2 d R_h)`
    /// (the law of cosines, independent of the thickness formula).
    #[test]
    fn the_crescent_footprint_ends_where_the_circles_cross() {
        let (r, c, a, n) = (9.525e-3, 2e-4, 3e-5, 3600);
        let f = crescent_footprint(r, c, a, n);
        assert!((f[0] - 1.0).abs() < 1e-9);
        let (d, rh) = (c + a, r + c);
        let half = ((d * d + rh * rh - r * r) / (2.0 * d * rh)).acos();
        let last = f.iter().rposition(|x| *x > 0.0).unwrap();
        let step = std::f64::consts::TAU / n as f64;
        assert!(
            (last as f64 * step - half).abs() <= step,
            "{} vs {half}",
            last as f64 * step
        );
        // the thickness falls from the middle to the edge
        assert!(f.windows(2).take(last).all(|w| w[1] <= w[0]));
        // spreading keeps the profile's peak at 1 and its symmetry
        let mut volumes = vec![0.0; 72];
        volumes[10] = 1.0;
        let shape = spread(&crescent_footprint(r, c, a, 72), &volumes);
        assert_eq!(shape[10], 1.0);
        for j in 1..36 {
            assert_eq!(shape[(10 + j) % 72], shape[(10 + 72 - j) % 72]);
        }
    }
}
