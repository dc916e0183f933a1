//! `obstacle = { type = … }` of a `[[contacts]]` entry: a plane, a bi-plane (two parallel
//! planes), a circular hole, a polygonal hole or a rod (cylinder), as the case file gives it (THEORY §3).

use serde::Deserialize;

/// The obstacle of a contact as written (built into a [`crate::contact::obstacle::Obstacle`] by
/// the contacts' section; a scar's shape is checked against its type).
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub(super) enum ObstacleInput {
    Plane {
        #[serde(default)]
        origin: [f64; 3],
        normal: [f64; 3],
        #[serde(default)]
        gap: f64,
        tangent: Option<[f64; 3]>,
    },
    Circle {
        centre: [f64; 3],
        axis: [f64; 3],
        clearance: f64,
    },
    BiPlane {
        #[serde(default)]
        origin: [f64; 3],
        normal: [f64; 3],
        gap: f64,
        tangent: Option<[f64; 3]>,
    },
    Polygon {
        centre: [f64; 3],
        axis: [f64; 3],
        reference: Option<[f64; 3]>,
        /// In-plane vertices `[x1, x2]` along (reference, axis × reference), m.
        vertices: Option<Vec<[f64; 2]>>,
        /// Vertices as `[angle_deg, radius]` pairs.
        polar: Option<Vec<[f64; 2]>>,
    },
    /// A rod the point stays outside of (tube against tube side by side, THEORY §15).
    Cylinder {
        #[serde(default)]
        centre: [f64; 3],
        axis: [f64; 3],
        /// Distance between the axes at contact, m (for two tubes: the sum of their outer
        /// radii, the default of a two-body contact).
        radius: Option<f64>,
    },
}
