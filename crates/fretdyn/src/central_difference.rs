//! Explicit central differences on the modal coordinates (THEORY §2).
//!
//! With `A = I + (Δt/2) C_m` (diagonal: modal damping `C_m = diag(2 ξ_i ω_i)`), one step is
//!
//! ```text
//! 1. q_{n+1} = q_n + Δt q̇_n + (Δt²/2) q̈_n
//! 2. q̇*      = q̇_n + (Δt/2) q̈_n                      (predicted velocity)
//! 5. q̈_free  = A⁻¹ (f(t_{n+1}) − Ω² q_{n+1} − C_m q̇*)
//! 6. q̈_{n+1} = q̈_free − A⁻¹ Lᵀ λ                      (Lagrange methods only)
//! 7. q̇_{n+1} = q̇* + (Δt/2) q̈_{n+1}
//! ```
//!
//! Steps 3, 4 and 6 (contacts) are done by the caller between [`predict`](CentralDifference::predict)
//! and [`correct`](CentralDifference::correct). Damping enters through `A` so that it acts on
//! `q̇_{n+1}`: the scheme is Newmark (β = 0, γ = ½), stable for `Δt < 2/ω_max` with any damping.

use crate::modal::ModalBasis;

/// State and constants of the integrator.
#[derive(Debug, Clone)]
pub struct CentralDifference {
    /// Time step Δt, s.
    pub dt: f64,
    omega2: Vec<f64>,
    damping: Vec<f64>,
    /// Diagonal of `A⁻¹`.
    pub a_inv: Vec<f64>,
    /// Modal displacements `q_n`.
    pub q: Vec<f64>,
    /// Modal velocities `q̇_n` (full step).
    pub qd: Vec<f64>,
    /// Modal accelerations `q̈_n`.
    pub qdd: Vec<f64>,
    /// Predicted velocity `q̇*` of the current step.
    pub qd_star: Vec<f64>,
}

impl CentralDifference {
    /// Integrator for `basis` at rest; set `q`, `qd` then call [`start`](Self::start).
    pub fn new(basis: &ModalBasis, dt: f64) -> Self {
        let p = basis.modes();
        let omega2: Vec<f64> = basis.omega.iter().map(|w| w * w).collect();
        let damping: Vec<f64> = basis
            .omega
            .iter()
            .zip(&basis.damping_ratio)
            .map(|(w, xi)| 2.0 * xi * w)
            .collect();
        let a_inv = damping.iter().map(|c| 1.0 / (1.0 + 0.5 * dt * c)).collect();
        Self {
            dt,
            omega2,
            damping,
            a_inv,
            q: vec![0.0; p],
            qd: vec![0.0; p],
            qdd: vec![0.0; p],
            qd_star: vec![0.0; p],
        }
    }

    /// Initial acceleration `q̈_0 = f_0 − Ω² q_0 − C_m q̇_0` from the modal force at t = 0.
    pub fn start(&mut self, force: &[f64]) {
        for i in 0..self.q.len() {
            self.qdd[i] = force[i] - self.omega2[i] * self.q[i] - self.damping[i] * self.qd[i];
        }
    }

    /// Steps 1–2: positions at `n+1` and predicted velocity.
    #[inline]
    pub fn predict(&mut self) {
        let dt = self.dt;
        let h = 0.5 * dt;
        for i in 0..self.q.len() {
            self.q[i] += dt * self.qd[i] + h * dt * self.qdd[i];
            self.qd_star[i] = self.qd[i] + h * self.qdd[i];
        }
    }

    /// Step 5: `q̈_free = A⁻¹ (f − Ω² q − C_m q̇*)`, written to `self.qdd`.
    #[inline]
    pub fn free_acceleration(&mut self, force: &[f64]) {
        for i in 0..self.q.len() {
            self.qdd[i] = self.a_inv[i]
                * (force[i] - self.omega2[i] * self.q[i] - self.damping[i] * self.qd_star[i]);
        }
    }

    /// Step 7: full-step velocity.
    #[inline]
    pub fn correct(&mut self) {
        let h = 0.5 * self.dt;
        for i in 0..self.q.len() {
            self.qd[i] = self.qd_star[i] + h * self.qdd[i];
        }
    }

    /// Kinetic plus strain energy `½ q̇ᵀq̇ + ½ qᵀΩ²q`.
    #[inline]
    pub fn modal_energy(&self) -> f64 {
        let mut e = 0.0;
        for i in 0..self.q.len() {
            e += self.qd[i] * self.qd[i] + self.omega2[i] * self.q[i] * self.q[i];
        }
        0.5 * e
    }

    /// Power dissipated by modal damping, `q̇ᵀ C_m q̇`.
    #[inline]
    pub fn damping_power(&self) -> f64 {
        self.qd
            .iter()
            .zip(&self.damping)
            .map(|(v, c)| c * v * v)
            .sum()
    }
}
