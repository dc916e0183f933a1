//! A contact's preload (THEORY §16.1): an anti-vibration bar pressed on the tube at rest, by
//! an imposed interference or by a contact force at rest.
//!
//! An interference `I` moves the contact's plane by `I` towards the structure along its
//! normal (the plane's clearance becomes `gap − I`), so that the rest position penetrates
//! it by `I − gap`; a force `F` asks for the interference at which the static equilibrium's
//! normal force is `F` (found by the model layer's `apply_preloads`). Only planes take a preload (flat
//! bars, and two-body planes): a bi-plane has one active side at a time, and a hole or a rod
//! has no one direction to be pressed in.

use crate::contact::obstacle::{Obstacle, Plane};
use crate::error::{Error, Result, number};

/// What the case gives: an interference or a force at rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PreloadInput {
    /// Interference `I ≥ 0`, m: the plane moved by `I` towards the structure.
    Interference(f64),
    /// Normal force at rest `F ≥ 0`, N: the interference is what gives it.
    Force(f64),
}

/// A contact's preload: as given, and once the static equilibrium is computed the
/// interference applied to the obstacle and the normal force at rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Preload {
    /// As the case gives it.
    pub input: PreloadInput,
    /// `(interference, force)` once applied (m, N): the interference the plane was moved by
    /// and the static normal force; `None` before.
    pub applied: Option<(f64, f64)>,
}

impl Preload {
    /// A checked preload; `field` names it in errors (`contacts[0].preload`).
    pub fn new(input: PreloadInput, field: &str) -> Result<Self> {
        let (key, value, what) = match input {
            PreloadInput::Interference(v) => (
                "interference",
                v,
                "an interference ≥ 0 in m (a clearance is obstacle.gap)",
            ),
            PreloadInput::Force(v) => ("force", v, "a contact force at rest ≥ 0 in N"),
        };
        if !(value.is_finite() && value >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.{key}"),
                format!("must be {what} (got {})", number(value)),
            ));
        }
        Ok(Self {
            input,
            applied: None,
        })
    }

    /// The plane of `obstacle`, or an error if it cannot take a preload; `field` names the
    /// contact.
    pub fn plane<'a>(obstacle: &'a Obstacle, field: &str) -> Result<&'a Plane> {
        match obstacle {
            Obstacle::Plane(p) => Ok(p),
            Obstacle::BiPlane(_) => Err(Error::invalid(
                format!("{field}.preload"),
                "a bi_plane has one side in contact at a time and cannot be preloaded on both: give two plane contacts at the point with opposite normals, each with its preload",
            )),
            other => Err(Error::invalid(
                format!("{field}.preload"),
                format!(
                    "a preload presses a flat bar on the tube: it is for plane obstacles (and two-body planes), not a {}",
                    other.kind()
                ),
            )),
        }
    }
}

/// The plane of `obstacle` moved by `interference` towards the free side along its normal:
/// clearance `gap − interference`, the same origin, normal and tangents.
pub fn pressed(obstacle: &Obstacle, interference: f64, field: &str) -> Result<Obstacle> {
    let p = Preload::plane(obstacle, field)?;
    Ok(Obstacle::Plane(Plane::new(
        p.origin(),
        p.normal(),
        p.gap() - interference,
        Some(p.tangents()[0]),
        &format!("{field}.obstacle"),
    )?))
}
