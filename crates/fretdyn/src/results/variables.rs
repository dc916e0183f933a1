//! Names, dimensions, units and long names of the time histories of a run (the keys of
//! `results.npz`, THEORY §5), and of the coordinates along their dimensions: the one table
//! that self-describing outputs (`results.nc`, the Python package's `Result.to_xarray()`)
//! and plot labels take their metadata from. Units are UDUNITS strings (`m s-1`); the modal
//! coordinates of mass-normalised modes are in `kg^0.5 m` (`Φᵀ M Φ = I`, THEORY §1).

/// Dimension of the samples (`[output] every` decimates).
pub const TIME: &str = "time";
/// Dimension of the contacts, in the order of the case file.
pub const CONTACT: &str = "contact";
/// Dimension of the modes of the basis.
pub const MODE: &str = "mode";
/// Dimension of the two components of a tangential vector or of a position relative to the
/// obstacle (each variable's long name says what they are).
pub const DIRECTION: &str = "direction";

/// A variable or coordinate: its name, dimensions, units and long name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Variable {
    /// Name: the key of `results.npz` for a variable.
    pub name: &'static str,
    /// Dimensions, in the order of the array's axes.
    pub dims: &'static [&'static str],
    /// Units (UDUNITS; `1` for a dimensionless number or a code).
    pub units: &'static str,
    /// What it is.
    pub long_name: &'static str,
    /// For a code: its values' meanings, in the order of the values 0, 1, 2, … (CF
    /// `flag_values`/`flag_meanings`); empty otherwise.
    pub flag_meanings: &'static [&'static str],
}

const fn variable(
    name: &'static str,
    dims: &'static [&'static str],
    units: &'static str,
    long_name: &'static str,
) -> Variable {
    Variable {
        name,
        dims,
        units,
        long_name,
        flag_meanings: &[],
    }
}

/// The time histories of a run, in the order of `results.npz`
/// ([`crate::results::output::write_results_npz`]). `t` is the time coordinate.
pub const VARIABLES: [Variable; 9] = [
    variable("t", &[TIME], "s", "time"),
    variable(
        "q",
        &[TIME, MODE],
        "kg^0.5 m",
        "modal displacement (mass-normalised modes)",
    ),
    variable(
        "qdot",
        &[TIME, MODE],
        "kg^0.5 m s-1",
        "modal velocity (full step, mass-normalised modes)",
    ),
    variable(
        "contact_normal_force",
        &[TIME, CONTACT],
        "N",
        "normal contact force R_N >= 0",
    ),
    variable(
        "contact_tangential_force",
        &[TIME, CONTACT, DIRECTION],
        "N",
        "tangential force of the obstacle on the structure, in the contact's tangent basis (t1, t2)",
    ),
    variable(
        "contact_slip_velocity",
        &[TIME, CONTACT, DIRECTION],
        "m s-1",
        "tangential velocity relative to the obstacle (full step), in the contact's tangent basis (t1, t2)",
    ),
    variable(
        "contact_penetration",
        &[TIME, CONTACT],
        "m",
        "penetration (negative: remaining clearance)",
    ),
    Variable {
        name: "contact_status",
        dims: &[TIME, CONTACT],
        units: "1",
        long_name: "contact status: 0 open, 1 stick, 2 slip",
        flag_meanings: &["open", "stick", "slip"],
    },
    variable(
        "contact_position",
        &[TIME, CONTACT, DIRECTION],
        "m",
        "position of the point relative to the obstacle: in a hole, the offset from its centre in the hole's axes (e1, e2); for a plane or bars, the distance from the plane and the position along t1",
    ),
];

/// The coordinates of the dimensions and what else is known along them: `time` (the samples'
/// times, `t`), `contact` (the contacts' names), `point` (the structure point of each
/// contact), `mode` (mode numbers from 1), `frequency` (the modes' natural frequencies),
/// `direction` (1 and 2, the components).
pub const COORDINATES: [Variable; 6] = [
    variable(TIME, &[TIME], "s", "time"),
    variable(CONTACT, &[CONTACT], "", "contact name"),
    variable("point", &[CONTACT], "", "structure point of the contact"),
    variable(MODE, &[MODE], "1", "mode number (from 1)"),
    variable("frequency", &[MODE], "Hz", "natural frequency of the mode"),
    variable(
        DIRECTION,
        &[DIRECTION],
        "1",
        "component (1, 2): see the long name of each variable",
    ),
];

/// The variable or coordinate called `name`.
pub fn find(name: &str) -> Option<&'static Variable> {
    VARIABLES
        .iter()
        .chain(&COORDINATES)
        .find(|v| v.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::recorder::Recorder;

    /// Every array of the recorder is described, with as many dimensions as it has axes.
    #[test]
    fn every_time_history_has_its_dimensions() {
        let r = Recorder::new(3, 4, 2);
        let ndims = [
            r.t.ndim(),
            r.q.ndim(),
            r.qdot.ndim(),
            r.normal_force.ndim(),
            r.tangential_force.ndim(),
            r.slip_velocity.ndim(),
            r.penetration.ndim(),
            r.status.ndim(),
            r.position.ndim(),
        ];
        for (v, n) in VARIABLES.iter().zip(ndims) {
            assert_eq!(v.dims.len(), n, "{}", v.name);
            assert_eq!(v.dims[0], TIME, "{}", v.name);
            assert!(!v.units.is_empty() && !v.long_name.is_empty(), "{}", v.name);
        }
        // the names are the keys of results.npz, each once
        let mut names: Vec<&str> = VARIABLES.iter().map(|v| v.name).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), VARIABLES.len());
        // every dimension has its coordinate
        for v in &VARIABLES {
            for d in v.dims {
                assert!(find(d).is_some_and(|c| c.dims == [*d]), "{d}");
            }
        }
    }
}
