//! Where a line along a tube meets its modes: the quadrature stations of distributed flow
//! forces ([`Station`], THEORY §9) and the mesh cells that a line load covers ([`LineCell`],
//! THEORY §10). Built by [`super::tube`], read by [`crate::loads`].

use nalgebra::Vector3;

/// One element of a beam mesh, or the part of it that a line load covers: the load on
/// `loaded = [s0, s1]` goes to the end nodes through the linear shape functions of the element
/// `ends = [s_a, s_b]`, `N_a(s) = (s_b − s)/(s_b − s_a)`, `N_b(s) = (s − s_a)/(s_b − s_a)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineCell {
    /// Rows of the end nodes `a`, `b` in the covariance matrix.
    pub nodes: [usize; 2],
    /// Abscissae `s_a < s_b` of the end nodes along the tube, m.
    pub ends: [f64; 2],
    /// The loaded part `[s0, s1]`, `s_a ≤ s0 < s1 ≤ s_b`, m.
    pub loaded: [f64; 2],
}

/// A quadrature point along the tube.
#[derive(Debug, Clone, PartialEq)]
pub struct Station {
    /// Abscissa along the tube, m.
    pub s: f64,
    /// Quadrature weight, m (`Σ w = ` the length covered).
    pub weight: f64,
    /// Translation rows of the tube's axis there, row-major 3 × p (as [`crate::structure::modal::Point::rows`]).
    pub rows: Vec<f64>,
    /// Unit tangent of the tube's axis (zero when unknown: then the whole translation counts
    /// as transverse).
    pub tangent: Vector3<f64>,
}

impl Station {
    /// Translation of mode `i` at the station.
    pub fn translation(&self, i: usize) -> Vector3<f64> {
        let p = self.rows.len() / 3;
        Vector3::new(self.rows[i], self.rows[p + i], self.rows[2 * p + i])
    }

    /// `|u − (u·t) t|²` of mode `i`: the squared displacement normal to the axis.
    pub fn transverse_square(&self, i: usize) -> f64 {
        let u = self.translation(i);
        let t = self.tangent;
        (u - t * u.dot(&t)).norm_squared()
    }
}
