//! Statistics accumulated at every step (not only at output samples), THEORY §5: per-contact
//! wear, impact and force statistics over a time window `[t_start, t_end]` and optionally in
//! blocks, and the table of impacts.
//!
//! A step `(t − Δt, t]` counts in the window (and in a block) when its midpoint `t − Δt/2` is
//! in it, so that bounds that are multiples of Δt split the steps exactly despite round-off. An **impact** starts when the contact closes after being open longer than the rest
//! duration, and ends at the last opening before such a rest: openings shorter than the rest
//! duration are **rebounds** within the impact. Its start and end times are interpolated
//! linearly between steps on the penetration's zero crossing; it belongs to the window when
//! the step in which it starts does (the same midpoint rule, not the interpolated start time:
//! an impact that starts on the window's first step, e.g. a contact closed from `t_start`
//! exactly, is counted once and has its row, its duration and its peak in the histogram like
//! any other). An impact still going on when the run ends is ended there.
//!
//! One concept, kept whole: the window, the blocks, the impacts and the peak histogram are
//! accumulated from the same step values by one midpoint rule, in one state per contact (the
//! energy balance is apart, in [`crate::results::energy`]).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// What the statistics cover and how impacts are told apart.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StatisticsSettings {
    /// Start of the window, s (a transient before it is skipped).
    pub t_start: f64,
    /// End of the window, s (`f64::INFINITY`: the end of the run).
    pub t_end: f64,
    /// Duration of the blocks the window is also cut into, s (`None`: no blocks).
    pub block: Option<f64>,
    /// An opening longer than this ends an impact; shorter ones are rebounds, s.
    pub rest_duration: f64,
    /// Wear coefficient `K_wear` of the work-rate (Archard-type) wear law, m³/J:
    /// wear volume `V = K_wear ∫|R_T·v_T| dt` (THEORY §5).
    pub wear_coefficient: f64,
}

impl Default for StatisticsSettings {
    fn default() -> Self {
        Self {
            t_start: 0.0,
            t_end: f64::INFINITY,
            block: None,
            rest_duration: 0.0,
            wear_coefficient: 0.0,
        }
    }
}

impl StatisticsSettings {
    /// Checks the numbers; `field` names the section in errors.
    pub fn validate(&self, field: &str) -> Result<()> {
        if !(self.t_start.is_finite() && self.t_start >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.t_start"),
                format!("must be a time ≥ 0 in s (got {})", self.t_start),
            ));
        }
        if self.t_end.is_nan() || self.t_end <= self.t_start {
            return Err(Error::invalid(
                format!("{field}.t_end"),
                format!(
                    "must be after t_start = {} s (got {}); leave it out for the end of the run",
                    self.t_start, self.t_end
                ),
            ));
        }
        if let Some(b) = self.block {
            if !(b.is_finite() && b > 0.0) {
                return Err(Error::invalid(
                    format!("{field}.block"),
                    format!("must be a positive duration in s (got {b})"),
                ));
            }
        }
        if !(self.rest_duration.is_finite() && self.rest_duration >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.rest_duration"),
                format!("must be a duration ≥ 0 in s (got {})", self.rest_duration),
            ));
        }
        if !(self.wear_coefficient.is_finite() && self.wear_coefficient >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.wear_coefficient"),
                format!(
                    "must be a wear coefficient ≥ 0 in m³/J (got {})",
                    self.wear_coefficient
                ),
            ));
        }
        Ok(())
    }

    #[inline]
    fn in_window(&self, t: f64) -> bool {
        t > self.t_start && t <= self.t_end
    }

    /// Whether the step ending at `t` counts: its midpoint `t − Δt/2` is in the window (the
    /// step times `nΔt` are not exact multiples of the window's bounds in floating point).
    #[inline]
    fn step_in_window(&self, t: f64, dt: f64) -> bool {
        self.in_window(t - 0.5 * dt)
    }

    /// Block of the step ending at `t` (by its midpoint).
    #[inline]
    fn block_of(&self, t: f64, dt: f64, block: f64) -> u64 {
        ((t - 0.5 * dt - self.t_start) / block).floor().max(0.0) as u64
    }
}

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

impl StepValues {
    /// The angle `θ` of [`StepValues::direction`], degrees in (−180, 180].
    fn angle_deg(&self) -> f64 {
        self.direction[1].atan2(self.direction[0]).to_degrees()
    }
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
    /// has acted yet.
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
}

impl ImpactTracker {
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
    /// impact)` (whether that impact started in the window is [`Self::in_window`]).
    fn step(
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
                        angle_deg: v.angle_deg(),
                    });
                }
            }
            if let Some(imp) = &mut self.current {
                imp.impulse += v.normal * dt;
                imp.contact_time += dt;
                if v.normal > imp.peak_force {
                    imp.peak_force = v.normal;
                    imp.peak_time = v.t;
                    imp.angle_deg = v.angle_deg();
                }
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
                if let Some(mut imp) = self.current.take() {
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

/// Running sums of one contact over a window or a block.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactAccumulator {
    steps: u64,
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
    penetration_max: Option<f64>,
    radial_sum: f64,
    radial_sq_sum: f64,
    radial_min: Option<f64>,
    radial_max: Option<f64>,
    /// Σ cos θ, Σ sin θ over the contact steps (circular mean of the contact angle).
    angle_cos: f64,
    angle_sin: f64,
    peak_histogram: Vec<u64>,
}

impl ContactAccumulator {
    /// Empty sums, with the histogram's room.
    pub fn new() -> Self {
        Self {
            peak_histogram: vec![0; PEAK_DECADES * PEAK_BINS_PER_DECADE],
            ..Self::default()
        }
    }

    /// Back to empty sums, keeping the room.
    fn reset(&mut self) {
        let mut histogram = std::mem::take(&mut self.peak_histogram);
        histogram.iter_mut().for_each(|c| *c = 0);
        *self = Self {
            peak_histogram: histogram,
            ..Self::default()
        };
    }

    fn add_step(&mut self, v: &StepValues, dt: f64) {
        self.steps += 1;
        let min = |m: &mut Option<f64>, x: f64| *m = Some(m.map_or(x, |m| m.min(x)));
        let max = |m: &mut Option<f64>, x: f64| *m = Some(m.map_or(x, |m| m.max(x)));
        self.radial_sum += v.radial;
        self.radial_sq_sum += v.radial * v.radial;
        min(&mut self.radial_min, v.radial);
        max(&mut self.radial_max, v.radial);
        max(&mut self.penetration_max, v.penetration);
        if v.closed {
            self.contact_steps += 1;
            if v.stick {
                self.stick_steps += 1;
            } else {
                self.slip_steps += 1;
            }
            self.normal_sum += v.normal;
            self.normal_sq_sum += v.normal * v.normal;
            self.normal_max = self.normal_max.max(v.normal);
            self.tangential_sum += v.tangential;
            self.tangential_sq_sum += v.tangential * v.tangential;
            self.tangential_max = self.tangential_max.max(v.tangential);
            self.wear_work += v.friction_power * dt;
            self.normal_wear_work += v.normal * v.slip_speed * dt;
            self.angle_cos += v.direction[0];
            self.angle_sin += v.direction[1];
        }
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

    /// Statistics over the steps added, each of duration `dt`.
    pub fn finish(&self, name: &str, dt: f64, wear_coefficient: f64) -> ContactStatistics {
        let n = self.steps.max(1) as f64;
        let nc = self.contact_steps.max(1) as f64;
        let duration = self.steps as f64 * dt;
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
        ContactStatistics {
            name: name.to_string(),
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
            penetration_max: self.penetration_max.unwrap_or(0.0),
            displacement_mean: self.radial_sum / n,
            displacement_rms: (self.radial_sq_sum / n).sqrt(),
            displacement_min: self.radial_min.unwrap_or(0.0),
            displacement_max: self.radial_max.unwrap_or(0.0),
            contact_angle_mean_deg: angle_mean,
            contact_angle_spread_deg: angle_spread,
            peak_force_histogram: histogram,
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
}

/// Statistics of one contact over one block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BlockStatistics {
    /// Block number (0 is the first block of the window).
    pub block: u64,
    /// Start and end of the block, s.
    pub t_start: f64,
    pub t_end: f64,
    /// The statistics (without the histogram).
    pub statistics: ContactStatistics,
}

/// Everything the statistics keep for the contacts of a run: window and block accumulators,
/// impact trackers; finished impacts and blocks wait in [`Self::impacts`] and
/// [`Self::blocks`] until drained by the caller (a streaming run drains them at each flush,
/// so that memory stays flat).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactStatisticsState {
    settings_block: Option<f64>,
    window: Vec<ContactAccumulator>,
    block: Vec<ContactAccumulator>,
    block_index: u64,
    trackers: Vec<ImpactTracker>,
    /// Finished impacts started in the window, not yet drained.
    pub impacts: Vec<Impact>,
    /// Finished blocks `(block, contact, accumulator)`, not yet drained.
    pub blocks: Vec<BlockStatistics>,
}

impl ContactStatisticsState {
    /// Empty statistics for `contacts` contacts.
    pub fn new(contacts: usize, settings: &StatisticsSettings) -> Self {
        Self {
            settings_block: settings.block,
            window: vec![ContactAccumulator::new(); contacts],
            block: vec![ContactAccumulator::new(); contacts],
            block_index: 0,
            trackers: vec![ImpactTracker::default(); contacts],
            // room for the impacts that end between two drains: the step loop does not
            // allocate unless more wait (then the room grows once and is kept)
            impacts: Vec::with_capacity(IMPACT_ROOM_PER_CONTACT * contacts),
            blocks: Vec::with_capacity(if settings.block.is_some() {
                4 * contacts
            } else {
                0
            }),
        }
    }

    /// True when it follows `n` contacts.
    pub fn has_contacts(&self, n: usize) -> bool {
        self.window.len() == n && self.block.len() == n && self.trackers.len() == n
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

    /// Adds one step: `values[k]` for contact k, the step ending at `t`.
    pub fn step(
        &mut self,
        settings: &StatisticsSettings,
        names: &[String],
        t: f64,
        dt: f64,
        values: impl Iterator<Item = StepValues>,
    ) {
        let in_window = settings.step_in_window(t, dt);
        if in_window {
            if let Some(b) = settings.block {
                // the block of this step; close the previous ones
                let index = settings.block_of(t, dt, b);
                while index > self.block_index {
                    self.close_block(settings, names, dt);
                }
            }
        }
        for (k, v) in values.enumerate() {
            let (started, finished) =
                self.trackers[k].step(k, &v, settings.rest_duration, in_window);
            if in_window {
                self.window[k].add_step(&v, dt);
                self.block[k].add_step(&v, dt);
                if started {
                    self.window[k].impacts += 1;
                    self.block[k].impacts += 1;
                }
            }
            if let Some(imp) = finished {
                if self.trackers[k].in_window {
                    self.window[k].add_impact(&imp);
                    self.block[k].add_impact(&imp);
                    self.impacts.push(imp);
                }
            }
        }
    }

    fn close_block(&mut self, settings: &StatisticsSettings, names: &[String], dt: f64) {
        let b = settings.block.unwrap_or(f64::INFINITY);
        let t0 = settings.t_start + self.block_index as f64 * b;
        for (k, acc) in self.block.iter_mut().enumerate() {
            let mut statistics = acc.finish(&names[k], dt, settings.wear_coefficient);
            statistics.peak_force_histogram.clear();
            self.blocks.push(BlockStatistics {
                block: self.block_index,
                t_start: t0,
                t_end: t0 + b,
                statistics,
            });
            acc.reset();
        }
        self.block_index += 1;
    }

    /// Window statistics of every contact. An impact still in progress ends with the run (at
    /// its last opening, or at the last step if closed); a last, partial block that has steps
    /// is closed.
    pub fn finish(
        &mut self,
        settings: &StatisticsSettings,
        names: &[String],
        dt: f64,
    ) -> Vec<ContactStatistics> {
        for (k, tr) in self.trackers.iter_mut().enumerate() {
            if let Some(mut imp) = tr.current.take() {
                let end = if tr.open {
                    tr.last_opening
                } else {
                    tr.previous_t
                };
                imp.duration = end - imp.start;
                tr.active = false;
                if tr.in_window {
                    self.window[k].add_impact(&imp);
                    self.block[k].add_impact(&imp);
                    self.impacts.push(imp);
                }
            }
        }
        if settings.block.is_some() && self.block.iter().any(|a| a.steps > 0) {
            let b = settings.block.unwrap_or(f64::INFINITY);
            let t0 = settings.t_start + self.block_index as f64 * b;
            let steps = self.block[0].steps;
            self.close_block(settings, names, dt);
            // a partial block ends with its last step
            let n = names.len();
            let len = self.blocks.len();
            for row in &mut self.blocks[len - n..] {
                row.t_end = t0 + steps as f64 * dt;
            }
        }
        self.window
            .iter()
            .zip(names)
            .map(|(a, name)| a.finish(name, dt, settings.wear_coefficient))
            .collect()
    }
}
