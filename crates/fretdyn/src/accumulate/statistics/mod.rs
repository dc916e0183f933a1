//! Statistics accumulated at every step (not only at output samples), THEORY §5: per-contact
//! wear, impact and force statistics over a time window `[t_start, t_end]` and in blocks
//! (batches, from which the standard errors of the window's rates are estimated by batch
//! means), and the table of impacts.
//!
//! A step `(t − Δt, t]` counts in the window (and in a block) when its midpoint `t − Δt/2` is
//! in it, so that bounds that are multiples of Δt split the steps exactly despite round-off. An **impact** starts when the contact closes after being open longer than the rest
//! duration, and ends at the last opening before such a rest: openings shorter than the rest
//! duration are **rebounds** within the impact. Its start and end times are interpolated
//! linearly between steps on the penetration's zero crossing; it belongs to the window when
//! the step in which it starts does (the same midpoint rule, not the interpolated start time:
//! an impact that starts on the window's first step, e.g. a contact closed from `t_start`
//! exactly, is counted once and has its row, its duration and its peak in the histogram like
//! any other). An impact under way when the window opens — a contact closed at the start of
//! the window's first step, a preload at t = 0 or the middle of an impact — starts there
//! ([`ContactStatisticsState::open_window`]). An impact still going on when the run ends is
//! ended there.
//!
//! The window, the blocks, the impacts and the peak histogram are accumulated from the same
//! step values by one midpoint rule, in one state per contact ([`state`]; the energy balance
//! is apart, in [`crate::accumulate::energy`]). One concept per file, lower ones first:
//! [`step`] (a contact's values over a step), [`impacts`] (an impact and its tracker),
//! [`report`] (what is reported: [`ContactStatistics`], [`StandardErrors`]), [`columns`]
//! (the one table of the statistics, from which the files' columns are derived),
//! [`accumulator`] (the running sums and the peak histogram), [`batch_means`] (the
//! standard errors) and [`state`] (all of them for the contacts of a run). This file only
//! declares them and re-exports their items.

pub mod accumulator;
pub mod batch_means;
pub mod columns;
pub mod impacts;
pub mod report;
pub mod state;
pub mod step;

pub use accumulator::{ContactAccumulator, PEAK_BINS_PER_DECADE};
pub use batch_means::{MIN_TARGET_BATCHES, TARGET_WEAR_SHARE};
pub use columns::{
    BATCHED, BATCHED_STATISTICS, Batched, Kind, STATISTICS, STUDY, STUDY_STATISTICS, Statistic,
    Value, batched_statistics, block_columns, statistic,
};
pub use impacts::Impact;
pub use report::{BlockStatistics, ContactStatistics, PeakBin, StandardErrors};
pub use state::{ContactStatisticsState, name_blocks};
pub use step::{ContactStep, StepValues};

pub use crate::settings::statistics::{
    DEFAULT_BATCHES, DEFAULT_MAX_RELATIVE_ERROR, DEFAULT_TARGET_BATCHES, StatisticsSettings,
};
