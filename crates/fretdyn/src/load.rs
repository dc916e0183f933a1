//! External loads: point forces with a time history, projected once on the modes
//! (`f_q(t) = Σ_l s_l(t) Φ_lᵀ F_l`), and a base acceleration (`f_q = −s(t) Γ A`).

use nalgebra::Vector3;

use crate::error::{Error, Result};

/// Time history of a load, multiplying its force vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeHistory {
    /// `s(t) = 1`.
    Constant,
    /// `s(t) = sin(2π f t + φ)`.
    Harmonic {
        /// Frequency `f`, Hz.
        frequency_hz: f64,
        /// Phase `φ`, rad.
        phase: f64,
    },
}

impl TimeHistory {
    /// Value at time `t`.
    #[inline]
    pub fn value(&self, t: f64) -> f64 {
        match *self {
            TimeHistory::Constant => 1.0,
            TimeHistory::Harmonic {
                frequency_hz,
                phase,
            } => (std::f64::consts::TAU * frequency_hz * t + phase).sin(),
        }
    }
}

/// A force `F s(t)` applied at a point of the structure.
#[derive(Debug, Clone, PartialEq)]
pub struct PointLoad {
    /// Index of the point in the modal basis.
    pub point: usize,
    /// Force vector `F`, N (global axes).
    pub force: Vector3<f64>,
    /// Time history `s(t)`.
    pub history: TimeHistory,
}

impl PointLoad {
    /// Validated constructor.
    pub fn new(
        point: usize,
        force: Vector3<f64>,
        history: TimeHistory,
        field: &str,
    ) -> Result<Self> {
        if force.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{field}.force"),
                "must be 3 finite numbers, in N",
            ));
        }
        check_history(&history, field)?;
        Ok(Self {
            point,
            force,
            history,
        })
    }
}

/// A uniform acceleration `a(t) = A s(t)` of the supports (the base) of the whole structure:
/// plate vibration, seismic motion. The structure is then described relatively to the base —
/// its displacements, and those of the obstacles attached to the base, are relative — and the
/// base loads the modes with the inertia force `−Γ a(t)`, `Γ = Φᵀ M r` the modal
/// participation factors ([`crate::modal::ModalBasis::participation`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseAcceleration {
    /// Acceleration vector `A`, m/s² (global axes).
    pub acceleration: Vector3<f64>,
    /// Time history `s(t)`.
    pub history: TimeHistory,
}

impl BaseAcceleration {
    /// Validated constructor.
    pub fn new(acceleration: Vector3<f64>, history: TimeHistory, field: &str) -> Result<Self> {
        if acceleration.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{field}.acceleration"),
                "must be 3 finite numbers, in m/s²",
            ));
        }
        check_history(&history, field)?;
        Ok(Self {
            acceleration,
            history,
        })
    }

    /// Modal load per unit `s(t)`: `−Γ A` (p values), from the 3 × p participation factors.
    pub fn modal_row(&self, participation: &[f64]) -> Vec<f64> {
        let p = participation.len() / 3;
        let a = &self.acceleration;
        (0..p)
            .map(|i| {
                -(participation[i] * a.x
                    + participation[p + i] * a.y
                    + participation[2 * p + i] * a.z)
            })
            .collect()
    }
}

fn check_history(history: &TimeHistory, field: &str) -> Result<()> {
    if let TimeHistory::Harmonic {
        frequency_hz,
        phase,
    } = *history
    {
        if !(frequency_hz.is_finite() && frequency_hz >= 0.0 && phase.is_finite()) {
            return Err(Error::invalid(
                format!("{field}.frequency_hz"),
                format!("must be a finite frequency ≥ 0 in Hz (got {frequency_hz})"),
            ));
        }
    }
    Ok(())
}
