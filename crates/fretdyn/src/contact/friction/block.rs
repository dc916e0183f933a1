//! A contact's 2 × 2 diagonal block `H_ii` of the Delassus operator prepared for its local
//! solves ([`DiagonalBlock`]): its inverse, its eigen-decomposition in closed form, and the
//! regularisation of a singular block (THEORY §4.4, §4.6).

use std::cell::Cell;

use nalgebra::{Matrix2, Vector2};

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
    pub(super) inverse: Matrix2<f64>,
    /// The eigen-decomposition `H = Q diag(h) Qᵀ` for the exact slip solution, once formed.
    pub(super) eigen: Cell<Option<(Matrix2<f64>, [f64; 2])>>,
    pub(super) isotropic: bool,
    /// An eigenvalue at most `τ` ([`Self::is_singular`]).
    pub(super) singular: bool,
    /// `2/tr(H_ii)` ([`Self::rho`]).
    pub(super) rho: f64,
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
    pub(super) fn eigen(&self) -> (Matrix2<f64>, [f64; 2]) {
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
    /// and goes to [`singular_solve`](super::local_solve)).
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
    pub(super) fn raised_free(&self, c: &Vector2<f64>) -> Vector2<f64> {
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
pub(super) fn unit(c: &Vector2<f64>) -> Option<Vector2<f64>> {
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

/// `H = h I`: then `(sH + tI)u = c` makes `u` parallel to `c`, hence to `H⁻¹c`, and the exact
/// slip solution is the radial projection of the free one, in closed form.
#[inline]
pub(super) fn is_isotropic(h: &Matrix2<f64>) -> bool {
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

/// Eigen-decomposition `H = Q diag(h) Qᵀ` of a symmetric 2 × 2 matrix, in closed form: the
/// Jacobi rotation that zeroes `h₁₂` (Golub & Van Loan, *Matrix Computations*, §8.5.2,
/// `sym.schur2`), `τ = (h₂₂ − h₁₁)/(2h₁₂)`, `t = sign(τ)/(|τ| + √(1 + τ²))`, `c = 1/√(1 + t²)`,
/// `s = t c`, without trigonometric functions (this runs in every local solve).
#[inline]
pub(super) fn symmetric_eigen2(h: &Matrix2<f64>) -> (Matrix2<f64>, [f64; 2]) {
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
    use super::*;

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
}
