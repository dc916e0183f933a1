//! Running extrema of the statistics and the energy balance, one instruction each on x86-64
//! (THEORY §5, §11): the maximum and minimum of a value that is never NaN.

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
}
