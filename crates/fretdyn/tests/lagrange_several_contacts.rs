//! Several contacts at once (THEORY §4.2–§4.6): the two Lagrange solvers on a rattling tube,
//! one step's tangential problem solved by both and checked against the Coulomb conditions and
//! an independent projected-gradient solution of the convex problem, and the stability limit
//! of central differences (THEORY §2).

use std::ops::ControlFlow;

use fretdyn::accumulate::statistics::ContactStatistics;
use fretdyn::apps::benchmark::rattling_tube;
use fretdyn::contact::delassus::{Slot, TangentialProblem};
use fretdyn::contact::friction::Slide;
use fretdyn::contact::tangential::active_set::{ActiveSet, History, Outcome};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, LocalSolve, PenaltySettings, SolverStatistics,
    TangentialMethod, gauss_seidel,
};
use fretdyn::integrator::simulation::{RunResults, Termination, run, simulate};
use nalgebra::{DMatrix, DVector, Vector2, Vector3};

// ---------------------------------------------------------------------------------------------
// Rattling tube: 10 modes, 4 point–plane supports, μ_s = μ_d (convex per-step problem).
// ---------------------------------------------------------------------------------------------

/// Long enough that the statistics are averaged over ~2000 impacts per support (see
/// `gauss_seidel_and_active_set_give_the_same_wear_statistics`).
const TUBE_STEPS: u64 = 80_000;

fn tube(method: TangentialMethod, steps: u64) -> RunResults {
    let case = rattling_tube(10, 4, method, steps);
    assert_eq!(case.model.contacts.len(), 4);
    assert_eq!(case.model.basis.modes(), 10);
    for c in &case.model.contacts {
        assert_eq!(c.friction.mu_static, c.friction.mu_dynamic);
    }
    simulate(&case.model, &case.settings).expect("the benchmark case is valid")
}

fn gs() -> TangentialMethod {
    TangentialMethod::GaussSeidel(GaussSeidelSettings::default())
}

fn active_set() -> TangentialMethod {
    TangentialMethod::ActiveSet(ActiveSetSettings::default())
}

fn assert_sane_tube_run(label: &str, r: &RunResults, steps: u64) {
    assert_eq!(r.termination, Termination::Completed, "{label}");
    assert_eq!(r.steps, steps, "{label}");
    let rec = &r.recorder;
    for (name, finite) in [
        ("normal", rec.normal_force.iter().all(|v| v.is_finite())),
        (
            "tangential",
            rec.tangential_force.iter().all(|v| v.is_finite()),
        ),
        (
            "slip velocity",
            rec.slip_velocity.iter().all(|v| v.is_finite()),
        ),
        ("q", rec.q.iter().all(|v| v.is_finite())),
        ("qdot", rec.qdot.iter().all(|v| v.is_finite())),
    ] {
        assert!(finite, "{label}: non-finite recorded {name}");
    }
    // Coulomb holds at every recorded sample: |R_T| ≤ μ R_N (μ = 0.3), no force when open.
    for i in 0..rec.len() {
        for c in 0..4 {
            let rn = rec.normal_force[[i, c]];
            let rt = rec.tangential_force[[i, c, 0]].hypot(rec.tangential_force[[i, c, 1]]);
            assert!(
                rt <= 0.3 * rn * (1.0 + 1e-9) + 1e-12,
                "{label}: contact {c} at t = {}: |R_T| = {rt} > μ R_N = {}",
                rec.t[i],
                0.3 * rn
            );
            if rec.status[[i, c]] == 0 {
                assert_eq!(rn, 0.0);
                assert_eq!(rt, 0.0);
            }
        }
    }
    // every support is hit, and both sticks and slips
    for c in &r.contacts {
        assert!(
            c.impacts > 100,
            "{label}: {} has {} impacts",
            c.name,
            c.impacts
        );
        assert!(
            c.stick_time_fraction > 0.0 && c.slip_time_fraction > 0.0,
            "{label}: {c:?}"
        );
        assert!(c.wear_work_rate > 0.0, "{label}: {c:?}");
    }
    assert_eq!(r.solver.gs_nonconverged_steps, 0, "{label}: {:?}", r.solver);
    assert!(
        r.solver.lagrange_steps > steps / 2,
        "{label}: {:?}",
        r.solver
    );
}

/// The two Lagrange solvers solve the same convex problem at every step. The rattling is
/// chaotic — round-off differences of 1e-12 grow by ~1e3 every 250 steps, so even two
/// Gauss–Seidel runs with tolerances 1e-12 and 1e-14 part ways after a few thousand steps —
/// hence the comparison is (a) of the trajectories over the first steps, before the divergence
/// has grown, and (b) of the per-contact statistics over the long run, which must agree
/// within their sampling error.
///
/// The sampling error of a chaotic run's statistic is measured by batch means: the run is cut
/// into 20 blocks (fretdyn's block statistics), whose spread gives the standard error of the
/// window's mean, `σ/√20`. The two solvers' wear rates and contact fractions must agree within
/// 4 combined standard errors (a false alarm about once in 16 000 comparisons). A fixed 5 %
/// bound is not a property of the solvers: measured, the differences are 0.3–6 % over
/// 1 600 000 steps (29 s simulated, ~7 000 impacts), and which contact shows 6 % moves with the
/// round-off of the kernels. Too long for a debug build, so this test runs with `--release`
/// (the README's test command).
/// One number of a contact's statistics.
type Statistic = fn(&ContactStatistics) -> f64;

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "long run (1 600 000 steps): run with cargo test --release"
)]
fn gauss_seidel_and_active_set_give_the_same_wear_statistics() {
    const STEPS: u64 = 1_600_000;
    const BLOCKS: f64 = 20.0;
    let run = |method| {
        let mut case = rattling_tube(10, 4, method, STEPS);
        case.settings.statistics.block = Some(STEPS as f64 * case.settings.dt / BLOCKS);
        simulate(&case.model, &case.settings).expect("the benchmark case is valid")
    };
    let a = run(gs());
    let b = run(active_set());
    assert_sane_tube_run("gauss_seidel", &a, STEPS);
    assert_sane_tube_run("active_set", &b, STEPS);
    let s = &b.solver;
    assert_eq!(s.as_fallbacks, s.as_cycles + s.as_iteration_limit, "{s:?}");
    assert!(s.as_iterations_total >= s.lagrange_steps, "{s:?}");

    // standard error of the window's mean of `value` from the block means (batch means)
    let standard_error = |r: &RunResults, name: &str, value: Statistic| {
        let x: Vec<f64> = r
            .blocks
            .iter()
            .filter(|b| b.statistics.name == name)
            .map(|b| value(&b.statistics))
            .collect();
        assert_eq!(x.len(), BLOCKS as usize, "{name}: blocks");
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (var / n).sqrt()
    };
    let mut report = Vec::new();
    let mut worst = 0.0f64;
    for (ca, cb) in a.contacts.iter().zip(&b.contacts) {
        assert_eq!(ca.name, cb.name);
        let quantities: [(&str, Statistic); 2] = [
            ("wear rate (W)", |c| c.wear_work_rate),
            ("contact fraction", |c| c.contact_time_fraction),
        ];
        for (what, value) in quantities {
            let (x, y) = (value(ca), value(cb));
            let se = standard_error(&a, &ca.name, value).hypot(standard_error(&b, &cb.name, value));
            assert!(se > 0.0, "{}: no spread between blocks", ca.name);
            let z = (x - y).abs() / se;
            worst = worst.max(z);
            report.push(format!(
                "{} {what}: {x:.5e} vs {y:.5e} ({:.2} %), {z:.2} standard errors",
                ca.name,
                100.0 * (x - y).abs() / x.abs().max(y.abs())
            ));
        }
    }
    assert!(
        worst <= 4.0,
        "GS vs AS statistics differ by more than 4 standard errors:\n{}",
        report.join("\n")
    );
}

/// Over the first steps (several impacts, with stick and slip) the trajectories coincide.
#[test]
fn gauss_seidel_and_active_set_trajectories_coincide_before_chaos_sets_in() {
    const STEPS: u64 = 300;
    let runs: Vec<RunResults> = [gs(), active_set()]
        .into_iter()
        .map(|m| {
            let mut case = rattling_tube(10, 4, m, STEPS);
            case.settings.output_every = 1;
            simulate(&case.model, &case.settings).unwrap()
        })
        .collect();
    let (a, b) = (&runs[0].recorder, &runs[1].recorder);
    assert_eq!(a.len(), STEPS as usize + 1);
    let statuses: Vec<i8> = a.status.iter().copied().collect();
    assert!(
        statuses.contains(&1) && statuses.contains(&2),
        "no stick and slip in {STEPS} steps"
    );
    let qmax = a.q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let fmax = a
        .tangential_force
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(fmax > 0.0);
    for i in 0..a.len() {
        for k in 0..10 {
            let d = (a.q[[i, k]] - b.q[[i, k]]).abs();
            assert!(
                d <= 1e-8 * qmax,
                "step {i}, mode {k}: q differs by {d:e} (max |q| {qmax:e})"
            );
        }
        for c in 0..4 {
            for j in 0..2 {
                let d = (a.tangential_force[[i, c, j]] - b.tangential_force[[i, c, j]]).abs();
                assert!(
                    d <= 1e-6 * fmax,
                    "step {i}, contact {c}: R_T differs by {d:e}"
                );
            }
        }
    }
}

/// THEORY §4.3 asks that cycles be detected and counted and that a fallback finish the step;
/// the target is that such steps stay rare (< 0.1 %) on a convex (μ_s = μ_d) problem.
#[test]
fn active_set_fallbacks_are_rare_on_the_rattling_tube() {
    let r = tube(active_set(), TUBE_STEPS);
    let s = &r.solver;
    assert_eq!(s.as_fallbacks, s.as_cycles + s.as_iteration_limit, "{s:?}");
    assert!(
        (s.as_fallbacks as f64) < 1e-3 * s.lagrange_steps as f64,
        "{} fallbacks ({} cycles) in {} Lagrange steps ({:.3} %)",
        s.as_fallbacks,
        s.as_cycles,
        s.lagrange_steps,
        100.0 * s.as_fallbacks as f64 / s.lagrange_steps as f64
    );
}

// ---------------------------------------------------------------------------------------------
// One step's tangential problem, by hand.
// ---------------------------------------------------------------------------------------------

/// Tiny deterministic LCG (Knuth's MMIX constants), uniform in [-1, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    fn vec3(&mut self) -> Vector3<f64> {
        Vector3::new(self.next(), self.next(), self.next())
    }
}

/// A hand-built problem: its data, so that the tests can recompute everything independently.
struct Hand {
    problem: TangentialProblem,
    /// `L` (2m × p), rows `t_aᵀ Φ_c`.
    l: DMatrix<f64>,
    /// `g` such that `b = L g` (a_inv = 1, θΔt = 1, no obstacle motion).
    g: DVector<f64>,
    s: Vec<f64>,
}

/// `contacts` contacts on `p` modes; `factors[k]` × |unconstrained λ_k| is contact k's
/// friction threshold (small → slip, large → stick).
fn hand_problem(seed: u64, p: usize, contacts: usize, factors: &[f64]) -> Hand {
    hand_problem_with(seed, p, contacts, factors, false)
}

/// As [`hand_problem`]; with `redundant`, contact 1 is contact 0 again (same point, same
/// tangent plane: two obstacles acting on one point in the same directions, THEORY §4.6).
fn hand_problem_with(
    seed: u64,
    p: usize,
    contacts: usize,
    factors: &[f64],
    redundant: bool,
) -> Hand {
    let mut rng = Lcg(seed);
    let mut problem = TangentialProblem::new(p, contacts);
    let a_inv = vec![1.0; p];
    let mut l = DMatrix::<f64>::zeros(2 * contacts, p);
    let mut pushed: Vec<([Vector3<f64>; 2], Vec<f64>)> = Vec::new();
    for k in 0..contacts {
        if redundant && k == 1 {
            let (tangents, rows) = pushed[0].clone();
            for r in 0..2 {
                for i in 0..p {
                    l[(2 + r, i)] = l[(r, i)];
                }
            }
            pushed.push((tangents, rows));
            continue;
        }
        let rows: Vec<f64> = (0..3 * p).map(|_| rng.next()).collect();
        let n = rng.vec3().normalize();
        let t1 = {
            let t = rng.vec3();
            (t - n * n.dot(&t)).normalize()
        };
        let t2 = n.cross(&t1);
        let tangents = [t1, t2];
        for (a, t) in tangents.iter().enumerate() {
            assert!((t.norm() - 1.0).abs() < 1e-14 && t.dot(&n).abs() < 1e-14);
            for i in 0..p {
                l[(2 * k + a, i)] = t.x * rows[i] + t.y * rows[p + i] + t.z * rows[2 * p + i];
            }
        }
        assert!(t1.dot(&t2).abs() < 1e-14);
        pushed.push((tangents, rows));
    }
    let qdd_free: Vec<f64> = (0..p).map(|_| rng.next()).collect();
    let qd_star: Vec<f64> = (0..p).map(|_| rng.next()).collect();
    let g = DVector::from_iterator(p, qdd_free.iter().zip(&qd_star).map(|(a, b)| a + b));
    // thresholds from the unconstrained solution (least squares if H is singular)
    let h = &l * l.transpose();
    let b = &l * &g;
    let free = h.clone().pseudo_inverse(1e-12).unwrap() * &b;
    let s: Vec<f64> = (0..contacts)
        .map(|k| factors[k] * free.rows(2 * k, 2).norm())
        .collect();
    for (k, (tangents, rows)) in pushed.iter().enumerate() {
        problem.push(
            Slot {
                contact: k,
                s_static: s[k],
                s_dynamic: s[k],
            },
            tangents,
            rows,
            &a_inv,
        );
    }
    problem.assemble(&qdd_free, &qd_star, 1.0, |_| Vector2::zeros());
    // the library's H and b are L Lᵀ and L g
    for r in 0..2 * contacts {
        assert!((problem.rhs(r / 2)[r % 2] - b[r]).abs() <= 1e-12 * b.amax());
        for c in 0..2 * contacts {
            assert!((problem.h(r, c) - h[(r, c)]).abs() <= 1e-12 * h.amax());
        }
    }
    Hand { problem, l, g, s }
}

fn objective(hand: &Hand, lambda: &DVector<f64>) -> f64 {
    let h = &hand.l * hand.l.transpose();
    let b = &hand.l * &hand.g;
    0.5 * lambda.dot(&(&h * lambda)) - b.dot(lambda)
}

fn to_dvector(lambda: &[Vector2<f64>]) -> DVector<f64> {
    DVector::from_iterator(2 * lambda.len(), lambda.iter().flat_map(|v| [v.x, v.y]))
}

/// Projects each 2-block onto its disk `|λ_k| ≤ s_k`.
fn project(lambda: &mut DVector<f64>, s: &[f64]) {
    for (k, &sk) in s.iter().enumerate() {
        let n = lambda[2 * k].hypot(lambda[2 * k + 1]);
        if n > sk {
            lambda[2 * k] *= sk / n;
            lambda[2 * k + 1] *= sk / n;
        }
    }
}

/// Independent solution of `min ½λᵀHλ − bᵀλ, |λ_k| ≤ s_k` by accelerated projected gradient
/// (FISTA with adaptive restart), H = L Lᵀ built here.
fn projected_gradient(hand: &Hand) -> DVector<f64> {
    let h = &hand.l * hand.l.transpose();
    let b = &hand.l * &hand.g;
    let lmax = h.clone().symmetric_eigen().eigenvalues.max();
    let step = 1.0 / lmax;
    let n = b.len();
    let mut x = DVector::zeros(n);
    let mut y = x.clone();
    let mut t = 1.0f64;
    for _ in 0..2_000_000 {
        let mut xn = &y - (&h * &y - &b) * step;
        project(&mut xn, &hand.s);
        let tn = 0.5 * (1.0 + (1.0 + 4.0 * t * t).sqrt());
        let dx = &xn - &x;
        // restart the momentum when it points uphill
        if (&y - &xn).dot(&dx) > 0.0 {
            t = 1.0;
            y = xn.clone();
        } else {
            y = &xn + &dx * ((t - 1.0) / tn);
            t = tn;
        }
        let done = dx.norm() <= 1e-15 * xn.norm().max(1e-300);
        x = xn;
        if done {
            break;
        }
    }
    x
}

/// Coulomb conditions (THEORY §4.2) with `w = b − Hλ`: stick (`w = 0`, `|λ| ≤ s`) or slip
/// (`|λ| = s`, `λ ∥ w`, `λ·w > 0`). Returns the statuses found.
fn assert_coulomb(label: &str, hand: &Hand, lambda: &[Vector2<f64>]) -> Vec<Slide> {
    let bscale = (&hand.l * &hand.g).amax();
    let mut statuses = Vec::new();
    for (k, lam) in lambda.iter().enumerate() {
        let w = hand.problem.residual_velocity(k, lambda);
        let s = hand.s[k];
        assert!(
            lam.norm() <= s * (1.0 + 1e-12),
            "{label}: |λ_{k}| = {} > s = {s}",
            lam.norm()
        );
        if w.norm() <= 1e-9 * bscale {
            statuses.push(Slide::Stick);
        } else {
            assert!(
                (lam.norm() - s).abs() <= 1e-10 * s,
                "{label}: contact {k} slides (|w| = {:e}) but |λ| = {} ≠ s = {s}",
                w.norm(),
                lam.norm()
            );
            let cross = lam.x * w.y - lam.y * w.x;
            assert!(
                cross.abs() <= 1e-8 * lam.norm() * w.norm(),
                "{label}: contact {k}: λ = {lam:?} not parallel to w = {w:?}"
            );
            assert!(lam.dot(&w) > 0.0, "{label}: contact {k}: λ·w ≤ 0");
            statuses.push(Slide::Slip);
        }
    }
    statuses
}

fn solve_gs(problem: &TangentialProblem) -> Vec<Vector2<f64>> {
    let m = problem.len();
    let mut lambda = vec![Vector2::zeros(); m];
    let mut slide = vec![Slide::Stick; m];
    let settings = GaussSeidelSettings {
        tolerance: 1e-14,
        max_sweeps: 100_000,
        ..GaussSeidelSettings::default()
    };
    let sweeps = gauss_seidel::solve(&settings, problem, &mut lambda, &mut slide);
    assert!(
        sweeps.converged,
        "Gauss–Seidel did not converge: {sweeps:?}"
    );
    // converged means both tests passed: the residual it reports is that of its λ (formed
    // from the last sweep's local problems: the same up to the order of the sums)
    let residual = problem.natural_map_residual(&lambda, &slide);
    let reported = sweeps
        .residual
        .expect("a converged solve reports its residual");
    assert!(
        (reported - residual).abs() <= 1e-13,
        "{reported:e} vs {residual:e}"
    );
    assert!(residual <= settings.residual_tolerance, "{residual}");
    lambda
}

fn solve_active_set(
    problem: &TangentialProblem,
    history: &[History],
) -> (Vec<Vector2<f64>>, Vec<Slide>, Outcome, SolverStatistics) {
    let m = problem.len();
    let mut solver = ActiveSet::new(ActiveSetSettings::default(), m);
    let mut lambda = vec![Vector2::zeros(); m];
    let mut slide = vec![Slide::Stick; m];
    let mut stats = SolverStatistics::default();
    let outcome = solver.solve(problem, history, &mut lambda, &mut slide, &mut stats);
    (lambda, slide, outcome, stats)
}

/// The residual Gauss–Seidel reports is formed from its last sweep's local right-hand sides
/// and changes (THEORY §4.6): after a single sweep from λ = 0 (far from the solution, every λ
/// changed) it must still be the natural-map residual of the λ it returns, formed from
/// `b − Hλ` directly.
#[test]
fn residual_from_the_last_sweep_is_the_natural_map_residual() {
    let hand = hand_problem(0x5eed_0001, 8, 3, &[3.0, 0.2, 0.05]);
    for local_solve in [LocalSolve::Exact, LocalSolve::Radial] {
        let problem = &hand.problem;
        let m = problem.len();
        let mut lambda = vec![Vector2::zeros(); m];
        let mut slide = vec![Slide::Stick; m];
        // the change test passes at once: the residual is evaluated after the first sweep
        let settings = GaussSeidelSettings {
            tolerance: 1e300,
            max_sweeps: 1,
            local_solve,
            ..GaussSeidelSettings::default()
        };
        let sweeps = gauss_seidel::solve(&settings, problem, &mut lambda, &mut slide);
        let reported = sweeps.residual.expect("the change test passed");
        let direct = problem.natural_map_residual(&lambda, &slide);
        assert!(
            direct > 1e-3,
            "{local_solve:?}: one sweep should be far from the solution"
        );
        assert!(
            (reported - direct).abs() <= 1e-13 * direct,
            "{local_solve:?}: {reported:e} vs {direct:e}"
        );
    }
}

/// The residual the Active Set reports is formed with the sliding contacts' right-hand sides
/// of its last iteration: it must be the natural-map residual of the λ it returns, formed from
/// `b − Hλ` directly, bit for bit — on 3-contact problems of mixed statuses (from a cold
/// history; the iteration bound 1 leaves only the problems solved at once converged).
#[test]
fn active_set_residual_is_the_natural_map_residual() {
    let mut slips = 0;
    for seed in 0..3u64 {
        for factors in [[3.0, 0.2, 0.05], [0.3, 0.2, 0.1], [3.0, 2.0, 1.5]] {
            let hand = hand_problem(0x5eed_0100 + seed, 8, 3, &factors);
            let problem = &hand.problem;
            let m = problem.len();
            for iterations in [1, ActiveSetSettings::default().max_iterations] {
                let settings = ActiveSetSettings {
                    max_iterations: iterations,
                    ..ActiveSetSettings::default()
                };
                let mut solver = ActiveSet::new(settings, m);
                let mut lambda = vec![Vector2::zeros(); m];
                let mut slide = vec![Slide::Stick; m];
                let mut stats = SolverStatistics::default();
                let history = vec![History::default(); m];
                let outcome = solver.solve(problem, &history, &mut lambda, &mut slide, &mut stats);
                if !matches!(outcome, Outcome::Converged(_)) {
                    continue;
                }
                slips += slide.iter().filter(|&&s| s == Slide::Slip).count();
                let reported = solver.residual(problem, &lambda, &slide);
                let direct = problem.natural_map_residual(&lambda, &slide);
                assert_eq!(
                    reported.to_bits(),
                    direct.to_bits(),
                    "seed {seed}, {factors:?}: {reported:e} vs {direct:e}"
                );
            }
        }
    }
    assert!(
        slips > 0,
        "no sliding contact: the recorded right-hand sides untested"
    );
}

#[test]
fn one_step_problem_gauss_seidel_active_set_and_projected_gradient_agree() {
    // 3 contacts, 6 unknowns; p = 8 modes so that L has full row rank and H is SPD (with
    // p = 5 < 6 H is singular: see the next test).
    let hand = hand_problem(0x5eed_0001, 8, 3, &[3.0, 0.2, 0.05]);
    let h = &hand.l * hand.l.transpose();
    let eig = h.clone().symmetric_eigen().eigenvalues;
    assert!(eig.min() > 1e-6 * eig.max(), "H should be SPD: {eig:?}");

    let lg = solve_gs(&hand.problem);
    let (la, slide_a, outcome, stats) = solve_active_set(&hand.problem, &[History::default(); 3]);
    assert!(
        matches!(outcome, Outcome::Converged(_)),
        "{outcome:?} {stats:?}"
    );
    let sg = assert_coulomb("gauss_seidel", &hand, &lg);
    let sa = assert_coulomb("active_set", &hand, &la);
    assert_eq!(sg, sa);
    assert_eq!(slide_a, sa, "Active Set statuses vs Coulomb conditions");
    assert!(
        sg.contains(&Slide::Stick) && sg.contains(&Slide::Slip),
        "test data should mix stick and slip: {sg:?}"
    );

    let (xg, xa) = (to_dvector(&lg), to_dvector(&la));
    let scale = xg.norm();
    assert!((&xg - &xa).norm() <= 1e-8 * scale, "GS {xg} vs AS {xa}");
    let xp = projected_gradient(&hand);
    assert!(
        (&xg - &xp).norm() <= 1e-8 * scale,
        "GS {xg} vs projected gradient {xp}"
    );

    // global optimality against random feasible points, local against small perturbations
    let f_star = objective(&hand, &xg);
    let fscale = f_star.abs() + (&hand.l * &hand.g).norm() * scale;
    let mut rng = Lcg(42);
    for _ in 0..20_000 {
        let mut x = DVector::zeros(6);
        for k in 0..3 {
            // uniform in the disk
            let r = hand.s[k] * (0.5 * (rng.next() + 1.0)).sqrt();
            let a = std::f64::consts::PI * rng.next();
            x[2 * k] = r * a.cos();
            x[2 * k + 1] = r * a.sin();
        }
        let f = objective(&hand, &x);
        assert!(
            f >= f_star - 1e-12 * fscale,
            "random feasible point {x} beats the solution"
        );
    }
    for i in 0..20_000 {
        let eps = 10f64.powf(-2.0 - 3.0 * (i as f64 / 20_000.0));
        let mut x = xg.clone();
        for k in 0..6 {
            x[k] += eps * hand.s[k / 2] * rng.next();
        }
        project(&mut x, &hand.s);
        let f = objective(&hand, &x);
        assert!(
            f >= f_star - 1e-12 * fscale,
            "perturbation of size {eps:e} lowers the objective: {f} < {f_star}"
        );
    }
}

/// THEORY §4.6: with p = 5 modes and 3 contacts (6 unknowns) H = L Lᵀ is singular; λ is not
/// unique but the modal force Lᵀλ is (with a_inv = 1, Lᵀλ is the projection of g on a convex
/// set). Both solvers must satisfy Coulomb and give the same modal force.
#[test]
fn one_step_problem_with_singular_delassus_gives_unique_modal_forces() {
    let hand = hand_problem(0x5eed_0002, 5, 3, &[3.0, 0.2, 0.05]);
    let h = &hand.l * hand.l.transpose();
    let eig = h.clone().symmetric_eigen().eigenvalues;
    assert!(
        eig.min().abs() < 1e-12 * eig.max(),
        "H should be singular: {eig:?}"
    );

    let lg = solve_gs(&hand.problem);
    let (la, _, outcome, stats) = solve_active_set(&hand.problem, &[History::default(); 3]);
    let sg = assert_coulomb("gauss_seidel", &hand, &lg);
    let sa = assert_coulomb("active_set", &hand, &la);
    assert_eq!(sg, sa);
    assert!(
        matches!(outcome, Outcome::Converged(_)),
        "{outcome:?} {stats:?}"
    );
    let (xg, xa) = (to_dvector(&lg), to_dvector(&la));
    let fg = hand.l.transpose() * &xg;
    let fa = hand.l.transpose() * &xa;
    assert!(
        (&fg - &fa).norm() <= 1e-8 * fg.norm(),
        "Lᵀλ: GS {fg} vs AS {fa}"
    );
    let xp = projected_gradient(&hand);
    let fp = hand.l.transpose() * &xp;
    assert!(
        (&fg - &fp).norm() <= 1e-7 * fg.norm(),
        "Lᵀλ: GS {fg} vs projected gradient {fp}"
    );
}

/// THEORY §4.6: two contacts on the same point with the same tangent plane, both sticking:
/// H_SS is singular, the Active Set must say so (and regularise), and the modal force is
/// still unique and the same as Gauss–Seidel's.
#[test]
fn one_step_problem_with_redundant_contacts_is_flagged_singular_and_solved() {
    let hand = hand_problem_with(0x5eed_0003, 8, 3, &[3.0, 3.0, 0.05], true);
    let lg = solve_gs(&hand.problem);
    let (la, _, outcome, stats) = solve_active_set(&hand.problem, &[History::default(); 3]);
    let sg = assert_coulomb("gauss_seidel", &hand, &lg);
    let sa = assert_coulomb("active_set", &hand, &la);
    assert_eq!(sg, sa);
    assert_eq!(
        sa,
        vec![Slide::Stick, Slide::Stick, Slide::Slip],
        "test data"
    );
    assert!(stats.singular_delassus > 0, "{outcome:?} {stats:?}");
    // the redundant pair only acts through λ_0 + λ_1
    let fg = hand.l.transpose() * to_dvector(&lg);
    let fa = hand.l.transpose() * to_dvector(&la);
    assert!(
        (&fg - &fa).norm() <= 1e-8 * fg.norm(),
        "Lᵀλ: GS {fg} vs AS {fa}"
    );
    assert!(((lg[0] + lg[1]) - (la[0] + la[1])).norm() <= 1e-8 * fg.norm());
    assert!((lg[2] - la[2]).norm() <= 1e-8 * hand.s[2]);
}

/// One contact that was sliding along +x at the previous step and whose free velocity now
/// points the other way, with a friction disk too small to stop it: the answer is slip along
/// the new velocity, which the Active Set reaches after a stick guess.
fn reversal_problem() -> (Hand, Vec<History>) {
    // p = 2, a point whose two tangents see one mode each: H = diag(1, 1)
    let mut problem = TangentialProblem::new(2, 1);
    let rows = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0]; // x row, y row, z row
    let tangents = [Vector3::x(), Vector3::y()];
    let s = 1.0;
    problem.push(
        Slot {
            contact: 0,
            s_static: s,
            s_dynamic: s,
        },
        &tangents,
        &rows,
        &[1.0, 1.0],
    );
    let g = [-5.0, 0.3];
    problem.assemble(&g, &[0.0, 0.0], 1.0, |_| Vector2::zeros());
    let l = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.0]);
    let history = vec![History {
        closed: true,
        slide: Slide::Slip,
        direction: Vector2::x(),
    }];
    (
        Hand {
            problem,
            l,
            g: DVector::from_column_slice(&g),
            s: vec![s],
        },
        history,
    )
}

#[test]
fn active_set_single_contact_slip_reversal_gives_the_coulomb_solution() {
    let (hand, history) = reversal_problem();
    let (la, slide, _, _) = solve_active_set(&hand.problem, &history);
    assert_eq!(assert_coulomb("active_set", &hand, &la), vec![Slide::Slip]);
    assert_eq!(slide, vec![Slide::Slip]);
    let b: Vector2<f64> = Vector2::new(-5.0, 0.3);
    assert!((la[0] - b / b.norm()).norm() < 1e-12, "λ = {:?}", la[0]);
}

#[test]
fn active_set_single_contact_slip_reversal_is_not_a_cycle() {
    let (hand, history) = reversal_problem();
    let (_, _, outcome, stats) = solve_active_set(&hand.problem, &history);
    assert!(matches!(outcome, Outcome::Converged(_)), "{outcome:?}");
    assert_eq!(stats.as_cycles, 0, "{stats:?}");
}

/// One contact with an anisotropic diagonal block `H = diag(1, 4)` that slides: the exact
/// solution is `λ = s u`, `(sH + tI) u = b`, `t = |w| > 0` (what GS's exact local solve finds).
fn anisotropic_problem(s: f64) -> Hand {
    let mut problem = TangentialProblem::new(2, 1);
    let rows = [1.0, 0.0, 0.0, 2.0, 0.0, 0.0]; // x row, y row, z row: L = diag(1, 2)
    problem.push(
        Slot {
            contact: 0,
            s_static: s,
            s_dynamic: s,
        },
        &[Vector3::x(), Vector3::y()],
        &rows,
        &[1.0, 1.0],
    );
    let g = [3.0, 1.0];
    problem.assemble(&g, &[0.0, 0.0], 1.0, |_| Vector2::zeros());
    Hand {
        problem,
        l: DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 2.0]),
        g: DVector::from_column_slice(&g),
        s: vec![s],
    }
}

const ANISOTROPIC_S: [f64; 4] = [0.5, 1.0, 2.5, 2.9];

#[test]
fn active_set_single_anisotropic_contact_gives_the_coulomb_solution() {
    for s in ANISOTROPIC_S {
        let hand = anisotropic_problem(s);
        let (la, slide, _, _) = solve_active_set(&hand.problem, &[History::default()]);
        assert_eq!(assert_coulomb("active_set", &hand, &la), vec![Slide::Slip]);
        assert_eq!(slide, vec![Slide::Slip]);
        // the secular equation Σ b_k²/(s h_k + t)² = 1 for t = |w|, solved here by bisection
        let (b, h) = ([3.0, 2.0], [1.0, 4.0]);
        let norm_u =
            |t: f64| ((b[0] / (s * h[0] + t)).powi(2) + (b[1] / (s * h[1] + t)).powi(2)).sqrt();
        let (mut lo, mut hi) = (0.0, 10.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if norm_u(mid) > 1.0 {
                lo = mid
            } else {
                hi = mid
            }
        }
        let t = 0.5 * (lo + hi);
        let exact = Vector2::new(b[0] / (s * h[0] + t), b[1] / (s * h[1] + t)) * s;
        assert!(
            (la[0] - exact).norm() <= 1e-10 * s,
            "s = {s}: λ = {:?}, exact {exact:?}",
            la[0]
        );
    }
}

#[test]
fn active_set_converges_on_a_single_anisotropic_contact() {
    for s in ANISOTROPIC_S {
        let hand = anisotropic_problem(s);
        let (_, _, outcome, stats) = solve_active_set(&hand.problem, &[History::default()]);
        assert!(
            matches!(outcome, Outcome::Converged(_)),
            "s = {s}: {outcome:?} {stats:?}"
        );
    }
}

/// Same data as the main cross-check but with contacts sliding slowly (|w| small against
/// μ R_N |H|): the Active Set needs its fallback, and the answer must still be Coulomb's.
#[test]
fn one_step_problem_with_slow_slip_still_gives_the_coulomb_solution() {
    let hand = hand_problem(0x5eed_0001, 8, 3, &[3.0, 0.5, 0.15]);
    let lg = solve_gs(&hand.problem);
    let (la, _, outcome, stats) = solve_active_set(&hand.problem, &[History::default(); 3]);
    let sg = assert_coulomb("gauss_seidel", &hand, &lg);
    let sa = assert_coulomb("active_set", &hand, &la);
    assert_eq!(sg, sa);
    if !matches!(outcome, Outcome::Converged(_)) {
        assert_eq!(stats.as_fallbacks, 1, "{outcome:?} {stats:?}");
    }
    let (xg, xa) = (to_dvector(&lg), to_dvector(&la));
    assert!((&xg - &xa).norm() <= 1e-8 * xg.norm(), "GS {xg} vs AS {xa}");
    let xp = projected_gradient(&hand);
    assert!(
        (&xg - &xp).norm() <= 1e-8 * xg.norm(),
        "GS {xg} vs projected gradient {xp}"
    );
}

// ---------------------------------------------------------------------------------------------
// Stability limit (THEORY §2)
// ---------------------------------------------------------------------------------------------

fn point_mass_on_plane(mass: f64, kn: f64, gap: f64) -> fretdyn::model::Model {
    use fretdyn::contact::friction::Coulomb;
    use fretdyn::contact::obstacle::{Obstacle, Plane};
    use fretdyn::contact::{Contact, NormalLaw};
    use fretdyn::structure::modal::ModalBasis;
    let basis = ModalBasis::point_mass(mass, "m", Vector3::zeros()).unwrap();
    let mut model = fretdyn::model::Model::new(basis);
    model.contacts.push(Contact::new(
        "plane",
        0,
        Obstacle::Plane(
            Plane::new(Vector3::zeros(), Vector3::z(), gap, Some(Vector3::x()), "p").unwrap(),
        ),
        NormalLaw::new(kn, 0.0, "n").unwrap(),
        Coulomb::new(0.3, 0.3, "f").unwrap(),
    ));
    model
}

#[test]
fn stable_time_step_of_a_point_mass_on_a_plane_is_two_over_omega() {
    let (m, kn) = (2.5f64, 4e6f64);
    let model = point_mass_on_plane(m, kn, 0.0);
    let expected = 2.0 / (kn / m).sqrt();
    for method in [gs(), active_set()] {
        let dt = fretdyn::integrator::stability::stable_time_step(&model, &method);
        assert!(
            (dt - expected).abs() <= 1e-12 * expected,
            "{}: {dt} vs {expected}",
            method.name()
        );
    }
    // a tangential penalty spring stiffer than K_N sets the limit (C_T = 0)
    let kt = 1e7;
    let penalty = TangentialMethod::Penalty(PenaltySettings {
        stiffness: kt,
        damping: 0.0,
    });
    let dt = fretdyn::integrator::stability::stable_time_step(&model, &penalty);
    let expected_t = 2.0 / (kt / m).sqrt();
    assert!(
        (dt - expected_t).abs() <= 1e-12 * expected_t,
        "penalty: {dt} vs {expected_t}"
    );
}

#[test]
fn time_step_above_the_stable_limit_is_refused_with_the_limit_in_the_message() {
    let (m, kn) = (2.5f64, 4e6f64);
    let model = point_mass_on_plane(m, kn, 0.0);
    let limit = 2.0 / (kn / m).sqrt();
    let settings = fretdyn::integrator::simulation::RunSettings {
        dt: 1.01 * limit,
        steps: 10,
        method: gs(),
        stick_velocity: Default::default(),
        output_every: 1,
        monitors: Vec::new(),
        statistics: Default::default(),
    };
    let err = simulate(&model, &settings).expect_err("Δt above the limit must be refused");
    let fretdyn::Error::UnstableTimeStep { dt, limit: l, .. } = &err else {
        panic!("expected UnstableTimeStep, got {err:?}");
    };
    assert_eq!(*dt, settings.dt);
    assert!((l - limit).abs() <= 1e-12 * limit, "{l} vs {limit}");
    let msg = err.to_string();
    assert!(msg.contains("stable limit"), "{msg}");
    // to 3 significant digits, as a person reads it (the fix, `set time.dt ≤ …`, follows)
    let printed: f64 = format!("{l:.2e}").parse().unwrap();
    assert!(
        msg.contains(&format!("{printed:e}")),
        "message should give the limit {printed:e}: {msg}"
    );
}

/// Just below the limit the scheme is stable: a mass pressed on the plane by a constant force
/// (always closed, a linear oscillator of ω = √(K_N/m)) stays bounded at Δt = 0.98 × 2/ω,
/// with the amplitude of the discrete oscillator, v₀/(ω √(1 − (ωΔt/2)²)) ≈ 5 v₀/ω.
#[test]
fn time_step_just_below_the_limit_is_stable() {
    use fretdyn::loads::{PointLoad, TimeHistory};
    let (m, kn) = (2.5f64, 4e6f64);
    let omega = (kn / m).sqrt();
    let preload = 1e-3; // equilibrium penetration, m
    let mut model = point_mass_on_plane(m, kn, -preload); // δ = preload at x = 0
    model.loads.push(
        PointLoad::new(
            0,
            Vector3::new(0.0, 0.0, -kn * preload),
            TimeHistory::Constant,
            "load",
        )
        .unwrap(),
    );
    let v0 = 0.1;
    model
        .set_initial_from_point(0, Vector3::zeros(), Vector3::new(0.0, 0.0, v0))
        .unwrap();
    let h = 0.98 * 2.0;
    let settings = fretdyn::integrator::simulation::RunSettings {
        dt: h / omega,
        steps: 5000,
        method: gs(),
        stick_velocity: Default::default(),
        output_every: 1,
        monitors: Vec::new(),
        statistics: Default::default(),
    };
    let r = run(&model, &settings, |_| ControlFlow::Continue(())).unwrap();
    assert_eq!(r.termination, Termination::Completed);
    let amplitude = v0 / (omega * (1.0 - h * h / 4.0).sqrt());
    let max_dev = r
        .recorder
        .penetration
        .iter()
        .map(|d| (d - preload).abs())
        .fold(0.0, f64::max);
    assert!(
        r.recorder.status.iter().all(|&s| s != 0),
        "the contact opened"
    );
    assert!(
        max_dev <= 1.0001 * amplitude && max_dev >= 0.9 * amplitude,
        "max |δ − δ_eq| = {max_dev:e}, discrete amplitude {amplitude:e}"
    );
}

/// The natural-map residual (the same measure for both Lagrange solvers) is at round-off for
/// the exact Gauss–Seidel and the Active Set, and exposes the paper's radial projection, whose
/// force is not opposite to the slip when a contact's block of H is anisotropic.
#[test]
fn natural_map_residual_ranks_the_solvers() {
    let steps = 20_000;
    let radial = TangentialMethod::GaussSeidel(GaussSeidelSettings {
        local_solve: fretdyn::contact::friction::LocalSolve::Radial,
        ..GaussSeidelSettings::default()
    });
    let mut report = Vec::new();
    for (label, method) in [
        ("exact GS", gs()),
        ("active set", active_set()),
        ("radial GS", radial),
    ] {
        let s = tube(method, steps).solver;
        report.push(format!(
            "{label}: mean {:.2e} max {:.2e} above 1e-8 {} of {}",
            s.residual_mean(),
            s.residual_max,
            s.residual_steps_above_1e_8,
            s.lagrange_steps
        ));
        if label == "radial GS" {
            assert!(s.residual_max > 1e-3, "{report:?}");
        } else {
            assert!(s.residual_max < 1e-8, "{report:?}");
            assert_eq!(s.residual_steps_above_1e_8, 0, "{report:?}");
        }
    }
    println!("{}", report.join("\n"));
}

// ---------------------------------------------------------------------------------------------
// Brute force: enumerate every stick/slip pattern of a small problem (THEORY §4.2, §4.4).
// ---------------------------------------------------------------------------------------------

/// One candidate solution of the Coulomb conditions for a fixed stick/slip pattern.
struct Candidate {
    lambda: Vec<Vector2<f64>>,
    pattern: Vec<Slide>,
    /// How far inside its own admissibility conditions the candidate is (stick: `1 − |λ|/s`,
    /// slip: `γ / |b|`); negative means it violates them.
    margin: f64,
}

/// Solves the pattern's equations, with `w = b − Hλ`:
/// stick `k`: `w_k = 0` (λ_k free); slip `k`: `λ_k = s_k (cos θ_k, sin θ_k)`,
/// `w_k = γ_k (cos θ_k, sin θ_k)` (θ_k, γ_k free). 2m equations, 2m unknowns, nonlinear in the
/// angles only: Newton from a grid of starting angles, each start first made consistent by the
/// linear solve in (λ_stick, γ) at fixed angles. Returns every distinct converged root.
fn pattern_roots(hand: &Hand, pattern: &[Slide]) -> Vec<Candidate> {
    let m = pattern.len();
    let h = &hand.l * hand.l.transpose();
    let b = &hand.l * &hand.g;
    let slips: Vec<usize> = (0..m).filter(|&k| pattern[k] == Slide::Slip).collect();
    let n = 2 * m;
    // unknown layout: for stick k: (λ_k,x, λ_k,y) at 2k, 2k+1; for slip k: (θ_k, γ_k) there.
    let lambda_of = |x: &DVector<f64>| -> DVector<f64> {
        let mut lam = DVector::zeros(n);
        for k in 0..m {
            if pattern[k] == Slide::Stick {
                lam[2 * k] = x[2 * k];
                lam[2 * k + 1] = x[2 * k + 1];
            } else {
                lam[2 * k] = hand.s[k] * x[2 * k].cos();
                lam[2 * k + 1] = hand.s[k] * x[2 * k].sin();
            }
        }
        lam
    };
    let residual = |x: &DVector<f64>| -> DVector<f64> {
        let w = &b - &h * lambda_of(x);
        let mut r = w.clone();
        for &k in &slips {
            r[2 * k] -= x[2 * k + 1] * x[2 * k].cos();
            r[2 * k + 1] -= x[2 * k + 1] * x[2 * k].sin();
        }
        r
    };
    let jacobian = |x: &DVector<f64>| -> DMatrix<f64> {
        let mut j = DMatrix::zeros(n, n);
        for k in 0..m {
            if pattern[k] == Slide::Stick {
                for c in 0..2 {
                    j.set_column(2 * k + c, &(-h.column(2 * k + c)));
                }
            } else {
                let (st, ct) = x[2 * k].sin_cos();
                let dlam =
                    h.column(2 * k) * (-hand.s[k] * st) + h.column(2 * k + 1) * (hand.s[k] * ct);
                let mut col = -dlam;
                col[2 * k] += x[2 * k + 1] * st;
                col[2 * k + 1] -= x[2 * k + 1] * ct;
                j.set_column(2 * k, &col);
                let mut col = DVector::zeros(n);
                col[2 * k] = -ct;
                col[2 * k + 1] = -st;
                j.set_column(2 * k + 1, &col);
            }
        }
        j
    };
    let scale = b.amax();
    let grid = 12usize;
    let starts = grid.pow(slips.len() as u32);
    let mut roots: Vec<Candidate> = Vec::new();
    for start in 0..starts {
        let mut x = DVector::zeros(n);
        let mut idx = start;
        for &k in &slips {
            x[2 * k] = 2.0 * std::f64::consts::PI * (idx % grid) as f64 / grid as f64 + 0.1;
            idx /= grid;
        }
        // consistent start: at fixed angles the system is linear in (λ_stick, γ)
        let r0 = residual(&x);
        let mut jl = jacobian(&x);
        for &k in &slips {
            jl.set_column(2 * k, &DVector::zeros(n));
        }
        if let Ok(dx) = jl.svd(true, true).solve(&r0, 1e-12) {
            x -= dx;
        }
        let mut converged = false;
        for _ in 0..100 {
            let r = residual(&x);
            if r.amax() <= 1e-13 * scale {
                converged = true;
                break;
            }
            let Some(dx) = jacobian(&x).lu().solve(&r) else {
                break;
            };
            x -= dx;
        }
        if !converged {
            continue;
        }
        let lam = lambda_of(&x);
        let lambda: Vec<Vector2<f64>> = (0..m)
            .map(|k| Vector2::new(lam[2 * k], lam[2 * k + 1]))
            .collect();
        let margin = (0..m)
            .map(|k| match pattern[k] {
                Slide::Stick => 1.0 - lambda[k].norm() / hand.s[k],
                Slide::Slip => x[2 * k + 1] / scale,
            })
            .fold(f64::INFINITY, f64::min);
        let same = roots.iter().any(|c| {
            c.lambda
                .iter()
                .zip(&lambda)
                .all(|(a, b)| (a - b).norm() <= 1e-9 * scale)
        });
        if !same {
            roots.push(Candidate {
                lambda,
                pattern: pattern.to_vec(),
                margin,
            });
        }
    }
    roots
}

/// All 2^m patterns; the admissible roots (margin ≥ −tolerance).
fn brute_force(hand: &Hand) -> Vec<Candidate> {
    let m = hand.s.len();
    let mut admissible = Vec::new();
    for bits in 0..(1usize << m) {
        let pattern: Vec<Slide> = (0..m)
            .map(|k| {
                if bits >> k & 1 == 1 {
                    Slide::Slip
                } else {
                    Slide::Stick
                }
            })
            .collect();
        admissible.extend(
            pattern_roots(hand, &pattern)
                .into_iter()
                .filter(|c| c.margin >= -1e-10),
        );
    }
    admissible
}

/// For m = 2 and 3 contacts with μ_s = μ_d (a convex problem with H SPD, so exactly one
/// solution), enumerating the 2^m stick/slip patterns finds exactly one admissible pattern,
/// and its forces are those of Gauss–Seidel and of the Active Set. Random problems with
/// thresholds from 0.02 to 5 times the unconstrained force cover all-stick, all-slip and
/// mixed solutions (checked).
#[test]
fn one_step_problem_brute_force_enumeration_agrees_with_both_solvers() {
    // FRETDYN_BRUTE_FORCE_CASES=600 for the figures quoted in docs/VERIFICATION.md
    let cases: u64 = std::env::var("FRETDYN_BRUTE_FORCE_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(90);
    let mut rng = Lcg(0xb00f);
    for m in [2usize, 3] {
        let (mut all_stick, mut all_slip, mut mixed, mut fallbacks) = (0, 0, 0, 0);
        for case in 0..cases {
            // thresholds log-uniform in [lo, hi]: above 1 all contacts stick, far below all
            // slip; every third case of each kind
            let (lo, hi): (f64, f64) = [(1.05, 5.0), (0.02, 0.3), (0.02, 5.0)][case as usize % 3];
            let factors: Vec<f64> = (0..m)
                .map(|_| lo * (hi / lo).powf(0.5 * (rng.next() + 1.0)))
                .collect();
            let hand = hand_problem(0xb0_0000 + 100 * m as u64 + case, 2 * m + 2, m, &factors);
            let label = format!("m = {m}, case {case}, factors {factors:?}");
            let found = brute_force(&hand);
            assert!(!found.is_empty(), "{label}: no admissible pattern");
            // away from the stick/slip boundary exactly one pattern is admissible; on it two
            // patterns describe the same forces
            let clear: Vec<&Candidate> = found.iter().filter(|c| c.margin > 1e-6).collect();
            let degenerate = clear.len() != found.len();
            if !degenerate {
                assert_eq!(
                    found.len(),
                    1,
                    "{label}: {} admissible patterns",
                    found.len()
                );
            }
            let exact = &found[0];
            for c in &found[1..] {
                for k in 0..m {
                    assert!((c.lambda[k] - exact.lambda[k]).norm() <= 1e-8 * hand.s[k].max(1e-300));
                }
            }
            let lg = solve_gs(&hand.problem);
            let (la, slide_a, outcome, stats) =
                solve_active_set(&hand.problem, &vec![History::default(); m]);
            // the Active Set's slip directions are a fixed-point iteration: on strongly coupled
            // sliding contacts it may need its stated fallback (counted, answer still checked)
            if !matches!(outcome, Outcome::Converged(_)) {
                assert_eq!(stats.as_fallbacks, 1, "{label}: {outcome:?} {stats:?}");
                fallbacks += 1;
            }
            let scale = to_dvector(&exact.lambda).norm();
            for (name, l) in [("Gauss–Seidel", &lg), ("Active Set", &la)] {
                let diff = (to_dvector(l) - to_dvector(&exact.lambda)).norm();
                assert!(
                    diff <= 1e-8 * scale,
                    "{label}: {name} differs from enumeration by {diff:e}"
                );
            }
            if !degenerate {
                if matches!(outcome, Outcome::Converged(_)) {
                    assert_eq!(slide_a, exact.pattern, "{label}: Active Set statuses");
                }
                match exact.pattern.iter().filter(|s| **s == Slide::Slip).count() {
                    0 => all_stick += 1,
                    n if n == m => all_slip += 1,
                    _ => mixed += 1,
                }
            }
        }
        assert!(
            all_stick >= cases / 6 && all_slip >= cases / 6 && mixed >= cases / 12,
            "m = {m}: coverage all-stick {all_stick}, all-slip {all_slip}, mixed {mixed}"
        );
        println!(
            "m = {m}: all-stick {all_stick}, all-slip {all_slip}, mixed {mixed}, \
             Active Set fallbacks {fallbacks}/{cases}"
        );
    }
}
