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
    let (kt, ct) = match method {
        TangentialMethod::Penalty(s) => (s.stiffness, s.damping),
        _ => (0.0, 0.0),
    };
    for index in 0..model.contacts.len() {
        check_radius(model, index)?;
    }
    // a modal basis of many modes with few contact directions: `Ω² + U Uᵀ` without the dense
    // p × p matrices (20 000 modes: 3.2 GB each, and hours of eigen solver)
    let directions: usize = model.contacts.iter().map(direction_count).sum();
    let (w2, cmax) =
        if matches!(model.coordinates, Coordinates::Modal) && p > DENSE_MODES && 8 * directions < p
        {
            low_rank_largest_eigenvalues(model, kt, ct)?
        } else {
            dense_largest_eigenvalues(model, kt, ct)?
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

/// `ω_max²` and `c_max` (module doc) of a modal basis from `Ω²` and the contacts' springs as
/// rank-one terms ([`largest_eigenvalue_low_rank`]): memory `p × r` and time `p r²` per
/// bisection step, for `r` springs, where the dense matrices take `p²` and `p³`.
fn low_rank_largest_eigenvalues(
    model: &Model,
    kt: f64,
    ct: f64,
) -> Result<(Option<f64>, Option<f64>)> {
    let p = model.basis.modes();
    let omega2: Vec<f64> = model.basis.omega.iter().map(|w| w * w).collect();
    if let Some(i) = omega2.iter().position(|w2| !w2.is_finite()) {
        return Err(not_finite_mode(model, i));
    }
    let (mut k, mut c) = (Vec::new(), Vec::new());
    for (index, contact) in model.contacts.iter().enumerate() {
        for spring in contact_springs(model, contact, kt, ct) {
            let reach = largest(&spring.v).powi(2);
            if !(spring.stiffness * reach).is_finite() || !(spring.damping * reach).is_finite() {
                return Err(not_finite_contact(model, index));
            }
            let scaled = |s: f64| spring.v.iter().map(|v| s.sqrt() * v).collect::<Vec<_>>();
            if spring.stiffness > 0.0 {
                k.push(scaled(spring.stiffness));
            }
            if spring.damping > 0.0 {
                c.push(scaled(spring.damping));
            }
        }
    }
    Ok((
        largest_eigenvalue_low_rank(&omega2, &k),
        largest_eigenvalue_low_rank(&vec![0.0; p], &c),
    ))
}

/// `ω_max²` and `c_max` (module doc) from the dense `p × p` stiffness and damping: the
/// modal or physical matrices of the structure with every contact's springs added.
fn dense_largest_eigenvalues(
    model: &Model,
    kt: f64,
    ct: f64,
) -> Result<(Option<f64>, Option<f64>)> {
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
                    return Err(not_finite_mode(model, i));
                }
            }
            (k, DMatrix::<f64>::zeros(p, p))
        }
        // structural damping acts through A (implicitly): only contact damping is explicit
        Coordinates::Physical(m) => (m.stiffness.clone(), DMatrix::<f64>::zeros(p, p)),
    };
    for (index, contact) in model.contacts.iter().enumerate() {
        for spring in contact_springs(model, contact, kt, ct) {
            add_direction(&mut k, &spring.v, spring.stiffness);
            add_direction(&mut c, &spring.v, spring.damping);
        }
        if !(all_finite(&k) && all_finite(&c)) {
            return Err(not_finite_contact(model, index));
        }
    }
    Ok(match &model.coordinates {
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
    })
}

/// Mode `i`'s `ω²` is not a finite number.
fn not_finite_mode(model: &Model, i: usize) -> Error {
    let w = model.basis.omega[i];
    Error::invalid(
        format!("structure.frequencies_hz[{i}]"),
        format!(
            "mode {} has ω = {w:e} rad/s, whose square is not a finite number: check the units of the structure (masses, stiffnesses, sizes)",
            i + 1
        ),
    )
}

/// Modes above which the limit of a modal basis is computed from its diagonal and the
/// contacts' rank-one terms ([`largest_eigenvalue_low_rank`]) rather than from dense
/// matrices, when its contacts have fewer than an eighth as many directions (the bisection's
/// ~50 `p r²` against the eigen solver's ~10 `p³`); at or below it, the dense eigen solver
/// (a few ms).
const DENSE_MODES: usize = 400;

/// A direction along which a closed contact acts on the modal coordinates: `v = Φ_cᵀ d`,
/// with the contact's stiffness and damping along `d`.
struct Spring {
    v: Vec<f64>,
    stiffness: f64,
    damping: f64,
}

/// The springs of `contact` taken closed: its normals with the normal law, its tangents
/// with the tangential penalty (`kt`, `ct`; 0 for the Lagrange methods). On the surface of
/// a tube the rows depend on the normal: each normal the contact can take (both senses) with
/// the tangents orthogonal to it (a tangent may be counted more than once: conservative).
fn contact_springs(
    model: &Model,
    contact: &crate::contact::Contact,
    kt: f64,
    ct: f64,
) -> Vec<Spring> {
    let point = contact.point_in(&model.basis.points);
    let (normals, tangents) = contact.obstacle.penalty_directions();
    let (kn, cn) = (contact.normal.stiffness, contact.normal.damping);
    let mut springs = Vec::new();
    let mut add = |rows: &[f64], d: &Vector3<f64>, stiffness: f64, damping: f64| {
        springs.push(Spring {
            v: projected(rows, d),
            stiffness,
            damping,
        })
    };
    if !contact.at_surface() {
        for n in &normals {
            add(&point.rows, n, kn, cn);
        }
        for ta in &tangents {
            add(&point.rows, ta, kt, ct);
        }
    } else {
        let mut rows = point.rows.clone();
        for n in normals.iter().flat_map(|n| [*n, -n]) {
            contact.surface_rows(point, &n, &mut rows);
            add(&rows, &n, kn, cn);
            for ta in tangents.iter().filter(|ta| ta.dot(&n).abs() < 1e-9) {
                add(&rows, ta, kt, ct);
            }
        }
    }
    springs
}

/// How many springs [`contact_springs`] gives at most.
fn direction_count(contact: &crate::contact::Contact) -> usize {
    let (normals, tangents) = contact.obstacle.penalty_directions();
    let senses = if contact.at_surface() { 2 } else { 1 };
    senses * normals.len() * (1 + tangents.len())
}

/// `Φ_cᵀ d`: the modal components of direction `d` at a point of rows `rows` (3 × p, by
/// rows).
fn projected(rows: &[f64], d: &Vector3<f64>) -> Vec<f64> {
    let p = rows.len() / 3;
    (0..p)
        .map(|i| d.x * rows[i] + d.y * rows[p + i] + d.z * rows[2 * p + i])
        .collect()
}

/// The largest eigenvalue of `diag(d) + U Uᵀ`, `U` of columns `u` (p × r, r < p), from r × r
/// matrices only; `None` when it is not a finite number.
///
/// For `λ > max d`, `λ I − diag(d) − U Uᵀ` is positive definite if and only if
/// `M(λ) = I − Uᵀ (λ I − diag(d))⁻¹ U` is (the inertia of the bordered matrix
/// `[[diag(d) − λ I, U], [Uᵀ, −I]]` taken by its two Schur complements). `M` grows with `λ`,
/// so `λ_max` is where it stops being positive definite, found by bisection between `max d`
/// and `max d + tr(Uᵀ U)` (a bound of `λ_max`) to a relative 1e-15. The value returned is
/// the upper end of the last interval: never below `λ_max`, so the time step it gives is
/// never above the limit.
fn largest_eigenvalue_low_rank(d: &[f64], u: &[Vec<f64>]) -> Option<f64> {
    let dmax = d.iter().fold(f64::NEG_INFINITY, |a, &v| a.max(v)).max(0.0);
    let trace: f64 = u.iter().map(|c| c.iter().map(|x| x * x).sum::<f64>()).sum();
    if !(dmax + trace).is_finite() {
        return None;
    }
    if trace == 0.0 {
        return Some(dmax);
    }
    let r = u.len();
    let positive_definite = |lambda: f64| {
        let inverse: Vec<f64> = d.iter().map(|&di| 1.0 / (lambda - di)).collect();
        let m = DMatrix::from_fn(r, r, |a, b| {
            let dot: f64 = (u[a].iter().zip(&u[b]).zip(&inverse))
                .map(|((x, y), w)| x * y * w)
                .sum();
            f64::from(u8::from(a == b)) - dot
        });
        m.cholesky().is_some()
    };
    let (mut lo, mut hi) = (dmax, (dmax + trace) * (1.0 + 1e-12));
    if !positive_definite(hi) {
        // rounding in the bound: no closer answer than the bound itself, doubled
        return Some(2.0 * hi);
    }
    while hi - lo > 1e-15 * hi {
        let mid = lo + 0.5 * (hi - lo);
        if mid <= lo || mid >= hi {
            break;
        }
        if positive_definite(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
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
    let point = contact.point_in(&model.basis.points);
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
    let point = contact.point_in(&model.basis.points);
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

/// `m += s v vᵀ`, `v = Φ_cᵀ d` ([`projected`]).
fn add_direction(m: &mut DMatrix<f64>, v: &[f64], s: f64) {
    if s == 0.0 {
        return;
    }
    let p = m.nrows();
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
        let rows = &contact.point_in(&model.basis.points).rows;
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
    Some(crate::accumulate::energy::round_down(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::Case;

    /// A small generator of reproducible numbers in [-1, 1).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// The bisection on `M(λ)` against the dense eigen solver on `diag(d) + U Uᵀ`: random
    /// diagonals (repeated values, zeros) and 1 to 5 columns, one case with `U` orthogonal to
    /// the top mode (then `λ_max = max d`), one with a zero diagonal (the damping).
    #[test]
    fn low_rank_largest_eigenvalue_is_the_dense_one() {
        let mut rng = Lcg(7);
        let p = 30;
        for case in 0..40 {
            let mut d: Vec<f64> = (0..p).map(|_| 1e4 * (rng.next() + 1.0)).collect();
            if case % 3 == 0 {
                d[5] = d[9];
            }
            if case % 5 == 0 {
                d.iter_mut().for_each(|x| *x = 0.0);
            }
            let r = 1 + case % 5;
            let scale = [1e-3, 1.0, 1e3, 1e6][case % 4];
            let mut u: Vec<Vec<f64>> = (0..r)
                .map(|_| (0..p).map(|_| scale * rng.next()).collect())
                .collect();
            if case == 1 {
                // orthogonal to the top mode, and small: the top mode's eigenvalue stays
                let top = (0..p).max_by(|&a, &b| d[a].total_cmp(&d[b])).unwrap();
                u.iter_mut().for_each(|c| {
                    c[top] = 0.0;
                    c.iter_mut().for_each(|x| *x *= 1e-6);
                });
            }
            let mut m = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(d.clone()));
            for c in &u {
                add_direction(&mut m, c, 1.0);
            }
            let dense = largest_eigenvalue(m).unwrap();
            let low = largest_eigenvalue_low_rank(&d, &u).unwrap();
            assert!(
                low >= dense * (1.0 - 1e-13) && low <= dense * (1.0 + 1e-12),
                "case {case}: low-rank {low:e}, dense {dense:e}"
            );
        }
    }

    /// A tube of `modes` modes (finite elements, pinned at both ends), with contacts of every
    /// kind of spring: a plane on the axis (penalty tangents, normal damping), a circle on
    /// the tube's surface (both senses of each normal, rows turned by the rotations).
    fn tube(modes: usize, method: &str) -> Case {
        let text = format!(
            r#"
            title = "tube"
            [structure]
            type = "tube"
            outer_diameter = 19.05e-3
            wall_thickness = 1.09e-3
            young_modulus = 2.0e11
            poisson_ratio = 0.3
            density = 8200.0
            path = [[0.0, 0.0, 0.0], [1.5, 0.0, 0.0]]
            mesh_size = 0.015
            modes = {modes}
            damping_ratio = 0.01
            [[structure.supports]]
            at = [0.0, 0.0, 0.0]
            type = "pinned"
            [[structure.supports]]
            at = [1.5, 0.0, 0.0]
            type = "pinned"
            [[structure.points]]
            name = "a"
            at = [0.3, 0.0, 0.0]
            [[structure.points]]
            name = "b"
            at = [0.825, 0.0, 0.0]
            [[contacts]]
            point = "a"
            normal = {{ stiffness = 1e6, damping = 5.0 }}
            obstacle = {{ type = "plane", origin = [0.3, 0.0, 0.0], normal = [0.0, 1.0, 0.0], tangent = [1.0, 0.0, 0.0], gap = 1e-4 }}
            friction = {{ mu = 0.3 }}
            [[contacts]]
            point = "b"
            radius = 0.009525
            normal = {{ stiffness = 3e6 }}
            obstacle = {{ type = "circle", centre = [0.825, 0.0, 0.0], axis = [1.0, 0.0, 0.0], clearance = 2e-4 }}
            friction = {{ mu = 0.3 }}
            [tangential]
            {method}
            [time]
            dt = 1e-9
            duration = 1e-6
            "#
        );
        Case::from_toml_str(&text, std::path::Path::new(".")).unwrap()
    }

    /// Above [`DENSE_MODES`], the limit from the rank-one terms is that of the dense
    /// matrices, for a penalty method (tangential springs) and a Lagrange one.
    #[test]
    fn many_modes_give_the_dense_limit_from_the_contacts_terms() {
        for method in [
            r#"method = "penalty"
            penalty = { stiffness = 2e5, damping = 3.0 }"#,
            r#"method = "active_set""#,
        ] {
            let case = tube(410, method);
            let model = &case.model;
            assert!(model.basis.modes() > DENSE_MODES, "{}", model.basis.modes());
            let (kt, ct) = match &case.settings.method {
                TangentialMethod::Penalty(s) => (s.stiffness, s.damping),
                _ => (0.0, 0.0),
            };
            let (w2, c) = dense_largest_eigenvalues(model, kt, ct).unwrap();
            let (w2_low, c_low) = low_rank_largest_eigenvalues(model, kt, ct).unwrap();
            let (w2, c, w2_low, c_low) = (w2.unwrap(), c.unwrap(), w2_low.unwrap(), c_low.unwrap());
            assert!(
                (w2_low / w2 - 1.0).abs() < 1e-12 && (c_low / c - 1.0).abs() < 1e-12,
                "{method}: ω² {w2_low:e} / {w2:e}, c {c_low:e} / {c:e}"
            );
            // and it is the path the limit takes
            let dt = checked_stable_time_step(model, &case.settings.method).unwrap();
            let w = w2_low.sqrt();
            let zeta = c_low / (2.0 * w);
            assert_eq!(dt, (2.0 / w) / ((1.0 + zeta * zeta).sqrt() + zeta));
        }
    }
}
