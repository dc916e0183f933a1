//! `[time]`, `[tangential]`, `[output]`, `[statistics]`: the numerical settings of a run
//! (THEORY §2, §4, §5).

use nalgebra::Vector3;
use serde::Deserialize;

use crate::accumulate::statistics::StatisticsSettings;
use crate::contact::friction::LocalSolve;
use crate::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use crate::error::{Error, Result, number};
use crate::integrator::simulation::RunSettings;
use crate::integrator::stability::checked_stable_time_step;
use crate::model::Model;
use crate::settings::Monitor;

use super::shared::point_index;

/// `[statistics]`: the window, blocks (batches), standard errors and their target, impact
/// definition and wear coefficient (THEORY §5).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct StatisticsSection {
    #[serde(default)]
    t_start: f64,
    t_end: Option<f64>,
    block: Option<f64>,
    batches: Option<u64>,
    target_relative_error: Option<f64>,
    #[serde(default = "default_max_relative_error")]
    max_relative_error: f64,
    #[serde(default)]
    rest_duration: f64,
    #[serde(default)]
    wear_coefficient: f64,
}

impl Default for StatisticsSection {
    fn default() -> Self {
        Self {
            t_start: 0.0,
            t_end: None,
            block: None,
            batches: None,
            target_relative_error: None,
            max_relative_error: default_max_relative_error(),
            rest_duration: 0.0,
            wear_coefficient: 0.0,
        }
    }
}

fn default_max_relative_error() -> f64 {
    crate::accumulate::statistics::DEFAULT_MAX_RELATIVE_ERROR
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TimeSection {
    pub(super) dt: f64,
    duration: f64,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TangentialSection {
    #[serde(default)]
    method: MethodName,
    #[serde(default)]
    stick_velocity: StickVelocityName,
    penalty: Option<PenaltyInput>,
    #[serde(default)]
    gauss_seidel: GaussSeidelInput,
    #[serde(default)]
    active_set: ActiveSetInput,
}

#[derive(Debug, Default, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
pub(super) enum MethodName {
    Penalty,
    ActiveSet,
    #[default]
    GaussSeidel,
}

#[derive(Debug, Default, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
pub(super) enum StickVelocityName {
    #[default]
    HalfStep,
    FullStep,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PenaltyInput {
    stiffness: f64,
    #[serde(default)]
    damping: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct GaussSeidelInput {
    #[serde(default = "default_tolerance")]
    tolerance: f64,
    #[serde(default = "default_residual_tolerance")]
    residual_tolerance: f64,
    #[serde(default = "default_max_sweeps")]
    max_sweeps: usize,
    #[serde(default)]
    local_solve: LocalSolveName,
    #[serde(default = "yes")]
    warm_start: bool,
}

impl Default for GaussSeidelInput {
    fn default() -> Self {
        let d = GaussSeidelSettings::default();
        Self {
            tolerance: d.tolerance,
            residual_tolerance: d.residual_tolerance,
            max_sweeps: d.max_sweeps,
            local_solve: LocalSolveName::Exact,
            warm_start: d.warm_start,
        }
    }
}

fn default_tolerance() -> f64 {
    GaussSeidelSettings::default().tolerance
}
fn default_residual_tolerance() -> f64 {
    GaussSeidelSettings::default().residual_tolerance
}
fn default_max_sweeps() -> usize {
    GaussSeidelSettings::default().max_sweeps
}
fn yes() -> bool {
    true
}

#[derive(Debug, Default, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
pub(super) enum LocalSolveName {
    #[default]
    Exact,
    Radial,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ActiveSetInput {
    #[serde(default = "default_max_iterations")]
    max_iterations: usize,
}

impl Default for ActiveSetInput {
    fn default() -> Self {
        Self {
            max_iterations: default_max_iterations(),
        }
    }
}

fn default_max_iterations() -> usize {
    ActiveSetSettings::default().max_iterations
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct OutputSection {
    #[serde(default = "one")]
    every: u64,
    #[serde(default)]
    monitors: Vec<MonitorInput>,
}

impl Default for OutputSection {
    fn default() -> Self {
        Self {
            every: 1,
            monitors: Vec::new(),
        }
    }
}

/// `[[output.monitors]]`: the displacement of a point along a direction
/// ([`crate::accumulate::monitor`]).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MonitorInput {
    /// Name in the outputs (default: the point's).
    name: Option<String>,
    point: String,
    direction: [f64; 3],
}

impl OutputSection {
    /// The monitors, their points found in `model` and their directions made unit.
    fn monitors(&self, model: &Model) -> Result<Vec<Monitor>> {
        let mut names = std::collections::HashSet::new();
        let mut out = Vec::with_capacity(self.monitors.len());
        for (i, m) in self.monitors.iter().enumerate() {
            let field = format!("output.monitors[{i}]");
            let point = point_index(&m.point, format!("{field}.point"), model)?;
            let d = Vector3::from(m.direction);
            let norm = d.norm();
            if !(norm.is_finite() && norm > 0.0) {
                return Err(Error::invalid(
                    format!("{field}.direction"),
                    "must be a non-zero finite vector, e.g. [0.0, 0.0, 1.0] (the displacement along it is monitored)",
                ));
            }
            let name = m.name.clone().unwrap_or_else(|| m.point.clone());
            if !names.insert(name.clone()) {
                return Err(Error::invalid(
                    format!("{field}.name"),
                    format!("`{name}` names another monitor: give each its own name"),
                ));
            }
            out.push(Monitor {
                name,
                point,
                point_name: m.point.clone(),
                direction: d / norm,
            });
        }
        Ok(out)
    }
}

fn one() -> u64 {
    1
}

impl GaussSeidelInput {
    fn settings(&self) -> GaussSeidelSettings {
        GaussSeidelSettings {
            tolerance: self.tolerance,
            residual_tolerance: self.residual_tolerance,
            max_sweeps: self.max_sweeps,
            local_solve: match self.local_solve {
                LocalSolveName::Exact => LocalSolve::Exact,
                LocalSolveName::Radial => LocalSolve::Radial,
            },
            warm_start: self.warm_start,
        }
    }
}

/// The sections of a case file that set the numerical settings of a run.
pub(super) struct SettingsSections<'a> {
    pub time: &'a TimeSection,
    pub tangential: &'a TangentialSection,
    pub output: &'a OutputSection,
    pub statistics: &'a StatisticsSection,
}

impl SettingsSections<'_> {
    /// `[time]`, `[tangential]`, `[output]` and `[statistics]`: the run settings, checked
    /// against the model's stable time step (THEORY §2, §4, §5).
    pub(super) fn settings(&self, model: &Model) -> Result<RunSettings> {
        let t = self.tangential;
        let method = match t.method {
            MethodName::Penalty => {
                let p = t.penalty.as_ref().ok_or_else(|| {
                    Error::invalid(
                        "tangential.penalty",
                        "method = \"penalty\" needs [tangential.penalty] with stiffness (K_T, N/m) and damping (C_T, N·s/m)",
                    )
                })?;
                TangentialMethod::Penalty(PenaltySettings {
                    stiffness: p.stiffness,
                    damping: p.damping,
                })
            }
            MethodName::GaussSeidel => TangentialMethod::GaussSeidel(t.gauss_seidel.settings()),
            MethodName::ActiveSet => TangentialMethod::ActiveSet(ActiveSetSettings {
                max_iterations: t.active_set.max_iterations,
                fallback: t.gauss_seidel.settings(),
            }),
        };
        let dt = self.time.dt;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::invalid(
                "time.dt",
                format!("must be a positive time step in s (got {})", number(dt)),
            ));
        }
        let duration = self.time.duration;
        if !(duration.is_finite() && duration > 0.0) {
            return Err(Error::invalid(
                "time.duration",
                format!(
                    "must be a positive duration in s (got {})",
                    number(duration)
                ),
            ));
        }
        if duration < dt * (1.0 - 1e-9) {
            return Err(Error::invalid(
                "time.duration",
                format!(
                    "{} s is shorter than one step (time.dt = {} s): the run would do no step; set duration ≥ dt",
                    number(duration),
                    number(dt)
                ),
            ));
        }
        let statistics = self.statistics;
        // a step counts in the window when its middle is after t_start (THEORY §5): the last
        // step's middle is half a step before the end
        let last_middle = ((duration / dt).round() - 0.5) * dt;
        if statistics.t_start >= last_middle {
            return Err(Error::invalid(
                "statistics.t_start",
                format!(
                    "{} s is not before the end of the run (time.duration = {} s): the statistics window would hold no step; set t_start < duration",
                    number(statistics.t_start),
                    number(duration)
                ),
            ));
        }
        if let Some(block) = statistics
            .block
            .filter(|b| *b > 0.0 && *b < dt * (1.0 - 1e-9))
        {
            return Err(Error::invalid(
                "statistics.block",
                format!(
                    "{} s is shorter than one step (time.dt = {} s): a block holds whole steps; set block ≥ dt (e.g. a tenth of the window)",
                    number(block),
                    number(dt)
                ),
            ));
        }
        if statistics.block.is_some() && statistics.batches.is_some() {
            return Err(Error::invalid(
                "statistics.batches",
                "is given with statistics.block: give one of them (block: the batch duration in s; batches: their number in the window)",
            ));
        }
        let steps = (duration / dt).round();
        if steps > 1e12 {
            return Err(Error::invalid(
                "time.duration",
                format!(
                    "gives {} steps of {} s: more than 1e12 steps",
                    number(steps),
                    number(dt)
                ),
            ));
        }
        let settings = RunSettings {
            dt,
            steps: steps as u64,
            method,
            stick_velocity: match t.stick_velocity {
                StickVelocityName::HalfStep => StickVelocity::HalfStep,
                StickVelocityName::FullStep => StickVelocity::FullStep,
            },
            output_every: self.output.every,
            monitors: self.output.monitors(model)?,
            statistics: StatisticsSettings {
                t_start: self.statistics.t_start,
                t_end: self.statistics.t_end.unwrap_or(f64::INFINITY),
                block: self.statistics.block,
                batches: self.statistics.batches,
                target_relative_error: self.statistics.target_relative_error,
                max_relative_error: self.statistics.max_relative_error,
                rest_duration: self.statistics.rest_duration,
                wear_coefficient: self.statistics.wear_coefficient,
            },
        };
        settings.validate()?;
        let window =
            self.statistics.t_end.unwrap_or(f64::INFINITY).min(duration) - self.statistics.t_start;
        if let Some(block) = self.statistics.block.filter(|b| *b > window * (1.0 + 1e-9)) {
            return Err(Error::invalid(
                "statistics.block",
                format!(
                    "{} s is longer than the statistics window ({} s): the standard errors need several batches in it; set block ≤ a tenth of the window or leave it out ({} batches by default)",
                    number(block),
                    number(window),
                    crate::accumulate::statistics::DEFAULT_BATCHES
                ),
            ));
        }
        // contacts and turbulence that would not fit in memory: refused with the figure
        // before the run allocates them
        super::memory::check(model, &settings.method)?;
        // a model without a usable stable time step (a unit slip: a mass of 1e-320 kg, a
        // radius of 1e200 m) is refused here, naming its cause; a Δt above a usable limit is
        // left to the run, which says the limit
        let stable_dt = checked_stable_time_step(model, &settings.method)?;
        if duration / stable_dt > 1e12 {
            return Err(Error::invalid(
                "time.dt",
                format!(
                    "the stable limit of central differences is {stable_dt:.3e} s (a highest frequency of about {:.3e} Hz, docs/THEORY.md §2): {} s would take more than 1e12 steps; check the units of the structure (masses, densities, sizes, Young's modulus) and of the contact stiffnesses",
                    2.0 / (std::f64::consts::TAU * stable_dt),
                    number(duration)
                ),
            ));
        }
        Ok(settings)
    }
}
