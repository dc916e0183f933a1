//! Support-active modes (`[stability]` conditions, THEORY §16.3, docs/FLOW.md) against closed
//! forms and symmetry:
//! - a straight Euler–Bernoulli tube pinned at its ends (its own supports) and at inner points
//!   held by a `pinned` condition is the continuous beam on pinned supports: with equal spans
//!   every band of frequencies starts at the single span's pinned frequency
//!   `f_n = (nπ/L)² √(EI/m)/2π`; with any spans the frequencies are the roots of the exact
//!   characteristic determinant, built and solved here (per span
//!   `w = A sin βx + B cos βx + C sinh βx + D cosh βx`; `w = 0` at every support, `w'' = 0` at
//!   the ends, `w'` and `w''` continuous over the inner supports; the sign changes of the
//!   determinant bracketed on a fine grid of `βL`, then bisected). Mesh: 0.02 m elements
//!   (50 per metre of span), the supports at path vertices. Agreement: 1e-4 relative asked;
//!   the measured worst is printed;
//! - the U-bend of `examples/ubend_flow.toml`: its plane is a plane of symmetry, so every mode
//!   is in-plane or out-of-plane (share 0 or 1); holding its AVB points out of plane only
//!   leaves the in-plane frequencies as they are and raises the out-of-plane ones;
//! - bad input names its field.

use std::f64::consts::PI;
use std::path::Path;

use fretdyn::Case;
use fretdyn::loads::flow::{Plane, SUPPORT_INACTIVE};
use fretdyn::structure::beam::Dof;
use nalgebra::DMatrix;

const D: f64 = 0.02;
const T: f64 = 0.001;
const E: f64 = 2.0e11;
const RHO_T: f64 = 8000.0;
const RHO_I: f64 = 1000.0;
const RHO_O: f64 = 800.0;
const CA: f64 = 1.2;
const MESH: f64 = 0.02;

/// `√(EI/m)` of the section, by hand (m: tube, inner fluid, added mass `C_a ρ_o π D²/4`).
fn beam_constant() -> f64 {
    let di = D - 2.0 * T;
    let i = PI / 64.0 * (D.powi(4) - di.powi(4));
    let m = RHO_T * PI / 4.0 * (D * D - di * di)
        + RHO_I * PI / 4.0 * di * di
        + CA * RHO_O * PI / 4.0 * D * D;
    (E * i / m).sqrt()
}

/// A straight tube along x over spans `spans` (supports at the path vertices): pinned at its
/// ends by its own supports (axial motion and twist held at the first), the inner supports
/// named `s1`, `s2`, … and pinned by the condition `inner`; `modes` kept.
fn multispan(spans: &[f64], modes: usize) -> String {
    let mut x = vec![0.0];
    for l in spans {
        x.push(x.last().unwrap() + l);
    }
    let path: Vec<String> = x.iter().map(|v| format!("[{v}, 0.0, 0.0]")).collect();
    let end = x.last().unwrap();
    let mut points = String::new();
    let mut names = Vec::new();
    for (k, v) in x[1..x.len() - 1].iter().enumerate() {
        points.push_str(&format!(
            "[[structure.points]]\nname = \"s{}\"\nat = [{v}, 0.0, 0.0]\n\n",
            k + 1
        ));
        names.push(format!("\"s{}\"", k + 1));
    }
    format!(
        r#"
[time]
dt = 1e-6
duration = 1e-4

[structure]
type = "tube"
outer_diameter = {D}
wall_thickness = {T}
young_modulus = {E}
poisson_ratio = 0.3
density = {RHO_T}
inner_fluid_density = {RHO_I}
outer_fluid_density = {RHO_O}
added_mass_coefficient = {CA}
path = [{}]
mesh_size = {MESH}
modes = 4
damping_ratio = 0.02

[[structure.supports]]
at = [0.0, 0.0, 0.0]
type = "dofs"
fixed = ["ux", "uy", "uz", "rx"]

[[structure.supports]]
at = [{end}, 0.0, 0.0]
type = "pinned"

{points}
[[stability.conditions]]
name = "inner"
pinned = [{}]
modes = {modes}
"#,
        path.join(", "),
        names.join(", ")
    )
}

fn case(text: &str) -> Case {
    Case::from_toml_str(text, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

/// The bending frequencies (Hz, ascending) among the modes of the condition `inner`: the
/// modes whose transverse translations carry most of their kinetic energy
/// (`m h Σ (u_y² + u_z²) > 1/2` of `φᵀ M φ = 1`; axial and torsion modes carry none).
fn bending_frequencies(c: &Case) -> Vec<f64> {
    let tube = c.tube.as_ref().unwrap();
    let condition = &c.stability_checks.as_ref().unwrap().conditions[0];
    let b = tube
        .structure
        .constrained_basis(&tube.basis, &condition.constraints, condition.selection)
        .unwrap();
    let m = tube.structure.beam.tube.mass_per_length();
    let nodes = tube.structure.beam.mesh.nodes.len();
    let shapes: &DMatrix<f64> = &b.modes.shapes;
    (0..shapes.ncols())
        .filter(|&j| {
            let mut sum = 0.0;
            for node in 0..nodes {
                for dof in [Dof::Uy, Dof::Uz] {
                    if let Some(i) = b.assembled.reduced_index(node, dof) {
                        sum += shapes[(i, j)].powi(2);
                    }
                }
            }
            m * MESH * sum > 0.5
        })
        .map(|j| b.modes.omega[j] / (2.0 * PI))
        .collect()
}

/// The characteristic determinant of the continuous beam on pinned supports over `spans`
/// at the wavenumber `beta` (module documentation).
fn determinant(spans: &[f64], beta: f64) -> f64 {
    let n = spans.len();
    let mut a = DMatrix::<f64>::zeros(4 * n, 4 * n);
    let mut row = 0;
    // per span: w, w'/β, w''/β² at x = 0 and x = L (coefficients of A, B, C, D)
    let at0 = |k: usize| -> [f64; 4] {
        match k {
            0 => [0.0, 1.0, 0.0, 1.0],
            1 => [1.0, 0.0, 1.0, 0.0],
            _ => [0.0, -1.0, 0.0, 1.0],
        }
    };
    let at_l = |l: f64, k: usize| -> [f64; 4] {
        let x = beta * l;
        let (s, c, sh, ch) = (x.sin(), x.cos(), x.sinh(), x.cosh());
        match k {
            0 => [s, c, sh, ch],
            1 => [c, -s, ch, sh],
            _ => [-s, -c, sh, ch],
        }
    };
    let mut put = |row: usize, span: usize, v: [f64; 4], sign: f64| {
        for (j, x) in v.iter().enumerate() {
            a[(row, 4 * span + j)] += sign * x;
        }
    };
    for (i, l) in spans.iter().enumerate() {
        put(row, i, at0(0), 1.0);
        put(row + 1, i, at_l(*l, 0), 1.0);
        row += 2;
    }
    put(row, 0, at0(2), 1.0);
    put(row + 1, n - 1, at_l(spans[n - 1], 2), 1.0);
    row += 2;
    for (i, l) in spans.iter().enumerate().take(n - 1) {
        for k in [1, 2] {
            put(row, i, at_l(*l, k), 1.0);
            put(row, i + 1, at0(k), -1.0);
            row += 1;
        }
    }
    assert_eq!(row, 4 * n);
    a.determinant()
}

/// The lowest `count` roots `β` of [`determinant`], bracketed on a grid of `β` of step
/// `1e-4/L_max` and bisected to round-off.
fn roots(spans: &[f64], count: usize) -> Vec<f64> {
    let l_max = spans.iter().copied().fold(0.0, f64::max);
    let step = 1e-4 / l_max;
    let mut found = Vec::new();
    let mut b0 = step;
    let mut d0 = determinant(spans, b0);
    while found.len() < count {
        let b1 = b0 + step;
        let d1 = determinant(spans, b1);
        if d0 == 0.0 || d0.signum() != d1.signum() {
            let (mut lo, mut hi, mut dlo) = (b0, b1, d0);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                let dm = determinant(spans, mid);
                if dm.signum() == dlo.signum() && dm != 0.0 {
                    (lo, dlo) = (mid, dm);
                } else {
                    hi = mid;
                }
                if hi - lo <= 4.0 * f64::EPSILON * hi {
                    break;
                }
            }
            found.push(0.5 * (lo + hi));
        }
        (b0, d0) = (b1, d1);
    }
    found
}

/// The FE bending frequencies (degenerate pairs, y and z) against the roots, each twice;
/// returns the worst relative difference.
fn compare(spans: &[f64], count: usize) -> f64 {
    let c = case(&multispan(spans, 2 * count + 6));
    let fe = bending_frequencies(&c);
    assert!(fe.len() >= 2 * count, "{} bending modes", fe.len());
    let a = beam_constant();
    let mut worst = 0.0f64;
    for (k, beta) in roots(spans, count).iter().enumerate() {
        let f = beta * beta * a / (2.0 * PI);
        for fe in [fe[2 * k], fe[2 * k + 1]] {
            let e = (fe / f - 1.0).abs();
            assert!(
                e < 1e-4,
                "spans {spans:?}, root {k}: FE {fe} Hz, exact {f} Hz"
            );
            worst = worst.max(e);
        }
    }
    eprintln!("spans {spans:?}: {count} roots, worst relative difference {worst:e}");
    worst
}

#[test]
fn support_active_equal_spans_start_each_band_at_the_single_span_frequency() {
    let spans = [1.0, 1.0, 1.0];
    let c = case(&multispan(&spans, 24));
    let fe = bending_frequencies(&c);
    let a = beam_constant();
    // three equal spans: bands of 3 frequencies (each a y/z pair), the n-th starting at the
    // single span's n-th pinned frequency
    for n in 1..=3 {
        let f = (n as f64 * PI / spans[0]).powi(2) * a / (2.0 * PI);
        for fe in [fe[6 * (n - 1)], fe[6 * (n - 1) + 1]] {
            let e = (fe / f - 1.0).abs();
            eprintln!("band {n}: FE {fe} Hz, single span {f} Hz, relative {e:e}");
            assert!(e < 1e-4);
        }
    }
    // and every frequency against the characteristic equation
    compare(&spans, 9);
}

#[test]
fn support_active_unequal_spans_match_the_characteristic_equation() {
    compare(&[1.0, 1.4], 6);
    compare(&[0.8, 1.2, 1.0], 6);
}

#[test]
fn support_active_characteristic_equation_of_one_span_is_the_pinned_beam() {
    // the independent solver itself: one span gives βL = nπ
    let r = roots(&[1.3], 3);
    for (k, b) in r.iter().enumerate() {
        assert!((b * 1.3 / ((k + 1) as f64 * PI) - 1.0).abs() < 1e-12, "{b}");
    }
}

const UBEND: &str = include_str!("../../../examples/ubend_flow.toml");

/// The U-bend example without its `[[stability.conditions]]`, `stability` appended.
fn ubend_text(stability: &str) -> String {
    let start = UBEND.find("[[stability.conditions]]").unwrap();
    let end = UBEND.find("# Turbulence of a zone").unwrap();
    format!("{}{}\n{stability}", &UBEND[..start], &UBEND[end..])
}

/// The U-bend example's stability report with the conditions `stability`.
fn ubend(stability: &str) -> fretdyn::loads::flow::StabilityReport {
    let c = case(&ubend_text(stability));
    c.stability_checks().unwrap().unwrap()
}

#[test]
fn support_active_ubend_avb_held_out_of_plane_raises_only_out_of_plane_modes() {
    let r = ubend(
        "[[stability.conditions]]\nname = \"avb_out\"\nout_of_plane = [\"avb_cold\", \"avb_hot\"]\n",
    );
    let of = |condition: &str, plane: Plane| -> Vec<f64> {
        r.modes
            .iter()
            .filter(|m| m.condition == condition && m.plane == Some(plane))
            .map(|m| m.frequency_hz)
            .collect()
    };
    // symmetry: every mode is in one plane
    for m in &r.modes {
        let q = m.out_of_plane_share.unwrap();
        assert!(!(1e-9..=1.0 - 1e-9).contains(&q), "{m:?}");
    }
    let (free_in, free_out) = (
        of(SUPPORT_INACTIVE, Plane::InPlane),
        of(SUPPORT_INACTIVE, Plane::OutOfPlane),
    );
    let (held_in, held_out) = (
        of("avb_out", Plane::InPlane),
        of("avb_out", Plane::OutOfPlane),
    );
    assert!(!free_in.is_empty() && !free_out.is_empty());
    assert_eq!(free_in.len() + free_out.len(), 30);
    for (a, b) in free_in.iter().zip(&held_in) {
        assert!((a / b - 1.0).abs() < 1e-9, "in plane: {a} vs {b}");
    }
    assert!(held_in.len() >= free_in.len());
    for (a, b) in free_out.iter().zip(&held_out) {
        assert!(b >= &(a * (1.0 - 1e-9)), "out of plane: {a} vs {b}");
    }
    assert!(held_out[0] > 1.5 * free_out[0], "{held_out:?} {free_out:?}");
}

#[test]
fn support_active_bad_input_names_its_field() {
    let field = |stability: &str| {
        let e = Case::from_toml_str(&ubend_text(stability), Path::new("."))
            .expect_err("an input error");
        e.field().unwrap().to_string()
    };
    assert_eq!(
        field("[[stability.conditions]]\nname = \"x\"\npinned = [\"nowhere\"]\n"),
        "stability.conditions[0].pinned[0]"
    );
    assert_eq!(
        field("[[stability.conditions]]\nname = \"support_inactive\"\npinned = [\"apex\"]\n"),
        "stability.conditions[0].name"
    );
    assert_eq!(
        field("[[stability.conditions]]\nname = \"x\"\n"),
        "stability.conditions[0]"
    );
    assert_eq!(
        field("[stability]\nplane_normal = [0.0, 0.0, 0.0]\n"),
        "stability.plane_normal"
    );
    // a straight tube has no plane
    let straight = multispan(&[1.0, 1.0], 4).replace("pinned = [\"s1\"]", "in_plane = [\"s1\"]");
    let e = Case::from_toml_str(&straight, Path::new(".")).expect_err("no plane");
    assert_eq!(e.field(), Some("stability.conditions[0].in_plane[0]"));
}
