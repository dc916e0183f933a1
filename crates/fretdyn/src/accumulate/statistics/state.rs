//! The statistics of the contacts of a run (THEORY §5): [`ContactStatisticsState`], what the
//! step writes, in blocks (batches) and over the window, with its impacts; a checkpoint holds
//! it as is.
//!
//! Its step and the tests of the whole (window, blocks, impacts, errors, restore) are here.

use serde::{Deserialize, Serialize};

use super::accumulator::ContactAccumulator;
use super::batch_means::{BatchMoments, MIN_TARGET_BATCHES, TARGET_WEAR_SHARE, WEAR_WORK_RATE};
use super::impacts::{Impact, ImpactTracker};
use super::report::{BlockStatistics, ContactStatistics};
use super::step::{ContactStep, StepValues};
use crate::settings::statistics::StatisticsSettings;

/// Finished impacts kept per contact before the vector must grow.
const IMPACT_ROOM_PER_CONTACT: usize = 256;

/// Everything the statistics keep for the contacts of a run: block and window accumulators,
/// batch means, impact trackers; finished impacts and blocks wait in [`Self::impacts`] and
/// [`Self::blocks`] until drained by the caller (a streaming run drains them at each flush,
/// so that memory stays flat).
///
/// The window is always cut into blocks (batches, THEORY §5): of `[statistics] block` s, or
/// else [`DEFAULT_BATCHES`](super::DEFAULT_BATCHES) of the window ([`DEFAULT_TARGET_BATCHES`](super::DEFAULT_TARGET_BATCHES) of the longest window
/// with a target relative error). A step is added to the block's sums only; when the block
/// closes (at the step whose successor's midpoint is in the next block), its sums are added
/// to the window's, its batch means to the batch moments and its row to [`Self::blocks`]
/// (room reserved beforehand: closing a block does not allocate).
///
/// Cost per step: an open contact with no impact in progress adds its offset and penetration
/// to the block and keeps its penetration for the next crossing; the steps are counted once
/// for all contacts, and one comparison of `t` tells whether the block may close (its index is
/// computed only in the last two steps of a block).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactStatisticsState {
    /// Duration of a block, s (`∞`: one block, the window).
    block_length: f64,
    /// Relative standard error at which the run stops.
    target: Option<f64>,
    window: Vec<ContactAccumulator>,
    /// Steps in the closed blocks (the same for every contact).
    window_steps: u64,
    /// The block in progress, one per contact.
    block: Vec<ContactAccumulator>,
    /// Steps in the current block so far.
    block_steps: u64,
    block_index: u64,
    /// No step ending before this closes the current block (so that the block of the next
    /// step is only computed near the block's end).
    close_from: f64,
    batches: Vec<BatchMoments>,
    /// End of the step at which the target relative error was met.
    target_met: Option<f64>,
    trackers: Vec<ImpactTracker>,
    /// Finished impacts started in the window, not yet drained.
    pub impacts: Vec<Impact>,
    /// Finished blocks, block by block, contact by contact, not yet drained; their names are
    /// empty (the contact is [`BlockStatistics::contact`]) until [`name_blocks`].
    pub blocks: Vec<BlockStatistics>,
}

/// Gives the rows of `blocks` the names of their contacts (a row is formed in the step loop
/// without its name, which would allocate).
pub fn name_blocks(blocks: &mut [BlockStatistics], names: &[String]) {
    for b in blocks {
        if let Some(name) = names.get(b.contact) {
            b.statistics.name.clone_from(name);
        }
    }
}

/// Most block rows reserved before the run (beyond, a streamed run's drain makes room).
const BLOCK_ROOM: u64 = 4096;

impl ContactStatisticsState {
    /// Empty statistics for `contacts` contacts, for a run of `steps` steps of `dt`.
    pub fn new(contacts: usize, settings: &StatisticsSettings, steps: u64, dt: f64) -> Self {
        let block_length = settings.block_length(steps, dt);
        let blocks = (settings.window_steps(steps, dt) as f64 * dt / block_length).ceil();
        let rows = (blocks.min(BLOCK_ROOM as f64) as usize + 2) * contacts;
        let mut state = Self {
            block_length,
            target: settings.target_relative_error,
            window: vec![ContactAccumulator::new(); contacts],
            window_steps: 0,
            block: vec![ContactAccumulator::new(); contacts],
            block_steps: 0,
            block_index: 0,
            batches: vec![BatchMoments::default(); contacts],
            target_met: None,
            trackers: vec![ImpactTracker::default(); contacts],
            // room for the impacts that end between two drains: the step loop does not
            // allocate unless more wait (then the room grows once and is kept)
            impacts: Vec::with_capacity(IMPACT_ROOM_PER_CONTACT * contacts),
            blocks: Vec::with_capacity(rows),
            close_from: 0.0,
        };
        state.close_from = state.close_from_for(settings, dt);
        state
    }

    /// Two steps before the end of the current block (round-off cannot close it sooner).
    fn close_from_for(&self, settings: &StatisticsSettings, dt: f64) -> f64 {
        settings.t_start + (self.block_index + 1) as f64 * self.block_length - 2.0 * dt
    }

    /// True when it follows `n` contacts.
    pub fn has_contacts(&self, n: usize) -> bool {
        self.window.len() == n
            && self.block.len() == n
            && self.batches.len() == n
            && self.trackers.len() == n
    }

    /// Duration of a block (batch), s.
    pub fn block_length(&self) -> f64 {
        self.block_length
    }

    /// End time of the step at which the target relative error was met, if it was.
    pub fn target_met(&self) -> Option<f64> {
        self.target_met
    }

    /// Starts the trackers at t = 0 with the contacts' penetrations.
    pub fn start(&mut self, penetrations: impl Iterator<Item = (f64, bool)>) {
        for (tr, (d, closed)) in self.trackers.iter_mut().zip(penetrations) {
            tr.previous_penetration = d;
            tr.previous_t = 0.0;
            // a contact closed at t = 0 is in an impact that started before the run
            tr.active = closed;
        }
    }

    /// Opens the window at `t`, the end of the last step before it (the start of its first
    /// step: `t_start` to within `Δt/2`, exactly when `t_start` is a multiple of `Δt`).
    /// An impact under way there — its contact closed at `t`, from an impact that started
    /// before the window, or closed at t = 0 — **starts at `t`** (THEORY §11): it is counted
    /// in the window, and its row has its start `t`, its duration, contact time, impulse,
    /// peak and rebounds from `t` on, and as impact speed `speeds[k]`, the contact's normal
    /// approach speed at `t`. One in a rebound opening at `t` ends there, out of the window:
    /// its closing within the rest duration, if any, starts an impact in the window.
    /// Called once, at `t` (by the time loop; at t = 0 after [`Self::start`]).
    pub fn open_window(&mut self, t: f64, speeds: impl Iterator<Item = f64>) {
        for (k, ((tracker, block), speed)) in self
            .trackers
            .iter_mut()
            .zip(&mut self.block)
            .zip(speeds)
            .enumerate()
        {
            if !tracker.active {
                continue;
            }
            if tracker.open {
                tracker.active = false;
                tracker.open = false;
                tracker.current = None;
                continue;
            }
            tracker.current = Some(Impact {
                contact: k,
                start: t,
                duration: 0.0,
                contact_time: 0.0,
                peak_time: t,
                peak_force: 0.0,
                impulse: 0.0,
                impact_speed: speed,
                rebound_speed: 0.0,
                rebounds: 0,
                angle_deg: 0.0,
            });
            tracker.peak_direction = [1.0, 0.0];
            tracker.in_window = true;
            block.impacts += 1;
        }
    }

    /// Adds one step: `values[k]` for contact k, the step ending at `t`.
    #[inline]
    pub fn step(
        &mut self,
        settings: &StatisticsSettings,
        t: f64,
        dt: f64,
        values: impl Iterator<Item = ContactStep>,
    ) {
        let in_window = settings.step_in_window(t, dt);
        self.block_steps += in_window as u64;
        let rest = settings.rest_duration;
        let Self {
            block,
            trackers,
            impacts,
            ..
        } = self;
        for (k, ((input, tracker), block)) in values.zip(trackers.iter_mut()).zip(block).enumerate()
        {
            // the sums and the impacts' counts are apart: their order does not matter
            match input {
                ContactStep::Open {
                    radial,
                    penetration,
                } => {
                    if in_window {
                        block.add_offset(radial, penetration);
                    }
                    if tracker.active {
                        let v = StepValues::open(t, radial, penetration);
                        impact_step(k, v, rest, in_window, tracker, block, impacts);
                    } else {
                        tracker.idle(t, penetration);
                    }
                }
                ContactStep::Closed(v) => {
                    if in_window {
                        block.add_step(&v, dt);
                    }
                    impact_step(k, v, rest, in_window, tracker, block, impacts);
                }
            }
        }
        if in_window && t >= self.close_from {
            // the block closes when the next step's midpoint is in a later one
            let next = settings.block_of(t + dt, dt, self.block_length);
            if next > self.block_index {
                self.close_block(settings, dt, true, t);
                self.block_index = next;
                self.close_from = self.close_from_for(settings, dt);
            }
        }
    }

    /// Closes the block in progress: its row, its batch means when `whole`, its sums into
    /// the window's; at the end of a whole block (`t`), the target is checked.
    fn close_block(&mut self, settings: &StatisticsSettings, dt: f64, whole: bool, t: f64) {
        let b = self.block_length;
        let t0 = settings.t_start + self.block_index as f64 * b;
        let t1 = if whole {
            t0 + b
        } else {
            t0 + self.block_steps as f64 * dt
        };
        let steps = self.block_steps;
        for (k, ((acc, window), batches)) in self
            .block
            .iter_mut()
            .zip(&mut self.window)
            .zip(&mut self.batches)
            .enumerate()
        {
            self.blocks.push(BlockStatistics {
                block: self.block_index,
                contact: k,
                t_start: t0,
                t_end: t1,
                statistics: acc.statistics(steps, dt, settings.wear_coefficient),
            });
            if whole {
                batches.add(&acc.batch_values(steps, dt));
            }
            window.merge(acc);
            acc.reset();
        }
        self.window_steps += steps;
        self.block_steps = 0;
        if whole
            && t.is_finite()
            && self.target_met.is_none()
            && let Some(target) = self.target
            && self.target_reached(target)
        {
            self.target_met = Some(t);
        }
    }

    /// Every contact that wears (its wear work rate at least [`TARGET_WEAR_SHARE`] of the
    /// largest) has a relative standard error of its wear work rate `SE/x̄ ≤ target`, over
    /// at least [`MIN_TARGET_BATCHES`] batches.
    fn target_reached(&self, target: f64) -> bool {
        let mut largest = 0.0f64;
        for m in &self.batches {
            if m.n < MIN_TARGET_BATCHES {
                return false;
            }
            largest = largest.max(m.moments(WEAR_WORK_RATE).0);
        }
        largest > 0.0
            && self.batches.iter().all(|m| {
                let mean = m.moments(WEAR_WORK_RATE).0;
                mean < TARGET_WEAR_SHARE * largest
                    || m.se(WEAR_WORK_RATE).is_some_and(|se| se <= target * mean)
            })
    }

    /// Window statistics of every contact. An impact still in progress ends with the run (at
    /// its last opening, or at the last step if closed); a last block that has steps is
    /// closed (a partial one, shorter than a block by more than a step, has its row but is
    /// not a batch).
    pub fn finish(
        &mut self,
        settings: &StatisticsSettings,
        names: &[String],
        dt: f64,
    ) -> Vec<ContactStatistics> {
        for (k, tr) in self.trackers.iter_mut().enumerate() {
            if let Some(mut imp) = tr.end() {
                let end = if tr.open {
                    tr.last_opening
                } else {
                    tr.previous_t
                };
                imp.duration = end - imp.start;
                tr.active = false;
                if tr.in_window {
                    self.block[k].add_impact(&imp);
                    self.impacts.push(imp);
                }
            }
        }
        if self.block_steps > 0 {
            let whole = self.block_steps as f64 + 1.0 >= self.block_length / dt;
            let t = f64::NAN;
            self.close_block(settings, dt, whole, t);
        } else {
            // impacts that ended after the window's last block
            for (window, acc) in self.window.iter_mut().zip(&mut self.block) {
                window.merge(acc);
                acc.reset();
            }
        }
        self.window
            .iter()
            .zip(&self.batches)
            .zip(names)
            .map(|((a, batches), name)| {
                let mut s = a.finish(self.window_steps, name, dt, settings.wear_coefficient);
                s.errors = batches.errors(&s, self.block_length);
                s
            })
            .collect()
    }
}

/// The step of contact `k` when it is closed or in an impact (its tracker active): the
/// tracker's step, then an impact that starts in a step of the window counts in the block,
/// and one that ends, having started in the window, is added to it and to the table.
#[inline(always)]
fn impact_step(
    k: usize,
    v: StepValues,
    rest: f64,
    in_window: bool,
    tracker: &mut ImpactTracker,
    block: &mut ContactAccumulator,
    impacts: &mut Vec<Impact>,
) {
    let (started, finished) = tracker.step(k, &v, rest, in_window);
    if in_window && started {
        block.impacts += 1;
    }
    if let Some(imp) = finished
        && tracker.in_window
    {
        block.add_impact(&imp);
        impacts.push(imp);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 1e-3;
    const STEPS: u64 = 1000;

    /// Values of contact `k` at the end of step `n`: a penetration that oscillates through
    /// zero at a few frequencies (impacts, rebounds and long openings), forces of a closed
    /// contact only, an offset of both signs, and the first contact open all along.
    fn values(k: usize, n: u64) -> StepValues {
        let t = n as f64 * DT;
        let phase = k as f64;
        let penetration = if k == 0 {
            -1e-3 - 1e-4 * (7.0 * t).sin()
        } else {
            1e-4 * ((40.0 + 13.0 * phase) * t + phase).sin() - 4e-5 * (170.0 * t).cos()
        };
        let closed = penetration > 0.0;
        let normal = if closed { 1e6 * penetration } else { 0.0 };
        let angle = 3.0 * t + phase;
        StepValues {
            t,
            closed,
            stick: closed && (90.0 * t).sin() > 0.0,
            normal,
            tangential: 0.3 * normal,
            slip_speed: if closed { 1e-3 * (1.0 + t) } else { 0.0 },
            friction_power: if closed { 0.3 * normal * 1e-3 } else { 0.0 },
            penetration,
            radial: 2e-4 * (11.0 * t + phase).sin() + penetration,
            direction: [angle.cos(), angle.sin()],
        }
    }

    const CONTACTS: usize = 3;

    fn names() -> Vec<String> {
        (0..CONTACTS).map(|k| format!("c{k}")).collect()
    }

    /// Steps `from + 1 ..= to` of the synthetic run.
    fn advance(
        state: &mut ContactStatisticsState,
        settings: &StatisticsSettings,
        from: u64,
        to: u64,
    ) {
        for n in from + 1..=to {
            let t = n as f64 * DT;
            state.step(settings, t, DT, (0..CONTACTS).map(|k| values(k, n).into()));
        }
    }

    fn started(settings: &StatisticsSettings) -> ContactStatisticsState {
        let mut state = ContactStatisticsState::new(CONTACTS, settings, STEPS, DT);
        state.start((0..CONTACTS).map(|k| {
            let v = values(k, 0);
            (v.penetration, v.closed)
        }));
        state
    }

    /// Window statistics, impacts and blocks of the whole synthetic run.
    fn run(
        settings: &StatisticsSettings,
    ) -> (Vec<ContactStatistics>, Vec<Impact>, Vec<BlockStatistics>) {
        let mut state = started(settings);
        advance(&mut state, settings, 0, STEPS);
        let window = state.finish(settings, &names(), DT);
        (window, state.impacts, state.blocks)
    }

    fn settings(block: Option<f64>) -> StatisticsSettings {
        StatisticsSettings {
            t_start: 0.1,
            t_end: 0.85,
            block,
            rest_duration: 2e-3,
            wear_coefficient: 1e-15,
            ..Default::default()
        }
    }

    /// The window's statistics do not depend on how it is cut into blocks: counts and
    /// extrema exactly, the sums to round-off (a window sum is a sum of block sums), against
    /// sums formed here step by step from the values; the impacts are the same.
    #[test]
    fn blocks_do_not_change_the_window() {
        let s = settings(None);
        let (window, impacts, blocks) = run(&s);
        assert_eq!(
            blocks.len(),
            20 * CONTACTS,
            "20 batches of the window by default"
        );
        for b in [Some(0.07), Some(0.013), Some(1.0)] {
            let (window_b, impacts_b, _) = run(&settings(b));
            assert_eq!(impacts, impacts_b);
            for (w, wb) in window.iter().zip(&window_b) {
                assert_eq!(
                    (w.impacts, w.contact_time_fraction, w.stick_time_fraction),
                    (wb.impacts, wb.contact_time_fraction, wb.stick_time_fraction)
                );
                assert_eq!(
                    (w.normal_force_max, w.displacement_min, w.displacement_max),
                    (
                        wb.normal_force_max,
                        wb.displacement_min,
                        wb.displacement_max
                    )
                );
                assert_eq!(w.peak_force_histogram, wb.peak_force_histogram);
            }
        }
        for (k, w) in window.iter().enumerate() {
            let steps: Vec<_> = (1..=STEPS)
                .filter(|&n| s.step_in_window(n as f64 * DT, DT))
                .map(|n| values(k, n))
                .collect();
            let n = steps.len() as f64;
            let sum = |f: fn(&StepValues) -> f64| steps.iter().map(f).sum::<f64>();
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * b.abs().max(1e-300);
            let closed =
                |f: fn(&StepValues) -> f64| steps.iter().filter(|v| v.closed).map(f).sum::<f64>();
            assert!(close(w.normal_force_mean, closed(|v| v.normal) / n));
            assert!(close(
                w.normal_force_rms,
                (closed(|v| v.normal * v.normal) / n).sqrt()
            ));
            assert!(close(
                w.wear_work_rate,
                closed(|v| v.friction_power) * DT / (n * DT)
            ));
            assert!(close(w.displacement_mean, sum(|v| v.radial) / n));
            assert!(k == 0 || w.normal_force_mean > 0.0);
        }
        let state = ContactStatisticsState::new(CONTACTS, &settings(None), STEPS, DT);
        assert_eq!(state.block.len(), CONTACTS);
        assert!(state.has_contacts(CONTACTS) && !state.has_contacts(CONTACTS + 1));
        assert!((state.block_length() - 0.75 / 20.0).abs() < 1e-15);
    }

    /// The standard errors and the lag-1 autocorrelation formed from running shifted sums
    /// are those of the block rows formed directly (two-pass).
    #[test]
    fn errors_are_those_of_the_block_means() {
        for b in [None, Some(0.07), Some(0.013)] {
            let (window, _, blocks) = run(&settings(b));
            for (k, w) in window.iter().enumerate().skip(1) {
                // whole blocks only: the last 0.07-s block of the 0.75-s window is partial
                let length = blocks[0].t_end - blocks[0].t_start;
                let rows: Vec<_> = blocks
                    .iter()
                    .filter(|r| r.contact == k && r.t_end - r.t_start > length - 1.5 * DT)
                    .map(|r| &r.statistics)
                    .collect();
                assert_eq!(w.errors.batches, rows.len() as u64);
                let n = rows.len() as f64;
                let x: Vec<f64> = rows.iter().map(|r| r.wear_work_rate).collect();
                let m = x.iter().sum::<f64>() / n;
                let ss = x.iter().map(|x| (x - m).powi(2)).sum::<f64>();
                let se = (ss / (n * (n - 1.0))).sqrt();
                let r1 = x.windows(2).map(|p| (p[0] - m) * (p[1] - m)).sum::<f64>() / ss;
                let got = w.errors.wear_work_rate_se.unwrap();
                assert!((got - se).abs() <= 1e-9 * se, "{got} {se}");
                let r = w.errors.batch_autocorrelation.unwrap();
                assert!((r - r1).abs() <= 1e-9, "{r} {r1}");
                assert_eq!(w.errors.batches_correlated, r1 > 2.0 / n.sqrt());
                // the rms through the mean square: SE(rms) = SE(ms)/(2 rms)
                let ms: Vec<f64> = rows.iter().map(|r| r.normal_force_rms.powi(2)).collect();
                let mm = ms.iter().sum::<f64>() / n;
                let se_ms =
                    (ms.iter().map(|x| (x - mm).powi(2)).sum::<f64>() / (n * (n - 1.0))).sqrt();
                let got = w.errors.normal_force_rms_se.unwrap();
                let expected = se_ms / (2.0 * w.normal_force_rms);
                assert!((got - expected).abs() <= 1e-9 * expected);
            }
        }
    }

    /// The blocks add up to the window: their steps, their impacts started; their extrema
    /// are the window's.
    #[test]
    fn blocks_add_up_to_the_window() {
        let (window, _, blocks) = run(&settings(Some(0.07)));
        for (k, w) in window.iter().enumerate() {
            let rows: Vec<_> = blocks
                .iter()
                .filter(|b| b.contact == k)
                .map(|b| &b.statistics)
                .collect();
            assert_eq!(rows.len(), 11, "contact {k}: 0.75 s in blocks of 0.07 s");
            let steps = |d: f64| (d / DT).round() as u64;
            assert_eq!(
                rows.iter().map(|s| steps(s.duration)).sum::<u64>(),
                steps(w.duration)
            );
            assert_eq!(rows.iter().map(|s| s.impacts).sum::<u64>(), w.impacts);
            let fold = |f: fn(&ContactStatistics) -> f64, max: bool| {
                rows.iter().map(|s| f(s)).fold(
                    if max {
                        f64::NEG_INFINITY
                    } else {
                        f64::INFINITY
                    },
                    if max { f64::max } else { f64::min },
                )
            };
            assert_eq!(fold(|s| s.displacement_max, true), w.displacement_max);
            assert_eq!(fold(|s| s.displacement_min, false), w.displacement_min);
            assert_eq!(fold(|s| s.penetration_max, true), w.penetration_max);
            assert_eq!(fold(|s| s.normal_force_max, true), w.normal_force_max);
        }
    }

    /// An impact's peak is its largest normal force over its closed steps, and its angle the
    /// direction's at that step (formed when the impact ends), for every impact of the run,
    /// those ended by the run's end included.
    #[test]
    fn an_impact_peaks_at_its_largest_force_with_the_angle_of_that_step() {
        let s = settings(None);
        let (_, impacts, _) = run(&s);
        assert!(impacts.len() > 10, "{} impacts", impacts.len());
        for imp in &impacts {
            let first = ((imp.start / DT).ceil() as u64).max(1);
            let last = ((imp.start + imp.duration) / DT).floor() as u64;
            let peak = (first..=last.min(STEPS))
                .map(|n| values(imp.contact, n))
                .filter(|v| v.closed)
                .reduce(|a, b| if b.normal > a.normal { b } else { a })
                .expect("an impact has a closed step");
            assert_eq!(imp.peak_force, peak.normal);
            assert_eq!(imp.peak_time, peak.t);
            let expected = peak.direction[1].atan2(peak.direction[0]).to_degrees();
            assert_eq!(imp.angle_deg.to_bits(), expected.to_bits(), "{imp:?}");
        }
    }

    /// The window's extrema are those of the values of its steps (by the midpoint rule), and
    /// 0 for a window with no step.
    #[test]
    fn extrema_are_those_of_the_window_steps() {
        let s = settings(None);
        let (window, _, _) = run(&s);
        for (k, w) in window.iter().enumerate() {
            let steps: Vec<_> = (1..=STEPS)
                .filter(|&n| s.step_in_window(n as f64 * DT, DT))
                .map(|n| values(k, n))
                .collect();
            assert_eq!(steps.len(), 750);
            assert_eq!(w.duration, steps.len() as f64 * DT);
            let min = steps.iter().map(|v| v.radial).reduce(f64::min).unwrap();
            let max = steps.iter().map(|v| v.radial).reduce(f64::max).unwrap();
            let pen = steps
                .iter()
                .map(|v| v.penetration)
                .reduce(f64::max)
                .unwrap();
            assert_eq!((w.displacement_min, w.displacement_max), (min, max));
            assert_eq!(w.penetration_max, pen);
            assert!(k > 0 || pen < 0.0, "the first contact stays open");
        }
        let late = StatisticsSettings {
            t_start: 2.0 * STEPS as f64 * DT,
            ..settings(Some(0.07))
        };
        let (window, impacts, blocks) = run(&late);
        assert!(impacts.is_empty() && blocks.is_empty());
        for w in &window {
            assert_eq!((w.duration, w.impacts), (0.0, 0));
            assert_eq!(
                (w.displacement_min, w.displacement_max, w.penetration_max),
                (0.0, 0.0, 0.0)
            );
        }
    }

    /// A state saved (as a checkpoint saves it) and restored mid-run, even mid-block, ends
    /// with the results of the uninterrupted run.
    #[test]
    fn a_restored_state_gives_the_uninterrupted_results() {
        for block in [None, Some(0.07)] {
            let s = settings(block);
            let (window, impacts, blocks) = run(&s);
            let mut state = started(&s);
            let mut drained = (Vec::new(), Vec::new());
            for (from, to) in [(0, 137), (137, 512), (512, STEPS)] {
                advance(&mut state, &s, from, to);
                drained.0.append(&mut state.impacts);
                drained.1.append(&mut state.blocks);
                let mut bytes = Vec::new();
                ciborium::into_writer(&state, &mut bytes).unwrap();
                state = ciborium::from_reader(bytes.as_slice()).unwrap();
            }
            let window_r = state.finish(&s, &names(), DT);
            drained.0.append(&mut state.impacts);
            drained.1.append(&mut state.blocks);
            assert_eq!(window_r, window);
            assert_eq!(drained, (impacts, blocks));
        }
    }
}
