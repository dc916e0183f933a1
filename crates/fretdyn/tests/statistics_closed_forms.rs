//! The statistics of THEORY §5 against closed-form and event-driven solutions: the wear work
//! rate of a mass on a plane that vibrates tangentially (slip–slip, stick–slip and permanent
//! stick), and the impact of an undamped mass–spring on a stiff stop (time, peak force,
//! impulse, duration, impact and rebound speeds).

use std::f64::consts::TAU;

use fretdyn::accumulate::statistics::StatisticsSettings;
use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::motion::Motion;
use fretdyn::contact::obstacle::{Obstacle, Plane};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{RunResults, RunSettings, simulate};
use fretdyn::loads::{PointLoad, TimeHistory};
use fretdyn::model::Model;
use fretdyn::structure::modal::{ModalBasis, Point};
use nalgebra::Vector3;

/// A 1 kg point mass free in x, y, z (three rigid modes, unit rows).
fn free_mass(frequency_hz: [f64; 3]) -> Model {
    let point = Point {
        name: "mass".into(),
        coords: Vector3::zeros(),
        rows: vec![1., 0., 0., 0., 1., 0., 0., 0., 1.],
        rotations: Vec::new(),
    };
    Model::new(ModalBasis {
        omega: frequency_hz.iter().map(|f| TAU * f).collect(),
        damping_ratio: vec![0.0; 3],
        points: vec![point],
        participation: Vec::new(),
    })
}

fn settings(
    method: TangentialMethod,
    dt: f64,
    steps: u64,
    stats: StatisticsSettings,
) -> RunSettings {
    RunSettings {
        dt,
        steps,
        method,
        stick_velocity: StickVelocity::HalfStep,
        output_every: 1000,
        monitors: Vec::new(),
        statistics: stats,
    }
}

fn lagrange_methods() -> [(&'static str, TangentialMethod); 2] {
    [
        (
            "gauss_seidel",
            TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        ),
        (
            "active_set",
            TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        ),
    ]
}

// ---------------------------------------------------------------------------------------
// Mass on a vibrating plane

/// Event-driven exact solution of a mass (g = N/m the normal force per unit mass, friction
/// coefficient μ, static = dynamic) on a plane of acceleration `A sin(2πt)` (frequency 1 Hz),
/// starting at t = 0 stuck to it. With `u` the velocity relative to the plane, in slip
/// `u̇ = −A sin 2πt − μ g s` (s = sign u) is integrated in closed form; a slip ends when `u`
/// returns to 0, and sticks while `A |sin 2πt| ≤ μ g`. Returns `∫|u| dt` over `[ta, tb]`;
/// the friction power is `μ N |u|`.
fn reference_slip_integral(a: f64, mu_g: f64, ta: f64, tb: f64) -> f64 {
    let acc = |t: f64| a * (TAU * t).sin();
    // relative velocity and its integral from (t0, u = 0) in slip direction s
    let u = |t0: f64, s: f64, t: f64| {
        a / TAU * ((TAU * t).cos() - (TAU * t0).cos()) - mu_g * s * (t - t0)
    };
    let int_u = |t0: f64, s: f64, t: f64| {
        let h = t - t0;
        a / TAU * (((TAU * t).sin() - (TAU * t0).sin()) / TAU - (TAU * t0).cos() * h)
            - mu_g * s * h * h / 2.0
    };
    // first t in (t0, tb] where f changes sign from its sign just after t0 (bisection)
    let h = 1e-5;
    let root = |f: &dyn Fn(f64) -> f64, t0: f64| -> Option<f64> {
        let mut lo = t0 + h;
        let s0 = f(lo).signum();
        while lo < tb {
            let hi = lo + h;
            if f(hi).signum() != s0 {
                let (mut l, mut r) = (lo, hi);
                for _ in 0..80 {
                    let m = 0.5 * (l + r);
                    if f(m).signum() == s0 { l = m } else { r = m }
                }
                return Some(0.5 * (l + r));
            }
            lo = hi;
        }
        None
    };
    let mut total = 0.0;
    let mut t = 0.0;
    let mut sticking = true;
    let mut s = 0.0;
    while t < tb {
        if sticking {
            if a <= mu_g {
                break; // sticks for ever
            }
            // stick until |A sin 2πt| exceeds μ g
            let Some(t_end) = root(&|x| acc(x).abs() - mu_g, t) else {
                break;
            };
            t = t_end;
            s = -acc(t).signum();
            sticking = false;
        } else {
            let t0 = t;
            let t_end = root(&|x| u(t0, s, x) * s, t0).unwrap_or(tb.max(t0));
            let (lo, hi) = (t0.max(ta), t_end.min(tb));
            if hi > lo {
                total += (int_u(t0, s, hi) - int_u(t0, s, lo)).abs();
            }
            t = t_end;
            if acc(t).abs() <= mu_g {
                sticking = true;
            } else {
                s = -acc(t).signum();
            }
        }
    }
    total
}

/// The plane moves in x with acceleration `A sin 2πt`; the mass, pressed on it by 10 N, starts
/// stuck to it (same velocity, static penetration).
fn vibrating_plane(a: f64, mu: f64, normal: f64, kn: f64) -> Model {
    let mut model = free_mass([0.0; 3]);
    let mut contact = Contact::new(
        "plane",
        0,
        Obstacle::Plane(
            Plane::new(Vector3::zeros(), Vector3::y(), 0.0, Some(Vector3::x()), "p").unwrap(),
        ),
        NormalLaw::new(kn, 0.0, "n").unwrap(),
        Coulomb::new(mu, mu, "f").unwrap(),
    );
    // d = −A/(2π)² sin 2πt: acceleration A sin 2πt, velocity −A/(2π) cos 2πt
    contact.motion = Motion::Harmonic {
        amplitude: Vector3::new(-a / (TAU * TAU), 0.0, 0.0),
        frequency_hz: 1.0,
        phase: 0.0,
    };
    model.contacts.push(contact);
    model.loads.push(
        PointLoad::new(
            0,
            Vector3::new(0.0, -normal, 0.0),
            TimeHistory::Constant,
            "l",
        )
        .unwrap(),
    );
    model.initial.q = vec![0.0, -normal / kn, 0.0];
    model.initial.qdot = vec![-a / TAU, 0.0, 0.0];
    model
}

/// Wear work rate of the mass on the vibrating plane (m = 1 kg, N = 10 N, μ = 0.1) against the
/// event-driven solution, over the periods 1 s – 5 s, in the three regimes: A = 15 m/s²
/// (slip in both directions, reversing without sticking), 1.5 (stick–slip), 0.99 (A < μg:
/// permanent stick, no wear). Both definitions: `(1/T)∫|R_T·v_T|` and `(1/T)∫R_N|v_T|`.
#[test]
fn wear_work_rate_on_a_vibrating_plane_matches_the_event_driven_solution() {
    let (mu, normal, kn) = (0.1, 10.0, 1e7);
    let (ta, tb, dt) = (1.0, 5.0, 2e-5);
    let stats = StatisticsSettings {
        t_start: ta,
        t_end: tb,
        ..Default::default()
    };
    for a in [15.0, 1.5, 0.99] {
        let model = vibrating_plane(a, mu, normal, kn);
        let slip = reference_slip_integral(a, mu * normal, ta, tb);
        let expected = mu * normal * slip / (tb - ta);
        let expected_normal = normal * slip / (tb - ta);
        // scale of the rate: μ N times the plane's velocity amplitude
        let scale = mu * normal * a / TAU;
        for (label, method) in lagrange_methods() {
            let r = simulate(&model, &settings(method, dt, (tb / dt) as u64 + 10, stats)).unwrap();
            let c = &r.contacts[0];
            assert!(
                (c.duration - (tb - ta)).abs() < 1e-9,
                "{label}: window {}",
                c.duration
            );
            if expected > 0.0 {
                let err = (c.wear_work_rate - expected).abs() / expected;
                let err_n = (c.normal_wear_work_rate - expected_normal).abs() / expected_normal;
                eprintln!(
                    "A = {a}: {label} wear rate {:.6e} W, reference {expected:.6e} W, error {err:.1e}; R_N|v_T| {:.6e} vs {expected_normal:.6e} ({err_n:.1e}); stick {:.4}",
                    c.wear_work_rate, c.normal_wear_work_rate, c.stick_time_fraction
                );
                assert!(
                    err < 1e-3,
                    "{label} A = {a}: {} vs {expected}",
                    c.wear_work_rate
                );
                assert!(
                    err_n < 1e-3,
                    "{label} A = {a}: {} vs {expected_normal}",
                    c.normal_wear_work_rate
                );
            } else {
                eprintln!(
                    "A = {a}: {label} wear rate {:.3e} W (reference 0, scale {scale:.3e} W); stick {:.4}",
                    c.wear_work_rate, c.stick_time_fraction
                );
                assert!(
                    c.wear_work_rate < 1e-6 * scale,
                    "{label}: {}",
                    c.wear_work_rate
                );
                assert_eq!(c.stick_time_fraction, 1.0, "{label}");
            }
        }
    }
}

/// The same permanent-stick case with the tangential penalty law: the micro-slip of its
/// spring makes wear that does not exist (the reason for the Lagrange methods), and it is
/// reported as such, not hidden.
#[test]
fn penalty_micro_slip_makes_spurious_wear_in_permanent_stick() {
    let (a, mu, normal, kn) = (0.99, 0.1, 10.0, 1e7);
    let model = vibrating_plane(a, mu, normal, kn);
    let dt = 2e-5;
    let method = TangentialMethod::Penalty(PenaltySettings {
        stiffness: 1e5,
        damping: 10.0,
    });
    let stats = StatisticsSettings {
        t_start: 1.0,
        ..Default::default()
    };
    let r = simulate(&model, &settings(method, dt, 250_000, stats)).unwrap();
    let c = &r.contacts[0];
    eprintln!(
        "penalty, permanent stick: wear rate {:.3e} W, stick fraction {}",
        c.wear_work_rate, c.stick_time_fraction
    );
    assert_eq!(c.stick_time_fraction, 1.0);
    assert!(c.wear_work_rate > 0.0);
}

// ---------------------------------------------------------------------------------------
// Impact of a mass–spring on a stiff stop

struct ImpactCase {
    m: f64,
    ks: f64,
    kc: f64,
    gap: f64,
    v0: f64,
}

impl ImpactCase {
    /// Mass on a spring `k_s` along x, leaving its rest position at `v0` towards a stop at
    /// `gap` of stiffness `k_c`, undamped.
    fn model(&self) -> Model {
        let f = (self.ks / self.m).sqrt() / TAU;
        let s = 1.0 / self.m.sqrt();
        let point = Point {
            name: "mass".into(),
            coords: Vector3::zeros(),
            rows: vec![s, 0., 0., 0., s, 0., 0., 0., s],
            rotations: Vec::new(),
        };
        let mut model = Model::new(ModalBasis {
            omega: vec![TAU * f, 0.0, 0.0],
            damping_ratio: vec![0.0; 3],
            points: vec![point],
            participation: Vec::new(),
        });
        model.contacts.push(Contact::new(
            "stop",
            0,
            Obstacle::Plane(
                Plane::new(Vector3::zeros(), -Vector3::x(), self.gap, None, "p").unwrap(),
            ),
            NormalLaw::new(self.kc, 0.0, "n").unwrap(),
            Coulomb::new(0.3, 0.3, "f").unwrap(),
        ));
        model.initial.qdot = vec![self.v0 / s, 0.0, 0.0];
        model
    }

    /// Closed form: `(t1, v1, peak time, peak force, impulse, duration)`. Free flight
    /// `x = (v0/ω) sin ωt` reaches the gap at `t1 = asin(g ω / v0)/ω` with
    /// `v1 = sqrt(v0² − ω² g²)`; in contact `m ẍ = −k_s x − k_c (x − g)` oscillates about
    /// `x_e = k_c g/(k_s + k_c)` at `ω_c = sqrt((k_s + k_c)/m)`: with `a = g − x_e`,
    /// `B = sqrt(a² + (v1/ω_c)²)`, `φ = atan2(v1/ω_c, a)`, the contact lasts `2φ/ω_c`, peaks at
    /// `t1 + φ/ω_c` with `k_c (B − a)`, its impulse is `k_c (2 v1/ω_c² − a · 2φ/ω_c)`, and the
    /// mass leaves at `v1` (no dissipation).
    fn closed_form(&self) -> (f64, f64, f64, f64, f64, f64) {
        let w = (self.ks / self.m).sqrt();
        let t1 = (self.gap * w / self.v0).asin() / w;
        let v1 = (self.v0 * self.v0 - w * w * self.gap * self.gap).sqrt();
        let wc = ((self.ks + self.kc) / self.m).sqrt();
        let xe = self.kc * self.gap / (self.ks + self.kc);
        let a = self.gap - xe;
        let b = (a * a + (v1 / wc).powi(2)).sqrt();
        let phi = (v1 / wc).atan2(a);
        let duration = 2.0 * phi / wc;
        (
            t1,
            v1,
            t1 + phi / wc,
            self.kc * (b - a),
            self.kc * (2.0 * v1 / (wc * wc) - a * duration),
            duration,
        )
    }
}

/// Impact time, peak force and its time, impulse, duration, impact and rebound speeds of one
/// impact against the closed form, within 0.1 %, with every tangential method (the impact is
/// normal: friction plays no part).
#[test]
fn impact_of_a_mass_spring_on_a_stiff_stop_matches_the_closed_form() {
    let case = ImpactCase {
        m: 2.0,
        ks: 200.0,
        kc: 2e6,
        gap: 1e-3,
        v0: 0.1,
    };
    let model = case.model();
    let (t1, v1, t_peak, peak, impulse, duration) = case.closed_form();
    let dt = 1e-6;
    let steps = ((t1 + 3.0 * duration) / dt) as u64;
    let methods = [
        lagrange_methods()[0],
        lagrange_methods()[1],
        (
            "penalty",
            TangentialMethod::Penalty(PenaltySettings {
                stiffness: 1e6,
                damping: 0.0,
            }),
        ),
    ];
    for (label, method) in methods {
        let r: RunResults =
            simulate(&model, &settings(method, dt, steps, Default::default())).unwrap();
        assert_eq!(r.impacts.len(), 1, "{label}: {:?}", r.impacts);
        let i = r.impacts[0];
        let checks = [
            ("start", i.start, t1),
            ("impact speed", i.impact_speed, v1),
            ("rebound speed", i.rebound_speed, v1),
            ("peak time", i.peak_time, t_peak),
            ("peak force", i.peak_force, peak),
            ("impulse", i.impulse, impulse),
            ("duration", i.duration, duration),
            ("contact time", i.contact_time, duration),
        ];
        for (name, got, want) in checks {
            let err = (got - want).abs() / want.abs();
            eprintln!("{label}: {name} {got:.6e}, closed form {want:.6e}, error {err:.1e}");
            assert!(err < 1e-3, "{label}: {name} {got} vs {want}");
        }
        assert_eq!(i.rebounds, 0);
        let c = &r.contacts[0];
        assert_eq!(c.impacts, 1);
        assert!((c.contact_duration_mean - duration).abs() < 1e-3 * duration);
        assert!((c.normal_force_max - peak).abs() < 1e-3 * peak);
        assert_eq!(
            c.peak_force_histogram.iter().map(|b| b.count).sum::<u64>(),
            1
        );
    }
}

/// Repeated impacts of the same system: the mass leaves the stop at `−v1` and comes back to
/// it after the flight `(π + 2 ω t1)/ω` (the elastic rebound turns its phase `ω t1` into
/// `π − ω t1`), so impacts start every `(π + 2 ω t1)/ω` + contact duration. With a rest
/// duration shorter than the flight, each is an impact; with a longer one, they are the
/// rebounds of one impact.
#[test]
fn openings_shorter_than_the_rest_duration_are_rebounds() {
    let case = ImpactCase {
        m: 2.0,
        ks: 200.0,
        kc: 2e6,
        gap: 1e-3,
        v0: 0.1,
    };
    let model = case.model();
    let (t1, _, _, _, _, duration) = case.closed_form();
    let w = (case.ks / case.m).sqrt();
    let flight = (std::f64::consts::PI + 2.0 * w * t1) / w;
    let period = flight + duration;
    let dt = 1e-5;
    // four impacts, at t1 + k·period
    let steps = ((t1 + 3.0 * period + 2.0 * duration) / dt) as u64 + 10;
    for (rest, impacts, rebounds) in [(0.5 * flight, 4, 0), (1.5 * flight, 1, 3)] {
        let stats = StatisticsSettings {
            rest_duration: rest,
            ..Default::default()
        };
        let method = TangentialMethod::GaussSeidel(GaussSeidelSettings::default());
        let r = simulate(&model, &settings(method, dt, steps, stats)).unwrap();
        let c = &r.contacts[0];
        assert_eq!(c.impacts, impacts, "rest {rest}");
        if rebounds == 0 {
            assert_eq!(r.impacts.len(), 4);
            for (k, i) in r.impacts.iter().enumerate() {
                let t = t1 + k as f64 * period;
                assert!(
                    (i.start - t).abs() < 1e-3 * period,
                    "impact {k} at {}",
                    i.start
                );
                assert_eq!(i.rebounds, 0);
            }
            assert!((c.impacts_per_second - 4.0 / (steps as f64 * dt)).abs() < 1e-9);
        } else {
            // one impact from the first closing to the last opening, ended with the run
            assert_eq!(r.impacts.len(), 1);
            let i = r.impacts[0];
            assert_eq!(i.rebounds, 3);
            assert!((i.start - t1).abs() < 1e-3 * period);
            let end = t1 + 3.0 * period + duration;
            assert!((i.start + i.duration - end).abs() < 1e-3 * period, "{i:?}");
            assert!(
                (i.contact_time - 4.0 * duration).abs() < 1e-2 * duration,
                "{i:?}"
            );
            assert_eq!(c.rebounds_per_impact, 3.0);
        }
    }
}
