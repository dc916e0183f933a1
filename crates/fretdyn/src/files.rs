//! Writing files safely: to a temporary name, then renamed, so a failed write never leaves a
//! truncated file under the final name. Used by every stage that writes (the basis `.npz`,
//! `results.npz`, `summary.json`, streamed series and checkpoints).

use std::fs::File;
use std::path::Path;

use crate::error::{Error, Result};

/// Writes `path` through `write` on a `.partial` sibling, renamed to `path` on success.
pub(crate) fn write_atomically(
    path: &Path,
    write: impl FnOnce(File) -> std::io::Result<()>,
) -> Result<()> {
    let tmp = path.with_extension("partial");
    let file = File::create(&tmp).map_err(|e| Error::io(&tmp, e))?;
    if let Err(e) = write(file) {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io(path, e));
    }
    std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
}
