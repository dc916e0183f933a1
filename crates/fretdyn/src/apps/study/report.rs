//! What a study's table reports: the percentiles of `[percentiles]` across the draws
//! ([`percentiles`](crate::apps::percentiles)) and the runs whose case is above its Connors
//! critical velocity.

use std::path::Path;

use super::file::Study;
use super::table::CONNORS_COLUMN;
use crate::apps::percentiles::{PercentileReport, PercentileRequest, percentiles_of_table};
use crate::error::{Error, Result};

impl Study {
    /// The percentiles of `[percentiles]` (module [`percentiles`](crate::apps::percentiles)) from
    /// the table at `table`, grouped by the values of the `values` parameters; `None` when the
    /// study asks for none. The table must hold every run of the study, each from the inputs
    /// the study gives it now ([`Self::check_table_complete`]): an incomplete or stale table is
    /// refused.
    pub fn percentiles(&self, table: &Path) -> Result<Option<PercentileReport>> {
        let Some(spec) = &self.percentiles else {
            return Ok(None);
        };
        self.check_table_complete(table)?;
        let header = self.header(&self.contact_names());
        let names: Vec<&str> = header.split(',').collect();
        let columns = spec
            .statistics
            .iter()
            .flat_map(|s| self.percentile_columns(s, &names))
            .collect();
        let group_by = self
            .columns()
            .iter()
            .filter(|c| self.parameters[c.parameter].distribution.is_none())
            .map(|c| c.key.clone())
            .collect();
        let request = PercentileRequest {
            columns,
            levels: spec.levels.clone(),
            group_by,
            confidence: spec.confidence,
            bootstrap: spec.bootstrap,
            seed: self.sampling.as_ref().map_or(0, |s| s.seed),
        };
        percentiles_of_table(table, &request).map(Some)
    }
}

/// The percentiles of the study file at `study` from the table at `table` (a table written by
/// `fretdyn sweep`, or by `fretdyn.sweep` on a Dask cluster): [`Study::percentiles`].
pub fn percentiles_from_table(study: &Path, table: &Path) -> Result<Option<PercentileReport>> {
    Study::from_file(study)?.percentiles(table)
}

/// The runs of a study table whose case has a mode above its Connors critical velocity.
#[derive(Debug, Clone, PartialEq)]
pub struct ConnorsExceedance {
    /// Runs with `connors_max_ratio > 1`.
    pub runs: usize,
    /// Runs in the table.
    pub of: usize,
    /// The largest ratio, and the index of its run.
    pub largest: (f64, usize),
}

/// Reads the [`CONNORS_COLUMN`] of a study table (complete rows only): `None` when no run
/// has a ratio above 1 (or the table has no such column).
pub fn connors_exceedance(table: &Path) -> Result<Option<ConnorsExceedance>> {
    let text = std::fs::read_to_string(table).map_err(|e| Error::io(table, e))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let Some(col) = header.iter().position(|h| *h == CONNORS_COLUMN) else {
        return Ok(None);
    };
    let rows: Vec<Vec<&str>> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|r| r.len() == header.len())
        .collect();
    let mut found: Option<ConnorsExceedance> = None;
    for r in &rows {
        let (Ok(ratio), Ok(run)) = (r[col].parse::<f64>(), r[0].parse::<usize>()) else {
            continue;
        };
        if ratio > 1.0 {
            let f = found.get_or_insert(ConnorsExceedance {
                runs: 0,
                of: rows.len(),
                largest: (ratio, run),
            });
            f.runs += 1;
            if ratio > f.largest.0 {
                f.largest = (ratio, run);
            }
        }
    }
    Ok(found)
}
