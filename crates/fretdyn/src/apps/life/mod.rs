//! Service life (THEORY §14.5): the wear depth of each contact over years, with the scar fed
//! back into the obstacle's geometry.
//!
//! The vibration is simulated over a representative window (the case's `[time]` and
//! `[statistics]` window), from the case's initial state, on the obstacles worn so far. Each
//! contact's wear work rate `W` of the window and where it was done ([`WearMap`]) drive its
//! wear laws over a life step `[t, t + Δt]` at constant `W`: the tube's and the support's
//! volumes grow by `ΔV = ∫ V̇(W, τ) dτ`, spread over the bins of the map in the proportions of
//! the window's work; the scar geometry turns each volume into a depth ([`crate::wear`]). The
//! obstacle then recedes by the tube's plus the support's depth in the direction the scar
//! faces ([`crate::contact::scar`]) and the next window is simulated, until the target time.
//!
//! The life step is the longest (up to the target) over which no contact's depth (tube plus
//! support, where it is deepest) grows by more than `max_depth_change × max(g₀ + D, d_res)`,
//! `g₀` the contact's clearance at rest, `D` its depth so far and `d_res` the depth
//! resolution; it is found by bisection, the depth being monotone in `Δt`. Halving
//! `max_depth_change` shows the convergence (docs/WEAR.md).
//!
//! The same windows give the fixed-gap extrapolation (the first window's rates kept for the
//! whole life, as a post-processing of one run does) beside the coupled result.
//!
//! Files: `service` the life's loop; `window` one window of vibration; `step` one
//! life step of a contact's volumes and scars; `track` a wearing contact through the life;
//! `checkpoint` what a life is driven by and continued from; `results` what it gives;
//! `files` its folder and the texts of its files.

mod checkpoint;
mod files;
mod results;
mod service;
mod step;
mod track;
mod window;

pub use crate::settings::life::{DEFAULT_MAX_DEPTH_CHANGE, LifeSettings, MAX_ANGULAR_BINS, YEAR};
pub use checkpoint::{LIFE_CHECKPOINT_FORMAT, LIFE_CHECKPOINT_MAGIC, LifeCheckpoint, LifeControl};
pub use files::{
    CHECKPOINT_FILE, LIFE_CSV_COLUMNS, LIFE_RUN_FILE, OUTPUTS, Unresumable, convergence_csv,
    end_depths, life_csv, life_json, recorded_case_file, resume_checkpoint, scars_csv,
    start_afresh, write_life,
};
pub use results::{
    ContactLife, LifeEnd, LifeResults, LifeStep, ScarProfile, depth_standard_errors,
};
pub use service::{MAX_HALVINGS, check_life, service_life, service_life_with, worn_model};
