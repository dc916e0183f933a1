//! Worn obstacles (THEORY §14.4) and the map of where the friction work is done: the worn
//! geometry against the boundary it describes, computed independently (dense sampling of the
//! worn boundary), and the map's total against the window's wear work.

use std::f64::consts::TAU;
use std::path::Path;

use fretdyn::case::Case;
use fretdyn::contact::obstacle::{BiPlane, Circle, Obstacle, Plane};
use fretdyn::contact::scar::{AngularProfile, ObstacleWear};
use fretdyn::integrator::simulation::Simulation;
use nalgebra::{Vector2, Vector3};

#[test]
fn a_worn_plane_recedes_by_its_depth_and_bars_by_their_sides() {
    let plane =
        Obstacle::Plane(Plane::new(Vector3::zeros(), Vector3::z(), 1e-4, None, "p").unwrap());
    let worn = plane.worn(&ObstacleWear::Uniform(3e-5), "p").unwrap();
    for z in [-2e-4, -1.3e-4, 0.0, 5e-5] {
        let x = Vector3::new(0.1, -0.2, z);
        let d = worn.frame(&x).penetration - plane.frame(&x).penetration;
        assert!((d + 3e-5).abs() < 1e-18, "{d}");
    }
    let bars =
        Obstacle::BiPlane(BiPlane::new(Vector3::zeros(), Vector3::y(), 1e-4, None, "b").unwrap());
    let worn = bars
        .worn(
            &ObstacleWear::Sides {
                positive: 4e-5,
                negative: 1e-5,
            },
            "b",
        )
        .unwrap();
    // the surfaces are now at s = 1.4e-4 and s = −1.1e-4
    for (s, normal_y) in [(1.4e-4, -1.0), (-1.1e-4, 1.0)] {
        let f = worn.frame(&Vector3::new(0.0, s, 0.0));
        assert!(f.penetration.abs() < 1e-19, "{s}: {}", f.penetration);
        assert_eq!(f.normal.y, normal_y);
    }
    // a plane cannot take a profile, nor a hole a uniform depth
    let profile = ObstacleWear::Angular(AngularProfile::new(vec![0.0; 8]).unwrap());
    assert!(plane.worn(&profile, "contacts[0].wear").is_err());
    let hole = Obstacle::Circle(Circle::new(Vector3::zeros(), Vector3::x(), 2e-4, "h").unwrap());
    let e = hole
        .worn(&ObstacleWear::Uniform(1e-5), "contacts[1].wear")
        .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("contacts[1].wear: a circle obstacle"),
        "{e}"
    );
    assert!(AngularProfile::new(vec![1e-5, f64::NAN]).is_none());
    assert!(AngularProfile::new(vec![1e-5, -1e-9]).is_none());
}

#[test]
fn the_profile_interpolates_its_bins_periodically() {
    let depths: Vec<f64> = (0..12).map(|k| 1e-5 * (k as f64 + 1.0)).collect();
    let p = AngularProfile::new(depths.clone()).unwrap();
    let h = TAU / 12.0;
    for (k, d) in depths.iter().enumerate() {
        let (v, _) = p.at((k as f64 + 0.5) * h);
        assert!((v - d).abs() < 1e-18, "bin {k}");
    }
    // across 0 = 2π: continuous with its slope, between the neighbouring bins' depths
    let (a, slope) = p.at(0.0);
    let (b, slope_b) = p.at(TAU - 1e-15);
    assert!((a - b).abs() < 1e-17 && (slope - slope_b).abs() < 1e-12);
    assert!(a >= depths[0].min(depths[11]) && a <= depths[0].max(depths[11]));
    // the slope is the derivative of the value, and continuous at the bin centres
    for k in 0..12 {
        for th in [(k as f64 + 0.5) * h, (k as f64 + 0.8) * h] {
            let e = 1e-7;
            let numeric = (p.at(th + e).0 - p.at(th - e).0) / (2.0 * e);
            assert!((numeric - p.at(th).1).abs() < 1e-9, "{th}");
        }
    }
    // no overshoot: a bump stays within [0, its height]
    let bump =
        AngularProfile::new((0..36).map(|k| if k == 10 { 1e-5 } else { 0.0 }).collect()).unwrap();
    for j in 0..3600 {
        let v = bump.at(TAU * j as f64 / 3600.0).0;
        assert!((0.0..=1e-5).contains(&v), "{v}");
    }
    assert_eq!(AngularProfile::bin_of([1.0, 1e-9], 12), 0);
    assert_eq!(AngularProfile::bin_of([1.0, -1e-9], 12), 11);
    assert_eq!(AngularProfile::bin_of([-1.0, 0.0], 12), 6);
}

/// The worn hole's boundary `ρ = c + d(θ)` sampled densely: the signed distance from `r`
/// (positive outside) and the unit normal towards the inside at the nearest point.
fn distance_to_boundary(c: f64, p: &AngularProfile, r: Vector2<f64>) -> (f64, Vector2<f64>) {
    let n = 200_000;
    let at = |th: f64| Vector2::new(th.cos(), th.sin()) * (c + p.at(th).0);
    let mut best = (f64::INFINITY, 0.0);
    for k in 0..n {
        let th = TAU * k as f64 / n as f64;
        let d = (r - at(th)).norm();
        if d < best.0 {
            best = (d, th);
        }
    }
    // refined by a ternary search around the best sample
    let (mut lo, mut hi) = (best.1 - TAU / n as f64, best.1 + TAU / n as f64);
    for _ in 0..200 {
        let (a, b) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if (r - at(a)).norm() < (r - at(b)).norm() {
            hi = b;
        } else {
            lo = a;
        }
    }
    let nearest = at(0.5 * (lo + hi));
    let best = ((r - nearest).norm(), nearest);
    let th = r.y.atan2(r.x);
    let outside = r.norm() > c + p.at(th).0;
    let sign = if outside { 1.0 } else { -1.0 };
    (sign * best.0, (best.1 - r).normalize() * sign)
}

#[test]
fn a_worn_hole_gives_the_distance_and_normal_of_its_boundary() {
    let c = 2e-4;
    // a crescent-like scar over 60°, up to 8e-5 deep: slopes d'/ρ up to ~0.5; its bins'
    // centres are no longer corners, but the test keeps away from them
    let bins = 72;
    let depths: Vec<f64> = (0..bins)
        .map(|k| {
            let th = (k as f64 + 0.5) * TAU / bins as f64;
            let u = (th - 1.0) / 0.5;
            8e-5 * (1.0 - u * u).max(0.0)
        })
        .collect();
    let profile = AngularProfile::new(depths).unwrap();
    // the hole's axes: axis x, e1 = the least aligned global axis projected = y here
    let hole = Circle::new(Vector3::zeros(), Vector3::x(), c, "h").unwrap();
    let plain = Obstacle::Circle(hole);
    let worn = plain
        .worn(&ObstacleWear::Angular(profile.clone()), "h")
        .unwrap();
    let mut worst = (0.0f64, 0.0f64);
    // the boundary's curvature jumps at the bins' centres (a cubic on each piece): points
    // midway between them, within 5e-7 m of the boundary, have their nearest boundary point on
    // the same piece (the centres are 1.1e-5 m away along it)
    let h = TAU / bins as f64;
    for k in 5..22 {
        let th = k as f64 * h;
        for eps in [-2e-7, 1e-7, 5e-7] {
            let r_b = c + profile.at(th).0;
            let r = Vector2::new(th.cos(), th.sin()) * (r_b + eps);
            // the 3-D point with in-plane coordinates r in the hole's (e1, e2)
            let x0 = Vector3::new(0.0, 1.0, 0.0);
            let (e1, e2) = {
                let l = plain.local(&x0);
                let e1 = Vector3::new(0.0, l.x, l.y).normalize();
                (e1, Vector3::x().cross(&e1))
            };
            let _ = x0;
            let x = e1 * r.x + e2 * r.y;
            let f = worn.frame(&x);
            let (dist, n) = distance_to_boundary(c, &profile, r);
            let n3 = e1 * n.x + e2 * n.y;
            worst.0 = worst.0.max((f.penetration - dist).abs());
            worst.1 = worst.1.max((f.normal - n3).norm());
        }
    }
    // the first-order distance on a piece of spiral ρ = a + bθ: off by the curvature term
    // ~ε²/ρ ≈ 1e-9 m, and the normal by ~ε/ρ ≈ 2e-3
    assert!(worst.0 < 5e-9, "distance off by {:e}", worst.0);
    assert!(worst.1 < 5e-3, "normal off by {}", worst.1);
    // far inside, the clearance is measured to the least worn radius
    let f = worn.frame(&Vector3::new(0.0, 1e-5, 0.0));
    assert!((f.penetration - (1e-5 - c)).abs() < 1e-18);
}

#[test]
fn the_wear_map_holds_the_window_s_wear_work() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/tube_multispan.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("duration = 2.0", "duration = 0.3");
    let text = format!("{text}\n[statistics]\nt_start = 0.05\n");
    let case = Case::from_toml_str(&text, path.parent().unwrap()).unwrap();
    let mut sim = Simulation::new(&case.model, &case.settings).unwrap();
    sim.track_wear(72);
    while sim.steps_done() < case.settings.steps {
        sim.step().unwrap();
    }
    let map = sim.wear_map().unwrap().clone();
    let r = sim.finish(0.0, fretdyn::integrator::simulation::Termination::Completed);
    let window = 0.3 - 0.05;
    let mut wearing = 0;
    for (k, c) in r.contacts.iter().enumerate() {
        let work: f64 = map.work(k).iter().sum();
        assert_eq!(map.work(k).len(), 72);
        let expected = c.wear_work_rate * window;
        assert!(
            (work - expected).abs() <= 1e-9 * expected.max(1e-300),
            "{}: map {work:e} J, window {expected:e} J",
            c.name
        );
        if work > 0.0 {
            wearing += 1;
            // the tube is driven in y and z: its wear is not all in one bin
            assert!(map.work(k).iter().filter(|w| **w > 0.0).count() > 1);
        }
    }
    assert!(wearing >= 3, "{wearing} supports wear");
}

/// The multi-span tube rattling in holes worn by crescents where it strikes: the worn holes'
/// forces keep the energy balance closed as the round holes do (the first-order distance is
/// a potential to `O(δ²)`), and the worn holes are struck.
#[test]
fn worn_holes_keep_the_energy_balance() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/tube_multispan.toml");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("duration = 2.0", "duration = 0.5");
    let case = Case::from_toml_str(&text, path.parent().unwrap()).unwrap();
    let round = fretdyn::integrator::simulation::simulate(&case.model, &case.settings).unwrap();
    let mut worn = case.model.clone();
    // two crescents 40 µm deep, ±40° wide, at the ends of the forcing's stroke (31°, 211°)
    let depths = two_crescents(72);
    let profile = ObstacleWear::Angular(AngularProfile::new(depths).unwrap());
    for c in &mut worn.contacts {
        c.obstacle = c.obstacle.worn(&profile, &c.name).unwrap();
    }
    let r = fretdyn::integrator::simulation::simulate(&worn, &case.settings).unwrap();
    eprintln!(
        "energy balance: round {:e}, worn {:e}; impacts plate3 {} → {}",
        round.energy.relative_error,
        r.energy.relative_error,
        round.contacts[2].impacts,
        r.contacts[2].impacts
    );
    assert!(r.contacts[2].impacts > 0);
    assert!(
        r.energy.relative_error < 3.0 * round.energy.relative_error.max(1e-6),
        "worn {:e} vs round {:e}",
        r.energy.relative_error,
        round.energy.relative_error
    );
}

/// The penetration of a worn hole is a signed distance: 1-Lipschitz, and the normal is minus
/// its gradient (so that the normal force derives from `½ K_N δ²`).
#[test]
fn a_worn_hole_s_penetration_is_a_signed_distance() {
    let c = 2e-4;
    let depths = two_crescents(72);
    let hole = Obstacle::Circle(Circle::new(Vector3::zeros(), Vector3::x(), c, "h").unwrap());
    let worn = hole
        .worn(
            &ObstacleWear::Angular(AngularProfile::new(depths).unwrap()),
            "h",
        )
        .unwrap();
    let mut worst_lip = 0.0f64;
    let mut worst_grad = 0.0f64;
    let mut state = 12345u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..20000 {
        let th = TAU * next();
        // beyond the least worn radius (inside it, the clearance is measured to that radius)
        let rho = c + 1e-9 + 6e-5 * next();
        let x = Vector3::new(0.0, rho * th.cos(), rho * th.sin());
        let h = 1e-8;
        let dir = TAU * next();
        let dx = Vector3::new(0.0, h * dir.cos(), h * dir.sin());
        let (fa, fb) = (worn.frame(&x), worn.frame(&(x + dx)));
        if (x + dx).norm() <= c || (x - dx).norm() <= c {
            continue;
        }
        worst_lip = worst_lip.max((fa.penetration - fb.penetration).abs() / h);
        if fa.penetration > -5e-6 {
            // central difference of δ along dx against −n·dx
            let g = (fb.penetration - worn.frame(&(x - dx)).penetration) / (2.0 * h);
            worst_grad = worst_grad.max((g + fa.normal.dot(&dx) / h).abs());
        }
    }
    eprintln!("Lipschitz {worst_lip}, gradient {worst_grad}");
    assert!(worst_lip < 1.0 + 1e-4, "{worst_lip}");
    assert!(worst_grad < 1e-4, "{worst_grad}");
}

/// 72 bins of two crescent-like scars 40 µm deep and ±40° wide at the ends of the multi-span
/// tube's stroke (31°, 211°).
fn two_crescents(bins: usize) -> Vec<f64> {
    (0..bins)
        .map(|k| {
            let th = (k as f64 + 0.5) * TAU / bins as f64;
            [31f64.to_radians(), 211f64.to_radians()]
                .iter()
                .map(|m| {
                    let u = ((th - m + 0.5 * TAU).rem_euclid(TAU) - 0.5 * TAU) / 40f64.to_radians();
                    4e-5 * (1.0 - u * u).max(0.0)
                })
                .fold(0.0, f64::max)
        })
        .collect()
}
