//! Verification case V1 (THEORY §6): oblique impact of a point mass on a fixed plane, with its
//! analytic solution and the measurements that `fretdyn verify` and the tests compare to it.
//!
//! Taking `t = 0` at first contact, `ω = √(K_N/m)`, `v_n = V cos α`, `v_t = V sin α`:
//! contact lasts `π/ω`, `R_N = m v_n ω sin ωt`; while sliding `|R_T| = μ_d R_N` and
//! `v_T = v_t − μ_d v_n (1 − cos ωt)`; it sticks at `t* = arccos(1 − tan α/μ_d)/ω` when
//! `tan α ≤ 2 μ_d` and leaves with no tangential velocity, else leaves with `v_t − 2 μ_d v_n`.

use nalgebra::Vector3;
use serde::Serialize;

use crate::case::Case;
use crate::contact::friction::Coulomb;
use crate::contact::obstacle::{Obstacle, Plane};
use crate::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use crate::contact::{Contact, NormalLaw};
use crate::integrator::simulation::{RunResults, RunSettings};
use crate::model::Model;
use crate::structure::modal::{ModalBasis, recombine};

/// Parameters of the V1 case.
#[derive(Debug, Clone, PartialEq)]
pub struct V1 {
    /// Mass `m`, kg.
    pub mass: f64,
    /// Impact speed `V`, m/s.
    pub speed: f64,
    /// Incidence from the normal `α`, rad.
    pub alpha: f64,
    /// Contact stiffness `K_N`, N/m.
    pub stiffness: f64,
    /// Static friction coefficient.
    pub mu_static: f64,
    /// Dynamic friction coefficient.
    pub mu_dynamic: f64,
    /// Time step, s.
    pub dt: f64,
    /// Simulated time, s.
    pub duration: f64,
    /// Outward normal of the plane.
    pub normal: Vector3<f64>,
    /// First tangent of the plane's basis (`None`: fretdyn's default basis).
    pub plane_tangent: Option<Vector3<f64>>,
    /// Direction of the incoming tangential velocity (projected on the plane).
    pub slide_direction: Vector3<f64>,
}

impl V1 {
    /// THEORY §6 reference values: m = 1 kg, V = 1 m/s, K_N = 1e6 N/m, μ = 0.3, Δt = 1e-6 s,
    /// plane z = 0, sliding along x (the first tangent), 4 ms simulated.
    pub fn reference(alpha_deg: f64) -> Self {
        Self {
            mass: 1.0,
            speed: 1.0,
            alpha: alpha_deg.to_radians(),
            stiffness: 1e6,
            mu_static: 0.3,
            mu_dynamic: 0.3,
            dt: 1e-6,
            duration: 4e-3,
            normal: Vector3::z(),
            plane_tangent: Some(Vector3::x()),
            slide_direction: Vector3::x(),
        }
    }

    /// `ω = √(K_N/m)`.
    pub fn omega(&self) -> f64 {
        (self.stiffness / self.mass).sqrt()
    }
    /// Incoming normal speed `v_n = V cos α`.
    pub fn normal_speed(&self) -> f64 {
        self.speed * self.alpha.cos()
    }
    /// Incoming tangential speed `v_t = V sin α`.
    pub fn tangential_speed(&self) -> f64 {
        self.speed * self.alpha.sin()
    }
    /// Contact duration `π/ω`.
    pub fn contact_duration(&self) -> f64 {
        std::f64::consts::PI / self.omega()
    }
    /// Peak normal force `m v_n ω`.
    pub fn peak_normal_force(&self) -> f64 {
        self.mass * self.normal_speed() * self.omega()
    }
    /// Analytic normal force.
    pub fn normal_force(&self, t: f64) -> f64 {
        if t > 0.0 && t < self.contact_duration() {
            self.peak_normal_force() * (self.omega() * t).sin()
        } else {
            0.0
        }
    }
    /// Stick time `t*`, if the mass sticks (`tan α ≤ 2 μ_d`).
    pub fn stick_time(&self) -> Option<f64> {
        let r = self.alpha.tan() / self.mu_dynamic;
        (r <= 2.0).then(|| (1.0 - r).acos() / self.omega())
    }
    /// Analytic friction force magnitude.
    pub fn friction_force(&self, t: f64) -> f64 {
        match self.stick_time() {
            Some(ts) if t >= ts => 0.0,
            _ => self.mu_dynamic * self.normal_force(t),
        }
    }
    /// Analytic tangential speed after separation.
    pub fn leaving_tangential_speed(&self) -> f64 {
        match self.stick_time() {
            Some(_) => 0.0,
            None => self.tangential_speed() - 2.0 * self.mu_dynamic * self.normal_speed(),
        }
    }

    /// The model: a point mass at the origin on the plane through the origin, moving into it.
    pub fn model(&self) -> Model {
        let n = self.normal.normalize();
        let s = self.slide_direction - n * n.dot(&self.slide_direction);
        let s = if s.norm() > 0.0 { s.normalize() } else { s };
        let basis = ModalBasis::point_mass(self.mass, "mass", Vector3::zeros())
            .expect("V1 mass is positive");
        let mut model = Model::new(basis);
        model.contacts.push(Contact::new(
            "plane",
            0,
            Obstacle::Plane(
                Plane::new(Vector3::zeros(), n, 0.0, self.plane_tangent, "v1.plane")
                    .expect("V1 plane is valid"),
            ),
            NormalLaw::new(self.stiffness, 0.0, "v1.normal").expect("K_N > 0"),
            Coulomb::new(self.mu_static, self.mu_dynamic, "v1.friction").expect("μ_s ≥ μ_d ≥ 0"),
        ));
        let v = s * self.tangential_speed() - n * self.normal_speed();
        model
            .set_initial_from_point(0, Vector3::zeros(), v)
            .expect("a point mass takes any velocity");
        model
    }

    /// Run settings with `method`.
    pub fn settings(&self, method: TangentialMethod, stick_velocity: StickVelocity) -> RunSettings {
        RunSettings {
            dt: self.dt,
            steps: (self.duration / self.dt).round() as u64,
            method,
            stick_velocity,
            output_every: 1,
            monitors: Vec::new(),
            statistics: Default::default(),
        }
    }

    /// The case, ready to run.
    pub fn case(&self, title: &str, method: TangentialMethod) -> Case {
        Case::from_parts(
            title,
            self.model(),
            self.settings(method, StickVelocity::HalfStep),
        )
    }
}

/// The tangential methods compared on V1: the two Lagrange solvers and the penalty law with
/// THEORY §6's `C_T = 2000 kg/s` and the given `K_T`.
pub fn methods(penalty_stiffnesses: &[f64]) -> Vec<(String, TangentialMethod)> {
    let mut v = vec![
        (
            "active_set".to_string(),
            TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        ),
        (
            "gauss_seidel".to_string(),
            TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        ),
    ];
    for &k in penalty_stiffnesses {
        v.push((
            format!("penalty K_T={k:.0e}"),
            TangentialMethod::Penalty(PenaltySettings {
                stiffness: k,
                damping: 2000.0,
            }),
        ));
    }
    v
}

/// What is measured on a V1 run, each against the analytic solution. Forces are relative to
/// the analytic peak normal force `m v_n ω`, speeds to `V`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct V1Measurements {
    /// max |R_N − m v_n ω sin ωt| during contact / peak.
    pub normal_force_error: f64,
    /// |leaving normal speed − v_n| / V.
    pub leaving_normal_speed_error: f64,
    /// In the analytic slip phase: max | |R_T| − μ_d R_N | / peak (same-step R_N).
    pub slip_force_law_error: f64,
    /// In the analytic slip phase: max | |R_T| − μ_d m v_n ω sin ωt | / peak.
    pub slip_force_error: f64,
    /// In the slip phase: max |R_T/|R_T| + v_T/|v_T|| (0 when R_T opposes the slip exactly).
    pub slip_direction_error: f64,
    /// Time of the first sample with status stick, s.
    pub first_stick_time: Option<f64>,
    /// Time of the first closed sample, s.
    pub first_contact_time: Option<f64>,
    /// Whether every closed sample was sticking.
    pub stick_from_first_step: bool,
    /// max |R_T| / max R_N from 2Δt after t* until separation (0 if no stick).
    pub post_stick_force: f64,
    /// Number of closed samples with status slip after t* + 2Δt.
    pub post_stick_slip_samples: usize,
    /// Leaving tangential speed, m/s.
    pub leaving_tangential_speed: f64,
    /// |leaving tangential speed − analytic| / V.
    pub leaving_tangential_speed_error: f64,
    /// Energy balance error of the run.
    pub energy_error: f64,
}

/// Measures a V1 run against the analytic solution.
pub fn measure(v1: &V1, results: &RunResults) -> V1Measurements {
    let r = &results.recorder;
    let peak = v1.peak_normal_force();
    let n = v1.normal.normalize();
    let ts = v1.stick_time();
    let dt = v1.dt;
    let mut m = V1Measurements {
        normal_force_error: 0.0,
        leaving_normal_speed_error: 0.0,
        slip_force_law_error: 0.0,
        slip_force_error: 0.0,
        slip_direction_error: 0.0,
        first_stick_time: None,
        first_contact_time: None,
        stick_from_first_step: true,
        post_stick_force: 0.0,
        post_stick_slip_samples: 0,
        leaving_tangential_speed: f64::NAN,
        leaving_tangential_speed_error: f64::NAN,
        energy_error: results.energy.relative_error,
    };
    let mut max_rn = 0.0f64;
    let mut closed_any = false;
    for i in 0..r.len() {
        let t = r.t[i];
        let rn = r.normal_force[[i, 0]];
        let rt =
            nalgebra::Vector2::new(r.tangential_force[[i, 0, 0]], r.tangential_force[[i, 0, 1]]);
        let vt = nalgebra::Vector2::new(r.slip_velocity[[i, 0, 0]], r.slip_velocity[[i, 0, 1]]);
        let status = r.status[[i, 0]];
        max_rn = max_rn.max(rn);
        if t <= v1.contact_duration() + 2.0 * dt {
            m.normal_force_error = m
                .normal_force_error
                .max((rn - v1.normal_force(t)).abs() / peak);
        }
        if status != 0 {
            closed_any = true;
            m.first_contact_time.get_or_insert(t);
            if status == 1 {
                m.first_stick_time.get_or_insert(t);
            } else {
                m.stick_from_first_step = false;
            }
        }
        let in_slip = status != 0 && ts.is_none_or(|ts| t < ts - 2.0 * dt);
        if in_slip {
            let law = (rt.norm() - v1.mu_dynamic * rn).abs() / peak;
            m.slip_force_law_error = m.slip_force_law_error.max(law);
            m.slip_force_error = m
                .slip_force_error
                .max((rt.norm() - v1.mu_dynamic * v1.normal_force(t)).abs() / peak);
            if rt.norm() > 0.0 && vt.norm() > 0.0 {
                let e = (rt / rt.norm() + vt / vt.norm()).norm();
                m.slip_direction_error = m.slip_direction_error.max(e);
            }
        }
        if let Some(ts) = ts
            && t >= ts + 2.0 * dt
            && status != 0
        {
            m.post_stick_force = m.post_stick_force.max(rt.norm());
            if status == 2 {
                m.post_stick_slip_samples += 1;
            }
        }
    }
    if !closed_any {
        m.stick_from_first_step = false;
    }
    m.post_stick_force /= max_rn.max(f64::MIN_POSITIVE);
    if let Some(last) = r.len().checked_sub(1) {
        let qd: Vec<f64> = r.qdot.row(last).to_vec();
        let v = recombine(&results_rows(v1), &qd);
        let vn = v.dot(&n);
        let vt = (v - n * vn).norm();
        m.leaving_normal_speed_error = (vn - v1.normal_speed()).abs() / v1.speed;
        m.leaving_tangential_speed = vt;
        m.leaving_tangential_speed_error = (vt - v1.leaving_tangential_speed()).abs() / v1.speed;
    }
    m
}

fn results_rows(v1: &V1) -> Vec<f64> {
    let s = 1.0 / v1.mass.sqrt();
    vec![s, 0.0, 0.0, 0.0, s, 0.0, 0.0, 0.0, s]
}

/// One line of the verification table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    /// V1a, V1b, V1c, energy…
    pub case: String,
    /// Method label.
    pub method: String,
    /// What is compared.
    pub quantity: String,
    /// Measured value.
    pub value: f64,
    /// Bound it must respect (`value ≤ limit`).
    pub limit: f64,
    /// value ≤ limit (and finite).
    pub passed: bool,
}

impl Check {
    /// A check `value ≤ limit`.
    pub fn new(case: &str, method: &str, quantity: &str, value: f64, limit: f64) -> Self {
        Self {
            case: case.into(),
            method: method.into(),
            quantity: quantity.into(),
            value,
            limit,
            passed: value.is_finite() && value <= limit,
        }
    }
}

/// The acceptance checks of one V1 run (issue #2's "done when", THEORY §6).
pub fn checks(case: &str, method: &str, lagrange: bool, v1: &V1, m: &V1Measurements) -> Vec<Check> {
    let mut c = vec![
        Check::new(
            case,
            method,
            "normal force error / peak",
            m.normal_force_error,
            1e-4,
        ),
        Check::new(
            case,
            method,
            "leaving normal speed error / V",
            m.leaving_normal_speed_error,
            1e-4,
        ),
        Check::new(
            case,
            method,
            "slip |R_T| − μ_d R_N / peak",
            m.slip_force_law_error,
            1e-4,
        ),
        Check::new(
            case,
            method,
            "slip |R_T| − analytic / peak",
            m.slip_force_error,
            1e-4,
        ),
        Check::new(
            case,
            method,
            "slip force direction error",
            m.slip_direction_error,
            1e-6,
        ),
    ];
    match (case, v1.stick_time()) {
        ("V1b", _) if !lagrange || method == "gauss_seidel" => {
            c.push(Check::new(
                case,
                method,
                "samples not sticking from first contact",
                (!m.stick_from_first_step) as u8 as f64,
                0.0,
            ));
        }
        (_, Some(ts)) if lagrange && case != "V1b" => {
            let first = m.first_stick_time.map_or(f64::INFINITY, |t| (t - ts).abs());
            c.push(Check::new(
                case,
                method,
                "|first stick − t*| / Δt",
                first / v1.dt,
                2.0,
            ));
            c.push(Check::new(
                case,
                method,
                "max |R_T| after t*+2Δt / max R_N",
                m.post_stick_force,
                1e-9,
            ));
            c.push(Check::new(
                case,
                method,
                "leaving tangential speed (m/s)",
                m.leaving_tangential_speed,
                1e-9,
            ));
        }
        (_, None) => {
            c.push(Check::new(
                case,
                method,
                "stick samples (must be none)",
                m.first_stick_time.is_some() as u8 as f64,
                0.0,
            ));
            c.push(Check::new(
                case,
                method,
                "leaving tangential speed error / V",
                m.leaving_tangential_speed_error,
                1e-4,
            ));
        }
        _ => {}
    }
    c
}
