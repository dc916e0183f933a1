//! The series of a streamed run: `series/<key>.npy`, one `.npy` file per time history that
//! grows chunk by chunk ([`NpyAppender`]), and their packing into `results.npz`
//! ([`pack_npz`]).

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::output::layout::{Dtype, NPY_HEADER};

/// The series: key, element type, shape of one row.
pub(crate) fn series_layout(p: usize, c: usize) -> [(&'static str, Dtype, Vec<usize>); 9] {
    [
        ("t", Dtype::F64, vec![]),
        ("q", Dtype::F64, vec![p]),
        ("qdot", Dtype::F64, vec![p]),
        ("contact_normal_force", Dtype::F64, vec![c]),
        ("contact_tangential_force", Dtype::F64, vec![c, 2]),
        ("contact_slip_velocity", Dtype::F64, vec![c, 2]),
        ("contact_penetration", Dtype::F64, vec![c]),
        ("contact_status", Dtype::I8, vec![c]),
        ("contact_position", Dtype::F64, vec![c, 2]),
    ]
}

/// A `.npy` file (format 1.0) that grows by rows.
pub(crate) struct NpyAppender {
    pub(crate) key: String,
    pub(crate) path: PathBuf,
    file: BufWriter<File>,
    pub(crate) dtype: Dtype,
    pub(crate) row_shape: Vec<usize>,
    /// Values per row.
    pub(crate) row_len: usize,
    pub(crate) rows: u64,
}

impl NpyAppender {
    pub(crate) fn create(path: &Path, dtype: Dtype, row_shape: Vec<usize>) -> Result<Self> {
        let file = File::create(path).map_err(|e| Error::io(path, e))?;
        let mut s = Self::new(path, file, dtype, row_shape, 0);
        s.write_header()?;
        Ok(s)
    }

    /// Reopens a file written by [`Self::create`], cut to `rows` rows.
    pub(crate) fn reopen(
        path: &Path,
        dtype: Dtype,
        row_shape: Vec<usize>,
        rows: u64,
    ) -> Result<Self> {
        let io = |e| Error::io(path, e);
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(io)?;
        let mut magic = [0u8; 6];
        file.read_exact(&mut magic).map_err(io)?;
        let mut s = Self::new(path, file, dtype, row_shape, rows);
        let len = NPY_HEADER as u64 + rows * s.row_len as u64 * dtype.size();
        if &magic != b"\x93NUMPY" || s.file.get_ref().metadata().map_err(io)?.len() < len {
            return Err(Error::invalid(
                "checkpoint",
                format!(
                    "{} is shorter than at the checkpoint: the run folder was changed",
                    path.display()
                ),
            ));
        }
        s.file.get_mut().set_len(len).map_err(io)?;
        s.write_header()?;
        Ok(s)
    }

    fn new(path: &Path, file: File, dtype: Dtype, row_shape: Vec<usize>, rows: u64) -> Self {
        let key = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Self {
            key,
            path: path.to_path_buf(),
            file: BufWriter::with_capacity(1 << 16, file),
            dtype,
            row_len: row_shape.iter().product(),
            row_shape,
            rows,
        }
    }

    /// Writes the header for the rows written so far, then goes back to the end.
    fn write_header(&mut self) -> Result<()> {
        let mut shape = self.rows.to_string();
        for d in &self.row_shape {
            shape.push_str(&format!(", {d}"));
        }
        if self.row_shape.is_empty() {
            shape.push(',');
        }
        let dict = format!(
            "{{'descr': '{}', 'fortran_order': False, 'shape': ({shape}), }}",
            self.dtype.descr()
        );
        let mut header = Vec::with_capacity(NPY_HEADER);
        header.extend_from_slice(b"\x93NUMPY\x01\x00");
        header.extend_from_slice(&((NPY_HEADER - 10) as u16).to_le_bytes());
        header.extend_from_slice(dict.as_bytes());
        header.resize(NPY_HEADER - 1, b' ');
        header.push(b'\n');
        let io = |e| Error::io(&self.path, e);
        self.file.flush().map_err(io)?;
        let f = self.file.get_mut();
        f.seek(SeekFrom::Start(0)).map_err(io)?;
        f.write_all(&header).map_err(io)?;
        f.seek(SeekFrom::End(0)).map_err(io)?;
        Ok(())
    }

    /// Appends `rows` rows (`values` holds `rows × row_len` values: none for a row of
    /// length 0, e.g. the contact arrays of a model without contacts).
    pub(crate) fn append_f64(&mut self, values: &[f64], rows: usize) -> Result<()> {
        debug_assert_eq!(self.dtype, Dtype::F64);
        debug_assert_eq!(values.len(), rows * self.row_len);
        for v in values {
            self.file
                .write_all(&v.to_le_bytes())
                .map_err(|e| Error::io(&self.path, e))?;
        }
        self.rows += rows as u64;
        self.write_header()
    }

    /// As [`Self::append_f64`].
    pub(crate) fn append_i8(&mut self, values: &[i8], rows: usize) -> Result<()> {
        debug_assert_eq!(self.dtype, Dtype::I8);
        debug_assert_eq!(values.len(), rows * self.row_len);
        let bytes: Vec<u8> = values.iter().map(|v| *v as u8).collect();
        self.file
            .write_all(&bytes)
            .map_err(|e| Error::io(&self.path, e))?;
        self.rows += rows as u64;
        self.write_header()
    }

    pub(crate) fn sync(&mut self) -> Result<()> {
        self.file
            .flush()
            .and_then(|_| self.file.get_ref().sync_data())
            .map_err(|e| Error::io(&self.path, e))
    }
}

/// Writes `path` (`results.npz`): the `series` files (key, path) as its stored entries,
/// copied file by file, never whole in memory; whole or not at all.
pub(crate) fn pack_npz(path: &Path, series: &[(String, PathBuf)]) -> Result<()> {
    crate::files::write_atomically(path, |file| {
        // after an error (a full disk), the writer swallows what the ZipWriter's drop
        // writes: the error is reported once, by the caller, and the file removed
        let mut zip = zip::ZipWriter::new(BufWriter::new(FailOnce::new(file)));
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored)
            .large_file(true);
        for (key, p) in series {
            zip.start_file(format!("{key}.npy"), options)
                .map_err(zip_io)?;
            let mut f = File::open(p)?;
            std::io::copy(&mut f, &mut zip)?;
        }
        zip.finish().map_err(zip_io)?.flush()
    })
}

/// A zip error as the I/O error it is (a full disk says "No space left on device", not "i/o
/// error"), or wrapped.
fn zip_io(e: zip::result::ZipError) -> std::io::Error {
    match e {
        zip::result::ZipError::Io(e) => e,
        other => std::io::Error::other(other),
    }
}

/// A file that, once a write, flush or seek failed, accepts everything silently: for the
/// [`zip::ZipWriter`], which on drop tries to finish the archive after an error and prints
/// that second failure.
struct FailOnce {
    file: File,
    failed: bool,
}

impl FailOnce {
    fn new(file: File) -> Self {
        Self {
            file,
            failed: false,
        }
    }

    fn guard<T>(&mut self, r: std::io::Result<T>, instead: T) -> std::io::Result<T> {
        if self.failed {
            return Ok(instead);
        }
        if r.is_err() {
            self.failed = true;
        }
        r
    }
}

impl Write for FailOnce {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.failed {
            return Ok(buf.len());
        }
        let r = self.file.write(buf);
        self.guard(r, buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if self.failed {
            return Ok(());
        }
        let r = self.file.flush();
        self.guard(r, ())
    }
}

impl Seek for FailOnce {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        if self.failed {
            return Ok(0);
        }
        let r = self.file.seek(pos);
        self.guard(r, 0)
    }
}
