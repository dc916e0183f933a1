//! The damping terms of a fluid-elastic design check (docs/FLOW.md, "Damping models"): per
//! mode of frequency `f`, the damping ratio the Connors check uses is the basis's plus the
//! models':
//!
//! ```text
//! ζ = ζ_basis + ζ_v(f) + ζ_TP + ζ_F + ζ_SF(f)
//! ζ_v(f)  = (π ρ D / (2 m)) √(ν / (π f)) · (1 + (D/D_e)³) / (1 − (D/D_e)²)²
//! ζ_SF(f) = ζ_SF,ref · f_ref / f
//! ```
//!
//! - `ζ_v`: viscous damping of a cylinder vibrating in a still liquid of density `ρ` and
//!   kinematic viscosity `ν`, in the thin Stokes-layer limit (`δ = √(2ν/ω) ≪ D`), confined in
//!   a concentric cylinder of diameter `D_e`. Derived in docs/FLOW.md from the dissipation of
//!   the oscillating boundary layers on both walls under the potential-flow slip of the
//!   annulus (`c = 2π ρ (D/2) ω δ` per unit length unconfined, `ζ = c / (2 m ω)`); the form
//!   the design guides' viscous term is recalled to have (Rogers et al. 1984, not read
//!   here). `m` is the tube's mass per unit length.
//! - `ζ_TP` (two-phase), `ζ_F` (friction at the supports): ratios the user takes from a design
//!   guide; no formula was readable (docs/FLOW.md says what was searched).
//! - `ζ_SF`: squeeze-film damping at the supports, inversely proportional to the frequency (as
//!   Pettigrew, Rogers & Axisa 2011 state), scaled from the user's value at `f_ref`.

use serde::Serialize;

/// Viscous damping in a still liquid (see the module's documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViscousDamping {
    /// Liquid density `ρ`, kg/m³.
    pub density: f64,
    /// Kinematic viscosity `ν`, m²/s.
    pub kinematic_viscosity: f64,
    /// `D_e / D` of the confinement (`∞`: unconfined).
    pub confinement: f64,
}

/// Support damping inversely proportional to the frequency: `ζ = ratio · frequency / f`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SqueezeFilm {
    /// `ζ_SF,ref` at the reference frequency.
    pub ratio: f64,
    /// `f_ref`, Hz.
    pub frequency_hz: f64,
}

/// The damping models of `[flow.damping]`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DampingModels {
    /// `ζ_v(f)`.
    pub viscous: Option<ViscousDamping>,
    /// `ζ_TP`.
    pub two_phase: Option<f64>,
    /// `ζ_F`.
    pub friction: Option<f64>,
    /// `ζ_SF(f)`.
    pub squeeze_film: Option<SqueezeFilm>,
    /// Add the fluid terms (viscous, two-phase) to the run's modal damping.
    pub in_run: bool,
    /// The basis's own damping ratios, when the fluid terms (viscous, two-phase) were added to
    /// the run's modal damping (`in_run = true`): the check's basis term, so that they are not
    /// counted twice.
    pub structural: Option<Vec<f64>>,
}

/// The damping ratio of one mode, term by term (reported per mode in `stability.json`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DampingTerms {
    /// The basis's damping ratio (without the fluid terms the run may add).
    pub basis: f64,
    /// `ζ_v`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub viscous: Option<f64>,
    /// `ζ_TP`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub two_phase: Option<f64>,
    /// `ζ_F`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// `ζ_SF`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub squeeze_film: Option<f64>,
}

impl DampingTerms {
    /// The sum of the terms.
    pub fn total(&self) -> f64 {
        self.basis
            + [
                self.viscous,
                self.two_phase,
                self.friction,
                self.squeeze_film,
            ]
            .iter()
            .flatten()
            .sum::<f64>()
    }

    /// The fluid's terms (viscous and two-phase): what `in_run` adds to the run.
    pub fn fluid(&self) -> f64 {
        self.viscous.unwrap_or(0.0) + self.two_phase.unwrap_or(0.0)
    }
}

/// `ζ_v = (π ρ D / (2 m)) √(ν / (π f)) · (1 + (D/D_e)³) / (1 − (D/D_e)²)²` (module
/// documentation); `confinement = D_e/D` (`∞`: unconfined). Zero for `f ≤ 0`.
pub fn viscous_damping_ratio(
    f: f64,
    viscous: &ViscousDamping,
    diameter: f64,
    mass_per_length: f64,
) -> f64 {
    if !(f > 0.0) {
        return 0.0;
    }
    let r = 1.0 / viscous.confinement;
    let confined = (1.0 + r.powi(3)) / (1.0 - r * r).powi(2);
    std::f64::consts::PI * viscous.density * diameter / (2.0 * mass_per_length)
        * (viscous.kinematic_viscosity / (std::f64::consts::PI * f)).sqrt()
        * confined
}

impl DampingModels {
    /// With `in_run`: adds the fluid terms of each mode to `damping_ratio` (the run's modal
    /// damping, modes of angular frequencies `omega`), keeping the ratios as they were for the
    /// check's basis term. Nothing without `in_run`.
    pub fn add_to_run(
        &mut self,
        omega: &[f64],
        damping_ratio: &mut [f64],
        diameter: f64,
        mass_per_length: f64,
    ) {
        if !self.in_run {
            return;
        }
        self.structural = Some(damping_ratio.to_vec());
        for (i, (w, z)) in omega.iter().zip(damping_ratio.iter_mut()).enumerate() {
            let f = w / std::f64::consts::TAU;
            *z += self.terms(i, *z, f, diameter, mass_per_length).fluid();
        }
    }

    /// The terms of mode `i` of frequency `f` (Hz) whose basis damping ratio is `basis`, for a
    /// tube of diameter `diameter` (m) and mass per length `mass_per_length` (kg/m).
    pub fn terms(
        &self,
        i: usize,
        basis: f64,
        f: f64,
        diameter: f64,
        mass_per_length: f64,
    ) -> DampingTerms {
        DampingTerms {
            basis: self
                .structural
                .as_ref()
                .and_then(|s| s.get(i).copied())
                .unwrap_or(basis),
            viscous: self
                .viscous
                .map(|v| viscous_damping_ratio(f, &v, diameter, mass_per_length)),
            two_phase: self.two_phase,
            friction: self.friction,
            squeeze_film: self.squeeze_film.map(|s| {
                if f > 0.0 {
                    s.ratio * s.frequency_hz / f
                } else {
                    0.0
                }
            }),
        }
    }
}
