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
    /// Tangent basis `[t1, t2]`, orthonormal and orthogonal to `normal`.
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

/// A drilled hole of a support plate (point–circle, THEORY §3): circle of centre `c` in the
/// plane normal to the tube axis `a`, radial clearance `g`. With `r` the in-plane offset of the
/// point from `c`: `δ = |r| − g`, `n = −r/|r|` (towards the hole's centre), tangents
/// `[e_θ, a]` with `e_θ = a × r/|r|` (circumferential, axial).
#[derive(Debug, Clone, PartialEq)]
pub struct Circle {
    centre: Vector3<f64>,
    axis: Vector3<f64>,
    clearance: f64,
    /// An in-plane unit vector, for the frame of a point exactly on the axis.
    e1: Vector3<f64>,
}

impl Circle {
    /// Builds a hole; `field` names it in error messages.
    pub fn new(
        centre: Vector3<f64>,
        axis: Vector3<f64>,
        clearance: f64,
        field: &str,
    ) -> Result<Self> {
        if centre.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{field}.centre"),
                "must be 3 finite numbers",
            ));
        }
        let na = axis.norm();
        if !(na.is_finite() && na > 0.0) {
            return Err(Error::invalid(
                format!("{field}.axis"),
                "must be a non-zero finite vector (the tube's axis through the hole)",
            ));
        }
        if !(clearance.is_finite() && clearance >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.clearance"),
                format!("must be a radial clearance ≥ 0 in m (got {clearance})"),
            ));
        }
        let axis = axis / na;
        Ok(Self {
            centre,
            axis,
            clearance,
            e1: default_tangent(&axis).normalize(),
        })
    }

    #[inline]
    fn frame(&self, x: &Vector3<f64>) -> ContactFrame {
        let d = x - self.centre;
        let r = d - self.axis * self.axis.dot(&d);
        let rho = r.norm();
        let radial = if rho > 0.0 { r / rho } else { self.e1 };
        ContactFrame {
            penetration: rho - self.clearance,
            normal: -radial,
            tangents: [self.axis.cross(&radial), self.axis],
            velocity: Vector3::zeros(),
        }
    }
}

/// Two flat bars on both sides of the tube (anti-vibration bars, THEORY §3): planes at
/// `±gap` from `x0` along `n`; the one the point is nearer to is the only one that can be
/// active. With `s = (x − x0)·n`: `δ = |s| − gap`, normal `−sign(s) n`; tangents fixed.
#[derive(Debug, Clone, PartialEq)]
pub struct BiPlane {
    origin: Vector3<f64>,
    normal: Vector3<f64>,
    gap: f64,
    tangents: [Vector3<f64>; 2],
}

impl BiPlane {
    /// Builds the pair; `tangent` fixes the first tangent direction (projected).
    pub fn new(
        origin: Vector3<f64>,
        normal: Vector3<f64>,
        gap: f64,
        tangent: Option<Vector3<f64>>,
        field: &str,
    ) -> Result<Self> {
        if !(gap.is_finite() && gap >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.gap"),
                format!("must be the clearance ≥ 0 on each side, in m (got {gap})"),
            ));
        }
        let plane = Plane::new(origin, normal, 0.0, tangent, field)?;
        Ok(Self {
            origin,
            normal: plane.normal,
            gap,
            tangents: plane.tangents,
        })
    }

    #[inline]
    fn frame(&self, x: &Vector3<f64>) -> ContactFrame {
        let s = (x - self.origin).dot(&self.normal);
        ContactFrame {
            penetration: s.abs() - self.gap,
            normal: if s >= 0.0 { -self.normal } else { self.normal },
            tangents: self.tangents,
            velocity: Vector3::zeros(),
        }
    }
}

/// The obstacles fretdyn knows.
#[derive(Debug, Clone, PartialEq)]
pub enum Obstacle {
    /// Point–plane contact.
    Plane(Plane),
    /// Point–circle contact: a tube in a drilled hole.
    Circle(Circle),
    /// Two parallel bars at ±gap.
    BiPlane(BiPlane),
}

impl Obstacle {
    /// Frame at physical position `x` (THEORY §3).
    #[inline]
    pub fn frame(&self, x: &Vector3<f64>) -> ContactFrame {
        match self {
            Obstacle::Plane(p) => p.frame(x),
            Obstacle::Circle(c) => c.frame(x),
            Obstacle::BiPlane(b) => b.frame(x),
        }
    }

    /// The tangent basis, when it does not depend on the position or time (fixed planes and
    /// bars): the Delassus rows of such a contact are computed once.
    pub fn fixed_tangents(&self) -> Option<[Vector3<f64>; 2]> {
        match self {
            Obstacle::Plane(p) => Some(p.tangents),
            Obstacle::BiPlane(b) => Some(b.tangents),
            Obstacle::Circle(_) => None,
        }
    }

    /// Directions along which the normal and the tangential penalty stiffnesses can act,
    /// for the stability bound (every direction they can take, when they turn with the
    /// position: a conservative bound).
    pub fn penalty_directions(&self) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
        match self {
            Obstacle::Plane(p) => (vec![p.normal], p.tangents.to_vec()),
            Obstacle::BiPlane(b) => (vec![b.normal], b.tangents.to_vec()),
            Obstacle::Circle(c) => {
                let e2 = c.axis.cross(&c.e1);
                (vec![c.e1, e2], vec![c.e1, e2, c.axis])
            }
        }
    }
}
