//! Support-active modes of a tube: the modes of its finite-element model with chosen supports
//! held in chosen directions, for the design-guide stability checks (docs/FLOW.md, "Connors
//! check with the supports active"; THEORY §16.3).
//!
//! A support held in the unit direction `e` at a named point (node `a`, offset `r` from the
//! axis) is the linear constraint
//!
//! ```text
//! eᵀ (u_a + θ_a × r) = 0,   i.e. the row  [eᵀ on u_a, (r × e)ᵀ on θ_a]  of  C d = 0
//! ```
//!
//! over the reduced DOFs `d` (a DOF the tube's own supports hold contributes nothing). With
//! `Z` an orthonormal basis of the null space of `C` (`C Z = 0`, `Zᵀ Z = I`), the constrained
//! modes solve `(Zᵀ K Z) y = ω² (Zᵀ M Z) y` and are `φ = Z y`, mass-normalised
//! (`φᵀ M φ = yᵀ Zᵀ M Z y = 1`): the exact finite-element modes of the tube with those
//! displacements held, no penalty. `Z` comes from the Householder QR of an orthonormal basis
//! `W` of the row space of `C` (the right singular vectors of `C` above `1e-10 σ_max`, so that
//! repeated or already-held constraints drop out): `Q = [W' | Z]`, and `Qᵀ K Q` is computed by
//! applying the reflectors on both sides, `O(r n²)`.

use nalgebra::{DMatrix, Vector3};

use crate::error::{Error, Result};
use crate::structure::beam::{Assembled, Dof};
use crate::structure::eigen::{ModeSelection, Modes, lowest_modes};
use crate::structure::tube::{TubeBasis, TubeStructure};

/// A support held in one direction at a point of the tube: `direction · (u + θ × offset) = 0`
/// at `node`.
#[derive(Debug, Clone, PartialEq)]
pub struct PointConstraint {
    /// Mesh node.
    pub node: usize,
    /// Offset from the node (on the axis) to the point, m.
    pub offset: Vector3<f64>,
    /// Unit direction held.
    pub direction: Vector3<f64>,
}

/// The constraint matrix `C` (rows: constraints; columns: the reduced DOFs of `assembled`).
pub fn constraint_matrix(assembled: &Assembled, constraints: &[PointConstraint]) -> DMatrix<f64> {
    let n = assembled.mass.nrows();
    let mut c = DMatrix::zeros(constraints.len(), n);
    for (k, pc) in constraints.iter().enumerate() {
        let e = pc.direction;
        // e·(θ × r) = θ·(r × e)
        let re = pc.offset.cross(&e);
        let terms = [
            (Dof::Ux, e.x),
            (Dof::Uy, e.y),
            (Dof::Uz, e.z),
            (Dof::Rx, re.x),
            (Dof::Ry, re.y),
            (Dof::Rz, re.z),
        ];
        for (dof, v) in terms {
            if let Some(i) = assembled.reduced_index(pc.node, dof) {
                c[(k, i)] += v;
            }
        }
    }
    c
}

/// `(Qᵀ, k)`: an orthogonal `n × n` matrix `Q` whose first `k` columns span the row space of
/// `c` and whose last `n − k` span its null space (`k` the numerical rank of `c`).
fn null_space_split(c: &DMatrix<f64>) -> (DMatrix<f64>, usize) {
    let n = c.ncols();
    if c.nrows() == 0 || c.iter().all(|v| *v == 0.0) {
        return (DMatrix::identity(n, n), 0);
    }
    let svd = c.clone().svd(false, true);
    let v_t = svd.v_t.expect("right singular vectors were asked for");
    let s_max = svd.singular_values.max();
    let kept: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&i| svd.singular_values[i] > 1e-10 * s_max)
        .collect();
    let k = kept.len();
    let w = DMatrix::from_fn(n, k, |i, j| v_t[(kept[j], i)]);
    let qr = w.qr();
    let mut q_t = DMatrix::identity(n, n);
    qr.q_tr_mul(&mut q_t);
    (q_t, k)
}

/// The lowest modes (over the reduced DOFs of `assembled`) of the tube with `constraints`
/// held: `φ = Z y` (module documentation), mass-normalised, ascending.
pub fn constrained_modes(
    assembled: &Assembled,
    constraints: &[PointConstraint],
    selection: ModeSelection,
) -> Result<Modes> {
    let n = assembled.mass.nrows();
    let (q_t, k) = null_space_split(&constraint_matrix(assembled, constraints));
    if k >= n {
        return Err(Error::invalid(
            "stability.conditions",
            "the supports held leave the tube no free degree of freedom: hold fewer points or directions",
        ));
    }
    // Qᵀ A Q = Qᵀ (Qᵀ A)ᵀ for a symmetric A; keep the null-space block
    let project = |a: &DMatrix<f64>| {
        let left = &q_t * a;
        let both = &q_t * left.transpose();
        let block = both.view((k, k), (n - k, n - k));
        // symmetric up to round-off: symmetrise
        DMatrix::from_fn(n - k, n - k, |i, j| 0.5 * (block[(i, j)] + block[(j, i)]))
    };
    let (mass, stiffness) = (project(&assembled.mass), project(&assembled.stiffness));
    let reduced = lowest_modes(&mass, &stiffness, selection)?;
    let z_t = q_t.rows(k, n - k);
    let shapes = z_t.transpose() * &reduced.shapes;
    Ok(Modes {
        omega: reduced.omega,
        shapes,
    })
}

impl TubeStructure {
    /// The modal basis of the tube with `constraints` held ([`constrained_modes`] of the
    /// assembled model `base`), its damping from the tube's damping model at the constrained
    /// frequencies, the rows of its named points.
    pub fn constrained_basis(
        &self,
        base: &TubeBasis,
        constraints: &[PointConstraint],
        selection: ModeSelection,
    ) -> Result<TubeBasis> {
        let modes = constrained_modes(&base.assembled, constraints, selection)?;
        self.basis_of(base.assembled.clone(), modes)
    }

    /// The unit normal of the plane the tube's axis lies in (a U-bend's), `None` for a
    /// straight tube or one that is not planar: the eigenvector of the smallest eigenvalue of
    /// the nodes' scatter matrix when it is below `1e-12` of the largest and the middle one is
    /// above `1e-6` of it.
    pub fn plane_normal(&self) -> Option<Vector3<f64>> {
        let nodes = &self.beam.mesh.nodes;
        if nodes.len() < 3 {
            return None;
        }
        let c = nodes.iter().sum::<Vector3<f64>>() / nodes.len() as f64;
        let scatter = nodes
            .iter()
            .map(|x| (x - c) * (x - c).transpose())
            .sum::<nalgebra::Matrix3<f64>>();
        let eig = scatter.symmetric_eigen();
        let mut order = [0, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let (lo, mid, hi) = (
            eig.eigenvalues[order[0]],
            eig.eigenvalues[order[1]],
            eig.eigenvalues[order[2]],
        );
        (hi > 0.0 && lo.abs() <= 1e-12 * hi && mid > 1e-6 * hi)
            .then(|| eig.eigenvectors.column(order[0]).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constrained_null_space_is_orthonormal_and_drops_repeated_rows() {
        // rows 0 and 2 repeat, row 3 is zero: rank 2
        let c = DMatrix::from_row_slice(
            4,
            5,
            &[
                1.0, 2.0, 0.0, 0.0, 1.0, //
                0.0, 1.0, 1.0, 0.0, 0.0, //
                2.0, 4.0, 0.0, 0.0, 2.0, //
                0.0, 0.0, 0.0, 0.0, 0.0,
            ],
        );
        let (q_t, k) = null_space_split(&c);
        assert_eq!(k, 2);
        let q = q_t.transpose();
        let gram = &q_t * &q - DMatrix::<f64>::identity(5, 5);
        assert!(gram.abs().max() < 1e-14, "{gram}");
        let z = q.columns(k, 5 - k);
        assert!((&c * z).abs().max() < 1e-14);
    }
}
