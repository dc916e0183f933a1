//! Case files of several structures (`[[structures]]`, THEORY §15) and their two-body
//! contacts: a structure alone among several runs as in a case of its own, two free bodies
//! colliding through a case-file pair contact keep their momentum, the obstacles of a pair are
//! placed in relative coordinates, studies reach into `structures[i]`, and bad input names
//! its field.

use std::path::Path;

use fretdyn::Error;
use fretdyn::apps::study::Study;
use fretdyn::case::Case;
use fretdyn::contact::obstacle::Obstacle;
use fretdyn::integrator::simulation::simulate;

fn parse(text: &str) -> fretdyn::Result<Case> {
    Case::from_toml_str(text, Path::new("."))
}

fn field_of(e: &Error) -> String {
    e.field().unwrap_or_default().to_string()
}

/// A unit point mass at the origin thrown obliquely at a plane below it (V1a-like), with the
/// sections a one-structure case gives at the top level; `prefix` = "" (top level) or
/// "structures." (an entry of several).
fn thrown_mass(prefix: &str) -> String {
    format!(
        r#"[{prefix}structure]
type = "point_mass"
mass = 1.0
point = "mass"

[{prefix}initial]
point = "mass"
velocity = [0.5, 0.1, -1.0]

[[{prefix}contacts]]
name = "plane"
point = "mass"
obstacle = {{ type = "plane", normal = [0.0, 0.0, 1.0], gap = 1e-4 }}
normal = {{ stiffness = 1e6 }}
friction = {{ mu = 0.3 }}
"#
    )
}

const SETTINGS: &str = r#"
[time]
dt = 1e-6
duration = 4e-3

[tangential]
method = "active_set"

[output]
every = 1
"#;

/// A structure in a case of several, with a second structure beside it that nothing couples
/// to it, runs as in a case of its own: its modal coordinates and its contact's forces are the
/// same to round-off (the union's basis is block diagonal, THEORY §15).
#[test]
fn a_structure_alone_among_several_runs_as_in_a_case_of_its_own() {
    let alone = parse(&format!("{SETTINGS}\n{}", thrown_mass(""))).unwrap();
    let several = parse(&format!(
        "{SETTINGS}\n[[structures]]\nname = \"a\"\n{}\n[[structures]]\nname = \"b\"\n\
         [structures.structure]\ntype = \"point_mass\"\nmass = 3.0\nposition = [1.0, 0.0, 0.0]\n\
         [[structures.loads]]\npoint = \"mass\"\nforce = [0.0, 2.0, 0.0]\n",
        thrown_mass("structures.")
    ))
    .unwrap();
    assert!(alone.model.structures.is_empty());
    let names: Vec<&str> = several
        .model
        .structures
        .iter()
        .map(|s| s.name.as_str())
        .collect();
    assert_eq!(names, ["a", "b"]);
    assert_eq!(several.model.contacts[0].name, "a.plane");
    assert_eq!(several.model.basis.points[1].name, "b.mass");
    let ra = simulate(&alone.model, &alone.settings).unwrap().recorder;
    let rs = simulate(&several.model, &several.settings)
        .unwrap()
        .recorder;
    assert_eq!(ra.len(), rs.len());
    // it hits the plane, slips and sticks: the comparison covers all three
    assert!(ra.normal_force.iter().any(|f| *f > 0.0));
    for (x, y) in [(&ra.q, &rs.q), (&ra.qdot, &rs.qdot)] {
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (i, row) in x.outer_iter().enumerate() {
            for j in 0..3 {
                assert!(
                    (row[j] - y[(i, j)]).abs() <= 1e-12 * scale,
                    "step {i}, mode {j}: {} alone, {} among two",
                    row[j],
                    y[(i, j)]
                );
            }
        }
    }
    let scale = ra.normal_force.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (x, y) in ra.normal_force.iter().zip(rs.normal_force.iter()) {
        assert!((x - y).abs() <= 1e-12 * scale, "{x} {y}");
    }
    // structure b moves under its load alone: u = F t²/(2m) along y, exactly
    let t = *rs.t.last().unwrap();
    let last = rs.q.nrows() - 1;
    let u_b = rs.q[(last, 4)] / 3.0f64.sqrt();
    let expected = 2.0 * t * t / (2.0 * 3.0);
    assert!(
        (u_b - expected).abs() <= 1e-3 * expected,
        "{u_b} {expected}"
    );
}

/// Two free bodies, masses 1 and 3 kg, the first thrown obliquely at the second through a
/// top-level two-body contact with friction (Lagrange, Active Set): the total linear momentum
/// `Σ m u̇ = Σ √m q̇` stays what it was, at every step, to round-off — through the impact,
/// slip and stick — and the second body is pushed along +x, away from the first.
#[test]
fn two_free_bodies_keep_their_momentum_through_a_case_file_pair_contact() {
    let text = format!(
        r#"{SETTINGS}
[[structures]]
name = "a"
[structures.structure]
type = "point_mass"
mass = 1.0
[structures.initial]
point = "mass"
velocity = [1.0, 0.3, 0.0]

[[structures]]
name = "b"
[structures.structure]
type = "point_mass"
mass = 3.0
position = [0.01, 0.0, 0.0]

# A against B along x: the plane's normal from B to A, 1 mm of clearance at rest
[[contacts]]
name = "a_b"
point = "a.mass"
other = "b.mass"
obstacle = {{ type = "plane", normal = [-1.0, 0.0, 0.0], gap = 1e-3 }}
normal = {{ stiffness = 1e6 }}
friction = {{ mu = 0.2 }}
"#
    );
    let case = parse(&text).unwrap();
    let r = simulate(&case.model, &case.settings).unwrap().recorder;
    let (sa, sb) = (1.0f64.sqrt(), 3.0f64.sqrt());
    let momentum = |i: usize, d: usize| sa * r.qdot[(i, d)] + sb * r.qdot[(i, 3 + d)];
    assert!(r.normal_force.iter().any(|f| *f > 0.0), "no impact");
    let slipping = r.status.iter().any(|s| *s == 2);
    let sticking = r.status.iter().any(|s| *s == 1);
    assert!(slipping && sticking, "slip {slipping}, stick {sticking}");
    for d in 0..3 {
        let p0 = momentum(0, d);
        for i in 0..r.len() {
            assert!(
                (momentum(i, d) - p0).abs() <= 1e-12,
                "axis {d}, step {i}: {} against {p0}",
                momentum(i, d)
            );
        }
    }
    let last = r.len() - 1;
    assert!(r.qdot[(last, 3)] > 0.0, "B is pushed along +x");
    // the gap closed at 1 mm: contact began once A had travelled it
    let first = r.normal_force.iter().position(|f| *f > 0.0).unwrap();
    let travelled = r.q[(first, 0)] - r.q[(first, 3)] / sb;
    assert!((travelled - 1e-3).abs() < 2e-6, "{travelled}");
}

/// The obstacle of a pair is in relative coordinates: a plane's origin is an offset from the
/// rest relative position `x0_A − x0_B`, a cylinder's centre from B's point and its radius
/// `R_A + R_B` by default; the contact's radius is `R_A + R_B`.
#[test]
fn a_pairs_obstacle_is_placed_in_relative_coordinates() {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/tube_to_tube.toml");
    let case = Case::from_file(&example).unwrap();
    let k = case
        .model
        .contacts
        .iter()
        .position(|c| c.name == "tube_to_tube")
        .unwrap();
    let c = &case.model.contacts[k];
    let a = case.model.basis.point_index("tube_a.mid").unwrap();
    let b = case.model.basis.point_index("tube_b.mid").unwrap();
    assert_eq!((c.point, c.other()), (a, Some(b)));
    assert_eq!(c.radius, 2.0 * 9.525e-3);
    match &c.obstacle {
        Obstacle::Cylinder(cyl) => assert_eq!(cyl.radius(), 2.0 * 9.525e-3),
        other => panic!("{other:?}"),
    }
    // the contact sees A − B: 19.35 mm apart at rest, a gap of 0.3 mm
    let rel = c.point_in(&case.model.basis.points);
    assert!((rel.coords.y + 19.35e-3).abs() < 1e-12, "{:?}", rel.coords);
    // every structure's turbulence its own default seed: 1000·i + k
    let seeds: Vec<u64> = case.model.turbulence.iter().map(|t| t.seed).collect();
    assert_eq!(seeds, [0, 1000]);
    // and an explicit seed is kept
    let text = std::fs::read_to_string(&example).unwrap().replacen(
        "correlation_length = 0.25\n",
        "correlation_length = 0.25\nseed = 7\n",
        1,
    );
    let seeded = Case::from_toml_str(&text, example.parent().unwrap()).unwrap();
    let seeds: Vec<u64> = seeded.model.turbulence.iter().map(|t| t.seed).collect();
    assert_eq!(seeds, [7, 1000]);

    // a plane: origin = x0_A − x0_B + offset
    let avb = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/tube_flexible_avb.toml");
    let case = Case::from_file(&avb).unwrap();
    let c = case
        .model
        .contacts
        .iter()
        .find(|c| c.pair.is_some())
        .unwrap();
    let (pa, pb) = (
        &case.model.basis.points[c.point],
        &case.model.basis.points[c.other().unwrap()],
    );
    match &c.obstacle {
        Obstacle::Plane(p) => assert_eq!(p.origin(), pa.coords - pb.coords),
        other => panic!("{other:?}"),
    }
}

/// A study reaches into `structures[i]` and the top-level contacts by key paths.
#[test]
fn key_paths_reach_into_structures() {
    let base: toml::Value = toml::from_str(&format!(
        "{SETTINGS}\n[[structures]]\nname = \"a\"\n{}\n[[structures]]\nname = \"b\"\n\
         [structures.structure]\ntype = \"point_mass\"\nmass = 3.0\nposition = [0.01, 0.0, 0.0]\n\
         [[contacts]]\nname = \"a_b\"\npoint = \"a.mass\"\nother = \"b.mass\"\n\
         obstacle = {{ type = \"plane\", normal = [-1.0, 0.0, 0.0], gap = 1e-3 }}\n\
         normal = {{ stiffness = 1e6 }}\nfriction = {{ mu = 0.2 }}\n",
        thrown_mass("structures.")
    ))
    .unwrap();
    let study = Study::from_toml_str(
        "combine = \"list\"\n\
         [[parameters]]\nkey = \"structures[1].structure.mass\"\nvalues = [2.0, 5.0]\n\
         [[parameters]]\nkey = \"structures[0].contacts[0].friction.mu\"\nvalues = [0.1, 0.4]\n\
         [[parameters]]\nkey = \"contacts[0].normal.stiffness\"\nvalues = [2e6, 3e6]\n",
        Path::new("."),
        Some((base, Path::new(".").to_path_buf())),
    )
    .unwrap();
    assert_eq!(study.contact_names(), ["a.plane", "a_b"]);
    let runs = study.runs();
    assert_eq!(runs.len(), 2);
    let case = study.case(&runs[1]).unwrap();
    // a point mass of 5 kg: rows 1/√m
    let b = case.model.basis.point_index("b.mass").unwrap();
    let row = case.model.basis.points[b].rows[3];
    assert!((row - 1.0 / 5.0f64.sqrt()).abs() < 1e-15, "{row}");
    assert_eq!(case.model.contacts[0].friction.mu_dynamic, 0.4);
    assert_eq!(case.model.contacts[1].normal.stiffness, 3e6);
}

/// Bad input of several structures gives one clear error naming its field.
#[test]
fn bad_input_of_several_structures_names_its_field() {
    let one = thrown_mass("");
    let entry = format!(
        "[[structures]]\nname = \"a\"\n{}",
        thrown_mass("structures.")
    );
    let b =
        "[[structures]]\nname = \"b\"\n[structures.structure]\ntype = \"point_mass\"\nmass = 3.0\n";
    let pair = |extra: &str| {
        format!(
            "[[contacts]]\nname = \"a_b\"\npoint = \"a.mass\"\nother = \"b.mass\"\n{extra}\
             obstacle = {{ type = \"plane\", normal = [-1.0, 0.0, 0.0], gap = 1e-3 }}\n\
             normal = {{ stiffness = 1e6 }}\nfriction = {{ mu = 0.2 }}\n"
        )
    };
    let cases = [
        // both, none
        (
            format!("{SETTINGS}{one}\n{entry}"),
            "structures",
            "not both",
        ),
        (SETTINGS.to_string(), "structure", "[[structures]]"),
        // a structure's section at the top level
        (
            format!("{SETTINGS}{entry}{b}[[loads]]\npoint = \"a.mass\"\nforce = [1.0, 0.0, 0.0]\n"),
            "loads",
            "per structure",
        ),
        // an error inside an entry is prefixed with it
        (
            format!("{SETTINGS}{entry}{b}").replace("mass = 3.0", "mass = -3.0"),
            "structures[1].structure.mass",
            "",
        ),
        (
            format!("{SETTINGS}{entry}{}", b.replace("\"b\"", "\"a\"")),
            "structures[1].name",
            "already",
        ),
        // a pair
        (
            format!("{SETTINGS}{entry}{b}{}", pair("radius = 0.01\n")),
            "contacts[0].radius",
            "radii",
        ),
        (
            format!(
                "{SETTINGS}{entry}{b}{}",
                pair("").replace("\"b.mass\"", "\"b.nowhere\"")
            ),
            "contacts[0].other",
            "b.mass",
        ),
        (
            format!(
                "{SETTINGS}{entry}{b}{}",
                pair("").replace("\"b.mass\"", "\"a.mass\"")
            ),
            "contacts[0].other",
            "own point",
        ),
        (
            format!("{SETTINGS}{entry}{b}{}", pair("radii = [0.01, 0.01]\n")),
            "contacts[0].radii",
            "rotations",
        ),
        (
            format!(
                "{SETTINGS}{entry}{b}{}",
                pair("").replace("other = \"b.mass\"\n", "radii = [0.0, 0.0]\n")
            ),
            "contacts[0].radii",
            "other",
        ),
    ];
    for (text, field, words) in cases {
        let e = parse(&text).unwrap_err();
        assert_eq!(field_of(&e), field, "{e}");
        assert!(e.to_string().contains(words), "{e}");
    }
}

/// `[life]` in a case of several structures (`examples/tube_to_tube.toml`, windows of 1 s):
/// the two-body contact wears both tubes — equal laws and equal radii, so equal depths — and
/// the gap opens by their approach, more than either depth and less than their sum
/// (THEORY §15); the criterion is a depth in m (no one tube's wall to take a fraction of).
#[test]
fn a_service_life_of_two_tubes_wears_both() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(root.join("tube_to_tube.toml")).unwrap();
    assert!(text.contains("duration = 10.0"));
    let text = text.replace("duration = 10.0", "duration = 1.0");
    let case = parse(&format!(
        "{text}\n[life]\ntarget_years = 40.0\ncriterion_depth = 4e-4\n"
    ))
    .unwrap();
    let life = case.life.clone().unwrap();
    assert_eq!(life.wall, None);
    let r = fretdyn::service_life(&case, &life, |_| {}).unwrap();
    assert_eq!(r.end, fretdyn::apps::life::LifeEnd::Completed);
    assert_eq!(r.contacts, vec!["tube_to_tube".to_string()]);
    assert_eq!(
        r.bodies,
        vec![Some(["tube_a.mid".to_string(), "tube_b.mid".to_string()])]
    );
    let last = &r.steps.last().unwrap().contacts[0];
    assert!(last.tube_depth > 1e-7, "{}", last.tube_depth);
    assert!(
        (last.tube_depth - last.support_depth).abs() <= 1e-12 * last.tube_depth,
        "{} vs {}",
        last.tube_depth,
        last.support_depth
    );
    assert!(last.clearance_increase > last.tube_depth);
    assert!(last.clearance_increase < last.tube_depth + last.support_depth);
    // a fraction of the wall needs one tube
    let e = parse(&format!(
        "{text}\n[life]\ntarget_years = 40.0\ncriterion_wall_fraction = 0.4\n"
    ))
    .unwrap_err();
    assert_eq!(field_of(&e), "life.criterion_wall_fraction");
    assert!(e.to_string().contains("criterion_depth"), "{e}");
}
