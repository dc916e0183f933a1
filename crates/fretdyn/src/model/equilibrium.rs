//! The static equilibrium of a model resting on its contacts (THEORY §16.1): the state a
//! preloaded run starts from, and a tube pressed statically on a bar.
//!
//! At rest (`q̇ = 0`, no damping force) the equations of motion reduce to
//!
//! ```text
//!   K q = Σ_c g_c(q) F_c(q) + f,    F_c = K_N,c max(0, δ_c(q)),    g_c = Φ_cᵀ n_c
//! ```
//!
//! with `K = Ω²` in modal coordinates (`M = I`) or the stiffness matrix in physical ones,
//! `δ_c` the penetration of contact `c` at the position `x_c = x0_c + Φ_c q` of the point it
//! sees (its structure point, or the relative point of a pair, THEORY §15), `n_c` its normal
//! and `f` a constant modal force. The friction force is zero at rest (nothing slides), the
//! contact damping `C_N δ̇` too.
//!
//! Newton's method with an active set solves it: at the iterate `q`, the closed contacts
//! (`δ_c > 0`) give the tangent matrix `J = K + Σ_closed K_N,c g_c g_cᵀ` and the step
//! `J Δq = −r(q)`, `r = K q − Σ g_c F_c − f`; the geometry (penetration, normal) is
//! re-evaluated at every iterate. For planes `r` is affine on each active set, so the step
//! is exact once the set is right; on curved obstacles (holes, rods) the normal turns with
//! the point and a few more steps are needed. It stops when the active set no longer
//! changes and the step is at round-off (`‖Δq‖∞ ≤ 1e-12 ‖q‖∞`, or exactly zero), or fails
//! with a typed error.

use nalgebra::{DMatrix, DVector, Vector3};

use super::{Coordinates, Model};
use crate::error::{Error, Result};

/// Iterations after which [`static_equilibrium`] gives up.
const MAX_ITERATIONS: usize = 200;

/// Relative size of the last Newton step at which the equilibrium is converged (round-off).
const STEP_TOLERANCE: f64 = 1e-12;

/// Relative size of the singular values of the tangent matrix taken as zero (free modes).
const SINGULAR: f64 = 1e-12;

/// Largest residual `‖r‖∞` of a converged equilibrium, relative to the largest term of the
/// sum `K q − Σ g F − f` (round-off, with room for the cancellation between them).
const RESIDUAL_TOLERANCE: f64 = 1e-9;

/// A static equilibrium ([`static_equilibrium`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StaticState {
    /// Generalised displacements `q` at equilibrium.
    pub q: Vec<f64>,
    /// Normal force `F_c = K_N max(0, δ_c)` of each contact, N (0 when open).
    pub forces: Vec<f64>,
    /// Penetration `δ_c` of each contact at equilibrium, m (negative: the clearance).
    pub penetrations: Vec<f64>,
    /// Newton iterations taken.
    pub iterations: usize,
}

/// One contact at `q`: its penetration and `g_c = Φ_cᵀ n_c` (p values).
pub(super) fn contact_at(model: &Model, c: usize, q: &[f64], g: &mut [f64]) -> f64 {
    let contact = &model.contacts[c];
    let point = contact.point_in(&model.basis.points);
    let p = q.len();
    let mut x: Vector3<f64> = point.coords;
    for d in 0..3 {
        let row = &point.rows[d * p..(d + 1) * p];
        x[d] += row.iter().zip(q).map(|(a, b)| a * b).sum::<f64>();
    }
    let frame = contact.frame(&x, 0.0);
    let n = frame.normal;
    for (i, gi) in g.iter_mut().enumerate() {
        *gi = n.x * point.rows[i] + n.y * point.rows[p + i] + n.z * point.rows[2 * p + i];
    }
    frame.penetration
}

/// Refuses an equilibrium whose residual is not at round-off: a constant force on a mode that
/// nothing holds (zero stiffness, no closed contact) has no static equilibrium.
fn check_residual(
    stiffness: &DMatrix<f64>,
    q: &DVector<f64>,
    f: &[f64],
    model: &Model,
    g: &[Vec<f64>],
    delta: &[f64],
) -> Result<()> {
    let kq = stiffness * q;
    let mut r = &kq - DVector::from_column_slice(f);
    let mut scale = kq.amax().max(f.iter().fold(0.0, |m, v| m.max(v.abs())));
    for (c, gc) in g.iter().enumerate() {
        let force = model.contacts[c].normal.stiffness * delta[c].max(0.0);
        for (ri, gi) in r.iter_mut().zip(gc) {
            *ri -= force * gi;
            scale = scale.max((force * gi).abs());
        }
    }
    if r.amax() > RESIDUAL_TOLERANCE * scale {
        return Err(Error::invalid(
            "static_equilibrium",
            format!(
                "no static equilibrium (residual {:.3e} of {:.3e}): a constant force pushes a mode of zero stiffness that no contact holds",
                r.amax(),
                scale
            ),
        ));
    }
    Ok(())
}

/// The static equilibrium of `model` on its contacts under the constant modal force
/// `modal_force` (`None`: no force), from `q = 0` (THEORY §16.1, see the module's doc).
///
/// The model's own loads, motions after `t = 0` and initial state are not used: only its
/// stiffness, its contacts' obstacles (at `t = 0`) and normal stiffnesses, and `modal_force`.
/// Errors: a force of the wrong length or not finite, a force on a mode of zero stiffness
/// that no contact holds, no convergence.
pub fn static_equilibrium(model: &Model, modal_force: Option<&[f64]>) -> Result<StaticState> {
    let p = model.basis.modes();
    let f = match modal_force {
        None => vec![0.0; p],
        Some(f) => {
            if f.len() != p {
                return Err(Error::invalid(
                    "static_equilibrium.modal_force",
                    format!("must have one value per mode ({p}), got {}", f.len()),
                ));
            }
            if f.iter().any(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    "static_equilibrium.modal_force",
                    "must be finite numbers",
                ));
            }
            f.to_vec()
        }
    };
    let stiffness = match &model.coordinates {
        Coordinates::Modal => DMatrix::from_diagonal(&DVector::from_iterator(
            p,
            model.basis.omega.iter().map(|w| w * w),
        )),
        Coordinates::Physical(m) => m.stiffness.clone(),
    };
    let m = model.contacts.len();
    let mut q = DVector::<f64>::zeros(p);
    let mut g = vec![vec![0.0; p]; m];
    let mut delta = vec![0.0; m];
    let evaluate = |q: &DVector<f64>, g: &mut [Vec<f64>], delta: &mut [f64]| {
        for c in 0..m {
            delta[c] = contact_at(model, c, q.as_slice(), &mut g[c]);
        }
    };
    evaluate(&q, &mut g, &mut delta);
    for iteration in 1..=MAX_ITERATIONS {
        let active: Vec<bool> = delta.iter().map(|d| *d > 0.0).collect();
        // r = K q − Σ g F − f, J = K + Σ_closed K_N g gᵀ
        let mut r = &stiffness * &q - DVector::from_column_slice(&f);
        let mut jac = stiffness.clone();
        for c in (0..m).filter(|c| active[*c]) {
            let k = model.contacts[c].normal.stiffness;
            let gc = DVector::from_column_slice(&g[c]);
            r.axpy(-k * delta[c], &gc, 1.0);
            jac.ger(k, &gc, &gc, 1.0);
        }
        // a mode of zero stiffness that no closed contact holds (a tube's free torsion
        // between pinned ends) makes `J` singular: its step is the least-squares one, 0 in
        // that mode when nothing pushes it (checked on the residual at the end)
        let step = match jac.clone().cholesky() {
            Some(chol) => chol.solve(&(-&r)),
            None => {
                let tol = SINGULAR * jac.amax();
                jac.svd(true, true)
                    .solve(&(-&r), tol)
                    .map_err(|e| Error::invalid("static_equilibrium", e.to_string()))?
            }
        };
        if step.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                "static_equilibrium",
                "the Newton step is not finite: check the stiffnesses and the force",
            ));
        }
        q += &step;
        evaluate(&q, &mut g, &mut delta);
        let same_set = delta.iter().zip(&active).all(|(d, a)| (*d > 0.0) == *a);
        if same_set && step.amax() <= STEP_TOLERANCE * q.amax() {
            check_residual(&stiffness, &q, &f, model, &g, &delta)?;
            let forces = model
                .contacts
                .iter()
                .zip(&delta)
                .map(|(c, d)| c.normal.stiffness * d.max(0.0))
                .collect();
            return Ok(StaticState {
                q: q.iter().copied().collect(),
                forces,
                penetrations: delta,
                iterations: iteration,
            });
        }
    }
    Err(Error::invalid(
        "static_equilibrium",
        format!(
            "Newton's method did not converge in {MAX_ITERATIONS} iterations (the set of closed contacts keeps changing): check the obstacles' positions and the preloads"
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::friction::Coulomb;
    use crate::contact::obstacle::{Obstacle, Plane};
    use crate::contact::{Contact, NormalLaw};
    use crate::structure::modal::{ModalBasis, Point};

    /// A point mass of stiffness `k_s` (ω² = k_s, M = 1) pressed by a plane at interference
    /// `δ0` of stiffness `k`: two springs in series, `F = δ0 k k_s / (k + k_s)`; pushed off by
    /// a force `f` larger than `k_s δ0`, the contact opens and `q = f / k_s`.
    #[test]
    fn springs_in_series() {
        let ks: f64 = 4.0e4;
        let k = 1.0e5;
        let d0 = 1.0e-4;
        let basis = ModalBasis {
            omega: vec![ks.sqrt()],
            damping_ratio: vec![0.0],
            points: vec![Point {
                name: "p".into(),
                coords: Vector3::zeros(),
                rows: vec![1.0, 0.0, 0.0],
                rotations: Vec::new(),
            }],
            participation: Vec::new(),
        };
        let mut model = Model::new(basis);
        // the plane x = −d0 with the free side at x < −d0: the rest position penetrates by d0
        let plane = Plane::new(Vector3::zeros(), -Vector3::x(), -d0, None, "o").unwrap();
        model.contacts.push(Contact::new(
            "c",
            0,
            Obstacle::Plane(plane),
            NormalLaw::new(k, 0.0, "n").unwrap(),
            Coulomb::new(0.3, 0.3, "f").unwrap(),
        ));
        let s = static_equilibrium(&model, None).unwrap();
        let expected = d0 * k * ks / (k + ks);
        assert!((s.forces[0] - expected).abs() <= 1e-14 * expected, "{s:?}");
        // equilibrium of the mass: k_s q = −F (the plane pushes towards −x)
        assert!((ks * s.q[0] + s.forces[0]).abs() <= 1e-14 * expected);
        assert!(s.iterations <= 2, "{s:?}");
        // a force that pulls the point past the plane's surface: the contact opens
        let f = -2.0 * ks * d0;
        let s = static_equilibrium(&model, Some(&[f])).unwrap();
        assert_eq!(s.forces[0], 0.0);
        assert!((s.q[0] - f / ks).abs() <= 1e-15 * (f / ks).abs());
        assert!(s.penetrations[0] < 0.0);
        // wrong length: a typed error
        assert!(static_equilibrium(&model, Some(&[1.0, 2.0])).is_err());
    }
}
