//! Three bodies in a row (issue [3.4], THEORY §15): three point masses on springs to the walls,
//! with two node-to-node contacts (point against point along x: a plane in relative
//! coordinates, origin `x0_A − x0_B`, normal from B to A) and a harmonic force on the first.
//! Both contacts impact repeatedly. The contact forces
//!
//! - converge as `Δt` is halved (`Δt`, `Δt/2`, `Δt/4`) at order 2, the order of central
//!   differences: the penalty force is Lipschitz, smooth between the instants a contact opens
//!   or closes, so its kinks only add `O(Δt³)` errors on the steps that straddle them;
//! - match an independent integration written here from scratch (no fretdyn code): RK4 on the
//!   6 states with each contact's state (open/closed) frozen over a step, the instants of
//!   opening and closing located by bisection, so that it keeps its order 4 through the
//!   kinks. At `Δt/40` its error is far below fretdyn's, and fretdyn's error at `Δt/4` must
//!   be within the error estimate `|R_{Δt/2} − R_{Δt/4}| / (2^p − 1)` of the convergence study
//!   (p the measured order); peaks and impulses within the bounds that follow from it.

use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::obstacle::{Obstacle, Plane};
use fretdyn::contact::tangential::{PenaltySettings, TangentialMethod};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{Termination, simulate};
use fretdyn::loads::{PointLoad, TimeHistory};
use fretdyn::model::Model;
use fretdyn::structure::modal::ModalBasis;
use nalgebra::Vector3;
#[path = "common/every_step.rs"]
mod every_step;
use every_step::every_step;

/// The system: masses, wall springs, modal damping ratio, contact stiffnesses and gaps, force.
struct Row {
    mass: [f64; 3],
    spring: [f64; 3],
    zeta: f64,
    /// Contact 0 between bodies 0 and 1, contact 1 between bodies 1 and 2.
    stiffness: [f64; 2],
    gap: [f64; 2],
    force: f64,
    frequency_hz: f64,
    duration: f64,
}

const ROW: Row = Row {
    mass: [2.0, 3.0, 1.5],
    spring: [3e4, 5e4, 4e4],
    zeta: 0.02,
    stiffness: [2e6, 5e6],
    gap: [5e-5, 3e-5],
    force: 30.0,
    frequency_hz: 40.0,
    duration: 0.06,
};

const SPACING: f64 = 0.1;

impl Row {
    fn omega(&self, b: usize) -> f64 {
        (self.spring[b] / self.mass[b]).sqrt()
    }

    /// The fretdyn model: the union of three point masses (`b0.p`, `b1.p`, `b2.p`, at
    /// `x = 0, 0.1, 0.2`), contact `c` between `b{c+1}` (A) and `b{c}` (B).
    fn model(&self) -> Model {
        let parts = (0..3)
            .map(|b| {
                let x0 = Vector3::new(SPACING * b as f64, 0.0, 0.0);
                let mut basis = ModalBasis::point_mass(self.mass[b], "p", x0).unwrap();
                // the wall spring k in every direction: ω = √(k/m) on each of its 3 modes
                basis.omega = vec![self.omega(b); 3];
                basis.damping_ratio = vec![self.zeta; 3];
                (format!("b{b}"), Model::new(basis))
            })
            .collect();
        let mut model = Model::union(parts).unwrap();
        for c in 0..2 {
            // point against point along x: δ = (u_B − u_A)·x − g
            let plane = Plane::new(
                Vector3::new(SPACING, 0.0, 0.0),
                Vector3::x(),
                self.gap[c],
                None,
                "plane",
            )
            .unwrap();
            let contact = Contact::between(
                format!("c{c}"),
                c + 1,
                c,
                &model.basis.points,
                [0.0, 0.0],
                Obstacle::Plane(plane),
                NormalLaw::new(self.stiffness[c], 0.0, "normal").unwrap(),
                Coulomb::new(0.0, 0.0, "friction").unwrap(),
            )
            .unwrap();
            model.contacts.push(contact);
        }
        model.loads.push(
            PointLoad::new(
                0,
                Vector3::new(self.force, 0.0, 0.0),
                TimeHistory::Harmonic {
                    frequency_hz: self.frequency_hz,
                    phase: 0.0,
                },
                "load",
            )
            .unwrap(),
        );
        model
    }
}

/// Contact force histories `R_c(t_i)` at `t_i = i Δt`, i = 0..=N.
type Histories = [Vec<f64>; 2];

fn fretdyn_forces(row: &Row, dt: f64) -> Histories {
    let steps = (row.duration / dt).round() as u64;
    let r = simulate(
        &row.model(),
        &every_step(
            TangentialMethod::Penalty(PenaltySettings {
                stiffness: 1e6,
                damping: 0.0,
            }),
            dt,
            steps,
        ),
    )
    .expect("valid run");
    assert_eq!(r.termination, Termination::Completed);
    let rec = &r.recorder;
    let mut out: Histories = [vec![0.0; steps as usize + 1], vec![0.0; steps as usize + 1]];
    for i in 0..rec.len() {
        let k = (rec.t[i] / dt).round() as usize;
        assert!((rec.t[i] - k as f64 * dt).abs() < 1e-9 * dt);
        for (c, history) in out.iter_mut().enumerate() {
            history[k] = rec.normal_force[[i, c]];
        }
    }
    // nothing moves across the line
    assert!(
        rec.q
            .iter()
            .enumerate()
            .all(|(j, q)| j % 3 == 0 || *q == 0.0)
    );
    out
}

// ---- the independent integration: RK4 with frozen contact states and located events ----

/// State: displacements, velocities of the 3 bodies along x.
type State = [f64; 6];

fn penetrations(row: &Row, y: &State) -> [f64; 2] {
    [y[0] - y[1] - row.gap[0], y[1] - y[2] - row.gap[1]]
}

fn rhs(row: &Row, t: f64, y: &State, closed: [bool; 2]) -> State {
    let d = penetrations(row, y);
    let r: Vec<f64> = (0..2)
        .map(|c| {
            if closed[c] {
                row.stiffness[c] * d[c]
            } else {
                0.0
            }
        })
        .collect();
    let f = row.force * (std::f64::consts::TAU * row.frequency_hz * t).sin();
    let ext = [f - r[0], r[0] - r[1], r[1]];
    let mut dy = [0.0; 6];
    for b in 0..3 {
        let c = 2.0 * row.zeta * (row.spring[b] * row.mass[b]).sqrt();
        dy[b] = y[3 + b];
        dy[3 + b] = (ext[b] - row.spring[b] * y[b] - c * y[3 + b]) / row.mass[b];
    }
    dy
}

fn rk4(row: &Row, t: f64, y: &State, h: f64, closed: [bool; 2]) -> State {
    let add = |a: &State, k: &State, s: f64| -> State { std::array::from_fn(|i| a[i] + s * k[i]) };
    let k1 = rhs(row, t, y, closed);
    let k2 = rhs(row, t + h / 2.0, &add(y, &k1, h / 2.0), closed);
    let k3 = rhs(row, t + h / 2.0, &add(y, &k2, h / 2.0), closed);
    let k4 = rhs(row, t + h, &add(y, &k3, h), closed);
    std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// The contacts whose state the step to `y` changes (closed and opened, or open and closed).
fn events(row: &Row, y: &State, closed: [bool; 2]) -> [bool; 2] {
    let d = penetrations(row, y);
    [0, 1].map(|c| if closed[c] { d[c] < 0.0 } else { d[c] > 0.0 })
}

/// What the reference gives: the contact force histories `R_c(t_i)`, `t_i = i Δt`, the number
/// of impacts of each contact, and the sum over its openings and closings of the jump of
/// `dR/dt` there, `K |δ̇|` (for the quadrature error bound of the impulse).
struct Reference {
    forces: Histories,
    impacts: [usize; 2],
    kinks: [f64; 2],
}

/// The reference from RK4 steps of `Δt / substeps`.
fn reference_forces(row: &Row, dt: f64, substeps: usize) -> Reference {
    let n = (row.duration / dt).round() as usize;
    let h = dt / substeps as f64;
    let mut y: State = [0.0; 6];
    let mut closed = [false; 2];
    let mut impacts = [0; 2];
    let mut kinks = [0.0; 2];
    let mut out: Histories = [vec![0.0; n + 1], vec![0.0; n + 1]];
    let mut t = 0.0;
    for i in 1..=n {
        for s in 1..=substeps {
            let end = (i - 1) as f64 * dt + s as f64 * h;
            while t < end {
                let tau = end - t;
                let trial = rk4(row, t, &y, tau, closed);
                let ev = events(row, &trial, closed);
                if !ev.contains(&true) {
                    (t, y) = (end, trial);
                    continue;
                }
                // the first instant a contact changes state, by bisection on the step length
                let (mut lo, mut hi) = (0.0, tau);
                for _ in 0..80 {
                    let mid = 0.5 * (lo + hi);
                    if mid <= lo || mid >= hi {
                        break;
                    }
                    if events(row, &rk4(row, t, &y, mid, closed), closed).contains(&true) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                let at = rk4(row, t, &y, hi, closed);
                let ev = events(row, &at, closed);
                for c in 0..2 {
                    if ev[c] {
                        closed[c] = !closed[c];
                        impacts[c] += closed[c] as usize;
                        let rate = [at[3] - at[4], at[4] - at[5]][c];
                        kinks[c] += row.stiffness[c] * rate.abs();
                    }
                }
                (t, y) = (t + hi, at);
            }
            t = end;
        }
        let d = penetrations(row, &y);
        for (c, history) in out.iter_mut().enumerate() {
            history[i] = row.stiffness[c] * d[c].max(0.0);
        }
    }
    Reference {
        forces: out,
        impacts,
        kinks,
    }
}

// ---- comparisons ----

/// Every `stride`-th sample of `h`, so that it is on the grid of a `stride` times coarser run.
fn every(h: &[f64], stride: usize) -> Vec<f64> {
    h.iter().step_by(stride).copied().collect()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

fn peak(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, x| m.max(*x))
}

/// `∫ R dt` by the trapezoidal rule (the force is 0 at both ends of the run).
fn impulse(a: &[f64], dt: f64) -> f64 {
    dt * (a.iter().sum::<f64>() - 0.5 * (a[0] + a[a.len() - 1]))
}

#[test]
fn contact_forces_converge_at_order_two_and_match_an_independent_integration() {
    let row = ROW;
    let dt = 1e-6;
    let refinements = [1, 2, 4];
    let runs: Vec<Histories> = refinements
        .iter()
        .map(|d| fretdyn_forces(&row, dt / *d as f64))
        .collect();
    let dt_ref = dt / 4.0;
    let reference = reference_forces(&row, dt_ref, 10);
    let impacts = reference.impacts;
    assert!(
        impacts.iter().all(|n| *n >= 3),
        "both contacts impact repeatedly: {impacts:?}"
    );
    for c in 0..2 {
        let fref = &reference.forces[c];
        let scale = peak(fref);
        // histories on the common grid t = i Δt
        let f: Vec<Vec<f64>> = refinements
            .iter()
            .zip(&runs)
            .map(|(d, r)| every(&r[c], *d))
            .collect();
        let d1 = max_diff(&f[0], &f[1]);
        let d2 = max_diff(&f[1], &f[2]);
        let e4 = max_diff(&f[2], &every(fref, 4));
        let extrapolated: Vec<f64> = f[2]
            .iter()
            .zip(&f[1])
            .map(|(a, b)| (4.0 * a - b) / 3.0)
            .collect();
        let e_rich = max_diff(&extrapolated, &every(fref, 4));
        let order = (d1 / d2).log2();
        eprintln!(
            "contact {c} ({} impacts): peak {scale:.6e} N; max |ΔR|/peak Δt↔Δt/2 {:.3e}, Δt/2↔Δt/4 {:.3e} (order {order:.2}); Δt/4 vs reference {:.3e}, Richardson vs reference {:.3e}",
            impacts[c],
            d1 / scale,
            d2 / scale,
            e4 / scale,
            e_rich / scale
        );
        // order 2 of central differences (the kinks of the penalty force at opening and
        // closing cost a little of it at these steps: 1.8–1.9 measured)
        assert!((order - 2.0).abs() < 0.25, "contact {c}: order {order}");
        // the independent integration: fretdyn's error at Δt/4 is within the error estimate of
        // the convergence study, d2/(2^p − 1), ×1.5 for the estimate's own spread (measured:
        // 0.9 and 0.3 of it). (The order-2 Richardson extrapolation (4 R_{Δt/4} − R_{Δt/2})/3
        // is 6.5× closer to the reference on contact 0, not on contact 1: in the max norm,
        // taken near the kinks, the error is not yet C Δt^p at these steps.)
        let estimate = d2 / (2f64.powf(order) - 1.0);
        assert!(
            e4 < 1.5 * estimate,
            "contact {c}: {e4:e} vs estimate {estimate:e}"
        );
        assert!(e4 < 1e-6 * scale, "contact {c}: {:e}", e4 / scale);
        // peak and impulse of each run, each on its own grid, against the reference's: the
        // peak within the history error plus the sampling error of a maximum, R ω_c² h²/8
        // (ω_c² = K (1/m_A + 1/m_B)); the impulse within T × the history error plus the
        // trapezoidal error, (h²/8) Σ K|δ̇| at the kinks + T R ω_c² h²/12 between them
        let omega2 = row.stiffness[c] * (1.0 / row.mass[c] + 1.0 / row.mass[c + 1]);
        let (pref, iref) = (peak(fref), impulse(fref, dt_ref));
        for (k, d) in refinements.iter().enumerate() {
            let h = dt / *d as f64;
            let e = max_diff(&runs[k][c], &every(fref, 4 / d));
            let sampled = h * h + dt_ref * dt_ref;
            let (p, i) = (peak(&runs[k][c]), impulse(&runs[k][c], h));
            let peak_bound = e + scale * omega2 * sampled / 8.0;
            let impulse_bound = row.duration * e
                + reference.kinks[c] * sampled / 8.0
                + row.duration * scale * omega2 * sampled / 12.0;
            eprintln!(
                "  Δt/{d}: peak {p:.9e} (ref {pref:.9e}, bound {peak_bound:.1e}), impulse {i:.9e} N s (ref {iref:.9e}, bound {impulse_bound:.1e})"
            );
            assert!((p - pref).abs() <= peak_bound, "contact {c} Δt/{d}: peak");
            assert!(
                (i - iref).abs() <= impulse_bound,
                "contact {c} Δt/{d}: impulse"
            );
        }
    }
}

/// With friction (μ_s = 0.4, μ_d = 0.3) and a transverse load on the middle body, for every
/// tangential method: the contacts stick and slip across the line, yet the motion along it
/// and the normal forces are exactly the frictionless ones — the tangents `[y, z]` of the
/// plane of normal x have exact zeros along x, so the friction forces never enter the x modes.
#[test]
fn friction_and_a_transverse_load_leave_the_motion_along_the_line_unchanged() {
    use fretdyn::contact::tangential::{ActiveSetSettings, GaussSeidelSettings};
    let row = ROW;
    let dt = 1e-6;
    let steps = (row.duration / dt).round() as u64;
    let settings = |method| every_step(method, dt, steps);
    let penalty = TangentialMethod::Penalty(PenaltySettings {
        stiffness: 1e6,
        damping: 100.0,
    });
    let frictionless = simulate(&row.model(), &settings(penalty)).unwrap();
    let mut model = row.model();
    for c in &mut model.contacts {
        c.friction = Coulomb::new(0.4, 0.3, "friction").unwrap();
    }
    model.loads.push(
        PointLoad::new(
            1,
            Vector3::new(0.0, 40.0, 0.0),
            TimeHistory::Harmonic {
                frequency_hz: 25.0,
                phase: 0.3,
            },
            "shear",
        )
        .unwrap(),
    );
    for method in [
        penalty,
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
    ] {
        let r = simulate(&model, &settings(method)).unwrap();
        let (a, b) = (&frictionless.recorder, &r.recorder);
        for c in 0..2 {
            let s: Vec<i8> = b.status.column(c).to_vec();
            assert!(
                s.contains(&1) && s.contains(&2),
                "{} contact {c}: stick and slip",
                method.name()
            );
        }
        assert_eq!(a.normal_force, b.normal_force, "{}", method.name());
        for m in [0, 3, 6] {
            assert_eq!(a.q.column(m), b.q.column(m), "{} mode {m}", method.name());
        }
        let ft = b
            .tangential_force
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(ft > 1.0, "{}: friction acted ({ft})", method.name());
    }
}
