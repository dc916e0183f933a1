//! A flat bar of finite width, twisted (`width`, `points_across`, `twist_deg` on a contact;
//! `contact::flat_bar`, `case/flat_bar.rs`): a static tube pressed on the bar carries its load
//! where the closed form of the beam says — at one edge, or over the width — and a bar of one
//! point without twist is the old contact bit for bit.

use fretdyn::case::Case;
use fretdyn::integrator::simulation::simulate;
use fretdyn::model::static_equilibrium;
use fretdyn::structure::modal::recombine;
use fretdyn::wear::Scar;
use nalgebra::{DMatrix, DVector, Vector3};

const L: f64 = 1.0;
const D: f64 = 19.05e-3;
const WALL: f64 = 1.09e-3;
const E: f64 = 2.0e11;
const P: f64 = 5.0;
const K: f64 = 2e5;
const W: f64 = 0.0254;

/// A tube along x from 0 to `L`, both ends pinned (torsion held at x = 0), every mode kept,
/// heavily mass-damped (every mode decays as `e^{−α t/2}`), pushed down by `P` at mid-span
/// onto a flat bar below it (normal +z) of width `W`, `n` points across, twisted by
/// `twist_deg`, centre clearance `gap`.
fn case(n: usize, twist_deg: f64, gap: f64, extra: &str) -> Case {
    Case::from_toml_str(&source(n, twist_deg, gap, extra), std::path::Path::new(".")).unwrap()
}

/// The text of [`case`].
fn source(n: usize, twist_deg: f64, gap: f64, extra: &str) -> String {
    format!(
        r#"
[time]
dt = 2e-6
duration = 0.4

[output]
every = 1000

[structure]
type = "tube"
outer_diameter = {D:?}
wall_thickness = {WALL:?}
young_modulus = {E:?}
poisson_ratio = 0.3
density = 8000.0
path = [[0.0, 0.0, 0.0], [{L:?}, 0.0, 0.0]]
mesh_size = 0.1
modes = 59
rayleigh = {{ alpha = 600.0, beta = 0.0 }}

[[structure.supports]]
at = [0.0, 0.0, 0.0]
type = "dofs"
fixed = ["ux", "uy", "uz", "rx"]

[[structure.supports]]
at = [{L:?}, 0.0, 0.0]
type = "dofs"
fixed = ["ux", "uy", "uz"]

[[structure.points]]
name = "mid"
at = [0.5, 0.0, 0.0]

[[loads]]
point = "mid"
force = [0.0, 0.0, -{P:?}]

[[contacts]]
name = "bar"
point = "mid"
radius = {r:?}
obstacle = {{ type = "plane", normal = [0.0, 0.0, 1.0], gap = {gap:?} }}
normal = {{ stiffness = {K:?} }}
friction = {{ mu = 0.0 }}
width = {W:?}
points_across = {n}
twist_deg = {twist_deg:?}
{extra}
"#,
        r = D / 2.0
    )
}

/// The closed form: the mid-span node of a pinned–pinned Euler–Bernoulli beam has the
/// flexibilities `L/(4EA)` axially (both ends held), `L³/(48EI)` in deflection and
/// `L/(12EI)` in rotation, uncoupled at mid-span (symmetry). The bar's points `j` (axial
/// offsets `s_j`, stiffnesses `K ω_j`, twisted normal `n' = (−sin α, 0, cos α)`) see the
/// section's `y = (u_x, u_z, θ_y)` through `a_j·y = n'·(u + θ × s_j x̂)
/// = −sin α u_x + cos α (u_z − s_j θ_y)`, and penetrate by `δ_j = s_j sin α − gap − a_j·y`.
/// With the points that close (the set `A`, found by trying): `y = G (f + Σ_A F_j a_j)`,
/// `F_j = K ω_j δ_j`, a linear system in the forces. Returns the forces and `y`.
fn closed_form(n: usize, twist_deg: f64, gap: f64) -> (Vec<f64>, Vector3<f64>) {
    let area = std::f64::consts::PI / 4.0 * (D * D - (D - 2.0 * WALL).powi(2));
    let inertia = std::f64::consts::PI / 64.0 * (D.powi(4) - (D - 2.0 * WALL).powi(4));
    let g = Vector3::new(
        L / (4.0 * E * area),
        L.powi(3) / (48.0 * E * inertia),
        L / (12.0 * E * inertia),
    );
    let alpha = twist_deg.to_radians();
    let (sa, ca) = alpha.sin_cos();
    let h = if n == 1 { 0.0 } else { 1.0 / (n - 1) as f64 };
    let s: Vec<f64> = (0..n)
        .map(|j| {
            if n == 1 {
                0.0
            } else {
                0.5 * W * ca * (2.0 * j as f64 * h - 1.0)
            }
        })
        .collect();
    let k: Vec<f64> = (0..n)
        .map(|j| {
            if n == 1 {
                K
            } else if j == 0 || j == n - 1 {
                K * 0.5 * h
            } else {
                K * h
            }
        })
        .collect();
    let a: Vec<Vector3<f64>> = s.iter().map(|s| Vector3::new(-sa, ca, -ca * s)).collect();
    let f = Vector3::new(0.0, -P, 0.0);
    let gf = g.component_mul(&f);
    // active set by trying: start with all, drop the tensile ones, add the penetrating ones
    let mut active = vec![true; n];
    for _ in 0..4 * n {
        let idx: Vec<usize> = (0..n).filter(|&j| active[j]).collect();
        let m = idx.len();
        // (1/k_i) F_i + Σ_l a_i·G a_l F_l = δ0_i − a_i·G f
        let mut mat = DMatrix::<f64>::zeros(m, m);
        let mut rhs = DVector::<f64>::zeros(m);
        for (r, &i) in idx.iter().enumerate() {
            for (c, &l) in idx.iter().enumerate() {
                mat[(r, c)] = a[i].dot(&g.component_mul(&a[l]));
            }
            mat[(r, r)] += 1.0 / k[i];
            rhs[r] = s[i] * sa - gap - a[i].dot(&gf);
        }
        let forces = mat.lu().solve(&rhs).unwrap();
        let mut fj = vec![0.0; n];
        for (r, &i) in idx.iter().enumerate() {
            fj[i] = forces[r];
        }
        let mut load = f;
        for j in 0..n {
            load += a[j] * fj[j];
        }
        let y = g.component_mul(&load);
        let mut changed = false;
        for j in 0..n {
            let delta = s[j] * sa - gap - a[j].dot(&y);
            if active[j] && fj[j] < 0.0 {
                active[j] = false;
                changed = true;
            } else if !active[j] && delta > 0.0 {
                active[j] = true;
                changed = true;
            }
        }
        if !changed {
            return (fj, y);
        }
    }
    panic!("no active set found");
}

/// The run's last normal forces and the mid-span section's `(u_x, u_z, θ_y)`.
fn final_state(case: &Case) -> (Vec<f64>, Vector3<f64>) {
    let r = simulate(&case.model, &case.settings).unwrap();
    let last = r.recorder.len() - 1;
    let forces = (0..case.model.contacts.len())
        .map(|c| r.recorder.normal_force[[last, c]])
        .collect();
    let q: Vec<f64> = r.recorder.q.row(last).iter().copied().collect();
    (forces, section(case, &q))
}

/// The mid-span section's `(u_x, u_z, θ_y)` at `q`.
fn section(case: &Case, q: &[f64]) -> Vector3<f64> {
    let mid = &case.model.basis.points[case.model.basis.point_index("mid").unwrap()];
    let u = recombine(&mid.rows, q);
    let theta = recombine(&mid.rotations, q);
    Vector3::new(u.x, u.z, theta.y)
}

/// The same by the second method, the static equilibrium of the model on its contacts
/// (`model::static_equilibrium`, Newton on the active set) under the modal force of `P`.
fn static_state(case: &Case) -> (Vec<f64>, Vector3<f64>) {
    let mid = &case.model.basis.points[case.model.basis.point_index("mid").unwrap()];
    let p = case.model.basis.modes();
    let force: Vec<f64> = (0..p).map(|i| -P * mid.rows[2 * p + i]).collect();
    let s = static_equilibrium(&case.model, Some(&force)).unwrap();
    let y = section(case, &s.q);
    (s.forces, y)
}

/// Prints the largest differences from the closed form, relative to the largest force and
/// the largest section displacement (`--nocapture`).
fn report(what: &str, f: &[f64], fe: &[f64], y: &Vector3<f64>, ye: &Vector3<f64>) {
    let scale = fe.iter().cloned().fold(0.0, f64::max);
    let df = f
        .iter()
        .zip(fe)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / scale;
    let dy = (y - ye).amax() / ye.amax();
    eprintln!(
        "{what}: forces {f:?}, closed form {fe:?}; relative differences {df:.1e} (forces), {dy:.1e} (section)"
    );
}

/// Twisted by 2°, the bar's face rises towards +x: the edge there touches the tube at rest and
/// the next point is 0.22 mm below it, more than the tube's deflection under P (0.1 mm), so
/// only that edge touches and carries P less the supports' share; the edge point is at `+(w/2) cos α` along
/// the tube, and the forces (each point's, and so their resultant and moment about the
/// section) and the section's displacement and rotation are the closed form's to 1e-10
/// (measured 8e-14: the transient has decayed by `e^{−αt/2} = e^{−120}`, what is left is
/// round-off); the static equilibrium of the model (`model::static_equilibrium`), a second
/// method, agrees with them.
#[test]
fn a_twisted_bar_carries_the_load_at_its_edge() {
    // the centre clearance that puts the +x edge at the tube's surface at rest
    let (n, twist) = (5, 2.0f64);
    let gap = 0.5 * W * twist.to_radians().sin() * twist.to_radians().cos();
    let case = case(n, twist, gap, "");
    assert_eq!(case.model.contacts.len(), n);
    let names: Vec<&str> = case
        .model
        .contacts
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    assert_eq!(names, ["bar[0]", "bar[1]", "bar[2]", "bar[3]", "bar[4]"]);
    let (expected, y) = closed_form(n, twist, gap);
    // only the +x edge closes
    assert!(
        expected[n - 1] > 0.0 && expected[..n - 1].iter().all(|f| *f == 0.0),
        "{expected:?} {y:?}"
    );
    let (forces, got_y) = final_state(&case);
    report("edge", &forces, &expected, &got_y, &y);
    let (f2, y2) = static_state(&case);
    report("edge, static equilibrium", &f2, &expected, &y2, &y);
    for j in 0..n {
        assert!((f2[j] - expected[j]).abs() <= 1e-10 * expected[n - 1]);
    }
    for j in 0..n {
        assert!(
            (forces[j] - expected[j]).abs() <= 1e-10 * expected[n - 1],
            "point {j}: {} N against {} N",
            forces[j],
            expected[j]
        );
    }
    for d in 0..3 {
        assert!(
            (got_y[d] - y[d]).abs() <= 1e-10 * y.amax(),
            "section {d}: {} against {}",
            got_y[d],
            y[d]
        );
    }
    // where: the edge, (w/2) cos α along the tube from the section
    let edge = &case.model.contacts[n - 1];
    let across = edge.across.unwrap();
    let half = 0.5 * W * twist.to_radians().cos();
    assert!((across.offset - half).abs() < 1e-15);
    let x = case.model.basis.points[edge.point].coords;
    assert!((x - Vector3::new(0.5 + half, 0.0, 0.0)).norm() < 1e-15);
    // equilibrium: the supports take P − F cos α (by statics: a pinned beam with P at
    // mid-span and F at the section; here the closed form's own statics)
    let fz: f64 = forces.iter().sum::<f64>() * twist.to_radians().cos();
    let moment: f64 = forces
        .iter()
        .zip(case.model.contacts.iter())
        .map(|(f, c)| f * c.across.unwrap().offset)
        .sum();
    assert!(fz > 0.0 && fz < P);
    assert!((moment / forces.iter().sum::<f64>() - half).abs() < 1e-9 * half);
}

/// A smaller twist, 0.02°: the deflection under P closes the whole width; the five points'
/// forces (more towards the +x edge, the ends' halved by their share of the width) against
/// the closed form to 1e-10 (measured 5e-15), their resultant and moment with them.
#[test]
fn a_slightly_twisted_bar_touches_over_its_width() {
    let (n, twist, gap) = (5, 0.02, 0.0);
    let case = case(n, twist, gap, "");
    let (expected, y) = closed_form(n, twist, gap);
    assert!(expected.iter().all(|f| *f > 0.0), "{expected:?}");
    assert!(expected[n - 1] > expected[0]);
    let (forces, got_y) = final_state(&case);
    report("width", &forces, &expected, &got_y, &y);
    let (f2, y2) = static_state(&case);
    report("width, static equilibrium", &f2, &expected, &y2, &y);
    for j in 0..n {
        assert!((f2[j] - expected[j]).abs() <= 1e-10 * expected[n - 1]);
    }
    let scale = expected.iter().cloned().fold(0.0, f64::max);
    for j in 0..n {
        assert!(
            (forces[j] - expected[j]).abs() <= 1e-10 * scale,
            "point {j}: {} N against {} N",
            forces[j],
            expected[j]
        );
    }
    for d in 0..3 {
        assert!((got_y[d] - y[d]).abs() <= 1e-10 * y.amax());
    }
}

/// A bar of one point without twist is the contact without width, bit for bit: the same
/// contact, the same run.
#[test]
fn one_point_without_twist_is_the_old_contact() {
    let a = case(1, 0.0, 1e-4, "");
    // the same case, the bar's keys removed
    let text: String = source(1, 0.0, 1e-4, "")
        .lines()
        .filter(|l| {
            !["width", "points_across", "twist_deg"]
                .iter()
                .any(|k| l.starts_with(k))
        })
        .map(|l| format!("{l}\n"))
        .collect();
    let b = Case::from_toml_str(&text, std::path::Path::new(".")).unwrap();
    assert!(b.model.contacts[0].across.is_none());
    let mut ca = a.model.contacts[0].clone();
    ca.across = None;
    assert_eq!(ca, b.model.contacts[0]);
    assert_eq!(a.model.basis, b.model.basis);
    let mut settings = a.settings.clone();
    settings.steps = 10_000;
    let (ra, rb) = (
        simulate(&a.model, &settings).unwrap(),
        simulate(&b.model, &settings).unwrap(),
    );
    assert!(ra.recorder.normal_force.iter().any(|f| *f > 0.0));
    assert_eq!(ra.recorder.q, rb.recorder.q);
    assert_eq!(ra.recorder.normal_force, rb.recorder.normal_force);
}

/// A scar of a bar with width: each point's strip of the bar (`ω_j w`), tilted by the twist;
/// a scar's width or tilt that differs from the bar's is refused naming the key. The strips,
/// each cut by the twisted face at its depth there (`ρ − x sin α`, `x` the distance of the
/// strip's deeper side from the bar's deep edge), hold together the closed-form volume of the
/// whole bar's wedge (`Scar::FlatBar` of width `w`, docs/WEAR.md), for a wedge shorter than
/// the width and for a cut over the whole width: the width caps the scar.
#[test]
fn a_bar_s_scar_is_its_strips() {
    let wear = |scar: &str| {
        format!(
            "wear = {{ tube = {{ law = \"archard\", coefficient = 2e-15 }}, support = {{ law = \"archard\", coefficient = 1e-15 }}, scar = {scar} }}"
        )
    };
    let (n, twist) = (5, 2.0f64);
    let alpha = twist.to_radians();
    let c = case(n, twist, 0.0, &wear("{ type = \"flat_bar\" }"));
    let h = 1.0 / (n - 1) as f64;
    let strips: Vec<Scar> = (0..n)
        .map(|k| c.model.contact_wear(k).unwrap().scar.clone())
        .collect();
    for (k, scar) in strips.iter().enumerate() {
        let Scar::FlatBar {
            width,
            tilt,
            tube_radius,
        } = *scar
        else {
            panic!("{scar:?}")
        };
        let share = if k == 0 || k == n - 1 { 0.5 * h } else { h };
        assert_eq!((width, tilt, tube_radius), (share * W, alpha, D / 2.0));
    }
    let whole = Scar::FlatBar {
        tube_radius: D / 2.0,
        width: W,
        tilt: alpha,
    };
    // the deep edge is +x (the last point); strips from there
    for rho in [
        0.2 * W * alpha.sin(),
        0.7 * W * alpha.sin(),
        1.5 * W * alpha.sin(),
    ] {
        let mut x = 0.0;
        let mut sum = 0.0;
        for scar in strips.iter().rev() {
            let Scar::FlatBar { width, .. } = *scar else {
                unreachable!()
            };
            let depth = rho - x * alpha.sin();
            if depth > 0.0 {
                sum += scar.tube_volume(depth).unwrap();
            }
            x += width;
        }
        let v = whole.tube_volume(rho).unwrap();
        assert!((sum - v).abs() <= 1e-12 * v, "ρ = {rho}: {sum} against {v}");
    }
    // the scar's own width and tilt, if given, are the bar's
    for (scar, refused) in [
        ("width = 0.02", Some("width")),
        ("tilt_deg = 1.0", Some("tilt_deg")),
        ("width = 0.0254, tilt_deg = 2.0", None),
    ] {
        let text = source(
            n,
            twist,
            0.0,
            &wear(&format!("{{ type = \"flat_bar\", {scar} }}")),
        );
        let built = Case::from_toml_str(&text, std::path::Path::new("."));
        let field = refused.map(|k| format!("contacts[0].wear.scar.{k}"));
        assert_eq!(built.err().and_then(|e| e.field().map(String::from)), field);
    }
}

/// A bar's keys without a width, a width on a hole, and a normal along the tube are refused
/// naming the key.
#[test]
fn bad_bars_are_refused_naming_the_key() {
    let text = source(3, 0.0, 0.0, "").replace("width = 0.0254\n", "");
    let e = Case::from_toml_str(&text, std::path::Path::new(".")).unwrap_err();
    assert_eq!(e.field(), Some("contacts[0].points_across"), "{e}");
    let text =
        source(3, 0.0, 0.0, "").replace("normal = [0.0, 0.0, 1.0]", "normal = [1.0, 0.0, 1.0]");
    let e = Case::from_toml_str(&text, std::path::Path::new(".")).unwrap_err();
    assert_eq!(e.field(), Some("contacts[0].obstacle.normal"), "{e}");
    let text = source(3, 0.0, 0.0, "").replace(
        "type = \"plane\", normal = [0.0, 0.0, 1.0], gap = 0.0",
        "type = \"circle\", centre = [0.5, 0.0, 0.0], axis = [1.0, 0.0, 0.0], clearance = 1e-4",
    );
    let e = Case::from_toml_str(&text, std::path::Path::new(".")).unwrap_err();
    assert_eq!(e.field(), Some("contacts[0].width"), "{e}");
}

/// The U-bend of `examples/ubend.toml` with its hot-leg bars 25.4 mm wide, 3 points across,
/// twisted by 0.2° (each edge 44 µm nearer than the middle on one side, of the 0.1 mm gap),
/// wearing: the edges rattle, slide and do wear work, each point's strip wears by the laws, and the run's energy balance closes within the code's own limit
/// (`MAX_RELATIVE_ERROR`, no warning) — the points' forces, friction included, do the work
/// the balance books; `summary.json` gives each point's axial offset and share of the width.
#[test]
fn a_u_bend_on_wide_twisted_bars_rattles_and_wears() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/ubend.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let hot = "tangent = [-0.707106781187, 0.0, 0.707106781187] }\n";
    assert_eq!(text.matches(hot).count(), 1);
    let text = text.replace(
        hot,
        &format!(
            "{hot}width = 0.0254\npoints_across = 3\ntwist_deg = 0.2\nwear = {{ tube = {{ law = \"archard\", coefficient = 2e-14 }}, support = {{ law = \"archard\", coefficient = 1e-14 }}, scar = {{ type = \"flat_bar\" }} }}\n"
        ),
    );
    let mut case = Case::from_toml_str(&text, path.parent().unwrap()).unwrap();
    let names: Vec<&str> = case
        .model
        .contacts
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    assert_eq!(
        names,
        [
            "cold_leg_plate",
            "hot_leg_plate",
            "avb_cold",
            "avb_hot[0]",
            "avb_hot[1]",
            "avb_hot[2]"
        ]
    );
    case.settings.steps = 50_000;
    let r = simulate(&case.model, &case.settings).unwrap();
    assert!(
        fretdyn::accumulate::energy::energy_warnings(&r.energy, case.settings.dt).is_empty(),
        "{:?}",
        r.energy
    );
    let mut total = 0.0;
    for k in 3..6 {
        let s = &r.contacts[k];
        assert!(
            s.wear_work_rate.is_finite() && s.wear_work_rate >= 0.0,
            "{s:?}"
        );
        if k == 4 {
            // the middle of a twisted face is farther than one of the edges on either side
            continue;
        }
        assert!(s.impacts > 0 && s.slip_time_fraction > 0.0, "{s:?}");
        assert!(s.wear_work_rate > 0.0, "{s:?}");
        let w = case.model.contact_wear(k).unwrap();
        let (tube, support) = w.volume_rates(s.wear_work_rate, 0.0);
        assert!((tube - 2e-14 * s.wear_work_rate).abs() <= 1e-15 * tube && support > 0.0);
        total += s.wear_work_rate;
    }
    // summary.json: which point is where across the width
    let summary = fretdyn::output::summary::summary(&case, &r);
    let half = 0.5 * 0.0254 * 0.2f64.to_radians().cos();
    for (k, (s, w)) in [(-half, 0.25), (0.0, 0.5), (half, 0.25)]
        .into_iter()
        .enumerate()
    {
        let entry = &summary["contacts"][3 + k];
        assert_eq!(entry["name"], format!("avb_hot[{k}]"));
        assert!((entry["axial_offset"].as_f64().unwrap() - s).abs() < 1e-15);
        assert_eq!(entry["width_share"].as_f64(), Some(w));
    }
    assert!(summary["contacts"][2].get("axial_offset").is_none());
    eprintln!(
        "avb_hot points: wear work rates {:?} W (sum {total:e}); energy balance {:e}",
        (3..6)
            .map(|k| r.contacts[k].wear_work_rate)
            .collect::<Vec<_>>(),
        r.energy.relative_error
    );
}
