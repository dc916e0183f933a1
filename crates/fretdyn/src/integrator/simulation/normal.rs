//! Phase 2 of a step — the modal force: external force plus the contact forces of the closed
//! contacts, with the penalty tangential law (THEORY §2 step 4, §4.1), and the free
//! acceleration it gives (step 5).

use super::contact_kinds::ContactKinds;
use super::{Simulation, Tangential, contact_rows, contact_states};
use crate::numerics::Lanes;
use crate::structure::modal::project_add;

impl Simulation<'_> {
    /// Steps 4–5: the modal force ([`Self::contact_forces`]) and the free acceleration. With
    /// one closed contact of the common case (a fixed plane's or bars' row, no tangential
    /// force before the Lagrange solve) in one pass over the modes, the force `f_ext + s (n·Φ_c)ᵀ`
    /// not formed ([`Lanes::free_acceleration_plus`]: the same bits).
    #[inline(always)]
    pub(super) fn free_acceleration<K: Lanes, O: ContactKinds>(&mut self) {
        if let (true, &[k]) = (O::COMMON, self.closed.as_slice())
            && let Some(rows) = O::rows(&self.frame_rows[k])
        {
            let state = &self.contacts[k];
            debug_assert_eq!(state.tangential_force, nalgebra::Vector2::zeros());
            let (s, row) = rows.normal_projection(&state.frame.normal, state.normal_force);
            if self
                .cd
                .free_acceleration_plus_with::<K>(&self.external, s, row)
            {
                return;
            }
        }
        self.contact_forces::<K, O>();
        self.cd
            .free_acceleration_with::<K>(modal_force(&self.closed, &self.external, &self.force));
    }

    /// Step 4 (and the penalty tangential forces): modal force `f = f_ext + Σ Φ_cᵀ R_c`,
    /// formed only when a contact is closed ([`modal_force`] is `f_ext` otherwise).
    #[inline(always)]
    pub(super) fn contact_forces<K: Lanes, O: ContactKinds>(&mut self) {
        if let (true, Tangential::Penalty { settings, contacts }) =
            (O::penalty(true), &mut self.tangential)
        {
            for (k, (c, state)) in contact_states(self.model, &mut self.contacts) {
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
        if self.closed.is_empty() {
            return;
        }
        self.force.copy_from_slice(&self.external);
        for &k in &self.closed {
            let state = &self.contacts[k];
            match O::rows(&self.frame_rows[k]) {
                Some(rows) => rows.project_add::<K>(
                    &state.frame.normal,
                    state.normal_force,
                    &state.tangential_force,
                    &mut self.force,
                ),
                None => project_add(
                    contact_rows(self.model, &self.surface_rows, k),
                    &state.force(),
                    &mut self.force,
                ),
            }
        }
    }
}

/// The modal force of the step: the external force when no contact is closed, else the one
/// [`Simulation::contact_forces`] formed.
#[inline(always)]
pub(super) fn modal_force<'a>(
    closed: &[usize],
    external: &'a [f64],
    force: &'a [f64],
) -> &'a [f64] {
    if closed.is_empty() { external } else { force }
}
