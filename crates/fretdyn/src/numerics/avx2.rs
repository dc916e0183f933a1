//! The kernels on AVX2, for x86-64 processors that have it: [`Avx2`] dispatches each kernel of
//! [`Lanes`] to its intrinsics ([`super::avx2_intrinsics`]), which give the portable kernels'
//! bits (THEORY §2, §5).

use super::avx2_intrinsics as avx2;
use super::lanes::Lanes;
use super::padded::PaddedRows;

/// AVX2 intrinsics (x86-64 only; see the trait's safety note).
///
/// `Tag` names a copy of the large kernels (the predictor, the free acceleration, the velocity
/// update): a step compiled more than once
/// ([`crate::integrator::simulation::Simulation::steps`]) gives each of its versions its own
/// `Tag`, so that each copy has one caller and is inlined into it (a kernel with two callers
/// stays a function of its own, and the calls cost the step a few per cent).
#[derive(Debug)]
pub(crate) struct Avx2<Tag = ()>(std::marker::PhantomData<Tag>);

impl<Tag> Clone for Avx2<Tag> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<Tag> Copy for Avx2<Tag> {}

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::lanes::values;
    use crate::numerics::portable::Portable;

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
