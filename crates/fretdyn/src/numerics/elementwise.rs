//! An elementwise map over slices that the compiler vectorises: the rows of a contact on the
//! tube surface and its Delassus rows (THEORY §3, §4.2).

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
