//! Spatial correlation of a random force per unit length along a tube (`docs/LOADS.md`,
//! "Spatial correlation along the tube").
//!
//! A force per unit length `f(s, t)` whose cross-PSD between abscissae `s` and `s'` is
//! `S(f) exp(−|s − s'|/λ)` loads the nodes of a beam mesh with the consistent nodal forces
//! `F_i(t) = ∫ N_i(s) f(s, t) ds` (`N_i` the linear shape function of node `i`, the same
//! shares as a uniform line load), so the nodal cross-PSD is `S(f) C_ik` with
//!
//! ```text
//! C_ik = ∫∫ N_i(s) N_k(s') exp(−|s − s'| / λ) ds ds'          (line_covariance)
//! ```
//!
//! Forces with that covariance are `F = L ξ`, `L Lᵀ ≈ C` ([`covariance_factor`]), with `ξ_j`
//! independent signals of PSD `S` ([`crate::loads::turbulence::RandomChannels`]).
//! [`correlated_factor`] is the lumped model of point nodes, `C_ik = w_i w_k exp(−|x_i − x_k|/λ)`.

use nalgebra::DMatrix;

use crate::error::{Error, Result};
pub use crate::structure::line::LineCell;

/// Kernel `exp(−|s − s'|/λ)` below `exp(−CUTOFF)` (4e-18) is left out.
const CUTOFF: f64 = 40.0;
/// Most Gauss sub-intervals per cell: a cell longer than `MAX_SUBDIVISIONS λ` is integrated
/// less accurately (`docs/LOADS.md`).
const MAX_SUBDIVISIONS: usize = 1024;
/// 8-point Gauss–Legendre abscissae and weights on `[−1, 1]`.
const GAUSS: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
];

impl LineCell {
    /// `[N_a(s), N_b(s)]`.
    fn shape(&self, s: f64) -> [f64; 2] {
        let [sa, sb] = self.ends;
        let h = sb - sa;
        [(sb - s) / h, (s - sa) / h]
    }

    /// `[∫ N_a(y) k(x − y) dy, ∫ N_b(y) k(x − y) dy]` over the loaded part, `k(u) =
    /// exp(−|u|/λ)`, in closed form: on each side of `x` the shape function is linear in the
    /// distance `u`, `∫ (N_n + (N_f − N_n) v/δ) e^{−(u₀+v)/λ} dv` over `v ∈ [0, δ]`
    /// `= λ e^{−u₀/λ} (N_n ψ(δ/λ) + (N_f − N_n) χ(δ/λ))` with `N_n`, `N_f` the values at the
    /// near and far ends, `ψ(r) = 1 − e^{−r}`, `χ(r) = (1 − (1 + r) e^{−r})/r`.
    fn kernel_integrals(&self, x: f64, lambda: f64) -> [f64; 2] {
        let [p, q] = self.loaded;
        let mut out = [0.0; 2];
        if x > p {
            self.add_side(x, q.min(x), p, lambda, &mut out);
        }
        if x < q {
            self.add_side(x, p.max(x), q, lambda, &mut out);
        }
        out
    }

    fn add_side(&self, x: f64, near: f64, far: f64, lambda: f64, out: &mut [f64; 2]) {
        let delta = (far - near).abs();
        if delta == 0.0 {
            return;
        }
        let (nn, nf) = (self.shape(near), self.shape(far));
        let (scale, psi, chi) = if lambda.is_infinite() {
            (1.0, delta, 0.5 * delta)
        } else {
            let r = delta / lambda;
            let decay = lambda * (-(near - x).abs() / lambda).exp();
            (decay, -(-r).exp_m1(), phi_over_r(r))
        };
        for j in 0..2 {
            out[j] += scale * (nn[j] * psi + (nf[j] - nn[j]) * chi);
        }
    }
}

/// `χ(r) = (1 − (1 + r) e^{−r}) / r = Σ_{n≥2} (−1)ⁿ (n − 1) r^{n−1} / n!`, the series below
/// `r = 0.1` where the closed form cancels.
fn phi_over_r(r: f64) -> f64 {
    if r >= 0.1 {
        (1.0 - (1.0 + r) * (-r).exp()) / r
    } else {
        phi_over_r_series(r)
    }
}

fn phi_over_r_series(r: f64) -> f64 {
    let mut sum = 0.0;
    let mut power = 1.0; // r^{n−1}
    let mut factorial = 1.0; // n!
    for n in 2..18 {
        power *= r;
        factorial *= n as f64;
        let term = (n - 1) as f64 * power / factorial;
        sum += if n % 2 == 0 { term } else { -term };
    }
    sum
}

/// The covariance `C_ik = ∫∫ N_i(s) N_k(s') exp(−|s − s'|/λ) ds ds'` (m²) of the consistent
/// nodal forces of a unit-variance force per unit length with correlation length `λ`, over
/// `n` nodes and the `cells` that carry the load (module doc). `λ = ∞` gives `w wᵀ` with
/// `w_i = ∫ N_i`; `λ → 0` tends to `2λ ∫ N_i N_k`. The inner integral is exact
/// ([`LineCell`]), the outer one 8-point Gauss–Legendre on sub-intervals no longer than `λ`
/// (at most 1024 per cell); the result is symmetrised. Input errors name `cells[j]` or
/// `correlation_length`.
pub fn line_covariance(
    n: usize,
    cells: &[LineCell],
    correlation_length: f64,
) -> Result<DMatrix<f64>> {
    let lambda = correlation_length;
    if !(lambda > 0.0) {
        return Err(Error::invalid(
            "correlation_length",
            format!(
                "must be > 0 m (infinity: fully correlated); a force per unit length correlated \
                 over 0 m has no resultant. Got {lambda}"
            ),
        ));
    }
    if cells.is_empty() {
        return Err(Error::invalid("cells", "needs at least one loaded element"));
    }
    for (j, c) in cells.iter().enumerate() {
        let [sa, sb] = c.ends;
        let [s0, s1] = c.loaded;
        let ok = [sa, sb, s0, s1].iter().all(|v| v.is_finite())
            && sa < sb
            && sa <= s0
            && s0 < s1
            && s1 <= sb
            && c.nodes.iter().all(|&i| i < n);
        if !ok {
            return Err(Error::invalid(
                format!("cells[{j}]"),
                format!(
                    "needs node rows below {n}, finite ends s_a < s_b and a loaded part \
                     s_a ≤ s0 < s1 ≤ s_b (got nodes {:?}, ends {:?}, loaded {:?})",
                    c.nodes, c.ends, c.loaded
                ),
            ));
        }
    }
    let mut cov = DMatrix::zeros(n, n);
    for outer in cells {
        let [lo, hi] = outer.loaded;
        let parts = if lambda.is_infinite() {
            1
        } else {
            (((hi - lo) / lambda).ceil() as usize).clamp(1, MAX_SUBDIVISIONS)
        };
        let h = (hi - lo) / parts as f64;
        for part in 0..parts {
            for &(xi, wg) in &GAUSS {
                let x = lo + h * (part as f64 + 0.5 * (1.0 + xi));
                let weight = 0.5 * h * wg;
                let nx = outer.shape(x);
                for inner in cells {
                    let [p, q] = inner.loaded;
                    let gap = (p - x).max(x - q).max(0.0);
                    if gap > CUTOFF * lambda {
                        continue;
                    }
                    let k = inner.kernel_integrals(x, lambda);
                    for a in 0..2 {
                        for b in 0..2 {
                            cov[(outer.nodes[a], inner.nodes[b])] += weight * nx[a] * k[b];
                        }
                    }
                }
            }
        }
    }
    let sym = 0.5 * (&cov + cov.transpose());
    Ok(sym)
}

/// Factor `L` (n × m, `m` ≤ n) with `L Lᵀ ≈ C` of a symmetric positive semi-definite
/// covariance, from the symmetric eigen-decomposition `C = Σ μ_p v_p v_pᵀ`: the columns
/// `√μ_p v_p` of the fewest largest eigenvalues whose sum reaches `(1 − tolerance) tr C`
/// (`tolerance = 0` keeps every eigenvalue above the round-off level `8 n ε tr C`). Each
/// column has its largest entry positive. A zero `C` gives one zero column. Input errors
/// name `covariance` or `tolerance`.
pub fn covariance_factor(covariance: DMatrix<f64>, tolerance: f64) -> Result<DMatrix<f64>> {
    let n = covariance.nrows();
    if n == 0 || covariance.ncols() != n {
        return Err(Error::invalid(
            "covariance",
            format!(
                "must be a non-empty square matrix (got {} × {})",
                n,
                covariance.ncols()
            ),
        ));
    }
    if let Some(k) = covariance.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            "covariance",
            format!("entry ({}, {}) is not finite", k % n, k / n),
        ));
    }
    if !(tolerance.is_finite() && (0.0..1.0).contains(&tolerance)) {
        return Err(Error::invalid(
            "tolerance",
            format!(
                "must be in [0, 1): the fraction of the trace the truncated factor may miss \
                 (got {tolerance})"
            ),
        ));
    }
    let trace = covariance.trace();
    if trace <= 0.0 {
        return Ok(DMatrix::zeros(n, 1));
    }
    let eig = nalgebra::SymmetricEigen::new(covariance);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let target = (1.0 - tolerance) * trace;
    // Eigenvalues at the level of the round-off of the decomposition are zeros.
    let negligible = 8.0 * n as f64 * f64::EPSILON * trace;
    let mut kept = 0;
    let mut sum = 0.0;
    for &p in &order {
        let mu = eig.eigenvalues[p];
        if !(mu > negligible) {
            break;
        }
        kept += 1;
        sum += mu;
        if sum >= target {
            break;
        }
    }
    let kept = kept.max(1);
    let mut l = DMatrix::zeros(n, kept);
    for (col, &p) in order.iter().take(kept).enumerate() {
        let v = eig.eigenvectors.column(p);
        let scale = eig.eigenvalues[p].max(0.0).sqrt();
        let big = v
            .iter()
            .fold(0.0_f64, |m, &x| if x.abs() > m.abs() { x } else { m });
        let sign = if big < 0.0 { -1.0 } else { 1.0 };
        for i in 0..n {
            l[(i, col)] = sign * scale * v[i];
        }
    }
    Ok(l)
}

/// The lumped model of point nodes: the factor ([`covariance_factor`]) of
/// `C_ik = w_i w_k exp(−|x_i − x_k|/λ)`.
///
/// `positions` `x_i` (m) and `weights` `w_i` (the length of tube attached to node `i`, m) give
/// nodal forces `F_i = Σ_j L_ij ξ_j(t)` with cross-PSD `S(f) w_i w_k exp(−|x_i − x_k|/λ)` when
/// the `ξ_j` are independent with PSD `S` ([`crate::loads::turbulence::RandomChannels`]). `λ = ∞` (fully correlated)
/// gives rank 1, `λ = 0` independent nodes (`L = diag(w)` up to column order). An all-zero
/// `w` gives one zero column. Input errors name the argument (`positions`, `weights`,
/// `correlation_length`, `tolerance`).
///
/// For the nodes of a beam mesh, `w_i w_k exp(−|x_i − x_k|/λ)` is the midpoint rule of
/// [`line_covariance`]: it overstates the nodal variance unless the elements are short
/// compared with `λ` (by 3 % at `w = λ/10`); tubes use [`line_covariance`].
pub fn correlated_factor(
    positions: &[f64],
    weights: &[f64],
    correlation_length: f64,
    tolerance: f64,
) -> Result<DMatrix<f64>> {
    let n = positions.len();
    if n == 0 {
        return Err(Error::invalid("positions", "needs at least one node"));
    }
    if weights.len() != n {
        return Err(Error::invalid(
            "weights",
            format!(
                "must have one weight per position: {} weights for {} positions",
                weights.len(),
                n
            ),
        ));
    }
    if let Some(i) = positions.iter().position(|x| !x.is_finite()) {
        return Err(Error::invalid(
            format!("positions[{i}]"),
            format!("must be a finite abscissa in m (got {})", positions[i]),
        ));
    }
    if let Some(i) = weights.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
        return Err(Error::invalid(
            format!("weights[{i}]"),
            format!("must be a finite tube length ≥ 0 in m (got {})", weights[i]),
        ));
    }
    if !(correlation_length >= 0.0) {
        return Err(Error::invalid(
            "correlation_length",
            format!(
                "must be ≥ 0 in m (0: independent nodes, infinity: fully correlated), got \
                 {correlation_length}"
            ),
        ));
    }
    let c = DMatrix::from_fn(n, n, |i, k| {
        let dx = (positions[i] - positions[k]).abs();
        let rho = if dx == 0.0 {
            1.0
        } else {
            (-dx / correlation_length).exp()
        };
        weights[i] * weights[k] * rho
    });
    covariance_factor(c, tolerance)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field_of(e: Error) -> String {
        e.field().expect("an input error").to_string()
    }

    #[test]
    fn turbulence_correlated_factor_validation() {
        let x = [0.0, 1.0];
        let w = [1.0, 1.0];
        let e = |r: Result<DMatrix<f64>>| field_of(r.unwrap_err());
        assert_eq!(e(correlated_factor(&[], &[], 1.0, 0.0)), "positions");
        assert_eq!(e(correlated_factor(&x, &[1.0], 1.0, 0.0)), "weights");
        assert_eq!(
            e(correlated_factor(&[0.0, f64::NAN], &w, 1.0, 0.0)),
            "positions[1]"
        );
        assert_eq!(
            e(correlated_factor(&x, &[1.0, -1.0], 1.0, 0.0)),
            "weights[1]"
        );
        assert_eq!(
            e(correlated_factor(&x, &w, -1.0, 0.0)),
            "correlation_length"
        );
        assert_eq!(
            e(correlated_factor(&x, &w, f64::NAN, 0.0)),
            "correlation_length"
        );
        assert_eq!(e(correlated_factor(&x, &w, 1.0, 1.0)), "tolerance");
        assert_eq!(e(correlated_factor(&x, &w, 1.0, -0.1)), "tolerance");
        let zero = correlated_factor(&x, &[0.0, 0.0], 1.0, 0.0).unwrap();
        assert_eq!(zero.shape(), (2, 1));
        assert!(zero.iter().all(|&v| v == 0.0));
    }

    /// A non-uniform mesh of `[0, 1]` whose load covers `[a, b]` (clipped mid-element).
    fn mesh(a: f64, b: f64) -> (usize, Vec<LineCell>) {
        let s = ABSCISSAE;
        let mut cells = Vec::new();
        for e in 0..s.len() - 1 {
            let (lo, hi) = (s[e].max(a), s[e + 1].min(b));
            if hi > lo {
                cells.push(LineCell {
                    nodes: [e, e + 1],
                    ends: [s[e], s[e + 1]],
                    loaded: [lo, hi],
                });
            }
        }
        (s.len(), cells)
    }

    const ABSCISSAE: [f64; 8] = [0.0, 0.07, 0.2, 0.26, 0.5, 0.55, 0.81, 1.0];

    /// `Σ_ik C_ik = ∫∫ exp(−|x − y|/λ)` and `Σ_ik s_i s_k C_ik = ∫∫ x y exp(−|x − y|/λ)` over
    /// the loaded span (the shape functions sum to 1 and reproduce `s`): closed forms, for
    /// correlation lengths from 1/1000 to 100 times the span.
    #[test]
    fn line_covariance_integrates_the_kernel_and_its_moment() {
        let (a, b) = (0.03, 0.9);
        let (n, cells) = mesh(a, b);
        let l = b - a;
        for lambda in [1e-3, 1e-2, 0.05, 0.3, 1.0, 10.0, 100.0] {
            let c = line_covariance(n, &cells, lambda).unwrap();
            let r = l / lambda;
            let total = 2.0 * lambda * lambda * (r + (-r).exp_m1());
            let moment = if r > 0.5 {
                lambda / 3.0
                    * (2.0 * l.powi(3) - 3.0 * l * l * lambda + 6.0 * lambda.powi(3)
                        - (6.0 * l * lambda * lambda + 6.0 * lambda.powi(3)) * (-r).exp())
            } else {
                // its Taylor series in r (the closed form cancels)
                let c = [
                    1.0 / 4.0,
                    -1.0 / 15.0,
                    1.0 / 72.0,
                    -1.0 / 420.0,
                    1.0 / 2880.0,
                    -1.0 / 22680.0,
                    1.0 / 201600.0,
                    -1.0 / 1995840.0,
                    1.0 / 21772800.0,
                ];
                l.powi(4) * c.iter().rev().fold(0.0, |acc, ci| acc * r + ci)
            };
            let x: Vec<f64> = ABSCISSAE.iter().map(|s| s - a).collect();
            let (mut sum, mut first) = (0.0, 0.0);
            for i in 0..n {
                for k in 0..n {
                    sum += c[(i, k)];
                    first += x[i] * x[k] * c[(i, k)];
                }
            }
            let (e0, e1) = ((sum / total - 1.0).abs(), (first / moment - 1.0).abs());
            eprintln!("λ = {lambda}: sum {e0:.1e}, moment {e1:.1e}");
            assert!(e0 < 1e-11 && e1 < 1e-11, "λ = {lambda}: {e0:.1e} {e1:.1e}");
        }
    }

    /// Fully correlated: `C = w wᵀ` with `w_i = ∫ N_i`; a correlation length far below the
    /// elements: `C → 2λ ∫ N_i N_k` (the consistent "mass" of the span) up to `O(λ/h)`.
    #[test]
    fn line_covariance_limits() {
        let (n, cells) = mesh(0.1, 0.7);
        let mut w = vec![0.0; n];
        let mut mass = DMatrix::zeros(n, n);
        for c in &cells {
            let ([sa, sb], [lo, hi]) = (c.ends, c.loaded);
            // exact integrals of N_a, N_b and their products on [lo, hi] (Simpson is exact)
            let mid = 0.5 * (lo + hi);
            let (na, nm, nb) = (c.shape(lo), c.shape(mid), c.shape(hi));
            for j in 0..2 {
                w[c.nodes[j]] += (hi - lo) * (na[j] + 4.0 * nm[j] + nb[j]) / 6.0;
                for k in 0..2 {
                    let f = |v: [f64; 2]| v[j] * v[k];
                    mass[(c.nodes[j], c.nodes[k])] +=
                        (hi - lo) * (f(na) + 4.0 * f(nm) + f(nb)) / 6.0;
                }
            }
            assert!(sa <= lo && hi <= sb);
        }
        let full = line_covariance(n, &cells, f64::INFINITY).unwrap();
        let outer = DMatrix::from_fn(n, n, |i, k| w[i] * w[k]);
        assert!(
            (&full - &outer).amax() < 1e-15,
            "{}",
            (&full - &outer).amax()
        );
        let lambda = 1e-6;
        let short = line_covariance(n, &cells, lambda).unwrap() / (2.0 * lambda);
        let err = (&short - &mass).amax() / mass.amax();
        eprintln!("λ = 1e-6: C/2λ vs consistent mass {err:.1e}");
        assert!(err < 1e-4, "{err:.1e}");
    }

    /// Each entry against a brute-force double midpoint sum on a fine grid, extrapolated
    /// (Richardson, the kink of the kernel on the diagonal makes the error `O(Δ²)`).
    #[test]
    fn line_covariance_matches_a_brute_force_double_sum() {
        let (n, cells) = mesh(0.0, 1.0);
        let lambda = 0.15;
        let exact = line_covariance(n, &cells, lambda).unwrap();
        let brute = |m: usize| {
            let d = 1.0 / m as f64;
            let xs: Vec<f64> = (0..m).map(|p| (p as f64 + 0.5) * d).collect();
            // shape values at each grid point: (row, value) of the element containing it
            let shapes: Vec<[(usize, f64); 2]> = xs
                .iter()
                .map(|&x| {
                    let c = cells
                        .iter()
                        .find(|c| c.loaded[0] <= x && x <= c.loaded[1])
                        .unwrap();
                    let v = c.shape(x);
                    [(c.nodes[0], v[0]), (c.nodes[1], v[1])]
                })
                .collect();
            let mut c = DMatrix::zeros(n, n);
            for p in 0..m {
                for q in 0..m {
                    let k = d * d * (-(xs[p] - xs[q]).abs() / lambda).exp();
                    for &(i, a) in &shapes[p] {
                        for &(j, b) in &shapes[q] {
                            c[(i, j)] += a * b * k;
                        }
                    }
                }
            }
            c
        };
        let (coarse, fine) = (brute(400), brute(800));
        let extrapolated: DMatrix<f64> = (&fine * 4.0 - &coarse) / 3.0;
        let scale = exact.amax();
        let err = (&extrapolated - &exact).amax() / scale;
        let raw = (&fine - &exact).amax() / scale;
        eprintln!("brute force: {err:.1e} extrapolated, {raw:.1e} at 800 points");
        assert!(
            err < 1e-6 && err < 0.05 * raw,
            "{err:.1e} (unextrapolated {raw:.1e})"
        );
    }

    #[test]
    fn line_covariance_series_meets_the_closed_form() {
        let r: f64 = 0.1;
        let closed = (1.0 - (1.0 + r) * (-r).exp()) / r;
        // the closed form keeps ~13 digits at r = 0.1 (1 − 1.1 e^{−0.1} = 0.0047)
        assert!((phi_over_r_series(r) / closed - 1.0).abs() < 2e-13);
        assert!((phi_over_r(1e-8) / 0.5e-8 - 1.0).abs() < 1e-8);
    }

    #[test]
    fn line_covariance_validation() {
        let (n, cells) = mesh(0.0, 1.0);
        let e = |r: Result<DMatrix<f64>>| field_of(r.unwrap_err());
        for lambda in [0.0, -1.0, f64::NAN] {
            assert_eq!(e(line_covariance(n, &cells, lambda)), "correlation_length");
        }
        assert_eq!(e(line_covariance(n, &[], 1.0)), "cells");
        let mut bad = cells.clone();
        bad[2].loaded = [0.3, 0.2];
        assert_eq!(e(line_covariance(n, &bad, 1.0)), "cells[2]");
        let mut bad = cells.clone();
        bad[1].nodes = [1, n];
        assert_eq!(e(line_covariance(n, &bad, 1.0)), "cells[1]");
        assert_eq!(
            e(covariance_factor(DMatrix::zeros(2, 3), 0.0)),
            "covariance"
        );
        let nan = DMatrix::from_element(2, 2, f64::NAN);
        assert_eq!(e(covariance_factor(nan, 0.0)), "covariance");
    }
}
