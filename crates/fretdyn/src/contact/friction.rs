//! Coulomb friction with static and dynamic coefficients, and the exact solution of one
//! contact's local tangential problem (THEORY §4, §4.4).
//!
//! Sign convention: the tangential multiplier `λ` of a contact is minus the tangential force of
//! the obstacle on the structure in the contact's tangent basis, `R_T = −λ`. Sliding means
//! `λ = μ_d R_N v/|v|` (the force opposes the slip velocity), sticking `|λ| ≤ μ_s R_N`, `v = 0`.

use std::cell::Cell;

use nalgebra::{Matrix2, Vector2};

use crate::error::{Error, Result};

/// Friction coefficients, `μ_s ≥ μ_d ≥ 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coulomb {
    /// Static coefficient: sticking holds while `|R_T| ≤ μ_s R_N`.
    pub mu_static: f64,
    /// Dynamic coefficient: sliding force `|R_T| = μ_d R_N`.
    pub mu_dynamic: f64,
}

impl Coulomb {
    /// Validated constructor; `field` prefixes error messages.
    pub fn new(mu_static: f64, mu_dynamic: f64, field: &str) -> Result<Self> {
        if !(mu_dynamic.is_finite() && mu_dynamic >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.mu_dynamic"),
                format!("must be a friction coefficient ≥ 0 (got {mu_dynamic})"),
            ));
        }
        if !(mu_static.is_finite() && mu_static >= mu_dynamic) {
            return Err(Error::invalid(
                format!("{field}.mu_static"),
                format!(
                    "must be ≥ mu_dynamic = {mu_dynamic} (got {mu_static}): static friction is at least the dynamic one"
                ),
            ));
        }
        Ok(Self {
            mu_static,
            mu_dynamic,
        })
    }
}

/// Stick or slip, as decided by a local solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Slide {
    /// Inside the static disk: the tangential velocity is zero.
    Stick,
    /// On the dynamic circle: the force opposes the slip.
    Slip,
}

/// How the Gauss–Seidel block update treats a 2-component block (THEORY §4.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LocalSolve {
    /// Exact solution of the block problem: `λ = s w/|w|` with `w = c − H_ii λ`.
    Exact,
    /// The paper's radial projection of the unconstrained block solution onto the disk.
    Radial,
}

impl LocalSolve {
    /// Its name in case files and summaries: `exact`, `radial`.
    pub fn name(self) -> &'static str {
        match self {
            LocalSolve::Exact => "exact",
            LocalSolve::Radial => "radial",
        }
    }
}

/// Relative threshold below which an eigenvalue of a contact's block `H_ii` counts as zero:
/// `τ = SINGULAR_RATIO · max(h₁₁, h₂₂)`, the threshold of the singularity test of `H` and of
/// the Active Set's Cholesky (THEORY §4.4, §4.6).
pub const SINGULAR_RATIO: f64 = 1e-12;

/// A contact's 2 × 2 diagonal block `H_ii` of the Delassus operator with what its local solve
/// needs of it: its inverse ([`inverse2`]) and its eigen-decomposition, formed once per step
/// rather than at every sweep — the eigen-decomposition (two square roots, two divisions)
/// only when an exact slip solve first asks for it, so that a sticking contact, or the
/// radial projection, never pays for it.
///
/// A block with an eigenvalue at most `τ = 1e-12 max(h₁₁, h₂₂)` ([`SINGULAR_RATIO`]) is
/// **singular**: along its eigenvector `d` no mode moves the contact point, and the slip
/// velocity's component `c·d` does not depend on `λ`. Its free solution is that of the block
/// with that eigenvalue raised to `τ`, `H_τ⁻¹c = Σ_k q_k (q_k·c)/max(h_k, τ)`
/// ([`Self::stick_force`]), so that the stick test `|H_τ⁻¹c| ≤ s` fails when `|c·d| > τ s`
/// (no `λ` can stop the slip along `d`: the contact slides), passes with the minimum-norm
/// `λ` when `c·d = 0`, and is continuous with that of a block whose eigenvalue is just above
/// `τ` (THEORY §4.4). It is formed in the eigenbasis, term by term: as a matrix, `1/τ` would
/// swamp the other eigenvalue's term.
#[derive(Debug, Clone)]
pub struct DiagonalBlock {
    /// `H_ii`.
    pub h: Matrix2<f64>,
    inverse: Matrix2<f64>,
    /// The eigen-decomposition `H = Q diag(h) Qᵀ` for the exact slip solution, once formed.
    eigen: Cell<Option<(Matrix2<f64>, [f64; 2])>>,
    isotropic: bool,
    /// An eigenvalue at most `τ` ([`Self::is_singular`]).
    singular: bool,
    /// `2/tr(H_ii)` ([`Self::rho`]).
    rho: f64,
}

impl DiagonalBlock {
    /// The block `h` (symmetric positive semi-definite); its eigen-decomposition is formed at
    /// its first exact slip solve and kept (for the run, for a fixed plane's block).
    #[inline]
    pub fn new(h: Matrix2<f64>) -> Self {
        let (inverse, singular) = regularised_inverse(&h);
        Self {
            h,
            inverse,
            eigen: Cell::new(None),
            isotropic: is_isotropic(&h),
            singular,
            rho: {
                let trace = h[(0, 0)] + h[(1, 1)];
                // a zero block (nothing moves the point in the tangent plane): ρ = ∞, the
                // natural map's limit, whose residual is 0 only for λ = s w/|w| (w ≠ 0)
                if trace > 0.0 {
                    2.0 / trace
                } else if trace == 0.0 {
                    f64::INFINITY
                } else {
                    0.0
                }
            },
        }
    }

    /// The eigen-decomposition `H = Q diag(h) Qᵀ` ([`symmetric_eigen2`]), formed at the first
    /// call and kept.
    #[inline(always)]
    fn eigen(&self) -> (Matrix2<f64>, [f64; 2]) {
        match self.eigen.get() {
            Some(e) => e,
            None => {
                let e = symmetric_eigen2(&self.h);
                self.eigen.set(Some(e));
                e
            }
        }
    }

    /// `H_ii⁻¹` of a regular block; not a number for a singular one, whose free solution is
    /// [`Self::stick_force`]'s (so that a free solution formed with it fails every stick test
    /// and goes to [`singular_solve`]).
    #[inline]
    pub fn inverse(&self) -> &Matrix2<f64> {
        &self.inverse
    }

    /// Whether `H_ii` has an eigenvalue at most `τ = 1e-12 max(h₁₁, h₂₂)`: a direction in the
    /// tangent plane along which no mode moves the contact point (THEORY §4.4).
    #[inline]
    pub fn is_singular(&self) -> bool {
        self.singular
    }

    /// Whether `H_ii = 0`: no mode moves the contact point in its tangent plane.
    #[inline]
    pub fn is_zero(&self) -> bool {
        self.h[(0, 0)] == 0.0 && self.h[(1, 1)] == 0.0
    }

    /// The stick force `H_ii⁻¹ c` of the local problem with the right-hand side `c`; for a
    /// singular block `H_τ⁻¹c` (the minimum-norm one when `c` has no component along the
    /// null direction). A zero block has none unless `c = 0`: for `c ≠ 0` the force returned,
    /// along `c`, is twice `s_static` (at least `1.5e-154`), so that a stick test
    /// `|λ| ≤ s_static` fails, and finite (THEORY §4.3).
    #[inline]
    pub fn stick_force(&self, c: &Vector2<f64>, s_static: f64) -> Vector2<f64> {
        if self.singular {
            singular_stick_force(self, c, s_static)
        } else {
            self.inverse * c
        }
    }

    /// `τ = 1e-12 max(h₁₁, h₂₂)`.
    #[inline]
    fn tau(&self) -> f64 {
        SINGULAR_RATIO * self.h[(0, 0)].abs().max(self.h[(1, 1)].abs())
    }

    /// `H_τ⁻¹c = Σ_k q_k (q_k·c)/max(h_k, τ)` in the eigenbasis (a singular, nonzero block).
    fn raised_free(&self, c: &Vector2<f64>) -> Vector2<f64> {
        let (q, e) = self.eigen();
        let tau = self.tau();
        let cp = q.transpose() * c;
        // a NaN eigenvalue (a diverging run) stays NaN
        let raised = |k: usize| if e[k] < tau { tau } else { e[k] };
        q * Vector2::new(cp[0] / raised(0), cp[1] / raised(1))
    }

    /// The step `ρ = 2/tr(H_ii)` of the natural map (THEORY §4.2), `∞` for a zero block.
    #[inline]
    pub fn rho(&self) -> f64 {
        self.rho
    }
}

/// [`DiagonalBlock::stick_force`] of a singular block.
#[cold]
#[inline(never)]
fn singular_stick_force(block: &DiagonalBlock, c: &Vector2<f64>, s_static: f64) -> Vector2<f64> {
    if !block.is_zero() {
        return block.raised_free(c);
    }
    match unit(c) {
        Some(u) => u * (2.0 * s_static).max(f64::MIN_POSITIVE.sqrt()),
        None if c.x == 0.0 && c.y == 0.0 => Vector2::zeros(),
        // not a number: the step diverges
        None => c * f64::NAN,
    }
}

/// `c/|c|`, its norm formed scaled (no overflow or underflow); `None` for `c = 0` or a `c`
/// that is not finite.
#[inline]
fn unit(c: &Vector2<f64>) -> Option<Vector2<f64>> {
    let m = c.amax();
    if !(m > 0.0 && m.is_finite()) {
        return None;
    }
    let scaled = c / m;
    Some(scaled / scaled.norm())
}

impl Default for DiagonalBlock {
    fn default() -> Self {
        Self::new(Matrix2::zeros())
    }
}

/// Solves one contact's tangential problem with the other contacts frozen:
/// find `λ` such that, with `w = c − H λ` (the slip velocity up to the factor θΔt),
/// either `w = 0` and `|λ| ≤ s_static` (stick), or `λ = s_dynamic w/|w|` (slip).
///
/// `h` is the contact's 2 × 2 diagonal block of the Delassus operator (symmetric positive
/// semi-definite), `c` the right-hand side with the other contacts' multipliers subtracted.
/// A singular `h` (THEORY §4.4): the contact slides when `c` has a component along the
/// null direction (above `τ s_static`, [`DiagonalBlock`]), sticks with the minimum-norm
/// `λ` otherwise when that is inside the static disk.
#[inline]
pub fn local_solve(
    h: &Matrix2<f64>,
    c: &Vector2<f64>,
    s_static: f64,
    s_dynamic: f64,
    mode: LocalSolve,
) -> (Vector2<f64>, Slide) {
    let block = DiagonalBlock::new(*h);
    local_solve_block(&block, c, s_static, s_dynamic, mode, &Cell::new(f64::NAN))
}

/// [`local_solve`] on a block prepared once per step ([`DiagonalBlock`]). `newton` is the
/// exact slip solution's Newton start: the root of the contact's last exact slip solve of
/// this step (NaN: none), where the next one starts — the sweeps and the status iterations
/// of a step solve the same contact with nearly the same right-hand side.
///
/// A singular block ([`DiagonalBlock`]: an eigenvalue at most `τ`) has an inverse that is not
/// a number: its free solution fails the stick test, and [`singular_solve`] decides — stick
/// when `|H_τ⁻¹ c| ≤ s_static` (a component of `c` along the null direction `d` above
/// `τ s_static` fails it), else the slip solution, which satisfies `λ ∥ w` with
/// `w·d = c·d ≠ 0`. The one test this costs, on the slip path, also catches a free solution
/// whose square overflows. The solvers run the same code without it on a step whose blocks are
/// all regular ([`local_solve_with`], THEORY §4.4).
#[inline(always)]
pub fn local_solve_block(
    block: &DiagonalBlock,
    c: &Vector2<f64>,
    s_static: f64,
    s_dynamic: f64,
    mode: LocalSolve,
    newton: &Cell<f64>,
) -> (Vector2<f64>, Slide) {
    local_solve_with::<true>(block, c, s_static, s_dynamic, mode, newton)
}

/// [`local_solve_block`] (`SINGULAR`), or without its test for a singular block
/// (`!SINGULAR`: the code of a step whose closed contacts' blocks are all regular,
/// [`crate::contact::delassus::TangentialProblem::may_be_singular`]; on a singular block its
/// answer is then not a number).
#[inline(always)]
pub(crate) fn local_solve_with<const SINGULAR: bool>(
    block: &DiagonalBlock,
    c: &Vector2<f64>,
    s_static: f64,
    s_dynamic: f64,
    mode: LocalSolve,
    newton: &Cell<f64>,
) -> (Vector2<f64>, Slide) {
    let free = block.inverse * c;
    // |free| ≤ s_static compared squared: no square root for a stick
    let norm2 = free.norm_squared();
    if norm2 <= s_static * s_static {
        return (free, Slide::Stick);
    }
    if SINGULAR && !(norm2 < f64::INFINITY) {
        // a singular block (its inverse is not a number), or |H⁻¹c|² beyond the largest
        // number
        return singular_solve(block, c, s_static, s_dynamic, mode, newton);
    }
    if s_dynamic <= 0.0 {
        return (Vector2::zeros(), Slide::Slip);
    }
    let norm = norm2.sqrt();
    let lambda = match mode {
        LocalSolve::Radial => free * (s_dynamic / norm),
        LocalSolve::Exact if block.isotropic => free * (s_dynamic / norm),
        LocalSolve::Exact => disk_boundary_solve(block, c, s_dynamic, newton),
    };
    (lambda, Slide::Slip)
}

/// [`local_solve_block`] when the free solution `H_ii⁻¹c` is not a finite vector (THEORY
/// §4.4):
/// - a zero block `H_ii = 0`: the slip velocity is `c` whatever `λ` — stick with `λ = 0`
///   when `c = 0`, else slip with `λ = s_dynamic c/|c|`, the exact and the radial solutions
///   alike;
/// - a singular block: stick with `λ = H_τ⁻¹c` ([`DiagonalBlock::stick_force`]) when that is
///   in the static disk; else slip, the exact solution from the block's own eigenvalues
///   ([`disk_boundary_solve`]: its secular equation has a root `t > 0`), the radial one the
///   projection of `H_τ⁻¹c` on the dynamic circle;
/// - a regular block whose free solution's square overflows: its slip solution, the radial
///   projection's norm formed scaled.
#[cold]
#[inline(never)]
fn singular_solve(
    block: &DiagonalBlock,
    c: &Vector2<f64>,
    s_static: f64,
    s_dynamic: f64,
    mode: LocalSolve,
    newton: &Cell<f64>,
) -> (Vector2<f64>, Slide) {
    let free = if block.singular {
        if block.is_zero() {
            return match unit(c) {
                Some(u) if s_dynamic > 0.0 => (u * s_dynamic, Slide::Slip),
                _ if c.x == 0.0 && c.y == 0.0 => (Vector2::zeros(), Slide::Stick),
                Some(_) => (Vector2::zeros(), Slide::Slip),
                None => (c * f64::NAN, Slide::Slip),
            };
        }
        let free = block.raised_free(c);
        if free.norm_squared() <= s_static * s_static {
            return (free, Slide::Stick);
        }
        free
    } else {
        block.inverse * c
    };
    if s_dynamic <= 0.0 {
        return (Vector2::zeros(), Slide::Slip);
    }
    let lambda = match mode {
        LocalSolve::Exact if !block.isotropic => disk_boundary_solve(block, c, s_dynamic, newton),
        _ => match unit(&free) {
            Some(u) => u * s_dynamic,
            None => free * f64::NAN,
        },
    };
    (lambda, Slide::Slip)
}

/// `H = h I`: then `(sH + tI)u = c` makes `u` parallel to `c`, hence to `H⁻¹c`, and the exact
/// slip solution is the radial projection of the free one, in closed form.
#[inline]
fn is_isotropic(h: &Matrix2<f64>) -> bool {
    h[(0, 1)] == 0.0 && h[(1, 0)] == 0.0 && h[(0, 0)] == h[(1, 1)]
}

/// `H⁻¹` for a symmetric positive semi-definite 2 × 2 matrix whose eigenvalues are above
/// `τ = 1e-12 max(h₁₁, h₂₂)` ([`SINGULAR_RATIO`]); not a number for a singular one (an
/// eigenvalue at most `τ`: [`DiagonalBlock`] solves with it, THEORY §4.4).
#[inline]
pub fn inverse2(h: &Matrix2<f64>) -> Matrix2<f64> {
    regularised_inverse(h).0
}

/// [`inverse2`] and whether `h` is singular. `h_min ≤ τ` is tested without the
/// eigenvalues: with `τ ≤ h_max` (a diagonal term is at most `h_max`), `(τ − h_min)(τ − h_max)
/// = τ² − τ tr H + det H ≤ 0` exactly when `h_min ≤ τ`; a regular `h` takes the closed-form
/// inverse.
#[inline(always)]
fn regularised_inverse(h: &Matrix2<f64>) -> (Matrix2<f64>, bool) {
    let det = h[(0, 0)] * h[(1, 1)] - h[(0, 1)] * h[(1, 0)];
    let scale = h[(0, 0)].abs().max(h[(1, 1)].abs());
    let tau = SINGULAR_RATIO * scale;
    if det > tau * (h[(0, 0)] + h[(1, 1)] - tau) {
        let id = 1.0 / det;
        (
            Matrix2::new(
                h[(1, 1)] * id,
                -h[(0, 1)] * id,
                -h[(1, 0)] * id,
                h[(0, 0)] * id,
            ),
            false,
        )
    } else {
        (Matrix2::repeat(f64::NAN), true)
    }
}

/// `H⁻¹ c` for a regular 2 × 2 matrix ([`inverse2`]; not a number when `H` is singular).
#[inline]
pub fn solve2(h: &Matrix2<f64>, c: &Vector2<f64>) -> Vector2<f64> {
    inverse2(h) * c
}

/// The slip solution on the circle of radius `s`: `λ = s u`, `|u| = 1`, `(s H + t I) u = c`,
/// `t > 0` (then `w = c − Hλ = t u` is along `λ`). In the eigenbasis of `H` the condition is
/// the secular equation `Σ c_k²/(s h_k + t)² = 1`, solved by Newton on `φ(t) = 1/|u(t)| − 1`,
/// which is concave and increasing on `t > −s h_min`: from below the root Newton climbs to it
/// monotonically, from above its first step lands below it.
///
/// The root lies between `|c| − s h_max` and `|c| − s h_min` (from
/// `|c| = |(sH + tI)u|`, `|u| = 1`); the start is the root's expansion in powers of
/// `s h/|c|` to third order (to first order when the `s h_k` spread over more than 1 % of
/// `|c|`), kept above the lower bound.
/// A start above the root (it may be, and the lower bound itself may be by round-off when
/// `c` lies along the stiff eigenvector of an `H` anisotropic by 10³, a tube sliding round a
/// hole) costs Newton one step down (an earlier version projected radially when the start
/// was not below the root, off by up to 1e-4 in direction).
#[inline(always)]
fn disk_boundary_solve(
    block: &DiagonalBlock,
    c: &Vector2<f64>,
    s: f64,
    newton: &Cell<f64>,
) -> Vector2<f64> {
    let (q, eigenvalues) = block.eigen();
    let hs = [s * eigenvalues[0], s * eigenvalues[1]];
    let cp = q.transpose() * c;
    let c2 = [cp[0] * cp[0], cp[1] * cp[1]];
    // u(t) in the eigenbasis; a component of c that is exactly 0 stays 0 (also at t = lower).
    let u_of = |t: f64| {
        let part = |k: usize| {
            if cp[k] == 0.0 {
                0.0
            } else {
                cp[k] / (hs[k] + t)
            }
        };
        [part(0), part(1)]
    };
    let lower = -hs[0].min(hs[1]);
    // warm start: the last root of this contact in this step (above the root, Newton's first
    // step lands below it; below, it climbs monotonically)
    let warm = newton.get();
    let mut t = if warm > lower {
        warm
    } else {
        // The root lies in [|c| − s h_max, |c| − s h_min]; start from its expansion in
        // powers of s h/|c| (a fast slip): with the weights w_k = c_k²/|c|², the mean
        // m = Σ w_k s h_k and the central moments μ₂ = w₀w₁Δ², μ₃ = μ₂(w₁ − w₀)Δ of the s h_k
        // (Δ = s h₀ − s h₁), t = |c| − m + 3μ₂/(2|c|) − 2μ₃/|c|² + O(μ₂²/|c|³): a relative
        // error below 1e-9 when the spread √μ₂ is below 1 % of |c|, which leaves Newton one
        // step. A wider spread starts from the first-order term alone.
        let n2 = c2[0] + c2[1];
        let norm = n2.sqrt(); // |c|, rotated
        let inverse_n2 = 1.0 / n2;
        let (w0, w1) = (c2[0] * inverse_n2, c2[1] * inverse_n2);
        let delta = hs[0] - hs[1];
        let mu2 = w0 * w1 * delta * delta;
        let mut expansion = norm - (w0 * hs[0] + w1 * hs[1]);
        if mu2 <= 1e-4 * n2 {
            let inverse_norm = norm * inverse_n2;
            expansion += inverse_norm * (1.5 * mu2 - 2.0 * inverse_norm * mu2 * (w1 - w0) * delta);
        }
        // the bound that does not need the expansion first, off its dependency chain
        let floor = lower.max(norm - hs[0].max(hs[1])).max(0.0);
        let t = floor.max(expansion);
        if t <= lower {
            // on the pole of a singular H: start just above it
            lower + f64::EPSILON * (norm + hs[0].abs().max(hs[1].abs()))
        } else {
            t
        }
    };
    // Newton's error after a step δ is κδ² with κ = |φ''|/(2φ') (below); this is the part of
    // κ that does not change over the iterations
    let curvature = newton_curvature(c2, hs);
    let mut converged = false;
    // the converged step's start e₀, e₁, 1/(e₀e₁), and the step when it was taken whole
    let mut last = None;
    for _ in 0..100 {
        // φ = 1/|u| − 1, φ' = Σ u_k²/(s h_k + t) / |u|³, so the Newton step φ/φ' is
        // |u|²(1 − |u|) / Σ u_k²/(s h_k + t). With e_k = s h_k + t, D = e₀e₁,
        // N = c₀²e₁² + c₁²e₀² = D²|u|² and M = c₀²e₁³ + c₁²e₀³, it is N (D − √N) / M:
        // one square root and one division (the form with u needs three), side by side on
        // the dependent chain — 1/M is formed while √N is (one rounding more than N (D − √N)
        // / M, and 3–5 % of the exact methods' step time less).
        let (e0, e1) = (hs[0] + t, hs[1] + t);
        let (w0, w1) = (c2[0] * e1, c2[1] * e0);
        let n = w0 * e1 + w1 * e0;
        let m = w0 * e1 * e1 + w1 * e0 * e0;
        let inverse_m = 1.0 / m;
        // for λ at the root, formed off the chain, while √N is (below)
        let inverse_d = 1.0 / (e0 * e1);
        let mut step = n * (e0 * e1 - n.sqrt()) * inverse_m;
        if !step.is_finite() {
            // overflow of the products, or a pole (e_k = 0 where c_k = 0): the form with u
            step = newton_step_direct(&cp, &hs, t);
            if !step.is_finite() {
                break;
            }
        }
        let next = t - step;
        // Stay in the domain t > lower (a flat tangent far above the root could leave it).
        let whole = next > lower;
        t = if whole { next } else { 0.5 * (t + lower) };
        // Newton's error after a step δ is κδ² (the root being between the two iterates),
        // κ = |φ''|/(2φ') at the step's start; φ is close to linear in t − lower (exactly so
        // when one term dominates or H is isotropic), so that κ ≤ 1/(t − lower) but for a
        // strongly anisotropic H: a step below 1e-8 (t − lower) leaves round-off, and so
        // does one whose κδ² is below 1e-16 (t − lower), which κ's closed form below tells
        // without a division (N/M > 0 is the ratio that the step formed already). The second
        // test ends most solves one Newton step earlier (on S1, 1.35 → 1.19 steps per solve).
        let bound = 1e-16 * (t - lower) * n;
        if step.abs() <= 1e-8 * (t - lower)
            || (curvature * (e0 * e1) * step * step * inverse_m <= bound && bound < f64::INFINITY)
        {
            converged = true;
            if whole {
                last = Some((e0, e1, inverse_d, step));
            }
            break;
        }
    }
    newton.set(t);
    if let Some((e0, e1, inverse_d, step)) = last {
        // λ = s (c₀/e₀', c₁/e₁') at the root, e_k' = e_k − δ, from the converged step's start
        // without a division on the chain: 1/e_k' = (1/e_k)/(1 − x_k), x_k = δ/e_k, and
        // 1/(1 − x) = (1 + x)(1 + x²) + O(x⁴), below round-off for |x| ≤ 5e-5.
        let (r0, r1) = (e1 * inverse_d, e0 * inverse_d);
        let (x0, x1) = (step * r0, step * r1);
        if e0 > 0.0 && e1 > 0.0 && x0.abs() <= 5e-5 && x1.abs() <= 5e-5 {
            let (a0, a1) = (s * cp[0] * r0, s * cp[1] * r1);
            let lambda = q * Vector2::new(
                a0 * ((1.0 + x0) * (1.0 + x0 * x0)),
                a1 * ((1.0 + x1) * (1.0 + x1 * x1)),
            );
            if lambda.x.is_finite() && lambda.y.is_finite() {
                return lambda;
            }
        }
    }
    let (e0, e1) = (hs[0] + t, hs[1] + t);
    if converged && e0 > 0.0 && e1 > 0.0 {
        // At the root |u| = 1 to round-off: λ = s u = s (c₀/e₀, c₁/e₁) in the eigenbasis,
        // with one division and no square root.
        let r = s / (e0 * e1);
        let lambda = q * Vector2::new(cp[0] * e1 * r, cp[1] * e0 * r);
        if lambda.x.is_finite() && lambda.y.is_finite() {
            return lambda;
        }
    }
    // u(t) ∥ (c₀ e₁, c₁ e₀) (times 1/D > 0): λ = s u/|u| needs no division by e_k
    let v = q * Vector2::new(cp[0] * e1, cp[1] * e0);
    let n2 = v.norm_squared();
    if n2.is_finite() && n2 > 0.0 && e0 > 0.0 && e1 > 0.0 {
        v * (s / n2.sqrt())
    } else {
        let [a, b] = u_of(t);
        let u = q * Vector2::new(a, b);
        let n = u.norm();
        if n.is_finite() && n > 0.0 {
            u * (s / n)
        } else {
            // Degenerate input (c = 0 cannot slide): project the free solution radially.
            let free = if block.singular {
                block.raised_free(c)
            } else {
                block.inverse * c
            };
            let nf = free.norm();
            if nf > 0.0 { free * (s / nf) } else { free }
        }
    }
}

/// The part of the Newton's error factor of [`disk_boundary_solve`] that does not depend on
/// `t`: `(3/2) c₀²c₁²Δ²`, `Δ = s h₀ − s h₁`. With `e_k = s h_k + t`, `D = e₀e₁`,
/// `N = c₀²e₁² + c₁²e₀²` and `M = c₀²e₁³ + c₁²e₀³`, the curvature of `φ(t) = 1/|u(t)| − 1`
/// relative to its slope is `|φ''|/(2φ') = (3/2)(S₂S₄ − S₃²)/(S₂S₃)` with
/// `S_j = Σ c_k²/e_k^j`, and `S₂S₄ − S₃² = c₀²c₁²Δ²/D⁴`, so that
/// `|φ''|/(2φ') = (3/2) c₀²c₁²Δ² D/(N M)`: zero for an isotropic `H` or a `c` along an
/// eigenvector, where `φ` is linear and one Newton step lands on the root.
#[inline(always)]
fn newton_curvature(c2: [f64; 2], hs: [f64; 2]) -> f64 {
    let delta = hs[0] - hs[1];
    1.5 * c2[0] * c2[1] * delta * delta
}

/// The Newton step of [`disk_boundary_solve`] in the form with `u = (c_k/(s h_k + t))`:
/// `|u|²(1 − |u|) / Σ u_k²/(s h_k + t)`, a component of `c` that is exactly 0 contributing 0
/// (also on its pole).
#[cold]
fn newton_step_direct(cp: &Vector2<f64>, hs: &[f64; 2], t: f64) -> f64 {
    let (r0, r1) = (1.0 / (hs[0] + t), 1.0 / (hs[1] + t));
    let (a, b) = (
        if cp[0] == 0.0 { 0.0 } else { cp[0] * r0 },
        if cp[1] == 0.0 { 0.0 } else { cp[1] * r1 },
    );
    let n2 = a * a + b * b;
    n2 * (1.0 - n2.sqrt()) / (a * a * r0 + b * b * r1)
}

/// Eigen-decomposition `H = Q diag(h) Qᵀ` of a symmetric 2 × 2 matrix, in closed form: the
/// Jacobi rotation that zeroes `h₁₂` (Golub & Van Loan, *Matrix Computations*, §8.5.2,
/// `sym.schur2`), `τ = (h₂₂ − h₁₁)/(2h₁₂)`, `t = sign(τ)/(|τ| + √(1 + τ²))`, `c = 1/√(1 + t²)`,
/// `s = t c`, without trigonometric functions (this runs in every local solve).
#[inline]
fn symmetric_eigen2(h: &Matrix2<f64>) -> (Matrix2<f64>, [f64; 2]) {
    let (a, b, d) = (h[(0, 0)], 0.5 * (h[(0, 1)] + h[(1, 0)]), h[(1, 1)]);
    let (cs, sn) = if b == 0.0 {
        (1.0, 0.0)
    } else {
        let tau = (d - a) / (2.0 * b);
        let t = if tau.is_finite() {
            tau.signum() / (tau.abs() + (1.0 + tau * tau).sqrt())
        } else {
            0.5 / tau // τ overflowed: t = 1/(2τ) to first order, i.e. 0
        };
        let c = 1.0 / (1.0 + t * t).sqrt();
        (c, -t * c)
    };
    let q = Matrix2::new(cs, -sn, sn, cs);
    let e0 = a * cs * cs + 2.0 * b * sn * cs + d * sn * sn;
    let e1 = a * sn * sn - 2.0 * b * sn * cs + d * cs * cs;
    (q, [e0, e1])
}

#[cfg(test)]
mod tests {
    #[test]
    fn closed_form_eigen_reconstructs_the_matrix() {
        for h in [
            Matrix2::new(2.0, 0.7, 0.7, 0.5),
            Matrix2::new(1.0, 0.0, 0.0, 4.0),
            Matrix2::new(3.0, -1.0, -1.0, 3.0),
            Matrix2::new(1.0, 0.0, 0.0, 1.0),
            Matrix2::new(3.0179, -7.96e-4, -7.96e-4, 4.69e-3),
            Matrix2::new(1.0, 1e-300, 1e-300, 1.0 + 1e-16),
            Matrix2::new(2.0, 0.0, 0.0, 1.0),
        ] {
            let (q, e) = symmetric_eigen2(&h);
            let back = q * Matrix2::new(e[0], 0.0, 0.0, e[1]) * q.transpose();
            assert!((back - h).norm() < 1e-14 * h.norm(), "{h} vs {back}");
            let diag = q.transpose() * h * q;
            assert!(diag[(0, 1)].abs() < 1e-15 * h.norm(), "{diag}");
            assert!((q.transpose() * q - Matrix2::identity()).norm() < 1e-15);
        }
    }

    use super::*;

    /// The exact local solution satisfies the slip condition `λ ∥ c − Hλ`, `|λ| = s`;
    /// the radial projection does not when `H` is not a multiple of the identity.
    #[test]
    fn exact_local_solve_satisfies_coulomb_radial_does_not() {
        let h = Matrix2::new(2.0, 0.7, 0.7, 0.5);
        let c = Vector2::new(3.0, -1.0);
        let s = 0.4;
        let (lam, st) = local_solve(&h, &c, s, s, LocalSolve::Exact);
        assert_eq!(st, Slide::Slip);
        let w = c - h * lam;
        assert!((lam.norm() - s).abs() < 1e-14);
        let cross = lam.x * w.y - lam.y * w.x;
        assert!(
            cross.abs() < 1e-12 * lam.norm() * w.norm(),
            "cross = {cross}"
        );
        assert!(lam.dot(&w) > 0.0);

        let (rad, _) = local_solve(&h, &c, s, s, LocalSolve::Radial);
        let wr = c - h * rad;
        let cross_r = rad.x * wr.y - rad.y * wr.x;
        assert!(cross_r.abs() > 1e-3 * rad.norm() * wr.norm());
    }

    /// The exact slip solution minimises `½λᵀHλ − cᵀλ` on the disk: compare with a dense scan.
    #[test]
    fn exact_local_solve_is_the_disk_minimiser() {
        let h = Matrix2::new(1.0, -0.3, -0.3, 4.0);
        let c = Vector2::new(-2.0, 5.0);
        let s = 0.8;
        let (lam, _) = local_solve(&h, &c, s, s, LocalSolve::Exact);
        let f = |l: Vector2<f64>| 0.5 * l.dot(&(h * l)) - c.dot(&l);
        let best = (0..200_000)
            .map(|k| {
                let a = k as f64 / 200_000.0 * std::f64::consts::TAU;
                f(Vector2::new(a.cos(), a.sin()) * s)
            })
            .fold(f64::INFINITY, f64::min);
        assert!(f(lam) <= best + 1e-9);
    }

    /// A block forms its eigen-decomposition at its first exact slip solve only (not for a
    /// stick, nor for the radial projection), keeps it, and its later solves give the bits of
    /// a block given that decomposition from the start.
    #[test]
    fn eigen_decomposition_is_formed_at_the_first_exact_slip() {
        let h = Matrix2::new(2.0, 0.7, 0.7, 0.5);
        let lazy = DiagonalBlock::new(h);
        let eager = DiagonalBlock::new(h);
        eager.eigen.set(Some(symmetric_eigen2(&h)));
        let start = || Cell::new(f64::NAN);
        let c = Vector2::new(3.0, -1.0);
        let (_, st) = local_solve_block(&lazy, &(c * 1e-3), 1.0, 0.5, LocalSolve::Exact, &start());
        assert_eq!(st, Slide::Stick);
        let (_, st) = local_solve_block(&lazy, &c, 0.4, 0.4, LocalSolve::Radial, &start());
        assert_eq!(st, Slide::Slip);
        assert!(lazy.eigen.get().is_none());
        let from_lazy = local_solve_block(&lazy, &c, 0.4, 0.4, LocalSolve::Exact, &start());
        assert!(lazy.eigen.get().is_some());
        assert_eq!(lazy.eigen.get(), eager.eigen.get());
        let from_eager = local_solve_block(&eager, &c, 0.4, 0.4, LocalSolve::Exact, &start());
        assert_eq!(from_lazy, from_eager);
        assert_eq!(from_lazy.1, Slide::Slip);
    }

    #[test]
    fn stick_inside_static_disk() {
        let h = Matrix2::new(1.0, 0.0, 0.0, 1.0);
        let c = Vector2::new(0.1, 0.2);
        let (lam, st) = local_solve(&h, &c, 1.0, 0.5, LocalSolve::Exact);
        assert_eq!(st, Slide::Stick);
        assert_eq!(lam, c);
    }

    /// A tube sliding round a hole: `H` anisotropic (eigenvalues 3.0 and 4.7e-3, circumferential
    /// and axial), `c` almost along the stiff eigenvector, so that the start of the Newton
    /// iteration is at the root within round-off (a step of the tube case under turbulence).
    /// The slip direction must be that of `c − Hλ` to round-off; the reference root `t` is
    /// found by bisection on `|(sH + tI)⁻¹ c| = 1`, independently of the eigen-decomposition.
    #[test]
    fn exact_local_solve_when_the_start_is_at_the_root() {
        let h = Matrix2::new(
            3.017911803129995,
            -0.0007964053757638976,
            -0.0007964053757638976,
            0.004689538498432074,
        );
        let c = Vector2::new(3378.686345562826, -0.8927309287548405);
        let s = 0.2077213738615471;
        let (lam, st) = local_solve(&h, &c, s, s, LocalSolve::Exact);
        assert_eq!(st, Slide::Slip);
        let w = c - h * lam;
        let cross = (lam.x * w.y - lam.y * w.x) / (lam.norm() * w.norm());
        assert!(
            cross.abs() < 1e-12,
            "λ not along the slip velocity: sin = {cross:.1e}"
        );
        assert!(lam.dot(&w) > 0.0 && (lam.norm() - s).abs() < 1e-15);
        let size = |t: f64| {
            (h * s + Matrix2::identity() * t)
                .lu()
                .solve(&c)
                .unwrap()
                .norm()
        };
        let (mut lo, mut hi) = (3000.0, 4000.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if size(mid) > 1.0 { lo = mid } else { hi = mid }
        }
        let u = (h * s + Matrix2::identity() * lo).lu().solve(&c).unwrap();
        let reference = u * (s / u.norm());
        assert!((lam - reference).norm() < 1e-13 * s, "{lam} vs {reference}");
    }

    /// `c` exactly along an eigenvector of `H` (one component of `c` is 0 in the eigenbasis,
    /// also with an anisotropy of 10¹²): the slip solution is `λ = s c/|c|`, `t = |c| − s h` of that
    /// eigenvector, in closed form.
    #[test]
    fn exact_local_solve_along_an_eigenvector() {
        let s = 0.5;
        for (h, c) in [
            (Matrix2::new(1.0, 0.0, 0.0, 4.0), Vector2::new(3.0, 0.0)),
            (Matrix2::new(1.0, 0.0, 0.0, 4.0), Vector2::new(0.0, -7.0)),
            (Matrix2::new(1.0, 0.0, 0.0, 1e-12), Vector2::new(2.0, 0.0)),
            (Matrix2::new(1e-12, 0.0, 0.0, 1.0), Vector2::new(2.0, 0.0)),
        ] {
            let (lam, st) = local_solve(&h, &c, s, s, LocalSolve::Exact);
            assert_eq!(st, Slide::Slip, "{h} {c}");
            let expected = c * (s / c.norm());
            assert!(
                (lam - expected).norm() <= 1e-15 * s,
                "{h} {c}: {lam} vs {expected}"
            );
        }
    }

    /// Uniform numbers in [0, 1) from a xorshift generator seeded with `seed` (≠ 0).
    fn uniform_from(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The Newton's error factor `|φ''|/(2φ') = newton_curvature · D/(N M)` against central
    /// differences of `φ(t) = (Σ c_k²/(s h_k + t)²)^(−1/2) − 1` on random terms.
    #[test]
    fn newton_curvature_is_the_second_derivative_over_twice_the_first() {
        let mut uniform = uniform_from(0x9e37_79b9_7f4a_7c15_u64);
        for _ in 0..200 {
            let hs = [
                10f64.powf(2.0 * uniform() - 1.0),
                10f64.powf(2.0 * uniform() - 1.0),
            ];
            let c2 = [10f64.powf(2.0 * uniform()), 10f64.powf(2.0 * uniform())];
            let t = 10f64.powf(2.0 * uniform() - 1.0);
            let phi = |t: f64| {
                (c2[0] / (hs[0] + t).powi(2) + c2[1] / (hs[1] + t).powi(2)).powf(-0.5) - 1.0
            };
            let d = 1e-3 * t;
            let first = (phi(t + d) - phi(t - d)) / (2.0 * d);
            let second = (phi(t + d) - 2.0 * phi(t) + phi(t - d)) / (d * d);
            let (e0, e1) = (hs[0] + t, hs[1] + t);
            let n = c2[0] * e1 * e1 + c2[1] * e0 * e0;
            let m = c2[0] * e1 * e1 * e1 + c2[1] * e0 * e0 * e0;
            let closed_form = newton_curvature(c2, hs) * e0 * e1 / (n * m);
            let numeric = second.abs() / (2.0 * first);
            assert!(
                second <= 1e-9 * first.abs() / t,
                "φ is concave: φ'' = {second}"
            );
            // the differences' truncation error is O(d²), their round-off 4ε|1 + φ|/d² in φ''
            let noise = 4.0 * f64::EPSILON * (1.0 + phi(t)).abs() / (d * d) / (2.0 * first);
            assert!(
                (closed_form - numeric).abs() <= 1e-4 * numeric + 2.0 * noise,
                "hs = {hs:?}, c² = {c2:?}, t = {t}: {closed_form} vs {numeric}"
            );
        }
    }

    /// `(αs H + αt I) u = αc` has the root `αt` and the same `u`: the slip solution of
    /// `(αH, αc, s)` is that of `(H, c, s)`, also at scales where the Newton step's products
    /// `N = c₀²e₁² + c₁²e₀²`, `M = c₀²e₁³ + c₁²e₀³` overflow or vanish (from `α ≈ 1e60` and
    /// `α ≈ 1e-70`: the step is then taken in the form with `u`).
    #[test]
    fn exact_local_solve_is_scale_invariant() {
        let h = Matrix2::new(2.0, 0.7, 0.7, 0.5);
        let c = Vector2::new(3.0, -1.0);
        let s = 0.4;
        let (reference, _) = local_solve(&h, &c, s, s, LocalSolve::Exact);
        for alpha in [1e-150, 1e-70, 1e40, 1e60, 1e70, 1e75, 1e100, 1e150] {
            let (lam, st) = local_solve(&(h * alpha), &(c * alpha), s, s, LocalSolve::Exact);
            assert_eq!(st, Slide::Slip, "α = {alpha}");
            assert!(
                (lam - reference).norm() <= 1e-12 * s,
                "α = {alpha}: {lam} vs {reference}"
            );
        }
    }

    /// Random blocks (anisotropy up to 10⁶, any orientation) and right-hand sides: the exact
    /// slip solution against the root of `|(sH + tI)⁻¹c| = 1` found by bisection in the
    /// original basis (no eigen-decomposition, no Newton).
    #[test]
    fn exact_local_solve_matches_bisection_on_random_blocks() {
        let mut uniform = uniform_from(0x2545_f491_4f6c_dd1d_u64);
        for _ in 0..2000 {
            let angle = std::f64::consts::PI * uniform();
            let (cs, sn) = (angle.cos(), angle.sin());
            let q = Matrix2::new(cs, -sn, sn, cs);
            let h0 = 10f64.powf(3.0 * uniform() - 1.0);
            let h1 = h0 * 10f64.powf(-6.0 * uniform());
            let h = q * Matrix2::new(h0, 0.0, 0.0, h1) * q.transpose();
            let h = 0.5 * (h + h.transpose());
            let c = Vector2::new(uniform() - 0.5, uniform() - 0.5) * 10f64.powf(4.0 * uniform());
            // a slip: s below |H⁻¹c|
            let free = inverse2(&h) * c;
            let s = free.norm() * (0.05 + 0.9 * uniform());
            let (lam, st) = local_solve(&h, &c, s, s, LocalSolve::Exact);
            assert_eq!(st, Slide::Slip);
            // on the circle to round-off, though not normalised (|u| = 1 at the root)
            assert!(
                (lam.norm() - s).abs() <= 8.0 * f64::EPSILON * s,
                "|λ| = {} for s = {s}",
                lam.norm()
            );
            let size = |t: f64| {
                (h * s + Matrix2::identity() * t)
                    .lu()
                    .solve(&c)
                    .map_or(f64::INFINITY, |u| u.norm())
            };
            // |u(t)| decreases from ∞ at the pole; the root is below |c|
            let (mut lo, mut hi) = (-s * h1.min(h0), c.norm());
            for _ in 0..300 {
                let mid = 0.5 * (lo + hi);
                if size(mid) > 1.0 { lo = mid } else { hi = mid }
            }
            let u = (h * s + Matrix2::identity() * hi).lu().solve(&c).unwrap();
            let reference = u * (s / u.norm());
            assert!(
                (lam - reference).norm() <= 1e-9 * s,
                "H = {h}, c = {c}, s = {s}: {lam} vs {reference}"
            );
        }
    }

    /// `λ` on the circle of radius `s` along `w = c − Hλ`: Coulomb's slip condition.
    fn assert_slides(h: &Matrix2<f64>, c: &Vector2<f64>, lam: &Vector2<f64>, s: f64, what: &str) {
        let w = c - h * lam;
        assert!(
            (lam.norm() - s).abs() <= 1e-14 * s,
            "{what}: |λ| = {}",
            lam.norm()
        );
        let sine = (lam.x * w.y - lam.y * w.x) / (lam.norm() * w.norm());
        assert!(sine.abs() <= 1e-12, "{what}: λ = {lam} not along w = {w}");
        assert!(lam.dot(&w) > 0.0, "{what}: λ = {lam} against w = {w}");
    }

    /// A rank-one block `H = h v vᵀ` (no mode moves the point along `d = v⊥`): a right-hand
    /// side with a component `β` along `d` cannot be met by any λ (the slip velocity along
    /// `d` is `β` whatever λ), so the contact slides on the dynamic circle even when the
    /// regular part `α/h` is well inside the static disk (it stuck before: the pseudo-inverse
    /// dropped `β`). The exact solution is that of the secular equation
    /// `α²/(sh + t)² + β²/t² = 1`, `λ = s (α/(sh + t), β/t)` in the basis `(v, d)`, found here by
    /// bisection; the radial one is the projection of the block's regularised free solution,
    /// `(α/h) v + (β/τ) d`, nearly `s sign(β) d`.
    #[test]
    fn a_singular_block_slides_when_c_has_a_component_along_its_null_direction() {
        let (h, s) = (3.0, 0.5);
        for angle in [0.0, 0.3, std::f64::consts::FRAC_PI_2, 2.0] {
            let v = Vector2::new(f64::cos(angle), f64::sin(angle));
            let d = Vector2::new(-v.y, v.x);
            let hm = v * v.transpose() * h;
            for (alpha, beta) in [
                (0.3, 1e-3),
                (0.3, -2.0),
                (-1.0, 0.05),
                (0.0, 1.0),
                (5.0, 1.0),
            ] {
                let c = v * alpha + d * beta;
                let what = format!("θ = {angle}, α = {alpha}, β = {beta}");
                let block = DiagonalBlock::new(hm);
                assert!(block.is_singular(), "{what}");
                let (lam, st) = local_solve(&hm, &c, 2.0 * s, s, LocalSolve::Exact);
                assert_eq!(st, Slide::Slip, "{what}");
                assert_slides(&hm, &c, &lam, s, &what);
                // the secular equation by bisection: |u(t)| decreases from ∞ at t = 0
                let size = |t: f64| ((alpha / (s * h + t)).powi(2) + (beta / t).powi(2)).sqrt();
                let (mut lo, mut hi) = (0.0, c.norm());
                for _ in 0..300 {
                    let mid = 0.5 * (lo + hi);
                    if size(mid) > 1.0 { lo = mid } else { hi = mid }
                }
                let reference = (v * (alpha / (s * h + hi)) + d * (beta / hi)) * s;
                assert!(
                    (lam - reference).norm() <= 1e-12 * s,
                    "{what}: {lam} vs {reference}"
                );

                let (rad, st) = local_solve(&hm, &c, 2.0 * s, s, LocalSolve::Radial);
                assert_eq!(st, Slide::Slip, "{what}: radial");
                let tau = SINGULAR_RATIO * hm[(0, 0)].max(hm[(1, 1)]);
                let free = v * (alpha / h) + d * (beta / tau);
                let expected = free * (s / free.norm());
                assert!(
                    (rad - expected).norm() <= 1e-12 * s,
                    "{what}: {rad} vs {expected}"
                );
                assert!(
                    rad.dot(&d) * beta.signum() >= s * (1.0 - 1e-9),
                    "{what}: {rad}"
                );
            }
        }
    }

    /// A rank-one block with a right-hand side along the range of `H` only (`c·d = 0`,
    /// exactly: `d` a coordinate axis) inside the static disk sticks, with the minimum-norm
    /// force `(α/h) v` — nothing along `d` — and no slip velocity; outside the disk it slides
    /// along `v` (`λ = s sign(α) v`). Rotated (`d` not an axis, so that `c·d` is round-off),
    /// the force along `d` is `c·d/τ`: a few `ε|c|/τ` (a few 1e-4 of `|c|/h`).
    #[test]
    fn a_singular_block_sticks_with_the_minimum_norm_force_when_c_is_in_its_range() {
        let (h, s) = (3.0, 0.5);
        for (hm, c, v) in [
            (
                Matrix2::new(h, 0.0, 0.0, 0.0),
                Vector2::new(0.9, 0.0),
                Vector2::x(),
            ),
            (
                Matrix2::new(0.0, 0.0, 0.0, h),
                Vector2::new(0.0, -1.2),
                Vector2::y(),
            ),
        ] {
            for mode in [LocalSolve::Exact, LocalSolve::Radial] {
                let (lam, st) = local_solve(&hm, &c, s, 0.8 * s, mode);
                assert_eq!(st, Slide::Stick, "{hm} {c}");
                assert_eq!(lam, c / h, "{hm} {c}: the minimum-norm force");
                assert!((c - hm * lam).norm() <= f64::EPSILON * c.norm(), "no slip");
                // outside the static disk: slides along v
                let (lam, st) = local_solve(&hm, &(c * 10.0), s, 0.8 * s, mode);
                assert_eq!(st, Slide::Slip);
                let expected = v * (0.8 * s * c.dot(&v).signum());
                assert!((lam - expected).norm() <= 1e-15 * s, "{lam} vs {expected}");
            }
        }
        for angle in [0.3, 1.0, 2.5] {
            let v = Vector2::new(f64::cos(angle), f64::sin(angle));
            let hm = v * v.transpose() * h;
            let c = v * 0.9;
            let (lam, st) = local_solve(&hm, &c, s, 0.8 * s, LocalSolve::Exact);
            assert_eq!(st, Slide::Stick, "θ = {angle}");
            let d = Vector2::new(-v.y, v.x);
            assert!((lam.dot(&v) - 0.3).abs() <= 1e-15, "θ = {angle}: {lam}");
            // c·d is round-off, a few ε|c|, and the force along d that over τ
            let tau = SINGULAR_RATIO * hm[(0, 0)].max(hm[(1, 1)]);
            let bound = 4.0 * f64::EPSILON * c.norm() / tau;
            assert!(lam.dot(&d).abs() <= bound, "θ = {angle}: {lam}");
        }
    }

    /// A zero block (no mode moves the point in its tangent plane): the slip velocity is `c`
    /// whatever λ — it sticks with `λ = 0` when `c = 0`, and otherwise slides with
    /// `λ = s c/|c|`, whatever the static disk (it stuck before, with `λ = 0`).
    #[test]
    fn a_zero_block_slides_along_c_unless_c_is_zero() {
        let h = Matrix2::zeros();
        for mode in [LocalSolve::Exact, LocalSolve::Radial] {
            let (lam, st) = local_solve(&h, &Vector2::zeros(), 1.0, 0.5, mode);
            assert_eq!((lam, st), (Vector2::zeros(), Slide::Stick));
            for (c, unit) in [
                (Vector2::new(1e-300, 0.0), Vector2::x()),
                (Vector2::new(-3.0, 4.0), Vector2::new(-0.6, 0.8)),
                (Vector2::new(0.0, 1e300), Vector2::y()),
            ] {
                let (lam, st) = local_solve(&h, &c, 1e6, 0.5, mode);
                assert_eq!(st, Slide::Slip, "{c}");
                let expected = unit * 0.5;
                assert!((lam - expected).norm() <= 1e-16, "{c}: {lam}");
            }
            let (lam, st) = local_solve(&h, &Vector2::new(1.0, 1.0), 1.0, 0.0, mode);
            assert_eq!((lam, st), (Vector2::zeros(), Slide::Slip));
        }
        let block = DiagonalBlock::new(h);
        assert!(block.is_singular() && block.is_zero());
        assert_eq!(block.stick_force(&Vector2::zeros(), 1.0), Vector2::zeros());
        assert!(block.stick_force(&Vector2::new(0.0, 1e-9), 1.0).norm() > 1.0);
        assert!(
            block
                .stick_force(&Vector2::new(0.0, 1e-9), 0.0)
                .norm_squared()
                > 0.0
        );
    }

    /// Continuity across the threshold `τ`: a block `h v vᵀ + ε d dᵀ` whose small eigenvalue
    /// `ε` crosses `τ` (regular above, singular below) gives the same stick/slip answer and the
    /// same λ on both sides, to the relative size `δ` of the step in `ε`, both for a
    /// right-hand side whose null component sticks (`|c·d| = τ s/2`) and for one that slides
    /// (`2τ s`); below `τ` the answer no longer depends on `ε`. For a rotated block (`d` not
    /// an axis) the determinant `h ε` is formed from products of size `h²`: it, the singularity
    /// test and the regular inverse along `d` are then known to `ε_mach h/ε ≈ 1e-4` only, and
    /// the step and the tolerance are `1e-3`.
    #[test]
    fn a_block_crossing_the_singularity_threshold_is_solved_continuously() {
        let (h, s) = (3.0, 0.5);
        for (angle, delta, tolerance) in [(0.0, 1e-7, 1e-6), (0.7, 1e-3, 3e-3)] {
            let v = Vector2::new(f64::cos(angle), f64::sin(angle));
            let d = Vector2::new(-v.y, v.x);
            let block = |eps: f64| v * v.transpose() * h + d * d.transpose() * eps;
            let t0 = SINGULAR_RATIO * block(0.0)[(0, 0)].max(block(0.0)[(1, 1)]);
            for (null, slide) in [(0.5 * t0 * s, Slide::Stick), (2.0 * t0 * s, Slide::Slip)] {
                let c = v * 0.6 + d * null;
                let mut answers = Vec::new();
                for ratio in [1.0 + delta, 1.0 - delta, 0.5, 0.0] {
                    let b = block(ratio * t0);
                    assert_eq!(DiagonalBlock::new(b).is_singular(), ratio < 1.0, "{ratio}");
                    for mode in [LocalSolve::Exact, LocalSolve::Radial] {
                        let (lam, st) = local_solve(&b, &c, s, s, mode);
                        assert_eq!(st, slide, "θ = {angle}, ε = {ratio} τ, {mode:?}");
                        answers.push((ratio, mode, lam));
                    }
                }
                for (ratio, mode, lam) in &answers[2..] {
                    let (_, _, above) = answers[if *mode == LocalSolve::Exact { 0 } else { 1 }];
                    assert!(
                        (lam - above).norm() <= tolerance * s,
                        "θ = {angle}, {slide:?}, {mode:?}: ε = {ratio} τ gives {lam}, above τ {above}"
                    );
                }
            }
        }
    }
}
