//! `results.nc`: the time histories of `results.npz` in a self-describing netCDF-4/HDF5 file
//! (THEORY §5), which `xarray.open_dataset`, `ncdump -h` or HDFView read without the README:
//!
//! - dimensions `time` (unlimited), `mode`, `contact`, `tangent` (t1, t2: the contact's tangent
//!   basis), `local_axis` (e1, e2: the obstacle's axes of `contact_position`), `point` and
//!   `direction` (x, y, z);
//! - coordinates: `time` (the `t` of `results.npz`), `mode` (numbers from 1, with
//!   `frequency` and `damping_ratio`), `contact` (the contacts' names, with `contact_point`
//!   and `contact_obstacle`), `point` (the structure points' names), and the labels of
//!   `tangent`, `local_axis` and `direction`;
//! - every other key of `results.npz` under its own name, with the same numbers (bit for
//!   bit) and shapes, the sample first (`time`);
//! - `units` (SI, UDUNITS spelling) and `long_name` on every numeric variable, `long_name` on
//!   the name labels (names have no unit);
//! - global attributes: `title`, `fretdyn_version`, `case` (the text of the case file) and
//!   `summary` (the text of `summary.json`) when the front end gives them
//!   ([`ResultsMetadata`]).
//!
//! # When it is written, and why then
//!
//! At the end of a streamed run ([`crate::results::stream`]), just after `results.npz` and in
//! the same way: packed from the streamed `series/<key>.npy`, read back a block of rows at a
//! time (at most [`READ_BYTES`] of one series in memory), appended along `time`. The step loop
//! is untouched and memory does not grow with the run's length. Appending to `results.nc`
//! at each flush instead was rejected:
//!
//! - a resume truncates every streamed file back to the lengths its checkpoint recorded;
//!   an HDF5 dataset cannot be cut back (an unlimited dimension only grows), so the rows
//!   flushed after the last checkpoint could not be taken away, and the file would have to
//!   be rewritten from the series anyway;
//! - a killed HDF5 writer leaves a file whose metadata (kept in memory until closed) may not
//!   be on disk: the file can be unreadable, where the `.npy` series are readable up to their
//!   last flush; they stay the durable record of a running or killed run.
//!
//! Packed from the same bytes as `results.npz`, `results.nc` holds the same numbers by
//! construction, and a resumed run, whose series are those of an uninterrupted run bit for
//! bit, gets the same `results.nc`. The file is written to `results.nc.partial`, synced and
//! renamed: a run killed while writing it leaves no truncated `results.nc`, and `resume`
//! writes it again.
//!
//! Behind the cargo feature `netcdf` of this crate (the command line enables it; the Python
//! package does not, its wheel does not link libnetcdf): the `netcdf` crate binds the system
//! library (`libnetcdf-dev` on Debian and Ubuntu).

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::model::{Coordinates, Model};
use crate::results::stream::{Dtype, NPY_HEADER, ResultsMetadata};

/// The file name in a run folder.
pub use crate::results::stream::NETCDF_FILE;

/// Bytes of one series read at a time while packing.
pub const READ_BYTES: usize = 4 << 20;

/// Bytes of an HDF5 chunk along `time` (at most; fewer for a short run).
const CHUNK_BYTES: usize = 1 << 20;

/// The names and reference values of a model that label the arrays of `results.nc`: its
/// contacts, points and modes (a few per contact, point or mode; kept by a streamed run for
/// its packing).
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
    /// `q` are modal coordinates (else physical ones, in m).
    modal: bool,
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
        }
    }
}

/// One streamed series (`series/<key>.npy`, written by [`crate::results::stream`]): a
/// fixed [`NPY_HEADER`]-byte header, then `rows` rows of `row_shape` little-endian values.
pub(crate) struct SeriesFile<'a> {
    pub key: &'a str,
    pub path: &'a Path,
    pub dtype: Dtype,
    pub row_shape: &'a [usize],
    pub rows: u64,
}

/// What `results.nc` calls a key of `results.npz`: name, dimensions, units, long name.
struct Described {
    name: &'static str,
    dims: &'static [&'static str],
    units: &'static str,
    long_name: &'static str,
}

/// The description of the series `key` (README "Reading the results"); `None` for a key
/// this module does not know (a new series must be described here: the tests check that
/// every key of `results.npz` is in `results.nc`).
fn describe(key: &str, modal: bool) -> Option<Described> {
    let d = |name, dims, units, long_name| {
        Some(Described {
            name,
            dims,
            units,
            long_name,
        })
    };
    const TC: &[&str] = &["time", "contact"];
    const TCT: &[&str] = &["time", "contact", "tangent"];
    match key {
        "t" => d("time", &["time"], "s", "time"),
        "q" if modal => d(
            "q",
            &["time", "mode"],
            "kg^0.5 m",
            "modal displacement (mass-normalised modes: displacement = mode shape × q)",
        ),
        "q" => d(
            "q",
            &["time", "mode"],
            "m",
            "displacement (physical coordinates)",
        ),
        "qdot" if modal => d(
            "qdot",
            &["time", "mode"],
            "kg^0.5 m/s",
            "modal velocity (full step)",
        ),
        "qdot" => d(
            "qdot",
            &["time", "mode"],
            "m/s",
            "velocity (physical coordinates, full step)",
        ),
        "contact_normal_force" => d(
            "contact_normal_force",
            TC,
            "N",
            "normal contact force magnitude R_N (>= 0)",
        ),
        "contact_tangential_force" => d(
            "contact_tangential_force",
            TCT,
            "N",
            "tangential force of the obstacle on the structure, in the contact's tangent basis (t1, t2)",
        ),
        "contact_slip_velocity" => d(
            "contact_slip_velocity",
            TCT,
            "m/s",
            "tangential velocity relative to the obstacle (full step), in the contact's tangent basis (t1, t2)",
        ),
        "contact_penetration" => d(
            "contact_penetration",
            TC,
            "m",
            "penetration (negative: the remaining clearance)",
        ),
        "contact_status" => d(
            "contact_status",
            TC,
            "1",
            "contact status: 0 open, 1 stick, 2 slip",
        ),
        "contact_position" => d(
            "contact_position",
            &["time", "contact", "local_axis"],
            "m",
            "the point relative to the obstacle: in a hole, the tube centre's offset from the hole's centre in the hole's axes (e1, e2); for a plane or bars, the distance from the plane (e1) and the position along t1 (e2)",
        ),
        _ => None,
    }
}

/// Writes `results.nc` in `dir` from the streamed `series`, labelled by `labels`, with the
/// global attributes of `meta` (see the module doc). Written to `results.nc.partial`,
/// synced, then renamed.
pub(crate) fn write(
    dir: &Path,
    series: &[SeriesFile],
    labels: &Labels,
    meta: &ResultsMetadata,
) -> Result<PathBuf> {
    let path = dir.join(NETCDF_FILE);
    let tmp = dir.join(format!("{NETCDF_FILE}.partial"));
    let written = write_to(&tmp, series, labels, meta)
        .and_then(|()| File::open(&tmp).and_then(|f| f.sync_all()));
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(&path, e));
    }
    std::fs::rename(&tmp, &path).map_err(|e| Error::io(&path, e))?;
    Ok(path)
}

/// A netCDF error as an I/O error of the file (a full disk reaches here as an HDF5 error).
fn nc(e: ::netcdf::Error) -> std::io::Error {
    std::io::Error::other(format!("netCDF: {e}"))
}

fn write_to(
    path: &Path,
    series: &[SeriesFile],
    labels: &Labels,
    meta: &ResultsMetadata,
) -> std::io::Result<()> {
    let _ = std::fs::remove_file(path);
    let mut file = ::netcdf::create(path).map_err(nc)?;

    // global attributes; long texts as NC_STRING (stored out of the object header, which
    // limits NC_CHAR attributes to 64 kB)
    if let Some(title) = &meta.title {
        file.add_attribute("title", title.as_str()).map_err(nc)?;
    }
    file.add_attribute("fretdyn_version", env!("CARGO_PKG_VERSION"))
        .map_err(nc)?;
    file.add_attribute(
        "comment",
        "the arrays of results.npz under their keys, t as the coordinate time (README, \"Reading the results\")",
    )
    .map_err(nc)?;
    for (name, text) in [("case", &meta.case_toml), ("summary", &meta.summary_json)] {
        if let Some(text) = text {
            file.add_attribute(name, vec![text.clone()]).map_err(nc)?;
        }
    }

    // dimensions (a length 0, e.g. no contact, is an unlimited dimension in netCDF-4: the
    // arrays still have length 0 along it)
    let (p, c, n) = (
        labels.frequencies_hz.len(),
        labels.contacts.len(),
        labels.points.len(),
    );
    file.add_unlimited_dimension("time").map_err(nc)?;
    for (name, len) in [
        ("mode", p),
        ("contact", c),
        ("tangent", 2),
        ("local_axis", 2),
        ("point", n),
        ("direction", 3),
    ] {
        file.add_dimension(name, len).map_err(nc)?;
    }

    // coordinates and labels
    let numbers: Vec<i32> = (1..=p as i32).collect();
    numeric(
        &mut file,
        "mode",
        &["mode"],
        "1",
        "mode number, from 1, in the order of the modal basis",
        &numbers,
    )?;
    numeric(
        &mut file,
        "frequency",
        &["mode"],
        "Hz",
        "natural frequency of the mode (undamped, without contact)",
        &labels.frequencies_hz,
    )?;
    numeric(
        &mut file,
        "damping_ratio",
        &["mode"],
        "1",
        "modal damping ratio",
        &labels.damping_ratios,
    )?;
    strings(
        &mut file,
        "contact",
        "contact",
        "contact name",
        &labels.contacts,
    )?;
    strings(
        &mut file,
        "contact_point",
        "contact",
        "the structure point of the contact",
        &labels.contact_points,
    )?;
    let obstacles: Vec<String> = labels
        .contact_obstacles
        .iter()
        .map(|k| k.to_string())
        .collect();
    strings(
        &mut file,
        "contact_obstacle",
        "contact",
        "obstacle type (plane, circle, bi_plane, polygon)",
        &obstacles,
    )?;
    strings(
        &mut file,
        "tangent",
        "tangent",
        "direction of the contact's tangent basis",
        &["t1".into(), "t2".into()],
    )?;
    strings(
        &mut file,
        "local_axis",
        "local_axis",
        "axis of the obstacle's local frame (contact_position)",
        &["e1".into(), "e2".into()],
    )?;
    strings(
        &mut file,
        "point",
        "point",
        "structure point name",
        &labels.points,
    )?;
    strings(
        &mut file,
        "direction",
        "direction",
        "axis of the global frame",
        &["x".into(), "y".into(), "z".into()],
    )?;
    numeric(
        &mut file,
        "point_position",
        &["point", "direction"],
        "m",
        "reference (undeformed) position of the point",
        &labels.point_positions,
    )?;

    // the time histories, streamed from series/
    let rows = series.first().map_or(0, |s| s.rows) as usize;
    for s in series {
        let Some(d) = describe(s.key, labels.modal) else {
            return Err(std::io::Error::other(format!(
                "series '{}' has no description for results.nc",
                s.key
            )));
        };
        let row_len: usize = s.row_shape.iter().product();
        let row_bytes = row_len.max(1) * s.dtype.size() as usize;
        // equal chunks of CHUNK_BYTES at most: the last one is not mostly padding
        let chunks = (rows * row_bytes).div_ceil(CHUNK_BYTES).max(1);
        let chunk_rows = rows.div_ceil(chunks).max(1);
        let mut v = match s.dtype {
            Dtype::F64 => file.add_variable::<f64>(d.name, d.dims),
            Dtype::I8 => file.add_variable::<i8>(d.name, d.dims),
        }
        .map_err(nc)?;
        let mut chunking = vec![chunk_rows];
        chunking.extend(s.row_shape.iter().map(|&l| l.max(1)));
        v.set_chunking(&chunking).map_err(nc)?;
        v.put_attribute("units", d.units).map_err(nc)?;
        v.put_attribute("long_name", d.long_name).map_err(nc)?;
        match s.key {
            "q" | "qdot" => {
                v.put_attribute("coordinates", "frequency damping_ratio")
                    .map_err(nc)?;
            }
            "contact_status" => {
                v.put_attribute("flag_values", vec![0i8, 1, 2])
                    .map_err(nc)?;
                v.put_attribute("flag_meanings", "open stick slip")
                    .map_err(nc)?;
            }
            _ => {}
        }
        if s.key.starts_with("contact_") {
            v.put_attribute("coordinates", "contact_point contact_obstacle")
                .map_err(nc)?;
        }
        if row_len == 0 || s.rows == 0 {
            continue;
        }
        // blocks of whole chunks, READ_BYTES at most
        let block_rows = chunk_rows * (READ_BYTES / (chunk_rows * row_bytes)).max(1);
        let mut f = File::open(s.path)?;
        f.seek(SeekFrom::Start(NPY_HEADER as u64))?;
        let mut bytes = vec![0u8; block_rows * row_bytes];
        let mut f64s: Vec<f64> = Vec::new();
        let mut start = 0;
        while start < s.rows as usize {
            let k = block_rows.min(s.rows as usize - start);
            let buf = &mut bytes[..k * row_bytes];
            f.read_exact(buf)?;
            let mut extents = vec![::netcdf::Extent::from(start..start + k)];
            extents.extend(std::iter::repeat_n(
                ::netcdf::Extent::from(..),
                s.row_shape.len(),
            ));
            match s.dtype {
                Dtype::F64 => {
                    f64s.clear();
                    f64s.extend(
                        buf.chunks_exact(8)
                            .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes"))),
                    );
                    v.put_values(&f64s, extents).map_err(nc)?;
                }
                Dtype::I8 => {
                    let i8s: Vec<i8> = buf.iter().map(|&b| b as i8).collect();
                    v.put_values(&i8s, extents).map_err(nc)?;
                }
            }
            start += k;
        }
    }
    file.close().map_err(nc)
}

/// A numeric variable written whole, with its units and long name.
fn numeric<T: ::netcdf::NcTypeDescriptor>(
    file: &mut ::netcdf::FileMut,
    name: &str,
    dims: &[&str],
    units: &str,
    long_name: &str,
    values: &[T],
) -> std::io::Result<()> {
    let mut v = file.add_variable::<T>(name, dims).map_err(nc)?;
    v.put_attribute("units", units).map_err(nc)?;
    v.put_attribute("long_name", long_name).map_err(nc)?;
    if !values.is_empty() {
        v.put_values(values, ..).map_err(nc)?;
    }
    Ok(())
}

/// A variable of names along `dim`, with its long name.
fn strings(
    file: &mut ::netcdf::FileMut,
    name: &str,
    dim: &str,
    long_name: &str,
    values: &[String],
) -> std::io::Result<()> {
    let mut v = file.add_string_variable(name, &[dim]).map_err(nc)?;
    v.put_attribute("long_name", long_name).map_err(nc)?;
    for (i, s) in values.iter().enumerate() {
        v.put_string(s, [i]).map_err(nc)?;
    }
    Ok(())
}
