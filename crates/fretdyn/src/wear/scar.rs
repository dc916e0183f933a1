//! Scar geometry: the worn volume of the tube and of its support against the depth of their
//! scars, for each support type fretdyn models (`docs/THEORY.md §14`, `docs/WEAR.md`).
//!
//! Each body's scar is the imprint of the other body's unworn surface, pushed in by the
//! scar's depth `d` (the largest depth of the scar): the tube worn by a flat bar has a flat
//! cut, the bar a groove of the tube's radius. Depths come from volumes by the closed-form
//! inverse where there is one, by bisection on the monotone `V(d)` elsewhere.
//!
//! Notation: `R` the tube's outer radius; a circular segment of height `u` in a circle of
//! radius `r` has the half-angle `α = 2 asin √(u / 2r)` and the area
//! `A_r(u) = (r²/2)(2α − sin 2α)`; its integral over the height is
//! `F_r(u) = ∫₀ᵘ A_r = r³ (sin α − α cos α − sin³α / 3)`. Both are computed without
//! cancellation at small `α` (series), so that relative accuracy holds down to nanometre scars.

use crate::error::{Error, Result, number};

/// The shape of the scar in a drilled hole.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HoleScar {
    /// The tube rubs on one side of the hole: both scars are the lens between the tube's
    /// circle and the hole's circle, the tube pushed by `d` beyond the hole's edge.
    Crescent,
    /// The tube rubs all around (rotating contact): a ring of depth `d` over the thickness.
    Uniform,
}

/// The scar geometry of one contact: what turns the worn volumes of the tube and of the
/// support into depths (`docs/THEORY.md §14`, `docs/WEAR.md`). Angles in radians.
#[derive(Debug, Clone, PartialEq)]
pub enum Scar {
    /// A flat (anti-vibration) bar of width `width` along the tube's axis, the tube's axis
    /// inclined by `tilt` to the bar's face (0: aligned, the tube lies flat on the bar).
    ///
    /// Both scars are the overlap of the unworn tube and bar pushed together, bounded by the
    /// bar's side faces. Aligned: tube `V = w A_R(d)` (a flat cut over the bar's width), bar
    /// `V = w A_R(d)` (a groove of the tube's radius across the bar: the same segment).
    ///
    /// Tilted by `θ`: at the distance `x` across the bar the overlap's section is a segment of
    /// height `ρ − x sin θ` of the tube's circle, stretched by `1 / cos θ`, where `ρ` is the
    /// deepest radial loss of the tube's wall. While `ρ < w sin θ` the scar is a wedge shorter
    /// than the width, then the cut covers the whole width:
    /// `V = [F_R(ρ) − F_R(max(0, ρ − w sin θ))] / (sin θ cos θ)`.
    /// The tube's depth is `ρ` (its wall loss); the bar's depth, normal to its face, is
    /// `ρ / cos θ`. Continuous in depth and volume at the transition, and `→ w A_R(d)` as
    /// `θ → 0`. Small depths: `V ≈ 8 √(2R) ρ^{5/2} / (15 sin θ cos θ)` (the wedge).
    FlatBar {
        /// `R`, m.
        tube_radius: f64,
        /// `w`, m.
        width: f64,
        /// `θ`, rad, in [0, π/2).
        tilt: f64,
    },
    /// A drilled hole of radius `R + clearance` through a plate of thickness `e`.
    ///
    /// Uniform: tube `V = π e d (2R − d)` (a ring, `d ≤ R`), plate
    /// `V = π e d (2(R + c) + d)`, both inverted in closed form.
    ///
    /// Crescent: both `V = e L(d)`, `L` the area of the tube's disc outside the hole's disc
    /// when their centres are `c + d` apart (circle–circle intersection, closed form):
    /// `L = R² [h(δ) + 2 sin δ sin²(σ/2)] − c (2R + c) h(2θ_h)/2` with `h(x) = x − sin x`,
    /// `θ_h` the half-angle of the common chord seen from the hole's centre, `δ` the angle
    /// between the two radii at a corner of the lens and `σ = 2θ_h + δ` (this is
    /// `cap_tube − cap_hole` rearranged without cancellation).
    DrilledHole {
        /// `R`, m.
        tube_radius: f64,
        /// `e`, m.
        thickness: f64,
        /// `c`, the radial clearance of the hole, m (hole radius `R + c`).
        clearance: f64,
        /// Crescent or uniform.
        shape: HoleScar,
    },
    /// A broached (trefoil, quatrefoil) hole: `lobes` flat lands, each like a flat bar of the
    /// plate's thickness, share the volume equally: tube `V = n e A_R(d)` (n flat cuts), plate
    /// `V = n e A_R(d)` (a groove in each land). With `land_width` given, the scar's chord
    /// `2 √(d (2R − d))` must stay within the land.
    BroachedHole {
        /// `R`, m.
        tube_radius: f64,
        /// `e`, m.
        thickness: f64,
        /// `n`, the number of lands the tube rubs on.
        lobes: u32,
        /// The width of a land across the tube's axis, m, if known.
        land_width: Option<f64>,
    },
    /// Another tube (radius `R₂`) crossing this one at the angle `crossing`: both scars are
    /// the overlap of the two unworn cylinders pushed together by `d`.
    ///
    /// Crossing (`φ > 0`): `V = (4 / sin φ) ∫ √(R² − z²) √(R₂² − (z − D)²) dz` over the
    /// overlap, `D = R + R₂ − d` (two strips crossing at `φ` overlap on a parallelogram);
    /// with `u = d (1 − cos t)/2`,
    /// `V = (d² / sin φ) ∫₀^π sin²t √((2R − u)(2R₂ − d + u)) dt`, by the trapezoidal rule
    /// (spectrally accurate: the integrand is a smooth even periodic function of `t`).
    /// Small `d`: `V ≈ π √(R R₂) d² / sin φ`.
    ///
    /// Parallel (`φ = 0`, `length` `L` required): `V = L` × the area of the two discs'
    /// intersection (two circular caps on the common chord, closed form).
    Tube {
        /// `R`, m.
        tube_radius: f64,
        /// `R₂`, m.
        other_radius: f64,
        /// `φ`, rad, in [0, π/2]; 0 is parallel.
        crossing: f64,
        /// The contact length of parallel tubes, m.
        length: Option<f64>,
    },
}

/// Which body a volume or a depth is of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Body {
    Tube,
    Support,
}

impl Body {
    fn name(self) -> &'static str {
        match self {
            Body::Tube => "tube",
            Body::Support => "support",
        }
    }
}

impl Scar {
    /// Checks the dimensions; `field` names the scar in errors (e.g.
    /// `contacts[0].wear.scar`), each error naming the key as written in a case file.
    pub fn validate(&self, field: &str) -> Result<()> {
        let positive = |key: &str, x: f64, what: &str| -> Result<()> {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(
                    format!("{field}.{key}"),
                    format!("must be {what} > 0 in m (got {})", number(x)),
                ))
            }
        };
        match *self {
            Scar::FlatBar {
                tube_radius,
                width,
                tilt,
            } => {
                positive("tube_radius", tube_radius, "the tube's outer radius")?;
                positive("width", width, "the bar's width along the tube")?;
                if !(tilt.is_finite() && (0.0..std::f64::consts::FRAC_PI_2).contains(&tilt)) {
                    return Err(Error::invalid(
                        format!("{field}.tilt_deg"),
                        format!(
                            "must be the angle between the tube's axis and the bar's face, in [0, 90) degrees (got {})",
                            number(tilt.to_degrees())
                        ),
                    ));
                }
            }
            Scar::DrilledHole {
                tube_radius,
                thickness,
                clearance,
                ..
            } => {
                positive("tube_radius", tube_radius, "the tube's outer radius")?;
                positive("thickness", thickness, "the plate's thickness")?;
                if !(clearance.is_finite() && clearance >= 0.0) {
                    return Err(Error::invalid(
                        format!("{field}.clearance"),
                        format!(
                            "must be the hole's radial clearance ≥ 0 in m (got {})",
                            number(clearance)
                        ),
                    ));
                }
            }
            Scar::BroachedHole {
                tube_radius,
                thickness,
                lobes,
                land_width,
            } => {
                positive("tube_radius", tube_radius, "the tube's outer radius")?;
                positive("thickness", thickness, "the plate's thickness")?;
                if lobes == 0 {
                    return Err(Error::invalid(
                        format!("{field}.lobes"),
                        "must be the number of lands the tube rubs on, ≥ 1 (e.g. 4 for a quatrefoil hole)",
                    ));
                }
                if let Some(lw) = land_width {
                    positive("land_width", lw, "the land's width")?;
                }
            }
            Scar::Tube {
                tube_radius,
                other_radius,
                crossing,
                length,
            } => {
                positive("tube_radius", tube_radius, "the tube's outer radius")?;
                positive(
                    "other_radius",
                    other_radius,
                    "the other tube's outer radius",
                )?;
                if !(crossing.is_finite()
                    && (0.0..=std::f64::consts::FRAC_PI_2 * (1.0 + 1e-15)).contains(&crossing))
                {
                    return Err(Error::invalid(
                        format!("{field}.crossing_deg"),
                        format!(
                            "must be the angle between the two tubes' axes, in [0, 90] degrees (got {})",
                            number(crossing.to_degrees())
                        ),
                    ));
                }
                match (crossing > 0.0, length) {
                    (false, None) => {
                        return Err(Error::invalid(
                            format!("{field}.length"),
                            "parallel tubes (crossing_deg = 0) need the contact length, in m",
                        ));
                    }
                    (false, Some(l)) => positive("length", l, "the contact length")?,
                    (true, Some(_)) => {
                        return Err(Error::invalid(
                            format!("{field}.length"),
                            "is only for parallel tubes (crossing_deg = 0): crossing tubes touch over a length set by the depth",
                        ));
                    }
                    (true, None) => {}
                }
            }
        }
        Ok(())
    }

    /// The name of the geometry as written in a case file (`flat_bar`, …).
    pub fn kind(&self) -> &'static str {
        match self {
            Scar::FlatBar { .. } => "flat_bar",
            Scar::DrilledHole { .. } => "drilled_hole",
            Scar::BroachedHole { .. } => "broached_hole",
            Scar::Tube { .. } => "tube",
        }
    }

    /// The largest depth of the tube's scar the geometry allows, m: `2R` (the flat cut or the
    /// crescent through the whole tube), `R` for a uniform ring, the land's width for a
    /// broached hole, `min(R, R₂)` against a tube.
    pub fn tube_depth_limit(&self) -> f64 {
        self.depth_limit(Body::Tube)
    }

    /// The largest depth of the support's scar, m: `R` for a bar's groove (`R / cos θ`
    /// tilted), `2R` for a crescent, none (`f64::INFINITY`) for a uniform ring, `R` for a
    /// land (or the land's width), `min(R, R₂)` against a tube.
    pub fn support_depth_limit(&self) -> f64 {
        self.depth_limit(Body::Support)
    }

    /// The tube's worn volume for a scar of depth `depth`, m³ (formulas on [`Scar`],
    /// `docs/THEORY.md §14`).
    pub fn tube_volume(&self, depth: f64) -> Result<f64> {
        self.volume_of(Body::Tube, depth)
    }

    /// The support's worn volume for a scar of depth `depth`, m³.
    pub fn support_volume(&self, depth: f64) -> Result<f64> {
        self.volume_of(Body::Support, depth)
    }

    /// The depth of the tube's scar that holds `volume` m³, m: the inverse of
    /// [`Self::tube_volume`] (closed form for a uniform ring, bisection elsewhere). An error
    /// if the volume is more than the geometry holds (the tube worn through).
    pub fn tube_depth(&self, volume: f64) -> Result<f64> {
        self.depth_of(Body::Tube, volume)
    }

    /// The depth of the support's scar that holds `volume` m³, m.
    pub fn support_depth(&self, volume: f64) -> Result<f64> {
        self.depth_of(Body::Support, volume)
    }

    /// How far the tube and the support have come together, m, measured along the support's
    /// normal: the local growth of the clearance when the tube has lost `tube_volume` and the
    /// support `support_volume` (m³). Both scars together fill the overlap of the two unworn
    /// bodies, whatever the shape of the worn interface, so the approach `D` is the depth of
    /// the overlap holding `V_tube + V_support`; for a uniform ring the tube's and the hole's
    /// radii change independently, `D = d_tube + d_support`. `D ≤ d_tube + d_support`
    /// otherwise: each scar's own depth assumes the other body unworn (`docs/WEAR.md`,
    /// `docs/THEORY.md §14`).
    pub fn approach(&self, tube_volume: f64, support_volume: f64) -> Result<f64> {
        match *self {
            Scar::DrilledHole {
                shape: HoleScar::Uniform,
                ..
            } => Ok(self.tube_depth(tube_volume)? + self.support_depth(support_volume)?),
            Scar::FlatBar { tilt, .. } => {
                // the tube's function is the overlap at the wall loss ρ = D cos θ
                Ok(self.tube_depth(tube_volume + support_volume)? / tilt.cos())
            }
            // the tube's and the support's volumes are the same overlap function
            _ => self.tube_depth(tube_volume + support_volume),
        }
    }

    fn depth_limit(&self, body: Body) -> f64 {
        match *self {
            Scar::FlatBar {
                tube_radius, tilt, ..
            } => match body {
                Body::Tube => 2.0 * tube_radius,
                Body::Support => tube_radius / tilt.cos(),
            },
            Scar::DrilledHole {
                tube_radius, shape, ..
            } => match (shape, body) {
                (HoleScar::Crescent, _) => 2.0 * tube_radius,
                (HoleScar::Uniform, Body::Tube) => tube_radius,
                (HoleScar::Uniform, Body::Support) => f64::INFINITY,
            },
            Scar::BroachedHole {
                tube_radius,
                land_width,
                ..
            } => {
                let own = match body {
                    Body::Tube => 2.0 * tube_radius,
                    Body::Support => tube_radius,
                };
                match land_width {
                    // chord 2√(d(2R − d)) = land width
                    Some(lw) if lw < 2.0 * tube_radius => {
                        let q = 0.25 * lw * lw;
                        own.min(q / (tube_radius + (tube_radius * tube_radius - q).sqrt()))
                    }
                    _ => own,
                }
            }
            Scar::Tube {
                tube_radius,
                other_radius,
                ..
            } => tube_radius.min(other_radius),
        }
    }

    fn volume_of(&self, body: Body, depth: f64) -> Result<f64> {
        self.validate("wear.scar")?;
        let limit = self.depth_limit(body);
        if !(depth.is_finite() && depth >= 0.0) {
            return Err(Error::invalid(
                format!("wear.scar.{}_depth", body.name()),
                format!("must be a depth ≥ 0 in m (got {})", number(depth)),
            ));
        }
        if depth > limit {
            return Err(Error::invalid(
                format!("wear.scar.{}_depth", body.name()),
                format!(
                    "{} m is deeper than the {} scar of a {} can be ({} m, {})",
                    number(depth),
                    body.name(),
                    self.kind(),
                    number(limit),
                    self.limit_reason(body)
                ),
            ));
        }
        Ok(self.volume_unchecked(body, depth))
    }

    fn depth_of(&self, body: Body, volume: f64) -> Result<f64> {
        self.validate("wear.scar")?;
        let field = format!("wear.scar.{}_volume", body.name());
        if !(volume.is_finite() && volume >= 0.0) {
            return Err(Error::invalid(
                field,
                format!("must be a worn volume ≥ 0 in m³ (got {})", number(volume)),
            ));
        }
        if volume == 0.0 {
            return Ok(0.0);
        }
        // closed-form inverses
        if let Scar::DrilledHole {
            tube_radius,
            thickness,
            clearance,
            shape: HoleScar::Uniform,
        } = *self
        {
            let q = volume / (std::f64::consts::PI * thickness);
            match body {
                Body::Tube => {
                    // q = d (2R − d): d = q / (R + √(R² − q))
                    let r2 = tube_radius * tube_radius;
                    if q <= r2 {
                        return Ok((q / (tube_radius + (r2 - q).sqrt())).min(tube_radius));
                    }
                }
                Body::Support => {
                    // q = d (2 R_h + d): d = q / (R_h + √(R_h² + q))
                    let rh = tube_radius + clearance;
                    return Ok(q / (rh + (rh * rh + q).sqrt()));
                }
            }
        }
        let limit = self.depth_limit(body);
        let largest = self.volume_unchecked(body, limit);
        if volume > largest {
            return Err(Error::invalid(
                field,
                format!(
                    "{} m³ is more than the {} scar of a {} can hold ({} m³ at the largest depth {} m, {})",
                    number(volume),
                    body.name(),
                    self.kind(),
                    number(largest),
                    number(limit),
                    self.limit_reason(body)
                ),
            ));
        }
        Ok(bisect(|d| self.volume_unchecked(body, d), volume, limit))
    }

    fn limit_reason(&self, body: Body) -> &'static str {
        if let Scar::BroachedHole {
            tube_radius,
            land_width: Some(_),
            ..
        } = *self
        {
            let own = match body {
                Body::Tube => 2.0 * tube_radius,
                Body::Support => tube_radius,
            };
            if self.depth_limit(body) < own {
                return "the scar would be wider than the land (land_width)";
            }
        }
        match (self, body) {
            (Scar::Tube { .. }, _) => {
                "deeper than the smaller radius the overlap of the two tubes is no longer a scar"
            }
            (_, Body::Tube) => "the tube is worn through",
            (Scar::FlatBar { .. } | Scar::BroachedHole { .. }, Body::Support) => {
                "the groove reaches the tube's axis"
            }
            (_, Body::Support) => "the tube has left the hole",
        }
    }

    /// The tube's outer radius `R`, m.
    pub fn tube_radius(&self) -> f64 {
        match *self {
            Scar::FlatBar { tube_radius, .. }
            | Scar::DrilledHole { tube_radius, .. }
            | Scar::BroachedHole { tube_radius, .. }
            | Scar::Tube { tube_radius, .. } => tube_radius,
        }
    }

    /// `V(d)` for `0 ≤ d ≤ limit` of a valid geometry.
    fn volume_unchecked(&self, body: Body, d: f64) -> f64 {
        match *self {
            Scar::FlatBar {
                tube_radius,
                width,
                tilt,
            } => {
                // the tube's wall loss ρ: the tube's depth, the bar's depth × cos θ
                let (sin, cos) = tilt.sin_cos();
                let rho = match body {
                    Body::Tube => d,
                    Body::Support => (d * cos).min(tube_radius),
                };
                width / cos * mean_segment(tube_radius, rho, width * sin)
            }
            Scar::DrilledHole {
                tube_radius,
                thickness,
                clearance,
                shape,
            } => match (shape, body) {
                (HoleScar::Uniform, Body::Tube) => {
                    std::f64::consts::PI * thickness * d * (2.0 * tube_radius - d)
                }
                (HoleScar::Uniform, Body::Support) => {
                    std::f64::consts::PI * thickness * d * (2.0 * (tube_radius + clearance) + d)
                }
                (HoleScar::Crescent, _) => thickness * crescent_area(tube_radius, clearance, d),
            },
            Scar::BroachedHole {
                tube_radius,
                thickness,
                lobes,
                ..
            } => f64::from(lobes) * thickness * segment_area(tube_radius, d),
            Scar::Tube {
                tube_radius,
                other_radius,
                crossing,
                length,
            } => {
                if crossing > 0.0 {
                    crossing_overlap(tube_radius, other_radius, d) / crossing.sin()
                } else {
                    length.unwrap_or(0.0) * lens_area(tube_radius, other_radius, d)
                }
            }
        }
    }
}

/// `x − sin x`, without cancellation at small `x` (series below 1).
fn x_minus_sin(x: f64) -> f64 {
    if x.abs() >= 1.0 {
        return x - x.sin();
    }
    // Σ_{k≥1} (−1)^{k+1} x^{2k+1} / (2k+1)!
    let x2 = x * x;
    let mut term = x * x2 / 6.0;
    let mut sum = 0.0_f64;
    let mut k = 1.0;
    while term.abs() > 1e-18 * sum.abs() || sum == 0.0 {
        sum += term;
        term *= -x2 / ((2.0 * k + 2.0) * (2.0 * k + 3.0));
        k += 1.0;
        if term == 0.0 {
            break;
        }
    }
    sum
}

/// The half-angle `α = 2 asin √(u / 2r)` of a segment of height `u ∈ [0, 2r]`.
fn half_angle(r: f64, u: f64) -> f64 {
    2.0 * (0.5 * u / r).clamp(0.0, 1.0).sqrt().asin()
}

/// `A_r(u) = (r²/2)(2α − sin 2α)`, the area of a circular segment of height `u`.
fn segment_area(r: f64, u: f64) -> f64 {
    0.5 * r * r * x_minus_sin(2.0 * half_angle(r, u))
}

/// `F_r(u) = ∫₀ᵘ A_r(s) ds = r³ (sin α − α cos α − sin³α / 3)`, series at small `α`:
/// `Σ_{k≥2} (−1)^k c_k α^{2k+1}/(2k+1)!`, `c_k = (3^{2k+1} − 3)/12 − 2k` (from
/// `sin³α = (3 sin α − sin 3α)/4`); leading term `2α⁵/15`, i.e. `F ≈ (8/15) √(2r) u^{5/2}`.
fn segment_integral(r: f64, u: f64) -> f64 {
    let a = half_angle(r, u);
    let g = if a >= 1.0 {
        let (s, c) = a.sin_cos();
        s - a * c - s * s * s / 3.0
    } else {
        let a2 = a * a;
        let mut power = a.powi(5); // α^{2k+1}, k = 2
        let mut factorial = 120.0; // (2k+1)!
        let mut three = 243.0; // 3^{2k+1}
        let mut sum = 0.0_f64;
        let mut k = 2.0_f64;
        loop {
            let c = (three - 3.0) / 12.0 - 2.0 * k;
            let sign = if (k as i64) % 2 == 0 { 1.0 } else { -1.0 };
            let term = sign * c * power / factorial;
            sum += term;
            if term.abs() <= 1e-18 * sum.abs() {
                break;
            }
            power *= a2;
            factorial *= (2.0 * k + 2.0) * (2.0 * k + 3.0);
            three *= 9.0;
            k += 1.0;
        }
        sum
    };
    r * r * r * g
}

/// Gauss–Legendre nodes and weights on [−1, 1], `n` points (Newton on `P_n`).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (1..=n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let kf = k as f64;
                    let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// `(1/δ) ∫_{max(0, d − δ)}^{d} A_r(u) du` (`A_r(d)` at `δ = 0`): the wedge and the full cut
/// of a tilted bar, `[F_r(d) − F_r(max(0, d − δ))]/δ`; by 16-point Gauss–Legendre when the
/// interval is short against its distance to the singular ends `0` and `2r` (there the
/// difference of `F` would cancel, the quadrature error is below 1e-20).
fn mean_segment(r: f64, d: f64, delta: f64) -> f64 {
    if delta == 0.0 {
        return segment_area(r, d);
    }
    let lo = d - delta;
    if lo > 0.0 && delta <= 0.1 * lo.min(2.0 * r - d) {
        let (mid, half) = (d - 0.5 * delta, 0.5 * delta);
        let sum: f64 = gauss_legendre(16)
            .iter()
            .map(|(x, w)| w * segment_area(r, mid + half * x))
            .sum();
        return 0.5 * sum;
    }
    (segment_integral(r, d) - segment_integral(r, lo.max(0.0))) / delta
}

/// The area of the tube's disc (radius `r`) outside the hole's disc (radius `r + c`) when
/// their centres are `c + d` apart, `0 ≤ d ≤ 2r` (docs/WEAR.md, drilled hole).
fn crescent_area(r: f64, c: f64, d: f64) -> f64 {
    if d <= 0.0 {
        return 0.0;
    }
    let big_d = c + d;
    // half-chord, Heron's formula factored: no cancellation
    let y = (d * (2.0 * r - d).max(0.0) * (2.0 * c + d) * (2.0 * r + 2.0 * c + d)).sqrt()
        / (2.0 * big_d);
    // distance from the hole's centre to the chord, > 0
    let a = (big_d * big_d + c * (2.0 * r + c)) / (2.0 * big_d);
    let theta_h = y.atan2(a);
    // angle between the radii at a corner: sin δ = y D / (r R_h), cos δ = (r² + R_h² − D²)/(2 r R_h)
    let delta = (y * big_d).atan2(0.5 * (2.0 * r * (r + c) - d * (2.0 * c + d)));
    let sigma = 2.0 * theta_h + delta;
    let half = (0.5 * sigma).sin();
    r * r * (x_minus_sin(delta) + 2.0 * delta.sin() * half * half)
        - 0.5 * c * (2.0 * r + c) * x_minus_sin(2.0 * theta_h)
}

/// The intersection area of two discs of radii `r1`, `r2` whose centres are `r1 + r2 − d`
/// apart, `0 ≤ d ≤ min(r1, r2)`: two circular caps on the common chord.
fn lens_area(r1: f64, r2: f64, d: f64) -> f64 {
    if d <= 0.0 {
        return 0.0;
    }
    let big_d = r1 + r2 - d;
    let y =
        (d * (2.0 * r1 - d) * (2.0 * r2 - d) * (2.0 * r1 + 2.0 * r2 - d)).sqrt() / (2.0 * big_d);
    let a1 = (big_d * big_d + r1 * r1 - r2 * r2) / (2.0 * big_d);
    let a2 = (big_d * big_d + r2 * r2 - r1 * r1) / (2.0 * big_d);
    0.5 * r1 * r1 * x_minus_sin(2.0 * y.atan2(a1)) + 0.5 * r2 * r2 * x_minus_sin(2.0 * y.atan2(a2))
}

/// `sin φ` × the overlap volume of two cylinders of radii `r1`, `r2` crossing at `φ`, pushed
/// together by `d ≤ min(r1, r2)`:
/// `d² ∫₀^π sin²t √((2r1 − u)(2r2 − d + u)) dt`, `u = d (1 − cos t)/2`, by the trapezoidal
/// rule doubled until it settles (the integrand is even and 2π-periodic in `t`).
fn crossing_overlap(r1: f64, r2: f64, d: f64) -> f64 {
    if d <= 0.0 {
        return 0.0;
    }
    let f = |t: f64| {
        let (s, c) = t.sin_cos();
        let u = 0.5 * d * (1.0 - c);
        s * s * ((2.0 * r1 - u) * (2.0 * r2 - d + u)).sqrt()
    };
    let mut n = 8usize;
    let mut sum: f64 = (1..n)
        .map(|j| f(std::f64::consts::PI * j as f64 / n as f64))
        .sum();
    let mut integral = sum * std::f64::consts::PI / n as f64;
    while n < 1 << 16 {
        // add the midpoints
        sum += (0..n)
            .map(|j| f(std::f64::consts::PI * (j as f64 + 0.5) / n as f64))
            .sum::<f64>();
        n *= 2;
        let next = sum * std::f64::consts::PI / n as f64;
        let settled = (next - integral).abs() <= 1e-15 * next.abs();
        integral = next;
        if settled {
            break;
        }
    }
    d * d * integral
}

/// The depth `d ∈ [0, limit]` where the increasing `volume(d)` equals `target`
/// (`0 < target ≤ volume(limit)`), by bisection down to adjacent floating-point numbers.
fn bisect(volume: impl Fn(f64) -> f64, target: f64, limit: f64) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, limit);
    for _ in 0..2100 {
        let mid = 0.5 * (lo + hi);
        if !(mid > lo && mid < hi) {
            break;
        }
        if volume(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // the nearer end
    if (target - volume(lo)).abs() < (volume(hi) - target).abs() {
        lo
    } else {
        hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn series_agree_with_the_direct_formulas_where_both_hold() {
        for x in [0.5_f64, 0.9, 0.999] {
            let direct = x - x.sin();
            assert!((x_minus_sin(x) - direct).abs() <= 1e-14 * direct);
        }
        let r = 2.0;
        for a in [0.6_f64, 0.9, 0.99] {
            let u = r * (1.0 - a.cos());
            let (s, c) = a.sin_cos();
            let direct = r * r * r * (s - a * c - s * s * s / 3.0);
            let series = segment_integral(r, u);
            assert!(
                (series - direct).abs() <= 1e-12 * direct,
                "α {a}: {series} {direct}"
            );
        }
    }

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let rule = gauss_legendre(16);
        let total: f64 = rule.iter().map(|(_, w)| w).sum();
        assert!((total - 2.0).abs() < 1e-14);
        let x30: f64 = rule.iter().map(|(x, w)| w * x.powi(30)).sum();
        assert!((x30 - 2.0 / 31.0).abs() < 1e-14);
    }
}
