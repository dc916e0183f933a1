//! Tangential penalty law with stick/slip statuses (THEORY §4.1, paper Algorithm 1,
//! Antunes–Axisa).
//!
//! Each contact carries a status and an anchor `x_0` (the physical position where sticking
//! started). In stick `R_T = −K_T Tᵀ(x − x_0) − C_T v_T`; stick → slip when
//! `|R_T| > μ_s R_N`; slip → stick when the slip velocity reverses
//! (`v_T^n · v_T^{n+1} ≤ 0`), the anchor then being reset to the current position; in slip
//! `R_T = −μ_d R_N v_T/|v_T|`.
//!
//! The velocity available when the forces are computed is the predicted one, `q̇*`: every
//! `v_T` here is `Tᵀ(Φ_c q̇* − v_obstacle)`. A newly closed contact starts in stick at the
//! point where it landed. After a slip → stick switch the stick force is checked against the
//! static disk at once, as for a contact already sticking (the paper's Algorithm 1 does not
//! check on that step; checking keeps `|R_T| ≤ μ_s R_N` at every step).

use nalgebra::{Vector2, Vector3};

use super::PenaltySettings;
use crate::contact::friction::{Coulomb, Slide};

/// State of one contact under the penalty law.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PenaltyContact {
    /// Whether the contact was closed at the previous step.
    pub closed: bool,
    /// Stick or slip.
    pub slide: Slide,
    /// Physical position where the current stick phase started.
    pub anchor: Vector3<f64>,
    /// Previous step's tangential velocity, for the reversal test.
    pub previous_velocity: Vector2<f64>,
}

impl Default for PenaltyContact {
    fn default() -> Self {
        Self {
            closed: false,
            slide: Slide::Stick,
            anchor: Vector3::zeros(),
            previous_velocity: Vector2::zeros(),
        }
    }
}

impl PenaltyContact {
    /// Tangential force `R_T` (tangent basis, force of the obstacle on the structure) of a
    /// closed contact at position `x` with tangential velocity `v_t` and normal force `r_n`;
    /// updates the status and anchor.
    #[inline]
    pub fn force(
        &mut self,
        law: &PenaltySettings,
        friction: &Coulomb,
        tangents: &[Vector3<f64>; 2],
        x: &Vector3<f64>,
        v_t: Vector2<f64>,
        r_n: f64,
    ) -> Vector2<f64> {
        if !self.closed {
            self.closed = true;
            self.slide = Slide::Stick;
            self.anchor = *x;
        } else if self.slide == Slide::Slip && self.previous_velocity.dot(&v_t) <= 0.0 {
            self.slide = Slide::Stick;
            self.anchor = *x;
        }
        self.previous_velocity = v_t;
        if self.slide == Slide::Stick {
            let d = x - self.anchor;
            let u = Vector2::new(tangents[0].dot(&d), tangents[1].dot(&d));
            let r = -law.stiffness * u - law.damping * v_t;
            if r.norm() <= friction.mu_static * r_n {
                return r;
            }
            self.slide = Slide::Slip;
            let dir = if v_t.norm() > 0.0 {
                v_t / v_t.norm()
            } else {
                -r / r.norm()
            };
            return -friction.mu_dynamic * r_n * dir;
        }
        let nv = v_t.norm();
        if nv > 0.0 {
            -friction.mu_dynamic * r_n * v_t / nv
        } else {
            Vector2::zeros()
        }
    }

    /// Marks the contact open.
    #[inline]
    pub fn open(&mut self) {
        self.closed = false;
    }
}
