//! The numeric keys of the case schema in one table ([`QUANTITIES`]): for each, what it is
//! and its unit (the words of the schema's messages: `output.every: must be a whole number
//! ≥ 1, got -1`), the range of values that any tube, support or flow has (a value outside it
//! is accepted with a warning: a unit slip, `8.2` kg/m³ for a steel tube typed in g/cm³, is
//! the usual cause) and, for the few keys whose value can make the computation meaningless,
//! the range outside which the case is refused.
//!
//! The checks run on the case file's tree before anything is built ([`check`]); every other
//! check of a key (its sign, its finiteness, its consistency with other keys) stays where
//! the key is built. A key not in the table is not checked for plausibility: the time
//! settings (checked against the stability limit and the run's length), the mode shapes and
//! modal forces (whose units follow the basis's normalisation), times, phases, directions,
//! tolerances and seeds.
//!
//! The ranges are deliberately wide (one to two orders of magnitude around the values of
//! steam-generator tubes, heat-exchanger and piping supports and their flows): a warning
//! says a value is unlike any such structure, not that it is unusual.
//!
//! One concept in one file although it is longer than 800 lines: most of it is the table, an
//! entry per numeric key of the schema (~580 lines of data), kept whole so that a key's
//! words, unit and ranges are found and changed in one place — as the time-history variables
//! are in `output::variables`; the lookups and the check over it are ~100 lines.

use crate::error::{Error, Result, number};

/// How a key's value is written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Kind {
    /// A number (integer or decimal).
    Real,
    /// A whole number at least `min`.
    Whole { min: u64 },
}

/// One numeric key (or several keys of the same quantity) of the schema.
#[derive(Debug)]
pub(super) struct Quantity {
    /// Key paths, `[*]` for any index of a list: `contacts[*].friction.mu`,
    /// `loads[*].force[*]` (each of the three components).
    pub keys: &'static [&'static str],
    pub kind: Kind,
    /// What the value is, for messages: "a friction coefficient".
    pub what: &'static str,
    /// Its unit ("" for none).
    pub unit: &'static str,
    /// The plausible values, both ends included: outside, a warning.
    pub plausible: Option<(f64, f64)>,
    /// Values outside this range (both ends included) are refused, for the reason given.
    pub limit: Option<(f64, f64, &'static str)>,
}

const fn real(
    keys: &'static [&'static str],
    what: &'static str,
    unit: &'static str,
    lo: f64,
    hi: f64,
) -> Quantity {
    Quantity {
        keys,
        kind: Kind::Real,
        what,
        unit,
        plausible: Some((lo, hi)),
        limit: None,
    }
}

/// A key without a plausible range (its own checks bound it), for the words of messages.
const fn described(
    keys: &'static [&'static str],
    what: &'static str,
    unit: &'static str,
) -> Quantity {
    Quantity {
        keys,
        kind: Kind::Real,
        what,
        unit,
        plausible: None,
        limit: None,
    }
}

const fn whole(keys: &'static [&'static str], what: &'static str, min: u64) -> Quantity {
    Quantity {
        keys,
        kind: Kind::Whole { min },
        what,
        unit: "",
        plausible: None,
        limit: None,
    }
}

/// Coordinates of points, obstacles and supports, m.
const COORDINATE: (f64, f64) = (-1e3, 1e3);
/// A tube's or a support's size (diameters, radii, widths), m.
const SIZE: (f64, f64) = (1e-4, 2.0);
/// Densities of fluids (steam to liquid metals), kg/m³.
const FLUID_DENSITY: (f64, f64) = (1e-2, 2e4);
/// Flow velocities, m/s.
const VELOCITY: (f64, f64) = (-100.0, 100.0);
/// Frequencies, Hz.
const FREQUENCY: (f64, f64) = (0.0, 1e6);
/// Archard wear coefficients, Pa⁻¹ (measured: 1e-17 to 1e-13).
const WEAR_COEFFICIENT: (f64, f64) = (0.0, 1e-10);

/// The largest magnitude of a load or of a gap the run computes with: the run sums their
/// squares and products over its steps (energies, work, statistics of forces and
/// penetrations), which must stay far below the largest `f64` (1.8e308) for up to 1e12 steps.
pub(super) const SQUARED_LIMIT: f64 = 1e100;

const SQUARED: &str =
    "the run sums its square over the steps (energies, work, statistics), which would overflow";

/// A key with a plausible range and a refused one beyond `±SQUARED_LIMIT`.
const fn squared(
    keys: &'static [&'static str],
    what: &'static str,
    unit: &'static str,
    lo: f64,
    hi: f64,
) -> Quantity {
    Quantity {
        keys,
        kind: Kind::Real,
        what,
        unit,
        plausible: Some((lo, hi)),
        limit: Some((-SQUARED_LIMIT, SQUARED_LIMIT, SQUARED)),
    }
}

/// The exponent `b` of a decaying wear law beyond which `W^b` overflows or vanishes for
/// every work rate outside `[1e-10, 1e10]` W (`e^709` is the largest `f64`, `ln 1e10 ≈ 23`).
pub(super) const WEAR_EXPONENT_LIMIT: f64 = 30.0;

/// Every numeric key of the case schema that has a plausible range, or a refused one, or a
/// minimum of a whole number (see the module doc). Ranges are of the value as written, in
/// the key's unit.
pub(super) const QUANTITIES: &[Quantity] = &[
    // [time]: checked against the stability limit and the number of steps
    described(&["time.dt"], "a time step", "s"),
    described(&["time.duration"], "a duration", "s"),
    // [structure]: a point mass
    real(&["structure.mass"], "a mass", "kg", 1e-6, 1e6),
    real(
        &["structure.position[*]"],
        "a coordinate",
        "m",
        COORDINATE.0,
        COORDINATE.1,
    ),
    // a modal basis inline
    real(
        &["structure.frequencies_hz[*]"],
        "a natural frequency",
        "Hz",
        FREQUENCY.0,
        FREQUENCY.1,
    ),
    real(
        &["structure.damping_ratio", "structure.damping_ratio[*]"],
        "a modal damping ratio",
        "",
        0.0,
        1.0,
    ),
    real(
        &["structure.points[*].coords[*]"],
        "a coordinate",
        "m",
        COORDINATE.0,
        COORDINATE.1,
    ),
    real(
        &["structure.points[*].s", "structure.points[*].x"],
        "an abscissa along the tube",
        "m",
        COORDINATE.0,
        COORDINATE.1,
    ),
    // a tube
    real(
        &["structure.outer_diameter"],
        "a tube's outer diameter",
        "m",
        1e-3,
        2.0,
    ),
    real(
        &["structure.wall_thickness"],
        "a tube's wall thickness",
        "m",
        1e-5,
        0.2,
    ),
    real(
        &["structure.young_modulus"],
        "a Young's modulus",
        "Pa",
        1e9,
        1e12,
    ),
    real(
        &["structure.poisson_ratio"],
        "a Poisson's ratio",
        "",
        0.0,
        0.5,
    ),
    real(
        &["structure.density"],
        "a tube's density",
        "kg/m³",
        1e3,
        2.5e4,
    ),
    real(
        &[
            "structure.inner_fluid_density",
            "structure.outer_fluid_density",
        ],
        "a fluid's density",
        "kg/m³",
        0.0,
        FLUID_DENSITY.1,
    ),
    real(
        &["structure.added_mass_coefficient"],
        "an added-mass coefficient",
        "",
        0.0,
        10.0,
    ),
    real(
        &["structure.mesh_size"],
        "an element length",
        "m",
        1e-4,
        10.0,
    ),
    real(
        &[
            "structure.path[*][*]",
            "structure.supports[*].at[*]",
            "structure.points[*].at[*]",
        ],
        "a coordinate",
        "m",
        COORDINATE.0,
        COORDINATE.1,
    ),
    real(
        &["structure.points[*].offset[*]"],
        "an offset from the tube's axis",
        "m",
        -1.0,
        1.0,
    ),
    real(
        &["structure.u_bend.leg_length"],
        "a leg length",
        "m",
        1e-3,
        1e3,
    ),
    real(
        &["structure.u_bend.radius"],
        "a bend radius",
        "m",
        1e-3,
        1e2,
    ),
    real(
        &["structure.max_frequency_hz"],
        "a frequency",
        "Hz",
        FREQUENCY.0,
        FREQUENCY.1,
    ),
    real(
        &["structure.rayleigh.alpha"],
        "Rayleigh's α",
        "1/s",
        0.0,
        1e3,
    ),
    real(&["structure.rayleigh.beta"], "Rayleigh's β", "s", 0.0, 1e-2),
    real(
        &["structure.supports[*].stiffness[*]"],
        "a support's spring stiffness",
        "N/m or N·m/rad",
        0.0,
        1e15,
    ),
    whole(&["structure.modes"], "a number of modes", 1),
    // an analytic pinned beam
    real(&["structure.length"], "a beam's length", "m", 1e-3, 1e3),
    real(
        &["structure.bending_stiffness"],
        "a bending stiffness EI",
        "N·m²",
        1e-3,
        1e10,
    ),
    real(
        &["structure.mass_per_length"],
        "a mass per unit length",
        "kg/m",
        1e-3,
        1e4,
    ),
    real(
        &["structure.axial_stiffness"],
        "an axial stiffness EA",
        "N",
        0.0,
        1e12,
    ),
    whole(
        &["structure.modes_per_plane"],
        "a number of modes per plane",
        1,
    ),
    whole(&["structure.axial_modes"], "a number of axial modes", 0),
    // [initial]
    real(
        &["initial.displacement[*]"],
        "a displacement",
        "m",
        -1.0,
        1.0,
    ),
    real(&["initial.velocity[*]"], "a velocity", "m/s", -100.0, 100.0),
    // [[contacts]]
    real(
        &["contacts[*].radius", "contacts[*].radii[*]"],
        "a tube's outer radius",
        "m",
        0.0,
        1.0,
    ),
    real(
        &[
            "contacts[*].obstacle.origin[*]",
            "contacts[*].obstacle.centre[*]",
        ],
        "a coordinate",
        "m",
        COORDINATE.0,
        COORDINATE.1,
    ),
    squared(&["contacts[*].obstacle.gap"], "a gap", "m", -0.1, 0.1),
    squared(
        &["contacts[*].obstacle.clearance"],
        "a radial clearance",
        "m",
        0.0,
        0.1,
    ),
    real(
        &[
            "contacts[*].obstacle.vertices[*][*]",
            "contacts[*].obstacle.polar[*][1]",
        ],
        "a hole's size",
        "m",
        -1.0,
        1.0,
    ),
    real(
        &["contacts[*].motion.velocity[*]"],
        "an obstacle's velocity",
        "m/s",
        -10.0,
        10.0,
    ),
    real(
        &[
            "contacts[*].motion.amplitude[*]",
            "contacts[*].motion.table[*][1]",
            "contacts[*].motion.table[*][2]",
            "contacts[*].motion.table[*][3]",
        ],
        "an obstacle's displacement",
        "m",
        -1.0,
        1.0,
    ),
    real(
        &["contacts[*].motion.frequency_hz"],
        "a frequency",
        "Hz",
        0.0,
        1e5,
    ),
    real(
        &["contacts[*].normal.stiffness"],
        "a contact stiffness",
        "N/m",
        1e2,
        1e11,
    ),
    real(
        &["contacts[*].normal.damping"],
        "a contact damping",
        "N·s/m",
        0.0,
        1e6,
    ),
    real(
        &["contacts[*].preload.interference"],
        "an interference",
        "m",
        0.0,
        1e-2,
    ),
    real(
        &["contacts[*].preload.force"],
        "a contact force at rest",
        "N",
        0.0,
        1e4,
    ),
    real(
        &[
            "contacts[*].friction.mu",
            "contacts[*].friction.mu_static",
            "contacts[*].friction.mu_dynamic",
        ],
        "a friction coefficient",
        "",
        0.0,
        2.0,
    ),
    // a flat bar's width and its points across it (case/flat_bar.rs)
    real(&["contacts[*].width"], "a bar's width", "m", 1e-3, 0.2),
    Quantity {
        keys: &["contacts[*].points_across"],
        kind: Kind::Whole { min: 1 },
        what: "a number of contact points across a bar's width",
        unit: "",
        plausible: Some((1.0, 21.0)),
        limit: None,
    },
    // a contact's wear (docs/WEAR.md)
    real(
        &[
            "contacts[*].wear.tube.coefficient",
            "contacts[*].wear.support.coefficient",
            "statistics.wear_coefficient",
        ],
        "an Archard wear coefficient",
        "Pa⁻¹",
        WEAR_COEFFICIENT.0,
        WEAR_COEFFICIENT.1,
    ),
    Quantity {
        keys: &["contacts[*].wear.tube.b", "contacts[*].wear.support.b"],
        kind: Kind::Real,
        what: "a wear law's exponent of the work rate",
        unit: "",
        plausible: Some((0.0, 5.0)),
        limit: Some((
            -WEAR_EXPONENT_LIMIT,
            WEAR_EXPONENT_LIMIT,
            "the volume rate A W^b would overflow or vanish for every work rate outside 1e-10 to 1e10 W",
        )),
    },
    real(
        &[
            "contacts[*].wear.scar.width",
            "contacts[*].wear.scar.tube_radius",
            "contacts[*].wear.scar.other_radius",
        ],
        "a tube's or a support's size",
        "m",
        SIZE.0,
        SIZE.1,
    ),
    real(
        &["contacts[*].wear.scar.thickness"],
        "a support plate's thickness",
        "m",
        1e-4,
        0.5,
    ),
    real(
        &["contacts[*].wear.scar.land_width"],
        "a land's width",
        "m",
        0.0,
        0.1,
    ),
    real(
        &["contacts[*].wear.scar.length"],
        "a scar's length",
        "m",
        0.0,
        10.0,
    ),
    Quantity {
        keys: &["contacts[*].wear.scar.lobes"],
        kind: Kind::Whole { min: 1 },
        what: "a number of lobes",
        unit: "",
        plausible: Some((2.0, 12.0)),
        limit: None,
    },
    // loads
    squared(&["loads[*].force[*]"], "a force", "N", -1e7, 1e7),
    squared(
        &["line_loads[*].force_per_length[*]"],
        "a force per unit length",
        "N/m",
        -1e6,
        1e6,
    ),
    squared(
        &["base_excitation.acceleration[*]"],
        "an acceleration",
        "m/s²",
        -1e4,
        1e4,
    ),
    real(
        &[
            "loads[*].history.frequency_hz",
            "modal_loads[*].history.frequency_hz",
            "line_loads[*].history.frequency_hz",
            "base_excitation.history.frequency_hz",
            "loads[*].history.terms[*][1]",
            "modal_loads[*].history.terms[*][1]",
            "line_loads[*].history.terms[*][1]",
            "base_excitation.history.terms[*][1]",
        ],
        "a load's frequency",
        "Hz",
        0.0,
        1e5,
    ),
    // [[turbulence]] (its f_max is checked against the time step where it is built)
    real(
        &["turbulence[*].correlation_length"],
        "a correlation length",
        "m",
        0.0,
        1e3,
    ),
    real(&["turbulence[*].f_max"], "a band limit", "Hz", 0.0, 1e5),
    real(
        &["turbulence[*].spectrum.frequency_hz[*]"],
        "a frequency",
        "Hz",
        0.0,
        1e5,
    ),
    real(
        &["turbulence[*].spectrum.velocity"],
        "a flow velocity",
        "m/s",
        VELOCITY.0,
        VELOCITY.1,
    ),
    real(
        &["turbulence[*].spectrum.density"],
        "a fluid's density",
        "kg/m³",
        FLUID_DENSITY.0,
        FLUID_DENSITY.1,
    ),
    real(
        &["turbulence[*].spectrum.diameter"],
        "a tube's outer diameter",
        "m",
        1e-3,
        2.0,
    ),
    real(
        &["turbulence[*].spectrum.beta"],
        "a spectrum's high-frequency slope",
        "",
        1.0,
        10.0,
    ),
    real(
        &["turbulence[*].spectrum.reduced_cutoff"],
        "a reduced cut-off frequency",
        "",
        1e-3,
        10.0,
    ),
    whole(&["turbulence[*].seed"], "a seed", 0),
    // [flow]
    real(
        &["flow.pitch_ratio"],
        "a pitch-to-diameter ratio",
        "",
        1.0,
        5.0,
    ),
    real(
        &["flow.connors_constant"],
        "Connors' constant",
        "",
        0.5,
        20.0,
    ),
    real(
        &["flow.diameter"],
        "a tube's outer diameter",
        "m",
        1e-3,
        2.0,
    ),
    real(
        &["flow.mass_per_length"],
        "a mass per unit length",
        "kg/m",
        1e-3,
        1e4,
    ),
    real(
        &[
            "flow.zones[*].density",
            "flow.zones[*].liquid_density",
            "flow.zones[*].gas_density",
        ],
        "a fluid's density",
        "kg/m³",
        FLUID_DENSITY.0,
        FLUID_DENSITY.1,
    ),
    real(
        &[
            "flow.zones[*].velocity",
            "flow.zones[*].velocity_profile[*][1]",
        ],
        "a flow velocity",
        "m/s",
        VELOCITY.0,
        VELOCITY.1,
    ),
    real(
        &[
            "flow.zones[*].fluid_elastic.lift_slope",
            "flow.zones[*].fluid_elastic.drag_slope",
            "flow.zones[*].fluid_elastic.drag",
        ],
        "a fluid force coefficient",
        "",
        -100.0,
        100.0,
    ),
    real(
        &["flow.zones[*].fluid_elastic.mu"],
        "a time-lag factor",
        "",
        0.0,
        10.0,
    ),
    real(
        &["flow.zones[*].fluid_elastic.reduced_velocity[*]"],
        "a reduced velocity",
        "",
        0.0,
        1e3,
    ),
    Quantity {
        keys: &["flow.zones[*].fluid_elastic.delay_segments"],
        kind: Kind::Whole { min: 1 },
        what: "a number of delay segments",
        unit: "",
        plausible: Some((1.0, 1e3)),
        limit: None,
    },
    // [tangential]
    real(
        &["tangential.penalty.stiffness"],
        "a tangential penalty stiffness",
        "N/m",
        1e2,
        1e11,
    ),
    real(
        &["tangential.penalty.damping"],
        "a tangential penalty damping",
        "N·s/m",
        0.0,
        1e6,
    ),
    whole(
        &["tangential.gauss_seidel.max_sweeps"],
        "a number of sweeps",
        1,
    ),
    whole(
        &["tangential.active_set.max_iterations"],
        "a number of iterations",
        1,
    ),
    described(
        &[
            "tangential.gauss_seidel.tolerance",
            "tangential.gauss_seidel.residual_tolerance",
        ],
        "a relative tolerance",
        "",
    ),
    // [output], [statistics]
    whole(&["output.every"], "a number of steps", 1),
    whole(&["statistics.batches"], "a number of batches", 2),
    described(
        &[
            "statistics.t_start",
            "statistics.t_end",
            "statistics.block",
            "statistics.rest_duration",
        ],
        "a time",
        "s",
    ),
    described(
        &[
            "statistics.target_relative_error",
            "statistics.max_relative_error",
        ],
        "a relative error",
        "",
    ),
    // [life]
    real(
        &["life.target_years"],
        "a service time",
        "years",
        0.0,
        200.0,
    ),
    real(&["life.criterion_depth"], "a wear depth", "m", 0.0, 0.1),
];

/// Whether the key path `key` (`contacts[0].friction.mu`) is `pattern`
/// (`contacts[*].friction.mu`: `[*]` any index).
fn matches(pattern: &str, key: &str) -> bool {
    let (mut p, mut k) = (pattern.as_bytes(), key.as_bytes());
    loop {
        match (p.first(), k.first()) {
            (None, None) => return true,
            (Some(b'['), Some(b'[')) if p.starts_with(b"[*]") => {
                let Some(close) = k.iter().position(|&c| c == b']') else {
                    return false;
                };
                if close == 1 || !k[1..close].iter().all(u8::is_ascii_digit) {
                    return false;
                }
                p = &p[3..];
                k = &k[close + 1..];
            }
            (Some(a), Some(b)) if a == b => {
                p = &p[1..];
                k = &k[1..];
            }
            _ => return false,
        }
    }
}

/// The quantity of the key path `key`, if the table has it. A key of a `[[structures]]`
/// entry (`structures[1].structure.density`) is the key of the same section of a
/// one-structure case (`structure.density`).
pub(super) fn quantity(key: &str) -> Option<&'static Quantity> {
    let key = key
        .strip_prefix("structures[")
        .and_then(|rest| rest.split_once("]."))
        .filter(|(index, _)| index.bytes().all(|c| c.is_ascii_digit()))
        .map_or(key, |(_, rest)| rest);
    QUANTITIES
        .iter()
        .find(|q| q.keys.iter().any(|p| matches(p, key)))
}

/// What the value of `key` must be, in words, if the table knows: "a whole number ≥ 1",
/// "a number (a friction coefficient)", "a number (a gap in m)".
pub(super) fn expected(key: &str) -> Option<String> {
    let q = quantity(key)?;
    Some(match q.kind {
        Kind::Whole { min } => format!("a whole number ≥ {min} ({})", q.what),
        Kind::Real if q.unit.is_empty() => format!("a number ({})", q.what),
        Kind::Real => format!("a number ({} in {})", q.what, q.unit),
    })
}

/// `value unit` for a message.
fn with_unit(value: f64, unit: &str) -> String {
    if unit.is_empty() {
        number(value)
    } else {
        format!("{} {unit}", number(value))
    }
}

/// Checks every number of the case file's tree `case` against [`QUANTITIES`]: refuses a
/// value outside its refused range (naming the key as written), and returns a warning for
/// each value outside its plausible range, one line each:
/// `structure.density = 8.2 kg/m³ is outside the range of a tube's density, 1000 to 25000
/// kg/m³: check the value and its unit`. Values that are not finite numbers are left to the
/// checks of their key.
pub(super) fn check(case: &toml::Value) -> Result<Vec<String>> {
    let mut warnings = Vec::new();
    visit(case, &mut String::new(), &mut warnings)?;
    Ok(warnings)
}

fn visit(v: &toml::Value, path: &mut String, warnings: &mut Vec<String>) -> Result<()> {
    let len = path.len();
    match v {
        toml::Value::Table(t) => {
            for (k, child) in t {
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(k);
                visit(child, path, warnings)?;
                path.truncate(len);
            }
        }
        toml::Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                path.push_str(&format!("[{i}]"));
                visit(child, path, warnings)?;
                path.truncate(len);
            }
        }
        toml::Value::Integer(i) => check_number(*i as f64, path, warnings)?,
        toml::Value::Float(x) => check_number(*x, path, warnings)?,
        _ => {}
    }
    Ok(())
}

fn check_number(x: f64, key: &str, warnings: &mut Vec<String>) -> Result<()> {
    let Some(q) = quantity(key).filter(|_| x.is_finite()) else {
        return Ok(());
    };
    if let Some((lo, hi, why)) = q.limit.filter(|(lo, hi, _)| !(*lo..=*hi).contains(&x)) {
        return Err(Error::invalid(
            key,
            format!(
                "{} is beyond what can be computed with ({} to {}): {why}; check the value and its unit",
                with_unit(x, q.unit),
                with_unit(lo, q.unit),
                with_unit(hi, q.unit)
            ),
        ));
    }
    if let Some((lo, hi)) = q.plausible.filter(|(lo, hi)| !(*lo..=*hi).contains(&x)) {
        warnings.push(format!(
            "{key} = {} is outside the range of {}, {} to {}: check the value and its unit",
            with_unit(x, q.unit),
            q.what,
            number(lo),
            with_unit(hi, q.unit)
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_patterns_match_indices_only_where_they_say() {
        assert!(matches(
            "contacts[*].friction.mu",
            "contacts[0].friction.mu"
        ));
        assert!(matches(
            "contacts[*].friction.mu",
            "contacts[12].friction.mu"
        ));
        assert!(!matches(
            "contacts[*].friction.mu",
            "contacts[].friction.mu"
        ));
        assert!(!matches(
            "contacts[*].friction.mu",
            "contacts[a].friction.mu"
        ));
        assert!(!matches(
            "contacts[*].friction.mu",
            "contacts[0].friction.mu_static"
        ));
        assert!(matches(
            "contacts[*].motion.table[*][1]",
            "contacts[0].motion.table[3][1]"
        ));
        assert!(!matches(
            "contacts[*].motion.table[*][1]",
            "contacts[0].motion.table[3][0]"
        ));
        assert!(matches(
            "structure.damping_ratio[*]",
            "structure.damping_ratio[2]"
        ));
        assert!(!matches(
            "structure.damping_ratio",
            "structure.damping_ratio[2]"
        ));
        // a [[structures]] entry's keys are those of a one-structure case
        let density = quantity("structure.density").map(|q| q.what);
        assert_eq!(
            quantity("structures[3].structure.density").map(|q| q.what),
            density
        );
        assert!(quantity("structures[x].structure.density").is_none());
        assert!(quantity("structures[0].name").is_none());
    }

    /// Every pattern is well formed, listed once, and its ranges ordered.
    #[test]
    fn the_table_is_consistent() {
        let mut seen = std::collections::HashSet::new();
        for q in QUANTITIES {
            assert!(!q.what.is_empty());
            for key in q.keys {
                assert!(seen.insert(*key), "{key} is listed twice");
                assert!(!key.contains(' ') && !key.ends_with('.'), "{key}");
            }
            if let Some((lo, hi)) = q.plausible {
                assert!(lo <= hi, "{:?}", q.keys);
            }
            if let Some((lo, hi, _)) = q.limit {
                assert!(lo <= hi, "{:?}", q.keys);
                // a refused value is implausible first
                let (plo, phi) = q.plausible.expect("a limit comes with a plausible range");
                assert!(lo <= plo && phi <= hi, "{:?}", q.keys);
            }
        }
    }

    #[test]
    fn a_value_out_of_its_range_warns_in_one_line() {
        let case: toml::Value = toml::from_str(
            "[structure]\ndensity = 8.2\nmass = 1.0\n[[contacts]]\nfriction = { mu = 1e6 }\n",
        )
        .unwrap();
        let warnings = check(&case).unwrap();
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        for w in [
            "structure.density = 8.2 kg/m³ is outside the range of a tube's density, 1000 to 25000 kg/m³: check the value and its unit",
            "contacts[0].friction.mu = 1e6 is outside the range of a friction coefficient, 0 to 2: check the value and its unit",
        ] {
            assert!(warnings.iter().any(|x| x == w), "{warnings:?}");
        }
        // a value that cannot be computed with is refused, naming the key
        let case: toml::Value = toml::from_str(
            "[[contacts]]
wear = { tube = { b = -1e300 } }
",
        )
        .unwrap();
        let err = check(&case).unwrap_err();
        assert_eq!(err.field(), Some("contacts[0].wear.tube.b"));
    }
}
