//! Long runs: results streamed to disk while the run goes on, periodic checkpoints, and a
//! killed or interrupted run resumed from its last checkpoint with results identical, bit for
//! bit, to those of an uninterrupted run.
//!
//! A streamed run writes in its folder:
//! - `series/<key>.npy`: one `.npy` file per time history of [`crate::accumulate::recorder::Recorder`]
//!   (keys of `results.npz`), appended chunk by chunk; the header, rewritten after each
//!   append, always gives the number of rows completely written, so that `numpy.load` reads
//!   what a killed run had flushed;
//! - `impacts.csv`: the per-impact table, appended as impacts end;
//! - `blocks.csv`: the per-block statistics (the batches of the standard errors: always);
//! - `checkpoint.bin`: the [`Snapshot`] with the length of every file at that step, written to
//!   a temporary name and renamed; its format is in [`CHECKPOINT_MAGIC`];
//! - at the end, `results.npz`, packed from `series/` (copied entry by entry, never whole in
//!   memory), then (with the `netcdf` feature) `results.nc`, the same arrays with names and
//!   units, packed from `series/` block by block (`results/netcdf.rs` says why at the
//!   end and not at each flush); after which `series/` is removed.
//!
//! A run ends with a checkpoint at its last step, then [`StreamObserver::finished`] (where a
//! front end writes its summary), then the packing: a run killed, or out of disk, before
//! `results.npz` (and `results.nc`) are in place is finished by [`resume`], which does those
//! again; a last checkpoint with them beside it is a complete run.
//!
//! Memory does not grow with the run's length: the recorder holds one chunk, finished impacts
//! and blocks are written out at each flush, and the statistics are running sums.
//!
//! One concept, kept whole: the files of a streamed run, their chunked writing, the checkpoint
//! that records their lengths and the resume that truncates them back are one format; none
//! reads right without the others.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::accumulate::recorder::Recorder;
use crate::accumulate::statistics::{BlockStatistics, Impact};
use crate::error::{Error, Result};
use crate::integrator::simulation::{
    Progress, RunResults, RunSettings, Simulation, Snapshot, Termination,
};
use crate::model::Model;
pub use crate::output::layout::{
    BLOCKS_FILE, CHECKPOINT_FILE, IMPACTS_FILE, NETCDF_FILE, RESULTS_FILE, ResultsMetadata,
    SERIES_DIR,
};
use crate::output::layout::{Dtype, NPY_HEADER};

/// How a streamed run writes and checkpoints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamSettings {
    /// Output samples held in memory between two flushes to disk.
    pub chunk_samples: usize,
    /// Checkpoint every this many steps (a multiple of 1024 is honoured exactly).
    pub checkpoint_every_steps: Option<u64>,
    /// Checkpoint every this many seconds of wall time.
    pub checkpoint_every_seconds: Option<f64>,
}

impl Default for StreamSettings {
    fn default() -> Self {
        Self {
            chunk_samples: 4096,
            checkpoint_every_steps: None,
            checkpoint_every_seconds: Some(60.0),
        }
    }
}

/// What a streamed run tells its caller while it goes on.
pub trait StreamObserver {
    /// Called every 1024 steps and at the end; `Break` stops the run (after a flush and a
    /// checkpoint, so that it can be resumed).
    fn progress(&mut self, progress: Progress) -> ControlFlow<()>;
    /// Called after each checkpoint with the statistics so far (its recorder is empty).
    fn checkpoint(&mut self, _partial: &RunResults) {}
    /// Called once the run has ended (completed, stopped or diverged) and its files but
    /// `results.npz` are written, before the packing; an error fails the run. A run that
    /// ended but was not packed (killed, out of disk) calls it again when it is resumed.
    fn finished(&mut self, _results: &RunResults) -> Result<()> {
        Ok(())
    }
    /// What `results.nc` says of the run besides its arrays (the title, the case file, the
    /// summary): asked once per packing, after [`Self::finished`].
    fn metadata(&self) -> ResultsMetadata {
        ResultsMetadata::default()
    }
}

/// An observer that only reports progress through a closure.
pub struct ProgressOnly<F>(pub F);

impl<F: FnMut(Progress) -> ControlFlow<()>> StreamObserver for ProgressOnly<F> {
    fn progress(&mut self, progress: Progress) -> ControlFlow<()> {
        (self.0)(progress)
    }
}

/// The files a complete run has packed from `series/`.
fn packed_files() -> &'static [&'static str] {
    if cfg!(feature = "netcdf") {
        &[RESULTS_FILE, NETCDF_FILE]
    } else {
        &[RESULTS_FILE]
    }
}

/// First bytes of `checkpoint.bin`. The file is: these 8 bytes, the format version
/// ([`CHECKPOINT_FORMAT`], u32 little-endian), the length of the version of fretdyn that
/// wrote it (u8) and that version (UTF-8, e.g. `0.1.0`), then the checkpoint in CBOR (RFC
/// 8949; exact for every `f64`). [`resume`] refuses a checkpoint of another format or another
/// version of fretdyn: a resumed run gives the results of an uninterrupted one only with the
/// code that started it.
pub const CHECKPOINT_MAGIC: &[u8; 8] = b"FRETDYNC";

/// Format version of `checkpoint.bin` (1 was bincode, without a header; 2 counted the
/// statistics' steps per contact and accumulated blocks when there were none; 4 had blocks
/// only when set, and no batch moments; 5 had the angle of an impact's peak formed at the
/// peak, not its direction).
pub const CHECKPOINT_FORMAT: u32 = 6;

#[derive(Serialize, Deserialize)]
struct Checkpoint {
    fingerprint: u64,
    snapshot: Snapshot,
    /// Rows in every series file at the checkpoint.
    rows: u64,
    impacts_bytes: u64,
    blocks_bytes: u64,
}

/// Runs `model` and streams its results into `dir` (created if needed). `fingerprint`
/// identifies the case (e.g. a hash of the case file): [`resume`] refuses a checkpoint made
/// for another one.
pub fn run(
    model: &Model,
    settings: &RunSettings,
    dir: &Path,
    stream: &StreamSettings,
    fingerprint: u64,
    observer: &mut dyn StreamObserver,
) -> Result<RunResults> {
    let sim = Simulation::with_recorder(model, settings, stream.chunk_samples)?;
    std::fs::create_dir_all(dir.join(SERIES_DIR)).map_err(|e| Error::io(dir, e))?;
    let _ = std::fs::remove_file(dir.join(CHECKPOINT_FILE));
    let _ = std::fs::remove_file(dir.join(RESULTS_FILE));
    let _ = std::fs::remove_file(dir.join(NETCDF_FILE));
    let files = Files::create(dir, model)?;
    drive(sim, files, settings, stream, fingerprint, observer)
}

/// Continues the run streamed into `dir` from its last checkpoint, with the same model and
/// settings; the results are those an uninterrupted run gives, bit for bit.
pub fn resume(
    model: &Model,
    settings: &RunSettings,
    dir: &Path,
    stream: &StreamSettings,
    fingerprint: u64,
    observer: &mut dyn StreamObserver,
) -> Result<RunResults> {
    let checkpoint = read_checkpoint(dir)?;
    let path = dir.join(CHECKPOINT_FILE);
    if checkpoint.fingerprint != fingerprint_with(fingerprint, settings) {
        return Err(Error::invalid(
            "checkpoint",
            format!(
                "{} was written for another case or other settings: resume with the case file the run was started with",
                path.display()
            ),
        ));
    }
    let ended =
        checkpoint.snapshot.step >= settings.steps || checkpoint.snapshot.target_met().is_some();
    if ended && packed_files().iter().all(|f| dir.join(f).exists()) {
        // killed while removing series/, after the packing: what is left is not needed
        let _ = std::fs::remove_dir_all(dir.join(SERIES_DIR));
        return Err(Error::invalid(
            "checkpoint",
            format!(
                "{}: the run is complete, there is nothing to resume",
                dir.display()
            ),
        ));
    }
    let sim = Simulation::resume(model, settings, checkpoint.snapshot, stream.chunk_samples)?;
    let files = Files::reopen(
        dir,
        model,
        checkpoint.rows,
        checkpoint.impacts_bytes,
        checkpoint.blocks_bytes,
    )?;
    // the results.npz (and results.nc) of a stop are packed again at the end; until then,
    // they beside the last checkpoint are those of a complete run
    for file in [RESULTS_FILE, NETCDF_FILE] {
        match std::fs::remove_file(dir.join(file)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(Error::io(dir.join(file), e));
            }
            _ => {}
        }
    }
    drive(sim, files, settings, stream, fingerprint, observer)
}

/// Reads the checkpoint of the run in `dir`; an error says why it cannot be resumed.
fn read_checkpoint(dir: &Path) -> Result<Checkpoint> {
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
    decode_checkpoint(&bytes)
        .map_err(|message| Error::invalid("checkpoint", format!("{}: {message}", path.display())))
}

/// The step of the last checkpoint of the run in `dir` (the steps a resumed run starts after).
pub fn checkpoint_step(dir: &Path) -> Result<u64> {
    Ok(read_checkpoint(dir)?.snapshot.step)
}

fn encode_checkpoint(checkpoint: &Checkpoint) -> std::io::Result<Vec<u8>> {
    let version = env!("CARGO_PKG_VERSION").as_bytes();
    let mut bytes = Vec::with_capacity(4096);
    bytes.extend_from_slice(CHECKPOINT_MAGIC);
    bytes.extend_from_slice(&CHECKPOINT_FORMAT.to_le_bytes());
    bytes.push(version.len() as u8);
    bytes.extend_from_slice(version);
    ciborium::into_writer(checkpoint, &mut bytes).map_err(std::io::Error::other)?;
    Ok(bytes)
}

/// Decodes [`encode_checkpoint`]; the error says what is wrong and what to do.
fn decode_checkpoint(bytes: &[u8]) -> std::result::Result<Checkpoint, String> {
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

/// The step loop of a streamed run.
fn drive(
    mut sim: Simulation,
    mut files: Files,
    settings: &RunSettings,
    stream: &StreamSettings,
    fingerprint: u64,
    observer: &mut dyn StreamObserver,
) -> Result<RunResults> {
    let fingerprint = fingerprint_with(fingerprint, settings);
    let start = Instant::now();
    let mut last_checkpoint = Instant::now();
    let total = settings.steps;
    let mut termination = Termination::Completed;
    let model = files.model_contacts.clone();
    while sim.steps_done() < total && sim.target_met().is_none() {
        // to the end of the batch or the next multiple of the checkpoints' steps, where the
        // loop below looks at the clock and the observer
        let n = sim.steps_done();
        let mut chunk = sim.steps_to_batch_end(total);
        if let Some(every) = stream.checkpoint_every_steps.filter(|&e| e > 0) {
            chunk = chunk.min(every - n % every);
        }
        if let Err(d) = sim.steps(chunk) {
            termination = Termination::Diverged {
                step: d.step,
                time: d.time,
                contact: d.contact.map(|c| model[c].clone()),
            };
            break;
        }
        if sim.recorder().is_full() {
            files.flush(&mut sim)?;
        }
        let n = sim.steps_done();
        let by_steps = stream
            .checkpoint_every_steps
            .is_some_and(|every| every > 0 && n.is_multiple_of(every));
        if n.is_multiple_of(Simulation::BATCH) || by_steps {
            let by_time = stream
                .checkpoint_every_seconds
                .is_some_and(|s| last_checkpoint.elapsed().as_secs_f64() >= s);
            if (by_steps || by_time) && n < total {
                files.checkpoint(&mut sim, fingerprint)?;
                last_checkpoint = Instant::now();
                observer.checkpoint(&partial(&sim, start));
            }
            if n.is_multiple_of(Simulation::BATCH)
                && n < total
                && observer.progress(Progress { step: n, total }).is_break()
            {
                termination = Termination::Stopped { step: n };
                break;
            }
        }
    }
    // the step loop's time (RunResults::wall_time): the last flush and checkpoint are the
    // run's output, as the set-up is its input
    let wall_time = start.elapsed().as_secs_f64();
    files.flush(&mut sim)?;
    if !matches!(termination, Termination::Diverged { .. }) {
        files.checkpoint(&mut sim, fingerprint)?;
    }
    let _ = observer.progress(Progress {
        step: sim.steps_done(),
        total,
    });
    let mut results = sim.finish(wall_time, termination);
    // impacts in progress and the last partial block, ended with the run
    files.write_impacts(&results.impacts)?;
    files.write_blocks(&results.blocks)?;
    files.sync()?;
    observer.finished(&results)?;
    files.pack(
        matches!(results.termination, Termination::Completed),
        &observer.metadata(),
    )?;
    results.impacts.clear();
    results.blocks.clear();
    Ok(results)
}

/// A zip error as the I/O error it is (a full disk says "No space left on device", not "i/o
/// error"), or wrapped.
fn zip_io(e: zip::result::ZipError) -> std::io::Error {
    match e {
        zip::result::ZipError::Io(e) => e,
        other => std::io::Error::other(other),
    }
}

/// Statistics so far, without touching the run.
fn partial(sim: &Simulation, start: Instant) -> RunResults {
    sim.partial_results(start.elapsed().as_secs_f64())
}

fn fingerprint_with(fingerprint: u64, settings: &RunSettings) -> u64 {
    let mut bytes = Vec::new();
    let _ = ciborium::into_writer(settings, &mut bytes);
    fnv1a(fingerprint.to_le_bytes().iter().chain(&bytes))
}

/// FNV-1a hash of bytes (a fingerprint, not a security measure).
pub(crate) fn fnv1a<'a>(bytes: impl IntoIterator<Item = &'a u8>) -> u64 {
    bytes.into_iter().fold(0xcbf29ce484222325, |h, b| {
        (h ^ *b as u64).wrapping_mul(0x100000001b3)
    })
}

/// The series: key, element type, shape of one row.
fn series_layout(p: usize, c: usize) -> [(&'static str, Dtype, Vec<usize>); 9] {
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

/// The open files of a streamed run.
struct Files {
    dir: PathBuf,
    series: Vec<NpyAppender>,
    impacts: BufWriter<File>,
    blocks: BufWriter<File>,
    model_contacts: Vec<String>,
    /// The names and units of `results.nc`.
    #[cfg(feature = "netcdf")]
    labels: crate::output::variables::Labels,
}

impl Files {
    fn create(dir: &Path, model: &Model) -> Result<Self> {
        let (p, c) = (model.basis.modes(), model.contacts.len());
        let series = series_layout(p, c)
            .into_iter()
            .map(|(key, dtype, row)| {
                NpyAppender::create(&dir.join(SERIES_DIR).join(format!("{key}.npy")), dtype, row)
            })
            .collect::<Result<Vec<_>>>()?;
        let mut impacts = create(&dir.join(IMPACTS_FILE))?;
        let mut blocks = create(&dir.join(BLOCKS_FILE))?;
        let io = |p: &Path| {
            let p = p.to_path_buf();
            move |e| Error::io(p, e)
        };
        impacts
            .write_all(IMPACTS_HEADER.as_bytes())
            .map_err(io(&dir.join(IMPACTS_FILE)))?;
        blocks
            .write_all(BLOCKS_HEADER.as_bytes())
            .map_err(io(&dir.join(BLOCKS_FILE)))?;
        let mut files = Self {
            dir: dir.to_path_buf(),
            series,
            impacts,
            blocks,
            model_contacts: model.contacts.iter().map(|c| c.name.clone()).collect(),
            #[cfg(feature = "netcdf")]
            labels: crate::output::variables::Labels::of(model),
        };
        files.sync()?;
        Ok(files)
    }

    fn reopen(
        dir: &Path,
        model: &Model,
        rows: u64,
        impacts_bytes: u64,
        blocks_bytes: u64,
    ) -> Result<Self> {
        let (p, c) = (model.basis.modes(), model.contacts.len());
        let series = series_layout(p, c)
            .into_iter()
            .map(|(key, dtype, row)| {
                NpyAppender::reopen(
                    &dir.join(SERIES_DIR).join(format!("{key}.npy")),
                    dtype,
                    row,
                    rows,
                )
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            dir: dir.to_path_buf(),
            series,
            impacts: reopen_at(&dir.join(IMPACTS_FILE), impacts_bytes)?,
            blocks: reopen_at(&dir.join(BLOCKS_FILE), blocks_bytes)?,
            model_contacts: model.contacts.iter().map(|c| c.name.clone()).collect(),
            #[cfg(feature = "netcdf")]
            labels: crate::output::variables::Labels::of(model),
        })
    }

    /// Writes the recorder's samples, the finished impacts and blocks; empties them.
    fn flush(&mut self, sim: &mut Simulation) -> Result<()> {
        self.append_samples(sim.recorder())?;
        sim.recorder_mut().clear();
        let stats = sim.statistics_mut();
        let impacts = std::mem::take(&mut stats.impacts);
        let blocks = std::mem::take(&mut stats.blocks);
        self.write_impacts(&impacts)?;
        self.write_blocks(&blocks)?;
        // give the vectors back, so that their room is reused
        let stats = sim.statistics_mut();
        stats.impacts = reuse(impacts);
        stats.blocks = reuse(blocks);
        Ok(())
    }

    fn append_samples(&mut self, r: &Recorder) -> Result<()> {
        let n = r.len();
        if n == 0 {
            return Ok(());
        }
        let f64s: [&[f64]; 8] = [
            r.t.as_slice().unwrap_or(&[]),
            r.q.as_slice().unwrap_or(&[]),
            r.qdot.as_slice().unwrap_or(&[]),
            r.normal_force.as_slice().unwrap_or(&[]),
            r.tangential_force.as_slice().unwrap_or(&[]),
            r.slip_velocity.as_slice().unwrap_or(&[]),
            r.penetration.as_slice().unwrap_or(&[]),
            r.position.as_slice().unwrap_or(&[]),
        ];
        let order = [0, 1, 2, 3, 4, 5, 6, 8];
        for (data, &k) in f64s.iter().zip(&order) {
            let s = &mut self.series[k];
            s.append_f64(&data[..n * s.row_len], n)?;
        }
        let s = &mut self.series[7];
        let status = r.status.as_slice().unwrap_or(&[]);
        s.append_i8(&status[..n * s.row_len], n)?;
        Ok(())
    }

    fn write_impacts(&mut self, impacts: &[Impact]) -> Result<()> {
        let path = self.dir.join(IMPACTS_FILE);
        for i in impacts {
            writeln!(
                self.impacts,
                "{},{},{},{},{},{},{},{},{},{},{},{}",
                i.contact,
                csv_name(&self.model_contacts[i.contact]),
                i.start,
                i.duration,
                i.contact_time,
                i.peak_time,
                i.peak_force,
                i.impulse,
                i.impact_speed,
                i.rebound_speed,
                i.rebounds,
                i.angle_deg
            )
            .map_err(|e| Error::io(&path, e))?;
        }
        Ok(())
    }

    fn write_blocks(&mut self, blocks: &[BlockStatistics]) -> Result<()> {
        let path = self.dir.join(BLOCKS_FILE);
        for b in blocks {
            let s = &b.statistics;
            writeln!(
                self.blocks,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                b.block,
                b.t_start,
                b.t_end,
                csv_name(self.model_contacts.get(b.contact).map_or(&s.name, |n| n)),
                s.impacts,
                s.impacts_per_second,
                s.contact_time_fraction,
                s.stick_time_fraction,
                s.slip_time_fraction,
                s.normal_force_mean,
                s.normal_force_rms,
                s.normal_force_max,
                s.tangential_force_rms,
                s.wear_work_rate,
                s.normal_wear_work_rate,
                s.wear_volume
            )
            .map_err(|e| Error::io(&path, e))?;
        }
        Ok(())
    }

    /// Flushes every file to the disk.
    fn sync(&mut self) -> Result<()> {
        for s in &mut self.series {
            s.sync()?;
        }
        for (w, name) in [
            (&mut self.impacts, IMPACTS_FILE),
            (&mut self.blocks, BLOCKS_FILE),
        ] {
            w.flush()
                .and_then(|_| w.get_ref().sync_data())
                .map_err(|e| Error::io(self.dir.join(name), e))?;
        }
        Ok(())
    }

    /// Flush, then the checkpoint with the files' lengths.
    fn checkpoint(&mut self, sim: &mut Simulation, fingerprint: u64) -> Result<()> {
        self.flush(sim)?;
        self.sync()?;
        let position = |w: &mut BufWriter<File>, name: &str| {
            w.get_mut()
                .stream_position()
                .map_err(|e| Error::io(self.dir.join(name), e))
        };
        let impacts_bytes = position(&mut self.impacts, IMPACTS_FILE)?;
        let blocks_bytes = position(&mut self.blocks, BLOCKS_FILE)?;
        let checkpoint = Checkpoint {
            fingerprint,
            snapshot: sim.snapshot(),
            rows: self.series[0].rows,
            impacts_bytes,
            blocks_bytes,
        };
        let bytes = encode_checkpoint(&checkpoint)
            .map_err(|e| Error::io(self.dir.join(CHECKPOINT_FILE), e))?;
        crate::files::write_atomically(&self.dir.join(CHECKPOINT_FILE), |mut f| {
            f.write_all(&bytes)?;
            f.sync_data()
        })
    }

    /// Packs `series/` into `results.npz` (stored entries, copied file by file), then with
    /// the `netcdf` feature into `results.nc` (with `meta`); removes `series/` when the run
    /// is complete (it is kept for a resume otherwise).
    fn pack(&mut self, complete: bool, meta: &ResultsMetadata) -> Result<()> {
        let path = self.dir.join(RESULTS_FILE);
        let series: Vec<(String, PathBuf)> = self
            .series
            .iter()
            .map(|s| (s.key.clone(), s.path.clone()))
            .collect();
        crate::files::write_atomically(&path, |file| {
            // after an error (a full disk), the writer swallows what the ZipWriter's drop
            // writes: the error is reported once, by the caller, and the file removed
            let mut zip = zip::ZipWriter::new(BufWriter::new(FailOnce::new(file)));
            let options = zip::write::SimpleFileOptions::default()
                .compression_method(zip::CompressionMethod::Stored)
                .large_file(true);
            for (key, p) in &series {
                zip.start_file(format!("{key}.npy"), options)
                    .map_err(zip_io)?;
                let mut f = File::open(p)?;
                std::io::copy(&mut f, &mut zip)?;
            }
            zip.finish().map_err(zip_io)?.flush()
        })?;
        #[cfg(feature = "netcdf")]
        {
            let series: Vec<crate::output::netcdf::SeriesFile> = self
                .series
                .iter()
                .map(|s| crate::output::netcdf::SeriesFile {
                    key: &s.key,
                    path: &s.path,
                    dtype: s.dtype,
                    row_shape: &s.row_shape,
                    rows: s.rows,
                })
                .collect();
            crate::output::netcdf::write(&self.dir, &series, &self.labels, meta)?;
        }
        #[cfg(not(feature = "netcdf"))]
        let _ = meta;
        if complete {
            self.series.clear();
            let _ = std::fs::remove_dir_all(self.dir.join(SERIES_DIR));
        }
        Ok(())
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

fn reuse<T>(mut v: Vec<T>) -> Vec<T> {
    v.clear();
    v
}

const IMPACTS_HEADER: &str = "contact,name,start,duration,contact_time,peak_time,peak_force,impulse,impact_speed,rebound_speed,rebounds,angle_deg\n";
const BLOCKS_HEADER: &str = "block,t_start,t_end,name,impacts,impacts_per_second,contact_time_fraction,stick_time_fraction,slip_time_fraction,normal_force_mean,normal_force_rms,normal_force_max,tangential_force_rms,wear_work_rate,normal_wear_work_rate,wear_volume\n";

/// A name safe in a CSV field.
fn csv_name(name: &str) -> String {
    name.replace([',', '\n', '"'], "_")
}

fn create(path: &Path) -> Result<BufWriter<File>> {
    File::create(path)
        .map(BufWriter::new)
        .map_err(|e| Error::io(path, e))
}

/// Opens `path` for appending after cutting it to `len` bytes (what the checkpoint saw).
fn reopen_at(path: &Path, len: u64) -> Result<BufWriter<File>> {
    let io = |e| Error::io(path, e);
    let mut file = OpenOptions::new().write(true).open(path).map_err(io)?;
    file.set_len(len).map_err(io)?;
    file.seek(SeekFrom::Start(len)).map_err(io)?;
    Ok(BufWriter::new(file))
}

/// A `.npy` file (format 1.0) that grows by rows.
struct NpyAppender {
    key: String,
    path: PathBuf,
    file: BufWriter<File>,
    dtype: Dtype,
    row_shape: Vec<usize>,
    /// Values per row.
    row_len: usize,
    rows: u64,
}

impl NpyAppender {
    fn create(path: &Path, dtype: Dtype, row_shape: Vec<usize>) -> Result<Self> {
        let file = File::create(path).map_err(|e| Error::io(path, e))?;
        let mut s = Self::new(path, file, dtype, row_shape, 0);
        s.write_header()?;
        Ok(s)
    }

    /// Reopens a file written by [`Self::create`], cut to `rows` rows.
    fn reopen(path: &Path, dtype: Dtype, row_shape: Vec<usize>, rows: u64) -> Result<Self> {
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
    fn append_f64(&mut self, values: &[f64], rows: usize) -> Result<()> {
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
    fn append_i8(&mut self, values: &[i8], rows: usize) -> Result<()> {
        debug_assert_eq!(self.dtype, Dtype::I8);
        debug_assert_eq!(values.len(), rows * self.row_len);
        let bytes: Vec<u8> = values.iter().map(|v| *v as u8).collect();
        self.file
            .write_all(&bytes)
            .map_err(|e| Error::io(&self.path, e))?;
        self.rows += rows as u64;
        self.write_header()
    }

    fn sync(&mut self) -> Result<()> {
        self.file
            .flush()
            .and_then(|_| self.file.get_ref().sync_data())
            .map_err(|e| Error::io(&self.path, e))
    }
}
