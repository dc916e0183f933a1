//! Obstacle geometry: for a point position, the penetration `δ`, the outward normal `n` and the
//! tangent basis `T` (THEORY §3).

use nalgebra::{Vector2, Vector3};

use crate::contact::scar::{AngularProfile, ObstacleWear};
use crate::error::{Error, Result};

/// What a contact needs from the obstacle at one instant.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
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

    /// Reference point `x0`.
    pub fn origin(&self) -> Vector3<f64> {
        self.origin
    }

    /// Clearance `gap`, m.
    pub fn gap(&self) -> f64 {
        self.gap
    }
}

/// The offset of `x` from the line through `centre` along the unit `axis`, normal to it:
/// its length `ρ` and direction (`e1` when `x` is on the line) — a hole's and a rod's frame.
#[inline(always)]
fn radial_offset(
    centre: &Vector3<f64>,
    axis: &Vector3<f64>,
    e1: &Vector3<f64>,
    x: &Vector3<f64>,
) -> (f64, Vector3<f64>) {
    let d = x - centre;
    let r = d - axis * axis.dot(&d);
    let rho = r.norm();
    (rho, if rho > 0.0 { r / rho } else { *e1 })
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
    /// The wear scar's depth profile, in the axes `(e1, a × e1)` (THEORY §14.4).
    scar: Option<Box<AngularProfile>>,
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
            scar: None,
        })
    }

    #[inline]
    fn frame(&self, x: &Vector3<f64>) -> ContactFrame {
        let (rho, radial) = radial_offset(&self.centre, &self.axis, &self.e1, x);
        if let Some(scar) = &self.scar {
            return self.worn_frame(scar, rho, radial);
        }
        ContactFrame {
            penetration: rho - self.clearance,
            normal: -radial,
            tangents: [self.axis.cross(&radial), self.axis],
            velocity: Vector3::zeros(),
        }
    }

    /// The frame in a worn hole (module [`crate::contact::scar`]): the signed distance to
    /// the worn boundary `ρ = c + d(θ)` and the normal at its nearest point `b`,
    /// `δ = ±|r − b|`, `n = (b − r)/|b − r|` outside; if the nearest point is not found, the
    /// first-order distance `φ/|∇φ|`, `φ = ρ − c − d(θ)`. Inside the least worn radius
    /// `c + min d` the contact is open and its clearance is measured to that radius (no angle
    /// is needed).
    #[inline(never)]
    fn worn_frame(&self, scar: &AngularProfile, rho: f64, radial: Vector3<f64>) -> ContactFrame {
        let e_theta = self.axis.cross(&radial);
        if rho <= self.clearance + scar.min() {
            return ContactFrame {
                penetration: rho - self.clearance - scar.min(),
                normal: -radial,
                tangents: [e_theta, self.axis],
                velocity: Vector3::zeros(),
            };
        }
        let e2 = self.axis.cross(&self.e1);
        let (x1, x2) = (rho * radial.dot(&self.e1), rho * radial.dot(&e2));
        let theta = x2.atan2(x1);
        let (penetration, n2) = match scar.nearest(self.clearance, [x1, x2], theta) {
            Some((b, db)) => {
                let to = [b[0] - x1, b[1] - x2];
                let dist = (to[0] * to[0] + to[1] * to[1]).sqrt();
                // outside when r is beyond the boundary along its outward normal (db rotated)
                let outward = [db[1], -db[0]];
                let outside = -(to[0] * outward[0] + to[1] * outward[1]) > 0.0;
                if dist > 0.0 {
                    let s = if outside { 1.0 } else { -1.0 };
                    (s * dist, [s * to[0] / dist, s * to[1] / dist])
                } else {
                    let l = db[0].hypot(db[1]);
                    (0.0, [-outward[0] / l, -outward[1] / l])
                }
            }
            None => {
                let (depth, slope) = scar.at(theta);
                let grad = radial - e_theta * (slope / rho);
                let norm = grad.norm();
                let n = -grad / norm;
                let p = (rho - self.clearance - depth) / norm;
                (p, [n.dot(&self.e1), n.dot(&e2)])
            }
        };
        let normal = self.e1 * n2[0] + e2 * n2[1];
        ContactFrame {
            penetration,
            normal,
            tangents: [self.axis.cross(&-normal), self.axis],
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

    /// Reference point `x0` of the mid-plane.
    pub fn origin(&self) -> Vector3<f64> {
        self.origin
    }

    /// Clearance `gap` on each side, m.
    pub fn gap(&self) -> f64 {
        self.gap
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

/// A broached (quatrefoil, trefoil) or any polygonal hole of a support plate, as the region
/// the point (the tube axis) can move in: a simple polygon in the plane normal to the tube
/// axis `a` through `c`, with vertices in the in-plane axes `(e1, e2 = a × e1)`. With `r` the
/// in-plane position of the point and `b` the nearest point of the boundary: outside the
/// polygon `δ = |r − b|`, `n = (b − r)/|r − b|` (back towards the hole); inside,
/// `δ = −|r − b|`. On a flat land this is the point–plane law; at a corner the normal turns
/// continuously. Tangents `[n × a, a]` (circumferential, axial), as for a circle.
#[derive(Debug, Clone, PartialEq)]
pub struct Polygon {
    centre: Vector3<f64>,
    axis: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    vertices: Vec<Vector2<f64>>,
    /// The wear scar's depth profile, in the axes `(e1, e2)` (THEORY §14.4).
    scar: Option<Box<AngularProfile>>,
}

impl Polygon {
    /// Builds a hole from its vertices `(x1, x2)` along `(e1, e2)`, m; `reference` fixes `e1`
    /// (projected on the plane; default: the global axis least aligned with `axis`).
    pub fn new(
        centre: Vector3<f64>,
        axis: Vector3<f64>,
        reference: Option<Vector3<f64>>,
        vertices: Vec<Vector2<f64>>,
        field: &str,
    ) -> Result<Self> {
        let circle = Circle::new(centre, axis, 0.0, field)?;
        let a = circle.axis;
        let e1 = match reference {
            Some(r) => {
                let rp = r - a * a.dot(&r);
                if !(rp.norm() > 1e-12 * r.norm().max(1e-300)) || rp.iter().any(|v| !v.is_finite())
                {
                    return Err(Error::invalid(
                        format!("{field}.reference"),
                        "must be a finite vector not parallel to the axis",
                    ));
                }
                rp.normalize()
            }
            None => circle.e1,
        };
        if vertices.len() < 3 {
            return Err(Error::invalid(
                format!("{field}.vertices"),
                format!(
                    "a polygonal hole needs at least 3 vertices (got {})",
                    vertices.len()
                ),
            ));
        }
        if let Some(k) = vertices
            .iter()
            .position(|v| !v.iter().all(|x| x.is_finite()))
        {
            return Err(Error::invalid(
                format!("{field}.vertices[{k}]"),
                "must be finite numbers, in m",
            ));
        }
        let n = vertices.len();
        if let Some(k) = (0..n).find(|&k| (vertices[(k + 1) % n] - vertices[k]).norm() == 0.0) {
            return Err(Error::invalid(
                format!("{field}.vertices[{k}]"),
                "repeats the next vertex: every edge must have a length",
            ));
        }
        let polygon = Self {
            centre,
            axis: a,
            e1,
            e2: a.cross(&e1),
            vertices,
            scar: None,
        };
        if !polygon.contains(&Vector2::zeros()) {
            return Err(Error::invalid(
                format!("{field}.vertices"),
                "the hole's centre (where the tube axis is at rest) must be inside the polygon",
            ));
        }
        Ok(polygon)
    }

    /// Vertices of a hole given as `(angle, radius)` pairs: angle from `e1` towards `e2`, rad.
    pub fn polar(pairs: &[(f64, f64)]) -> Vec<Vector2<f64>> {
        pairs
            .iter()
            .map(|&(angle, radius)| Vector2::new(radius * angle.cos(), radius * angle.sin()))
            .collect()
    }

    /// Crossing-number test: is the in-plane point `r` inside the polygon?
    fn contains(&self, r: &Vector2<f64>) -> bool {
        let v = &self.vertices;
        let mut inside = false;
        let mut j = v.len() - 1;
        for i in 0..v.len() {
            let (a, b) = (v[i], v[j]);
            if (a.y > r.y) != (b.y > r.y) && r.x < (b.x - a.x) * (r.y - a.y) / (b.y - a.y) + a.x {
                inside = !inside;
            }
            j = i;
        }
        inside
    }

    #[inline]
    fn frame(&self, x: &Vector3<f64>) -> ContactFrame {
        let d = x - self.centre;
        let r = Vector2::new(d.dot(&self.e1), d.dot(&self.e2));
        // nearest point of the boundary
        let v = &self.vertices;
        let (mut best, mut nearest) = (f64::INFINITY, v[0]);
        let mut j = v.len() - 1;
        for i in 0..v.len() {
            let (a, b) = (v[j], v[i]);
            let ab = b - a;
            let s = ((r - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            let p = a + ab * s;
            let dist = (r - p).norm_squared();
            if dist < best {
                best = dist;
                nearest = p;
            }
            j = i;
        }
        let dist = best.sqrt();
        let inside = self.contains(&r);
        let to_boundary = nearest - r;
        let n2 = if dist > 0.0 {
            (if inside { -to_boundary } else { to_boundary }) / dist
        } else {
            // on the boundary: back towards the centre
            -r / r.norm().max(1e-300)
        };
        let normal = self.e1 * n2.x + self.e2 * n2.y;
        // a worn hole: the boundary recedes by d(θ) along its normal
        let scar = self.scar.as_ref().map_or(0.0, |s| s.at(r.y.atan2(r.x)).0);
        ContactFrame {
            penetration: (if inside { -dist } else { dist }) - scar,
            normal,
            tangents: [normal.cross(&self.axis), self.axis],
            velocity: Vector3::zeros(),
        }
    }
}

/// A rod the point must stay outside of — with a two-body contact ([`crate::contact::Pair`]),
/// **tube against tube side by side** (THEORY §15): the axis of tube B through `c` (in
/// relative coordinates, B's point: `c = 0`), along `a`, and the distance `ρ_c = R_A + R_B`
/// between the two axes at contact. With `r` the offset of the point (A's axis) from B's
/// axis normal to `a`: `δ = ρ_c − |r|`, `n = r/|r|` (from B to A), tangents `[a × n, a]`
/// (circumferential, axial). Valid for parallel axes; crossing tubes touch along their
/// common normal, a plane.
#[derive(Debug, Clone, PartialEq)]
pub struct Cylinder {
    centre: Vector3<f64>,
    axis: Vector3<f64>,
    radius: f64,
    /// An in-plane unit vector, for the frame of a point exactly on the axis.
    e1: Vector3<f64>,
}

impl Cylinder {
    /// Builds a rod of radius `radius` (for two tubes: the sum of their outer radii) around
    /// the line through `centre` along `axis`; `field` names it in error messages.
    pub fn new(centre: Vector3<f64>, axis: Vector3<f64>, radius: f64, field: &str) -> Result<Self> {
        let line = Circle::new(centre, axis, 0.0, field)?;
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::invalid(
                format!("{field}.radius"),
                format!(
                    "must be the distance between the axes at contact (the sum of the two tubes' outer radii) > 0, in m (got {radius})"
                ),
            ));
        }
        Ok(Self {
            centre,
            axis: line.axis,
            radius,
            e1: line.e1,
        })
    }

    #[inline]
    fn frame(&self, x: &Vector3<f64>) -> ContactFrame {
        let (rho, radial) = radial_offset(&self.centre, &self.axis, &self.e1, x);
        ContactFrame {
            penetration: self.radius - rho,
            normal: radial,
            tangents: [self.axis.cross(&radial), self.axis],
            velocity: Vector3::zeros(),
        }
    }

    /// The distance between the axes at contact, m.
    pub fn radius(&self) -> f64 {
        self.radius
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
    /// Point–polygon contact: a tube in a broached hole.
    Polygon(Polygon),
    /// Point outside a rod: a tube against a parallel tube (THEORY §15).
    Cylinder(Cylinder),
}

impl Obstacle {
    /// Frame at physical position `x` (THEORY §3).
    #[inline]
    pub fn frame(&self, x: &Vector3<f64>) -> ContactFrame {
        match self {
            Obstacle::Plane(p) => p.frame(x),
            Obstacle::Circle(c) => c.frame(x),
            Obstacle::BiPlane(b) => b.frame(x),
            Obstacle::Polygon(p) => p.frame(x),
            Obstacle::Cylinder(c) => c.frame(x),
        }
    }

    /// Where the point is relative to the obstacle, for the displacement statistics and the
    /// orbit plots (THEORY §5): for a hole, the in-plane offset `(r·e1, r·e2)` of the point
    /// from the hole's centre; for a plane or bars, `((x − x0)·n, (x − x0)·t1)`, the distance
    /// from the plane through `x0` (the bars' mid-plane) and the position along `t1`.
    pub fn local(&self, x: &Vector3<f64>) -> Vector2<f64> {
        match self {
            Obstacle::Plane(p) => {
                let d = x - p.origin;
                Vector2::new(d.dot(&p.normal), d.dot(&p.tangents[0]))
            }
            Obstacle::BiPlane(b) => {
                let d = x - b.origin;
                Vector2::new(d.dot(&b.normal), d.dot(&b.tangents[0]))
            }
            Obstacle::Circle(c) => {
                let d = x - c.centre;
                let e2 = c.axis.cross(&c.e1);
                Vector2::new(d.dot(&c.e1), d.dot(&e2))
            }
            Obstacle::Polygon(p) => {
                let d = x - p.centre;
                Vector2::new(d.dot(&p.e1), d.dot(&p.e2))
            }
            Obstacle::Cylinder(c) => {
                let d = x - c.centre;
                let e2 = c.axis.cross(&c.e1);
                Vector2::new(d.dot(&c.e1), d.dot(&e2))
            }
        }
    }

    /// The unworn obstacle with a wear scar (THEORY §14.4; module [`crate::contact::scar`]):
    /// a plane recedes by a [`ObstacleWear::Uniform`] depth, bars by their
    /// [`ObstacleWear::Sides`] depths, a hole takes an [`ObstacleWear::Angular`] profile. Another
    /// pairing, or a depth that is not finite and ≥ 0, is an error naming `field`.
    pub fn worn(&self, wear: &ObstacleWear, field: &str) -> Result<Obstacle> {
        let bad = |what: &str| {
            Error::invalid(
                field.to_string(),
                format!("a {} obstacle cannot take {what}", self.kind()),
            )
        };
        let depth_ok = |d: f64| d.is_finite() && d >= 0.0;
        match (self, wear) {
            (Obstacle::Plane(p), ObstacleWear::Uniform(d)) if depth_ok(*d) => {
                let mut worn = p.clone();
                worn.gap += d;
                Ok(Obstacle::Plane(worn))
            }
            (Obstacle::BiPlane(b), ObstacleWear::Sides { positive, negative })
                if depth_ok(*positive) && depth_ok(*negative) =>
            {
                let mut worn = b.clone();
                worn.origin += b.normal * (0.5 * (positive - negative));
                worn.gap += 0.5 * (positive + negative);
                Ok(Obstacle::BiPlane(worn))
            }
            (Obstacle::Circle(c), ObstacleWear::Angular(profile)) => {
                let mut worn = c.clone();
                worn.scar = Some(Box::new(profile.clone()));
                Ok(Obstacle::Circle(worn))
            }
            (Obstacle::Polygon(p), ObstacleWear::Angular(profile)) => {
                let mut worn = p.clone();
                worn.scar = Some(Box::new(profile.clone()));
                Ok(Obstacle::Polygon(worn))
            }
            (Obstacle::Cylinder(c), ObstacleWear::Uniform(d)) if depth_ok(*d) && *d < c.radius => {
                let mut worn = c.clone();
                worn.radius -= d;
                Ok(Obstacle::Cylinder(worn))
            }
            (_, ObstacleWear::Uniform(_)) => Err(bad("a uniform depth ≥ 0")),
            (_, ObstacleWear::Sides { .. }) => Err(bad("two side depths ≥ 0")),
            (_, ObstacleWear::Angular(_)) => Err(bad("a depth profile around a hole")),
        }
    }

    /// Name of the obstacle's type, as in case files.
    pub fn kind(&self) -> &'static str {
        match self {
            Obstacle::Plane(_) => "plane",
            Obstacle::Circle(_) => "circle",
            Obstacle::BiPlane(_) => "bi_plane",
            Obstacle::Polygon(_) => "polygon",
            Obstacle::Cylinder(_) => "cylinder",
        }
    }

    /// The boundary of a hole, or of a rod, in its [`local`](Self::local) axes (closed: the
    /// last point is the first), for orbit plots; `None` for planes and bars.
    pub fn outline(&self) -> Option<Vec<[f64; 2]>> {
        match self {
            Obstacle::Circle(c) => Some(
                (0..=180)
                    .map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / 180.0;
                        let r = c.clearance + c.scar.as_ref().map_or(0.0, |s| s.at(a).0);
                        [r * a.cos(), r * a.sin()]
                    })
                    .collect(),
            ),
            Obstacle::Polygon(p) => Some(
                p.vertices
                    .iter()
                    .chain(p.vertices.first())
                    .map(|v| [v.x, v.y])
                    .collect(),
            ),
            Obstacle::Cylinder(c) => Some(
                (0..=180)
                    .map(|k| {
                        let a = std::f64::consts::TAU * k as f64 / 180.0;
                        [c.radius * a.cos(), c.radius * a.sin()]
                    })
                    .collect(),
            ),
            Obstacle::Plane(_) | Obstacle::BiPlane(_) => None,
        }
    }

    /// True for holes (circle, polygon) and rods (cylinder): their [`local`](Self::local)
    /// position is an in-plane offset whose radius and angle are meaningful.
    pub fn is_hole(&self) -> bool {
        matches!(
            self,
            Obstacle::Circle(_) | Obstacle::Polygon(_) | Obstacle::Cylinder(_)
        )
    }

    /// For planes and bars, whose normal never turns: `(n, x0, gap, two-sided)`, with which
    /// the penetration follows from the signed distance `s = (x − x0)·n` alone
    /// ([`crate::contact::frame_rows::FrameRows`]).
    pub fn fixed_normal(&self) -> Option<(Vector3<f64>, Vector3<f64>, f64, bool)> {
        match self {
            Obstacle::Plane(p) => Some((p.normal, p.origin, p.gap, false)),
            Obstacle::BiPlane(b) => Some((b.normal, b.origin, b.gap, true)),
            Obstacle::Circle(_) | Obstacle::Polygon(_) | Obstacle::Cylinder(_) => None,
        }
    }

    /// The tangent basis, when it does not depend on the position or time (fixed planes and
    /// bars): the Delassus rows of such a contact are computed once.
    pub fn fixed_tangents(&self) -> Option<[Vector3<f64>; 2]> {
        match self {
            Obstacle::Plane(p) => Some(p.tangents),
            Obstacle::BiPlane(b) => Some(b.tangents),
            Obstacle::Circle(_) | Obstacle::Polygon(_) | Obstacle::Cylinder(_) => None,
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
            Obstacle::Polygon(p) => (vec![p.e1, p.e2], vec![p.e1, p.e2, p.axis]),
            Obstacle::Cylinder(c) => {
                let e2 = c.axis.cross(&c.e1);
                (vec![c.e1, e2], vec![c.e1, e2, c.axis])
            }
        }
    }
}
