//! Wear laws and scar geometries (docs/WEAR.md, THEORY §14): each law against its closed form
//! and its rate integrated by quadrature; each scar's volume against an independent
//! computation (the scar's section or chord integrated by tanh–sinh quadrature, from the
//! geometry written out here, not from the library's formulas), the volume → depth → volume
//! round trip, the tilted bar's transition, bad input refused; the `wear` table of a case file.

use std::f64::consts::PI;
use std::path::Path;

use fretdyn::Case;
use fretdyn::wear::{HoleScar, Scar, WearLaw};

// ---------------------------------------------------------------- independent quadrature

/// `∫_a^b f` by the tanh–sinh (double exponential) rule, step halved until two levels agree
/// to `1e-15` relative: exact to rounding for integrands with algebraic singularities at the
/// ends. `f(x, x − a, b − x)` gets the distances to both ends without cancellation.
fn tanh_sinh(f: &dyn Fn(f64, f64, f64) -> f64, a: f64, b: f64) -> f64 {
    let half = 0.5 * (b - a);
    let node = |t: f64| -> f64 {
        let u = 0.5 * PI * t.sinh();
        // distance from the nearer end: (b − a) / (1 + e^{2|u|})
        let off = (b - a) / (1.0 + (2.0 * u.abs()).exp());
        let (x, from_a, to_b) = if t >= 0.0 {
            (b - off, (b - a) - off, off)
        } else {
            (a + off, off, (b - a) - off)
        };
        if off <= 0.0 {
            return 0.0;
        }
        let w = half * 0.5 * PI * t.cosh() / (u.cosh() * u.cosh());
        w * f(x, from_a, to_b)
    };
    let tmax = 6.5;
    let mut h = 0.5;
    let mut sum = node(0.0);
    let mut k = 1;
    while k as f64 * h <= tmax {
        sum += node(k as f64 * h) + node(-(k as f64) * h);
        k += 1;
    }
    let mut estimate = h * sum;
    for _ in 0..12 {
        h *= 0.5;
        let mut k = 1;
        while k as f64 * h <= tmax {
            sum += node(k as f64 * h) + node(-(k as f64) * h);
            k += 2;
        }
        let next = h * sum;
        if (next - estimate).abs() <= 1e-15 * next.abs() {
            return next;
        }
        estimate = next;
    }
    estimate
}

/// Area of a circular segment of height `h` in a circle of radius `r`, as the integral of
/// its chord `2 √(u (2r − u))` over the height `u` from the circle's bottom.
fn segment_ref(r: f64, h: f64) -> f64 {
    if h <= 0.0 {
        return 0.0;
    }
    tanh_sinh(&|u, from0, _| 2.0 * (from0 * (2.0 * r - u)).sqrt(), 0.0, h)
}

fn close(got: f64, want: f64, tol: f64) -> bool {
    (got - want).abs() <= tol * want.abs().max(f64::MIN_POSITIVE)
}

fn log_depths(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| lo * (hi / lo).powf(k as f64 / (n - 1) as f64))
        .collect()
}

// ---------------------------------------------------------------- wear laws

#[test]
fn archard_volume_is_k_w_t() {
    let law = WearLaw::Archard {
        coefficient: 20e-15,
    };
    law.validate("law").unwrap();
    let (w, t) = (0.013, 3.15e8);
    assert!(close(law.volume(w, t), 20e-15 * w * t, 1e-15));
    assert!(close(law.volume_rate(w, 7.0), 20e-15 * w, 1e-15));
    assert!(close(
        law.volume_increment(w, 1e7, 3e7),
        20e-15 * w * 2e7,
        1e-15
    ));
}

fn decaying() -> WearLaw {
    WearLaw::Decaying {
        a: 3e-14,
        b: 1.3,
        s: 0.2,
        n: 2e-8,
    }
}

#[test]
fn decaying_law_integrates_its_rate() {
    let law = decaying();
    law.validate("law").unwrap();
    let w: f64 = 0.04;
    let v0 = 3e-14 * w.powf(1.3);
    for t in [1e3_f64, 1e7, 5e7, 1.26e9] {
        // the closed form of the issue: V(t) = V̇0 [s t + (1 − s)/N (1 − e^{−N t})]
        let closed = v0 * (0.2 * t + 0.8 / 2e-8 * (1.0 - (-2e-8 * t).exp()));
        assert!(close(law.volume(w, t), closed, 1e-12), "t {t}");
        assert!(close(
            law.volume_increment(w, 0.0, t),
            law.volume(w, t),
            1e-15
        ));
        // the rate integrated by quadrature
        let integral = tanh_sinh(&|x, _, _| law.volume_rate(w, x), 0.0, t);
        assert!(
            close(integral, law.volume(w, t), 1e-12),
            "t {t}: {integral} vs {}",
            law.volume(w, t)
        );
        // increments over life steps add up to the volume
        let steps = 37;
        let sum: f64 = (0..steps)
            .map(|k| {
                let (t0, t1) = (
                    t * k as f64 / steps as f64,
                    t * (k + 1) as f64 / steps as f64,
                );
                law.volume_increment(w, t0, t1)
            })
            .sum();
        assert!(close(sum, law.volume(w, t), 1e-13));
    }
    // the rate at the start is A W^B, at the end s A W^B
    assert!(close(law.volume_rate(w, 0.0), v0, 1e-15));
    assert!(close(law.volume_rate(w, 1e12), 0.2 * v0, 1e-12));
    // no decay is a power law, B = 1 and s = 1 is Archard
    let archard = WearLaw::Decaying {
        a: 2e-14,
        b: 1.0,
        s: 1.0,
        n: 5e-8,
    };
    assert!(close(archard.volume(w, 1e8), 2e-14 * w * 1e8, 1e-14));
    let tiny_n = WearLaw::Decaying {
        a: 2e-14,
        b: 1.0,
        s: 0.0,
        n: 1e-30,
    };
    assert!(close(tiny_n.volume(w, 1e8), 2e-14 * w * 1e8, 1e-14));
}

#[test]
fn table_law_interpolates_linearly() {
    let law = WearLaw::Table {
        work_rate: vec![0.001, 0.01, 0.1],
        volume_rate: vec![1e-17, 3e-16, 2e-15],
    };
    law.validate("law").unwrap();
    for (w, v) in [(0.001, 1e-17), (0.01, 3e-16), (0.1, 2e-15)] {
        assert!(close(law.volume_rate(w, 0.0), v, 1e-15));
    }
    let mid = law.volume_rate(0.055, 0.0);
    assert!(close(mid, 0.5 * (3e-16 + 2e-15), 1e-14), "{mid}");
    assert!(close(law.volume_rate(0.0005, 0.0), 0.5e-17, 1e-14));
    assert!(close(law.volume_rate(0.2, 0.0), 4e-15, 1e-14));
    assert_eq!(law.volume_rate(0.0, 0.0), 0.0);
    assert!(close(law.volume(0.01, 1e8), 3e-16 * 1e8, 1e-15));
}

#[test]
fn bad_laws_are_refused_naming_the_key() {
    let cases: Vec<(WearLaw, &str)> = vec![
        (
            WearLaw::Archard {
                coefficient: -1e-15,
            },
            "w.coefficient",
        ),
        (
            WearLaw::Archard {
                coefficient: f64::NAN,
            },
            "w.coefficient",
        ),
        (
            WearLaw::Decaying {
                a: 1.0,
                b: 1.0,
                s: 1.5,
                n: 1.0,
            },
            "w.s",
        ),
        (
            WearLaw::Decaying {
                a: 1.0,
                b: 1.0,
                s: 0.5,
                n: -1.0,
            },
            "w.n",
        ),
        (
            WearLaw::Decaying {
                a: -1.0,
                b: 1.0,
                s: 0.5,
                n: 1.0,
            },
            "w.a",
        ),
        (
            WearLaw::Table {
                work_rate: vec![0.1, 0.05],
                volume_rate: vec![1.0, 2.0],
            },
            "w.work_rate[1]",
        ),
        (
            WearLaw::Table {
                work_rate: vec![0.1, 0.2],
                volume_rate: vec![1.0],
            },
            "w.volume_rate",
        ),
        (
            WearLaw::Table {
                work_rate: vec![0.1, 0.2],
                volume_rate: vec![1.0, -2.0],
            },
            "w.volume_rate[1]",
        ),
        (
            WearLaw::Table {
                work_rate: vec![],
                volume_rate: vec![],
            },
            "w.volume_rate",
        ),
        (
            WearLaw::Table {
                work_rate: vec![0.0],
                volume_rate: vec![1.0],
            },
            "w.work_rate",
        ),
    ];
    for (law, field) in cases {
        let e = law.validate("w").unwrap_err();
        assert_eq!(e.field(), Some(field), "{law:?}: {e}");
    }
}

// ---------------------------------------------------------------- scars

const R: f64 = 0.0095; // a 19 mm steam generator tube

/// A function of the depth or of the volume.
type Curve<'a> = Box<dyn Fn(f64) -> f64 + 'a>;

/// The geometries tested, with an independent reference `V(d)` for the tube and the support.
fn geometries() -> Vec<(Scar, Curve<'static>, Curve<'static>)> {
    let mut out: Vec<(Scar, Curve<'static>, Curve<'static>)> = Vec::new();
    // aligned flat bar: the segment over the width, for both
    let w = 0.0254;
    out.push((
        Scar::FlatBar {
            tube_radius: R,
            width: w,
            tilt: 0.0,
        },
        Box::new(move |d| w * segment_ref(R, d)),
        Box::new(move |d| w * segment_ref(R, d)),
    ));
    // tilted bars: the overlap of the cylinder (axis direction (cos θ, 0, sin θ)) and the bar
    // z < 0, 0 ≤ x ≤ w. A point (x, y, z) is at the squared distance y² + (x sin θ − ζ cos θ)²
    // from the axis, ζ = z − z_axis(0); with the bar's depth D (normal to its face) at x = 0,
    // z_axis(0) = R / cos θ − D. Across the bar at x the section {z < 0} in the tube is the
    // set of q = ζ cos θ − x sin θ ∈ [−R, D cos θ − R − x sin θ], chord 2√(R² − q²), dz = dq / cos θ.
    for tilt_deg in [0.5_f64, 5.0, 30.0] {
        let t = tilt_deg.to_radians();
        let (s, c) = t.sin_cos();
        let bar = move |depth_normal: f64| {
            let section = |x: f64| segment_ref(R, depth_normal * c - x * s) / c;
            // the section vanishes beyond x = D cos θ / sin θ (the wedge's tip)
            let end = w.min(depth_normal * c / s);
            tanh_sinh(&|x, _, _| section(x), 0.0, end)
        };
        out.push((
            Scar::FlatBar {
                tube_radius: R,
                width: w,
                tilt: t,
            },
            // the tube's depth is its radial wall loss: D cos θ
            Box::new(move |rho| bar(rho / c)),
            Box::new(bar),
        ));
    }
    // drilled hole, crescent: d/dd of the area outside the hole is the common chord 2y
    // (the tube moves by dd along the line of centres): L(d) = ∫₀ᵈ 2 y(s) ds, y from Heron's
    // formula for the triangle (hole centre, tube centre, corner): sides R + c, R, c + s.
    for c in [0.0, 1e-6, 2e-4, 1e-3, 0.02] {
        let e = 0.03;
        let crescent = move |d: f64| {
            let chord = |s: f64, s_from0: f64| {
                let big_d = c + s;
                let p = s_from0 * (2.0 * R - s) * (2.0 * c + s) * (2.0 * R + 2.0 * c + s);
                p.sqrt() / big_d
            };
            e * tanh_sinh(&|s, from0, _| chord(s, from0), 0.0, d)
        };
        out.push((
            Scar::DrilledHole {
                tube_radius: R,
                thickness: e,
                clearance: c,
                shape: HoleScar::Crescent,
            },
            Box::new(crescent),
            Box::new(crescent),
        ));
    }
    // drilled hole, uniform: rings
    let (e, c) = (0.03, 2e-4);
    out.push((
        Scar::DrilledHole {
            tube_radius: R,
            thickness: e,
            clearance: c,
            shape: HoleScar::Uniform,
        },
        // ∫ 2π r dr over the ring, r = R − u (tube) or R + c + u (plate)
        Box::new(move |d| e * tanh_sinh(&|u, _, _| 2.0 * PI * (R - u), 0.0, d)),
        Box::new(move |d| e * tanh_sinh(&|u, _, _| 2.0 * PI * (R + c + u), 0.0, d)),
    ));
    // broached holes: n lands, each a flat bar of the plate's thickness
    for (lobes, land_width) in [(4, None), (3, Some(0.008))] {
        out.push((
            Scar::BroachedHole {
                tube_radius: R,
                thickness: e,
                lobes,
                land_width,
            },
            Box::new(move |d| f64::from(lobes) * e * segment_ref(R, d)),
            Box::new(move |d| f64::from(lobes) * e * segment_ref(R, d)),
        ));
    }
    // crossing tubes: V = (4 / sin φ) ∫ w1 w2 over the overlap's height, w1, w2 the
    // half-widths of the two cylinders' sections at that height
    for (r2, phi_deg) in [(R, 90.0_f64), (0.006, 30.0), (0.02, 3.0)] {
        let phi = phi_deg.to_radians();
        let crossing = move |d: f64| {
            4.0 / phi.sin()
                * tanh_sinh(
                    &|u, from0, to_d| (from0 * (2.0 * R - u) * to_d * (2.0 * r2 - d + u)).sqrt(),
                    0.0,
                    d,
                )
        };
        out.push((
            Scar::Tube {
                tube_radius: R,
                other_radius: r2,
                crossing: phi,
                length: None,
            },
            Box::new(crossing),
            Box::new(crossing),
        ));
    }
    // parallel tubes: the two discs' intersection, ∫ of its chord 2y over the approach
    for r2 in [R, 0.004] {
        let l = 0.05;
        let parallel = move |d: f64| {
            l * tanh_sinh(
                &|s, from0, _| {
                    let big_d = R + r2 - s;
                    (from0 * (2.0 * R - s) * (2.0 * r2 - s) * (2.0 * R + 2.0 * r2 - s)).sqrt()
                        / big_d
                },
                0.0,
                d,
            )
        };
        out.push((
            Scar::Tube {
                tube_radius: R,
                other_radius: r2,
                crossing: 0.0,
                length: Some(l),
            },
            Box::new(parallel),
            Box::new(parallel),
        ));
    }
    out
}

#[test]
fn scar_volumes_match_an_independent_integral() {
    for (scar, tube_ref, support_ref) in geometries() {
        scar.validate("scar").unwrap();
        for (body, limit, reference) in [
            ("tube", scar.tube_depth_limit(), &tube_ref),
            ("support", scar.support_depth_limit(), &support_ref),
        ] {
            let top = if limit.is_finite() { limit } else { 2.0 * R };
            for d in log_depths(1e-9, top, 25) {
                let got = match body {
                    "tube" => scar.tube_volume(d).unwrap(),
                    _ => scar.support_volume(d).unwrap(),
                };
                let want = reference(d);
                assert!(
                    close(got, want, 1e-12),
                    "{scar:?} {body} d = {d:e}: {got:e} vs {want:e} ({:e})",
                    (got - want) / want
                );
            }
        }
    }
}

#[test]
fn scars_round_trip_volume_depth_volume() {
    for (scar, _, _) in geometries() {
        for body in ["tube", "support"] {
            let (limit, volume, depth): (f64, Curve, Curve) = match body {
                "tube" => (
                    scar.tube_depth_limit(),
                    Box::new(|d| scar.tube_volume(d).unwrap()),
                    Box::new(|v| scar.tube_depth(v).unwrap()),
                ),
                _ => (
                    scar.support_depth_limit(),
                    Box::new(|d| scar.support_volume(d).unwrap()),
                    Box::new(|v| scar.support_depth(v).unwrap()),
                ),
            };
            let top = if limit.is_finite() { limit } else { 2.0 * R };
            let mut depths = log_depths(1e-9, top, 60);
            depths.push(top);
            for d in depths {
                let v = volume(d);
                let d2 = depth(v);
                let v2 = volume(d2);
                assert!(
                    close(v2, v, 1e-12),
                    "{scar:?} {body} d = {d:e}: V {v:e} → d {d2:e} → V {v2:e}"
                );
                // the depth itself where V(d) is well conditioned (not at a flat end)
                if d < 0.5 * top {
                    assert!(close(d2, d, 1e-11), "{scar:?} {body}: d {d:e} → {d2:e}");
                }
            }
        }
    }
}

#[test]
fn small_scars_follow_code_aster_power_laws() {
    // POST_USURE (bibfor/prepost/usupru.F90): aligned bar d = (1/2R)^{1/3} (3V/4L)^{2/3},
    // i.e. V = (4/3) L √(2R) d^{3/2}; tilted bar V = 8 √(2R) d^{5/2} / (15 θ); the parabolic
    // approximation of the circle, exact as d → 0.
    let d: f64 = 1e-9;
    let w = 0.0254;
    let aligned = Scar::FlatBar {
        tube_radius: R,
        width: w,
        tilt: 0.0,
    };
    let want = 4.0 / 3.0 * w * (2.0 * R).sqrt() * d.powf(1.5);
    assert!(close(aligned.tube_volume(d).unwrap(), want, 1e-6));
    let t = 2f64.to_radians();
    let tilted = Scar::FlatBar {
        tube_radius: R,
        width: w,
        tilt: t,
    };
    let want = 8.0 * (2.0 * R).sqrt() * d.powf(2.5) / (15.0 * t.sin() * t.cos());
    assert!(close(tilted.tube_volume(d).unwrap(), want, 1e-6));
    // crossing tubes: V ≈ π √(R R₂) d² / sin φ
    let phi = 40f64.to_radians();
    let tubes = Scar::Tube {
        tube_radius: R,
        other_radius: 0.006,
        crossing: phi,
        length: None,
    };
    let want = PI * (R * 0.006).sqrt() * d * d / phi.sin();
    assert!(close(tubes.tube_volume(d).unwrap(), want, 1e-6));
}

#[test]
fn exact_circle_cases() {
    // equal circles (no clearance): outside area = π R² − (2R² acos(d/2R) − (d/2)√(4R² − d²))
    let e = 0.02;
    let hole = Scar::DrilledHole {
        tube_radius: R,
        thickness: e,
        clearance: 0.0,
        shape: HoleScar::Crescent,
    };
    for d in [1e-4, 3e-3, R, 1.7 * R] {
        let lens = 2.0 * R * R * (d / (2.0 * R)).acos() - 0.5 * d * (4.0 * R * R - d * d).sqrt();
        let want = e * (PI * R * R - lens);
        assert!(close(hole.tube_volume(d).unwrap(), want, 1e-12), "d {d}");
    }
    // the whole tube outside the hole at d = 2R
    let hole = Scar::DrilledHole {
        tube_radius: R,
        thickness: e,
        clearance: 3e-4,
        shape: HoleScar::Crescent,
    };
    assert!(close(
        hole.tube_volume(2.0 * R).unwrap(),
        e * PI * R * R,
        1e-14
    ));
    // a flat cut through the axis is half the tube
    let bar = Scar::FlatBar {
        tube_radius: R,
        width: e,
        tilt: 0.0,
    };
    assert!(close(
        bar.tube_volume(R).unwrap(),
        0.5 * e * PI * R * R,
        1e-14
    ));
    // parallel equal tubes at d = R: 2R² acos(1/2 · 3/2 …) with centres 2R − d apart
    let tubes = Scar::Tube {
        tube_radius: R,
        other_radius: R,
        crossing: 0.0,
        length: Some(e),
    };
    let dc: f64 = R; // centre distance 2R − R = R
    let lens = 2.0 * R * R * (dc / (2.0 * R)).acos() - 0.5 * dc * (4.0 * R * R - dc * dc).sqrt();
    assert!(close(tubes.tube_volume(R).unwrap(), e * lens, 1e-13));
}

#[test]
fn tilted_bar_transition_is_continuous() {
    let w = 0.0254;
    for tilt_deg in [0.2_f64, 3.0, 20.0] {
        let t = tilt_deg.to_radians();
        let scar = Scar::FlatBar {
            tube_radius: R,
            width: w,
            tilt: t,
        };
        for (name, at, volume) in [
            (
                "tube",
                w * t.sin(),
                Box::new(|d: f64| scar.tube_volume(d).unwrap()) as Curve,
            ),
            (
                "support",
                w * t.tan(),
                Box::new(|d: f64| scar.support_volume(d).unwrap()),
            ),
        ] {
            // volume continuous: the jump over ±ε is the slope × 2ε
            let eps = 1e-9 * at;
            let (below, on, above) = (volume(at - eps), volume(at), volume(at + eps));
            assert!(
                below < on && on < above,
                "{name} {tilt_deg}° not increasing"
            );
            // slopes on both sides agree (dV/dd is continuous: the wedge's tip reaches the edge)
            let h = 1e-5 * at;
            let left = (volume(at) - volume(at - h)) / h;
            let right = (volume(at + h) - volume(at)) / h;
            assert!(left.is_finite() && right.is_finite() && left > 0.0);
            assert!(
                close(right, left, 1e-4),
                "{name} {tilt_deg}°: slopes {left:e} {right:e}"
            );
            // depth continuous through the transition
            let d = if name == "tube" {
                scar.tube_depth(on).unwrap()
            } else {
                scar.support_depth(on).unwrap()
            };
            assert!(close(d, at, 1e-12), "{name} {tilt_deg}°: {d:e} vs {at:e}");
        }
    }
}

#[test]
fn bad_scars_and_volumes_give_errors_not_panics() {
    let bar = Scar::FlatBar {
        tube_radius: R,
        width: 0.0254,
        tilt: 0.0,
    };
    for v in [-1e-12, f64::NAN, f64::INFINITY] {
        assert!(bar.tube_depth(v).is_err());
        assert!(bar.support_depth(v).is_err());
    }
    for d in [-1e-6, f64::NAN, 2.0 * R * 1.001] {
        assert!(bar.tube_volume(d).is_err());
    }
    assert_eq!(bar.tube_depth(0.0).unwrap(), 0.0);
    // worn through: a clear message
    let full = bar.tube_volume(2.0 * R).unwrap();
    let e = bar.tube_depth(full * 1.01).unwrap_err().to_string();
    assert!(e.contains("worn through"), "{e}");
    let e = bar
        .support_depth(bar.support_volume(R).unwrap() * 1.01)
        .unwrap_err()
        .to_string();
    assert!(e.contains("more than the support scar"), "{e}");
    let land = Scar::BroachedHole {
        tube_radius: R,
        thickness: 0.03,
        lobes: 4,
        land_width: Some(0.004),
    };
    let limit = land.tube_depth_limit();
    assert!(close(
        2.0 * (limit * (2.0 * R - limit)).sqrt(),
        0.004,
        1e-12
    ));
    let e = land
        .tube_depth(land.tube_volume(limit).unwrap() * 1.1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("land_width"), "{e}");
    // the uniform ring's closed-form inverse refuses a tube worn away
    let ring = Scar::DrilledHole {
        tube_radius: R,
        thickness: 0.03,
        clearance: 1e-4,
        shape: HoleScar::Uniform,
    };
    assert!(ring.tube_depth(0.03 * PI * R * R * 1.001).is_err());
    // invalid geometries name the key
    let invalid = [
        (
            Scar::FlatBar {
                tube_radius: R,
                width: 0.0,
                tilt: 0.0,
            },
            "s.width",
        ),
        (
            Scar::FlatBar {
                tube_radius: -R,
                width: 0.01,
                tilt: 0.0,
            },
            "s.tube_radius",
        ),
        (
            Scar::FlatBar {
                tube_radius: R,
                width: 0.01,
                tilt: 90f64.to_radians(),
            },
            "s.tilt_deg",
        ),
        (
            Scar::DrilledHole {
                tube_radius: R,
                thickness: 0.01,
                clearance: -1e-4,
                shape: HoleScar::Crescent,
            },
            "s.clearance",
        ),
        (
            Scar::BroachedHole {
                tube_radius: R,
                thickness: 0.01,
                lobes: 0,
                land_width: None,
            },
            "s.lobes",
        ),
        (
            Scar::Tube {
                tube_radius: R,
                other_radius: R,
                crossing: 0.0,
                length: None,
            },
            "s.length",
        ),
        (
            Scar::Tube {
                tube_radius: R,
                other_radius: R,
                crossing: 2.0,
                length: None,
            },
            "s.crossing_deg",
        ),
    ];
    for (scar, field) in invalid {
        let e = scar.validate("s").unwrap_err();
        assert_eq!(e.field(), Some(field), "{scar:?}: {e}");
        assert!(scar.tube_volume(1e-6).is_err() && scar.tube_depth(1e-12).is_err());
    }
}

// ---------------------------------------------------------------- case file

fn case_with(obstacle: &str, radius: &str, wear: &str) -> String {
    const POINT_MASS: &str = include_str!("fixtures/point_mass.toml");
    format!(
        r#"
[time]
dt = 1e-6
duration = 2e-3

{POINT_MASS}
[initial]
point = "mass"
velocity = [0.5, 0.0, -0.5]

[[contacts]]
point = "mass"
obstacle = {obstacle}
{radius}
normal = {{ stiffness = 1e6 }}
friction = {{ mu = 0.3 }}
wear = {wear}
"#
    )
}

const PLANE: &str = r#"{ type = "plane", normal = [0.0, 0.0, 1.0], tangent = [1.0, 0.0, 0.0] }"#;
const CIRCLE: &str =
    r#"{ type = "circle", centre = [0.0, 0.0, 0.0], axis = [0.0, 1.0, 0.0], clearance = 2e-4 }"#;
const BAR_WEAR: &str = r#"{ tube = { law = "archard", coefficient = 20e-15 }, support = { law = "archard", coefficient = 10e-15 }, scar = { type = "flat_bar", width = 0.0254, tilt_deg = 0.0, tube_radius = 0.0095 } }"#;

fn parse(text: &str) -> fretdyn::Result<Case> {
    Case::from_toml_str(text, Path::new("."))
}

#[test]
fn case_file_wear_table_is_read() {
    let case = parse(&case_with(PLANE, "", BAR_WEAR)).unwrap();
    let wear = case.model.contact_wear(0).expect("the contact has wear");
    assert_eq!(
        wear.tube,
        WearLaw::Archard {
            coefficient: 20e-15
        }
    );
    assert_eq!(
        wear.scar,
        Scar::FlatBar {
            tube_radius: 0.0095,
            width: 0.0254,
            tilt: 0.0
        }
    );
    // the same as a sub-table of the contact (docs/WEAR.md)
    let sub = case_with(PLANE, "", BAR_WEAR).replace(&format!("wear = {BAR_WEAR}"), "")
        + "[contacts.wear]\ntube = { law = \"archard\", coefficient = 20e-15 }\nsupport = { law = \"archard\", coefficient = 10e-15 }\nscar = { type = \"flat_bar\", width = 0.0254, tilt_deg = 0.0, tube_radius = 0.0095 }\n";
    assert_eq!(parse(&sub).unwrap().model.wear, case.model.wear);
    // a drilled hole takes the circle's clearance; the radius from the scar table
    let hole = r#"{ tube = { law = "decaying", a = 1e-14, b = 1.2, s = 0.3, n = 1e-8 }, support = { law = "table", work_rate = [0.0, 0.1], volume_rate = [0.0, 1e-15] }, scar = { type = "drilled_hole", thickness = 0.03, shape = "crescent", tube_radius = 0.0095 } }"#;
    let case = parse(&case_with(CIRCLE, "", hole)).unwrap();
    assert_eq!(
        case.model.contact_wear(0).unwrap().scar,
        Scar::DrilledHole {
            tube_radius: 0.0095,
            thickness: 0.03,
            clearance: 2e-4,
            shape: HoleScar::Crescent
        }
    );
    // without wear: none
    let case = parse(&case_with(PLANE, "", r#"{ tube = { law = "archard", coefficient = 1e-15 }, support = { law = "archard", coefficient = 1e-15 }, scar = { type = "tube", other_radius = 0.0095, crossing_deg = 90.0, tube_radius = 0.0095 } }"#)).unwrap();
    assert!(case.model.contact_wear(0).is_some());
}

#[test]
fn case_file_wear_errors_name_the_field() {
    let drilled = r#"{ tube = { law = "archard", coefficient = 20e-15 }, support = { law = "archard", coefficient = 10e-15 }, scar = { type = "drilled_hole", thickness = 0.03, shape = "uniform" } }"#;
    let e = parse(&case_with(PLANE, "", drilled)).unwrap_err();
    assert_eq!(e.field(), Some("contacts[0].wear.scar.type"), "{e}");
    assert!(e.to_string().contains("circle"), "{e}");
    let e = parse(&case_with(CIRCLE, "", BAR_WEAR)).unwrap_err();
    assert_eq!(e.field(), Some("contacts[0].wear.scar.type"), "{e}");
    // no tube radius anywhere
    let e = parse(&case_with(
        PLANE,
        "",
        &BAR_WEAR.replace(", tube_radius = 0.0095", ""),
    ))
    .unwrap_err();
    assert_eq!(e.field(), Some("contacts[0].wear.scar.tube_radius"), "{e}");
    // a bad coefficient, a bad width
    let e = parse(&case_with(PLANE, "", &BAR_WEAR.replace("20e-15", "-1.0"))).unwrap_err();
    assert_eq!(e.field(), Some("contacts[0].wear.tube.coefficient"), "{e}");
    let e = parse(&case_with(
        PLANE,
        "",
        &BAR_WEAR.replace("width = 0.0254", "width = 0.0"),
    ))
    .unwrap_err();
    assert_eq!(e.field(), Some("contacts[0].wear.scar.width"), "{e}");
    // an unknown law or key is a parse error
    assert!(matches!(
        parse(&case_with(
            PLANE,
            "",
            &BAR_WEAR.replace("\"archard\"", "\"linear\"")
        )),
        Err(fretdyn::Error::Parse { .. })
    ));
}

#[test]
fn summary_gives_the_volume_rates_at_the_run_wear_work_rate() {
    let case = parse(&case_with(PLANE, "", BAR_WEAR)).unwrap();
    let results = fretdyn::simulate(&case.model, &case.settings).unwrap();
    let w = results.contacts[0].wear_work_rate;
    assert!(w > 0.0, "the mass slides on the plane");
    let summary = fretdyn::output::summary::summary(&case, &results);
    let c = &summary["contacts"][0];
    assert_eq!(c["tube_volume_rate"].as_f64().unwrap(), 20e-15 * w);
    assert_eq!(c["support_volume_rate"].as_f64().unwrap(), 10e-15 * w);
    assert_eq!(c["wear_work_rate"].as_f64().unwrap(), w);
    // no wear table: no such keys
    let plain =
        parse(&case_with(PLANE, "", BAR_WEAR).replace(&format!("wear = {BAR_WEAR}"), "")).unwrap();
    let results = fretdyn::simulate(&plain.model, &plain.settings).unwrap();
    let summary = fretdyn::output::summary::summary(&plain, &results);
    assert!(summary["contacts"][0].get("tube_volume_rate").is_none());
}

#[test]
fn the_tube_radius_comes_from_the_contact() {
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(base.join("tube_multispan.toml")).unwrap();
    let with = |scar: &str| {
        text.replacen(
            "friction = { mu = 0.3 }\n",
            &format!(
                "friction = {{ mu = 0.3 }}\nwear = {{ tube = {{ law = \"archard\", coefficient = 20e-15 }}, support = {{ law = \"archard\", coefficient = 10e-15 }}, scar = {scar} }}\n"
            ),
            1,
        )
    };
    let case = Case::from_toml_str(
        &with(r#"{ type = "drilled_hole", thickness = 0.03, shape = "uniform" }"#),
        &base,
    )
    .unwrap();
    assert_eq!(
        case.model.contact_wear(0).unwrap().scar,
        Scar::DrilledHole {
            tube_radius: 9.525e-3,
            thickness: 0.03,
            clearance: 2e-4,
            shape: HoleScar::Uniform
        }
    );
    assert!(case.model.contact_wear(1).is_none());
    assert_eq!(case.model.wear.len(), case.model.contacts.len());
    let e = Case::from_toml_str(
        &with(
            r#"{ type = "drilled_hole", thickness = 0.03, shape = "uniform", tube_radius = 0.01 }"#,
        ),
        &base,
    )
    .unwrap_err();
    assert_eq!(e.field(), Some("contacts[0].wear.scar.tube_radius"), "{e}");
}

#[test]
fn approach_is_the_depth_of_the_overlap_holding_both_volumes() {
    let (vt, vs) = (3e-9, 1.5e-9);
    let w = 0.0254;
    for tilt_deg in [0.0_f64, 4.0] {
        let t = tilt_deg.to_radians();
        let bar = Scar::FlatBar {
            tube_radius: R,
            width: w,
            tilt: t,
        };
        let d = bar.approach(vt, vs).unwrap();
        // the overlap at the approach d (normal to the bar) holds both volumes: the bar's
        // groove function is that overlap
        assert!(close(bar.support_volume(d).unwrap(), vt + vs, 1e-12));
        if tilt_deg == 0.0 {
            assert!(close(w * segment_ref(R, d), vt + vs, 1e-12));
        }
        // less than the sum of the scars' own depths (the segment's area is convex in d),
        // more than either
        let (dt, ds) = (bar.tube_depth(vt).unwrap(), bar.support_depth(vs).unwrap());
        assert!(d < dt / t.cos() + ds && d > ds && d > dt, "{d} {dt} {ds}");
    }
    let ring = Scar::DrilledHole {
        tube_radius: R,
        thickness: 0.03,
        clearance: 2e-4,
        shape: HoleScar::Uniform,
    };
    let d = ring.approach(vt, vs).unwrap();
    assert_eq!(
        d,
        ring.tube_depth(vt).unwrap() + ring.support_depth(vs).unwrap()
    );
    let hole = Scar::DrilledHole {
        tube_radius: R,
        thickness: 0.03,
        clearance: 2e-4,
        shape: HoleScar::Crescent,
    };
    let d = hole.approach(vt, vs).unwrap();
    assert!(close(hole.tube_volume(d).unwrap(), vt + vs, 1e-12));
    assert!(hole.approach(-1.0, vs).is_err());
}
