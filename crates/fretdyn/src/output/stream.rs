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
//! - `checkpoint.bin`: the run's [`Snapshot`](crate::integrator::simulation::Snapshot) with
//!   the length of every file at that step ([`super::checkpoint`]);
//! - at the end, `results.npz`, packed from `series/` (copied entry by entry, never whole in
//!   memory), then (with the `netcdf` feature) `results.nc`, the same arrays with names and
//!   units, packed from `series/` block by block (`output/netcdf.rs` says why at the
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
//! The steps run on the one run loop ([`crate::integrator::simulation::drive`]); what this
//! file adds is its sink: the flushes, the checkpoints and the progress at the ends of the
//! batches.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::accumulate::recorder::Recorder;
use crate::accumulate::statistics::{BlockStatistics, Impact, block_columns};
use crate::error::{Error, Result};
use crate::integrator::simulation::{
    BatchEnd, BatchSink, Driven, Progress, RunResults, RunSettings, Simulation, Termination, drive,
};
use crate::model::Model;
use crate::output::checkpoint::{self, Checkpoint};
pub use crate::output::layout::{
    BLOCKS_FILE, CHECKPOINT_FILE, IMPACTS_FILE, NETCDF_FILE, RESULTS_FILE, ResultsMetadata,
    SERIES_DIR,
};
use crate::output::series::{NpyAppender, pack_npz, series_layout};

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
    streamed(sim, files, settings, stream, fingerprint, observer)
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
    let checkpoint = checkpoint::read(dir)?;
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
        checkpoint.snapshot.step() >= settings.steps || checkpoint.snapshot.target_met().is_some();
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
    streamed(sim, files, settings, stream, fingerprint, observer)
}

/// A streamed run from `sim` into `files`: the run loop with the [`Streamed`] sink, then the
/// run's end — the last flush and checkpoint, the observer's [`StreamObserver::finished`],
/// the packing.
fn streamed(
    sim: Simulation,
    files: Files,
    settings: &RunSettings,
    stream: &StreamSettings,
    fingerprint: u64,
    observer: &mut dyn StreamObserver,
) -> Result<RunResults> {
    let mut sink = Streamed {
        files,
        stream,
        fingerprint: fingerprint_with(fingerprint, settings),
        observer,
        start: Instant::now(),
        last_checkpoint: Instant::now(),
    };
    // the step loop's time (RunResults::wall_time): the last flush and checkpoint are the
    // run's output, as the set-up is its input
    let Driven {
        mut sim,
        termination,
        wall_time,
    } = drive(sim, &mut sink)?;
    let Streamed {
        mut files,
        fingerprint,
        observer,
        ..
    } = sink;
    files.flush(&mut sim)?;
    if !matches!(termination, Termination::Diverged { .. }) {
        files.checkpoint(&mut sim, fingerprint)?;
    }
    let _ = observer.progress(Progress {
        step: sim.steps_done(),
        total: settings.steps,
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

/// What a streamed run does at the ends of its batches: the recorder flushed when full, a
/// checkpoint every so many steps or seconds, the progress told to the observer.
struct Streamed<'a> {
    files: Files,
    stream: &'a StreamSettings,
    /// [`fingerprint_with`] of the case and the settings.
    fingerprint: u64,
    observer: &'a mut dyn StreamObserver,
    /// When the step loop started.
    start: Instant,
    last_checkpoint: Instant,
}

impl BatchSink for Streamed<'_> {
    fn every_steps(&self) -> Option<u64> {
        self.stream.checkpoint_every_steps
    }

    fn drain(&mut self, sim: &mut Simulation) -> Result<()> {
        self.files.flush(sim)
    }

    fn batch_end(&mut self, sim: &mut Simulation, end: BatchEnd) -> Result<ControlFlow<()>> {
        let by_time = self
            .stream
            .checkpoint_every_seconds
            .is_some_and(|s| self.last_checkpoint.elapsed().as_secs_f64() >= s);
        if (end.by_steps || by_time) && end.before_the_end() {
            self.files.checkpoint(sim, self.fingerprint)?;
            self.last_checkpoint = Instant::now();
            let partial = sim.partial_results(self.start.elapsed().as_secs_f64());
            self.observer.checkpoint(&partial);
        }
        Ok(if end.whole && end.before_the_end() {
            self.observer.progress(Progress {
                step: end.step,
                total: end.total,
            })
        } else {
            ControlFlow::Continue(())
        })
    }
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
            .write_all(blocks_header().as_bytes())
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
            let w = &mut self.blocks;
            let name = self.model_contacts.get(b.contact).map_or(&s.name, |n| n);
            write!(
                w,
                "{},{},{},{}",
                b.block,
                b.t_start,
                b.t_end,
                csv_name(name)
            )
            .and_then(|()| block_columns().try_for_each(|c| write!(w, ",{}", (c.value)(s))))
            .and_then(|()| writeln!(w))
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
        checkpoint::write(&self.dir, &checkpoint)
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
        pack_npz(&path, &series)?;
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

fn reuse<T>(mut v: Vec<T>) -> Vec<T> {
    v.clear();
    v
}

const IMPACTS_HEADER: &str = "contact,name,start,duration,contact_time,peak_time,peak_force,impulse,impact_speed,rebound_speed,rebounds,angle_deg\n";
/// The header of `blocks.csv`: the block, its start and end, the contact's name, then the
/// statistics of the table that `blocks.csv` has ([`block_columns`]).
fn blocks_header() -> String {
    let mut header = String::from("block,t_start,t_end,name");
    for s in block_columns() {
        header.push(',');
        header.push_str(s.key);
    }
    header.push('\n');
    header
}

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
