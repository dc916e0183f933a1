//! Case files (TOML) and modal-basis `.npz` files: a case written in TOML is the same case as
//! the one built in code, and every kind of bad input gives the right typed error naming the
//! field or file.

mod common;
use common::TempDir;

use std::path::Path;

use fretdyn::Error;
use fretdyn::accumulate::recorder::Recorder;
use fretdyn::apps::verification::V1;
use fretdyn::case::Case;
use fretdyn::contact::tangential::{GaussSeidelSettings, TangentialMethod};
use fretdyn::integrator::simulation::simulate;

/// V1a (THEORY §6) as a case file. The incoming velocity is written with Rust's shortest
/// round-trip formatting of the same expressions `V1::model` evaluates, so it is exact.
fn v1a_toml() -> String {
    const POINT_MASS: &str = include_str!("fixtures/point_mass.toml");
    let v1 = V1::reference(20.0);
    let vx = v1.speed * v1.alpha.sin();
    let vz = -(v1.speed * v1.alpha.cos());
    format!(
        r#"title = "V1a in TOML"

[time]
dt = 1e-6
duration = 4e-3

{POINT_MASS}
[initial]
point = "mass"
velocity = [{vx:?}, 0.0, {vz:?}]

[[contacts]]
name = "plane"
point = "mass"
obstacle = {{ type = "plane", origin = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], gap = 0.0, tangent = [1.0, 0.0, 0.0] }}
normal = {{ stiffness = 1e6, damping = 0.0 }}
friction = {{ mu = 0.3 }}

[tangential]
method = "gauss_seidel"
stick_velocity = "half_step"

[output]
every = 1
"#
    )
}

fn parse(text: &str) -> fretdyn::Result<Case> {
    Case::from_toml_str(text, Path::new("."))
}

fn replace_once(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "'{from}' should occur once");
    text.replacen(from, to, 1)
}

fn assert_same_recorder(a: &Recorder, b: &Recorder) {
    assert_eq!(a.len(), b.len());
    assert!(a.len() > 4000);
    // bit for bit: compare the bit patterns (NaN-safe, distinguishes ±0)
    let bits = |x: &f64| x.to_bits();
    assert!(a.t.iter().map(bits).eq(b.t.iter().map(bits)), "t");
    assert!(a.q.iter().map(bits).eq(b.q.iter().map(bits)), "q");
    assert!(a.qdot.iter().map(bits).eq(b.qdot.iter().map(bits)), "qdot");
    assert!(
        a.normal_force
            .iter()
            .map(bits)
            .eq(b.normal_force.iter().map(bits)),
        "normal force"
    );
    assert!(
        a.tangential_force
            .iter()
            .map(bits)
            .eq(b.tangential_force.iter().map(bits)),
        "tangential force"
    );
    assert!(
        a.slip_velocity
            .iter()
            .map(bits)
            .eq(b.slip_velocity.iter().map(bits)),
        "slip velocity"
    );
    assert!(
        a.penetration
            .iter()
            .map(bits)
            .eq(b.penetration.iter().map(bits)),
        "penetration"
    );
    assert_eq!(a.status, b.status, "status");
}

#[test]
fn v1a_case_file_runs_bit_for_bit_like_the_case_built_in_code() {
    let from_file = parse(&v1a_toml()).expect("valid V1a case");
    let in_code = V1::reference(20.0).case(
        "V1a",
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
    );
    assert_eq!(from_file.title, "V1a in TOML");
    assert_eq!(from_file.settings, in_code.settings);
    assert_eq!(from_file.model.initial, in_code.model.initial);
    let a = simulate(&from_file.model, &from_file.settings).unwrap();
    let b = simulate(&in_code.model, &in_code.settings).unwrap();
    assert_same_recorder(&a.recorder, &b.recorder);
    // and it is V1a: it sticks and leaves with no tangential velocity (THEORY §6)
    let m = fretdyn::apps::verification::measure(&V1::reference(20.0), &a);
    assert!(m.leaving_tangential_speed <= 1e-9, "{m:?}");
}

/// A point mass m = 1 written as a general modal basis (three rigid-body modes, rows I) is the
/// same structure: same run, bit for bit.
#[test]
fn point_mass_as_inline_modal_basis_gives_the_same_run() {
    let text = v1a_toml();
    let modal = replace_once(
        &text,
        "type = \"point_mass\"\nmass = 1.0\npoint = \"mass\"\nposition = [0.0, 0.0, 0.0]\n",
        "type = \"modal\"\nfrequencies_hz = [0.0, 0.0, 0.0]\ndamping_ratio = 0.0\n\
         [[structure.points]]\nname = \"mass\"\ncoords = [0.0, 0.0, 0.0]\n\
         rows = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\n",
    );
    // participation factors Φᵀ M r of the unit mass: a point_mass structure computes them
    let modal = replace_once(
        &modal,
        "damping_ratio = 0.0\n",
        "damping_ratio = 0.0\nparticipation = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\n",
    );
    let a = parse(&text).unwrap();
    let b = parse(&modal).unwrap();
    assert_eq!(a.model, b.model);
    let ra = simulate(&a.model, &a.settings).unwrap();
    let rb = simulate(&b.model, &b.settings).unwrap();
    assert_same_recorder(&ra.recorder, &rb.recorder);
}

#[test]
fn method_names_and_options_are_read() {
    let text = v1a_toml();
    let penalty = replace_once(
        &text,
        "method = \"gauss_seidel\"\nstick_velocity = \"half_step\"\n",
        "method = \"penalty\"\n[tangential.penalty]\nstiffness = 1e6\ndamping = 2000.0\n",
    );
    let case = parse(&penalty).unwrap();
    assert_eq!(
        case.settings.method,
        TangentialMethod::Penalty(fretdyn::contact::tangential::PenaltySettings {
            stiffness: 1e6,
            damping: 2000.0
        })
    );
    let full = replace_once(&text, "\"half_step\"", "\"full_step\"");
    assert_eq!(
        parse(&full).unwrap().settings.stick_velocity,
        fretdyn::contact::tangential::StickVelocity::FullStep
    );
    let active = replace_once(
        &text,
        "method = \"gauss_seidel\"\nstick_velocity = \"half_step\"\n",
        "method = \"active_set\"\n[tangential.active_set]\nmax_iterations = 7\n",
    );
    match parse(&active).unwrap().settings.method {
        TangentialMethod::ActiveSet(a) => assert_eq!(a.max_iterations, 7),
        m => panic!("{m:?}"),
    }
    let mus = replace_once(
        &text,
        "friction = { mu = 0.3 }",
        "friction = { mu_static = 0.4, mu_dynamic = 0.25 }",
    );
    let f = parse(&mus).unwrap().model.contacts[0].friction;
    assert_eq!((f.mu_static, f.mu_dynamic), (0.4, 0.25));
}

// ---------------------------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------------------------

fn invalid_field(text: &str) -> (String, String) {
    match parse(text) {
        Err(Error::Invalid { field, message }) => (field, message),
        Err(e) => panic!("expected Error::Invalid, got {e:?}"),
        Ok(_) => panic!("expected an error"),
    }
}

#[test]
fn unknown_key_is_a_parse_error_with_its_line() {
    let text = replace_once(
        &v1a_toml(),
        "duration = 4e-3\n",
        "duration = 4e-3\ndurration = 1\n",
    );
    let line = text
        .lines()
        .position(|l| l.starts_with("durration"))
        .unwrap()
        + 1;
    match parse(&text) {
        Err(e @ Error::Parse { .. }) => {
            let Error::Parse {
                line: l, message, ..
            } = &e
            else {
                unreachable!()
            };
            assert_eq!(*l, line, "{e}");
            assert_eq!(e.field(), Some("time.durration"), "{e}");
            assert!(message.contains("unknown key"), "{message}");
            assert!(e.to_string().starts_with(&format!("line {line},")), "{e}");
        }
        other => panic!("expected Error::Parse, got {other:?}"),
    }
}

#[test]
fn unknown_method_is_a_parse_error_listing_the_valid_ones() {
    let text = replace_once(&v1a_toml(), "\"gauss_seidel\"", "\"newton\"");
    match parse(&text) {
        Err(Error::Parse { message, line, .. }) => {
            assert!(message.contains("newton"), "{message}");
            for valid in ["penalty", "active_set", "gauss_seidel"] {
                assert!(message.contains(valid), "{message} should list {valid}");
            }
            let expected = text.lines().position(|l| l.contains("newton")).unwrap() + 1;
            assert_eq!(line, expected);
        }
        other => panic!("expected Error::Parse, got {other:?}"),
    }
}

#[test]
fn negative_mass_names_structure_mass() {
    let text = replace_once(&v1a_toml(), "mass = 1.0", "mass = -1.0");
    let (field, message) = invalid_field(&text);
    assert_eq!(field, "structure.mass");
    assert!(message.contains("-1"), "{message}");
}

#[test]
fn negative_contact_stiffness_names_the_field() {
    let text = replace_once(&v1a_toml(), "stiffness = 1e6", "stiffness = -1e6");
    let (field, _) = invalid_field(&text);
    assert_eq!(field, "contacts[0].normal.stiffness");
}

#[test]
fn non_finite_mode_shape_rows_are_refused() {
    for bad in ["nan", "inf", "-inf"] {
        let text = format!(
            r#"
[time]
dt = 1e-6
duration = 1e-3

[structure]
type = "modal"
frequencies_hz = [0.0, 10.0, 20.0]

[[structure.points]]
name = "A"
rows = [[1.0, 0.0, 0.0], [0.0, {bad}, 0.0], [0.0, 0.0, 1.0]]
"#
        );
        let (field, message) = invalid_field(&text);
        assert!(
            field.contains("rows") && field.contains('A'),
            "{bad}: {field}"
        );
        assert!(message.contains("not finite"), "{bad}: {message}");
    }
}

#[test]
fn mu_static_below_mu_dynamic_is_refused() {
    let text = replace_once(
        &v1a_toml(),
        "friction = { mu = 0.3 }",
        "friction = { mu_static = 0.2, mu_dynamic = 0.3 }",
    );
    let (field, message) = invalid_field(&text);
    assert_eq!(field, "contacts[0].friction.mu_static");
    assert!(message.contains("mu_dynamic"), "{message}");
}

#[test]
fn unknown_point_name_is_refused() {
    let text = replace_once(
        &v1a_toml(),
        "name = \"plane\"\npoint = \"mass\"",
        "name = \"plane\"\npoint = \"mas\"",
    );
    let (field, message) = invalid_field(&text);
    assert_eq!(field, "contacts[0].point");
    assert!(
        message.contains("'mas'") && message.contains("mass"),
        "{message}"
    );
}

#[test]
fn time_step_above_the_stable_limit_is_refused_by_simulate() {
    // ω = √(K_N/m) = 1000 rad/s: limit 2 ms
    let text = replace_once(&v1a_toml(), "dt = 1e-6", "dt = 2.5e-3");
    let case = parse(&text).expect("parsing does not check stability");
    match simulate(&case.model, &case.settings) {
        Err(e @ Error::UnstableTimeStep { .. }) => {
            let Error::UnstableTimeStep { dt, limit, .. } = &e else {
                unreachable!()
            };
            assert_eq!(*dt, 2.5e-3);
            assert!(
                (limit - 2e-3).abs() <= 1e-12 * 2e-3,
                "limit {limit:e}, 2/ω = 2e-3"
            );
            let msg = e.to_string();
            assert!(msg.contains("stable limit"), "{msg}");
            assert!(msg.contains(&format!("{limit:e}")), "{msg}");
        }
        other => panic!("expected UnstableTimeStep, got {:?}", other.err()),
    }
}

// ---------------------------------------------------------------------------------------------
// Modal bases in .npz files
// ---------------------------------------------------------------------------------------------

#[test]
fn missing_npz_basis_is_an_io_error_naming_the_path() {
    let dir = TempDir::new("missing");
    let text = r#"
[time]
dt = 1e-6
duration = 1e-3

[structure]
type = "modal"
file = "no_such_basis.npz"
"#;
    match Case::from_toml_str(text, &dir.0) {
        Err(e @ Error::Io { .. }) => {
            let Error::Io { path, .. } = &e else {
                unreachable!()
            };
            assert_eq!(path, &dir.0.join("no_such_basis.npz"));
            assert!(e.to_string().contains("no_such_basis.npz"), "{e}");
        }
        other => panic!("expected Error::Io, got {:?}", other.err()),
    }
}

#[test]
fn modal_basis_npz_round_trip() {
    let dir = TempDir::new("roundtrip");
    let stations = vec![("A".to_string(), 0.3), ("support_1".to_string(), 1.1)];
    let beam = fretdyn::structure::modal::PinnedBeam {
        length: 2.0,
        bending_stiffness: 498.0,
        mass_per_length: 1.0,
        modes_per_plane: 3,
        axial_stiffness: 1.23e7,
        axial_modes: 2,
        damping_ratio: 0.02,
    };
    let mut basis = fretdyn::structure::modal::ModalBasis::pinned_beam(&beam, &stations).unwrap();
    basis.damping_ratio[1] = 0.05;
    basis.points[1].coords = nalgebra::Vector3::new(1.1, -0.25, 3.5);
    let path = dir.0.join("basis.npz");
    fretdyn::structure::basis_file::write_basis_npz(&path, &basis).unwrap();
    let back = fretdyn::structure::basis_file::read_basis_npz(&path)
        .unwrap()
        .basis;
    assert_eq!(
        back.points, basis.points,
        "rows and coords are stored as float64"
    );
    assert_eq!(back.damping_ratio, basis.damping_ratio);
    // frequencies go through Hz (ω/2π, then ×2π): equal to round-off
    assert_eq!(back.omega.len(), basis.omega.len());
    for (a, b) in back.omega.iter().zip(&basis.omega) {
        assert!((a - b).abs() <= 4.0 * f64::EPSILON * b, "{a} vs {b}");
    }
    // and a case reading it is that basis
    let text = r#"
[time]
dt = 1e-6
duration = 1e-3

[structure]
type = "modal"
file = "basis.npz"
"#;
    let case = Case::from_toml_str(text, &dir.0).unwrap();
    assert_eq!(case.model.basis, back);
    // written without abscissae, read without them; the case knows none
    assert_eq!(case.point_abscissae, [None, None]);
    // with the abscissa of one point: `s_<name>` of that one only, read back bit for bit
    fretdyn::structure::basis_file::write_basis_npz_with_abscissae(
        &path,
        &basis,
        &[None, Some(1.1)],
    )
    .unwrap();
    let file = fretdyn::structure::basis_file::read_basis_npz(&path).unwrap();
    assert_eq!(file.abscissae, [None, Some(1.1)]);
    assert_eq!(file.basis.points, basis.points);
    let case = Case::from_toml_str(text, &dir.0).unwrap();
    assert_eq!(case.point_abscissae, [None, Some(1.1)]);
}

#[test]
fn npz_rows_of_the_wrong_shape_are_refused_with_the_expected_shape() {
    use ndarray::{Array1, Array2};
    let dir = TempDir::new("shape");
    let path = dir.0.join("bad.npz");
    {
        let file = std::fs::File::create(&path).unwrap();
        let mut npz = ndarray_npy::NpzWriter::new(file);
        npz.add_array("frequencies_hz", &Array1::from(vec![1.0, 2.0, 3.0]))
            .unwrap();
        // (2, 3) instead of (3, 3)
        npz.add_array("rows_A", &Array2::<f64>::zeros((2, 3)))
            .unwrap();
        npz.finish().unwrap();
    }
    match fretdyn::structure::basis_file::read_basis_npz(&path) {
        Err(Error::Npz { path: p, message }) => {
            assert_eq!(p, path);
            assert!(message.contains("rows_A"), "{message}");
            assert!(message.contains("(3, 3)"), "{message}");
        }
        other => panic!("expected Error::Npz, got {other:?}"),
    }
}

/// A basis exported with its mass matrix and full shapes is checked for `Φᵀ M Φ = I`:
/// exact → accepted silently; off by 1e-6 → accepted with a warning giving the worst
/// deviation; off by 1e-2 → refused.
#[test]
fn npz_mass_normalisation_is_checked_when_the_mass_matrix_is_given() {
    use ndarray::{Array1, Array2};
    // 2 DOFs, M = diag(4, 9): mass-normalised modes are e1/2 and e2/3
    let write = |name: &str, scale: f64| {
        let dir = TempDir::new(name);
        let path = dir.0.join("basis.npz");
        let file = std::fs::File::create(&path).unwrap();
        let mut npz = ndarray_npy::NpzWriter::new(file);
        npz.add_array("frequencies_hz", &Array1::from(vec![1.0, 2.0]))
            .unwrap();
        npz.add_array(
            "mass_matrix",
            &Array2::from_shape_vec((2, 2), vec![4.0, 0.0, 0.0, 9.0]).unwrap(),
        )
        .unwrap();
        let shapes =
            Array2::from_shape_vec((2, 2), vec![0.5 * scale, 0.0, 0.0, 1.0 / 3.0]).unwrap();
        npz.add_array("shapes", &shapes).unwrap();
        npz.add_array(
            "rows_A",
            &Array2::from_shape_vec((3, 2), vec![0.5 * scale, 0.0, 0.0, 1.0 / 3.0, 0.0, 0.0])
                .unwrap(),
        )
        .unwrap();
        npz.finish().unwrap();
        let result = fretdyn::structure::basis_file::read_basis_npz(&path);
        (dir, result)
    };
    let (_d, exact) = write("exact", 1.0);
    assert!(exact.unwrap().warnings.is_empty());
    // φ₁ᵀ M φ₁ = (1 + 5e-7)² ≈ 1 + 1e-6
    let (_d, approx) = write("approx", 1.0 + 5e-7);
    let w = approx.unwrap().warnings;
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("1.000e-6") && w[0].contains("modes (1, 1)"),
        "{w:?}"
    );
    let (_d, bad) = write("bad", 1.01);
    match bad {
        Err(Error::Npz { message, .. }) => {
            assert!(message.contains("not mass-normalised"), "{message}");
            assert!(message.contains("2.010e-2"), "{message}");
        }
        other => panic!("expected Error::Npz, got {other:?}"),
    }
}

/// Tube supports: `type = "dofs"` with the six DOFs listed is a clamp, with the three
/// translations a pin; a point off the nodes is refused with the nearest node.
#[test]
fn tube_supports_by_dof_equal_the_named_ones() {
    let case = |supports: &str| {
        let text = format!(
            r#"
[time]
dt = 1e-6
duration = 1e-4
[structure]
type = "tube"
outer_diameter = 19.05e-3
wall_thickness = 1.09e-3
young_modulus = 2.0e11
poisson_ratio = 0.3
density = 8200.0
path = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
mesh_size = 0.1
modes = 6
{supports}
[[structure.points]]
name = "mid"
at = [0.5, 0.0, 0.0]
"#
        );
        Case::from_toml_str(&text, Path::new("."))
    };
    let named = case(
        "[[structure.supports]]\nat = [0.0, 0.0, 0.0]\ntype = \"clamped\"\n[[structure.supports]]\nat = [1.0, 0.0, 0.0]\ntype = \"pinned\"",
    )
    .unwrap();
    let dofs = case(
        "[[structure.supports]]\nat = [0.0, 0.0, 0.0]\ntype = \"dofs\"\nfixed = [\"ux\", \"uy\", \"uz\", \"rx\", \"ry\", \"rz\"]\n[[structure.supports]]\nat = [1.0, 0.0, 0.0]\ntype = \"dofs\"\nfixed = [\"ux\", \"uy\", \"uz\"]",
    )
    .unwrap();
    assert_eq!(named.model.basis.omega, dofs.model.basis.omega);
    let off = case("[[structure.supports]]\nat = [0.05, 0.0, 0.0]\ntype = \"clamped\"")
        .unwrap_err()
        .to_string();
    assert!(
        off.contains("structure.supports[0].at") && off.contains("no node"),
        "{off}"
    );
}

#[test]
fn circle_and_bi_plane_obstacles_from_toml() {
    let text = |obstacle: &str| {
        format!(
            r#"
[time]
dt = 1e-6
duration = 1e-4
[structure]
type = "point_mass"
mass = 1.0
[[contacts]]
point = "mass"
obstacle = {obstacle}
normal = {{ stiffness = 1e6 }}
friction = {{ mu = 0.3 }}
"#
        )
    };
    let c = Case::from_toml_str(
        &text(r#"{ type = "circle", centre = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 2.0], clearance = 2e-4 }"#),
        Path::new("."),
    )
    .unwrap();
    // the mass sits on the hole's axis: 0.2 mm of clearance all round
    let f = c.model.contacts[0].frame(&nalgebra::Vector3::zeros(), 0.0);
    assert_eq!(f.penetration, -2e-4);
    assert_eq!(f.tangents[1], nalgebra::Vector3::z());
    let b = Case::from_toml_str(
        &text(r#"{ type = "bi_plane", normal = [0.0, 1.0, 0.0], gap = 1e-4 }"#),
        Path::new("."),
    )
    .unwrap();
    let f = b.model.contacts[0].frame(&nalgebra::Vector3::new(0.0, 3e-4, 0.0), 0.0);
    assert!((f.penetration - 2e-4).abs() < 1e-15 && f.normal == -nalgebra::Vector3::y());
    let e = Case::from_toml_str(
        &text(r#"{ type = "circle", centre = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], clearance = -1.0 }"#),
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("contacts[0].obstacle.clearance"), "{e}");
}
