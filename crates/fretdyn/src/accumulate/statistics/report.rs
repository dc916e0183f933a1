//! What the statistics report per contact (THEORY §5): [`ContactStatistics`] over a window or
//! a block, with the [`StandardErrors`] of a window by batch means; the columns of the files
//! of a run are derived from them by the table of [`super::columns`].

use serde::{Deserialize, Serialize};

use crate::wear::WearWork;

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
