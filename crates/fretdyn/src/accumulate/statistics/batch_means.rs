//! Batch means (THEORY §5): the running moments of one contact's batch means, from which
//! the standard errors of its window's statistics and the lag-1 autocorrelation are formed,
//! and the target relative error's settings.

use serde::{Deserialize, Serialize};

use super::columns::{BATCHED, batch_index, batched_statistics};
use super::report::{ContactStatistics, StandardErrors};

/// Batches needed before a target relative error is checked (fewer give too noisy an SE).
pub const MIN_TARGET_BATCHES: u64 = 20;
/// A contact holds a run with a target while its wear work rate is at least this fraction
/// of the largest contact's (one that barely wears is reported, with its error, but does not
/// make the run go on).
pub const TARGET_WEAR_SHARE: f64 = 0.01;

/// The place among the batch means of the wear work rate, whose relative error a target
/// checks ([`super::ContactStatisticsState`]).
pub(super) const WEAR_WORK_RATE: usize = batch_index("wear_work_rate");

/// The batch means the lag-1 autocorrelation is formed from: the wear work rate's, or when
/// it does not vary, the impact rate's, the contact time fraction's or the mean normal
/// force's.
const AUTOCORRELATION_OF: [usize; 4] = [
    WEAR_WORK_RATE,
    batch_index("impacts_per_second"),
    batch_index("contact_time_fraction"),
    batch_index("normal_force_mean"),
];

/// Running sums over the batch means of one contact, shifted by the first batch's so that
/// `Σ(x_b − x̄)²` does not cancel: `d_b = x_b − x_1`, `Σd_b`, `Σd_b²`, `Σd_b d_{b−1}`, and the
/// last `d_b`. Fixed size: a run of any length keeps the same room.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct BatchMoments {
    pub(super) n: u64,
    shift: [f64; BATCHED],
    sum: [f64; BATCHED],
    squares: [f64; BATCHED],
    lag: [f64; BATCHED],
    last: [f64; BATCHED],
}

impl BatchMoments {
    pub(super) fn add(&mut self, x: &[f64; BATCHED]) {
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
    pub(super) fn moments(&self, i: usize) -> (f64, f64, f64) {
        let n = self.n as f64;
        let m = self.sum[i] / n;
        let ss = (self.squares[i] - n * m * m).max(0.0);
        // d_1 = 0 by the shift
        let lag = self.lag[i] - m * (2.0 * self.sum[i] - self.last[i]) + (n - 1.0) * m * m;
        (self.shift[i] + m, ss, lag)
    }

    /// Standard error of the mean of statistic `i`, `√(Σ(x_b − x̄)²/(n(n−1)))`.
    pub(super) fn se(&self, i: usize) -> Option<f64> {
        (self.n >= 2).then(|| {
            let n = self.n as f64;
            (self.moments(i).1 / (n * (n - 1.0))).sqrt()
        })
    }

    /// The errors of the window's statistics `s`.
    pub(super) fn errors(&self, s: &ContactStatistics, batch_length: f64) -> StandardErrors {
        let mut se: [Option<f64>; BATCHED] = std::array::from_fn(|i| self.se(i));
        for (statistic, b) in batched_statistics().filter(|(_, b)| b.rms) {
            let rms = (statistic.value)(s).as_f64();
            se[b.index] = se[b.index].map(|e| if rms > 0.0 { e / (2.0 * rms) } else { 0.0 });
        }
        // a statistic varies when its spread is above the round-off of its mean
        let n = self.n as f64;
        let headline = AUTOCORRELATION_OF
            .into_iter()
            .map(|i| self.moments(i))
            .find(|(m, ss, _)| *ss > n * (1e-12 * m).powi(2) && *ss > f64::MIN_POSITIVE);
        let r1 = (self.n >= 3)
            .then_some(headline)
            .flatten()
            .map(|(_, ss, lag)| (lag / ss).clamp(-1.0, 1.0))
            .filter(|r| r.is_finite());
        let mut errors = StandardErrors {
            batches: self.n,
            // a window without a step has no batch
            batch_length: if batch_length.is_finite() {
                batch_length
            } else {
                0.0
            },
            batch_autocorrelation: r1,
            batches_correlated: r1.is_some_and(|r| r > 2.0 / (self.n as f64).sqrt()),
            ..StandardErrors::default()
        };
        for (_, b) in batched_statistics() {
            *(b.se_mut)(&mut errors) = se[b.index];
        }
        errors
    }
}
