//! Wear on both bodies of a two-body contact (THEORY §14, §15; docs/WEAR.md "Two bodies"):
//! the friction work of the pair wears body A by the `tube` law and body B by the `support`
//! law, both scars grow over a service life and the pair's relative obstacle opens by their
//! approach — exactly as a rigid obstacle's when body B does not move, and against the hand
//! computation of the laws and the scar when both bodies move.

use std::path::Path;

use fretdyn::apps::life::{LifeEnd, LifeResults, YEAR, service_life, worn_model};
use fretdyn::case::Case;
use fretdyn::contact::Contact;
use fretdyn::model::Model;
use fretdyn::structure::modal::Point;
use nalgebra::Vector3;

/// The sliding mass of `tests/service_life.rs`: a point mass pressed on a bar (10 N) that
/// slides under it at 1 cm/s; once the transient has died out the mass stands still and the
/// bar slides, `W = μ N v` exactly, whatever the gap.
fn sliding_mass(wear: &str, life: &str) -> Case {
    const BODY: &str = include_str!("fixtures/sliding_mass.toml");
    let text = format!(
        "title = \"mass sliding on a bar\"\n{BODY}wear = {wear}\n[tangential]\nmethod = \"gauss_seidel\"\n[statistics]\nt_start = 1.0\n[life]\n{life}\n"
    );
    Case::from_toml_str(&text, Path::new(".")).unwrap()
}

const MU_N_V: f64 = 0.3 * 10.0 * 0.01;
const R_A: f64 = 0.0095;
const R_B: f64 = 0.008;
const LENGTH: f64 = 0.02;
const K_A: f64 = 2e-15;
/// Body B's decaying law: `A W^B [s t + (1 − s)(1 − e^{−N t})/N]`.
const DECAY: (f64, f64, f64, f64) = (1.5e-15, 1.2, 0.2, 1.0 / YEAR);

/// Two parallel tubes (radii `R_A`, `R_B`, touching over `LENGTH`): A wears by Archard, B by
/// the decaying law.
fn tube_wear() -> String {
    let (a, b, s, n) = DECAY;
    format!(
        r#"{{ tube = {{ law = "archard", coefficient = {K_A:e} }}, support = {{ law = "decaying", a = {a:e}, b = {b}, s = {s}, n = {n:e} }}, scar = {{ type = "tube", other_radius = {R_B}, crossing_deg = 0.0, length = {LENGTH}, tube_radius = {R_A} }} }}"#
    )
}

/// The contact of `case` (on its one point, index 0) turned into a two-body contact between
/// that point (A) and `other` (B) of `model`, with the same obstacle (in relative
/// coordinates), motion, laws and wear.
fn pair_of(case: &Case, model: &mut Model, a: usize, b: usize) {
    let c = case.model.contacts[0].clone();
    let mut pair = Contact::between(
        c.name.clone(),
        a,
        b,
        &model.basis.points,
        [0.0, 0.0],
        c.obstacle.clone(),
        c.normal,
        c.friction,
    )
    .unwrap();
    pair.motion = c.motion.clone();
    model.contacts = vec![pair];
    model.wear = case.model.wear.clone();
    model.validate().unwrap();
}

/// Circular lens of two discs of radii `r1`, `r2` whose centres are `r1 + r2 − d` apart (the
/// textbook formula with `acos`, independent of the library's cancellation-free one).
fn lens(r1: f64, r2: f64, d: f64) -> f64 {
    let big = r1 + r2 - d;
    let c1 = ((big * big + r1 * r1 - r2 * r2) / (2.0 * big * r1)).acos();
    let c2 = ((big * big + r2 * r2 - r1 * r1) / (2.0 * big * r2)).acos();
    let k = ((-big + r1 + r2) * (big + r1 - r2) * (big - r1 + r2) * (big + r1 + r2)).sqrt();
    r1 * r1 * c1 + r2 * r2 * c2 - 0.5 * k
}

/// The depth of the parallel tubes' scar holding `volume`, by bisection on `LENGTH × lens`.
fn tube_depth(volume: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, R_B);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if LENGTH * lens(R_A, R_B, mid) < volume {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The worn volumes of A and B over `[t0, t1]` at the work rate `w`, by hand: Archard's
/// `K_A w (t1 − t0)`, and the decaying law's `V(t1) − V(t0)`,
/// `V(t) = A w^B [s t + (1 − s)(1 − e^{−N t})/N]`.
fn volumes(w: f64, t0: f64, t1: f64) -> (f64, f64) {
    let (a, b, s, n) = DECAY;
    let v = |t: f64| a * w.powf(b) * (s * t + (1.0 - s) * (1.0 - (-n * t).exp()) / n);
    (K_A * w * (t1 - t0), v(t1) - v(t0))
}

/// Largest relative difference of the two lives' volumes, depths and clearances.
fn largest_difference(a: &LifeResults, b: &LifeResults) -> f64 {
    assert_eq!(a.steps.len(), b.steps.len());
    let mut worst = 0.0f64;
    for (x, y) in a.steps.iter().zip(&b.steps) {
        let rel = |p: f64, q: f64| (p - q).abs() / p.abs().max(q.abs()).max(1e-300);
        worst = worst.max(rel(x.time, y.time));
        let (c, d) = (&x.contacts[0], &y.contacts[0]);
        for (p, q) in [
            (c.tube_volume, d.tube_volume),
            (c.support_volume, d.support_volume),
            (c.tube_depth, d.tube_depth),
            (c.support_depth, d.support_depth),
            (c.clearance_increase, d.clearance_increase),
        ] {
            worst = worst.max(rel(p, q));
        }
    }
    worst
}

/// A pair whose body B is a point with zero rows (it never moves) at the origin is, to the
/// bit, the contact of A with the rigid obstacle: the relative point is A's, the relative
/// obstacle the obstacle. Its service life — B's scar grown by its own law, the gap opened by
/// both scars' approach — is the rigid obstacle's with support wear, bit for bit; only the
/// outputs name the two bodies.
#[test]
fn a_pair_with_a_fixed_body_b_is_the_rigid_obstacle_s_life_bit_for_bit() {
    let rigid = sliding_mass(&tube_wear(), "target_years = 40.0\nmax_depth_change = 0.2");
    let life = rigid.life.clone().unwrap();
    let mut case = rigid.clone();
    let p = case.model.basis.modes();
    case.model.basis.points.push(Point {
        name: "fixed".into(),
        coords: Vector3::zeros(),
        rows: vec![0.0; 3 * p],
        rotations: Vec::new(),
    });
    case.point_abscissae.push(None);
    let mut model = case.model.clone();
    pair_of(&rigid, &mut model, 0, 1);
    case.model = model;
    assert!(case.model.contacts[0].pair.is_some());

    let r0 = service_life(&rigid, &life, |_| {}).unwrap();
    let r1 = service_life(&case, &life, |_| {}).unwrap();
    assert_eq!(r0.end, LifeEnd::Completed);
    assert_eq!(r1.end, r0.end);
    assert!(r1.steps.len() > 5);
    assert_eq!(r1.steps, r0.steps);
    assert_eq!(r1.scars, r0.scars);
    assert_eq!(r1.clearances, r0.clearances);
    assert_eq!(r0.bodies, vec![None]);
    assert_eq!(
        r1.bodies,
        vec![Some(["mass".to_string(), "fixed".to_string()])]
    );
    // both scars grew: B's by its own law
    let last = &r1.steps[r1.steps.len() - 1].contacts[0];
    assert!(last.tube_depth > 0.0 && last.support_depth > 0.0);
    // the worn obstacles are the same
    let (w0, w1) = (
        worn_model(&rigid.model, &r0).unwrap(),
        worn_model(&case.model, &r1).unwrap(),
    );
    assert_eq!(w1.contacts[0].obstacle, w0.contacts[0].obstacle);
    // life.json names the bodies of a pair only
    let json = fretdyn::apps::life::life_json("t", &r1, None);
    assert!(json.contains("\"bodies\""), "{json}");
    assert!(!fretdyn::apps::life::life_json("t", &r0, None).contains("\"bodies\""));
}

/// Two moving bodies — masses A and B on springs, pressed together by ±10 N, their relative
/// obstacle a bar sliding at 1 cm/s — do the rigid case's friction work `W = μ N v`: body A
/// wears by Archard `V_A = K_A W t`, body B by the decaying law, each scar's depth is the
/// parallel tubes' lens holding its volume, and the relative obstacle opens by the approach,
/// the lens holding `V_A + V_B` (all against the hand computation); the life is the rigid
/// obstacle's within the window's rate (1e-7).
#[test]
fn two_moving_bodies_wear_both_scars_and_open_their_gap_by_the_approach() {
    let rigid = sliding_mass(&tube_wear(), "target_years = 40.0\nmax_depth_change = 0.2");
    let life = rigid.life.clone().unwrap();
    // each body: the rigid case's structure and load, without its contact; B pushed up
    let part = |sign: f64| {
        let mut m = rigid.model.clone();
        m.contacts.clear();
        m.wear.clear();
        for l in &mut m.loads {
            l.force *= sign;
        }
        m
    };
    let mut model = Model::union(vec![
        ("a".to_string(), part(1.0)),
        ("b".to_string(), part(-1.0)),
    ])
    .unwrap();
    pair_of(&rigid, &mut model, 0, 1);
    let mut case = rigid.clone();
    case.point_abscissae = vec![None; model.basis.points.len()];
    case.model = model;

    let r = service_life(&case, &life, |_| {}).unwrap();
    assert_eq!(r.end, LifeEnd::Completed);
    assert!(r.steps.len() > 5, "{} steps", r.steps.len());
    assert_eq!(
        r.bodies,
        vec![Some(["a.mass".to_string(), "b.mass".to_string()])]
    );
    // each life step's volumes grown by the two laws at its window's rate, by hand
    let (mut va, mut vb, mut t0) = (0.0, 0.0, 0.0);
    let (mut split, mut depths, mut rate) = (0.0f64, 0.0f64, 0.0f64);
    let rel = |x: f64, y: f64| (x - y).abs() / y;
    for s in &r.steps[1..] {
        let c = &s.contacts[0];
        let (da, db) = volumes(c.wear_work_rate, t0, s.time);
        (va, vb, t0) = (va + da, vb + db, s.time);
        split = split
            .max(rel(c.tube_volume, va))
            .max(rel(c.support_volume, vb));
        // each scar the lens of the two tubes holding its volume, the opening the lens
        // holding both (from 1 µm: below, the textbook `acos` of a number near 1 loses
        // ε R² / (α A) of the lens's area A, α its half-angle: 1e-6 at 0.1 µm)
        for (depth, volume) in [
            (c.tube_depth, va),
            (c.support_depth, vb),
            (c.clearance_increase, va + vb),
        ] {
            if depth > 1e-6 {
                depths = depths.max(rel(depth, tube_depth(volume)));
            }
        }
        rate = rate.max(rel(c.wear_work_rate, MU_N_V));
        // both scars grow, and the opening is less than the sum of their depths (each depth
        // assumes the other body unworn)
        assert!(c.tube_depth > 0.0 && c.support_depth > 0.0);
        assert!(c.clearance_increase < c.tube_depth + c.support_depth);
        assert!(c.clearance_increase > c.tube_depth.max(c.support_depth));
    }
    assert!(split < 1e-12, "volumes off the laws by {split:e}");
    assert!(depths < 1e-7, "depths off the lens by {depths:e}");
    // the pair's friction work is the rigid case's μ N v: measured 5.7e-6 to 7.4e-6 above it
    // over the life (the rigid obstacle's windows are within 1e-7; the same with Δt halved)
    assert!(rate < 1e-5, "W off μ N v by {rate:e}");
    // so is its life the rigid obstacle's
    let r0 = service_life(&rigid, &life, |_| {}).unwrap();
    let d = largest_difference(&r, &r0);
    assert!(d < 1e-5, "pair and rigid obstacle differ by {d:e}");
    // the worn relative obstacle: the bodies at their reference positions are apart by the
    // final approach (the clearance at rest was 0)
    let worn = worn_model(&case.model, &r).unwrap();
    let c = &worn.contacts[0];
    let x = c.point_in(&worn.basis.points).coords;
    let approach = r.steps[r.steps.len() - 1].contacts[0].clearance_increase;
    let gap = -c.frame(&x, 0.0).penetration;
    assert!((gap - approach).abs() <= 1e-15, "{gap} vs {approach}");
    assert!((gap - tube_depth(va + vb)).abs() < 1e-7 * gap);
    // scars.csv gives both bodies' depths
    let scars = fretdyn::apps::life::scars_csv(&r);
    assert!(scars.starts_with(
        "contact,kind,bin,angle_deg,clearance_increase,tube_depth,support_depth\nbar,plane,0,,"
    ));
}
