//! How a service life is driven from outside (its checkpoint, a life to continue, a stop
//! signal) and its checkpoint: the state of the life between two batches of steps.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use serde::{Deserialize, Serialize};

use super::results::LifeStep;
use super::track::TrackState;
use super::window::{Window, WindowProgress};
use crate::error::{Error, Result};

/// How a service life is driven from outside: where its checkpoint goes, a life to
/// continue, and a stop signal.
#[derive(Default)]
pub struct LifeControl<'a> {
    /// The checkpoint file, written after every life step and, inside a window, every
    /// `checkpoint_every_seconds` of wall-clock time and when the life is stopped
    /// ([`LifeCheckpoint`]); `None`: no checkpoint.
    pub checkpoint: Option<&'a Path>,
    /// Wall-clock seconds between checkpoints inside a window (0: at every batch of steps).
    pub checkpoint_every_seconds: f64,
    /// The fingerprint of the inputs (the case as resolved, the files it reads, the life's
    /// settings): a checkpoint is resumed only by the inputs it was written for.
    pub fingerprint: u64,
    /// A life to continue, read by [`LifeCheckpoint::read`]: the results are those of an
    /// uninterrupted life, bit for bit (but the wall-clock time).
    pub resume: Option<LifeCheckpoint>,
    /// Set from outside (a signal): the life stops at the next batch of steps of its window
    /// or the next life step, after a checkpoint ([`LifeEnd::Stopped`]).
    pub stop: Option<&'a AtomicBool>,
}

/// The state of a service life between two batches of steps, as its checkpoint holds it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct LifeState {
    /// Service time reached, s.
    pub(super) t: f64,
    /// Windows simulated (finished).
    pub(super) windows: usize,
    /// The state at t = 0 and after every life step so far.
    pub(super) steps: Vec<LifeStep>,
    /// The first window's rates (the fixed-gap extrapolation).
    pub(super) first: Option<Window>,
    /// Each wearing contact's volumes and the times found so far.
    pub(super) tracks: Vec<TrackState>,
    /// Wall-clock time of the sessions before this one, s.
    pub(super) wall_time: f64,
    /// The window under way, if the checkpoint was taken inside one.
    pub(super) window: Option<WindowProgress>,
}

/// A service life's checkpoint (`life_checkpoint.bin`): these bytes, then the format
/// version (u32 little-endian), the length of fretdyn's version (u8) and the version, the
/// fingerprint of the inputs (u64 little-endian), then the state in CBOR (exact for every
/// `f64`). A checkpoint of another format or version, or of other inputs, is refused.
#[derive(Debug, Clone)]
pub struct LifeCheckpoint {
    pub(super) fingerprint: u64,
    pub(super) state: LifeState,
}

/// First bytes of a service life's checkpoint.
pub const LIFE_CHECKPOINT_MAGIC: &[u8; 8] = b"FRETDYNL";

/// Format version of a service life's checkpoint (1: the window's wear map beside its
/// simulation's hand-kept snapshot).
pub const LIFE_CHECKPOINT_FORMAT: u32 = 2;

impl LifeCheckpoint {
    /// Reads the checkpoint at `path`; the error says why it cannot be resumed.
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let bad = |why: String| Error::invalid("checkpoint", format!("{}: {why}", path.display()));
        let again = "start the life again";
        let rest = bytes
            .strip_prefix(LIFE_CHECKPOINT_MAGIC)
            .ok_or_else(|| bad(format!("not a service life's checkpoint: {again}")))?;
        let truncated = || bad(format!("truncated: {again}"));
        let format = u32::from_le_bytes(
            rest.get(..4)
                .and_then(|b| b.try_into().ok())
                .ok_or_else(truncated)?,
        );
        let len = *rest.get(4).ok_or_else(truncated)? as usize;
        let version = String::from_utf8_lossy(rest.get(5..5 + len).ok_or_else(truncated)?);
        let ours = env!("CARGO_PKG_VERSION");
        if format != LIFE_CHECKPOINT_FORMAT || version != ours {
            return Err(bad(format!(
                "written by fretdyn {version} (format {format}), this is fretdyn {ours} (format {LIFE_CHECKPOINT_FORMAT}): resume it with fretdyn {version}, or {again}"
            )));
        }
        let fingerprint = u64::from_le_bytes(
            rest.get(5 + len..13 + len)
                .and_then(|b| b.try_into().ok())
                .ok_or_else(truncated)?,
        );
        let state: LifeState = ciborium::from_reader(&rest[13 + len..])
            .map_err(|e| bad(format!("damaged ({e}): {again}")))?;
        Ok(Self { fingerprint, state })
    }

    /// The service time the checkpoint reached, s.
    pub fn time(&self) -> f64 {
        self.state.t
    }

    /// The fingerprint of the inputs it was written for.
    pub fn fingerprint(&self) -> u64 {
        self.fingerprint
    }

    /// Whether it was taken inside a window of vibration (else between two life steps).
    pub fn inside_window(&self) -> bool {
        self.state.window.is_some()
    }

    pub(super) fn write(path: &Path, fingerprint: u64, state: &LifeState) -> Result<()> {
        let version = env!("CARGO_PKG_VERSION").as_bytes();
        let mut bytes = Vec::with_capacity(4096);
        bytes.extend_from_slice(LIFE_CHECKPOINT_MAGIC);
        bytes.extend_from_slice(&LIFE_CHECKPOINT_FORMAT.to_le_bytes());
        bytes.push(version.len() as u8);
        bytes.extend_from_slice(version);
        bytes.extend_from_slice(&fingerprint.to_le_bytes());
        ciborium::into_writer(state, &mut bytes)
            .map_err(|e| Error::io(path, std::io::Error::other(e)))?;
        crate::files::write_atomically(path, |mut f| {
            use std::io::Write;
            f.write_all(&bytes)?;
            f.sync_data()
        })
    }
}
