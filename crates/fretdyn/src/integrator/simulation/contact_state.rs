//! One contact's state within a step and after it (THEORY §3, §5): its frame, position,
//! velocities, forces and status, and the values the statistics read of it.

use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::accumulate::statistics::{ContactStep, StepValues};
use crate::contact::Contact;
use crate::contact::frame_rows::FrameRows;
use crate::contact::friction::Slide;
use crate::contact::obstacle::ContactFrame;
use crate::model::Model;

/// Per-contact state within a step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(super) struct ContactState {
    pub(super) frame: ContactFrame,
    /// Physical position of the point: updated at every step for a hole, at output samples
    /// only for a plane or bars (whose detection needs [`Self::distance`] only).
    pub(super) x: Vector3<f64>,
    /// Plane or bars ([`FrameRows`]): the signed distance `s = (x − d(t) − x₀)·n`.
    pub(super) distance: f64,
    /// Position of the contact point (on the surface for a tube contact) relative to the
    /// moving obstacle: the penalty law's anchor lives in this frame.
    pub(super) x_relative: Vector3<f64>,
    /// Velocity of the point relative to the obstacle along the frame's normal (predicted
    /// during the step, full-step after; see
    /// [`Simulation::full_step_velocities`](super::Simulation)); formed only when the normal
    /// law has damping, 0 otherwise.
    pub(super) v_normal: f64,
    /// Its tangential velocity relative to the obstacle, tangent basis.
    pub(super) v_tangential: Vector2<f64>,
    pub(super) normal_force: f64,
    /// Tangential force of the obstacle on the structure, tangent basis.
    pub(super) tangential_force: Vector2<f64>,
    pub(super) closed: bool,
    pub(super) slide: Slide,
    /// Lagrange methods: the stick constraint held this contact's full-step velocity to the
    /// obstacle's — it sticks at this step and, with the half-step constraint, stuck at the
    /// previous one too, so both half-step velocities whose mean is `q̇_{n+1}` were imposed
    /// (THEORY §2). Its slip velocity is then zero by construction and is reported as exactly
    /// 0, without the round-off of `Φ_c q̇_{n+1}` (THEORY §5: in stick `v_T = 0`). Set within
    /// each step, so not part of a checkpoint.
    #[serde(skip)]
    pub(super) held: bool,
}

impl ContactState {
    /// An open contact at rest, its frame zero (set by detection).
    pub(super) fn blank() -> Self {
        Self {
            frame: ContactFrame {
                penetration: 0.0,
                normal: Vector3::zeros(),
                tangents: [Vector3::zeros(); 2],
                velocity: Vector3::zeros(),
            },
            x: Vector3::zeros(),
            distance: 0.0,
            x_relative: Vector3::zeros(),
            v_normal: 0.0,
            v_tangential: Vector2::zeros(),
            normal_force: 0.0,
            tangential_force: Vector2::zeros(),
            closed: false,
            slide: Slide::Stick,
            held: false,
        }
    }

    /// Contact force on the structure, global axes: `R_N n + T R_T`.
    pub(super) fn force(&self) -> Vector3<f64> {
        let t = &self.frame.tangents;
        self.frame.normal * self.normal_force
            + t[0] * self.tangential_force.x
            + t[1] * self.tangential_force.y
    }

    /// Tangential velocity relative to the obstacle, tangent basis; exactly 0 when
    /// [held](Self::held) in stick.
    pub(super) fn tangential_velocity(&self) -> Vector2<f64> {
        if self.held {
            return Vector2::zeros();
        }
        self.v_tangential
    }

    /// True when `R_N² + |R_T|² + δ² + |v|²` (`v` of a closed contact only: an open one's is
    /// not used) is at most `bound/4` (false for a non-finite value). Then every increment
    /// the statistics form from the contact's values is at most `bound`
    /// ([`Simulation::accumulation_bound`](super::Simulation::accumulation_bound)): the
    /// squares of the forces and of the penetration, the friction powers
    /// `|R_T·v_T| ≤ (|R_T|² + |v|²)/2` and `R_N |v_T| ≤ (R_N² + |v|²)/2` (THEORY §5), and the
    /// point's offset, which is the penetration give or take the obstacle's clearance.
    #[inline]
    pub(super) fn accumulable(&self, bound: f64) -> bool {
        let v2 = if self.closed {
            self.v_normal * self.v_normal + self.v_tangential.norm_squared()
        } else {
            0.0
        };
        self.normal_force * self.normal_force
            + self.tangential_force.norm_squared()
            + self.frame.penetration * self.frame.penetration
            + v2
            <= 0.25 * bound
    }

    pub(super) fn status_code(&self) -> i8 {
        match (self.closed, self.slide) {
            (false, _) => 0,
            (true, Slide::Stick) => 1,
            (true, Slide::Slip) => 2,
        }
    }

    /// The step ending at `t` for the statistics (THEORY §5): an open contact's offset and
    /// penetration, or a closed one's [`Self::values`]. `c` is the contact, `rows` its frame
    /// rows if any.
    #[inline(always)]
    pub(super) fn statistics_step(
        &self,
        c: &Contact,
        rows: Option<&FrameRows>,
        t: f64,
    ) -> ContactStep {
        if self.closed {
            ContactStep::Closed(self.values(c, rows, t))
        } else {
            ContactStep::Open {
                radial: self.offset(c, rows, t).0,
                penetration: self.frame.penetration,
            }
        }
    }

    /// The offset of the contact and its direction ([`StepValues::radial`],
    /// [`StepValues::direction`]).
    #[inline(always)]
    fn offset(&self, c: &Contact, rows: Option<&FrameRows>, t: f64) -> (f64, [f64; 2]) {
        if rows.is_some() {
            // a plane or bars: the distance from the (mid-)plane, THEORY §5
            (self.distance, [1.0, 0.0])
        } else if c.obstacle.is_hole() {
            let local = c.local(&self.x, t);
            let r = local.norm();
            let unit = if r > 0.0 {
                [local.x / r, local.y / r]
            } else {
                [1.0, 0.0]
            };
            (r, unit)
        } else {
            (c.local(&self.x, t).x, [1.0, 0.0])
        }
    }

    /// The contact's values of the step ending at `t`, for the statistics (THEORY §5).
    #[inline(always)]
    pub(super) fn values(&self, c: &Contact, rows: Option<&FrameRows>, t: f64) -> StepValues {
        let (radial, direction) = self.offset(c, rows, t);
        let (slip_speed, friction_power, tangential) = if self.closed {
            let vt = self.tangential_velocity();
            (
                vt.norm(),
                self.tangential_force.dot(&vt).abs(),
                self.tangential_force.norm(),
            )
        } else {
            (0.0, 0.0, 0.0)
        };
        StepValues {
            t,
            closed: self.closed,
            stick: self.slide == Slide::Stick,
            normal: self.normal_force,
            tangential,
            slip_speed,
            friction_power,
            penetration: self.frame.penetration,
            radial,
            direction,
        }
    }
}

/// The model's contacts with their states, by index: the loop of the contact phases.
#[inline]
pub(super) fn contact_states<'a>(
    model: &'a Model,
    states: &'a mut [ContactState],
) -> impl Iterator<Item = (usize, (&'a Contact, &'a mut ContactState))> {
    model.contacts.iter().zip(states).enumerate()
}
