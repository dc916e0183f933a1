//! `[structure]` and `[initial]`: the modal basis (a point mass, a pinned beam, a modal basis
//! inline or from `.npz`, or a tube meshed and reduced on its modes) and the initial state
//! (THEORY §1, §7, §9).

use std::path::Path;

use nalgebra::Vector3;
use serde::Deserialize;

use super::shared::{Abscissae, TubeModel, named_file, point_index, v3};
use crate::error::{Error, Result, number};
use crate::model::Model;
use crate::structure::beam::{
    BeamModel, Dof, Fluid, Material, Mesh, Restraint, Theory, Tube, TubeSection, clamped, pinned,
};
use crate::structure::eigen::ModeSelection;
use crate::structure::modal::{ModalBasis, PinnedBeam, Point, check_damping_ratio};
use crate::structure::tube::{Damping, NamedPoint, TubeStructure, node_at};

#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub(super) enum StructureSection {
    PointMass {
        mass: f64,
        #[serde(default = "default_point_name")]
        point: String,
        #[serde(default)]
        position: [f64; 3],
    },
    Modal {
        frequencies_hz: Option<Vec<f64>>,
        damping_ratio: Option<DampingInput>,
        file: Option<String>,
        #[serde(default)]
        points: Vec<PointInput>,
        /// 3 rows (x, y, z) of p values `Φᵀ M r`.
        participation: Option<Vec<Vec<f64>>>,
    },
    Tube(Box<TubeInput>),
    PinnedBeam {
        length: f64,
        bending_stiffness: f64,
        mass_per_length: f64,
        modes_per_plane: usize,
        #[serde(default)]
        axial_stiffness: f64,
        #[serde(default)]
        axial_modes: usize,
        #[serde(default)]
        damping_ratio: f64,
        points: Vec<StationInput>,
    },
}

/// `type = "tube"`: a beam finite-element tube (see `examples/tube_clamped_one_support.toml`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TubeInput {
    outer_diameter: f64,
    wall_thickness: f64,
    young_modulus: f64,
    poisson_ratio: f64,
    density: f64,
    #[serde(default)]
    inner_fluid_density: f64,
    #[serde(default)]
    outer_fluid_density: f64,
    #[serde(default)]
    added_mass_coefficient: f64,
    #[serde(default)]
    theory: TheoryName,
    mesh_size: f64,
    path: Option<Vec<[f64; 3]>>,
    u_bend: Option<UBendInput>,
    modes: Option<usize>,
    max_frequency_hz: Option<f64>,
    damping_ratio: Option<DampingInput>,
    rayleigh: Option<RayleighInput>,
    #[serde(default)]
    supports: Vec<SupportInput>,
    #[serde(default)]
    points: Vec<TubePointInput>,
}

#[derive(Debug, Default, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
pub(super) enum TheoryName {
    #[default]
    EulerBernoulli,
    Timoshenko,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct UBendInput {
    leg_length: f64,
    radius: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RayleighInput {
    alpha: f64,
    beta: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SupportInput {
    at: [f64; 3],
    #[serde(rename = "type")]
    kind: SupportKind,
    stiffness: Option<[f64; 6]>,
    #[serde(default)]
    fixed: Vec<Dof>,
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
pub(super) enum SupportKind {
    Clamped,
    Pinned,
    Springs,
    Dofs,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TubePointInput {
    name: String,
    at: [f64; 3],
    #[serde(default)]
    offset: [f64; 3],
}

fn default_point_name() -> String {
    "mass".to_string()
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub(super) enum DampingInput {
    Constant(f64),
    PerMode(Vec<f64>),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PointInput {
    name: String,
    #[serde(default)]
    coords: [f64; 3],
    rows: Vec<Vec<f64>>,
    #[serde(default)]
    rotations: Vec<Vec<f64>>,
    /// Abscissa along the tube, m (for `[[flow.zones]]`).
    s: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct StationInput {
    name: String,
    x: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct InitialSection {
    point: Option<String>,
    displacement: Option<[f64; 3]>,
    velocity: Option<[f64; 3]>,
    q: Option<Vec<f64>>,
    qdot: Option<Vec<f64>>,
}

impl TubeInput {
    fn structure(&self) -> Result<TubeStructure> {
        let tube = Tube {
            section: TubeSection {
                outer_diameter: self.outer_diameter,
                wall_thickness: self.wall_thickness,
            },
            material: Material {
                young_modulus: self.young_modulus,
                poisson_ratio: self.poisson_ratio,
                density: self.density,
            },
            fluid: Fluid {
                inner_density: self.inner_fluid_density,
                outer_density: self.outer_fluid_density,
                added_mass_coefficient: self.added_mass_coefficient,
            },
            theory: match self.theory {
                TheoryName::EulerBernoulli => Theory::EulerBernoulli,
                TheoryName::Timoshenko => Theory::Timoshenko,
            },
        };
        tube.validate("structure")?;
        if !(self.mesh_size.is_finite() && self.mesh_size > 0.0) {
            return Err(Error::invalid(
                "structure.mesh_size",
                format!(
                    "must be a positive element length in m (got {})",
                    number(self.mesh_size)
                ),
            ));
        }
        let mesh = match (&self.path, &self.u_bend) {
            (Some(path), None) => {
                let vertices: Vec<Vector3<f64>> = path.iter().map(|v| v3(*v)).collect();
                Mesh::polyline(&vertices, self.mesh_size)?
            }
            (None, Some(u)) => Mesh::u_bend(u.leg_length, u.radius, self.mesh_size)?,
            _ => {
                return Err(Error::invalid(
                    "structure",
                    "a tube needs either path = [[x, y, z], …] (straight segments) or u_bend = { leg_length, radius }",
                ));
            }
        };
        let tolerance = 1e-3 * self.mesh_size;
        let mut restraints = Vec::new();
        for (k, sup) in self.supports.iter().enumerate() {
            let field = format!("structure.supports[{k}]");
            let node = node_at(&mesh, &v3(sup.at), tolerance, &format!("{field}.at"))?;
            if !sup.fixed.is_empty() && !matches!(sup.kind, SupportKind::Dofs) {
                return Err(Error::invalid(
                    format!("{field}.fixed"),
                    "only type = \"dofs\" takes a list of fixed DOFs",
                ));
            }
            let r = match (sup.kind, sup.stiffness) {
                (SupportKind::Clamped, None) => clamped(),
                (SupportKind::Pinned, None) => pinned(),
                (SupportKind::Dofs, springs) => {
                    let mut r = match springs {
                        Some(k) => spring_restraints(&k, &field)?,
                        None => [Restraint::Free; 6],
                    };
                    for d in &sup.fixed {
                        r[*d as usize] = Restraint::Fixed;
                    }
                    r
                }
                (SupportKind::Springs, Some(k)) => spring_restraints(&k, &field)?,
                (SupportKind::Springs, None) => {
                    return Err(Error::invalid(
                        format!("{field}.stiffness"),
                        "type = \"springs\" needs stiffness = [kx, ky, kz, krx, kry, krz] (N/m, N·m/rad; 0 = free)",
                    ));
                }
                (_, Some(_)) => {
                    return Err(Error::invalid(
                        format!("{field}.stiffness"),
                        "only type = \"springs\" or \"dofs\" takes stiffnesses",
                    ));
                }
            };
            restraints.push((node, r));
        }
        let mut points = Vec::new();
        for (k, pt) in self.points.iter().enumerate() {
            let field = format!("structure.points[{k}]");
            let node = node_at(&mesh, &v3(pt.at), tolerance, &format!("{field}.at"))?;
            let offset = v3(pt.offset);
            if offset.iter().any(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    format!("{field}.offset"),
                    "must be 3 finite numbers",
                ));
            }
            points.push(NamedPoint {
                name: pt.name.clone(),
                node,
                offset,
            });
        }
        let selection = match (self.modes, self.max_frequency_hz) {
            (Some(n), None) if n > 0 => ModeSelection::Count(n),
            (None, Some(f)) if f.is_finite() && f > 0.0 => ModeSelection::BelowHz(f),
            _ => {
                return Err(Error::invalid(
                    "structure.modes",
                    "give either modes = N (the N lowest modes) or max_frequency_hz = F (every mode below F), N and F positive",
                ));
            }
        };
        let damping = match (&self.damping_ratio, &self.rayleigh) {
            (Some(DampingInput::Constant(x)), None) => {
                check_damping_ratio(*x, "structure.damping_ratio")?;
                Damping::Constant(*x)
            }
            (Some(DampingInput::PerMode(v)), None) => Damping::PerMode(v.clone()),
            (None, Some(r)) => {
                for (v, key, unit) in [(r.alpha, "alpha", "1/s"), (r.beta, "beta", "s")] {
                    if !(v.is_finite() && v >= 0.0) {
                        return Err(Error::invalid(
                            format!("structure.rayleigh.{key}"),
                            format!(
                                "must be a finite coefficient ≥ 0 in {unit} of C = αM + βK (got {})",
                                number(v)
                            ),
                        ));
                    }
                }
                Damping::Rayleigh {
                    alpha: r.alpha,
                    beta: r.beta,
                }
            }
            (None, None) => Damping::Constant(0.0),
            (Some(_), Some(_)) => {
                return Err(Error::invalid(
                    "structure.rayleigh",
                    "give either damping_ratio or rayleigh = { alpha, beta }, not both",
                ));
            }
        };
        Ok(TubeStructure {
            beam: BeamModel {
                mesh,
                tube,
                restraints,
            },
            points,
            selection,
            damping,
        })
    }
}

/// Refuses, before they are allocated, more analytic modes than the memory holds: the rows
/// of `points` points (3 per mode each) and the dense matrices of the stable time step.
fn check_mode_count(modes: usize, points: usize) -> Result<()> {
    let needed = crate::integrator::stability::memory_bytes(modes)
        + 8.0 * 3.0 * modes as f64 * points.max(1) as f64;
    let available = crate::structure::beam::available_memory();
    if needed > available {
        return Err(Error::invalid(
            "structure.modes_per_plane",
            format!(
                "gives {modes} modes, which would need {} of memory, more than the {} available: keep fewer modes",
                crate::structure::beam::gigabytes(needed),
                crate::structure::beam::gigabytes(available)
            ),
        ));
    }
    Ok(())
}

/// Grounded springs `[kx, ky, kz, krx, kry, krz]` (0 = free).
fn spring_restraints(k: &[f64; 6], field: &str) -> Result<[Restraint; 6]> {
    if let Some(v) = k.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(Error::invalid(
            format!("{field}.stiffness"),
            format!("spring stiffnesses must be ≥ 0 (got {})", number(*v)),
        ));
    }
    Ok(k.map(|v| {
        if v > 0.0 {
            Restraint::Spring(v)
        } else {
            Restraint::Free
        }
    }))
}

impl StructureSection {
    pub(super) fn build(
        &self,
        base: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<(ModalBasis, Option<Box<TubeModel>>, Abscissae)> {
        if let StructureSection::Tube(t) = self {
            let structure = t.structure()?;
            let basis = structure.modal_basis()?;
            let abscissae = Abscissae {
                s: structure.point_abscissae().into_iter().map(Some).collect(),
                source: "the tube's named points (at their node's arc length)".into(),
            };
            return Ok((
                basis.basis.clone(),
                Some(Box::new(TubeModel { structure, basis })),
                abscissae,
            ));
        }
        let mut abscissae = Abscissae::default();
        let basis = self.build_basis(base, warnings, &mut abscissae)?;
        abscissae.s.resize(basis.points.len(), None);
        Ok((basis, None, abscissae))
    }

    /// The basis, and the abscissae of its points where the case gives them.
    fn build_basis(
        &self,
        base: &Path,
        warnings: &mut Vec<String>,
        abscissae: &mut Abscissae,
    ) -> Result<ModalBasis> {
        match self {
            StructureSection::Tube(_) => unreachable!("handled by build"),
            StructureSection::PointMass {
                mass,
                point,
                position,
            } => ModalBasis::point_mass(*mass, point, v3(*position)),
            StructureSection::PinnedBeam {
                length,
                bending_stiffness,
                mass_per_length,
                modes_per_plane,
                axial_stiffness,
                axial_modes,
                damping_ratio,
                points,
            } => {
                abscissae.s = points.iter().map(|s| Some(s.x)).collect();
                abscissae.source = "the stations' x (structure.points)".into();
                check_damping_ratio(*damping_ratio, "structure.damping_ratio")
                    .and_then(|_| {
                        check_mode_count(
                            modes_per_plane
                                .saturating_mul(2)
                                .saturating_add(*axial_modes),
                            points.len(),
                        )
                    })
                    .and_then(|_| {
                        ModalBasis::pinned_beam(
                            &PinnedBeam {
                                length: *length,
                                bending_stiffness: *bending_stiffness,
                                mass_per_length: *mass_per_length,
                                modes_per_plane: *modes_per_plane,
                                axial_stiffness: *axial_stiffness,
                                axial_modes: *axial_modes,
                                damping_ratio: *damping_ratio,
                            },
                            &points
                                .iter()
                                .map(|s| (s.name.clone(), s.x))
                                .collect::<Vec<_>>(),
                        )
                    })
            }
            StructureSection::Modal {
                frequencies_hz,
                damping_ratio,
                file,
                points,
                participation,
            } => {
                let mut basis = match (file, frequencies_hz) {
                    (Some(f), None) => {
                        let path = named_file(base, f, "structure.file", "the case file")?;
                        let file = crate::structure::basis_file::read_basis_npz(&path)?;
                        warnings.extend(file.warnings);
                        abscissae.s = file.abscissae;
                        abscissae.source = format!(
                            "the arrays 's_<point>' (float64, one value, m) of {}",
                            path.display()
                        );
                        file.basis
                    }
                    (None, Some(freq)) => ModalBasis {
                        omega: freq.iter().map(|f| f * std::f64::consts::TAU).collect(),
                        damping_ratio: vec![0.0; freq.len()],
                        points: Vec::new(),
                        participation: Vec::new(),
                    },
                    _ => {
                        return Err(Error::invalid(
                            "structure",
                            "a modal structure needs either frequencies_hz (inline) or file (a .npz basis), not both",
                        ));
                    }
                };
                let p = basis.modes();
                match damping_ratio {
                    Some(DampingInput::Constant(x)) => {
                        check_damping_ratio(*x, "structure.damping_ratio")?;
                        basis.damping_ratio = vec![*x; p]
                    }
                    Some(DampingInput::PerMode(v)) => basis.damping_ratio = v.clone(),
                    None => {}
                }
                for (j, pt) in points.iter().enumerate() {
                    if !(pt.rotations.is_empty()
                        || pt.rotations.len() == 3 && pt.rotations.iter().all(|r| r.len() == p))
                    {
                        return Err(Error::invalid(
                            format!("structure.points[{j}].rotations"),
                            format!(
                                "must be 3 rows (θx, θy, θz) of {p} values each, one value per mode"
                            ),
                        ));
                    }
                    if pt.rows.len() != 3 || pt.rows.iter().any(|r| r.len() != p) {
                        return Err(Error::invalid(
                            format!("structure.points[{j}].rows"),
                            format!(
                                "must be 3 rows (x, y, z) of {p} values each, one value per mode"
                            ),
                        ));
                    }
                    if abscissae.source.is_empty() {
                        abscissae.source = "s = … (m) on the points of [structure]".into();
                    }
                    abscissae.s.resize(basis.points.len(), None);
                    if let Some(s) = pt.s
                        && !s.is_finite()
                    {
                        return Err(Error::invalid(
                            format!("structure.points[{j}].s"),
                            format!("must be a finite abscissa in m (got {})", number(s)),
                        ));
                    }
                    abscissae.s.push(pt.s);
                    basis.points.push(Point {
                        name: pt.name.clone(),
                        coords: v3(pt.coords),
                        rows: pt.rows.concat(),
                        rotations: pt.rotations.concat(),
                    });
                }
                if let Some(g) = participation {
                    if g.len() != 3 || g.iter().any(|r| r.len() != p) {
                        return Err(Error::invalid(
                            "structure.participation",
                            format!("must be 3 rows (x, y, z) of {p} values Φᵀ M r, one per mode"),
                        ));
                    }
                    basis.participation = g.concat();
                }
                Ok(basis)
            }
        }
    }
}

impl InitialSection {
    /// `[initial]`: the initial state, at a point or in modal coordinates.
    pub(super) fn build(&self, model: &mut Model) -> Result<()> {
        let p = model.basis.modes();
        match (&self.point, &self.q, &self.qdot) {
            (Some(name), None, None) => {
                let pt = point_index(name, "initial.point".into(), model)?;
                for (key, v, unit) in [
                    ("displacement", self.displacement, "m"),
                    ("velocity", self.velocity, "m/s"),
                ] {
                    if let Some(v) = v.filter(|v| v.iter().any(|x| !x.is_finite())) {
                        return Err(Error::invalid(
                            format!("initial.{key}"),
                            format!(
                                "must be 3 finite numbers [x, y, z] in {unit} (got [{}, {}, {}])",
                                v[0], v[1], v[2]
                            ),
                        ));
                    }
                }
                model.set_initial_from_point(
                    pt,
                    v3(self.displacement.unwrap_or_default()),
                    v3(self.velocity.unwrap_or_default()),
                )?;
            }
            (None, q, qd) if self.displacement.is_none() && self.velocity.is_none() => {
                model.initial.q = q.clone().unwrap_or_else(|| vec![0.0; p]);
                model.initial.qdot = qd.clone().unwrap_or_else(|| vec![0.0; p]);
            }
            _ => {
                return Err(Error::invalid(
                    "initial",
                    "give either point with displacement/velocity, or q/qdot (modal), not both",
                ));
            }
        }
        Ok(())
    }
}
