//! The contact frame projected on the modes, for obstacles whose normal never turns (planes
//! and bars, fixed or translating): the rows `n·Φ_c`, `t₁·Φ_c`, `t₂·Φ_c` (THEORY §3, §9).
//!
//! With them, the signed distance of the point along the obstacle's normal is one dot product
//! on the modal coordinates,
//!
//! ```text
//! s = (x − d(t) − x₀)·n = (n·Φ_c) q + (x_c − x₀)·n − d(t)·n,
//! ```
//!
//! from which the obstacle gives the penetration (plane `δ = −s − g`, bars `δ = |s| − g`):
//! an open contact costs that dot product and nothing else; its 3-D position is recombined
//! only for an output sample. A closed contact's velocity in its frame is
//! `(n·Φ_c q̇ − n·ḋ, t_a·Φ_c q̇ − t_a·ḋ)` (three dot products, not a 3-D recombination and
//! its projection), and its force enters the modal force as `R_N (n·Φ_c)ᵀ + R_T,a (t_a·Φ_c)ᵀ`.

use nalgebra::{Vector2, Vector3};

use crate::contact::Contact;
use crate::contact::motion::Motion;
use crate::contact::obstacle::ContactFrame;
use crate::numerics::Lanes;
use crate::structure::modal::Point;

/// The frame rows of one contact (see the module's documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameRows {
    /// `[n·Φ_c, t₁·Φ_c, t₂·Φ_c]`, p values each; `n` is the obstacle's normal as declared
    /// (for bars, the normal of the side reached at `s < 0`).
    /// (Three vectors, not one of `3p` values sliced at every use: a step takes a contact's
    /// rows several times.)
    rows: [Vec<f64>; 3],
    normal: Vector3<f64>,
    tangents: [Vector3<f64>; 2],
    /// `(x_c − x₀)·n`.
    offset: f64,
    gap: f64,
    /// Bars: the obstacle on both sides.
    two_sided: bool,
}

impl FrameRows {
    /// The rows of `contact` at `point`, when its obstacle's normal never turns (a plane or
    /// bars; on the tube surface only for a plane, whose surface rows
    /// [`Contact::surface_rows`] are then fixed too); `None` otherwise.
    pub fn new(contact: &Contact, point: &Point) -> Option<Self> {
        let tangents = contact.fixed_tangents()?;
        let (normal, origin, gap, two_sided) = contact.obstacle.fixed_normal()?;
        let p = point.rows.len() / 3;
        let mut surface = point.rows.clone();
        if contact.at_surface() {
            contact.surface_rows(point, &normal, &mut surface);
        }
        let mut rows = [vec![0.0; p], vec![0.0; p], vec![0.0; p]];
        // the normal row from the point's own rows (n·(R n × Θ) = 0: the surface adds nothing
        // along the normal), the tangent rows from the contact point's
        for (d, (dir, src)) in [
            (normal, &point.rows),
            (tangents[0], &surface),
            (tangents[1], &surface),
        ]
        .iter()
        .enumerate()
        {
            let out = &mut rows[d];
            for (i, o) in out.iter_mut().enumerate() {
                *o = dir.x * src[i] + dir.y * src[p + i] + dir.z * src[2 * p + i];
            }
        }
        Some(Self {
            rows,
            normal,
            tangents,
            offset: (point.coords - origin).dot(&normal),
            gap,
            two_sided,
        })
    }

    /// `+1` when `normal` is the declared normal, `−1` for its opposite (the other bar).
    #[inline(always)]
    fn sign(&self, normal: &Vector3<f64>) -> f64 {
        if *normal == self.normal { 1.0 } else { -1.0 }
    }

    /// The row `n·Φ_c` (`a = 0`) or `t_a·Φ_c` (`a = 1, 2`).
    #[inline(always)]
    pub fn row(&self, a: usize) -> &[f64] {
        &self.rows[a]
    }

    /// Signed distance `s` along the declared normal at time `t` for modal displacements `q`
    /// (`fixed`: whether the obstacle's `motion` is [fixed](Motion::is_fixed), which the
    /// caller may know when it is compiled).
    #[inline(always)]
    pub(crate) fn distance<K: Lanes>(
        &self,
        q: &[f64],
        fixed: bool,
        motion: &Motion,
        t: f64,
    ) -> f64 {
        let s = self.distance_from_dot(K::dot(self.row(0), q));
        if fixed {
            s
        } else {
            s - motion.at(t).0.dot(&self.normal)
        }
    }

    /// The signed distance `s` of a fixed obstacle from the dot product `(n·Φ_c) q`
    /// ([`Self::distance`] with the dot product formed by the caller).
    #[inline(always)]
    pub(crate) fn distance_from_dot(&self, dot: f64) -> f64 {
        dot + self.offset
    }

    /// Sets the penetration and the normal of `frame` for the distance `s` (the obstacle's
    /// `frame` of THEORY §3 without the 3-D position: plane `δ = −s − g`, normal `n`; bars
    /// `δ = |s| − g`, normal `−sign(s) n`). The tangents are the fixed ones.
    #[inline(always)]
    pub fn update(&self, s: f64, frame: &mut ContactFrame) {
        if self.two_sided {
            frame.penetration = s.abs() - self.gap;
            frame.normal = if s >= 0.0 { -self.normal } else { self.normal };
        } else {
            frame.penetration = -s - self.gap;
        }
    }

    /// The frame at distance `s` (fixed tangents, obstacle at rest: a moving obstacle's
    /// velocity is set by the caller).
    pub fn frame(&self, s: f64) -> ContactFrame {
        let mut frame = ContactFrame {
            penetration: 0.0,
            normal: self.normal,
            tangents: self.tangents,
            velocity: Vector3::zeros(),
        };
        self.update(s, &mut frame);
        frame
    }

    /// Tangential velocity relative to the obstacle, `v_t = T·(Φ_c q̇ − v̄)`, for modal
    /// velocities `qd` and the obstacle's velocity `v̄` (`None` for a fixed obstacle: nothing
    /// to subtract, and `T·Φ_c q̇ − 0` would be the same bits — the sums are never `−0`).
    #[inline(always)]
    pub(crate) fn tangential_velocity<K: Lanes>(
        &self,
        qd: &[f64],
        obstacle: Option<&Vector3<f64>>,
    ) -> Vector2<f64> {
        // one pass over q̇ for both rows (a·b = b·a bit for bit: the same sums as two dots)
        let (t1, t2) = K::dot2(qd, self.row(1), self.row(2));
        let v = Vector2::new(t1, t2);
        match obstacle {
            Some(o) => v - Vector2::new(self.tangents[0].dot(o), self.tangents[1].dot(o)),
            None => v,
        }
    }

    /// Normal velocity relative to the obstacle along the frame's normal (positive away from
    /// the obstacle), `v_n = n·(Φ_c q̇ − v̄)`.
    #[inline(always)]
    pub(crate) fn normal_velocity<K: Lanes>(
        &self,
        frame: &ContactFrame,
        qd: &[f64],
        obstacle: &Vector3<f64>,
    ) -> f64 {
        self.sign(&frame.normal) * (K::dot(self.row(0), qd) - self.normal.dot(obstacle))
    }

    /// The normal force's modal force `Φ_cᵀ R_N n = s (n·Φ_c)ᵀ` as its coefficient `s` and
    /// row `n·Φ_c`, for the frame's normal `normal` (the declared one or its opposite).
    #[inline(always)]
    pub(crate) fn normal_projection(
        &self,
        normal: &Vector3<f64>,
        normal_force: f64,
    ) -> (f64, &[f64]) {
        (self.sign(normal) * normal_force, self.row(0))
    }

    /// `f += Φ_cᵀ (R_N n + T R_T)` for the frame's normal `normal` (the declared one or its
    /// opposite).
    #[inline(always)]
    pub(crate) fn project_add<K: Lanes>(
        &self,
        normal: &Vector3<f64>,
        normal_force: f64,
        tangential: &Vector2<f64>,
        f: &mut [f64],
    ) {
        let (s, row) = self.normal_projection(normal, normal_force);
        K::axpy(f, s, row);
        if tangential.x != 0.0 {
            K::axpy(f, tangential.x, self.row(1));
        }
        if tangential.y != 0.0 {
            K::axpy(f, tangential.y, self.row(2));
        }
    }
}
