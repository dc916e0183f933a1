//! Writing files safely: to a temporary name, then renamed, so a failed write never leaves a
//! truncated file under the final name; and the lock that keeps two programs from writing
//! the same results. Used by every stage that writes (the basis `.npz`, `results.npz`,
//! `summary.json`, streamed series and checkpoints, study tables, service lives).

use std::fs::File;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Writes `path` through `write` on a `.partial` sibling, renamed to `path` on success.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(File) -> std::io::Result<()>,
) -> Result<()> {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".partial");
    let tmp = path.with_file_name(name);
    let file = File::create(&tmp).map_err(|e| Error::io(&tmp, e))?;
    if let Err(e) = write(file) {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
}

/// [`write_atomically`] of a text, synced to the disk before it takes its name.
pub fn write_text_atomically(path: &Path, text: &str) -> Result<()> {
    write_atomically(path, |mut f| {
        f.write_all(text.as_bytes())?;
        f.sync_data()
    })
}

/// The file in an output folder that a program writing there (`fretdyn run`, `sweep`,
/// `life`, Python's `fretdyn.life`) holds a [`Lock`] on, so that two never mix their results.
pub const FOLDER_LOCK_FILE: &str = ".fretdyn.lock";

/// An exclusive advisory lock on a file (`flock` on Unix, `LockFileEx` on Windows), held
/// until dropped; the operating system lets it go with the process, however the process
/// ends (killed, out of memory), so a lock is never left behind.
#[derive(Debug)]
pub struct Lock {
    _file: File,
    path: PathBuf,
}

impl Lock {
    /// Takes the lock of `path` (created if missing), or says who holds it: `Ok(Err(holder))`
    /// with what the holder wrote. The holder writes its process id and `label` (what it
    /// is, e.g. `fretdyn sweep`) into the file, for the message of the next one.
    pub fn try_new(path: &Path, label: &str) -> Result<std::result::Result<Self, Holder>> {
        let io = |e: std::io::Error| Error::io(path, e);
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(io)?;
        match file.try_lock() {
            Ok(()) => {
                // who holds it (the lock is what counts, not the text)
                let _ = file
                    .set_len(0)
                    .and_then(|_| file.rewind())
                    .and_then(|_| writeln!(file, "{} {label}", std::process::id()));
                Ok(Ok(Self {
                    _file: file,
                    path: path.to_path_buf(),
                }))
            }
            Err(std::fs::TryLockError::WouldBlock) => {
                let mut text = String::new();
                let _ = file.read_to_string(&mut text);
                let (pid, label) = text.trim().split_once(' ').unwrap_or((text.trim(), ""));
                Ok(Err(Holder {
                    pid: pid.to_string(),
                    label: label.to_string(),
                }))
            }
            Err(std::fs::TryLockError::Error(e)) => Err(io(e)),
        }
    }

    /// The locked file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Who holds a lock, as it wrote it ([`Lock::try_new`]; empty when unknown).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Holder {
    /// Its process id.
    pub pid: String,
    /// What it is (`fretdyn run`, `fretdyn sweep`, …).
    pub label: String,
}

impl std::fmt::Display for Holder {
    /// `fretdyn sweep (process 1234)`, or what is known of it, or `another program`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.label.is_empty(), self.pid.is_empty()) {
            (false, false) => write!(f, "{} (process {})", self.label, self.pid),
            (false, true) => write!(f, "{}", self.label),
            (true, false) => write!(f, "a program (process {})", self.pid),
            (true, true) => write!(f, "a program"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A second lock of the same file is refused while the first is held (even in the same
    /// process: `flock` locks belong to the open file), and taken once it is dropped.
    #[test]
    fn a_lock_is_exclusive_until_dropped() {
        let dir = std::env::temp_dir().join(format!("fretdyn_lock_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(".lock");
        let first = Lock::try_new(&path, "fretdyn test").unwrap().expect("free");
        let second = Lock::try_new(&path, "other").unwrap().unwrap_err();
        assert_eq!(second.pid, std::process::id().to_string());
        assert_eq!(
            second.to_string(),
            format!("fretdyn test (process {})", std::process::id())
        );
        drop(first);
        assert!(Lock::try_new(&path, "other").unwrap().is_ok());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The temporary name keeps the whole file name: `life.csv` and `life.json` written one
    /// after the other do not share it.
    #[test]
    fn the_temporary_name_keeps_the_extension() {
        let dir = std::env::temp_dir().join(format!("fretdyn_atomic_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let err = write_atomically(&dir.join("a.csv"), |_| {
            assert!(dir.join("a.csv.partial").exists());
            Err(std::io::Error::other("full"))
        });
        assert!(err.is_err());
        assert!(!dir.join("a.csv").exists() && !dir.join("a.csv.partial").exists());
        write_text_atomically(&dir.join("a.csv"), "x\n").unwrap();
        assert_eq!(std::fs::read_to_string(dir.join("a.csv")).unwrap(), "x\n");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
