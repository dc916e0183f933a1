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
//!
//! The same steps run on physical coordinates (`A = M + (Δt/2) C`, dense) for the reference
//! solver of [`Coordinates::Physical`]: with every mode kept the two give the same motion.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::model::{Coordinates, Model};
use crate::numerics::{Lanes, Portable};

/// The linear operators of the coordinates.
#[derive(Debug, Clone)]
enum Operators {
    /// Modal: `M = I`, `K = diag(ω²)`, `C = diag(2ξω)`, `A⁻¹` diagonal.
    Modal {
        omega2: Vec<f64>,
        damping: Vec<f64>,
        a_inv: Vec<f64>,
    },
    /// Physical: dense `M`, `C`, `K`, `A⁻¹` and `M⁻¹`.
    Dense {
        mass: DMatrix<f64>,
        damping: DMatrix<f64>,
        stiffness: DMatrix<f64>,
        a_inv: DMatrix<f64>,
        m_inv: DMatrix<f64>,
        work: DVector<f64>,
    },
}

/// The modal state a step carries to the next: `q_n`, `q̇_n`, `q̈_n` (part of a run's
/// checkpointed state, [`crate::integrator::simulation::State`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModalState {
    /// Displacements `q_n`.
    pub q: Vec<f64>,
    /// Velocities `q̇_n` (full step).
    pub qd: Vec<f64>,
    /// Accelerations `q̈_n`.
    pub qdd: Vec<f64>,
}

impl ModalState {
    /// The state `q`, `q̇` with a zero acceleration (set by [`CentralDifference::start`]).
    pub fn new(q: &[f64], qd: &[f64]) -> Self {
        Self {
            q: q.to_vec(),
            qd: qd.to_vec(),
            qdd: vec![0.0; q.len()],
        }
    }
}

/// The constants of the integrator and the predicted velocity of the step under way; the
/// state it advances ([`ModalState`]) is passed to each phase.
#[derive(Debug, Clone)]
pub struct CentralDifference {
    /// Time step Δt, s.
    pub dt: f64,
    operators: Operators,
    /// Predicted velocity `q̇*` of the current step.
    pub qd_star: Vec<f64>,
}

impl CentralDifference {
    /// Integrator for `model`; a [`ModalState`] set to the initial `q`, `q̇` then goes to
    /// [`start`](Self::start). The model must have been validated (a physical mass matrix is
    /// then positive definite).
    pub fn new(model: &Model, dt: f64) -> Self {
        let basis = &model.basis;
        let p = basis.modes();
        let operators = match &model.coordinates {
            Coordinates::Modal => {
                let damping: Vec<f64> = basis
                    .omega
                    .iter()
                    .zip(&basis.damping_ratio)
                    .map(|(w, xi)| 2.0 * xi * w)
                    .collect();
                Operators::Modal {
                    omega2: basis.omega.iter().map(|w| w * w).collect(),
                    a_inv: damping.iter().map(|c| 1.0 / (1.0 + 0.5 * dt * c)).collect(),
                    damping,
                }
            }
            Coordinates::Physical(m) => {
                let a = &m.mass + &m.damping * (0.5 * dt);
                let inverse = |x: DMatrix<f64>| {
                    x.cholesky()
                        .map(|c| c.inverse())
                        .unwrap_or_else(|| DMatrix::zeros(p, p))
                };
                Operators::Dense {
                    a_inv: inverse(a),
                    m_inv: inverse(m.mass.clone()),
                    mass: m.mass.clone(),
                    damping: m.damping.clone(),
                    stiffness: m.stiffness.clone(),
                    work: DVector::zeros(p),
                }
            }
        };
        Self {
            dt,
            operators,
            qd_star: vec![0.0; p],
        }
    }

    /// Initial acceleration `q̈_0 = M⁻¹ (f_0 − K q_0 − C q̇_0)` from the force at t = 0.
    pub fn start(&mut self, x: &mut ModalState, force: &[f64]) {
        match &mut self.operators {
            Operators::Modal {
                omega2, damping, ..
            } => {
                for i in 0..x.q.len() {
                    x.qdd[i] = force[i] - omega2[i] * x.q[i] - damping[i] * x.qd[i];
                }
            }
            Operators::Dense {
                damping,
                stiffness,
                m_inv,
                work,
                ..
            } => {
                residual(force, stiffness, &x.q, damping, &x.qd, work);
                mat_vec(m_inv, work.as_slice(), &mut x.qdd);
            }
        }
    }

    /// Steps 1–2: positions at `n+1` and predicted velocity.
    #[inline(always)]
    pub fn predict(&mut self, x: &mut ModalState) {
        self.predict_with::<Portable>(x)
    }

    /// [`Self::predict`] with the kernels `K` ([`crate::kernels`]): `q += Δt q̇ + ½Δt² q̈`,
    /// `q̇* = q̇ + ½Δt q̈`.
    #[inline(always)]
    pub(crate) fn predict_with<K: Lanes>(&mut self, x: &mut ModalState) {
        let dt = self.dt;
        K::predict(&mut x.q, &mut self.qd_star, &x.qd, &x.qdd, dt, 0.5 * dt);
    }

    /// [`Self::predict_with`] and, in the same pass, `f = s g` (the first load's modal force).
    #[inline(always)]
    pub(crate) fn predict_and_scale_with<K: Lanes>(
        &mut self,
        x: &mut ModalState,
        f: &mut [f64],
        s: f64,
        g: &[f64],
    ) {
        let dt = self.dt;
        K::predict_and_scale(
            &mut x.q,
            &mut self.qd_star,
            &x.qd,
            &x.qdd,
            dt,
            0.5 * dt,
            f,
            s,
            g,
        );
    }

    /// Step 5: `q̈_free = A⁻¹ (f − K q − C q̇*)`, written to `x.qdd`.
    #[inline(always)]
    pub fn free_acceleration(&mut self, x: &mut ModalState, force: &[f64]) {
        self.free_acceleration_with::<Portable>(x, force)
    }

    /// [`Self::free_acceleration`] with the kernels `K` ([`crate::kernels`]).
    #[inline(always)]
    pub(crate) fn free_acceleration_with<K: Lanes>(&mut self, x: &mut ModalState, force: &[f64]) {
        match &mut self.operators {
            Operators::Modal {
                omega2,
                damping,
                a_inv,
            } => {
                K::free_acceleration(
                    &mut x.qdd,
                    a_inv,
                    force,
                    omega2,
                    &x.q,
                    damping,
                    &self.qd_star,
                );
            }
            Operators::Dense {
                damping,
                stiffness,
                a_inv,
                work,
                ..
            } => {
                residual(force, stiffness, &x.q, damping, &self.qd_star, work);
                mat_vec(a_inv, work.as_slice(), &mut x.qdd);
            }
        }
    }

    /// [`Self::free_acceleration_with`] of the force `force + s row` without forming it
    /// ([`Lanes::free_acceleration_plus`], the same bits); `false`, with nothing done, for
    /// dense operators (the caller then forms the force).
    #[inline(always)]
    pub(crate) fn free_acceleration_plus_with<K: Lanes>(
        &mut self,
        x: &mut ModalState,
        force: &[f64],
        s: f64,
        row: &[f64],
    ) -> bool {
        match &self.operators {
            Operators::Modal {
                omega2,
                damping,
                a_inv,
            } => {
                K::free_acceleration_plus(
                    &mut x.qdd,
                    a_inv,
                    force,
                    s,
                    row,
                    omega2,
                    &x.q,
                    damping,
                    &self.qd_star,
                );
                true
            }
            Operators::Dense { .. } => false,
        }
    }

    /// `out = A⁻¹ l`: how a force `l` on the coordinates changes the acceleration.
    #[inline]
    pub fn apply_a_inv(&self, l: &[f64], out: &mut [f64]) {
        match &self.operators {
            Operators::Modal { a_inv, .. } => {
                for ((o, a), l) in out.iter_mut().zip(a_inv).zip(l) {
                    *o = a * l;
                }
            }
            Operators::Dense { a_inv, .. } => mat_vec(a_inv, l, out),
        }
    }

    /// Step 7: full-step velocity; returns, computed in the same pass,
    /// [`Self::energy_and_powers`] of the new state with the modal force `f`.
    #[inline(always)]
    pub fn correct(&mut self, x: &mut ModalState, f: &[f64]) -> (f64, f64, f64) {
        self.correct_with::<Portable>(x, f)
    }

    /// [`Self::correct`] with the reduction kernels `K` ([`crate::kernels`]).
    #[inline(always)]
    pub(crate) fn correct_with<K: Lanes>(
        &mut self,
        x: &mut ModalState,
        f: &[f64],
    ) -> (f64, f64, f64) {
        let h = 0.5 * self.dt;
        let Operators::Modal {
            omega2, damping, ..
        } = &self.operators
        else {
            for (v, (vs, a)) in x.qd.iter_mut().zip(self.qd_star.iter().zip(&x.qdd)) {
                *v = vs + h * a;
            }
            return self.energy_and_powers(x, f);
        };
        K::correct_with_energy(
            &mut x.qd,
            &self.qd_star,
            &x.qdd,
            h,
            &x.q,
            omega2,
            damping,
            f,
        )
    }

    /// In one pass over the modes: the kinetic plus strain energy `½ q̇ᵀMq̇ + ½ qᵀKq`, the
    /// power dissipated by damping `q̇ᵀ C q̇`, and the power `fᵀq̇` of the modal force `f`
    /// (THEORY §5, the energy balance).
    #[inline]
    pub fn energy_and_powers(&self, x: &ModalState, f: &[f64]) -> (f64, f64, f64) {
        match &self.operators {
            Operators::Modal {
                omega2, damping, ..
            } => crate::numerics::energy_sums(&x.qd, &x.q, omega2, damping, f),
            Operators::Dense {
                mass,
                stiffness,
                damping,
                ..
            } => (
                0.5 * (quadratic(mass, &x.qd) + quadratic(stiffness, &x.q)),
                quadratic(damping, &x.qd),
                f.iter().zip(&x.qd).map(|(f, v)| f * v).sum(),
            ),
        }
    }
}

/// `work = f − K q − C v`.
fn residual(
    f: &[f64],
    k: &DMatrix<f64>,
    q: &[f64],
    c: &DMatrix<f64>,
    v: &[f64],
    work: &mut DVector<f64>,
) {
    for i in 0..f.len() {
        let mut r = f[i];
        for j in 0..f.len() {
            r -= k[(i, j)] * q[j] + c[(i, j)] * v[j];
        }
        work[i] = r;
    }
}

/// `out = A x`.
fn mat_vec(a: &DMatrix<f64>, x: &[f64], out: &mut [f64]) {
    for (i, o) in out.iter_mut().enumerate() {
        *o = a.row(i).iter().zip(x).map(|(a, v)| a * v).sum();
    }
}

/// `xᵀ A x`.
fn quadratic(a: &DMatrix<f64>, x: &[f64]) -> f64 {
    let mut s = 0.0;
    for i in 0..x.len() {
        for j in 0..x.len() {
            s += x[i] * a[(i, j)] * x[j];
        }
    }
    s
}
