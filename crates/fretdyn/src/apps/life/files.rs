//! The folder of a service life, as `fretdyn life` and Python's `fretdyn.life` keep it: the
//! record of the inputs it belongs to (`life_run.json`), a new life started afresh there, the
//! checkpoint a life continues from, and the files of its results — `life.csv` (one row per
//! life step), `scars.csv` (the final scar profiles), `convergence.csv` (the life with
//! `max_depth_change` halved), `life.json` — one text each, byte for byte the same from both
//! front ends.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::checkpoint::LifeCheckpoint;
use super::results::LifeResults;
use crate::error::{Error, Result};
use crate::settings::life::YEAR;

/// The file that records which inputs a life's folder belongs to, for a resume.
pub const LIFE_RUN_FILE: &str = "life_run.json";

/// The checkpoint of a life in its folder ([`LifeCheckpoint`]).
pub const CHECKPOINT_FILE: &str = "life_checkpoint.bin";

/// What a life writes in its folder (removed when a new life starts there, so that a folder
/// never mixes two lives).
pub const OUTPUTS: [&str; 6] = [
    "life.csv",
    "life.json",
    "scars.csv",
    "life.png",
    "convergence.csv",
    "convergence.png",
];

/// The text of `life.json`, as `fretdyn life` and Python's `fretdyn.life` write it: the case
/// `title`, the plugging `criterion_depth` (m, or null) and the `results`.
pub fn life_json(title: &str, results: &LifeResults, criterion: Option<f64>) -> String {
    let json = serde_json::json!({
        "title": title,
        "criterion_depth": criterion,
        "results": results,
    });
    serde_json::to_string_pretty(&json).unwrap_or_default() + "\n"
}

/// A new life in `dir`: the folder made, the files of an earlier life there removed
/// ([`OUTPUTS`] and its checkpoint, so that a folder never mixes two lives), and the
/// `fingerprint` of its inputs recorded in [`LIFE_RUN_FILE`], with `case_file` when the case
/// is the file's as it is on disk (then `fretdyn life --resume DIR` continues the life).
pub fn start_afresh(dir: &Path, fingerprint: u64, case_file: Option<&Path>) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    for name in OUTPUTS.iter().chain(&[CHECKPOINT_FILE]) {
        let p = dir.join(name);
        match std::fs::remove_file(&p) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(Error::io(&p, e)),
            _ => {}
        }
    }
    let mut info = serde_json::json!({ "fingerprint": fingerprint.to_string() });
    if let Some(path) = case_file {
        let absolute = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        info["case_file"] = serde_json::json!(absolute);
    }
    crate::files::write_text_atomically(&dir.join(LIFE_RUN_FILE), &format!("{info:#}\n"))
}

/// The record of the life in `dir` ([`LIFE_RUN_FILE`], written by [`start_afresh`]); the
/// error names it when it is missing or unreadable.
fn life_run(dir: &Path) -> Result<serde_json::Value> {
    let path = dir.join(LIFE_RUN_FILE);
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    serde_json::from_str(&text).map_err(|e| Error::io(&path, std::io::Error::other(e)))
}

/// The case file the life in `dir` was started from, as [`start_afresh`] recorded it (for
/// `fretdyn life --resume DIR`); `None` when the life was started from a case that is not a
/// file's. The error names the record when it is missing or unreadable.
pub fn recorded_case_file(dir: &Path) -> Result<Option<PathBuf>> {
    Ok(life_run(dir)?["case_file"].as_str().map(PathBuf::from))
}

/// Why the life in a folder cannot be continued ([`resume_checkpoint`]); each front end says
/// it in its words, with how to start the life again.
#[derive(Debug)]
pub enum Unresumable {
    /// The inputs changed since the life started there, or no life was started there (the
    /// fingerprint in [`LIFE_RUN_FILE`] is not the inputs').
    Changed,
    /// No checkpoint: the life there is over (`life.json` says how it ended), or stopped
    /// before its first checkpoint.
    NoCheckpoint,
    /// The checkpoint (at this path) was written for other inputs.
    OtherInputs(PathBuf),
    /// The checkpoint cannot be read (another version of fretdyn, damaged): why.
    Unreadable(Error),
}

/// The checkpoint to continue the life in `dir` from, for the inputs of this `fingerprint`:
/// refused when the inputs changed since the life started there, when there is no checkpoint,
/// or when it was written for other inputs ([`Unresumable`]).
pub fn resume_checkpoint(
    dir: &Path,
    fingerprint: u64,
) -> std::result::Result<LifeCheckpoint, Unresumable> {
    let recorded = life_run(dir).unwrap_or_default();
    if recorded["fingerprint"].as_str() != Some(fingerprint.to_string().as_str()) {
        return Err(Unresumable::Changed);
    }
    let checkpoint = dir.join(CHECKPOINT_FILE);
    if !checkpoint.exists() {
        return Err(Unresumable::NoCheckpoint);
    }
    let c = LifeCheckpoint::read(&checkpoint).map_err(Unresumable::Unreadable)?;
    if c.fingerprint() != fingerprint {
        return Err(Unresumable::OtherInputs(checkpoint));
    }
    Ok(c)
}

/// The columns of each wearing contact in `life.csv`, as `<contact>.<column>`, in order (the
/// fields of [`ContactLife`](super::ContactLife)).
pub const LIFE_CSV_COLUMNS: [&str; 8] = [
    "wear_work_rate",
    "wear_work_rate_se",
    "tube_volume",
    "support_volume",
    "tube_depth",
    "support_depth",
    "clearance_increase",
    "tube_depth_fixed_gap",
];

/// The text of `life.csv`: `time_years`, then the [`LIFE_CSV_COLUMNS`] of every wearing
/// contact; one row per life step (the start first). Numbers in the shortest exponent form
/// that reads back the same `f64`; an unknown standard error is an empty cell.
pub fn life_csv(r: &LifeResults) -> String {
    let mut csv = String::from("time_years");
    for name in &r.contacts {
        for col in LIFE_CSV_COLUMNS {
            let _ = write!(csv, ",{name}.{col}");
        }
    }
    csv.push('\n');
    for s in &r.steps {
        let _ = write!(csv, "{:e}", s.time / YEAR);
        for c in &s.contacts {
            let se = c
                .wear_work_rate_se
                .map(|x| format!("{x:e}"))
                .unwrap_or_default();
            let _ = write!(
                csv,
                ",{:e},{se},{:e},{:e},{:e},{:e},{:e},{:e}",
                c.wear_work_rate,
                c.tube_volume,
                c.support_volume,
                c.tube_depth,
                c.support_depth,
                c.clearance_increase,
                c.tube_depth_fixed_gap
            );
        }
        csv.push('\n');
    }
    csv
}

/// The text of `scars.csv`: one row per bin of every final scar profile (`angle_deg`, the
/// centre of the bin, for a hole only), the tube's and the support's depth (bodies A and B of
/// a two-body contact).
pub fn scars_csv(r: &LifeResults) -> String {
    let mut scars =
        String::from("contact,kind,bin,angle_deg,clearance_increase,tube_depth,support_depth\n");
    for s in &r.scars {
        let n = s.clearance_increase.len();
        let depths = s.tube_depth.iter().zip(&s.support_depth);
        for (b, (a, (t, sd))) in s.clearance_increase.iter().zip(depths).enumerate() {
            let angle = if s.kind == "hole" {
                format!("{}", (b as f64 + 0.5) * 360.0 / n as f64)
            } else {
                String::new()
            };
            let _ = writeln!(
                scars,
                "{},{},{b},{angle},{a:e},{t:e},{sd:e}",
                s.contact, s.kind
            );
        }
    }
    scars
}

/// The text of `convergence.csv`: one row per life of `lives` (its `max_depth_change` and
/// results, the life itself first): its life steps, how it ended, the years it reached and
/// the tube depth at its end of every contact of `contacts`.
pub fn convergence_csv(contacts: &[String], lives: &[(f64, &LifeResults)]) -> String {
    let mut csv = String::from("max_depth_change,life_steps,life_end,end_years");
    for name in contacts {
        let _ = write!(csv, ",{name}.tube_depth");
    }
    csv.push('\n');
    for (f, r) in lives {
        let end = r.steps.last().map_or(0.0, |s| s.time) / YEAR;
        let _ = write!(csv, "{f:e},{},{},{end:e}", r.steps.len() - 1, r.end.name());
        for x in end_depths(r) {
            let _ = write!(csv, ",{x:e}");
        }
        csv.push('\n');
    }
    csv
}

/// Each contact's tube depth at the end of a life.
pub fn end_depths(r: &LifeResults) -> Vec<f64> {
    r.steps
        .last()
        .map(|s| s.contacts.iter().map(|c| c.tube_depth).collect())
        .unwrap_or_default()
}

/// Writes `life.csv`, `scars.csv` and `life.json` ([`life_json`]) into `dir`, each to a
/// temporary name then renamed (a full disk never leaves a truncated table under its final
/// name).
pub fn write_life(dir: &Path, title: &str, r: &LifeResults, criterion: Option<f64>) -> Result<()> {
    let put =
        |name: &str, text: String| crate::files::write_text_atomically(&dir.join(name), &text);
    put("life.csv", life_csv(r))?;
    put("scars.csv", scars_csv(r))?;
    put("life.json", life_json(title, r, criterion))
}
