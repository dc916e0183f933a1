//! Statistics accumulated at every step (not only at output samples): per-contact wear and
//! force statistics (THEORY §5) and the discrete energy balance.

use serde::Serialize;

/// Running sums of one contact.
#[derive(Debug, Clone, Default)]
pub struct ContactAccumulator {
    impacts: u64,
    contact_steps: u64,
    stick_steps: u64,
    slip_steps: u64,
    normal_sum: f64,
    normal_sq_sum: f64,
    normal_max: f64,
    tangential_sum: f64,
    tangential_max: f64,
    wear_work: f64,
    penetration_max: f64,
    was_closed: bool,
}

impl ContactAccumulator {
    /// Adds one step of duration `dt`. `friction_power` is `|R_T · v_T|` with the full-step
    /// tangential velocity (THEORY §2, §5).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn add(
        &mut self,
        closed: bool,
        stick: bool,
        normal: f64,
        tangential: f64,
        friction_power: f64,
        penetration: f64,
        dt: f64,
    ) {
        if closed {
            if !self.was_closed {
                self.impacts += 1;
            }
            self.contact_steps += 1;
            if stick {
                self.stick_steps += 1;
            } else {
                self.slip_steps += 1;
            }
            self.normal_sum += normal;
            self.normal_sq_sum += normal * normal;
            self.normal_max = self.normal_max.max(normal);
            self.tangential_sum += tangential;
            self.tangential_max = self.tangential_max.max(tangential);
            self.wear_work += friction_power * dt;
            self.penetration_max = self.penetration_max.max(penetration);
        }
        self.was_closed = closed;
    }

    /// Statistics over `steps` steps of `dt`.
    pub fn finish(&self, name: &str, steps: u64, dt: f64) -> ContactStatistics {
        let n = steps.max(1) as f64;
        let duration = steps as f64 * dt;
        ContactStatistics {
            name: name.to_string(),
            impacts: self.impacts,
            contact_time_fraction: self.contact_steps as f64 / n,
            stick_time_fraction: self.stick_steps as f64 / n,
            slip_time_fraction: self.slip_steps as f64 / n,
            normal_force_mean: self.normal_sum / n,
            normal_force_rms: (self.normal_sq_sum / n).sqrt(),
            normal_force_max: self.normal_max,
            tangential_force_mean: self.tangential_sum / n,
            tangential_force_max: self.tangential_max,
            wear_work: self.wear_work,
            wear_work_rate: if duration > 0.0 {
                self.wear_work / duration
            } else {
                0.0
            },
            penetration_max: self.penetration_max,
        }
    }
}

/// Per-contact statistics of a run (THEORY §5). Means and fractions are over the whole run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactStatistics {
    /// Contact name.
    pub name: String,
    /// Number of open → closed transitions.
    pub impacts: u64,
    /// Fraction of the run spent closed.
    pub contact_time_fraction: f64,
    /// Fraction of the run spent closed and sticking.
    pub stick_time_fraction: f64,
    /// Fraction of the run spent closed and sliding.
    pub slip_time_fraction: f64,
    /// Mean normal force over the whole run, N.
    pub normal_force_mean: f64,
    /// RMS normal force over the whole run, N.
    pub normal_force_rms: f64,
    /// Largest normal force, N.
    pub normal_force_max: f64,
    /// Mean tangential force magnitude over the whole run, N.
    pub tangential_force_mean: f64,
    /// Largest tangential force magnitude, N.
    pub tangential_force_max: f64,
    /// Friction work `∫|R_T · v_T| dt`, J.
    pub wear_work: f64,
    /// Wear work rate `(1/T)∫|R_T · v_T| dt`, W.
    pub wear_work_rate: f64,
    /// Largest penetration, m.
    pub penetration_max: f64,
}

/// Discrete energy balance: `E(t) − E(0) − W_ext + D`, with `E` kinetic + strain + normal
/// penalty potential, `W_ext` the work of external loads and `D` the energy dissipated by
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
    /// Largest `|E − E(0) − W_ext + D|` over the run divided by the largest energy scale
    /// `max(E, E(0) + |W_ext|)` seen.
    pub relative_error: f64,
    #[serde(skip)]
    scale: f64,
    #[serde(skip)]
    max_abs: f64,
    #[serde(skip)]
    last_powers: [f64; 4],
}

impl EnergyBalance {
    /// Starts the balance with energy `e0` and powers `[external, modal damping, contact
    /// damping, tangential]` at t = 0.
    pub fn start(e0: f64, powers: [f64; 4]) -> Self {
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
    pub fn step(&mut self, e: f64, powers: [f64; 4], dt: f64) {
        let h = 0.5 * dt;
        self.external_work += h * (self.last_powers[0] + powers[0]);
        self.modal_damping += h * (self.last_powers[1] + powers[1]);
        self.contact_damping += h * (self.last_powers[2] + powers[2]);
        self.tangential += h * (self.last_powers[3] + powers[3]);
        self.last_powers = powers;
        self.last = e;
        let residual = self.residual();
        self.max_abs = self.max_abs.max(residual.abs());
        self.scale = self
            .scale
            .max(e.abs())
            .max(self.initial.abs() + self.external_work.abs());
        self.relative_error = if self.scale > 0.0 {
            self.max_abs / self.scale
        } else {
            0.0
        };
    }

    /// `E − E(0) − W_ext + D` now, J.
    pub fn residual(&self) -> f64 {
        self.last - self.initial - self.external_work
            + self.modal_damping
            + self.contact_damping
            + self.tangential
    }
}
