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

use crate::error::Result;

/// The wear of one contact: the law of each body and the geometry of their scars
/// (`docs/THEORY.md §14`). The tube and the support each wear by their own law from the same
/// wear work rate (Code_Aster's `MOBILE` and `OBSTACLE` coefficients), and each scar is the
/// imprint of the other body.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactWear {
    /// The tube's wear law.
    pub tube: WearLaw,
    /// The support's (obstacle's) wear law.
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
