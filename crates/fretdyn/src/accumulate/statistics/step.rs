//! One contact's values over one step, as the step hands them to the statistics
//! ([`super::ContactStatisticsState::step`], THEORY §5).

/// One contact's values over one step, at its end.
#[derive(Debug, Clone, Copy, Default)]
pub struct StepValues {
    /// End time of the step, s.
    pub t: f64,
    /// Closed at the end of the step.
    pub closed: bool,
    /// Sticking (when closed).
    pub stick: bool,
    /// Normal force `R_N`, N.
    pub normal: f64,
    /// Tangential force magnitude `|R_T|`, N.
    pub tangential: f64,
    /// Slip speed `|v_T|` (full step, relative to the obstacle), m/s.
    pub slip_speed: f64,
    /// Friction power `|R_T·v_T|`, W.
    pub friction_power: f64,
    /// Penetration `δ` (negative: the remaining clearance), m.
    pub penetration: f64,
    /// Radial offset of the point from the hole's centre (holes), or its distance to the
    /// plane / the bars' mid-plane (planes), m.
    pub radial: f64,
    /// Direction of that offset in the hole's plane, `(cos θ, sin θ)` (`(1, 0)` for planes
    /// and at the centre): the angle `θ` is only formed (`atan2`) where it is reported.
    pub direction: [f64; 2],
}

/// One contact's step as [`ContactStatisticsState::step`] takes it: an open contact's offset
/// and penetration (its forces and slip are zero, its angle unused), or a closed contact's
/// values. Most contacts are open at most steps: they cost these two numbers.
#[derive(Debug, Clone, Copy)]
pub enum ContactStep {
    /// Open at the end of the step: [`StepValues::radial`] and [`StepValues::penetration`].
    Open {
        /// The offset ([`StepValues::radial`]), m.
        radial: f64,
        /// The penetration, negative ([`StepValues::penetration`]), m.
        penetration: f64,
    },
    /// Closed at the end of the step.
    Closed(StepValues),
}

impl From<StepValues> for ContactStep {
    fn from(v: StepValues) -> Self {
        if v.closed {
            ContactStep::Closed(v)
        } else {
            ContactStep::Open {
                radial: v.radial,
                penetration: v.penetration,
            }
        }
    }
}

impl StepValues {
    /// The values of an open contact at `t` (what [`ContactStep::Open`] stands for).
    pub(super) fn open(t: f64, radial: f64, penetration: f64) -> Self {
        StepValues {
            t,
            closed: false,
            stick: true,
            normal: 0.0,
            tangential: 0.0,
            slip_speed: 0.0,
            friction_power: 0.0,
            penetration,
            radial,
            direction: [1.0, 0.0],
        }
    }
}

/// The angle `θ` of a direction `(cos θ, sin θ)` ([`StepValues::direction`]), degrees in
/// (−180, 180].
pub(super) fn angle_deg(direction: [f64; 2]) -> f64 {
    direction[1].atan2(direction[0]).to_degrees()
}
