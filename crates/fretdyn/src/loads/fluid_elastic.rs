//! Fluid-elastic forces on the modes (THEORY §13): the force the flow exerts because the tube
//! moves, projected on the modes once before the run,
//!
//! ```text
//! f_fe(t) = Σ_g K_g q(t − τ_g) − C q̇(t),
//! ```
//!
//! with `K_g` the modal fluid stiffness of a delay group `g` (a flow zone, or part of one)
//! acting on the displacement delayed by `τ_g`, and `C` the modal fluid damping. The
//! quasi-steady model with a time lag (Price & Païdoussis) gives, per unit length of a zone of
//! density `ρ`, velocity `U`, tube diameter `D`,
//!
//! ```text
//! lift  (across the flow): f_y = ½ρU² C_L' y(t − τ_L) − ½ρUD C_D ẏ,    τ_L = μ_L D / U
//! drag  (along the flow):  f_x = ½ρU² C_D' x(t − τ_D) −  ρUD C_D ẋ,    τ_D = μ_D D / U,
//! ```
//!
//! so `K_g = ∫ ½ρU² ([τ_L ∈ g] C_L' φ_y φ_yᵀ + [τ_D ∈ g] C_D' φ_x φ_xᵀ) ds` (each direction's
//! term in the group of its own delay) and `C = ∫ ρUD C_D (½ φ_y φ_yᵀ +
//! φ_x φ_xᵀ) ds`. Tabulated modal coefficients (the form of Code_Aster and EDF: fluid damping
//! `c(V_r)` and stiffness `k(V_r)` per unit length against the reduced velocity
//! `V_r = U / (f_i D)`) give diagonal `C` and `K` with no delay.
//!
//! In the step ([`FluidElasticForce`]) the delayed displacements come from a ring buffer of
//! the past `q`, interpolated linearly between the two steps around `t − τ`; before `t = 0`
//! the displacement is the initial one (the structure held still). The force is explicit, as
//! the contact forces are: its velocity is extrapolated to the step's end,
//! `q̇_{n+1} ≈ q̇_n + Δt q̈_n` (second-order; the half-step velocity `q̇*` would lag by `Δt/2`
//! and shift the frequency by `C Δt ω / 4`, first order).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::numerics::Lanes;

/// A modal matrix (`p × p`, row-major) or its diagonal.
#[derive(Debug, Clone, PartialEq)]
pub enum ModalMatrix {
    /// Every term, row-major.
    Dense(Vec<f64>),
    /// The diagonal only (tabulated modal coefficients).
    Diagonal(Vec<f64>),
}

impl ModalMatrix {
    /// `out += s · M x` (`p = x.len()`; `work` holds p values), the rows' products summed by
    /// the kernels `K` ([`crate::numerics::Lanes::dots`]).
    #[inline(always)]
    fn mul_add<K: Lanes>(&self, s: f64, x: &[f64], work: &mut [f64], out: &mut [f64]) {
        match self {
            ModalMatrix::Dense(m) => {
                K::dots(m, x, work);
                for (o, w) in out.iter_mut().zip(work.iter()) {
                    *o += s * w;
                }
            }
            ModalMatrix::Diagonal(d) => {
                for ((o, a), b) in out.iter_mut().zip(d).zip(x) {
                    *o += s * a * b;
                }
            }
        }
    }

    /// `self + other` (dense unless both are diagonal).
    pub fn sum(&self, other: &ModalMatrix) -> ModalMatrix {
        match (self, other) {
            (ModalMatrix::Diagonal(a), ModalMatrix::Diagonal(b)) => {
                ModalMatrix::Diagonal(a.iter().zip(b).map(|(x, y)| x + y).collect())
            }
            _ => {
                // one of them is dense: p × p values
                let p = match (self, other) {
                    (ModalMatrix::Dense(m), _) | (_, ModalMatrix::Dense(m)) => m.len().isqrt(),
                    _ => 0,
                };
                let mut out = self.dense(p);
                for (o, v) in out.iter_mut().zip(other.dense(p)) {
                    *o += v;
                }
                ModalMatrix::Dense(out)
            }
        }
    }

    /// Every term, row-major `p × p`.
    fn dense(&self, p: usize) -> Vec<f64> {
        match self {
            ModalMatrix::Dense(m) => m.clone(),
            ModalMatrix::Diagonal(d) => {
                let mut m = vec![0.0; p * p];
                for (i, v) in d.iter().enumerate() {
                    m[i * p + i] = *v;
                }
                m
            }
        }
    }

    /// The largest absolute row sum `max_i Σ_j |M_ij|`: a bound of every eigenvalue of the
    /// symmetric part (for the stable time step).
    pub fn row_sum_bound(&self, p: usize) -> f64 {
        match self {
            ModalMatrix::Dense(m) => m
                .chunks_exact(p.max(1))
                .map(|row| row.iter().map(|v| v.abs()).sum::<f64>())
                .fold(0.0, f64::max),
            ModalMatrix::Diagonal(d) => d.iter().fold(0.0f64, |a, v| a.max(v.abs())),
        }
    }

    fn check(&self, p: usize, field: &str) -> Result<()> {
        let (values, n) = match self {
            ModalMatrix::Dense(m) => (m, p * p),
            ModalMatrix::Diagonal(d) => (d, p),
        };
        if values.len() != n {
            return Err(Error::invalid(
                field,
                format!("has {} values, expected {n} for {p} modes", values.len()),
            ));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                field,
                format!(
                    "value {i} is not a finite number: check the flow's velocity, density and coefficients"
                ),
            ));
        }
        Ok(())
    }
}

/// The stiffness of one delay group: `f += K q(t − τ)`.
#[derive(Debug, Clone, PartialEq)]
pub struct DelayedStiffness {
    /// Where it comes from (e.g. `flow.zones[0]`), for messages.
    pub name: String,
    /// Delay `τ ≥ 0`, s.
    pub delay: f64,
    /// Modal fluid stiffness `K`, 1/s² (per unit modal mass).
    pub stiffness: ModalMatrix,
}

/// The fluid-elastic forces of a model, on its modes (see the module's documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct FluidElastic {
    /// Delay groups.
    pub delayed: Vec<DelayedStiffness>,
    /// Modal fluid damping `C` (a sum of terms), 1/s: `f −= C q̇`.
    pub damping: Vec<ModalMatrix>,
}

impl FluidElastic {
    /// Checks the sizes and values for `p` modes.
    pub fn validate(&self, p: usize) -> Result<()> {
        for g in &self.delayed {
            if !(g.delay >= 0.0 && g.delay.is_finite()) {
                return Err(Error::invalid(
                    format!("{}.delay", g.name),
                    format!(
                        "τ = {} s must be a finite number ≥ 0 (τ = μ D / U: check the velocity)",
                        g.delay
                    ),
                ));
            }
            g.stiffness.check(p, &g.name)?;
        }
        for c in &self.damping {
            c.check(p, "fluid-elastic damping")?;
        }
        Ok(())
    }

    /// A bound of the fluid stiffness's eigenvalues, 1/s², added to `ω_max²` for the stable
    /// time step (THEORY §13).
    pub fn stiffness_bound(&self, p: usize) -> f64 {
        self.delayed
            .iter()
            .map(|g| g.stiffness.row_sum_bound(p))
            .sum()
    }

    /// A bound of the fluid damping's eigenvalues, 1/s, added to the explicit damping rate
    /// for the stable time step.
    pub fn damping_bound(&self, p: usize) -> f64 {
        self.damping.iter().map(|c| c.row_sum_bound(p)).sum()
    }

    /// The longest delay, s.
    pub fn longest_delay(&self) -> f64 {
        self.delayed.iter().map(|g| g.delay).fold(0.0, f64::max)
    }

    /// Adds `other`'s terms (a delay group of the same delay is merged into this one's).
    pub fn merge(&mut self, other: FluidElastic) {
        for g in other.delayed {
            match self.delayed.iter_mut().find(|h| h.delay == g.delay) {
                Some(h) => h.stiffness = h.stiffness.sum(&g.stiffness),
                None => self.delayed.push(g),
            }
        }
        for c in other.damping {
            match self.damping.pop() {
                Some(d) => self.damping.push(d.sum(&c)),
                None => self.damping.push(c),
            }
        }
    }

    /// The quasi-steady model with a time lag (Price & Païdoussis; THEORY §13) on the flow
    /// `nodes` of one zone: per unit length `f_lift = ½ρU² C_L' y(t − τ_L) − ½ρUD C_D ẏ`,
    /// `f_drag = ½ρU² C_D' x(t − τ_D) − ρUD C_D ẋ`, integrated with the
    /// nodes' weights, each direction of each node with its delay
    /// ([`FlowNode::delay_lift`] `μ_L D / U`, [`FlowNode::delay_drag`] `μ_D D / U`; one delay
    /// group per distinct delay). `name` names the zone.
    pub fn quasi_steady(
        name: &str,
        coefficients: &QuasiSteady,
        nodes: &[FlowNode],
        p: usize,
    ) -> FluidElastic {
        let mut out = FluidElastic {
            delayed: Vec::new(),
            damping: Vec::new(),
        };
        let mut damping = vec![0.0; p * p];
        let (mut lift, mut drag) = (vec![0.0; p], vec![0.0; p]);
        // one node's stiffness, added to its delay group's
        let mut k = vec![0.0; p * p];
        for n in nodes {
            n.directional_rows(&mut lift, &mut drag);
            let q = 0.5 * n.density * n.velocity * n.velocity * n.weight;
            let c = n.density * n.velocity * n.diameter * coefficients.drag * n.weight;
            add_outer(&mut damping, 0.5 * c, &lift);
            add_outer(&mut damping, c, &drag);
            if n.delay_lift == n.delay_drag {
                // one delay: both directions' stiffness in one group (as before per-direction
                // delays existed, so that such cases keep their bits)
                k.fill(0.0);
                add_outer(&mut k, q * coefficients.lift_slope, &lift);
                add_outer(&mut k, q * coefficients.drag_slope, &drag);
                out.add_to_group(name, n.delay_lift, &k);
            } else {
                for (slope, rows, delay) in [
                    (coefficients.lift_slope, &lift, n.delay_lift),
                    (coefficients.drag_slope, &drag, n.delay_drag),
                ] {
                    if slope != 0.0 {
                        k.fill(0.0);
                        add_outer(&mut k, q * slope, rows);
                        out.add_to_group(name, delay, &k);
                    }
                }
            }
        }
        out.damping.push(ModalMatrix::Dense(damping));
        out
    }

    /// Adds the dense stiffness `k` to the delay group of delay `delay` (a new group named
    /// `name` when none has it).
    fn add_to_group(&mut self, name: &str, delay: f64, k: &[f64]) {
        match self.delayed.iter_mut().find(|g| g.delay == delay) {
            Some(DelayedStiffness {
                stiffness: ModalMatrix::Dense(h),
                ..
            }) => h.iter_mut().zip(k).for_each(|(h, k)| *h += k),
            _ => self.delayed.push(DelayedStiffness {
                name: name.to_string(),
                delay,
                stiffness: ModalMatrix::Dense(k.to_vec()),
            }),
        }
    }

    /// Tabulated modal coefficients (the form of Code_Aster and EDF; THEORY §13): per mode
    /// `i` of frequency `f_i`, at each node the reduced velocity `V_r = U / (f_i D)` gives a
    /// damping `c(V_r)` (N·s/m²) and a stiffness `k(V_r)` (N/m²) per unit length, acting on
    /// the displacement across the tube in both directions of the flow's plane:
    /// `C_ii = Σ w c φ_i²`, `K_ii = Σ w k φ_i²` with `φ_i² = (e_L·Φ_i)² + (e_D·Φ_i)²`
    /// (the force is `−C q̇ − K q`).
    pub fn tabulated(
        name: &str,
        table: &ReducedVelocityTable,
        nodes: &[FlowNode],
        frequencies_hz: &[f64],
    ) -> FluidElastic {
        let p = frequencies_hz.len();
        let (mut c, mut k) = (vec![0.0; p], vec![0.0; p]);
        let (mut lift, mut drag) = (vec![0.0; p], vec![0.0; p]);
        for n in nodes {
            n.directional_rows(&mut lift, &mut drag);
            for i in 0..p {
                let phi2 = lift[i] * lift[i] + drag[i] * drag[i];
                let vr = if frequencies_hz[i] > 0.0 {
                    n.velocity / (frequencies_hz[i] * n.diameter)
                } else {
                    f64::INFINITY
                };
                let (ci, ki) = table.at(vr);
                c[i] += n.weight * ci * phi2;
                k[i] += n.weight * ki * phi2;
            }
        }
        FluidElastic {
            delayed: vec![DelayedStiffness {
                name: name.to_string(),
                delay: 0.0,
                stiffness: ModalMatrix::Diagonal(k.iter().map(|v| -v).collect()),
            }],
            damping: vec![ModalMatrix::Diagonal(c)],
        }
    }
}

/// `m += s x xᵀ` (`p × p`, row-major).
fn add_outer(m: &mut [f64], s: f64, x: &[f64]) {
    let p = x.len();
    for (i, row) in m.chunks_exact_mut(p.max(1)).enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v += s * x[i] * x[j];
        }
    }
}

/// Coefficients of the quasi-steady model (THEORY §13; published values in docs/FLOW.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuasiSteady {
    /// `C_L' = ∂C_L/∂(y/D)`, lift derivative across the flow.
    pub lift_slope: f64,
    /// `C_D' = ∂C_D/∂(x/D)`, drag derivative along the flow.
    pub drag_slope: f64,
    /// Steady drag coefficient `C_D`.
    pub drag: f64,
    /// Time-lag factor `μ_L` of the lift's delay `τ_L = μ_L D / U`.
    pub mu_lift: f64,
    /// Time-lag factor `μ_D` of the drag's delay `τ_D = μ_D D / U` (a streamwise motion's
    /// delay need not be the transverse one's).
    pub mu_drag: f64,
}

/// Modal fluid damping and stiffness per unit length against the reduced velocity, linearly
/// interpolated and held at the end values.
#[derive(Debug, Clone, PartialEq)]
pub struct ReducedVelocityTable {
    /// Increasing reduced velocities `U / (f D)`.
    pub reduced_velocity: Vec<f64>,
    /// Damping per unit length, N·s/m².
    pub damping: Vec<f64>,
    /// Stiffness per unit length, N/m².
    pub stiffness: Vec<f64>,
}

impl ReducedVelocityTable {
    /// `(c, k)` at reduced velocity `vr`.
    pub fn at(&self, vr: f64) -> (f64, f64) {
        let x = &self.reduced_velocity;
        let n = x.len();
        if n == 0 {
            return (0.0, 0.0);
        }
        if !(vr > x[0]) {
            return (self.damping[0], self.stiffness[0]);
        }
        if vr >= x[n - 1] {
            return (self.damping[n - 1], self.stiffness[n - 1]);
        }
        let j = x.partition_point(|v| *v <= vr).max(1);
        let s = (vr - x[j - 1]) / (x[j] - x[j - 1]);
        let lerp = |y: &[f64]| y[j - 1] + s * (y[j] - y[j - 1]);
        (lerp(&self.damping), lerp(&self.stiffness))
    }
}

/// A quadrature node of a flow zone: weight (length, m), the flow there, and the node's
/// translation rows.
#[derive(Debug, Clone)]
pub struct FlowNode<'a> {
    /// Quadrature weight, m.
    pub weight: f64,
    /// Fluid density `ρ`, kg/m³.
    pub density: f64,
    /// Flow velocity `U` (the gap velocity), m/s.
    pub velocity: f64,
    /// Delay `τ_L` of the quasi-steady model's lift term, s (`μ_L D / U` with the node's `U`,
    /// or with its stretch's velocity; ignored by the tabulated model).
    pub delay_lift: f64,
    /// Delay `τ_D` of its drag term, s (`μ_D D / U`).
    pub delay_drag: f64,
    /// Tube outer diameter `D`, m.
    pub diameter: f64,
    /// Unit direction across the flow (lift).
    pub lift: nalgebra::Vector3<f64>,
    /// Unit direction of the flow (drag).
    pub drag: nalgebra::Vector3<f64>,
    /// Translation rows of the node, row-major 3 × p.
    pub rows: &'a [f64],
}

impl FlowNode<'_> {
    /// `e_L·Φ` and `e_D·Φ` into `lift` and `drag`.
    fn directional_rows(&self, lift: &mut [f64], drag: &mut [f64]) {
        let p = lift.len();
        for i in 0..p {
            let (x, y, z) = (self.rows[i], self.rows[p + i], self.rows[2 * p + i]);
            lift[i] = self.lift.x * x + self.lift.y * y + self.lift.z * z;
            drag[i] = self.drag.x * x + self.drag.y * y + self.drag.z * z;
        }
    }
}

/// The fluid-elastic force during a run: the model's matrices with the ring buffer of past
/// displacements, allocated once.
#[derive(Debug, Clone)]
pub struct FluidElasticForce {
    /// Per group: the delay in steps `τ/Δt` split as `(m, θ)`, `τ/Δt = m + θ`, `0 ≤ θ < 1`.
    delays: Vec<(usize, f64)>,
    /// The past displacements, `slots` rows of `p`: the row of step `n` is `n mod slots`.
    ring: Vec<f64>,
    slots: usize,
    /// The delayed displacement of the group being applied.
    work: Vec<f64>,
    /// The velocity of the damping term.
    velocity: Vec<f64>,
    /// A matrix's product.
    product: Vec<f64>,
    /// The force of the step (kept for its power).
    pub force: Vec<f64>,
}

/// The state of the ring buffer, for checkpoints: the displacements of the last steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DelayHistory {
    /// Rows of `p` values, the row of step `n` at `n mod slots`.
    pub ring: Vec<f64>,
}

impl FluidElasticForce {
    /// For `fe` with time step `dt`, `p` modes, and the initial displacement `q0` (the
    /// displacement at every time before the start).
    pub fn new(fe: &FluidElastic, dt: f64, q0: &[f64]) -> Self {
        let p = q0.len();
        let delays: Vec<(usize, f64)> = fe
            .delayed
            .iter()
            .map(|g| {
                let d = g.delay / dt;
                let m = d.floor();
                (m as usize, d - m)
            })
            .collect();
        // rows n+1−m and n−m are read at step n+1: m + 2 rows
        let slots = delays.iter().map(|(m, _)| m + 2).max().unwrap_or(1);
        let mut ring = Vec::with_capacity(slots * p);
        for _ in 0..slots {
            ring.extend_from_slice(q0);
        }
        Self {
            delays,
            ring,
            slots,
            work: vec![0.0; p],
            velocity: vec![0.0; p],
            product: vec![0.0; p],
            force: vec![0.0; p],
        }
    }

    /// Memory the ring buffer will take for `fe`, bytes.
    pub fn ring_bytes(fe: &FluidElastic, dt: f64, p: usize) -> f64 {
        8.0 * (fe.longest_delay() / dt + 2.0).ceil() * p as f64
    }

    /// Stores the displacement `q` of step `n`.
    #[inline]
    pub fn record(&mut self, n: u64, q: &[f64]) {
        let p = q.len();
        let row = (n % self.slots as u64) as usize;
        self.ring[row * p..(row + 1) * p].copy_from_slice(q);
    }

    /// The force at step `n` (whose displacement [`Self::record`] stored) with the velocity
    /// `q̇ + h q̈` of the previous step's velocity and acceleration (`h = Δt`; `h = 0` at the
    /// start, where `q̇` is the initial velocity): written to [`Self::force`] and added to `out`.
    #[inline(always)]
    pub(crate) fn apply<K: Lanes>(
        &mut self,
        fe: &FluidElastic,
        n: u64,
        (qd, qdd, h): (&[f64], &[f64], f64),
        out: &mut [f64],
    ) {
        let p = qd.len();
        self.force.fill(0.0);
        for (g, &(m, theta)) in fe.delayed.iter().zip(&self.delays) {
            // q(t_n − τ) = (1 − θ) q_{n−m} + θ q_{n−m−1}; steps before 0 hold q(0)
            let row = |k: u64| {
                let r = (k % self.slots as u64) as usize;
                r * p..(r + 1) * p
            };
            let a = n.saturating_sub(m as u64);
            let b = n.saturating_sub(m as u64 + 1);
            let (ra, rb) = (row(a), row(b));
            for ((w, x), y) in self.work.iter_mut().zip(&self.ring[ra]).zip(&self.ring[rb]) {
                *w = (1.0 - theta) * x + theta * y;
            }
            g.stiffness
                .mul_add::<K>(1.0, &self.work, &mut self.product, &mut self.force);
        }
        if !fe.damping.is_empty() {
            for ((v, x), a) in self.velocity.iter_mut().zip(qd).zip(qdd) {
                *v = x + h * a;
            }
            for c in &fe.damping {
                c.mul_add::<K>(-1.0, &self.velocity, &mut self.product, &mut self.force);
            }
        }
        for (o, f) in out.iter_mut().zip(&self.force) {
            *o += f;
        }
    }

    /// The ring buffer, for a checkpoint.
    pub fn history(&self) -> DelayHistory {
        DelayHistory {
            ring: self.ring.clone(),
        }
    }

    /// Restores the ring buffer of a checkpoint; `false` when its size does not match.
    pub fn restore(&mut self, history: &DelayHistory) -> bool {
        if history.ring.len() != self.ring.len() {
            return false;
        }
        self.ring.copy_from_slice(&history.ring);
        true
    }
}
