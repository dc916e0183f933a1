//! Stable time step of central differences with penalty contacts (THEORY §2).
//!
//! Undamped central differences need `Δt < 2/ω_max`, `ω_max²` the largest eigenvalue of
//! `Ω² + Σ_c Φ_cᵀ (K_N n nᵀ + K_T T Tᵀ) Φ_c`, bounded by taking every contact closed. The
//! velocity-proportional contact forces (`C_N`, `C_T`) are computed from the predicted velocity,
//! i.e. explicitly; their largest rate `c_max` (same construction) lowers the limit to
//! `(2/ω_max)(√(1+ζ²) − ζ)`, `ζ = c_max/(2 ω_max)`, the limit of an explicitly damped oscillator.
//!
//! The stability limit says nothing about accuracy: a contact whose impacts last only a few
//! steps is stable but coarse. [`impact_resolution`] gives each contact's impact duration in
//! steps, and [`impact_resolution_warnings`] the warning before a run (THEORY §2).
//!
//! A model whose terms are not finite numbers (a mass of 1e-320 kg, a radius of 1e200 m: a
//! unit slip) has no stable time step: [`checked_stable_time_step`] refuses it naming the
//! culprit, before the eigen solver (which would not terminate on such a matrix) runs.

use nalgebra::{DMatrix, Vector3};

use crate::contact::tangential::TangentialMethod;
use crate::error::{Error, Result, number};
use crate::model::{Coordinates, Model};

/// The stable time step of `model` with `method`, s; 0 for a model without one (terms that
/// are not finite numbers, see [`checked_stable_time_step`]), so that every `Δt` is refused.
pub fn stable_time_step(model: &Model, method: &TangentialMethod) -> f64 {
    checked_stable_time_step(model, method).unwrap_or(0.0)
}

/// The stable time step of `model` with `method`, s (`∞` when nothing is stiff: a free mass
/// without contact). In physical coordinates the eigenvalues are those of `K φ = ω² M φ`
/// (and `C φ = c M φ`). A stiffness or damping term that is not a finite number is an error
/// naming the mode or the contact it comes from; so is a limit that is 0 or not a number.
pub fn checked_stable_time_step(model: &Model, method: &TangentialMethod) -> Result<f64> {
    let p = model.basis.modes();
    let (needed, available) = (memory_bytes(p), crate::structure::beam::available_memory());
    if needed > available {
        return Err(Error::invalid(
            "structure",
            format!(
                "has {p} modes: the stable time step is computed on dense {p} × {p} matrices, which would need {}, more than the {} of memory available; keep fewer modes (at most {:.0})",
                crate::structure::beam::gigabytes(needed),
                crate::structure::beam::gigabytes(available),
                (available / (8.0 * DENSE_MATRICES)).sqrt()
            ),
        ));
    }
    let (mut k, mut c) = match &model.coordinates {
        Coordinates::Modal => {
            let mut k = DMatrix::<f64>::zeros(p, p);
            for (i, w) in model.basis.omega.iter().enumerate() {
                k[(i, i)] = w * w;
                if !k[(i, i)].is_finite() {
                    return Err(Error::invalid(
                        format!("structure.frequencies_hz[{i}]"),
                        format!(
                            "mode {} has ω = {w:e} rad/s, whose square is not a finite number: check the units of the structure (masses, stiffnesses, sizes)",
                            i + 1
                        ),
                    ));
                }
            }
            (k, DMatrix::<f64>::zeros(p, p))
        }
        // structural damping acts through A (implicitly): only contact damping is explicit
        Coordinates::Physical(m) => (m.stiffness.clone(), DMatrix::<f64>::zeros(p, p)),
    };
    let (kt, ct) = match method {
        TangentialMethod::Penalty(s) => (s.stiffness, s.damping),
        _ => (0.0, 0.0),
    };
    for (index, contact) in model.contacts.iter().enumerate() {
        check_radius(model, index)?;
        let point = &model.basis.points[contact.point];
        let (normals, tangents) = contact.obstacle.penalty_directions();
        if !contact.at_surface() {
            for n in &normals {
                add_direction(&mut k, &point.rows, n, contact.normal.stiffness);
                add_direction(&mut c, &point.rows, n, contact.normal.damping);
            }
            for ta in &tangents {
                add_direction(&mut k, &point.rows, ta, kt);
                add_direction(&mut c, &point.rows, ta, ct);
            }
        } else {
            // on the surface the rows depend on the normal: each normal the contact can take
            // (both senses) with the tangents orthogonal to it (a tangent may be counted more
            // than once: conservative)
            let mut rows = point.rows.clone();
            for n in normals.iter().flat_map(|n| [*n, -n]) {
                contact.surface_rows(point, &n, &mut rows);
                add_direction(&mut k, &rows, &n, contact.normal.stiffness);
                add_direction(&mut c, &rows, &n, contact.normal.damping);
                for ta in tangents.iter().filter(|ta| ta.dot(&n).abs() < 1e-9) {
                    add_direction(&mut k, &rows, ta, kt);
                    add_direction(&mut c, &rows, ta, ct);
                }
            }
        }
        if !(all_finite(&k) && all_finite(&c)) {
            return Err(not_finite_contact(model, index));
        }
    }
    let (w2, cmax) = match &model.coordinates {
        Coordinates::Modal => (largest_eigenvalue(k), largest_eigenvalue(c)),
        Coordinates::Physical(m) => match m.mass.clone().cholesky() {
            Some(chol) => {
                // L⁻¹ X L⁻ᵀ has the eigenvalues of X φ = λ M φ
                let scaled = |x: DMatrix<f64>| {
                    let y = chol.l().solve_lower_triangular(&x).unwrap_or(x);
                    let z = chol.l().solve_lower_triangular(&y.transpose()).unwrap_or(y);
                    largest_eigenvalue((&z + z.transpose()) * 0.5)
                };
                (scaled(k), scaled(c))
            }
            None => {
                return Err(Error::invalid(
                    "structure.mass",
                    "the mass matrix is not positive definite",
                ));
            }
        },
    };
    let (Some(w2), Some(cmax)) = (w2, cmax) else {
        return Err(Error::invalid(
            "structure",
            "the highest frequency of the structure with its contacts is not a finite number: check the units of the masses, stiffnesses and sizes",
        ));
    };
    // the fluid-elastic forces are explicit: their stiffness and damping bounds are added
    // (conservative: the delayed stiffness as if it acted at once, THEORY §13)
    let (w2, cmax) = match &model.fluid_elastic {
        Some(fe) => (w2 + fe.stiffness_bound(p), cmax + fe.damping_bound(p)),
        None => (w2, cmax),
    };
    if w2 <= 0.0 {
        return Ok(f64::INFINITY);
    }
    let w = w2.sqrt();
    let zeta = cmax / (2.0 * w);
    // (2/ω)(√(1+ζ²) − ζ), written without the cancellation of large ζ
    let dt = (2.0 / w) / ((1.0 + zeta * zeta).sqrt() + zeta);
    if dt > 0.0 {
        Ok(dt)
    } else {
        Err(Error::invalid(
            "time.dt",
            format!(
                "the stable time step of central differences is {dt:e} s (highest frequency {:e} Hz, contact damping rate {cmax:e} 1/s): check the units of the masses, stiffnesses and damping",
                w / std::f64::consts::TAU
            ),
        ))
    }
}

/// Dense `p × p` matrices alive at once while the limit is computed: the stiffness and the
/// damping, the eigen solver's copy and its workspace.
const DENSE_MATRICES: f64 = 4.0;

/// Bytes the stable time step of a model of `p` modes needs: `8 DENSE_MATRICES p²`.
pub fn memory_bytes(p: usize) -> f64 {
    8.0 * DENSE_MATRICES * (p as f64).powi(2)
}

/// The largest magnitude of a row.
fn largest(rows: &[f64]) -> f64 {
    rows.iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

/// Refuses a contact on the surface whose radius makes the contact point's rows (`Φ_u +
/// R [n]_× Θ`) numbers out of range: the Delassus operator of the Lagrange methods, built
/// from their squares, would not be finite (a radius of 1e200 m: a unit slip).
fn check_radius(model: &Model, index: usize) -> Result<()> {
    let contact = &model.contacts[index];
    if !contact.at_surface() {
        return Ok(());
    }
    let point = &model.basis.points[contact.point];
    let r = contact.radius;
    let reach = r * largest(&point.rotations) * model.basis.modes() as f64;
    if (contact.normal.stiffness.max(1.0) * reach * reach).is_finite() {
        return Ok(());
    }
    Err(Error::invalid(
        format!("contacts[{index}].radius"),
        format!(
            "{} m makes the rotations of point '{}' move the contact point by amounts that are not finite numbers: give the outer radius of the tube in m",
            number(r),
            point.name
        ),
    ))
}

/// Why contact `index` adds terms that are not finite numbers: its stiffness or damping over
/// the modal mass of its point (tiny when a mass or a density is in the wrong unit).
fn not_finite_contact(model: &Model, index: usize) -> Error {
    let contact = &model.contacts[index];
    let point = &model.basis.points[contact.point];
    // the point's modal mass, 1/max|Φ|² (exact for a point mass)
    let modal_mass = (1.0 / largest(&point.rows)).powi(2);
    Error::invalid(
        format!("contacts[{index}].normal"),
        format!(
            "stiffness {} N/m and damping {} N·s/m at point '{}' (whose modal mass is {:e} kg) give a frequency that is not a finite number: check the units of the structure's mass (mass, density, diameters) and of the contact's stiffness and damping",
            number(contact.normal.stiffness),
            number(contact.normal.damping),
            point.name,
            modal_mass
        ),
    )
}

fn all_finite(m: &DMatrix<f64>) -> bool {
    m.iter().all(|v| v.is_finite())
}

/// `m += s (Φ_cᵀ d)(Φ_cᵀ d)ᵀ`.
fn add_direction(m: &mut DMatrix<f64>, rows: &[f64], d: &Vector3<f64>, s: f64) {
    if s == 0.0 {
        return;
    }
    let p = m.nrows();
    let v: Vec<f64> = (0..p)
        .map(|i| d.x * rows[i] + d.y * rows[p + i] + d.z * rows[2 * p + i])
        .collect();
    for i in 0..p {
        for j in 0..p {
            m[(i, j)] += s * v[i] * v[j];
        }
    }
}

/// The largest eigenvalue of a symmetric matrix; `None` when it has a term, or would have an
/// eigenvalue, that is not a finite number (the eigen solver would not terminate on it).
fn largest_eigenvalue(m: DMatrix<f64>) -> Option<f64> {
    if !all_finite(&m) {
        return None;
    }
    // |λ| ≤ n max|m_ij| (Gershgorin): finite eigenvalues, and no overflow in the solver
    let largest = m.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if !(largest * m.nrows() as f64).is_finite() {
        return None;
    }
    Some(m.symmetric_eigenvalues().max())
}

/// Fewest time steps an impact should last: at 15 steps per impact the energy balance of an
/// elastic impact errs by about 0.9 % (case V1a; 0.6 % on an oscillator bouncing on a stop),
/// and the error falls as `Δt²` (THEORY §2, VERIFICATION.md "Steps per impact").
pub const MIN_STEPS_PER_IMPACT: f64 = 15.0;

/// How finely the impacts of one contact are resolved in time by a time step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactResolution {
    /// Index of the contact.
    pub contact: usize,
    /// Effective mass at the contact point along its normal, `1/(nᵀ Φ_c M⁻¹ Φ_cᵀ n)`, kg
    /// (for a hole or a polygon, the most mobile normal of its plane).
    pub effective_mass: f64,
    /// Duration of an elastic impact on the normal spring, `π √(m_eff/K_N)`, s.
    pub duration: f64,
    /// That duration in time steps.
    pub steps: f64,
}

/// The impacts' resolution of every contact that a mode can move along its normal
/// ([`ImpactResolution`]), with the time step `dt`.
///
/// The mobility of the contact point is `G = Φ_c M⁻¹ Φ_cᵀ` (`Φ_c Φ_cᵀ` on a mass-normalised
/// modal basis, where `M = I`); along a normal `n`, `nᵀ G n = 1/m_eff`. On the tube's surface
/// the normal row is the axis point's (`n·(R n × Θ) = 0`, THEORY §3), so the point's rows
/// serve. An impact on the penalty spring `K_N` lasts about half a period of `m_eff` on it,
/// `π √(m_eff/K_N)` (exactly so for a point mass; the structure's own stiffness shortens it).
pub fn impact_resolution(model: &Model, dt: f64) -> Vec<ImpactResolution> {
    let mass_factor = match &model.coordinates {
        Coordinates::Modal => None,
        Coordinates::Physical(m) => m.mass.clone().cholesky(),
    };
    let mut out = Vec::new();
    for (index, contact) in model.contacts.iter().enumerate() {
        let rows = &model.basis.points[contact.point].rows;
        let p = rows.len() / 3;
        if p == 0 || !(contact.normal.stiffness > 0.0) {
            continue;
        }
        // the three rows, and M⁻¹ applied to them (physical coordinates)
        let r = DMatrix::from_row_slice(3, p, rows);
        let g = match (&model.coordinates, &mass_factor) {
            (Coordinates::Physical(_), Some(chol)) => &r * chol.solve(&r.transpose()),
            (Coordinates::Physical(_), None) => continue,
            (Coordinates::Modal, _) => &r * r.transpose(),
        };
        let quadratic = |a: &Vector3<f64>, b: &Vector3<f64>| {
            let mut s = 0.0;
            for i in 0..3 {
                for j in 0..3 {
                    s += a[i] * g[(i, j)] * b[j];
                }
            }
            s
        };
        let (normals, _) = contact.obstacle.penalty_directions();
        let mobility = match normals.as_slice() {
            [n] => quadratic(n, n),
            [a, b] => {
                // the largest eigenvalue of G restricted to the plane of the normals
                let (aa, ab, bb) = (quadratic(a, a), quadratic(a, b), quadratic(b, b));
                0.5 * (aa + bb) + (0.25 * (aa - bb).powi(2) + ab * ab).sqrt()
            }
            _ => continue,
        };
        if !(mobility > 0.0 && mobility.is_finite()) {
            continue;
        }
        let effective_mass = 1.0 / mobility;
        let duration = std::f64::consts::PI / (contact.normal.stiffness * mobility).sqrt();
        out.push(ImpactResolution {
            contact: index,
            effective_mass,
            duration,
            steps: duration / dt,
        });
    }
    out
}

/// The largest time step, rounded down to two digits, that resolves the impacts of every
/// contact of `model` with at least [`MIN_STEPS_PER_IMPACT`] steps ([`impact_resolution`]);
/// `None` when no mode moves a contact point along its normal.
pub fn impact_time_step(model: &Model) -> Option<f64> {
    let shortest = impact_resolution(model, 1.0)
        .iter()
        .map(|r| r.duration)
        .reduce(f64::min)?;
    Some(crate::results::energy::round_down(
        shortest / MIN_STEPS_PER_IMPACT,
        |dt| shortest / dt >= MIN_STEPS_PER_IMPACT,
    ))
}

/// A warning when `dt` resolves some contact's impacts with fewer than
/// [`MIN_STEPS_PER_IMPACT`] steps ([`impact_resolution`]): one line naming the contacts, the
/// steps per impact, and the `time.dt` that would resolve every impact with that many
/// ([`impact_time_step`]). None when an impact lasts `π/2` steps or fewer: `Δt` is then
/// at least `2/ω_c ≥ 2/ω_max` (the stable limit, `ω_c = √(K_N/m_eff)` being at most the
/// highest frequency of the structure with its contacts), and the run is refused with the
/// limit (THEORY §2).
pub fn impact_resolution_warnings(model: &Model, dt: f64) -> Vec<String> {
    let all = impact_resolution(model, dt);
    if all.iter().any(|r| r.steps <= 0.5 * std::f64::consts::PI) {
        return Vec::new();
    }
    let coarse: Vec<ImpactResolution> = all
        .into_iter()
        .filter(|r| r.steps < MIN_STEPS_PER_IMPACT)
        .collect();
    let Some(suggested) = impact_time_step(model).filter(|_| !coarse.is_empty()) else {
        return Vec::new();
    };
    const NAMED: usize = 4;
    let mut names: Vec<String> = coarse
        .iter()
        .take(NAMED)
        .map(|r| {
            format!(
                "'{}' ({:.1} steps: π √(m_eff/K_N) = {} s, m_eff = {} kg)",
                model.contacts[r.contact].name,
                r.steps,
                three_digits(r.duration),
                three_digits(r.effective_mass)
            )
        })
        .collect();
    if coarse.len() > NAMED {
        names.push(format!("{} more", coarse.len() - NAMED));
    }
    vec![format!(
        "time.dt = {} s resolves the impacts of contact{} {} with fewer than {} steps each: the energy balance then errs by about 1 % or more and impact forces and durations are coarse (THEORY §2); set time.dt to at most {} s",
        number(dt),
        if coarse.len() > 1 { "s" } else { "" },
        names.join(", "),
        MIN_STEPS_PER_IMPACT,
        number(suggested)
    )]
}

/// `x` to three significant digits, as [`number`] writes it.
fn three_digits(x: f64) -> String {
    number(format!("{x:.2e}").parse().unwrap_or(x))
}
