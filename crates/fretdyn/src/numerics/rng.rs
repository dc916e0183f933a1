//! The one random generator of the crate, counter-based so that every number is a pure function
//! of a key and an index: the draws of a study (`docs/STUDIES.md`: the same study gives the
//! same draws whatever runs them, in whatever order — rayon here, Dask workers in Python) and
//! the white noise of the turbulence (`docs/LOADS.md`: a run resumed at any step reproduces
//! the forces bit for bit).
//!
//! The generator is SplitMix64 (Steele, Lea & Flood 2014): the `j`-th output of the stream
//! with key `k` is `mix64(k + (j+1)·γ)`, `γ = 0x9e3779b97f4a7c15`, and the key of a stream is
//! the seed folded with its indices through `mix64` (Stafford's variant 13 finaliser, a
//! bijection with full avalanche), so that streams of neighbouring indices are unrelated.
//! Normal numbers come from uniform ones by Box–Muller ([`box_muller`]): one per two uniforms
//! for a [`Stream`], a pair for the turbulence's [`normal_pair`].

use std::f64::consts::TAU;

/// `γ`, the increment of SplitMix64's counter (the odd integer nearest `2⁶⁴/φ`).
pub(crate) const GOLDEN_GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// `2⁻⁵³`: a 53-bit integer times it is a uniform number of `[0, 1)`.
const UNIT_53: f64 = 1.0 / (1u64 << 53) as f64;

/// SplitMix64 output function (Stafford's variant 13): a bijection of `u64` with full
/// avalanche.
#[inline]
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The uniform number of `[0, 1)` of the random bits `bits`: their high 53 bits times `2⁻⁵³`.
#[inline]
fn uniform_of(bits: u64) -> f64 {
    (bits >> 11) as f64 * UNIT_53
}

/// Box–Muller: the two independent standard normal numbers `√(−2 ln u₁) (cos 2πu₂, sin 2πu₂)`
/// of the uniform numbers `u₁ ∈ (0, 1]`, `u₂ ∈ [0, 1)`.
#[inline]
fn box_muller(u1: f64, u2: f64) -> (f64, f64) {
    let r = (-2.0 * u1.ln()).sqrt();
    let (s, c) = (TAU * u2).sin_cos();
    (r * c, r * s)
}

/// A reproducible stream of random numbers identified by a seed and a list of indices.
#[derive(Debug, Clone)]
pub struct Stream {
    key: u64,
    counter: u64,
}

impl Stream {
    /// The stream of `seed` and `indices` (e.g. `[sample, parameter, element]`): its numbers
    /// depend on nothing else.
    pub fn new(seed: u64, indices: &[u64]) -> Self {
        let key = indices.iter().fold(mix64(seed ^ GOLDEN_GAMMA), |k, &i| {
            mix64(k ^ mix64(i.wrapping_add(GOLDEN_GAMMA)))
        });
        Self::from_key(key)
    }

    /// The stream whose key is `key` (its `j`-th output `mix64(key + (j+1)·γ)`).
    pub(crate) fn from_key(key: u64) -> Self {
        Self { key, counter: 0 }
    }

    /// Next 64 random bits (SplitMix64).
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.counter = self.counter.wrapping_add(1);
        mix64(
            self.key
                .wrapping_add(self.counter.wrapping_mul(GOLDEN_GAMMA)),
        )
    }

    /// Uniform on `[0, 1)`, 53 bits.
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        uniform_of(self.next_u64())
    }

    /// Uniform integer in `0..n` (`n > 0`), by Lemire's multiply-shift (bias below `n/2⁶⁴`).
    #[inline]
    pub fn below(&mut self, n: usize) -> usize {
        ((self.next_u64() as u128 * n as u128) >> 64) as usize
    }

    /// Standard normal by Box–Muller, `√(−2 ln u₁) cos 2πu₂` with `u₁ ∈ (0, 1]`,
    /// `u₂ ∈ [0, 1)` (one normal per two uniforms: the sine is not kept, so that a draw
    /// uses a fixed number of the stream's numbers).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        box_muller(u1, u2).0
    }
}

/// Standard normal pair number `pair` of the stream `key` (samples `2·pair` and `2·pair + 1`),
/// drawn directly at its index (no state: the turbulence's white noise at any sample): two
/// 53-bit uniforms `u₁ ∈ (0, 1]`, `u₂ ∈ [0, 1)` from hashes of `(key, 2·pair)` and
/// `(key, 2·pair + 1)`, then Box–Muller ([`box_muller`]).
#[inline]
pub(crate) fn normal_pair(key: u64, pair: u64) -> (f64, f64) {
    let a = mix64(key.wrapping_add(mix64(pair.wrapping_mul(2))));
    let b = mix64(key.wrapping_add(mix64(pair.wrapping_mul(2).wrapping_add(1))));
    let u1 = ((a >> 11) as f64 + 1.0) * UNIT_53;
    box_muller(u1, uniform_of(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_of_other_indices_differ_and_one_repeats() {
        let a: Vec<u64> = (0..4)
            .map({
                let mut s = Stream::new(7, &[0, 1]);
                move |_| s.next_u64()
            })
            .collect();
        let b: Vec<u64> = (0..4)
            .map({
                let mut s = Stream::new(7, &[0, 1]);
                move |_| s.next_u64()
            })
            .collect();
        let c: Vec<u64> = (0..4)
            .map({
                let mut s = Stream::new(7, &[1, 0]);
                move |_| s.next_u64()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    /// The draws of the two generators this one replaced (the study's streams, the
    /// turbulence's white noise), pinned: the same seeds give the same draws, bit for bit
    /// (values printed by the former code).
    #[test]
    fn draws_are_those_of_the_former_generators() {
        let streams = [
            (
                0,
                vec![],
                0xbfdc14033d8878d9,
                0x3fd8c6a4553eeafc,
                656,
                0xc9b5ae106698f0bb,
            ),
            (
                42,
                vec![3, 1, 4],
                0xbfef7642f7d8a1fc,
                0x3faea39c48e16740,
                955,
                0x0cfb936153ff4e30,
            ),
            (
                u64::MAX,
                vec![0, u64::MAX],
                0xbff146577b05f3f9,
                0x3fd801b88c12a112,
                509,
                0x7f9225a8f1a52d2a,
            ),
        ];
        for (seed, indices, normal, uniform, below, next) in streams {
            let mut s = Stream::new(seed, &indices);
            assert_eq!(s.normal().to_bits(), normal, "{seed} {indices:?}");
            assert_eq!(s.uniform().to_bits(), uniform, "{seed} {indices:?}");
            assert_eq!(s.below(1000), below, "{seed} {indices:?}");
            assert_eq!(s.next_u64(), next, "{seed} {indices:?}");
        }
        // the turbulence's channel keys (seed 7) and white-noise pairs
        let mut root = Stream::from_key(mix64(7 ^ 0x5851_f42d_4c95_7f2d));
        let keys: Vec<u64> = (0..3).map(|_| root.next_u64()).collect();
        assert_eq!(
            keys,
            [0x717dc091ca0d84f3, 0xaa41caf57d04246c, 0x22ed76d677c9dd1f]
        );
        for (key, pair, a, b) in [
            (keys[0], 0, 0x3ff70ff2e8c26d42, 0xbff1388a17e79ee2),
            (keys[2], 123_456_789, 0xbfcdbfd25353ec7c, 0xbfe9ade14a443906),
            (keys[1], u64::MAX, 0xbfd25df44f8ade97, 0x3ff0d76aef8ab3be),
        ] {
            let (x, y) = normal_pair(key, pair);
            assert_eq!((x.to_bits(), y.to_bits()), (a, b), "{key:#x} {pair}");
        }
    }

    #[test]
    fn turbulence_white_noise_is_standard_normal() {
        // Moments of 2·10⁵ draws against their standard errors (4.5 σ bands).
        let key = mix64(12345);
        let n = 100_000u64;
        let (mut s1, mut s2, mut s4, mut lag) = (0.0, 0.0, 0.0, 0.0);
        let mut prev = 0.0;
        let mut count = 0.0;
        for p in 0..n {
            let (a, b) = normal_pair(key, p);
            for z in [a, b] {
                s1 += z;
                s2 += z * z;
                s4 += z * z * z * z;
                lag += z * prev;
                prev = z;
                count += 1.0;
            }
        }
        let mean = s1 / count;
        let var = s2 / count;
        let kurt = s4 / count;
        assert!(mean.abs() < 4.5 / count.sqrt(), "mean {mean}");
        assert!(
            (var - 1.0).abs() < 4.5 * (2.0 / count).sqrt(),
            "variance {var}"
        );
        assert!(
            (kurt - 3.0).abs() < 4.5 * (96.0 / count).sqrt(),
            "kurtosis {kurt}"
        );
        assert!(
            (lag / count).abs() < 4.5 / count.sqrt(),
            "lag-1 {}",
            lag / count
        );
        // Negative indices are valid and distinct.
        assert_ne!(normal_pair(key, u64::MAX), normal_pair(key, 0));
    }
}
