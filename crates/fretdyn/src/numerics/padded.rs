//! Rows laid out for the reductions of several rows at once ([`super::Lanes::padded_dots`]):
//! each row followed by zeros up to a multiple of four values, so that the AVX2 code reads a
//! row's last chunk whole (THEORY §3: the frame rows of detection).

/// Rows of `p` values laid out for [`super::Lanes::padded_dots`]: each row followed by zeros up
/// to `stride`, `p` rounded up to a multiple of four.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct PaddedRows {
    /// The rows, `stride` values each: a row's `p` values, then zeros.
    pub(super) values: Vec<f64>,
    /// The number of rows.
    pub(super) rows: usize,
    /// The values of a row.
    pub(super) p: usize,
    /// `p` rounded up to a multiple of four.
    pub(super) stride: usize,
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

    /// The number of rows: the length of [`super::Lanes::padded_dots`]'s output.
    pub(crate) fn rows(&self) -> usize {
        self.rows
    }

    /// Row `r` (its `p` values).
    pub(super) fn row(&self, r: usize) -> &[f64] {
        &self.values[r * self.stride..r * self.stride + self.p]
    }
}
