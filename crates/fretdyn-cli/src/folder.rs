//! The output folder of a command that writes results (`run`, `sweep`, `life`): locked while
//! it writes, so that two commands never mix their results in one folder.

use std::path::Path;

use fretdyn::files::Lock;

use crate::Failure;

/// The file a command holds an advisory lock on while it writes in its folder; the lock
/// goes with the process, however it ends.
pub use fretdyn::files::FOLDER_LOCK_FILE as LOCK_FILE;

/// The lock of an output folder, held until dropped.
pub struct FolderLock {
    _lock: Lock,
}

/// Creates the folder `dir` if needed and takes its lock for `command` (`run`, `sweep`,
/// `life`), or refuses: another command writes there (exit code 2, naming it).
pub fn lock(dir: &Path, command: &str) -> Result<FolderLock, Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::failed(format!("{}: cannot create the folder: {e}", dir.display()))
    })?;
    match Lock::try_new(&dir.join(LOCK_FILE), &format!("fretdyn {command}")) {
        Ok(Ok(lock)) => Ok(FolderLock { _lock: lock }),
        Ok(Err(holder)) => Err(Failure::input(format!(
            "{}: another {} is writing in this folder; wait for it to end, or give another output folder (-o DIR)",
            dir.display(),
            if holder.label.is_empty() {
                "program".to_string()
            } else {
                holder.to_string()
            }
        ))),
        Err(e) => Err(Failure::failed(e.to_string())),
    }
}
