//! Where each contact's friction work is done (THEORY §14.4): the work `∫|R_T·v_T| dt` (and
//! `∫R_N |v_T| dt`) of the
//! statistics window (THEORY §5) split by where the contact was — around a hole, in `N` equal
//! angular bins of the contact direction (in the hole's in-plane axes, as
//! [`crate::contact::Contact::local`]); between flat bars, on the `+n` and the `−n` side; on
//! a plane, one bin. The service life ([`crate::apps::life`]) spreads a contact's wear volume
//! with it. Off by default; the closed contacts of a step only when on.

use crate::accumulate::statistics::StepValues;
use crate::contact::obstacle::Obstacle;
use crate::contact::scar::AngularProfile;
use crate::model::Model;

/// Friction work and normal work per contact and bin, J.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WearMap {
    work: Vec<Vec<f64>>,
    normal_work: Vec<Vec<f64>>,
}

impl WearMap {
    /// Zero work for the contacts of `model`, `angular_bins` (≥ 1) around each hole.
    pub fn new(model: &Model, angular_bins: usize) -> Self {
        let work = model
            .contacts
            .iter()
            .map(|c| match c.obstacle {
                Obstacle::Circle(_) | Obstacle::Polygon(_) => vec![0.0; angular_bins.max(1)],
                Obstacle::BiPlane(_) => vec![0.0; 2],
                Obstacle::Plane(_) | Obstacle::Cylinder(_) => vec![0.0; 1],
            })
            .collect::<Vec<_>>();
        Self {
            normal_work: work.clone(),
            work,
        }
    }

    /// Adds the step `(t − Δt, t]` of contact `k` (closed): `|R_T·v_T| Δt` and
    /// `R_N |v_T| Δt` in its bin.
    #[inline]
    pub fn add(&mut self, k: usize, v: &StepValues, dt: f64) {
        let bins = &mut self.work[k];
        let bin = match bins.len() {
            1 => 0,
            // bars: the side of the mid-plane the point is on
            2 => usize::from(v.radial < 0.0),
            n => AngularProfile::bin_of(v.direction, n),
        };
        bins[bin] += v.friction_power * dt;
        self.normal_work[k][bin] += v.normal * v.slip_speed * dt;
    }

    /// Contact `k`'s friction work `∫|R_T·v_T| dt` per bin, J.
    pub fn work(&self, k: usize) -> &[f64] {
        &self.work[k]
    }

    /// Contact `k`'s normal work `∫R_N |v_T| dt` per bin, J (Code_Aster's definition of the
    /// wear work).
    pub fn normal_work(&self, k: usize) -> &[f64] {
        &self.normal_work[k]
    }
}
