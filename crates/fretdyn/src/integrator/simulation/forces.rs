//! Phase 3 of a step — the forces: the modal force, external force plus the contact forces
//! of the closed contacts (THEORY §2 step 4), and the free acceleration it gives (step 5).
//! The penalty tangential law sets its forces first (`penalty`).

use super::contact_kinds::ContactKinds;
use super::step::Simulation;
use super::workspace::{contact_rows, modal_force};
use crate::numerics::Lanes;
use crate::structure::modal::project_add;

impl Simulation<'_> {
    /// Steps 4–5: the modal force ([`Self::contact_forces`]) and the free acceleration. With
    /// one closed contact of the common case (a fixed plane's or bars' row, no tangential
    /// force before the Lagrange solve) in one pass over the modes, the force `f_ext + s (n·Φ_c)ᵀ`
    /// not formed ([`Lanes::free_acceleration_plus`]: the same bits).
    #[inline(always)]
    pub(super) fn free_acceleration<K: Lanes, O: ContactKinds>(&mut self) {
        let w = &mut self.work;
        if let (true, &[k]) = (O::COMMON, w.closed.as_slice())
            && let Some(rows) = O::rows(&w.frame_rows[k])
        {
            let state = &self.state.contacts[k];
            debug_assert_eq!(state.tangential_force, nalgebra::Vector2::zeros());
            let (s, row) = rows.normal_projection(&state.frame.normal, state.normal_force);
            if w.cd
                .free_acceleration_plus_with::<K>(&mut self.state.modal, &w.external, s, row)
            {
                return;
            }
        }
        self.contact_forces::<K, O>();
        let w = &mut self.work;
        w.cd.free_acceleration_with::<K>(
            &mut self.state.modal,
            modal_force(&w.closed, &w.external, &w.force),
        );
    }

    /// Step 4 (and the penalty tangential forces, [`Self::penalty_forces`]): modal force
    /// `f = f_ext + Σ Φ_cᵀ R_c`, formed only when a contact is closed ([`modal_force`] is
    /// `f_ext` otherwise).
    #[inline(always)]
    pub(super) fn contact_forces<K: Lanes, O: ContactKinds>(&mut self) {
        self.penalty_forces::<O>();
        let w = &mut self.work;
        if w.closed.is_empty() {
            return;
        }
        w.force.copy_from_slice(&w.external);
        for &k in &w.closed {
            let state = &self.state.contacts[k];
            match O::rows(&w.frame_rows[k]) {
                Some(rows) => rows.project_add::<K>(
                    &state.frame.normal,
                    state.normal_force,
                    &state.tangential_force,
                    &mut w.force,
                ),
                None => project_add(
                    contact_rows(self.model, &w.surface_rows, k),
                    &state.force(),
                    &mut w.force,
                ),
            }
        }
    }
}
