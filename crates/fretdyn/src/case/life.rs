//! `[life]`: the service-life computation of `fretdyn life` (THEORY §14.5, docs/WEAR.md).

use serde::Deserialize;

use super::shared::TubeModel;
use crate::error::{Error, Result};
use crate::settings::life::{DEFAULT_MAX_DEPTH_CHANGE, LifeSettings, YEAR};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LifeSection {
    /// Service time to reach, years (of operation).
    target_years: f64,
    #[serde(default = "default_change")]
    max_depth_change: f64,
    #[serde(default = "default_resolution")]
    depth_resolution: f64,
    /// The tube's plugging depth, m.
    criterion_depth: Option<f64>,
    /// Or as a fraction of a tube structure's wall thickness.
    criterion_wall_fraction: Option<f64>,
    #[serde(default = "yes")]
    feedback: bool,
    #[serde(default = "default_bins")]
    angular_bins: usize,
    #[serde(default = "default_steps")]
    max_steps: usize,
}

/// The default `max_depth_change`: on `examples/tube_multispan_life.toml` (40 years, 2 s
/// windows) the deepest scar (plate 3) at 0.1, 0.05, 0.025 and 0.0125 is −16 %, −10 %, 0.0 %
/// and +2.6 % off its depth at 0.00625, for 2, 3, 7 and 14 windows (docs/WEAR.md, the
/// convergence table): 0.025 is within the noise of one window's wear work rate (a standard
/// error of 5–16 % at the loaded plates), for about twice the windows of 0.05.
fn default_change() -> f64 {
    DEFAULT_MAX_DEPTH_CHANGE
}
fn default_resolution() -> f64 {
    1e-6
}
fn yes() -> bool {
    true
}
fn default_bins() -> usize {
    72
}
fn default_steps() -> usize {
    1000
}

impl LifeSection {
    pub(super) fn build(&self, tube: Option<&TubeModel>) -> Result<LifeSettings> {
        let criterion = match (self.criterion_depth, self.criterion_wall_fraction) {
            (Some(_), Some(_)) => {
                return Err(Error::invalid(
                    "life.criterion_wall_fraction",
                    "give criterion_depth (m) or criterion_wall_fraction, not both",
                ));
            }
            (Some(d), None) => Some(d),
            (None, Some(f)) => {
                if !(f.is_finite() && f > 0.0 && f <= 1.0) {
                    return Err(Error::invalid(
                        "life.criterion_wall_fraction",
                        format!(
                            "must be a fraction of the wall in (0, 1] (got {}), e.g. 0.4",
                            crate::error::number(f)
                        ),
                    ));
                }
                let tube = tube.ok_or_else(|| {
                    Error::invalid(
                        "life.criterion_wall_fraction",
                        "needs one type = \"tube\" structure (its wall_thickness; a case of several structures has no one wall): give criterion_depth in m instead",
                    )
                })?;
                Some(f * tube.structure.beam.tube.section.wall_thickness)
            }
            (None, None) => None,
        };
        let settings = LifeSettings {
            target: self.target_years * YEAR,
            max_depth_change: self.max_depth_change,
            depth_resolution: self.depth_resolution,
            criterion,
            wall: tube.map(|t| t.structure.beam.tube.section.wall_thickness),
            feedback: self.feedback,
            angular_bins: self.angular_bins,
            max_steps: self.max_steps,
        };
        settings.validate("life")?;
        Ok(settings)
    }
}
