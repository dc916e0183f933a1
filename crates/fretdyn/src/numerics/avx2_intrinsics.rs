//! The AVX2 intrinsics behind [`super::Avx2`] (x86-64 only): each kernel of
//! [`super::Lanes`] with four modes per instruction, summed in the lanes the portable kernels
//! use (THEORY §2, §5).

// Rust 1.85 (the crate's minimum) needs `unsafe` around every intrinsic; later versions only
// around loads and stores: the blocks are kept for the former.
#![allow(unused_unsafe)]

use super::padded::PaddedRows;
use std::arch::x86_64::{
    __m256d, _mm_add_sd, _mm_cvtsd_f64, _mm_hadd_pd, _mm_load_sd, _mm_loadu_pd, _mm_store_sd,
    _mm_storeu_pd, _mm_unpackhi_pd, _mm256_add_pd, _mm256_castpd256_pd128, _mm256_extractf128_pd,
    _mm256_hadd_pd, _mm256_insertf128_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_permute2f128_pd,
    _mm256_set1_pd, _mm256_setzero_pd, _mm256_storeu_pd, _mm256_sub_pd, _mm256_zextpd128_pd256,
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

/// `(x₀ + x₁) + (x₂ + x₃)`, [`super::lanes::combine`] of the four lanes, in registers: one
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
pub(super) unsafe fn padded_dots(a: &PaddedRows, x: &[f64], out: &mut [f64]) {
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
