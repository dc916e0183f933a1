//! The one-sided power spectral density of the turbulent force per unit length
//! ([`Spectrum`]): a table interpolated log-log, or the cross-flow model of Code_Aster
//! (`docs/LOADS.md`, "Random turbulence").

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
    pub(super) fn feature_scale(&self, f_max: f64) -> Option<f64> {
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

/// What the turbulence tests share.
#[cfg(test)]
pub(super) mod fixtures {
    use super::Spectrum;
    use crate::error::Error;

    /// The field an input error names.
    pub(in crate::loads::turbulence) fn field_of(e: Error) -> String {
        e.field().expect("an input error").to_string()
    }

    /// The table spectrum of `(f, s)`.
    pub(in crate::loads::turbulence) fn table(f: &[f64], s: &[f64]) -> Spectrum {
        Spectrum::Table {
            frequency_hz: f.to_vec(),
            psd: s.to_vec(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::fixtures::{field_of, table};
    use super::*;
    use crate::loads::turbulence::RandomChannels;
    use std::f64::consts::PI;

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
}
