//! One life step of a wearing contact (THEORY §14.4, §14.5): its volumes grown at the
//! window's wear work rate, spread over the bins of its wear map in the proportions of the
//! window's work, turned into the depths of its scar(s) and the clearance they add, and the
//! obstacle worn by them.

use serde::{Deserialize, Serialize};

use crate::contact::scar::{AngularProfile, ObstacleWear};
use crate::error::{Error, Result};
use crate::wear::{ContactWear, HoleScar, Scar};

/// Cumulative wear of one contact, per bin of its [`WearMap`].
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct Worn {
    /// Tube volume per bin, m³.
    pub(super) tube: Vec<f64>,
    /// Support volume per bin, m³.
    pub(super) support: Vec<f64>,
}

/// The depths of a contact's scar(s) from its volumes.
pub(super) struct Depths {
    /// Tube depth per bin (what faces each direction), m.
    pub(super) tube: Vec<f64>,
    /// Support depth per bin (body B's of a two-body contact), m.
    pub(super) support: Vec<f64>,
    /// Added clearance per bin, m.
    pub(super) added: Vec<f64>,
    /// Support depth where deepest, m.
    pub(super) support_max: f64,
}

impl Worn {
    pub(super) fn new(bins: usize) -> Self {
        Self {
            tube: vec![0.0; bins],
            support: vec![0.0; bins],
        }
    }

    /// Depths from the volumes (THEORY §14.4): a plane's or a side's scar from its own
    /// volumes; around a hole, the scar's depth from the whole volume, spread over the bins
    /// in proportion to each bin's volume (the deepest bin takes the full depth), or all
    /// around for a uniform scar.
    pub(super) fn depths(&self, wear: &ContactWear, field: &str) -> Result<Depths> {
        let n = self.tube.len();
        if n <= 2 {
            let mut d = Depths {
                tube: vec![0.0; n],
                support: vec![0.0; n],
                added: vec![0.0; n],
                support_max: 0.0,
            };
            for b in 0..n {
                let (vt, vs) = (self.tube[b], self.support[b]);
                let t = wear.scar.tube_depth(vt).map_err(|e| at(e, field))?;
                let s = wear.scar.support_depth(vs).map_err(|e| at(e, field))?;
                d.tube[b] = t;
                d.support[b] = s;
                d.added[b] = wear.scar.approach(vt, vs).map_err(|e| at(e, field))?;
                d.support_max = d.support_max.max(s);
            }
            return Ok(d);
        }
        let (vt, vs): (f64, f64) = (self.tube.iter().sum(), self.support.iter().sum());
        let t = wear.scar.tube_depth(vt).map_err(|e| at(e, field))?;
        let s = wear.scar.support_depth(vs).map_err(|e| at(e, field))?;
        let approach = wear.scar.approach(vt, vs).map_err(|e| at(e, field))?;
        let uniform = matches!(
            wear.scar,
            Scar::DrilledHole {
                shape: HoleScar::Uniform,
                ..
            }
        );
        let total: Vec<f64> = self
            .tube
            .iter()
            .zip(&self.support)
            .map(|(a, b)| a + b)
            .collect();
        let shape: Vec<f64> = match wear.scar {
            _ if uniform => vec![1.0; n],
            Scar::DrilledHole {
                tube_radius,
                clearance,
                ..
            } => spread(
                &crescent_footprint(tube_radius, clearance, approach, n),
                &total,
            ),
            _ => spread(&[1.0], &total),
        };
        Ok(Depths {
            tube: shape.iter().map(|f| f * t).collect(),
            support: shape.iter().map(|f| f * s).collect(),
            added: shape.iter().map(|f| f * approach).collect(),
            support_max: s,
        })
    }
}

/// The crescent a tube of radius `r` leaves when it is pushed `a` beyond a hole of clearance
/// `c` (THEORY §14.4), over `n` bins: the thickness of the lens at the angle `φ` from its
/// middle, `t(φ) = d cos φ + √(r² − d² sin²φ) − (r + c)` (≥ 0), `d = c + a`, relative to its
/// depth `a`; index `j` is `φ = ±j 2π/n`, `j ∈ [0, n/2]` (it is even in `φ`).
pub(super) fn crescent_footprint(r: f64, c: f64, a: f64, n: usize) -> Vec<f64> {
    if a <= 0.0 {
        let mut one = vec![0.0; n / 2 + 1];
        one[0] = 1.0;
        return one;
    }
    let d = c + a;
    (0..=n / 2)
        .map(|j| {
            let phi = std::f64::consts::TAU * j as f64 / n as f64;
            let (s, co) = phi.sin_cos();
            let inner = r * r - d * d * s * s;
            if inner < 0.0 {
                return 0.0;
            }
            ((d * co + inner.sqrt() - (r + c)) / a).max(0.0)
        })
        .collect()
}

/// The shape of a scar around a hole: each bin's volume spread by `footprint` (index `j`: `±j`
/// bins away, periodic, `j ≤ n/2`), normalised to 1 where deepest (0 everywhere without
/// volume).
pub(super) fn spread(footprint: &[f64], volumes: &[f64]) -> Vec<f64> {
    let n = volumes.len();
    let mut shape = vec![0.0; n];
    for (b, v) in volumes.iter().enumerate().filter(|(_, v)| **v > 0.0) {
        for (j, f) in footprint.iter().enumerate().filter(|(_, f)| **f > 0.0) {
            shape[(b + j) % n] += v * f;
            if j > 0 && 2 * j != n {
                shape[(b + n - j) % n] += v * f;
            }
        }
    }
    let max = shape.iter().copied().fold(0.0, f64::max);
    if max > 0.0 {
        shape.iter_mut().for_each(|x| *x /= max);
    }
    shape
}

/// `e` of a contact's wear (its field `wear.…`) named in the case: `contacts[k].wear.…`
/// with `field` = `contacts[k].wear`.
pub(super) fn at(e: Error, field: &str) -> Error {
    match e {
        Error::Invalid { field: f, message } => {
            let f = f.strip_prefix("wear.").unwrap_or(&f);
            Error::invalid(format!("{field}.{f}"), message)
        }
        other => other,
    }
}

/// The obstacle's wear for the added clearance per bin.
pub(super) fn obstacle_wear(added: &[f64]) -> ObstacleWear {
    match added.len() {
        1 => ObstacleWear::Uniform(added[0]),
        2 => ObstacleWear::Sides {
            positive: added[0],
            negative: added[1],
        },
        // the bins' depths are finite and ≥ 0 by construction
        _ => {
            ObstacleWear::Angular(AngularProfile::new(added.to_vec()).unwrap_or_else(|| {
                AngularProfile::new(vec![0.0; added.len()]).expect("zero profile")
            }))
        }
    }
}

/// The volumes after `[t0, t1]` at the window's rates.
pub(super) fn advanced(
    worn: &Worn,
    wear: &ContactWear,
    rate: f64,
    fractions: &[f64],
    t0: f64,
    t1: f64,
) -> Worn {
    let dvt = wear.tube.volume_increment(rate, t0, t1);
    let dvs = wear.support.volume_increment(rate, t0, t1);
    Worn {
        tube: worn
            .tube
            .iter()
            .zip(fractions)
            .map(|(v, f)| v + f * dvt)
            .collect(),
        support: worn
            .support
            .iter()
            .zip(fractions)
            .map(|(v, f)| v + f * dvs)
            .collect(),
    }
}

pub(super) fn deepest(d: &[f64]) -> f64 {
    d.iter().copied().fold(0.0, f64::max)
}

/// The time in `[t0, t1]` at which `depth(t)` (increasing) reaches `c`, by bisection.
pub(super) fn crossing(
    t0: f64,
    t1: f64,
    c: f64,
    depth: impl Fn(f64) -> Result<f64>,
) -> Result<f64> {
    let (mut lo, mut hi) = (t0, t1);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if depth(mid)? >= c {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crescent's footprint is the lens between the tube's circle and the hole's: 1 at its
    /// middle, and it ends where the two circles cross, `cos θ_h = (d² + R_h² − r²)/(2 d R_h)`
    /// (the law of cosines, independent of the thickness formula).
    #[test]
    fn the_crescent_footprint_ends_where_the_circles_cross() {
        let (r, c, a, n) = (9.525e-3, 2e-4, 3e-5, 3600);
        let f = crescent_footprint(r, c, a, n);
        assert!((f[0] - 1.0).abs() < 1e-9);
        let (d, rh) = (c + a, r + c);
        let half = ((d * d + rh * rh - r * r) / (2.0 * d * rh)).acos();
        let last = f.iter().rposition(|x| *x > 0.0).unwrap();
        let step = std::f64::consts::TAU / n as f64;
        assert!(
            (last as f64 * step - half).abs() <= step,
            "{} vs {half}",
            last as f64 * step
        );
        // the thickness falls from the middle to the edge
        assert!(f.windows(2).take(last).all(|w| w[1] <= w[0]));
        // spreading keeps the profile's peak at 1 and its symmetry
        let mut volumes = vec![0.0; 72];
        volumes[10] = 1.0;
        let shape = spread(&crescent_footprint(r, c, a, 72), &volumes);
        assert_eq!(shape[10], 1.0);
        for j in 1..36 {
            assert_eq!(shape[(10 + j) % 72], shape[(10 + 72 - j) % 72]);
        }
    }
}
