//! The contacts a step is compiled for: any, or those of the common case (THEORY §3, §4, §9).
//!
//! Most cases users run have the same kind of contacts: every obstacle a fixed plane or fixed
//! bars, seen through the contact's frame rows ([`FrameRows`]: detection is one dot product,
//! a closed contact's velocity three), a normal penalty law without damping, and friction by
//! Lagrange multipliers (Gauss–Seidel or Active Set). The phases of the step that visit the
//! contacts are compiled twice from the same source: for any contact ([`AnyContacts`]) and
//! for the common case ([`CommonContacts`]), in which the paths of the others (a hole's 3-D
//! point, surface rows, a moving obstacle's velocities, the normal damping, the penalty
//! tangential law) are not compiled and the tests that choose them are constants.
//! [`Simulation::steps`](super::Simulation::steps) runs the second when every contact and the
//! method qualify ([`is_common`]). Both run the same floating-point operations in the same
//! order: their results are the same bit for bit (`tests/common_contacts.rs`).

use crate::contact::Contact;
use crate::contact::frame_rows::FrameRows;
use crate::contact::tangential::TangentialMethod;

/// Which contacts the step's code handles.
pub(super) trait ContactKinds {
    /// Every contact a fixed plane or fixed bars with frame rows, an undamped normal law;
    /// friction by Lagrange multipliers.
    const COMMON: bool;

    /// A contact's frame rows (`rows`), if it has them. In the common case every contact has
    /// them: the test is not compiled.
    #[inline(always)]
    fn rows(rows: &Option<FrameRows>) -> Option<&FrameRows> {
        if Self::COMMON {
            debug_assert!(rows.is_some());
            // SAFETY: the step runs under `CommonContacts` only when every contact has frame
            // rows (`Simulation::steps` dispatches on the workspace's `common_contacts`, set
            // from [`is_common`] in `Workspace::new`, its only constructor, and only ever
            // cleared after), and a workspace's frame rows never change. The trait is private
            // to the step's module, whose phases are called from that dispatch only (its start
            // runs under `AnyContacts`).
            Some(unsafe { rows.as_ref().unwrap_unchecked() })
        } else {
            rows.as_ref()
        }
    }

    /// Whether contact `c`'s obstacle is fixed (always, in the common case).
    #[inline(always)]
    fn is_fixed(c: &Contact) -> bool {
        Self::COMMON || c.motion.is_fixed()
    }

    /// Whether contact `c`'s normal law has damping (never, in the common case).
    #[inline(always)]
    fn damped(c: &Contact) -> bool {
        !Self::COMMON && c.normal.damping > 0.0
    }

    /// Whether the tangential law is the penalty one (`penalty`: the run's; never, in the
    /// common case).
    #[inline(always)]
    fn penalty(penalty: bool) -> bool {
        !Self::COMMON && penalty
    }
}

/// Any contact, any method: the general step.
pub(super) struct AnyContacts;

impl ContactKinds for AnyContacts {
    const COMMON: bool = false;
}

/// The common case only.
pub(super) struct CommonContacts;

impl ContactKinds for CommonContacts {
    const COMMON: bool = true;
}

/// Whether a run qualifies for [`CommonContacts`]: every contact has frame rows (`rows`), a
/// fixed obstacle and an undamped normal law, and the `method` is a Lagrange one.
pub(super) fn is_common(
    contacts: &[Contact],
    rows: &[Option<FrameRows>],
    method: &TangentialMethod,
) -> bool {
    !matches!(method, TangentialMethod::Penalty(_))
        && contacts
            .iter()
            .zip(rows)
            .all(|(c, r)| r.is_some() && c.motion.is_fixed() && c.normal.damping == 0.0)
}
