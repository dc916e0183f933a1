//! A flat bar of finite width crossing a tube, its face possibly twisted (THEORY §16.2): the
//! contact is a segment along the tube's axis, discretised by `N` point
//! contacts across the width.
//!
//! **Geometry.** The tube's axis at the contact is `t`, the bar's (untwisted) outward normal
//! `n ⊥ t`, the bar's length direction `b = t × n`. The bar's face has the width `w` along
//! `t`. A **twist** `α` turns the face about `b` (through the foot of the point on the
//! obstacle's reference plane): its normal becomes `n' = n cos α − t sin α` and its
//! direction across the width `t' = t cos α + n sin α`, so that `α > 0` brings the face's
//! edge on the `+t` side nearer to the tube. The edges are at `±(w/2) t'`: the tube meets
//! them at the axial offsets `±(w/2) cos α`. A **tilt** about the tube's axis does nothing to a
//! cylinder on a plane (the line of contact rolls round the tube): it is not a parameter.
//!
//! **Points.** Contact `j` of `N` is at the axial offset
//! `s_j = (w/2) cos α (2j/(N − 1) − 1)` (`s = 0` for `N = 1`): the two edges and evenly
//! spaced points between them, so that an edge contact is exactly the edge point. Its rows are
//! those of the section translated rigidly by `s_j t`: `Φ_j = Φ_c + Θ_c × (s_j t)` (the
//! section is rigid over the width: the beam's deflection over `w/2` differs from `u + θ s` by
//! `κ s²/2`, second order in `w` against the bending wavelength). Each point carries the
//! share `ω_j` of the user's stiffness and damping: the **trapezoidal rule** over the width
//! (`ω = 1/(2(N − 1))` at the edges, `1/(N − 1)` inside, `Σ ω_j = 1`), a uniform (Winkler)
//! contact stiffness per unit length integrated with nodes at the edges. The friction
//! coefficients are the bar's.
//!
//! Why points rather than an equivalent force-and-moment law: the Lagrange methods, the
//! Delassus operator, the statistics and the wear work on point contacts unchanged, and an
//! edge contact is just the edge point closing alone.

use nalgebra::Vector3;

use crate::error::{Error, Result, number};
use crate::structure::modal::{Point, thirds};

/// The most points across a bar's width (each is a contact of its own).
pub const MAX_POINTS: usize = 101;

/// A flat bar of width `w` crossing a tube, twisted by `α`, with `N` contact points across
/// its width (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatBar {
    /// `w`, m: the face's width across the bar (along the tube when untwisted).
    pub width: f64,
    /// `N`, the contact points across the width.
    pub points: usize,
    /// `α`, rad, the face turned about the bar's length direction `b = t × n`.
    pub twist: f64,
}

/// Where one of a bar's points is across its width: what a contact of a bar is.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Across {
    /// `j`, its index across the width, from the `−t` edge.
    pub index: usize,
    /// `s_j`, its axial offset from the section's centre along the tube's axis `t`, m.
    pub offset: f64,
    /// `ω_j`, its share of the bar's contact stiffness and damping (and of its width, for the
    /// scar).
    pub weight: f64,
    /// The bar's width `w`, m.
    pub width: f64,
}

impl FlatBar {
    /// Checks the values; `field` names the contact (`contacts[k]`) in errors.
    pub fn new(width: f64, points: usize, twist: f64, field: &str) -> Result<Self> {
        if !(width.is_finite() && width > 0.0) {
            return Err(Error::invalid(
                format!("{field}.width"),
                format!("must be the bar's width > 0 in m (got {})", number(width)),
            ));
        }
        if !(1..=MAX_POINTS).contains(&points) {
            return Err(Error::invalid(
                format!("{field}.points_across"),
                format!(
                    "must be between 1 and {MAX_POINTS} contact points across the bar's width (got {points}; 3 by default: the two edges and the middle)"
                ),
            ));
        }
        if !(twist.is_finite() && twist.abs() < std::f64::consts::FRAC_PI_4) {
            return Err(Error::invalid(
                format!("{field}.twist_deg"),
                format!(
                    "must be the bar's twist about its length, in degrees between −45 and 45 (got {})",
                    number(twist.to_degrees())
                ),
            ));
        }
        Ok(Self {
            width,
            points,
            twist,
        })
    }

    /// The points across the width, from the `−t` edge (module doc: `s_j`, `ω_j`).
    pub fn across(&self) -> Vec<Across> {
        let n = self.points;
        let half = 0.5 * self.width * self.twist.cos();
        (0..n)
            .map(|j| {
                let (offset, weight) = if n == 1 {
                    (0.0, 1.0)
                } else {
                    let h = 1.0 / (n - 1) as f64;
                    let end = j == 0 || j == n - 1;
                    (
                        half * (2.0 * j as f64 * h - 1.0),
                        if end { 0.5 * h } else { h },
                    )
                };
                Across {
                    index: j,
                    offset,
                    weight,
                    width: self.width,
                }
            })
            .collect()
    }

    /// `v` turned by the twist about `b = t × n` (Rodrigues), `t`, `n` orthonormal: `n → n'`,
    /// `t → t'` (module doc).
    pub fn turn(&self, v: &Vector3<f64>, t: &Vector3<f64>, n: &Vector3<f64>) -> Vector3<f64> {
        let b = t.cross(n);
        let (s, c) = self.twist.sin_cos();
        v * c + b.cross(v) * s + b * (b.dot(v) * (1.0 - c))
    }
}

/// The point `point` translated rigidly with its section by `r`: coordinates `x + r`,
/// translation rows `Φ + Θ × r`, the same rotation rows (THEORY §7); named `name`.
/// `point` must have its rotation rows.
pub fn offset_point(point: &Point, r: &Vector3<f64>, name: String) -> Point {
    let p = point.rows.len() / 3;
    let [ux, uy, uz] = thirds(&point.rows, p);
    let [tx, ty, tz] = thirds(&point.rotations, p);
    let mut rows = Vec::with_capacity(3 * p);
    // θ × r = (θy rz − θz ry, θz rx − θx rz, θx ry − θy rx)
    rows.extend((0..p).map(|i| ux[i] + ty[i] * r.z - tz[i] * r.y));
    rows.extend((0..p).map(|i| uy[i] + tz[i] * r.x - tx[i] * r.z));
    rows.extend((0..p).map(|i| uz[i] + tx[i] * r.y - ty[i] * r.x));
    Point {
        name,
        coords: point.coords + r,
        rows,
        rotations: point.rotations.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The trapezoidal weights sum to 1 and integrate `s²` over the width as the rule does;
    /// the edges are at `±(w/2) cos α`; the twisted normal is `n cos α − t sin α`.
    #[test]
    fn points_weights_and_the_turned_face() {
        let bar = FlatBar::new(0.02, 5, 0.1, "c").unwrap();
        let a = bar.across();
        let sum: f64 = a.iter().map(|p| p.weight).sum();
        assert!((sum - 1.0).abs() < 1e-15);
        let half = 0.01 * 0.1f64.cos();
        assert!((a[0].offset + half).abs() < 1e-15 && (a[4].offset - half).abs() < 1e-15);
        assert_eq!(a[2].offset, 0.0);
        let (t, n) = (Vector3::x(), Vector3::z());
        let np = bar.turn(&n, &t, &n);
        assert!((np - (n * 0.1f64.cos() - t * 0.1f64.sin())).norm() < 1e-15);
        let tp = bar.turn(&t, &t, &n);
        assert!((tp - (t * 0.1f64.cos() + n * 0.1f64.sin())).norm() < 1e-15);
        assert_eq!(
            FlatBar::new(0.02, 1, 0.0, "c").unwrap().across()[0].offset,
            0.0
        );
        let e = FlatBar::new(0.02, 0, 0.0, "c").unwrap_err();
        assert_eq!(e.field(), Some("c.points_across"));
        let e = FlatBar::new(-1.0, 3, 0.0, "c").unwrap_err();
        assert_eq!(e.field(), Some("c.width"));
    }

    /// A rigid rotation `θ` of the section moves the offset point by `θ × r`.
    #[test]
    fn an_offset_point_moves_with_its_section() {
        // two modes: a translation along z, a rotation about y
        let point = Point {
            name: "a".into(),
            coords: Vector3::new(1.0, 0.0, 0.0),
            rows: vec![0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            rotations: vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        };
        let r = Vector3::new(0.5, 0.0, 0.0);
        let o = offset_point(&point, &r, "a[0]".into());
        // mode 2 (θy = 1): θ × r = (0, 0, −0.5)
        assert_eq!(o.rows, vec![0.0, 0.0, 0.0, 0.0, 1.0, -0.5]);
        assert_eq!(o.coords, Vector3::new(1.5, 0.0, 0.0));
    }
}
