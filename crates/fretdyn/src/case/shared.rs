//! What the sections of a case share as they are built: a tube's finite-element model and
//! modes ([`TubeModel`]), where the points of the basis are along the tube ([`Abscissae`]),
//! and how a section names a point of the structure, a file, a vector.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use crate::error::{Error, Result};
use crate::model::Model;
use crate::structure::tube::{TubeBasis, TubeStructure};

/// A tube case keeps its finite-element model and full modes (for `fretdyn modes`).
#[derive(Debug, Clone)]
pub struct TubeModel {
    /// The structure as described in the case.
    pub structure: TubeStructure,
    /// Its modes.
    pub basis: TubeBasis,
}

/// Where the points of a structure are along the tube, for zones given by points on a
/// structure that is not a tube (the same order as the basis's points).
#[derive(Debug, Clone, Default)]
pub(super) struct Abscissae {
    /// `s` of each point of the basis, m, if known.
    pub s: Vec<Option<f64>>,
    /// Where the case gives them (for the messages), e.g. "the arrays 's_<name>' of b.npz".
    pub source: String,
}

/// The file a key names, `name` relative to `base`; an empty name is refused naming the key
/// `field` (it was read as the folder `base` itself, or as no file at all, with an error that
/// named neither the key nor a file: `: No such file or directory`). `relative_to` says what
/// the name is relative to (`the case file`, `the study file`).
pub(crate) fn named_file(
    base: &Path,
    name: &str,
    field: &str,
    relative_to: &str,
) -> Result<PathBuf> {
    if name.trim().is_empty() {
        return Err(Error::invalid(
            field,
            format!("an empty file name: give the name of the file, relative to {relative_to}"),
        ));
    }
    Ok(base.join(name))
}

/// A vector `[x, y, z]` of a case file.
pub(super) fn v3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// The index of the structure point `name`; `field` is where the case names it.
pub(super) fn point_index(name: &str, field: String, model: &Model) -> Result<usize> {
    model.basis.point_index(name).ok_or_else(|| {
        let known: Vec<&str> = model.basis.points.iter().map(|p| p.name.as_str()).collect();
        Error::invalid(
            field,
            format!("unknown point '{name}': the structure has {known:?}"),
        )
    })
}
