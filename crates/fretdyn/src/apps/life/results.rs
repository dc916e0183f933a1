//! What a service life gives (THEORY §14.5): each wearing contact's volumes, depths and wear
//! work rate after every life step, how the life ended, the final scar profiles; and the
//! first-order standard error of the depths from the windows' wear work rates.

use serde::{Deserialize, Serialize};

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
    /// The clearance the scars add where they are deepest ([`Scar::approach`](crate::wear::Scar::approach) of the two
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
    /// by [`service_life_with`](super::service_life_with) and [`LifeControl::resume`](super::LifeControl::resume).
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
    /// Added clearance (the approach of tube and support, [`Scar::approach`](crate::wear::Scar::approach)) per bin, m.
    pub clearance_increase: Vec<f64>,
    /// Tube depth per bin, m.
    pub tube_depth: Vec<f64>,
    /// Support depth per bin (body B's scar of a two-body contact), m.
    pub support_depth: Vec<f64>,
}

/// The result of [`service_life`](super::service_life).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LifeResults {
    /// Names of the wearing contacts.
    pub contacts: Vec<String>,
    /// Clearance at rest of each wearing contact, m.
    pub clearances: Vec<f64>,
    /// For each wearing contact between two bodies (THEORY §15), the names of the points
    /// `[A, B]` whose bodies its `tube_*` and `support_*` values are of
    /// ([`pair_bodies`](crate::wear::pair_bodies)); `None` for a contact with an obstacle (its
    /// support is the obstacle). In `life.json` only when a contact is between two bodies.
    #[serde(skip_serializing_if = "no_pairs")]
    pub bodies: Vec<Option<[String; 2]>>,
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

fn no_pairs(bodies: &[Option<[String; 2]>]) -> bool {
    bodies.iter().all(Option::is_none)
}

/// The first-order standard error of one contact's tube depth after each life step, with the
/// scars fed back and at fixed gap, from the columns of its rows in `life.csv` (row 0 the
/// start). The depth gained over step `i` is the wear work rate `W_i` of the window that drove
/// it (row `i`) times the step, so its relative error is that window's, `s_i / W_i`; the
/// windows are independent simulations, so the steps' errors add in quadrature:
/// `σ_i = √(Σ_{j≤i} (Δd_j s_j / W_j)²)` (a step that gains no depth adds nothing; one that
/// gains depth without a known error, `s_j` NaN, leaves the error unknown, NaN, from there
/// on). At fixed gap every step has the first window's rate: its relative error throughout
/// (the first row with a rate and a finite error; 0 without one).
pub fn depth_standard_errors(
    depth: &[f64],
    fixed_gap: &[f64],
    rate: &[f64],
    rate_se: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let mut sum = 0.0;
    let mut before = 0.0;
    let coupled = (0..depth.len())
        .map(|i| {
            let gained = depth[i] - before;
            before = depth[i];
            let relative = if gained > 0.0 {
                rate_se[i] / rate[i]
            } else {
                0.0
            };
            let x = gained * relative;
            sum += x * x;
            f64::sqrt(sum)
        })
        .collect();
    let first = (0..rate.len())
        .map(|i| {
            let (r, se) = (rate[i], rate_se[i]);
            if r > 0.0 && se.is_finite() {
                se / r
            } else {
                0.0
            }
        })
        .find(|r| *r > 0.0)
        .unwrap_or(0.0);
    let fixed = fixed_gap.iter().map(|d| d * first).collect();
    (coupled, fixed)
}
