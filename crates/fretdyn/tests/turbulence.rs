//! Random turbulence signals checked against independent estimates (docs/LOADS.md, "Random
//! turbulence"):
//! - Welch's method written here (Hann window, 50 % overlap, one-sided, ∫PSD df = variance)
//!   against the expected value of the estimator, `E[P̂](f) = (S_obs ⊛ |W|²)(f) / Σw²`, at
//!   every frequency of the band, inside the 99.9 % two-sided chi-square band of `ν` degrees
//!   of freedom (Welch 1967; Percival & Walden 1993); at most 1 % of the frequencies may fall
//!   out (0.1 % expected);
//! - sample variances against `∫ S_obs df` within 3.29 standard errors,
//!   `SE² = (1/T) ∫ S_obs² df` (Gaussian process);
//! - seeds, purity in `t`, independence of the channels, the spatial correlation factor.
//!
//! `S_obs` is the PSD of what is sampled: the generator's own samples have `S / sinc⁴(f/f_s)`
//! (the FIR pre-compensates the linear interpolation); the interpolated signal sampled at an
//! incommensurate rate has `S` in the band.
//!
//! `cargo test -p fretdyn --test turbulence -- --nocapture` prints the measured figures.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

use fretdyn::loads::spatial_correlation::correlated_factor;
use fretdyn::loads::turbulence::{GeneratorSettings, RandomChannels, Spectrum};
use nalgebra::DMatrix;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

// ---------------------------------------------------------------------------------------------
// Allocation counting on the test's own thread (as tests/no_allocation.rs).

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static COUNTED: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if COUNTED.with(|c| c.get()) {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

// ---------------------------------------------------------------------------------------------
// Independent tools.

/// Standard normal quantile of 0.9995 (99.9 % two-sided).
const Z_999: f64 = 3.290_526_731_491_926;

fn sinc(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        (PI * x).sin() / (PI * x)
    }
}

/// Composite Simpson on `[a, b]` with `n` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for i in 1..n {
        s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(a + i as f64 * h);
    }
    s * h / 3.0
}

/// Periodic Hann window.
fn hann(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| 0.5 - 0.5 * (2.0 * PI * i as f64 / n as f64).cos())
        .collect()
}

struct Welch {
    /// Bin frequencies `j f_s / N_seg`, `j = 0 ..= N_seg/2`.
    freq: Vec<f64>,
    psd: Vec<f64>,
    segments: usize,
    /// Equivalent degrees of freedom.
    dof: f64,
}

/// One-sided Welch estimate, Hann window, 50 % overlap, no detrending, scaled so that
/// `Σ P̂ Δf = mean x²`.
fn welch(x: &[f64], fs: f64, nseg: usize) -> Welch {
    let w = hann(nseg);
    let u: f64 = w.iter().map(|v| v * v).sum();
    let hop = nseg / 2;
    let segments = (x.len() - nseg) / hop + 1;
    let fft = FftPlanner::<f64>::new().plan_fft_forward(nseg);
    let mut acc = vec![0.0; nseg / 2 + 1];
    let mut buf = vec![Complex::new(0.0, 0.0); nseg];
    for s in 0..segments {
        for (i, b) in buf.iter_mut().enumerate() {
            *b = Complex::new(x[s * hop + i] * w[i], 0.0);
        }
        fft.process(&mut buf);
        for (j, a) in acc.iter_mut().enumerate() {
            *a += buf[j].norm_sqr();
        }
    }
    let psd = acc
        .iter()
        .enumerate()
        .map(|(j, a)| {
            let one_sided = if j == 0 || j == nseg / 2 { 1.0 } else { 2.0 };
            one_sided * a / (segments as f64 * fs * u)
        })
        .collect();
    // Welch (1967), Percival & Walden (1993): ν = 2K / (1 + 2 Σ_m (1 − m/K) c_m²), c_m the
    // normalised overlap of windows m hops apart (only m = 1 overlaps at 50 %).
    let c1: f64 = (0..nseg - hop).map(|i| w[i] * w[i + hop]).sum::<f64>() / u;
    let k = segments as f64;
    let dof = 2.0 * k / (1.0 + 2.0 * (1.0 - 1.0 / k) * c1 * c1);
    Welch {
        freq: (0..=nseg / 2)
            .map(|j| j as f64 * fs / nseg as f64)
            .collect(),
        psd,
        segments,
        dof,
    }
}

/// Chi-square quantile (Wilson–Hilferty), `z` the standard normal quantile.
fn chi2_quantile(nu: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * nu);
    nu * (1.0 - a + z * a.sqrt()).powi(3)
}

/// `E[P̂](f)` for a one-sided PSD `s_obs`: the spectral window `|W(δ)|²` of the Hann segment
/// (direct DTFT sum), convolved over ±24 bins with 8 points per bin, normalised.
struct Expectation {
    offsets: Vec<f64>,
    kernel: Vec<f64>,
}

impl Expectation {
    fn new(fs: f64, nseg: usize) -> Self {
        let w = hann(nseg);
        let bin = fs / nseg as f64;
        let (half, per_bin) = (24i64, 8i64);
        let mut offsets = Vec::new();
        let mut kernel = Vec::new();
        for m in -half * per_bin..=half * per_bin {
            let delta = m as f64 * bin / per_bin as f64;
            let theta = 2.0 * PI * delta / fs;
            let (mut re, mut im) = (0.0, 0.0);
            for (n, wn) in w.iter().enumerate() {
                let (s, c) = (theta * n as f64).sin_cos();
                re += wn * c;
                im -= wn * s;
            }
            offsets.push(delta);
            kernel.push(re * re + im * im);
        }
        Self { offsets, kernel }
    }

    fn at(&self, f: f64, s_obs: &impl Fn(f64) -> f64) -> f64 {
        let mut num = 0.0;
        let mut den = 0.0;
        for (d, k) in self.offsets.iter().zip(&self.kernel) {
            num += s_obs((f - d).abs()) * k;
            den += k;
        }
        num / den
    }
}

struct BandCheck {
    bins: usize,
    out: usize,
    max_dev: f64,
    band: (f64, f64),
    dof: f64,
    segments: usize,
}

/// Compares the Welch estimate of `x` with its expectation at every bin of `[f_lo, f_hi]`.
fn check_band(
    x: &[f64],
    fs: f64,
    nseg: usize,
    f_lo: f64,
    f_hi: f64,
    s_obs: impl Fn(f64) -> f64,
) -> BandCheck {
    let est = welch(x, fs, nseg);
    let expect = Expectation::new(fs, nseg);
    let lo = chi2_quantile(est.dof, -Z_999) / est.dof;
    let hi = chi2_quantile(est.dof, Z_999) / est.dof;
    let (mut bins, mut out, mut max_dev) = (0, 0, 0.0_f64);
    for (f, p) in est.freq.iter().zip(&est.psd) {
        if *f < f_lo || *f > f_hi {
            continue;
        }
        let e = expect.at(*f, &s_obs);
        let ratio = p / e;
        bins += 1;
        max_dev = max_dev.max((ratio - 1.0).abs());
        if !(lo..=hi).contains(&ratio) {
            out += 1;
            println!("  out of band: f = {f:.3} Hz, P̂/E = {ratio:.4}");
        }
    }
    BandCheck {
        bins,
        out,
        max_dev,
        band: (lo, hi),
        dof: est.dof,
        segments: est.segments,
    }
}

fn report(name: &str, c: &BandCheck) {
    println!(
        "{name}: {} bins, {} segments, ν = {:.0}, 99.9 % band [{:.4}, {:.4}], {} out \
         ({:.2} %), max |P̂/E − 1| = {:.4}",
        c.bins,
        c.segments,
        c.dof,
        c.band.0,
        c.band.1,
        c.out,
        100.0 * c.out as f64 / c.bins as f64,
        c.max_dev
    );
    assert!(c.bins >= 100, "{name}: too few bins ({})", c.bins);
    assert!(
        c.out as f64 <= 0.01 * c.bins as f64,
        "{name}: {} of {} bins outside the 99.9 % band",
        c.out,
        c.bins
    );
}

/// `n` values of channel 0 at `t = (k + phase) / rate`.
fn sample(g: &mut RandomChannels, rate: f64, n: usize, phase: f64) -> Vec<f64> {
    let mut out = vec![0.0; g.channels()];
    (0..n)
        .map(|k| {
            g.values((k as f64 + phase) / rate, &mut out);
            out[0]
        })
        .collect()
}

fn mean_square(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64
}

/// Checks the sample variance of `x` (duration `t`) against `∫ s_obs` within 3.29 SE.
fn check_variance(name: &str, x: &[f64], t: f64, f_max: f64, s_obs: impl Fn(f64) -> f64) {
    let expected = simpson(&s_obs, 0.0, f_max, 200_000);
    let se = (simpson(|f| s_obs(f).powi(2), 0.0, f_max, 200_000) / t).sqrt();
    let measured = mean_square(x);
    println!(
        "{name}: variance {measured:.6e}, expected {expected:.6e}, error {:.2} SE \
         (SE = {:.2} %)",
        (measured - expected) / se,
        100.0 * se / expected
    );
    assert!(
        (measured - expected).abs() <= Z_999 * se,
        "{name}: variance {measured} vs {expected} (SE {se})"
    );
}

fn peaked_table() -> Spectrum {
    Spectrum::Table {
        frequency_hz: vec![1.0, 5.0, 10.0, 15.0, 20.0, 30.0, 50.0, 80.0, 100.0],
        psd: vec![0.01, 0.2, 1.0, 2.0, 1.0, 0.3, 0.05, 0.005, 0.001],
    }
}

/// Steam-generator-like cross flow: water at 750 kg/m³, 3 m/s, 19.05 mm tubes.
fn cross_flow() -> Spectrum {
    Spectrum::cross_flow(3.0, 750.0, 0.019_05)
}

// ---------------------------------------------------------------------------------------------
// Spectra.

#[test]
fn table_spectrum_welch_within_chi_square_band() {
    let s = peaked_table();
    let f_max = 100.0;
    let mut g = RandomChannels::new(&s, 1, 20240611, f_max, "t").unwrap();
    let fs = g.sample_rate();
    let n = 1 << 20;
    let x = sample(&mut g, fs, n, 0.0);
    // The generator's samples: S / sinc⁴(f/f_s) in the band, nothing above f_max.
    let s_obs = |f: f64| {
        if f <= f_max {
            s.psd(f) / sinc(f / fs).powi(4)
        } else {
            0.0
        }
    };
    println!(
        "table: f_s = {fs} Hz, L = {}, B = {}, variance() = {:.6e}, sample_variance() = {:.6e}",
        g.filter_length(),
        g.block_length(),
        g.variance(),
        g.sample_variance()
    );
    let c = check_band(&x, fs, 1024, 2.0, 95.0, s_obs);
    report("table, samples at f_s", &c);
    check_variance("table, samples at f_s", &x, n as f64 / fs, f_max, s_obs);
    // The generator's own variances against quadratures of the spectrum.
    let target = simpson(|f| s.psd(f), 0.0, f_max, 200_000);
    let samples = simpson(s_obs, 0.0, f_max, 200_000);
    println!(
        "table: variance() / ∫S = {:.6}, sample_variance() / ∫S/sinc⁴ = {:.6}",
        g.variance() / target,
        g.sample_variance() / samples
    );
    assert!((g.variance() / target - 1.0).abs() < 1e-4);
    assert!((g.sample_variance() / samples - 1.0).abs() < 1e-3);
}

#[test]
fn cross_flow_spectrum_welch_within_chi_square_band() {
    let s = cross_flow();
    let f_max = 200.0;
    let mut g = RandomChannels::new(&s, 1, 7, f_max, "t").unwrap();
    let fs = g.sample_rate();
    let n = 1 << 20;
    let x = sample(&mut g, fs, n, 0.0);
    let s_obs = |f: f64| {
        if f <= f_max {
            s.psd(f) / sinc(f / fs).powi(4)
        } else {
            0.0
        }
    };
    println!(
        "cross flow: S(0) = {:.4e} (N/m)²/Hz, knee {:.2} Hz, f_s = {fs} Hz, L = {}, B = {}",
        s.psd(0.0),
        0.1 * 3.0 / 0.019_05,
        g.filter_length(),
        g.block_length()
    );
    let c = check_band(&x, fs, 1024, 2.0, 190.0, s_obs);
    report("cross flow, samples at f_s", &c);
    check_variance(
        "cross flow, samples at f_s",
        &x,
        n as f64 / fs,
        f_max,
        s_obs,
    );
    let target = simpson(|f| s.psd(f), 0.0, f_max, 200_000);
    assert!((g.variance() / target - 1.0).abs() < 1e-6);
    // The mean: Var(mean) = S_obs(0) / 2T.
    let mean = x.iter().sum::<f64>() / n as f64;
    let se = (s_obs(0.0) / (2.0 * n as f64 / fs)).sqrt();
    println!("cross flow: mean {mean:.3e} = {:.2} SE", mean / se);
    assert!(mean.abs() <= Z_999 * se);
}

#[test]
fn interpolated_signal_has_the_target_psd_in_the_band() {
    // A time-stepper samples ξ(t) at a rate unrelated to f_s: here 3.7 f_s. In the band the
    // PSD is S (aliases of the interpolation images weigh < 1e-6); the variance includes the
    // images: ∫ S (2 + cos 2πf/f_s) / (3 sinc⁴(f/f_s)) df.
    let s = peaked_table();
    let f_max = 100.0;
    let mut g = RandomChannels::new(&s, 1, 99, f_max, "t").unwrap();
    let fs = g.sample_rate();
    let rate = 3.7 * fs;
    let n = 1 << 21;
    let x = sample(&mut g, rate, n, 0.25);
    let in_band = |f: f64| if f <= f_max { s.psd(f) } else { 0.0 };
    let c = check_band(&x, rate, 4096, 2.0, 95.0, in_band);
    report("table, interpolated at 3.7 f_s", &c);
    check_variance(
        "table, interpolated at 3.7 f_s",
        &x,
        n as f64 / rate,
        f_max,
        |f| s.psd(f) * (2.0 + (2.0 * PI * f / fs).cos()) / (3.0 * sinc(f / fs).powi(4)),
    );
}

#[test]
fn a_bare_psd_function_is_resolved() {
    // A narrow resonance (Q = 20 at 60 Hz, half-power width 3 Hz) given as a closure.
    let peak = |f: f64| {
        let r = f / 60.0;
        1.0 / ((1.0 - r * r).powi(2) + (r / 20.0).powi(2))
    };
    let f_max = 100.0;
    let g = RandomChannels::from_psd(peak, 1, 3, &GeneratorSettings::new(f_max), "t").unwrap();
    let df = g.sample_rate() / g.filter_length() as f64;
    println!(
        "resonance: L = {}, f_s/L = {df:.4} Hz, variance() / ∫S = {:.6}",
        g.filter_length(),
        g.variance() / simpson(peak, 0.0, f_max, 400_000)
    );
    assert!(df <= 0.5, "resolution {df} Hz for a 3 Hz wide peak");
    assert!((g.variance() / simpson(peak, 0.0, f_max, 400_000) - 1.0).abs() < 1e-4);
}

// ---------------------------------------------------------------------------------------------
// Seeds, purity, independence.

fn times() -> Vec<f64> {
    // A time step of 37 µs over 3 s: many samples per step interval, many blocks.
    (0..81_081).map(|k| k as f64 * 37e-6).collect()
}

fn run(g: &mut RandomChannels, order: &[usize], t: &[f64]) -> Vec<Vec<u64>> {
    let r = g.channels();
    let mut res = vec![Vec::new(); t.len()];
    let mut out = vec![0.0; r];
    for &k in order {
        g.values(t[k], &mut out);
        res[k] = out.iter().map(|v| v.to_bits()).collect();
    }
    res
}

#[test]
fn same_seed_gives_identical_values_and_another_seed_does_not() {
    let s = cross_flow();
    let t = times();
    let order: Vec<usize> = (0..t.len()).collect();
    let a = run(
        &mut RandomChannels::new(&s, 3, 42, 500.0, "t").unwrap(),
        &order,
        &t,
    );
    let b = run(
        &mut RandomChannels::new(&s, 3, 42, 500.0, "t").unwrap(),
        &order,
        &t,
    );
    assert_eq!(a, b);
    let c = run(
        &mut RandomChannels::new(&s, 3, 43, 500.0, "t").unwrap(),
        &order,
        &t,
    );
    let same = a.iter().zip(&c).filter(|(x, y)| x == y).count();
    assert_eq!(same, 0, "{same} equal values with another seed");
    // Channel j does not depend on how many channels are generated.
    let d = run(
        &mut RandomChannels::new(&s, 5, 42, 500.0, "t").unwrap(),
        &order,
        &t,
    );
    assert!(a.iter().zip(&d).all(|(x, y)| x[..] == y[..3]));
}

#[test]
fn values_are_a_pure_function_of_time() {
    let s = peaked_table();
    let t = times();
    let n = t.len();
    let make = || RandomChannels::new(&s, 2, 5, 100.0, "t").unwrap();
    let forward: Vec<usize> = (0..n).collect();
    let reference = run(&mut make(), &forward, &t);
    // Backwards.
    let backward: Vec<usize> = (0..n).rev().collect();
    assert_eq!(run(&mut make(), &backward, &t), reference);
    // Resumed at a late step (as from a checkpoint), then the beginning.
    let resumed: Vec<usize> = (n / 2..n).chain(0..n / 2).collect();
    assert_eq!(run(&mut make(), &resumed, &t), reference);
    // 500 times in a pseudo-random order (full-period LCG; each call in another block).
    let m = n.next_power_of_two();
    let mut order = Vec::new();
    let mut x = 1usize;
    while order.len() < 500 {
        x = (x.wrapping_mul(5).wrapping_add(3)) % m;
        if x < n {
            order.push(x);
        }
    }
    let mut g = make();
    let mut out = [0.0; 2];
    for &k in &order {
        g.values(t[k], &mut out);
        let bits: Vec<u64> = out.iter().map(|v| v.to_bits()).collect();
        assert_eq!(bits, reference[k], "t = {}", t[k]);
    }
    // A generator cloned mid-run, or used at other times in between, continues identically.
    let mut g = make();
    let mut out = [0.0; 2];
    g.values(1234.5, &mut out);
    let mut h = g.clone();
    assert_eq!(run(&mut h, &forward, &t), reference);
}

#[test]
fn channels_are_independent() {
    let s = cross_flow();
    let f_max = 200.0;
    let r = 3;
    let mut g = RandomChannels::new(&s, r, 11, f_max, "t").unwrap();
    let fs = g.sample_rate();
    let n = 1 << 18;
    let mut x = vec![vec![0.0; n]; r];
    let mut out = vec![0.0; r];
    for k in 0..n {
        g.values(k as f64 / fs, &mut out);
        for (xj, o) in x.iter_mut().zip(&out) {
            xj[k] = *o;
        }
    }
    // SE of a cross-correlation coefficient of independent series with the same spectrum:
    // Σ_τ ρ(τ)² / N = (f_s/2) ∫ S_obs² / (σ⁴ N).
    let s_obs = |f: f64| s.psd(f) / sinc(f / fs).powi(4);
    let var = simpson(s_obs, 0.0, f_max, 100_000);
    let sum_rho2 = 0.5 * fs * simpson(|f| s_obs(f).powi(2), 0.0, f_max, 100_000) / (var * var);
    let se = (sum_rho2 / n as f64).sqrt();
    // 3 pairs × 5 lags: each at 99.99 % (z = 3.89) for a family-wise 0.15 %.
    let z = 3.890_591_886_413_094;
    let mut worst = 0.0_f64;
    for a in 0..r {
        for b in a + 1..r {
            let (va, vb) = (mean_square(&x[a]), mean_square(&x[b]));
            for lag in [-10i64, -1, 0, 1, 10] {
                let mut c = 0.0;
                let mut m = 0;
                for k in 10..n - 10 {
                    c += x[a][k] * x[b][(k as i64 + lag) as usize];
                    m += 1;
                }
                let rho = c / m as f64 / (va * vb).sqrt();
                worst = worst.max(rho.abs() / se);
                assert!(
                    rho.abs() <= z * se,
                    "channels {a},{b} lag {lag}: ρ = {rho} (SE {se})"
                );
            }
        }
    }
    println!(
        "independence: SE(ρ) = {se:.4e} (N_eff = {:.0}), worst |ρ| = {worst:.2} SE",
        1.0 / (se * se)
    );
}

#[test]
fn values_do_not_allocate() {
    let s = cross_flow();
    let mut g = RandomChannels::new(&s, 4, 1, 500.0, "t").unwrap();
    let mut out = [0.0; 4];
    let span = 50.0 * g.block_length() as f64 / g.sample_rate();
    COUNTED.with(|c| c.set(true));
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let mut k = 0u64;
    let mut t = 0.0;
    while t < span {
        t = k as f64 * 1e-5;
        g.values(t, &mut out);
        k += 1;
    }
    g.values(1.0e6, &mut out);
    g.values(0.0, &mut out);
    let allocations = ALLOCATIONS.load(Ordering::Relaxed) - before;
    COUNTED.with(|c| c.set(false));
    assert_eq!(
        allocations, 0,
        "{allocations} allocations in {k} calls over 50 blocks"
    );
}

// ---------------------------------------------------------------------------------------------
// Spatial correlation.

fn covariance(x: &[f64], w: &[f64], lambda: f64) -> DMatrix<f64> {
    let n = x.len();
    DMatrix::from_fn(n, n, |i, k| {
        let dx = (x[i] - x[k]).abs();
        let rho = if dx == 0.0 { 1.0 } else { (-dx / lambda).exp() };
        w[i] * w[k] * rho
    })
}

#[test]
fn correlated_factor_reproduces_the_covariance() {
    let x: Vec<f64> = (0..11).map(|i| 0.1 * i as f64).collect();
    let w: Vec<f64> = (0..11)
        .map(|i| if i == 0 || i == 10 { 0.05 } else { 0.1 })
        .collect();
    for lambda in [0.0, 1e-9, 0.05, 0.3, 2.0, f64::INFINITY] {
        let l = correlated_factor(&x, &w, lambda, 0.0).unwrap();
        let c = covariance(&x, &w, lambda);
        let err = (&l * l.transpose() - &c).amax();
        println!(
            "λ = {lambda}: {} columns, max |L Lᵀ − C| = {err:.2e}",
            l.ncols()
        );
        assert!(err <= 1e-14, "λ = {lambda}: {err}");
        if lambda.is_infinite() {
            assert_eq!(l.ncols(), 1);
            // Rank one: L = w.
            for i in 0..11 {
                assert!((l[(i, 0)] - w[i]).abs() < 1e-15);
            }
        }
        if lambda < 1e-6 {
            assert_eq!(l.ncols(), 11);
        }
    }
    // Truncation: the dropped part is positive semi-definite and at most 5 % of the trace.
    let (lambda, tol) = (0.3, 0.05);
    let l = correlated_factor(&x, &w, lambda, tol).unwrap();
    let c = covariance(&x, &w, lambda);
    let rest = &c - &l * l.transpose();
    let all = correlated_factor(&x, &w, lambda, 0.0).unwrap().ncols();
    println!(
        "λ = 0.3, tolerance 5 %: {} of {all} columns, dropped trace {:.2} %",
        l.ncols(),
        100.0 * rest.trace() / c.trace()
    );
    assert!(l.ncols() < all);
    assert!(rest.trace() <= tol * c.trace() + 1e-15);
    assert!(rest.trace() >= 0.0);
    let min_eig = rest.symmetric_eigenvalues().min();
    assert!(min_eig >= -1e-15, "{min_eig}");
    // Fewest columns: one column less would miss more than 5 %.
    let l1 = l.columns(0, l.ncols() - 1).into_owned();
    assert!((&c - &l1 * l1.transpose()).trace() > tol * c.trace());
}

#[test]
fn correlated_forces_have_the_expected_correlation() {
    let s = cross_flow();
    let f_max = 200.0;
    let x = [0.0, 0.2, 0.5];
    let w = [0.1, 0.15, 0.1];
    let lambda = 0.4;
    let l = correlated_factor(&x, &w, lambda, 0.0).unwrap();
    let r = l.ncols();
    let mut g = RandomChannels::new(&s, r, 2024, f_max, "t").unwrap();
    let fs = g.sample_rate();
    let n = 1 << 18;
    let mut xi = vec![0.0; r];
    let mut f = vec![vec![0.0; n]; 3];
    for k in 0..n {
        g.values(k as f64 / fs, &mut xi);
        for (i, fi) in f.iter_mut().enumerate() {
            fi[k] = (0..r).map(|j| l[(i, j)] * xi[j]).sum();
        }
    }
    // Var(ρ̂) = (1 − ρ²)² Σ_τ a(τ)² / N (Bartlett), a the common autocorrelation.
    let s_obs = |f: f64| s.psd(f) / sinc(f / fs).powi(4);
    let var = simpson(s_obs, 0.0, f_max, 100_000);
    let sum_a2 = 0.5 * fs * simpson(|f| s_obs(f).powi(2), 0.0, f_max, 100_000) / (var * var);
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let expected = (-(x[b] - x[a]) / lambda).exp();
        let cab: f64 = f[a].iter().zip(&f[b]).map(|(p, q)| p * q).sum::<f64>() / n as f64;
        let rho = cab / (mean_square(&f[a]) * mean_square(&f[b])).sqrt();
        let se = (1.0 - expected * expected) * (sum_a2 / n as f64).sqrt();
        println!(
            "nodes {a},{b}: ρ̂ = {rho:.4}, exp(−Δx/λ) = {expected:.4}, error {:.2} SE",
            (rho - expected) / se
        );
        assert!((rho - expected).abs() <= Z_999 * se);
        // The force variance is w² σ², relative SE √(∫S_obs²/T)/σ².
        let v = mean_square(&f[a]) / (w[a] * w[a] * var);
        let se_v =
            (simpson(|f| s_obs(f).powi(2), 0.0, f_max, 100_000) * fs / n as f64).sqrt() / var;
        assert!(
            (v - 1.0).abs() <= Z_999 * se_v,
            "variance ratio {v} (SE {se_v})"
        );
    }
}
