//! The numerical settings of a run ([`RunSettings`]) and their checks.

use nalgebra::Vector3;
use serde::Serialize;

use crate::contact::tangential::{StickVelocity, TangentialMethod};
use crate::error::{Error, Result};
use crate::settings::statistics::StatisticsSettings;

/// Numerical settings of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSettings {
    /// Time step Δt, s.
    pub dt: f64,
    /// Number of steps.
    pub steps: u64,
    /// Tangential method.
    pub method: TangentialMethod,
    /// Velocity the stick constraint acts on (Lagrange methods).
    pub stick_velocity: StickVelocity,
    /// Keep every `output_every`-th step in the recorded time histories (statistics use all).
    pub output_every: u64,
    /// Window, blocks and impact definition of the statistics.
    pub statistics: StatisticsSettings,
    /// Displacements of points along directions whose statistics the run reports
    /// ([`crate::accumulate::monitor`]).
    pub monitors: Vec<Monitor>,
}

/// A displacement monitor: the displacement `u = d·(Φ_x q)` of the model's point `point`
/// along the unit direction `d` (THEORY §5).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Monitor {
    /// Name in the outputs.
    pub name: String,
    /// Index of the point in the model's basis.
    pub point: usize,
    /// The point's name.
    pub point_name: String,
    /// Unit direction `d`.
    pub direction: Vector3<f64>,
}

impl RunSettings {
    /// Checks the numbers (not the stability limit, which needs the model).
    pub fn validate(&self) -> Result<()> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::invalid(
                "time.dt",
                format!("must be a positive time step in s (got {})", self.dt),
            ));
        }
        if self.output_every == 0 {
            return Err(Error::invalid(
                "output.every",
                "must be at least 1 (1 keeps every step)",
            ));
        }
        self.statistics.validate("statistics")?;
        for (i, m) in self.monitors.iter().enumerate() {
            let norm = m.direction.norm();
            if !(norm.is_finite() && (norm - 1.0).abs() < 1e-12) {
                return Err(Error::invalid(
                    format!("output.monitors[{i}].direction"),
                    "must be a unit vector (the case file's is normalised when read)",
                ));
            }
        }
        match &self.method {
            TangentialMethod::Penalty(p) => {
                if !(p.stiffness.is_finite() && p.stiffness > 0.0) {
                    return Err(Error::invalid(
                        "tangential.penalty.stiffness",
                        format!("must be a positive K_T in N/m (got {})", p.stiffness),
                    ));
                }
                if !(p.damping.is_finite() && p.damping >= 0.0) {
                    return Err(Error::invalid(
                        "tangential.penalty.damping",
                        format!("must be a C_T ≥ 0 in N·s/m (got {})", p.damping),
                    ));
                }
            }
            TangentialMethod::GaussSeidel(g) => check_gs(g, "tangential.gauss_seidel")?,
            TangentialMethod::ActiveSet(a) => {
                if a.max_iterations == 0 {
                    return Err(Error::invalid(
                        "tangential.active_set.max_iterations",
                        "must be at least 1",
                    ));
                }
                check_gs(&a.fallback, "tangential.gauss_seidel")?;
            }
        }
        Ok(())
    }
}

fn check_gs(g: &crate::contact::tangential::GaussSeidelSettings, field: &str) -> Result<()> {
    if !(g.tolerance.is_finite() && g.tolerance > 0.0) {
        return Err(Error::invalid(
            format!("{field}.tolerance"),
            format!(
                "must be a positive relative tolerance, e.g. 1e-12 (got {})",
                g.tolerance
            ),
        ));
    }
    if !(g.residual_tolerance.is_finite() && g.residual_tolerance > 0.0) {
        return Err(Error::invalid(
            format!("{field}.residual_tolerance"),
            format!(
                "must be a positive bound on the relative natural-map residual, e.g. 1e-8 \
                 (got {})",
                g.residual_tolerance
            ),
        ));
    }
    if g.max_sweeps == 0 {
        return Err(Error::invalid(
            format!("{field}.max_sweeps"),
            "must be at least 1",
        ));
    }
    Ok(())
}

/// `x` rounded down to 3 significant digits, for the time step suggested to the user.
pub(crate) fn round_down(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let exponent = x.log10().floor() as i32 - 2;
    let digits = (x / 10f64.powi(exponent)).floor();
    // through the decimal text, so that it prints as typed (1.8e-3, not 1.8000000000000002e-3)
    format!("{digits}e{exponent}").parse().unwrap_or(x)
}
