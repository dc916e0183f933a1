//! An impact under way when the statistics window opens (issue 3.1, THEORY §11): it starts at
//! the window's start, with its row in the impacts table, its duration from there, and as its
//! impact speed the normal approach speed at that time. Checked on an undamped oscillator that
//! bounces periodically on a stiff stop (closed form: the contact and flight phases are
//! harmonic), with the window at t = 0 and the contact closed there (started at its deepest
//! penetration), and with the window opening in the middle of a contact: the window holds as
//! many impacts as periods, each where the closed form puts it.

use std::f64::consts::TAU;

use fretdyn::accumulate::statistics::StatisticsSettings;
use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::obstacle::{Obstacle, Plane};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{RunResults, RunSettings, simulate};
use fretdyn::model::Model;
use fretdyn::structure::modal::{ModalBasis, Point};
use nalgebra::Vector3;

/// A mass `m` on a spring `k_s` along x (one mode), and a stop at `x = g` of stiffness
/// `k_c` (a plane of normal `−x`). Started at the deepest point of a contact whose impact
/// speed is `v1`, at rest, it bounces with the period of the closed form.
struct Bouncer {
    m: f64,
    ks: f64,
    kc: f64,
    g: f64,
    v1: f64,
}

/// The closed form of [`Bouncer`]'s motion.
struct Orbit {
    /// Contact frequency `√((k_s + k_c)/m)`, rad/s.
    omega_c: f64,
    /// Equilibrium of the contact phase `x_e = k_c g/(k_s + k_c)` and the amplitude `B` about it.
    x_e: f64,
    b: f64,
    /// Half a contact, from the deepest point to the opening, s.
    half_contact: f64,
    /// Period: a contact and a flight, s.
    period: f64,
}

impl Bouncer {
    /// In contact `m ẍ = −k_s x − k_c (x − g)`: `x = x_e + B cos ω_c τ` (τ from the deepest
    /// point), with `a = g − x_e` and `B = √(a² + (v1/ω_c)²)`; it opens at
    /// `τ_o = acos(a/B)/ω_c` with the speed `v1`. In flight `x = A cos(ωt + θ)`,
    /// `A = √(g² + (v1/ω)²)`: it leaves `x = g` at `θ = acos(g/A)` and comes back at
    /// `2π − acos(g/A)`, after `(2π − 2 acos(g/A))/ω`.
    fn orbit(&self) -> Orbit {
        let omega = (self.ks / self.m).sqrt();
        let omega_c = ((self.ks + self.kc) / self.m).sqrt();
        let x_e = self.kc * self.g / (self.ks + self.kc);
        let a = self.g - x_e;
        let b = (a * a + (self.v1 / omega_c).powi(2)).sqrt();
        let half_contact = (a / b).acos() / omega_c;
        let amplitude = (self.g * self.g + (self.v1 / omega).powi(2)).sqrt();
        let flight = (TAU - 2.0 * (self.g / amplitude).acos()) / omega;
        Orbit {
            omega_c,
            x_e,
            b,
            half_contact,
            period: 2.0 * half_contact + flight,
        }
    }

    fn model(&self) -> Model {
        let s = 1.0 / self.m.sqrt();
        let point = Point {
            name: "mass".into(),
            coords: Vector3::zeros(),
            rows: vec![s, 0.0, 0.0],
            rotations: Vec::new(),
        };
        let mut model = Model::new(ModalBasis {
            omega: vec![(self.ks / self.m).sqrt()],
            damping_ratio: vec![0.0],
            points: vec![point],
            participation: Vec::new(),
        });
        model.contacts.push(Contact::new(
            "stop",
            0,
            Obstacle::Plane(
                Plane::new(Vector3::zeros(), -Vector3::x(), self.g, None, "p").unwrap(),
            ),
            NormalLaw::new(self.kc, 0.0, "n").unwrap(),
            Coulomb::new(0.3, 0.3, "f").unwrap(),
        ));
        // at rest at the deepest point of a contact: penetration B − a > 0 at t = 0
        let o = self.orbit();
        model.initial.q = vec![(o.x_e + o.b) / s];
        model
    }
}

const BOUNCER: Bouncer = Bouncer {
    m: 1.0,
    ks: 4e3,
    kc: 1e6,
    g: 1e-3,
    v1: 0.1,
};

fn methods() -> [(&'static str, TangentialMethod); 3] {
    [
        (
            "gauss_seidel",
            TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        ),
        (
            "active_set",
            TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        ),
        (
            "penalty",
            TangentialMethod::Penalty(PenaltySettings {
                stiffness: 1e5,
                damping: 0.0,
            }),
        ),
    ]
}

fn run(method: TangentialMethod, dt: f64, duration: f64, t_start: f64) -> RunResults {
    let settings = RunSettings {
        dt,
        steps: (duration / dt).round() as u64,
        method,
        stick_velocity: StickVelocity::HalfStep,
        output_every: 1000,
        monitors: Vec::new(),
        statistics: StatisticsSettings {
            t_start,
            ..Default::default()
        },
    };
    simulate(&BOUNCER.model(), &settings).unwrap()
}

/// Time of the discrete scheme against the closed form: `Δt = 1e-5 s` resolves a contact
/// (`π/ω_c ≈ 3 ms`) with 300 steps; the linear interpolation of the zero crossings and the
/// period's error over 20 periods stay below a step.
const DT: f64 = 1e-5;

/// The window at t = 0 with the contact closed there (the mass starts at its deepest point):
/// the first impact starts at 0, lasts half a contact, and its impact speed is the approach
/// speed at t = 0, exactly 0 (at rest); then one impact per period, the k-th from
/// `k T − τ_o` for `2 τ_o`. Over 20 periods, 20 impacts.
#[test]
fn a_contact_closed_at_t0_starts_an_impact_at_t0() {
    let o = BOUNCER.orbit();
    assert!(o.half_contact > 100.0 * DT && o.period > 20.0 * o.half_contact);
    // to the middle of the 20th flight
    let duration = 20.0 * o.period - 0.5 * (o.period - 2.0 * o.half_contact);
    for (label, method) in methods() {
        let r = run(method, DT, duration, 0.0);
        let c = &r.contacts[0];
        assert_eq!(c.impacts, 20, "{label}: impacts in 20 periods");
        assert_eq!(r.impacts.len(), 20, "{label}: rows");
        let first = &r.impacts[0];
        assert_eq!(first.start, 0.0, "{label}: starts with the window");
        assert_eq!(first.impact_speed, 0.0, "{label}: at rest at t = 0");
        assert!(
            (first.duration - o.half_contact).abs() <= DT,
            "{label}: {} s, τ_o = {} s",
            first.duration,
            o.half_contact
        );
        // closed steps, against the interpolated opening: within a step
        assert!(
            (first.contact_time - first.duration).abs() <= DT,
            "{label}: {first:?}"
        );
        for (k, imp) in r.impacts.iter().enumerate().skip(1) {
            let start = k as f64 * o.period - o.half_contact;
            assert!(
                (imp.start - start).abs() <= DT,
                "{label}: impact {k} at {} s, closed form {start} s",
                imp.start
            );
            assert!(
                (imp.duration - 2.0 * o.half_contact).abs() <= DT,
                "{label}: impact {k} lasts {} s",
                imp.duration
            );
            assert!((imp.impact_speed - BOUNCER.v1).abs() <= 1e-3 * BOUNCER.v1);
        }
    }
}

/// The window opens in the middle of the contact of the 4th period (`t_s = 3T + 0.3 τ_o`,
/// the contact opening): the impact under way starts at the window's first step (within
/// `Δt/2` of `t_s`), lasts to the opening at `3T + τ_o`, and its impact speed is the normal
/// approach speed there, `ẋ = −B ω_c sin(0.3 ω_c τ_o)` (negative: the contact is opening).
/// Over the 20 periods from `t_s`, 20 impacts (it was dropped: 19).
#[test]
fn a_window_opening_during_an_impact_starts_it_there() {
    let o = BOUNCER.orbit();
    let t_s = 3.0 * o.period + 0.3 * o.half_contact;
    let duration = 23.0 * o.period - 0.5 * (o.period - 2.0 * o.half_contact);
    let speed = -o.b * o.omega_c * (0.3 * o.omega_c * o.half_contact).sin();
    assert!(speed < -0.01);
    for (label, method) in methods() {
        let r = run(method, DT, duration, t_s);
        let c = &r.contacts[0];
        assert_eq!(
            c.impacts, 20,
            "{label}: impacts in the 20 periods of the window"
        );
        assert_eq!(r.impacts.len(), 20, "{label}: rows");
        let first = &r.impacts[0];
        assert!(
            (first.start - t_s).abs() <= 0.5 * DT + 1e-12,
            "{label}: starts at {} s, the window at {t_s} s",
            first.start
        );
        let end = 3.0 * o.period + o.half_contact;
        assert!(
            (first.start + first.duration - end).abs() <= DT,
            "{label}: ends at {} s, closed form {end} s",
            first.start + first.duration
        );
        assert!(
            (first.contact_time - first.duration).abs() <= DT,
            "{label}: {first:?}"
        );
        // the full-step velocity at the first step's start, t_s within Δt/2: ẍ ≈ B ω_c²
        let tolerance = o.b * o.omega_c * o.omega_c * DT;
        assert!(
            (first.impact_speed - speed).abs() <= tolerance,
            "{label}: impact speed {} m/s, closed form {speed} m/s",
            first.impact_speed
        );
        for (k, imp) in r.impacts.iter().enumerate().skip(1) {
            let start = (3 + k) as f64 * o.period - o.half_contact;
            assert!(
                (imp.start - start).abs() <= DT,
                "{label}: impact {k} at {} s, closed form {start} s",
                imp.start
            );
            assert!((imp.duration - 2.0 * o.half_contact).abs() <= DT, "{label}");
        }
    }
}
