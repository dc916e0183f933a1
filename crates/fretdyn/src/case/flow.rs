//! `[flow]` and its `[[flow.zones]]`: the cross flow along the tube (bundle geometry, and per
//! zone a stretch of the tube, a density and a velocity), sampled on the mode shapes for the
//! Connors check and the loads that use the zones (docs/FLOW.md).

use nalgebra::Vector3;
use serde::Deserialize;

use super::flow_damping::DampingSection;
use super::shared::{Abscissae, TubeModel, point_index};
use crate::error::{Error, Result, number};
use crate::loads::flow::ZoneFluidElastic;
use crate::loads::flow::{
    Bundle, BundlePattern, Flow, FlowZone, Station, VelocityDefinition, VelocityProfile,
    homogeneous_density, homogeneous_void_fraction, midpoint_weights,
};
use crate::loads::fluid_elastic::{QuasiSteady, ReducedVelocityTable};
use crate::model::Model;

/// `[flow]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FlowSection {
    pattern: BundlePattern,
    /// `P/D`.
    pitch_ratio: f64,
    /// Whether the zones' velocities are gap or upstream velocities.
    velocity_definition: VelocityDefinition,
    #[serde(default = "default_connors_constant")]
    connors_constant: f64,
    /// Default: the tube's outer diameter.
    diameter: Option<f64>,
    /// Default: the tube's mass per unit length (tube, inner fluid, added mass).
    mass_per_length: Option<f64>,
    zones: Vec<ZoneSection>,
    /// The damping models of the check.
    damping: Option<DampingSection>,
}

fn default_connors_constant() -> f64 {
    3.0
}

/// `[[flow.zones]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ZoneSection {
    name: String,
    span: Option<[f64; 2]>,
    from: Option<String>,
    to: Option<String>,
    density: Option<f64>,
    void_fraction: Option<f64>,
    /// Steam quality `x` (mass fraction of gas): the homogeneous void fraction.
    quality: Option<f64>,
    liquid_density: Option<f64>,
    gas_density: Option<f64>,
    velocity: Option<f64>,
    /// `[[s, U], ...]`.
    velocity_profile: Option<Vec<[f64; 2]>>,
    /// `G`, kg/(m² s): the velocity is `G / ρ`.
    mass_flux: Option<f64>,
    /// `[[s, G], ...]`.
    mass_flux_profile: Option<Vec<[f64; 2]>>,
    /// The zone's fluid-elastic forces (THEORY §13).
    fluid_elastic: Option<FluidElasticInput>,
}

/// `fluid_elastic = { model = "quasi_steady", ... }` or `{ model = "table", ... }` of a zone.
#[derive(Debug, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
enum FluidElasticInput {
    QuasiSteady {
        lift_slope: Option<f64>,
        drag_slope: Option<f64>,
        /// A U-bend's coefficients by plane instead of by direction.
        in_plane: Option<PlaneInput>,
        out_of_plane: Option<PlaneInput>,
        drag: f64,
        /// `μ` of both directions, unless `mu_lift` / `mu_drag` give theirs.
        mu: Option<f64>,
        mu_lift: Option<f64>,
        mu_drag: Option<f64>,
        flow_direction: [f64; 3],
        #[serde(default = "default_delay_segments")]
        delay_segments: usize,
    },
    Table {
        reduced_velocity: Vec<f64>,
        damping: Vec<f64>,
        stiffness: Vec<f64>,
    },
}

/// `in_plane = { slope, mu }` / `out_of_plane = { slope, mu }`: a planar zone's quasi-steady
/// stiffness coefficient and delay factor by plane, resolved into lift and drag by the flow's
/// direction against the zone's plane.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PlaneInput {
    slope: f64,
    mu: Option<f64>,
}

fn default_delay_segments() -> usize {
    4
}

impl FluidElasticInput {
    fn build(
        &self,
        field: &str,
        stations: &[crate::loads::flow::Station],
    ) -> Result<ZoneFluidElastic> {
        let finite = |v: f64, key: &str| {
            if v.is_finite() {
                Ok(v)
            } else {
                Err(Error::invalid(
                    format!("{field}.{key}"),
                    format!("must be a finite number (got {})", number(v)),
                ))
            }
        };
        match self {
            FluidElasticInput::QuasiSteady {
                lift_slope,
                drag_slope,
                in_plane,
                out_of_plane,
                drag,
                mu,
                mu_lift,
                mu_drag,
                flow_direction,
                delay_segments,
            } => {
                let d = Vector3::from(*flow_direction);
                if !(d.iter().all(|v| v.is_finite()) && d.norm() > 0.0) {
                    return Err(Error::invalid(
                        format!("{field}.flow_direction"),
                        "must be a nonzero finite vector [x, y, z], the direction of the cross flow",
                    ));
                }
                let d = d.normalize();
                // by plane: resolved into lift and drag (the absent plane: no stiffness, the
                // other's delay)
                let by_plane = in_plane.is_some() || out_of_plane.is_some();
                let (lift_slope, drag_slope, mu_lift, mu_drag) = if by_plane {
                    if lift_slope.is_some()
                        || drag_slope.is_some()
                        || mu_lift.is_some()
                        || mu_drag.is_some()
                    {
                        return Err(Error::invalid(
                            format!("{field}.in_plane"),
                            "give the coefficients either by plane (in_plane, out_of_plane) or by direction (lift_slope, drag_slope, mu_lift, mu_drag), not both",
                        ));
                    }
                    let flow_in_plane = flow_in_zone_plane(field, stations, &d)?;
                    let pick = |p: &Option<PlaneInput>, other: &Option<PlaneInput>| {
                        let mu_other = other.as_ref().and_then(|o| o.mu).or(*mu);
                        match p {
                            Some(p) => (Some(p.slope), p.mu.or(*mu)),
                            None => (Some(0.0), mu_other),
                        }
                    };
                    let (inp, out) = (pick(in_plane, out_of_plane), pick(out_of_plane, in_plane));
                    // flow in the plane: the drag is in-plane, the lift out of plane
                    let (lift, drag) = if flow_in_plane {
                        (out, inp)
                    } else {
                        (inp, out)
                    };
                    (lift.0, drag.0, lift.1, drag.1)
                } else {
                    (*lift_slope, *drag_slope, *mu_lift, *mu_drag)
                };
                let Some(lift_slope) = lift_slope else {
                    return Err(Error::invalid(
                        format!("{field}.lift_slope"),
                        "is missing: give lift_slope (and drag_slope), or in_plane/out_of_plane for a planar zone",
                    ));
                };
                let drag_slope = drag_slope.unwrap_or(0.0);
                finite(lift_slope, "lift_slope")?;
                finite(drag_slope, "drag_slope")?;
                finite(*drag, "drag")?;
                // each direction's μ: its own key, else `mu`
                let lag = |own: Option<f64>, key: &str| -> Result<f64> {
                    let (v, key) = match (own, mu) {
                        (Some(v), _) => (v, key),
                        (None, Some(v)) => (*v, "mu"),
                        (None, None) => {
                            return Err(Error::invalid(
                                format!("{field}.{key}"),
                                "is missing: give mu (the time-lag factor of τ = μ D / U for both directions) or both mu_lift and mu_drag",
                            ));
                        }
                    };
                    if v.is_finite() && v >= 0.0 {
                        Ok(v)
                    } else {
                        Err(Error::invalid(
                            format!("{field}.{key}"),
                            format!(
                                "must be a number ≥ 0, the time-lag factor of τ = μ D / U (got {})",
                                number(v)
                            ),
                        ))
                    }
                };
                let mu_lift = lag(mu_lift, "mu_lift")?;
                let mu_drag = lag(mu_drag, "mu_drag")?;
                if *delay_segments == 0 {
                    return Err(Error::invalid(
                        format!("{field}.delay_segments"),
                        "must be at least 1",
                    ));
                }
                if let Some(st) = stations
                    .iter()
                    .find(|st| (d - st.tangent * d.dot(&st.tangent)).norm() < 1e-6)
                {
                    return Err(Error::invalid(
                        format!("{field}.flow_direction"),
                        format!(
                            "is along the tube's axis at s = {} m: a cross flow must cross the tube",
                            number(st.s)
                        ),
                    ));
                }
                Ok(ZoneFluidElastic::QuasiSteady {
                    coefficients: QuasiSteady {
                        lift_slope,
                        drag_slope,
                        drag: *drag,
                        mu_lift,
                        mu_drag,
                    },
                    flow_direction: d,
                    delay_segments: *delay_segments,
                })
            }
            FluidElasticInput::Table {
                reduced_velocity,
                damping,
                stiffness,
            } => {
                let n = reduced_velocity.len();
                if n == 0 || damping.len() != n || stiffness.len() != n {
                    return Err(Error::invalid(
                        field,
                        format!(
                            "reduced_velocity, damping and stiffness must have the same number (≥ 1) of values (got {n}, {}, {})",
                            damping.len(),
                            stiffness.len()
                        ),
                    ));
                }
                for (key, v) in [
                    ("reduced_velocity", reduced_velocity),
                    ("damping", damping),
                    ("stiffness", stiffness),
                ] {
                    for (i, x) in v.iter().enumerate() {
                        finite(*x, &format!("{key}[{i}]"))?;
                    }
                }
                if let Some(i) = reduced_velocity.windows(2).position(|w| w[1] <= w[0]) {
                    return Err(Error::invalid(
                        format!("{field}.reduced_velocity[{}]", i + 1),
                        "the reduced velocities must increase",
                    ));
                }
                Ok(ZoneFluidElastic::Table(ReducedVelocityTable {
                    reduced_velocity: reduced_velocity.clone(),
                    damping: damping.clone(),
                    stiffness: stiffness.clone(),
                }))
            }
        }
    }
}

/// Whether the flow `d` lies in the plane of the zone's axis (`true`) or is normal to it
/// (`false`); an error on `{field}.in_plane` when the zone is straight or not planar, on
/// `{field}.flow_direction` when the flow is neither.
fn flow_in_zone_plane(field: &str, stations: &[Station], d: &Vector3<f64>) -> Result<bool> {
    let t0 = stations.first().map_or(Vector3::zeros(), |s| s.tangent);
    let normal = stations
        .iter()
        .map(|s| t0.cross(&s.tangent))
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .unwrap_or(Vector3::zeros());
    let planar = normal.norm() > 1e-6 && {
        let n = normal.normalize();
        stations.iter().all(|s| s.tangent.dot(&n).abs() < 1e-6)
    };
    if !planar {
        return Err(Error::invalid(
            format!("{field}.in_plane"),
            "the zone's axis is straight or not planar, so it has no plane: give lift_slope and drag_slope (across and along the flow)",
        ));
    }
    let n = normal.normalize();
    if d.dot(&n).abs() < 1e-6 {
        Ok(true)
    } else if d.cross(&n).norm() < 1e-6 {
        Ok(false)
    } else {
        Err(Error::invalid(
            format!("{field}.flow_direction"),
            "lies neither in the zone's plane nor normal to it: in_plane/out_of_plane cannot name the lift and drag; give lift_slope and drag_slope",
        ))
    }
}

/// The geometry the zones are placed on.
enum Line<'a> {
    Tube(&'a TubeModel, Vec<f64>),
    Points(&'a Abscissae),
}

impl FlowSection {
    /// The flow, its zones sampled on the modes of `model` (`tube` for a tube structure,
    /// `abscissae` otherwise).
    pub(super) fn build(
        &self,
        tube: Option<&TubeModel>,
        abscissae: &Abscissae,
        model: &Model,
    ) -> Result<Flow> {
        if !(self.pitch_ratio.is_finite() && self.pitch_ratio > 1.0) {
            return Err(Error::invalid(
                "flow.pitch_ratio",
                format!(
                    "must be the pitch-to-diameter ratio P/D > 1 (got {})",
                    number(self.pitch_ratio)
                ),
            ));
        }
        if !(self.connors_constant.is_finite() && self.connors_constant > 0.0) {
            return Err(Error::invalid(
                "flow.connors_constant",
                format!(
                    "must be Connors' constant K > 0 (design guides: 3.0; got {})",
                    number(self.connors_constant)
                ),
            ));
        }
        let not_a_tube = |key: &str, what: &str| {
            Error::invalid(
                format!("flow.{key}"),
                format!("give {what}: the structure is not a tube, there is no default"),
            )
        };
        let diameter = match (self.diameter, tube) {
            (Some(d), _) => d,
            (None, Some(t)) => t.structure.beam.tube.section.outer_diameter,
            (None, None) => return Err(not_a_tube("diameter", "the tube's outer diameter in m")),
        };
        let mass_per_length = match (self.mass_per_length, tube) {
            (Some(m), _) => m,
            (None, Some(t)) => t.structure.beam.tube.mass_per_length(),
            (None, None) => {
                return Err(not_a_tube(
                    "mass_per_length",
                    "the tube's mass per unit length in kg/m (tube, internal fluid and hydrodynamic mass)",
                ));
            }
        };
        for (key, v, what) in [
            ("diameter", diameter, "an outer diameter > 0 in m"),
            (
                "mass_per_length",
                mass_per_length,
                "a mass per unit length > 0 in kg/m",
            ),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    format!("flow.{key}"),
                    format!("must be {what} (got {})", number(v)),
                ));
            }
        }
        let bundle = Bundle {
            pattern: self.pattern,
            pitch_ratio: self.pitch_ratio,
        };
        let factor = match self.velocity_definition {
            VelocityDefinition::Gap => 1.0,
            VelocityDefinition::Upstream => bundle.gap_factor(),
        };
        let line = match tube {
            Some(t) => Line::Tube(t, t.structure.node_abscissae()),
            None => Line::Points(abscissae),
        };
        let range = line.range(model)?;
        if self.zones.is_empty() {
            return Err(Error::invalid(
                "flow.zones",
                "give at least one zone: [[flow.zones]] with name, span (or from/to), density and velocity",
            ));
        }
        let mut zones: Vec<(usize, FlowZone)> = Vec::new();
        for (k, z) in self.zones.iter().enumerate() {
            let field = format!("flow.zones[{k}]");
            let zone = z.build(&field, &line, range, model, factor)?;
            if let Some((j, _)) = zones.iter().find(|(_, o)| o.name == zone.name) {
                return Err(Error::invalid(
                    format!("{field}.name"),
                    format!(
                        "'{}' is already the name of flow.zones[{j}]: give each zone its own name",
                        zone.name
                    ),
                ));
            }
            zones.push((k, zone));
        }
        zones.sort_by(|a, b| a.1.span[0].total_cmp(&b.1.span[0]));
        for w in zones.windows(2) {
            let ((_, a), (k, b)) = (&w[0], &w[1]);
            if b.span[0] < a.span[1] {
                return Err(Error::invalid(
                    format!("flow.zones[{k}].span"),
                    format!(
                        "[{}, {}] m overlaps zone '{}' [{}, {}] m: a stretch of tube is in one zone at most",
                        b.span[0], b.span[1], a.name, a.span[0], a.span[1]
                    ),
                ));
            }
        }
        let whole = line.stations(range.0, range.1, model);
        Ok(Flow {
            bundle,
            diameter,
            mass_per_length,
            connors_constant: self.connors_constant,
            zones: zones.into_iter().map(|(_, z)| z).collect(),
            whole,
            damping: self.damping.as_ref().map(|d| d.build()).transpose()?,
        })
    }
}

impl Line<'_> {
    /// `[s_min, s_max]` the zones may cover.
    fn range(&self, model: &Model) -> Result<(f64, f64)> {
        match self {
            Line::Tube(t, _) => Ok((0.0, t.structure.length())),
            Line::Points(a) => {
                let known: Vec<f64> = a.s.iter().flatten().copied().collect();
                if known.len() < 2 {
                    let names: Vec<&str> =
                        model.basis.points.iter().map(|p| p.name.as_str()).collect();
                    return Err(Error::invalid(
                        "flow",
                        format!(
                            "zones along a structure that is not a tube need the abscissa s (m along the tube) of its points {names:?}, at least 2 of them: give {}",
                            a.source
                        ),
                    ));
                }
                let lo = known.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = known.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                Ok((lo, hi))
            }
        }
    }

    /// The abscissa of point `name`; `field` is where the case names it.
    fn point_s(&self, name: &str, field: String, model: &Model) -> Result<f64> {
        let i = point_index(name, field.clone(), model)?;
        match self {
            Line::Tube(t, s) => {
                let pt = &t.structure.points[i];
                Ok(s[pt.node])
            }
            Line::Points(a) => a.s[i].ok_or_else(|| {
                Error::invalid(
                    field,
                    format!(
                        "point '{name}' has no abscissa s along the tube: give {}",
                        a.source
                    ),
                )
            }),
        }
    }

    /// Stations over `[s0, s1]`.
    fn stations(&self, s0: f64, s1: f64, model: &Model) -> Vec<Station> {
        match self {
            Line::Tube(t, _) => t.structure.flow_stations(&t.basis, s0, s1),
            Line::Points(a) => {
                // every point with an abscissa, along the tube; the tangent from the
                // neighbours' positions (zero when they coincide)
                let mut order: Vec<(f64, usize)> =
                    a.s.iter()
                        .enumerate()
                        .filter_map(|(i, s)| s.map(|s| (s, i)))
                        .collect();
                order.sort_by(|x, y| x.0.total_cmp(&y.0));
                let points = &model.basis.points;
                let n = order.len();
                let tangent = |k: usize| {
                    let (i, j) = (order[k.saturating_sub(1)].1, order[(k + 1).min(n - 1)].1);
                    let d = points[j].coords - points[i].coords;
                    let norm = d.norm();
                    if norm > 0.0 && norm.is_finite() {
                        d / norm
                    } else {
                        nalgebra::Vector3::zeros()
                    }
                };
                let inside: Vec<usize> = (0..n)
                    .filter(|&k| order[k].0 >= s0 && order[k].0 <= s1)
                    .collect();
                let s: Vec<f64> = inside.iter().map(|&k| order[k].0).collect();
                let weights = midpoint_weights(&s, s0, s1);
                inside
                    .iter()
                    .zip(weights)
                    .map(|(&k, weight)| Station {
                        s: order[k].0,
                        weight,
                        rows: points[order[k].1].rows.clone(),
                        tangent: tangent(k),
                    })
                    .collect()
            }
        }
    }
}

impl ZoneSection {
    fn build(
        &self,
        field: &str,
        line: &Line,
        (lo, hi): (f64, f64),
        model: &Model,
        factor: f64,
    ) -> Result<FlowZone> {
        let name_ok = !self.name.is_empty()
            && self
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'));
        if !name_ok {
            return Err(Error::invalid(
                format!("{field}.name"),
                format!(
                    "'{}': a zone name is letters, digits, '_', '-' and '.' (it heads columns and rows of the outputs)",
                    self.name
                ),
            ));
        }
        let span = match (&self.span, &self.from, &self.to) {
            (Some(s), None, None) => *s,
            (None, Some(a), Some(b)) => [
                line.point_s(a, format!("{field}.from"), model)?,
                line.point_s(b, format!("{field}.to"), model)?,
            ],
            _ => {
                return Err(Error::invalid(
                    field,
                    "give the stretch of tube either as span = [s0, s1] (m along the tube) or as from = \"point\", to = \"point\"",
                ));
            }
        };
        let [s0, s1] = span;
        let key = if self.span.is_some() { "span" } else { "from" };
        let tol = 1e-12 * (hi - lo).abs().max(1.0);
        if !(s0.is_finite() && s1.is_finite() && s0 < s1) {
            return Err(Error::invalid(
                format!("{field}.{key}"),
                format!(
                    "gives [{}, {}] m: the zone needs s0 < s1 along the tube",
                    number(s0),
                    number(s1)
                ),
            ));
        }
        if s0 < lo - tol || s1 > hi + tol {
            return Err(Error::invalid(
                format!("{field}.{key}"),
                format!(
                    "[{}, {}] m is outside the tube, which runs over [{}, {}] m: keep the zone on it",
                    number(s0),
                    number(s1),
                    number(lo),
                    number(hi)
                ),
            ));
        }
        let (s0, s1) = (s0.max(lo), s1.min(hi));
        let density = self.density(field)?;
        let profile = |rows: &Vec<[f64; 2]>, scale: f64| VelocityProfile::Table {
            s: rows.iter().map(|r| r[0]).collect(),
            velocity: rows.iter().map(|r| r[1] * scale).collect(),
        };
        let given = (
            self.velocity,
            &self.velocity_profile,
            self.mass_flux,
            &self.mass_flux_profile,
        );
        let (velocity, key) = match given {
            (Some(u), None, None, None) => (VelocityProfile::Constant(u), "velocity"),
            (None, Some(rows), None, None) => (profile(rows, 1.0), "velocity_profile"),
            // U = G / ρ: the mass flux is referred to the same section as the velocity
            // (velocity_definition), the density is the zone's (homogeneous) one
            (None, None, Some(g), None) => (VelocityProfile::Constant(g / density), "mass_flux"),
            (None, None, None, Some(rows)) => (profile(rows, 1.0 / density), "mass_flux_profile"),
            _ => {
                return Err(Error::invalid(
                    field,
                    "give one of velocity = U (m/s), velocity_profile = [[s, U], ...] (m, m/s; linear in s), mass_flux = G (kg/(m² s); U = G/ρ) or mass_flux_profile = [[s, G], ...]",
                ));
            }
        };
        let vfield = format!("{field}.{key}");
        // as given, then as gap velocities (an upstream velocity times P/(P − D) may overflow)
        velocity.validate(&vfield)?;
        let velocity = velocity.scaled(factor);
        velocity.validate(&vfield)?;
        let stations = line.stations(s0, s1, model);
        if let Line::Points(a) = line
            && stations.len() < 2
        {
            return Err(Error::invalid(
                format!("{field}.{key}"),
                format!(
                    "[{}, {}] m holds {} point(s) with an abscissa: at least 2 are needed to integrate along the zone (give more points, with {})",
                    number(s0),
                    number(s1),
                    stations.len(),
                    a.source
                ),
            ));
        }
        let fluid_elastic = match &self.fluid_elastic {
            Some(f) => Some(f.build(&format!("{field}.fluid_elastic"), &stations)?),
            None => None,
        };
        Ok(FlowZone {
            name: self.name.clone(),
            span: [s0, s1],
            density,
            velocity,
            stations,
            fluid_elastic,
        })
    }

    /// `ρ`, or `(1 − α) ρ_l + α ρ_g` (homogeneous two-phase density).
    fn density(&self, field: &str) -> Result<f64> {
        let check = |v: f64, key: &str, what: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(Error::invalid(
                    format!("{field}.{key}"),
                    format!("must be {what} (got {})", number(v)),
                ))
            }
        };
        let alpha = match (self.void_fraction, self.quality) {
            (Some(a), None) => Some((a, "void_fraction")),
            (None, Some(x)) => Some((x, "quality")),
            (None, None) => None,
            (Some(_), Some(_)) => {
                return Err(Error::invalid(
                    format!("{field}.quality"),
                    "give either void_fraction or quality (the homogeneous void fraction follows from it), not both",
                ));
            }
        };
        match (self.density, alpha, self.liquid_density, self.gas_density) {
            (Some(rho), None, None, None) => check(rho, "density", "a fluid density > 0 in kg/m³"),
            (None, Some((a, key)), Some(rl), Some(rg)) => {
                if !(a.is_finite() && (0.0..=1.0).contains(&a)) {
                    return Err(Error::invalid(
                        format!("{field}.{key}"),
                        format!("must be in [0, 1] (got {})", number(a)),
                    ));
                }
                let rl = check(rl, "liquid_density", "a density > 0 in kg/m³")?;
                let rg = check(rg, "gas_density", "a density > 0 in kg/m³")?;
                let alpha = if key == "quality" {
                    homogeneous_void_fraction(a, rl, rg)
                } else {
                    a
                };
                Ok(homogeneous_density(alpha, rl, rg))
            }
            _ => Err(Error::invalid(
                field,
                "give either density = ρ (kg/m³) or void_fraction (or quality), liquid_density and gas_density (homogeneous two-phase density (1 − α) ρ_l + α ρ_g)",
            )),
        }
    }
}
