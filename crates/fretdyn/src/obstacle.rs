//! Obstacle geometry: for a point position, the penetration `δ`, the outward normal `n` and the
//! tangent basis `T` (THEORY §3).

use nalgebra::Vector3;

use crate::error::{Error, Result};

/// What a contact needs from the obstacle at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFrame {
    /// Penetration `δ` (m): positive when the point is past the obstacle surface, negative is
    /// the remaining clearance.
    pub penetration: f64,
    /// Outward unit normal of the obstacle (pointing to the free side).
    pub normal: Vector3<f64>,
    /// Tangent basis `[t1, t2]`, orthonormal and orthogonal to `normal`, right-handed with it.
    pub tangents: [Vector3<f64>; 2],
    /// Velocity of the obstacle surface at the contact (0 for a fixed obstacle).
    pub velocity: Vector3<f64>,
}

/// A fixed plane: `δ = −(x − x0)·n − gap`, tangent plane spanned by `t1`, `t2 = n × t1`.
///
/// `x0` is the reference point from which the clearance `gap` is measured along `−n`: the
/// obstacle surface is the plane through `x0 − gap n`.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    origin: Vector3<f64>,
    normal: Vector3<f64>,
    gap: f64,
    tangents: [Vector3<f64>; 2],
}

impl Plane {
    /// Builds a plane; `tangent`, if given, fixes the first tangent direction (projected on the
    /// plane). `field` names the obstacle in error messages.
    pub fn new(
        origin: Vector3<f64>,
        normal: Vector3<f64>,
        gap: f64,
        tangent: Option<Vector3<f64>>,
        field: &str,
    ) -> Result<Self> {
        if origin.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{field}.origin"),
                "must be 3 finite numbers",
            ));
        }
        let nn = normal.norm();
        if !(nn.is_finite() && nn > 0.0) {
            return Err(Error::invalid(
                format!("{field}.normal"),
                "must be a non-zero finite vector (the obstacle's outward normal)",
            ));
        }
        if !gap.is_finite() {
            return Err(Error::invalid(
                format!("{field}.gap"),
                "must be a finite clearance in m",
            ));
        }
        let n = normal / nn;
        let seed = match tangent {
            Some(t) => {
                let tp = t - n * n.dot(&t);
                if !(tp.norm() > 1e-12 * t.norm().max(1e-300)) || tp.iter().any(|v| !v.is_finite())
                {
                    return Err(Error::invalid(
                        format!("{field}.tangent"),
                        "must be a finite vector not parallel to the normal",
                    ));
                }
                tp
            }
            None => default_tangent(&n),
        };
        let t1 = seed.normalize();
        let t2 = n.cross(&t1);
        Ok(Self {
            origin,
            normal: n,
            gap,
            tangents: [t1, t2],
        })
    }

    /// Frame at physical position `x`.
    #[inline]
    pub fn frame(&self, x: &Vector3<f64>) -> ContactFrame {
        ContactFrame {
            penetration: -(x - self.origin).dot(&self.normal) - self.gap,
            normal: self.normal,
            tangents: self.tangents,
            velocity: Vector3::zeros(),
        }
    }

    /// Outward unit normal.
    pub fn normal(&self) -> Vector3<f64> {
        self.normal
    }

    /// Tangent basis.
    pub fn tangents(&self) -> [Vector3<f64>; 2] {
        self.tangents
    }
}

/// A first tangent for a normal `n`: the global axis least aligned with `n`, projected.
fn default_tangent(n: &Vector3<f64>) -> Vector3<f64> {
    let axes = [Vector3::x(), Vector3::y(), Vector3::z()];
    let a = axes
        .iter()
        .min_by(|a, b| a.dot(n).abs().total_cmp(&b.dot(n).abs()))
        .copied()
        .unwrap_or_else(Vector3::x);
    a - n * n.dot(&a)
}

/// The obstacles fretdyn knows. Issue-driven: more shapes (circle, bi-plane) join here.
#[derive(Debug, Clone, PartialEq)]
pub enum Obstacle {
    /// Point–plane contact.
    Plane(Plane),
}

impl Obstacle {
    /// Frame at physical position `x` (THEORY §3).
    #[inline]
    pub fn frame(&self, x: &Vector3<f64>) -> ContactFrame {
        match self {
            Obstacle::Plane(p) => p.frame(x),
        }
    }

    /// The tangent basis, when it does not depend on the position or time (a fixed plane):
    /// the Delassus rows of such a contact are computed once.
    pub fn fixed_tangents(&self) -> Option<[Vector3<f64>; 2]> {
        match self {
            Obstacle::Plane(p) => Some(p.tangents),
        }
    }

    /// Directions along which the penalty stiffnesses act, for the stability bound: the
    /// normal and the tangents. For a plane they do not depend on the position.
    pub fn stiffness_directions(&self) -> (Vector3<f64>, [Vector3<f64>; 2]) {
        match self {
            Obstacle::Plane(p) => (p.normal, p.tangents),
        }
    }
}
