//! Cross flow along a tube: flow zones (a stretch of the tube, a fluid density, a gap velocity
//! that may vary along it, the mode shapes sampled along it) and the Connors fluid-elastic
//! stability check of every mode. `docs/FLOW.md` states the definitions, their sources and
//! their limits.
//!
//! A zone holds what a per-zone force model needs to project a force per unit length on the
//! modes once, before the run: quadrature stations `(s_k, w_k)` along its stretch with the
//! translation rows `Φ(s_k)` (3 × p) and the tube's unit tangent `t(s_k)` there, so that
//! `∫_zone g(s) φ_i(s)·φ_j(s) ds ≈ Σ_k w_k g(s_k) φ_i(s_k)·φ_j(s_k)`.
//!
//! Connors check (Pettigrew & Taylor 2003, Part 1, eqs. for the effective velocity; ASME
//! Boiler and Pressure Vessel Code, Section III, Appendix N-1330), per mode `i`:
//!
//! ```text
//! U_eff² = ∫ ρ(s) U(s)² φ(s)² ds / (ρ_ref ∫ (m(s)/m_ref) φ(s)² ds)
//! U_c    = K f D √(m_ref δ / (ρ_ref D²)),   δ = 2π ζ
//! ratio  = U_eff / U_c
//! ```
//!
//! with `φ(s)²` the squared transverse displacement (both directions normal to the tube's axis),
//! `U` the gap velocity, the numerator over the zones and the denominator over the whole tube,
//! `ρ_ref` the density of the zone with the largest `∫ρU²φ²` of the mode and `m_ref` the
//! (uniform) mass per unit length of the tube with its internal fluid and hydrodynamic mass.

use nalgebra::Vector3;

use crate::loads::flow_damping::{DampingModels, DampingTerms};
use crate::loads::fluid_elastic::{FlowNode, FluidElastic, QuasiSteady, ReducedVelocityTable};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result, number};
pub use crate::structure::line::Station;
use crate::structure::modal::ModalBasis;

/// Tube bundle pattern (the angle between the flow and the pitch lines).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BundlePattern {
    /// Square, flow along a pitch line (90°).
    InLineSquare,
    /// Square rotated by 45°.
    RotatedSquare,
    /// Triangle with the flow normal to a side (30°).
    NormalTriangle,
    /// Triangle with the flow parallel to a side (60°).
    ParallelTriangle,
}

/// What velocity the case gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VelocityDefinition {
    /// The gap velocity `U_g = U_∞ P/(P − D)` (the "pitch velocity" `V_p` of Pettigrew &
    /// Taylor, the "gap velocity" of ASME N-1331), the velocity of the Connors check.
    Gap,
    /// The upstream (free-stream, approach) velocity `U_∞`; the gap velocity is
    /// `U_∞ P/(P − D)`.
    Upstream,
}

/// The bundle's geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bundle {
    /// Pattern.
    pub pattern: BundlePattern,
    /// Pitch-to-diameter ratio `P/D` (> 1).
    pub pitch_ratio: f64,
}

impl Bundle {
    /// `U_g / U_∞ = P/(P − D) = r/(r − 1)`, `r = P/D`.
    pub fn gap_factor(&self) -> f64 {
        self.pitch_ratio / (self.pitch_ratio - 1.0)
    }
}

/// Gap velocity along a zone, m/s.
#[derive(Debug, Clone, PartialEq)]
pub enum VelocityProfile {
    /// The same everywhere.
    Constant(f64),
    /// `(s_k, U_k)` with strictly increasing `s_k`, linear between rows, held at the end values
    /// beyond them.
    Table {
        /// Abscissae along the tube, m.
        s: Vec<f64>,
        /// Gap velocities, m/s (≥ 0).
        velocity: Vec<f64>,
    },
}

impl VelocityProfile {
    /// `U(s)`, m/s.
    pub fn at(&self, s: f64) -> f64 {
        match self {
            VelocityProfile::Constant(u) => *u,
            VelocityProfile::Table { s: xs, velocity } => {
                let n = xs.len();
                if s <= xs[0] {
                    return velocity[0];
                }
                if s >= xs[n - 1] {
                    return velocity[n - 1];
                }
                let i = xs.partition_point(|&x| x <= s);
                let (x0, x1, u0, u1) = (xs[i - 1], xs[i], velocity[i - 1], velocity[i]);
                u0 + (u1 - u0) * (s - x0) / (x1 - x0)
            }
        }
    }

    /// The velocity if it is the same everywhere.
    pub fn constant(&self) -> Option<f64> {
        match self {
            VelocityProfile::Constant(u) => Some(*u),
            VelocityProfile::Table { .. } => None,
        }
    }

    /// Multiplies every velocity by `factor`.
    pub fn scaled(self, factor: f64) -> Self {
        match self {
            VelocityProfile::Constant(u) => VelocityProfile::Constant(u * factor),
            VelocityProfile::Table { s, velocity } => VelocityProfile::Table {
                s,
                velocity: velocity.into_iter().map(|u| u * factor).collect(),
            },
        }
    }

    /// Checks the values; `field` is where the case gives them.
    pub fn validate(&self, field: &str) -> Result<()> {
        let check_u = |u: f64, field: String| {
            if u.is_finite() && u >= 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(
                    field,
                    format!("must be a finite velocity ≥ 0 in m/s (got {})", number(u)),
                ))
            }
        };
        match self {
            VelocityProfile::Constant(u) => check_u(*u, field.to_string()),
            VelocityProfile::Table { s, velocity } => {
                if s.len() < 2 || s.len() != velocity.len() {
                    return Err(Error::invalid(
                        field,
                        format!(
                            "needs at least 2 rows [s, U] to interpolate (got {})",
                            s.len()
                        ),
                    ));
                }
                for k in 0..s.len() {
                    let row = format!("{field}[{k}]");
                    if !s[k].is_finite() {
                        return Err(Error::invalid(
                            row,
                            format!("s = {} must be a finite abscissa in m", number(s[k])),
                        ));
                    }
                    if k > 0 && !(s[k] > s[k - 1]) {
                        return Err(Error::invalid(
                            row,
                            format!(
                                "s = {} m is not after the previous row's {} m: the rows [s, U] must have strictly increasing s",
                                number(s[k]),
                                number(s[k - 1])
                            ),
                        ));
                    }
                    check_u(velocity[k], row)?;
                }
                Ok(())
            }
        }
    }
}

/// Homogeneous void fraction of a two-phase flow of steam quality `x` (mass fraction of gas),
/// liquid and gas densities `ρ_l`, `ρ_g` (no slip between the phases):
/// `ε = x ρ_l / (x ρ_l + (1 − x) ρ_g)` (docs/FLOW.md, "Two-phase flow").
pub fn homogeneous_void_fraction(quality: f64, liquid: f64, gas: f64) -> f64 {
    quality * liquid / (quality * liquid + (1.0 - quality) * gas)
}

/// Homogeneous density `ρ_h = ε ρ_g + (1 − ε) ρ_l` of void fraction `ε`, kg/m³.
pub fn homogeneous_density(void_fraction: f64, liquid: f64, gas: f64) -> f64 {
    (1.0 - void_fraction) * liquid + void_fraction * gas
}

/// Quadrature weights of stations at the sorted abscissae `s` covering `[a, b]` (a midpoint
/// rule: each station carries from the midpoint with its neighbour before to the one after,
/// the first from `a`, the last to `b`).
pub fn midpoint_weights(s: &[f64], a: f64, b: f64) -> Vec<f64> {
    let n = s.len();
    (0..n)
        .map(|k| {
            let lo = if k == 0 { a } else { 0.5 * (s[k - 1] + s[k]) };
            let hi = if k + 1 == n {
                b
            } else {
                0.5 * (s[k] + s[k + 1])
            };
            hi - lo
        })
        .collect()
}

/// The fluid-elastic force model of a zone (THEORY §13, docs/FLOW.md).
#[derive(Debug, Clone, PartialEq)]
pub enum ZoneFluidElastic {
    /// The quasi-steady model with a time lag.
    QuasiSteady {
        /// `C_L'`, `C_D'`, `C_D`, `μ_L`, `μ_D`.
        coefficients: QuasiSteady,
        /// Direction of the flow (drag); the lift is across it and the tube's axis.
        flow_direction: Vector3<f64>,
        /// A velocity profile's zone is cut into this many equal stretches, each with the delay
        /// `μ D / U` of the velocity at its middle (the force itself uses the local `U`).
        delay_segments: usize,
    },
    /// Tabulated modal damping and stiffness per unit length against the reduced velocity.
    Table(ReducedVelocityTable),
}

/// A stretch of the tube in a uniform-density cross flow.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowZone {
    /// Name (letters, digits, `_`, `-`, `.`).
    pub name: String,
    /// `[s0, s1]`, m along the tube.
    pub span: [f64; 2],
    /// Fluid density (homogeneous two-phase density allowed), kg/m³.
    pub density: f64,
    /// Gap velocity along the zone.
    pub velocity: VelocityProfile,
    /// Quadrature stations over the span with the mode shapes.
    pub stations: Vec<Station>,
    /// Its fluid-elastic forces, if any.
    pub fluid_elastic: Option<ZoneFluidElastic>,
}

impl FlowZone {
    /// `(∫ ρ U² φ_i² ds, ∫ φ_i² ds)` over the zone for mode `i`.
    pub fn integrals(&self, i: usize) -> (f64, f64) {
        let (mut a, mut b) = (0.0, 0.0);
        for st in &self.stations {
            let u = self.velocity.at(st.s);
            let w = st.weight * st.transverse_square(i);
            a += self.density * u * u * w;
            b += w;
        }
        (a, b)
    }
}

/// The flow over a tube: bundle, zones, and what the Connors check needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Flow {
    /// Bundle geometry.
    pub bundle: Bundle,
    /// Tube outer diameter `D`, m.
    pub diameter: f64,
    /// `m_ref`: the tube's mass per unit length (tube, internal fluid, hydrodynamic mass), kg/m,
    /// uniform along the tube.
    pub mass_per_length: f64,
    /// Connors' constant `K`.
    pub connors_constant: f64,
    /// The zones, sorted along the tube, not overlapping.
    pub zones: Vec<FlowZone>,
    /// Stations over the whole tube (the denominator `∫ φ² ds` of `U_eff²`).
    pub whole: Vec<Station>,
    /// The damping models added to the basis's damping in the check (`[flow.damping]`).
    pub damping: Option<DampingModels>,
}

/// `U_c = K f D √(m δ / (ρ D²))`, `δ = 2π ζ` (Connors; Pettigrew & Taylor 2003): the critical
/// gap velocity of fluid-elastic instability, m/s, of a mode of frequency `f` (Hz) and damping
/// ratio `ζ`, mass per unit length `m` (kg/m), fluid density `ρ` (kg/m³), diameter `D` (m).
pub fn connors_critical_velocity(f: f64, zeta: f64, m: f64, rho: f64, d: f64, k: f64) -> f64 {
    let delta = std::f64::consts::TAU * zeta;
    k * f * d * (m * delta / (rho * d * d)).sqrt()
}

/// The Connors check of one mode.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeStability {
    /// Mode number, from 1.
    pub mode: usize,
    /// Natural frequency `f`, Hz.
    pub frequency_hz: f64,
    /// Damping ratio `ζ` (`δ = 2πζ`).
    pub damping_ratio: f64,
    /// The zone whose density is `ρ_ref` (largest `∫ρU²φ²`).
    pub reference_zone: String,
    /// `ρ_ref`, kg/m³.
    pub reference_density: f64,
    /// `U_eff`, m/s.
    pub effective_velocity: f64,
    /// `U_c`, m/s.
    pub critical_velocity: f64,
    /// `U_eff / U_c`; `None` when undefined (`U_eff = U_c = 0`).
    pub ratio: Option<f64>,
    /// The terms of `damping_ratio` (their sum), with `[flow.damping]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping_terms: Option<DampingTerms>,
    /// The support condition of the mode: `support_inactive` (the basis's modes), or the
    /// name of a `[[stability.conditions]]` (docs/FLOW.md).
    pub condition: String,
    /// The mode's plane, when the structure has one (docs/FLOW.md).
    pub plane: Option<Plane>,
    /// The share of the mode's transverse displacement normal to the structure's plane,
    /// `∫ (u⊥·n)² ds / ∫ |u⊥|² ds` over the tube, when it has a plane.
    pub out_of_plane_share: Option<f64>,
}

/// The plane a mode moves in, from its [`ModeStability::out_of_plane_share`] `q`:
/// out of plane when `q ≥ 0.9`, in plane when `q ≤ 0.1`, mixed between.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Plane {
    /// In the structure's plane (`q ≤ 0.1`).
    InPlane,
    /// Normal to it (`q ≥ 0.9`).
    OutOfPlane,
    /// Neither.
    Mixed,
}

impl Plane {
    /// The class of a mode whose out-of-plane share is `q`.
    pub fn of_share(q: f64) -> Self {
        if q >= 0.9 {
            Plane::OutOfPlane
        } else if q <= 0.1 {
            Plane::InPlane
        } else {
            Plane::Mixed
        }
    }

    /// `in_plane`, `out_of_plane`, `mixed`.
    pub fn name(self) -> &'static str {
        match self {
            Plane::InPlane => "in_plane",
            Plane::OutOfPlane => "out_of_plane",
            Plane::Mixed => "mixed",
        }
    }
}

impl ModeStability {
    /// `U_eff / U_c > 1` (an undamped mode in a flow is unstable).
    pub fn unstable(&self) -> bool {
        self.ratio.is_some_and(|r| r > 1.0)
    }
}

/// The Connors check of every mode, with the constants used.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StabilityReport {
    /// `K`.
    pub connors_constant: f64,
    /// `D`, m.
    pub diameter: f64,
    /// `m_ref`, kg/m.
    pub mass_per_length: f64,
    /// Per mode.
    pub modes: Vec<ModeStability>,
}

/// Columns of [`StabilityReport::to_csv`].
pub const STABILITY_CSV_HEADER: &str = "mode,frequency_hz,damping_ratio,reference_zone,reference_density,effective_velocity,critical_velocity,ratio,condition,plane,out_of_plane_share";

/// The name of the condition of the basis's own modes (the supports inactive).
pub const SUPPORT_INACTIVE: &str = "support_inactive";

impl StabilityReport {
    /// The modes whose ratio exceeds 1.
    pub fn unstable(&self) -> impl Iterator<Item = &ModeStability> {
        self.modes.iter().filter(|m| m.unstable())
    }

    /// The largest `U_eff / U_c` over the modes (`∞` for an undamped mode in a flow); `None`
    /// when no mode has a ratio (no modes, or `U_eff = U_c = 0` for all).
    pub fn max_ratio(&self) -> Option<f64> {
        self.modes.iter().filter_map(|m| m.ratio).reduce(f64::max)
    }

    /// One row per mode under [`STABILITY_CSV_HEADER`]; numbers in Rust's shortest round-trip
    /// form, an undefined or infinite ratio as an empty field or `inf`. Zone names need no
    /// quoting (letters, digits, `_`, `-`, `.` only).
    pub fn to_csv(&self) -> String {
        let mut text = format!("{STABILITY_CSV_HEADER}\n");
        for m in &self.modes {
            text.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{}\n",
                m.mode,
                m.frequency_hz,
                m.damping_ratio,
                m.reference_zone,
                m.reference_density,
                m.effective_velocity,
                m.critical_velocity,
                m.ratio.map(|r| r.to_string()).unwrap_or_default(),
                m.condition,
                m.plane.map(Plane::name).unwrap_or_default(),
                m.out_of_plane_share
                    .map(|r| r.to_string())
                    .unwrap_or_default()
            ));
        }
        text
    }
}

impl Flow {
    /// The Connors check of every mode of `basis` (the module documentation has the formulas).
    /// Modes are those whose rows the stations hold (the basis's); their condition is
    /// [`SUPPORT_INACTIVE`], no plane.
    pub fn connors(&self, basis: &ModalBasis) -> StabilityReport {
        self.connors_in(basis, SUPPORT_INACTIVE, None)
    }

    /// [`Flow::connors`] with the modes' condition named `condition` and, when the structure
    /// has a plane of unit normal `plane_normal`, each mode's out-of-plane share and plane.
    pub fn connors_in(
        &self,
        basis: &ModalBasis,
        condition: &str,
        plane_normal: Option<Vector3<f64>>,
    ) -> StabilityReport {
        let modes = (0..basis.modes())
            .map(|i| {
                // ∫ m/m_ref φ² over the whole tube: m is uniform, the ratio is 1
                let norm: f64 = self
                    .whole
                    .iter()
                    .map(|st| st.weight * st.transverse_square(i))
                    .sum();
                let mut numerator = 0.0;
                // ρ_ref: the zone of largest ∫ρU²φ² (ties: the first; a mode no zone loads:
                // the zone of largest ∫ρφ²)
                let mut reference = (f64::NEG_INFINITY, f64::NEG_INFINITY, 0usize);
                for (z, zone) in self.zones.iter().enumerate() {
                    let (a, b) = zone.integrals(i);
                    numerator += a;
                    let key = (a, zone.density * b, z);
                    if (key.0, key.1) > (reference.0, reference.1) {
                        reference = key;
                    }
                }
                let zone = &self.zones[reference.2];
                let rho_ref = zone.density;
                let effective = if numerator > 0.0 && norm > 0.0 {
                    (numerator / (rho_ref * norm)).sqrt()
                } else {
                    0.0
                };
                let f = basis.omega[i] / std::f64::consts::TAU;
                // the basis's damping, plus the models' ([flow.damping])
                let damping_terms = self.damping.as_ref().map(|d| {
                    let zeta = basis.damping_ratio[i];
                    d.terms(i, zeta, f, self.diameter, self.mass_per_length)
                });
                let zeta = damping_terms.map_or(basis.damping_ratio[i], |t| t.total());
                let critical = connors_critical_velocity(
                    f,
                    zeta,
                    self.mass_per_length,
                    rho_ref,
                    self.diameter,
                    self.connors_constant,
                );
                let ratio = if effective == 0.0 {
                    (critical > 0.0).then_some(0.0)
                } else {
                    Some(effective / critical)
                };
                let out_of_plane_share = plane_normal.map(|n| self.out_of_plane_share(i, &n));
                ModeStability {
                    mode: i + 1,
                    frequency_hz: f,
                    damping_ratio: zeta,
                    reference_zone: zone.name.clone(),
                    reference_density: rho_ref,
                    effective_velocity: effective,
                    critical_velocity: critical,
                    ratio,
                    condition: condition.to_string(),
                    plane: out_of_plane_share.map(Plane::of_share),
                    out_of_plane_share,
                    damping_terms,
                }
            })
            .collect();
        StabilityReport {
            connors_constant: self.connors_constant,
            diameter: self.diameter,
            mass_per_length: self.mass_per_length,
            modes,
        }
    }

    /// `∫ (u⊥·n)² ds / ∫ |u⊥|² ds` of mode `i` over the whole tube (`u⊥` the displacement
    /// normal to the axis, `n` the unit normal of the structure's plane); 0 for a mode
    /// without transverse displacement.
    pub fn out_of_plane_share(&self, i: usize, n: &Vector3<f64>) -> f64 {
        let (mut out, mut all) = (0.0, 0.0);
        for st in &self.whole {
            let u = st.translation(i);
            let t = st.tangent;
            let normal = u - t * u.dot(&t);
            out += st.weight * normal.dot(n).powi(2);
            all += st.weight * normal.norm_squared();
        }
        if all > 0.0 { out / all } else { 0.0 }
    }

    /// The same flow with the stations of its zones and of the whole tube (over `range`)
    /// sampled again by `stations(s0, s1)`: on the modes of another basis of the same tube.
    pub fn resampled(
        &self,
        range: (f64, f64),
        stations: impl Fn(f64, f64) -> Vec<Station>,
    ) -> Flow {
        Flow {
            zones: self
                .zones
                .iter()
                .map(|z| FlowZone {
                    stations: stations(z.span[0], z.span[1]),
                    ..z.clone()
                })
                .collect(),
            whole: stations(range.0, range.1),
            ..self.clone()
        }
    }

    /// The fluid-elastic forces of the zones that have them, projected on the modes of
    /// frequencies `frequencies_hz` (THEORY §13): `None` when no zone has any.
    pub fn fluid_elastic(&self, frequencies_hz: &[f64]) -> Option<FluidElastic> {
        let p = frequencies_hz.len();
        let mut total: Option<FluidElastic> = None;
        for zone in &self.zones {
            let Some(model) = &zone.fluid_elastic else {
                continue;
            };
            let name = format!("flow.zones.{}", zone.name);
            let (s0, s1) = (zone.span[0], zone.span[1]);
            let segments = match model {
                ZoneFluidElastic::QuasiSteady { delay_segments, .. }
                    if zone.velocity.constant().is_none() =>
                {
                    (*delay_segments).max(1)
                }
                _ => 1,
            };
            let (mu, direction) = match model {
                ZoneFluidElastic::QuasiSteady {
                    coefficients,
                    flow_direction,
                    ..
                } => (
                    [coefficients.mu_lift, coefficients.mu_drag],
                    *flow_direction,
                ),
                ZoneFluidElastic::Table(_) => ([0.0; 2], Vector3::zeros()),
            };
            let nodes: Vec<FlowNode> = zone
                .stations
                .iter()
                .map(|st| {
                    let u = zone.velocity.at(st.s);
                    let k = (((st.s - s0) / (s1 - s0)) * segments as f64).floor() as usize;
                    let k = k.min(segments - 1);
                    let mid = s0 + (k as f64 + 0.5) * (s1 - s0) / segments as f64;
                    let u_delay = if segments == 1 {
                        zone.velocity.constant().unwrap_or(u)
                    } else {
                        zone.velocity.at(mid)
                    };
                    let (lift, drag) = cross_flow_axes(&st.tangent, &direction);
                    let delay = |mu: f64| {
                        if u_delay > 0.0 {
                            mu * self.diameter / u_delay
                        } else {
                            0.0
                        }
                    };
                    FlowNode {
                        weight: st.weight,
                        density: zone.density,
                        velocity: u,
                        delay_lift: delay(mu[0]),
                        delay_drag: delay(mu[1]),
                        diameter: self.diameter,
                        lift,
                        drag,
                        rows: &st.rows,
                    }
                })
                .collect();
            let fe = match model {
                ZoneFluidElastic::QuasiSteady { coefficients, .. } => {
                    FluidElastic::quasi_steady(&name, coefficients, &nodes, p)
                }
                ZoneFluidElastic::Table(table) => {
                    FluidElastic::tabulated(&name, table, &nodes, frequencies_hz)
                }
            };
            match &mut total {
                Some(t) => t.merge(fe),
                None => total = Some(fe),
            }
        }
        total
    }

    /// The zone named `name`.
    pub fn zone(&self, name: &str) -> Option<&FlowZone> {
        self.zones.iter().find(|z| z.name == name)
    }
}

/// The lift and drag directions at a station of axis `tangent` for the flow `direction`:
/// drag = the flow's direction made normal to the axis, lift = axis × drag. For the tabulated
/// model (`direction` zero), any two unit vectors normal to the axis and to each other (its
/// coefficients act on the whole transverse displacement).
fn cross_flow_axes(
    tangent: &Vector3<f64>,
    direction: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let t = if tangent.norm() > 0.0 {
        tangent.normalize()
    } else {
        Vector3::zeros()
    };
    let d = if direction.norm() > 0.0 {
        *direction
    } else {
        // a vector not along the axis
        if t.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        }
    };
    let drag = (d - t * d.dot(&t)).normalize();
    let lift = if t.norm() > 0.0 {
        t.cross(&drag)
    } else {
        // no axis known: the lift is any unit vector normal to the drag
        let e = if drag.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        (e - drag * e.dot(&drag)).normalize()
    };
    (lift, drag)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flow_profile_interpolates_and_holds_its_ends() {
        let p = VelocityProfile::Table {
            s: vec![1.0, 2.0, 4.0],
            velocity: vec![1.0, 3.0, 2.0],
        };
        assert_eq!(p.at(0.0), 1.0);
        assert_eq!(p.at(1.5), 2.0);
        assert_eq!(p.at(3.0), 2.5);
        assert_eq!(p.at(9.0), 2.0);
        assert!(p.validate("v").is_ok());
        let bad = VelocityProfile::Table {
            s: vec![1.0, 1.0],
            velocity: vec![1.0, 1.0],
        };
        assert_eq!(bad.validate("v").unwrap_err().field(), Some("v[1]"));
    }

    #[test]
    fn flow_connors_formula_by_hand() {
        // K = 3, f = 10 Hz, ζ = 0.01, m = 0.5 kg/m, ρ = 750 kg/m³, D = 0.019 m:
        // δ = 0.0628318531, mδ/(ρD²) = 0.0314159265/0.27075 = 0.116032969,
        // √ = 0.340636125, U_c = 3 · 10 · 0.019 · 0.340636125 = 0.194162591 m/s
        let u = connors_critical_velocity(10.0, 0.01, 0.5, 750.0, 0.019, 3.0);
        assert!((u - 0.194_162_591).abs() < 1e-8, "{u}");
    }

    #[test]
    fn flow_gap_factor() {
        let b = Bundle {
            pattern: BundlePattern::RotatedSquare,
            pitch_ratio: 1.5,
        };
        assert_eq!(b.gap_factor(), 3.0);
    }
}
