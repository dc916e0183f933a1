//! A load's history evaluated along the steps of a run, `t_n = n Δt`, without a sine per step
//! (THEORY §10).
//!
//! A harmonic history, or a sum of sines, is `Σ_k a_k sin(θ_k(n))`, `θ_k(n) = ω_k t_n + φ_k`.
//! From one step to the next each angle turns by the same `α_k = ω_k Δt`, so the pair
//! `(s, c) = (sin θ, cos θ)` is rotated:
//!
//! ```text
//! s' = s + (a s + b c),   c' = c + (a c − b s),   a = cos α − 1 = −2 sin²(α/2),   b = sin α
//! ```
//!
//! (`a` formed without the cancellation of `cos α − 1`): four products and four sums instead
//! of a `sin` (about 90 instructions and the longest latency of a small step). The rotation
//! adds a rounding error of a few `ε` per step; every [`ANCHOR_STEPS`] steps the pair is
//! formed again from `sin` and `cos` of the angle computed as [`TimeHistory::value`] computes
//! it: there the values are exactly the direct ones, and their error against the sine of the
//! exact angle is at most the direct evaluation's own (the rounding of `ω t`, which grows with
//! `t`) plus `4 ε · ANCHOR_STEPS` (the tests below). The value at step `n` is a
//! function of `n` only: a run resumed from a checkpoint, or stepped one step at a time, gives
//! the same bits as one run through (a step that does not follow the previous one starts from
//! its anchor, `n − n mod ANCHOR_STEPS`).
//!
//! Constant and tabulated histories are evaluated directly.

use std::f64::consts::TAU;

use super::TimeHistory;

/// Steps between two exact evaluations of a rotated sine (module documentation).
pub const ANCHOR_STEPS: u64 = 1024;

/// One term `amplitude · sin(ω t + φ)` and its pair `(sin, cos)` at the current step.
#[derive(Debug, Clone, Copy)]
struct Rotor {
    amplitude: f64,
    frequency_hz: f64,
    phase: f64,
    /// `cos α − 1`, `α = ω Δt`.
    a: f64,
    /// `sin α`.
    b: f64,
    s: f64,
    c: f64,
}

impl Rotor {
    fn new(amplitude: f64, frequency_hz: f64, phase: f64, dt: f64) -> Self {
        let alpha = TAU * frequency_hz * dt;
        let half = (0.5 * alpha).sin();
        Self {
            amplitude,
            frequency_hz,
            phase,
            a: -2.0 * half * half,
            b: alpha.sin(),
            s: 0.0,
            c: 1.0,
        }
    }

    /// The pair at time `t`, from the angle formed as [`TimeHistory::value`] forms it.
    #[inline]
    fn anchor(&mut self, t: f64) {
        (self.s, self.c) = (TAU * self.frequency_hz * t + self.phase).sin_cos();
    }

    /// One step on.
    #[inline(always)]
    fn turn(&mut self) {
        let (s, c) = (self.s, self.c);
        self.s = s + (self.a * s + self.b * c);
        self.c = c + (self.a * c - self.b * s);
    }
}

/// How a history is evaluated along the steps.
#[derive(Debug, Clone)]
enum Terms {
    /// Directly at each step (constant, table).
    Direct,
    /// A harmonic history: one rotated sine.
    One(Rotor),
    /// A sum of sines: one rotated sine per term.
    Many(Vec<Rotor>),
}

/// A [`TimeHistory`] evaluated at the steps `t_n = n Δt` of a run (module documentation).
#[derive(Debug, Clone)]
pub struct SteppedHistory<'a> {
    history: &'a TimeHistory,
    dt: f64,
    terms: Terms,
    /// The step the rotated sines are at.
    at: Option<u64>,
}

impl<'a> SteppedHistory<'a> {
    /// `history` at the steps of a run with time step `dt`.
    pub fn new(history: &'a TimeHistory, dt: f64) -> Self {
        let terms = match history {
            TimeHistory::Harmonic {
                frequency_hz,
                phase,
            } => Terms::One(Rotor::new(1.0, *frequency_hz, *phase, dt)),
            TimeHistory::Sines(sines) => Terms::Many(
                sines
                    .iter()
                    .map(|s| Rotor::new(s.amplitude, s.frequency_hz, s.phase, dt))
                    .collect(),
            ),
            TimeHistory::Constant | TimeHistory::Table { .. } => Terms::Direct,
        };
        Self {
            history,
            dt,
            terms,
            at: None,
        }
    }

    /// The value at step `n`, time `t = n Δt` (as the step forms it: `n as f64 * Δt`).
    #[inline(always)]
    pub fn value(&mut self, n: u64, t: f64) -> f64 {
        let follows = self.at.is_some_and(|m| m + 1 == n) && !n.is_multiple_of(ANCHOR_STEPS);
        // (a harmonic history's one sine apart: as a slice of one, its loop costs ~35
        // instructions per step)
        let value = match &mut self.terms {
            Terms::Direct => return self.history.value(t),
            Terms::One(r) => {
                if follows {
                    r.turn();
                } else {
                    Self::move_to(std::slice::from_mut(r), n, self.dt);
                }
                r.amplitude * r.s
            }
            Terms::Many(rotors) => {
                if follows {
                    rotors.iter_mut().for_each(Rotor::turn);
                } else {
                    Self::move_to(rotors, n, self.dt);
                }
                rotors.iter().map(|r| r.amplitude * r.s).sum()
            }
        };
        self.at = Some(n);
        value
    }

    /// The pairs at step `n`: from the anchor at or before it, turned to it.
    #[cold]
    fn move_to(rotors: &mut [Rotor], n: u64, dt: f64) {
        let anchor = n - n % ANCHOR_STEPS;
        for r in rotors {
            r.anchor(anchor as f64 * dt);
            for _ in anchor..n {
                r.turn();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loads::Sine;

    /// Largest differences from `sin` of the exact angle, over `steps` steps in order, of the
    /// stepped and of the direct evaluations of `Σ a_k sin(2π f_k t + φ_k)`. `f_k Δt` must be
    /// exact in binary (the reference reduces `f_k t` modulo 1 without error).
    fn errors(terms: &[(f64, f64, f64)], dt: f64, steps: u64) -> (f64, f64) {
        let sines = terms
            .iter()
            .map(|&(amplitude, frequency_hz, phase)| Sine {
                amplitude,
                frequency_hz,
                phase,
            })
            .collect();
        let history = TimeHistory::Sines(sines);
        let mut stepped = SteppedHistory::new(&history, dt);
        let (mut stepped_error, mut direct_error) = (0.0_f64, 0.0_f64);
        for n in 0..steps {
            let t = n as f64 * dt;
            let exact: f64 = terms
                .iter()
                .map(|&(a, f, phase)| a * (TAU * (f * t).fract() + phase).sin())
                .sum();
            stepped_error = stepped_error.max((stepped.value(n, t) - exact).abs());
            direct_error = direct_error.max((history.value(t) - exact).abs());
        }
        (stepped_error, direct_error)
    }

    #[test]
    fn a_rotated_sine_is_as_accurate_as_the_direct_one() {
        // 20 Hz at Δt = 2⁻¹⁴ s (α = 7.7e-3 rad per step, 12 s) and 1 kHz at 2⁻¹² s (α = 1.5 rad)
        for (f, dt, phase) in [(20.0, 2f64.powi(-14), 0.0), (1.0e3, 2f64.powi(-12), 0.7)] {
            let (stepped, direct) = errors(&[(1.0, f, phase)], dt, 200_000);
            // the direct value's error is the rounding of its angle (|θ| up to 3e5 rad here:
            // 5e-11), which the anchors share; the rotation adds a few ε per step between
            // two anchors, ~1e-13 at most: a wrong rotation would give errors of order 1
            assert!(
                stepped <= direct + (ANCHOR_STEPS as f64) * 4.0 * f64::EPSILON,
                "f = {f} Hz: stepped {stepped:e}, direct {direct:e}"
            );
        }
    }

    #[test]
    fn a_rotated_sum_of_sines_is_as_accurate_as_the_direct_one() {
        let terms = [(2.0, 5.0, 0.1), (-0.5, 333.0, -1.2)];
        let (stepped, direct) = errors(&terms, 2f64.powi(-16), 100_000);
        assert!(
            stepped <= direct + 2.5 * (ANCHOR_STEPS as f64) * 4.0 * f64::EPSILON,
            "stepped {stepped:e}, direct {direct:e}"
        );
    }

    #[test]
    fn the_anchors_are_the_direct_values() {
        let h = TimeHistory::Harmonic {
            frequency_hz: 37.0,
            phase: 0.3,
        };
        let dt = 3.3e-5;
        let mut stepped = SteppedHistory::new(&h, dt);
        for n in 0..5 * ANCHOR_STEPS + 1 {
            let t = n as f64 * dt;
            let v = stepped.value(n, t);
            if n % ANCHOR_STEPS == 0 {
                assert_eq!(v.to_bits(), h.value(t).to_bits(), "step {n}");
            }
        }
    }

    #[test]
    fn a_value_depends_on_its_step_only() {
        // resumed at any step, or a step skipped, gives the bits of the run through
        let h = TimeHistory::Sines(vec![
            Sine {
                amplitude: 1.0,
                frequency_hz: 20.0,
                phase: 0.0,
            },
            Sine {
                amplitude: 0.25,
                frequency_hz: 71.0,
                phase: 2.0,
            },
        ]);
        let dt = 1e-4;
        let mut through = SteppedHistory::new(&h, dt);
        let all: Vec<f64> = (0..3000).map(|n| through.value(n, n as f64 * dt)).collect();
        for start in [1, 500, 1023, 1024, 1025, 2999] {
            let mut resumed = SteppedHistory::new(&h, dt);
            for n in start..3000 {
                let v = resumed.value(n, n as f64 * dt);
                assert_eq!(
                    v.to_bits(),
                    all[n as usize].to_bits(),
                    "from {start}, step {n}"
                );
            }
        }
    }

    #[test]
    fn constant_and_table_histories_are_direct() {
        let table = TimeHistory::Table {
            times: vec![0.0, 1.0],
            values: vec![0.0, 2.0],
        };
        let mut stepped = SteppedHistory::new(&table, 0.1);
        assert_eq!(stepped.value(3, 0.3), table.value(0.3));
        let mut constant = SteppedHistory::new(&TimeHistory::Constant, 0.1);
        assert_eq!(constant.value(7, 0.7), 1.0);
    }
}
