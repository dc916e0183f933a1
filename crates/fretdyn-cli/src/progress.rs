//! A progress bar on stderr, shown only for runs that last more than a second.

use std::ops::ControlFlow;
use std::time::{Duration, Instant};

use fretdyn::integrator::simulation::Progress;
use indicatif::{ProgressBar, ProgressStyle};

/// Observer for [`fretdyn::integrator::simulation::run`] that shows a bar after `delay`.
pub struct Bar {
    start: Instant,
    delay: Duration,
    bar: Option<ProgressBar>,
    enabled: bool,
    label: String,
}

impl Bar {
    /// A bar labelled `label`; `enabled = false` never draws.
    pub fn new(label: &str, enabled: bool) -> Self {
        Self {
            start: Instant::now(),
            delay: Duration::from_secs(1),
            bar: None,
            enabled,
            label: label.to_string(),
        }
    }

    /// The observer callback.
    pub fn observe(&mut self, p: Progress) -> ControlFlow<()> {
        if !self.enabled {
            return ControlFlow::Continue(());
        }
        let elapsed = self.start.elapsed();
        if self.bar.is_none() && elapsed >= self.delay && p.step < p.total {
            let bar = ProgressBar::new(p.total);
            bar.set_style(
                ProgressStyle::with_template("{prefix} [{bar:40}] {pos}/{len} steps, {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> "),
            );
            bar.set_prefix(self.label.clone());
            self.bar = Some(bar);
        }
        if let Some(bar) = &self.bar {
            // Rate and remaining time from the run's own clock: the bar starts late, so its
            // own estimator would see the first jump as instantaneous.
            let rate = p.step as f64 / elapsed.as_secs_f64().max(1e-9);
            let eta = (p.total - p.step) as f64 / rate.max(1e-9);
            bar.set_position(p.step);
            bar.set_message(format!("{rate:.3e} steps/s, {eta:.0} s left"));
            if p.step >= p.total {
                bar.finish_and_clear();
            }
        }
        ControlFlow::Continue(())
    }

    /// Clears the bar.
    pub fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}
