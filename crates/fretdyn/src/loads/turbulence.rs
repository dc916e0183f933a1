//! Random turbulence loads: a one-sided power spectral density of a force per unit length
//! ([`Spectrum`]) and `r` independent stationary Gaussian signals with that spectrum that are a
//! pure function of time ([`RandomChannels`]). Their spatial correlation along the tube is
//! [`crate::loads::spatial_correlation`]. `docs/LOADS.md`, section "Random turbulence", states the
//! models, their sources and the measured accuracy.
//!
//! The nodal turbulent force is
//!
//! ```text
//! F_i(t) = Σ_j L_ij ξ_j(t),      L Lᵀ ≈ C,   C_ik = ∫∫ N_i(s) N_k(s') exp(−|s − s'| / λ) ds ds'
//! ```
//!
//! with `ξ_j` the unit-less channels of [`RandomChannels`] (one-sided PSD `S(f)`), so that the
//! cross-PSD of the nodal forces is `S(f) C_ik` (`N_i` the shape function of node `i`).
//!
//! One concept, kept whole (the longest module of the crate): the spectra, the synthesis of
//! the signals from them and the generator's state across blocks are one model of the random
//! force; each part is checked against the others in its tests.

use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlannerScalar};

use crate::error::{Error, Result};

/// One-sided power spectral density `S(f)` of a force per unit length, in (N/m)²/Hz, defined
/// for `f ≥ 0` (`∫₀^∞ S df` is the variance of the force per unit length, (N/m)²).
#[derive(Debug, Clone, PartialEq)]
pub enum Spectrum {
    /// A table `(f_i, S_i)`, interpolated log-log between rows,
    /// `S(f) = S_i (f/f_i)^(ln(S_{i+1}/S_i) / ln(f_{i+1}/f_i))`, or linearly when `S_i` or
    /// `S_{i+1}` is 0; `S = 0` below the first and above the last frequency.
    Table {
        /// Strictly increasing frequencies `f_i > 0`, Hz (at least 2).
        frequency_hz: Vec<f64>,
        /// `S_i ≥ 0`, (N/m)²/Hz, one per frequency.
        psd: Vec<f64>,
    },
    /// Turbulence in single-phase cross flow through a tube bundle, the "correlation length"
    /// spectrum of Code_Aster (`DEFI_SPEC_TURB`, keyword `SPEC_LONG_COR_2`, evaluated in its
    /// routine `spect1`):
    ///
    /// ```text
    /// S(f) = (½ ρ V² D)² (D/V) Φ(f_R),   f_R = f D / V,   Φ(f_R) = Φ₀ / (1 + (f_R/f_Rc)^β)
    /// ```
    ///
    /// with Code_Aster's defaults `Φ₀ = 1.5e-3`, `β = 2.7`, `f_Rc = 0.1`
    /// ([`Spectrum::cross_flow`]). Integrated over `[0, ∞)`:
    /// `σ² = (½ρV²D)² Φ₀ f_Rc (π/β) / sin(π/β)` (β > 1). The spatial correlation that goes with
    /// it is `exp(−|Δx|/λ)` ([`crate::loads::spatial_correlation`]); Code_Aster gives `λ` as a multiple of `D`.
    ///
    /// The formula is evaluated as written and taken as one-sided. Code_Aster defines its
    /// interspectra as two-sided transforms; if these defaults follow that convention, the
    /// one-sided equivalent is `phi0 = 3.0e-3` (not confirmed, docs/LOADS.md).
    CrossFlow {
        /// Cross-flow velocity `V`, m/s (> 0).
        velocity: f64,
        /// Fluid density `ρ`, kg/m³ (> 0).
        density: f64,
        /// Tube outer diameter `D`, m (> 0).
        diameter: f64,
        /// Plateau `Φ₀` of the dimensionless spectrum (≥ 0).
        phi0: f64,
        /// High-frequency slope `β` (> 1, so that the variance is finite).
        beta: f64,
        /// Reduced cut-off frequency `f_Rc` (> 0).
        reduced_cutoff: f64,
    },
}

impl Spectrum {
    /// Code_Aster's `SPEC_LONG_COR_2` defaults for single-phase cross flow in a tube bundle:
    /// `Φ₀ = 1.5e-3`, `β = 2.7`, `f_Rc = 0.1`.
    pub fn cross_flow(velocity: f64, density: f64, diameter: f64) -> Self {
        Spectrum::CrossFlow {
            velocity,
            density,
            diameter,
            phi0: 1.5e-3,
            beta: 2.7,
            reduced_cutoff: 0.1,
        }
    }

    /// `S(f)`, (N/m)²/Hz; 0 for `f < 0` or NaN.
    pub fn psd(&self, f: f64) -> f64 {
        if !(f >= 0.0) {
            return 0.0;
        }
        match self {
            Spectrum::Table { frequency_hz, psd } => table_psd(frequency_hz, psd, f),
            Spectrum::CrossFlow {
                velocity,
                density,
                diameter,
                phi0,
                beta,
                reduced_cutoff,
            } => {
                let q = 0.5 * density * velocity * velocity * diameter;
                let fr = f * diameter / velocity;
                q * q * (diameter / velocity) * phi0 / (1.0 + (fr / reduced_cutoff).powf(*beta))
            }
        }
    }

    /// Checks the parameters; `field` is the dotted path of the spectrum in the case file.
    pub fn validate(&self, field: &str) -> Result<()> {
        match self {
            Spectrum::Table { frequency_hz, psd } => {
                if frequency_hz.len() < 2 {
                    return Err(Error::invalid(
                        format!("{field}.frequency_hz"),
                        format!(
                            "needs at least 2 rows to interpolate (got {})",
                            frequency_hz.len()
                        ),
                    ));
                }
                if psd.len() != frequency_hz.len() {
                    return Err(Error::invalid(
                        format!("{field}.psd"),
                        format!(
                            "must have one value per frequency: {} values for {} frequencies",
                            psd.len(),
                            frequency_hz.len()
                        ),
                    ));
                }
                for (i, &f) in frequency_hz.iter().enumerate() {
                    if !(f.is_finite() && f > 0.0) {
                        return Err(Error::invalid(
                            format!("{field}.frequency_hz[{i}]"),
                            format!("must be a finite frequency > 0 in Hz (got {f})"),
                        ));
                    }
                    if i > 0 && !(f > frequency_hz[i - 1]) {
                        return Err(Error::invalid(
                            format!("{field}.frequency_hz[{i}]"),
                            format!(
                                "frequencies must be strictly increasing ({} Hz after {} Hz)",
                                f,
                                frequency_hz[i - 1]
                            ),
                        ));
                    }
                }
                for (i, &s) in psd.iter().enumerate() {
                    if !(s.is_finite() && s >= 0.0) {
                        return Err(Error::invalid(
                            format!("{field}.psd[{i}]"),
                            format!("must be a finite density ≥ 0 in (N/m)²/Hz (got {s})"),
                        ));
                    }
                }
                Ok(())
            }
            Spectrum::CrossFlow {
                velocity,
                density,
                diameter,
                phi0,
                beta,
                reduced_cutoff,
            } => {
                let positive = [
                    ("velocity", *velocity, "a flow velocity > 0 in m/s"),
                    ("density", *density, "a fluid density > 0 in kg/m³"),
                    ("diameter", *diameter, "a tube outer diameter > 0 in m"),
                    (
                        "reduced_cutoff",
                        *reduced_cutoff,
                        "a reduced frequency f D / V > 0 (Code_Aster default 0.1)",
                    ),
                ];
                for (name, v, what) in positive {
                    if !(v.is_finite() && v > 0.0) {
                        return Err(Error::invalid(
                            format!("{field}.{name}"),
                            format!("must be {what} (got {v})"),
                        ));
                    }
                }
                if !(phi0.is_finite() && *phi0 >= 0.0) {
                    return Err(Error::invalid(
                        format!("{field}.phi0"),
                        format!("must be finite and ≥ 0 (Code_Aster default 1.5e-3, got {phi0})"),
                    ));
                }
                if !(beta.is_finite() && *beta > 1.0) {
                    return Err(Error::invalid(
                        format!("{field}.beta"),
                        format!(
                            "must be finite and > 1 for a finite variance \
                             (Code_Aster default 2.7, got {beta})"
                        ),
                    ));
                }
                Ok(())
            }
        }
    }

    /// Frequency detail the filter must resolve below `f_max`: half the smallest table interval
    /// (and half the first table frequency), or an eighth of the cut-off `f_Rc V / D`.
    fn feature_scale(&self, f_max: f64) -> Option<f64> {
        match self {
            Spectrum::Table { frequency_hz, .. } => {
                let mut scale = frequency_hz[0];
                for w in frequency_hz.windows(2) {
                    if w[0] < f_max {
                        scale = scale.min(w[1] - w[0]);
                    }
                }
                Some(0.5 * scale)
            }
            Spectrum::CrossFlow {
                velocity,
                diameter,
                reduced_cutoff,
                ..
            } => Some(reduced_cutoff * velocity / diameter / 8.0),
        }
    }
}

fn table_psd(freq: &[f64], psd: &[f64], f: f64) -> f64 {
    let n = freq.len();
    if n == 0 || f < freq[0] || f > freq[n - 1] {
        return 0.0;
    }
    // First row with freq > f; f ≥ freq[0] so i ≥ 1.
    let i = freq.partition_point(|&x| x <= f);
    if i >= n {
        return psd[n - 1];
    }
    let (f0, f1, s0, s1) = (freq[i - 1], freq[i], psd[i - 1], psd[i]);
    if s0 > 0.0 && s1 > 0.0 {
        s0 * (f / f0).powf((s1 / s0).ln() / (f1 / f0).ln())
    } else {
        s0 + (s1 - s0) * (f - f0) / (f1 - f0)
    }
}

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
        let root = mix64(seed ^ 0x5851_f42d_4c95_7f2d);
        let keys = (0..channels as u64)
            .map(|j| mix64(root.wrapping_add((j + 1).wrapping_mul(GOLDEN_GAMMA))))
            .collect();
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

const GOLDEN_GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// SplitMix64 output function (Stafford's variant 13): a bijection of `u64` with full
/// avalanche.
#[inline]
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Standard normal pair number `pair` of the stream `key` (samples `2·pair` and `2·pair + 1`):
/// two 53-bit uniforms `u₁ ∈ (0, 1]`, `u₂ ∈ [0, 1)` from hashes of `(key, 2·pair)` and
/// `(key, 2·pair + 1)`, then Box–Muller `√(−2 ln u₁) (cos 2πu₂, sin 2πu₂)`.
#[inline]
fn normal_pair(key: u64, pair: u64) -> (f64, f64) {
    const SCALE: f64 = 1.0 / (1u64 << 53) as f64;
    let a = mix64(key.wrapping_add(mix64(pair.wrapping_mul(2))));
    let b = mix64(key.wrapping_add(mix64(pair.wrapping_mul(2).wrapping_add(1))));
    let u1 = ((a >> 11) as f64 + 1.0) * SCALE;
    let u2 = (b >> 11) as f64 * SCALE;
    let r = (-2.0 * u1.ln()).sqrt();
    let (s, c) = (TAU * u2).sin_cos();
    (r * c, r * s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field_of(e: Error) -> String {
        e.field().expect("an input error").to_string()
    }

    fn table(f: &[f64], s: &[f64]) -> Spectrum {
        Spectrum::Table {
            frequency_hz: f.to_vec(),
            psd: s.to_vec(),
        }
    }

    #[test]
    fn turbulence_table_validation_names_the_field() {
        let cases = [
            (table(&[10.0], &[1.0]), "t.spectrum.frequency_hz"),
            (table(&[1.0, 2.0], &[1.0]), "t.spectrum.psd"),
            (
                table(&[0.0, 2.0], &[1.0, 1.0]),
                "t.spectrum.frequency_hz[0]",
            ),
            (
                table(&[3.0, 2.0], &[1.0, 1.0]),
                "t.spectrum.frequency_hz[1]",
            ),
            (
                table(&[2.0, 2.0], &[1.0, 1.0]),
                "t.spectrum.frequency_hz[1]",
            ),
            (
                table(&[1.0, f64::NAN], &[1.0, 1.0]),
                "t.spectrum.frequency_hz[1]",
            ),
            (table(&[1.0, 2.0], &[-1.0, 1.0]), "t.spectrum.psd[0]"),
            (
                table(&[1.0, 2.0], &[1.0, f64::INFINITY]),
                "t.spectrum.psd[1]",
            ),
        ];
        for (spectrum, field) in cases {
            let e = spectrum.validate("t.spectrum").unwrap_err();
            assert_eq!(field_of(e), field);
            let e = RandomChannels::new(&spectrum, 1, 0, 100.0, "t").unwrap_err();
            assert_eq!(field_of(e), field);
        }
        assert!(table(&[1.0, 2.0], &[0.0, 0.0]).validate("t").is_ok());
    }

    #[test]
    fn turbulence_cross_flow_validation_names_the_field() {
        let ok = Spectrum::cross_flow(3.0, 750.0, 0.019);
        assert!(ok.validate("s").is_ok());
        let with = |name: &str, v: f64| {
            let mut s = ok.clone();
            if let Spectrum::CrossFlow {
                velocity,
                density,
                diameter,
                phi0,
                beta,
                reduced_cutoff,
            } = &mut s
            {
                match name {
                    "velocity" => *velocity = v,
                    "density" => *density = v,
                    "diameter" => *diameter = v,
                    "phi0" => *phi0 = v,
                    "beta" => *beta = v,
                    _ => *reduced_cutoff = v,
                }
            }
            s
        };
        for (name, v) in [
            ("velocity", 0.0),
            ("velocity", -1.0),
            ("density", f64::NAN),
            ("diameter", 0.0),
            ("phi0", -1e-3),
            ("beta", 1.0),
            ("beta", f64::INFINITY),
            ("reduced_cutoff", 0.0),
        ] {
            let e = with(name, v).validate("s").unwrap_err();
            assert_eq!(field_of(e), format!("s.{name}"), "{name} = {v}");
        }
    }

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
    fn turbulence_table_interpolates_log_log_and_linearly_through_zero() {
        let s = table(&[10.0, 100.0, 200.0], &[1.0, 1e-2, 0.0]);
        assert_eq!(s.psd(9.999), 0.0);
        assert_eq!(s.psd(200.001), 0.0);
        assert_eq!(s.psd(-5.0), 0.0);
        assert_eq!(s.psd(f64::NAN), 0.0);
        assert!((s.psd(10.0) - 1.0).abs() < 1e-15);
        // log-log: slope −2, S(31.62…) = 0.1.
        assert!((s.psd(10f64.powf(1.5)) - 0.1).abs() < 1e-12);
        // linear towards the zero row.
        assert!((s.psd(150.0) - 0.5e-2).abs() < 1e-15);
        assert_eq!(s.psd(200.0), 0.0);
    }

    #[test]
    fn turbulence_cross_flow_formula_and_closed_form_variance() {
        let (v, rho, d) = (3.0, 750.0, 0.019);
        let s = Spectrum::cross_flow(v, rho, d);
        let q = 0.5 * rho * v * v * d;
        // Plateau (f → 0) and the knee f = f_Rc V / D where Φ = Φ₀/2.
        assert!((s.psd(0.0) / (q * q * d / v * 1.5e-3) - 1.0).abs() < 1e-14);
        let knee = 0.1 * v / d;
        assert!((s.psd(knee) / (q * q * d / v * 0.75e-3) - 1.0).abs() < 1e-14);
        // ∫₀^∞ S df = q² Φ₀ f_Rc (π/β)/sin(π/β): substitution f = knee·e^u, trapezoid in u.
        let beta: f64 = 2.7;
        let exact = q * q * 1.5e-3 * 0.1 * (PI / beta) / (PI / beta).sin();
        let (a, b, n) = (-40.0_f64, 40.0_f64, 200_000);
        let h = (b - a) / n as f64;
        let mut sum = 0.0;
        for i in 0..=n {
            let u = a + i as f64 * h;
            let f = knee * u.exp();
            let w = if i == 0 || i == n { 0.5 } else { 1.0 };
            sum += w * s.psd(f) * f;
        }
        assert!(
            (sum * h / exact - 1.0).abs() < 1e-9,
            "{} vs {exact}",
            sum * h
        );
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
