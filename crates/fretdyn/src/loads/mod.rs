//! **Stage 3 — the loads.** What enters: the modal basis and the load sections of a case.
//! What leaves: the modal force `f(t)` the integrator adds at each step (THEORY §8, §10).
//!
//! External loads. Every deterministic load is a fixed modal vector times a scalar history,
//! projected once on the modes: point forces (`f_q(t) = Σ_l s_l(t) Φ_lᵀ F_l`), line loads along
//! a tube (lumped at its nodes, `Σ_i w_i Φ_iᵀ f`), modal forces given directly, and a base
//! acceleration (`f_q = −s(t) Γ A`). Histories: constant, harmonic, sums of sines, tables
//! (interpolated linearly, held at their end values); they are defined here. Random
//! turbulence ([`TurbulentLoad`]) is synthesised by [`turbulence`] with the spatial
//! correlation of [`spatial_correlation`]. See `docs/LOADS.md`.

pub mod flow;
pub mod flow_damping;
pub mod fluid_elastic;
pub mod spatial_correlation;
pub mod stepped;
pub mod turbulence;

use nalgebra::Vector3;

use crate::error::{Error, Result};

/// Time history of a load, multiplying its force vector.
#[derive(Debug, Clone, PartialEq)]
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
    /// `s(t) = Σ_k a_k sin(2π f_k t + φ_k)`.
    Sines(Vec<Sine>),
    /// Piecewise-linear through `(t_k, s_k)`, held at the end values outside the table.
    Table {
        /// Strictly increasing times, s.
        times: Vec<f64>,
        /// Values.
        values: Vec<f64>,
    },
}

/// One term `a sin(2π f t + φ)` of a sum of sines.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sine {
    /// Amplitude `a`.
    pub amplitude: f64,
    /// Frequency `f`, Hz.
    pub frequency_hz: f64,
    /// Phase `φ`, rad.
    pub phase: f64,
}

impl TimeHistory {
    /// Value at time `t`. A harmonic history, the common one, is formed in line (the time
    /// step calls this for every load at every step); the others through a call.
    #[inline(always)]
    pub fn value(&self, t: f64) -> f64 {
        match *self {
            TimeHistory::Harmonic {
                frequency_hz,
                phase,
            } => harmonic(frequency_hz, phase, t),
            _ => self.value_by_call(t),
        }
    }

    /// [`Self::value`] of any history, out of line.
    #[inline(never)]
    fn value_by_call(&self, t: f64) -> f64 {
        match *self {
            TimeHistory::Constant => 1.0,
            TimeHistory::Harmonic {
                frequency_hz,
                phase,
            } => harmonic(frequency_hz, phase, t),
            TimeHistory::Sines(ref terms) => terms
                .iter()
                .map(|s| s.amplitude * (std::f64::consts::TAU * s.frequency_hz * t + s.phase).sin())
                .sum(),
            TimeHistory::Table {
                ref times,
                ref values,
            } => interpolate(times, values, t),
        }
    }

    /// Checks the numbers; `field` names the history in error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        match self {
            TimeHistory::Constant => Ok(()),
            TimeHistory::Harmonic {
                frequency_hz,
                phase,
            } => check_sine(*frequency_hz, *phase, 1.0, field),
            TimeHistory::Sines(terms) => {
                if terms.is_empty() {
                    return Err(Error::invalid(
                        format!("{field}.terms"),
                        "needs at least one [amplitude, frequency_hz, phase_deg] term",
                    ));
                }
                for (k, s) in terms.iter().enumerate() {
                    check_sine(
                        s.frequency_hz,
                        s.phase,
                        s.amplitude,
                        &format!("{field}.terms[{k}]"),
                    )?;
                }
                Ok(())
            }
            TimeHistory::Table { times, values } => check_table(times, values, field),
        }
    }
}

/// `sin(2π f t + φ)`.
#[inline(always)]
fn harmonic(frequency_hz: f64, phase: f64, t: f64) -> f64 {
    (std::f64::consts::TAU * frequency_hz * t + phase).sin()
}

/// Linear interpolation in a table (strictly increasing `times`), held at the ends.
#[inline]
pub fn interpolate(times: &[f64], values: &[f64], t: f64) -> f64 {
    let n = times.len();
    if n == 0 {
        return 0.0;
    }
    if t <= times[0] {
        return values[0];
    }
    if t >= times[n - 1] {
        return values[n - 1];
    }
    // first index with times[k] > t
    let k = times.partition_point(|&x| x <= t);
    let (t0, t1) = (times[k - 1], times[k]);
    values[k - 1] + (values[k] - values[k - 1]) * (t - t0) / (t1 - t0)
}

fn check_sine(frequency_hz: f64, phase: f64, amplitude: f64, field: &str) -> Result<()> {
    if !(frequency_hz.is_finite() && frequency_hz >= 0.0) {
        return Err(Error::invalid(
            format!("{field}.frequency_hz"),
            format!("must be a finite frequency ≥ 0 in Hz (got {frequency_hz})"),
        ));
    }
    if !(phase.is_finite() && amplitude.is_finite()) {
        return Err(Error::invalid(
            field.to_string(),
            "amplitude and phase must be finite numbers",
        ));
    }
    Ok(())
}

/// A table `(t_k, s_k)`: at least 2 rows, times finite and strictly increasing, values finite.
pub fn check_table(times: &[f64], values: &[f64], field: &str) -> Result<()> {
    if times.len() < 2 || times.len() != values.len() {
        return Err(Error::invalid(
            format!("{field}.table"),
            "needs at least 2 rows [t, value]",
        ));
    }
    if let Some(k) = (0..times.len()).find(|&k| {
        !times[k].is_finite() || !values[k].is_finite() || (k > 0 && times[k] <= times[k - 1])
    }) {
        return Err(Error::invalid(
            format!("{field}.table[{k}]"),
            "times must be finite and strictly increasing, values finite",
        ));
    }
    Ok(())
}

/// A generalized force `f_q(t) = s(t) g` given directly on the modes (or built from a line
/// load along a tube).
#[derive(Debug, Clone, PartialEq)]
pub struct ModalLoad {
    /// The modal vector `g` (one value per mode), N (generalized).
    pub row: Vec<f64>,
    /// Time history `s(t)`.
    pub history: TimeHistory,
}

impl ModalLoad {
    /// Validated constructor; `modes` is the size of the basis.
    pub fn new(row: Vec<f64>, history: TimeHistory, modes: usize, field: &str) -> Result<Self> {
        if row.len() != modes {
            return Err(Error::invalid(
                format!("{field}.force"),
                format!("must have one value per mode ({modes}), got {}", row.len()),
            ));
        }
        if let Some(k) = row.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{field}.force[{k}]"),
                "must be a finite number",
            ));
        }
        history.validate(field)?;
        Ok(Self { row, history })
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
/// participation factors ([`crate::structure::modal::ModalBasis::participation`]).
#[derive(Debug, Clone, PartialEq)]
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
    history.validate(field)
}

/// Random turbulence on the modes: `r` independent stationary Gaussian signals `ξ_j(t)` of
/// one-sided PSD `S(f)` ([`crate::loads::turbulence::RandomChannels`], seeded, a pure function of
/// time), each loading the modes along a fixed vector `g_j`: `f_q(t) = Σ_j ξ_j(t) g_j`.
/// For a tube, `g_j = Σ_i L_ij Φ_iᵀ e` with `L` the factor of the spatial correlation
/// ([`crate::loads::spatial_correlation::line_covariance`]) of the nodes along the span, and `e` a
/// direction of the force.
#[derive(Debug, Clone, PartialEq)]
pub struct TurbulentLoad {
    /// PSD of the force per unit length, (N/m)²/Hz.
    pub spectrum: crate::loads::turbulence::Spectrum,
    /// The vectors `g_j`, one row of p per channel (r × p, row-major).
    pub rows: Vec<f64>,
    /// Seed of the signals.
    pub seed: u64,
    /// Band limit of the signals, Hz.
    pub f_max: f64,
}

impl TurbulentLoad {
    /// Number of channels for a basis of `modes` modes.
    pub fn channels(&self, modes: usize) -> usize {
        self.rows.len() / modes.max(1)
    }

    /// Checks the vectors against the basis size and the spectrum.
    pub fn validate(&self, modes: usize, field: &str) -> Result<()> {
        if modes == 0 || self.rows.is_empty() || !self.rows.len().is_multiple_of(modes) {
            return Err(Error::invalid(
                format!("{field}.rows"),
                format!("must hold one row of {modes} values per channel"),
            ));
        }
        if self.rows.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(format!("{field}.rows"), "must be finite"));
        }
        if !(self.f_max.is_finite() && self.f_max > 0.0) {
            return Err(Error::invalid(
                format!("{field}.f_max"),
                format!("must be a positive frequency in Hz (got {})", self.f_max),
            ));
        }
        self.spectrum.validate(&format!("{field}.spectrum"))
    }
}
