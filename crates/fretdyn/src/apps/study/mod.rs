//! Parametric and Monte-Carlo studies: a base case, parameters to vary (as a grid or a list)
//! and seeds; every run independent, run in parallel on the cores of the machine (rayon),
//! one row per finished run appended to a CSV table, so that a study killed midway keeps its
//! finished rows and, run again, skips them.
//!
//! A study file (`examples/study_clearance.toml`):
//!
//! ```toml
//! base = "tube_multispan.toml"       # the case, relative to the study file
//! combine = "grid"                   # every combination ("grid") or row by row ("list")
//! seeds = [1, 2]                     # optional: each run once per seed (turbulence[*].seed)
//!
//! [[parameters]]
//! key = "contacts.*.obstacle.clearance"   # dotted path in the case; * = every element
//! values = [1e-4, 2e-4]
//!
//! [plot]                             # optional: what `fretdyn sweep` plots
//! x = "contacts.*.obstacle.clearance"
//! statistic = "wear_work_rate"
//! ```
//!
//! A probabilistic study draws parameters from distributions
//! ([`sampling`](crate::apps::sampling), `docs/STUDIES.md`):
//!
//! ```toml
//! base = "tube_multispan.toml"
//! samples = 200                      # draws; every grid point gets all of them
//! seed = 1                           # the draws depend on (seed, sample, parameter) only
//!
//! [[parameters]]
//! key = "contacts.*.obstacle.clearance"
//! independent = true                 # one draw per contact, a column each
//! distribution = { type = "uniform", low = 1e-4, high = 3e-4 }
//!
//! [percentiles]                      # optional: P50, P95, P99 and their errors
//! statistics = ["wear_work_rate"]
//! ```
//!
//! The runs are: every combination of the `values` parameters (grid or list) × every sample ×
//! every seed, in that order; percentiles ([`percentiles`](crate::apps::percentiles)) pool the
//! samples and seeds of a combination.
//!
//! Files, lowest first: `table` the columns and rows of `study.csv`; `file` the study file
//! read and checked; `runs` the list of runs, each run's case and its row; `execute` the
//! pending runs into the table (checked, locked, continued, in parallel); `report` the
//! percentiles and the Connors check of a finished table.

mod execute;
mod file;
mod report;
mod runs;
mod table;

pub use execute::{StudyOptions, StudyOutcome, StudyTable, record_path};
pub use file::{
    Column, Combine, DEFAULT_PERCENTILE_STATISTIC, MAX_BOOTSTRAP, MAX_SAMPLES, Parameter,
    PercentileSpec, PlotSpec, Sampling, Study,
};
pub use report::{ConnorsExceedance, connors_exceedance, percentiles_from_table};
pub use runs::{RunSpec, run_statistics};
pub use table::{CONNORS_COLUMN, FINGERPRINT_COLUMN, LIFE_COLUMNS, TABLE_STATISTICS, table_errors};
