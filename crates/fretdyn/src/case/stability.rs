//! `[stability]` and its `[[stability.conditions]]`: the support conditions under which
//! `fretdyn stability` checks the modes besides the basis's own (support-inactive) ones —
//! supports held at named points or contacts' points, in both directions normal to the tube's
//! axis (`pinned`), or only normal to the structure's plane (`out_of_plane`) or only in it
//! (`in_plane`) — and the structure's plane that classes the modes (docs/FLOW.md, "Connors
//! check"; THEORY §16.3). Only a tube's finite-element model can hold supports.

use nalgebra::Vector3;
use serde::Deserialize;

use super::shared::{TubeModel, point_index};
use crate::error::{Error, Result, number};
use crate::loads::flow::SUPPORT_INACTIVE;
use crate::model::Model;
use crate::structure::constrained::PointConstraint;
use crate::structure::eigen::ModeSelection;
use crate::structure::tube::TubeStructure;

/// `[stability]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct StabilitySection {
    /// The structure's plane; default: the plane of a planar tube's axis (a U-bend's).
    plane_normal: Option<[f64; 3]>,
    #[serde(default)]
    conditions: Vec<ConditionSection>,
}

/// `[[stability.conditions]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConditionSection {
    name: String,
    /// Held in both directions normal to the axis.
    #[serde(default)]
    pinned: Vec<String>,
    /// Held normal to the structure's plane only.
    #[serde(default)]
    out_of_plane: Vec<String>,
    /// Held in the structure's plane (normal to the axis) only.
    #[serde(default)]
    in_plane: Vec<String>,
    /// Modes kept; default the structure's selection.
    modes: Option<usize>,
}

/// A support condition: its name, the supports it holds, how many modes to check.
#[derive(Debug, Clone, PartialEq)]
pub struct SupportCondition {
    /// Name (letters, digits, `_`, `-`, `.`).
    pub name: String,
    /// The directions held.
    pub constraints: Vec<PointConstraint>,
    /// The modes kept.
    pub selection: ModeSelection,
}

/// The resolved `[stability]` section.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityChecks {
    /// Unit normal of the structure's plane, if it has one.
    pub plane_normal: Option<Vector3<f64>>,
    /// The conditions, in the order of the file.
    pub conditions: Vec<SupportCondition>,
}

impl StabilitySection {
    /// The conditions on the tube `tube` of `model`; an error names the field.
    pub(super) fn build(&self, tube: Option<&TubeModel>, model: &Model) -> Result<StabilityChecks> {
        let plane_normal = match self.plane_normal {
            Some(n) => {
                let v = Vector3::from(n);
                if !(v.iter().all(|x| x.is_finite()) && v.norm() > 0.0) {
                    return Err(Error::invalid(
                        "stability.plane_normal",
                        "must be a nonzero finite vector [x, y, z], the normal of the structure's plane",
                    ));
                }
                Some(v.normalize())
            }
            None => tube.and_then(|t| t.structure.plane_normal()),
        };
        if self.conditions.is_empty() {
            return Ok(StabilityChecks {
                plane_normal,
                conditions: Vec::new(),
            });
        }
        let Some(tube) = tube else {
            return Err(Error::invalid(
                "stability.conditions",
                "support conditions need a tube's finite-element model (structure type = \"tube\"): a modal basis has no mass and stiffness matrices to hold supports in; remove [[stability.conditions]]",
            ));
        };
        let mut conditions: Vec<SupportCondition> = Vec::new();
        for (k, c) in self.conditions.iter().enumerate() {
            let field = format!("stability.conditions[{k}]");
            let name_ok = !c.name.is_empty()
                && c.name
                    .chars()
                    .all(|ch| ch.is_ascii_alphanumeric() || matches!(ch, '_' | '-' | '.'));
            if !name_ok || c.name == SUPPORT_INACTIVE {
                return Err(Error::invalid(
                    format!("{field}.name"),
                    format!(
                        "'{}': a condition's name is letters, digits, '_', '-' and '.', other than '{SUPPORT_INACTIVE}' (the basis's own modes)",
                        c.name
                    ),
                ));
            }
            if let Some(j) = conditions.iter().position(|o| o.name == c.name) {
                return Err(Error::invalid(
                    format!("{field}.name"),
                    format!(
                        "'{}' is already the name of stability.conditions[{j}]: give each condition its own name",
                        c.name
                    ),
                ));
            }
            let selection = match c.modes {
                Some(0) => {
                    return Err(Error::invalid(
                        format!("{field}.modes"),
                        "must be at least 1 (default: the structure's modes)",
                    ));
                }
                Some(n) => ModeSelection::Count(n),
                None => tube.structure.selection,
            };
            let mut constraints = Vec::new();
            for (key, names) in [
                ("pinned", &c.pinned),
                ("out_of_plane", &c.out_of_plane),
                ("in_plane", &c.in_plane),
            ] {
                for (i, name) in names.iter().enumerate() {
                    let at = format!("{field}.{key}[{i}]");
                    let point = support_point(name, at.clone(), model)?;
                    let pt = &tube.structure.points[point];
                    let t = axis_tangent(&tube.structure, pt.node);
                    let directions = held_directions(key, &t, plane_normal, &at)?;
                    constraints.extend(directions.into_iter().map(|direction| PointConstraint {
                        node: pt.node,
                        offset: pt.offset,
                        direction,
                    }));
                }
            }
            if constraints.is_empty() {
                return Err(Error::invalid(
                    field,
                    "holds no support: give pinned, out_of_plane or in_plane = [\"point or contact\", …]",
                ));
            }
            conditions.push(SupportCondition {
                name: c.name.clone(),
                constraints,
                selection,
            });
        }
        Ok(StabilityChecks {
            plane_normal,
            conditions,
        })
    }
}

/// The point of the basis a support condition names: a contact's point, or a point.
fn support_point(name: &str, field: String, model: &Model) -> Result<usize> {
    if let Some(c) = model.contacts.iter().find(|c| c.name == name) {
        return Ok(c.point);
    }
    point_index(name, field, model)
}

/// The unit tangent of the tube's axis at `node`: the mean of the directions of the elements
/// that meet there.
fn axis_tangent(tube: &TubeStructure, node: usize) -> Vector3<f64> {
    let mesh = &tube.beam.mesh;
    let t: Vector3<f64> = mesh
        .elements
        .iter()
        .filter(|[a, b]| *a == node || *b == node)
        .map(|[a, b]| (mesh.nodes[*b] - mesh.nodes[*a]).normalize())
        .sum();
    t.normalize()
}

/// The directions held by a support of kind `key` at a point of axis tangent `t`: both normal
/// to the axis (`pinned`), the plane's normal made normal to the axis (`out_of_plane`), or
/// `t × n` (`in_plane`).
fn held_directions(
    key: &str,
    t: &Vector3<f64>,
    plane_normal: Option<Vector3<f64>>,
    field: &str,
) -> Result<Vec<Vector3<f64>>> {
    let out = match plane_normal {
        Some(n) => n - t * n.dot(t),
        None if key == "pinned" => {
            let e = if t.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            e - t * e.dot(t)
        }
        None => {
            return Err(Error::invalid(
                field,
                "the structure has no plane (a straight tube): give [stability] plane_normal = [x, y, z] to say which direction is out of plane",
            ));
        }
    };
    if out.norm() < 1e-9 {
        return Err(Error::invalid(
            field,
            format!(
                "the tube's axis here is along the plane's normal ([{}, {}, {}]): no direction is in the plane and normal to the axis; check [stability] plane_normal",
                number(t.x),
                number(t.y),
                number(t.z)
            ),
        ));
    }
    let out = out.normalize();
    let inp = t.cross(&out).normalize();
    Ok(match key {
        "pinned" => vec![out, inp],
        "out_of_plane" => vec![out],
        _ => vec![inp],
    })
}
