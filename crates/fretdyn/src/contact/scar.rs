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
//!   angle in the hole's axes `(e1, e2)`, a monotone cubic through equal bins (periodic). With
//!   `ρ`, `θ` the point's in-plane polar position and `g(θ)` the unworn boundary's distance,
//!   the worn boundary is `ρ = g(θ) + d(θ)`; the penetration is the signed distance to it,
//!   `δ = ±|r − b|` with `b` its nearest point (Newton's method on `(b − r)·b'(θ) = 0` from the
//!   point's own angle), the normal `n = (b − r)/|b − r|` outside: the normal force derives
//!   from `½ K_N δ²` and the energy balance holds (for a broached hole the polygon's own
//!   normal is kept and only `δ` is shifted by `−d(θ)`).
//!
//! The profile's bins hold the depth of the material removed in their direction; how the
//! depths come from the wear volumes is in [`crate::apps::life`].

use std::f64::consts::TAU;

/// Depth profile of a scar around a hole: `depths[k]` at the angle `θ_k = (k + ½) 2π/N` in the
/// hole's in-plane axes, m; in between a monotone cubic (Fritsch–Butland slopes, periodic): the
/// profile and its slope are continuous — the normal of the worn boundary turns continuously —
/// and it does not overshoot its bins (a depth stays ≥ 0).
#[derive(Debug, Clone, PartialEq)]
pub struct AngularProfile {
    depths: Vec<f64>,
    /// Slope at each bin centre, per bin (`dd/du`, `u = θ/h`).
    slopes: Vec<f64>,
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
        let n = depths.len();
        let slopes = (0..n)
            .map(|k| {
                let before = depths[k] - depths[(k + n - 1) % n];
                let after = depths[(k + 1) % n] - depths[k];
                if before * after > 0.0 {
                    2.0 * before * after / (before + after)
                } else {
                    0.0
                }
            })
            .collect();
        Some(Self {
            depths,
            slopes,
            min,
        })
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
        let (d, d1, _) = self.at2(theta);
        (d, d1)
    }

    /// Depth `d(θ)` and its first two derivatives at the angle `θ` (rad).
    #[inline]
    pub fn at2(&self, theta: f64) -> (f64, f64, f64) {
        let n = self.depths.len();
        if n == 1 {
            return (self.depths[0], 0.0, 0.0);
        }
        let h = TAU / n as f64;
        // position in bin centres: u = θ/h − ½
        let u = (theta.rem_euclid(TAU) / h - 0.5).rem_euclid(n as f64);
        let k = (u as usize).min(n - 1);
        let s = u - k as f64;
        let (a, b) = (self.depths[k], self.depths[(k + 1) % n]);
        let (ma, mb) = (self.slopes[k], self.slopes[(k + 1) % n]);
        // cubic Hermite on [0, 1]
        let (s2, s3) = (s * s, s * s * s);
        let value = (2.0 * s3 - 3.0 * s2 + 1.0) * a
            + (s3 - 2.0 * s2 + s) * ma
            + (-2.0 * s3 + 3.0 * s2) * b
            + (s3 - s2) * mb;
        let slope = (6.0 * s2 - 6.0 * s) * a
            + (3.0 * s2 - 4.0 * s + 1.0) * ma
            + (-6.0 * s2 + 6.0 * s) * b
            + (3.0 * s2 - 2.0 * s) * mb;
        let curvature = (12.0 * s - 6.0) * a
            + (6.0 * s - 4.0) * ma
            + (-12.0 * s + 6.0) * b
            + (6.0 * s - 2.0) * mb;
        (value, slope / h, curvature / (h * h))
    }

    /// The point of the worn boundary `b(θ) = (c + d(θ)) e(θ)` nearest to the in-plane point
    /// `r` (polar angle `theta`), for a hole of clearance `c`: `(b, b'(θ))`. The boundary is
    /// sampled over the angles within reach (`|r − b(θ)|` no more than the radial distance
    /// at `theta`), and the best sample refined by Newton's method on `(b − r)·b' = 0`;
    /// `None` when Newton's method does not converge.
    #[inline]
    pub fn nearest(&self, c: f64, r: [f64; 2], theta: f64) -> Option<([f64; 2], [f64; 2])> {
        let rho = r[0].hypot(r[1]);
        let reach = (rho - c - self.at(theta).0).abs();
        // the boundary is beyond c from the centre: the angles within reach of r
        let half = if rho > reach {
            ((reach / rho).min(1.0).asin() * 1.5).max(1e-9)
        } else {
            std::f64::consts::PI
        };
        let distance = |th: f64| {
            let (sn, cs) = th.sin_cos();
            let rad = c + self.at(th).0;
            (rad * cs - r[0]).hypot(rad * sn - r[1])
        };
        const SAMPLES: usize = 24;
        let mut th = theta;
        let mut best = distance(theta);
        for j in 0..=SAMPLES {
            let a = theta - half + 2.0 * half * j as f64 / SAMPLES as f64;
            let d = distance(a);
            if d < best {
                (best, th) = (d, a);
            }
        }
        for _ in 0..20 {
            let (d, d1, d2) = self.at2(th);
            let (sn, cs) = th.sin_cos();
            let rad = c + d;
            // b, b' = d' e_r + (c + d) e_θ, b'' = (d'' − c − d) e_r + 2 d' e_θ
            let b = [rad * cs, rad * sn];
            let b1 = [d1 * cs - rad * sn, d1 * sn + rad * cs];
            let b2 = [
                (d2 - rad) * cs - 2.0 * d1 * sn,
                (d2 - rad) * sn + 2.0 * d1 * cs,
            ];
            let e = [b[0] - r[0], b[1] - r[1]];
            let f = e[0] * b1[0] + e[1] * b1[1];
            let df = b1[0] * b1[0] + b1[1] * b1[1] + e[0] * b2[0] + e[1] * b2[1];
            if !(df > 0.0) {
                return None;
            }
            let step = f / df;
            th -= step;
            if step.abs() < 1e-13 {
                let (d, d1, _) = self.at2(th);
                let (sn, cs) = th.sin_cos();
                let rad = c + d;
                return Some((
                    [rad * cs, rad * sn],
                    [d1 * cs - rad * sn, d1 * sn + rad * cs],
                ));
            }
        }
        None
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
