//! Dense symmetric factorisations of the tangential problem's Delassus matrix `H` (THEORY §4.3,
//! §4.6), on row-major `n × n` slices that the caller's workspace holds (nothing allocated):
//! the `LDLᵀ` pivot test that tells a singular `H` ([`ldlt_singular`]), and the Cholesky solve
//! regularised by a Tikhonov shift when `H` is singular ([`cholesky_solve`]).

/// Whether the symmetric `n × n` matrix whose lower triangle (diagonal included) is in `a`
/// has a pivot of its `LDLᵀ` factorisation at most `tiny` (or not a number): the Cholesky's
/// pivot test (its pivots before their square roots, `d_j = a_jj − Σ_k l_jk² d_k`) with no
/// square root, one division per column and no solve — what a singularity test needs
/// (THEORY §4.6). `a` is overwritten; `inverse_pivots` holds `n` values.
#[inline(always)]
pub(crate) fn ldlt_singular(
    a: &mut [f64],
    inverse_pivots: &mut [f64],
    n: usize,
    tiny: f64,
) -> bool {
    for j in 0..n {
        let (done, row) = a.split_at_mut(j * n);
        let row = &mut row[..j + 1];
        // u_jk = l_jk d_k = a_jk − Σ_{i<k} u_ji l_ki, row k (< j) holding l_k·
        for k in 0..j {
            let lk = &done[k * n..k * n + k];
            let mut u = row[k];
            for (ui, li) in row[..k].iter().zip(lk) {
                u -= ui * li;
            }
            row[k] = u;
        }
        // d_j = a_jj − Σ_k u_jk l_jk, and row j turned into l_j·
        let mut d = row[j];
        for k in 0..j {
            let l = row[k] * inverse_pivots[k];
            d -= row[k] * l;
            row[k] = l;
        }
        if !(d > tiny) {
            return true;
        }
        inverse_pivots[j] = 1.0 / d;
    }
    false
}

/// In-place Cholesky solve of the SPD `n × n` system `a x = rhs` (rhs overwritten by x).
/// Only the upper triangle of `a` is read; `diag` must hold its diagonal. A pivot below `tiny`
/// marks the matrix singular: the factorisation is restarted on `a + shift·I` with the
/// smallest `shift = tiny·10^k` that succeeds; when none does (a non-finite `a`), `x` is NaN.
/// Returns whether regularisation was needed.
pub(crate) fn cholesky_solve(
    a: &mut [f64],
    diag: &[f64],
    x: &mut [f64],
    n: usize,
    tiny: f64,
) -> bool {
    // Factor into the lower triangle (diagonal included); the strict upper part keeps `a`.
    let factor = |a: &mut [f64], shift: f64| -> bool {
        for j in 0..n {
            for i in j + 1..n {
                a[i * n + j] = a[j * n + i];
            }
            a[j * n + j] = diag[j] + shift;
        }
        for j in 0..n {
            let mut d = a[j * n + j];
            for k in 0..j {
                d -= a[j * n + k] * a[j * n + k];
            }
            if !(d > tiny) {
                return false;
            }
            let d = d.sqrt();
            a[j * n + j] = d;
            for i in j + 1..n {
                let mut s = a[i * n + j];
                for k in 0..j {
                    s -= a[i * n + k] * a[j * n + k];
                }
                a[i * n + j] = s / d;
            }
        }
        true
    };
    let mut regularised = false;
    if !factor(a, 0.0) {
        regularised = true;
        let mut shift = tiny.max(1e-300);
        while !factor(a, shift) {
            shift *= 10.0;
            if !shift.is_finite() {
                // a non-finite H (a diverging run): no shift helps. NaN multipliers make the
                // step non-finite, and the run stops there as diverged (never a hang).
                x[..n].fill(f64::NAN);
                return true;
            }
        }
    }
    for i in 0..n {
        let mut s = x[i];
        for k in 0..i {
            s -= a[i * n + k] * x[k];
        }
        x[i] = s / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for k in i + 1..n {
            s -= a[k * n + i] * x[k];
        }
        x[i] = s / a[i * n + i];
    }
    regularised
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The square-root-free pivot test gives the Cholesky's answer: regular for SPD matrices
    /// (down to a smallest eigenvalue 1e-9 of the largest, at scales 1e-6 to 1e6), singular for a
    /// rank-deficient one (two contacts with the same rows), a pivot just below the
    /// threshold, and a NaN.
    #[test]
    fn ldlt_pivots_flag_what_the_cholesky_flags() {
        let test = |spd: &nalgebra::DMatrix<f64>| {
            let n = spd.nrows();
            let dmax = (0..n).map(|i| spd[(i, i)].abs()).fold(0.0, f64::max);
            let tiny = 1e-12 * dmax;
            let mut a: Vec<f64> = (0..n * n).map(|k| spd[(k / n, k % n)]).collect();
            let mut inverse_pivots = vec![0.0; n];
            let ldlt = ldlt_singular(&mut a, &mut inverse_pivots, n, tiny);
            let mut a: Vec<f64> = (0..n * n).map(|k| spd[(k / n, k % n)]).collect();
            let diag: Vec<f64> = (0..n).map(|i| spd[(i, i)]).collect();
            let cholesky = cholesky_solve(&mut a, &diag, &mut vec![0.0; n], n, tiny);
            assert_eq!(ldlt, cholesky, "{spd}");
            ldlt
        };
        for n in [2, 4, 6] {
            let m =
                nalgebra::DMatrix::<f64>::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 5) as f64 + 0.3);
            for smallest in [1.0f64, 1e-3, 1e-9] {
                // Q diag Qᵀ with eigenvalues from 1 down to `smallest`
                let q = m.clone().qr().q();
                let d =
                    nalgebra::DVector::from_fn(n, |i, _| smallest.powf(i as f64 / (n - 1) as f64));
                let spd = &q * nalgebra::DMatrix::from_diagonal(&d) * q.transpose();
                for scale in [1e-6, 1.0, 1e6] {
                    assert!(!test(&(&spd * scale)));
                }
            }
            // two contacts with the same rows: H = L Lᵀ with repeated rows of L
            let mut l =
                nalgebra::DMatrix::<f64>::from_fn(n, 8, |i, j| ((i * 5 + j * 11) % 7) as f64 - 3.0);
            for j in 0..8 {
                l[(n - 1, j)] = l[(0, j)];
            }
            assert!(test(&(&l * l.transpose())));
        }
        // the second pivot 1 − 0.99999999999999² ≈ 2e-14 below 1e-12: singular
        let near = nalgebra::DMatrix::from_row_slice(
            2,
            2,
            &[1.0, 0.99999999999999, 0.99999999999999, 1.0],
        );
        assert!(test(&near));
        let mut a = vec![1.0, 0.0, 0.0, f64::NAN];
        assert!(ldlt_singular(&mut a, &mut [0.0; 2], 2, 1e-12));
    }

    #[test]
    fn cholesky_of_a_non_finite_matrix_returns_nan_instead_of_looping() {
        // a NaN pivot fails every shifted factorisation: this looped forever
        let mut a = vec![1.0, 0.0, 0.0, f64::NAN];
        let mut x = vec![1.0, 1.0];
        assert!(cholesky_solve(&mut a, &[1.0, f64::NAN], &mut x, 2, 1e-12));
        assert!(x.iter().all(|v| v.is_nan()));
    }

    #[test]
    fn cholesky_matches_dense_solve_and_flags_singular() {
        let n = 4;
        let m = nalgebra::DMatrix::<f64>::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 5) as f64 + 0.3);
        let spd = &m * m.transpose() + nalgebra::DMatrix::identity(n, n);
        let rhs = nalgebra::DVector::from_fn(n, |i, _| i as f64 - 1.5);
        let mut a: Vec<f64> = (0..n * n).map(|k| spd[(k / n, k % n)]).collect();
        let diag: Vec<f64> = (0..n).map(|i| spd[(i, i)]).collect();
        let mut x: Vec<f64> = rhs.iter().copied().collect();
        assert!(!cholesky_solve(&mut a, &diag, &mut x, n, 1e-12));
        let exact = spd.clone().cholesky().unwrap().solve(&rhs);
        for i in 0..n {
            assert!((x[i] - exact[i]).abs() < 1e-12 * exact.amax());
        }
        // rank-deficient: two equal rows/columns
        let mut a = vec![1.0, 1.0, 1.0, 1.0];
        let mut x = vec![1.0, 1.0];
        assert!(cholesky_solve(&mut a, &[1.0, 1.0], &mut x, 2, 1e-12));
        assert!(x.iter().all(|v| v.is_finite()));
        // the regularised solution still solves the consistent system
        assert!((x[0] + x[1] - 1.0).abs() < 1e-6);
    }
}
