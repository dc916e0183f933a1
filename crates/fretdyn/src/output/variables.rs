//! The one table of names, dimensions, units and long names of a run's time histories (the
//! keys of `results.npz`, THEORY §5) and of the coordinates along their dimensions. Every
//! self-describing output takes its metadata from here, and nowhere else: `results.nc`
//! (`crate::output::netcdf`), the Python package's `Result.to_xarray()` and its plot labels
//! (`fretdyn.variables()`). `xarray.open_dataset("results.nc")` and `to_xarray()` are then the
//! same Dataset.
//!
//! - dimensions: [`TIME`], [`MODE`], [`CONTACT`], [`TANGENT`] (t1, t2: the contact's tangent
//!   basis), [`LOCAL_AXIS`] (e1, e2: the obstacle's axes of `contact_position`), [`POINT`]
//!   and [`DIRECTION`] (x, y, z: the global frame);
//! - the time histories ([`time_histories`]): the key `t` is the coordinate `time`, every
//!   other key keeps its name;
//! - the coordinates ([`COORDINATES`]): `mode` (numbers from 1) with `frequency` and
//!   `damping_ratio`; `contact` (names) with `contact_point` and `contact_obstacle`; `point`
//!   (names) with `point_position`; the labels of `tangent`, `local_axis` and `direction`.
//!   Their values come from the model ([`Labels`]);
//! - of a model of several structures or with two-body contacts only (THEORY §15), after
//!   them ([`NEIGHBOUR_COORDINATES`], [`Labels::coordinates`]): `structure` (names, a
//!   dimension) with `mode_structure` and `point_structure` (the structure of each mode and
//!   point), and `contact_other_point` (point B of a two-body contact, empty for an
//!   obstacle). A model of one structure without them keeps its files as they were.
//!
//! Units are UDUNITS strings, products by a space and powers by a number (`m s-1`,
//! `kg^0.5 m`); `1` for a dimensionless number or a code; names have none. The modal
//! coordinates of mass-normalised modes are in `kg^0.5 m` (`Φᵀ M Φ = I`, THEORY §1): the
//! displacement is the mode shape (m kg^-0.5) times `q`. A model in physical coordinates
//! ([`crate::model::Coordinates::Physical`]) has `q` in m and `q̇` in `m s-1`.

use crate::model::{Coordinates, Model, StructureRange};

/// Dimension of the samples (`[output] every` decimates); unlimited in `results.nc`.
pub const TIME: &str = "time";
/// Dimension of the modes of the basis (of the degrees of freedom in physical coordinates).
pub const MODE: &str = "mode";
/// Dimension of the contacts, in the order of the case file.
pub const CONTACT: &str = "contact";
/// Dimension of the two components of a tangential vector in the contact's tangent basis
/// (`t1`, `t2`).
pub const TANGENT: &str = "tangent";
/// Dimension of the two components of `contact_position` in the obstacle's axes (`e1`,
/// `e2`).
pub const LOCAL_AXIS: &str = "local_axis";
/// Dimension of the structure's named points.
pub const POINT: &str = "point";
/// Dimension of the three components of a position in the global frame (`x`, `y`, `z`).
pub const DIRECTION: &str = "direction";
/// Dimension of the structures of a model of several (THEORY §15); absent otherwise.
pub const STRUCTURE: &str = "structure";

/// A variable or coordinate as `results.nc` and `to_xarray()` name and describe it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Variable {
    /// Name in `results.nc` and in `to_xarray()`.
    pub name: &'static str,
    /// Dimensions, in the order of the array's axes.
    pub dims: &'static [&'static str],
    /// Units (UDUNITS; `1` for a dimensionless number or a code); `None` for names.
    pub units: Option<&'static str>,
    /// What it is.
    pub long_name: &'static str,
    /// For a code: its values' meanings, in the order of the values 0, 1, 2, … (CF
    /// `flag_values`, of the variable's type, and `flag_meanings`, joined by spaces); empty
    /// otherwise.
    pub flag_meanings: &'static [&'static str],
}

/// A time history of a run: the key of `results.npz` (and of the Python `Result`) and its
/// description.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TimeHistory {
    /// Key of `results.npz`.
    pub key: &'static str,
    /// Name, dimensions, units, long name.
    pub variable: Variable,
}

/// Where the values of a coordinate come from ([`Labels::values`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// `1, 2, …, p` (`i32`).
    ModeNumbers,
    /// `ω_i / 2π`, Hz.
    Frequencies,
    /// `ξ_i`.
    DampingRatios,
    /// The contacts' names.
    ContactNames,
    /// The name of each contact's structure point.
    ContactPoints,
    /// Each contact's obstacle type ([`crate::contact::obstacle::Obstacle::kind`]).
    ContactObstacles,
    /// The points' names.
    PointNames,
    /// The points' reference positions, row-major (point, direction), m.
    PointPositions,
    /// The structures' names (a model of several).
    StructureNames,
    /// The name of each mode's structure.
    ModeStructures,
    /// The name of each point's structure.
    PointStructures,
    /// The name of point B of each two-body contact, empty for a contact with an obstacle.
    ContactOtherPoints,
    /// Fixed labels.
    Fixed(&'static [&'static str]),
}

/// A coordinate: its description and where its values come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Coordinate {
    /// Name, dimensions, units, long name.
    pub variable: Variable,
    /// Its values.
    pub source: Source,
}

const fn v(
    name: &'static str,
    dims: &'static [&'static str],
    units: Option<&'static str>,
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

const fn history(key: &'static str, variable: Variable) -> TimeHistory {
    TimeHistory { key, variable }
}

const TC: &[&str] = &[TIME, CONTACT];
const TCT: &[&str] = &[TIME, CONTACT, TANGENT];

/// The time histories in modal coordinates, in the order of `results.npz`
/// ([`crate::output::summary::write_results_npz`]).
const MODAL: [TimeHistory; 9] = [
    history("t", v(TIME, &[TIME], Some("s"), "time")),
    history(
        "q",
        v(
            "q",
            &[TIME, MODE],
            Some("kg^0.5 m"),
            "modal displacement (mass-normalised modes: displacement = mode shape × q)",
        ),
    ),
    history(
        "qdot",
        v(
            "qdot",
            &[TIME, MODE],
            Some("kg^0.5 m s-1"),
            "modal velocity (full step, mass-normalised modes)",
        ),
    ),
    history(
        "contact_normal_force",
        v(
            "contact_normal_force",
            TC,
            Some("N"),
            "normal contact force magnitude R_N (>= 0)",
        ),
    ),
    history(
        "contact_tangential_force",
        v(
            "contact_tangential_force",
            TCT,
            Some("N"),
            "tangential force of the obstacle on the structure, in the contact's tangent basis (t1, t2)",
        ),
    ),
    history(
        "contact_slip_velocity",
        v(
            "contact_slip_velocity",
            TCT,
            Some("m s-1"),
            "tangential velocity relative to the obstacle (full step), in the contact's tangent basis (t1, t2)",
        ),
    ),
    history(
        "contact_penetration",
        v(
            "contact_penetration",
            TC,
            Some("m"),
            "penetration (negative: the remaining clearance)",
        ),
    ),
    history(
        "contact_status",
        Variable {
            name: "contact_status",
            dims: TC,
            units: Some("1"),
            long_name: "contact status: 0 open, 1 stick, 2 slip",
            flag_meanings: &["open", "stick", "slip"],
        },
    ),
    history(
        "contact_position",
        v(
            "contact_position",
            &[TIME, CONTACT, LOCAL_AXIS],
            Some("m"),
            "the point relative to the obstacle: in a hole, the tube centre's offset from the hole's centre in the hole's axes (e1, e2); for a plane or bars, the distance from the plane (e1) and the position along t1 (e2)",
        ),
    ),
];

/// `q` and `q̇` of a model in physical coordinates.
const PHYSICAL_Q: Variable = v(
    "q",
    &[TIME, MODE],
    Some("m"),
    "displacement (physical coordinates)",
);
const PHYSICAL_QDOT: Variable = v(
    "qdot",
    &[TIME, MODE],
    Some("m s-1"),
    "velocity (physical coordinates, full step)",
);

/// The time histories of a run, in the order of `results.npz`: of a modal model (`modal`,
/// `q` in `kg^0.5 m`) or of one in physical coordinates (`q` in m).
pub fn time_histories(modal: bool) -> [TimeHistory; 9] {
    let mut out = MODAL;
    if !modal {
        for h in &mut out {
            match h.key {
                "q" => h.variable = PHYSICAL_Q,
                "qdot" => h.variable = PHYSICAL_QDOT,
                _ => {}
            }
        }
    }
    out
}

/// The coordinates besides `time` (a time history), in the order `results.nc` writes them.
/// Those that are not a dimension (`frequency`, `contact_point`, `point_position`, …) are
/// auxiliary coordinates ([`auxiliary_coordinates`]).
pub const COORDINATES: [Coordinate; 11] = [
    Coordinate {
        variable: v(
            MODE,
            &[MODE],
            Some("1"),
            "mode number, from 1, in the order of the modal basis",
        ),
        source: Source::ModeNumbers,
    },
    Coordinate {
        variable: v(
            "frequency",
            &[MODE],
            Some("Hz"),
            "natural frequency of the mode (undamped, without contact)",
        ),
        source: Source::Frequencies,
    },
    Coordinate {
        variable: v("damping_ratio", &[MODE], Some("1"), "modal damping ratio"),
        source: Source::DampingRatios,
    },
    Coordinate {
        variable: v(CONTACT, &[CONTACT], None, "contact name"),
        source: Source::ContactNames,
    },
    Coordinate {
        variable: v(
            "contact_point",
            &[CONTACT],
            None,
            "the structure point of the contact",
        ),
        source: Source::ContactPoints,
    },
    Coordinate {
        variable: v(
            "contact_obstacle",
            &[CONTACT],
            None,
            "obstacle type (plane, circle, bi_plane, polygon)",
        ),
        source: Source::ContactObstacles,
    },
    Coordinate {
        variable: v(
            TANGENT,
            &[TANGENT],
            None,
            "direction of the contact's tangent basis",
        ),
        source: Source::Fixed(&["t1", "t2"]),
    },
    Coordinate {
        variable: v(
            LOCAL_AXIS,
            &[LOCAL_AXIS],
            None,
            "axis of the obstacle's local frame (contact_position)",
        ),
        source: Source::Fixed(&["e1", "e2"]),
    },
    Coordinate {
        variable: v(POINT, &[POINT], None, "structure point name"),
        source: Source::PointNames,
    },
    Coordinate {
        variable: v(
            "point_position",
            &[POINT, DIRECTION],
            Some("m"),
            "reference (undeformed) position of the point",
        ),
        source: Source::PointPositions,
    },
    Coordinate {
        variable: v(DIRECTION, &[DIRECTION], None, "axis of the global frame"),
        source: Source::Fixed(&["x", "y", "z"]),
    },
];

/// The coordinates of a model of several structures (the first three) or with two-body
/// contacts (the last), after [`COORDINATES`]; [`Labels::coordinates`] says which a model
/// has. Names, as `contact_point`: `ds.q.where(ds.mode_structure == "tube_a")`.
pub const NEIGHBOUR_COORDINATES: [Coordinate; 4] = [
    Coordinate {
        variable: v(STRUCTURE, &[STRUCTURE], None, "structure name"),
        source: Source::StructureNames,
    },
    Coordinate {
        variable: v(
            "mode_structure",
            &[MODE],
            None,
            "the structure whose mode (or degree of freedom) it is",
        ),
        source: Source::ModeStructures,
    },
    Coordinate {
        variable: v(
            "point_structure",
            &[POINT],
            None,
            "the structure of the point",
        ),
        source: Source::PointStructures,
    },
    Coordinate {
        variable: v(
            "contact_other_point",
            &[CONTACT],
            None,
            "point B of a two-body contact (its forces act on contact_point, their opposite on it; recorded positions and velocities are of contact_point relative to it); empty for an obstacle",
        ),
        source: Source::ContactOtherPoints,
    },
];

/// The global attribute `comment` of `results.nc` and of `to_xarray()`.
pub const COMMENT: &str = "the arrays of results.npz under their keys, t as the coordinate time (README, \"Reading the results\")";

/// The auxiliary coordinates (coordinates that are not a dimension) along `dims`' dimensions:
/// those whose dimensions are all among `dims`. Of a time history, the CF `coordinates`
/// attribute (`q`: `frequency damping_ratio`; a contact's: `contact_point
/// contact_obstacle`).
pub fn auxiliary_coordinates(dims: &[&str]) -> Vec<&'static str> {
    auxiliary_among(&COORDINATES, dims)
}

fn auxiliary_among(coordinates: &[Coordinate], dims: &[&str]) -> Vec<&'static str> {
    coordinates
        .iter()
        .map(|c| &c.variable)
        .filter(|c| c.dims != [c.name] && c.dims.iter().all(|d| dims.contains(d)))
        .map(|c| c.name)
        .collect()
}

/// The auxiliary coordinates along the dimensions of no time history (`point_position`):
/// xarray reads them as coordinates from the global attribute `coordinates`.
pub fn global_coordinates() -> Vec<&'static str> {
    global_among(&COORDINATES)
}

fn global_among(coordinates: &[Coordinate]) -> Vec<&'static str> {
    let attached: Vec<&str> = MODAL
        .iter()
        .flat_map(|h| auxiliary_among(coordinates, h.variable.dims))
        .collect();
    auxiliary_among(
        coordinates,
        &[
            MODE, CONTACT, TANGENT, LOCAL_AXIS, POINT, DIRECTION, STRUCTURE,
        ],
    )
    .into_iter()
    .filter(|c| !attached.contains(c))
    .collect()
}

/// The time history or coordinate called `name` (in `results.nc`; `t` is `time`), of a modal
/// model.
pub fn find(name: &str) -> Option<Variable> {
    MODAL
        .iter()
        .map(|h| h.variable)
        .chain(COORDINATES.iter().map(|c| c.variable))
        .chain(NEIGHBOUR_COORDINATES.iter().map(|c| c.variable))
        .find(|v| v.name == name)
}

/// The values of a coordinate.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Names.
    Text(Vec<String>),
    /// Integers (mode numbers).
    Int(Vec<i32>),
    /// Numbers, row-major for more than one dimension.
    Float(Vec<f64>),
}

/// The names and reference values of a model that label its results: its contacts, points
/// and modes (a few per contact, point or mode; kept by a streamed run for `results.nc`).
#[derive(Debug, Clone, PartialEq)]
pub struct Labels {
    contacts: Vec<String>,
    contact_points: Vec<String>,
    contact_obstacles: Vec<&'static str>,
    points: Vec<String>,
    /// Reference positions, row-major (point, direction), m.
    point_positions: Vec<f64>,
    /// `ω_i / 2π`, Hz.
    frequencies_hz: Vec<f64>,
    damping_ratios: Vec<f64>,
    modal: bool,
    /// The structures' names, empty for a model of one.
    structures: Vec<String>,
    mode_structures: Vec<String>,
    point_structures: Vec<String>,
    /// Point B of each contact, `None` when the model has no two-body contact and one
    /// structure.
    contact_other_points: Option<Vec<String>>,
}

impl Labels {
    /// The labels of `model`'s results.
    pub fn of(model: &Model) -> Self {
        let b = &model.basis;
        Self {
            contacts: model.contacts.iter().map(|c| c.name.clone()).collect(),
            contact_points: model
                .contacts
                .iter()
                .map(|c| {
                    b.points
                        .get(c.point)
                        .map_or_else(String::new, |p| p.name.clone())
                })
                .collect(),
            contact_obstacles: model.contacts.iter().map(|c| c.obstacle.kind()).collect(),
            points: b.points.iter().map(|p| p.name.clone()).collect(),
            point_positions: b
                .points
                .iter()
                .flat_map(|p| [p.coords.x, p.coords.y, p.coords.z])
                .collect(),
            frequencies_hz: b
                .omega
                .iter()
                .map(|w| w / (2.0 * std::f64::consts::PI))
                .collect(),
            damping_ratios: b.damping_ratio.clone(),
            modal: matches!(model.coordinates, Coordinates::Modal),
            structures: model.structures.iter().map(|s| s.name.clone()).collect(),
            mode_structures: owners(model, b.modes(), |s| &s.modes),
            point_structures: owners(model, b.points.len(), |s| &s.points),
            contact_other_points: neighbours(model).then(|| {
                model
                    .contacts
                    .iter()
                    .map(|c| {
                        c.other()
                            .and_then(|k| b.points.get(k))
                            .map_or_else(String::new, |p| p.name.clone())
                    })
                    .collect()
            }),
        }
    }

    /// The coordinates of the results besides `time`, in the order `results.nc` writes them:
    /// [`COORDINATES`], then those of [`NEIGHBOUR_COORDINATES`] the model has (the structures'
    /// of a model of several, `contact_other_point` of one with two-body contacts or several
    /// structures).
    pub fn coordinates(&self) -> Vec<Coordinate> {
        let several = !self.structures.is_empty();
        let pairs = self.contact_other_points.is_some();
        COORDINATES
            .into_iter()
            .chain(
                NEIGHBOUR_COORDINATES
                    .into_iter()
                    .filter(|c| match c.source {
                        Source::ContactOtherPoints => pairs,
                        _ => several,
                    }),
            )
            .collect()
    }

    /// [`auxiliary_coordinates`] among [`Self::coordinates`].
    pub fn auxiliary_coordinates(&self, dims: &[&str]) -> Vec<&'static str> {
        auxiliary_among(&self.coordinates(), dims)
    }

    /// [`global_coordinates`] among [`Self::coordinates`].
    pub fn global_coordinates(&self) -> Vec<&'static str> {
        global_among(&self.coordinates())
    }

    /// `q` are modal coordinates (else physical ones, in m): the argument of
    /// [`time_histories`].
    pub fn modal(&self) -> bool {
        self.modal
    }

    /// The length of dimension `dim`; `None` for `time` (the run's samples) and for a name
    /// that is no dimension.
    pub fn dimension_len(&self, dim: &str) -> Option<usize> {
        match dim {
            MODE => Some(self.frequencies_hz.len()),
            CONTACT => Some(self.contacts.len()),
            TANGENT | LOCAL_AXIS => Some(2),
            POINT => Some(self.points.len()),
            DIRECTION => Some(3),
            STRUCTURE => Some(self.structures.len()),
            _ => None,
        }
    }

    /// The values of the coordinate whose values come from `source`.
    pub fn values(&self, source: Source) -> Values {
        match source {
            Source::ModeNumbers => Values::Int((1..=self.frequencies_hz.len() as i32).collect()),
            Source::Frequencies => Values::Float(self.frequencies_hz.clone()),
            Source::DampingRatios => Values::Float(self.damping_ratios.clone()),
            Source::ContactNames => Values::Text(self.contacts.clone()),
            Source::ContactPoints => Values::Text(self.contact_points.clone()),
            Source::ContactObstacles => Values::Text(
                self.contact_obstacles
                    .iter()
                    .map(|k| k.to_string())
                    .collect(),
            ),
            Source::PointNames => Values::Text(self.points.clone()),
            Source::PointPositions => Values::Float(self.point_positions.clone()),
            Source::StructureNames => Values::Text(self.structures.clone()),
            Source::ModeStructures => Values::Text(self.mode_structures.clone()),
            Source::PointStructures => Values::Text(self.point_structures.clone()),
            Source::ContactOtherPoints => {
                Values::Text(self.contact_other_points.clone().unwrap_or_default())
            }
            Source::Fixed(labels) => Values::Text(labels.iter().map(|s| s.to_string()).collect()),
        }
    }
}

/// The model has several structures or a two-body contact: its results then say each
/// contact's second point (`contact_other_point`, `other_point`), and are otherwise as
/// those of a model of one structure.
pub fn neighbours(model: &Model) -> bool {
    !model.structures.is_empty() || model.contacts.iter().any(|c| c.pair.is_some())
}

/// For each of `n` modes or points, the name of the structure whose `range` holds it (none
/// for a model of one structure).
fn owners(
    model: &Model,
    n: usize,
    range: impl Fn(&StructureRange) -> &std::ops::Range<usize>,
) -> Vec<String> {
    if model.structures.is_empty() {
        return Vec::new();
    }
    (0..n)
        .map(|i| {
            model
                .structures
                .iter()
                .find(|s| range(s).contains(&i))
                .map_or_else(String::new, |s| s.name.clone())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accumulate::recorder::Recorder;

    /// The multi-span tube: 30 modes, 5 contacts in holes, 6 named points.
    fn tube() -> Model {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/tube_multispan.toml");
        crate::case::Case::from_file(&path).unwrap().model
    }

    const DIMENSIONS: [&str; 7] = [TIME, MODE, CONTACT, TANGENT, LOCAL_AXIS, POINT, DIRECTION];

    /// Every array of the recorder is described, with its dimensions' lengths, and the keys
    /// are those of `results.npz`.
    #[test]
    fn every_time_history_has_its_dimensions() {
        let model = tube();
        let labels = Labels::of(&model);
        let (p, c) = (model.basis.modes(), model.contacts.len());
        assert!(p > 1 && c > 1);
        let r = Recorder::new(3, p, c);
        let shapes = [
            r.t.shape(),
            r.q.shape(),
            r.qdot.shape(),
            r.normal_force.shape(),
            r.tangential_force.shape(),
            r.slip_velocity.shape(),
            r.penetration.shape(),
            r.status.shape(),
            r.position.shape(),
        ];
        // the keys of results.npz (output::write_results_npz, README "Reading the results")
        let keys = [
            "t",
            "q",
            "qdot",
            "contact_normal_force",
            "contact_tangential_force",
            "contact_slip_velocity",
            "contact_penetration",
            "contact_status",
            "contact_position",
        ];
        for modal in [true, false] {
            let table = time_histories(modal);
            assert_eq!(table.map(|h| h.key), keys);
            for (h, shape) in table.iter().zip(shapes) {
                let v = &h.variable;
                assert_eq!(v.dims[0], TIME, "{}", v.name);
                let lens: Vec<usize> = v.dims[1..]
                    .iter()
                    .map(|d| labels.dimension_len(d).unwrap())
                    .collect();
                assert_eq!(lens, shape[1..], "{}", v.name);
                assert!(
                    v.units.is_some_and(|u| !u.is_empty()) && !v.long_name.is_empty(),
                    "{}",
                    v.name
                );
                assert_eq!(v.name == TIME, h.key == "t");
            }
        }
        // every dimension has its coordinate, a 1-D variable of its name
        for d in DIMENSIONS {
            assert!(find(d).is_some_and(|c| c.dims == [d]), "{d}");
        }
        // names are unique
        let mut names: Vec<&str> = MODAL
            .iter()
            .map(|h| h.variable.name)
            .chain(COORDINATES.iter().map(|c| c.variable.name))
            .collect();
        names.sort_unstable();
        let n = names.len();
        names.dedup();
        assert_eq!(names.len(), n);
    }

    /// Each coordinate's values have the lengths of its dimensions; names have no units,
    /// numbers have.
    #[test]
    fn every_coordinate_has_values_of_its_shape() {
        let model = tube();
        let labels = Labels::of(&model);
        for c in &COORDINATES {
            let v = &c.variable;
            let len: usize = v
                .dims
                .iter()
                .map(|d| labels.dimension_len(d).unwrap())
                .product();
            let (n, text) = match labels.values(c.source) {
                Values::Text(s) => (s.len(), true),
                Values::Int(i) => (i.len(), false),
                Values::Float(f) => (f.len(), false),
            };
            assert_eq!(n, len, "{}", v.name);
            assert_eq!(v.units.is_none(), text, "{}", v.name);
            assert!(v.dims.iter().all(|d| DIMENSIONS.contains(d)), "{}", v.name);
        }
        let Values::Float(f) = labels.values(Source::Frequencies) else {
            panic!()
        };
        for (f, w) in f.iter().zip(&model.basis.omega) {
            assert!((f * std::f64::consts::TAU - w).abs() <= 1e-12 * w);
        }
    }

    /// A model of one structure has the coordinates it always had (its `results.nc` and
    /// `to_xarray()` are unchanged); the union of two tubes has the structures' too, naming
    /// each mode's and point's structure (the prefix of the point's name), and no second
    /// point (no two-body contact). `tests/neighbours_outputs.rs` of the CLI reads them back.
    #[test]
    fn several_structures_label_modes_and_points() {
        let one = Labels::of(&tube());
        assert_eq!(one.coordinates(), COORDINATES);
        assert_eq!(one.global_coordinates(), global_coordinates());
        let union = Model::union(vec![("a".into(), tube()), ("b".into(), tube())]).unwrap();
        let labels = Labels::of(&union);
        assert_eq!(
            labels.coordinates()[COORDINATES.len()..],
            NEIGHBOUR_COORDINATES
        );
        let text = |s| match labels.values(s) {
            Values::Text(t) => t,
            _ => panic!(),
        };
        assert_eq!(text(Source::StructureNames), ["a", "b"]);
        let p = tube().basis.modes();
        let modes = text(Source::ModeStructures);
        assert_eq!(modes.len(), 2 * p);
        assert!(modes[..p].iter().all(|s| s == "a") && modes[p..].iter().all(|s| s == "b"));
        let owners: Vec<String> = text(Source::PointNames)
            .iter()
            .map(|p| p.split_once('.').unwrap().0.to_string())
            .collect();
        assert_eq!(text(Source::PointStructures), owners);
        let others = text(Source::ContactOtherPoints);
        assert!(others.len() == union.contacts.len() && others.iter().all(String::is_empty));
        assert_eq!(
            labels.global_coordinates(),
            ["point_position", "point_structure"]
        );
    }

    /// Modal coordinates are in kg^0.5 m; physical ones in m (m s-1 for the velocities);
    /// the other time histories do not change.
    #[test]
    fn q_units_follow_the_coordinates() {
        let units = |modal, key| {
            time_histories(modal)
                .iter()
                .find(|h| h.key == key)
                .and_then(|h| h.variable.units)
        };
        assert_eq!(units(true, "q"), Some("kg^0.5 m"));
        assert_eq!(units(true, "qdot"), Some("kg^0.5 m s-1"));
        assert_eq!(units(false, "q"), Some("m"));
        assert_eq!(units(false, "qdot"), Some("m s-1"));
        for (a, b) in time_histories(true).iter().zip(time_histories(false)) {
            if !["q", "qdot"].contains(&a.key) {
                assert_eq!(*a, b);
            }
        }
    }

    /// The CF `coordinates` of each time history, and `point_position` left for the global
    /// attribute: every auxiliary coordinate is reachable.
    #[test]
    fn auxiliary_coordinates_are_attached() {
        let of = |key| {
            let h = MODAL.iter().find(|h| h.key == key).unwrap();
            auxiliary_coordinates(h.variable.dims)
        };
        assert_eq!(of("q"), ["frequency", "damping_ratio"]);
        assert_eq!(
            of("contact_position"),
            ["contact_point", "contact_obstacle"]
        );
        assert!(of("t").is_empty());
        assert_eq!(global_coordinates(), ["point_position"]);
    }
}
