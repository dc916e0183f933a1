//! The discrete energy balance of a run (THEORY §5): the energy at each step and the work of
//! the powers, summed by the trapezoidal rule; its error measures the scheme.

use serde::Serialize;

use crate::error::number;
use crate::numerics::running_max;

/// Relative error of the energy balance ([`EnergyBalance::relative_error`]) above which a run
/// is worth a warning: 1 %, about what 15 steps per impact give (VERIFICATION.md "Steps per
/// impact"), and a bias of that size on the energy the contacts exchange, hence on their
/// impact forces and wear.
pub const MAX_RELATIVE_ERROR: f64 = 0.01;

/// The time step that should bring the relative error of the energy balance `energy`
/// (settled, [`EnergyBalance::settle`]) of a run of time step `dt` to half
/// [`MAX_RELATIVE_ERROR`], when its error exceeds that: central differences are of order 2,
/// and so is the balance's error on impacts (measured, VERIFICATION.md "Steps per impact"),
/// so that `Δt √(0.5 %/error)` does (rounded down to two digits). `None` when the error is
/// at most [`MAX_RELATIVE_ERROR`].
pub fn energy_time_step(energy: &EnergyBalance, dt: f64) -> Option<f64> {
    let error = energy.relative_error;
    (error > MAX_RELATIVE_ERROR)
        .then(|| round_down(dt * (0.5 * MAX_RELATIVE_ERROR / error).sqrt(), |_| true))
}

/// The warning on a run's energy balance `energy` (settled) when its relative error exceeds
/// [`MAX_RELATIVE_ERROR`], with the time step of [`energy_time_step`]; `dt` is the run's time
/// step. One line, or none.
pub fn energy_warnings(energy: &EnergyBalance, dt: f64) -> Vec<String> {
    let Some(suggested) = energy_time_step(energy, dt) else {
        return Vec::new();
    };
    vec![format!(
        "the energy balance errs by {:.2} % of the largest energy (energy_balance.relative_error in summary.json, above {} %): time.dt = {} s is too coarse for the motion, its impacts most likely; the error falls as Δt², and time.dt = {} s should bring it to about {} % (THEORY §5)",
        100.0 * energy.relative_error,
        number(100.0 * MAX_RELATIVE_ERROR),
        number(dt),
        number(suggested),
        number(50.0 * MAX_RELATIVE_ERROR)
    )]
}

/// Discrete energy balance: `E(t) − E(0) − W_ext − W_fe + D`, with `E` kinetic + strain +
/// normal penalty potential, `W_ext` the work of external loads, `W_fe` the work of the
/// fluid-elastic forces and `D` the energy dissipated by
/// modal damping, normal contact damping and the tangential forces (trapezoidal rule on the
/// powers at full-step velocities).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct EnergyBalance {
    /// Initial energy, J.
    pub initial: f64,
    /// Final energy, J.
    pub last: f64,
    /// Work of the external loads, J.
    pub external_work: f64,
    /// Energy dissipated by modal damping, J.
    pub modal_damping: f64,
    /// Energy dissipated by normal contact damping, J.
    pub contact_damping: f64,
    /// Work done against the tangential contact forces, J (friction dissipation, plus the
    /// energy momentarily stored in tangential penalty springs).
    pub tangential: f64,
    /// Work of the fluid-elastic forces on the structure, J: the energy the flow feeds in
    /// (negative when the flow damps the motion; THEORY §13). Not part of `external_work`.
    pub fluid_work: f64,
    /// Largest `|E − E(0) − W_ext − W_fe + D|` over the run divided by the largest energy
    /// scale `max(E, E(0) + |W_ext| + |W_fe|)` seen.
    pub relative_error: f64,
    #[serde(skip)]
    scale: f64,
    #[serde(skip)]
    max_abs: f64,
    #[serde(skip)]
    last_powers: [f64; 5],
}

/// Every number of an [`EnergyBalance`], for checkpoints.
pub(crate) type EnergyRaw = [f64; 16];

impl EnergyBalance {
    /// Starts the balance with energy `e0` and powers `[external, modal damping, contact
    /// damping, tangential, fluid-elastic]` at t = 0.
    pub fn start(e0: f64, powers: [f64; 5]) -> Self {
        Self {
            initial: e0,
            last: e0,
            scale: e0.abs(),
            last_powers: powers,
            ..Self::default()
        }
    }

    /// Adds one step of duration `dt` ending with energy `e` and `powers`.
    #[inline]
    pub fn step(&mut self, e: f64, powers: [f64; 5], dt: f64) {
        let h = 0.5 * dt;
        self.external_work += h * (self.last_powers[0] + powers[0]);
        self.modal_damping += h * (self.last_powers[1] + powers[1]);
        self.contact_damping += h * (self.last_powers[2] + powers[2]);
        self.tangential += h * (self.last_powers[3] + powers[3]);
        self.fluid_work += h * (self.last_powers[4] + powers[4]);
        self.last_powers = powers;
        self.last = e;
        let residual = self.residual();
        // the running maximum starts at 0 and skips a NaN residual
        self.max_abs = running_max(self.max_abs, residual.abs());
        // (running maxima: the scale starts at |E(0)| and the step's values are never NaN — a
        // step whose energy or powers are not finite has diverged before it is added)
        let work = self.initial.abs() + self.external_work.abs() + self.fluid_work.abs();
        self.scale = running_max(running_max(self.scale, e.abs()), work);
    }

    /// Sets [`Self::relative_error`] from the running maxima (once, when the balance is
    /// read: not at every step).
    pub fn settle(&mut self) {
        self.relative_error = if self.scale > 0.0 {
            self.max_abs / self.scale
        } else {
            0.0
        };
    }

    pub(crate) fn raw(&self) -> EnergyRaw {
        let p = self.last_powers;
        [
            self.initial,
            self.last,
            self.external_work,
            self.modal_damping,
            self.contact_damping,
            self.tangential,
            self.relative_error,
            self.scale,
            self.max_abs,
            p[0],
            p[1],
            p[2],
            p[3],
            0.0,
            self.fluid_work,
            p[4],
        ]
    }

    pub(crate) fn from_raw(r: &EnergyRaw) -> Self {
        Self {
            initial: r[0],
            last: r[1],
            external_work: r[2],
            modal_damping: r[3],
            contact_damping: r[4],
            tangential: r[5],
            relative_error: r[6],
            scale: r[7],
            max_abs: r[8],
            fluid_work: r[14],
            last_powers: [r[9], r[10], r[11], r[12], r[15]],
        }
    }

    /// `E − E(0) − W_ext − W_fe + D` now, J.
    pub fn residual(&self) -> f64 {
        self.last - self.initial - self.external_work - self.fluid_work
            + self.modal_damping
            + self.contact_damping
            + self.tangential
    }
}

/// `x` rounded down to two significant digits, lowered by a unit of the second digit until
/// `fits` holds (so that a round-off of the division cannot make it fail); `x` itself when
/// it is not a positive finite number.
pub(crate) fn round_down(x: f64, fits: impl Fn(f64) -> bool) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return x;
    }
    // x = k / scale with 10 ≤ k < 100: the division by a power of ten gives the double
    // nearest to the decimal number
    let exponent = 1 - x.log10().floor() as i32;
    let scale = 10f64.powi(exponent);
    let mut k = (x * scale).floor();
    while k > 1.0 && !(k / scale <= x && fits(k / scale)) {
        k -= 1.0;
    }
    k / scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_down_keeps_two_digits_and_the_condition() {
        assert_eq!(round_down(1.4567e-5, |_| true), 1.4e-5);
        assert_eq!(round_down(9.99, |_| true), 9.9);
        assert_eq!(round_down(0.3, |_| true), 0.3);
        assert_eq!(round_down(1.4e-5, |dt| dt < 1.4e-5), 1.3e-5);
        assert!(round_down(f64::NAN, |_| true).is_nan());
    }
}
