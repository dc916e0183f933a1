//! The contacts' preloads applied to a model (THEORY §16.1): the planes pressed by their
//! interferences (given, or found from the forces at rest) and the run started at rest in the
//! static equilibrium ([`super::equilibrium`]), so that the first step sees no jolt.
//!
//! A force `F_j` at rest is met exactly: at the equilibrium, contact `j` pushes `F_j g_j`
//! (`g_j = Φ_jᵀ n_j`, constant on a plane), so the equilibrium of the model *without* the
//! force-preloaded contacts under the modal force `Σ_j F_j g_j` is `q*`; contact `j` must then
//! penetrate by `F_j / K_N,j` at `q*`, i.e. its plane is pressed by
//! `I_j = F_j / K_N,j − δ_j(q*)` (`δ_j` the penetration of the plane as given). With these
//! interferences `q*` is the equilibrium of the whole model (unique: the potential energy
//! `½ qᵀKq + Σ ½ K_N max(0, δ)² − fᵀq` is strictly convex), which is computed again to give
//! every contact's force at rest.

use super::Model;
use super::equilibrium::{StaticState, contact_at, static_equilibrium};
use crate::contact::preload::{Preload, PreloadInput, pressed};
use crate::error::{Error, Result};

/// Presses every preloaded contact's plane by its interference (the given one, or the one
/// that gives its force at rest), records `(interference, force)` in its
/// [`Preload::applied`], and adds the static equilibrium to the initial state (`q0 = q_static
/// + q_given`, `q̇0` as given: `[initial]` is a perturbation of the equilibrium). Returns the
/// equilibrium, or `None` (and changes nothing) when no contact has a preload not yet applied.
pub fn apply_preloads(model: &mut Model) -> Result<Option<StaticState>> {
    let pending: Vec<usize> = (0..model.contacts.len())
        .filter(|k| matches!(&model.contacts[*k].preload, Some(p) if p.applied.is_none()))
        .collect();
    if pending.is_empty() {
        return Ok(None);
    }
    let p = model.basis.modes();
    let mut forced = Vec::new();
    let mut interference = vec![0.0; model.contacts.len()];
    for &k in &pending {
        let field = format!("contacts[{k}]");
        let c = &model.contacts[k];
        Preload::plane(&c.obstacle, &field)?;
        match c.preload.map(|p| p.input) {
            Some(PreloadInput::Interference(i)) => interference[k] = i,
            Some(PreloadInput::Force(f)) => forced.push((k, f)),
            None => {}
        }
    }
    if !forced.is_empty() {
        // the equilibrium without the force-preloaded contacts, pressed by their forces
        let mut g = vec![0.0; p];
        let mut force = vec![0.0; p];
        for &(k, f) in &forced {
            contact_at(model, k, &vec![0.0; p], &mut g);
            force.iter_mut().zip(&g).for_each(|(a, b)| *a += f * b);
        }
        let mut contacts = Vec::with_capacity(model.contacts.len());
        for (k, c) in model.contacts.iter().enumerate() {
            if forced.iter().all(|(j, _)| *j != k) {
                let mut c = c.clone();
                if c.preload.is_some() {
                    c.obstacle = pressed(&c.obstacle, interference[k], &format!("contacts[{k}]"))?;
                }
                contacts.push(c);
            }
        }
        let reduced = Model {
            contacts,
            ..model.clone()
        };
        let star = static_equilibrium(&reduced, Some(&force)).map_err(in_case)?;
        for &(k, f) in &forced {
            let delta = contact_at(model, k, &star.q, &mut g);
            interference[k] = f / model.contacts[k].normal.stiffness - delta;
        }
    }
    for &k in &pending {
        let field = format!("contacts[{k}]");
        let c = &mut model.contacts[k];
        c.obstacle = pressed(&c.obstacle, interference[k], &field)?;
    }
    let state = static_equilibrium(model, None).map_err(in_case)?;
    for &k in &pending {
        if let Some(pre) = &mut model.contacts[k].preload {
            pre.applied = Some((interference[k], state.forces[k]));
        }
    }
    for (q0, qs) in model.initial.q.iter_mut().zip(&state.q) {
        *q0 += qs;
    }
    Ok(Some(state))
}

/// An error of the static equilibrium, named by the case key that asked for it.
fn in_case(e: Error) -> Error {
    match e {
        Error::Invalid { message, .. } => Error::invalid(
            "contacts.preload",
            format!("the static preloaded equilibrium: {message}"),
        ),
        other => other,
    }
}
