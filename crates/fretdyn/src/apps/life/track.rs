//! One wearing contact through a service life (THEORY §14.5): what it is, its volumes with
//! the scars fed back and at fixed gap, the longest life step its depth limit allows, and when
//! its depth reaches a level.

use serde::{Deserialize, Serialize};

use super::step::{Depths, Worn, advanced, crossing, deepest};
use crate::accumulate::wear_map::WearMap;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::settings::life::LifeSettings;
use crate::wear::ContactWear;

/// One wearing contact through the life: what it is, and its volumes with and without
/// feedback.
pub(super) struct Track<'a> {
    /// Index of the contact in the model.
    pub(super) k: usize,
    pub(super) name: String,
    /// `contacts[k].wear`, for messages.
    pub(super) field: String,
    pub(super) wear: &'a ContactWear,
    /// Clearance at rest `g₀`, m.
    pub(super) clearance: f64,
    /// Volumes with the scars fed back.
    pub(super) worn: Worn,
    /// Volumes of the fixed-gap extrapolation.
    pub(super) fixed: Worn,
    /// When the tube's depth reached the criterion (with feedback, at fixed gap) and its wall.
    pub(super) criterion: Option<f64>,
    pub(super) criterion_fixed: Option<f64>,
    pub(super) perforation: Option<f64>,
}

/// A volume state advanced over a life step, with its depths.
pub(super) struct Advanced {
    pub(super) worn: Worn,
    pub(super) depths: Depths,
}

impl<'a> Track<'a> {
    pub(super) fn new(model: &'a Model, k: usize, bins: usize) -> Self {
        let c = &model.contacts[k];
        // the point the contact sees: the relative point A − B of a two-body contact
        let x = c.point_in(&model.basis.points).coords;
        let worn = Worn::new(WearMap::new(model, bins).work(k).len());
        Self {
            k,
            name: c.name.clone(),
            field: format!("contacts[{k}].wear"),
            wear: model.wear[k].as_ref().expect("a wearing contact"),
            clearance: (-c.frame(&x, 0.0).penetration).max(0.0),
            fixed: worn.clone(),
            worn,
            criterion: None,
            criterion_fixed: None,
            perforation: None,
        }
    }

    /// What the track has accumulated, for a checkpoint.
    pub(super) fn state(&self) -> TrackState {
        TrackState {
            worn: self.worn.clone(),
            fixed: self.fixed.clone(),
            criterion: self.criterion,
            criterion_fixed: self.criterion_fixed,
            perforation: self.perforation,
        }
    }

    /// Takes up what a checkpoint's track had accumulated.
    pub(super) fn restore(&mut self, s: &TrackState) {
        self.worn = s.worn.clone();
        self.fixed = s.fixed.clone();
        self.criterion = s.criterion;
        self.criterion_fixed = s.criterion_fixed;
        self.perforation = s.perforation;
    }

    pub(super) fn advance(
        &self,
        from: &Worn,
        rate: f64,
        fractions: &[f64],
        t0: f64,
        t1: f64,
    ) -> Result<Advanced> {
        let worn = advanced(from, self.wear, rate, fractions, t0, t1);
        let depths = worn.depths(self.wear, &self.field)?;
        Ok(Advanced { worn, depths })
    }

    /// The longest step from `t` (at most `dt`) over which the added clearance grows by no
    /// more than the settings allow (§14.5); beyond the scar's geometry counts as too much.
    /// Found by bisection on `[0, dt]`; a step below `1e-9 dt` (a fast wear against a long
    /// life), which that bisection cannot resolve, by halving `dt` down to it, then
    /// bisection between it and its double. `Err` (inside): no step is short enough — the
    /// scar is at the limit of its geometry (the error of its smallest step).
    pub(super) fn longest_step(
        &self,
        rate: f64,
        fractions: &[f64],
        t: f64,
        dt: f64,
        life: &LifeSettings,
    ) -> Result<std::result::Result<f64, Error>> {
        let now = deepest(&self.worn.depths(self.wear, &self.field)?.added);
        let limit = life.max_depth_change * (self.clearance + now).max(life.depth_resolution);
        let growth = |h: f64| {
            self.advance(&self.worn, rate, fractions, t, t + h)
                .map(|a| deepest(&a.depths.added) - now)
        };
        let grown = |h: f64| growth(h).unwrap_or(f64::INFINITY);
        if grown(dt) <= limit {
            return Ok(Ok(dt));
        }
        let (mut lo, mut hi) = (0.0, dt);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if grown(mid) > limit {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        if lo > 1e-9 * dt {
            return Ok(Ok(lo));
        }
        // halvings down to a step within the limit, then bisection in [h, 2h]
        let mut h = hi;
        loop {
            h *= 0.5;
            match growth(h) {
                Ok(g) if g <= limit => break,
                Err(e) if h <= f64::MIN_POSITIVE => return Ok(Err(e)),
                _ if h <= f64::MIN_POSITIVE => {
                    return Ok(Err(Error::invalid(
                        format!("{}.tube", self.field),
                        format!(
                            "the depth grows by more than {limit:e} m in any life step: is the wear rate finite?"
                        ),
                    )));
                }
                _ => {}
            }
        }
        let (mut lo, mut hi) = (h, 2.0 * h);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if grown(mid) > limit {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Ok(Ok(lo))
    }

    /// The time in `[t0, t1]` at which the tube's depth from `from` reaches `level`.
    pub(super) fn reaches(
        &self,
        from: &Worn,
        rate: f64,
        fractions: &[f64],
        t0: f64,
        t1: f64,
        level: f64,
    ) -> Result<f64> {
        crossing(t0, t1, level, |h| {
            self.advance(from, rate, fractions, t0, h)
                .map(|a| deepest(&a.depths.tube))
        })
    }
}

/// What a wearing contact has accumulated (the part of [`Track`] that changes).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct TrackState {
    pub(super) worn: Worn,
    pub(super) fixed: Worn,
    pub(super) criterion: Option<f64>,
    pub(super) criterion_fixed: Option<f64>,
    pub(super) perforation: Option<f64>,
}
