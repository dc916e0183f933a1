//! The local problem of one contact, the others frozen (THEORY §4.3, §4.4): stick when the free
//! solution `H_ii⁻¹c` is in the static disk, else slip on the dynamic circle — the radial
//! projection of the free solution, or the exact solution ([`super::disk_boundary`]); a
//! singular block slides when `c` has a component along its null direction.

use std::cell::Cell;

use nalgebra::{Matrix2, Vector2};

use super::block::{DiagonalBlock, unit};
use super::coulomb::{LocalSolve, Slide};
use super::disk_boundary::disk_boundary_solve;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::friction::SINGULAR_RATIO;
    use crate::contact::friction::block::symmetric_eigen2;

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
