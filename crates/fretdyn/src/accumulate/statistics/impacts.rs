//! Impacts (THEORY §5): an impact starts when the contact closes after being open longer than
//! the rest duration and ends at the last opening before such a rest; [`ImpactTracker`]
//! follows one contact's, [`Impact`] is a finished one (a row of `impacts.csv`).

use serde::{Deserialize, Serialize};

use super::step::{StepValues, angle_deg};

/// A finished impact (per-impact table).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Impact {
    /// Index of the contact.
    pub contact: usize,
    /// Start (first closing, interpolated), s.
    pub start: f64,
    /// Duration from the first closing to the last opening, s.
    pub duration: f64,
    /// Time spent closed within it, s.
    pub contact_time: f64,
    /// Time of the peak normal force, s.
    pub peak_time: f64,
    /// Peak normal force, N.
    pub peak_force: f64,
    /// Normal impulse `∫R_N dt`, N·s.
    pub impulse: f64,
    /// Normal approach speed at the first closing, m/s: `(δ_{n+1} − δ_n)/Δt` over the step
    /// where it closes, the central-difference velocity `q̇_{n+½}`, on which no contact force
    /// has acted yet. For an impact under way when the statistics window opens (it starts
    /// there, [`ContactStatisticsState::open_window`]): the normal approach speed `δ̇` at the
    /// window's start, from the full-step velocity `q̇` there (at t = 0 the initial velocity;
    /// negative when the contact is opening).
    pub impact_speed: f64,
    /// Normal separation speed at the last opening, m/s: `(δ_n − δ_{n+1})/Δt` over the step
    /// where it opens.
    pub rebound_speed: f64,
    /// Rebounds (openings shorter than the rest duration) within the impact.
    pub rebounds: u32,
    /// Angle of the contact point in the hole's plane at the peak, degrees (0 for planes).
    pub angle_deg: f64,
}

/// Follows one contact's impacts.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub(super) struct ImpactTracker {
    pub(super) active: bool,
    pub(super) open: bool,
    pub(super) current: Option<Impact>,
    pub(super) last_opening: f64,
    pub(super) previous_penetration: f64,
    pub(super) previous_t: f64,
    /// The current impact started in a step of the window: it is counted in the window's
    /// impacts, and its row and duration go to the window's table when it ends.
    pub(super) in_window: bool,
    /// [`StepValues::direction`] at the current impact's peak: its angle
    /// ([`Impact::angle_deg`]) is formed when the impact ends ([`Self::end`]).
    pub(super) peak_direction: [f64; 2],
}

impl ImpactTracker {
    /// [`Self::step`] of an open contact with no impact in progress (`active` false): it
    /// neither starts nor ends one, and only its penetration and time are kept for the next
    /// crossing.
    #[inline]
    pub(super) fn idle(&mut self, t: f64, penetration: f64) {
        self.previous_penetration = penetration;
        self.previous_t = t;
    }

    /// Zero crossing of the penetration between the previous step and this one.
    fn crossing(&self, v: &StepValues) -> f64 {
        let (d0, d1) = (self.previous_penetration, v.penetration);
        if d0 != d1 && (d0 <= 0.0) != (d1 <= 0.0) {
            self.previous_t + (v.t - self.previous_t) * (d0 / (d0 - d1))
        } else {
            v.t
        }
    }

    /// One step, `in_window` when it counts in the window; returns `(started, finished
    /// impact)` (whether that impact started in the window is [`Self::in_window`]). The
    /// common step of a closed contact, within its impact and not reclosing, in line; the
    /// others by [`Self::step_in_general`].
    #[inline(always)]
    pub(super) fn step(
        &mut self,
        contact: usize,
        v: &StepValues,
        rest: f64,
        in_window: bool,
    ) -> (bool, Option<Impact>) {
        if v.closed
            && self.active
            && !self.open
            && let Some(imp) = &mut self.current
        {
            let dt = v.t - self.previous_t;
            Self::add_closed(imp, &mut self.peak_direction, v, dt);
            self.previous_penetration = v.penetration;
            self.previous_t = v.t;
            return (false, None);
        }
        self.step_in_general(contact, v, rest, in_window)
    }

    /// A closed step of impact `imp` (of `dt`, its values `v`): its impulse, its contact
    /// time and its peak.
    #[inline(always)]
    fn add_closed(imp: &mut Impact, peak_direction: &mut [f64; 2], v: &StepValues, dt: f64) {
        imp.impulse += v.normal * dt;
        imp.contact_time += dt;
        if v.normal > imp.peak_force {
            imp.peak_force = v.normal;
            imp.peak_time = v.t;
            *peak_direction = v.direction;
        }
    }

    /// The current impact, ended: its angle at the peak formed.
    pub(super) fn end(&mut self) -> Option<Impact> {
        self.current.take().map(|mut imp| {
            imp.angle_deg = angle_deg(self.peak_direction);
            imp
        })
    }

    /// [`Self::step`], every case.
    #[inline(never)]
    fn step_in_general(
        &mut self,
        contact: usize,
        v: &StepValues,
        rest: f64,
        in_window: bool,
    ) -> (bool, Option<Impact>) {
        let dt = v.t - self.previous_t;
        let mut started = false;
        let mut finished = None;
        if v.closed {
            match (&mut self.current, self.active) {
                (Some(imp), true) => {
                    if self.open {
                        imp.rebounds += 1;
                        self.open = false;
                    }
                }
                _ => {
                    started = true;
                    self.active = true;
                    self.open = false;
                    self.in_window = in_window;
                    self.current = Some(Impact {
                        contact,
                        start: self.crossing(v),
                        impact_speed: (v.penetration - self.previous_penetration) / dt,
                        duration: 0.0,
                        contact_time: 0.0,
                        peak_time: v.t,
                        peak_force: 0.0,
                        impulse: 0.0,
                        rebound_speed: 0.0,
                        rebounds: 0,
                        angle_deg: 0.0,
                    });
                    self.peak_direction = v.direction;
                }
            }
            if let Some(imp) = &mut self.current {
                Self::add_closed(imp, &mut self.peak_direction, v, dt);
            }
        } else if self.active {
            if !self.open {
                self.open = true;
                self.last_opening = self.crossing(v);
                if let Some(imp) = &mut self.current {
                    imp.rebound_speed = (self.previous_penetration - v.penetration) / dt;
                }
            }
            if v.t - self.last_opening > rest {
                self.active = false;
                self.open = false;
                if let Some(mut imp) = self.end() {
                    imp.duration = self.last_opening - imp.start;
                    finished = Some(imp);
                }
            }
        }
        self.previous_penetration = v.penetration;
        self.previous_t = v.t;
        (started, finished)
    }
}
