//! Fluid-elastic forces (THEORY §13) against the linear theory, solved independently of the
//! time stepping: a single mode with the delayed quasi-steady force vibrates freely with the
//! dominant root `s = σ + iω` of its characteristic equation
//!
//! ```text
//! s² + (2ζω₀ + c) s + ω₀² − k e^{−sτ} = 0,
//! ```
//!
//! found here by Newton's method on the complex root; the decay (growth) rate and frequency
//! measured from the run's peaks must match it within 1e-3, and the threshold velocity found by
//! bisection on runs must match the linear one within 1 %. Tabulated modal coefficients add a
//! damping and a stiffness that the run's decay and frequency must show within 1e-3.

use fretdyn::contact::tangential::{PenaltySettings, StickVelocity, TangentialMethod};
use fretdyn::integrator::simulation::{RunSettings, simulate};
use fretdyn::loads::fluid_elastic::{
    DelayedStiffness, FlowNode, FluidElastic, ModalMatrix, QuasiSteady, ReducedVelocityTable,
};
use fretdyn::model::Model;
use fretdyn::structure::modal::{ModalBasis, Point};
use nalgebra::Vector3;

const F0: f64 = 10.0;
const ZETA: f64 = 0.01;

/// A complex number, enough for Newton's method.
#[derive(Clone, Copy, Debug)]
struct C(f64, f64);

impl C {
    fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    fn sub(self, o: C) -> C {
        C(self.0 - o.0, self.1 - o.1)
    }
    fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn scale(self, a: f64) -> C {
        C(a * self.0, a * self.1)
    }
    fn div(self, o: C) -> C {
        let d = o.0 * o.0 + o.1 * o.1;
        C(
            (self.0 * o.0 + self.1 * o.1) / d,
            (self.1 * o.0 - self.0 * o.1) / d,
        )
    }
    fn exp(self) -> C {
        let r = self.0.exp();
        C(r * self.1.cos(), r * self.1.sin())
    }
}

/// The root of `s² + a s + b − k e^{−sτ} = 0` near `s = −a/2 + i√b` (Newton).
fn characteristic_root(a: f64, b: f64, k: f64, tau: f64) -> (f64, f64) {
    let mut s = C(-0.5 * a, b.sqrt());
    for _ in 0..100 {
        let e = s.scale(-tau).exp();
        let f = s.mul(s).add(s.scale(a)).add(C(b, 0.0)).sub(e.scale(k));
        let df = s.scale(2.0).add(C(a, 0.0)).add(e.scale(k * tau));
        let step = f.div(df);
        s = s.sub(step);
        if step.0.hypot(step.1) < 1e-14 * s.0.hypot(s.1) {
            break;
        }
    }
    (s.0, s.1)
}

/// One mode of frequency F0 and damping ZETA, seen at one point.
fn model(fe: FluidElastic) -> Model {
    let basis = ModalBasis {
        omega: vec![std::f64::consts::TAU * F0],
        damping_ratio: vec![ZETA],
        points: vec![Point {
            name: "p".into(),
            coords: Vector3::zeros(),
            rows: vec![0.0, 1.0, 0.0],
            rotations: Vec::new(),
        }],
        participation: Vec::new(),
    };
    let mut m = Model::new(basis);
    m.initial.qdot = vec![1.0];
    m.fluid_elastic = Some(fe);
    m
}

fn settings(dt: f64, duration: f64) -> RunSettings {
    RunSettings {
        dt,
        steps: (duration / dt).round() as u64,
        // no contact: the tangential method plays no role
        method: TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1.0,
            damping: 0.0,
        }),
        stick_velocity: StickVelocity::HalfStep,
        output_every: 1,
        monitors: Vec::new(),
        statistics: Default::default(),
    }
}

/// `(σ, ω)` of the free vibration `q(t)` after `skip` s: ω from the mean spacing of the
/// peaks, σ from the least-squares slope of the log of the peaks (each peak located by a
/// parabola through the three samples around it).
fn measured_rate(t: &[f64], q: &[f64], skip: f64) -> (f64, f64) {
    let mut peaks = Vec::new();
    for i in 1..q.len() - 1 {
        if t[i] > skip && q[i] > q[i - 1] && q[i] >= q[i + 1] {
            let (a, b, c) = (q[i - 1], q[i], q[i + 1]);
            let den = a - 2.0 * b + c;
            let x = 0.5 * (a - c) / den;
            let h = t[i + 1] - t[i];
            peaks.push((t[i] + x * h, b - 0.25 * (a - c) * x));
        }
    }
    assert!(peaks.len() > 20, "{} peaks", peaks.len());
    let n = peaks.len() as f64;
    let period = (peaks.last().unwrap().0 - peaks[0].0) / (n - 1.0);
    let (mt, ml) = (
        peaks.iter().map(|p| p.0).sum::<f64>() / n,
        peaks.iter().map(|p| p.1.ln()).sum::<f64>() / n,
    );
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for &(tp, a) in &peaks {
        sxy += (tp - mt) * (a.ln() - ml);
        sxx += (tp - mt) * (tp - mt);
    }
    (sxy / sxx, std::f64::consts::TAU / period)
}

fn run_rate(fe: FluidElastic, dt: f64, duration: f64, skip: f64) -> (f64, f64) {
    let r = simulate(&model(fe), &settings(dt, duration)).unwrap();
    let t = r.recorder.t.to_vec();
    let q = r.recorder.q.column(0).to_vec();
    measured_rate(&t, &q, skip)
}

fn delayed(k: f64, tau: f64, c: f64) -> FluidElastic {
    FluidElastic {
        delayed: vec![DelayedStiffness {
            name: "test".into(),
            delay: tau,
            stiffness: ModalMatrix::Dense(vec![k]),
        }],
        damping: if c != 0.0 {
            vec![ModalMatrix::Dense(vec![c])]
        } else {
            Vec::new()
        },
    }
}

#[test]
fn delayed_stiffness_gives_the_root_of_the_characteristic_equation() {
    let w0 = std::f64::consts::TAU * F0;
    // a delayed stiffness of 5 % of the mode's, with delays that damp (ωτ ≈ 1.9 rad) and
    // that feed energy in (ωτ ≈ 4.4 rad), and a velocity damping term on the first
    for (k, tau, c) in [
        (0.05 * w0 * w0, 0.03, 0.5),
        (0.05 * w0 * w0, 0.07, 0.0),
        (-0.03 * w0 * w0, 0.011, 0.0),
    ] {
        let (sigma, omega) = characteristic_root(2.0 * ZETA * w0 + c, w0 * w0, k, tau);
        let (ms, mw) = run_rate(delayed(k, tau, c), 1e-5, 4.0, 1.0);
        let scale = sigma.abs();
        assert!(
            (ms - sigma).abs() <= 1e-3 * scale,
            "k {k}, τ {tau}: σ run {ms} against {sigma}"
        );
        assert!(
            (mw - omega).abs() <= 1e-3 * omega,
            "k {k}, τ {tau}: ω run {mw} against {omega}"
        );
    }
}

/// A zone of 1 m of cross flow along y... across a mode `φ(s) = √2 sin(πs)` along y (lift),
/// at 20 midpoint nodes: `a = Σ w φ²`.
const RHO: f64 = 1000.0;
const D: f64 = 0.02;
const NODES: usize = 20;

fn shape(i: usize) -> f64 {
    let s = (i as f64 + 0.5) / NODES as f64;
    std::f64::consts::SQRT_2 * (std::f64::consts::PI * s).sin()
}

fn zone_rows() -> Vec<Vec<f64>> {
    (0..NODES).map(|i| vec![0.0, shape(i), 0.0]).collect()
}

fn nodes(rows: &[Vec<f64>], u: f64) -> Vec<FlowNode<'_>> {
    directed_nodes(rows, u, &QS)
}

const QS: QuasiSteady = QuasiSteady {
    lift_slope: -3.0,
    drag_slope: 0.0,
    drag: 1.0,
    mu_lift: 1.0,
    mu_drag: 1.0,
};

/// `(σ, ω)` of the linear theory of the mode across the flow at velocity `u` with the
/// coefficients `qs`: `k = ½ρU² C_L' a`, `c = ½ρUD C_D a`, `τ = μ_L D/U`, with
/// `a = Σ w φ²` computed here.
fn lift_root(qs: &QuasiSteady, u: f64) -> (f64, f64) {
    let a: f64 = (0..NODES).map(|i| shape(i).powi(2) / NODES as f64).sum();
    let w0 = std::f64::consts::TAU * F0;
    let k = 0.5 * RHO * u * u * qs.lift_slope * a;
    let c = 0.5 * RHO * u * D * qs.drag * a;
    characteristic_root(2.0 * ZETA * w0 + c, w0 * w0, k, qs.mu_lift * D / u)
}

fn linear_sigma(u: f64) -> f64 {
    lift_root(&QS, u).0
}

/// The run's `(σ, ω)` against the root's, within 1e-3 of each.
fn assert_rate((ms, mw): (f64, f64), (sigma, omega): (f64, f64), u: f64) {
    assert!(
        (ms - sigma).abs() <= 1e-3 * sigma.abs(),
        "U {u}: σ {ms} against {sigma}"
    );
    assert!(
        (mw - omega).abs() <= 1e-3 * omega,
        "U {u}: ω {mw} against {omega}"
    );
}

fn run_sigma(u: f64) -> f64 {
    let rows = zone_rows();
    let fe = FluidElastic::quasi_steady("zone", &QS, &nodes(&rows, u), 1);
    run_rate(fe, 2e-5, 4.0, 1.5).0
}

/// The velocity in `[lo, hi]` where `sigma` changes sign, by bisection to `1e-4` relative.
fn threshold(mut lo: f64, mut hi: f64, sigma: impl Fn(f64) -> f64) -> f64 {
    let s_lo = sigma(lo);
    assert!(s_lo * sigma(hi) < 0.0, "no sign change in [{lo}, {hi}]");
    while hi - lo > 1e-4 * hi {
        let mid = 0.5 * (lo + hi);
        if sigma(mid) * s_lo > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The first velocity below `max` where the linear σ crosses 0 (bracketed on a grid of
/// 0.01 m/s), by bisection on the linear theory and on the runs: they must agree within 1 %.
/// Returns the linear one.
fn same_threshold(max: f64, linear: impl Fn(f64) -> f64, runs: impl Fn(f64) -> f64) -> f64 {
    let grid: Vec<f64> = (1..=(max / 0.01).round() as usize)
        .map(|i| 0.01 * i as f64)
        .collect();
    let i = grid
        .windows(2)
        .position(|w| linear(w[0]) < 0.0 && linear(w[1]) > 0.0)
        .unwrap_or_else(|| panic!("an instability below {max} m/s"));
    let (lo, hi) = (grid[i], grid[i + 1]);
    let theory = threshold(lo, hi, &linear);
    let measured = threshold(lo, hi, runs);
    eprintln!("threshold: runs {measured} m/s, linear theory {theory} m/s");
    assert!(
        (measured - theory).abs() <= 0.01 * theory,
        "threshold from runs {measured} m/s against {theory} m/s"
    );
    theory
}

#[test]
fn quasi_steady_model_matches_the_linear_theory_and_its_threshold() {
    // below and above the threshold: σ and ω of the runs against the roots
    for u in [0.05, 0.3] {
        let rows = zone_rows();
        let fe = FluidElastic::quasi_steady("zone", &QS, &nodes(&rows, u), 1);
        assert_rate(run_rate(fe, 2e-5, 4.0, 1.5), lift_root(&QS, u), u);
    }
    same_threshold(0.6, linear_sigma, run_sigma);
}

/// Coefficients of a streamwise (drag-direction) instability, each direction with its own
/// delay factor: `C_D' < 0` with `μ_D` feeds a motion along the flow; the lift terms differ
/// (`C_L'`, `μ_L`) so that a test sees which ones act.
const QS_DRAG: QuasiSteady = QuasiSteady {
    lift_slope: -1.0,
    drag_slope: -3.0,
    drag: 0.5,
    mu_lift: 0.4,
    mu_drag: 1.0,
};

/// The zone's nodes for the mode `φ` along `direction` (x: along the flow, y: across it).
fn directed_nodes<'a>(rows: &'a [Vec<f64>], u: f64, qs: &QuasiSteady) -> Vec<FlowNode<'a>> {
    rows.iter()
        .map(|r| FlowNode {
            weight: 1.0 / NODES as f64,
            density: RHO,
            velocity: u,
            delay_lift: qs.mu_lift * D / u,
            delay_drag: qs.mu_drag * D / u,
            diameter: D,
            lift: Vector3::y(),
            drag: Vector3::x(),
            rows: r,
        })
        .collect()
}

/// Rows of the mode `√2 sin(πs)` along the flow (x).
fn streamwise_rows() -> Vec<Vec<f64>> {
    (0..NODES).map(|i| vec![shape(i), 0.0, 0.0]).collect()
}

/// σ of the linear theory of a mode moving along the flow: `k = ½ρU² C_D' a`,
/// `c = ρUD C_D a` (the drag's damping is twice the lift's), `τ = μ_D D/U`.
fn streamwise_sigma(u: f64) -> f64 {
    let a: f64 = (0..NODES).map(|i| shape(i).powi(2) / NODES as f64).sum();
    let w0 = std::f64::consts::TAU * F0;
    let k = 0.5 * RHO * u * u * QS_DRAG.drag_slope * a;
    let c = RHO * u * D * QS_DRAG.drag * a;
    characteristic_root(2.0 * ZETA * w0 + c, w0 * w0, k, QS_DRAG.mu_drag * D / u).0
}

fn streamwise_run_sigma(u: f64) -> f64 {
    let rows = streamwise_rows();
    let fe = FluidElastic::quasi_steady("zone", &QS_DRAG, &directed_nodes(&rows, u, &QS_DRAG), 1);
    run_rate(fe, 2e-5, 4.0, 1.5).0
}

#[test]
fn streamwise_motion_goes_unstable_at_the_drag_coefficients_threshold() {
    let linear = same_threshold(0.8, streamwise_sigma, streamwise_run_sigma);
    // the lift's coefficients alone would give another threshold: the drag's are the ones used
    let lift_sigma = |u: f64| lift_root(&QS_DRAG, u).0;
    // at the streamwise threshold the lift's theory is far from neutral (more than a tenth of
    // the structural decay rate ζω₀ away from σ = 0)
    let w0 = std::f64::consts::TAU * F0;
    assert!(
        lift_sigma(linear).abs() > 0.1 * ZETA * w0,
        "σ with the lift's coefficients {} at {linear} m/s",
        lift_sigma(linear)
    );
}

#[test]
fn motion_across_the_flow_does_not_see_the_drag_terms() {
    // the mode across the flow (y), the zone with both directions' coefficients and delays:
    // the run follows the root with the lift's coefficients and delay only
    let rows = zone_rows();
    for u in [0.1, 0.6] {
        let fe =
            FluidElastic::quasi_steady("zone", &QS_DRAG, &directed_nodes(&rows, u, &QS_DRAG), 1);
        // two delay groups; the drag's holds no stiffness for this mode
        assert_eq!(fe.delayed.len(), 2, "one group per direction's delay");
        let drag_group = fe
            .delayed
            .iter()
            .find(|g| g.delay == QS_DRAG.mu_drag * D / u)
            .unwrap();
        assert_eq!(drag_group.stiffness, ModalMatrix::Dense(vec![0.0]));
        assert_rate(run_rate(fe, 2e-5, 4.0, 1.5), lift_root(&QS_DRAG, u), u);
    }
}

#[test]
fn tabulated_coefficients_add_their_damping_and_stiffness() {
    let w0 = std::f64::consts::TAU * F0;
    let rows = zone_rows();
    let a: f64 = (0..NODES).map(|i| shape(i).powi(2) / NODES as f64).sum();
    let table = ReducedVelocityTable {
        reduced_velocity: vec![0.0, 5.0, 10.0],
        damping: vec![0.0, 2.0, -1.0],
        stiffness: vec![0.0, 50.0, -80.0],
    };
    // V_r = U/(f D) = 2.5 and 7.5: halfway along each segment of the table
    for (u, c, k) in [(0.5, 1.0, 25.0), (1.5, 0.5, -15.0)] {
        let fe = FluidElastic::tabulated("zone", &table, &nodes(&rows, u), &[F0]);
        let (ms, mw) = run_rate(fe, 2e-5, 4.0, 1.0);
        // modal added damping C = c a and stiffness K = k a: s² + (2ζω₀ + C) s + ω₀² + K = 0
        let (cm, km) = (c * a, k * a);
        let sigma = -0.5 * (2.0 * ZETA * w0 + cm);
        let omega = (w0 * w0 + km - sigma * sigma).sqrt();
        eprintln!(
            "U {u}: added decay {} against {}, frequency shift {} against {}",
            ms + ZETA * w0,
            sigma + ZETA * w0,
            mw - w0,
            omega - w0
        );
        assert!(
            (ms - sigma).abs() <= 1e-3 * (sigma + ZETA * w0).abs(),
            "U {u}: σ {ms} against {sigma}"
        );
        assert!(
            (mw - omega).abs() <= 1e-3 * (omega - w0).abs(),
            "U {u}: ω {mw} against {omega}"
        );
    }
}

/// The energy the flow feeds in is a term of the balance (THEORY §5, §13): above the
/// threshold the fluid's work is positive and the energy grows by it; below, the flow damps.
#[test]
fn energy_balance_counts_the_fluid_work() {
    let rows = zone_rows();
    let unstable = (1..=100)
        .map(|i| 0.01 * i as f64)
        .find(|u| linear_sigma(*u) > 0.3)
        .expect("a growth rate above 0.3/s below 1 m/s");
    for (u, feeds) in [(0.05, false), (unstable, true)] {
        let fe = FluidElastic::quasi_steady("zone", &QS, &nodes(&rows, u), 1);
        let r = simulate(&model(fe), &settings(2e-5, 2.0)).unwrap();
        let e = &r.energy;
        assert_eq!(
            e.fluid_work > 0.0,
            feeds,
            "U {u}: fluid work {}",
            e.fluid_work
        );
        assert_eq!(e.external_work, 0.0);
        // without the fluid's work the balance would be off by all of it
        let gap = (e.last - e.initial + e.modal_damping).abs();
        assert!(
            e.fluid_work.abs() > 0.1 * gap.max(e.initial),
            "U {u}: {e:?}"
        );
        assert!(e.relative_error < 1e-6, "U {u}: {e:?}");
    }
}

/// A run stopped and resumed from its checkpoint (the delays' past displacements with it)
/// ends bit for bit where the uninterrupted run ends.
#[test]
fn checkpoint_carries_the_delayed_displacements() {
    use fretdyn::integrator::simulation::{Simulation, Snapshot};
    let rows = zone_rows();
    let fe = FluidElastic::quasi_steady("zone", &QS, &nodes(&rows, 0.4), 1);
    let m = model(fe);
    let s = settings(2e-5, 0.2);
    let mut whole = Simulation::new(&m, &s).unwrap();
    for _ in 0..s.steps {
        whole.step().unwrap();
    }
    let mut first = Simulation::new(&m, &s).unwrap();
    // stopped at a step that is not a multiple of the delay's steps
    for _ in 0..3_333 {
        first.step().unwrap();
    }
    let bytes = first.snapshot().to_bytes();
    let snapshot = Snapshot::from_bytes(&bytes).unwrap();
    let mut second = Simulation::resume(&m, &s, snapshot, 16).unwrap();
    for _ in 3_333..s.steps {
        second.step().unwrap();
    }
    // the state, the delays' past displacements, the statistics and the energy balance
    assert_eq!(whole.snapshot().to_bytes(), second.snapshot().to_bytes());
}

/// The tube of examples/tube_fluid_elastic.toml above the fluid-elastic threshold: the
/// supports bound the motion (each plate's radial displacement stays within its clearance
/// plus the largest penetration) while the flow feeds energy in, and the wear work rate is
/// far above the one without the delayed lift stiffness (C_L' = 0): the jump of the curve
/// in docs/FLOW.md.
#[test]
fn supports_bound_the_motion_above_the_threshold() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(dir.join("tube_fluid_elastic.toml")).unwrap();
    let case = |lift_slope: f64| {
        let t = text
            .replace("duration = 3.0", "duration = 1.5")
            .replace("t_start = 1.0", "t_start = 0.5")
            .replace("velocity = 1.5", "velocity = 2.5")
            .replace("lift_slope = -3.0", &format!("lift_slope = {lift_slope:?}"));
        fretdyn::Case::from_toml_str(&t, &dir).unwrap()
    };
    let run = |c: &fretdyn::Case| simulate(&c.model, &c.settings).unwrap();
    let unstable = run(&case(-3.0));
    let quiet = run(&case(0.0));
    assert!(unstable.energy.fluid_work > 0.0, "{:?}", unstable.energy);
    assert!(quiet.energy.fluid_work < 0.0, "{:?}", quiet.energy);
    let clearance = 2e-4;
    for (a, b) in unstable.contacts.iter().zip(&quiet.contacts) {
        assert!(
            a.displacement_max <= clearance + a.penetration_max + 1e-12,
            "{}: {} m",
            a.name,
            a.displacement_max
        );
        assert!(a.displacement_max > 0.99 * clearance, "{} rattles", a.name);
        assert!(
            a.wear_work_rate > 5.0 * b.wear_work_rate,
            "{}: {} W against {} W",
            a.name,
            a.wear_work_rate,
            b.wear_work_rate
        );
    }
}

/// The stable time step counts the explicit fluid forces (THEORY §13): a fluid stiffness of
/// 3 ω₀² (bound added to ω₀²) halves the limit `2/ω`, and a Δt between the two limits is
/// refused with the new limit; bad matrices are refused naming the group.
#[test]
fn stable_time_step_and_bad_input_count_the_fluid_forces() {
    use fretdyn::integrator::simulation::Simulation;
    let w0 = std::f64::consts::TAU * F0;
    let alone = Simulation::check(&model(delayed(0.0, 0.0, 0.0)), &settings(1e-5, 0.01)).unwrap();
    let stiff = delayed(-3.0 * w0 * w0, 0.01, 0.0);
    let limit = Simulation::check(&model(stiff.clone()), &settings(1e-5, 0.01)).unwrap();
    assert!((alone / limit - 2.0).abs() < 1e-3, "{alone} {limit}");
    let between = 0.75 * alone;
    let err = Simulation::check(&model(stiff), &settings(between, 0.01)).unwrap_err();
    assert!(err.to_string().contains("fluid-elastic forces"), "{err}");
    let mut nan = delayed(1.0, 0.01, 0.0);
    nan.delayed[0].stiffness = ModalMatrix::Dense(vec![f64::NAN]);
    let err = Simulation::check(&model(nan), &settings(1e-5, 0.01)).unwrap_err();
    assert_eq!(err.field(), Some("test"), "{err}");
    let mut wrong = delayed(1.0, 0.01, 0.0);
    wrong.delayed[0].delay = -1.0;
    let err = Simulation::check(&model(wrong), &settings(1e-5, 0.01)).unwrap_err();
    assert_eq!(err.field(), Some("test.delay"), "{err}");
}
