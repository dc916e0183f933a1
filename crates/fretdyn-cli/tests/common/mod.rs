//! What the command-line tests share: running the `fretdyn` binary, the examples folder, and
//! scratch folders.
#![allow(dead_code)] // each test program uses a part

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `fretdyn` binary built with the tests, with `args`, in `cwd`.
pub fn fretdyn(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("fretdyn runs")
}

/// The repository's `examples/` folder.
pub fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

/// A fresh scratch folder, removed at the end; named after the test program, `name` and the
/// process, so that test programs running at the same time do not share one.
pub struct Scratch(pub PathBuf);

impl Scratch {
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!(
            "fretdyn-{}-{name}-{}",
            env!("CARGO_CRATE_NAME"),
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Waits until the streamed run `child` writing into `dir` has a checkpoint at step `step` or
/// later (it must still be running: a run that ends first fails the test), then `kill -9`s it.
pub fn kill_past_checkpoint(child: &mut std::process::Child, dir: &Path, step: u64) {
    let start = std::time::Instant::now();
    while fretdyn::output::checkpoint::checkpoint_step(dir)
        .ok()
        .is_none_or(|n| n < step)
    {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before it could be killed"
        );
        assert!(
            start.elapsed().as_secs() < 600,
            "no checkpoint at step {step}"
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    Command::new("kill")
        .args(["-9", &child.id().to_string()])
        .status()
        .unwrap();
    child.wait().unwrap();
}
