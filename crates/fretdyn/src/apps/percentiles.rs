//! Percentiles of a study's results across its samples (`docs/STUDIES.md`), each with its
//! sampling error, from the study table alone (so that a table written by Dask workers gives
//! the same report as one written here).
//!
//! - **Estimate**: the sample quantile of Hyndman & Fan's definition 7 (NumPy's default):
//!   with the `n` values sorted `x₍₁₎ ≤ … ≤ x₍ₙ₎` and `h = (n − 1) p`,
//!   `Q(p) = x₍⌊h⌋+1₎ + (h − ⌊h⌋)(x₍⌊h⌋+2₎ − x₍⌊h⌋+1₎)`.
//! - **Confidence interval, distribution-free**: `[x₍l₎, x₍u₎]` from order statistics. For a
//!   continuous distribution the number `B` of values below the true quantile `ξ_p` is
//!   `Binomial(n, p)`, and `x₍l₎ ≤ ξ_p < x₍u₎` exactly when `l ≤ B ≤ u − 1`, so that the
//!   coverage is `F(u−1) − F(l−1)` with `F` the binomial CDF. `l` is the largest rank with
//!   `F(l−1) ≤ α/2` and `u` the smallest with `1 − F(u−1) ≤ α/2` (`α = 1 −` confidence):
//!   an equal-tailed interval of coverage at least the confidence (reported exactly). A bound
//!   is missing when no rank qualifies: the upper bound of P99 at 95 % needs
//!   `0.99ⁿ ≤ 0.025`, i.e. `n ≥ 368` samples.
//! - **Bootstrap standard error**: the standard deviation of the estimate over `B` resamples
//!   of the `n` values with replacement, drawn from a [`Stream`] seeded by the study seed, the
//!   group and the column: reproducible.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use super::sampling::Stream;
use crate::error::{Error, Result};

/// The sample quantile of definition 7 (linear interpolation between order statistics) of
/// `sorted` (ascending, not empty) at probability `p ∈ [0, 1]`.
pub fn quantile(sorted: &[f64], p: f64) -> f64 {
    let n = sorted.len();
    let h = (n - 1) as f64 * p;
    let lo = (h.floor() as usize).min(n - 1);
    let hi = (lo + 1).min(n - 1);
    between(sorted[lo], sorted[hi], h - lo as f64)
}

/// `a + f (b − a)`, and `a` when `a = b` (two infinite values, e.g. a criterion never
/// reached, give that infinity, not NaN).
fn between(a: f64, b: f64, f: f64) -> f64 {
    if a == b || f == 0.0 {
        a
    } else {
        a + f * (b - a)
    }
}

/// `ln k!` for `k = 0..=n`.
fn ln_factorials(n: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(n + 1);
    let mut s = 0.0;
    out.push(0.0);
    for k in 1..=n {
        s += (k as f64).ln();
        out.push(s);
    }
    out
}

/// Ranks (1-based) of the distribution-free confidence interval `[x₍l₎, x₍u₎]` of the
/// `p`-quantile from `n` values at `confidence` (module docs), and its exact coverage
/// `P(l ≤ B ≤ u−1)`, `B ~ Binomial(n, p)`: `None` for a bound no rank gives (its side's
/// coverage is then counted to the infinite bound).
pub fn order_statistic_interval(
    n: usize,
    p: f64,
    confidence: f64,
) -> (Option<usize>, Option<usize>, f64) {
    let tail = (1.0 - confidence) / 2.0;
    let lf = ln_factorials(n);
    let (lp, lq) = (p.ln(), (1.0 - p).ln());
    let pmf: Vec<f64> = (0..=n)
        .map(|i| (lf[n] - lf[i] - lf[n - i] + i as f64 * lp + (n - i) as f64 * lq).exp())
        .collect();
    // lower: the largest l ≥ 1 with F(l−1) = Σ_{i<l} pmf ≤ tail
    let mut below = 0.0; // F(l−1)
    let mut lower = None;
    let mut lower_tail = 0.0;
    for l in 1..=n {
        below += pmf[l - 1];
        if below <= tail {
            lower = Some(l);
            lower_tail = below;
        } else {
            break;
        }
    }
    // upper: the smallest u ≤ n with 1 − F(u−1) = Σ_{i≥u} pmf ≤ tail
    let mut above = 0.0;
    let mut upper = None;
    let mut upper_tail = 0.0;
    for u in (1..=n).rev() {
        above += pmf[u];
        if above <= tail {
            upper = Some(u);
            upper_tail = above;
        } else {
            break;
        }
    }
    (lower, upper, 1.0 - lower_tail - upper_tail)
}

/// Bootstrap standard errors of the definition-7 quantiles at `ps` of `sorted` (ascending),
/// from `resamples` resamples drawn from `stream`: NaN when fewer than 2 values.
pub fn bootstrap_standard_errors(
    sorted: &[f64],
    ps: &[f64],
    resamples: usize,
    stream: &mut Stream,
) -> Vec<f64> {
    let n = sorted.len();
    if n < 2 || resamples < 2 {
        return vec![f64::NAN; ps.len()];
    }
    let mut counts = vec![0u32; n];
    let mut sums = vec![0.0; ps.len()];
    let mut squares = vec![0.0; ps.len()];
    // positions (0-based) of the order statistics each quantile needs
    let needs: Vec<(usize, usize, f64)> = ps
        .iter()
        .map(|&p| {
            let h = (n - 1) as f64 * p;
            let lo = (h.floor() as usize).min(n - 1);
            (lo, (lo + 1).min(n - 1), h - lo as f64)
        })
        .collect();
    let mut order = vec![0.0; n];
    for _ in 0..resamples {
        counts.iter_mut().for_each(|c| *c = 0);
        for _ in 0..n {
            counts[stream.below(n)] += 1;
        }
        // the resample sorted: each value as many times as drawn (sorted is ascending)
        let mut k = 0;
        for (i, &c) in counts.iter().enumerate() {
            for _ in 0..c {
                order[k] = sorted[i];
                k += 1;
            }
        }
        for (j, &(lo, hi, f)) in needs.iter().enumerate() {
            let q = between(order[lo], order[hi], f);
            sums[j] += q;
            squares[j] += q * q;
        }
    }
    let b = resamples as f64;
    sums.iter()
        .zip(&squares)
        .map(|(s, s2)| ((s2 - s * s / b) / (b - 1.0)).max(0.0).sqrt())
        .collect()
}

/// One percentile of one column in one group of runs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PercentileRow {
    /// Values of the grid parameters that define the group (`key`, value as in the table).
    pub group: Vec<(String, String)>,
    /// Column of the table.
    pub column: String,
    /// Level, percent (95 for P95).
    pub level: f64,
    /// Number of values (completed runs with a number in the column).
    pub n: usize,
    /// Runs of the group left out (not completed, or no number in the column).
    pub excluded: usize,
    /// The sample quantile (definition 7).
    pub estimate: f64,
    /// Lower bound of the distribution-free confidence interval (`None`: too few samples).
    pub ci_low: Option<f64>,
    /// Upper bound (`None`: too few samples).
    pub ci_high: Option<f64>,
    /// Exact coverage of the interval (at least the confidence when both bounds exist).
    pub ci_coverage: f64,
    /// Bootstrap standard error of the estimate.
    pub bootstrap_se: f64,
}

/// Percentiles of a study table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PercentileReport {
    /// Confidence of the intervals (0.95).
    pub confidence: f64,
    /// Bootstrap resamples.
    pub bootstrap_resamples: usize,
    /// Seed of the bootstrap streams (the study's).
    pub seed: u64,
    /// The rows, by group, column, level.
    pub rows: Vec<PercentileRow>,
}

/// What to compute: which columns, at which levels, groups by which columns.
#[derive(Debug, Clone, PartialEq)]
pub struct PercentileRequest {
    /// Columns of the table.
    pub columns: Vec<String>,
    /// Levels, percent.
    pub levels: Vec<f64>,
    /// Columns whose values define a group (the grid parameters).
    pub group_by: Vec<String>,
    /// Confidence of the intervals.
    pub confidence: f64,
    /// Bootstrap resamples.
    pub bootstrap: usize,
    /// Seed of the bootstrap.
    pub seed: u64,
}

/// The report of `request` on the table at `table` (complete rows only; rows whose `status`
/// is not `completed` are left out and counted).
pub fn percentiles_of_table(table: &Path, request: &PercentileRequest) -> Result<PercentileReport> {
    let text = std::fs::read_to_string(table).map_err(|e| Error::io(table, e))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let column = |name: &str| -> Result<usize> {
        header.iter().position(|h| *h == name).ok_or_else(|| {
            Error::invalid(
                "table",
                format!(
                    "{} has no column '{name}': it belongs to another study",
                    table.display()
                ),
            )
        })
    };
    let run = column("run")?;
    let status = column("status")?;
    let groups_at: Vec<usize> = request
        .group_by
        .iter()
        .map(|g| column(g))
        .collect::<Result<_>>()?;
    let values_at: Vec<usize> = request
        .columns
        .iter()
        .map(|c| column(c))
        .collect::<Result<_>>()?;
    let complete = if text.ends_with('\n') {
        text.lines().count()
    } else {
        text.lines().count().saturating_sub(1)
    };
    let mut rows: Vec<(usize, Vec<&str>)> = lines
        .take(complete.saturating_sub(1))
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|r| r.len() == header.len())
        .filter_map(|r| Some((r[run].parse().ok()?, r)))
        .collect();
    // the table's order is that in which runs finished: the report follows the run index
    rows.sort_by_key(|(i, _)| *i);
    let mut groups: Vec<(Vec<&str>, Vec<&Vec<&str>>)> = Vec::new();
    for (_, r) in &rows {
        let key: Vec<&str> = groups_at.iter().map(|&g| r[g]).collect();
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, members)) => members.push(r),
            None => groups.push((key, vec![r])),
        }
    }
    let ps: Vec<f64> = request.levels.iter().map(|l| l / 100.0).collect();
    let mut out = Vec::new();
    for (g, (key, members)) in groups.iter().enumerate() {
        for (c, (&at, name)) in values_at.iter().zip(&request.columns).enumerate() {
            let mut values: Vec<f64> = members
                .iter()
                .filter(|r| r[status] == "completed")
                .filter_map(|r| r[at].parse::<f64>().ok())
                .filter(|x| !x.is_nan())
                .collect();
            values.sort_by(f64::total_cmp);
            let n = values.len();
            let mut stream = Stream::new(request.seed, &[u64::MAX, g as u64, c as u64]);
            let se = bootstrap_standard_errors(&values, &ps, request.bootstrap, &mut stream);
            for (&level, (&p, se)) in request.levels.iter().zip(ps.iter().zip(se)) {
                let (estimate, ci_low, ci_high, ci_coverage) = if n == 0 {
                    (f64::NAN, None, None, f64::NAN)
                } else {
                    let (l, u, coverage) = order_statistic_interval(n, p, request.confidence);
                    (
                        quantile(&values, p),
                        l.map(|l| values[l - 1]),
                        u.map(|u| values[u - 1]),
                        coverage,
                    )
                };
                out.push(PercentileRow {
                    group: request
                        .group_by
                        .iter()
                        .zip(key)
                        .map(|(k, v)| (k.clone(), v.to_string()))
                        .collect(),
                    column: name.clone(),
                    level,
                    n,
                    excluded: members.len() - n,
                    estimate,
                    ci_low,
                    ci_high,
                    ci_coverage,
                    bootstrap_se: se,
                });
            }
        }
    }
    Ok(PercentileReport {
        confidence: request.confidence,
        bootstrap_resamples: request.bootstrap,
        seed: request.seed,
        rows: out,
    })
}

impl PercentileReport {
    /// The report as CSV: the group's columns, then `column, level, n, excluded, estimate,
    /// ci_low, ci_high, ci_coverage, bootstrap_se`. A value the samples cannot give (a missing
    /// bound; the estimate and coverage of no sample; the bootstrap error of fewer than 2) is
    /// an empty cell, as in the study table (`null` in [`Self::to_json`]; NaN for numpy's
    /// `genfromtxt` and pandas); an infinite one is `inf`.
    pub fn to_csv(&self) -> String {
        let mut s = String::new();
        let group: Vec<&str> = self
            .rows
            .first()
            .map(|r| r.group.iter().map(|(k, _)| k.as_str()).collect())
            .unwrap_or_default();
        let mut head: Vec<&str> = group.clone();
        head.extend([
            "column",
            "level",
            "n",
            "excluded",
            "estimate",
            "ci_low",
            "ci_high",
            "ci_coverage",
            "bootstrap_se",
        ]);
        let _ = writeln!(s, "{}", head.join(","));
        let cell = |x: f64| {
            if x.is_nan() {
                String::new()
            } else {
                x.to_string()
            }
        };
        let opt = |x: Option<f64>| x.map(cell).unwrap_or_default();
        for r in &self.rows {
            let mut cols: Vec<String> = r.group.iter().map(|(_, v)| v.clone()).collect();
            cols.extend([
                r.column.clone(),
                r.level.to_string(),
                r.n.to_string(),
                r.excluded.to_string(),
                cell(r.estimate),
                opt(r.ci_low),
                opt(r.ci_high),
                cell(r.ci_coverage),
                cell(r.bootstrap_se),
            ]);
            let _ = writeln!(s, "{}", cols.join(","));
        }
        s
    }

    /// The report as JSON: a value the samples cannot give (NaN, a missing bound) is `null`,
    /// at the places of the empty cells of [`Self::to_csv`] (JSON has no infinity: an
    /// infinite value is `null` too, `inf` in the CSV).
    pub fn to_json(&self) -> String {
        let rows: Vec<serde_json::Value> = self
            .rows
            .iter()
            .map(|r| {
                let num = |x: f64| {
                    serde_json::Number::from_f64(x)
                        .map(serde_json::Value::Number)
                        .unwrap_or(serde_json::Value::Null)
                };
                serde_json::json!({
                    "group": r.group.iter().map(|(k, v)| (k.clone(), serde_json::Value::String(v.clone()))).collect::<serde_json::Map<_, _>>(),
                    "column": r.column,
                    "level": r.level,
                    "n": r.n,
                    "excluded": r.excluded,
                    "estimate": num(r.estimate),
                    "ci_low": r.ci_low.map(num),
                    "ci_high": r.ci_high.map(num),
                    "ci_coverage": num(r.ci_coverage),
                    "bootstrap_se": num(r.bootstrap_se),
                })
            })
            .collect();
        serde_json::to_string_pretty(&serde_json::json!({
            "confidence": self.confidence,
            "bootstrap_resamples": self.bootstrap_resamples,
            "seed": self.seed,
            "rows": rows,
        }))
        .unwrap_or_default()
    }

    /// Writes `percentiles.csv` and `percentiles.json` into `dir`.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let csv = dir.join("percentiles.csv");
        std::fs::write(&csv, self.to_csv()).map_err(|e| Error::io(&csv, e))?;
        let json = dir.join("percentiles.json");
        std::fs::write(&json, self.to_json()).map_err(|e| Error::io(&json, e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantile_of_definition_7_by_hand() {
        let x = [1.0, 2.0, 4.0, 8.0, 16.0];
        assert_eq!(quantile(&x, 0.5), 4.0);
        // h = 4·0.95 = 3.8: 8 + 0.8·8
        assert!((quantile(&x, 0.95) - 14.4).abs() < 1e-12);
        assert_eq!(quantile(&x, 0.0), 1.0);
        assert_eq!(quantile(&x, 1.0), 16.0);
        assert_eq!(quantile(&[3.0], 0.99), 3.0);
        // infinite values (a criterion never reached) stay infinite
        let x = [1.0, f64::INFINITY, f64::INFINITY];
        assert_eq!(quantile(&x, 0.9), f64::INFINITY);
        assert_eq!(quantile(&x, 0.25), f64::INFINITY);
    }

    #[test]
    fn what_one_sample_cannot_give_is_an_empty_cell_and_null() {
        // one completed run and one without a number: P50 of one value has no interval and
        // no bootstrap error; the group without a value has no estimate either
        let dir = std::env::temp_dir().join(format!("fretdyn-percentiles-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let table = dir.join("study.csv");
        std::fs::write(
            &table,
            "run,g,status,x\n0,a,completed,2.5\n1,b,completed,\n2,c,completed,inf\n",
        )
        .unwrap();
        let request = PercentileRequest {
            columns: vec!["x".into()],
            levels: vec![50.0],
            group_by: vec!["g".into()],
            confidence: 0.95,
            bootstrap: 100,
            seed: 1,
        };
        let r = percentiles_of_table(&table, &request).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        let csv = r.to_csv();
        assert!(!csv.contains("NaN"), "{csv}");
        assert_eq!(
            csv,
            "g,column,level,n,excluded,estimate,ci_low,ci_high,ci_coverage,bootstrap_se\n\
             a,x,50,1,0,2.5,,,1,\n\
             b,x,50,0,1,,,,,\n\
             c,x,50,1,0,inf,,,1,\n"
        );
        // null in the JSON where the CSV has an empty cell (and for inf: JSON has none)
        let json: serde_json::Value = serde_json::from_str(&r.to_json()).unwrap();
        let keys = [
            "estimate",
            "ci_low",
            "ci_high",
            "ci_coverage",
            "bootstrap_se",
        ];
        for (row, line) in json["rows"]
            .as_array()
            .unwrap()
            .iter()
            .zip(csv.lines().skip(1))
        {
            let cells: Vec<&str> = line.split(',').skip(5).collect();
            for (k, cell) in keys.iter().zip(cells) {
                assert_eq!(
                    row[k].is_null(),
                    cell.is_empty() || cell == "inf",
                    "{k}: {line}"
                );
                if let Some(x) = row[k].as_f64() {
                    assert_eq!(cell.parse::<f64>().unwrap(), x, "{k}: {line}");
                }
            }
        }
    }

    #[test]
    fn median_interval_of_ten_by_hand() {
        // n = 10, p = 1/2: F(1) = 11/1024 = 0.0107 ≤ 0.025 < F(2) = 56/1024 → l = 2, u = 9,
        // coverage 1 − 2·11/1024
        let (l, u, c) = order_statistic_interval(10, 0.5, 0.95);
        assert_eq!((l, u), (Some(2), Some(9)));
        assert!((c - (1.0 - 22.0 / 1024.0)).abs() < 1e-12);
        // P99 from 100 values: 0.99^100 = 0.366 > 0.025, no upper bound
        let (_, u, _) = order_statistic_interval(100, 0.99, 0.95);
        assert_eq!(u, None);
        // 0.99^367 = 0.02503 > 0.025, 0.99^368 = 0.02478: the upper bound needs n ≥ 368
        assert_eq!(order_statistic_interval(367, 0.99, 0.95).1, None);
        assert_eq!(order_statistic_interval(368, 0.99, 0.95).1, Some(368));
    }
}
