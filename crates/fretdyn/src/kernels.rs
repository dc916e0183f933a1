//! The reductions over the modes that the time step runs every step — the dot products of
//! detection, of the contacts' velocities and of `b` (THEORY §2, §3), and the energy balance's
//! sums fused with the velocity update (THEORY §5) — in two implementations that give the same
//! bits: portable code, and AVX2 intrinsics for x86-64 processors that have them (chosen once
//! per run, [`crate::integrator::simulation::Simulation::step`]).
//!
//! Both sum in four lanes: lane `k` accumulates the terms `i ≡ k (mod 4)` of the whole chunks
//! of four, in order; the remaining `r < 4` terms are then added to lanes `0..r` and, when
//! `r > 0`, `+0` to the others (one vector operation on the tail loaded with zeros after it:
//! it changes a lane's `−0` into `+0`, nothing else); the result is `(s₀ + s₁) + (s₂ + s₃)`.
//! Each lane does the same multiplications and additions in the same
//! order in both implementations (no fused multiply-add), so they agree bit for bit
//! (tested below and in `tests/vector_width.rs`). The compiler does not turn such four-lane
//! sums into clean vector code by itself, hence the intrinsics.

/// A set of reduction kernels (see the module's documentation).
///
/// # Safety of [`Avx2`]
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

/// `max(m, x)` for a running maximum `m` that is never NaN: `x` when `x > m`, else `m` (a NaN
/// `x` is skipped) — the value of `m.max(x)`, whose fix-up for a NaN `m` costs two more
/// instructions on x86-64, where this is one `maxsd`. (Written as a select, `if x > m`, the
/// compiler may turn the update of a field into a masked store, microcoded on some
/// processors.)
#[inline(always)]
pub(crate) fn running_max(m: f64, x: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvtsd_f64, _mm_max_sd, _mm_set_sd};
        // maxsd(x, m) = x > m ? x : m
        // SAFETY: SSE2 is part of every x86-64 processor
        unsafe { _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(x), _mm_set_sd(m))) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        m.max(x)
    }
}

/// `min(m, x)` for a running minimum `m` that is never NaN, as [`running_max`]: `x` when
/// `x < m`, else `m`.
#[inline(always)]
pub(crate) fn running_min(m: f64, x: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvtsd_f64, _mm_min_sd, _mm_set_sd};
        // minsd(x, m) = x < m ? x : m
        // SAFETY: SSE2 is part of every x86-64 processor
        unsafe { _mm_cvtsd_f64(_mm_min_sd(_mm_set_sd(x), _mm_set_sd(m))) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        m.min(x)
    }
}

/// `out_i = f(x_i, y_i, z_i)` over slices of `out`'s length: an indexed loop over slices of
/// equal length, which the compiler turns into vector operations where the same loop over
/// four zipped slices stays scalar (elementwise: the same bits either way). The rows of a
/// contact on the tube surface and its Delassus rows, formed at every step when the
/// obstacle is not a fixed plane.
#[inline(always)]
pub(crate) fn map3(
    out: &mut [f64],
    x: &[f64],
    y: &[f64],
    z: &[f64],
    f: impl Fn(f64, f64, f64) -> f64,
) {
    let n = out.len();
    let (x, y, z) = (&x[..n], &y[..n], &z[..n]);
    #[allow(clippy::needless_range_loop)] // the zipped form stays scalar
    for i in 0..n {
        out[i] = f(x[i], y[i], z[i]);
    }
}

/// Rows of `p` values laid out for [`Lanes::padded_dots`]: each row followed by zeros up to
/// `stride`, `p` rounded up to a multiple of four.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct PaddedRows {
    values: Vec<f64>,
    rows: usize,
    p: usize,
    stride: usize,
}

impl PaddedRows {
    /// The rows `rows` of `p` values each (a row of another length is cut or completed by
    /// zeros: the caller's rows have `p`).
    pub(crate) fn new<'a>(p: usize, rows: impl ExactSizeIterator<Item = &'a [f64]>) -> Self {
        let stride = p.next_multiple_of(4);
        let n = rows.len();
        let mut values = vec![0.0; stride * n];
        for (out, row) in values.chunks_exact_mut(stride.max(1)).zip(rows) {
            for (o, v) in out[..p].iter_mut().zip(row) {
                *o = *v;
            }
        }
        Self {
            values,
            rows: n,
            p,
            stride,
        }
    }

    /// The number of rows: the length of [`Lanes::padded_dots`]'s output.
    pub(crate) fn rows(&self) -> usize {
        self.rows
    }

    /// Row `r` (its `p` values).
    fn row(&self, r: usize) -> &[f64] {
        &self.values[r * self.stride..r * self.stride + self.p]
    }
}

/// Plain Rust, for every processor.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Portable;

#[inline(always)]
fn combine(s: [f64; 4]) -> f64 {
    (s[0] + s[1]) + (s[2] + s[3])
}

/// The tail's `+0` on the lanes `r..4` of each sum, when `r > 0` (module documentation).
#[inline(always)]
fn masked_zeros(sums: &mut [&mut [f64; 4]], r: usize) {
    if r > 0 {
        for s in sums.iter_mut() {
            for lane in s[r..].iter_mut() {
                *lane += 0.0;
            }
        }
    }
}

impl Lanes for Portable {
    #[inline(always)]
    fn dot(a: &[f64], b: &[f64]) -> f64 {
        let n = a.len().min(b.len());
        let (a, b) = (&a[..n], &b[..n]);
        let mut s = [0.0f64; 4];
        let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
        let (ra, rb) = (ca.remainder(), cb.remainder());
        for (x, y) in ca.zip(cb) {
            for k in 0..4 {
                s[k] += x[k] * y[k];
            }
        }
        for (k, (x, y)) in ra.iter().zip(rb).enumerate() {
            s[k] += x * y;
        }
        masked_zeros(&mut [&mut s], ra.len());
        combine(s)
    }

    #[inline(always)]
    fn dot2(a: &[f64], b: &[f64], c: &[f64]) -> (f64, f64) {
        let n = a.len().min(b.len()).min(c.len());
        let (a, b, c) = (&a[..n], &b[..n], &c[..n]);
        let (mut s, mut t) = ([0.0f64; 4], [0.0f64; 4]);
        let (ca, cb, cc) = (a.chunks_exact(4), b.chunks_exact(4), c.chunks_exact(4));
        let (ra, rb, rc) = (ca.remainder(), cb.remainder(), cc.remainder());
        for ((x, y), z) in ca.zip(cb).zip(cc) {
            for k in 0..4 {
                s[k] += x[k] * y[k];
                t[k] += x[k] * z[k];
            }
        }
        for (k, ((x, y), z)) in ra.iter().zip(rb).zip(rc).enumerate() {
            s[k] += x * y;
            t[k] += x * z;
        }
        masked_zeros(&mut [&mut s, &mut t], ra.len());
        (combine(s), combine(t))
    }

    #[inline(always)]
    fn dots(a: &[f64], x: &[f64], out: &mut [f64]) {
        let p = x.len();
        if p == 0 {
            out.fill(0.0);
            return;
        }
        for (o, row) in out.iter_mut().zip(a.chunks_exact(p)) {
            *o = Self::dot(row, x);
        }
    }

    #[inline(always)]
    fn padded_dots(a: &PaddedRows, x: &[f64], out: &mut [f64]) {
        if a.p == 0 || x.len() < a.p {
            out.fill(0.0);
            return;
        }
        for (r, o) in out.iter_mut().enumerate().take(a.rows) {
            *o = Self::dot(a.row(r), x);
        }
    }

    #[inline(always)]
    fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
        for (o, v) in y.iter_mut().zip(x) {
            *o += a * v;
        }
    }

    #[inline(always)]
    fn scale(y: &mut [f64], a: f64, x: &[f64]) {
        for (o, v) in y.iter_mut().zip(x) {
            *o = a * v;
        }
    }

    #[inline(always)]
    fn predict(q: &mut [f64], vs: &mut [f64], v: &[f64], a: &[f64], dt: f64, h: f64) {
        portable_predict::<false>(q, vs, v, a, dt, h, &mut [], 0.0, &[]);
    }

    #[inline(always)]
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
    ) {
        portable_predict::<true>(q, vs, v, a, dt, h, f, s, g);
    }

    #[inline(always)]
    fn free_acceleration(
        out: &mut [f64],
        ai: &[f64],
        f: &[f64],
        w2: &[f64],
        q: &[f64],
        c: &[f64],
        vs: &[f64],
    ) {
        let p = out.len();
        let (ai, f, w2, q, c, vs) = (&ai[..p], &f[..p], &w2[..p], &q[..p], &c[..p], &vs[..p]);
        for i in 0..p {
            out[i] = ai[i] * (f[i] - w2[i] * q[i] - c[i] * vs[i]);
        }
    }

    #[inline(always)]
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
    ) {
        let p = out.len();
        let (ai, f, x, w2) = (&ai[..p], &f[..p], &x[..p], &w2[..p]);
        let (q, c, vs) = (&q[..p], &c[..p], &vs[..p]);
        for i in 0..p {
            out[i] = ai[i] * ((f[i] + s * x[i]) - w2[i] * q[i] - c[i] * vs[i]);
        }
    }

    #[inline(always)]
    fn correct_with_energy(
        v: &mut [f64],
        vs: &[f64],
        a: &[f64],
        h: f64,
        q: &[f64],
        w2: &[f64],
        c: &[f64],
        f: &[f64],
    ) -> (f64, f64, f64) {
        let p = v.len();
        let (vs, a) = (&vs[..p], &a[..p]);
        for (i, x) in v.iter_mut().enumerate() {
            *x = vs[i] + h * a[i];
        }
        energy_sums(v, q, w2, c, f)
    }
}

/// `(½ Σ (v_i² + w2_i q_i²), Σ c_i v_i², Σ f_i v_i)` in four lanes: the structure's energy, its
/// damping power and the power of the force `f` for velocities `v` (the sums of
/// [`Lanes::correct_with_energy`], without the update).
#[inline(always)]
pub(crate) fn energy_sums(
    v: &[f64],
    q: &[f64],
    w2: &[f64],
    c: &[f64],
    f: &[f64],
) -> (f64, f64, f64) {
    let p = v.len();
    let (q, w2, c, f) = (&q[..p], &w2[..p], &c[..p], &f[..p]);
    let (mut e, mut d, mut w) = ([0.0f64; 4], [0.0f64; 4], [0.0f64; 4]);
    let full = p - p % 4;
    for i in 0..p {
        let (x, k) = (v[i], if i < full { i % 4 } else { i - full });
        e[k] += x * x + w2[i] * q[i] * q[i];
        d[k] += c[i] * x * x;
        w[k] += f[i] * x;
    }
    masked_zeros(&mut [&mut e, &mut d, &mut w], p - full);
    (0.5 * combine(e), combine(d), combine(w))
}

/// AVX2 intrinsics (x86-64 only; see the trait's safety note).
///
/// `Tag` names a copy of the large kernels (the predictor, the free acceleration, the velocity
/// update): a step compiled more than once
/// ([`crate::integrator::simulation::Simulation::steps`]) gives each of its versions its own
/// `Tag`, so that each copy has one caller and is inlined into it (a kernel with two callers
/// stays a function of its own, and the calls cost the step a few per cent).
#[cfg(target_arch = "x86_64")]
#[derive(Debug)]
pub(crate) struct Avx2<Tag = ()>(std::marker::PhantomData<Tag>);

#[cfg(target_arch = "x86_64")]
impl<Tag> Clone for Avx2<Tag> {
    fn clone(&self) -> Self {
        *self
    }
}

/// [`Portable::predict`], with [`Portable::predict_and_scale`]'s `f_i = s g_i` in the same
/// loop when `LOAD` (`f` and `g` are not read otherwise): one loop for both, as
/// `avx2::predict` is one for its two.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn portable_predict<const LOAD: bool>(
    q: &mut [f64],
    vs: &mut [f64],
    v: &[f64],
    a: &[f64],
    dt: f64,
    h: f64,
    f: &mut [f64],
    s: f64,
    g: &[f64],
) {
    let p = q.len();
    let (vs, v, a) = (&mut vs[..p], &v[..p], &a[..p]);
    let (f, g) = if LOAD { (&mut f[..p], &g[..p]) } else { (f, g) };
    let hdt = h * dt;
    for i in 0..p {
        q[i] += dt * v[i] + hdt * a[i];
        vs[i] = v[i] + h * a[i];
        if LOAD {
            f[i] = s * g[i];
        }
    }
}

#[cfg(target_arch = "x86_64")]
impl<Tag> Copy for Avx2<Tag> {}

#[cfg(target_arch = "x86_64")]
impl<Tag> Lanes for Avx2<Tag> {
    #[inline(always)]
    fn dot(a: &[f64], b: &[f64]) -> f64 {
        // SAFETY: instantiated only when the processor has AVX2 (the trait's note)
        unsafe { avx2::dot(a, b) }
    }

    #[inline(always)]
    fn dot2(a: &[f64], b: &[f64], c: &[f64]) -> (f64, f64) {
        // SAFETY: as above
        unsafe { avx2::dot2(a, b, c) }
    }

    #[inline(always)]
    fn dots(a: &[f64], x: &[f64], out: &mut [f64]) {
        // SAFETY: as above
        unsafe { avx2::dots(a, x, out) }
    }

    #[inline(always)]
    fn padded_dots(a: &PaddedRows, x: &[f64], out: &mut [f64]) {
        // SAFETY: as above
        unsafe { avx2::padded_dots(a, x, out) }
    }

    #[inline(always)]
    fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
        // SAFETY: as above
        unsafe { avx2::axpy(y, a, x) }
    }

    #[inline(always)]
    fn scale(y: &mut [f64], a: f64, x: &[f64]) {
        // SAFETY: as above
        unsafe { avx2::scale(y, a, x) }
    }

    #[inline(always)]
    fn predict(q: &mut [f64], vs: &mut [f64], v: &[f64], a: &[f64], dt: f64, h: f64) {
        // SAFETY: as above
        unsafe { avx2::predict::<Tag, false>(q, vs, v, a, dt, h, &mut [], 0.0, &[]) }
    }

    #[inline(always)]
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
    ) {
        // SAFETY: as above
        unsafe { avx2::predict::<Tag, true>(q, vs, v, a, dt, h, f, s, g) }
    }

    #[inline(always)]
    fn free_acceleration(
        out: &mut [f64],
        ai: &[f64],
        f: &[f64],
        w2: &[f64],
        q: &[f64],
        c: &[f64],
        vs: &[f64],
    ) {
        // SAFETY: as above
        unsafe { avx2::free_acceleration::<Tag, false>(out, ai, f, 0.0, f, w2, q, c, vs) }
    }

    #[inline(always)]
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
    ) {
        // SAFETY: as above
        unsafe { avx2::free_acceleration::<Tag, true>(out, ai, f, s, x, w2, q, c, vs) }
    }

    #[inline(always)]
    fn correct_with_energy(
        v: &mut [f64],
        vs: &[f64],
        a: &[f64],
        h: f64,
        q: &[f64],
        w2: &[f64],
        c: &[f64],
        f: &[f64],
    ) -> (f64, f64, f64) {
        // SAFETY: as above
        unsafe { avx2::correct_with_energy::<Tag>(v, vs, a, h, q, w2, c, f) }
    }
}

#[cfg(target_arch = "x86_64")]
// Rust 1.85 (the crate's minimum) needs `unsafe` around every intrinsic; later versions only
// around loads and stores: the blocks are kept for the former.
#[allow(unused_unsafe)]
mod avx2 {
    use std::arch::x86_64::{
        __m256d, _mm_add_sd, _mm_cvtsd_f64, _mm_hadd_pd, _mm_load_sd, _mm_loadu_pd, _mm_store_sd,
        _mm_storeu_pd, _mm_unpackhi_pd, _mm256_add_pd, _mm256_castpd256_pd128,
        _mm256_extractf128_pd, _mm256_hadd_pd, _mm256_insertf128_pd, _mm256_loadu_pd,
        _mm256_mul_pd, _mm256_permute2f128_pd, _mm256_set1_pd, _mm256_setzero_pd, _mm256_storeu_pd,
        _mm256_sub_pd, _mm256_zextpd128_pd256,
    };

    /// The `r < 4` values at `p` in the first lanes, the others `+0`: one 64-bit load, one
    /// 128-bit load or both, which read the `r` values only (a masked 256-bit load waits on
    /// its mask and is slow on some processors).
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn tail(p: *const f64, r: usize) -> __m256d {
        // SAFETY: the caller's `p..p + r` is inside a slice
        unsafe {
            match r {
                1 => _mm256_zextpd128_pd256(_mm_load_sd(p)),
                2 => _mm256_zextpd128_pd256(_mm_loadu_pd(p)),
                3 => _mm256_insertf128_pd::<1>(
                    _mm256_zextpd128_pd256(_mm_loadu_pd(p)),
                    _mm_load_sd(p.add(2)),
                ),
                _ => _mm256_setzero_pd(),
            }
        }
    }

    /// `(x₀ + x₁) + (x₂ + x₃)`, [`super::combine`] of the four lanes, in registers: one
    /// horizontal addition of the two halves, then the sum of its two lanes (a store of the
    /// vector and four scalar loads would wait on store forwarding).
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn sum(x: __m256d) -> f64 {
        let halves = _mm_hadd_pd(_mm256_castpd256_pd128(x), _mm256_extractf128_pd::<1>(x));
        _mm_cvtsd_f64(_mm_add_sd(halves, _mm_unpackhi_pd(halves, halves)))
    }

    /// Stores the first `r < 4` lanes of `x` at `p` (a 128-bit store, a 64-bit one or both:
    /// a masked 256-bit store is microcoded on some processors).
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn store_first(p: *mut f64, r: usize, x: __m256d) {
        let low = _mm256_castpd256_pd128(x);
        // SAFETY: the caller's `p..p + r` is inside a slice
        unsafe {
            match r {
                1 => _mm_store_sd(p, low),
                2 => _mm_storeu_pd(p, low),
                3 => {
                    _mm_storeu_pd(p, low);
                    _mm_store_sd(p.add(2), _mm256_extractf128_pd::<1>(x));
                }
                _ => {}
            }
        }
    }

    /// [`super::Portable::dot`] on AVX2.
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn dot(a: &[f64], b: &[f64]) -> f64 {
        let n = a.len().min(b.len());
        let full = n - n % 4;
        // SAFETY: AVX2 (the caller's guarantee); every load reads i..i + 4 ≤ full ≤ n, the
        // tail's loads full..n
        unsafe {
            let (pa, pb) = (a.as_ptr(), b.as_ptr());
            let mut acc = _mm256_setzero_pd();
            let mut i = 0;
            // two chunks per turn, added in order: the same sums as one per turn
            while i + 8 <= full {
                acc = _mm256_add_pd(
                    acc,
                    _mm256_mul_pd(_mm256_loadu_pd(pa.add(i)), _mm256_loadu_pd(pb.add(i))),
                );
                acc = _mm256_add_pd(
                    acc,
                    _mm256_mul_pd(
                        _mm256_loadu_pd(pa.add(i + 4)),
                        _mm256_loadu_pd(pb.add(i + 4)),
                    ),
                );
                i += 8;
            }
            if i < full {
                acc = _mm256_add_pd(
                    acc,
                    _mm256_mul_pd(_mm256_loadu_pd(pa.add(i)), _mm256_loadu_pd(pb.add(i))),
                );
            }
            if n > full {
                let m = n - full;
                acc = _mm256_add_pd(
                    acc,
                    _mm256_mul_pd(tail(pa.add(full), m), tail(pb.add(full), m)),
                );
            }
            sum(acc)
        }
    }

    /// [`super::Portable::dot2`] on AVX2.
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn dot2(a: &[f64], b: &[f64], c: &[f64]) -> (f64, f64) {
        let n = a.len().min(b.len()).min(c.len());
        let full = n - n % 4;
        // SAFETY: AVX2 (the caller's guarantee); every load reads i..i + 4 ≤ full ≤ n, the
        // tail's loads full..n
        unsafe {
            let (pa, pb, pc) = (a.as_ptr(), b.as_ptr(), c.as_ptr());
            let (mut s, mut t) = (_mm256_setzero_pd(), _mm256_setzero_pd());
            let mut i = 0;
            while i < full {
                let x = _mm256_loadu_pd(pa.add(i));
                s = _mm256_add_pd(s, _mm256_mul_pd(x, _mm256_loadu_pd(pb.add(i))));
                t = _mm256_add_pd(t, _mm256_mul_pd(x, _mm256_loadu_pd(pc.add(i))));
                i += 4;
            }
            if n > full {
                let m = n - full;
                let x = tail(pa.add(full), m);
                s = _mm256_add_pd(s, _mm256_mul_pd(x, tail(pb.add(full), m)));
                t = _mm256_add_pd(t, _mm256_mul_pd(x, tail(pc.add(full), m)));
            }
            (sum(s), sum(t))
        }
    }

    /// The four-lane sums of the rows at `rows` times `x` over the whole chunks `0..full`
    /// (`full` a multiple of four): the loop that [`dots`] and [`padded_dots`] share, one
    /// load of `x` for the four rows.
    ///
    /// # Safety
    /// The processor must have AVX2, and `rows[j]..rows[j] + full` and `x..x + full` must be
    /// inside slices.
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn four_rows(rows: [*const f64; 4], x: *const f64, full: usize) -> [__m256d; 4] {
        let mut s = [_mm256_setzero_pd(); 4];
        let mut i = 0;
        // SAFETY: AVX2 and the loads' ranges are the caller's guarantees
        unsafe {
            while i < full {
                let y = _mm256_loadu_pd(x.add(i));
                for (sum, row) in s.iter_mut().zip(rows) {
                    *sum = _mm256_add_pd(*sum, _mm256_mul_pd(_mm256_loadu_pd(row.add(i)), y));
                }
                i += 4;
            }
        }
        s
    }

    /// [`super::Portable::dots`] on AVX2: four rows at a time share each load of `x`; every
    /// row is summed as [`dot`] sums it.
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn dots(a: &[f64], x: &[f64], out: &mut [f64]) {
        let p = x.len();
        if p == 0 {
            out.fill(0.0);
            return;
        }
        let rows = out.len().min(a.len() / p);
        let full = p - p % 4;
        let mut r = 0;
        // SAFETY: AVX2 (the caller's guarantee); row `r + j < rows` spans
        // `a[(r + j) p..(r + j + 1) p]`, inside `a`, and every load reads `i..i + 4 ≤ full ≤ p`
        unsafe {
            while r + 4 <= rows {
                let base = a.as_ptr().add(r * p);
                let [mut s0, mut s1, mut s2, mut s3] = four_rows(
                    [base, base.add(p), base.add(2 * p), base.add(3 * p)],
                    x.as_ptr(),
                    full,
                );
                if p > full {
                    let m = p - full;
                    let y = tail(x.as_ptr().add(full), m);
                    s0 = _mm256_add_pd(s0, _mm256_mul_pd(tail(base.add(full), m), y));
                    s1 = _mm256_add_pd(s1, _mm256_mul_pd(tail(base.add(p + full), m), y));
                    s2 = _mm256_add_pd(s2, _mm256_mul_pd(tail(base.add(2 * p + full), m), y));
                    s3 = _mm256_add_pd(s3, _mm256_mul_pd(tail(base.add(3 * p + full), m), y));
                }
                for (j, acc) in [s0, s1, s2, s3].into_iter().enumerate() {
                    out[r + j] = sum(acc);
                }
                r += 4;
            }
            while r < rows {
                out[r] = dot(&a[r * p..(r + 1) * p], x);
                r += 1;
            }
        }
    }

    /// [`super::Portable::padded_dots`] on AVX2: four rows at a time share each load of `x`,
    /// `x`'s last `p mod 4` values are read once ([`tail`]) and multiply each row's last chunk
    /// (whose lanes past `p` are zeros, as [`dot`]'s tail loads them), and the four rows'
    /// lanes are added in one pass: `(s₀ + s₁) + (s₂ + s₃)` of each row, as [`sum`] adds them;
    /// the rows left over one at a time.
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn padded_dots(a: &super::PaddedRows, x: &[f64], out: &mut [f64]) {
        let (p, stride) = (a.p, a.stride);
        let rows = out.len().min(a.rows);
        if p == 0 || x.len() < p {
            out.fill(0.0);
            return;
        }
        let full = p - p % 4;
        // SAFETY: AVX2 (the caller's guarantee); row `r < rows ≤ a.rows` spans
        // `a.values[r stride..(r + 1) stride]`, inside `a.values`; each row's loads read
        // `i..i + 4 ≤ stride` of its values, `x`'s `i..i + 4 ≤ full ≤ p` and its tail
        // `full..p`; the stores write `out[r..r + 4]` with `r + 4 ≤ rows`, or `out[r]`
        unsafe {
            let xt = if p > full {
                tail(x.as_ptr().add(full), p - full)
            } else {
                _mm256_setzero_pd()
            };
            let (px, po) = (x.as_ptr(), out.as_mut_ptr());
            let mut base = a.values.as_ptr();
            let mut r = 0;
            while r + 4 <= rows {
                let (b0, b1, b2, b3) = (
                    base,
                    base.add(stride),
                    base.add(2 * stride),
                    base.add(3 * stride),
                );
                let [mut s0, mut s1, mut s2, mut s3] = four_rows([b0, b1, b2, b3], px, full);
                if p > full {
                    s0 = _mm256_add_pd(s0, _mm256_mul_pd(_mm256_loadu_pd(b0.add(full)), xt));
                    s1 = _mm256_add_pd(s1, _mm256_mul_pd(_mm256_loadu_pd(b1.add(full)), xt));
                    s2 = _mm256_add_pd(s2, _mm256_mul_pd(_mm256_loadu_pd(b2.add(full)), xt));
                    s3 = _mm256_add_pd(s3, _mm256_mul_pd(_mm256_loadu_pd(b3.add(full)), xt));
                }
                // (s0₀ + s0₁, s1₀ + s1₁, s0₂ + s0₃, s1₂ + s1₃) and the same of s2, s3
                let h01 = _mm256_hadd_pd(s0, s1);
                let h23 = _mm256_hadd_pd(s2, s3);
                let low = _mm256_permute2f128_pd::<0x20>(h01, h23);
                let high = _mm256_permute2f128_pd::<0x31>(h01, h23);
                _mm256_storeu_pd(po.add(r), _mm256_add_pd(low, high));
                base = base.add(4 * stride);
                r += 4;
            }
            while r < rows {
                let mut acc = _mm256_setzero_pd();
                let mut i = 0;
                // two chunks per turn, added in order, as in `dot`
                while i + 8 <= full {
                    let (y, z) = (_mm256_loadu_pd(px.add(i)), _mm256_loadu_pd(px.add(i + 4)));
                    acc = _mm256_add_pd(acc, _mm256_mul_pd(_mm256_loadu_pd(base.add(i)), y));
                    acc = _mm256_add_pd(acc, _mm256_mul_pd(_mm256_loadu_pd(base.add(i + 4)), z));
                    i += 8;
                }
                if i < full {
                    let y = _mm256_loadu_pd(px.add(i));
                    acc = _mm256_add_pd(acc, _mm256_mul_pd(_mm256_loadu_pd(base.add(i)), y));
                }
                if p > full {
                    acc = _mm256_add_pd(acc, _mm256_mul_pd(_mm256_loadu_pd(base.add(full)), xt));
                }
                *po.add(r) = sum(acc);
                base = base.add(stride);
                r += 1;
            }
        }
    }

    /// [`super::Portable::axpy`] on AVX2 when `SET` is false, [`super::Portable::scale`]
    /// when it is true: four values at a time; the last `n mod 4` as part of the last four
    /// values `n − 4..n` when `n ≥ 4` (formed before the loop, stored after it), else by
    /// [`tail`] and [`store_first`].
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn scaled<const SET: bool>(y: &mut [f64], a: f64, x: &[f64]) {
        let n = y.len().min(x.len());
        let full = n - n % 4;
        // SAFETY: AVX2 (the caller's guarantee); every load and store touches i..i + 4 ≤ full,
        // the last chunk's n − 4..n with n ≥ 4, the tail's ones full..n, within both slices
        unsafe {
            let av = _mm256_set1_pd(a);
            let value = |y: __m256d, x: __m256d| {
                let ax = _mm256_mul_pd(av, x);
                if SET { ax } else { _mm256_add_pd(y, ax) }
            };
            let (py, px) = (y.as_mut_ptr(), x.as_ptr());
            // the last four values when n mod 4 ≠ 0 (and n ≥ 4): computed before the loop, from
            // the `y` it has not yet overwritten, and stored after it (elementwise: the values
            // shared with the last whole chunk are written twice, the same)
            let last = (n > full && n >= 4).then(|| {
                let y = if SET {
                    _mm256_setzero_pd()
                } else {
                    _mm256_loadu_pd(py.add(n - 4))
                };
                value(y, _mm256_loadu_pd(px.add(n - 4)))
            });
            let mut i = 0;
            while i < full {
                let y = if SET {
                    _mm256_setzero_pd()
                } else {
                    _mm256_loadu_pd(py.add(i))
                };
                _mm256_storeu_pd(py.add(i), value(y, _mm256_loadu_pd(px.add(i))));
                i += 4;
            }
            if let Some(x) = last {
                _mm256_storeu_pd(py.add(n - 4), x);
            } else if n > full {
                let m = n - full;
                let y = if SET {
                    _mm256_setzero_pd()
                } else {
                    tail(py.add(full), m)
                };
                store_first(py.add(full), m, value(y, tail(px.add(full), m)));
            }
        }
    }

    /// [`super::Portable::axpy`] on AVX2.
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
        // SAFETY: the caller's
        unsafe { scaled::<false>(y, a, x) }
    }

    /// [`super::Portable::scale`] on AVX2.
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn scale(y: &mut [f64], a: f64, x: &[f64]) {
        // SAFETY: the caller's
        unsafe { scaled::<true>(y, a, x) }
    }

    /// [`super::Portable::predict`] on AVX2 (with [`super::Portable::predict_and_scale`]'s
    /// `f_i = s g_i` in the same pass when `LOAD`; `f` and `g` are not read otherwise): four
    /// modes at a time; the last `p mod 4` as part of the last four modes `p − 4..p` when
    /// `p ≥ 4` (formed before the loop overwrites any of them, stored after it: elementwise,
    /// the same bits), else by plain loads and stores of the first lanes ([`tail`],
    /// [`store_first`]).
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::extra_unused_type_parameters)] // `Tag`: a copy per caller ([`super::Avx2`])
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn predict<Tag, const LOAD: bool>(
        q: &mut [f64],
        vs: &mut [f64],
        v: &[f64],
        a: &[f64],
        dt: f64,
        h: f64,
        f: &mut [f64],
        s: f64,
        g: &[f64],
    ) {
        let p = q.len();
        let (vs, v, a) = (&mut vs[..p], &v[..p], &a[..p]);
        let (f, g) = if LOAD { (&mut f[..p], &g[..p]) } else { (f, g) };
        let full = p - p % 4;
        // SAFETY: AVX2 (the caller's guarantee); every load and store touches i..i + 4 ≤ full,
        // the last chunk's p − 4..p with p ≥ 4, the tail's ones full..p, within every slice
        // (`f` and `g` of length p when `LOAD`)
        unsafe {
            let (dtv, hh, hdt, sv) = (
                _mm256_set1_pd(dt),
                _mm256_set1_pd(h),
                _mm256_set1_pd(h * dt),
                _mm256_set1_pd(s),
            );
            let step = |qi: __m256d, vi: __m256d, ai: __m256d| {
                (
                    _mm256_add_pd(
                        qi,
                        _mm256_add_pd(_mm256_mul_pd(dtv, vi), _mm256_mul_pd(hdt, ai)),
                    ),
                    _mm256_add_pd(vi, _mm256_mul_pd(hh, ai)),
                )
            };
            // the last four modes when p mod 4 ≠ 0 (and p ≥ 4): computed before the loop, from
            // the values it has not yet overwritten, and stored after it (elementwise: the
            // modes it shares with the last whole chunk get the same values twice)
            let last = (p > full && p >= 4).then(|| {
                let j = p - 4;
                let (qn, vn) = step(
                    _mm256_loadu_pd(q.as_ptr().add(j)),
                    _mm256_loadu_pd(v.as_ptr().add(j)),
                    _mm256_loadu_pd(a.as_ptr().add(j)),
                );
                let fnew = if LOAD {
                    _mm256_mul_pd(sv, _mm256_loadu_pd(g.as_ptr().add(j)))
                } else {
                    _mm256_setzero_pd()
                };
                (qn, vn, fnew)
            });
            let mut i = 0;
            while i < full {
                let (qn, vn) = step(
                    _mm256_loadu_pd(q.as_ptr().add(i)),
                    _mm256_loadu_pd(v.as_ptr().add(i)),
                    _mm256_loadu_pd(a.as_ptr().add(i)),
                );
                _mm256_storeu_pd(q.as_mut_ptr().add(i), qn);
                _mm256_storeu_pd(vs.as_mut_ptr().add(i), vn);
                if LOAD {
                    let gi = _mm256_loadu_pd(g.as_ptr().add(i));
                    _mm256_storeu_pd(f.as_mut_ptr().add(i), _mm256_mul_pd(sv, gi));
                }
                i += 4;
            }
            if let Some((qn, vn, fnew)) = last {
                let j = p - 4;
                _mm256_storeu_pd(q.as_mut_ptr().add(j), qn);
                _mm256_storeu_pd(vs.as_mut_ptr().add(j), vn);
                if LOAD {
                    _mm256_storeu_pd(f.as_mut_ptr().add(j), fnew);
                }
            } else if p > full {
                let m = p - full;
                let (qn, vn) = step(
                    tail(q.as_ptr().add(full), m),
                    tail(v.as_ptr().add(full), m),
                    tail(a.as_ptr().add(full), m),
                );
                store_first(q.as_mut_ptr().add(full), m, qn);
                store_first(vs.as_mut_ptr().add(full), m, vn);
                if LOAD {
                    let gi = tail(g.as_ptr().add(full), m);
                    store_first(f.as_mut_ptr().add(full), m, _mm256_mul_pd(sv, gi));
                }
            }
        }
    }

    /// [`super::Portable::free_acceleration`] on AVX2 (with [`super::Portable::free_acceleration_plus`]'s
    /// `f_i + s x_i` when `PLUS`; `x` is not read otherwise): four modes at a time; the last
    /// `p mod 4` as part of the last four modes `p − 4..p` again when `p ≥ 4`, else by
    /// [`tail`] and [`store_first`].
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::too_many_arguments)]
    #[allow(clippy::extra_unused_type_parameters)] // `Tag`: a copy per caller ([`super::Avx2`])
    pub(super) unsafe fn free_acceleration<Tag, const PLUS: bool>(
        out: &mut [f64],
        ai: &[f64],
        f: &[f64],
        s: f64,
        x: &[f64],
        w2: &[f64],
        q: &[f64],
        c: &[f64],
        vs: &[f64],
    ) {
        let p = out.len();
        let (ai, f, w2, q, c, vs) = (&ai[..p], &f[..p], &w2[..p], &q[..p], &c[..p], &vs[..p]);
        let x = if PLUS { &x[..p] } else { x };
        let full = p - p % 4;
        // SAFETY: as in `predict` (`x` of length p when `PLUS`)
        unsafe {
            let sv = _mm256_set1_pd(s);
            // the force f + s x (f alone unless `PLUS`)
            let force = |f: __m256d, at: *const f64, tail_of: Option<usize>| {
                if PLUS {
                    let xi = match tail_of {
                        Some(m) => tail(at, m),
                        None => _mm256_loadu_pd(at),
                    };
                    _mm256_add_pd(f, _mm256_mul_pd(sv, xi))
                } else {
                    f
                }
            };
            let value = |ai: __m256d, f: __m256d, w2: __m256d, q: __m256d, c: __m256d, vs| {
                _mm256_mul_pd(
                    ai,
                    _mm256_sub_pd(_mm256_sub_pd(f, _mm256_mul_pd(w2, q)), _mm256_mul_pd(c, vs)),
                )
            };
            let mut i = 0;
            while i < full {
                let x = value(
                    _mm256_loadu_pd(ai.as_ptr().add(i)),
                    force(_mm256_loadu_pd(f.as_ptr().add(i)), x.as_ptr().add(i), None),
                    _mm256_loadu_pd(w2.as_ptr().add(i)),
                    _mm256_loadu_pd(q.as_ptr().add(i)),
                    _mm256_loadu_pd(c.as_ptr().add(i)),
                    _mm256_loadu_pd(vs.as_ptr().add(i)),
                );
                _mm256_storeu_pd(out.as_mut_ptr().add(i), x);
                i += 4;
            }
            if p > full && p >= 4 {
                // the last four modes again, as the loop forms them (`out` is apart from the
                // inputs: the modes they share with the last whole chunk get the same values
                // twice)
                let j = p - 4;
                let x = value(
                    _mm256_loadu_pd(ai.as_ptr().add(j)),
                    force(_mm256_loadu_pd(f.as_ptr().add(j)), x.as_ptr().add(j), None),
                    _mm256_loadu_pd(w2.as_ptr().add(j)),
                    _mm256_loadu_pd(q.as_ptr().add(j)),
                    _mm256_loadu_pd(c.as_ptr().add(j)),
                    _mm256_loadu_pd(vs.as_ptr().add(j)),
                );
                _mm256_storeu_pd(out.as_mut_ptr().add(j), x);
            } else if p > full {
                let m = p - full;
                let x = value(
                    tail(ai.as_ptr().add(full), m),
                    force(tail(f.as_ptr().add(full), m), x.as_ptr().add(full), Some(m)),
                    tail(w2.as_ptr().add(full), m),
                    tail(q.as_ptr().add(full), m),
                    tail(c.as_ptr().add(full), m),
                    tail(vs.as_ptr().add(full), m),
                );
                store_first(out.as_mut_ptr().add(full), m, x);
            }
        }
    }

    /// [`super::Portable::correct_with_energy`] on AVX2.
    ///
    /// # Safety
    /// The processor must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::too_many_arguments)]
    #[allow(clippy::extra_unused_type_parameters)] // `Tag`: a copy per caller ([`super::Avx2`])
    pub(super) unsafe fn correct_with_energy<Tag>(
        v: &mut [f64],
        vs: &[f64],
        a: &[f64],
        h: f64,
        q: &[f64],
        w2: &[f64],
        c: &[f64],
        f: &[f64],
    ) -> (f64, f64, f64) {
        let p = v.len();
        let (vs, a, q, w2, c, f) = (&vs[..p], &a[..p], &q[..p], &w2[..p], &c[..p], &f[..p]);
        let full = p - p % 4;
        // SAFETY: AVX2 (the caller's guarantee); every load and store touches i..i + 4 ≤ p,
        // the length of every slice
        unsafe {
            let hh = _mm256_set1_pd(h);
            let (mut e, mut d, mut w) = (
                _mm256_setzero_pd(),
                _mm256_setzero_pd(),
                _mm256_setzero_pd(),
            );
            let mut i = 0;
            while i < full {
                let x = _mm256_add_pd(
                    _mm256_loadu_pd(vs.as_ptr().add(i)),
                    _mm256_mul_pd(hh, _mm256_loadu_pd(a.as_ptr().add(i))),
                );
                _mm256_storeu_pd(v.as_mut_ptr().add(i), x);
                let qi = _mm256_loadu_pd(q.as_ptr().add(i));
                let wq = _mm256_mul_pd(_mm256_loadu_pd(w2.as_ptr().add(i)), qi);
                e = _mm256_add_pd(e, _mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(wq, qi)));
                let cx = _mm256_mul_pd(_mm256_loadu_pd(c.as_ptr().add(i)), x);
                d = _mm256_add_pd(d, _mm256_mul_pd(cx, x));
                w = _mm256_add_pd(w, _mm256_mul_pd(_mm256_loadu_pd(f.as_ptr().add(i)), x));
                i += 4;
            }
            if p > full {
                let m = p - full;
                let x = _mm256_add_pd(
                    tail(vs.as_ptr().add(full), m),
                    _mm256_mul_pd(hh, tail(a.as_ptr().add(full), m)),
                );
                store_first(v.as_mut_ptr().add(full), m, x);
                let qi = tail(q.as_ptr().add(full), m);
                let wq = _mm256_mul_pd(tail(w2.as_ptr().add(full), m), qi);
                e = _mm256_add_pd(e, _mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(wq, qi)));
                let cx = _mm256_mul_pd(tail(c.as_ptr().add(full), m), x);
                d = _mm256_add_pd(d, _mm256_mul_pd(cx, x));
                w = _mm256_add_pd(w, _mm256_mul_pd(tail(f.as_ptr().add(full), m), x));
            }
            (0.5 * sum(e), sum(d), sum(w))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The running extrema are `f64::max` / `f64::min` bit for bit whenever the running value
    /// is not NaN: a NaN, an infinite or a signed zero `x` included.
    #[test]
    fn running_extrema_are_those_of_f64_max_and_min() {
        let special = [
            0.0,
            -0.0,
            1.5,
            -2.5,
            1e-300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for &m in &special {
            for x in special.iter().copied().chain([f64::NAN]) {
                assert_eq!(
                    running_max(m, x).to_bits(),
                    m.max(x).to_bits(),
                    "max({m}, {x})"
                );
                assert_eq!(
                    running_min(m, x).to_bits(),
                    m.min(x).to_bits(),
                    "min({m}, {x})"
                );
            }
        }
    }

    /// Values of many magnitudes and signs, so that the rounding of every lane is exercised.
    fn values(n: usize, seed: u64) -> Vec<f64> {
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

    /// The portable kernels sum as the module says: lane by lane, then pairwise.
    #[test]
    fn portable_lanes_are_as_documented() {
        for n in 0..23 {
            let (a, b) = (values(n, 1), values(n, 2));
            let mut s = [0.0; 4];
            let full = n - n % 4;
            for i in 0..full {
                s[i % 4] += a[i] * b[i];
            }
            for i in full..n {
                s[i - full] += a[i] * b[i];
            }
            assert_eq!(
                Portable::dot(&a, &b).to_bits(),
                ((s[0] + s[1]) + (s[2] + s[3])).to_bits()
            );
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_kernels_give_the_portable_bits() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2 on this processor: nothing to compare");
            return;
        }
        for n in 0..41 {
            let [a, b, c, vs, acc, q, w2, damping, f] =
                std::array::from_fn(|k| values(n, 10 * n as u64 + k as u64));
            assert_eq!(
                Avx2::<()>::dot(&a, &b).to_bits(),
                Portable::dot(&a, &b).to_bits(),
                "{n}"
            );
            let (x, y) = (Avx2::<()>::dot2(&a, &b, &c), Portable::dot2(&a, &b, &c));
            assert_eq!(
                (x.0.to_bits(), x.1.to_bits()),
                (y.0.to_bits(), y.1.to_bits())
            );
            // 0–9 rows: the groups of four and the rows left over
            for rows in 0..10 {
                let m = values(rows * n, 7 * n as u64 + rows as u64);
                let (mut o1, mut o2) = (vec![f64::NAN; rows], vec![f64::NAN; rows]);
                Avx2::<()>::dots(&m, &a, &mut o1);
                Portable::dots(&m, &a, &mut o2);
                // the same rows laid out with zeros after each: the same bits
                let padded = PaddedRows::new(n, (0..rows).map(|r| &m[r * n..(r + 1) * n]));
                assert_eq!(padded.rows(), rows);
                let (mut o3, mut o4) = (vec![f64::NAN; rows], vec![f64::NAN; rows]);
                Avx2::<()>::padded_dots(&padded, &a, &mut o3);
                Portable::padded_dots(&padded, &a, &mut o4);
                for r in 0..rows {
                    let single = Portable::dot(&m[r * n..(r + 1) * n], &a);
                    for (o, what) in [
                        (&o1, "dots"),
                        (&o2, "dots"),
                        (&o3, "padded"),
                        (&o4, "padded"),
                    ] {
                        assert_eq!(o[r].to_bits(), single.to_bits(), "{what} {n} {rows} {r}");
                    }
                }
            }
            let (mut q1, mut q2, mut s1, mut s2) =
                (q.clone(), q.clone(), vec![0.0; n], vec![0.0; n]);
            Avx2::<()>::predict(&mut q1, &mut s1, &vs, &acc, 0.37, 0.185);
            Portable::predict(&mut q2, &mut s2, &vs, &acc, 0.37, 0.185);
            // with the load in the same pass: the same state, and the load as `scale` forms it
            let (mut q3, mut q4, mut s3, mut s4) =
                (q.clone(), q.clone(), vec![0.0; n], vec![0.0; n]);
            let (mut f1, mut f2, mut f3) = (vec![f64::NAN; n], vec![f64::NAN; n], vec![0.0; n]);
            let load = -0.73;
            Avx2::<()>::predict_and_scale(
                &mut q3, &mut s3, &vs, &acc, 0.37, 0.185, &mut f1, load, &b,
            );
            Portable::predict_and_scale(
                &mut q4, &mut s4, &vs, &acc, 0.37, 0.185, &mut f2, load, &b,
            );
            Portable::scale(&mut f3, load, &b);
            let (mut a1, mut a2) = (vec![0.0; n], vec![0.0; n]);
            Avx2::<()>::free_acceleration(&mut a1, &w2, &f, &damping, &q, &b, &c);
            Portable::free_acceleration(&mut a2, &w2, &f, &damping, &q, &b, &c);
            // the force f + s x not formed: the bits of axpy into a copy of f, then the above
            let (mut a3, mut a4, mut a5) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            let mut force = f.clone();
            Portable::axpy(&mut force, -1.3, &a);
            Portable::free_acceleration(&mut a5, &w2, &force, &damping, &q, &b, &c);
            Avx2::<()>::free_acceleration_plus(&mut a3, &w2, &f, -1.3, &a, &damping, &q, &b, &c);
            Portable::free_acceleration_plus(&mut a4, &w2, &f, -1.3, &a, &damping, &q, &b, &c);
            let all = |x: &[f64]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(all(&a3), all(&a5), "{n}");
            assert_eq!(all(&a4), all(&a5), "{n}");
            assert_eq!(all(&q1), all(&q2), "{n}");
            assert_eq!(all(&s1), all(&s2), "{n}");
            for (x, y) in [
                (&q3, &q1),
                (&q4, &q1),
                (&s3, &s1),
                (&s4, &s1),
                (&f1, &f3),
                (&f2, &f3),
            ] {
                assert_eq!(all(x), all(y), "{n}");
            }
            assert_eq!(all(&a1), all(&a2), "{n}");
            let (mut v1, mut v2) = (vec![0.0; n], vec![0.0; n]);
            let e1 =
                Avx2::<()>::correct_with_energy(&mut v1, &vs, &acc, 0.37, &q, &w2, &damping, &f);
            let e2 = Portable::correct_with_energy(&mut v2, &vs, &acc, 0.37, &q, &w2, &damping, &f);
            let bits = |e: (f64, f64, f64)| (e.0.to_bits(), e.1.to_bits(), e.2.to_bits());
            assert_eq!(bits(e1), bits(e2), "{n}");
            assert_eq!(
                v1.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                v2.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
            );
            // axpy and scale: element by element as defined, and nothing written past the
            // slice (the AVX2 tail's stores)
            let (mut y1, mut y2) = (q.clone(), q.clone());
            y1.push(f64::NAN);
            Avx2::<()>::axpy(&mut y1[..n], -0.37, &a);
            Portable::axpy(&mut y2, -0.37, &a);
            let expected: Vec<u64> = (0..n).map(|i| (q[i] + -0.37 * a[i]).to_bits()).collect();
            assert_eq!(all(&y1[..n]), expected, "{n}");
            assert_eq!(all(&y2), expected, "{n}");
            assert!(y1[n].is_nan());
            Avx2::<()>::scale(&mut y1[..n], 1.7, &b);
            Portable::scale(&mut y2, 1.7, &b);
            let expected: Vec<u64> = (0..n).map(|i| (1.7 * b[i]).to_bits()).collect();
            assert_eq!(all(&y1[..n]), expected, "{n}");
            assert_eq!(all(&y2), expected, "{n}");
            assert!(y1[n].is_nan());
        }
    }
}
