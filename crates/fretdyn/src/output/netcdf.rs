//! `results.nc`: the time histories of `results.npz` in a self-describing netCDF-4/HDF5 file
//! (THEORY §5), which `xarray.open_dataset`, `ncdump -h` or HDFView read without the README:
//!
//! - the dimensions, variables and coordinates of the one table
//!   [`crate::output::variables`], with its names, `units` (UDUNITS) and `long_name` (CF
//!   `flag_values`/`flag_meanings` for `contact_status`), and nothing of its own: `time`
//!   (unlimited; the `t` of `results.npz`), `mode`, `contact`, `tangent` (t1, t2),
//!   `local_axis` (e1, e2), `point`, `direction` (x, y, z), and for a model of several
//!   structures `structure` (with `mode_structure`, `point_structure`) and of two-body
//!   contacts `contact_other_point` ([`Labels::coordinates`]); the auxiliary coordinates in the
//!   CF `coordinates` attribute of the variables along their dimensions, `point_position` in
//!   the global one (xarray's convention);
//! - every other key of `results.npz` under its own name, with the same numbers (bit for
//!   bit) and shapes, the sample first (`time`);
//! - global attributes: `title`, `fretdyn_version`, `comment`, `case` (the text of the case
//!   file) and `summary` (the text of `summary.json`) when the front end gives them
//!   ([`ResultsMetadata`]).
//!
//! The Python package's `Result.to_xarray()` builds the Dataset that `xarray.open_dataset`
//! reads from this file, from the same table.
//!
//! # When it is written, and why then
//!
//! At the end of a streamed run ([`crate::output::stream`]), just after `results.npz` and in
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
use crate::output::layout::{Dtype, NPY_HEADER, ResultsMetadata};
use crate::output::variables::{self, TIME, Values, Variable};

/// The names and reference values that label the arrays (see [`variables::Labels`]).
pub use crate::output::variables::Labels;

/// The file name in a run folder.
pub use crate::output::layout::NETCDF_FILE;

/// Bytes of one series read at a time while packing.
pub const READ_BYTES: usize = 4 << 20;

/// Bytes of an HDF5 chunk along `time` (at most; fewer for a short run).
const CHUNK_BYTES: usize = 1 << 20;

/// One streamed series (`series/<key>.npy`, written by [`crate::output::stream`]): a
/// fixed [`NPY_HEADER`]-byte header, then `rows` rows of `row_shape` little-endian values.
pub(crate) struct SeriesFile<'a> {
    pub key: &'a str,
    pub path: &'a Path,
    pub dtype: Dtype,
    pub row_shape: &'a [usize],
    pub rows: u64,
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
        return Err(Error::io(&path, disk_full(e, dir)));
    }
    std::fs::rename(&tmp, &path).map_err(|e| Error::io(&path, e))?;
    Ok(path)
}

/// A failure of the netCDF library: its message, and the error of the operating system
/// that was pending when it failed.
#[derive(Debug)]
struct NetcdfFailure {
    message: String,
    os: std::io::Error,
}

impl std::fmt::Display for NetcdfFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for NetcdfFailure {}

/// A netCDF error as an I/O error of the file. The library reports a full disk as
/// "NetCDF: HDF error": the error number of the write that failed in it is kept (read here,
/// at once after the failing call) for [`disk_full`] to tell.
fn nc(e: ::netcdf::Error) -> std::io::Error {
    let os = std::io::Error::last_os_error();
    std::io::Error::other(NetcdfFailure {
        message: format!("netCDF: {e}"),
        os,
    })
}

/// Whether `e` says the disk (or the user's quota) is full.
fn is_full(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        std::io::ErrorKind::StorageFull | std::io::ErrorKind::QuotaExceeded
    )
}

/// The error to report for a failure `e` of writing `results.nc` in `dir`: a netCDF failure
/// on a full disk becomes the system's "No space left on device (os error 28)" (like a full
/// disk met while writing `results.npz`), with what stays written, from the error number of
/// the write that failed or, when the library has overwritten it, from a write of one chunk
/// ([`CHUNK_BYTES`]) of zeros in `dir` that fails the same way. Any other failure is kept
/// as it is.
fn disk_full(e: std::io::Error, dir: &Path) -> std::io::Error {
    let Some(failure) = e
        .get_ref()
        .and_then(|inner| inner.downcast_ref::<NetcdfFailure>())
    else {
        return e;
    };
    let full = if is_full(&failure.os) {
        match failure.os.raw_os_error() {
            Some(code) => std::io::Error::from_raw_os_error(code),
            None => std::io::Error::from(failure.os.kind()),
        }
    } else {
        match probe_space(dir) {
            Err(full) if is_full(&full) => full,
            _ => return e,
        }
    };
    // results.npz is packed first (crate::output::stream): it and the series stay
    std::io::Error::new(
        full.kind(),
        format!("{full}: results.npz and the time histories in series/ stay written"),
    )
}

/// Writes and removes a file of [`CHUNK_BYTES`] zeros in `dir` (synced, so that a full disk
/// says so now).
fn probe_space(dir: &Path) -> std::io::Result<()> {
    use std::io::Write;
    let path = dir.join(format!("{NETCDF_FILE}.space"));
    let written = File::create(&path).and_then(|mut f| {
        f.write_all(&vec![0u8; CHUNK_BYTES])?;
        f.sync_all()
    });
    let _ = std::fs::remove_file(&path);
    written
}

/// Turns off HDF5's automatic printing of its error stack (`HDF5-DIAG: Error detected in
/// HDF5 …`) in the calling thread, for a program that reads `results.nc` with the `netcdf`
/// crate. libnetcdf 4.9 probes attributes that a file may not have (the quantization
/// attributes, on every variable it opens): HDF5 reports each miss as an error on standard
/// error, some twenty lines each, although nothing is wrong. libnetcdf turns the printing off
/// in the thread that first opens a file; with a thread-safe HDF5 the setting is per thread,
/// so a reader in another thread (a test of a multi-threaded harness) prints them all. The
/// function `H5Eset_auto2` is looked up in the HDF5 library libnetcdf loaded, so nothing more
/// is linked; without it (a libnetcdf built without HDF5) nothing is done.
pub fn quiet_hdf5_errors() {
    use std::ffi::{c_char, c_int, c_void};
    unsafe extern "C" {
        fn dlsym(handle: *mut c_void, symbol: *const c_char) -> *mut c_void;
    }
    /// `herr_t H5Eset_auto2(hid_t estack_id, H5E_auto2_t func, void *client_data)`.
    type SetAuto = unsafe extern "C" fn(i64, *const c_void, *mut c_void) -> c_int;
    /// glibc's `RTLD_DEFAULT`: the global symbols of the program and its libraries.
    const RTLD_DEFAULT: *mut c_void = std::ptr::null_mut();
    /// HDF5's `H5E_DEFAULT`: the current thread's error stack.
    const H5E_DEFAULT: i64 = 0;
    // SAFETY: dlsym with a NUL-terminated name; the symbol, when found, is HDF5's
    // H5Eset_auto2 (hid_t is a 64-bit integer since HDF5 1.10), and a null function and
    // client data turn the printing off.
    unsafe {
        let f = dlsym(RTLD_DEFAULT, c"H5Eset_auto2".as_ptr());
        if !f.is_null() {
            let set_auto: SetAuto = std::mem::transmute::<*mut c_void, SetAuto>(f);
            set_auto(H5E_DEFAULT, std::ptr::null(), std::ptr::null_mut());
        }
    }
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
    file.add_attribute("comment", variables::COMMENT)
        .map_err(nc)?;
    for (name, text) in [("case", &meta.case_toml), ("summary", &meta.summary_json)] {
        if let Some(text) = text {
            file.add_attribute(name, vec![text.clone()]).map_err(nc)?;
        }
    }
    let global = labels.global_coordinates();
    if !global.is_empty() {
        file.add_attribute("coordinates", global.join(" "))
            .map_err(nc)?;
    }

    // dimensions, in the order of their coordinates (a length 0, e.g. no contact, is an
    // unlimited dimension in netCDF-4: the arrays still have length 0 along it)
    file.add_unlimited_dimension(TIME).map_err(nc)?;
    let coordinates = labels.coordinates();
    for c in &coordinates {
        let name = c.variable.name;
        if c.variable.dims == [name] {
            let len = labels.dimension_len(name).ok_or_else(|| {
                std::io::Error::other(format!("dimension '{name}' has no length"))
            })?;
            file.add_dimension(name, len).map_err(nc)?;
        }
    }

    // coordinates
    for c in &coordinates {
        let v = &c.variable;
        match labels.values(c.source) {
            Values::Text(names) => strings(&mut file, v, &names)?,
            Values::Int(numbers) => numeric(&mut file, v, &numbers)?,
            Values::Float(numbers) => numeric(&mut file, v, &numbers)?,
        }
    }

    // the time histories, streamed from series/
    let table = variables::time_histories(labels.modal());
    let rows = series.first().map_or(0, |s| s.rows) as usize;
    for s in series {
        let Some(d) = table.iter().find(|h| h.key == s.key).map(|h| &h.variable) else {
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
        describe(&mut v, d)?;
        if !d.flag_meanings.is_empty() {
            let n = d.flag_meanings.len() as i8;
            match s.dtype {
                Dtype::I8 => v.put_attribute("flag_values", (0..n).collect::<Vec<i8>>()),
                Dtype::F64 => {
                    v.put_attribute("flag_values", (0..n).map(f64::from).collect::<Vec<f64>>())
                }
            }
            .map_err(nc)?;
            v.put_attribute("flag_meanings", d.flag_meanings.join(" "))
                .map_err(nc)?;
        }
        let auxiliary = labels.auxiliary_coordinates(d.dims);
        if !auxiliary.is_empty() {
            v.put_attribute("coordinates", auxiliary.join(" "))
                .map_err(nc)?;
        }
        if row_len == 0 || s.rows == 0 {
            continue;
        }
        // blocks of whole chunks, READ_BYTES at most, and no more rows than the series has
        // (the buffer is zeroed: a short run's 4 MiB per series was most of its write)
        let block_rows =
            (chunk_rows * (READ_BYTES / (chunk_rows * row_bytes)).max(1)).min(s.rows as usize);
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

/// The `units` (numbers only) and `long_name` of the table on `v`.
fn describe(v: &mut ::netcdf::VariableMut, d: &Variable) -> std::io::Result<()> {
    if let Some(units) = d.units {
        v.put_attribute("units", units).map_err(nc)?;
    }
    v.put_attribute("long_name", d.long_name).map_err(nc)?;
    Ok(())
}

/// A numeric coordinate written whole.
fn numeric<T: ::netcdf::NcTypeDescriptor>(
    file: &mut ::netcdf::FileMut,
    d: &Variable,
    values: &[T],
) -> std::io::Result<()> {
    let mut v = file.add_variable::<T>(d.name, d.dims).map_err(nc)?;
    describe(&mut v, d)?;
    if !values.is_empty() {
        v.put_values(values, ..).map_err(nc)?;
    }
    Ok(())
}

/// A coordinate of names.
fn strings(file: &mut ::netcdf::FileMut, d: &Variable, values: &[String]) -> std::io::Result<()> {
    let mut v = file.add_string_variable(d.name, d.dims).map_err(nc)?;
    if d.dims.len() == 1 && !values.is_empty() {
        // one chunk of the names: HDF5's default chunk for a string is allocated and
        // zeroed at every `put_string` (megabytes each)
        v.set_chunking(&[values.len()]).map_err(nc)?;
    }
    describe(&mut v, d)?;
    for (i, s) in values.iter().enumerate() {
        v.put_string(s, [i]).map_err(nc)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::ops::ControlFlow;

    /// The netCDF library says "NetCDF: HDF error" for a full disk: the error number of the
    /// write that failed says it is full (`tests/cli.rs` fills a real disk).
    #[cfg(target_os = "linux")]
    #[test]
    fn a_full_disk_is_said_so_with_what_stays_written() {
        let dir = std::env::temp_dir().join(format!("fretdyn-nc-full-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let failure = |code: i32| {
            std::io::Error::other(super::NetcdfFailure {
                message: "netCDF: netcdf error(-101): NetCDF: HDF error".into(),
                os: std::io::Error::from_raw_os_error(code),
            })
        };
        // ENOSPC, EDQUOT
        for (code, words) in [
            (28, "No space left on device"),
            (122, "Disk quota exceeded"),
        ] {
            let e = super::disk_full(failure(code), &dir);
            assert!(super::is_full(&e), "{e}");
            let text = e.to_string();
            assert!(
                text.starts_with(words)
                    && text.ends_with("results.npz and the time histories in series/ stay written"),
                "{text}"
            );
        }
        // another failure (EIO) on a disk with room: the library's words
        let e = super::disk_full(failure(5), &dir);
        assert!(e.to_string().contains("HDF error"), "{e}");
        // not the library's: as it is
        let e = super::disk_full(std::io::Error::other("x"), &dir);
        assert_eq!(e.to_string(), "x");
        // the probe leaves nothing
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    use nalgebra::DMatrix;

    use crate::model::{Coordinates, PhysicalMatrices};
    use crate::output::stream::{self, ProgressOnly, StreamSettings};

    /// The units of `q` and `q̇` follow the model's coordinates: the V1a point mass (1 kg, so
    /// `Φ = I`) run in modal coordinates, then in physical ones (`M = I`, `C = K = 0`: the
    /// same motion), gives `q` in `kg^0.5 m` then in m, each with the other attributes of
    /// the table.
    #[test]
    fn q_has_the_units_of_the_models_coordinates() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/v1a_oblique_impact.toml");
        let case = crate::case::Case::from_file(&path).unwrap();
        let mut physical = case.model.clone();
        physical.coordinates = Coordinates::Physical(Box::new(PhysicalMatrices {
            mass: DMatrix::identity(3, 3),
            damping: DMatrix::zeros(3, 3),
            stiffness: DMatrix::zeros(3, 3),
        }));
        let dir = std::env::temp_dir().join(format!("fretdyn-nc-units-{}", std::process::id()));
        let mut q_values = Vec::new();
        for (model, q, qdot) in [
            (&case.model, "kg^0.5 m", "kg^0.5 m s-1"),
            (&physical, "m", "m s-1"),
        ] {
            let _ = std::fs::remove_dir_all(&dir);
            stream::run(
                model,
                &case.settings,
                &dir,
                &StreamSettings::default(),
                0,
                &mut ProgressOnly(|_| ControlFlow::Continue(())),
            )
            .unwrap();
            super::quiet_hdf5_errors();
            let file = ::netcdf::open(dir.join(super::NETCDF_FILE)).unwrap();
            let text = |var: &str, attr: &str| -> String {
                let v = file.variable(var).unwrap();
                let value = v.attribute_value(attr).unwrap().unwrap();
                String::try_from(value).unwrap()
            };
            assert_eq!(text("q", "units"), q);
            assert_eq!(text("qdot", "units"), qdot);
            for key in ["q", "qdot"] {
                assert_eq!(text(key, "coordinates"), "frequency damping_ratio");
            }
            assert_eq!(text("contact_slip_velocity", "units"), "m s-1");
            let v = file.variable("q").unwrap();
            q_values.push(v.get_values::<f64, _>(..).unwrap());
            drop(file);
            std::fs::remove_dir_all(&dir).unwrap();
        }
        // the same motion (the two solvers round alike or nearly)
        let (a, b) = (&q_values[0], &q_values[1]);
        assert_eq!(a.len(), b.len());
        let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(scale > 0.0);
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-9 * scale, "{x} {y}");
        }
    }
}
