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

use serde::Serialize;

use crate::apps::study::statistics_run;
use crate::case::Case;
use crate::contact::scar::{AngularProfile, ObstacleWear};
use crate::error::{Error, Result};
use crate::integrator::simulation::Termination;
use crate::model::Model;
use crate::results::wear_map::WearMap;
use crate::wear::{ContactWear, HoleScar, Scar, WearWork};

/// Seconds in a year (365.25 days).
pub const YEAR: f64 = 365.25 * 86_400.0;

/// The `[life]` section (THEORY §14.5).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LifeSettings {
    /// Service time to reach, s.
    pub target: f64,
    /// Largest growth of a contact's depth in one life step, as a fraction of
    /// `max(g₀ + D, depth_resolution)`.
    pub max_depth_change: f64,
    /// Depth below which the relative limit does not apply, m.
    pub depth_resolution: f64,
    /// The tube's plugging depth, m (time to reach it reported), if any.
    pub criterion: Option<f64>,
    /// The tube's wall thickness, m, if known (a tube structure): the life stops when a
    /// tube's depth reaches it.
    pub wall: Option<f64>,
    /// Feed the scars back into the obstacles (`false`: the fixed-gap extrapolation only).
    pub feedback: bool,
    /// Angular bins of a hole's scar profile.
    pub angular_bins: usize,
    /// Largest number of life steps.
    pub max_steps: usize,
}

impl LifeSettings {
    /// Checks the numbers; `field` is the section's name in messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !positive(self.target) {
            return Err(Error::invalid(
                format!("{field}.target_years"),
                "must be a service time > 0 in years",
            ));
        }
        if !(positive(self.max_depth_change) && self.max_depth_change <= 1.0) {
            return Err(Error::invalid(
                format!("{field}.max_depth_change"),
                format!(
                    "must be a fraction in (0, 1] (got {}); 0.1 is a good start, halve it to check convergence",
                    self.max_depth_change
                ),
            ));
        }
        if !positive(self.depth_resolution) {
            return Err(Error::invalid(
                format!("{field}.depth_resolution"),
                "must be a depth > 0 in m (e.g. 1e-6)",
            ));
        }
        if let Some(c) = self.criterion
            && !positive(c)
        {
            return Err(Error::invalid(
                format!("{field}.criterion_depth"),
                "must be a depth > 0 in m (e.g. 40 % of the tube wall)",
            ));
        }
        if self.angular_bins < 4 {
            return Err(Error::invalid(
                format!("{field}.angular_bins"),
                "must be at least 4 (72 = 5° bins by default)",
            ));
        }
        if self.max_steps == 0 {
            return Err(Error::invalid(
                format!("{field}.max_steps"),
                "must be at least 1",
            ));
        }
        Ok(())
    }
}

/// One contact at the end of a life step.
#[derive(Debug, Clone, PartialEq, Serialize)]
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
#[derive(Debug, Clone, PartialEq, Serialize)]
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
#[derive(Debug, Clone)]
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

fn at(e: Error, field: &str) -> Error {
    match e {
        Error::Invalid { field: f, message } => Error::invalid(format!("{field}.{f}"), message),
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
#[derive(Clone)]
struct Window {
    rates: Vec<f64>,
    errors: Vec<Option<f64>>,
    fractions: Vec<Vec<f64>>,
}

/// Runs one window of `model`, tracking where the friction work is done.
fn window(
    case: &Case,
    model: &Model,
    wearing: &[usize],
    bins: usize,
) -> Result<std::result::Result<Window, (u64, Option<String>)>> {
    let (results, map) = statistics_run(model, &case.settings, Some(bins))?;
    let map = map.expect("tracked");
    if let Termination::Diverged { step, contact, .. } = results.termination {
        return Ok(Err((step, contact)));
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
    Ok(Ok(Window {
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
    fn longest_step(
        &self,
        rate: f64,
        fractions: &[f64],
        t: f64,
        dt: f64,
        life: &LifeSettings,
    ) -> Result<f64> {
        let now = deepest(&self.worn.depths(self.wear, &self.field)?.added);
        let limit = life.max_depth_change * (self.clearance + now).max(life.depth_resolution);
        let grown = |h: f64| {
            self.advance(&self.worn, rate, fractions, t, t + h)
                .map_or(f64::INFINITY, |a| deepest(&a.depths.added) - now)
        };
        if grown(dt) <= limit {
            return Ok(dt);
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
        Ok(lo)
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
    mut observer: impl FnMut(&LifeStep),
) -> Result<LifeResults> {
    life.validate("life")?;
    let start = Instant::now();
    let model = &case.model;
    let mut tracks: Vec<Track> = (0..model.contacts.len())
        .filter(|&k| model.wear.get(k).is_some_and(|w| w.is_some()))
        .map(|k| Track::new(model, k, life.angular_bins))
        .collect();
    if tracks.is_empty() {
        return Err(Error::invalid(
            "life",
            "no contact has a wear law: give `wear = { tube = …, support = …, scar = … }` in the [[contacts]] that wear (docs/WEAR.md)",
        ));
    }
    let wearing: Vec<usize> = tracks.iter().map(|c| c.k).collect();
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
    let mut steps = vec![LifeStep {
        time: 0.0,
        contacts: vec![zero; tracks.len()],
    }];
    observer(&steps[0]);
    let mut first: Option<Window> = None;
    let mut current = model.clone();
    let (mut t, mut windows) = (0.0, 0);
    let mut end = LifeEnd::StepLimit;
    for _ in 0..life.max_steps {
        if t >= life.target {
            break;
        }
        // the window on the obstacles worn so far (only the first one without feedback)
        let w = match &first {
            Some(f) if !life.feedback => f.clone(),
            _ => {
                windows += 1;
                match window(case, &current, &wearing, life.angular_bins)? {
                    Ok(w) => w,
                    Err((step, contact)) => {
                        end = LifeEnd::Diverged {
                            window: windows - 1,
                            time: t,
                            step,
                            contact,
                        };
                        break;
                    }
                }
            }
        };
        let w0 = first.get_or_insert_with(|| w.clone()).clone();
        let mut dt = life.target - t;
        for (i, c) in tracks.iter().enumerate() {
            dt = c.longest_step(w.rates[i], &w.fractions[i], t, dt, life)?;
        }
        let t1 = if life.target - t - dt <= 1e-12 * life.target {
            life.target
        } else {
            t + dt
        };
        // every contact's next state, or the first scar beyond its geometry
        let mut next = Vec::with_capacity(tracks.len());
        for (i, c) in tracks.iter().enumerate() {
            let a = c.advance(&c.worn, w.rates[i], &w.fractions[i], t, t1);
            let f = c.advance(&c.fixed, w0.rates[i], &w0.fractions[i], t, t1);
            match (a, f) {
                (Ok(a), Ok(f)) if t1 - t > 1e-12 * life.target => next.push((a, f)),
                (a, f) => {
                    let message = match (a.err(), f.err()) {
                        (Some(e), _) | (None, Some(e)) => e.to_string(),
                        _ => "the scar's depth no longer grows within its geometry".into(),
                    };
                    end = LifeEnd::ScarLimit {
                        contact: c.name.clone(),
                        time: t,
                        message,
                    };
                    break;
                }
            }
        }
        if next.len() < tracks.len() {
            break;
        }
        let mut state = Vec::with_capacity(tracks.len());
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
            state.push(ContactLife {
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
        t = t1;
        steps.push(LifeStep {
            time: t,
            contacts: state,
        });
        observer(steps.last().expect("pushed"));
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
    }
    if t >= life.target && matches!(end, LifeEnd::StepLimit) {
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
        steps,
        time_to_criterion: tracks.iter().map(|c| c.criterion).collect(),
        time_to_criterion_fixed_gap: tracks.iter().map(|c| c.criterion_fixed).collect(),
        scars,
        end,
        windows,
        wall_time: start.elapsed().as_secs_f64(),
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
