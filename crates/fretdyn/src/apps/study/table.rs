//! A study's table (`study.csv`): its header, the row of a finished run, and the table read
//! back — each row tied to its run's inputs by a fingerprint, so that a table of other inputs
//! is refused instead of continued; the record of the inputs beside it (`.inputs.json`) and
//! the lock while a study writes it.

use std::path::Path;

use crate::accumulate::monitor::MONITOR_COLUMNS;
use crate::error::{Error, Result};
use crate::integrator::simulation::{RunResults, Termination};

/// Statistics written per contact in the table, as `<contact>.<statistic>`: those of the
/// table of statistics marked for `study.csv`.
pub const TABLE_STATISTICS: [&str; crate::accumulate::statistics::STUDY] =
    crate::accumulate::statistics::STUDY_STATISTICS;

/// The statistics of [`TABLE_STATISTICS`] with a standard error by batch means, written
/// as `<contact>.<statistic>_se` after a contact's statistics (empty with fewer than 2
/// batches).
pub fn table_errors() -> impl Iterator<Item = &'static str> {
    TABLE_STATISTICS
        .into_iter()
        .filter(|s| crate::accumulate::statistics::BATCHED_STATISTICS.contains(s))
}

/// The header of a study's table: `run`, the `parameters` columns ([`Study::columns`](super::Study::columns)),
/// `sample` (with `sampling`, a probabilistic study), seed, status, steps/s, then
/// `<contact>.<statistic>` for every contact of the base case, the [`LIFE_COLUMNS`] with
/// `life` (a study of service lives), `<monitor>.<column>` ([`MONITOR_COLUMNS`]) for every
/// displacement monitor, then [`CONNORS_COLUMN`] and [`FINGERPRINT_COLUMN`].
pub(super) fn header(
    parameters: impl IntoIterator<Item = String>,
    sampling: bool,
    life: bool,
    contacts: &[String],
    monitors: &[String],
) -> String {
    let mut cols = vec!["run".to_string()];
    cols.extend(parameters);
    if sampling {
        cols.push("sample".into());
    }
    cols.extend(["seed", "status", "steps_per_second"].map(String::from));
    for c in contacts {
        for s in TABLE_STATISTICS {
            cols.push(format!("{c}.{s}"));
        }
        for s in table_errors() {
            cols.push(format!("{c}.{s}_se"));
        }
    }
    if life {
        cols.push("life_end".into());
        for c in contacts {
            for s in LIFE_COLUMNS {
                cols.push(format!("{c}.{s}"));
            }
        }
    }
    for m in monitors {
        cols.extend(MONITOR_COLUMNS.map(|s| format!("{m}.{s}")));
    }
    cols.push(CONNORS_COLUMN.to_string());
    cols.push(FINGERPRINT_COLUMN.to_string());
    cols.join(",")
}

/// A row of the table: `cols`, the run's own cells (index, values, sample, seed), then how its
/// run `r` ended and its speed, the statistics of `r` per contact, the `life` cells of a study
/// of service lives ([`LIFE_COLUMNS`]), its monitors' cells, the largest Connors ratio of its case
/// ([`CONNORS_COLUMN`]) and the `fingerprint` of its inputs: the columns of [`header`].
pub(super) fn row(
    mut cols: Vec<String>,
    r: &RunResults,
    life: Option<Vec<String>>,
    connors: Option<f64>,
    fingerprint: String,
) -> String {
    cols.push(
        match r.termination {
            Termination::Completed => "completed",
            Termination::Diverged { .. } => "diverged",
            Termination::Stopped { .. } | Termination::InProgress { .. } => "stopped",
        }
        .to_string(),
    );
    cols.push(r.steps_per_second().to_string());
    for c in &r.contacts {
        let v = serde_json::to_value(c).unwrap_or_default();
        for s in TABLE_STATISTICS {
            cols.push(v[s].as_f64().map(|x| x.to_string()).unwrap_or_default());
        }
        for s in table_errors() {
            let se = &v[format!("{s}_se")];
            cols.push(se.as_f64().map(|x| x.to_string()).unwrap_or_default());
        }
    }
    cols.extend(life.into_iter().flatten());
    for m in &r.monitors {
        let cells = m
            .cells()
            .map(|x| x.map(|x| x.to_string()).unwrap_or_default());
        cols.extend(cells);
    }
    cols.push(connors.map(|x| x.to_string()).unwrap_or_default());
    cols.push(fingerprint);
    cols.join(",")
}

/// Column of the study table that ties each row to the inputs it was computed from: the
/// fingerprint of its run's case as resolved and of the files it reads
/// ([`Fingerprint::text`]). A row is reused only when it is the fingerprint the study gives
/// its run now.
pub const FINGERPRINT_COLUMN: &str = "fingerprint";

/// Per-contact columns of a study whose base case has a `[life]` section (THEORY §14.5): the
/// tube's depth at the end of the life (m; at the target time, or where it stopped), the time
/// to the criterion (years; `inf` when not reached), and the same by the fixed-gap
/// extrapolation. Empty for a contact without `wear`.
pub const LIFE_COLUMNS: [&str; 4] = [
    "depth_at_target",
    "time_to_criterion",
    "depth_at_target_fixed_gap",
    "time_to_criterion_fixed_gap",
];

/// Column of the study table with the largest Connors ratio `U_eff/U_c` over the modes of
/// the run's case (docs/FLOW.md; `inf` for an undamped mode in a flow; empty without
/// `[flow]`).
pub const CONNORS_COLUMN: &str = "connors_max_ratio";

pub(super) fn csv_value(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.replace(',', "_"),
        other => other.to_string(),
    }
}

/// A complete row of a study table: its run, its parameter cells and its fingerprint.
#[derive(Debug)]
pub(super) struct TableRow {
    pub(super) index: usize,
    pub(super) values: Vec<String>,
    pub(super) fingerprint: String,
}

/// The complete rows of the table at `table` (none when it is missing or empty; a last line
/// without its end of line is cut, not complete); checks its header.
pub(super) fn read_rows(table: &Path, header: &str) -> Result<Vec<TableRow>> {
    let Ok(text) = std::fs::read_to_string(table) else {
        return Ok(Vec::new());
    };
    let mut lines = text.lines();
    match lines.next() {
        None => return Ok(Vec::new()),
        Some(h) if h == header => {}
        Some(h) => {
            let why = if h.split(',').all(|c| c != FINGERPRINT_COLUMN) {
                "it was written without the fingerprints of its runs' inputs (by fretdyn before 0.1.0 of 2026-11-28), so its rows cannot be tied to this study"
            } else {
                "its columns are those of another study"
            };
            return Err(Error::invalid(
                "table",
                format!(
                    "{} has another header: {why}; start afresh with --fresh (Python: fresh=True; the table is replaced), or write to another table (-o DIR)",
                    table.display()
                ),
            ));
        }
    }
    let columns = header.split(',').count();
    let parameters = header
        .split(',')
        .position(|c| c == "seed")
        .map_or(0, |seed| seed.saturating_sub(1));
    let complete = if text.ends_with('\n') {
        text.lines().count()
    } else {
        text.lines().count().saturating_sub(1)
    };
    Ok(lines
        .take(complete.saturating_sub(1))
        .filter_map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            if cells.len() != columns {
                return None;
            }
            Some(TableRow {
                index: cells[0].parse().ok()?,
                values: cells[1..1 + parameters]
                    .iter()
                    .map(|c| c.to_string())
                    .collect(),
                fingerprint: cells[columns - 1].to_string(),
            })
        })
        .collect())
}
