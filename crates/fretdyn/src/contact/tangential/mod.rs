//! The three tangential methods of THEORY §4: a penalty law (§4.1) and Lagrange multipliers
//! solved by an Active Set method (§4.3) or a projected Gauss–Seidel (§4.4).

// The solvers are crate-private: public only for the crate's tests (feature `testing`).
#[cfg(feature = "testing")]
pub mod active_set;
#[cfg(not(feature = "testing"))]
pub(crate) mod active_set;
#[cfg(feature = "testing")]
pub mod gauss_seidel;
#[cfg(not(feature = "testing"))]
pub(crate) mod gauss_seidel;
#[cfg(feature = "testing")]
pub mod penalty;
#[cfg(not(feature = "testing"))]
pub(crate) mod penalty;

use serde::Serialize;

pub use crate::contact::friction::LocalSolve;

/// Which velocity the stick constraint of the Lagrange methods acts on (THEORY §2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StickVelocity {
    /// The half-step velocity `v_{n+3/2} = q̇* + Δt q̈_{n+1}` that moves the positions: exact
    /// sticking, zero force after the stick. The default.
    #[default]
    HalfStep,
    /// The paper's literal `γ_imp = (2/Δt)(v_imp − L u̇)` on the full-step velocity; it leaves an
    /// alternating spurious force after sticking. Kept to show that.
    FullStep,
}

impl StickVelocity {
    /// θ such that the constrained velocity is `L q̇* + θ Δt L q̈`.
    pub fn theta(self) -> f64 {
        match self {
            StickVelocity::HalfStep => 1.0,
            StickVelocity::FullStep => 0.5,
        }
    }
}

/// Tangential penalty parameters (THEORY §4.1): `R_T = −K_T (u_T − u_T0) − C_T v_T` in stick.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PenaltySettings {
    /// Tangential stiffness `K_T`, N/m.
    pub stiffness: f64,
    /// Tangential damping `C_T`, N·s/m.
    pub damping: f64,
}

/// Projected Gauss–Seidel parameters (THEORY §4.4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GaussSeidelSettings {
    /// Stop when `‖λ^{k+1} − λ^k‖ ≤ tol ‖λ^{k+1}‖`...
    pub tolerance: f64,
    /// ... and the natural-map residual
    /// (THEORY §4.2, `TangentialProblem::natural_map_residual`)
    /// is at most this.
    pub residual_tolerance: f64,
    /// Sweep bound; a step that reaches it is counted as non-converged.
    pub max_sweeps: usize,
    /// Exact block solve (default) or the paper's radial projection.
    #[serde(serialize_with = "serialize_local_solve")]
    pub local_solve: LocalSolve,
    /// Start from the previous step's λ of contacts that stay closed.
    pub warm_start: bool,
}

impl Default for GaussSeidelSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-12,
            residual_tolerance: 1e-8,
            max_sweeps: 1000,
            local_solve: LocalSolve::Exact,
            warm_start: true,
        }
    }
}

fn serialize_local_solve<S: serde::Serializer>(v: &LocalSolve, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(v.name())
}

/// Active Set parameters (THEORY §4.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ActiveSetSettings {
    /// Bound on status iterations per step.
    pub max_iterations: usize,
    /// The fallback used when the statuses cycle or the bound is reached: a projected
    /// Gauss–Seidel started from the Active Set's last λ.
    pub fallback: GaussSeidelSettings,
}

impl Default for ActiveSetSettings {
    fn default() -> Self {
        Self {
            max_iterations: 50,
            fallback: GaussSeidelSettings::default(),
        }
    }
}

/// The tangential method of a run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum TangentialMethod {
    /// Penalty law, Algorithm 1.
    Penalty(PenaltySettings),
    /// Lagrange multipliers, Active Set, Algorithm 2.
    ActiveSet(ActiveSetSettings),
    /// Lagrange multipliers, projected Gauss–Seidel, Algorithm 3.
    GaussSeidel(GaussSeidelSettings),
}

impl TangentialMethod {
    /// Short name as used in case files.
    pub fn name(&self) -> &'static str {
        match self {
            TangentialMethod::Penalty(_) => "penalty",
            TangentialMethod::ActiveSet(_) => "active_set",
            TangentialMethod::GaussSeidel(_) => "gauss_seidel",
        }
    }

    /// True for the Lagrange-multiplier methods.
    pub fn is_lagrange(&self) -> bool {
        !matches!(self, TangentialMethod::Penalty(_))
    }
}

/// Counters of the tangential solvers over a run; never hidden, always reported.
#[derive(Debug, Clone, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct SolverStatistics {
    /// Steps with at least one closed contact solved by a Lagrange method.
    pub lagrange_steps: u64,
    /// Gauss–Seidel: total sweeps (including Active Set fallbacks).
    pub gs_sweeps_total: u64,
    /// Gauss–Seidel: largest sweep count of a step.
    pub gs_sweeps_max: u64,
    /// Gauss–Seidel: steps that hit `max_sweeps` before the tolerance.
    pub gs_nonconverged_steps: u64,
    /// Active Set: total status iterations.
    pub as_iterations_total: u64,
    /// Active Set: largest iteration count of a step.
    pub as_iterations_max: u64,
    /// Active Set: steps whose statuses cycled.
    pub as_cycles: u64,
    /// Active Set: steps that reached `max_iterations` without cycling.
    pub as_iteration_limit: u64,
    /// Active Set: steps solved by the Gauss–Seidel fallback (cycles + iteration limit).
    pub as_fallbacks: u64,
    /// Redundant constraints (THEORY §4.6): Gauss–Seidel steps whose `H` was singular
    /// (tolerated), Active Set direct solves whose `H_SS` was singular (regularised).
    pub singular_delassus: u64,
    /// Largest natural-map residual of a step (relative; see
    /// `TangentialProblem::natural_map_residual`, THEORY §4.2).
    pub residual_max: f64,
    /// Sum of the steps' residuals (the mean is `residual_sum / lagrange_steps`).
    pub residual_sum: f64,
    /// Steps whose residual is above 1e-8.
    pub residual_steps_above_1e_8: u64,
}

impl SolverStatistics {
    /// Mean Gauss–Seidel sweeps per Lagrange step.
    pub fn gs_sweeps_mean(&self) -> f64 {
        ratio(self.gs_sweeps_total, self.lagrange_steps)
    }

    /// Mean natural-map residual per Lagrange step.
    pub fn residual_mean(&self) -> f64 {
        if self.lagrange_steps == 0 {
            0.0
        } else {
            self.residual_sum / self.lagrange_steps as f64
        }
    }

    /// Counts one step's residual.
    pub fn add_residual(&mut self, r: f64) {
        // the running maximum starts at 0 and skips a NaN `r`
        self.residual_max = crate::numerics::running_max(self.residual_max, r);
        self.residual_sum += r;
        if !(r <= 1e-8) {
            self.residual_steps_above_1e_8 += 1;
        }
    }

    /// Mean Active Set iterations per Lagrange step.
    pub fn as_iterations_mean(&self) -> f64 {
        ratio(self.as_iterations_total, self.lagrange_steps)
    }
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 { 0.0 } else { a as f64 / b as f64 }
}
