//! Standard errors by batch means (THEORY §5): checked against the spread of independent
//! runs, the correlated-batch flag, the run that stops at a target relative error (in memory
//! and streamed, resumed), and the refusal of bad settings.
//!
//! The case: a 1 m cantilevered tube (4 modes, damping ratio 0.1, first mode ≈ 18 Hz)
//! rattling in a drilled hole at its tip (0.2 mm clearance, μ = 0.3) under band-limited
//! white-noise turbulence (flat PSD to 200 Hz). Its correlation time is about
//! `1/(ζ ω₁) ≈ 0.09 s` (less with the impacts' dissipation): batches of 0.5 s are more than 5
//! correlation times long, so that their means are nearly independent, and runs with other
//! seeds are independent realisations of the same stationary process.

use std::ops::ControlFlow;
use std::path::Path;

use fretdyn::accumulate::statistics::ContactStatistics;
use fretdyn::case::Case;
use fretdyn::integrator::simulation::{Termination, simulate};
use fretdyn::output::stream::{self, ProgressOnly, StreamSettings};

const CASE: &str = concat!(
    r#"
title = "Tube tip rattling in a hole under white-noise turbulence"
[time]
dt = 1e-4
duration = 10.5
"#,
    include_str!("fixtures/sg_tube.toml"),
    r#"path = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
mesh_size = 0.05
modes = 4
damping_ratio = DAMPING
[[structure.supports]]
at = [0.0, 0.0, 0.0]
type = "clamped"
[[structure.points]]
name = "tip"
at = [1.0, 0.0, 0.0]
[[contacts]]
name = "ring"
point = "tip"
radius = 9.525e-3
obstacle = { type = "circle", centre = [1.0, 0.0, 0.0], axis = [1.0, 0.0, 0.0], clearance = 2e-4 }
normal = { stiffness = 1e6 }
friction = { mu = 0.3 }
[[turbulence]]
directions = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
correlation_length = 0.25
seed = SEED
f_max = 200.0
spectrum = { type = "table", frequency_hz = [1.0, 200.0], psd = [1.0, 1.0] }
[statistics]
t_start = 0.5
rest_duration = 1e-3
EXTRA
[tangential]
method = "gauss_seidel"
[output]
every = 1000
"#
);

fn case(seed: u64, damping: f64, extra: &str) -> Case {
    let text = CASE
        .replace("SEED", &seed.to_string())
        .replace("DAMPING", &damping.to_string())
        .replace("EXTRA", extra);
    Case::from_toml_str(&text, Path::new(".")).unwrap()
}

fn window(seed: u64) -> ContactStatistics {
    let c = case(seed, 0.1, "");
    let r = simulate(&c.model, &c.settings).unwrap();
    assert_eq!(r.termination, Termination::Completed);
    r.contacts.into_iter().next().unwrap()
}

/// Mean and sample standard deviation.
fn mean_std(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (
        m,
        (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt(),
    )
}

/// The standard error one run reports (20 batches of 0.5 s) is the spread of the window's
/// value over 20 independent runs (20 seeds): `SE/s` within 3 combined sampling errors of 1,
/// each of `SE` and `s` having a relative sampling error of `1/√(2(n − 1))` = 16 % for 20
/// batches or runs (so 23 % for their ratio; the SE averaged over the 20 runs has 4 %).
#[test]
fn the_error_of_one_run_is_the_spread_of_independent_runs() {
    let runs: Vec<ContactStatistics> = (1..=20).map(window).collect();
    assert!(runs.iter().all(|r| r.errors.batches == 20));
    assert!(
        (runs[0].errors.batch_length - 0.5).abs() < 1e-12,
        "{}",
        runs[0].errors.batch_length
    );
    let n = 20.0f64;
    let one = 1.0 / (2.0 * (n - 1.0)).sqrt();
    let mut correlated = 0;
    for (name, _, _) in runs[0].batched() {
        let values: Vec<f64> = runs
            .iter()
            .map(|r| r.batched().iter().find(|b| b.0 == name).unwrap().1)
            .collect();
        let errors: Vec<f64> = runs
            .iter()
            .map(|r| r.batched().iter().find(|b| b.0 == name).unwrap().2.unwrap())
            .collect();
        let (mean, spread) = mean_std(&values);
        let (se_mean, _) = mean_std(&errors);
        let single = errors[0] / spread;
        let averaged = se_mean / spread;
        println!(
            "{name:<24} mean {mean:.5e}  spread of 20 runs {spread:.3e}  SE run 1 {:.3e} ({single:.2})  mean SE {se_mean:.3e} ({averaged:.2})",
            errors[0]
        );
        assert!(mean > 0.0 && spread > 0.0, "{name}: the case rattles");
        // the ratio's logarithm: sampling errors one (SE of one run) and one (the spread)
        let sigma_single = (2.0 * one * one).sqrt();
        let sigma_averaged = (one * one + one * one / n).sqrt();
        assert!(
            single.ln().abs() < 3.0 * sigma_single,
            "{name}: SE of one run {} against the spread {spread}",
            errors[0]
        );
        assert!(
            averaged.ln().abs() < 3.0 * sigma_averaged,
            "{name}: mean SE {se_mean} against the spread {spread}"
        );
    }
    for r in &runs {
        correlated += r.errors.batches_correlated as usize;
        println!(
            "r1 = {:+.3}",
            r.errors.batch_autocorrelation.unwrap_or(f64::NAN)
        );
    }
    // r₁ > 2/√20 by chance: about 2 % of independent runs
    assert!(correlated <= 2, "{correlated} of 20 runs flagged");
}

/// Batches much shorter than the correlation time (a lightly damped tube, 200 batches of
/// 0.05 s against a correlation time of seconds) are flagged, with a large lag-1
/// autocorrelation; the same run with batches of 2 s is not.
#[test]
fn short_batches_are_flagged_as_correlated() {
    let c = case(3, 0.002, "block = 0.05");
    let r = simulate(&c.model, &c.settings).unwrap();
    let e = &r.contacts[0].errors;
    println!("{e:?}");
    assert_eq!(e.batches, 200);
    assert!(e.batches_correlated, "{e:?}");
    assert!(e.batch_autocorrelation.unwrap() > 0.5, "{e:?}");
    let c = case(3, 0.1, "block = 2.0");
    let r = simulate(&c.model, &c.settings).unwrap();
    assert!(
        !r.contacts[0].errors.batches_correlated,
        "{:?}",
        r.contacts[0].errors
    );
}

/// With a target relative error the run stops at the end of the first batch (from the 20th)
/// where the wear work rate's `SE/x̄` is at most the target, before `time.duration`; its
/// reported error then meets the target. The streamed run stops at the same step with the
/// same statistics, and a resume of it finds it complete.
#[test]
fn a_target_relative_error_stops_the_run_once_met() {
    let target = 0.05;
    let c = case(5, 0.1, &format!("target_relative_error = {target}"));
    // `time.duration` (10.5 s) is the longest run: 100 batches of 0.1 s
    let r = simulate(&c.model, &c.settings).unwrap();
    let s = &r.contacts[0];
    let met = r.target_met_at.expect("the target is met");
    println!(
        "met at t = {met} s after {} batches: wear work rate {:.4e} ± {:.2e}",
        s.errors.batches,
        s.wear_work_rate,
        s.errors.wear_work_rate_se.unwrap()
    );
    assert_eq!(r.termination, Termination::Completed);
    assert!(r.steps < c.settings.steps, "stopped early");
    assert!((r.steps as f64 * r.dt - met).abs() < 1e-9);
    assert!((s.errors.batch_length - 0.1).abs() < 1e-12);
    assert!(s.errors.batches >= 20);
    assert!(
        (s.duration - (met - 0.5)).abs() < 1e-9,
        "the window ends there"
    );
    let se = s.errors.wear_work_rate_se.unwrap();
    assert!(se <= target * s.wear_work_rate * (1.0 + 1e-6), "{se}");
    // one batch earlier it was not met: the run one batch shorter, with the same batches,
    // goes on to its end
    let mut shorter = c.clone();
    shorter.settings.steps = r.steps - 1000;
    shorter.settings.statistics.block = Some(s.errors.batch_length);
    let r2 = simulate(&shorter.model, &shorter.settings).unwrap();
    assert_eq!(r2.target_met_at, None);
    assert_eq!(r2.steps, shorter.settings.steps);
    // streamed, stopped midway and resumed: the same stop and the same statistics
    let dir = std::env::temp_dir().join(format!("fretdyn-se-{}", std::process::id()));
    let settings = StreamSettings {
        chunk_samples: 7,
        checkpoint_every_steps: Some(4096),
        checkpoint_every_seconds: None,
    };
    let stop = r.steps / 2;
    let first = stream::run(
        &c.model,
        &c.settings,
        &dir,
        &settings,
        1,
        &mut ProgressOnly(|p: fretdyn::integrator::simulation::Progress| {
            if p.step >= stop {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        }),
    )
    .unwrap();
    assert!(matches!(first.termination, Termination::Stopped { .. }));
    let resumed = stream::resume(
        &c.model,
        &c.settings,
        &dir,
        &settings,
        1,
        &mut ProgressOnly(|_| ControlFlow::Continue(())),
    )
    .unwrap();
    assert_eq!(resumed.target_met_at, r.target_met_at);
    assert_eq!(resumed.steps, r.steps);
    assert_eq!(resumed.contacts, r.contacts);
    assert!(dir.join("results.npz").exists());
    let blocks = std::fs::read_to_string(dir.join("blocks.csv")).unwrap();
    assert_eq!(blocks.lines().count() as u64, 1 + s.errors.batches);
    let again = stream::resume(
        &c.model,
        &c.settings,
        &dir,
        &settings,
        1,
        &mut ProgressOnly(|_| ControlFlow::Continue(())),
    );
    assert!(
        again.unwrap_err().to_string().contains("nothing to resume"),
        "a run stopped at its target is complete"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bad settings of the standard errors: one-line errors naming the field.
#[test]
fn bad_error_settings_are_refused_naming_the_field() {
    for (extra, field) in [
        (
            "target_relative_error = -0.02",
            "statistics.target_relative_error",
        ),
        (
            "target_relative_error = 0.0",
            "statistics.target_relative_error",
        ),
        (
            "target_relative_error = 2.0",
            "statistics.target_relative_error",
        ),
        ("max_relative_error = -1.0", "statistics.max_relative_error"),
        ("block = 20.0", "statistics.block"),
        ("batches = 1", "statistics.batches"),
        ("block = 0.5\nbatches = 10", "statistics.batches"),
    ] {
        let text = CASE
            .replace("SEED", "1")
            .replace("DAMPING", "0.1")
            .replace("EXTRA", extra);
        let e = Case::from_toml_str(&text, Path::new("."))
            .err()
            .unwrap_or_else(|| panic!("{extra}: accepted"))
            .to_string();
        assert!(e.contains(field), "{extra}: {e}");
        assert!(!e.contains('\n'), "{extra}: {e}");
    }
}
