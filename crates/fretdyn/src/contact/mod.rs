//! **Stage 4 — the contacts.** What enters: a point of the modal basis, an obstacle (possibly
//! moving), the normal law and the friction coefficients. What leaves: per contact, the gap
//! and frame ([`obstacle`]), the normal penalty force ([`NormalLaw`], THEORY §3) and the
//! tangential force from a friction law ([`friction`]) or from the Lagrange problem on the
//! Delassus operator (`delassus`, crate-private) solved by the [`tangential`] methods (THEORY §4, §7, §8).
//!
//! - [`obstacle`]: planes, bi-planes, circles, polygons: gap, normal, tangent frame;
//! - [`preload`]: a plane pressed on the structure at rest (THEORY §16.1);
//! - [`scar`]: the clearance a wear scar adds to an obstacle (THEORY §14.4);
//! - [`flat_bar`]: a flat bar of finite width, possibly twisted: its points across the width;
//! - [`frame_rows`]: the frame of a plane or bars projected on the modes (detection in one
//!   dot product);
//! - [`motion`]: the imposed motion of an obstacle (THEORY §8);
//! - [`friction`]: Coulomb coefficients, the local stick/slip solve;
//! - `delassus` (crate-private): the tangential problem `W λ + b` on the closed contacts
//!   (THEORY §4.2);
//! - [`tangential`]: the settings of the penalty, Active Set and projected Gauss–Seidel
//!   methods (THEORY §4.1, §4.3, §4.4; the solvers themselves are crate-private).
//!
//! A contact itself ([`Contact`]: structure point, obstacle, normal law, Coulomb
//! coefficients) is defined here.

// The Delassus problem is crate-private: public only for the crate's tests (feature `testing`).
#[cfg(feature = "testing")]
pub mod delassus;
// (the builders and checks only the tests call are unused without it)
#[cfg(not(feature = "testing"))]
#[allow(dead_code)]
pub(crate) mod delassus;
pub mod flat_bar;
pub mod frame_rows;
pub mod friction;
pub mod motion;
pub mod obstacle;
pub mod preload;
pub mod scar;
pub mod tangential;

use crate::contact::friction::Coulomb;
use crate::error::{Error, Result};
use nalgebra::Vector3;

use crate::contact::motion::Motion;
use crate::contact::obstacle::{ContactFrame, Obstacle};
use crate::numerics::map3;
use crate::structure::modal::{Point, thirds};

/// Normal penalty law `R_N = max(0, K_N δ + C_N δ̇)` for `δ > 0`, `R_N = 0` otherwise (THEORY §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalLaw {
    /// Contact stiffness `K_N`, N/m (for a tube: the ovalisation stiffness).
    pub stiffness: f64,
    /// Contact damping `C_N`, N·s/m (0: elastic impact).
    pub damping: f64,
}

impl NormalLaw {
    /// Validated constructor; `field` prefixes error messages.
    pub fn new(stiffness: f64, damping: f64, field: &str) -> Result<Self> {
        if !(stiffness.is_finite() && stiffness > 0.0) {
            return Err(Error::invalid(
                format!("{field}.stiffness"),
                format!("must be a positive contact stiffness K_N in N/m (got {stiffness})"),
            ));
        }
        if !(damping.is_finite() && damping >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.damping"),
                format!("must be a contact damping C_N ≥ 0 in N·s/m (got {damping})"),
            ));
        }
        Ok(Self { stiffness, damping })
    }

    /// Normal force magnitude for penetration `δ` and penetration rate `δ̇`; 0 when open and
    /// never tensile.
    #[inline]
    pub fn force(&self, penetration: f64, penetration_rate: f64) -> f64 {
        if penetration > 0.0 {
            (self.stiffness * penetration + self.damping * penetration_rate).max(0.0)
        } else {
            0.0
        }
    }
}

/// The second body of a two-body contact (THEORY §15): point B of a structure (the same or
/// another one) that the contact's point A rattles against.
///
/// Everything the contact computes — penetration, frame, velocity, forces, Delassus rows —
/// is that of the **relative point** `x = x_A − x_B` (reference position `x0_A − x0_B`, rows
/// `Φ_A − Φ_B`), seen by the contact's obstacle expressed in relative coordinates: the
/// force `R` it finds acts on A, `−R` on B (`f_q = (Φ_A − Φ_B)ᵀ R`). On the surfaces of radii
/// `R_A`, `R_B` around the points (tube or bar surfaces), the contact points are
/// `x_A − R_A n` and `x_B + R_B n`, whose relative velocity is
/// `u̇_A − u̇_B + n × (R_A θ̇_A + R_B θ̇_B)`: the relative point's rotation rows are
/// `(R_A Θ_A + R_B Θ_B) / (R_A + R_B)` and the contact's radius is `R_A + R_B`, so that
/// [`Contact::surface_rows`] forms exactly these rows.
#[derive(Debug, Clone, PartialEq)]
pub struct Pair {
    /// Index of point B in the modal basis.
    pub other: usize,
    /// Surface radii `[R_A, R_B]` around points A and B, m (0: the contact is at the point).
    pub radii: [f64; 2],
    /// The relative point A − B.
    relative: Point,
}

impl Pair {
    /// The pair of points `a` (index in the contact) and `b` (index `other`), with the surface
    /// radii `radii`; `field` names the contact in error messages.
    pub fn new(a: &Point, other: usize, b: &Point, radii: [f64; 2], field: &str) -> Result<Self> {
        for (r, side) in radii.iter().zip(["A", "B"]) {
            if !(r.is_finite() && *r >= 0.0) {
                return Err(Error::invalid(
                    format!("{field}.radii"),
                    format!("the radius of side {side} must be ≥ 0 in m (got {r})"),
                ));
            }
        }
        if a.rows.len() != b.rows.len() {
            return Err(Error::invalid(
                format!("{field}.other"),
                format!(
                    "points '{}' and '{}' have rows of different lengths",
                    a.name, b.name
                ),
            ));
        }
        let total = radii[0] + radii[1];
        let mut rotations = Vec::new();
        if total > 0.0 {
            rotations = vec![0.0; a.rows.len()];
            for (r, point) in radii.iter().zip([a, b]) {
                if *r == 0.0 {
                    continue;
                }
                if point.rotations.len() != a.rows.len() {
                    return Err(Error::invalid(
                        format!("{field}.radii"),
                        format!(
                            "a contact on the surface around point '{}' needs its rotations: use a tube or beam structure, or set its radius to 0",
                            point.name
                        ),
                    ));
                }
                let w = r / total;
                for (o, t) in rotations.iter_mut().zip(&point.rotations) {
                    *o += w * t;
                }
            }
        }
        Ok(Self {
            other,
            radii,
            relative: Point {
                name: format!("{}-{}", a.name, b.name),
                coords: a.coords - b.coords,
                rows: a.rows.iter().zip(&b.rows).map(|(x, y)| x - y).collect(),
                rotations,
            },
        })
    }

    /// The relative point A − B.
    pub fn relative(&self) -> &Point {
        &self.relative
    }
}

/// One contact of the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// Name, used in outputs.
    pub name: String,
    /// Index of the structure point in the modal basis (point A of a two-body contact).
    pub point: usize,
    /// The second body of a two-body contact, `None` for a contact with an obstacle (the
    /// common case). Build with [`Contact::between`].
    pub pair: Option<Box<Pair>>,
    /// The obstacle.
    pub obstacle: Obstacle,
    /// Prescribed rigid motion of the obstacle ([`Motion::Fixed`] by default).
    pub motion: Motion,
    /// Outer radius `R` of the tube when the point is on its axis and the contact is on its
    /// surface (0: the contact is at the point). The obstacle's gap or clearance is then the
    /// clearance of the surface, the contact point is `x − R n`, and its velocity
    /// `u̇ + θ̇ × (−R n) = u̇ + R n × θ̇`: the tube's rotations (torsion for the
    /// circumferential slip in a hole, bending for the axial slip) enter the tangential
    /// velocity and the friction force exerts a moment `−R n × R_T` on the tube.
    pub radius: f64,
    /// Normal penalty law.
    pub normal: NormalLaw,
    /// Static and dynamic friction coefficients.
    pub friction: Coulomb,
    /// The preload of a plane pressed on the structure at rest (THEORY §16.1), `None` for
    /// none (the common case); applied by `apply_preloads` of the model layer.
    pub preload: Option<preload::Preload>,
    /// Where the contact is across a flat bar's width (one of its points,
    /// [`flat_bar`]), `None` for a contact that is not one of a bar's points.
    pub across: Option<flat_bar::Across>,
}

impl Contact {
    /// A contact at the point itself with a fixed obstacle.
    pub fn new(
        name: impl Into<String>,
        point: usize,
        obstacle: Obstacle,
        normal: NormalLaw,
        friction: Coulomb,
    ) -> Self {
        Self {
            name: name.into(),
            point,
            pair: None,
            obstacle,
            motion: Motion::Fixed,
            radius: 0.0,
            normal,
            friction,
            preload: None,
            across: None,
        }
    }

    /// A two-body contact between point `a` and point `b` of `points` (THEORY §15), with the
    /// surface radii `radii = [R_A, R_B]` around them; `obstacle` is in relative coordinates
    /// (the position `x_A − x_B`, reference `x0_A − x0_B`): a plane of normal `n` pointing
    /// from B to A for point against point along `n`, a cylinder for tubes side by side.
    #[allow(clippy::too_many_arguments)]
    pub fn between(
        name: impl Into<String>,
        a: usize,
        b: usize,
        points: &[Point],
        radii: [f64; 2],
        obstacle: Obstacle,
        normal: NormalLaw,
        friction: Coulomb,
    ) -> Result<Self> {
        let name = name.into();
        let field = format!("contact '{name}'");
        let (pa, pb) = match (points.get(a), points.get(b)) {
            (Some(pa), Some(pb)) => (pa, pb),
            _ => {
                return Err(Error::invalid(
                    format!("{field}.other"),
                    "refers to no point of the model",
                ));
            }
        };
        if a == b {
            return Err(Error::invalid(
                format!("{field}.other"),
                format!(
                    "is the contact's own point '{}': name another point",
                    pa.name
                ),
            ));
        }
        let pair = Pair::new(pa, b, pb, radii, &field)?;
        let mut contact = Self::new(name, a, obstacle, normal, friction);
        contact.radius = radii[0] + radii[1];
        contact.pair = Some(Box::new(pair));
        Ok(contact)
    }

    /// The point the contact sees: its structure point, or for a two-body contact the
    /// relative point A − B ([`Pair`]).
    #[inline(always)]
    pub fn point_in<'a>(&'a self, points: &'a [Point]) -> &'a Point {
        match &self.pair {
            None => &points[self.point],
            Some(pair) => &pair.relative,
        }
    }

    /// Index of point B of a two-body contact.
    pub fn other(&self) -> Option<usize> {
        self.pair.as_ref().map(|p| p.other)
    }

    /// Frame of the obstacle at time `t` for the point's physical position `x` (the tube axis
    /// when `radius > 0`): the obstacle translated by `d(t)`, its surface moving at `ḋ(t)`.
    #[inline]
    pub fn frame(&self, x: &Vector3<f64>, t: f64) -> ContactFrame {
        if self.motion.is_fixed() {
            return self.obstacle.frame(x);
        }
        let (d, v) = self.motion.at(t);
        let mut frame = self.obstacle.frame(&(x - d));
        frame.velocity = v;
        frame
    }

    /// Position of the point relative to the obstacle at time `t`
    /// ([`Obstacle::local`] of `x − d(t)`).
    #[inline]
    pub fn local(&self, x: &Vector3<f64>, t: f64) -> nalgebra::Vector2<f64> {
        if self.motion.is_fixed() {
            self.obstacle.local(x)
        } else {
            self.obstacle.local(&(x - self.motion.at(t).0))
        }
    }

    /// True when the contact is on the tube surface rather than at the point.
    #[inline]
    pub fn at_surface(&self) -> bool {
        self.radius > 0.0
    }

    /// Rows (3 × p) of the contact point on the surface for the normal `n`:
    /// `Φ_u + R [n]_× Θ`, from the point's translation rows `Φ_u` and rotation rows `Θ`.
    #[inline(always)]
    pub fn surface_rows(&self, point: &Point, n: &Vector3<f64>, out: &mut [f64]) {
        let p = out.len() / 3;
        let r = self.radius;
        // slices of equal length, indexed (`map3`): no bounds checks, vector operations
        let [ux, uy, uz] = thirds(&point.rows, p);
        let [tx, ty, tz] = thirds(&point.rotations, p);
        let (ox, rest) = out[..3 * p].split_at_mut(p);
        let (oy, oz) = rest.split_at_mut(p);
        map3(ox, ux, tz, ty, |u, a, b| u + r * (n.y * a - n.z * b));
        map3(oy, uy, tx, tz, |u, a, b| u + r * (n.z * a - n.x * b));
        map3(oz, uz, ty, tx, |u, a, b| u + r * (n.x * a - n.y * b));
    }

    /// The tangent basis when the contact's Delassus rows never change: a fixed tangent basis,
    /// and (on the surface) a fixed normal.
    pub fn fixed_tangents(&self) -> Option<[Vector3<f64>; 2]> {
        match (&self.obstacle, self.at_surface()) {
            (_, false) | (Obstacle::Plane(_), true) => self.obstacle.fixed_tangents(),
            _ => None,
        }
    }

    /// Checks the radius and the motion; `point` is the contact's point.
    pub fn validate(&self, point: &Point, field: &str) -> Result<()> {
        if !(self.radius.is_finite() && self.radius >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.radius"),
                format!(
                    "must be the tube's outer radius ≥ 0 in m (got {})",
                    self.radius
                ),
            ));
        }
        if self.at_surface() && point.rotations.is_empty() {
            return Err(Error::invalid(
                format!("{field}.radius"),
                format!(
                    "a contact on the tube surface needs the rotations of point '{}': use a tube structure, or give rotations (rows or 'rotations_<name>' in the .npz), or remove radius",
                    point.name
                ),
            ));
        }
        self.motion.validate(&format!("{field}.motion"))
    }
}
