//! **Wear depth** (after the run): the wear laws that turn a contact's wear work rate
//! `W = (1/T)∫|R_T·v_T| dt` (THEORY §5) into worn volumes of the tube and of its support, and
//! the scar geometries that turn those volumes into depths (`docs/THEORY.md §14`,
//! `docs/WEAR.md`). Nothing here runs in the time-step loop.
//!
//! ```
//! use fretdyn::wear::{ContactWear, Scar, WearLaw, WearWork};
//! let wear = ContactWear {
//!     tube: WearLaw::Archard { coefficient: 20e-15 },
//!     support: WearLaw::Archard { coefficient: 10e-15 },
//!     scar: Scar::FlatBar { tube_radius: 0.0095, width: 0.0254, tilt: 0.0 },
//!     work: WearWork::Friction,
//! };
//! // 40 years at 10 mW
//! let t = 40.0 * 365.25 * 86400.0;
//! let depth = wear.scar.tube_depth(wear.tube.volume(0.01, t))?;
//! assert!(depth > 0.0 && depth < 2.0 * 0.0095);
//! # Ok::<(), fretdyn::Error>(())
//! ```

pub mod law;
pub mod scar;

pub use law::WearLaw;
pub use scar::{HoleScar, Scar};

use crate::contact::Contact;
use crate::error::Result;
use crate::structure::modal::Point;

/// The bodies whose wear the `tube` and the `support` laws of a two-body contact give: the
/// names of its point A and of its point B in `points` (the model's basis). `None` for a
/// contact with an obstacle (the support is then its obstacle).
pub fn pair_bodies<'a>(contact: &Contact, points: &'a [Point]) -> Option<[&'a str; 2]> {
    let b = contact.other()?;
    Some([
        points.get(contact.point)?.name.as_str(),
        points.get(b)?.name.as_str(),
    ])
}

/// The wear of one contact: the law of each body and the geometry of their scars
/// (`docs/THEORY.md §14`). The tube and the support each wear by their own law from the same
/// wear work rate (Code_Aster's `MOBILE` and `OBSTACLE` coefficients), and each scar is the
/// imprint of the other body.
///
/// **Two-body contacts** ([`crate::contact::Pair`]): the "tube" is body A (the contact's
/// point) and the "support" is body B (the pair's other point); the friction work `W` done
/// at their interface wears both, `V_A = f_A(W, t)` and `V_B = f_B(W, t)` by their own laws
/// (Archard: `V_A = K_A W t`, `V_B = K_B W t`). The scar is A's against B: [`Scar::Tube`]
/// for tube against tube (`tube_radius = R_A`, `other_radius = R_B`: both scars are the
/// overlap of the two cylinders), [`Scar::FlatBar`] for a tube A against a bar B (a flat cut
/// on the tube, a groove in the bar). In a service life both scars grow and the pair's
/// relative obstacle recedes by their approach, as a rigid obstacle's does (THEORY §14.4);
/// [`pair_bodies`] names the two bodies in the outputs.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactWear {
    /// The tube's wear law (body A of a two-body contact).
    pub tube: WearLaw,
    /// The support's (obstacle's) wear law (body B of a two-body contact).
    pub support: WearLaw,
    /// The scar geometry.
    pub scar: Scar,
    /// The work the laws take as `W`.
    pub work: WearWork,
}

/// Which wear work rate a contact's laws take (THEORY §5, §14.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WearWork {
    /// The friction power `(1/T)∫|R_T·v_T| dt` (`wear_work_rate`).
    #[default]
    Friction,
    /// The normal work rate `(1/T)∫R_N |v_T| dt` (`normal_wear_work_rate`): Code_Aster's
    /// definition, on which most published coefficients are measured (docs/WEAR.md).
    Normal,
}

impl ContactWear {
    /// Checks the laws and the geometry; `field` names the contact's `wear` table.
    pub fn validate(&self, field: &str) -> Result<()> {
        self.tube.validate(&format!("{field}.tube"))?;
        self.support.validate(&format!("{field}.support"))?;
        self.scar.validate(&format!("{field}.scar"))
    }

    /// The volume rates `(tube, support)`, m³/s, at the work rate `work_rate` (W) and the
    /// service time `service_time` (s).
    pub fn volume_rates(&self, work_rate: f64, service_time: f64) -> (f64, f64) {
        (
            self.tube.volume_rate(work_rate, service_time),
            self.support.volume_rate(work_rate, service_time),
        )
    }
}
