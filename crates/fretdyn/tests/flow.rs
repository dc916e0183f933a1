//! Flow zones and the Connors check (docs/FLOW.md) against closed forms:
//! - a pinned–pinned tube (modes `sin(nπs/L)`, degenerate pairs in y and z): the effective
//!   velocity of a uniform zone over the whole tube is the zone's velocity; over a part
//!   `[a, b]` it is `U √(∫_a^b sin² / ∫_0^L sin²)`, the integral by hand; a second zone with no
//!   velocity changes nothing;
//! - the critical velocity against Connors' formula with the frequency of the beam's closed
//!   form and the mass per length of the section by hand;
//! - the same on the analytic pinned beam of a point basis (stations with their abscissa);
//! - a turbulence spectrum taking its velocity and density from a zone is the explicit one,
//!   bit for bit, run included;
//! - bad input names its field.

use std::f64::consts::PI;
use std::path::Path;

use fretdyn::Case;

const L: f64 = 1.0;
const D: f64 = 0.02;
const T: f64 = 0.001;
const E: f64 = 2.0e11;
const RHO_T: f64 = 8000.0;
const RHO_I: f64 = 1000.0;
const RHO_O: f64 = 800.0;
const CA: f64 = 1.2;

/// A pinned–pinned straight tube along x (axial and torsion held at s = 0), its 4 lowest
/// modes (the pairs n = 1, 2 in y and z), damping ζ = 0.02, and `flow` appended.
fn pinned_tube(mesh: f64, flow: &str) -> String {
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
path = [[0.0, 0.0, 0.0], [{L}, 0.0, 0.0]]
mesh_size = {mesh}
modes = 4
damping_ratio = 0.02

[[structure.supports]]
at = [0.0, 0.0, 0.0]
type = "dofs"
fixed = ["ux", "uy", "uz", "rx"]

[[structure.supports]]
at = [{L}, 0.0, 0.0]
type = "pinned"

[[structure.points]]
name = "a"
at = [0.2, 0.0, 0.0]

[[structure.points]]
name = "b"
at = [0.7, 0.0, 0.0]
{flow}
"#
    )
}

fn case(text: &str) -> Case {
    Case::from_toml_str(text, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

fn error_field(text: &str) -> String {
    let e = Case::from_toml_str(text, Path::new(".")).expect_err("an input error");
    e.field()
        .unwrap_or_else(|| panic!("not a field error: {e}"))
        .to_string()
}

const FLOW_HEAD: &str = r#"
[flow]
pattern = "rotated_square"
pitch_ratio = 1.44
velocity_definition = "gap"
"#;

/// `∫_a^b sin²(kπs/L) ds`, by hand.
fn sin2(k: f64, a: f64, b: f64) -> f64 {
    let w = k * PI / L;
    0.5 * (b - a) - ((2.0 * w * b).sin() - (2.0 * w * a).sin()) / (4.0 * w)
}

/// Mode order n of each of the 4 modes (pairs).
const ORDER: [f64; 4] = [1.0, 1.0, 2.0, 2.0];

#[test]
fn flow_uniform_zone_over_the_whole_tube_gives_its_velocity() {
    let c = case(&pinned_tube(
        0.02,
        &format!(
            "{FLOW_HEAD}\n[[flow.zones]]\nname = \"all\"\nspan = [0.0, {L}]\ndensity = 750.0\nvelocity = 2.5\n"
        ),
    ));
    let r = c.stability().unwrap();
    assert_eq!(r.modes.len(), 4);
    for m in &r.modes {
        assert!(
            (m.effective_velocity / 2.5 - 1.0).abs() < 1e-13,
            "mode {}: {}",
            m.mode,
            m.effective_velocity
        );
        assert_eq!(m.reference_density, 750.0);
        assert_eq!(m.reference_zone, "all");
    }
}

/// Partial spans: `U_eff² = U² ∫_a^b sin² / (L/2)`. The finite elements' shapes differ from
/// the sines by their discretisation error only (the stations interpolate them with the
/// elements' own cubic Hermite functions): it falls faster than h⁴ with the mesh (halving it
/// divides the error by more than 10; measured: 1.2e-9 → 1.9e-11) and is below 1e-9 on the
/// finer mesh.
#[test]
fn flow_partial_zone_matches_the_closed_form_integral() {
    let (a, b, u) = (0.2, 0.7, 3.0);
    let mut errors = Vec::new();
    for mesh in [0.05, 0.025] {
        let c = case(&pinned_tube(
            mesh,
            &format!(
                "{FLOW_HEAD}\n[[flow.zones]]\nname = \"part\"\nspan = [{a}, {b}]\ndensity = 600.0\nvelocity = {u}\n"
            ),
        ));
        let r = c.stability().unwrap();
        let mut worst: f64 = 0.0;
        for (m, n) in r.modes.iter().zip(ORDER) {
            let exact = u * (sin2(n, a, b) / (0.5 * L)).sqrt();
            worst = worst.max((m.effective_velocity / exact - 1.0).abs());
        }
        errors.push(worst);
    }
    assert!(errors[1] < 1e-9, "{errors:?}");
    assert!(
        errors[0] > 10.0 * errors[1] || errors[0] < 1e-12,
        "{errors:?}"
    );
}

/// The same span given by named points, and a second zone with zero velocity (and another
/// density): the closed form of the partial span again; ρ_ref is the flowing zone's.
#[test]
fn flow_two_zones_one_still_gives_the_partial_span_closed_form() {
    let (a, b, u) = (0.2, 0.7, 3.0);
    let flow = format!(
        "{FLOW_HEAD}\n[[flow.zones]]\nname = \"still\"\nspan = [0.0, {a}]\ndensity = 1000.0\nvelocity = 0.0\n\n[[flow.zones]]\nname = \"moving\"\nfrom = \"a\"\nto = \"b\"\ndensity = 600.0\nvelocity = {u}\n"
    );
    let c = case(&pinned_tube(0.025, &flow));
    let r = c.stability().unwrap();
    for (m, n) in r.modes.iter().zip(ORDER) {
        let exact = u * (sin2(n, a, b) / (0.5 * L)).sqrt();
        assert!(
            (m.effective_velocity / exact - 1.0).abs() < 1e-9,
            "mode {}: {} vs {exact}",
            m.mode,
            m.effective_velocity
        );
        assert_eq!(m.reference_zone, "moving");
        assert_eq!(m.reference_density, 600.0);
    }
}

/// `U_c = K f D √(m 2πζ / (ρ D²))` with f of the closed form `(nπ/L)² √(EI/m) / 2π` and m, I
/// of the section by hand; the ratio is U_eff / U_c; upstream velocities are × P/(P − D).
#[test]
fn flow_critical_velocity_is_connors_formula_by_hand() {
    let flow = r#"
[flow]
pattern = "normal_triangle"
pitch_ratio = 1.5
velocity_definition = "upstream"
connors_constant = 2.4

[[flow.zones]]
name = "all"
span = [0.0, 1.0]
void_fraction = 0.25
liquid_density = 740.0
gas_density = 40.0
velocity = 1.0
"#;
    let c = case(&pinned_tube(0.025, flow));
    let r = c.stability().unwrap();
    let (ro, ri) = (0.5 * D, 0.5 * D - T);
    let m = RHO_T * PI * (ro * ro - ri * ri) + RHO_I * PI * ri * ri + CA * RHO_O * PI * ro * ro;
    let i = 0.25 * PI * (ro.powi(4) - ri.powi(4));
    let rho = 0.75 * 740.0 + 0.25 * 40.0;
    assert_eq!(r.mass_per_length, m);
    assert_eq!(r.diameter, D);
    assert_eq!(r.connors_constant, 2.4);
    for (mode, n) in r.modes.iter().zip(ORDER) {
        let f = (n * PI / L).powi(2) * (E * i / m).sqrt() / (2.0 * PI);
        let uc = 2.4 * f * D * (m * 2.0 * PI * 0.02 / (rho * D * D)).sqrt();
        assert!(
            (mode.critical_velocity / uc - 1.0).abs() < 1e-6,
            "mode {}: {} vs {uc}",
            mode.mode,
            mode.critical_velocity
        );
        assert_eq!(mode.reference_density, rho);
        // upstream 1 m/s: gap velocity 1.5/(1.5 − 1) = 3 m/s over the whole tube
        assert!((mode.effective_velocity / 3.0 - 1.0).abs() < 1e-13);
        let ratio = mode.ratio.unwrap();
        assert_eq!(ratio, mode.effective_velocity / mode.critical_velocity);
        assert_eq!(mode.unstable(), ratio > 1.0);
    }
}

/// A point basis (the analytic pinned beam, stations with their x as abscissa): a zone over
/// part of it against the closed form, within the midpoint rule's error over 201 stations.
#[test]
fn flow_zone_on_a_point_basis_uses_the_stations() {
    let n = 201;
    let mut points = String::new();
    for k in 0..n {
        let x = k as f64 * L / (n - 1) as f64;
        points.push_str(&format!("[[structure.points]]\nname = \"p{k}\"\nx = {x}\n"));
    }
    let text = format!(
        r#"
[time]
dt = 1e-6
duration = 1e-4

[structure]
type = "pinned_beam"
length = {L}
bending_stiffness = 1000.0
mass_per_length = 2.0
modes_per_plane = 2
damping_ratio = 0.01
{points}
[flow]
pattern = "in_line_square"
pitch_ratio = 1.4
velocity_definition = "gap"
diameter = 0.02
mass_per_length = 2.0

[[flow.zones]]
name = "z"
from = "p40"
to = "p140"
density = 500.0
velocity = 2.0
"#
    );
    let c = case(&text);
    let r = c.stability().unwrap();
    let (a, b) = (0.2, 0.7);
    for (m, n) in r.modes.iter().zip(ORDER) {
        let exact = 2.0 * (sin2(n, a, b) / (0.5 * L)).sqrt();
        // the midpoint rule's error, O(h²) with h = 5e-3 (measured: 1.6e-5 for n = 1)
        assert!(
            (m.effective_velocity / exact - 1.0).abs() < 1e-4,
            "mode {}: {} vs {exact}",
            m.mode,
            m.effective_velocity
        );
        let f = (n * PI / L).powi(2) * (1000.0f64 / 2.0).sqrt() / (2.0 * PI);
        let uc = 3.0 * f * 0.02 * (2.0 * 2.0 * PI * 0.01 / (500.0 * 0.02 * 0.02)).sqrt();
        assert!((m.critical_velocity / uc - 1.0).abs() < 1e-12);
    }
}

const TURBULENCE: &str = r#"
[[turbulence]]
directions = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
correlation_length = 0.1
seed = 7
f_max = 500.0
"#;

/// `zone = "…"` with a cross-flow spectrum without velocity or density is the explicit
/// spectrum over the zone's span with the zone's numbers: same loads, same run, bit for bit.
#[test]
fn flow_turbulence_from_a_zone_is_the_explicit_form_bit_for_bit() {
    let zones = format!(
        "{FLOW_HEAD}\n[[flow.zones]]\nname = \"lower\"\nspan = [0.0, 0.35]\ndensity = 1000.0\nvelocity = 0.5\n\n[[flow.zones]]\nname = \"upper\"\nspan = [0.35, 0.9]\ndensity = 720.0\nvelocity = 4.0\n"
    );
    let explicit = case(&pinned_tube(
        0.05,
        &format!(
            "{zones}{TURBULENCE}span = [0.35, 0.9]\nspectrum = {{ type = \"cross_flow\", velocity = 4.0, density = 720.0 }}\n"
        ),
    ));
    let from_zone = case(&pinned_tube(
        0.05,
        &format!("{zones}{TURBULENCE}zone = \"upper\"\nspectrum = {{ type = \"cross_flow\" }}\n"),
    ));
    assert_eq!(explicit.model.turbulence, from_zone.model.turbulence);
    let a = fretdyn::simulate(&explicit.model, &explicit.settings).unwrap();
    let b = fretdyn::simulate(&from_zone.model, &from_zone.settings).unwrap();
    assert_eq!(a.recorder.q, b.recorder.q);
    assert!(a.recorder.q.iter().any(|v| *v != 0.0));
    // the same case without the [flow] section: the explicit form is unchanged by it
    let bare = case(&pinned_tube(
        0.05,
        &format!(
            "{TURBULENCE}span = [0.35, 0.9]\nspectrum = {{ type = \"cross_flow\", velocity = 4.0, density = 720.0 }}\n"
        ),
    ));
    let c = fretdyn::simulate(&bare.model, &bare.settings).unwrap();
    assert_eq!(a.recorder.q, c.recorder.q);
}

#[test]
fn flow_bad_input_names_the_field() {
    let zone = |body: &str| pinned_tube(0.05, &format!("{FLOW_HEAD}\n[[flow.zones]]\n{body}\n"));
    let ok = "name = \"z\"\nspan = [0.1, 0.5]\ndensity = 700.0\nvelocity = 1.0";
    assert!(Case::from_toml_str(&zone(ok), Path::new(".")).is_ok());
    for (body, field) in [
        (ok.replace("[0.1, 0.5]", "[0.1, 1.5]"), "flow.zones[0].span"),
        (ok.replace("[0.1, 0.5]", "[0.5, 0.1]"), "flow.zones[0].span"),
        (ok.replace("700.0", "-700.0"), "flow.zones[0].density"),
        (
            ok.replace("velocity = 1.0", "velocity = -1.0"),
            "flow.zones[0].velocity",
        ),
        (
            ok.replace(
                "velocity = 1.0",
                "velocity_profile = [[0.1, 1.0], [0.3, 2.0], [0.2, 1.0]]",
            ),
            "flow.zones[0].velocity_profile[2]",
        ),
        (
            ok.replace("span = [0.1, 0.5]", "from = \"a\"\nto = \"nowhere\""),
            "flow.zones[0].to",
        ),
        (ok.replace("\"z\"", "\"a b\""), "flow.zones[0].name"),
        (
            ok.replace(
                "density = 700.0",
                "void_fraction = 1.5\nliquid_density = 700.0\ngas_density = 30.0",
            ),
            "flow.zones[0].void_fraction",
        ),
        (ok.replace("velocity = 1.0", ""), "flow.zones[0]"),
    ] {
        assert_eq!(error_field(&zone(&body)), field, "{body}");
    }
    // overlapping zones
    let two = format!(
        "{ok}\n\n[[flow.zones]]\nname = \"y\"\nspan = [0.4, 0.8]\ndensity = 1.0\nvelocity = 1.0"
    );
    assert_eq!(error_field(&zone(&two)), "flow.zones[1].span");
    // P/D ≤ 1
    assert_eq!(
        error_field(&zone(ok).replace("pitch_ratio = 1.44", "pitch_ratio = 0.9")),
        "flow.pitch_ratio"
    );
    // turbulence: unknown zone, a profile zone without a velocity, span and zone both
    let profile = ok.replace(
        "velocity = 1.0",
        "velocity_profile = [[0.1, 1.0], [0.5, 2.0]]",
    );
    for (body, turbulence, field) in [
        (
            ok.to_string(),
            "zone = \"q\"\nspectrum = { type = \"cross_flow\" }",
            "turbulence[0].zone",
        ),
        (
            profile,
            "zone = \"z\"\nspectrum = { type = \"cross_flow\" }",
            "turbulence[0].spectrum.velocity",
        ),
        (
            ok.to_string(),
            "zone = \"z\"\nspan = [0.1, 0.2]\nspectrum = { type = \"cross_flow\" }",
            "turbulence[0].span",
        ),
        (
            ok.to_string(),
            "spectrum = { type = \"cross_flow\", velocity = 1.0 }",
            "turbulence[0].spectrum.density",
        ),
    ] {
        assert_eq!(
            error_field(&format!("{}{TURBULENCE}{turbulence}\n", zone(&body))),
            field
        );
    }
}

/// A zone's quasi-steady fluid-elastic forces projected on the tube's modes (THEORY §13): with
/// the flow along z across a tube along x, the y modes see the lift terms and the z modes the
/// drag terms. Per mode `C_ii / K_ii` is `D C_D / (U C_L')` (lift) and `2 D C_D / (U C_D')`
/// (drag) exactly; the n = 1 pair has one shape, so its drag damping is twice its lift
/// damping; the delay is `μ D / U`; a y mode and a z mode do not couple; and `∫φ² = 1/m` for
/// a mass-normalised mode (up to the rotary inertia and the mesh: 1e-3).
#[test]
fn flow_quasi_steady_forces_project_on_the_modes() {
    use fretdyn::loads::fluid_elastic::ModalMatrix;
    let (u, rho, cl, cdp, cd, mu) = (2.0, 750.0, -3.0, 1.5, 0.8, 1.2);
    let c = case(&pinned_tube(
        0.02,
        &format!(
            "{FLOW_HEAD}\n[[flow.zones]]\nname = \"all\"\nspan = [0.0, {L}]\ndensity = {rho}\nvelocity = {u}\nfluid_elastic = {{ model = \"quasi_steady\", lift_slope = {cl}, drag_slope = {cdp}, drag = {cd}, mu = {mu}, flow_direction = [0.0, 0.0, 1.0] }}\n"
        ),
    ));
    let fe = c
        .model
        .fluid_elastic
        .as_ref()
        .expect("fluid-elastic forces");
    assert_eq!(fe.delayed.len(), 1);
    assert!((fe.delayed[0].delay - mu * D / u).abs() <= 1e-15);
    let p = c.model.basis.modes();
    let (ModalMatrix::Dense(k), [ModalMatrix::Dense(cm)]) =
        (&fe.delayed[0].stiffness, &fe.damping[..])
    else {
        panic!("dense matrices expected");
    };
    // the direction each mode moves in, from its largest component at point "a"
    let a = &c.model.basis.points[c.model.basis.point_index("a").unwrap()];
    let moves_y = |i: usize| a.rows[p + i].abs() > a.rows[2 * p + i].abs();
    let m = {
        let t = T;
        let area = PI * (D * D - (D - 2.0 * t).powi(2)) / 4.0;
        let inner = PI * (D - 2.0 * t).powi(2) / 4.0;
        RHO_T * area + RHO_I * inner + CA * RHO_O * PI * D * D / 4.0
    };
    let mut lift_damping = None;
    for i in 0..p {
        let (kii, cii) = (k[i * p + i], cm[i * p + i]);
        let expected = if moves_y(i) {
            D * cd / (u * cl)
        } else {
            2.0 * D * cd / (u * cdp)
        };
        assert!((cii / kii / expected - 1.0).abs() < 1e-12, "mode {i}");
        // ∫φ² from the damping: C = ρUD C_D (½ or 1) ∫φ²
        let share = if moves_y(i) { 0.5 } else { 1.0 };
        let integral = cii / (rho * u * D * cd * share);
        assert!(
            (integral * m - 1.0).abs() < 1e-3,
            "mode {i}: ∫φ² m = {}",
            integral * m
        );
        if ORDER[i] == 1.0 {
            if moves_y(i) {
                lift_damping = Some(cii);
            } else if let Some(l) = lift_damping {
                assert!((cii / l - 2.0).abs() < 1e-9, "{cii} {l}");
            }
        }
        for j in 0..p {
            if moves_y(i) != moves_y(j) {
                assert!(k[i * p + j].abs() <= 1e-12 * kii.abs());
                assert!(cm[i * p + j].abs() <= 1e-12 * cii.abs());
            }
        }
    }
}

#[test]
fn flow_fluid_elastic_bad_input_names_the_field() {
    let zone = |fe: &str| {
        pinned_tube(
            0.05,
            &format!(
                "{FLOW_HEAD}\n[[flow.zones]]\nname = \"all\"\nspan = [0.0, {L}]\ndensity = 750.0\nvelocity = 2.0\nfluid_elastic = {fe}\n"
            ),
        )
    };
    for (fe, field) in [
        (
            "{ model = \"quasi_steady\", lift_slope = -3.0, drag = 1.0, mu = -1.0, flow_direction = [0.0, 0.0, 1.0] }",
            "flow.zones[0].fluid_elastic.mu",
        ),
        (
            "{ model = \"quasi_steady\", lift_slope = -3.0, drag = 1.0, mu = 1.0, mu_drag = -0.5, flow_direction = [0.0, 0.0, 1.0] }",
            "flow.zones[0].fluid_elastic.mu_drag",
        ),
        (
            "{ model = \"quasi_steady\", lift_slope = -3.0, drag = 1.0, mu_drag = 0.5, flow_direction = [0.0, 0.0, 1.0] }",
            "flow.zones[0].fluid_elastic.mu_lift",
        ),
        (
            "{ model = \"quasi_steady\", lift_slope = -3.0, drag = 1.0, mu = 1.0, flow_direction = [2.0, 0.0, 0.0] }",
            "flow.zones[0].fluid_elastic.flow_direction",
        ),
        (
            "{ model = \"quasi_steady\", lift_slope = -3.0, drag = 1.0, mu = 1.0, flow_direction = [0.0, 0.0, 0.0] }",
            "flow.zones[0].fluid_elastic.flow_direction",
        ),
        (
            "{ model = \"table\", reduced_velocity = [1.0, 1.0], damping = [0.0, 0.0], stiffness = [0.0, 0.0] }",
            "flow.zones[0].fluid_elastic.reduced_velocity[1]",
        ),
        (
            "{ model = \"table\", reduced_velocity = [1.0, 2.0], damping = [0.0], stiffness = [0.0, 0.0] }",
            "flow.zones[0].fluid_elastic",
        ),
    ] {
        assert_eq!(error_field(&zone(fe)), field, "{fe}");
    }
}

/// A velocity profile: `U(s) = 1 + 2 s/L` over the whole pinned tube gives
/// `U_eff² = ∫ U² sin²(nπs/L) ds / (L/2)`, integrated here by composite Simpson on 4 000
/// intervals (independent of the stations' Gauss quadrature on the elements); the elements'
/// shapes differ from the sines by their discretisation error (below 1e-9 on this mesh, see
/// the partial-span test).
#[test]
fn flow_velocity_profile_matches_a_numerical_quadrature() {
    let c = case(&pinned_tube(
        0.025,
        &format!(
            "{FLOW_HEAD}\n[[flow.zones]]\nname = \"all\"\nspan = [0.0, {L}]\ndensity = 750.0\nvelocity_profile = [[0.0, 1.0], [{L}, 3.0]]\n"
        ),
    ));
    let r = c.stability().unwrap();
    let simpson = |f: &dyn Fn(f64) -> f64| {
        let n = 4000;
        let h = L / n as f64;
        let mut s = f(0.0) + f(L);
        for i in 1..n {
            s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(i as f64 * h);
        }
        s * h / 3.0
    };
    for (m, order) in r.modes.iter().zip(ORDER) {
        let w = order * PI / L;
        let num = simpson(&|s: f64| (1.0 + 2.0 * s / L).powi(2) * (w * s).sin().powi(2));
        let expected = (num / (0.5 * L)).sqrt();
        assert!(
            (m.effective_velocity / expected - 1.0).abs() < 1e-8,
            "mode {}: {} against {expected}",
            m.mode,
            m.effective_velocity
        );
    }
}

/// Two-phase flow from a thermal-hydraulic map (docs/FLOW.md, "Two-phase flow"): quality `x`
/// and mass flux `G` give the homogeneous density `ρ_h = 1/(x/ρ_g + (1 − x)/ρ_l)` (the mixture's
/// specific volume, written here independently of the void fraction), and the zone's gap
/// velocity carries the mass flux: `ρ_h U_∞ = G` with `U = U_∞ P/(P − D)` (upstream), `ρ_h U = G`
/// (gap); `x = 0` is the liquid, `x = 1` the gas.
#[test]
fn flow_quality_and_mass_flux_give_the_homogeneous_density_and_velocity() {
    use fretdyn::loads::flow::{homogeneous_density, homogeneous_void_fraction};
    let (rl, rg, pd) = (740.0, 37.0, 1.44);
    for (x, definition) in [
        (0.0, "gap"),
        (0.05, "upstream"),
        (0.3, "gap"),
        (1.0, "upstream"),
    ] {
        let g = 500.0;
        let c = case(&pinned_tube(
            0.05,
            &format!(
                "\n[flow]\npattern = \"rotated_square\"\npitch_ratio = {pd}\nvelocity_definition = \"{definition}\"\n\n[[flow.zones]]\nname = \"bend\"\nspan = [0.0, {L}]\nquality = {x}\nliquid_density = {rl}\ngas_density = {rg}\nmass_flux = {g}\n"
            ),
        ));
        let zone = &c.flow.as_ref().unwrap().zones[0];
        let rho_h = 1.0 / (x / rg + (1.0 - x) / rl);
        assert!(
            (zone.density / rho_h - 1.0).abs() < 1e-14,
            "x {x}: ρ {} against {rho_h}",
            zone.density
        );
        let u = zone.velocity.constant().unwrap();
        let u_inf = if definition == "upstream" {
            u * (pd - 1.0) / pd
        } else {
            u
        };
        assert!(
            (zone.density * u_inf / g - 1.0).abs() < 1e-14,
            "x {x}: ρU = {} against G = {g}",
            zone.density * u_inf
        );
        // the effective velocity of a uniform zone is its velocity
        let r = c.stability().unwrap();
        assert!((r.modes[0].effective_velocity / u - 1.0).abs() < 1e-12);
    }
    // limits and the void fraction's definition
    assert_eq!(homogeneous_void_fraction(0.0, rl, rg), 0.0);
    assert_eq!(homogeneous_void_fraction(1.0, rl, rg), 1.0);
    assert_eq!(homogeneous_density(0.0, rl, rg), rl);
    assert_eq!(homogeneous_density(1.0, rl, rg), rg);
    // ε is the gas's volume fraction: x/ρ_g over the mixture's specific volume
    let x = 0.2;
    let eps = homogeneous_void_fraction(x, rl, rg);
    let volume = x / rg + (1.0 - x) / rl;
    assert!((eps - (x / rg) / volume).abs() < 1e-15);
}

/// A mass-flux profile is a velocity profile `G(s)/ρ`; bad two-phase input names its field.
#[test]
fn flow_mass_flux_profile_and_bad_two_phase_input() {
    let zone = |keys: &str| {
        pinned_tube(
            0.05,
            &format!("{FLOW_HEAD}\n[[flow.zones]]\nname = \"z\"\nspan = [0.0, {L}]\n{keys}\n"),
        )
    };
    let c = case(&zone(
        "quality = 0.1\nliquid_density = 740.0\ngas_density = 37.0\nmass_flux_profile = [[0.0, 300.0], [1.0, 600.0]]",
    ));
    let z = &c.flow.as_ref().unwrap().zones[0];
    for s in [0.0, 0.25, 0.5, 1.0] {
        let g = 300.0 + 300.0 * s;
        assert!((z.density * z.velocity.at(s) / g - 1.0).abs() < 1e-14);
    }
    for (keys, field) in [
        (
            "quality = 1.5\nliquid_density = 740.0\ngas_density = 37.0\nmass_flux = 500.0",
            "flow.zones[0].quality",
        ),
        (
            "quality = 0.1\nvoid_fraction = 0.5\nliquid_density = 740.0\ngas_density = 37.0\nmass_flux = 500.0",
            "flow.zones[0].quality",
        ),
        (
            "density = 740.0\nmass_flux = -5.0",
            "flow.zones[0].mass_flux",
        ),
        (
            "density = 740.0\nmass_flux = 5.0\nvelocity = 1.0",
            "flow.zones[0]",
        ),
    ] {
        assert_eq!(error_field(&zone(keys)), field, "{keys}");
    }
}

/// Viscous damping (docs/FLOW.md, "Damping models") recomputed independently: the power
/// dissipated in the oscillating Stokes layers on the tube (radius `a`) and on a concentric
/// wall (radius `b`), `μ V²/(2δ)` per unit area for a slip of amplitude `V`, with the slip of
/// the potential flow in the annulus — the potential `φ = U (A r + B/r) cos θ` solved here from
/// its two wall conditions, the slip from `∂φ/∂θ` by central differences — integrated over `θ`
/// by the trapezoidal rule (exact for these trigonometric integrands); `c = 2P/U²`,
/// `ζ = c/(2mω)`.
#[test]
fn flow_viscous_damping_is_the_stokes_layers_dissipation() {
    use fretdyn::loads::flow_damping::{ViscousDamping, viscous_damping_ratio};
    let (rho, nu, m, d) = (740.0, 1.2e-7, 0.6, 0.02);
    let a = 0.5 * d;
    for (f, ratio) in [
        (10.0, f64::INFINITY),
        (10.0, 1.6),
        (45.0, 1.3),
        (200.0, 3.0),
    ] {
        let w = 2.0 * PI * f;
        let delta = (2.0 * nu / w).sqrt();
        let mu = rho * nu;
        let u = 1.0;
        let b = a * ratio;
        // ∂φ/∂r = U cos θ at r = a, 0 at r = b: A − B/a² = 1, A − B/b² = 0
        let (aa, bb) = if b.is_finite() {
            let bb = 1.0 / (1.0 / (b * b) - 1.0 / (a * a));
            (bb / (b * b), bb)
        } else {
            (0.0, -a * a)
        };
        let phi = |r: f64, th: f64| u * (aa * r + bb / r) * th.cos();
        let n = 64;
        let h = 1e-6;
        let mut power = 0.0;
        for k in 0..n {
            let th = 2.0 * PI * k as f64 / n as f64;
            let tangential = |r: f64| (phi(r, th + h) - phi(r, th - h)) / (2.0 * h * r);
            // the tube's own tangential velocity is −U sin θ, the outer wall is still
            let inner = tangential(a) + u * th.sin();
            power += mu * inner * inner / (2.0 * delta) * a * 2.0 * PI / n as f64;
            if b.is_finite() {
                let outer = tangential(b);
                power += mu * outer * outer / (2.0 * delta) * b * 2.0 * PI / n as f64;
            }
        }
        let c = 2.0 * power / (u * u);
        let expected = c / (2.0 * m * w);
        let v = ViscousDamping {
            density: rho,
            kinematic_viscosity: nu,
            confinement: ratio,
        };
        let zeta = viscous_damping_ratio(f, &v, d, m);
        assert!(
            (zeta / expected - 1.0).abs() < 1e-8,
            "f {f}, D_e/D {ratio}: ζ_v {zeta} against {expected}"
        );
    }
}

/// `[flow.damping]`: the check's damping is the basis's plus the models' (each reported), the
/// critical velocity scales as `√δ` of the total, squeeze film as `1/f`; `in_run` adds the
/// fluid's terms to the run's damping without counting them twice in the check.
#[test]
fn flow_damping_models_add_to_the_connors_check() {
    let zone =
        "\n[[flow.zones]]\nname = \"all\"\nspan = [0.0, 1.0]\ndensity = 740.0\nvelocity = 1.0\n";
    let models = "\n[flow.damping]\nviscous = { density = 740.0, kinematic_viscosity = 1.2e-7, confinement = 1.5 }\ntwo_phase = 0.01\nfriction = 0.004\nsqueeze_film = { ratio = 0.02, frequency = 30.0 }\n";
    let plain = case(&pinned_tube(0.05, &format!("{FLOW_HEAD}{zone}")))
        .stability()
        .unwrap();
    let with = case(&pinned_tube(0.05, &format!("{FLOW_HEAD}{models}{zone}")));
    let r = with.stability().unwrap();
    for (a, b) in plain.modes.iter().zip(&r.modes) {
        let t = b.damping_terms.expect("the terms of each mode");
        assert_eq!(t.basis, 0.02);
        assert_eq!(t.two_phase, Some(0.01));
        assert_eq!(t.friction, Some(0.004));
        let sf = t.squeeze_film.unwrap();
        assert!((sf * b.frequency_hz / (0.02 * 30.0) - 1.0).abs() < 1e-14);
        let total = 0.02 + t.viscous.unwrap() + 0.01 + 0.004 + sf;
        assert!((b.damping_ratio / total - 1.0).abs() < 1e-15);
        // U_c ∝ √δ: the same mode, frequency, density and mass
        let scale = (b.damping_ratio / a.damping_ratio).sqrt();
        assert!(
            (b.critical_velocity / (a.critical_velocity * scale) - 1.0).abs() < 1e-13,
            "mode {}: {} against {}",
            b.mode,
            b.critical_velocity,
            a.critical_velocity * scale
        );
        assert!(a.damping_terms.is_none());
    }
    let json = serde_json::to_string(&r).unwrap();
    assert!(json.contains("\"damping_terms\":{\"basis\":0.02,\"viscous\":"));
    assert!(
        !serde_json::to_string(&plain)
            .unwrap()
            .contains("damping_terms")
    );
    // in_run: the run's damping gains the viscous and two-phase terms; the check is unchanged
    let run = case(&pinned_tube(
        0.05,
        &format!("{FLOW_HEAD}{models}in_run = true\n{zone}"),
    ));
    let checked = run.stability().unwrap();
    for (i, (m, n)) in checked.modes.iter().zip(&r.modes).enumerate() {
        assert_eq!(m.damping_ratio, n.damping_ratio);
        let t = m.damping_terms.unwrap();
        assert_eq!(t.basis, 0.02);
        assert_eq!(
            run.model.basis.damping_ratio[i],
            0.02 + (t.viscous.unwrap() + 0.01)
        );
        assert_eq!(with.model.basis.damping_ratio[i], 0.02);
    }
}

#[test]
fn flow_damping_bad_input_names_the_field() {
    let zone =
        "\n[[flow.zones]]\nname = \"all\"\nspan = [0.0, 1.0]\ndensity = 740.0\nvelocity = 1.0\n";
    for (models, field) in [
        ("two_phase = -0.01", "flow.damping.two_phase"),
        ("friction = nan", "flow.damping.friction"),
        (
            "viscous = { density = 740.0, kinematic_viscosity = 1.2e-7, confinement = 0.9 }",
            "flow.damping.viscous.confinement",
        ),
        (
            "viscous = { density = 740.0, kinematic_viscosity = 0.0 }",
            "flow.damping.viscous.kinematic_viscosity",
        ),
        (
            "squeeze_film = { ratio = 0.01, frequency = 0.0 }",
            "flow.damping.squeeze_film.frequency",
        ),
    ] {
        let text = pinned_tube(
            0.05,
            &format!("{FLOW_HEAD}\n[flow.damping]\n{models}\n{zone}"),
        );
        assert_eq!(error_field(&text), field, "{models}");
    }
}

/// A U-bend's coefficients by plane (`in_plane`, `out_of_plane`) are the lift's and drag's
/// the flow's direction makes them: flow normal to the bend's plane (examples/ubend_flow.toml,
/// the bend in xz, flow along y): the lift is in-plane; flow in the plane (along z, over the
/// apex): the drag is in-plane. The modal matrices equal, bit for bit, those of the explicit
/// keys. A straight zone, or a flow oblique to the plane, is refused.
#[test]
fn flow_u_bend_coefficients_by_plane_resolve_into_lift_and_drag() {
    let text = std::fs::read_to_string("../../examples/ubend_flow.toml").unwrap();
    let old = "fluid_elastic = { model = \"quasi_steady\", lift_slope = -3.0, drag = 1.0, mu = 1.0, flow_direction = [0.0, 1.0, 0.0], delay_segments = 4 }";
    assert!(text.contains(old));
    let with = |fe: &str, span: &str| {
        let t = text.replace(old, fe);
        let t = if span.is_empty() {
            t
        } else {
            t.replace(
                "from = \"cold_leg_plate\"\nto = \"hot_leg_plate\"",
                &format!("span = {span}"),
            )
        };
        Case::from_toml_str(&t, Path::new("../../examples"))
    };
    let fe = |keys: &str, dir: &str| {
        format!(
            "fluid_elastic = {{ model = \"quasi_steady\", {keys}, drag = 1.0, flow_direction = {dir} }}"
        )
    };
    let planes = "in_plane = { slope = -3.0, mu = 1.0 }, out_of_plane = { slope = -1.0, mu = 0.5 }";
    for (dir, span, explicit) in [
        (
            "[0.0, 1.0, 0.0]",
            "",
            "lift_slope = -3.0, mu_lift = 1.0, drag_slope = -1.0, mu_drag = 0.5",
        ),
        (
            "[0.0, 0.0, 1.0]",
            "[2.6, 2.97]",
            "lift_slope = -1.0, mu_lift = 0.5, drag_slope = -3.0, mu_drag = 1.0",
        ),
    ] {
        let a = with(&fe(planes, dir), span).unwrap_or_else(|e| panic!("{e}"));
        let b = with(&fe(explicit, dir), span).unwrap_or_else(|e| panic!("{e}"));
        let (fa, fb) = (
            a.model.fluid_elastic.unwrap(),
            b.model.fluid_elastic.unwrap(),
        );
        assert_eq!(fa, fb, "flow {dir}");
        // and not the other assignment
        let swapped = if explicit.starts_with("lift_slope = -3.0") {
            "lift_slope = -1.0, mu_lift = 0.5, drag_slope = -3.0, mu_drag = 1.0"
        } else {
            "lift_slope = -3.0, mu_lift = 1.0, drag_slope = -1.0, mu_drag = 0.5"
        };
        let c = with(&fe(swapped, dir), span).unwrap();
        assert_ne!(fa, c.model.fluid_elastic.unwrap(), "flow {dir}");
    }
    for (dir, span, field) in [
        (
            "[0.0, 1.0, 1.0]",
            "",
            "flow.zones[1].fluid_elastic.flow_direction",
        ),
        (
            "[0.0, 1.0, 0.0]",
            "[0.2, 1.8]",
            "flow.zones[1].fluid_elastic.in_plane",
        ),
    ] {
        let e = with(&fe(planes, dir), span).expect_err("refused");
        assert_eq!(e.field(), Some(field), "{e}");
    }
    let e = with(
        &fe(&format!("{planes}, lift_slope = -3.0"), "[0.0, 1.0, 0.0]"),
        "",
    )
    .expect_err("both ways refused");
    assert_eq!(e.field(), Some("flow.zones[1].fluid_elastic.in_plane"));
}
