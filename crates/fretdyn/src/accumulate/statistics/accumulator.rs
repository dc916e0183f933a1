//! Running sums of one contact over a window or a block (THEORY §5), from which its
//! [`ContactStatistics`] and its batch means are formed, and the histogram of the impacts'
//! peak forces.

use serde::{Deserialize, Serialize};

use super::columns::BATCHED;
use super::impacts::Impact;
use super::report::{ContactStatistics, PeakBin, StandardErrors};
use super::step::StepValues;

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
    pub(super) impacts: u64,
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
    pub(super) fn reset(&mut self) {
        let mut histogram = std::mem::take(&mut self.peak_histogram);
        histogram.iter_mut().for_each(|c| *c = 0);
        *self = Self::with_histogram(histogram);
    }

    /// Adds one step (the caller counts it). An open contact's step only moves the offset's
    /// sums and extrema and the largest penetration; the values are finite (checked by the
    /// step), so that the extrema, started at `±∞`, take the first value exactly.
    #[inline]
    pub(super) fn add_step(&mut self, v: &StepValues, dt: f64) {
        self.add_offset(v.radial, v.penetration);
        if v.closed {
            self.add_closed_step(v, dt);
        }
    }

    /// The sums of every step, open or closed: the offset's, and the largest penetration.
    #[inline(always)]
    pub(super) fn add_offset(&mut self, radial: f64, penetration: f64) {
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

    pub(super) fn add_impact(&mut self, imp: &Impact) {
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
    pub(super) fn statistics(
        &self,
        steps: u64,
        dt: f64,
        wear_coefficient: f64,
    ) -> ContactStatistics {
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

impl ContactAccumulator {
    /// The batch means of [`super::BATCHED_STATISTICS`] over `steps` steps of `dt` (mean squares
    /// for the rms).
    pub(super) fn batch_values(&self, steps: u64, dt: f64) -> [f64; BATCHED] {
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
    pub(super) fn merge(&mut self, other: &Self) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accumulate::statistics::batched_statistics;

    /// A block's batch means are its statistics of the table's batched rows, at their
    /// [`crate::accumulate::statistics::Batched::index`] (an rms as its mean square).
    #[test]
    fn batch_means_are_the_batched_statistics_in_their_order() {
        let (mut acc, dt, steps) = (ContactAccumulator::new(), 1e-3, 50);
        for n in 0..steps {
            let x = n as f64;
            let v = StepValues {
                t: x * dt,
                closed: n % 3 != 0,
                stick: n % 5 == 0,
                normal: 1.0 + x,
                tangential: 0.5 + 0.1 * x,
                slip_speed: 0.01 * x,
                friction_power: 0.02 * x,
                penetration: 1e-6 * x,
                radial: 1e-5 * x,
                direction: [1.0, 0.0],
            };
            acc.add_step(&v, dt);
        }
        acc.impacts = 7;
        let s = acc.statistics(steps, dt, 0.0);
        let means = acc.batch_values(steps, dt);
        let mut seen = Vec::new();
        for (row, b) in batched_statistics() {
            let value = (row.value)(&s).as_f64();
            let mean = if b.rms {
                means[b.index].sqrt()
            } else {
                means[b.index]
            };
            assert_eq!(mean, value, "{}", row.key);
            assert!(value != 0.0 && !seen.contains(&value), "{}", row.key);
            seen.push(value);
        }
    }
}
