//! The exact slip solution of a contact's local problem (THEORY §4.4): `λ` on the dynamic
//! circle along the slip velocity it leaves, `w = c − H_ii λ`, from the secular equation of
//! `H_ii`'s eigen-decomposition, solved by Newton from a warm start.

use std::cell::Cell;

use nalgebra::Vector2;

use super::block::DiagonalBlock;

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
pub(super) fn disk_boundary_solve(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::friction::{LocalSolve, Slide, inverse2, local_solve};
    use nalgebra::Matrix2;

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
}
