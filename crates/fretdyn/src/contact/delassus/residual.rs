//! The natural-map residual of the tangential problem (THEORY §4.2), the one measure of every
//! solver's answer: 0 exactly when `λ` satisfies Coulomb's law at every closed contact.

use nalgebra::Vector2;

use super::problem::{Slot, TangentialProblem};
use crate::contact::friction::Slide;

impl TangentialProblem {
    /// Natural-map residual of the tangential problem (THEORY §4.2), the same measure for
    /// every solver: per contact `r_i = λ_i − proj_{disk(s_i)}(λ_i + ρ_i w_i)` with
    /// `w = b − Hλ` (the slip velocity over θΔt, along which a sliding λ points),
    /// `ρ_i = 2/tr(H_ii)` and `s_i` the static threshold of a sticking contact, the dynamic one
    /// of a sliding contact; it is 0 exactly when λ satisfies Coulomb's law. Returned as
    /// `‖r‖ / max(‖λ‖, max_i s_i)`, relative to the friction forces at stake.
    pub fn natural_map_residual(&self, lambda: &[Vector2<f64>], slide: &[Slide]) -> f64 {
        self.natural_map_residual_given(lambda, slide, |_| None)
    }

    /// [`Self::natural_map_residual`] of a single contact whose local right-hand side
    /// (`b`, or the one its last sweep recorded) is `c` (`SINGULAR`: [`slot_residual`]).
    #[inline(always)]
    fn single_residual<const SINGULAR: bool>(
        &self,
        lambda: Vector2<f64>,
        c: Vector2<f64>,
        slide: Slide,
    ) -> f64 {
        let block = self.diagonal_block(0);
        let slot = &self.slots[0];
        let (r2, l2) =
            slot_residual::<SINGULAR>(lambda, c - block.h * lambda, block.rho(), slot, slide);
        relative_residual(0.0 + r2, 0.0 + l2, 0.0f64.max(slot.s_static))
    }

    /// [`Self::natural_map_residual_after_sweep`] of a single closed contact whose sweep
    /// found `lambda` with status `slide`, its block regular ([`Self::may_be_singular`]
    /// false): the same operations, inlined into the caller (the common case of a rattling
    /// structure, at every step with a closed contact).
    #[inline(always)]
    pub fn single_residual_after_sweep(&self, lambda: Vector2<f64>, slide: Slide) -> f64 {
        let [c, _] = self.sweep[0].get();
        self.single_residual::<false>(lambda, c, slide)
    }

    /// Records slot `k`'s local solve in a Gauss–Seidel sweep: its right-hand side `c_k`
    /// (the other contacts' λ as they were then) and the change of its `λ_k`.
    #[inline]
    pub(crate) fn record_sweep(&self, k: usize, rhs: Vector2<f64>, change: Vector2<f64>) {
        self.sweep[k].set([rhs, change]);
    }

    /// [`Self::natural_map_residual`] at the end of a Gauss–Seidel sweep whose every local
    /// solve was recorded ([`Self::record_sweep`]), without forming `Hλ` again: slot `k`'s
    /// right-hand side saw the new λ of the slots before it and the old λ of those after it,
    /// so `w_k = c_k − H_kk λ_k − Σ_{j>k} H_kj Δλ_j` (exactly `w_k` of
    /// [`Self::residual_velocity`] up to the order of the sums; for a single contact, the
    /// same operations).
    pub fn natural_map_residual_after_sweep(
        &self,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
    ) -> f64 {
        self.natural_map_residual_after_sweep_with::<true>(lambda, slide)
    }

    /// [`Self::natural_map_residual_after_sweep`]; `!SINGULAR` when no block is singular
    /// ([`Self::may_be_singular`], [`slot_residual`]).
    #[inline(always)]
    pub(crate) fn natural_map_residual_after_sweep_with<const SINGULAR: bool>(
        &self,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
    ) -> f64 {
        let m = self.slots.len().min(lambda.len());
        if m == 1 {
            // a single contact (the common case), without the loops: the same operations
            let [c, _] = self.sweep[0].get();
            return self.single_residual::<SINGULAR>(lambda[0], c, slide[0]);
        }
        self.natural_map::<SINGULAR>(lambda, slide, |k| {
            let [c, _] = self.sweep[k].get();
            let mut w = c - self.diagonal_block(k).h * lambda[k];
            for j in k + 1..m {
                w -= self.block(k, j) * self.sweep[j].get()[1];
            }
            w
        })
    }

    /// [`Self::natural_map_residual`] with contact `k`'s local right-hand side
    /// `c_k = b_k − Σ_{l≠k} H_kl λ_l` given by `rhs(k)` where it is known (`Some`): a solver
    /// that formed it from the final λ passes it rather than have it formed again; the same
    /// operations, so the same bits.
    pub fn natural_map_residual_given(
        &self,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
        rhs: impl Fn(usize) -> Option<Vector2<f64>>,
    ) -> f64 {
        self.natural_map_residual_given_with::<true>(lambda, slide, rhs)
    }

    /// [`Self::natural_map_residual_given`]; `!SINGULAR` when no block is singular
    /// ([`Self::may_be_singular`], [`slot_residual`]).
    #[inline(always)]
    pub(crate) fn natural_map_residual_given_with<const SINGULAR: bool>(
        &self,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
        rhs: impl Fn(usize) -> Option<Vector2<f64>>,
    ) -> f64 {
        if self.slots.len() == 1 && !lambda.is_empty() {
            // a single contact (the common case), without the loops: the same operations
            return self.single_residual::<SINGULAR>(lambda[0], self.rhs(0), slide[0]);
        }
        self.natural_map::<SINGULAR>(lambda, slide, |k| match rhs(k) {
            Some(c) => c - self.diagonal_block(k).h * lambda[k],
            None => self.residual_velocity(k, lambda),
        })
    }

    /// The natural-map residual with the residual velocities `w(k) = (b − Hλ)_k`.
    #[inline]
    fn natural_map<const SINGULAR: bool>(
        &self,
        lambda: &[Vector2<f64>],
        slide: &[Slide],
        w: impl Fn(usize) -> Vector2<f64>,
    ) -> f64 {
        let mut r2 = 0.0;
        let mut l2 = 0.0;
        let mut s_max = 0.0f64;
        for (k, slot) in self.slots.iter().enumerate() {
            let (r, l) = slot_residual::<SINGULAR>(
                lambda[k],
                w(k),
                self.diagonal_block(k).rho(),
                slot,
                slide[k],
            );
            r2 += r;
            l2 += l;
            s_max = s_max.max(slot.s_static);
        }
        relative_residual(r2, l2, s_max)
    }
}

/// One slot's terms of the natural-map residual ([`TangentialProblem::natural_map_residual`]):
/// `(|λ − proj_{disk(s)}(λ + ρ w)|², |λ|²)` for its `λ`, residual velocity `w`, `ρ` and status.
/// `SINGULAR`: a zero block's `ρ = ∞` is taken as its limit ([`zero_block_residual`]);
/// without it (no block singular, [`TangentialProblem::may_be_singular`]) `ρ` is finite.
#[inline(always)]
fn slot_residual<const SINGULAR: bool>(
    lambda: Vector2<f64>,
    w: Vector2<f64>,
    rho: f64,
    slot: &Slot,
    slide: Slide,
) -> (f64, f64) {
    let s = match slide {
        Slide::Stick => slot.s_static,
        Slide::Slip => slot.s_dynamic,
    };
    if SINGULAR && !(rho < f64::INFINITY) {
        return zero_block_residual(lambda, w, s);
    }
    let z = lambda + w * rho;
    let n2 = z.norm_squared();
    let projected = if n2 > s * s { z * (s / n2.sqrt()) } else { z };
    ((lambda - projected).norm_squared(), lambda.norm_squared())
}

/// [`slot_residual`] of a zero block (`ρ = ∞`, [`DiagonalBlock::rho`]): the natural map's
/// limit `proj_{disk(s)}(λ + ρ w) → s w/|w|` when `w ≠ 0`, `proj(λ)` when `w = 0` — the
/// residual is 0 exactly for Coulomb's solutions, `λ = s w/|w|` or `w = 0`, `|λ| ≤ s`.
#[cold]
#[inline(never)]
fn zero_block_residual(lambda: Vector2<f64>, w: Vector2<f64>, s: f64) -> (f64, f64) {
    let nw = w.norm();
    let projected = if nw > 0.0 {
        w * (s / nw)
    } else {
        let nl = lambda.norm();
        if nl > s { lambda * (s / nl) } else { lambda }
    };
    ((lambda - projected).norm_squared(), lambda.norm_squared())
}

/// `‖r‖ / max(‖λ‖, max_i s_i)` from the sums of squares (0 when both are 0).
#[inline(always)]
fn relative_residual(r2: f64, l2: f64, s_max: f64) -> f64 {
    let scale = l2.sqrt().max(s_max);
    if scale > 0.0 { r2.sqrt() / scale } else { 0.0 }
}
