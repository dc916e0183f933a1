//! Beam finite elements and modal analysis against the analytic Euler–Bernoulli frequencies.

use fretdyn::structure::beam::{
    BeamModel, Fluid, Material, Mesh, Restraint, Theory, Tube, TubeSection, clamped, pinned,
};
use fretdyn::structure::eigen::{ModeSelection, lowest_modes, orthonormality_error};
use nalgebra::Vector3;

fn tube(theory: Theory, fluid: Fluid) -> Tube {
    Tube {
        section: TubeSection {
            outer_diameter: 19.05e-3,
            wall_thickness: 1.09e-3,
        },
        material: Material {
            young_modulus: 2.0e11,
            poisson_ratio: 0.3,
            density: 8200.0,
        },
        fluid,
        theory,
    }
}

#[derive(Clone, Copy, Debug)]
enum Ends {
    SimplySupported,
    ClampedClamped,
    Cantilever,
}

/// β_k L of the first five bending modes.
fn beta_l(ends: Ends) -> [f64; 5] {
    match ends {
        Ends::SimplySupported => [1.0, 2.0, 3.0, 4.0, 5.0].map(|k| k * std::f64::consts::PI),
        Ends::ClampedClamped => [
            4.730040745,
            7.853204624,
            10.99560784,
            14.13716549,
            17.27875966,
        ],
        Ends::Cantilever => [
            1.875104069,
            4.694091133,
            7.854757438,
            10.99554073,
            14.13716839,
        ],
    }
}

/// A 1 m tube along `direction` with `elements` elements and the given end conditions.
fn model(ends: Ends, elements: usize, direction: Vector3<f64>, t: Tube) -> BeamModel {
    let d = direction.normalize();
    let mesh = Mesh::polyline(&[Vector3::zeros(), d], 1.0 / elements as f64).unwrap();
    assert_eq!(mesh.elements.len(), elements);
    let last = mesh.nodes.len() - 1;
    let restraints = match ends {
        // pinned ends; axial and torsion held at the first end so that there is no rigid mode
        Ends::SimplySupported => vec![
            (
                0,
                [
                    Restraint::Fixed,
                    Restraint::Fixed,
                    Restraint::Fixed,
                    Restraint::Fixed,
                    Restraint::Free,
                    Restraint::Free,
                ],
            ),
            (last, pinned()),
        ],
        Ends::ClampedClamped => vec![(0, clamped()), (last, clamped())],
        Ends::Cantilever => vec![(0, clamped())],
    };
    BeamModel {
        mesh,
        tube: t,
        restraints,
    }
}

/// Frequencies (Hz) of a model, ascending, first `count`.
fn frequencies(m: &BeamModel, count: usize) -> Vec<f64> {
    let a = m.assemble().unwrap();
    let modes = lowest_modes(&a.mass, &a.stiffness, ModeSelection::Count(count)).unwrap();
    assert!(orthonormality_error(&a.mass, &modes.shapes) < 1e-10);
    modes
        .omega
        .iter()
        .map(|w| w / std::f64::consts::TAU)
        .collect()
}

fn analytic_bending_hz(t: &Tube, ends: Ends) -> [f64; 5] {
    let ei = t.material.young_modulus * t.section.second_moment();
    let m = t.mass_per_length();
    beta_l(ends).map(|b| b * b * (ei / m).sqrt() / std::f64::consts::TAU)
}

/// The bending modes come in pairs (y and z planes): pick one of each pair.
fn bending_pairs(f: &[f64], t: &Tube, ends: Ends) -> Vec<f64> {
    // the axial/torsional modes of a 1 m steel tube are above 1 kHz: keep the paired ones
    let target = analytic_bending_hz(t, ends);
    target
        .iter()
        .map(|a| {
            let close: Vec<f64> = f
                .iter()
                .copied()
                .filter(|x| (x - a).abs() < 0.01 * a)
                .collect();
            assert_eq!(
                close.len(),
                2,
                "mode near {a} Hz should appear in both planes: {f:?}"
            );
            assert!(
                (close[0] - close[1]).abs() <= 1e-9 * a,
                "planes differ: {close:?}"
            );
            close[0]
        })
        .collect()
}

/// 40 elements: first five bending frequencies within 1e-3 (in fact within 2e-6).
#[test]
fn bending_frequencies_match_euler_bernoulli() {
    let t = tube(Theory::EulerBernoulli, Fluid::default());
    for ends in [
        Ends::SimplySupported,
        Ends::ClampedClamped,
        Ends::Cantilever,
    ] {
        let f = frequencies(&model(ends, 40, Vector3::x(), t), 14);
        let fe = bending_pairs(&f, &t, ends);
        for (k, (got, exact)) in fe.iter().zip(analytic_bending_hz(&t, ends)).enumerate() {
            let err = (got - exact).abs() / exact;
            println!(
                "{ends:?} mode {}: {got:.4} Hz, analytic {exact:.4} Hz, error {err:.2e}",
                k + 1
            );
            assert!(
                err < 1e-3,
                "{ends:?} mode {}: {got} Hz vs {exact} Hz ({err:e})",
                k + 1
            );
        }
    }
}

/// Axial and torsional modes of a cantilever: `(2k−1)π/(2L) √(E/ρ)` and `√(G/ρ)`.
#[test]
fn axial_and_torsion_frequencies_of_a_cantilever() {
    let t = tube(Theory::EulerBernoulli, Fluid::default());
    let m = model(Ends::Cantilever, 40, Vector3::x(), t);
    let f = frequencies(&m, 40);
    let e = t.material.young_modulus;
    let g = e / (2.0 * 1.3);
    let rho = t.material.density;
    let axial = (e / rho).sqrt() / 4.0; // (π/2L)√(E/ρ) / 2π with L = 1
    let torsion = (g / rho).sqrt() / 4.0;
    for target in [axial, torsion] {
        let nearest = f
            .iter()
            .copied()
            .min_by(|a, b| (a - target).abs().total_cmp(&(b - target).abs()))
            .unwrap();
        assert!(
            (nearest - target).abs() < 1e-3 * target,
            "{nearest} vs {target}"
        );
    }
}

/// Mesh convergence of the 5th clamped–clamped mode: the error falls as h⁴ (consistent mass,
/// cubic Hermite elements). Printed with `--nocapture`; the table is in docs/VERIFICATION.md.
#[test]
fn mesh_convergence_of_the_fifth_clamped_mode() {
    let t = tube(Theory::EulerBernoulli, Fluid::default());
    let exact = analytic_bending_hz(&t, Ends::ClampedClamped)[4];
    let mut previous = f64::INFINITY;
    for elements in [4, 8, 16, 32, 64] {
        let f = frequencies(&model(Ends::ClampedClamped, elements, Vector3::x(), t), 10);
        let got = f
            .iter()
            .copied()
            .min_by(|a, b| (a - exact).abs().total_cmp(&(b - exact).abs()))
            .unwrap();
        let err = (got - exact).abs() / exact;
        println!("{elements:>3} elements: f5 = {got:.6} Hz, exact {exact:.6} Hz, error {err:.3e}");
        assert!(err < previous, "error must fall with the mesh size");
        if previous.is_finite() && err > 1e-9 {
            // between h⁴ (ratio 16) and h² (ratio 4) per halving once in the asymptotic range
            assert!(previous / err > 3.0, "{elements}: ratio {}", previous / err);
        }
        previous = err;
    }
}

#[test]
fn frequencies_do_not_depend_on_the_orientation() {
    let t = tube(Theory::EulerBernoulli, Fluid::default());
    let a = frequencies(&model(Ends::ClampedClamped, 16, Vector3::x(), t), 12);
    for dir in [
        Vector3::new(1.0, 2.0, 3.0),
        Vector3::z(),
        Vector3::new(0.0, -1.0, 1e-3),
    ] {
        let b = frequencies(&model(Ends::ClampedClamped, 16, dir, t), 12);
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-9 * x, "{dir:?}: {x} vs {y}");
        }
    }
}

/// Inner fluid and outer added mass lower the bending frequencies by √(m_tube/m_total).
#[test]
fn fluid_mass_scales_the_bending_frequencies() {
    let dry = tube(Theory::EulerBernoulli, Fluid::default());
    let wet = tube(
        Theory::EulerBernoulli,
        Fluid {
            inner_density: 1000.0,
            outer_density: 750.0,
            added_mass_coefficient: 1.2,
        },
    );
    let fd = bending_pairs(
        &frequencies(&model(Ends::ClampedClamped, 20, Vector3::x(), dry), 12),
        &dry,
        Ends::ClampedClamped,
    );
    let fw = bending_pairs(
        &frequencies(&model(Ends::ClampedClamped, 20, Vector3::x(), wet), 12),
        &wet,
        Ends::ClampedClamped,
    );
    let ratio = (dry.mass_per_length() / wet.mass_per_length()).sqrt();
    for (d, w) in fd.iter().zip(&fw) {
        assert!((w / d - ratio).abs() <= 1e-9, "{w}/{d} vs {ratio}");
    }
}

/// Timoshenko lowers the frequencies of a stubby beam markedly and of a slender one barely.
#[test]
fn timoshenko_matters_only_for_stubby_beams() {
    let eb = tube(Theory::EulerBernoulli, Fluid::default());
    let ti = tube(Theory::Timoshenko, Fluid::default());
    let f = |t: Tube, length: f64| {
        let mut m = model(Ends::ClampedClamped, 40, Vector3::x(), t);
        for n in &mut m.mesh.nodes {
            *n *= length;
        }
        frequencies(&m, 2)[0]
    };
    // L/D ≈ 5
    let (a, b) = (f(eb, 0.1), f(ti, 0.1));
    assert!(
        b < 0.95 * a,
        "stubby: Timoshenko {b} vs Euler–Bernoulli {a}"
    );
    // L/D ≈ 260
    let (a, b) = (f(eb, 5.0), f(ti, 5.0));
    assert!(b < a && (a - b) / a < 1e-3, "slender: {b} vs {a}");
}

#[test]
fn a_free_tube_has_six_rigid_modes_and_springs_raise_frequencies() {
    let t = tube(Theory::EulerBernoulli, Fluid::default());
    let mut free = model(Ends::Cantilever, 10, Vector3::x(), t);
    free.restraints.clear();
    let f = frequencies(&free, 8);
    assert!(f[..6].iter().all(|x| *x == 0.0), "{f:?}");
    assert!(f[6] > 10.0);
    let c = frequencies(&model(Ends::Cantilever, 10, Vector3::x(), t), 2);
    let mut sprung = model(Ends::Cantilever, 10, Vector3::x(), t);
    let last = sprung.mesh.nodes.len() - 1;
    sprung.restraints.push((
        last,
        [
            Restraint::Free,
            Restraint::Spring(1e4),
            Restraint::Spring(1e4),
            Restraint::Free,
            Restraint::Free,
            Restraint::Free,
        ],
    ));
    let s = frequencies(&sprung, 2);
    assert!(s[0] > c[0] * 1.5, "{s:?} vs {c:?}");
}

#[test]
fn u_bend_mesh_is_symmetric_and_has_positive_modes() {
    let mesh = Mesh::u_bend(1.0, 0.3, 0.05).unwrap();
    let n = mesh.nodes.len();
    for i in 0..n {
        let (a, b) = (mesh.nodes[i], mesh.nodes[n - 1 - i]);
        assert!((a.x + b.x).abs() < 1e-12 && (a.z - b.z).abs() < 1e-12 && a.y == 0.0);
    }
    let max_len = mesh
        .elements
        .iter()
        .map(|[a, b]| (mesh.nodes[*b] - mesh.nodes[*a]).norm())
        .fold(0.0, f64::max);
    assert!(max_len <= 0.05 + 1e-12);
    let m = BeamModel {
        mesh,
        tube: tube(Theory::EulerBernoulli, Fluid::default()),
        restraints: vec![(0, clamped()), (n - 1, clamped())],
    };
    let f = frequencies(&m, 10);
    assert!(f.iter().all(|x| x.is_finite() && *x > 0.0), "{f:?}");
}

#[test]
fn bad_tubes_and_meshes_are_errors() {
    let mut t = tube(Theory::EulerBernoulli, Fluid::default());
    t.section.wall_thickness = -1e-3;
    assert!(
        t.validate("structure")
            .unwrap_err()
            .to_string()
            .contains("wall_thickness")
    );
    t.section.wall_thickness = 0.02;
    assert!(
        t.validate("structure")
            .unwrap_err()
            .to_string()
            .contains("outer radius")
    );
    let mut t = tube(Theory::EulerBernoulli, Fluid::default());
    t.material.poisson_ratio = 0.6;
    assert!(
        t.validate("structure")
            .unwrap_err()
            .to_string()
            .contains("poisson_ratio")
    );
    assert!(Mesh::polyline(&[Vector3::zeros(), Vector3::x()], 0.0).is_err());
    assert!(Mesh::polyline(&[Vector3::zeros(), Vector3::zeros()], 0.1).is_err());
    let zero = nalgebra::DMatrix::<f64>::zeros(3, 3);
    let err = lowest_modes(&zero, &zero, ModeSelection::Count(1)).unwrap_err();
    assert!(err.to_string().contains("not positive definite"), "{err}");
}
