//! Loads against independent results: a uniform line load on a pinned–pinned tube gives the
//! beam-theory static deflection; tabulated histories (inline, CSV, `.npy`) interpolate and
//! hold their ends; sums of sines; the turbulence's modal vectors reproduce the spatial
//! covariance they were built from.

use std::f64::consts::PI;
use std::path::Path;

use fretdyn::case::Case;
use fretdyn::loads::TimeHistory;
use fretdyn::loads::spatial_correlation::line_covariance;

fn tube_case(extra: &str) -> String {
    const SG_TUBE: &str = include_str!("fixtures/sg_tube.toml");
    format!(
        r#"
[time]
dt = 1e-5
duration = 1e-3

{SG_TUBE}path = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
mesh_size = 0.05
modes = 24

[[structure.supports]]
at = [0.0, 0.0, 0.0]
type = "pinned"

[[structure.supports]]
at = [2.0, 0.0, 0.0]
type = "pinned"

[[structure.points]]
name = "mid"
at = [1.0, 0.0, 0.0]

{extra}
"#
    )
}

/// Static response of the modes to the load vector `g`: `q_i = g_i / ω_i²`, at the point.
fn static_deflection(case: &Case, row: &[f64], axis: usize) -> f64 {
    let b = &case.model.basis;
    let p = b.modes();
    let rows = &b.points[b.point_index("mid").unwrap()].rows;
    (0..p)
        .filter(|&i| b.omega[i] > 0.0)
        .map(|i| rows[axis * p + i] * row[i] / (b.omega[i] * b.omega[i]))
        .sum()
}

/// A uniform load `f` along a pinned–pinned tube of length L: mid-span deflection
/// `5 f L⁴ / (384 E I)`, `I = π (D⁴ − d⁴)/64` — from the line load's modal vector and the
/// modes only. On half the span, `[0, L/2]`: half of it by symmetry.
#[test]
fn uniform_line_load_gives_the_beam_theory_deflection() {
    let f = 150.0;
    let case = Case::from_toml_str(
        &tube_case(&format!(
            "[[line_loads]]\nforce_per_length = [0.0, {f}, 0.0]\n\n[[line_loads]]\nspan = [0.0, 1.0]\nforce_per_length = [0.0, 0.0, {f}]\n"
        )),
        Path::new("."),
    )
    .unwrap();
    let (d, t, e, l): (f64, f64, f64, f64) = (19.05e-3, 1.09e-3, 2.0e11, 2.0);
    let inner: f64 = d - 2.0 * t;
    let i = PI * (d.powi(4) - inner.powi(4)) / 64.0;
    let expected = 5.0 * f * l.powi(4) / (384.0 * e * i);
    let full = static_deflection(&case, &case.model.modal_loads[0].row, 1);
    let half = static_deflection(&case, &case.model.modal_loads[1].row, 2);
    eprintln!(
        "mid-span deflection {full:.6e} m, beam theory {expected:.6e} m; half span {half:.6e} m"
    );
    assert!(
        (full - expected).abs() < 1e-3 * expected,
        "{full} vs {expected}"
    );
    assert!((half - 0.5 * expected).abs() < 1e-3 * expected, "{half}");
    // the load is in y only: the y and z bending modes come in pairs of equal frequency,
    // mixed by the eigen solver, whose z parts cancel — except for a pair that the mode count
    // cuts in two, whose static share is ~1e-6 of the deflection
    let cross = static_deflection(&case, &case.model.modal_loads[0].row, 2);
    eprintln!("z deflection under the y load: {cross:.1e} m");
    assert!(cross.abs() < 1e-5 * expected, "{cross}");
}

#[test]
fn tables_interpolate_linearly_and_hold_their_ends_from_every_source() {
    let dir = std::env::temp_dir().join(format!("fretdyn-loads-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("h.csv"),
        "# a history\nt, s\n0.0, 0.0\n1e-3; 2.0\n3e-3 -2.0\n",
    )
    .unwrap();
    let a = ndarray::arr2(&[[0.0, 0.0], [1e-3, 2.0], [3e-3, -2.0]]);
    ndarray_npy::write_npy(dir.join("h.npy"), &a).unwrap();
    let point = "[[structure.points]]\nname = \"load\"\nat = [0.5, 0.0, 0.0]\n";
    for source in [
        "table = [[0.0, 0.0], [1e-3, 2.0], [3e-3, -2.0]]",
        "file = \"h.csv\"",
        "file = \"h.npy\"",
    ] {
        let text = tube_case(&format!(
            "{point}\n[[loads]]\npoint = \"load\"\nforce = [0.0, 1.0, 0.0]\nhistory = {{ type = \"table\", {source} }}\n"
        ));
        let case = Case::from_toml_str(&text, &dir).unwrap();
        let h = &case.model.loads[0].history;
        for (t, s) in [
            (-1.0, 0.0),
            (0.0, 0.0),
            (5e-4, 1.0),
            (1e-3, 2.0),
            (2e-3, 0.0),
            (2.5e-3, -1.0),
            (3e-3, -2.0),
            (10.0, -2.0),
        ] {
            assert!(
                (h.value(t) - s).abs() < 1e-12,
                "{source}: s({t}) = {}",
                h.value(t)
            );
        }
    }
    // a bad table names the row
    let text = tube_case(&format!(
        "{point}\n[[loads]]\npoint = \"load\"\nforce = [0.0, 1.0, 0.0]\nhistory = {{ type = \"table\", table = [[0.0, 0.0], [0.0, 1.0]] }}\n"
    ));
    let err = Case::from_toml_str(&text, &dir).unwrap_err().to_string();
    assert!(err.contains("loads[0].history.table[1]"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sums_of_sines_add_their_terms() {
    let h = TimeHistory::Sines(vec![
        fretdyn::loads::Sine {
            amplitude: 2.0,
            frequency_hz: 3.0,
            phase: 0.5,
        },
        fretdyn::loads::Sine {
            amplitude: -1.0,
            frequency_hz: 7.5,
            phase: 0.0,
        },
    ]);
    for t in [0.0, 0.013, 0.4] {
        let expected = 2.0 * (2.0 * PI * 3.0 * t + 0.5).sin() - (2.0 * PI * 7.5 * t).sin();
        assert!((h.value(t) - expected).abs() < 1e-14);
    }
    assert!(TimeHistory::Sines(vec![]).validate("h").is_err());
}

/// The modal vectors `g_dj` of a turbulent load reproduce, summed over their channels, the
/// modal cross-spectral matrix of the definition: `Σ_j g_dj g_djᵀ = Φ_eᵀ C Φ_e` with
/// `C_ik = ∫∫ N_i(s) N_k(s') exp(−|s − s'|/λ) ds ds'` over the nodes of the span
/// (`line_covariance`, itself checked against closed forms and a brute-force sum), up to the
/// truncation tolerance, and the two directions load separate modes.
#[test]
fn turbulence_modal_vectors_reproduce_the_spatial_covariance() {
    let lambda = 0.2;
    let text = tube_case(&format!(
        "[[turbulence]]\nspan = [0.5, 2.0]\ndirections = [[0.0, 1.0, 0.0], [0.0, 0.0, 2.0]]\ncorrelation_length = {lambda}\nseed = 3\nf_max = 100.0\ntolerance = 1e-6\nspectrum = {{ type = \"cross_flow\", velocity = 2.0, density = 1000.0 }}\n"
    ));
    let case = Case::from_toml_str(&text, Path::new(".")).unwrap();
    let tube = case.tube.as_ref().unwrap();
    let p = case.model.basis.modes();
    let load = &case.model.turbulence[0];
    let r = load.channels(p);
    let nodes = tube.structure.line_nodes(&tube.basis, 0.5, 2.0);
    let total: f64 = nodes.iter().map(|n| n.weight).sum();
    assert!(
        (total - 1.5).abs() < 1e-12,
        "tributary lengths sum to the span: {total}"
    );
    let (_, cells) = tube.structure.line_cells(0.5, 2.0);
    let cov = line_covariance(nodes.len(), &cells, lambda).unwrap();
    for (dir, axis) in [(0usize, 1usize), (1, 2)] {
        // Φ_eᵀ C Φ_e from the definition
        let mut expected = vec![0.0; p * p];
        for (ia, a) in nodes.iter().enumerate() {
            for (ib, b) in nodes.iter().enumerate() {
                let c = cov[(ia, ib)];
                for i in 0..p {
                    for k in 0..p {
                        expected[i * p + k] += a.rows[axis * p + i] * c * b.rows[axis * p + k];
                    }
                }
            }
        }
        let mut got = vec![0.0; p * p];
        for j in dir * r / 2..(dir + 1) * r / 2 {
            let g = &load.rows[j * p..(j + 1) * p];
            for i in 0..p {
                for k in 0..p {
                    got[i * p + k] += g[i] * g[k];
                }
            }
        }
        let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = got
            .iter()
            .zip(&expected)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        eprintln!(
            "direction {dir}: {} channels, max error {:.1e} of {scale:.3e}",
            r / 2,
            err
        );
        assert!(err < 1e-5 * scale, "{err} vs {scale}");
    }
}
