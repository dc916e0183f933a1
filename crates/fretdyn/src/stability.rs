//! Stable time step of central differences with penalty contacts (THEORY §2).
//!
//! Undamped central differences need `Δt < 2/ω_max`, `ω_max²` the largest eigenvalue of
//! `Ω² + Σ_c Φ_cᵀ (K_N n nᵀ + K_T T Tᵀ) Φ_c`, bounded by taking every contact closed. The
//! velocity-proportional contact forces (`C_N`, `C_T`) are computed from the predicted velocity,
//! i.e. explicitly; their largest rate `c_max` (same construction) lowers the limit to
//! `(2/ω_max)(√(1+ζ²) − ζ)`, `ζ = c_max/(2 ω_max)`, the limit of an explicitly damped oscillator.

use nalgebra::{DMatrix, Vector3};

use crate::model::{Coordinates, Model};
use crate::tangential::TangentialMethod;

/// The stable time step of `model` with `method`, s. In physical coordinates the
/// eigenvalues are those of `K φ = ω² M φ` (and `C φ = c M φ`).
pub fn stable_time_step(model: &Model, method: &TangentialMethod) -> f64 {
    let p = model.basis.modes();
    let (mut k, mut c) = match &model.coordinates {
        Coordinates::Modal => {
            let mut k = DMatrix::<f64>::zeros(p, p);
            for (i, w) in model.basis.omega.iter().enumerate() {
                k[(i, i)] = w * w;
            }
            (k, DMatrix::<f64>::zeros(p, p))
        }
        // structural damping acts through A (implicitly): only contact damping is explicit
        Coordinates::Physical(m) => (m.stiffness.clone(), DMatrix::<f64>::zeros(p, p)),
    };
    let (kt, ct) = match method {
        TangentialMethod::Penalty(s) => (s.stiffness, s.damping),
        _ => (0.0, 0.0),
    };
    for contact in &model.contacts {
        let point = &model.basis.points[contact.point];
        let (normals, tangents) = contact.obstacle.penalty_directions();
        if !contact.at_surface() {
            for n in &normals {
                add_direction(&mut k, &point.rows, n, contact.normal.stiffness);
                add_direction(&mut c, &point.rows, n, contact.normal.damping);
            }
            for ta in &tangents {
                add_direction(&mut k, &point.rows, ta, kt);
                add_direction(&mut c, &point.rows, ta, ct);
            }
            continue;
        }
        // on the surface the rows depend on the normal: each normal the contact can take (both
        // senses) with the tangents orthogonal to it (a tangent may be counted more than once:
        // conservative)
        let mut rows = point.rows.clone();
        for n in normals.iter().flat_map(|n| [*n, -n]) {
            contact.surface_rows(point, &n, &mut rows);
            add_direction(&mut k, &rows, &n, contact.normal.stiffness);
            add_direction(&mut c, &rows, &n, contact.normal.damping);
            for ta in tangents.iter().filter(|ta| ta.dot(&n).abs() < 1e-9) {
                add_direction(&mut k, &rows, ta, kt);
                add_direction(&mut c, &rows, ta, ct);
            }
        }
    }
    let (w2, cmax) = match &model.coordinates {
        Coordinates::Modal => (largest_eigenvalue(k), largest_eigenvalue(c)),
        Coordinates::Physical(m) => match m.mass.clone().cholesky() {
            Some(chol) => {
                // L⁻¹ X L⁻ᵀ has the eigenvalues of X φ = λ M φ
                let scaled = |x: DMatrix<f64>| {
                    let y = chol.l().solve_lower_triangular(&x).unwrap_or(x);
                    let z = chol.l().solve_lower_triangular(&y.transpose()).unwrap_or(y);
                    largest_eigenvalue((&z + z.transpose()) * 0.5)
                };
                (scaled(k), scaled(c))
            }
            None => return 0.0,
        },
    };
    if w2 <= 0.0 {
        return f64::INFINITY;
    }
    let w = w2.sqrt();
    let zeta = cmax / (2.0 * w);
    (2.0 / w) * ((1.0 + zeta * zeta).sqrt() - zeta)
}

/// `m += s (Φ_cᵀ d)(Φ_cᵀ d)ᵀ`.
fn add_direction(m: &mut DMatrix<f64>, rows: &[f64], d: &Vector3<f64>, s: f64) {
    if s == 0.0 {
        return;
    }
    let p = m.nrows();
    let v: Vec<f64> = (0..p)
        .map(|i| d.x * rows[i] + d.y * rows[p + i] + d.z * rows[2 * p + i])
        .collect();
    for i in 0..p {
        for j in 0..p {
            m[(i, j)] += s * v[i] * v[j];
        }
    }
}

fn largest_eigenvalue(m: DMatrix<f64>) -> f64 {
    m.symmetric_eigenvalues().max()
}
