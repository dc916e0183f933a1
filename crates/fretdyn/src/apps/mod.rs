//! **Applications** built on the stages, apart from the physics: they run cases, they add no
//! equation.
//!
//! - [`study`]: parameter studies — one case file, a grid of values, one run per point;
//!   parameters drawn from distributions ([`sampling`]) and percentiles across the draws
//!   ([`percentiles`]);
//! - [`verification`]: the verification cases against closed forms (THEORY §6,
//!   `docs/VERIFICATION.md`);
//! - [`benchmark`]: the step-speed benchmark case (`docs/PERFORMANCE.md`, `docs/dev/PERFORMANCE_LOG.md`);
//! - [`life`]: the service life — wear depth over years with the scars fed back (THEORY §14.5).

pub mod benchmark;
pub mod life;
pub mod percentiles;
pub mod sampling;
pub mod study;
pub mod verification;

use crate::error::{Error, Result};
use crate::model::Model;

/// Refuses a contact name that would cut the tables of a study or a service life: it heads
/// their columns (`<name>.wear_work_rate` in `study.csv` and `life.csv`) and fills cells of
/// `scars.csv`, written and read back as plain comma-separated text, so a comma, a double
/// quote or a line break in it would shift every column after it. (`contacts.csv` of a run
/// quotes such a name, as CSV does: a run accepts it.)
pub(crate) fn check_names_for_tables(model: &Model, what: &str) -> Result<()> {
    for (k, contact) in model.contacts.iter().enumerate() {
        if contact.name.contains([',', '"', '\n', '\r']) {
            return Err(Error::invalid(
                format!("contacts[{k}].name"),
                format!(
                    "{:?}: the contact names of {what} cannot hold a comma, a double quote or a line break (they head the columns of its tables): rename the contact",
                    contact.name
                ),
            ));
        }
    }
    Ok(())
}
