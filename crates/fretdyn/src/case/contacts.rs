//! `[[contacts]]`: obstacles (plane, bi-plane, circle, polygon), their motion, the normal
//! law and the friction coefficients (THEORY §3, §4, §7, §8).

use nalgebra::{Vector2, Vector3};
use serde::Deserialize;

use super::obstacle::ObstacleInput;
use super::shared::{TubeModel, point_index, v3};
use super::wear::WearInput;
use crate::contact::friction::Coulomb;
use crate::contact::motion::Motion;
use crate::contact::obstacle::{BiPlane, Circle, Cylinder, Obstacle, Plane, Polygon};
use crate::contact::{Contact, NormalLaw};
use crate::error::{Error, Result, number};
use crate::model::Model;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ContactSection {
    name: Option<String>,
    point: String,
    obstacle: ObstacleInput,
    #[serde(default)]
    radius: f64,
    motion: Option<MotionInput>,
    normal: NormalInput,
    friction: FrictionInput,
    /// Wear laws and scar geometry (docs/WEAR.md).
    wear: Option<WearInput>,
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
/// coefficients (THEORY §3, §4, §7, §8).
pub(super) fn build_contacts(
    contacts: &[ContactSection],
    tube: Option<&TubeModel>,
    model: &mut Model,
) -> Result<()> {
    // the index of each name given so far (a search per contact was O(m²): minutes for
    // 100 000 contacts)
    let mut names = std::collections::HashMap::with_capacity(contacts.len());
    for (k, c) in contacts.iter().enumerate() {
        let field = format!("contacts[{k}]");
        let pt = point_index(&c.point, format!("{field}.point"), model)?;
        let obstacle = match c.obstacle {
            ObstacleInput::Plane {
                origin,
                normal,
                gap,
                tangent,
            } => Obstacle::Plane(Plane::new(
                v3(origin),
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
                v3(origin),
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
                let Some(radius) = radius else {
                    return Err(Error::invalid(
                        format!("{field}.obstacle.radius"),
                        "a cylinder needs its radius, m (the distance from its axis at which the point touches it)",
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
        if let (Some(t), true) = (tube, c.radius > 0.0) {
            let outer = 0.5 * t.structure.beam.tube.section.outer_diameter;
            if c.radius > outer * (1.0 + 1e-9) {
                return Err(Error::invalid(
                    format!("{field}.radius"),
                    format!(
                        "{} m is larger than the tube's outer radius {} m (structure.outer_diameter/2): give the outer radius in m",
                        number(c.radius),
                        number(outer)
                    ),
                ));
            }
        }
        let mut contact = Contact::new(name, pt, obstacle, normal, friction);
        contact.radius = c.radius;
        if let Some(m) = &c.motion {
            contact.motion = m.motion();
        }
        contact.validate(&model.basis.points[pt], &field)?;
        let wear = c
            .wear
            .as_ref()
            .map(|w| w.build(c.radius, &c.obstacle, &field));
        model.wear.push(wear.transpose()?);
        model.contacts.push(contact);
    }
    Ok(())
}
