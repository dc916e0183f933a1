//! A tube as engineers describe it — section, material, fluids, path, supports, named points —
//! turned into the modal basis the time integrator uses (and, for the tests, into the
//! physical-coordinates model of the same finite elements).
//!
//! The beam finite elements are in [`crate::structure::beam`], the eigen solver in [`crate::structure::eigen`]. A
//! named point sits at a node; with an `offset` (from the tube axis to a point of its outer
//! surface, where it touches a support) its rows include the rotations:
//! `u_surface = u + θ × r`.

use nalgebra::{DMatrix, Vector3};

use crate::error::{Error, Result, number};
use crate::structure::beam::{Assembled, BeamModel, Dof, Mesh};
use crate::structure::eigen::{ModeSelection, Modes, lowest_modes};
use crate::structure::line::{LineCell, Station};
use crate::structure::modal::{ModalBasis, Point};

/// A named point of the tube: a node, and an offset from the axis.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedPoint {
    /// Name used by contacts, loads and outputs.
    pub name: String,
    /// Node index in the mesh.
    pub node: usize,
    /// Offset from the node (on the axis) to the point, m.
    pub offset: Vector3<f64>,
}

/// Modal damping of the basis.
#[derive(Debug, Clone, PartialEq)]
pub enum Damping {
    /// The same ratio ξ for every mode.
    Constant(f64),
    /// One ratio per mode (as many as modes kept).
    PerMode(Vec<f64>),
    /// Rayleigh `C = α M + β K`: `ξ_i = α/(2ω_i) + β ω_i/2`.
    Rayleigh { alpha: f64, beta: f64 },
}

impl Damping {
    /// The damping ratio of each mode of circular frequency `omega` (rad/s): the constant, the
    /// first values of the per-mode list, or Rayleigh's `ξ = α/(2ω) + βω/2`.
    pub fn ratios(&self, omega: &[f64]) -> Result<Vec<f64>> {
        let p = omega.len();
        Ok(match self {
            Damping::Constant(x) => vec![*x; p],
            Damping::PerMode(v) => {
                if v.len() < p {
                    return Err(Error::invalid(
                        "structure.damping_ratio",
                        format!(
                            "has {} values for {p} modes kept: give one per mode",
                            v.len()
                        ),
                    ));
                }
                v[..p].to_vec()
            }
            Damping::Rayleigh { alpha, beta } => {
                let ratios: Vec<f64> = omega
                    .iter()
                    .map(|w| {
                        if *w > 0.0 {
                            0.5 * (alpha / w + beta * w)
                        } else {
                            0.0
                        }
                    })
                    .collect();
                if let Some(i) = ratios.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
                    return Err(Error::invalid(
                        "structure.rayleigh",
                        format!(
                            "α = {}, β = {} give mode {} (ω = {} rad/s) the damping ratio ξ = α/(2ω) + βω/2 = {}: give α ≥ 0 in 1/s and β ≥ 0 in s that make it a finite number",
                            number(*alpha),
                            number(*beta),
                            i + 1,
                            number(omega[i]),
                            number(ratios[i])
                        ),
                    ));
                }
                ratios
            }
        })
    }
}

/// A tube finite-element model with its named points, mode selection and damping.
#[derive(Debug, Clone)]
pub struct TubeStructure {
    /// Mesh, tube properties and restraints.
    pub beam: BeamModel,
    /// Named points.
    pub points: Vec<NamedPoint>,
    /// Which modes to keep.
    pub selection: ModeSelection,
    /// Modal damping.
    pub damping: Damping,
}

/// The modal basis of a tube, with what was computed to get it.
#[derive(Debug, Clone)]
pub struct TubeBasis {
    /// The basis restricted to the named points (what the time integrator uses).
    pub basis: ModalBasis,
    /// Reduced mass and stiffness matrices.
    pub assembled: Assembled,
    /// Every kept mode at every free DOF.
    pub modes: Modes,
}

impl TubeStructure {
    /// Assembles, computes the modes and extracts the rows of the named points.
    pub fn modal_basis(&self) -> Result<TubeBasis> {
        let assembled = self.beam.assemble()?;
        let n = assembled.mass.nrows();
        if let ModeSelection::Count(count) = self.selection
            && count > n
        {
            return Err(Error::invalid(
                "structure.modes",
                format!(
                    "{count} modes asked, but the tube has {n} free DOFs, hence {n} modes: set modes ≤ {n} (all of them), or refine mesh_size for more"
                ),
            ));
        }
        let modes = lowest_modes(&assembled.mass, &assembled.stiffness, self.selection)
            .map_err(|e| match e {
                Error::Invalid { field, message } if field == "structure" => Error::invalid(
                    field,
                    format!(
                        "{message} (the tube's outer_diameter and wall_thickness are in m, density in kg/m³, young_modulus in Pa)"
                    ),
                ),
                other => other,
            })?;
        self.basis_of(assembled, modes)
    }

    /// The basis of `modes` (over the reduced DOFs of `assembled`): their damping from the
    /// tube's damping model, the rows of its named points, the participation factors.
    pub(crate) fn basis_of(&self, assembled: Assembled, modes: Modes) -> Result<TubeBasis> {
        let damping_ratio = self.damping.ratios(&modes.omega)?;
        let points = self.named_points(&assembled, &modes.shapes);
        Ok(TubeBasis {
            basis: ModalBasis {
                omega: modes.omega.clone(),
                damping_ratio,
                points,
                // p × 3, column-major: the 3 × p row-major layout of `participation`
                participation: (modes.shapes.transpose() * &assembled.base_inertia)
                    .iter()
                    .copied()
                    .collect(),
            },
            assembled,
            modes,
        })
    }
}

impl TubeStructure {
    /// The named points with their rows taken from `shapes` (n × p, over the reduced DOFs).
    pub(crate) fn named_points(&self, assembled: &Assembled, shapes: &DMatrix<f64>) -> Vec<Point> {
        self.points
            .iter()
            .map(|pt| Point {
                name: pt.name.clone(),
                coords: self.beam.mesh.nodes[pt.node] + pt.offset,
                rows: point_rows(assembled, shapes, pt),
                rotations: rotation_rows(assembled, shapes, pt.node),
            })
            .collect()
    }
}

/// A node of a tube under a line load: its arc length, the length of tube it carries, and its
/// translation rows.
#[derive(Debug, Clone, PartialEq)]
pub struct LineNode {
    /// Arc length `s` along the tube from its first node, m.
    pub s: f64,
    /// Tributary length `w`, m: a uniform load `f` per unit length over the span gives the
    /// nodal force `w f` (lumped, statically equivalent element by element).
    pub weight: f64,
    /// Translation rows (3 × p, row-major).
    pub rows: Vec<f64>,
}

impl TubeStructure {
    /// Length of the tube along its axis, m.
    pub fn length(&self) -> f64 {
        let n = &self.beam.mesh.nodes;
        self.beam
            .mesh
            .elements
            .iter()
            .map(|[a, b]| (n[*b] - n[*a]).norm())
            .sum()
    }

    /// The elements under a line load on the arc-length span `[s0, s1]`, clipped to it, and
    /// the mesh node of each row they refer to (the nodes with a share of the load, in mesh
    /// order). Arc lengths run along the elements from the tube's first node.
    pub fn line_cells(&self, s0: f64, s1: f64) -> (Vec<usize>, Vec<LineCell>) {
        let mesh = &self.beam.mesh;
        let mut s = vec![0.0; mesh.nodes.len()];
        let mut acc = 0.0;
        let mut pieces = Vec::new();
        for [a, b] in &mesh.elements {
            let len = (mesh.nodes[*b] - mesh.nodes[*a]).norm();
            s[*a] = acc;
            acc += len;
            s[*b] = acc;
            let (lo, hi) = (s[*a].max(s0), s[*b].min(s1));
            if hi > lo && len > 0.0 {
                pieces.push(([*a, *b], [s[*a], s[*b]], [lo, hi]));
            }
        }
        let mut row = vec![usize::MAX; mesh.nodes.len()];
        for (nodes, _, _) in &pieces {
            for &i in nodes {
                row[i] = 0;
            }
        }
        let mut rows = Vec::new();
        for (i, r) in row.iter_mut().enumerate() {
            if *r == 0 {
                *r = rows.len();
                rows.push(i);
            }
        }
        let cells = pieces
            .into_iter()
            .map(|([a, b], ends, loaded)| LineCell {
                nodes: [row[a], row[b]],
                ends,
                loaded,
            })
            .collect();
        (rows, cells)
    }

    /// The nodes carrying a line load on the arc-length span `[s0, s1]` (those of
    /// [`TubeStructure::line_cells`]): each element's overlap with the span, of length `ℓ`
    /// and centroid `c`, is shared between its end nodes `a`, `b` as `ℓ (s_b − c)/(s_b − s_a)`
    /// and `ℓ (c − s_a)/(s_b − s_a)` (`∫ N_a`, `∫ N_b`: same resultant and same first moment
    /// as the uniform load).
    pub fn line_nodes(&self, basis: &TubeBasis, s0: f64, s1: f64) -> Vec<LineNode> {
        let (rows, cells) = self.line_cells(s0, s1);
        let mut nodes: Vec<LineNode> = rows
            .iter()
            .map(|&node| {
                let pt = NamedPoint {
                    name: String::new(),
                    node,
                    offset: Vector3::zeros(),
                };
                LineNode {
                    s: 0.0,
                    weight: 0.0,
                    rows: point_rows(&basis.assembled, &basis.modes.shapes, &pt),
                }
            })
            .collect();
        for cell in &cells {
            let ([sa, sb], [lo, hi]) = (cell.ends, cell.loaded);
            let (l, c) = (hi - lo, 0.5 * (lo + hi));
            let [a, b] = cell.nodes;
            nodes[a].s = sa;
            nodes[b].s = sb;
            nodes[a].weight += l * (sb - c) / (sb - sa);
            nodes[b].weight += l * (c - sa) / (sb - sa);
        }
        nodes
    }
}

impl TubeStructure {
    /// Arc length `s` of every mesh node along the tube from its first node, m (along the
    /// elements, as [`TubeStructure::line_cells`]).
    pub fn node_abscissae(&self) -> Vec<f64> {
        let mesh = &self.beam.mesh;
        let mut s = vec![0.0; mesh.nodes.len()];
        let mut acc = 0.0;
        for [a, b] in &mesh.elements {
            s[*a] = acc;
            acc += (mesh.nodes[*b] - mesh.nodes[*a]).norm();
            s[*b] = acc;
        }
        s
    }

    /// Arc length `s` of every named point along the tube, m: that of its node
    /// ([`TubeStructure::node_abscissae`]; an offset from the axis does not move it), in the
    /// order of [`TubeStructure::points`] — the abscissae the flow zones are placed on
    /// (docs/FLOW.md), written as `s_<name>` by `fretdyn modes`.
    pub fn point_abscissae(&self) -> Vec<f64> {
        let s = self.node_abscissae();
        self.points.iter().map(|pt| s[pt.node]).collect()
    }

    /// Quadrature stations over the arc-length span `[s0, s1]`: 4 Gauss–Legendre points on each
    /// element's overlap with the span, with the translation rows of the axis there from the
    /// element's own interpolation of the modes (docs/FLOW.md): along the unit tangent `t`
    /// linear, normal to it cubic Hermite on the end translations `u⊥` and slopes `θ × t`,
    ///
    /// ```text
    /// u(ξ) = [(1−ξ) u_a + ξ u_b]·t t + H₁ u⊥_a + H₂ ℓ θ_a×t + H₃ u⊥_b + H₄ ℓ θ_b×t,
    /// H₁ = 1 − 3ξ² + 2ξ³, H₂ = ξ − 2ξ² + ξ³, H₃ = 3ξ² − 2ξ³, H₄ = ξ³ − ξ²
    /// ```
    ///
    /// (exact for Euler–Bernoulli elements; the weights sum to `s1 − s0`).
    pub fn flow_stations(&self, basis: &TubeBasis, s0: f64, s1: f64) -> Vec<Station> {
        const GAUSS: [(f64, f64); 4] = [
            (-0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
            (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
        ];
        let mesh = &self.beam.mesh;
        let shapes = &basis.modes.shapes;
        let p = shapes.ncols();
        let translation = |node: usize| {
            let pt = NamedPoint {
                name: String::new(),
                node,
                offset: Vector3::zeros(),
            };
            point_rows(&basis.assembled, shapes, &pt)
        };
        let mut stations = Vec::new();
        let mut acc = 0.0;
        for [a, b] in &mesh.elements {
            let d = mesh.nodes[*b] - mesh.nodes[*a];
            let len = d.norm();
            let (sa, sb) = (acc, acc + len);
            acc = sb;
            let (lo, hi) = (sa.max(s0), sb.min(s1));
            if !(hi > lo && len > 0.0) {
                continue;
            }
            let t = d / len;
            let (ua, ub) = (translation(*a), translation(*b));
            let (ra, rb) = (
                rotation_rows(&basis.assembled, shapes, *a),
                rotation_rows(&basis.assembled, shapes, *b),
            );
            let at = |rows: &[f64], m: usize| Vector3::new(rows[m], rows[p + m], rows[2 * p + m]);
            let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            for (x, w) in GAUSS {
                let s = mid + half * x;
                let xi = (s - sa) / len;
                let (x2, x3) = (xi * xi, xi * xi * xi);
                let h = [
                    1.0 - 3.0 * x2 + 2.0 * x3,
                    len * (xi - 2.0 * x2 + x3),
                    3.0 * x2 - 2.0 * x3,
                    len * (x3 - x2),
                ];
                let mut rows = vec![0.0; 3 * p];
                for m in 0..p {
                    let (va, vb) = (at(&ua, m), at(&ub, m));
                    let axial = t * ((1.0 - xi) * va.dot(&t) + xi * vb.dot(&t));
                    let u = axial
                        + (va - t * va.dot(&t)) * h[0]
                        + at(&ra, m).cross(&t) * h[1]
                        + (vb - t * vb.dot(&t)) * h[2]
                        + at(&rb, m).cross(&t) * h[3];
                    for k in 0..3 {
                        rows[k * p + m] = u[k];
                    }
                }
                stations.push(Station {
                    s,
                    weight: w * half,
                    rows,
                    tangent: t,
                });
            }
        }
        stations
    }
}

/// Rows (3 × p) of a named point from shapes (n × p) over the reduced DOFs:
/// `u + θ × r` with `r` the point's offset; a restrained DOF contributes nothing.
fn point_rows(assembled: &Assembled, shapes: &DMatrix<f64>, pt: &NamedPoint) -> Vec<f64> {
    let p = shapes.ncols();
    let dof_row = |d: Dof| -> Option<usize> { assembled.reduced_index(pt.node, d) };
    let mut rows = vec![0.0; 3 * p];
    let r = pt.offset;
    let [ux, uy, uz, rx, ry, rz] =
        [Dof::Ux, Dof::Uy, Dof::Uz, Dof::Rx, Dof::Ry, Dof::Rz].map(dof_row);
    let value = |row: Option<usize>, mode: usize| row.map_or(0.0, |i| shapes[(i, mode)]);
    for m in 0..p {
        let (tx, ty, tz) = (value(rx, m), value(ry, m), value(rz, m));
        // θ × r
        let (cx, cy, cz) = (
            ty * r.z - tz * r.y,
            tz * r.x - tx * r.z,
            tx * r.y - ty * r.x,
        );
        rows[m] = value(ux, m) + cx;
        rows[p + m] = value(uy, m) + cy;
        rows[2 * p + m] = value(uz, m) + cz;
    }
    rows
}

/// Rotation rows (3 × p) of a node: `θx, θy, θz` of each mode (0 where restrained).
fn rotation_rows(assembled: &Assembled, shapes: &DMatrix<f64>, node: usize) -> Vec<f64> {
    let p = shapes.ncols();
    let mut rows = vec![0.0; 3 * p];
    for (d, dof) in [Dof::Rx, Dof::Ry, Dof::Rz].into_iter().enumerate() {
        if let Some(i) = assembled.reduced_index(node, dof) {
            for m in 0..p {
                rows[d * p + m] = shapes[(i, m)];
            }
        }
    }
    rows
}

/// The node where a point given by its position sits; an error names `field` when no node is
/// within `tolerance` of it.
pub fn node_at(mesh: &Mesh, at: &Vector3<f64>, tolerance: f64, field: &str) -> Result<usize> {
    let (node, distance) = mesh.nearest_node(at);
    if distance <= tolerance {
        Ok(node)
    } else {
        let x = mesh.nodes[node];
        Err(Error::invalid(
            field,
            format!(
                "no node at [{}, {}, {}]: the nearest is {} m away, at [{}, {}, {}]; put the point on a node (a path vertex, or a multiple of the mesh size along a segment)",
                number(at.x),
                number(at.y),
                number(at.z),
                number(distance),
                number(x.x),
                number(x.y),
                number(x.z)
            ),
        ))
    }
}
