//! The kernels' contract: the [`Lanes`] trait, the reductions over the modes that the time
//! step runs every step — the dot products of detection, of the contacts' velocities and of
//! `b` (THEORY §2, §3), and the energy balance's sums fused with the velocity update
//! (THEORY §5) — and the order in which every implementation sums ([`super::Portable`],
//! [`super::Avx2`], chosen once per run,
//! [`crate::integrator::simulation::Simulation::step`]).
//!
//! Both sum in four lanes: lane `k` accumulates the terms `i ≡ k (mod 4)` of the whole chunks
//! of four, in order; the remaining `r < 4` terms are then added to lanes `0..r` and, when
//! `r > 0`, `+0` to the others (one vector operation on the tail loaded with zeros after it:
//! it changes a lane's `−0` into `+0`, nothing else); the result is `(s₀ + s₁) + (s₂ + s₃)`.
//! Each lane does the same multiplications and additions in the same
//! order in both implementations (no fused multiply-add), so they agree bit for bit
//! (tested in `avx2.rs` and in `tests/vector_width.rs`). The compiler does not turn such four-lane
//! sums into clean vector code by itself, hence the intrinsics.

use super::padded::PaddedRows;

/// A set of reduction kernels (see the module's documentation).
///
/// # Safety of [`Avx2`](super::Avx2)
///
/// Its methods run AVX2 instructions: they may be called only on a processor that has AVX2
/// (the step loop instantiates them only after checking, at run time).
pub(crate) trait Lanes: Copy {
    /// `a·b`.
    fn dot(a: &[f64], b: &[f64]) -> f64;
    /// `(a·b, a·c)` in one pass over `a`.
    fn dot2(a: &[f64], b: &[f64], c: &[f64]) -> (f64, f64);
    /// `out_r = A_r·x` for the rows `A_r` of the row-major matrix `a` (`x.len()` values per
    /// row, `out.len()` rows), each summed exactly as [`Self::dot`] sums it: one pass over `x`
    /// serves four rows.
    fn dots(a: &[f64], x: &[f64], out: &mut [f64]);
    /// [`Self::dots`] on rows laid out by [`PaddedRows`] (`x` of the rows' length `p`; all 0
    /// when it is shorter): `out[r] = A_r·x` for `r` below both `out.len()` and the number of
    /// rows (`out`'s other values are left as they are), each summed exactly as [`Self::dot`]
    /// sums it. The zeros after each row let the AVX2 code read
    /// `x`'s last `p mod 4` values once for all rows, and it adds the lanes of four rows at
    /// a time in one pass.
    fn padded_dots(a: &PaddedRows, x: &[f64], out: &mut [f64]);
    /// `y_i += a x_i` (slices of equal length; elementwise, so every width gives the same
    /// bits): the contact forces added to the modal force, the loads, `q̈ −= A⁻¹Lᵀλ`.
    fn axpy(y: &mut [f64], a: f64, x: &[f64]);
    /// `y_i = a x_i` (slices of equal length; elementwise).
    fn scale(y: &mut [f64], a: f64, x: &[f64]);
    /// Steps 1–2 of central differences: `q_i += Δt v_i + (h Δt) a_i`, `vs_i = v_i + h a_i`
    /// (slices of equal length; elementwise, so every width gives the same bits).
    fn predict(q: &mut [f64], vs: &mut [f64], v: &[f64], a: &[f64], dt: f64, h: f64);
    /// [`Self::predict`] and, in the same pass, [`Self::scale`] `f_i = s g_i` (the first load's
    /// modal force: one pass over the modes instead of two; slices of equal length).
    #[allow(clippy::too_many_arguments)]
    fn predict_and_scale(
        q: &mut [f64],
        vs: &mut [f64],
        v: &[f64],
        a: &[f64],
        dt: f64,
        h: f64,
        f: &mut [f64],
        s: f64,
        g: &[f64],
    );
    /// Step 5: `out_i = ai_i ((f_i − w2_i q_i) − c_i vs_i)` (slices of equal length).
    #[allow(clippy::too_many_arguments)]
    fn free_acceleration(
        out: &mut [f64],
        ai: &[f64],
        f: &[f64],
        w2: &[f64],
        q: &[f64],
        c: &[f64],
        vs: &[f64],
    );
    /// [`Self::free_acceleration`] of the force `f_i + s x_i`, not formed: `out_i = ai_i
    /// (((f_i + s x_i) − w2_i q_i) − c_i vs_i)`, the bits of [`Self::axpy`] into a copy of `f`
    /// then [`Self::free_acceleration`] (a step's modal force with one closed contact in one
    /// pass over the modes instead of three; slices of equal length).
    #[allow(clippy::too_many_arguments)]
    fn free_acceleration_plus(
        out: &mut [f64],
        ai: &[f64],
        f: &[f64],
        s: f64,
        x: &[f64],
        w2: &[f64],
        q: &[f64],
        c: &[f64],
        vs: &[f64],
    );
    /// Writes `v_i = vs_i + h a_i` to `v` and returns `(½ Σ (v_i² + w2_i q_i²), Σ c_i v_i²,
    /// Σ f_i v_i)`: the velocity update of central differences with the structure's energy,
    /// its damping power and the power of the force `f` (slices of equal length).
    #[allow(clippy::too_many_arguments)]
    fn correct_with_energy(
        v: &mut [f64],
        vs: &[f64],
        a: &[f64],
        h: f64,
        q: &[f64],
        w2: &[f64],
        c: &[f64],
        f: &[f64],
    ) -> (f64, f64, f64);
}

/// `(s₀ + s₁) + (s₂ + s₃)`: the four lanes of a sum added pairwise (module documentation).
#[inline(always)]
pub(super) fn combine(s: [f64; 4]) -> f64 {
    (s[0] + s[1]) + (s[2] + s[3])
}

/// The tail's `+0` on the lanes `r..4` of each sum, when `r > 0` (module documentation).
#[inline(always)]
pub(super) fn masked_zeros(sums: &mut [&mut [f64; 4]], r: usize) {
    if r > 0 {
        for s in sums.iter_mut() {
            for lane in s[r..].iter_mut() {
                *lane += 0.0;
            }
        }
    }
}

/// Values of many magnitudes and signs, so that the rounding of every lane is exercised (the
/// kernels' tests).
#[cfg(test)]
pub(super) fn values(n: usize, seed: u64) -> Vec<f64> {
    let mut x = seed.wrapping_mul(0x9e3779b97f4a7c15) | 1;
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let m = (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            m * 10f64.powi((x % 13) as i32 - 6)
        })
        .collect()
}
