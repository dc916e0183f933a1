//! The modal basis: frequencies, damping ratios and the mode-shape rows of the few physical
//! points that matter (THEORY §1).
//!
//! The structure is `M ü + C u̇ + K u = F + R` reduced by `u = Φ q` with mass-normalised modes,
//! so that in modal coordinates `q̈ + C_m q̇ + Ω² q = Φᵀ(F + R)` with `Ω² = diag(ω_i²)` and
//! `C_m = diag(2 ξ_i ω_i)`. Only the rows `Φ_c` (3 × p, translations) of contact, load and
//! observation points are stored: recombination `u_c = Φ_c q` and projection `f_q = Φ_cᵀ f_c`
//! never touch the full physical vector.

use nalgebra::Vector3;

use crate::error::{Error, Result, number};

/// A named physical point of the structure and its mode-shape rows.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Name used by contacts, loads and initial conditions.
    pub name: String,
    /// Reference (undeformed) position, m.
    pub coords: Vector3<f64>,
    /// Translation rows, row-major 3 × p: `rows[d * p + i]` = component `d` of mode `i` at the point.
    pub rows: Vec<f64>,
    /// Rotation rows, same layout (`θ_c = Θ_c q`, rad), or empty when the basis has none
    /// (point masses, bases imported without them). A contact at the tube surface needs them.
    pub rotations: Vec<f64>,
}

/// Properties of an analytic pinned–pinned beam ([`ModalBasis::pinned_beam`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinnedBeam {
    /// Length `L`, m.
    pub length: f64,
    /// Bending stiffness `E I`, N·m².
    pub bending_stiffness: f64,
    /// Mass per unit length `ρA` (structure, inner fluid and added mass), kg/m.
    pub mass_per_length: f64,
    /// Bending modes in each of the planes (x, y) and (x, z).
    pub modes_per_plane: usize,
    /// Axial stiffness `E A`, N (used when `axial_modes > 0`).
    pub axial_stiffness: f64,
    /// Axial modes.
    pub axial_modes: usize,
    /// Damping ratio of every mode.
    pub damping_ratio: f64,
}

/// A mass-normalised modal basis restricted to named points.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalBasis {
    /// Circular frequencies `ω_i`, rad/s (0 for rigid-body modes).
    pub omega: Vec<f64>,
    /// Modal damping ratios `ξ_i` (dimensionless).
    pub damping_ratio: Vec<f64>,
    /// Points with their rows.
    pub points: Vec<Point>,
    /// Modal participation factors `Γ = Φᵀ M r` (row-major 3 × p: `participation[d * p + i]`
    /// for a unit translation `r` of the whole structure along axis `d`), or empty when not
    /// known. A base acceleration `a(t)` loads the modes with `−Γ a(t)`.
    pub participation: Vec<f64>,
}

impl ModalBasis {
    /// Number of modes `p`.
    pub fn modes(&self) -> usize {
        self.omega.len()
    }

    /// Index of a point by name.
    pub fn point_index(&self, name: &str) -> Option<usize> {
        self.points.iter().position(|pt| pt.name == name)
    }

    /// A free point mass `m`: three rigid-body modes `Φ = I/√m` (THEORY §1).
    pub fn point_mass(mass: f64, name: &str, coords: Vector3<f64>) -> Result<Self> {
        if !(mass.is_finite() && mass > 0.0) {
            return Err(Error::invalid(
                "structure.mass",
                format!("must be a positive mass in kg (got {})", number(mass)),
            ));
        }
        let s = 1.0 / mass.sqrt();
        let rows = vec![s, 0.0, 0.0, 0.0, s, 0.0, 0.0, 0.0, s];
        let participation = rows.iter().map(|v| v * mass).collect();
        Ok(Self {
            omega: vec![0.0; 3],
            damping_ratio: vec![0.0; 3],
            points: vec![Point {
                name: name.to_string(),
                coords,
                rows,
                rotations: Vec::new(),
            }],
            participation,
        })
    }

    /// Analytic modes of a pinned–pinned Euler–Bernoulli beam along x, bending in y and z, and
    /// optionally axial.
    ///
    /// Bending mode `k` (k = 1..n) in each plane: `φ_k(x) = √(2/(ρA L)) sin(kπx/L)`,
    /// `ω_k = (kπ/L)² √(EI/ρA)`; axial mode `k` (ends held axially):
    /// same shape along x, `ω_k = (kπ/L) √(EA/ρA)`. Modes are numbered y₁, z₁, y₂, z₂, …, y_n,
    /// z_n, then x₁ … x_na. Used by the multi-contact example and the synthetic benchmark case,
    /// where an exact basis with many modes and points is wanted without a finite-element model.
    pub fn pinned_beam(beam: &PinnedBeam, stations: &[(String, f64)]) -> Result<Self> {
        let positive = |v: f64, field: &str, unit: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(
                    field,
                    format!("must be positive, in {unit} (got {})", number(v)),
                ))
            }
        };
        positive(beam.length, "structure.length", "m")?;
        positive(
            beam.bending_stiffness,
            "structure.bending_stiffness",
            "N·m²",
        )?;
        positive(beam.mass_per_length, "structure.mass_per_length", "kg/m")?;
        if beam.modes_per_plane == 0 {
            return Err(Error::invalid(
                "structure.modes_per_plane",
                "must be at least 1",
            ));
        }
        if beam.axial_modes > 0 {
            positive(beam.axial_stiffness, "structure.axial_stiffness", "N (E A)")?;
        }
        check_damping_ratio(beam.damping_ratio, "structure.damping_ratio")?;
        let (length, n, na) = (beam.length, beam.modes_per_plane, beam.axial_modes);
        let p = 2 * n + na;
        let amp = (2.0 / (beam.mass_per_length * length)).sqrt();
        let c_bend = (beam.bending_stiffness / beam.mass_per_length).sqrt();
        let c_axial = (beam.axial_stiffness / beam.mass_per_length).sqrt();
        let wave = |k: usize| k as f64 * std::f64::consts::PI / length;
        let mut omega = Vec::with_capacity(p);
        for k in 1..=n {
            omega.push(wave(k).powi(2) * c_bend);
            omega.push(wave(k).powi(2) * c_bend);
        }
        for k in 1..=na {
            omega.push(wave(k) * c_axial);
        }
        let mut points = Vec::with_capacity(stations.len());
        for (j, (name, x)) in stations.iter().enumerate() {
            if !(x.is_finite() && *x >= 0.0 && *x <= length) {
                return Err(Error::invalid(
                    format!("structure.points[{j}].x"),
                    format!(
                        "must lie on the beam, between 0 and {} m (got {})",
                        number(length),
                        number(*x)
                    ),
                ));
            }
            let mut rows = vec![0.0; 3 * p];
            for k in 1..=n {
                let s = amp * (wave(k) * x).sin();
                rows[p + 2 * (k - 1)] = s; // y row, y-mode
                rows[2 * p + 2 * (k - 1) + 1] = s; // z row, z-mode
            }
            for k in 1..=na {
                rows[2 * n + k - 1] = amp * (wave(k) * x).sin(); // x row, axial mode
            }
            points.push(Point {
                name: name.clone(),
                coords: Vector3::new(*x, 0.0, 0.0),
                rows,
                rotations: Vec::new(),
            });
        }
        // Γ_k = ∫ ρA φ_k dx = √(2 ρA L) (1 − cos kπ)/(kπ), in the mode's direction
        let gamma = |k: usize| {
            let kpi = k as f64 * std::f64::consts::PI;
            (2.0 * beam.mass_per_length * length).sqrt() * (1.0 - kpi.cos()) / kpi
        };
        let mut participation = vec![0.0; 3 * p];
        for k in 1..=n {
            participation[p + 2 * (k - 1)] = gamma(k);
            participation[2 * p + 2 * (k - 1) + 1] = gamma(k);
        }
        for k in 1..=na {
            participation[2 * n + k - 1] = gamma(k);
        }
        Ok(Self {
            omega,
            damping_ratio: vec![beam.damping_ratio; p],
            points,
            participation,
        })
    }

    /// Checks every number of the basis: finite, non-negative frequencies and damping, finite
    /// rows of the right length, unique point names. `source` prefixes the field names.
    pub fn validate(&self, source: &str) -> Result<()> {
        let p = self.modes();
        if p == 0 {
            return Err(Error::invalid(source, "the modal basis has no mode"));
        }
        if self.damping_ratio.len() != p {
            return Err(Error::invalid(
                format!("{source}.damping_ratio"),
                format!(
                    "has {} values for {p} modes: give one per mode or a single number",
                    self.damping_ratio.len()
                ),
            ));
        }
        for (i, &w) in self.omega.iter().enumerate() {
            if !(w.is_finite() && w >= 0.0) {
                return Err(Error::invalid(
                    format!("{source}.frequencies_hz[{i}]"),
                    format!(
                        "must be a finite frequency ≥ 0 (got {}): 0 is a rigid-body mode, a negative value is not a mode",
                        number(w / std::f64::consts::TAU)
                    ),
                ));
            }
        }
        if !(self.participation.is_empty() || self.participation.len() == 3 * p)
            || self.participation.iter().any(|v| !v.is_finite())
        {
            return Err(Error::invalid(
                format!("{source}.participation"),
                format!("must be 3 rows (x, y, z) of {p} finite values Φᵀ M r, or none"),
            ));
        }
        for (i, &xi) in self.damping_ratio.iter().enumerate() {
            check_damping_ratio(xi, &format!("{source}.damping_ratio[{i}]"))?;
        }
        for (j, pt) in self.points.iter().enumerate() {
            if self.points[..j].iter().any(|o| o.name == pt.name) {
                return Err(Error::invalid(
                    format!("{source}.points[{j}].name"),
                    format!(
                        "point name '{}' is used twice: names must be unique",
                        pt.name
                    ),
                ));
            }
            if pt.rows.len() != 3 * p {
                return Err(Error::invalid(
                    format!("{source}.points.{}.rows", pt.name),
                    format!(
                        "must be 3 rows (x, y, z) of {p} values, one per mode (got {} values)",
                        pt.rows.len()
                    ),
                ));
            }
            if let Some(k) = pt.rows.iter().position(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    format!("{source}.points.{}.rows", pt.name),
                    format!(
                        "mode shape is not finite ({}) at component {} of mode {}: fix or drop that mode",
                        pt.rows[k],
                        ["x", "y", "z"][k / p],
                        k % p
                    ),
                ));
            }
            if !(pt.rotations.is_empty() || pt.rotations.len() == 3 * p) {
                return Err(Error::invalid(
                    format!("{source}.points.{}.rotations", pt.name),
                    format!(
                        "must be 3 rows (θx, θy, θz) of {p} values, one per mode, or none (got {} values)",
                        pt.rotations.len()
                    ),
                ));
            }
            if let Some(k) = pt.rotations.iter().position(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    format!("{source}.points.{}.rotations", pt.name),
                    format!(
                        "rotation of the mode shape is not finite ({}) at component {} of mode {}: fix or drop that mode",
                        pt.rotations[k],
                        ["θx", "θy", "θz"][k / p],
                        k % p
                    ),
                ));
            }
            if pt.coords.iter().any(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    format!("{source}.points.{}.coords", pt.name),
                    "coordinates must be finite numbers",
                ));
            }
        }
        Ok(())
    }
}

/// A damping ratio `ξ ≥ 0` (one number for every mode, or one mode's); `field` names it.
pub(crate) fn check_damping_ratio(xi: f64, field: &str) -> Result<()> {
    if xi.is_finite() && xi >= 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            field,
            format!(
                "must be a damping ratio ≥ 0, e.g. 0.01 for 1 % (got {})",
                number(xi)
            ),
        ))
    }
}

/// The three rows (x, y, z) of one point's 3 × p rows, as slices of equal length (loops over
/// them need no bounds checks and vectorise).
#[inline(always)]
pub(crate) fn thirds(rows: &[f64], p: usize) -> [&[f64]; 3] {
    let (x, rest) = rows[..3 * p].split_at(p);
    let (y, z) = rest.split_at(p);
    [x, y, z]
}

/// `u = Φ_c x` for one point's 3 × p rows.
#[inline(always)]
pub fn recombine(rows: &[f64], x: &[f64]) -> Vector3<f64> {
    recombine_with::<crate::numerics::Portable>(rows, x)
}

/// [`recombine`] with the reduction kernels `K` ([`crate::numerics`]).
#[inline(always)]
pub(crate) fn recombine_with<K: crate::numerics::Lanes>(rows: &[f64], x: &[f64]) -> Vector3<f64> {
    let p = x.len();
    Vector3::new(
        K::dot(&rows[..p], x),
        K::dot(&rows[p..2 * p], x),
        K::dot(&rows[2 * p..3 * p], x),
    )
}

/// `out += Φ_cᵀ f` for one point's 3 × p rows.
#[inline(always)]
pub fn project_add(rows: &[f64], f: &Vector3<f64>, out: &mut [f64]) {
    let p = out.len();
    // slices of equal length, indexed: no bounds checks, vector operations
    let [x, y, z] = thirds(rows, p);
    #[allow(clippy::needless_range_loop)] // four slices: the indexed loop vectorises
    for i in 0..p {
        out[i] += x[i] * f.x + y[i] * f.y + z[i] * f.z;
    }
}

/// Dot product `a·b` of two equal-length slices, summed in four interleaved partial sums
/// (`Σ_{i ≡ j mod 4} a_i b_i`, then `(s₀ + s₁) + (s₂ + s₃)`) so that its additions do not wait
/// on each other: the kernel of detection, `b` and the energy (THEORY §2, "Arithmetic").
/// Rounding differs from a left-to-right sum by round-off only.
#[inline(always)]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    use crate::numerics::Lanes;
    crate::numerics::Portable::dot(a, b)
}

/// The two dot products `(a·b, a·c)` in one pass over `a` ([`dot`]'s summation).
#[inline(always)]
pub fn dot2(a: &[f64], b: &[f64], c: &[f64]) -> (f64, f64) {
    use crate::numerics::Lanes;
    crate::numerics::Portable::dot2(a, b, c)
}

/// `out += s x` on equal-length slices (the step's kernel, `crate::numerics`).
#[inline(always)]
pub fn axpy(out: &mut [f64], s: f64, x: &[f64]) {
    use crate::numerics::Lanes;
    crate::numerics::Portable::axpy(out, s, x)
}
