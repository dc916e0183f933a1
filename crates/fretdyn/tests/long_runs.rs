//! Long runs: a streamed run gives the same results as a run held in memory; a run stopped
//! (or killed after its checkpoint) and resumed gives, bit for bit, the results of an
//! uninterrupted run.

use std::ops::ControlFlow;
use std::path::Path;

use fretdyn::accumulate::statistics::StatisticsSettings;
use fretdyn::case::Case;
use fretdyn::integrator::simulation::{Progress, RunResults, Termination, simulate};
use fretdyn::output::checkpoint;
use fretdyn::output::stream::{self, ProgressOnly, StreamObserver, StreamSettings};
use ndarray::{ArrayD, IxDyn};
use ndarray_npy::NpzReader;

const KEYS: [&str; 8] = [
    "t",
    "q",
    "qdot",
    "contact_normal_force",
    "contact_tangential_force",
    "contact_slip_velocity",
    "contact_penetration",
    "contact_position",
];

/// The multi-span tube, shortened, with blocks and a rest duration so that every output
/// file has content.
fn tube_case(steps: u64) -> Case {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/tube_multispan.toml");
    let mut case = Case::from_file(&path).unwrap();
    case.settings.steps = steps;
    case.settings.output_every = 10;
    case.settings.statistics = StatisticsSettings {
        t_start: 0.01,
        block: Some(0.02),
        rest_duration: 2e-4,
        ..Default::default()
    };
    case
}

fn read(dir: &Path) -> (Vec<ArrayD<f64>>, ArrayD<i8>) {
    let mut npz = NpzReader::new(std::fs::File::open(dir.join("results.npz")).unwrap()).unwrap();
    let f = KEYS
        .iter()
        .map(|k| {
            npz.by_name::<ndarray::OwnedRepr<f64>, IxDyn>(&format!("{k}.npy"))
                .unwrap()
        })
        .collect();
    let status = npz
        .by_name::<ndarray::OwnedRepr<i8>, IxDyn>("contact_status.npy")
        .unwrap();
    (f, status)
}

fn text(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap()
}

fn same_statistics(a: &RunResults, b: &RunResults) {
    assert_eq!(a.contacts, b.contacts);
    assert_eq!(a.solver, b.solver);
    assert_eq!(a.energy, b.energy);
    assert_eq!(a.steps, b.steps);
}

fn stream_settings(checkpoint_every_steps: Option<u64>) -> StreamSettings {
    StreamSettings {
        chunk_samples: 300,
        checkpoint_every_steps,
        checkpoint_every_seconds: None,
    }
}

/// Stops the run at a given step, like Ctrl-C.
struct StopAt(u64);

impl StreamObserver for StopAt {
    fn progress(&mut self, p: Progress) -> ControlFlow<()> {
        if p.step >= self.0 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// Dies (panics, unwinding through the writers) at a given step, after a checkpoint: the
/// files then hold more than the checkpoint saw, as after a `kill`.
struct DieAt(u64);

impl StreamObserver for DieAt {
    fn progress(&mut self, p: Progress) -> ControlFlow<()> {
        assert!(p.step < self.0, "killed");
        ControlFlow::Continue(())
    }
}

#[test]
fn streamed_run_equals_the_run_in_memory_and_resumes_bit_for_bit() {
    let steps = 10_000;
    let case = tube_case(steps);
    let tmp = tempdir();
    let full = tmp.join("full");
    let r_full = stream::run(
        &case.model,
        &case.settings,
        &full,
        &stream_settings(Some(3072)),
        7,
        &mut ProgressOnly(|_| ControlFlow::Continue(())),
    )
    .unwrap();
    assert_eq!(r_full.termination, Termination::Completed);
    assert!(!full.join("series").exists(), "series/ removed once packed");

    // the same run in memory
    let mem = simulate(&case.model, &case.settings).unwrap();
    same_statistics(&mem, &r_full);
    let (series, status) = read(&full);
    let r = &mem.recorder;
    let mem_series = [
        r.t.clone().into_dyn(),
        r.q.clone().into_dyn(),
        r.qdot.clone().into_dyn(),
        r.normal_force.clone().into_dyn(),
        r.tangential_force.clone().into_dyn(),
        r.slip_velocity.clone().into_dyn(),
        r.penetration.clone().into_dyn(),
        r.position.clone().into_dyn(),
    ];
    for ((k, a), b) in KEYS.iter().zip(&series).zip(&mem_series) {
        assert_eq!(a, b, "{k}");
    }
    assert_eq!(status, r.status.clone().into_dyn());
    assert_eq!(series[0].len(), (steps / 10 + 1) as usize);
    // impacts and blocks: the same as in memory, in the same order
    let impacts = text(&full, "impacts.csv");
    assert_eq!(impacts.lines().count(), mem.impacts.len() + 1);
    assert!(
        mem.impacts.len() > 5,
        "the case has impacts: {}",
        mem.impacts.len()
    );
    for (line, i) in impacts.lines().skip(1).zip(&mem.impacts) {
        let start: f64 = line.split(',').nth(2).unwrap().parse().unwrap();
        assert_eq!(start, i.start);
    }
    let blocks = text(&full, "blocks.csv");
    assert_eq!(blocks.lines().count(), mem.blocks.len() + 1);
    assert_eq!(mem.blocks.len(), 5 * case.model.contacts.len());

    // stopped at half time, then resumed
    let stopped = tmp.join("stopped");
    let r = stream::run(
        &case.model,
        &case.settings,
        &stopped,
        &stream_settings(None),
        7,
        &mut StopAt(5120),
    )
    .unwrap();
    assert_eq!(r.termination, Termination::Stopped { step: 5120 });
    // what was written is readable: results.npz up to the stop
    let (partial, _) = read(&stopped);
    assert_eq!(partial[0].len(), 5120 / 10 + 1);
    let r = resume(&case, &stopped, 7).unwrap();
    same_statistics(&r_full, &r);
    assert_eq!(read(&stopped), read(&full));
    assert_eq!(text(&stopped, "impacts.csv"), impacts);
    assert_eq!(text(&stopped, "blocks.csv"), blocks);

    // killed after a checkpoint, with more written since: resumed from the checkpoint (at
    // step 6000, between two exact evaluations of the harmonic load's sine: its rotation is
    // taken up there, loads::stepped)
    let killed = tmp.join("killed");
    let died = std::panic::catch_unwind(|| {
        stream::run(
            &case.model,
            &case.settings,
            &killed,
            &stream_settings(Some(3000)),
            7,
            &mut DieAt(7168),
        )
    });
    assert!(died.is_err());
    let r = resume(&case, &killed, 7).unwrap();
    same_statistics(&r_full, &r);
    assert_eq!(read(&killed), read(&full));
    assert_eq!(text(&killed, "impacts.csv"), impacts);
    assert_eq!(text(&killed, "blocks.csv"), blocks);

    // another case (fingerprint) or a complete run: refused
    let err = resume(&case, &full, 8).unwrap_err();
    assert!(err.to_string().contains("another case"), "{err}");
    let err = resume(&case, &full, 7).unwrap_err();
    assert!(err.to_string().contains("complete"), "{err}");
    std::fs::remove_dir_all(&tmp).ok();
}

/// Killed after its last checkpoint, before `results.npz` was packed (or out of disk while
/// packing): `resume` packs it, with the results of an uninterrupted run; then it is complete.
#[test]
fn a_run_killed_before_packing_is_finished_by_resume() {
    let steps = 4096;
    let case = tube_case(steps);
    let tmp = tempdir().join("packing");
    let full = tmp.join("full");
    let r_full = stream::run(
        &case.model,
        &case.settings,
        &full,
        &stream_settings(Some(1024)),
        7,
        &mut ProgressOnly(|_| ControlFlow::Continue(())),
    )
    .unwrap();
    // the last progress report comes after the last checkpoint, before the packing
    let killed = tmp.join("killed");
    let died = std::panic::catch_unwind(|| {
        stream::run(
            &case.model,
            &case.settings,
            &killed,
            &stream_settings(Some(1024)),
            7,
            &mut DieAt(steps),
        )
    });
    assert!(died.is_err());
    assert_eq!(checkpoint::checkpoint_step(&killed).unwrap(), steps);
    assert!(!killed.join("results.npz").exists());
    let r = resume(&case, &killed, 7).unwrap();
    same_statistics(&r_full, &r);
    assert_eq!(r.termination, Termination::Completed);
    assert_eq!(read(&killed), read(&full));
    assert_eq!(text(&killed, "impacts.csv"), text(&full, "impacts.csv"));
    assert_eq!(text(&killed, "blocks.csv"), text(&full, "blocks.csv"));
    assert!(!killed.join("series").exists());
    let err = resume(&case, &killed, 7).unwrap_err();
    assert!(err.to_string().contains("complete"), "{err}");
    std::fs::remove_dir_all(&tmp).ok();
}

/// `checkpoint.bin` is `FRETDYNC`, the format (u32 LE), the version of fretdyn (u8 length,
/// UTF-8), then CBOR; a checkpoint of another format or version, or without the header (the
/// bincode checkpoints of format 1), is refused with what to do; the file itself resumes.
#[test]
fn a_checkpoint_of_another_version_is_refused() {
    let case = tube_case(4096);
    let tmp = tempdir().join("versions");
    let dir = tmp.join("stopped");
    stream::run(
        &case.model,
        &case.settings,
        &dir,
        &stream_settings(None),
        7,
        &mut StopAt(2048),
    )
    .unwrap();
    let path = dir.join("checkpoint.bin");
    let bytes = std::fs::read(&path).unwrap();
    let version = env!("CARGO_PKG_VERSION");
    assert_eq!(&bytes[..8], b"FRETDYNC");
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()),
        checkpoint::CHECKPOINT_FORMAT
    );
    assert_eq!(bytes[12] as usize, version.len());
    assert_eq!(&bytes[13..13 + version.len()], version.as_bytes());
    let payload = &bytes[13 + version.len()..];
    let with_header = |format: u32, version: &str| {
        let mut b = b"FRETDYNC".to_vec();
        b.extend_from_slice(&format.to_le_bytes());
        b.push(version.len() as u8);
        b.extend_from_slice(version.as_bytes());
        b.extend_from_slice(payload);
        b
    };
    let refused = |bytes: Vec<u8>, needles: &[&str]| {
        std::fs::write(&path, bytes).unwrap();
        let err = resume(&case, &dir, 7).unwrap_err().to_string();
        for n in needles {
            assert!(err.contains(n), "'{n}' not in: {err}");
        }
        assert!(err.contains("checkpoint.bin"), "{err}");
        assert!(err.contains("start the run again"), "{err}");
    };
    refused(
        with_header(checkpoint::CHECKPOINT_FORMAT, "9.9.9"),
        &[
            "written by fretdyn 9.9.9",
            &format!("this is fretdyn {version}"),
        ],
    );
    // format 2: the statistics' layout before format 3; format 3: no fluid-elastic state
    refused(with_header(2, version), &["checkpoint format 2"]);
    refused(with_header(3, version), &["checkpoint format 3"]);
    // format 4: blocks only when set, no batch moments
    refused(with_header(4, version), &["checkpoint format 4"]);
    // format 5: the angle of an impact's peak formed at the peak
    refused(with_header(5, version), &["checkpoint format 5"]);
    // format 6: a snapshot copied field by field from the run, not its state as it is
    refused(with_header(6, version), &["checkpoint format 6"]);
    // format 1: bincode, starting with its version (1u32) and the fingerprint
    let mut old = 1u32.to_le_bytes().to_vec();
    old.extend_from_slice(&7u64.to_le_bytes());
    old.extend_from_slice(payload);
    refused(old, &["not a checkpoint of this fretdyn"]);
    refused(
        with_header(checkpoint::CHECKPOINT_FORMAT, version)[..40].to_vec(),
        &["damaged"],
    );
    // the checkpoint as written resumes
    std::fs::write(&path, &bytes).unwrap();
    let r = resume(&case, &dir, 7).unwrap();
    assert_eq!(r.termination, Termination::Completed);
    std::fs::remove_dir_all(&tmp).ok();
}

/// Resumes the run in `dir` to its end.
fn resume(case: &Case, dir: &Path, fingerprint: u64) -> fretdyn::Result<RunResults> {
    stream::resume(
        &case.model,
        &case.settings,
        dir,
        &stream_settings(None),
        fingerprint,
        &mut ProgressOnly(|_| ControlFlow::Continue(())),
    )
}

fn tempdir() -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("fretdyn-long-runs-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}
