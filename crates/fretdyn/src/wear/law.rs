//! Wear laws: the worn volume of one body (the tube, or its support) from the wear work rate
//! `W = (1/T)∫|R_T·v_T| dt` of its contact (THEORY §5) and the service time `t`
//! (`docs/THEORY.md §14`, `docs/WEAR.md`).

use crate::error::{Error, Result, number};

/// How the worn volume of one body grows with the wear work rate `W` (W) and the service time
/// `t` (s). Every law gives a rate `dV/dt = f(W, t)` ≥ 0; at constant `W` it integrates in
/// closed form ([`WearLaw::volume`], [`WearLaw::volume_increment`]), so that a service-life
/// loop that holds `W` constant over each life step `[t0, t1]` adds exactly
/// `∫_{t0}^{t1} f(W, t) dt` (`docs/THEORY.md §14`).
#[derive(Debug, Clone, PartialEq)]
pub enum WearLaw {
    /// Archard's law in its energy form, `V = K W t`: the worn volume is proportional to the
    /// friction work. `K` (Pa⁻¹ = m³/J) is the wear coefficient of this body against the other.
    Archard {
        /// `K`, m³/J.
        coefficient: f64,
    },
    /// EDF's law with a rate that decays from `A W^B` towards the threshold `s A W^B` with the
    /// service time (running-in): `dV/dt = V̇₀ [s + (1 − s) e^{−N t}]`, `V̇₀ = A W^B`, hence
    /// at constant `W` `V(t) = V̇₀ [s t + (1 − s)(1 − e^{−N t})/N]`. `s = 1` (or `N = 0`) is a
    /// power law without decay; `B = 1, s = 1` is Archard with `K = A`.
    Decaying {
        /// `A`, m³/s per W^B.
        a: f64,
        /// `B`, dimensionless.
        b: f64,
        /// `s`, the asymptotic fraction of the initial rate, in [0, 1].
        s: f64,
        /// `N`, the decay rate of the running-in, 1/s.
        n: f64,
    },
    /// A measured table of the volume rate against the work rate, `V̇(W)`, piecewise linear
    /// between its points (work rates strictly increasing, rates ≥ 0). Below the first point
    /// it is linear from `(0, 0)` (no work, no wear); above the last it is proportional,
    /// `V̇ = V̇_last W / W_last` (Archard through the last point). No dependence on `t`:
    /// `V = V̇(W) t`.
    Table {
        /// `W` at the points, W.
        work_rate: Vec<f64>,
        /// `V̇` at the points, m³/s.
        volume_rate: Vec<f64>,
    },
}

impl WearLaw {
    /// Checks the coefficients; `field` names the law in errors (e.g.
    /// `contacts[0].wear.tube`), each error naming the key as written in a case file.
    pub fn validate(&self, field: &str) -> Result<()> {
        let bad =
            |key: &str, message: String| Err(Error::invalid(format!("{field}.{key}"), message));
        match self {
            WearLaw::Archard { coefficient } => {
                if !(coefficient.is_finite() && *coefficient >= 0.0) {
                    return bad(
                        "coefficient",
                        format!(
                            "must be a wear coefficient ≥ 0 in Pa⁻¹ = m³/J, e.g. 20e-15 (got {})",
                            number(*coefficient)
                        ),
                    );
                }
            }
            WearLaw::Decaying { a, b, s, n } => {
                if !(a.is_finite() && *a >= 0.0) {
                    return bad(
                        "a",
                        format!("must be ≥ 0, in m³/s per W^b (got {})", number(*a)),
                    );
                }
                if !b.is_finite() {
                    return bad("b", format!("must be a finite exponent (got {b})"));
                }
                if !(0.0..=1.0).contains(s) {
                    return bad(
                        "s",
                        format!(
                            "must be the asymptotic fraction of the initial rate, in [0, 1] (got {})",
                            number(*s)
                        ),
                    );
                }
                if !(n.is_finite() && *n >= 0.0) {
                    return bad(
                        "n",
                        format!("must be a decay rate ≥ 0 in 1/s (got {})", number(*n)),
                    );
                }
            }
            WearLaw::Table {
                work_rate,
                volume_rate,
            } => {
                if work_rate.is_empty() || work_rate.len() != volume_rate.len() {
                    return bad(
                        "volume_rate",
                        format!(
                            "must have one value per work_rate, and at least one (got {} work rates, {} volume rates)",
                            work_rate.len(),
                            volume_rate.len()
                        ),
                    );
                }
                for (k, w) in work_rate.iter().enumerate() {
                    if !(w.is_finite() && *w >= 0.0) {
                        return bad(
                            &format!("work_rate[{k}]"),
                            format!("must be a work rate ≥ 0 in W (got {})", number(*w)),
                        );
                    }
                    if k > 0 && !(*w > work_rate[k - 1]) {
                        return bad(
                            &format!("work_rate[{k}]"),
                            format!(
                                "must be larger than work_rate[{}] = {}: sort the table by increasing work rate, without repeats",
                                k - 1,
                                number(work_rate[k - 1])
                            ),
                        );
                    }
                }
                if let Some(k) = volume_rate
                    .iter()
                    .position(|v| !(v.is_finite() && *v >= 0.0))
                {
                    return bad(
                        &format!("volume_rate[{k}]"),
                        format!(
                            "must be a wear rate ≥ 0 in m³/s (got {})",
                            number(volume_rate[k])
                        ),
                    );
                }
                if *work_rate.last().unwrap_or(&0.0) <= 0.0 {
                    return bad(
                        "work_rate",
                        "needs a point with a work rate > 0".to_string(),
                    );
                }
            }
        }
        Ok(())
    }

    /// `V̇₀(W)`, the rate at `t = 0` (m³/s): `K W`, `A W^B` (0 at `W = 0`), or the table.
    fn initial_rate(&self, work_rate: f64) -> f64 {
        match self {
            WearLaw::Archard { coefficient } => coefficient * work_rate,
            WearLaw::Decaying { a, b, .. } => {
                if work_rate > 0.0 {
                    a * work_rate.powf(*b)
                } else {
                    0.0
                }
            }
            WearLaw::Table {
                work_rate: w,
                volume_rate: v,
            } => interpolate(w, v, work_rate),
        }
    }

    /// The volume rate `dV/dt` (m³/s) at the work rate `work_rate` (W, ≥ 0) and the service
    /// time `service_time` (s): `K W`; `A W^B [s + (1 − s) e^{−N t}]`; `V̇(W)` of the table
    /// (`docs/THEORY.md §14`).
    pub fn volume_rate(&self, work_rate: f64, service_time: f64) -> f64 {
        let rate = self.initial_rate(work_rate);
        match self {
            WearLaw::Decaying { s, n, .. } => rate * (s + (1.0 - s) * (-n * service_time).exp()),
            _ => rate,
        }
    }

    /// The volume (m³) worn from `t = 0` to `service_time` at a constant work rate:
    /// `K W t`; `A W^B [s t + (1 − s)(1 − e^{−N t})/N]`; `V̇(W) t` (`docs/THEORY.md §14`).
    pub fn volume(&self, work_rate: f64, service_time: f64) -> f64 {
        self.volume_increment(work_rate, 0.0, service_time)
    }

    /// The volume (m³) worn over the life step `[t0, t1]` at a constant work rate, exactly:
    /// `∫_{t0}^{t1} dV/dt dt` = `K W (t1 − t0)`;
    /// `A W^B [s (t1 − t0) + (1 − s) e^{−N t0} (1 − e^{−N (t1 − t0)})/N]` (the last factor
    /// by `expm1`, `→ t1 − t0` as `N → 0`); `V̇(W) (t1 − t0)`. A service-life loop adds these
    /// increments step by step while `W` changes (`docs/THEORY.md §14`).
    pub fn volume_increment(&self, work_rate: f64, t0: f64, t1: f64) -> f64 {
        let rate = self.initial_rate(work_rate);
        let dt = t1 - t0;
        match self {
            WearLaw::Decaying { s, n, .. } => {
                // (1 − e^{−N Δt})/N, without cancellation for small N Δt
                let decayed = if *n > 0.0 {
                    -(-n * dt).exp_m1() / n
                } else {
                    dt
                };
                rate * (s * dt + (1.0 - s) * (-n * t0).exp() * decayed)
            }
            _ => rate * dt,
        }
    }
}

/// Piecewise-linear `V̇(W)` of a table (validated: `w` strictly increasing, ≥ 0, non-empty).
fn interpolate(w: &[f64], v: &[f64], x: f64) -> f64 {
    let n = w.len();
    if x <= w[0] {
        // linear from (0, 0) to the first point
        return if w[0] > 0.0 { v[0] * x / w[0] } else { v[0] };
    }
    if x >= w[n - 1] {
        return v[n - 1] * x / w[n - 1];
    }
    let k = w.partition_point(|wk| *wk <= x); // w[k-1] ≤ x < w[k]
    let (w0, w1, v0, v1) = (w[k - 1], w[k], v[k - 1], v[k]);
    v0 + (v1 - v0) * (x - w0) / (w1 - w0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn archard_is_linear_in_work_and_time() {
        let law = WearLaw::Archard { coefficient: 2e-14 };
        assert_eq!(law.volume_rate(0.5, 3.0), 1e-14);
        assert_eq!(law.volume(0.5, 4.0), 4e-14);
        assert_eq!(law.volume_increment(0.5, 1.0, 3.0), 2e-14);
    }

    #[test]
    fn table_interpolates_between_and_beyond_its_points() {
        let law = WearLaw::Table {
            work_rate: vec![1.0, 3.0],
            volume_rate: vec![2.0, 6.0],
        };
        law.validate("t").unwrap();
        assert_eq!(law.volume_rate(2.0, 0.0), 4.0);
        assert_eq!(law.volume_rate(0.5, 0.0), 1.0);
        assert_eq!(law.volume_rate(6.0, 0.0), 12.0);
        assert_eq!(law.volume(2.0, 10.0), 40.0);
    }

    #[test]
    fn decaying_without_decay_is_a_power_law() {
        let law = WearLaw::Decaying {
            a: 3.0,
            b: 2.0,
            s: 0.25,
            n: 0.0,
        };
        assert_eq!(law.volume(2.0, 5.0), 3.0 * 4.0 * 5.0);
        assert_eq!(law.volume_rate(0.0, 1.0), 0.0);
    }
}
