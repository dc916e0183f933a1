//! `width`, `points_across`, `twist_deg` of a `[[contacts]]` entry on a `plane` or `bi_plane`:
//! the contact of a flat bar of finite width, possibly twisted, expanded into its points across
//! the width (`contact::flat_bar`, THEORY §16.2). Every other key of the entry applies to
//! each point; a wear scar becomes one strip of the bar per point.

use nalgebra::Vector3;

use super::shared::TubeModel;
use crate::contact::flat_bar::{FlatBar, offset_point};
use crate::contact::obstacle::{BiPlane, Obstacle, Plane};
use crate::contact::{Contact, NormalLaw};
use crate::error::{Error, Result, number};
use crate::model::Model;
use crate::wear::{ContactWear, Scar};

/// The points across the width by default: the two edges and the middle.
pub(super) const DEFAULT_POINTS: usize = 3;

/// The contact `contact` (built as one point, its wear `wear`) of the bar `bar`, expanded into
/// the bar's points across its width: contact `j` named `name[j]` on a new point `name[j]`
/// (the section's point translated by `s_j t`), with the share `ω_j` of the normal stiffness
/// and damping and, twisted, the face turned about the bar's length; a `flat_bar` scar of the
/// width `ω_j w` (its strip) and the twist as its tilt. One point (`points_across = 1`)
/// without twist is the contact itself. `tube` is the tube the point is on (its axis is `t`),
/// `field` names the contact.
pub(super) fn expand(
    contact: Contact,
    wear: Option<ContactWear>,
    bar: FlatBar,
    tube: Option<&TubeModel>,
    model: &mut Model,
    field: &str,
) -> Result<Vec<(Contact, Option<ContactWear>)>> {
    if contact.pair.is_some() {
        return Err(Error::invalid(
            format!("{field}.width"),
            "a bar's width is for a tube against a fixed flat bar (plane or bi_plane), not a two-body contact: remove width, points_across and twist_deg",
        ));
    }
    let (normal, tangent) = match &contact.obstacle {
        Obstacle::Plane(_) | Obstacle::BiPlane(_) => (
            contact.obstacle.penalty_directions().0[0],
            contact.obstacle.fixed_tangents().map(|t| t[0]),
        ),
        _ => {
            return Err(Error::invalid(
                format!("{field}.width"),
                "a width is that of a flat bar: the obstacle must be a plane or a bi_plane (remove width, points_across and twist_deg)",
            ));
        }
    };
    let point = &model.basis.points[contact.point];
    let Some(tube) = tube else {
        return Err(Error::invalid(
            format!("{field}.width"),
            format!(
                "a bar's width lies along the tube's axis: point '{}' must be on a tube structure",
                point.name
            ),
        ));
    };
    if point.rotations.is_empty() {
        return Err(Error::invalid(
            format!("{field}.width"),
            format!(
                "the points across a bar's width need the rotations of point '{}'",
                point.name
            ),
        ));
    }
    let axis = axis_at(tube, &point.coords);
    if normal.dot(&axis).abs() > 1e-6 {
        return Err(Error::invalid(
            format!("{field}.obstacle.normal"),
            format!(
                "a flat bar with a width lies along the tube: its normal must be perpendicular to the tube's axis [{}, {}, {}] at point '{}' (normal · axis = {})",
                number(axis.x),
                number(axis.y),
                number(axis.z),
                point.name,
                number(normal.dot(&axis))
            ),
        ));
    }
    let t = (axis - normal * normal.dot(&axis)).normalize();
    let obstacle = if bar.twist == 0.0 {
        contact.obstacle.clone()
    } else {
        twisted(
            &contact.obstacle,
            &bar,
            &point.coords,
            &t,
            &normal,
            tangent,
            field,
        )?
    };
    let strip = |weight: f64| -> Result<Option<ContactWear>> {
        let Some(w) = &wear else { return Ok(None) };
        let Scar::FlatBar { tube_radius, .. } = w.scar else {
            return Err(Error::invalid(
                format!("{field}.wear.scar.type"),
                "a bar with a width wears with a flat_bar scar (its width and tilt are the bar's width and twist)",
            ));
        };
        let mut w = w.clone();
        w.scar = Scar::FlatBar {
            tube_radius,
            width: weight * bar.width,
            tilt: bar.twist.abs(),
        };
        Ok(Some(w))
    };
    if bar.points == 1 {
        let mut one = contact;
        one.obstacle = obstacle;
        one.across = Some(bar.across()[0]);
        return Ok(vec![(one, strip(1.0)?)]);
    }
    let mut out = Vec::with_capacity(bar.points);
    for a in bar.across() {
        let name = format!("{}[{}]", contact.name, a.index);
        if model.basis.point_index(&name).is_some() {
            return Err(Error::invalid(
                format!("{field}.name"),
                format!(
                    "the bar's points are named '{}[j]' and '{name}' is already a point: rename the contact",
                    contact.name
                ),
            ));
        }
        let sub = offset_point(
            &model.basis.points[contact.point],
            &(t * a.offset),
            name.clone(),
        );
        model.basis.points.push(sub);
        let mut c = contact.clone();
        c.name = name;
        c.point = model.basis.points.len() - 1;
        c.obstacle = obstacle.clone();
        c.normal = NormalLaw {
            stiffness: contact.normal.stiffness * a.weight,
            damping: contact.normal.damping * a.weight,
        };
        c.across = Some(a);
        out.push((c, strip(a.weight)?));
    }
    Ok(out)
}

/// The obstacle with its face turned by the bar's twist about `b = t × n` through the foot of
/// the point `x` on its reference plane: normal `n'`, the first tangent turned alike, the
/// same clearance.
fn twisted(
    obstacle: &Obstacle,
    bar: &FlatBar,
    x: &Vector3<f64>,
    t: &Vector3<f64>,
    n: &Vector3<f64>,
    tangent: Option<Vector3<f64>>,
    field: &str,
) -> Result<Obstacle> {
    let turned = bar.turn(n, t, n);
    let tangent = tangent.map(|t1| bar.turn(&t1, t, n));
    let field = format!("{field}.obstacle");
    Ok(match obstacle {
        Obstacle::Plane(p) => {
            let foot = x - n * (x - p.origin()).dot(n);
            Obstacle::Plane(Plane::new(foot, turned, p.gap(), tangent, &field)?)
        }
        Obstacle::BiPlane(b) => {
            let foot = x - n * (x - b.origin()).dot(n);
            Obstacle::BiPlane(BiPlane::new(foot, turned, b.gap(), tangent, &field)?)
        }
        _ => unreachable!("checked by expand: a bar is a plane or a bi_plane"),
    })
}

/// The unit axis of the tube at the node nearest `x`: the mean direction of its elements
/// there, from the first node to the last.
fn axis_at(tube: &TubeModel, x: &Vector3<f64>) -> Vector3<f64> {
    let mesh = &tube.structure.beam.mesh;
    let (node, _) = mesh.nearest_node(x);
    let mut sum = Vector3::zeros();
    for [a, b] in &mesh.elements {
        if *a == node || *b == node {
            sum += (mesh.nodes[*b] - mesh.nodes[*a]).normalize();
        }
    }
    sum.normalize()
}
