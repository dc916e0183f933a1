//! Random draws of study parameters (`docs/STUDIES.md`): the distributions a study file may give
//! instead of a list of values, drawn from a [`Stream`] of the crate's one counter-based
//! generator ([`crate::numerics::rng`]: SplitMix64), so that every draw is a pure function of
//! `(study seed, sample, parameter, element)`: the same study gives the same draws whatever
//! runs them, in whatever order (rayon here, Dask workers in Python).

use crate::error::{Error, Result};

pub use crate::numerics::rng::Stream;

/// A distribution of a study parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum Distribution {
    /// Uniform on `[low, high)`.
    Uniform {
        /// Lower bound.
        low: f64,
        /// Upper bound.
        high: f64,
    },
    /// Normal `N(mean, std²)`, truncated to `[min, max]` (infinite when not given): drawn by
    /// rejection, which keeps the shape of the density inside the bounds.
    Normal {
        /// Mean (of the untruncated distribution).
        mean: f64,
        /// Standard deviation (of the untruncated distribution).
        std: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Log-normal: `ln X ~ N(mu, sigma²)`, i.e. median `e^mu`; truncated to `[min, max]` like
    /// [`Distribution::Normal`].
    LogNormal {
        /// Mean of `ln X` (the log of the median).
        mu: f64,
        /// Standard deviation of `ln X`.
        sigma: f64,
        /// Lower bound (on X).
        min: f64,
        /// Upper bound (on X).
        max: f64,
    },
    /// One of `values` with probabilities proportional to the weights.
    Discrete {
        /// The values (numbers, strings, booleans: anything a case file takes).
        values: Vec<toml::Value>,
        /// Cumulative probabilities, the last one 1.
        cumulative: Vec<f64>,
    },
}

/// Fewest of the untruncated distribution a truncation may keep: below, the bounds are refused
/// (rejection would be slow and the bounds are most likely a mistake).
const MIN_KEPT: f64 = 1e-3;

/// Tries of a truncated draw before it takes the nearer bound: unreachable in practice, the
/// probability of `MAX_TRIES` rejections in a row being below `(1 − 10⁻³)^(10⁶)` = `e^{−1000}`.
const MAX_TRIES: usize = 1_000_000;

impl Distribution {
    /// Reads `distribution = { type = …, … }` of a study parameter; `field` names it in
    /// errors (`parameters[2].distribution`).
    pub fn from_toml(value: &toml::Value, field: &str) -> Result<Self> {
        let Some(t) = value.as_table() else {
            return Err(Error::invalid(
                field,
                "must be a table: distribution = { type = \"uniform\", low = …, high = … }",
            ));
        };
        let kind = t.get("type").and_then(|v| v.as_str()).ok_or_else(|| {
            Error::invalid(
                format!("{field}.type"),
                "missing: give type = \"uniform\", \"normal\", \"log_normal\" or \"discrete\"",
            )
        })?;
        let allowed: &[&str] = match kind {
            "uniform" => &["type", "low", "high"],
            "normal" => &["type", "mean", "std", "min", "max"],
            "log_normal" => &["type", "median", "sigma", "mean", "std", "min", "max"],
            "discrete" => &["type", "values", "weights"],
            other => {
                return Err(Error::invalid(
                    format!("{field}.type"),
                    format!(
                        "unknown distribution \"{other}\": use \"uniform\", \"normal\", \"log_normal\" or \"discrete\""
                    ),
                ));
            }
        };
        if let Some(k) = t.keys().find(|k| !allowed.contains(&k.as_str())) {
            return Err(Error::invalid(
                format!("{field}.{k}"),
                format!(
                    "not a field of a {kind} distribution: its fields are {}",
                    allowed[1..].join(", ")
                ),
            ));
        }
        let number = |k: &str| -> Result<Option<f64>> {
            match t.get(k) {
                None => Ok(None),
                Some(v) => {
                    let x = v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
                    match x {
                        Some(x) if x.is_finite() => Ok(Some(x)),
                        _ => Err(Error::invalid(
                            format!("{field}.{k}"),
                            format!("must be a finite number, got {v}"),
                        )),
                    }
                }
            }
        };
        let required = |k: &str| -> Result<f64> {
            number(k)?.ok_or_else(|| {
                Error::invalid(
                    format!("{field}.{k}"),
                    format!(
                        "missing: a {kind} distribution needs {}",
                        allowed[1..].join(", ")
                    ),
                )
            })
        };
        let positive = |k: &str, x: f64| -> Result<f64> {
            if x < 0.0 {
                Err(Error::invalid(
                    format!("{field}.{k}"),
                    format!("must be ≥ 0, got {x}"),
                ))
            } else {
                Ok(x)
            }
        };
        let bounds = || -> Result<(f64, f64)> {
            let min = number("min")?.unwrap_or(f64::NEG_INFINITY);
            let max = number("max")?.unwrap_or(f64::INFINITY);
            if min >= max {
                return Err(Error::invalid(
                    format!("{field}.max"),
                    format!("must be above min = {min}, got {max}"),
                ));
            }
            Ok((min, max))
        };
        let d = match kind {
            "uniform" => {
                let (low, high) = (required("low")?, required("high")?);
                if low >= high {
                    return Err(Error::invalid(
                        format!("{field}.high"),
                        format!("must be above low = {low}, got {high}"),
                    ));
                }
                Distribution::Uniform { low, high }
            }
            "normal" => {
                let mean = required("mean")?;
                let std = positive("std", required("std")?)?;
                let (min, max) = bounds()?;
                Distribution::Normal {
                    mean,
                    std,
                    min,
                    max,
                }
            }
            "log_normal" => {
                let (min, max) = bounds()?;
                let (mu, sigma) = match (number("median")?, number("sigma")?) {
                    (Some(median), Some(sigma))
                        if t.get("mean").is_none() && t.get("std").is_none() =>
                    {
                        if median <= 0.0 {
                            return Err(Error::invalid(
                                format!("{field}.median"),
                                format!("must be > 0, got {median}"),
                            ));
                        }
                        (median.ln(), positive("sigma", sigma)?)
                    }
                    (None, None) if t.get("mean").is_some() || t.get("std").is_some() => {
                        let (mean, std) = (required("mean")?, positive("std", required("std")?)?);
                        if mean <= 0.0 {
                            return Err(Error::invalid(
                                format!("{field}.mean"),
                                format!("must be > 0, got {mean}"),
                            ));
                        }
                        // σ² = ln(1 + (s/m)²), μ = ln m − σ²/2: the mean and standard
                        // deviation of X are m and s
                        let s2 = (1.0 + (std / mean).powi(2)).ln();
                        (mean.ln() - s2 / 2.0, s2.sqrt())
                    }
                    _ => {
                        return Err(Error::invalid(
                            field,
                            "a log_normal distribution takes either median and sigma (of ln X) or mean and std (of X)",
                        ));
                    }
                };
                Distribution::LogNormal {
                    mu,
                    sigma,
                    min,
                    max,
                }
            }
            _ => {
                let values = match t.get("values") {
                    Some(toml::Value::Array(v)) if !v.is_empty() => v.clone(),
                    _ => {
                        return Err(Error::invalid(
                            format!("{field}.values"),
                            "give a non-empty list of values: values = [1e-4, 2e-4] (numbers, strings or booleans)",
                        ));
                    }
                };
                let weights: Vec<f64> = match t.get("weights") {
                    None => vec![1.0; values.len()],
                    Some(toml::Value::Array(w)) => w
                        .iter()
                        .enumerate()
                        .map(|(i, v)| {
                            match v.as_float().or_else(|| v.as_integer().map(|i| i as f64)) {
                                Some(x) if x.is_finite() && x >= 0.0 => Ok(x),
                                _ => Err(Error::invalid(
                                    format!("{field}.weights[{i}]"),
                                    format!("must be a finite number ≥ 0, got {v}"),
                                )),
                            }
                        })
                        .collect::<Result<_>>()?,
                    Some(other) => {
                        return Err(Error::invalid(
                            format!("{field}.weights"),
                            format!("must be a list of numbers, got {other}"),
                        ));
                    }
                };
                if weights.len() != values.len() {
                    return Err(Error::invalid(
                        format!("{field}.weights"),
                        format!(
                            "has {} weights for {} values: give one weight per value",
                            weights.len(),
                            values.len()
                        ),
                    ));
                }
                let total: f64 = weights.iter().sum();
                if total <= 0.0 || !total.is_finite() {
                    return Err(Error::invalid(
                        format!("{field}.weights"),
                        "must add up to more than 0: give at least one positive weight",
                    ));
                }
                let mut sum = 0.0;
                let mut cumulative: Vec<f64> = weights
                    .iter()
                    .map(|w| {
                        sum += w;
                        sum / total
                    })
                    .collect();
                if let Some(last) = cumulative.last_mut() {
                    *last = 1.0;
                }
                Distribution::Discrete { values, cumulative }
            }
        };
        let kept = d.kept();
        if kept < MIN_KEPT {
            return Err(Error::invalid(
                format!("{field}.min"),
                format!(
                    "min and max keep only {kept:.1e} of the distribution (at least {MIN_KEPT} needed): widen them, or use a uniform distribution"
                ),
            ));
        }
        Ok(d)
    }

    /// Probability of the untruncated distribution inside the bounds (approximate, `|error|` <
    /// 1.2·10⁻⁷: [`normal_cdf`]); 1 for the others.
    fn kept(&self) -> f64 {
        match *self {
            Distribution::Normal {
                mean,
                std,
                min,
                max,
            } => {
                if std == 0.0 {
                    return if (min..=max).contains(&mean) {
                        1.0
                    } else {
                        0.0
                    };
                }
                normal_cdf((max - mean) / std) - normal_cdf((min - mean) / std)
            }
            Distribution::LogNormal {
                mu,
                sigma,
                min,
                max,
            } => {
                let z = |x: f64| {
                    if x <= 0.0 {
                        f64::NEG_INFINITY
                    } else if sigma == 0.0 {
                        (x.ln() - mu).signum() * f64::INFINITY
                    } else {
                        (x.ln() - mu) / sigma
                    }
                };
                normal_cdf(z(max)) - normal_cdf(z(min))
            }
            _ => 1.0,
        }
    }

    /// One draw, from `stream`.
    pub fn draw(&self, stream: &mut Stream) -> toml::Value {
        match self {
            Distribution::Uniform { low, high } => {
                toml::Value::Float(low + (high - low) * stream.uniform())
            }
            Distribution::Normal {
                mean,
                std,
                min,
                max,
            } => toml::Value::Float(truncated(|| mean + std * stream.normal(), *min, *max)),
            Distribution::LogNormal {
                mu,
                sigma,
                min,
                max,
            } => toml::Value::Float(truncated(
                || (mu + sigma * stream.normal()).exp(),
                *min,
                *max,
            )),
            Distribution::Discrete { values, cumulative } => {
                let u = stream.uniform();
                let i = cumulative
                    .partition_point(|&c| c <= u)
                    .min(values.len() - 1);
                values[i].clone()
            }
        }
    }
}

/// A draw of `draw` inside `[min, max]`, by rejection.
fn truncated(mut draw: impl FnMut() -> f64, min: f64, max: f64) -> f64 {
    let mut x = draw();
    for _ in 1..MAX_TRIES {
        if (min..=max).contains(&x) {
            return x;
        }
        x = draw();
    }
    x.clamp(min, max)
}

/// Standard normal CDF `Φ(z) = erfc(−z/√2)/2`, with the Chebyshev approximation of erfc of
/// Press et al., *Numerical Recipes* §6.2 (fractional error below 1.2·10⁻⁷): used to check
/// truncation bounds only.
pub fn normal_cdf(z: f64) -> f64 {
    if z.is_nan() {
        return f64::NAN;
    }
    let x = -z / std::f64::consts::SQRT_2;
    let a = x.abs();
    let t = 1.0 / (1.0 + 0.5 * a);
    let y = t
        * (-a * a - 1.265_512_23
            + t * (1.000_023_68
                + t * (0.374_091_96
                    + t * (0.096_784_18
                        + t * (-0.186_288_06
                            + t * (0.278_868_07
                                + t * (-1.135_203_98
                                    + t * (1.488_515_87
                                        + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
            .exp();
    let erfc = if x >= 0.0 { y } else { 2.0 - y };
    erfc / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_cdf_matches_known_values() {
        // Φ(0) = 1/2, Φ(1.959964) = 0.975, Φ(−1) = 0.158655254
        assert!((normal_cdf(0.0) - 0.5).abs() < 1e-7);
        assert!((normal_cdf(1.959_963_985) - 0.975).abs() < 1e-7);
        assert!((normal_cdf(-1.0) - 0.158_655_254).abs() < 1e-7);
        assert_eq!(normal_cdf(f64::INFINITY), 1.0);
        assert_eq!(normal_cdf(f64::NEG_INFINITY), 0.0);
    }
}
