//! Beam finite elements for slender tubes in 3D: two-node elements with 6 DOFs per node
//! (translations u_x, u_y, u_z, rotations θ_x, θ_y, θ_z), axial, torsion and bending in both
//! planes, consistent mass; Timoshenko shear flexibility as an option.
//!
//! Element matrices in local axes (x along the element, length `L`), e.g. Przemieniecki,
//! *Theory of Matrix Structural Analysis*, ch. 5 and 11:
//! - axial `EA/L [1 −1; −1 1]`, mass `m_a L/6 [2 1; 1 2]`;
//! - torsion `GJ/L [1 −1; −1 1]`, mass `ρJ L/6 [2 1; 1 2]`;
//! - bending in (x, y) on (v₁, θz₁, v₂, θz₂): `EI/((1+Φ)L³) [12, 6L, −12, 6L; 6L, (4+Φ)L², −6L,
//!   (2−Φ)L²; …]` with `Φ = 12EI/(κGAL²)` (0 for Euler–Bernoulli); consistent mass
//!   `m L/420 [156, 22L, 54, −13L; 22L, 4L², 13L, −3L²; …]`; bending in (x, z) on (w, θy) is the
//!   same with the signs of the `L` terms changed (θy = −dw/dx).
//!
//! Masses per unit length: lateral `m = ρA + ρ_i π r_i² + C_a ρ_o π r_o²` (tube, inner fluid,
//! outer added mass); axial `m_a = ρA` and torsional `ρJ` for the tube alone (an inviscid fluid
//! does not follow the tube's axial motion or twist). With Timoshenko, the rotary inertia
//! `ρI` of the section is added (`ρI/(30L) [36, 3L, −36, 3L; 3L, 4L², −3L, −L²; …]`); the
//! consistent mass is otherwise the Euler–Bernoulli one.
//!
//! One concept, kept whole: the element matrices, their assembly and the restraints share the
//! numbering of the degrees of freedom.

use nalgebra::{DMatrix, Matrix3, SMatrix, Vector3};

use crate::error::{Error, Result, number};

/// Circular tube section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TubeSection {
    /// Outer diameter, m.
    pub outer_diameter: f64,
    /// Wall thickness, m.
    pub wall_thickness: f64,
}

impl TubeSection {
    fn radii(&self) -> (f64, f64) {
        let ro = 0.5 * self.outer_diameter;
        (ro - self.wall_thickness, ro)
    }
    /// Area `A = π (r_o² − r_i²)`, m².
    pub fn area(&self) -> f64 {
        let (ri, ro) = self.radii();
        std::f64::consts::PI * (ro * ro - ri * ri)
    }
    /// Second moment `I = π (r_o⁴ − r_i⁴)/4`, m⁴.
    pub fn second_moment(&self) -> f64 {
        let (ri, ro) = self.radii();
        0.25 * std::f64::consts::PI * (ro.powi(4) - ri.powi(4))
    }
    /// Polar moment `J = 2I`, m⁴.
    pub fn polar_moment(&self) -> f64 {
        2.0 * self.second_moment()
    }
    /// Shear correction factor κ of a hollow circular section (Cowper):
    /// `κ = 6(1+ν)(1+m²)² / ((7+6ν)(1+m²)² + (20+12ν)m²)`, `m = r_i/r_o`.
    pub fn shear_factor(&self, poisson: f64) -> f64 {
        let (ri, ro) = self.radii();
        let m2 = (ri / ro).powi(2);
        let a = (1.0 + m2).powi(2);
        6.0 * (1.0 + poisson) * a / ((7.0 + 6.0 * poisson) * a + (20.0 + 12.0 * poisson) * m2)
    }
}

/// Elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus `E`, Pa.
    pub young_modulus: f64,
    /// Poisson's ratio `ν`.
    pub poisson_ratio: f64,
    /// Density `ρ`, kg/m³.
    pub density: f64,
}

/// Fluids inside and outside the tube (all 0 by default).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Fluid {
    /// Density of the fluid inside, kg/m³.
    pub inner_density: f64,
    /// Density of the fluid outside, kg/m³.
    pub outer_density: f64,
    /// Added-mass coefficient `C_a` of the outside fluid.
    pub added_mass_coefficient: f64,
}

/// Beam theory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Theory {
    /// No shear deformation, no rotary inertia.
    #[default]
    EulerBernoulli,
    /// Shear deformation (Cowper's κ) and rotary inertia.
    Timoshenko,
}

/// A tube: section, material, fluids, theory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tube {
    pub section: TubeSection,
    pub material: Material,
    pub fluid: Fluid,
    pub theory: Theory,
}

impl Tube {
    /// Lateral mass per unit length: tube, inner fluid and outer added mass, kg/m.
    pub fn mass_per_length(&self) -> f64 {
        let (ri, ro) = self.section.radii();
        let pi = std::f64::consts::PI;
        self.material.density * self.section.area()
            + self.fluid.inner_density * pi * ri * ri
            + self.fluid.added_mass_coefficient * self.fluid.outer_density * pi * ro * ro
    }

    /// Checks every property; `field` prefixes the error messages.
    pub fn validate(&self, field: &str) -> Result<()> {
        let positive = |v: f64, name: &str, what: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(
                    format!("{field}.{name}"),
                    format!("must be positive: {what} (got {})", number(v)),
                ))
            }
        };
        let s = &self.section;
        positive(s.outer_diameter, "outer_diameter", "outer diameter in m")?;
        positive(s.wall_thickness, "wall_thickness", "wall thickness in m")?;
        if s.wall_thickness >= 0.5 * s.outer_diameter {
            return Err(Error::invalid(
                format!("{field}.wall_thickness"),
                format!(
                    "{} m is not less than the outer radius {} m: a tube's wall is thinner than its radius",
                    number(s.wall_thickness),
                    number(0.5 * s.outer_diameter)
                ),
            ));
        }
        let m = &self.material;
        positive(m.young_modulus, "young_modulus", "Young's modulus E in Pa")?;
        positive(
            m.density,
            "density",
            "density of the tube material in kg/m³",
        )?;
        if !(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5) {
            return Err(Error::invalid(
                format!("{field}.poisson_ratio"),
                format!("must be in (−1, 0.5) (got {})", number(m.poisson_ratio)),
            ));
        }
        for (v, name) in [
            (self.fluid.inner_density, "inner_fluid_density"),
            (self.fluid.outer_density, "outer_fluid_density"),
            (self.fluid.added_mass_coefficient, "added_mass_coefficient"),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    format!("{field}.{name}"),
                    format!("must be ≥ 0 (got {})", number(v)),
                ));
            }
        }
        // the section's properties and the products the element matrices are made of must be
        // numbers a computation can use: an extreme value (a unit slip) under- or overflows
        let g = m.young_modulus / (2.0 * (1.0 + m.poisson_ratio));
        for (v, what, name, unit) in [
            (s.area(), "an area A", "outer_diameter", "m"),
            (
                s.second_moment(),
                "a second moment I",
                "outer_diameter",
                "m",
            ),
            (
                m.density * s.area(),
                "a mass per length ρA",
                "density",
                "kg/m³",
            ),
            (
                m.density * s.polar_moment(),
                "a rotary inertia ρJ",
                "density",
                "kg/m³",
            ),
            (
                self.mass_per_length(),
                "a mass per length",
                "density",
                "kg/m³",
            ),
            (
                m.young_modulus * s.area(),
                "an axial stiffness EA",
                "young_modulus",
                "Pa",
            ),
            (
                m.young_modulus * s.second_moment(),
                "a bending stiffness EI",
                "young_modulus",
                "Pa",
            ),
            (
                g * s.polar_moment(),
                "a torsional stiffness GJ",
                "young_modulus",
                "Pa",
            ),
        ] {
            if !v.is_normal() {
                return Err(Error::invalid(
                    format!("{field}.{name}"),
                    format!(
                        "gives the tube {what} of {}, too extreme to compute with: check the units of {name} ({unit}) and of the other properties of the tube (outer_diameter and wall_thickness in m, density in kg/m³, young_modulus in Pa)",
                        number(v)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Element stiffness and mass in local axes (12 × 12).
    fn local_matrices(&self, l: f64) -> (SMatrix<f64, 12, 12>, SMatrix<f64, 12, 12>) {
        let e = self.material.young_modulus;
        let nu = self.material.poisson_ratio;
        let g = e / (2.0 * (1.0 + nu));
        let a = self.section.area();
        let i = self.section.second_moment();
        let j = self.section.polar_moment();
        let rho = self.material.density;
        let m = self.mass_per_length();
        let phi = match self.theory {
            Theory::EulerBernoulli => 0.0,
            Theory::Timoshenko => 12.0 * e * i / (self.section.shear_factor(nu) * g * a * l * l),
        };
        let mut k = SMatrix::<f64, 12, 12>::zeros();
        let mut ms = SMatrix::<f64, 12, 12>::zeros();
        let put = |mat: &mut SMatrix<f64, 12, 12>, dofs: &[usize], block: &[f64]| {
            let n = dofs.len();
            for r in 0..n {
                for c in 0..n {
                    mat[(dofs[r], dofs[c])] += block[r * n + c];
                }
            }
        };
        // axial (u) and torsion (θx)
        let ka = e * a / l;
        put(&mut k, &[0, 6], &[ka, -ka, -ka, ka]);
        let kt = g * j / l;
        put(&mut k, &[3, 9], &[kt, -kt, -kt, kt]);
        let ma = rho * a * l / 6.0;
        put(&mut ms, &[0, 6], &[2.0 * ma, ma, ma, 2.0 * ma]);
        let mt = rho * j * l / 6.0;
        put(&mut ms, &[3, 9], &[2.0 * mt, mt, mt, 2.0 * mt]);
        // bending: (v, θz) with s = +1, (w, θy) with s = −1
        let kb = e * i / ((1.0 + phi) * l * l * l);
        let mb = m * l / 420.0;
        let mr = if self.theory == Theory::Timoshenko {
            rho * i / (30.0 * l)
        } else {
            0.0
        };
        for (dofs, s) in [([1usize, 5, 7, 11], 1.0), ([2usize, 4, 8, 10], -1.0)] {
            let (l2, sl) = (l * l, s * l);
            put(
                &mut k,
                &dofs,
                &[
                    12.0 * kb,
                    6.0 * sl * kb,
                    -12.0 * kb,
                    6.0 * sl * kb,
                    6.0 * sl * kb,
                    (4.0 + phi) * l2 * kb,
                    -6.0 * sl * kb,
                    (2.0 - phi) * l2 * kb,
                    -12.0 * kb,
                    -6.0 * sl * kb,
                    12.0 * kb,
                    -6.0 * sl * kb,
                    6.0 * sl * kb,
                    (2.0 - phi) * l2 * kb,
                    -6.0 * sl * kb,
                    (4.0 + phi) * l2 * kb,
                ],
            );
            put(
                &mut ms,
                &dofs,
                &[
                    156.0 * mb,
                    22.0 * sl * mb,
                    54.0 * mb,
                    -13.0 * sl * mb,
                    22.0 * sl * mb,
                    4.0 * l2 * mb,
                    13.0 * sl * mb,
                    -3.0 * l2 * mb,
                    54.0 * mb,
                    13.0 * sl * mb,
                    156.0 * mb,
                    -22.0 * sl * mb,
                    -13.0 * sl * mb,
                    -3.0 * l2 * mb,
                    -22.0 * sl * mb,
                    4.0 * l2 * mb,
                ],
            );
            if mr > 0.0 {
                put(
                    &mut ms,
                    &dofs,
                    &[
                        36.0 * mr,
                        3.0 * sl * mr,
                        -36.0 * mr,
                        3.0 * sl * mr,
                        3.0 * sl * mr,
                        4.0 * l2 * mr,
                        -3.0 * sl * mr,
                        -l2 * mr,
                        -36.0 * mr,
                        -3.0 * sl * mr,
                        36.0 * mr,
                        -3.0 * sl * mr,
                        3.0 * sl * mr,
                        -l2 * mr,
                        -3.0 * sl * mr,
                        4.0 * l2 * mr,
                    ],
                );
            }
        }
        (k, ms)
    }
}

/// A degree of freedom of a node (in case files: "ux", "uy", "uz", "rx", "ry", "rz").
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Dof {
    Ux,
    Uy,
    Uz,
    Rx,
    Ry,
    Rz,
}

/// Nodes and two-node elements.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Node positions, m; numbered along the tube.
    pub nodes: Vec<Vector3<f64>>,
    /// Elements as node pairs.
    pub elements: Vec<[usize; 2]>,
}

impl Mesh {
    /// Straight segments between consecutive vertices, each split into `⌈len/mesh_size⌉`
    /// equal elements; the vertices are nodes.
    pub fn polyline(vertices: &[Vector3<f64>], mesh_size: f64) -> Result<Mesh> {
        if !(mesh_size.is_finite() && mesh_size > 0.0) {
            return Err(Error::invalid(
                "structure.mesh_size",
                format!(
                    "must be a positive element length in m (got {})",
                    number(mesh_size)
                ),
            ));
        }
        if vertices.len() < 2 || vertices.iter().any(|v| v.iter().any(|x| !x.is_finite())) {
            return Err(Error::invalid(
                "structure.path",
                "needs at least two finite vertices [x, y, z]",
            ));
        }
        let mut elements = 0.0;
        let mut length = 0.0;
        for (k, w) in vertices.windows(2).enumerate() {
            let len = (w[1] - w[0]).norm();
            if !(len > 0.0) {
                return Err(Error::invalid(
                    format!("structure.path[{}]", k + 1),
                    "repeats the previous vertex: segments must have a length",
                ));
            }
            if !len.is_finite() {
                return Err(Error::invalid(
                    format!("structure.path[{}]", k + 1),
                    "is too far from the previous vertex (the distance is not a finite number): check the units (m)",
                ));
            }
            elements += segment_elements(len, mesh_size);
            length += len;
        }
        check_mesh_size(elements, length, mesh_size, vertices.len() - 1, "path")?;
        let mut nodes = vec![vertices[0]];
        for w in vertices.windows(2) {
            let len = (w[1] - w[0]).norm();
            let n = segment_elements(len, mesh_size) as usize;
            for i in 1..=n {
                nodes.push(w[0] + (w[1] - w[0]) * (i as f64 / n as f64));
            }
        }
        Ok(Self::chain(nodes))
    }

    /// A U-tube: two legs along +z from z = 0 (the tube sheet) to `leg_length`, at
    /// x = ∓`radius` (y = 0), joined by a half circle of centre (0, 0, leg_length) in the
    /// (x, z) plane. Node 0 is the foot of the x = −radius leg, the last node the other foot.
    pub fn u_bend(leg_length: f64, radius: f64, mesh_size: f64) -> Result<Mesh> {
        for (v, name) in [(leg_length, "leg_length"), (radius, "radius")] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    format!("structure.u_bend.{name}"),
                    format!("must be positive, in m (got {})", number(v)),
                ));
            }
        }
        let arc = std::f64::consts::PI * radius;
        let arc_elements = segment_elements(arc, mesh_size).max(2.0);
        check_mesh_size(
            2.0 * segment_elements(leg_length, mesh_size) + arc_elements,
            2.0 * leg_length + arc,
            mesh_size,
            3,
            "u_bend",
        )?;
        let leg = Self::polyline(
            &[
                Vector3::new(-radius, 0.0, 0.0),
                Vector3::new(-radius, 0.0, leg_length),
            ],
            mesh_size,
        )?;
        let mut nodes = leg.nodes;
        let n_arc = arc_elements as usize;
        for i in 1..=n_arc {
            let a = std::f64::consts::PI * (1.0 - i as f64 / n_arc as f64);
            nodes.push(Vector3::new(
                radius * a.cos(),
                0.0,
                leg_length + radius * a.sin(),
            ));
        }
        let n_leg = nodes.len() - n_arc - 1;
        for i in 1..=n_leg {
            nodes.push(Vector3::new(
                radius,
                0.0,
                leg_length * (1.0 - i as f64 / n_leg as f64),
            ));
        }
        Ok(Self::chain(nodes))
    }

    fn chain(nodes: Vec<Vector3<f64>>) -> Mesh {
        let elements = (1..nodes.len()).map(|i| [i - 1, i]).collect();
        Mesh { nodes, elements }
    }

    /// Index of the node nearest to `x`, and its distance.
    pub fn nearest_node(&self, x: &Vector3<f64>) -> (usize, f64) {
        self.nodes
            .iter()
            .enumerate()
            .map(|(i, n)| (i, (n - x).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, f64::INFINITY))
    }
}

/// Elements of at most `mesh_size` on a segment of length `len`: `⌈len/mesh_size⌉` (at least 1).
fn segment_elements(len: f64, mesh_size: f64) -> f64 {
    (len / mesh_size - 1e-9).ceil().max(1.0)
}

/// Refuses, before anything is allocated, a mesh whose modal analysis would not fit in memory
/// (`elements` of a tube `length` m long in `segments` straight pieces or arcs; `geometry`
/// names the key that gives the length).
fn check_mesh_size(
    elements: f64,
    length: f64,
    mesh_size: f64,
    segments: usize,
    geometry: &str,
) -> Result<()> {
    let dofs = 6.0 * (elements + 1.0);
    let (needed, available) = (modal_analysis_bytes(dofs), available_memory());
    if needed <= available {
        return Ok(());
    }
    // the largest mesh that fits: at most max_dofs/6 − 1 elements, plus one per segment
    // for the rounding up of each segment
    let max_elements = (max_dofs(available) / 6.0 - 1.0 - segments as f64).max(1.0);
    Err(Error::invalid(
        "structure.mesh_size",
        format!(
            "{} m on a tube {} m long gives {elements:.3e} elements ({dofs:.3e} DOFs): the dense matrices of its modal analysis would need {}, more than the {} of memory available; use mesh_size ≥ {:.3e} m, or check the units of {geometry} (m)",
            number(mesh_size),
            number(length),
            gigabytes(needed),
            gigabytes(available),
            length / max_elements
        ),
    ))
}

/// Dense `n × n` matrices of `f64` alive at once at the peak of a tube's modal analysis
/// ([`BeamModel::assemble`] then [`crate::structure::eigen::lowest_modes`]): the reduced mass and
/// stiffness, the Cholesky factor, the transformed matrix, the eigenvectors and the eigen
/// solver's workspace: the peak resident memory of `fretdyn modes` on a 3 006-DOF tube is
/// 7.6 × `8 n²` bytes; 9 leaves a margin.
pub const DENSE_MATRICES_AT_PEAK: f64 = 9.0;

/// Bytes the modal analysis of a tube of `dofs` degrees of freedom needs:
/// `8 DENSE_MATRICES_AT_PEAK dofs²` (the matrices are dense).
pub fn modal_analysis_bytes(dofs: f64) -> f64 {
    8.0 * DENSE_MATRICES_AT_PEAK * dofs * dofs
}

/// The most DOFs whose modal analysis fits in `bytes`.
fn max_dofs(bytes: f64) -> f64 {
    (bytes / (8.0 * DENSE_MATRICES_AT_PEAK)).sqrt()
}

/// Memory available to a model, bytes: `MemAvailable` of `/proc/meminfo` (Linux), or 16 GiB
/// where the system does not say.
pub fn available_memory() -> f64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
            let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
            Some(1024.0 * kib)
        })
        .unwrap_or(16.0 * 1024.0 * 1024.0 * 1024.0)
}

/// `bytes` as gigabytes, for messages, to 3 significant digits as a person writes them:
/// `12.8 GB`, `0.0512 GB`, `3.2e4 GB`.
pub(crate) fn gigabytes(bytes: f64) -> String {
    let gb = bytes / 1e9;
    let rounded = format!("{gb:.2e}").parse().unwrap_or(gb);
    format!("{} GB", crate::error::number(rounded))
}

/// How a DOF is held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Restraint {
    /// Not held.
    Free,
    /// Held (removed from the model).
    Fixed,
    /// A spring to the ground, N/m or N·m/rad.
    Spring(f64),
}

/// A meshed tube with its restraints.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamModel {
    pub mesh: Mesh,
    pub tube: Tube,
    /// Restraints per node; nodes not listed are free.
    pub restraints: Vec<(usize, [Restraint; 6])>,
}

/// Reduced (restrained DOFs removed) mass and stiffness matrices.
#[derive(Debug, Clone, PartialEq)]
pub struct Assembled {
    /// Consistent mass matrix, n × n.
    pub mass: DMatrix<f64>,
    /// Stiffness matrix (grounded springs included), n × n.
    pub stiffness: DMatrix<f64>,
    /// Global DOF (`6 node + dof`) of each reduced index.
    pub free_dofs: Vec<usize>,
    /// Inertia of a unit rigid translation of the whole structure and its supports,
    /// `(M r_d)` over the free DOFs, one column per axis d (n × 3): the load of a base
    /// acceleration is `−(M r) a`.
    pub base_inertia: DMatrix<f64>,
}

impl Assembled {
    /// Reduced index of a node's DOF, `None` when it is held.
    pub fn reduced_index(&self, node: usize, dof: Dof) -> Option<usize> {
        self.free_dofs
            .binary_search(&(6 * node + dof as usize))
            .ok()
    }
}

impl BeamModel {
    /// Assembles the global matrices, adds the grounded springs and removes the held DOFs.
    pub fn assemble(&self) -> Result<Assembled> {
        self.tube.validate("structure")?;
        let nn = self.mesh.nodes.len();
        let n = 6 * nn;
        let (needed, available) = (modal_analysis_bytes(n as f64), available_memory());
        if needed > available {
            return Err(Error::invalid(
                "structure.mesh_size",
                format!(
                    "the mesh has {nn} nodes ({n} DOFs): the dense matrices of its modal analysis would need {}, more than the {} of memory available; use a coarser mesh (at most {:.0} nodes)",
                    gigabytes(needed),
                    gigabytes(available),
                    max_dofs(available) / 6.0
                ),
            ));
        }
        let mut k = DMatrix::<f64>::zeros(n, n);
        let mut m = DMatrix::<f64>::zeros(n, n);
        for (e, &[a, b]) in self.mesh.elements.iter().enumerate() {
            if a >= nn || b >= nn {
                return Err(Error::invalid(
                    format!("mesh.elements[{e}]"),
                    "refers to a node that does not exist",
                ));
            }
            let d = self.mesh.nodes[b] - self.mesh.nodes[a];
            let l = d.norm();
            if !(l > 0.0) {
                return Err(Error::invalid(
                    format!("mesh.elements[{e}]"),
                    "has zero length",
                ));
            }
            let r = rotation(&(d / l));
            let (kl, ml) = self.tube.local_matrices(l);
            let mut t = SMatrix::<f64, 12, 12>::zeros();
            for blk in 0..4 {
                t.fixed_view_mut::<3, 3>(3 * blk, 3 * blk).copy_from(&r);
            }
            let kg = t.transpose() * kl * t;
            let mg = t.transpose() * ml * t;
            let dofs: Vec<usize> = (0..6)
                .map(|i| 6 * a + i)
                .chain((0..6).map(|i| 6 * b + i))
                .collect();
            for (i, &gi) in dofs.iter().enumerate() {
                for (j, &gj) in dofs.iter().enumerate() {
                    k[(gi, gj)] += kg[(i, j)];
                    m[(gi, gj)] += mg[(i, j)];
                }
            }
        }
        let mut held = vec![false; n];
        for (idx, (node, rs)) in self.restraints.iter().enumerate() {
            if *node >= nn {
                return Err(Error::invalid(
                    format!("structure.supports[{idx}]"),
                    "refers to a node that does not exist",
                ));
            }
            for (d, r) in rs.iter().enumerate() {
                let g = 6 * node + d;
                match r {
                    Restraint::Free => {}
                    Restraint::Fixed => held[g] = true,
                    Restraint::Spring(s) => k[(g, g)] += s,
                }
            }
        }
        let free_dofs: Vec<usize> = (0..n).filter(|g| !held[*g]).collect();
        let pick = |a: &DMatrix<f64>| {
            DMatrix::from_fn(free_dofs.len(), free_dofs.len(), |i, j| {
                a[(free_dofs[i], free_dofs[j])]
            })
        };
        let base_inertia = DMatrix::from_fn(free_dofs.len(), 3, |i, d| {
            (0..nn).map(|node| m[(free_dofs[i], 6 * node + d)]).sum()
        });
        Ok(Assembled {
            mass: pick(&m),
            stiffness: pick(&k),
            free_dofs,
            base_inertia,
        })
    }
}

/// Rotation from global to local axes (rows: local x, y, z) for an element along `ex`; the
/// local y axis is taken from global z (or global y when the element is nearly along z).
fn rotation(ex: &Vector3<f64>) -> Matrix3<f64> {
    let reference = if ex.z.abs() < 0.99 {
        Vector3::z()
    } else {
        Vector3::y()
    };
    let ey = (reference - ex * ex.dot(&reference)).normalize();
    let ez = ex.cross(&ey);
    Matrix3::from_rows(&[ex.transpose(), ey.transpose(), ez.transpose()])
}

/// All six DOFs held.
pub fn clamped() -> [Restraint; 6] {
    [Restraint::Fixed; 6]
}

/// Translations held, rotations free.
pub fn pinned() -> [Restraint; 6] {
    [
        Restraint::Fixed,
        Restraint::Fixed,
        Restraint::Fixed,
        Restraint::Free,
        Restraint::Free,
        Restraint::Free,
    ]
}
