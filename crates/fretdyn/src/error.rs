//! Typed errors of the library. The CLI and the Python package turn them into one-line messages.

use std::path::PathBuf;

/// Everything that can go wrong between a case file and a finished run.
///
/// Input errors name the offending field (`time.dt`, `contacts[1].normal.stiffness`, …) and
/// say how to fix it, so that a front end only has to prefix the file name.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A value is present but wrong (non-positive mass, NaN in a mode shape, unknown point…).
    #[error("{field}: {message}")]
    Invalid {
        /// Dotted path of the field in the case file.
        field: String,
        /// What is wrong and how to fix it.
        message: String,
    },

    /// The case file is not valid TOML or does not match the schema (unknown key, wrong type).
    #[error("line {line}, column {column}: {message}")]
    Parse {
        line: usize,
        column: usize,
        message: String,
    },

    /// Δt is above the stability limit of central differences (THEORY §2).
    #[error(
        "time.dt = {dt:e} s is above the stable limit {limit:e} s of central differences \
         (highest modal frequency plus contact penalty stiffnesses and fluid-elastic forces, docs/THEORY.md §2, §13): set time.dt ≤ {suggest:e}"
    )]
    UnstableTimeStep { dt: f64, limit: f64, suggest: f64 },

    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// A `.npz` modal basis is missing a key or has an array of the wrong shape.
    #[error("{path}: {message}")]
    Npz { path: PathBuf, message: String },

    /// One run of a study (a point of its grid or list) makes an invalid case: found before
    /// any run starts.
    #[error("run {index} ({point}): {source}")]
    StudyRun {
        /// Index of the run in the study.
        index: usize,
        /// Its parameter values and seed, as `key = value, …`.
        point: String,
        /// What is wrong with the case of this run.
        #[source]
        source: Box<Error>,
    },
}

impl Error {
    /// Shorthand for [`Error::Invalid`].
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    /// The offending field of an [`Error::Invalid`] (e.g. `turbulence[0].correlation_length`),
    /// `None` for other errors.
    pub fn field(&self) -> Option<&str> {
        match self {
            Error::Invalid { field, .. } => Some(field),
            Error::StudyRun { source, .. } => source.field(),
            _ => None,
        }
    }

    /// The one-line message of an error met while reading the file `path`: `path: error`,
    /// without naming the file twice when the error is the file itself that cannot be read.
    pub fn in_file(&self, path: &std::path::Path) -> String {
        match self {
            Error::Io { path: p, source } if p == path => format!("{}: {source}", p.display()),
            other => format!("{}: {other}", path.display()),
        }
    }

    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// Result alias of the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// A number for a message, as a user would type it: `0.004`, `1e-7`, `2.5e12`.
pub(crate) fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
