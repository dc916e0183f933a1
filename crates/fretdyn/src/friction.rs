//! Coulomb friction with static and dynamic coefficients, and the exact solution of one
//! contact's local tangential problem (THEORY §4, §4.4).
//!
//! Sign convention: the tangential multiplier `λ` of a contact is minus the tangential force of
//! the obstacle on the structure in the contact's tangent basis, `R_T = −λ`. Sliding means
//! `λ = μ_d R_N v/|v|` (the force opposes the slip velocity), sticking `|λ| ≤ μ_s R_N`, `v = 0`.

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

/// Solves one contact's tangential problem with the other contacts frozen:
/// find `λ` such that, with `w = c − H λ` (the slip velocity up to the factor θΔt),
/// either `w = 0` and `|λ| ≤ s_static` (stick), or `λ = s_dynamic w/|w|` (slip).
///
/// `h` is the contact's 2 × 2 diagonal block of the Delassus operator (SPD), `c` the right-hand
/// side with the other contacts' multipliers subtracted.
#[inline]
pub fn local_solve(
    h: &Matrix2<f64>,
    c: &Vector2<f64>,
    s_static: f64,
    s_dynamic: f64,
    mode: LocalSolve,
) -> (Vector2<f64>, Slide) {
    let free = solve2(h, c);
    if free.norm() <= s_static {
        return (free, Slide::Stick);
    }
    if s_dynamic <= 0.0 {
        return (Vector2::zeros(), Slide::Slip);
    }
    let lambda = match mode {
        LocalSolve::Radial => free * (s_dynamic / free.norm()),
        LocalSolve::Exact => disk_boundary_solve(h, c, s_dynamic),
    };
    (lambda, Slide::Slip)
}

/// `H⁻¹ c` for a 2 × 2 matrix, with a pseudo-inverse fallback when `H` is singular.
#[inline]
pub fn solve2(h: &Matrix2<f64>, c: &Vector2<f64>) -> Vector2<f64> {
    let det = h[(0, 0)] * h[(1, 1)] - h[(0, 1)] * h[(1, 0)];
    let scale = h[(0, 0)].abs().max(h[(1, 1)].abs());
    if det.abs() > 1e-13 * scale * scale {
        Vector2::new(
            (h[(1, 1)] * c.x - h[(0, 1)] * c.y) / det,
            (h[(0, 0)] * c.y - h[(1, 0)] * c.x) / det,
        )
    } else if scale > 0.0 {
        // Rank one (or zero): least-squares solution along the dominant eigenvector.
        let eig = h.symmetric_eigen();
        let mut out = Vector2::zeros();
        for k in 0..2 {
            let e = eig.eigenvalues[k];
            if e.abs() > 1e-13 * scale {
                let v = eig.eigenvectors.column(k);
                out += v * (v.dot(c) / e);
            }
        }
        out
    } else {
        Vector2::zeros()
    }
}

/// The slip solution on the circle of radius `s`: `λ = s u`, `|u| = 1`, `(s H + t I) u = c`,
/// `t > 0` (then `w = c − Hλ = t u` is along `λ`). In the eigenbasis of `H` the condition is
/// the secular equation `Σ c_k²/(s h_k + t)² = 1`, solved by Newton on `φ(t) = 1/|u(t)| − 1`,
/// which is concave and increasing so Newton from `t = 0` converges monotonically.
fn disk_boundary_solve(h: &Matrix2<f64>, c: &Vector2<f64>, s: f64) -> Vector2<f64> {
    let (q, eigenvalues) = symmetric_eigen2(h);
    let hs = [s * eigenvalues[0], s * eigenvalues[1]];
    let cp = q.transpose() * c;
    let norm_u = |t: f64| {
        let a = cp[0] / (hs[0] + t);
        let b = cp[1] / (hs[1] + t);
        (a * a + b * b).sqrt()
    };
    // Start below the root: |c| = |(sH + tI)u| ≤ s h_max + t gives t* ≥ |c| − s h_max.
    let mut t = (-hs[0].min(hs[1]))
        .max(c.norm() - hs[0].max(hs[1]))
        .max(0.0);
    if !(norm_u(t) > 1.0) {
        // Only possible through round-off at the disk edge: project radially.
        let free = solve2(h, c);
        let n = free.norm();
        return if n > 0.0 { free * (s / n) } else { free };
    }
    for _ in 0..100 {
        let a = cp[0] / (hs[0] + t);
        let b = cp[1] / (hs[1] + t);
        let n2 = a * a + b * b;
        let n = n2.sqrt();
        let phi = 1.0 / n - 1.0;
        let dphi = (a * a / (hs[0] + t) + b * b / (hs[1] + t)) / (n2 * n);
        let step = phi / dphi;
        t -= step;
        if step.abs() <= 1e-15 * t.abs().max(f64::MIN_POSITIVE) {
            break;
        }
    }
    let u = q * Vector2::new(cp[0] / (hs[0] + t), cp[1] / (hs[1] + t));
    u * (s / u.norm())
}

/// Eigen-decomposition `H = Q diag(h) Qᵀ` of a symmetric 2 × 2 matrix, in closed form
/// (Jacobi rotation by `θ = ½ atan2(2 h₁₂, h₁₁ − h₂₂)`).
#[inline]
fn symmetric_eigen2(h: &Matrix2<f64>) -> (Matrix2<f64>, [f64; 2]) {
    let (a, b, d) = (h[(0, 0)], 0.5 * (h[(0, 1)] + h[(1, 0)]), h[(1, 1)]);
    let theta = 0.5 * (2.0 * b).atan2(a - d);
    let (sn, cs) = theta.sin_cos();
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
        ] {
            let (q, e) = symmetric_eigen2(&h);
            let back = q * Matrix2::new(e[0], 0.0, 0.0, e[1]) * q.transpose();
            assert!((back - h).norm() < 1e-14 * h.norm(), "{h} vs {back}");
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

    #[test]
    fn stick_inside_static_disk() {
        let h = Matrix2::new(1.0, 0.0, 0.0, 1.0);
        let c = Vector2::new(0.1, 0.2);
        let (lam, st) = local_solve(&h, &c, 1.0, 0.5, LocalSolve::Exact);
        assert_eq!(st, Slide::Stick);
        assert_eq!(lam, c);
    }
}
