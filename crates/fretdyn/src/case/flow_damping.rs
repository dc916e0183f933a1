//! `[flow.damping]`: the damping models the Connors check adds to the basis's damping
//! (docs/FLOW.md, "Damping models"; `loads/flow_damping.rs`).

use serde::Deserialize;

use crate::error::{Error, Result, number};
use crate::loads::flow_damping::{DampingModels, SqueezeFilm, ViscousDamping};

/// `[flow.damping]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DampingSection {
    viscous: Option<ViscousInput>,
    /// `ζ_TP`.
    two_phase: Option<f64>,
    /// `ζ_F`.
    friction: Option<f64>,
    squeeze_film: Option<SqueezeFilmInput>,
    #[serde(default)]
    in_run: bool,
}

/// `viscous = { density, kinematic_viscosity, confinement }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ViscousInput {
    density: f64,
    kinematic_viscosity: f64,
    /// `D_e / D`; absent: unconfined.
    confinement: Option<f64>,
}

/// `squeeze_film = { ratio, frequency }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SqueezeFilmInput {
    ratio: f64,
    frequency: f64,
}

/// `v` if it is finite and > 0 (≥ 0 with `zero`), else the error on `flow.damping.<key>`.
fn checked(v: f64, key: &str, what: &str, zero: bool) -> Result<f64> {
    if v.is_finite() && (v > 0.0 || (zero && v == 0.0)) {
        Ok(v)
    } else {
        Err(Error::invalid(
            format!("flow.damping.{key}"),
            format!("must be {what} (got {})", number(v)),
        ))
    }
}

impl DampingSection {
    pub(super) fn build(&self) -> Result<DampingModels> {
        let ratio = |v: Option<f64>, key: &str| -> Result<Option<f64>> {
            v.map(|v| checked(v, key, "a damping ratio ≥ 0 (0.01 is 1 %)", true))
                .transpose()
        };
        let viscous = match &self.viscous {
            Some(v) => Some(ViscousDamping {
                density: checked(
                    v.density,
                    "viscous.density",
                    "the liquid's density > 0 in kg/m³",
                    false,
                )?,
                kinematic_viscosity: checked(
                    v.kinematic_viscosity,
                    "viscous.kinematic_viscosity",
                    "the liquid's kinematic viscosity > 0 in m²/s (water at 280 °C: about 1.2e-7)",
                    false,
                )?,
                confinement: match v.confinement {
                    Some(c) if c.is_finite() && c > 1.0 => c,
                    Some(c) => {
                        return Err(Error::invalid(
                            "flow.damping.viscous.confinement",
                            format!(
                                "must be D_e/D > 1, the equivalent confinement diameter over the tube's (got {}); leave it out for an unconfined tube",
                                number(c)
                            ),
                        ));
                    }
                    None => f64::INFINITY,
                },
            }),
            None => None,
        };
        let squeeze_film = match &self.squeeze_film {
            Some(s) => Some(SqueezeFilm {
                ratio: checked(
                    s.ratio,
                    "squeeze_film.ratio",
                    "a damping ratio ≥ 0 at the reference frequency",
                    true,
                )?,
                frequency_hz: checked(
                    s.frequency,
                    "squeeze_film.frequency",
                    "the reference frequency > 0 in Hz of the ratio",
                    false,
                )?,
            }),
            None => None,
        };
        Ok(DampingModels {
            viscous,
            two_phase: ratio(self.two_phase, "two_phase")?,
            friction: ratio(self.friction, "friction")?,
            squeeze_film,
            in_run: self.in_run,
            structural: None,
        })
    }
}
