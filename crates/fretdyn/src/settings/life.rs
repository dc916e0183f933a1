//! The `[life]` settings of a service life ([`LifeSettings`], THEORY §14.5), run by
//! [`crate::apps::life`].

use serde::Serialize;

use crate::error::{Error, Result};

/// Seconds in a year (365.25 days).
pub const YEAR: f64 = 365.25 * 86_400.0;

/// `max_depth_change` when `[life]` does not give it (measured in `case/life.rs`).
pub const DEFAULT_MAX_DEPTH_CHANGE: f64 = 0.025;

/// Most angular bins of a hole's scar profile (0.1° bins): the wear map holds two numbers
/// per bin and contact, and a life step spreads each bin's volume over the others.
pub const MAX_ANGULAR_BINS: usize = 3600;

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
                    "must be a fraction in (0, 1] (got {}); {DEFAULT_MAX_DEPTH_CHANGE} (the default) is a good start, halve it to check convergence (fretdyn life --halvings)",
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
        if !(4..=MAX_ANGULAR_BINS).contains(&self.angular_bins) {
            return Err(Error::invalid(
                format!("{field}.angular_bins"),
                format!(
                    "must be between 4 and {MAX_ANGULAR_BINS} (0.1° bins), got {}; 72 (5° bins) is the default",
                    self.angular_bins
                ),
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
