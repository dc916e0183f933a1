//! Prescribed motion of an obstacle: a support plate that vibrates, a plate carried by a
//! seismic motion, a bar that slides (THEORY §3, "obstacles may move").
//!
//! The obstacle is translated rigidly by `d(t)`: its geometry is evaluated at `x − d(t)` and
//! its surface moves with `ḋ(t)`. The time loop uses the velocities of its discrete motion,
//! consistent with central differences: the step velocity `(d(t_{n+2}) − d(t_{n+1}))/Δt` is
//! the `v_imp` of the stick constraint on the half-step velocity, and the mean of two step
//! velocities the full-step velocity the slip is measured against (THEORY §2, §4.2, §5;
//! [`Motion::step_velocity`], [`Motion::full_step_velocity`]).

use nalgebra::Vector3;

use crate::error::{Error, Result};

/// Rigid translation `d(t)` of an obstacle.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Motion {
    /// `d = 0`.
    #[default]
    Fixed,
    /// Constant velocity: `d = V t`.
    Velocity(Vector3<f64>),
    /// `d = A sin(2π f t + φ)`.
    Harmonic {
        /// Amplitude `A`, m.
        amplitude: Vector3<f64>,
        /// Frequency `f`, Hz.
        frequency_hz: f64,
        /// Phase `φ`, rad.
        phase: f64,
    },
    /// Piecewise-linear displacement through `(t_k, d_k)` (velocity constant on each
    /// interval), held at the end values outside the table.
    Table {
        /// Strictly increasing times, s.
        times: Vec<f64>,
        /// Displacement at each time, m.
        displacements: Vec<Vector3<f64>>,
    },
}

impl Motion {
    /// Checks the numbers; `field` names the motion in error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        let finite = |v: &Vector3<f64>| v.iter().all(|x| x.is_finite());
        match self {
            Motion::Fixed => Ok(()),
            Motion::Velocity(v) if finite(v) => Ok(()),
            Motion::Velocity(_) => Err(Error::invalid(
                format!("{field}.velocity"),
                "must be 3 finite numbers, in m/s",
            )),
            Motion::Harmonic {
                amplitude,
                frequency_hz,
                phase,
            } => {
                if !finite(amplitude) {
                    return Err(Error::invalid(
                        format!("{field}.amplitude"),
                        "must be 3 finite numbers, in m",
                    ));
                }
                if !(frequency_hz.is_finite() && *frequency_hz >= 0.0 && phase.is_finite()) {
                    return Err(Error::invalid(
                        format!("{field}.frequency_hz"),
                        format!("must be a finite frequency ≥ 0 in Hz (got {frequency_hz})"),
                    ));
                }
                Ok(())
            }
            Motion::Table {
                times,
                displacements,
            } => {
                if times.len() < 2 || times.len() != displacements.len() {
                    return Err(Error::invalid(
                        format!("{field}.table"),
                        "needs at least 2 rows [t, dx, dy, dz]",
                    ));
                }
                if let Some(k) =
                    (1..times.len()).find(|&k| !(times[k].is_finite() && times[k] > times[k - 1]))
                {
                    return Err(Error::invalid(
                        format!("{field}.table[{k}]"),
                        format!(
                            "times must be finite and strictly increasing (got {} after {})",
                            times[k],
                            times[k - 1]
                        ),
                    ));
                }
                if let Some(k) = displacements.iter().position(|d| !finite(d)) {
                    return Err(Error::invalid(
                        format!("{field}.table[{k}]"),
                        "displacements must be finite numbers, in m",
                    ));
                }
                Ok(())
            }
        }
    }

    /// True for an obstacle that never moves.
    #[inline]
    pub fn is_fixed(&self) -> bool {
        matches!(self, Motion::Fixed)
    }

    /// Velocity that carries a point with the obstacle from step `k` to step `k + 1`:
    /// `(d(t_{k+1}) − d(t_k))/Δt` with `t_k = kΔt` computed as the time loop computes it, so
    /// that the imposed velocities of successive steps telescope and a point sticking on the
    /// obstacle keeps its place on it (THEORY §2: the stick constraint acts on the half-step
    /// velocity `v_{n+3/2}`, which moves the positions from `t_{n+1}` to `t_{n+2}`).
    #[inline]
    pub fn step_velocity(&self, k: u64, dt: f64) -> Vector3<f64> {
        match self {
            Motion::Fixed => Vector3::zeros(),
            _ => (self.at((k + 1) as f64 * dt).0 - self.at(k as f64 * dt).0) / dt,
        }
    }

    /// The obstacle's full-step velocity at step `n` (time `t_n = nΔt`): the mean of
    /// the two step velocities around it, `½ (v_{n−½} + v_{n+½})` ([`Self::step_velocity`]),
    /// i.e. the central difference `(d(t_{n+1}) − d(t_{n−1}))/(2Δt)`. The structure's
    /// full-step velocity is the same mean of its half-step velocities,
    /// `q̇_n = ½ (v_{n−½} + v_{n+½}) = (q_{n+1} − q_{n−1})/(2Δt)` (THEORY §2), so the
    /// difference of the two is the central difference of the position relative to the
    /// obstacle: the slip velocity and the friction power (THEORY §5) are measured on it,
    /// and it is exactly zero (up to round-off) when both half-step velocities were held to
    /// the obstacle's. `ḋ(t_n)` differs from it by `O(Δt²)`. At `n = 0` (the initial
    /// velocity is given, not a difference of positions) it is `ḋ(0)`.
    #[inline]
    pub fn full_step_velocity(&self, n: u64, dt: f64) -> Vector3<f64> {
        match (self, n) {
            (Motion::Fixed, _) => Vector3::zeros(),
            (_, 0) => self.at(0.0).1,
            _ => 0.5 * (self.step_velocity(n - 1, dt) + self.step_velocity(n, dt)),
        }
    }

    /// Displacement `d(t)` and velocity `ḋ(t)`.
    #[inline]
    pub fn at(&self, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        match self {
            Motion::Fixed => (Vector3::zeros(), Vector3::zeros()),
            Motion::Velocity(v) => (v * t, *v),
            Motion::Harmonic {
                amplitude,
                frequency_hz,
                phase,
            } => {
                let w = std::f64::consts::TAU * frequency_hz;
                let a = w * t + phase;
                (amplitude * a.sin(), amplitude * (w * a.cos()))
            }
            Motion::Table {
                times,
                displacements,
            } => {
                let last = times.len() - 1;
                if t <= times[0] {
                    return (displacements[0], Vector3::zeros());
                }
                if t >= times[last] {
                    return (displacements[last], Vector3::zeros());
                }
                // first k with times[k] > t; 1 ≤ k ≤ last
                let k = times.partition_point(|&tk| tk <= t);
                let (t0, t1) = (times[k - 1], times[k]);
                let v = (displacements[k] - displacements[k - 1]) / (t1 - t0);
                (displacements[k - 1] + v * (t - t0), v)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn harmonic_velocity_is_the_derivative_of_the_displacement() {
        let m = Motion::Harmonic {
            amplitude: Vector3::new(1e-3, -2e-3, 0.5e-3),
            frequency_hz: 7.0,
            phase: 0.3,
        };
        let (t, h) = (0.0123, 1e-6);
        let d = (m.at(t + h).0 - m.at(t - h).0) / (2.0 * h);
        assert!((d - m.at(t).1).norm() < 1e-8 * m.at(t).1.norm());
    }

    #[test]
    fn table_interpolates_linearly_and_holds_its_ends() {
        let m = Motion::Table {
            times: vec![0.0, 1.0, 3.0],
            displacements: vec![Vector3::zeros(), Vector3::x(), Vector3::new(1.0, 4.0, 0.0)],
        };
        assert!(m.validate("m").is_ok());
        let (d, v) = m.at(2.0);
        assert_eq!(
            (d, v),
            (Vector3::new(1.0, 2.0, 0.0), Vector3::new(0.0, 2.0, 0.0))
        );
        assert_eq!(m.at(5.0), (Vector3::new(1.0, 4.0, 0.0), Vector3::zeros()));
        assert_eq!(m.at(-1.0), (Vector3::zeros(), Vector3::zeros()));
        let bad = Motion::Table {
            times: vec![0.0, 0.0],
            displacements: vec![Vector3::zeros(); 2],
        };
        assert!(bad.validate("m").is_err());
    }
}
