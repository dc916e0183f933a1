//! Phase 3a of a step — the penalty tangential law: each closed contact's tangential force
//! from its anchor on the obstacle, an open one's anchor let go (THEORY §4.1).

use super::contact_kinds::ContactKinds;
use super::contact_state::contact_states;
use super::step::Simulation;
use super::workspace::Tangential;

impl Simulation<'_> {
    /// With the penalty law, the tangential forces of the closed contacts and their slide
    /// status; nothing with the Lagrange methods (never compiled in the common case).
    #[inline(always)]
    pub(super) fn penalty_forces<O: ContactKinds>(&mut self) {
        let (true, Tangential::Penalty { settings }) = (O::penalty(true), &self.work.tangential)
        else {
            return;
        };
        let contacts = &mut self.state.penalty;
        for (k, (c, state)) in contact_states(self.model, &mut self.state.contacts) {
            if state.closed {
                let vt = state.tangential_velocity();
                state.tangential_force = contacts[k].force(
                    settings,
                    &c.friction,
                    &state.frame.tangents,
                    &state.x_relative,
                    vt,
                    state.normal_force,
                );
                state.slide = contacts[k].slide;
            } else {
                contacts[k].open();
            }
        }
    }
}
