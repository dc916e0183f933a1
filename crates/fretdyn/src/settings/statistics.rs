//! The `[statistics]` settings of a run ([`StatisticsSettings`], THEORY §5, §11): the window,
//! the blocks of the batch means, the impact definition and the target relative error; and
//! the steps they select (midpoint rule, [`crate::accumulate::statistics`]).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// What the statistics cover and how impacts are told apart.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StatisticsSettings {
    /// Start of the window, s (a transient before it is skipped).
    pub t_start: f64,
    /// End of the window, s (`f64::INFINITY`: the end of the run).
    pub t_end: f64,
    /// Duration of the blocks (batches) the window is cut into, s (`None`: [`Self::batches`]
    /// of the window, see [`StatisticsSettings::block_length`]).
    pub block: Option<f64>,
    /// Number of batches of the window when `block` is not given (`None`: [`DEFAULT_BATCHES`],
    /// or [`DEFAULT_TARGET_BATCHES`] of the longest window with a target).
    pub batches: Option<u64>,
    /// Stop the run once the relative standard error of the wear work rate of every contact
    /// that wears is at most this (checked at the end of each batch, from
    /// [`MIN_TARGET_BATCHES`] batches on); the run's duration is then the longest.
    pub target_relative_error: Option<f64>,
    /// A relative standard error above this is worth a warning (front ends).
    pub max_relative_error: f64,
    /// An opening longer than this ends an impact; shorter ones are rebounds, s.
    pub rest_duration: f64,
    /// Wear coefficient `K_wear` of the work-rate (Archard-type) wear law, m³/J:
    /// wear volume `V = K_wear ∫|R_T·v_T| dt` (THEORY §5).
    pub wear_coefficient: f64,
}

/// Relative standard error above which a statistic is worth a warning, by default: 5 %, the
/// spread at which two runs of a study differ visibly on a plot.
pub const DEFAULT_MAX_RELATIVE_ERROR: f64 = 0.05;

impl Default for StatisticsSettings {
    fn default() -> Self {
        Self {
            t_start: 0.0,
            t_end: f64::INFINITY,
            block: None,
            batches: None,
            target_relative_error: None,
            max_relative_error: DEFAULT_MAX_RELATIVE_ERROR,
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
        if let Some(b) = self.block
            && !(b.is_finite() && b > 0.0)
        {
            return Err(Error::invalid(
                format!("{field}.block"),
                format!("must be a positive duration in s (got {b})"),
            ));
        }
        if let Some(n) = self.batches
            && n < 2
        {
            return Err(Error::invalid(
                format!("{field}.batches"),
                format!("must be at least 2 batches to estimate an error (got {n})"),
            ));
        }
        if let Some(e) = self.target_relative_error
            && !(e.is_finite() && e > 0.0 && e < 1.0)
        {
            return Err(Error::invalid(
                format!("{field}.target_relative_error"),
                format!("must be a relative standard error in (0, 1), e.g. 0.02 for 2 % (got {e})"),
            ));
        }
        if !(self.max_relative_error.is_finite() && self.max_relative_error > 0.0) {
            return Err(Error::invalid(
                format!("{field}.max_relative_error"),
                format!(
                    "must be a positive relative standard error, e.g. 0.05 for 5 % (got {})",
                    self.max_relative_error
                ),
            ));
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
    pub(crate) fn in_window(&self, t: f64) -> bool {
        t > self.t_start && t <= self.t_end
    }

    /// Whether the step ending at `t` counts: its midpoint `t − Δt/2` is in the window (the
    /// step times `nΔt` are not exact multiples of the window's bounds in floating point).
    #[inline]
    pub(crate) fn step_in_window(&self, t: f64, dt: f64) -> bool {
        self.in_window(t - 0.5 * dt)
    }

    /// Block of the step ending at `t` (by its midpoint).
    #[inline]
    pub(crate) fn block_of(&self, t: f64, dt: f64, block: f64) -> u64 {
        ((t - 0.5 * dt - self.t_start) / block).floor().max(0.0) as u64
    }
}

/// Batches of the window when `[statistics] block` is not given (and no target is set).
pub const DEFAULT_BATCHES: u64 = 20;
/// Batches of the longest window (`time.duration`) when a target relative error is set: the
/// batch length is then fixed before the run, short enough for the run to stop early.
pub const DEFAULT_TARGET_BATCHES: u64 = 100;

impl StatisticsSettings {
    /// The first step (numbered from 1, the step ending at `n Δt`) of a run of `steps` steps
    /// of `dt` that counts in the window (midpoint rule); `None` when none does.
    pub fn first_window_step(&self, steps: u64, dt: f64) -> Option<u64> {
        // found near its estimate by the rule itself
        let inside = |n: u64| n >= 1 && n <= steps && self.step_in_window(n as f64 * dt, dt);
        let mut first = ((self.t_start / dt + 0.5).floor().max(0.0) as u64).min(steps);
        while first > 1 && inside(first - 1) {
            first -= 1;
        }
        while first <= steps && !inside(first) {
            first += 1;
        }
        (first <= steps).then_some(first)
    }

    /// Steps of a run of `steps` steps of `dt` that count in the window (midpoint rule).
    pub fn window_steps(&self, steps: u64, dt: f64) -> u64 {
        // first and last step in the window, found near their estimates by the rule itself
        let inside = |n: u64| n >= 1 && n <= steps && self.step_in_window(n as f64 * dt, dt);
        let estimate = |t: f64| ((t / dt + 0.5).floor().max(0.0) as u64).min(steps);
        let Some(first) = self.first_window_step(steps, dt) else {
            return 0;
        };
        let mut last = estimate(self.t_end.min(steps as f64 * dt)).max(first);
        while last < steps && inside(last + 1) {
            last += 1;
        }
        while last > first && !inside(last) {
            last -= 1;
        }
        last + 1 - first
    }

    /// Duration of the blocks of a run of `steps` steps of `dt`: `block` if set, else the
    /// window cut into [`StatisticsSettings::batches`] (default [`DEFAULT_BATCHES`], or
    /// [`DEFAULT_TARGET_BATCHES`] with a target), of whole or nearly whole steps (at most one
    /// step apart), and no shorter than a step.
    pub fn block_length(&self, steps: u64, dt: f64) -> f64 {
        if let Some(b) = self.block {
            return b;
        }
        let n = self.window_steps(steps, dt);
        let batches = self
            .batches
            .unwrap_or(if self.target_relative_error.is_some() {
                DEFAULT_TARGET_BATCHES
            } else {
                DEFAULT_BATCHES
            });
        let batches = batches.min(n).max(1);
        if n == 0 {
            f64::INFINITY
        } else {
            n as f64 * dt / batches as f64
        }
    }
}
