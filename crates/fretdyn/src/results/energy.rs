//! The discrete energy balance of a run (THEORY §5): the energy at each step and the work of
//! the powers, summed by the trapezoidal rule; its error measures the scheme.

use serde::Serialize;

use crate::kernels::running_max;

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
