//! `r` independent stationary Gaussian signals with a spectrum, a pure function of time
//! ([`RandomChannels`]): white noise from the crate's counter-based generator
//! ([`crate::numerics::rng`]) filtered by a FIR designed by frequency sampling, block by block
//! with FFT overlap-save (`docs/LOADS.md`, "Random turbulence").

use std::f64::consts::PI;
use std::sync::Arc;

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlannerScalar};

use super::spectrum::Spectrum;
use crate::error::{Error, Result};
use crate::numerics::rng::{Stream, mix64, normal_pair};

/// Sampling and filter choices of [`RandomChannels`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneratorSettings {
    /// Band limit `f_max`, Hz: the signals have no power above it.
    pub f_max: f64,
    /// `f_s / f_max` (≥ 4; default 8).
    pub oversampling: f64,
    /// FIR length `L` (16 ..= 2²⁰); `None`: the smallest power of two ≥ 256 that resolves the
    /// spectrum, at most 2¹⁸ (see [`RandomChannels`]).
    pub filter_length: Option<usize>,
    /// Samples per block `B` (≥ 1); `None`: `B = N − L` with `N = max(4096, 2^⌈log₂ 2L⌉)`.
    pub block_length: Option<usize>,
}

impl GeneratorSettings {
    /// Defaults for a band limit `f_max`, Hz.
    pub fn new(f_max: f64) -> Self {
        Self {
            f_max,
            oversampling: DEFAULT_OVERSAMPLING,
            filter_length: None,
            block_length: None,
        }
    }

    fn validate(&self, field: &str) -> Result<()> {
        if !(self.f_max.is_finite() && self.f_max > 0.0) {
            return Err(Error::invalid(
                format!("{field}.f_max"),
                format!("must be a finite band limit > 0 in Hz (got {})", self.f_max),
            ));
        }
        if !(self.f_max * self.oversampling).is_finite() {
            return Err(Error::invalid(
                format!("{field}.f_max"),
                format!(
                    "is too large: f_max × oversampling overflows (got {})",
                    self.f_max
                ),
            ));
        }
        if !(self.oversampling.is_finite() && self.oversampling >= MIN_OVERSAMPLING) {
            return Err(Error::invalid(
                format!("{field}.oversampling"),
                format!(
                    "must be ≥ {MIN_OVERSAMPLING} (sample rate / f_max, for an accurate linear \
                     interpolation; default {DEFAULT_OVERSAMPLING}), got {}",
                    self.oversampling
                ),
            ));
        }
        if let Some(l) = self.filter_length
            && !(MIN_FILTER_LENGTH..=MAX_FILTER_LENGTH).contains(&l)
        {
            return Err(Error::invalid(
                format!("{field}.filter_length"),
                format!(
                    "must be between {MIN_FILTER_LENGTH} and {MAX_FILTER_LENGTH} taps \
                         (got {l}); leave it unset to choose it from the spectrum"
                ),
            ));
        }
        if let Some(b) = self.block_length
            && !(1..=MAX_BLOCK_LENGTH).contains(&b)
        {
            return Err(Error::invalid(
                format!("{field}.block_length"),
                format!("must be between 1 and {MAX_BLOCK_LENGTH} samples (got {b})"),
            ));
        }
        Ok(())
    }
}

/// Default `f_s / f_max`.
pub const DEFAULT_OVERSAMPLING: f64 = 8.0;
const MIN_OVERSAMPLING: f64 = 4.0;
const MIN_FILTER_LENGTH: usize = 16;
const MIN_AUTO_FILTER_LENGTH: usize = 256;
const MAX_FILTER_LENGTH: usize = 1 << 20;
const MAX_AUTO_FILTER_LENGTH: usize = 1 << 18;
const MAX_BLOCK_LENGTH: usize = 1 << 24;
const MIN_FFT_LENGTH: usize = 4096;
/// Cached samples, all channels (2 GiB).
const MAX_CACHE: usize = 1 << 28;
/// For a bare PSD function: `Σ_k |S̄_k − S(f_k)| |cell_k|` below this fraction of the variance.
const AUTO_DISCREPANCY: f64 = 1e-3;
/// Band points at least: `f_s / L ≤ f_max / 64`.
const MIN_BAND_POINTS: f64 = 64.0;

/// `r` independent, zero-mean, stationary Gaussian signals `ξ_j(t)` with the same one-sided
/// PSD `S(f)` on `[0, f_max]` and no power above, seeded, and a pure function of `t`: the value
/// at `t` does not depend on the times evaluated before (a run resumed at any step reproduces
/// the forces bit for bit).
///
/// Construction (docs/LOADS.md):
/// - sample rate `f_s = oversampling · f_max`; white noise `w_j[k] ~ N(0, 1)` for every integer
///   `k` (negative too: the signal is stationary from `t = 0`), drawn by Box–Muller from a
///   counter-based hash of `(seed, j, ⌊k/2⌋)` (SplitMix64 finaliser);
/// - FIR filter `h` of length `L` by frequency sampling at `f_k = k f_s / L`:
///   `|H(f_k)|² = (f_s/2) S̄_k / sinc⁴(f_k/f_s)` for the cells below `f_max`, 0 above, zero
///   phase, circularly shifted by `⌊L/2⌋` to be causal (no window). `S̄_k` is the mean of `S`
///   over the cell `[f_k − f_s/2L, f_k + f_s/2L] ∩ [0, f_max]` (4-point Gauss), so the variance
///   is exactly `∫₀^{f_max} S df`. The `1/sinc⁴` pre-compensates the linear interpolation,
///   whose power response is `sinc⁴(f/f_s)`: the interpolated signal has the PSD `S` in the
///   band, the samples `y_j[k] = (h ∗ w_j)[k]` have `S / sinc⁴`;
/// - `L` (unless set): the smallest power of two ≥ 256 with `f_s/L` ≤ `f_max/64` and ≤ the
///   spectrum's detail (half the smallest table interval and half the first table frequency;
///   an eighth of the cross-flow cut-off `f_Rc V/D`), at most 2¹⁸; for a bare function,
///   doubled until `Σ_k |S̄_k − S(f_k)| |cell_k| ≤ 1e-3 ∫S`;
/// - samples computed by blocks of `B` with FFT overlap-save (`N = B + L`), each block a pure
///   function of `(seed, j, block index)`; one block per channel is cached;
/// - `ξ_j(t) = y_j[k] + u (y_j[k+1] − y_j[k])`, `k = ⌊t f_s⌋`, `u = t f_s − k`.
///
/// [`RandomChannels::values`] allocates nothing and costs O(r), plus `r` FFT pairs of length
/// `N` when `t` enters a new block.
#[derive(Clone)]
pub struct RandomChannels {
    channels: usize,
    fs: f64,
    f_max: f64,
    filter_length: usize,
    block_length: usize,
    variance: f64,
    sample_variance: f64,
    /// Per-channel stream keys.
    keys: Vec<u64>,
    /// FFT of the zero-padded filter, divided by `N`.
    filter_fft: Vec<Complex<f64>>,
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
    buffer: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
    /// `B + 1` samples per channel: `y_j[bB ..= bB + B]` of the cached block `b`.
    cache: Vec<f64>,
    block: Option<i64>,
}

impl std::fmt::Debug for RandomChannels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RandomChannels")
            .field("channels", &self.channels)
            .field("sample_rate", &self.fs)
            .field("f_max", &self.f_max)
            .field("filter_length", &self.filter_length)
            .field("block_length", &self.block_length)
            .field("variance", &self.variance)
            .finish_non_exhaustive()
    }
}

impl RandomChannels {
    /// `channels` signals with the spectrum `spectrum`, band-limited to `f_max` Hz, default
    /// [`GeneratorSettings`]. `field` is the dotted path of the load in the case file.
    pub fn new(
        spectrum: &Spectrum,
        channels: usize,
        seed: u64,
        f_max: f64,
        field: &str,
    ) -> Result<Self> {
        Self::with_settings(
            spectrum,
            channels,
            seed,
            &GeneratorSettings::new(f_max),
            field,
        )
    }

    /// As [`RandomChannels::new`] with explicit settings.
    pub fn with_settings(
        spectrum: &Spectrum,
        channels: usize,
        seed: u64,
        settings: &GeneratorSettings,
        field: &str,
    ) -> Result<Self> {
        spectrum.validate(&format!("{field}.spectrum"))?;
        settings.validate(field)?;
        Self::build(
            &|f| spectrum.psd(f),
            spectrum.feature_scale(settings.f_max),
            channels,
            seed,
            settings,
            field,
        )
    }

    /// Signals with the one-sided PSD given by a function `f ↦ S(f)` (finite, ≥ 0 on
    /// `[0, f_max]`), for spectra that are neither a table nor a standard model.
    pub fn from_psd(
        psd: impl Fn(f64) -> f64,
        channels: usize,
        seed: u64,
        settings: &GeneratorSettings,
        field: &str,
    ) -> Result<Self> {
        settings.validate(field)?;
        Self::build(&psd, None, channels, seed, settings, field)
    }

    fn build(
        psd: &dyn Fn(f64) -> f64,
        feature: Option<f64>,
        channels: usize,
        seed: u64,
        settings: &GeneratorSettings,
        field: &str,
    ) -> Result<Self> {
        if channels == 0 {
            return Err(Error::invalid(
                format!("{field}.channels"),
                "needs at least 1 random channel",
            ));
        }
        let f_max = settings.f_max;
        let fs = settings.oversampling * f_max;
        let filter_length = match settings.filter_length {
            Some(l) => l,
            None => auto_filter_length(psd, feature, fs, f_max, field)?,
        };
        let design = design_filter(psd, filter_length, fs, f_max, field)?;
        let l = filter_length;
        let (n, block_length) = match settings.block_length {
            Some(b) => (b + l, b),
            None => {
                let n = (2 * l).next_power_of_two().max(MIN_FFT_LENGTH);
                (n, n - l)
            }
        };
        if channels.saturating_mul(block_length + 1) > MAX_CACHE {
            return Err(Error::invalid(
                format!("{field}.channels"),
                format!(
                    "{channels} channels × {} cached samples exceed {MAX_CACHE} values: \
                     use fewer channels (a larger tolerance) or a shorter \
                     block_length",
                    block_length + 1
                ),
            ));
        }
        let mut planner = FftPlannerScalar::<f64>::new();
        let forward = planner.plan_fft_forward(n);
        let inverse = planner.plan_fft_inverse(n);
        let scratch_len = forward
            .get_inplace_scratch_len()
            .max(inverse.get_inplace_scratch_len());
        let mut scratch = vec![Complex::new(0.0, 0.0); scratch_len];
        let mut filter_fft = vec![Complex::new(0.0, 0.0); n];
        let scale = 1.0 / n as f64;
        for (x, &h) in filter_fft.iter_mut().zip(&design.taps) {
            *x = Complex::new(h * scale, 0.0);
        }
        forward.process_with_scratch(&mut filter_fft, &mut scratch);
        // channel j's key: output j of the stream whose key is the seed's hash
        let mut root = Stream::from_key(mix64(seed ^ 0x5851_f42d_4c95_7f2d));
        let keys = (0..channels).map(|_| root.next_u64()).collect();
        Ok(Self {
            channels,
            fs,
            f_max,
            filter_length: l,
            block_length,
            variance: design.variance,
            sample_variance: design.taps.iter().map(|h| h * h).sum(),
            keys,
            filter_fft,
            forward,
            inverse,
            buffer: vec![Complex::new(0.0, 0.0); n],
            scratch,
            cache: vec![0.0; channels * (block_length + 1)],
            block: None,
        })
    }

    /// Number of channels `r`.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// Sample rate `f_s`, Hz.
    pub fn sample_rate(&self) -> f64 {
        self.fs
    }

    /// Band limit `f_max`, Hz.
    pub fn f_max(&self) -> f64 {
        self.f_max
    }

    /// FIR length `L` (frequency resolution `f_s / L`).
    pub fn filter_length(&self) -> usize {
        self.filter_length
    }

    /// Samples per block `B`.
    pub fn block_length(&self) -> usize {
        self.block_length
    }

    /// Target variance `∫₀^{f_max} S df` of each channel (Gauss quadrature on the cells of the
    /// design grid): the variance of the interpolated signal in the band.
    pub fn variance(&self) -> f64 {
        self.variance
    }

    /// Exact variance `Σ h²` of the samples `y_j[k]` (`Σ_k ∫_cell_k S df / sinc⁴(f_k/f_s)`),
    /// slightly above [`RandomChannels::variance`] because of the interpolation
    /// pre-compensation.
    pub fn sample_variance(&self) -> f64 {
        self.sample_variance
    }

    /// Writes `ξ_j(t)` for `j = 0 .. min(r, out.len())` into `out`. Allocation-free; O(r)
    /// unless `t` enters another block. The result depends on `t` (and the seed and settings)
    /// only; calls with increasing `t` are the fast path.
    pub fn values(&mut self, t: f64, out: &mut [f64]) {
        let x = t * self.fs;
        let k0 = x.floor();
        let u = x - k0;
        // Saturating cast (NaN → 0): no panic on absurd times.
        let k = k0 as i64;
        let b_len = self.block_length as i64;
        let block = k.div_euclid(b_len);
        let offset = k.rem_euclid(b_len) as usize;
        if self.block != Some(block) {
            self.fill_block(block);
        }
        let stride = self.block_length + 1;
        for (j, o) in out.iter_mut().take(self.channels).enumerate() {
            let y = &self.cache[j * stride + offset..j * stride + offset + 2];
            *o = y[0] + u * (y[1] - y[0]);
        }
    }

    /// Computes samples `bB ..= bB + B` of every channel (overlap-save).
    fn fill_block(&mut self, block: i64) {
        let l = self.filter_length;
        let b_len = self.block_length;
        let n = self.buffer.len();
        let start = block.wrapping_mul(b_len as i64).wrapping_sub(l as i64 - 1);
        for j in 0..self.channels {
            let key = self.keys[j];
            let mut i = 0;
            while i < n {
                let idx = start.wrapping_add(i as i64);
                let (z0, z1) = normal_pair(key, (idx >> 1) as u64);
                if idx & 1 == 0 {
                    self.buffer[i] = Complex::new(z0, 0.0);
                    if i + 1 < n {
                        self.buffer[i + 1] = Complex::new(z1, 0.0);
                    }
                    i += 2;
                } else {
                    self.buffer[i] = Complex::new(z1, 0.0);
                    i += 1;
                }
            }
            self.forward
                .process_with_scratch(&mut self.buffer, &mut self.scratch);
            for (x, h) in self.buffer.iter_mut().zip(&self.filter_fft) {
                *x *= h;
            }
            self.inverse
                .process_with_scratch(&mut self.buffer, &mut self.scratch);
            let out = &mut self.cache[j * (b_len + 1)..(j + 1) * (b_len + 1)];
            for (o, y) in out.iter_mut().zip(&self.buffer[l - 1..]) {
                *o = y.re;
            }
        }
        self.block = Some(block);
    }
}

struct FilterDesign {
    taps: Vec<f64>,
    /// `Σ_k ∫_cell_k S df = ∫₀^{f_max} S df`.
    variance: f64,
    /// `Σ_k |S̄_k − S(f_k)| |cell_k|`: how far the spectrum is from linear within the cells.
    discrepancy: f64,
}

/// `sin(πx)/(πx)`.
fn sinc(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        (PI * x).sin() / (PI * x)
    }
}

fn checked_psd(psd: &dyn Fn(f64) -> f64, f: f64, field: &str) -> Result<f64> {
    let s = psd(f);
    if s.is_finite() && s >= 0.0 {
        Ok(s)
    } else {
        Err(Error::invalid(
            format!("{field}.psd"),
            format!("the spectrum must be finite and ≥ 0; it is {s} at f = {f} Hz"),
        ))
    }
}

/// `∫_a^b S df` by 4-point Gauss–Legendre.
fn cell_integral(psd: &dyn Fn(f64) -> f64, a: f64, b: f64, field: &str) -> Result<f64> {
    const NODES: [(f64, f64); 4] = [
        (-0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
        (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
    ];
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mut sum = 0.0;
    for (x, w) in NODES {
        sum += w * checked_psd(psd, m + h * x, field)?;
    }
    Ok(sum * h)
}

fn auto_filter_length(
    psd: &dyn Fn(f64) -> f64,
    feature: Option<f64>,
    fs: f64,
    f_max: f64,
    field: &str,
) -> Result<usize> {
    let mut l = first_filter_length(feature, fs, f_max);
    if feature.is_none() {
        // A bare function: refine until S is close to linear within the cells.
        while l < MAX_AUTO_FILTER_LENGTH {
            let d = design_filter(psd, l, fs, f_max, field)?;
            if d.discrepancy <= AUTO_DISCREPANCY * d.variance {
                break;
            }
            l *= 2;
        }
    }
    Ok(l)
}

/// The filter length `L` chosen for a spectrum whose detail is `feature` (the final one for a
/// table or a standard model; a bare function's first): the smallest power of two ≥ 256 with
/// `f_s/L` at most `f_max/64` and at most `feature`, at most 2¹⁸.
fn first_filter_length(feature: Option<f64>, fs: f64, f_max: f64) -> usize {
    let df = feature.unwrap_or(f_max).min(f_max / MIN_BAND_POINTS);
    let wanted = (fs / df).ceil();
    if wanted >= MAX_AUTO_FILTER_LENGTH as f64 {
        MAX_AUTO_FILTER_LENGTH
    } else {
        (wanted as usize)
            .next_power_of_two()
            .max(MIN_AUTO_FILTER_LENGTH)
    }
}

/// Memory, bytes, that [`RandomChannels::new`] takes for `channels` signals of `spectrum`
/// band-limited to `f_max` (default [`GeneratorSettings`]), without building it: the block
/// cache (`channels × (B + 1)` samples) and 12 complex numbers per point of the FFT length
/// `N` for the rest (the filter's transform, the work buffer, the scratch, the plans'
/// twiddles, the filter's design of `L = N/2` points at most; `tests/memory.rs` measures
/// 10.4 to 11.75). Whatever the spectrum, `L ≤ 2¹⁸` and `N ≤ 2¹⁹` (at most 101 MB beside
/// the cache), so this grows with the number of channels only. For a spectrum that does not
/// [validate](Spectrum::validate), or a band limit that is not a positive finite number, 0
/// (their errors come first).
pub fn generator_bytes(spectrum: &Spectrum, channels: usize, f_max: f64) -> f64 {
    let settings = GeneratorSettings::new(f_max);
    if spectrum.validate("").is_err() || settings.validate("").is_err() {
        return 0.0;
    }
    let fs = settings.oversampling * f_max;
    let l = first_filter_length(spectrum.feature_scale(f_max), fs, f_max);
    let n = (2 * l).next_power_of_two().max(MIN_FFT_LENGTH);
    let block = n - l;
    let complex = std::mem::size_of::<Complex<f64>>() as f64;
    8.0 * channels as f64 * (block + 1) as f64 + 12.0 * complex * n as f64
}

/// Frequency-sampling design of the causal, linear-phase FIR (see [`RandomChannels`]): the
/// squared gain at `f_k = k f_s/L` is `(f_s/2) S̄_k / sinc⁴(f_k/f_s)`, `S̄_k` the mean of `S`
/// over the cell `[f_k − f_s/2L, f_k + f_s/2L] ∩ [0, f_max]` (times the cell's fraction of
/// `f_s/L`), so that `Σ h² = Σ_k ∫_cell_k S / sinc⁴(f_k/f_s)`.
fn design_filter(
    psd: &dyn Fn(f64) -> f64,
    l: usize,
    fs: f64,
    f_max: f64,
    field: &str,
) -> Result<FilterDesign> {
    let df = fs / l as f64;
    let mut spectrum = vec![Complex::new(0.0, 0.0); l];
    let mut variance = 0.0;
    let mut discrepancy = 0.0;
    for k in 0..=l / 2 {
        let f = k as f64 * df;
        let lo = (f - 0.5 * df).max(0.0);
        let hi = (f + 0.5 * df).min(f_max);
        if !(hi > lo) {
            break;
        }
        let integral = cell_integral(psd, lo, hi, field)?;
        variance += integral;
        discrepancy += (integral - checked_psd(psd, f, field)? * (hi - lo)).abs();
        // One-sided cell `[0, Δf/2]` at k = 0 is counted once in Σ|X|²/L, the others twice.
        let mean = if k == 0 { 2.0 } else { 1.0 } * integral / df;
        let g = sinc(f / fs);
        let a = (mean * fs / 2.0).sqrt() / (g * g);
        spectrum[k] = Complex::new(a, 0.0);
        if k != 0 {
            spectrum[l - k] = Complex::new(a, 0.0);
        }
    }
    let mut planner = FftPlannerScalar::<f64>::new();
    planner.plan_fft_inverse(l).process(&mut spectrum);
    let shift = l / 2;
    let taps = (0..l)
        .map(|n| spectrum[(n + l - shift) % l].re / l as f64)
        .collect();
    Ok(FilterDesign {
        taps,
        variance,
        discrepancy,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loads::turbulence::spectrum::fixtures::{field_of, table};

    #[test]
    fn turbulence_generator_settings_are_validated() {
        let s = table(&[1.0, 50.0], &[1.0, 1.0]);
        let bad = |set: GeneratorSettings| {
            field_of(RandomChannels::with_settings(&s, 2, 1, &set, "t").unwrap_err())
        };
        assert_eq!(bad(GeneratorSettings::new(-1.0)), "t.f_max");
        assert_eq!(bad(GeneratorSettings::new(0.0)), "t.f_max");
        assert_eq!(bad(GeneratorSettings::new(f64::NAN)), "t.f_max");
        let mut set = GeneratorSettings::new(100.0);
        set.oversampling = 2.0;
        assert_eq!(bad(set), "t.oversampling");
        let mut set = GeneratorSettings::new(100.0);
        set.filter_length = Some(8);
        assert_eq!(bad(set), "t.filter_length");
        let mut set = GeneratorSettings::new(100.0);
        set.block_length = Some(0);
        assert_eq!(bad(set), "t.block_length");
        let e = RandomChannels::new(&s, 0, 1, 100.0, "t").unwrap_err();
        assert_eq!(field_of(e), "t.channels");
        let e = RandomChannels::new(&s, 1 << 20, 1, 100.0, "t").unwrap_err();
        assert_eq!(field_of(e), "t.channels");
        assert_eq!(bad(GeneratorSettings::new(1e308)), "t.f_max");
        let e = RandomChannels::from_psd(
            |f| if f > 10.0 { f64::NAN } else { 1.0 },
            1,
            1,
            &GeneratorSettings::new(100.0),
            "t",
        )
        .unwrap_err();
        assert_eq!(field_of(e), "t.psd");
        let e = RandomChannels::from_psd(|_| -1.0, 1, 1, &GeneratorSettings::new(100.0), "t")
            .unwrap_err();
        assert_eq!(field_of(e), "t.psd");
    }

    #[test]
    fn turbulence_absurd_times_do_not_panic() {
        let s = table(&[1.0, 50.0], &[1.0, 1.0]);
        let mut g = RandomChannels::new(&s, 2, 1, 100.0, "t").unwrap();
        let mut out = [0.0; 2];
        for t in [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e300,
            -1e300,
            -1.5,
            0.0,
        ] {
            g.values(t, &mut out);
        }
        // A short or long output slice is filled as far as it goes.
        g.values(0.1, &mut []);
        let mut long = [7.0; 3];
        g.values(0.1, &mut long);
        assert_eq!(long[2], 7.0);
        assert!(long[0].is_finite() && long[1].is_finite());
    }

    #[test]
    fn turbulence_auto_filter_length_resolves_the_spectrum() {
        // Feature scale 0.5 Hz (first table frequency 1 Hz) at f_s = 800 Hz: ≥ 1600 taps.
        let s = table(&[1.0, 10.0, 100.0], &[1.0, 1.0, 1e-3]);
        let g = RandomChannels::new(&s, 1, 0, 100.0, "t").unwrap();
        assert_eq!(g.sample_rate(), 800.0);
        assert!(g.filter_length() >= 1600, "{}", g.filter_length());
        assert!(g.filter_length().is_power_of_two());
        assert_eq!(g.block_length() + g.filter_length(), 4096);
        // Override.
        let mut set = GeneratorSettings::new(100.0);
        set.filter_length = Some(1000);
        set.block_length = Some(333);
        let g = RandomChannels::with_settings(&s, 1, 0, &set, "t").unwrap();
        assert_eq!((g.filter_length(), g.block_length()), (1000, 333));
    }
}
