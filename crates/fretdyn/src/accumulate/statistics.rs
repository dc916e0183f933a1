//! Statistics accumulated at every step (not only at output samples), THEORY §5: per-contact
//! wear, impact and force statistics over a time window `[t_start, t_end]` and in blocks
//! (batches, from which the standard errors of the window's rates are estimated by batch
//! means), and the table of impacts.
//!
//! A step `(t − Δt, t]` counts in the window (and in a block) when its midpoint `t − Δt/2` is
//! in it, so that bounds that are multiples of Δt split the steps exactly despite round-off. An **impact** starts when the contact closes after being open longer than the rest
//! duration, and ends at the last opening before such a rest: openings shorter than the rest
//! duration are **rebounds** within the impact. Its start and end times are interpolated
//! linearly between steps on the penetration's zero crossing; it belongs to the window when
//! the step in which it starts does (the same midpoint rule, not the interpolated start time:
//! an impact that starts on the window's first step, e.g. a contact closed from `t_start`
//! exactly, is counted once and has its row, its duration and its peak in the histogram like
//! any other). An impact under way when the window opens — a contact closed at the start of
//! the window's first step, a preload at t = 0 or the middle of an impact — starts there
//! ([`ContactStatisticsState::open_window`]). An impact still going on when the run ends is
//! ended there.
//!
//! One concept, kept whole: the window, the blocks, the impacts and the peak histogram are
//! accumulated from the same step values by one midpoint rule, in one state per contact (the
//! energy balance is apart, in [`crate::accumulate::energy`]).

use serde::{Deserialize, Serialize};

pub use crate::settings::statistics::{
    DEFAULT_BATCHES, DEFAULT_MAX_RELATIVE_ERROR, DEFAULT_TARGET_BATCHES, StatisticsSettings,
};
use crate::wear::WearWork;

/// One contact's values over one step, at its end.
#[derive(Debug, Clone, Copy, Default)]
pub struct StepValues {
    /// End time of the step, s.
    pub t: f64,
    /// Closed at the end of the step.
    pub closed: bool,
    /// Sticking (when closed).
    pub stick: bool,
    /// Normal force `R_N`, N.
    pub normal: f64,
    /// Tangential force magnitude `|R_T|`, N.
    pub tangential: f64,
    /// Slip speed `|v_T|` (full step, relative to the obstacle), m/s.
    pub slip_speed: f64,
    /// Friction power `|R_T·v_T|`, W.
    pub friction_power: f64,
    /// Penetration `δ` (negative: the remaining clearance), m.
    pub penetration: f64,
    /// Radial offset of the point from the hole's centre (holes), or its distance to the
    /// plane / the bars' mid-plane (planes), m.
    pub radial: f64,
    /// Direction of that offset in the hole's plane, `(cos θ, sin θ)` (`(1, 0)` for planes
    /// and at the centre): the angle `θ` is only formed (`atan2`) where it is reported.
    pub direction: [f64; 2],
}

/// One contact's step as [`ContactStatisticsState::step`] takes it: an open contact's offset
/// and penetration (its forces and slip are zero, its angle unused), or a closed contact's
/// values. Most contacts are open at most steps: they cost these two numbers.
#[derive(Debug, Clone, Copy)]
pub enum ContactStep {
    /// Open at the end of the step: [`StepValues::radial`] and [`StepValues::penetration`].
    Open {
        /// The offset ([`StepValues::radial`]), m.
        radial: f64,
        /// The penetration, negative ([`StepValues::penetration`]), m.
        penetration: f64,
    },
    /// Closed at the end of the step.
    Closed(StepValues),
}

impl From<StepValues> for ContactStep {
    fn from(v: StepValues) -> Self {
        if v.closed {
            ContactStep::Closed(v)
        } else {
            ContactStep::Open {
                radial: v.radial,
                penetration: v.penetration,
            }
        }
    }
}

impl StepValues {
    /// The values of an open contact at `t` (what [`ContactStep::Open`] stands for).
    fn open(t: f64, radial: f64, penetration: f64) -> Self {
        StepValues {
            t,
            closed: false,
            stick: true,
            normal: 0.0,
            tangential: 0.0,
            slip_speed: 0.0,
            friction_power: 0.0,
            penetration,
            radial,
            direction: [1.0, 0.0],
        }
    }
}

/// The angle `θ` of a direction `(cos θ, sin θ)` ([`StepValues::direction`]), degrees in
/// (−180, 180].
fn angle_deg(direction: [f64; 2]) -> f64 {
    direction[1].atan2(direction[0]).to_degrees()
}

/// A finished impact (per-impact table).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Impact {
    /// Index of the contact.
    pub contact: usize,
    /// Start (first closing, interpolated), s.
    pub start: f64,
    /// Duration from the first closing to the last opening, s.
    pub duration: f64,
    /// Time spent closed within it, s.
    pub contact_time: f64,
    /// Time of the peak normal force, s.
    pub peak_time: f64,
    /// Peak normal force, N.
    pub peak_force: f64,
    /// Normal impulse `∫R_N dt`, N·s.
    pub impulse: f64,
    /// Normal approach speed at the first closing, m/s: `(δ_{n+1} − δ_n)/Δt` over the step
    /// where it closes, the central-difference velocity `q̇_{n+½}`, on which no contact force
    /// has acted yet. For an impact under way when the statistics window opens (it starts
    /// there, [`ContactStatisticsState::open_window`]): the normal approach speed `δ̇` at the
    /// window's start, from the full-step velocity `q̇` there (at t = 0 the initial velocity;
    /// negative when the contact is opening).
    pub impact_speed: f64,
    /// Normal separation speed at the last opening, m/s: `(δ_n − δ_{n+1})/Δt` over the step
    /// where it opens.
    pub rebound_speed: f64,
    /// Rebounds (openings shorter than the rest duration) within the impact.
    pub rebounds: u32,
    /// Angle of the contact point in the hole's plane at the peak, degrees (0 for planes).
    pub angle_deg: f64,
}

/// Follows one contact's impacts.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
struct ImpactTracker {
    active: bool,
    open: bool,
    current: Option<Impact>,
    last_opening: f64,
    previous_penetration: f64,
    previous_t: f64,
    /// The current impact started in a step of the window: it is counted in the window's
    /// impacts, and its row and duration go to the window's table when it ends.
    in_window: bool,
    /// [`StepValues::direction`] at the current impact's peak: its angle
    /// ([`Impact::angle_deg`]) is formed when the impact ends ([`Self::end`]).
    peak_direction: [f64; 2],
}

impl ImpactTracker {
    /// [`Self::step`] of an open contact with no impact in progress (`active` false): it
    /// neither starts nor ends one, and only its penetration and time are kept for the next
    /// crossing.
    #[inline]
    fn idle(&mut self, t: f64, penetration: f64) {
        self.previous_penetration = penetration;
        self.previous_t = t;
    }

    /// Zero crossing of the penetration between the previous step and this one.
    fn crossing(&self, v: &StepValues) -> f64 {
        let (d0, d1) = (self.previous_penetration, v.penetration);
        if d0 != d1 && (d0 <= 0.0) != (d1 <= 0.0) {
            self.previous_t + (v.t - self.previous_t) * (d0 / (d0 - d1))
        } else {
            v.t
        }
    }

    /// One step, `in_window` when it counts in the window; returns `(started, finished
    /// impact)` (whether that impact started in the window is [`Self::in_window`]). The
    /// common step of a closed contact, within its impact and not reclosing, in line; the
    /// others by [`Self::step_in_general`].
    #[inline(always)]
    fn step(
        &mut self,
        contact: usize,
        v: &StepValues,
        rest: f64,
        in_window: bool,
    ) -> (bool, Option<Impact>) {
        if v.closed
            && self.active
            && !self.open
            && let Some(imp) = &mut self.current
        {
            let dt = v.t - self.previous_t;
            Self::add_closed(imp, &mut self.peak_direction, v, dt);
            self.previous_penetration = v.penetration;
            self.previous_t = v.t;
            return (false, None);
        }
        self.step_in_general(contact, v, rest, in_window)
    }

    /// A closed step of impact `imp` (of `dt`, its values `v`): its impulse, its contact
    /// time and its peak.
    #[inline(always)]
    fn add_closed(imp: &mut Impact, peak_direction: &mut [f64; 2], v: &StepValues, dt: f64) {
        imp.impulse += v.normal * dt;
        imp.contact_time += dt;
        if v.normal > imp.peak_force {
            imp.peak_force = v.normal;
            imp.peak_time = v.t;
            *peak_direction = v.direction;
        }
    }

    /// The current impact, ended: its angle at the peak formed.
    fn end(&mut self) -> Option<Impact> {
        self.current.take().map(|mut imp| {
            imp.angle_deg = angle_deg(self.peak_direction);
            imp
        })
    }

    /// [`Self::step`], every case.
    #[inline(never)]
    fn step_in_general(
        &mut self,
        contact: usize,
        v: &StepValues,
        rest: f64,
        in_window: bool,
    ) -> (bool, Option<Impact>) {
        let dt = v.t - self.previous_t;
        let mut started = false;
        let mut finished = None;
        if v.closed {
            match (&mut self.current, self.active) {
                (Some(imp), true) => {
                    if self.open {
                        imp.rebounds += 1;
                        self.open = false;
                    }
                }
                _ => {
                    started = true;
                    self.active = true;
                    self.open = false;
                    self.in_window = in_window;
                    self.current = Some(Impact {
                        contact,
                        start: self.crossing(v),
                        impact_speed: (v.penetration - self.previous_penetration) / dt,
                        duration: 0.0,
                        contact_time: 0.0,
                        peak_time: v.t,
                        peak_force: 0.0,
                        impulse: 0.0,
                        rebound_speed: 0.0,
                        rebounds: 0,
                        angle_deg: 0.0,
                    });
                    self.peak_direction = v.direction;
                }
            }
            if let Some(imp) = &mut self.current {
                Self::add_closed(imp, &mut self.peak_direction, v, dt);
            }
        } else if self.active {
            if !self.open {
                self.open = true;
                self.last_opening = self.crossing(v);
                if let Some(imp) = &mut self.current {
                    imp.rebound_speed = (self.previous_penetration - v.penetration) / dt;
                }
            }
            if v.t - self.last_opening > rest {
                self.active = false;
                self.open = false;
                if let Some(mut imp) = self.end() {
                    imp.duration = self.last_opening - imp.start;
                    finished = Some(imp);
                }
            }
        }
        self.previous_penetration = v.penetration;
        self.previous_t = v.t;
        (started, finished)
    }
}

/// Finished impacts kept per contact before the vector must grow.
const IMPACT_ROOM_PER_CONTACT: usize = 256;

/// Histogram of peak forces: 10 logarithmic bins per decade from 1 µN to 1 GN.
pub const PEAK_BINS_PER_DECADE: usize = 10;
const PEAK_MIN_DECADE: i32 = -6;
const PEAK_DECADES: usize = 15;

/// `min(m, x)` for a running minimum `m` that is never NaN (a NaN `x` is skipped):
/// [`crate::numerics::running_min`].
#[inline(always)]
fn smaller(m: f64, x: f64) -> f64 {
    crate::numerics::running_min(m, x)
}

/// `max(m, x)` for a running maximum `m` that is never NaN, as [`smaller`].
#[inline(always)]
fn larger(m: f64, x: f64) -> f64 {
    crate::numerics::running_max(m, x)
}

/// Running sums of one contact over a window or a block. The number of steps is the same for
/// every contact and is kept once, by [`ContactStatisticsState`]; the extrema start at ∓∞
/// (no value yet) and are reported as 0 when there was no step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactAccumulator {
    contact_steps: u64,
    stick_steps: u64,
    slip_steps: u64,
    impacts: u64,
    finished_impacts: u64,
    rebounds: u64,
    duration_sum: f64,
    duration_min: Option<f64>,
    duration_max: f64,
    normal_sum: f64,
    normal_sq_sum: f64,
    normal_max: f64,
    tangential_sum: f64,
    tangential_sq_sum: f64,
    tangential_max: f64,
    wear_work: f64,
    normal_wear_work: f64,
    penetration_max: f64,
    radial_sum: f64,
    radial_sq_sum: f64,
    radial_min: f64,
    radial_max: f64,
    /// Σ cos θ, Σ sin θ over the contact steps (circular mean of the contact angle).
    angle_cos: f64,
    angle_sin: f64,
    peak_histogram: Vec<u64>,
}

impl Default for ContactAccumulator {
    fn default() -> Self {
        Self::with_histogram(vec![0; PEAK_DECADES * PEAK_BINS_PER_DECADE])
    }
}

impl ContactAccumulator {
    /// Empty sums, with the histogram's room.
    pub fn new() -> Self {
        Self::default()
    }

    /// Empty sums with `peak_histogram` (all zero) as the histogram.
    fn with_histogram(peak_histogram: Vec<u64>) -> Self {
        Self {
            contact_steps: 0,
            stick_steps: 0,
            slip_steps: 0,
            impacts: 0,
            finished_impacts: 0,
            rebounds: 0,
            duration_sum: 0.0,
            duration_min: None,
            duration_max: 0.0,
            normal_sum: 0.0,
            normal_sq_sum: 0.0,
            normal_max: 0.0,
            tangential_sum: 0.0,
            tangential_sq_sum: 0.0,
            tangential_max: 0.0,
            wear_work: 0.0,
            normal_wear_work: 0.0,
            penetration_max: f64::NEG_INFINITY,
            radial_sum: 0.0,
            radial_sq_sum: 0.0,
            radial_min: f64::INFINITY,
            radial_max: f64::NEG_INFINITY,
            angle_cos: 0.0,
            angle_sin: 0.0,
            peak_histogram,
        }
    }

    /// Back to empty sums, keeping the room.
    fn reset(&mut self) {
        let mut histogram = std::mem::take(&mut self.peak_histogram);
        histogram.iter_mut().for_each(|c| *c = 0);
        *self = Self::with_histogram(histogram);
    }

    /// Adds one step (the caller counts it). An open contact's step only moves the offset's
    /// sums and extrema and the largest penetration; the values are finite (checked by the
    /// step), so that the extrema, started at `±∞`, take the first value exactly.
    #[inline]
    fn add_step(&mut self, v: &StepValues, dt: f64) {
        self.add_offset(v.radial, v.penetration);
        if v.closed {
            self.add_closed_step(v, dt);
        }
    }

    /// The sums of every step, open or closed: the offset's, and the largest penetration.
    #[inline(always)]
    fn add_offset(&mut self, radial: f64, penetration: f64) {
        self.radial_sum += radial;
        self.radial_sq_sum += radial * radial;
        self.radial_min = smaller(self.radial_min, radial);
        self.radial_max = larger(self.radial_max, radial);
        self.penetration_max = larger(self.penetration_max, penetration);
    }

    /// The sums of a closed step.
    #[inline]
    fn add_closed_step(&mut self, v: &StepValues, dt: f64) {
        self.contact_steps += 1;
        if v.stick {
            self.stick_steps += 1;
        } else {
            self.slip_steps += 1;
        }
        self.normal_sum += v.normal;
        self.normal_sq_sum += v.normal * v.normal;
        self.normal_max = larger(self.normal_max, v.normal);
        self.tangential_sum += v.tangential;
        self.tangential_sq_sum += v.tangential * v.tangential;
        self.tangential_max = larger(self.tangential_max, v.tangential);
        self.wear_work += v.friction_power * dt;
        self.normal_wear_work += v.normal * v.slip_speed * dt;
        self.angle_cos += v.direction[0];
        self.angle_sin += v.direction[1];
    }

    fn add_impact(&mut self, imp: &Impact) {
        self.finished_impacts += 1;
        self.rebounds += imp.rebounds as u64;
        self.duration_sum += imp.duration;
        self.duration_min = Some(
            self.duration_min
                .map_or(imp.duration, |m| m.min(imp.duration)),
        );
        self.duration_max = self.duration_max.max(imp.duration);
        let bins = self.peak_histogram.len();
        let x = (imp.peak_force.log10() - PEAK_MIN_DECADE as f64) * PEAK_BINS_PER_DECADE as f64;
        let bin = if x.is_finite() {
            (x.floor().max(0.0) as usize).min(bins - 1)
        } else {
            0
        };
        self.peak_histogram[bin] += 1;
    }

    /// Statistics over the `steps` steps added, each of duration `dt`, named `name`, with
    /// the histogram of peak forces (no errors: those come from the batches).
    pub fn finish(
        &self,
        steps: u64,
        name: &str,
        dt: f64,
        wear_coefficient: f64,
    ) -> ContactStatistics {
        let mut s = self.statistics(steps, dt, wear_coefficient);
        s.name = name.to_string();
        // sized first: the number of allocations does not depend on the data
        let mut histogram = Vec::with_capacity(
            self.peak_histogram
                .iter()
                .filter(|c| **c > 0)
                .count()
                .max(1),
        );
        histogram.extend(
            self.peak_histogram
                .iter()
                .enumerate()
                .filter(|(_, c)| **c > 0)
                .map(|(i, &c)| {
                    let lo = PEAK_MIN_DECADE as f64 + i as f64 / PEAK_BINS_PER_DECADE as f64;
                    PeakBin {
                        from: 10f64.powf(lo),
                        to: 10f64.powf(lo + 1.0 / PEAK_BINS_PER_DECADE as f64),
                        count: c,
                    }
                }),
        );
        s.peak_force_histogram = histogram;
        s
    }

    /// [`Self::finish`] without the name and the histogram: allocates nothing (a block's).
    fn statistics(&self, steps: u64, dt: f64, wear_coefficient: f64) -> ContactStatistics {
        let n = steps.max(1) as f64;
        let nc = self.contact_steps.max(1) as f64;
        let duration = steps as f64 * dt;
        let extremum = |x: f64| if steps > 0 { x } else { 0.0 };
        let rate = |x: f64| if duration > 0.0 { x / duration } else { 0.0 };
        let ni = self.finished_impacts.max(1) as f64;
        let (angle_mean, angle_spread) = if self.contact_steps > 0 {
            let (c, s) = (self.angle_cos / nc, self.angle_sin / nc);
            let r = c.hypot(s).min(1.0);
            (
                s.atan2(c).to_degrees(),
                (-2.0 * r.max(1e-300).ln()).sqrt().to_degrees(),
            )
        } else {
            (0.0, 0.0)
        };
        ContactStatistics {
            name: String::new(),
            duration,
            impacts: self.impacts,
            impacts_per_second: rate(self.impacts as f64),
            rebounds_per_impact: self.rebounds as f64 / ni,
            contact_duration_mean: self.duration_sum / ni,
            contact_duration_min: self.duration_min.unwrap_or(0.0),
            contact_duration_max: self.duration_max,
            contact_time_fraction: self.contact_steps as f64 / n,
            stick_time_fraction: self.stick_steps as f64 / n,
            slip_time_fraction: self.slip_steps as f64 / n,
            normal_force_mean: self.normal_sum / n,
            normal_force_mean_in_contact: self.normal_sum / nc,
            normal_force_rms: (self.normal_sq_sum / n).sqrt(),
            normal_force_max: self.normal_max,
            tangential_force_mean: self.tangential_sum / n,
            tangential_force_mean_in_contact: self.tangential_sum / nc,
            tangential_force_rms: (self.tangential_sq_sum / n).sqrt(),
            tangential_force_max: self.tangential_max,
            wear_work: self.wear_work,
            wear_work_rate: rate(self.wear_work),
            normal_wear_work_rate: rate(self.normal_wear_work),
            wear_volume: wear_coefficient * self.wear_work,
            penetration_max: extremum(self.penetration_max),
            displacement_mean: self.radial_sum / n,
            displacement_rms: (self.radial_sq_sum / n).sqrt(),
            displacement_min: extremum(self.radial_min),
            displacement_max: extremum(self.radial_max),
            contact_angle_mean_deg: angle_mean,
            contact_angle_spread_deg: angle_spread,
            peak_force_histogram: Vec::new(),
            errors: StandardErrors::default(),
        }
    }
}

/// A bin of the peak-force histogram: `count` impacts with `from ≤ peak < to` (N).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PeakBin {
    pub from: f64,
    pub to: f64,
    pub count: u64,
}

/// Per-contact statistics over a window or a block (THEORY §5). "Over the whole time" means
/// over every step of the window; "in contact" over its closed steps only.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactStatistics {
    /// Contact name.
    pub name: String,
    /// Duration covered, s.
    pub duration: f64,
    /// Impacts started (with no rest duration: open → closed transitions).
    pub impacts: u64,
    /// Impacts per second.
    pub impacts_per_second: f64,
    /// Mean rebounds per finished impact.
    pub rebounds_per_impact: f64,
    /// Mean / min / max duration of the finished impacts, s.
    pub contact_duration_mean: f64,
    pub contact_duration_min: f64,
    pub contact_duration_max: f64,
    /// Fraction of the time spent closed.
    pub contact_time_fraction: f64,
    /// Fraction of the time spent closed and sticking.
    pub stick_time_fraction: f64,
    /// Fraction of the time spent closed and sliding.
    pub slip_time_fraction: f64,
    /// Mean normal force over the whole time, N.
    pub normal_force_mean: f64,
    /// Mean normal force over the contact time, N.
    pub normal_force_mean_in_contact: f64,
    /// RMS normal force over the whole time, N.
    pub normal_force_rms: f64,
    /// Largest normal force, N.
    pub normal_force_max: f64,
    /// Mean tangential force magnitude over the whole time, N.
    pub tangential_force_mean: f64,
    /// Mean tangential force magnitude over the contact time, N.
    pub tangential_force_mean_in_contact: f64,
    /// RMS tangential force magnitude over the whole time, N.
    pub tangential_force_rms: f64,
    /// Largest tangential force magnitude, N.
    pub tangential_force_max: f64,
    /// Friction work `∫|R_T · v_T| dt`, J.
    pub wear_work: f64,
    /// Wear work rate `(1/T)∫|R_T · v_T| dt` (friction power), W.
    pub wear_work_rate: f64,
    /// Wear work rate with the normal force, `(1/T)∫R_N |v_T| dt` (Code_Aster's
    /// POST_DYNA_MODA_T definition), W.
    pub normal_wear_work_rate: f64,
    /// Wear volume `K_wear ∫|R_T·v_T| dt`, m³ (0 without a wear coefficient).
    pub wear_volume: f64,
    /// Largest penetration, m (negative: the contact never closed; the smallest clearance).
    pub penetration_max: f64,
    /// Mean / RMS / min / max of the point's radial offset from the hole's centre (holes) or
    /// of its distance to the plane / the bars' mid-plane (planes), m.
    pub displacement_mean: f64,
    pub displacement_rms: f64,
    pub displacement_min: f64,
    pub displacement_max: f64,
    /// Circular mean of the contact angle in the hole's plane over the contact time, degrees.
    pub contact_angle_mean_deg: f64,
    /// Circular standard deviation of that angle, degrees.
    pub contact_angle_spread_deg: f64,
    /// Histogram of the impacts' peak normal forces (non-empty bins).
    pub peak_force_histogram: Vec<PeakBin>,
    /// Standard errors by batch means (a window's; a block's are empty).
    #[serde(flatten)]
    pub errors: StandardErrors,
}

/// Statistics of one contact over one block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BlockStatistics {
    /// Block number (0 is the first block of the window).
    pub block: u64,
    /// Index of the contact.
    pub contact: usize,
    /// Start and end of the block, s.
    pub t_start: f64,
    pub t_end: f64,
    /// The statistics (without the histogram).
    pub statistics: ContactStatistics,
}

/// Statistics whose standard error is estimated by batch means (THEORY §5), in the order of
/// [`StandardErrors`]' fields. The two rms values are estimated through the mean squares.
pub const BATCHED_STATISTICS: [&str; BATCHED] = [
    "wear_work_rate",
    "normal_wear_work_rate",
    "impacts_per_second",
    "contact_time_fraction",
    "stick_time_fraction",
    "slip_time_fraction",
    "normal_force_mean",
    "normal_force_rms",
    "tangential_force_mean",
    "tangential_force_rms",
];
const BATCHED: usize = 10;
/// Index in [`BATCHED_STATISTICS`] of the mean squares (their rms is reported).
const MEAN_SQUARES: [usize; 2] = [7, 9];

/// Batches needed before a target relative error is checked (fewer give too noisy an SE).
pub const MIN_TARGET_BATCHES: u64 = 20;
/// A contact holds a run with a target while its wear work rate is at least this fraction
/// of the largest contact's (one that barely wears is reported, with its error, but does not
/// make the run go on).
pub const TARGET_WEAR_SHARE: f64 = 0.01;

/// Standard errors of a window's statistics by batch means (THEORY §5): the window is cut
/// into `batches` batches of `batch_length`, the statistic `x_b` of each batch is formed, and
/// `SE(x̄) = √(Σ(x_b − x̄)² / (n_b (n_b − 1)))`, valid when the batches are longer than the
/// correlation time of the response (then the `x_b` are independent). For an rms,
/// `SE(rms) = SE(mean square) / (2 rms)`. `None` (left out of `summary.json`) with fewer
/// than 2 batches. A last, partial batch (a run stopped early) is left out.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct StandardErrors {
    /// Whole batches the errors are formed from.
    pub batches: u64,
    /// Duration of a batch, s.
    pub batch_length: f64,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub wear_work_rate_se: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub normal_wear_work_rate_se: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub impacts_per_second_se: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub contact_time_fraction_se: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub stick_time_fraction_se: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub slip_time_fraction_se: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub normal_force_mean_se: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub normal_force_rms_se: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub tangential_force_mean_se: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub tangential_force_rms_se: Option<f64>,
    /// Lag-1 autocorrelation `r₁` of the batch means of the wear work rate (of the impact
    /// rate, the contact time fraction or the mean normal force when it does not vary).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub batch_autocorrelation: Option<f64>,
    /// `r₁ > 2/√n_b`: the batches are too short against the correlation time (independent
    /// batch means give `r₁ ≈ 0 ± 1/√n_b`) and the errors are underestimated by about
    /// `√((1 + r₁)/(1 − r₁))`; use longer batches (`[statistics] block`) or a longer run.
    pub batches_correlated: bool,
}

impl StandardErrors {
    /// The standard errors in the order of [`BATCHED_STATISTICS`].
    pub fn values(&self) -> [Option<f64>; BATCHED] {
        [
            self.wear_work_rate_se,
            self.normal_wear_work_rate_se,
            self.impacts_per_second_se,
            self.contact_time_fraction_se,
            self.stick_time_fraction_se,
            self.slip_time_fraction_se,
            self.normal_force_mean_se,
            self.normal_force_rms_se,
            self.tangential_force_mean_se,
            self.tangential_force_rms_se,
        ]
    }
}

impl ContactStatistics {
    /// `(name, value, standard error)` of the statistics of [`BATCHED_STATISTICS`].
    pub fn batched(&self) -> [(&'static str, f64, Option<f64>); BATCHED] {
        let values = [
            self.wear_work_rate,
            self.normal_wear_work_rate,
            self.impacts_per_second,
            self.contact_time_fraction,
            self.stick_time_fraction,
            self.slip_time_fraction,
            self.normal_force_mean,
            self.normal_force_rms,
            self.tangential_force_mean,
            self.tangential_force_rms,
        ];
        let se = self.errors.values();
        std::array::from_fn(|i| (BATCHED_STATISTICS[i], values[i], se[i]))
    }

    /// The statistics of [`BATCHED_STATISTICS`] whose relative standard error `SE/|x|`
    /// exceeds `threshold`, with it (a statistic that is 0 has none). The split of the
    /// contact time into stick and slip is left out: its smaller part is often a few steps
    /// per batch, noisy, and of no consequence for the wear (its error is reported).
    pub fn relative_errors_above(&self, threshold: f64) -> Vec<(&'static str, f64)> {
        self.batched()
            .into_iter()
            .filter(|(name, _, _)| !matches!(*name, "stick_time_fraction" | "slip_time_fraction"))
            .filter_map(|(name, x, se)| {
                let r = se? / x.abs();
                (x != 0.0 && r > threshold).then_some((name, r))
            })
            .collect()
    }
}

/// Running sums over the batch means of one contact, shifted by the first batch's so that
/// `Σ(x_b − x̄)²` does not cancel: `d_b = x_b − x_1`, `Σd_b`, `Σd_b²`, `Σd_b d_{b−1}`, and the
/// last `d_b`. Fixed size: a run of any length keeps the same room.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
struct BatchMoments {
    n: u64,
    shift: [f64; BATCHED],
    sum: [f64; BATCHED],
    squares: [f64; BATCHED],
    lag: [f64; BATCHED],
    last: [f64; BATCHED],
}

impl BatchMoments {
    fn add(&mut self, x: &[f64; BATCHED]) {
        if self.n == 0 {
            self.shift = *x;
        }
        for i in 0..BATCHED {
            let d = x[i] - self.shift[i];
            self.sum[i] += d;
            self.squares[i] += d * d;
            self.lag[i] += d * self.last[i];
            self.last[i] = d;
        }
        self.n += 1;
    }

    /// Mean of the batch means, `Σ(x_b − x̄)²` and `Σ(x_b − x̄)(x_{b−1} − x̄)`.
    fn moments(&self, i: usize) -> (f64, f64, f64) {
        let n = self.n as f64;
        let m = self.sum[i] / n;
        let ss = (self.squares[i] - n * m * m).max(0.0);
        // d_1 = 0 by the shift
        let lag = self.lag[i] - m * (2.0 * self.sum[i] - self.last[i]) + (n - 1.0) * m * m;
        (self.shift[i] + m, ss, lag)
    }

    /// Standard error of the mean of statistic `i`, `√(Σ(x_b − x̄)²/(n(n−1)))`.
    fn se(&self, i: usize) -> Option<f64> {
        (self.n >= 2).then(|| {
            let n = self.n as f64;
            (self.moments(i).1 / (n * (n - 1.0))).sqrt()
        })
    }

    /// The errors of the window's statistics `s`.
    fn errors(&self, s: &ContactStatistics, batch_length: f64) -> StandardErrors {
        let mut se: [Option<f64>; BATCHED] = std::array::from_fn(|i| self.se(i));
        for (i, rms) in MEAN_SQUARES
            .into_iter()
            .zip([s.normal_force_rms, s.tangential_force_rms])
        {
            se[i] = se[i].map(|e| if rms > 0.0 { e / (2.0 * rms) } else { 0.0 });
        }
        // a statistic varies when its spread is above the round-off of its mean
        let n = self.n as f64;
        let headline = [0, 2, 3, 6]
            .into_iter()
            .map(|i| self.moments(i))
            .find(|(m, ss, _)| *ss > n * (1e-12 * m).powi(2) && *ss > f64::MIN_POSITIVE);
        let r1 = (self.n >= 3)
            .then_some(headline)
            .flatten()
            .map(|(_, ss, lag)| (lag / ss).clamp(-1.0, 1.0))
            .filter(|r| r.is_finite());
        StandardErrors {
            batches: self.n,
            // a window without a step has no batch
            batch_length: if batch_length.is_finite() {
                batch_length
            } else {
                0.0
            },
            wear_work_rate_se: se[0],
            normal_wear_work_rate_se: se[1],
            impacts_per_second_se: se[2],
            contact_time_fraction_se: se[3],
            stick_time_fraction_se: se[4],
            slip_time_fraction_se: se[5],
            normal_force_mean_se: se[6],
            normal_force_rms_se: se[7],
            tangential_force_mean_se: se[8],
            tangential_force_rms_se: se[9],
            batch_autocorrelation: r1,
            batches_correlated: r1.is_some_and(|r| r > 2.0 / (self.n as f64).sqrt()),
        }
    }
}

impl ContactAccumulator {
    /// The batch means of [`BATCHED_STATISTICS`] over `steps` steps of `dt` (mean squares
    /// for the rms).
    fn batch_values(&self, steps: u64, dt: f64) -> [f64; BATCHED] {
        let n = steps.max(1) as f64;
        let duration = n * dt;
        [
            self.wear_work / duration,
            self.normal_wear_work / duration,
            self.impacts as f64 / duration,
            self.contact_steps as f64 / n,
            self.stick_steps as f64 / n,
            self.slip_steps as f64 / n,
            self.normal_sum / n,
            self.normal_sq_sum / n,
            self.tangential_sum / n,
            self.tangential_sq_sum / n,
        ]
    }

    /// Adds the sums of `other` (a block closed) to these (the window's): counts and
    /// extrema exactly, the `f64` sums as one more addition (a sum over the window is then a
    /// sum of block sums: equal to the step-by-step sum to round-off, THEORY §5).
    fn merge(&mut self, other: &Self) {
        self.contact_steps += other.contact_steps;
        self.stick_steps += other.stick_steps;
        self.slip_steps += other.slip_steps;
        self.impacts += other.impacts;
        self.finished_impacts += other.finished_impacts;
        self.rebounds += other.rebounds;
        self.duration_sum += other.duration_sum;
        self.duration_min = match (self.duration_min, other.duration_min) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        self.duration_max = self.duration_max.max(other.duration_max);
        self.normal_sum += other.normal_sum;
        self.normal_sq_sum += other.normal_sq_sum;
        self.normal_max = self.normal_max.max(other.normal_max);
        self.tangential_sum += other.tangential_sum;
        self.tangential_sq_sum += other.tangential_sq_sum;
        self.tangential_max = self.tangential_max.max(other.tangential_max);
        self.wear_work += other.wear_work;
        self.normal_wear_work += other.normal_wear_work;
        self.penetration_max = larger(self.penetration_max, other.penetration_max);
        self.radial_sum += other.radial_sum;
        self.radial_sq_sum += other.radial_sq_sum;
        self.radial_min = smaller(self.radial_min, other.radial_min);
        self.radial_max = larger(self.radial_max, other.radial_max);
        self.angle_cos += other.angle_cos;
        self.angle_sin += other.angle_sin;
        for (a, b) in self.peak_histogram.iter_mut().zip(&other.peak_histogram) {
            *a += b;
        }
    }
}

/// Everything the statistics keep for the contacts of a run: block and window accumulators,
/// batch means, impact trackers; finished impacts and blocks wait in [`Self::impacts`] and
/// [`Self::blocks`] until drained by the caller (a streaming run drains them at each flush,
/// so that memory stays flat).
///
/// The window is always cut into blocks (batches, THEORY §5): of `[statistics] block` s, or
/// else [`DEFAULT_BATCHES`] of the window ([`DEFAULT_TARGET_BATCHES`] of the longest window
/// with a target relative error). A step is added to the block's sums only; when the block
/// closes (at the step whose successor's midpoint is in the next block), its sums are added
/// to the window's, its batch means to the batch moments and its row to [`Self::blocks`]
/// (room reserved beforehand: closing a block does not allocate).
///
/// Cost per step: an open contact with no impact in progress adds its offset and penetration
/// to the block and keeps its penetration for the next crossing; the steps are counted once
/// for all contacts, and one comparison of `t` tells whether the block may close (its index is
/// computed only in the last two steps of a block).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactStatisticsState {
    /// Duration of a block, s (`∞`: one block, the window).
    block_length: f64,
    /// Relative standard error at which the run stops.
    target: Option<f64>,
    window: Vec<ContactAccumulator>,
    /// Steps in the closed blocks (the same for every contact).
    window_steps: u64,
    /// The block in progress, one per contact.
    block: Vec<ContactAccumulator>,
    /// Steps in the current block so far.
    block_steps: u64,
    block_index: u64,
    /// No step ending before this closes the current block (so that the block of the next
    /// step is only computed near the block's end).
    close_from: f64,
    batches: Vec<BatchMoments>,
    /// End of the step at which the target relative error was met.
    target_met: Option<f64>,
    trackers: Vec<ImpactTracker>,
    /// Finished impacts started in the window, not yet drained.
    pub impacts: Vec<Impact>,
    /// Finished blocks, block by block, contact by contact, not yet drained; their names are
    /// empty (the contact is [`BlockStatistics::contact`]) until [`name_blocks`].
    pub blocks: Vec<BlockStatistics>,
}

/// Gives the rows of `blocks` the names of their contacts (a row is formed in the step loop
/// without its name, which would allocate).
pub fn name_blocks(blocks: &mut [BlockStatistics], names: &[String]) {
    for b in blocks {
        if let Some(name) = names.get(b.contact) {
            b.statistics.name.clone_from(name);
        }
    }
}

/// Most block rows reserved before the run (beyond, a streamed run's drain makes room).
const BLOCK_ROOM: u64 = 4096;

impl ContactStatisticsState {
    /// Empty statistics for `contacts` contacts, for a run of `steps` steps of `dt`.
    pub fn new(contacts: usize, settings: &StatisticsSettings, steps: u64, dt: f64) -> Self {
        let block_length = settings.block_length(steps, dt);
        let blocks = (settings.window_steps(steps, dt) as f64 * dt / block_length).ceil();
        let rows = (blocks.min(BLOCK_ROOM as f64) as usize + 2) * contacts;
        let mut state = Self {
            block_length,
            target: settings.target_relative_error,
            window: vec![ContactAccumulator::new(); contacts],
            window_steps: 0,
            block: vec![ContactAccumulator::new(); contacts],
            block_steps: 0,
            block_index: 0,
            batches: vec![BatchMoments::default(); contacts],
            target_met: None,
            trackers: vec![ImpactTracker::default(); contacts],
            // room for the impacts that end between two drains: the step loop does not
            // allocate unless more wait (then the room grows once and is kept)
            impacts: Vec::with_capacity(IMPACT_ROOM_PER_CONTACT * contacts),
            blocks: Vec::with_capacity(rows),
            close_from: 0.0,
        };
        state.close_from = state.close_from_for(settings, dt);
        state
    }

    /// Two steps before the end of the current block (round-off cannot close it sooner).
    fn close_from_for(&self, settings: &StatisticsSettings, dt: f64) -> f64 {
        settings.t_start + (self.block_index + 1) as f64 * self.block_length - 2.0 * dt
    }

    /// True when it follows `n` contacts.
    pub fn has_contacts(&self, n: usize) -> bool {
        self.window.len() == n
            && self.block.len() == n
            && self.batches.len() == n
            && self.trackers.len() == n
    }

    /// Duration of a block (batch), s.
    pub fn block_length(&self) -> f64 {
        self.block_length
    }

    /// End time of the step at which the target relative error was met, if it was.
    pub fn target_met(&self) -> Option<f64> {
        self.target_met
    }

    /// Starts the trackers at t = 0 with the contacts' penetrations.
    pub fn start(&mut self, penetrations: impl Iterator<Item = (f64, bool)>) {
        for (tr, (d, closed)) in self.trackers.iter_mut().zip(penetrations) {
            tr.previous_penetration = d;
            tr.previous_t = 0.0;
            // a contact closed at t = 0 is in an impact that started before the run
            tr.active = closed;
        }
    }

    /// Opens the window at `t`, the end of the last step before it (the start of its first
    /// step: `t_start` to within `Δt/2`, exactly when `t_start` is a multiple of `Δt`).
    /// An impact under way there — its contact closed at `t`, from an impact that started
    /// before the window, or closed at t = 0 — **starts at `t`** (THEORY §11): it is counted
    /// in the window, and its row has its start `t`, its duration, contact time, impulse,
    /// peak and rebounds from `t` on, and as impact speed `speeds[k]`, the contact's normal
    /// approach speed at `t`. One in a rebound opening at `t` ends there, out of the window:
    /// its closing within the rest duration, if any, starts an impact in the window.
    /// Called once, at `t` (by the time loop; at t = 0 after [`Self::start`]).
    pub fn open_window(&mut self, t: f64, speeds: impl Iterator<Item = f64>) {
        for (k, ((tracker, block), speed)) in self
            .trackers
            .iter_mut()
            .zip(&mut self.block)
            .zip(speeds)
            .enumerate()
        {
            if !tracker.active {
                continue;
            }
            if tracker.open {
                tracker.active = false;
                tracker.open = false;
                tracker.current = None;
                continue;
            }
            tracker.current = Some(Impact {
                contact: k,
                start: t,
                duration: 0.0,
                contact_time: 0.0,
                peak_time: t,
                peak_force: 0.0,
                impulse: 0.0,
                impact_speed: speed,
                rebound_speed: 0.0,
                rebounds: 0,
                angle_deg: 0.0,
            });
            tracker.peak_direction = [1.0, 0.0];
            tracker.in_window = true;
            block.impacts += 1;
        }
    }

    /// Adds one step: `values[k]` for contact k, the step ending at `t`.
    #[inline]
    pub fn step(
        &mut self,
        settings: &StatisticsSettings,
        t: f64,
        dt: f64,
        values: impl Iterator<Item = ContactStep>,
    ) {
        let in_window = settings.step_in_window(t, dt);
        self.block_steps += in_window as u64;
        let rest = settings.rest_duration;
        let Self {
            block,
            trackers,
            impacts,
            ..
        } = self;
        for (k, ((input, tracker), block)) in values.zip(trackers.iter_mut()).zip(block).enumerate()
        {
            // the sums and the impacts' counts are apart: their order does not matter
            match input {
                ContactStep::Open {
                    radial,
                    penetration,
                } => {
                    if in_window {
                        block.add_offset(radial, penetration);
                    }
                    if tracker.active {
                        let v = StepValues::open(t, radial, penetration);
                        impact_step(k, v, rest, in_window, tracker, block, impacts);
                    } else {
                        tracker.idle(t, penetration);
                    }
                }
                ContactStep::Closed(v) => {
                    if in_window {
                        block.add_step(&v, dt);
                    }
                    impact_step(k, v, rest, in_window, tracker, block, impacts);
                }
            }
        }
        if in_window && t >= self.close_from {
            // the block closes when the next step's midpoint is in a later one
            let next = settings.block_of(t + dt, dt, self.block_length);
            if next > self.block_index {
                self.close_block(settings, dt, true, t);
                self.block_index = next;
                self.close_from = self.close_from_for(settings, dt);
            }
        }
    }

    /// Closes the block in progress: its row, its batch means when `whole`, its sums into
    /// the window's; at the end of a whole block (`t`), the target is checked.
    fn close_block(&mut self, settings: &StatisticsSettings, dt: f64, whole: bool, t: f64) {
        let b = self.block_length;
        let t0 = settings.t_start + self.block_index as f64 * b;
        let t1 = if whole {
            t0 + b
        } else {
            t0 + self.block_steps as f64 * dt
        };
        let steps = self.block_steps;
        for (k, ((acc, window), batches)) in self
            .block
            .iter_mut()
            .zip(&mut self.window)
            .zip(&mut self.batches)
            .enumerate()
        {
            self.blocks.push(BlockStatistics {
                block: self.block_index,
                contact: k,
                t_start: t0,
                t_end: t1,
                statistics: acc.statistics(steps, dt, settings.wear_coefficient),
            });
            if whole {
                batches.add(&acc.batch_values(steps, dt));
            }
            window.merge(acc);
            acc.reset();
        }
        self.window_steps += steps;
        self.block_steps = 0;
        if whole
            && t.is_finite()
            && self.target_met.is_none()
            && let Some(target) = self.target
            && self.target_reached(target)
        {
            self.target_met = Some(t);
        }
    }

    /// Every contact that wears (its wear work rate at least [`TARGET_WEAR_SHARE`] of the
    /// largest) has a relative standard error of its wear work rate `SE/x̄ ≤ target`, over
    /// at least [`MIN_TARGET_BATCHES`] batches.
    fn target_reached(&self, target: f64) -> bool {
        let mut largest = 0.0f64;
        for m in &self.batches {
            if m.n < MIN_TARGET_BATCHES {
                return false;
            }
            largest = largest.max(m.moments(0).0);
        }
        largest > 0.0
            && self.batches.iter().all(|m| {
                let mean = m.moments(0).0;
                mean < TARGET_WEAR_SHARE * largest || m.se(0).is_some_and(|se| se <= target * mean)
            })
    }

    /// Window statistics of every contact. An impact still in progress ends with the run (at
    /// its last opening, or at the last step if closed); a last block that has steps is
    /// closed (a partial one, shorter than a block by more than a step, has its row but is
    /// not a batch).
    pub fn finish(
        &mut self,
        settings: &StatisticsSettings,
        names: &[String],
        dt: f64,
    ) -> Vec<ContactStatistics> {
        for (k, tr) in self.trackers.iter_mut().enumerate() {
            if let Some(mut imp) = tr.end() {
                let end = if tr.open {
                    tr.last_opening
                } else {
                    tr.previous_t
                };
                imp.duration = end - imp.start;
                tr.active = false;
                if tr.in_window {
                    self.block[k].add_impact(&imp);
                    self.impacts.push(imp);
                }
            }
        }
        if self.block_steps > 0 {
            let whole = self.block_steps as f64 + 1.0 >= self.block_length / dt;
            let t = f64::NAN;
            self.close_block(settings, dt, whole, t);
        } else {
            // impacts that ended after the window's last block
            for (window, acc) in self.window.iter_mut().zip(&mut self.block) {
                window.merge(acc);
                acc.reset();
            }
        }
        self.window
            .iter()
            .zip(&self.batches)
            .zip(names)
            .map(|((a, batches), name)| {
                let mut s = a.finish(self.window_steps, name, dt, settings.wear_coefficient);
                s.errors = batches.errors(&s, self.block_length);
                s
            })
            .collect()
    }
}

/// The step of contact `k` when it is closed or in an impact (its tracker active): the
/// tracker's step, then an impact that starts in a step of the window counts in the block,
/// and one that ends, having started in the window, is added to it and to the table.
#[inline(always)]
fn impact_step(
    k: usize,
    v: StepValues,
    rest: f64,
    in_window: bool,
    tracker: &mut ImpactTracker,
    block: &mut ContactAccumulator,
    impacts: &mut Vec<Impact>,
) {
    let (started, finished) = tracker.step(k, &v, rest, in_window);
    if in_window && started {
        block.impacts += 1;
    }
    if let Some(imp) = finished
        && tracker.in_window
    {
        block.add_impact(&imp);
        impacts.push(imp);
    }
}

/// Which rate of these statistics a contact's wear laws take: here, not in [`crate::wear`],
/// because the wear laws sit below the statistics.
impl WearWork {
    /// The rate of a contact's statistics this work is.
    pub fn rate(self, statistics: &ContactStatistics) -> f64 {
        match self {
            WearWork::Friction => statistics.wear_work_rate,
            WearWork::Normal => statistics.normal_wear_work_rate,
        }
    }

    /// Its standard error by batch means (THEORY §11), when there are batches.
    pub fn rate_se(self, statistics: &ContactStatistics) -> Option<f64> {
        match self {
            WearWork::Friction => statistics.errors.wear_work_rate_se,
            WearWork::Normal => statistics.errors.normal_wear_work_rate_se,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 1e-3;
    const STEPS: u64 = 1000;

    /// Values of contact `k` at the end of step `n`: a penetration that oscillates through
    /// zero at a few frequencies (impacts, rebounds and long openings), forces of a closed
    /// contact only, an offset of both signs, and the first contact open all along.
    fn values(k: usize, n: u64) -> StepValues {
        let t = n as f64 * DT;
        let phase = k as f64;
        let penetration = if k == 0 {
            -1e-3 - 1e-4 * (7.0 * t).sin()
        } else {
            1e-4 * ((40.0 + 13.0 * phase) * t + phase).sin() - 4e-5 * (170.0 * t).cos()
        };
        let closed = penetration > 0.0;
        let normal = if closed { 1e6 * penetration } else { 0.0 };
        let angle = 3.0 * t + phase;
        StepValues {
            t,
            closed,
            stick: closed && (90.0 * t).sin() > 0.0,
            normal,
            tangential: 0.3 * normal,
            slip_speed: if closed { 1e-3 * (1.0 + t) } else { 0.0 },
            friction_power: if closed { 0.3 * normal * 1e-3 } else { 0.0 },
            penetration,
            radial: 2e-4 * (11.0 * t + phase).sin() + penetration,
            direction: [angle.cos(), angle.sin()],
        }
    }

    const CONTACTS: usize = 3;

    fn names() -> Vec<String> {
        (0..CONTACTS).map(|k| format!("c{k}")).collect()
    }

    /// Steps `from + 1 ..= to` of the synthetic run.
    fn advance(
        state: &mut ContactStatisticsState,
        settings: &StatisticsSettings,
        from: u64,
        to: u64,
    ) {
        for n in from + 1..=to {
            let t = n as f64 * DT;
            state.step(settings, t, DT, (0..CONTACTS).map(|k| values(k, n).into()));
        }
    }

    fn started(settings: &StatisticsSettings) -> ContactStatisticsState {
        let mut state = ContactStatisticsState::new(CONTACTS, settings, STEPS, DT);
        state.start((0..CONTACTS).map(|k| {
            let v = values(k, 0);
            (v.penetration, v.closed)
        }));
        state
    }

    /// Window statistics, impacts and blocks of the whole synthetic run.
    fn run(
        settings: &StatisticsSettings,
    ) -> (Vec<ContactStatistics>, Vec<Impact>, Vec<BlockStatistics>) {
        let mut state = started(settings);
        advance(&mut state, settings, 0, STEPS);
        let window = state.finish(settings, &names(), DT);
        (window, state.impacts, state.blocks)
    }

    fn settings(block: Option<f64>) -> StatisticsSettings {
        StatisticsSettings {
            t_start: 0.1,
            t_end: 0.85,
            block,
            rest_duration: 2e-3,
            wear_coefficient: 1e-15,
            ..Default::default()
        }
    }

    /// The window's statistics do not depend on how it is cut into blocks: counts and
    /// extrema exactly, the sums to round-off (a window sum is a sum of block sums), against
    /// sums formed here step by step from the values; the impacts are the same.
    #[test]
    fn blocks_do_not_change_the_window() {
        let s = settings(None);
        let (window, impacts, blocks) = run(&s);
        assert_eq!(
            blocks.len(),
            20 * CONTACTS,
            "20 batches of the window by default"
        );
        for b in [Some(0.07), Some(0.013), Some(1.0)] {
            let (window_b, impacts_b, _) = run(&settings(b));
            assert_eq!(impacts, impacts_b);
            for (w, wb) in window.iter().zip(&window_b) {
                assert_eq!(
                    (w.impacts, w.contact_time_fraction, w.stick_time_fraction),
                    (wb.impacts, wb.contact_time_fraction, wb.stick_time_fraction)
                );
                assert_eq!(
                    (w.normal_force_max, w.displacement_min, w.displacement_max),
                    (
                        wb.normal_force_max,
                        wb.displacement_min,
                        wb.displacement_max
                    )
                );
                assert_eq!(w.peak_force_histogram, wb.peak_force_histogram);
            }
        }
        for (k, w) in window.iter().enumerate() {
            let steps: Vec<_> = (1..=STEPS)
                .filter(|&n| s.step_in_window(n as f64 * DT, DT))
                .map(|n| values(k, n))
                .collect();
            let n = steps.len() as f64;
            let sum = |f: fn(&StepValues) -> f64| steps.iter().map(f).sum::<f64>();
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * b.abs().max(1e-300);
            let closed =
                |f: fn(&StepValues) -> f64| steps.iter().filter(|v| v.closed).map(f).sum::<f64>();
            assert!(close(w.normal_force_mean, closed(|v| v.normal) / n));
            assert!(close(
                w.normal_force_rms,
                (closed(|v| v.normal * v.normal) / n).sqrt()
            ));
            assert!(close(
                w.wear_work_rate,
                closed(|v| v.friction_power) * DT / (n * DT)
            ));
            assert!(close(w.displacement_mean, sum(|v| v.radial) / n));
            assert!(k == 0 || w.normal_force_mean > 0.0);
        }
        let state = ContactStatisticsState::new(CONTACTS, &settings(None), STEPS, DT);
        assert_eq!(state.block.len(), CONTACTS);
        assert!(state.has_contacts(CONTACTS) && !state.has_contacts(CONTACTS + 1));
        assert!((state.block_length() - 0.75 / 20.0).abs() < 1e-15);
    }

    /// The standard errors and the lag-1 autocorrelation formed from running shifted sums
    /// are those of the block rows formed directly (two-pass).
    #[test]
    fn errors_are_those_of_the_block_means() {
        for b in [None, Some(0.07), Some(0.013)] {
            let (window, _, blocks) = run(&settings(b));
            for (k, w) in window.iter().enumerate().skip(1) {
                // whole blocks only: the last 0.07-s block of the 0.75-s window is partial
                let length = blocks[0].t_end - blocks[0].t_start;
                let rows: Vec<_> = blocks
                    .iter()
                    .filter(|r| r.contact == k && r.t_end - r.t_start > length - 1.5 * DT)
                    .map(|r| &r.statistics)
                    .collect();
                assert_eq!(w.errors.batches, rows.len() as u64);
                let n = rows.len() as f64;
                let x: Vec<f64> = rows.iter().map(|r| r.wear_work_rate).collect();
                let m = x.iter().sum::<f64>() / n;
                let ss = x.iter().map(|x| (x - m).powi(2)).sum::<f64>();
                let se = (ss / (n * (n - 1.0))).sqrt();
                let r1 = x.windows(2).map(|p| (p[0] - m) * (p[1] - m)).sum::<f64>() / ss;
                let got = w.errors.wear_work_rate_se.unwrap();
                assert!((got - se).abs() <= 1e-9 * se, "{got} {se}");
                let r = w.errors.batch_autocorrelation.unwrap();
                assert!((r - r1).abs() <= 1e-9, "{r} {r1}");
                assert_eq!(w.errors.batches_correlated, r1 > 2.0 / n.sqrt());
                // the rms through the mean square: SE(rms) = SE(ms)/(2 rms)
                let ms: Vec<f64> = rows.iter().map(|r| r.normal_force_rms.powi(2)).collect();
                let mm = ms.iter().sum::<f64>() / n;
                let se_ms =
                    (ms.iter().map(|x| (x - mm).powi(2)).sum::<f64>() / (n * (n - 1.0))).sqrt();
                let got = w.errors.normal_force_rms_se.unwrap();
                let expected = se_ms / (2.0 * w.normal_force_rms);
                assert!((got - expected).abs() <= 1e-9 * expected);
            }
        }
    }

    /// The blocks add up to the window: their steps, their impacts started; their extrema
    /// are the window's.
    #[test]
    fn blocks_add_up_to_the_window() {
        let (window, _, blocks) = run(&settings(Some(0.07)));
        for (k, w) in window.iter().enumerate() {
            let rows: Vec<_> = blocks
                .iter()
                .filter(|b| b.contact == k)
                .map(|b| &b.statistics)
                .collect();
            assert_eq!(rows.len(), 11, "contact {k}: 0.75 s in blocks of 0.07 s");
            let steps = |d: f64| (d / DT).round() as u64;
            assert_eq!(
                rows.iter().map(|s| steps(s.duration)).sum::<u64>(),
                steps(w.duration)
            );
            assert_eq!(rows.iter().map(|s| s.impacts).sum::<u64>(), w.impacts);
            let fold = |f: fn(&ContactStatistics) -> f64, max: bool| {
                rows.iter().map(|s| f(s)).fold(
                    if max {
                        f64::NEG_INFINITY
                    } else {
                        f64::INFINITY
                    },
                    if max { f64::max } else { f64::min },
                )
            };
            assert_eq!(fold(|s| s.displacement_max, true), w.displacement_max);
            assert_eq!(fold(|s| s.displacement_min, false), w.displacement_min);
            assert_eq!(fold(|s| s.penetration_max, true), w.penetration_max);
            assert_eq!(fold(|s| s.normal_force_max, true), w.normal_force_max);
        }
    }

    /// An impact's peak is its largest normal force over its closed steps, and its angle the
    /// direction's at that step (formed when the impact ends), for every impact of the run,
    /// those ended by the run's end included.
    #[test]
    fn an_impact_peaks_at_its_largest_force_with_the_angle_of_that_step() {
        let s = settings(None);
        let (_, impacts, _) = run(&s);
        assert!(impacts.len() > 10, "{} impacts", impacts.len());
        for imp in &impacts {
            let first = ((imp.start / DT).ceil() as u64).max(1);
            let last = ((imp.start + imp.duration) / DT).floor() as u64;
            let peak = (first..=last.min(STEPS))
                .map(|n| values(imp.contact, n))
                .filter(|v| v.closed)
                .reduce(|a, b| if b.normal > a.normal { b } else { a })
                .expect("an impact has a closed step");
            assert_eq!(imp.peak_force, peak.normal);
            assert_eq!(imp.peak_time, peak.t);
            let expected = peak.direction[1].atan2(peak.direction[0]).to_degrees();
            assert_eq!(imp.angle_deg.to_bits(), expected.to_bits(), "{imp:?}");
        }
    }

    /// The window's extrema are those of the values of its steps (by the midpoint rule), and
    /// 0 for a window with no step.
    #[test]
    fn extrema_are_those_of_the_window_steps() {
        let s = settings(None);
        let (window, _, _) = run(&s);
        for (k, w) in window.iter().enumerate() {
            let steps: Vec<_> = (1..=STEPS)
                .filter(|&n| s.step_in_window(n as f64 * DT, DT))
                .map(|n| values(k, n))
                .collect();
            assert_eq!(steps.len(), 750);
            assert_eq!(w.duration, steps.len() as f64 * DT);
            let min = steps.iter().map(|v| v.radial).reduce(f64::min).unwrap();
            let max = steps.iter().map(|v| v.radial).reduce(f64::max).unwrap();
            let pen = steps
                .iter()
                .map(|v| v.penetration)
                .reduce(f64::max)
                .unwrap();
            assert_eq!((w.displacement_min, w.displacement_max), (min, max));
            assert_eq!(w.penetration_max, pen);
            assert!(k > 0 || pen < 0.0, "the first contact stays open");
        }
        let late = StatisticsSettings {
            t_start: 2.0 * STEPS as f64 * DT,
            ..settings(Some(0.07))
        };
        let (window, impacts, blocks) = run(&late);
        assert!(impacts.is_empty() && blocks.is_empty());
        for w in &window {
            assert_eq!((w.duration, w.impacts), (0.0, 0));
            assert_eq!(
                (w.displacement_min, w.displacement_max, w.penetration_max),
                (0.0, 0.0, 0.0)
            );
        }
    }

    /// A state saved (as a checkpoint saves it) and restored mid-run, even mid-block, ends
    /// with the results of the uninterrupted run.
    #[test]
    fn a_restored_state_gives_the_uninterrupted_results() {
        for block in [None, Some(0.07)] {
            let s = settings(block);
            let (window, impacts, blocks) = run(&s);
            let mut state = started(&s);
            let mut drained = (Vec::new(), Vec::new());
            for (from, to) in [(0, 137), (137, 512), (512, STEPS)] {
                advance(&mut state, &s, from, to);
                drained.0.append(&mut state.impacts);
                drained.1.append(&mut state.blocks);
                let mut bytes = Vec::new();
                ciborium::into_writer(&state, &mut bytes).unwrap();
                state = ciborium::from_reader(bytes.as_slice()).unwrap();
            }
            let window_r = state.finish(&s, &names(), DT);
            drained.0.append(&mut state.impacts);
            drained.1.append(&mut state.blocks);
            assert_eq!(window_r, window);
            assert_eq!(drained, (impacts, blocks));
        }
    }
}
