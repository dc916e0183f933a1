//! A modal basis as a `.npz` file: read (with its checks) and written.
//!
//! Modal basis `.npz` keys (all float64):
//! - `frequencies_hz` (p): natural frequencies, Hz (0 for rigid-body modes);
//! - `damping_ratio` (p), optional: modal damping ratios (default 0, or the case's value);
//! - `rows_<name>` (3, p): mode-shape rows of point `<name>` (x, y, z translations),
//!   mass-normalised (`Φᵀ M Φ = I`);
//! - `rotations_<name>` (3, p), optional: rotation rows of point `<name>` (θx, θy, θz, rad
//!   per unit modal coordinate), needed for a contact at the tube surface (`radius`);
//! - `coords_<name>` (3), optional: the point's reference position, m;
//! - `s_<name>` (1) or (), optional: the point's abscissa along the tube, m (the curvilinear
//!   coordinate the `[[flow.zones]]` of a case are given in, docs/FLOW.md);
//! - `participation` (3, p), optional: modal participation factors `Φᵀ M r` for unit rigid
//!   translations along x, y, z (kg^½), needed for a base excitation.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use nalgebra::Vector3;
use ndarray::{Array1, Array2};
use ndarray_npy::{NpzReader, NpzWriter};

use crate::error::{Error, Result};
use crate::files::write_atomically;
use crate::structure::modal::{ModalBasis, Point};

/// Reads a modal basis `.npz` (keys in the module documentation).
pub fn read_basis_npz(path: &Path) -> Result<BasisFile> {
    let npz_err = |message: String| Error::Npz {
        path: path.to_path_buf(),
        message,
    };
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let mut npz = NpzReader::new(file).map_err(|e| npz_err(format!("not a .npz file: {e}")))?;
    let names = npz
        .names()
        .map_err(|e| npz_err(format!("cannot list arrays: {e}")))?;
    let freq: Array1<f64> = npz.by_name("frequencies_hz").map_err(|e| {
        npz_err(format!(
            "key 'frequencies_hz' (float64, shape (p,)) missing or unreadable: {e}"
        ))
    })?;
    let p = freq.len();
    let damping_ratio = if names.iter().any(|n| n == "damping_ratio") {
        let d: Array1<f64> = npz
            .by_name("damping_ratio")
            .map_err(|e| npz_err(format!("key 'damping_ratio' must be float64 (p,): {e}")))?;
        if d.len() != p {
            return Err(npz_err(format!(
                "'damping_ratio' has {} values for {p} modes",
                d.len()
            )));
        }
        d.to_vec()
    } else {
        vec![0.0; p]
    };
    let mut points = Vec::new();
    let mut abscissae = Vec::new();
    for name in names.iter().filter_map(|n| n.strip_prefix("rows_")) {
        let rows: Array2<f64> = npz.by_name(&format!("rows_{name}")).map_err(|e| {
            npz_err(format!(
                "key 'rows_{name}' must be float64 of shape (3, {p}): {e}"
            ))
        })?;
        if rows.shape() != [3, p] {
            return Err(npz_err(format!(
                "'rows_{name}' has shape {:?}, expected (3, {p}): x, y, z rows, one column per mode",
                rows.shape()
            )));
        }
        let coords = if names.iter().any(|n| *n == format!("coords_{name}")) {
            let c: Array1<f64> = npz
                .by_name(&format!("coords_{name}"))
                .map_err(|e| npz_err(format!("key 'coords_{name}' must be float64 (3,): {e}")))?;
            if c.len() != 3 {
                return Err(npz_err(format!(
                    "'coords_{name}' has {} values, expected 3",
                    c.len()
                )));
            }
            Vector3::new(c[0], c[1], c[2])
        } else {
            Vector3::zeros()
        };
        let rotations = if names.iter().any(|n| *n == format!("rotations_{name}")) {
            let r: Array2<f64> = npz.by_name(&format!("rotations_{name}")).map_err(|e| {
                npz_err(format!(
                    "key 'rotations_{name}' must be float64 of shape (3, {p}): {e}"
                ))
            })?;
            if r.shape() != [3, p] {
                return Err(npz_err(format!(
                    "'rotations_{name}' has shape {:?}, expected (3, {p}): θx, θy, θz rows, one column per mode",
                    r.shape()
                )));
            }
            r.iter().copied().collect()
        } else {
            Vec::new()
        };
        let key = format!("s_{name}");
        abscissae.push(if names.contains(&key) {
            let s: ndarray::ArrayD<f64> = npz.by_name(&key).map_err(|e| {
                npz_err(format!(
                    "key '{key}' must be float64 of shape (1,) or (): {e}"
                ))
            })?;
            match s.iter().next() {
                Some(v) if s.len() == 1 && v.is_finite() => Some(*v),
                _ => {
                    return Err(npz_err(format!(
                        "'{key}' must be one finite abscissa in m (got {} value(s): {:?})",
                        s.len(),
                        s.iter().take(3).collect::<Vec<_>>()
                    )));
                }
            }
        } else {
            None
        });
        points.push(Point {
            name: name.to_string(),
            coords,
            rows: rows.iter().copied().collect(),
            rotations,
        });
    }
    if points.is_empty() {
        return Err(npz_err(
            "no point rows: add arrays 'rows_<name>' of shape (3, p)".to_string(),
        ));
    }
    let participation = if names.iter().any(|n| n == "participation") {
        let g: Array2<f64> = npz.by_name("participation").map_err(|e| {
            npz_err(format!(
                "key 'participation' must be float64 of shape (3, {p}): {e}"
            ))
        })?;
        if g.shape() != [3, p] {
            return Err(npz_err(format!(
                "'participation' has shape {:?}, expected (3, {p}): Φᵀ M r for x, y, z",
                g.shape()
            )));
        }
        g.iter().copied().collect()
    } else {
        Vec::new()
    };
    let basis = ModalBasis {
        omega: freq.iter().map(|f| f * std::f64::consts::TAU).collect(),
        damping_ratio,
        points,
        participation,
    };
    basis.validate(&path.display().to_string())?;
    let mut warnings = Vec::new();
    let has = |k: &str| names.iter().any(|n| n == k);
    if has("mass_matrix") || has("shapes") {
        let m: Array2<f64> = npz
            .by_name("mass_matrix")
            .map_err(|e| npz_err(format!("'mass_matrix' (n, n) must come with 'shapes': {e}")))?;
        let phi: Array2<f64> = npz
            .by_name("shapes")
            .map_err(|e| npz_err(format!("'shapes' (n, p) must come with 'mass_matrix': {e}")))?;
        let n = m.nrows();
        if m.shape() != [n, n] || phi.shape() != [n, p] {
            return Err(npz_err(format!(
                "'mass_matrix' has shape {:?} and 'shapes' {:?}: expected (n, n) and (n, {p})",
                m.shape(),
                phi.shape()
            )));
        }
        let gram = phi.t().dot(&m).dot(&phi);
        let (mut worst, mut at) = (0.0f64, (0, 0));
        for ((i, j), v) in gram.indexed_iter() {
            let d = (v - if i == j { 1.0 } else { 0.0 }).abs();
            if !(d <= worst) {
                worst = d;
                at = (i, j);
            }
        }
        if !(worst <= 1e-3) {
            return Err(npz_err(format!(
                "the modes are not mass-normalised: |ΦᵀMΦ − I| = {worst:.3e} at modes ({}, {}); normalise each mode to φᵀMφ = 1 and check they are M-orthogonal",
                at.0 + 1,
                at.1 + 1
            )));
        }
        if worst > 1e-9 {
            warnings.push(format!(
                "{}: the modes are only approximately mass-normalised: worst |ΦᵀMΦ − I| = {worst:.3e} at modes ({}, {})",
                path.display(),
                at.0 + 1,
                at.1 + 1
            ));
        }
    }
    Ok(BasisFile {
        basis,
        warnings,
        abscissae,
    })
}

/// A modal basis read from a `.npz`, with what the reader noticed.
#[derive(Debug, Clone)]
pub struct BasisFile {
    /// The basis.
    pub basis: ModalBasis,
    /// Accepted but doubtful things (an approximately mass-normalised basis).
    pub warnings: Vec<String>,
    /// The abscissa along the tube of each point (key `s_<name>`), m, where given.
    pub abscissae: Vec<Option<f64>>,
}

/// Writes a modal basis as `.npz` (keys in the module documentation), without abscissae.
pub fn write_basis_npz(path: &Path, basis: &ModalBasis) -> Result<()> {
    write_basis_npz_with_abscissae(path, basis, &[])
}

/// Writes a modal basis as `.npz` (keys in the module documentation), with `s_<name>` (shape
/// (1,), m) for every point whose abscissa along the tube is given: `abscissae[k]` is that of
/// `basis.points[k]` (missing or `None`: no key). With them, the `[[flow.zones]]` of a case
/// can be placed on the basis read back (docs/FLOW.md).
pub fn write_basis_npz_with_abscissae(
    path: &Path,
    basis: &ModalBasis,
    abscissae: &[Option<f64>],
) -> Result<()> {
    let p = basis.modes();
    write_atomically(path, |file| {
        let e = |err: ndarray_npy::WriteNpzError| std::io::Error::other(err.to_string());
        let mut npz = NpzWriter::new(BufWriter::new(file));
        let freq: Array1<f64> = basis
            .omega
            .iter()
            .map(|w| w / std::f64::consts::TAU)
            .collect();
        npz.add_array("frequencies_hz", &freq).map_err(e)?;
        npz.add_array("damping_ratio", &Array1::from(basis.damping_ratio.clone()))
            .map_err(e)?;
        if !basis.participation.is_empty() {
            let g = Array2::from_shape_vec((3, p), basis.participation.clone())
                .map_err(|err| std::io::Error::other(err.to_string()))?;
            npz.add_array("participation", &g).map_err(e)?;
        }
        for (k, pt) in basis.points.iter().enumerate() {
            let rows = Array2::from_shape_vec((3, p), pt.rows.clone())
                .map_err(|err| std::io::Error::other(err.to_string()))?;
            npz.add_array(format!("rows_{}", pt.name), &rows)
                .map_err(e)?;
            if !pt.rotations.is_empty() {
                let rot = Array2::from_shape_vec((3, p), pt.rotations.clone())
                    .map_err(|err| std::io::Error::other(err.to_string()))?;
                npz.add_array(format!("rotations_{}", pt.name), &rot)
                    .map_err(e)?;
            }
            npz.add_array(
                format!("coords_{}", pt.name),
                &Array1::from(pt.coords.iter().copied().collect::<Vec<_>>()),
            )
            .map_err(e)?;
            if let Some(Some(s)) = abscissae.get(k) {
                npz.add_array(format!("s_{}", pt.name), &Array1::from(vec![*s]))
                    .map_err(e)?;
            }
        }
        npz.finish().map_err(e)?;
        Ok(())
    })
}
