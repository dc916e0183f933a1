//! `checkpoint.bin`, the checkpoint of a streamed run ([`super::stream`]): a header that
//! names its format and the version of fretdyn that wrote it, then the run's state and the
//! lengths of its files in CBOR; written to a temporary name and renamed.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::integrator::simulation::Snapshot;
use crate::output::layout::CHECKPOINT_FILE;

/// First bytes of `checkpoint.bin`. The file is: these 8 bytes, the format version
/// ([`CHECKPOINT_FORMAT`], u32 little-endian), the length of the version of fretdyn that
/// wrote it (u8) and that version (UTF-8, e.g. `0.1.0`), then the checkpoint in CBOR (RFC
/// 8949; exact for every `f64`). [`super::stream::resume`] refuses a checkpoint of another format or another
/// version of fretdyn: a resumed run gives the results of an uninterrupted one only with the
/// code that started it.
pub const CHECKPOINT_MAGIC: &[u8; 8] = b"FRETDYNC";

/// Format version of `checkpoint.bin` (1 was bincode, without a header; 2 counted the
/// statistics' steps per contact and accumulated blocks when there were none; 4 had blocks
/// only when set, and no batch moments; 5 had the angle of an impact's peak formed at the
/// peak, not its direction; 6 was a snapshot copied field by field, not the run's state as
/// it is; 7 had no displacement monitors).
pub const CHECKPOINT_FORMAT: u32 = 8;

/// What `checkpoint.bin` holds after its header: the run's [`Snapshot`] (its
/// [`State`](crate::integrator::simulation::State) as it is) and the length of every file of
/// the run at that step, which a resume cuts them back to.
#[derive(Serialize, Deserialize)]
pub(crate) struct Checkpoint {
    /// The case's and the settings' fingerprint: a checkpoint resumes only its own run.
    pub(crate) fingerprint: u64,
    pub(crate) snapshot: Snapshot,
    /// Rows in every series file at the checkpoint.
    pub(crate) rows: u64,
    /// Bytes of `impacts.csv` at the checkpoint.
    pub(crate) impacts_bytes: u64,
    /// Bytes of `blocks.csv` at the checkpoint.
    pub(crate) blocks_bytes: u64,
}

/// Reads the checkpoint of the run in `dir`; an error says why it cannot be resumed.
pub(crate) fn read(dir: &Path) -> Result<Checkpoint> {
    let path = dir.join(CHECKPOINT_FILE);
    let bytes = match std::fs::read(&path) {
        Ok(bytes) => bytes,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(Error::invalid(
                "checkpoint",
                format!(
                    "{}: the run stopped before its first checkpoint, there is nothing to \
                     resume: start it again",
                    dir.display()
                ),
            ));
        }
        Err(e) => return Err(Error::io(&path, e)),
    };
    decode(&bytes)
        .map_err(|message| Error::invalid("checkpoint", format!("{}: {message}", path.display())))
}

/// The step of the last checkpoint of the run in `dir` (the steps a resumed run starts after).
pub fn checkpoint_step(dir: &Path) -> Result<u64> {
    Ok(read(dir)?.snapshot.step())
}

fn encode(checkpoint: &Checkpoint) -> std::io::Result<Vec<u8>> {
    let version = env!("CARGO_PKG_VERSION").as_bytes();
    let mut bytes = Vec::with_capacity(4096);
    bytes.extend_from_slice(CHECKPOINT_MAGIC);
    bytes.extend_from_slice(&CHECKPOINT_FORMAT.to_le_bytes());
    bytes.push(version.len() as u8);
    bytes.extend_from_slice(version);
    ciborium::into_writer(checkpoint, &mut bytes).map_err(std::io::Error::other)?;
    Ok(bytes)
}

/// Decodes [`encode`]; the error says what is wrong and what to do.
fn decode(bytes: &[u8]) -> std::result::Result<Checkpoint, String> {
    let start_again = "start the run again";
    let Some(rest) = bytes.strip_prefix(CHECKPOINT_MAGIC) else {
        return Err(format!(
            "not a checkpoint of this fretdyn (an older checkpoint format without a header, or \
             another file): {start_again}"
        ));
    };
    let truncated = || format!("truncated: {start_again}");
    let format = u32::from_le_bytes(
        rest.get(..4)
            .and_then(|b| b.try_into().ok())
            .ok_or_else(truncated)?,
    );
    let len = *rest.get(4).ok_or_else(truncated)? as usize;
    let version = rest.get(5..5 + len).ok_or_else(truncated)?;
    let version = String::from_utf8_lossy(version);
    let ours = env!("CARGO_PKG_VERSION");
    if format != CHECKPOINT_FORMAT || version != ours {
        return Err(format!(
            "written by fretdyn {version} (checkpoint format {format}), this is fretdyn {ours} \
             (format {CHECKPOINT_FORMAT}): resume it with fretdyn {version}, or {start_again}"
        ));
    }
    ciborium::from_reader(&rest[5 + len..]).map_err(|e| format!("damaged ({e}): {start_again}"))
}

/// Writes `checkpoint` as the checkpoint of the run in `dir` (whole or not at all: to a
/// temporary name, synced, renamed).
pub(crate) fn write(dir: &Path, checkpoint: &Checkpoint) -> Result<()> {
    let path = dir.join(CHECKPOINT_FILE);
    let bytes = encode(checkpoint).map_err(|e| Error::io(&path, e))?;
    crate::files::write_atomically(&path, |mut f| {
        std::io::Write::write_all(&mut f, &bytes)?;
        f.sync_data()
    })
}
