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
    #[error("line {line}, column {column}: {}", keyed(.key, .message))]
    Parse {
        line: usize,
        column: usize,
        /// The key the error is at, as written (`contacts[0].friction.mu`), when the schema
        /// (not the TOML syntax) refuses it and the key is known.
        key: Option<String>,
        /// What is wrong and what is expected, in plain words (not serde's).
        message: String,
    },

    /// Δt is above the stability limit of central differences (THEORY §2).
    #[error(
        "time.dt = {} s is above the stable limit {} s of central differences \
         (highest modal frequency plus contact penalty stiffnesses and fluid-elastic forces, docs/THEORY.md §2, §13): set time.dt ≤ {}",
        exponent(.dt),
        three_digits(.limit),
        exponent(.suggest)
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

    /// The offending field of an [`Error::Invalid`] (e.g. `turbulence[0].correlation_length`)
    /// or the key of an [`Error::Parse`], `None` for other errors.
    pub fn field(&self) -> Option<&str> {
        match self {
            Error::Invalid { field, .. } => Some(field),
            Error::Parse { key, .. } => key.as_deref(),
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

    /// The error of a part (a structure of several) as the whole sees it: an
    /// [`Error::Invalid`]'s field prefixed with `prefix` (`structures[1].` + `time.dt`); other
    /// errors unchanged.
    pub fn within(self, prefix: &str) -> Self {
        match self {
            Error::Invalid { field, message } => Error::Invalid {
                field: format!("{prefix}.{field}"),
                message,
            },
            other => other,
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

/// `key: message`, or the message alone without a key.
fn keyed(key: &Option<String>, message: &str) -> String {
    match key {
        Some(k) => format!("{k}: {message}"),
        None => message.to_string(),
    }
}

/// Significant digits of [`number`]: the most that every decimal number keeps through a
/// round trip to `f64` (`DBL_DIG`), so a value typed with up to 15 digits is printed as typed,
/// and the round-off of a computation (`0.1 + 0.2 = 0.30000000000000004`, `1000 × 1e-3`) is
/// not printed.
const DIGITS: usize = 15;

/// A number for a message, as a person would write it: `0.004`, `0.3`, `1e-7`, `2.5e12`,
/// `40` — the shortest form of the number rounded to 15 significant digits (a value typed
/// with at most 15 digits reads as typed; `0.1 + 0.2` reads `0.3`), in exponent notation
/// outside `[1e-4, 1e6)`. Use it for every number a message prints, computed ones
/// especially (`steps as f64 * dt`).
pub fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let rounded = rounded(x);
    if (1e-4..1e6).contains(&rounded.abs()) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

/// `x` rounded to [`DIGITS`] significant digits (`f64::MAX`, which would round up to
/// infinity, is kept as it is).
fn rounded(x: f64) -> f64 {
    format!("{x:.prec$e}", prec = DIGITS - 1)
        .parse::<f64>()
        .ok()
        .filter(|r| r.is_finite())
        .unwrap_or(x)
}

/// [`number`] always in exponent notation (`2e-3`, `1.8e-3`), for a time step and its limit.
fn exponent(x: &f64) -> String {
    format!("{:e}", rounded(*x))
}

/// A computed figure to three significant digits, in exponent notation (`2.04e-10`, `2e-3`):
/// its fifteen digits (`2.04313638318077e-10`) say nothing more to a reader.
fn three_digits(x: &f64) -> String {
    format!("{:e}", format!("{x:.2e}").parse::<f64>().unwrap_or(*x))
}

#[cfg(test)]
mod tests {
    use super::number;

    #[test]
    fn numbers_read_as_a_person_writes_them() {
        for (x, text) in [
            (0.1 + 0.2, "0.3"),
            (1000.0 * 1e-3, "1"),
            (3.0 * 1.1, "3.3"),
            (0.004, "0.004"),
            (1e-7, "1e-7"),
            (2.5e12, "2.5e12"),
            (-0.3, "-0.3"),
            (40.0, "40"),
            (999_999.0, "999999"),
            (1e6, "1e6"),
            (1e-4, "0.0001"),
            (0.3420201433256687, "0.342020143325669"),
            (9.525e-3, "0.009525"),
            (1e300, "1e300"),
            (-1e-320, "-1e-320"),
            (f64::MAX, "1.7976931348623157e308"),
            (0.0, "0"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(number(x), text, "{x:e}");
        }
        // a computed limit, in exponent notation, to three significant digits
        let e = super::Error::UnstableTimeStep {
            dt: 1e-5,
            limit: 2.04313638318077e-10,
            suggest: 1.83e-10,
        };
        assert!(e.to_string().contains("the stable limit 2.04e-10 s"), "{e}");
        let e = super::Error::UnstableTimeStep {
            dt: 3e-3,
            limit: 2.0 / 1000.0 * (1.0 - 1e-16),
            suggest: 0.9 * 2e-3,
        };
        assert!(
            e.to_string()
                .contains("time.dt = 3e-3 s is above the stable limit 2e-3 s")
                && e.to_string().ends_with("set time.dt ≤ 1.8e-3"),
            "{e}"
        );
    }
}
