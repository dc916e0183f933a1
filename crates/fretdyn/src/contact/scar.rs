//! Worn obstacles: the clearance a wear scar adds to an obstacle (THEORY §14.4).
//!
//! A scar deepens the material of the tube and of the support where they rub; seen from the
//! point (the tube axis), the surface it can reach recedes along the contact normal by the sum
//! of the two depths. fretdyn applies it as
//!
//! - a plane: the plane recedes, `gap → gap + d`;
//! - flat bars on both sides: each side by its own depth `d₊`, `d₋`: the mid-plane moves by
//!   `(d₊ − d₋)/2` along `n` and the gap grows by `(d₊ + d₋)/2`;
//! - a hole (drilled or broached): a depth profile `d(θ)` around the hole, `θ` the in-plane
//!   angle in the hole's axes `(e1, e2)`, piecewise linear over equal bins (periodic). With
//!   `ρ`, `θ` the point's in-plane polar position and `g(θ)` the unworn boundary's distance,
//!   the worn boundary is `φ(r) = ρ − g(θ) − d(θ) = 0`; the penetration is the first-order
//!   signed distance `δ = φ/|∇φ|`, the normal `n = −∇φ/|∇φ|` with
//!   `∇φ = e_ρ − (d'(θ)/ρ) e_θ` (for a broached hole the polygon's own normal is kept and only
//!   `δ` is shifted by `−d(θ)`).
//!
//! The profile's bins hold the depth of the material removed in their direction; how the
//! depths come from the wear volumes is in [`crate::apps::life`].

use std::f64::consts::TAU;

/// Depth profile of a scar around a hole: `depths[k]` at the angle `θ_k = (k + ½) 2π/N` in the
/// hole's in-plane axes, linear in between (periodic), m.
#[derive(Debug, Clone, PartialEq)]
pub struct AngularProfile {
    depths: Vec<f64>,
    /// Least depth (an open contact whose radius is below `g + min` needs no angle).
    min: f64,
}

impl AngularProfile {
    /// A profile from its bin depths (`N ≥ 1`, every depth finite and ≥ 0; else `None`).
    pub fn new(depths: Vec<f64>) -> Option<Self> {
        if depths.is_empty() || !depths.iter().all(|d| d.is_finite() && *d >= 0.0) {
            return None;
        }
        let min = depths.iter().copied().fold(f64::INFINITY, f64::min);
        Some(Self { depths, min })
    }

    /// The bins' depths.
    pub fn depths(&self) -> &[f64] {
        &self.depths
    }

    /// Least depth of the profile.
    pub fn min(&self) -> f64 {
        self.min
    }

    /// Bin of the in-plane direction `(c, s) = (cos θ, sin θ)` (any length), for the wear
    /// map: `⌊θ N / 2π⌋` with `θ ∈ [0, 2π)`.
    #[inline]
    pub fn bin_of(direction: [f64; 2], bins: usize) -> usize {
        let theta = direction[1].atan2(direction[0]).rem_euclid(TAU);
        ((theta / TAU * bins as f64) as usize).min(bins - 1)
    }

    /// Depth `d(θ)` and slope `d'(θ)` at the angle `θ` (rad).
    #[inline]
    pub fn at(&self, theta: f64) -> (f64, f64) {
        let n = self.depths.len();
        if n == 1 {
            return (self.depths[0], 0.0);
        }
        let h = TAU / n as f64;
        // position in bin centres: u = θ/h − ½
        let u = (theta.rem_euclid(TAU) / h - 0.5).rem_euclid(n as f64);
        let k = (u as usize).min(n - 1);
        let s = u - k as f64;
        let (a, b) = (self.depths[k], self.depths[(k + 1) % n]);
        (a + (b - a) * s, (b - a) / h)
    }
}

/// The wear an obstacle carries (see the module's documentation).
#[derive(Debug, Clone, PartialEq)]
pub enum ObstacleWear {
    /// A plane: the depth it recedes by, m.
    Uniform(f64),
    /// Flat bars: the depths on the `+n` and the `−n` side, m.
    Sides {
        /// Depth of the bar on the `+n` side (reached with `s > 0`).
        positive: f64,
        /// Depth of the bar on the `−n` side.
        negative: f64,
    },
    /// A hole: its depth profile.
    Angular(AngularProfile),
}
