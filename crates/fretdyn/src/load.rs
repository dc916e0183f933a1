//! External loads: point forces with a time history, projected once on the modes
//! (`f_q(t) = Σ_l s_l(t) Φ_lᵀ F_l`).

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
        if let TimeHistory::Harmonic {
            frequency_hz,
            phase,
        } = history
        {
            if !(frequency_hz.is_finite() && frequency_hz >= 0.0 && phase.is_finite()) {
                return Err(Error::invalid(
                    format!("{field}.frequency_hz"),
                    format!("must be a finite frequency ≥ 0 in Hz (got {frequency_hz})"),
                ));
            }
        }
        Ok(Self {
            point,
            force,
            history,
        })
    }
}
