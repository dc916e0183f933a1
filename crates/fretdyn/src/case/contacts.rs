//! `[[contacts]]`: obstacles (plane, bi-plane, circle, polygon, cylinder), their motion, the
//! normal law and the friction coefficients (THEORY §3, §4, §7, §8); with `other`, a
//! two-body contact between two points (THEORY §15); a plane's `preload` (THEORY §16.1); with
//! `width`, a flat bar's points across its width (`flat_bar.rs`).

use nalgebra::{Vector2, Vector3};
use serde::Deserialize;

use super::flat_bar;
use super::obstacle::ObstacleInput;
use super::shared::{TubeModel, point_index, v3};
use super::wear::WearInput;
use crate::contact::flat_bar::FlatBar;
use crate::contact::friction::Coulomb;
use crate::contact::motion::Motion;
use crate::contact::obstacle::{BiPlane, Circle, Cylinder, Obstacle, Plane, Polygon};
use crate::contact::preload::{Preload, PreloadInput};
use crate::contact::{Contact, NormalLaw};
use crate::error::{Error, Result, number};
use crate::model::Model;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ContactSection {
    name: Option<String>,
    point: String,
    /// Point B of a two-body contact (THEORY §15): the contact is on the relative point
    /// `point − other`, its obstacle in relative coordinates.
    other: Option<String>,
    obstacle: ObstacleInput,
    /// The tube's outer radius around `point` (0: the contact is on the axis).
    radius: Option<f64>,
    /// A two-body contact's surface radii `[R_A, R_B]` around `point` and `other`, m
    /// (default `[0, 0]`).
    radii: Option<[f64; 2]>,
    motion: Option<MotionInput>,
    normal: NormalInput,
    friction: FrictionInput,
    /// Wear laws and scar geometry (docs/WEAR.md).
    wear: Option<WearInput>,
    /// A flat bar's width along the tube, m: the contact becomes `points_across` contacts
    /// across it (`case/flat_bar.rs`).
    width: Option<f64>,
    /// The contact points across the bar's width (default 3: the edges and the middle).
    points_across: Option<usize>,
    /// The bar's face turned about the bar's length, degrees (> 0: nearer the tube on the
    /// side of the tube's last node).
    twist_deg: Option<f64>,
    /// A plane pressed on the structure at rest (THEORY §16.1).
    preload: Option<PreloadSection>,
}

/// `preload = { interference = I }` (m) or `preload = { force = F }` (N) of a plane contact.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PreloadSection {
    interference: Option<f64>,
    force: Option<f64>,
}

impl PreloadSection {
    /// The checked preload of the contact `field`, whose obstacle is `obstacle`.
    fn build(&self, obstacle: &Obstacle, field: &str) -> Result<Preload> {
        let pf = format!("{field}.preload");
        let input = match (self.interference, self.force) {
            (Some(i), None) => PreloadInput::Interference(i),
            (None, Some(f)) => PreloadInput::Force(f),
            _ => {
                return Err(Error::invalid(
                    pf,
                    "give either interference (m: the plane pressed into the structure at rest) or force (N: the contact force at rest), not both",
                ));
            }
        };
        Preload::plane(obstacle, field)?;
        Preload::new(input, &pf)
    }
}

#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub(super) enum MotionInput {
    Velocity {
        velocity: [f64; 3],
    },
    Harmonic {
        amplitude: [f64; 3],
        frequency_hz: f64,
        #[serde(default)]
        phase_deg: f64,
    },
    Table {
        table: Vec<[f64; 4]>,
    },
}

impl MotionInput {
    fn motion(&self) -> Motion {
        match self {
            MotionInput::Velocity { velocity } => Motion::Velocity(v3(*velocity)),
            MotionInput::Harmonic {
                amplitude,
                frequency_hz,
                phase_deg,
            } => Motion::Harmonic {
                amplitude: v3(*amplitude),
                frequency_hz: *frequency_hz,
                phase: phase_deg.to_radians(),
            },
            MotionInput::Table { table } => Motion::Table {
                times: table.iter().map(|r| r[0]).collect(),
                displacements: table
                    .iter()
                    .map(|r| Vector3::new(r[1], r[2], r[3]))
                    .collect(),
            },
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct NormalInput {
    stiffness: f64,
    #[serde(default)]
    damping: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FrictionInput {
    mu: Option<f64>,
    mu_static: Option<f64>,
    mu_dynamic: Option<f64>,
}

/// `[[contacts]]`: each contact's point, obstacle (and its motion), normal law and friction
/// coefficients (THEORY §3, §4, §7, §8), or, with `other`, the two points of a two-body
/// contact (THEORY §15). `tube_of` gives the tube structure a point (its index) belongs to,
/// if it is one: the radii are checked against its outer radius, and a flat bar's `width`
/// lies along its axis (its points across the width, `case/flat_bar.rs`).
pub(super) fn build_contacts<'t>(
    contacts: &[ContactSection],
    tube_of: &dyn Fn(usize) -> Option<&'t TubeModel>,
    model: &mut Model,
) -> Result<()> {
    // the index of each name given so far (a search per contact was O(m²): minutes for
    // 100 000 contacts)
    let mut names = std::collections::HashMap::with_capacity(contacts.len());
    for (k, c) in contacts.iter().enumerate() {
        let field = format!("contacts[{k}]");
        let pt = point_index(&c.point, format!("{field}.point"), model)?;
        let pair = match &c.other {
            None if c.radii.is_some() => {
                return Err(Error::invalid(
                    format!("{field}.radii"),
                    "radii = [R_A, R_B] are the two surfaces of a two-body contact: name its second point with other = \"…\", or give the tube's radius as radius",
                ));
            }
            None => None,
            Some(other) => Some(two_body(c, pt, other, &field, tube_of, model)?),
        };
        // a pair's planes are placed from the rest relative position x0_A − x0_B
        let at = |origin: [f64; 3]| match &pair {
            Some((b, _)) => {
                v3(origin) + model.basis.points[pt].coords - model.basis.points[*b].coords
            }
            None => v3(origin),
        };
        let obstacle = match c.obstacle {
            ObstacleInput::Plane {
                origin,
                normal,
                gap,
                tangent,
            } => Obstacle::Plane(Plane::new(
                at(origin),
                v3(normal),
                gap,
                tangent.map(v3),
                &format!("{field}.obstacle"),
            )?),
            ObstacleInput::Circle {
                centre,
                axis,
                clearance,
            } => Obstacle::Circle(Circle::new(
                v3(centre),
                v3(axis),
                clearance,
                &format!("{field}.obstacle"),
            )?),
            ObstacleInput::BiPlane {
                origin,
                normal,
                gap,
                tangent,
            } => Obstacle::BiPlane(BiPlane::new(
                at(origin),
                v3(normal),
                gap,
                tangent.map(v3),
                &format!("{field}.obstacle"),
            )?),
            ObstacleInput::Polygon {
                centre,
                axis,
                reference,
                ref vertices,
                ref polar,
            } => {
                let vertices = match (vertices, polar) {
                    (Some(v), None) => v.iter().map(|p| Vector2::new(p[0], p[1])).collect(),
                    (None, Some(p)) => Polygon::polar(
                        &p.iter()
                            .map(|p| (p[0].to_radians(), p[1]))
                            .collect::<Vec<_>>(),
                    ),
                    _ => {
                        return Err(Error::invalid(
                            format!("{field}.obstacle"),
                            "a polygonal hole needs either vertices ([x1, x2] pairs, m) or polar ([angle_deg, radius] pairs), not both",
                        ));
                    }
                };
                Obstacle::Polygon(Polygon::new(
                    v3(centre),
                    v3(axis),
                    reference.map(v3),
                    vertices,
                    &format!("{field}.obstacle"),
                )?)
            }
            ObstacleInput::Cylinder {
                centre,
                axis,
                radius,
            } => {
                let sum = pair.map(|(_, r)| r[0] + r[1]).filter(|r| *r > 0.0);
                let Some(radius) = radius.or(sum) else {
                    return Err(Error::invalid(
                        format!("{field}.obstacle.radius"),
                        "a cylinder needs its radius, m (the distance from its axis at which the point touches it; for two tubes the sum of their outer radii, the default when the contact gives radii = [R_A, R_B])",
                    ));
                };
                Obstacle::Cylinder(Cylinder::new(
                    v3(centre),
                    v3(axis),
                    radius,
                    &format!("{field}.obstacle"),
                )?)
            }
        };
        let normal = NormalLaw::new(
            c.normal.stiffness,
            c.normal.damping,
            &format!("{field}.normal"),
        )?;
        let ff = format!("{field}.friction");
        let (mu_s, mu_d) = match (c.friction.mu, c.friction.mu_static, c.friction.mu_dynamic) {
            (Some(mu), None, None) => (mu, mu),
            (None, Some(s), Some(d)) => (s, d),
            (None, Some(s), None) => (s, s),
            (None, None, Some(d)) => (d, d),
            _ => {
                return Err(Error::invalid(
                    ff,
                    "give either mu, or mu_static and mu_dynamic",
                ));
            }
        };
        // errors name the key written: `mu` stands for both coefficients, and a lone
        // `mu_static` (or `mu_dynamic`) for the other one too
        let written = match (c.friction.mu, c.friction.mu_static, c.friction.mu_dynamic) {
            (Some(_), _, _) => Some("mu"),
            (None, Some(_), None) => Some("mu_static"),
            (None, None, Some(_)) => Some("mu_dynamic"),
            _ => None,
        };
        let friction = Coulomb::new(mu_s, mu_d, &ff).map_err(|e| match (e, written) {
            (Error::Invalid { message, .. }, Some(key)) => {
                Error::invalid(format!("{ff}.{key}"), message)
            }
            (e, _) => e,
        })?;
        let name = c.name.clone().unwrap_or_else(|| format!("contact{k}"));
        if let Some(j) = names.insert(name.clone(), k) {
            return Err(Error::invalid(
                format!("{field}.name"),
                format!(
                    "'{name}' is already the name of contacts[{j}]: contact names must be unique (they label the outputs)"
                ),
            ));
        }
        let radius = c.radius.unwrap_or(0.0);
        if radius > 0.0 {
            check_radius(radius, tube_of(pt), &format!("{field}.radius"))?;
        }
        let mut contact = match pair {
            None => {
                let mut contact = Contact::new(name, pt, obstacle, normal, friction);
                contact.radius = radius;
                contact
            }
            Some((b, radii)) => Contact::between(
                name,
                pt,
                b,
                &model.basis.points,
                radii,
                obstacle,
                normal,
                friction,
            )
            .map_err(|e| match e {
                Error::Invalid { field: f, message } => Error::invalid(
                    format!("{field}.{}", f.rsplit('.').next().unwrap_or(&f)),
                    message,
                ),
                other => other,
            })?,
        };
        if let Some(m) = &c.motion {
            contact.motion = m.motion();
        }
        if let Some(pre) = &c.preload {
            contact.preload = Some(pre.build(&contact.obstacle, &field)?);
        }
        contact.validate(contact.point_in(&model.basis.points), &field)?;
        let bar = flat_bar_of(c, &field)?;
        // a pair's wear: A's scar against B, each side's radius (THEORY §15)
        let wear = c.wear.as_ref().map(|w| match pair {
            Some((_, radii)) => w.build_pair(radii, &c.obstacle, &field),
            None => w.build(radius, bar.as_ref(), &c.obstacle, &field),
        });
        let wear = wear.transpose()?;
        if let (Some(bar), Some(pre)) = (&bar, &contact.preload)
            && bar.points > 1
            && matches!(pre.input, PreloadInput::Force(_))
        {
            return Err(Error::invalid(
                format!("{field}.preload.force"),
                "a bar with a width is pressed as one face: give its preload as an interference (m, every point of the face moved alike); a force at rest would not say how it spreads over the width",
            ));
        }
        let Some(bar) = bar else {
            model.wear.push(wear);
            model.contacts.push(contact);
            continue;
        };
        for (sub, wear) in flat_bar::expand(contact, wear, bar, tube_of(pt), model, &field)? {
            if bar.points > 1
                && let Some(j) = names.insert(sub.name.clone(), k)
            {
                return Err(Error::invalid(
                    format!("{field}.name"),
                    format!(
                        "'{}', one of its bar's points, is already the name of contacts[{j}]: rename one",
                        sub.name
                    ),
                ));
            }
            model.wear.push(wear);
            model.contacts.push(sub);
        }
    }
    Ok(())
}

/// The flat bar of the contact `c` if it gives a `width` (`points_across`, `twist_deg` need
/// one); `field` names the contact.
fn flat_bar_of(c: &ContactSection, field: &str) -> Result<Option<FlatBar>> {
    let Some(width) = c.width else {
        for (key, given) in [
            ("points_across", c.points_across.is_some()),
            ("twist_deg", c.twist_deg.is_some()),
        ] {
            if given {
                return Err(Error::invalid(
                    format!("{field}.{key}"),
                    "is a flat bar's: give the bar's width (width = …, m) with it, or remove it",
                ));
            }
        }
        return Ok(None);
    };
    FlatBar::new(
        width,
        c.points_across.unwrap_or(flat_bar::DEFAULT_POINTS),
        c.twist_deg.unwrap_or(0.0).to_radians(),
        field,
    )
    .map(Some)
}

/// Point B and the radii `[R_A, R_B]` of the two-body contact `c` (THEORY §15), whose point A
/// is `a`: `other` names B; `radii` (default `[0, 0]`) replaces `radius`, and the obstacle
/// moves with B (no `motion`).
fn two_body<'t>(
    c: &ContactSection,
    a: usize,
    other: &str,
    field: &str,
    tube_of: &dyn Fn(usize) -> Option<&'t TubeModel>,
    model: &Model,
) -> Result<(usize, [f64; 2])> {
    let b = point_index(other, format!("{field}.other"), model)?;
    if c.radius.is_some() {
        return Err(Error::invalid(
            format!("{field}.radius"),
            "a two-body contact (with other) gives its surface radii as radii = [R_A, R_B] (m, around point and other): replace radius",
        ));
    }
    if c.motion.is_some() {
        return Err(Error::invalid(
            format!("{field}.motion"),
            "a two-body contact's obstacle moves with point B (other): remove motion",
        ));
    }
    let radii = c.radii.unwrap_or([0.0; 2]);
    for (k, (r, p)) in radii.iter().zip([a, b]).enumerate() {
        if *r > 0.0 {
            check_radius(*r, tube_of(p), &format!("{field}.radii[{k}]"))?;
        }
    }
    Ok((b, radii))
}

/// Refuses a surface radius larger than the outer radius of the tube the point is on.
fn check_radius(radius: f64, tube: Option<&TubeModel>, field: &str) -> Result<()> {
    if let Some(t) = tube {
        let outer = 0.5 * t.structure.beam.tube.section.outer_diameter;
        if radius > outer * (1.0 + 1e-9) {
            return Err(Error::invalid(
                field,
                format!(
                    "{} m is larger than the tube's outer radius {} m (structure.outer_diameter/2): give the outer radius in m",
                    number(radius),
                    number(outer)
                ),
            ));
        }
    }
    Ok(())
}
