//! The kernels in plain Rust, for every processor: four lanes summed as [`super::lanes`] says,
//! which the AVX2 kernels reproduce bit for bit (THEORY §2, §5).

use super::lanes::{Lanes, combine, masked_zeros};
use super::padded::PaddedRows;

/// Plain Rust, for every processor.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Portable;

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

/// [`Portable::predict`], with [`Portable::predict_and_scale`]'s `f_i = s g_i` in the same
/// loop when `LOAD` (`f` and `g` are not read otherwise): one loop for both, as
/// `avx2_intrinsics::predict` is one for its two.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::lanes::values;

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
}
