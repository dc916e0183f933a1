//! Probabilistic studies (docs/STUDIES.md), against independent references: the draws follow
//! their distributions (moments and Kolmogorov–Smirnov statistic against the analytic CDF,
//! computed here by quadrature; χ² for a discrete law), they are a function of the study and
//! the run's index only (two loads, one or two threads give the same rows), the percentile
//! intervals cover the true quantile as often as their binomial coverage says over 200
//! repetitions, the bootstrap error matches the spread of the estimate over repetitions, a
//! table's row order changes nothing, a study cut midway resumes, and bad input names its
//! field.

use std::path::{Path, PathBuf};

use fretdyn::apps::percentiles::{
    PercentileRequest, bootstrap_standard_errors, order_statistic_interval, percentiles_of_table,
    quantile,
};
use fretdyn::apps::sampling::{Distribution, Stream};
use fretdyn::apps::study::Study;

/// Standard normal CDF by composite Simpson quadrature of the density (independent of the
/// library's erfc approximation): `Φ(z) = 1/2 + ∫₀ᶻ e^{−t²/2}/√(2π) dt`.
fn phi(z: f64) -> f64 {
    if z.abs() > 9.0 {
        return if z > 0.0 { 1.0 } else { 0.0 };
    }
    let n = 2000;
    let h = z / n as f64;
    let f = |t: f64| (-t * t / 2.0).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let mut s = f(0.0) + f(z);
    for i in 1..n {
        s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(i as f64 * h);
    }
    0.5 + s * h / 3.0
}

/// `n` draws of `d` as numbers, from the streams of sample `0..n` (as a study draws them).
fn draws(d: &Distribution, n: usize) -> Vec<f64> {
    (0..n)
        .map(|s| {
            let v = d.draw(&mut Stream::new(11, &[s as u64, 0]));
            v.as_float()
                .or_else(|| v.as_integer().map(|i| i as f64))
                .unwrap()
        })
        .collect()
}

/// Kolmogorov–Smirnov statistic of `x` against the CDF `f`.
fn ks(mut x: Vec<f64>, f: impl Fn(f64) -> f64) -> f64 {
    x.sort_by(f64::total_cmp);
    let n = x.len() as f64;
    x.iter()
        .enumerate()
        .map(|(i, &v)| {
            let c = f(v);
            (c - i as f64 / n).abs().max((c - (i + 1) as f64 / n).abs())
        })
        .fold(0.0, f64::max)
}

fn distribution(text: &str) -> Distribution {
    let v: toml::Value = toml::from_str(&format!("d = {text}")).unwrap();
    Distribution::from_toml(&v["d"], "d").unwrap()
}

fn mean_std(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, v.sqrt())
}

const N: usize = 4000;
/// Critical value of the KS statistic at the 0.1 % level, `1.95/√n`.
fn ks_critical(n: usize) -> f64 {
    1.95 / (n as f64).sqrt()
}

#[test]
fn draws_follow_their_distributions() {
    // uniform on [2, 5): mean 3.5, std 3/√12
    let x = draws(
        &distribution("{ type = \"uniform\", low = 2.0, high = 5.0 }"),
        N,
    );
    let (m, s) = mean_std(&x);
    let sd = 3.0 / 12f64.sqrt();
    assert!((m - 3.5).abs() < 4.0 * sd / (N as f64).sqrt(), "{m}");
    assert!((s / sd - 1.0).abs() < 0.05, "{s}");
    assert!(x.iter().all(|v| (2.0..5.0).contains(v)));
    let d = ks(x, |v| ((v - 2.0) / 3.0).clamp(0.0, 1.0));
    assert!(d < ks_critical(N), "uniform KS {d}");

    // normal N(10, 2²)
    let x = draws(
        &distribution("{ type = \"normal\", mean = 10.0, std = 2.0 }"),
        N,
    );
    let (m, s) = mean_std(&x);
    assert!((m - 10.0).abs() < 4.0 * 2.0 / (N as f64).sqrt(), "{m}");
    assert!((s / 2.0 - 1.0).abs() < 0.05, "{s}");
    let d = ks(x, |v| phi((v - 10.0) / 2.0));
    assert!(d < ks_critical(N), "normal KS {d}");

    // normal truncated to [9, 14]: CDF (Φ(z) − Φ(a))/(Φ(b) − Φ(a))
    let x = draws(
        &distribution("{ type = \"normal\", mean = 10.0, std = 2.0, min = 9.0, max = 14.0 }"),
        N,
    );
    assert!(x.iter().all(|v| (9.0..=14.0).contains(v)));
    let (a, b) = (phi(-0.5), phi(2.0));
    let d = ks(x, |v| (phi((v - 10.0) / 2.0) - a) / (b - a));
    assert!(d < ks_critical(N), "truncated normal KS {d}");

    // log-normal of median 0.3, sigma 0.2: ln X ~ N(ln 0.3, 0.2²)
    let x = draws(
        &distribution("{ type = \"log_normal\", median = 0.3, sigma = 0.2 }"),
        N,
    );
    let d = ks(x, |v| phi((v.ln() - 0.3f64.ln()) / 0.2));
    assert!(d < ks_critical(N), "log-normal KS {d}");

    // log-normal of mean 2 and std 0.5: the draws' mean and std
    let x = draws(
        &distribution("{ type = \"log_normal\", mean = 2.0, std = 0.5 }"),
        N,
    );
    let (m, s) = mean_std(&x);
    assert!((m - 2.0).abs() < 4.0 * 0.5 / (N as f64).sqrt(), "{m}");
    assert!((s / 0.5 - 1.0).abs() < 0.08, "{s}");

    // discrete with weights 1, 2, 7 (strings): χ² with 2 degrees of freedom below 13.8 (0.1 %)
    let d = distribution(
        "{ type = \"discrete\", values = [\"a\", \"b\", \"c\"], weights = [1, 2, 7] }",
    );
    let mut counts = [0usize; 3];
    for s in 0..N {
        match d.draw(&mut Stream::new(3, &[s as u64])).as_str().unwrap() {
            "a" => counts[0] += 1,
            "b" => counts[1] += 1,
            _ => counts[2] += 1,
        }
    }
    let chi2: f64 = counts
        .iter()
        .zip([0.1, 0.2, 0.7])
        .map(|(&o, p)| (o as f64 - p * N as f64).powi(2) / (p * N as f64))
        .sum();
    assert!(chi2 < 13.8, "{counts:?} χ² = {chi2}");
    // a zero weight is never drawn
    let d = distribution("{ type = \"discrete\", values = [true, false], weights = [0, 1] }");
    assert!((0..1000).all(|s| d.draw(&mut Stream::new(3, &[s])) == toml::Value::Boolean(false)));
}

/// The 95 % interval of P95 from 100 normal values covers the true quantile in as many of 200
/// repetitions as its exact binomial coverage says (within 3.5 standard deviations), and the
/// bootstrap standard error matches the spread of the estimate over the repetitions.
#[test]
fn percentile_intervals_cover_the_true_quantile_and_bootstrap_errors_match_the_spread() {
    let (n, p, reps) = (100, 0.95, 200);
    let xi = 1.644_853_626_951_472_2; // Φ⁻¹(0.95)
    assert!((phi(xi) - 0.95).abs() < 1e-10);
    let (l, u, coverage) = order_statistic_interval(n, p, 0.95);
    let (l, u) = (l.unwrap(), u.unwrap());
    assert!((0.95..0.99).contains(&coverage), "{coverage}");
    let mut covered = 0;
    let mut estimates = Vec::new();
    let mut errors = Vec::new();
    for r in 0..reps {
        let mut s = Stream::new(r, &[]);
        let mut x: Vec<f64> = (0..n).map(|_| s.normal()).collect();
        x.sort_by(f64::total_cmp);
        if x[l - 1] <= xi && xi <= x[u - 1] {
            covered += 1;
        }
        estimates.push(quantile(&x, p));
        errors.push(bootstrap_standard_errors(&x, &[p], 500, &mut Stream::new(r, &[1]))[0]);
    }
    let expected = reps as f64 * coverage;
    let sd = (reps as f64 * coverage * (1.0 - coverage)).sqrt();
    assert!(
        (covered as f64 - expected).abs() < 3.5 * sd,
        "{covered} of {reps} covered, {expected:.1} expected"
    );
    // the spread of the estimate over the repetitions against the mean bootstrap error: the
    // spread's own relative error is about 1/√(2·200) = 5 %
    let (_, spread) = mean_std(&estimates);
    let (mean_error, _) = mean_std(&errors);
    assert!(
        (mean_error / spread - 1.0).abs() < 0.2,
        "bootstrap {mean_error}, spread {spread}"
    );
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fretdyn-prob-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    std::fs::copy(examples.join("tube_multispan.toml"), dir.join("tube.toml")).unwrap();
    dir
}

/// A probabilistic study of the multispan tube, 20 ms runs: clearances per plate, friction
/// shared, a grid of two damping values × `samples`.
fn write_study(dir: &Path, samples: usize) -> PathBuf {
    let path = dir.join("study.toml");
    std::fs::write(
        &path,
        format!(
            r#"base = "tube.toml"
samples = {samples}
seed = 7

[[parameters]]
key = "contacts.*.obstacle.clearance"
independent = true
distribution = {{ type = "uniform", low = 1e-5, high = 3e-5 }}

[[parameters]]
key = "contacts.*.friction.mu"
distribution = {{ type = "discrete", values = [0.2, 0.4] }}

[[parameters]]
key = "structure.damping_ratio"
values = [0.01, 0.02]

[[parameters]]
key = "time.duration"
values = [0.02]

[percentiles]
statistics = ["normal_force_max", "connors_max_ratio"]
levels = [50, 90]
bootstrap = 200
"#
        ),
    )
    .unwrap();
    path
}

fn rows(table: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(table).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let speed = header
        .iter()
        .position(|h| *h == "steps_per_second")
        .unwrap();
    let mut r: Vec<Vec<String>> = text
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .enumerate()
                .filter(|(i, _)| *i != speed)
                .map(|(_, c)| c.to_string())
                .collect()
        })
        .collect();
    r.sort_by_key(|l| l[0].parse::<usize>().unwrap());
    r
}

#[test]
fn draws_are_a_function_of_the_study_and_the_run_index() {
    let dir = scratch("reproducible");
    let path = write_study(&dir, 3);
    let a = Study::from_file(&path).unwrap();
    let b = Study::from_file(&path).unwrap();
    let runs = a.runs();
    assert_eq!(runs, b.runs());
    // 2 damping values × 3 samples
    assert_eq!(runs.len(), 6);
    let header = a.header(&a.contact_names());
    assert!(header.starts_with(
        "run,contacts.0.obstacle.clearance,contacts.1.obstacle.clearance,contacts.2.obstacle.clearance,contacts.3.obstacle.clearance,contacts.4.obstacle.clearance,contacts.*.friction.mu,structure.damping_ratio,time.duration,sample,seed,status,"
    ), "{header}");
    // each grid point sees the same samples (common random numbers); elements drawn apart
    for s in 0..3 {
        assert_eq!(runs[s].values[..6], runs[3 + s].values[..6]);
        assert_eq!(runs[s].sample, Some(s));
    }
    assert_ne!(runs[0].values[0], runs[0].values[1]);
    assert_ne!(runs[0].values[0], runs[1].values[0]);
    // the case gets the drawn values
    let case = a.case(&runs[4]).unwrap();
    let c = runs[4].values[2].as_float().unwrap();
    assert!((1e-5..3e-5).contains(&c));
    let mu = runs[4].values[5].as_float().unwrap();
    assert!(mu == 0.2 || mu == 0.4);
    for contact in &case.model.contacts {
        assert_eq!(contact.friction.mu_dynamic, mu);
    }

    // one thread or two: the same rows; the percentiles of a shuffled table are the same
    let one = dir.join("one.csv");
    let two = dir.join("two.csv");
    assert_eq!(a.execute(&one, 1, &|_, _| {}).unwrap(), 6);
    assert_eq!(b.execute(&two, 2, &|_, _| {}).unwrap(), 6);
    assert_eq!(rows(&one), rows(&two));
    // the row of one index from a fresh load (what a Dask worker runs: study_row(study, 4))
    let fresh = Study::from_file(&path).unwrap();
    let row = fresh.run_row(&fresh.runs()[4]).unwrap();
    let single = dir.join("single.csv");
    std::fs::write(&single, format!("{header}\n{row}\n")).unwrap();
    assert_eq!(rows(&single)[0], rows(&one)[4]);
    let text = std::fs::read_to_string(&one).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[1..].reverse();
    let shuffled = dir.join("shuffled.csv");
    std::fs::write(&shuffled, lines.join("\n") + "\n").unwrap();
    let p = a.percentiles(&one).unwrap().unwrap();
    let q = a.percentiles(&shuffled).unwrap().unwrap();
    assert_eq!(p.to_csv(), q.to_csv());
    // the draws matter: the contacts' largest forces differ between samples
    assert!(
        p.rows.iter().any(|r| r.bootstrap_se > 0.0),
        "{}",
        p.to_csv()
    );
    // 2 groups × (5 contacts + connors) × 2 levels, 3 samples each
    assert_eq!(p.rows.len(), 2 * 6 * 2);
    assert!(
        p.rows
            .iter()
            .all(|r| r.n == 3 || r.column == "connors_max_ratio")
    );
    assert_eq!(
        p.rows[0].group[0],
        ("structure.damping_ratio".into(), "0.01".into())
    );
    assert_eq!(p.rows.last().unwrap().group[0].1, "0.02");

    // a study cut midway: the missing samples only are run, the same rows result
    let full = rows(&one);
    std::fs::write(&one, lines[..3].join("\n") + "\n").unwrap();
    assert_eq!(a.execute(&one, 2, &|_, _| {}).unwrap(), 4);
    assert_eq!(rows(&one), full);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn percentiles_of_a_known_table() {
    let dir = scratch("known");
    // values 1..=100 in a scrambled order, one run not completed, group by g
    let mut text = String::from("run,g,status,x\n");
    for i in 0..100 {
        let v = (i * 37) % 100 + 1;
        text += &format!("{i},a,completed,{v}\n");
    }
    text += "100,a,diverged,1000\n101,b,completed,5\n";
    let table = dir.join("t.csv");
    std::fs::write(&table, text).unwrap();
    let request = PercentileRequest {
        columns: vec!["x".into()],
        levels: vec![50.0, 95.0],
        group_by: vec!["g".into()],
        confidence: 0.95,
        bootstrap: 100,
        seed: 1,
    };
    let r = percentiles_of_table(&table, &request).unwrap();
    assert_eq!(r.rows.len(), 4);
    let (p50, p95) = (&r.rows[0], &r.rows[1]);
    assert_eq!((p50.n, p50.excluded), (100, 1));
    // definition 7: h = 99·0.5 = 49.5 → 50.5; h = 99·0.95 = 94.05 → 95.05
    assert!((p50.estimate - 50.5).abs() < 1e-12);
    assert!((p95.estimate - 95.05).abs() < 1e-12);
    // the bounds are order statistics, i.e. ranks: the k-th smallest of 1..=100 is k
    let (l, u, _) = order_statistic_interval(100, 0.5, 0.95);
    assert_eq!(p50.ci_low, Some(l.unwrap() as f64));
    assert_eq!(p50.ci_high, Some(u.unwrap() as f64));
    // P(B ≤ l−1) ≤ 2.5 % < P(B ≤ l), B ~ Bin(100, 1/2), by a direct sum
    let cdf = |k: usize| -> f64 {
        let mut c = 1.0f64; // C(100, i) built up
        let mut s = 0.0;
        for i in 0..=k {
            if i > 0 {
                c *= (100 - i + 1) as f64 / i as f64;
            }
            s += c * 0.5f64.powi(100);
        }
        s
    };
    let l = l.unwrap();
    assert!(cdf(l - 1) <= 0.025 && cdf(l) > 0.025);
    // the group of one value: the value, no interval
    let b = &r.rows[2];
    assert_eq!((b.n, b.estimate, b.ci_low, b.ci_high), (1, 5.0, None, None));
    assert!(b.bootstrap_se.is_nan());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_probabilistic_studies_name_the_field_and_the_fix() {
    let dir = scratch("bad");
    let base =
        "base = \"tube.toml\"\nsamples = 4\n\n[[parameters]]\nkey = \"contacts.*.friction.mu\"\n";
    for (study, needles) in [
        (
            format!("{base}distribution = {{ type = \"gamma\", k = 1 }}\n"),
            vec![
                "parameters[0].distribution.type",
                "\"gamma\"",
                "\"uniform\"",
            ],
        ),
        (
            format!("{base}distribution = {{ type = \"normal\", mean = 0.3, std = -0.1 }}\n"),
            vec!["parameters[0].distribution.std", "≥ 0"],
        ),
        (
            format!(
                "{base}distribution = {{ type = \"discrete\", values = [0.1, 0.2], weights = [0, 0] }}\n"
            ),
            vec!["parameters[0].distribution.weights", "more than 0"],
        ),
        (
            format!(
                "{base}distribution = {{ type = \"discrete\", values = [0.1, 0.2], weights = [1] }}\n"
            ),
            vec!["parameters[0].distribution.weights", "one weight per value"],
        ),
        (
            format!(
                "{base}values = [0.1]\ndistribution = {{ type = \"uniform\", low = 0.1, high = 0.2 }}\n"
            ),
            vec!["parameters[0]", "both values and distribution", "keep one"],
        ),
        (
            format!("{base}distribution = {{ type = \"uniform\", low = 0.3, high = 0.2 }}\n"),
            vec!["parameters[0].distribution.high", "above low"],
        ),
        (
            format!(
                "{base}distribution = {{ type = \"normal\", mean = 0.3, std = 0.01, min = 0.5 }}\n"
            ),
            vec!["parameters[0].distribution.min", "widen"],
        ),
        (
            format!("{base}distribution = {{ type = \"log_normal\", median = 0.3 }}\n"),
            vec!["parameters[0].distribution", "median and sigma"],
        ),
        (
            format!("{base}independent = true\nvalues = [0.1]\n"),
            vec!["parameters[0].independent", "distribution"],
        ),
        (
            base.replace("samples = 4", "samples = 0")
                + "distribution = { type = \"uniform\", low = 0.1, high = 0.2 }\n",
            vec!["samples", "between 1 and 100000"],
        ),
        (
            base.replace("samples = 4\n", "")
                + "distribution = { type = \"uniform\", low = 0.1, high = 0.2 }\n",
            vec!["samples", "missing", "samples = N"],
        ),
        (
            format!(
                "{base}distribution = {{ type = \"uniform\", low = 0.1, high = 0.2 }}\n\n[percentiles]\nstatistics = [\"wear_depth\"]\n"
            ),
            vec!["percentiles.statistics[0]", "'wear_depth'"],
        ),
        (
            format!(
                "{base}distribution = {{ type = \"uniform\", low = 0.1, high = 0.2 }}\n\n[percentiles]\nlevels = [50, 100]\n"
            ),
            vec!["percentiles.levels[1]", "between 0 and 100"],
        ),
    ] {
        let path = dir.join("study.toml");
        std::fs::write(&path, &study).unwrap();
        let err = Study::from_file(&path).unwrap_err().to_string();
        assert_eq!(err.lines().count(), 1, "{err}");
        for n in needles {
            assert!(err.contains(n), "'{n}' not in: {err}\n{study}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
