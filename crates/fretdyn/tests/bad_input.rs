//! Bad input is refused before a run, never with a panic, a hang or an abort: each error names
//! the field as the user wrote it (`contacts[0].friction.mu`, not the coefficient it stands
//! for) and says how to fix it. Models that would not fit in memory are refused with the
//! figure before anything is allocated.

mod common;
use common::TempDir;

use std::path::{Path, PathBuf};

use fretdyn::Error;
use fretdyn::apps::study::Study;
use fretdyn::case::Case;
use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::obstacle::{Obstacle, Plane};
use fretdyn::contact::tangential::{GaussSeidelSettings, TangentialMethod};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::stability::{checked_stable_time_step, stable_time_step};
use fretdyn::model::Model;
use fretdyn::structure::modal::ModalBasis;
use nalgebra::Vector3;

const V1A: &str = include_str!("../../../examples/v1a_oblique_impact.toml");
const TUBE: &str = include_str!("../../../examples/tube_clamped_one_support.toml");

fn replace_once(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "'{from}' should occur once");
    text.replacen(from, to, 1)
}

/// The field and message of the `Error::Invalid` that `text` gives (files relative to `base`).
fn invalid_in(text: &str, base: &Path) -> (String, String) {
    match Case::from_toml_str(text, base) {
        Err(Error::Invalid { field, message }) => (field, message),
        Err(e) => panic!("expected Error::Invalid, got {e:?}"),
        Ok(_) => panic!("expected an error"),
    }
}

fn invalid(text: &str) -> (String, String) {
    invalid_in(text, Path::new("."))
}

// ---------------------------------------------------------------------------------------------
// Time and statistics
// ---------------------------------------------------------------------------------------------

#[test]
fn a_duration_shorter_than_one_step_is_refused() {
    let text = replace_once(V1A, "duration = 4e-3", "duration = 4e-7");
    let (field, message) = invalid(&text);
    assert_eq!(field, "time.duration");
    assert!(
        message.contains("shorter than one step") && message.contains("duration ≥ dt"),
        "{message}"
    );
    // one step is a run
    let text = replace_once(V1A, "duration = 4e-3", "duration = 1e-6");
    assert_eq!(
        Case::from_toml_str(&text, Path::new("."))
            .unwrap()
            .settings
            .steps,
        1
    );
}

#[test]
fn a_statistics_window_after_the_run_is_refused() {
    // 3.99975e-3: after the middle of the last step, 3.9995e-3
    for t_start in ["4e-3", "5e-3", "3.99975e-3"] {
        let text = format!("{V1A}\n[statistics]\nt_start = {t_start}\n");
        let (field, message) = invalid(&text);
        assert_eq!(field, "statistics.t_start");
        assert!(
            message.contains("time.duration = 0.004") && message.contains("t_start < duration"),
            "{message}"
        );
    }
}

/// A block shorter than a step closed thousands of empty blocks per step (forever, for a block
/// of 1e-300 s).
#[test]
fn a_statistics_block_shorter_than_a_step_is_refused() {
    for block in ["1e-9", "1e-300"] {
        let text = format!("{V1A}\n[statistics]\nblock = {block}\n");
        let (field, message) = invalid(&text);
        assert_eq!(field, "statistics.block");
        assert!(
            message.contains("shorter than one step") && message.contains("block ≥ dt"),
            "{message}"
        );
    }
    let text = format!("{V1A}\n[statistics]\nblock = 1e-6\n");
    assert!(Case::from_toml_str(&text, Path::new(".")).is_ok());
}

// ---------------------------------------------------------------------------------------------
// Contacts, friction, initial state, damping: the field as written
// ---------------------------------------------------------------------------------------------

fn with_second_contact(name_line: &str) -> String {
    let start = V1A.find("[[contacts]]").unwrap();
    let end = V1A.find("[tangential]").unwrap();
    let second = V1A[start..end].replace("name = \"plane\"", name_line);
    format!("{}{second}{}", &V1A[..end], &V1A[end..])
}

#[test]
fn two_contacts_with_the_same_name_are_refused() {
    let (field, message) = invalid(&with_second_contact("name = \"plane\""));
    assert_eq!(field, "contacts[1].name");
    assert!(
        message.contains("'plane'") && message.contains("contacts[0]"),
        "{message}"
    );
    // an unnamed contact is contact<k>: a user name may not take it
    let text = with_second_contact("");
    let text = replace_once(&text, "name = \"plane\"", "name = \"contact1\"");
    let (field, _) = invalid(&text);
    assert_eq!(field, "contacts[1].name");
    // distinct names are fine
    assert!(Case::from_toml_str(&with_second_contact("name = \"other\""), Path::new(".")).is_ok());
}

/// A contact name heads columns of `study.csv` and `life.csv` (`<name>.wear_work_rate`): a
/// comma in it (found by the commands' fuzz test: a name taken from a title) gave a header of
/// more columns than the rows, and the sweep refused its own first row (exit code 1). A study
/// and a service life refuse a comma, a double quote or a line break, naming the key; a run
/// accepts them (its `contacts.csv` quotes the name: tests/contacts_csv.rs), and other
/// characters are accepted everywhere.
#[test]
fn a_contact_name_that_would_cut_the_study_and_life_tables_is_refused() {
    for name in ["plate, upper", "plate \\\"3\\\"", "plate\\n3"] {
        let text = replace_once(V1A, "name = \"plane\"", &format!("name = \"{name}\""));
        // a run takes it
        let case = Case::from_toml_str(&text, Path::new(".")).unwrap();
        // a service life does not
        let life = Case::from_toml_str(
            &format!("{text}\n[life]\ntarget_years = 10.0\n"),
            Path::new("."),
        )
        .unwrap();
        let err = fretdyn::apps::life::check_life(&life, life.life.as_ref().unwrap()).unwrap_err();
        assert_eq!(err.field(), Some("contacts[0].name"), "{name}: {err}");
        assert!(
            err.to_string().contains("cannot hold a comma") && !err.to_string().contains('\n'),
            "{err}"
        );
        // nor a study
        let dir = TempDir::new("study_name");
        std::fs::write(dir.0.join("v1a.toml"), &text).unwrap();
        let path = dir.0.join("study.toml");
        std::fs::write(
            &path,
            "base = \"v1a.toml\"\n\n[[parameters]]\nkey = \"contacts.*.friction.mu\"\nvalues = [0.1, 0.3]\n",
        )
        .unwrap();
        let err = Study::from_file(&path).unwrap().check(0).unwrap_err();
        assert!(
            err.to_string().contains("contacts[0].name")
                && err.to_string().contains("cannot hold a comma"),
            "{err}"
        );
        drop(case);
    }
    let text = replace_once(V1A, "name = \"plane\"", "name = \"plate 3 (upper)\"");
    let life = Case::from_toml_str(
        &format!("{text}\n[life]\ntarget_years = 10.0\n"),
        Path::new("."),
    )
    .unwrap();
    let err = fretdyn::apps::life::check_life(&life, life.life.as_ref().unwrap()).unwrap_err();
    // refused for another reason: no contact of V1a wears
    assert!(
        err.to_string().contains("no contact has a wear law"),
        "{err}"
    );
}

#[test]
fn friction_errors_name_the_key_written() {
    let text = replace_once(V1A, "friction = { mu = 0.3 }", "friction = { mu = -0.3 }");
    let (field, message) = invalid(&text);
    assert_eq!(field, "contacts[0].friction.mu");
    assert!(message.contains("-0.3"), "{message}");
    let text = replace_once(
        V1A,
        "friction = { mu = 0.3 }",
        "friction = { mu_static = nan }",
    );
    assert_eq!(invalid(&text).0, "contacts[0].friction.mu_static");
    let text = replace_once(
        V1A,
        "friction = { mu = 0.3 }",
        "friction = { mu_static = 0.2, mu_dynamic = -1 }",
    );
    assert_eq!(invalid(&text).0, "contacts[0].friction.mu_dynamic");
}

#[test]
fn a_non_finite_initial_velocity_is_named_as_written() {
    let line = V1A.lines().find(|l| l.starts_with("velocity = ")).unwrap();
    let text = replace_once(V1A, line, "velocity = [nan, 0.0, -1.0]");
    let (field, message) = invalid(&text);
    assert_eq!(field, "initial.velocity");
    assert!(
        message.contains("NaN") && message.contains("m/s"),
        "{message}"
    );
    let text = replace_once(
        V1A,
        "displacement = [0.0, 0.0, 0.0]",
        "displacement = [0.0, inf, 0.0]",
    );
    assert_eq!(invalid(&text).0, "initial.displacement");
}

#[test]
fn rayleigh_coefficients_are_named_as_written() {
    let text = replace_once(
        TUBE,
        "damping_ratio = 0.01",
        "rayleigh = { alpha = -500, beta = 0 }",
    );
    let (field, message) = invalid(&text);
    assert_eq!(field, "structure.rayleigh.alpha");
    assert!(message.contains("-500"), "{message}");
    let text = replace_once(
        TUBE,
        "damping_ratio = 0.01",
        "rayleigh = { alpha = 0, beta = -1e-5 }",
    );
    assert_eq!(invalid(&text).0, "structure.rayleigh.beta");
    // one damping ratio for every mode is one field, not one per mode
    let text = replace_once(TUBE, "damping_ratio = 0.01", "damping_ratio = -0.01");
    assert_eq!(invalid(&text).0, "structure.damping_ratio");
}

/// A contact radius in mm (9.525 for 9.525e-3 m) on a tube of 19.05 mm.
#[test]
fn a_contact_radius_larger_than_the_tube_is_refused() {
    let text = replace_once(
        TUBE,
        "friction = { mu = 0.3 }",
        "friction = { mu = 0.3 }\nradius = 9.525",
    );
    let (field, message) = invalid(&text);
    assert_eq!(field, "contacts[0].radius");
    assert!(
        message.contains("9.525 m") && message.contains("0.009525 m"),
        "{message}"
    );
    // the outer radius itself is the radius of a contact on the surface
    let text = replace_once(
        TUBE,
        "friction = { mu = 0.3 }",
        "friction = { mu = 0.3 }\nradius = 9.525e-3",
    );
    let text = replace_once(&text, "offset = [0.0, -9.525e-3, 0.0]", "");
    let text = replace_once(
        &text,
        "origin = [0.5, -9.525e-3, 0.0]",
        "origin = [0.5, 0.0, 0.0]",
    );
    let case = Case::from_toml_str(&text, Path::new(".")).unwrap();
    assert_eq!(case.model.contacts[0].radius, 9.525e-3);
}

#[test]
fn a_bad_row_of_a_load_table_names_the_file_and_its_line() {
    let dir = TempDir::new("load_csv");
    let text = replace_once(
        V1A,
        "[tangential]\n",
        "[[loads]]\npoint = \"mass\"\nforce = [0.0, 1.0, 0.0]\nhistory = { type = \"table\", file = \"load.csv\" }\n\n[tangential]\n",
    );
    // line 4 goes back in time, line 3 is not finite, line 5 is not two numbers
    for (csv, line, needle) in [
        ("t,value\n0,0\n1e-3,1\n5e-4,2\n", 4, "strictly increasing"),
        ("# a comment\n0,0\n1e-3,nan\n2e-3,1\n", 3, "finite"),
        ("t,value\n0,0\n1e-3,1\n\n2e-3\n", 5, "two numbers"),
    ] {
        std::fs::write(dir.0.join("load.csv"), csv).unwrap();
        let (field, message) = invalid_in(&text, &dir.0);
        assert_eq!(field, "loads[0].history.file");
        assert!(
            message.contains(&format!("load.csv line {line}:")) && message.contains(needle),
            "{message}"
        );
    }
    std::fs::write(dir.0.join("load.csv"), "t,value\n0,0\n1e-3,1\n").unwrap();
    assert!(Case::from_toml_str(&text, &dir.0).is_ok());
}

#[test]
fn a_study_file_is_not_a_case() {
    let text = "base = \"v1a.toml\"\n[[parameters]]\nkey = \"time.dt\"\nvalues = [1e-6]\n";
    let (field, message) = invalid(text);
    assert_eq!(field, "base");
    assert!(
        message.contains("study file") && message.contains("fretdyn sweep"),
        "{message}"
    );
}

// ---------------------------------------------------------------------------------------------
// Extreme values: no hang, no abort
// ---------------------------------------------------------------------------------------------

/// A point mass of 1e-320 kg on a 1e6 N/m contact: K_N/m is not a finite number; the eigen
/// solver of the stability limit looped forever on it.
#[test]
fn a_mass_that_makes_the_stable_time_step_infinite_is_refused() {
    let text = replace_once(V1A, "mass = 1.0 ", "mass = 1e-320 ");
    let (field, message) = invalid(&text);
    assert_eq!(field, "contacts[0].normal");
    assert!(
        message.contains("1e-320 kg") && message.contains("not a finite number"),
        "{message}"
    );

    // the same model built in code: no stable time step, so every Δt is refused
    let mut model = Model::new(ModalBasis::point_mass(1e-320, "mass", Vector3::zeros()).unwrap());
    model.contacts.push(Contact::new(
        "plane",
        0,
        Obstacle::Plane(Plane::new(Vector3::zeros(), Vector3::z(), 0.0, None, "p").unwrap()),
        NormalLaw::new(1e6, 0.0, "n").unwrap(),
        Coulomb::new(0.3, 0.3, "f").unwrap(),
    ));
    let gs = TangentialMethod::GaussSeidel(GaussSeidelSettings::default());
    assert!(checked_stable_time_step(&model, &gs).is_err());
    assert_eq!(stable_time_step(&model, &gs), 0.0);
}

/// A contact on the surface of a modal structure with rotations, at a radius of 1e200 m: the
/// Delassus operator was not finite and the run looped forever.
#[test]
fn a_contact_radius_that_makes_the_contact_rows_infinite_is_refused() {
    let inline = include_str!("../../../examples/v1a_modal_inline.toml");
    let rows_end = "  [0.0, 0.0, 1.0],                  # z\n]\n";
    let text = replace_once(
        inline,
        rows_end,
        &format!("{rows_end}rotations = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]\n"),
    );
    let text = replace_once(
        &text,
        "friction = { mu = 0.3 }",
        "friction = { mu = 0.3 }\nradius = 1e200",
    );
    let (field, message) = invalid(&text);
    assert_eq!(field, "contacts[0].radius");
    assert!(message.contains("1e200 m"), "{message}");
    assert!(
        Case::from_toml_str(
            &text.replace("radius = 1e200", "radius = 0.01"),
            Path::new(".")
        )
        .is_ok()
    );
}

/// A mass of 1e-300 kg has a stable time step (2e-153 s), but no run can take 1e150 steps.
#[test]
fn a_mass_that_makes_the_run_endless_is_refused() {
    let text = replace_once(V1A, "mass = 1.0 ", "mass = 1e-300 ");
    let (field, message) = invalid(&text);
    assert_eq!(field, "time.dt");
    // 2/ω with ω = √(K_N/m) = 1e153 rad/s
    assert!(
        message.contains("2.000e-153 s") && message.contains("1e12 steps"),
        "{message}"
    );
}

/// With heavy contact damping the limit is (2/ω)(√(1+ζ²) − ζ) → 1/(ζω) = 2/c, c = C_N/m: it
/// was computed as 0 (cancellation) for ζ > 1e8.
#[test]
fn the_stable_time_step_with_heavy_damping_is_two_over_the_damping_rate() {
    let (m, kn, cn) = (1.0, 1e6, 1e12);
    let mut model = Model::new(ModalBasis::point_mass(m, "mass", Vector3::zeros()).unwrap());
    model.contacts.push(Contact::new(
        "plane",
        0,
        Obstacle::Plane(Plane::new(Vector3::zeros(), Vector3::z(), 0.0, None, "p").unwrap()),
        NormalLaw::new(kn, cn, "n").unwrap(),
        Coulomb::new(0.3, 0.3, "f").unwrap(),
    ));
    let gs = TangentialMethod::GaussSeidel(GaussSeidelSettings::default());
    let dt = checked_stable_time_step(&model, &gs).unwrap();
    // ζ = 5e8: the next term of the expansion, 1/(4ζ²), is 1e-18
    let expected = 2.0 / (cn / m);
    assert!(
        (dt - expected).abs() <= 1e-12 * expected,
        "{dt} vs {expected}"
    );
}

#[test]
fn a_tube_diameter_too_small_to_compute_with_is_refused() {
    for (d, t) in [("1e-100", "1e-101"), ("1e-80", "1e-81")] {
        let text = replace_once(
            TUBE,
            "outer_diameter = 19.05e-3",
            &format!("outer_diameter = {d}"),
        );
        let text = replace_once(
            &text,
            "wall_thickness = 1.09e-3",
            &format!("wall_thickness = {t}"),
        );
        let (field, message) = invalid(&text);
        assert_eq!(field, "structure.outer_diameter", "{message}");
        assert!(message.contains("units"), "{message}");
    }
    // a Young's modulus and a density of opposite extremes
    let text = replace_once(TUBE, "young_modulus = 2.0e11", "young_modulus = 1e-300");
    let text = replace_once(&text, "density = 8200.0", "density = 1e300");
    assert_eq!(invalid(&text).0, "structure.young_modulus");
}

/// A path of 1e9 m (a unit slip) and a mesh of 1e6 elements aborted with "memory allocation
/// failed": the memory the dense modal analysis needs is refused with its figure.
#[test]
fn a_tube_mesh_too_large_for_memory_is_refused_with_the_figure() {
    let long = replace_once(
        TUBE,
        "path = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]",
        "path = [[0.0, 0.0, 0.0], [1e9, 0.0, 0.0]]",
    );
    let fine = replace_once(TUBE, "mesh_size = 0.05 ", "mesh_size = 1e-6 ");
    for (text, elements) in [(long, "2.000e10 elements"), (fine, "1.000e6 elements")] {
        let (field, message) = invalid(&text);
        assert_eq!(field, "structure.mesh_size");
        assert!(
            message.contains(elements)
                && message.contains("GB")
                && message.contains("use mesh_size ≥")
                && message.contains("units of path"),
            "{message}"
        );
        // the figure: 6 DOFs per node, dense n × n matrices of 8 bytes
        let nodes: f64 = elements.split(' ').next().unwrap().parse::<f64>().unwrap() + 1.0;
        let gb = 8.0 * (6.0 * nodes).powi(2) / 1e9;
        let needed: f64 = message
            .split("would need ")
            .nth(1)
            .and_then(|r| r.split(' ').next())
            .unwrap()
            .parse()
            .unwrap();
        assert!(needed >= gb, "{needed} GB for {gb} GB of one matrix");
    }
    let u_bend = replace_once(
        TUBE,
        "path = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]",
        "u_bend = { leg_length = 1.0, radius = 1e12 }",
    );
    let (field, message) = invalid(&u_bend);
    assert_eq!(field, "structure.mesh_size");
    assert!(message.contains("units of u_bend"), "{message}");
}

/// `modes = 100000` on a tube of 114 free DOFs was cut to 114 silently.
#[test]
fn more_modes_than_the_tube_has_are_refused() {
    let text = replace_once(TUBE, "modes = 12", "modes = 100000");
    let (field, message) = invalid(&text);
    assert_eq!(field, "structure.modes");
    assert!(
        message.contains("114 free DOFs") && message.contains("modes ≤ 114"),
        "{message}"
    );
    let text = replace_once(TUBE, "modes = 12", "modes = 114");
    assert_eq!(
        Case::from_toml_str(&text, Path::new("."))
            .unwrap()
            .model
            .basis
            .modes(),
        114
    );
}

#[test]
fn an_analytic_beam_with_more_modes_than_memory_is_refused() {
    let text = r#"
[time]
dt = 1e-6
duration = 1e-3

[structure]
type = "pinned_beam"
length = 1.0
bending_stiffness = 1e3
mass_per_length = 1.0
modes_per_plane = 1000000000
points = [{ name = "mid", x = 0.5 }]
"#;
    let (field, message) = invalid(text);
    assert_eq!(field, "structure.modes_per_plane");
    assert!(message.contains("GB"), "{message}");
}

// ---------------------------------------------------------------------------------------------
// Studies
// ---------------------------------------------------------------------------------------------

fn study_dir(name: &str, study: &str) -> (TempDir, PathBuf) {
    let dir = TempDir::new(name);
    std::fs::write(dir.0.join("v1a.toml"), V1A).unwrap();
    let path = dir.0.join("study.toml");
    std::fs::write(&path, study).unwrap();
    (dir, path)
}

/// A value that makes one run's case invalid is found before any run, naming the run, its
/// values and the field; nothing is written.
#[test]
fn a_study_value_that_makes_a_case_invalid_is_refused_before_any_run() {
    let (dir, path) = study_dir(
        "study_value",
        "base = \"v1a.toml\"\n\n[[parameters]]\nkey = \"contacts.*.friction.mu\"\nvalues = [0.1, -0.3]\n\n[[parameters]]\nkey = \"time.dt\"\nvalues = [1e-6, 2e-6]\n",
    );
    let study = Study::from_file(&path).unwrap();
    let err = study.check(1).unwrap_err();
    let Error::StudyRun {
        index,
        point,
        source,
    } = &err
    else {
        panic!("expected StudyRun, got {err:?}");
    };
    // grid order: mu varies slowest
    assert_eq!(*index, 2);
    assert!(
        point.contains("contacts.*.friction.mu = -0.3") && point.contains("time.dt"),
        "{point}"
    );
    assert_eq!(source.field(), Some("contacts[0].friction.mu"));
    assert!(err.to_string().starts_with("run 2 ("), "{err}");
    let table = dir.0.join("study.csv");
    assert!(study.execute(&table, 1, &|_, _| {}).is_err());
    assert!(!table.exists(), "a run was made");

    // a Δt above the stable limit (ω = 1000 rad/s: 2 ms) is a bad value too
    let (_dir, path) = study_dir(
        "study_dt",
        "base = \"v1a.toml\"\n\n[[parameters]]\nkey = \"time.dt\"\nvalues = [1e-6, 3e-3]\n",
    );
    let err = Study::from_file(&path).unwrap().check(0).unwrap_err();
    assert!(matches!(&err, Error::StudyRun { index: 1, .. }), "{err}");
    assert!(err.to_string().contains("stable limit"), "{err}");

    // a value of the wrong kind names the parameter, not a line of a generated file
    let (_dir, path) = study_dir(
        "study_method",
        "base = \"v1a.toml\"\n\n[[parameters]]\nkey = \"tangential.method\"\nvalues = [\"gauss_seidel\", \"newton\"]\n",
    );
    let err = Study::from_file(&path).unwrap().check(0).unwrap_err();
    assert_eq!(err.field(), Some("parameters[0].values"), "{err}");
    assert!(
        err.to_string().contains("newton") && !err.to_string().contains("line "),
        "{err}"
    );
}

/// A value that makes a run unable to start is found by the check before any run, as a Δt
/// above the stable limit is, not only by the run itself (found by the commands' fuzz test:
/// an initial state whose energy overflows passed the check, the other runs ran and were
/// written, and the sweep failed with exit code 1 as if a run had failed).
#[test]
fn a_study_value_that_makes_a_run_unable_to_start_is_refused_before_any_run() {
    let (dir, path) = study_dir(
        "study_start",
        "base = \"v1a.toml\"\n\n[[parameters]]\nkey = \"initial.velocity\"\nvalues = [[0.3, 0.0, -0.9], [0.3, 1e300, -0.9]]\n",
    );
    let study = Study::from_file(&path).unwrap();
    let err = study.check(0).unwrap_err();
    let Error::StudyRun { index, source, .. } = &err else {
        panic!("expected StudyRun, got {err:?}");
    };
    assert_eq!(*index, 1);
    assert_eq!(source.field(), Some("initial"), "{err}");
    let table = dir.0.join("study.csv");
    assert!(study.execute(&table, 1, &|_, _| {}).is_err());
    assert!(!table.exists(), "a run was made");
    // a service life without a wearing contact
    std::fs::write(
        dir.0.join("v1a.toml"),
        format!("{V1A}\n[life]\ntarget_years = 1.0\n"),
    )
    .unwrap();
    std::fs::write(
        &path,
        "base = \"v1a.toml\"\n\n[[parameters]]\nkey = \"contacts.*.friction.mu\"\nvalues = [0.1]\n",
    )
    .unwrap();
    let err = Study::from_file(&path).unwrap().check(0).unwrap_err();
    let Error::StudyRun { source, .. } = &err else {
        panic!("expected StudyRun, got {err:?}");
    };
    assert_eq!(source.field(), Some("life"), "{err}");
    assert!(
        err.to_string().contains("no contact has a wear law"),
        "{err}"
    );
}

#[test]
fn study_syntax_errors_give_their_line_and_column() {
    let (_dir, path) = study_dir(
        "study_syntax",
        "base = \"v1a.toml\"\n\n[[parameters]]\nkey = \"time.dt\"\nvalues = [1e-6 2e-6]\n",
    );
    match Study::from_file(&path) {
        Err(Error::Parse { line, column, .. }) => assert_eq!((line, column), (5, 16)),
        other => panic!("expected a parse error, got {other:?}"),
    }
    let (_dir, path) = study_dir(
        "study_key",
        "base = \"v1a.toml\"\n\n[[parameters]]\nkey = \"time.dt\"\nvalues = [1e-6]\nvalue = 2\n",
    );
    match Study::from_file(&path) {
        Err(Error::Parse { line, message, .. }) => {
            assert_eq!(line, 6);
            assert!(message.contains("value"), "{message}");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    // a mistake in the base case: its own line
    let (dir, path) = study_dir("study_base", "base = \"v1a.toml\"\n");
    std::fs::write(
        dir.0.join("v1a.toml"),
        replace_once(V1A, "duration = 4e-3", "duration = 4e-3\nsteps = 3"),
    )
    .unwrap();
    let line = V1A.lines().position(|l| l.starts_with("duration")).unwrap() + 2;
    let err = Study::from_file(&path).unwrap_err();
    assert_eq!(err.field(), Some("base"));
    assert!(
        err.to_string()
            .contains(&format!("v1a.toml: line {line}, column 1")),
        "{err}"
    );
    // a case given as a study
    let (_dir, path) = study_dir("study_case", V1A);
    let err = Study::from_file(&path).unwrap_err().to_string();
    assert!(
        err.contains("case file") && err.contains("fretdyn run"),
        "{err}"
    );
}

/// A missing file is named once.
#[test]
fn a_missing_file_is_named_once() {
    let path = Path::new("no_such_case.toml");
    let err = Case::from_file(path).unwrap_err();
    let message = err.in_file(path);
    assert_eq!(message.matches("no_such_case.toml").count(), 1, "{message}");
    // another file in the message is still named
    let err = Error::invalid("structure", "x");
    assert_eq!(err.in_file(path), "no_such_case.toml: structure: x");
}

/// An empty file name is refused naming its key (found by the commands' fuzz test: a study's
/// `base = ""` was read as the study's folder, or as no file, and refused with
/// `study.toml: : No such file or directory (os error 2)`, naming neither the key nor a file);
/// so are a load table's and a modal basis's.
#[test]
fn an_empty_file_name_is_refused_naming_its_key() {
    let (dir, _) = study_dir("empty_base", "");
    for base in ["", " "] {
        let study = format!(
            "base = \"{base}\"\n\n[[parameters]]\nkey = \"time.duration\"\nvalues = [1e-3]\n"
        );
        let err = Study::from_toml_str(&study, &dir.0, None).unwrap_err();
        let Error::Invalid { field, message } = &err else {
            panic!("expected Error::Invalid, got {err:?}");
        };
        assert_eq!(field, "base");
        assert!(
            message.contains("an empty file name") && message.contains("the study file"),
            "{message}"
        );
    }
    let text = replace_once(
        V1A,
        "[tangential]\n",
        "[[loads]]\npoint = \"mass\"\nforce = [0.0, 1.0, 0.0]\nhistory = { type = \"table\", file = \"\" }\n\n[tangential]\n",
    );
    let (field, message) = invalid_in(&text, &dir.0);
    assert_eq!(field, "loads[0].history.file");
    assert!(message.contains("an empty file name"), "{message}");
    let modal = include_str!("../../../examples/v1a_modal_inline.toml");
    let text = replace_once(
        modal,
        "frequencies_hz = [0.0, 0.0, 0.0]   # natural frequencies, Hz (0: rigid-body mode)",
        "file = \"\"",
    );
    let (field, message) = invalid_in(&text, &dir.0);
    assert_eq!(field, "structure.file");
    assert!(message.contains("an empty file name"), "{message}");
}

/// An initial velocity whose kinetic energy overflows (found by the fuzz test: 1e300 m/s ran
/// one step and wrote an infinite initial energy in the summary) is refused before the run.
#[test]
fn an_initial_state_whose_energy_overflows_is_refused() {
    let case = Case::from_toml_str(
        &replace_once(
            V1A,
            "velocity = [0.3420201433256687, 0.0, -0.9396926207859084]",
            "velocity = [0.3420201433256687, 1e300, -0.9396926207859084]",
        ),
        Path::new("."),
    )
    .expect("a finite velocity is a valid case file");
    match fretdyn::integrator::simulation::simulate(&case.model, &case.settings) {
        Err(Error::Invalid { field, message }) => {
            assert_eq!(field, "initial");
            assert!(message.contains("units"), "{message}");
        }
        other => panic!("expected a refusal, got {:?}", other.map(|r| r.termination)),
    }
}

// ---------------------------------------------------------------------------------------------
// Schema errors in a person's words (issue [3.1])
// ---------------------------------------------------------------------------------------------

/// serde's words, which a schema error no longer shows.
const SERDE_WORDS: &[&str] = &[
    "invalid type",
    "invalid value",
    "invalid length",
    "expected usize",
    "expected u64",
    "expected u32",
    "expected f64",
    "expected a boolean",
    "expected a string",
    "expected struct",
    "expected internally tagged",
    "integer `",
    "floating point `",
    "boolean `",
    "unknown field",
    "unknown variant",
    "missing field",
    "untagged enum",
    "wanted string or table",
];

/// The key and the message of the schema error `text` gives, and the error as displayed.
fn schema_error(text: &str) -> (Option<String>, String, String) {
    match Case::from_toml_str(text, Path::new(".")) {
        Err(e @ Error::Parse { .. }) => {
            let Error::Parse { message, .. } = &e else {
                unreachable!()
            };
            (
                e.field().map(str::to_string),
                message.clone(),
                e.to_string(),
            )
        }
        Err(e) => panic!("expected a schema error, got {e:?}"),
        Ok(_) => panic!("expected an error"),
    }
}

/// The catalogue of bad inputs: each schema error names the key as written and says what
/// is expected in plain words, with the value as written (the messages were serde's:
/// `invalid value: integer `-1`, expected u64`, `invalid type: integer `1`, expected a
/// boolean`, at a line and column only).
#[test]
fn schema_errors_name_the_key_and_say_what_is_expected_in_plain_words() {
    let cases: &[(&str, &str, &str, &str, &[&str])] = &[
        (
            V1A,
            "every = 1 ",
            "every = -1 ",
            "output.every",
            &["a whole number ≥ 1", "got -1"],
        ),
        // an unknown key inside a tagged table is reported at the table: named with it
        (
            V1A,
            "gap = 0.0, tangent",
            "gap = 0.0, clearance = 2e-4, tangent",
            "contacts[0].obstacle.clearance",
            &[
                "unknown key",
                "the keys of contacts[0].obstacle are origin, normal, gap, tangent",
            ],
        ),
        (
            V1A,
            "every = 1 ",
            "every = 2.5 ",
            "output.every",
            &["whole number", "got 2.5"],
        ),
        (
            V1A,
            "warm_start = true",
            "warm_start = 1",
            "tangential.gauss_seidel.warm_start",
            &["true or false", "got 1"],
        ),
        (
            V1A,
            "max_sweeps = 1000",
            "max_sweeps = 1.5",
            "tangential.gauss_seidel.max_sweeps",
            &["a whole number ≥ 1", "got 1.5"],
        ),
        (
            V1A,
            "max_iterations = 50",
            "max_iterations = -5",
            "tangential.active_set.max_iterations",
            &["a whole number ≥ 1", "got -5"],
        ),
        (
            V1A,
            "dt = 1e-6",
            "dt = \"small\"",
            "time.dt",
            &["a number", "s)", "got \"small\""],
        ),
        (
            V1A,
            "method = \"gauss_seidel\"",
            "method = \"newton\"",
            "tangential.method",
            &[
                "one of \"penalty\", \"active_set\", \"gauss_seidel\"",
                "got \"newton\"",
            ],
        ),
        (
            V1A,
            "stick_velocity = \"half_step\"",
            "stick_velocity = 3",
            "tangential.stick_velocity",
            &["a name in double quotes", "got 3"],
        ),
        // inside a tagged table ([structure], an obstacle): the value below it
        (
            V1A,
            "position = [0.0, 0.0, 0.0]",
            "position = [0.0, 0.0]",
            "structure.position",
            &["a list of 3 values", "got [0.0, 0.0]"],
        ),
        (
            V1A,
            "normal = [0.0, 0.0, 1.0], gap",
            "normal = [0.0, 0.0, \"z\"], gap",
            "contacts[0].obstacle.normal[2]",
            &["a number", "got \"z\""],
        ),
        (
            V1A,
            "gap = 0.0, tangent",
            "gap = \"0\", tangent",
            "contacts[0].obstacle.gap",
            &["a number (a gap in m)", "got \"0\""],
        ),
        (
            V1A,
            "type = \"plane\", origin",
            "type = \"plan\", origin",
            "contacts[0].obstacle.type",
            &[
                "one of \"plane\", \"circle\", \"bi_plane\", \"polygon\"",
                "got \"plan\"",
            ],
        ),
        (
            V1A,
            "type = \"plane\", origin",
            "origin",
            "contacts[0].obstacle.type",
            &["is missing", "add type"],
        ),
        (
            V1A,
            "friction = { mu = 0.3 }",
            "friction = { mu = true }",
            "contacts[0].friction.mu",
            &["a number (a friction coefficient)", "got true"],
        ),
        (
            V1A,
            "friction = { mu = 0.3 }",
            "friction = 0.3",
            "contacts[0].friction",
            &["a table", "got 0.3"],
        ),
        (
            V1A,
            "velocity = [0.3420201433256687, 0.0, -0.9396926207859084]",
            "velocity = [0.34, 0.0, \"x\"]",
            "initial.velocity[2]",
            &["a number (a velocity in m/s)", "got \"x\""],
        ),
        (V1A, "dt = 1e-6", "", "time.dt", &["is missing", "[time]"]),
        (
            V1A,
            "duration = 4e-3",
            "duraton = 4e-3",
            "time.duraton",
            &["unknown key", "dt, duration"],
        ),
        (
            V1A,
            "name = \"plane\"",
            "nam = \"plane\"",
            "contacts[0].nam",
            &["unknown key", "name"],
        ),
        (
            TUBE,
            "damping_ratio = 0.01",
            "damping_ratio = \"1 %\"",
            "structure.damping_ratio",
            &["a damping ratio", "one per mode", "got \"1 %\""],
        ),
        (
            TUBE,
            "modes = 12",
            "modes = -12",
            "structure.modes",
            &["a whole number ≥ 1", "got -12"],
        ),
    ];
    for (base, from, to, key, needles) in cases {
        let text = replace_once(base, from, to);
        let (found, message, display) = schema_error(&text);
        assert_eq!(found.as_deref(), Some(*key), "{to}: {display}");
        assert!(display.contains(&format!(": {key}: ")), "{display}");
        for n in *needles {
            assert!(message.contains(n), "{to}: '{n}' not in: {message}");
        }
        for w in SERDE_WORDS {
            assert!(!display.contains(w), "{to}: serde's '{w}' in: {display}");
        }
    }
}

/// A study file's schema errors, and its base case's, are worded the same way.
#[test]
fn study_schema_errors_name_the_key_in_plain_words() {
    let (_dir, path) = study_dir(
        "study_words",
        "base = \"v1a.toml\"\nruns = 3\n\n[[parameters]]\nkey = \"time.dt\"\nvalues = [1e-6]\n",
    );
    let err = Study::from_file(&path).unwrap_err().to_string();
    assert!(
        err.contains("runs: unknown key") && err.contains("parameters"),
        "{err}"
    );
    let (dir, path) = study_dir("study_base_words", "base = \"v1a.toml\"\n");
    std::fs::write(
        dir.0.join("v1a.toml"),
        replace_once(V1A, "every = 1 ", "every = -1 "),
    )
    .unwrap();
    let err = Study::from_file(&path).unwrap_err().to_string();
    assert!(
        err.contains("output.every: must be a whole number ≥ 1") && err.contains("got -1"),
        "{err}"
    );
    for w in SERDE_WORDS {
        assert!(!err.contains(w), "serde's '{w}' in: {err}");
    }
}

// ---------------------------------------------------------------------------------------------
// Plausibility: finite but absurd values (issue [3.1])
// ---------------------------------------------------------------------------------------------

const MULTISPAN: &str = include_str!("../../../examples/tube_multispan.toml");
const LIFE: &str = include_str!("../../../examples/tube_multispan_life.toml");

fn examples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

/// The warnings of the case `text` (which builds).
fn warnings_of(text: &str) -> Vec<String> {
    match Case::from_toml_str(text, &examples_dir()) {
        Ok(case) => case.warnings,
        Err(e) => panic!("expected a case with warnings, got {e}"),
    }
}

/// The catalogue's absurd values, each accepted before without a word: a warning naming the
/// key as written, the value and the plausible range, or a refusal when no computation can
/// be made with it.
#[test]
fn absurd_values_warn_or_are_refused() {
    let load = |force: &str| {
        replace_once(
            V1A,
            "[tangential]\n",
            &format!("[[loads]]\npoint = \"mass\"\nforce = [0.0, {force}, 0.0]\n\n[tangential]\n"),
        )
    };
    let first = |text: &str, from: &str, to: &str| text.replacen(from, to, 1);
    let warned = [
        (load("1e9"), "loads[0].force[1] = 1e9 N", "-1e7 to 1e7 N"),
        (
            replace_once(V1A, "friction = { mu = 0.3 }", "friction = { mu = 1e6 }"),
            "contacts[0].friction.mu = 1e6 ",
            "friction coefficient, 0 to 2",
        ),
        (
            first(MULTISPAN, "clearance = 2e-4", "clearance = 1e3"),
            "contacts[0].obstacle.clearance = 1000 m",
            "0 to 0.1 m",
        ),
        (
            replace_once(TUBE, "density = 8200.0", "density = 8.2"),
            "structure.density = 8.2 kg/m³",
            "1000 to 25000 kg/m³",
        ),
        (
            first(LIFE, "thickness = 0.02", "thickness = 1e3"),
            "contacts[0].wear.scar.thickness = 1000 m",
            "0.0001 to 0.5 m",
        ),
    ];
    for (text, value, range) in warned {
        let warnings = warnings_of(&text);
        let w = warnings
            .iter()
            .find(|w| w.contains(value))
            .unwrap_or_else(|| panic!("no warning with '{value}': {warnings:?}"));
        assert!(
            w.contains(range) && w.contains("unit") && !w.contains('\n'),
            "{w}"
        );
    }
    // a load of 1e150 N: the energies and statistics the run sums from its square overflow
    // (a gap of 1e300 m: the run "diverged" at its first step)
    for (text, key, value) in [
        (load("1e150"), "loads[0].force[1]", "1e150 N"),
        (load("-1e300"), "loads[0].force[1]", "-1e300 N"),
        (
            replace_once(V1A, "gap = 0.0, tangent", "gap = 1e300, tangent"),
            "contacts[0].obstacle.gap",
            "1e300 m",
        ),
    ] {
        let (field, message) = invalid(&text);
        assert_eq!(field, key);
        assert!(
            message.contains(value) && message.contains("1e100") && message.contains("overflow"),
            "{message}"
        );
    }
    // a wear exponent of 1e300: every power of the work rate overflows or vanishes
    let text = first(
        LIFE,
        "tube = { law = \"archard\", coefficient = 6.0e-17 }",
        "tube = { law = \"decaying\", a = 1e-12, b = 1e300, s = 0.5, n = 1e-6 }",
    );
    let (field, message) = invalid_in(&text, &examples_dir());
    assert_eq!(field, "contacts[0].wear.tube.b");
    assert!(
        message.contains("1e300") && message.contains("-30 to 30") && message.contains("overflow"),
        "{message}"
    );
    // a plausible exponent is accepted without a word
    let text = text.replace("b = 1e300", "b = 1.2");
    assert!(warnings_of(&text).is_empty());
}

/// The shipped examples are plausible: no warning at all.
#[test]
fn the_examples_give_no_warning() {
    let mut cases = 0;
    for entry in std::fs::read_dir(examples_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        if text.lines().any(|l| l.starts_with("base = ")) {
            continue; // a study
        }
        let case = Case::from_file(&path).unwrap();
        assert!(
            case.warnings.is_empty(),
            "{}: {:?}",
            path.display(),
            case.warnings
        );
        cases += 1;
    }
    assert!(cases >= 10, "{cases} example cases");
}

/// A warning of a case file names the file.
#[test]
fn a_warning_names_the_case_file() {
    let dir = TempDir::new("warning_file");
    let path = dir.0.join("dense.toml");
    std::fs::write(
        &path,
        replace_once(TUBE, "density = 8200.0", "density = 8.2"),
    )
    .unwrap();
    let case = Case::from_file(&path).unwrap();
    assert_eq!(case.warnings.len(), 1, "{:?}", case.warnings);
    assert!(
        case.warnings[0].starts_with(&format!("{}: structure.density = 8.2", path.display())),
        "{}",
        case.warnings[0]
    );
}

// ---------------------------------------------------------------------------------------------
// Sizes derived from user numbers: turbulence band limit, contacts' memory (issue [3.1])
// ---------------------------------------------------------------------------------------------

const TURBULENCE: &str = include_str!("../../../examples/tube_turbulence.toml");

/// A band limit above the Nyquist frequency ran for hours (1e9 Hz: thousands of samples per
/// step) or never ended (9.2e18 Hz); refused with 1/(2Δt).
#[test]
fn a_turbulence_band_limit_above_the_nyquist_frequency_is_refused() {
    // Δt = 1e-5 s: 1/(2Δt) = 50 kHz
    for f_max in ["1e9", "9.2e18", "50001"] {
        let text = replace_once(TURBULENCE, "f_max = 250.0", &format!("f_max = {f_max}"));
        let (field, message) = invalid_in(&text, &examples_dir());
        assert_eq!(field, "turbulence[0].f_max");
        assert!(
            message.contains("Nyquist")
                && message.contains("50000 Hz")
                && message.contains("set f_max ≤ 50000 Hz"),
            "{message}"
        );
    }
    // the Nyquist frequency itself is a band limit
    let text = replace_once(TURBULENCE, "f_max = 250.0", "f_max = 5e4");
    assert!(Case::from_toml_str(&text, &examples_dir()).is_ok());
}

/// V1a's contact 20 000 times (each an unnamed plane): the Lagrange methods' dense matrices
/// of the 40 000 tangential unknowns (3 of 12.8 GB) aborted the run on their allocation;
/// the case is refused with the figure and the fix (unless this machine has the memory).
#[test]
fn contacts_whose_memory_is_not_available_are_refused_with_the_figure() {
    let contact = "[[contacts]]\npoint = \"mass\"\nobstacle = { type = \"plane\", normal = [0.0, 0.0, 1.0] }\nnormal = { stiffness = 1e6 }\nfriction = { mu = 0.3 }\n";
    let start = V1A.find("[[contacts]]").unwrap();
    let end = V1A.find("[tangential]").unwrap();
    let text = format!("{}{}{}", &V1A[..start], contact.repeat(20_000), &V1A[end..]);
    // 3 (2m)² matrices of 8 bytes at least
    let needed = 3.0 * 8.0 * 4e4 * 4e4;
    if needed <= fretdyn::structure::beam::available_memory() {
        eprintln!("skipped: this machine has {needed:e} bytes available");
        return;
    }
    let (field, message) = invalid(&text);
    assert_eq!(field, "contacts");
    assert!(
        message.contains("20000 contacts")
            && message.contains("GB")
            && message.contains("use fewer contacts")
            && message.contains("\"penalty\""),
        "{message}"
    );
    // the penalty method's memory grows as contacts × modes: it fits
    let penalty = replace_once(
        &text,
        "method = \"gauss_seidel\"",
        "method = \"penalty\"\npenalty = { stiffness = 1e6 }",
    );
    assert!(Case::from_toml_str(&penalty, Path::new(".")).is_ok());
}
