//! Phase 1 of a step — the loads: the external modal force at `t` (the loads' time histories,
//! the turbulence, THEORY §10; the fluid-elastic force, THEORY §13), the first load's formed
//! in the predictor's pass over the modes (THEORY §2 steps 1–2).

use super::step::Simulation;
use crate::numerics::Lanes;

impl Simulation<'_> {
    /// The external modal force of step `n`, at `t = n Δt`: `Σ_l s_l(t) Φ_lᵀ F_l` over the
    /// loads' rows (the histories' sines rotated from step to step, THEORY §10), plus the
    /// turbulence (THEORY §10). The step forms the first load's with the predictor instead
    /// ([`Self::predict_with_first_load`]).
    #[inline(always)]
    pub(super) fn external_force<K: Lanes>(&mut self, n: u64, t: f64) {
        let w = &mut self.work;
        let p = w.external.len();
        // the first load sets the force, the others add to it
        match w.load_histories.first_mut() {
            Some(first) => K::scale(&mut w.external, first.value(n, t), &w.load_rows[..p]),
            None => w.external.fill(0.0),
        }
        self.other_loads::<K>(n, t);
    }

    /// Steps 1–2 (the predictor) of step `n` and, in the same pass over the modes, the first
    /// load's force: the start of [`Self::external_force`] (the same bits), which
    /// [`Self::other_loads`] completes.
    #[inline(always)]
    pub(super) fn predict_with_first_load<K: Lanes>(&mut self, n: u64, t: f64) {
        let w = &mut self.work;
        let p = w.external.len();
        match w.load_histories.first_mut() {
            Some(first) => {
                let s = first.value(n, t);
                w.cd.predict_and_scale_with::<K>(
                    &mut self.state.modal,
                    &mut w.external,
                    s,
                    &w.load_rows[..p],
                );
            }
            None => {
                w.cd.predict_with::<K>(&mut self.state.modal);
                w.external.fill(0.0);
            }
        }
    }

    /// The loads after the first and the turbulence, added to the external force.
    #[inline(always)]
    pub(super) fn other_loads<K: Lanes>(&mut self, n: u64, t: f64) {
        let w = &mut self.work;
        let p = w.external.len();
        // (one load, the common case, skips the set-up of the loop: its rows' count is a
        // division)
        if w.load_histories.len() > 1 {
            for (history, row) in w.load_histories[1..]
                .iter_mut()
                .zip(w.load_rows[p..].chunks_exact(p.max(1)))
            {
                K::axpy(&mut w.external, history.value(n, t), row);
            }
        }
        if w.turbulence.is_empty() {
            return;
        }
        for (load, generator) in self.model.turbulence.iter().zip(&mut w.turbulence) {
            let r = generator.channels();
            let xi = &mut w.signals[..r];
            generator.values(t, xi);
            for (x, row) in xi.iter().zip(load.rows.chunks_exact(p.max(1))) {
                K::axpy(&mut w.external, *x, row);
            }
        }
    }

    /// The fluid-elastic force of step `n` added to the external force (THEORY §13): the
    /// displacement of the step is stored for the delays; the velocity is extrapolated from
    /// the previous step's (`started`), or is the initial one.
    #[inline(always)]
    pub(super) fn fluid_elastic_force<K: Lanes>(&mut self, n: u64, started: bool) {
        let w = &mut self.work;
        let (Some(fluid), Some(fe)) = (&mut w.fluid, &self.model.fluid_elastic) else {
            return;
        };
        let x = &self.state.modal;
        fluid.record(n, &x.q);
        let h = if started { self.settings.dt } else { 0.0 };
        fluid.apply::<K>(fe, n, (&x.qd, &x.qdd, h), &mut w.external);
    }
}
