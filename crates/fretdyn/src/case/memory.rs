//! The memory a run of a case will take for its contacts and its random turbulence,
//! estimated from the counts before anything is allocated, and the refusal of a case that
//! would not fit (the mesh and the modes are estimated where they are built:
//! `structure/beam.rs`, `integrator/stability.rs`).
//!
//! The estimate counts the buffers that `Simulation::allocate`
//! (`integrator/simulation/workspace.rs`), the tangential problem (`contact/delassus/`), the
//! Active Set solver (`contact/tangential/active_set.rs`), the per-contact statistics
//! (`accumulate/statistics/`) and the turbulence generator (`loads/turbulence/`) allocate;
//! `tests/memory.rs` measures them against it. With `m` contacts and `p` modes, the Lagrange
//! methods hold dense matrices of the `2m` tangential unknowns (the Delassus operator `H`
//! twice, the solver's work space once, and the Active Set's once more) and rows of `2m × p`:
//! their memory grows as `m²`, where the penalty method's grows as `m·p`.

use crate::contact::tangential::TangentialMethod;
use crate::error::{Error, Result};
use crate::loads::TurbulentLoad;
use crate::model::Model;
use crate::structure::beam::{available_memory, gigabytes};

/// Bytes per contact besides its rows and matrices: its state, its statistics (the room for
/// its impacts, 256 of them, is most of it) and its solver's per-contact vectors
/// (`tests/memory.rs` measures 34 kB), rounded up.
const PER_CONTACT: f64 = 40e3;

/// Dense `(2m)²` matrices of `f64` the tangential problem of a Lagrange method holds: `H` of
/// the fixed contacts and `H` of the closed ones (`contact/delassus/`), and the work space
/// of the step (`4m²` values, `integrator/simulation/lagrange.rs`).
const LAGRANGE_MATRICES: f64 = 3.0;

/// One more for the Active Set's work space (`contact/tangential/active_set.rs`).
const ACTIVE_SET_MATRICES: f64 = 1.0;

/// Rows of `p` values per contact: the surface rows (3), the frame rows (3), the padded
/// normal rows (1); a Lagrange method adds the tangential problem's `L` and `A⁻¹Lᵀ` (2 rows
/// each).
const ROWS: f64 = 7.0;
const LAGRANGE_ROWS: f64 = 4.0;

/// What the memory of the contacts depends on in a tangential method.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Solver {
    Penalty,
    GaussSeidel,
    ActiveSet,
}

impl From<&TangentialMethod> for Solver {
    fn from(method: &TangentialMethod) -> Self {
        match method {
            TangentialMethod::Penalty(_) => Solver::Penalty,
            TangentialMethod::GaussSeidel(_) => Solver::GaussSeidel,
            TangentialMethod::ActiveSet(_) => Solver::ActiveSet,
        }
    }
}

/// Bytes a run allocates for `contacts` contacts on `modes` modes with the tangential
/// method `method` (see the module doc).
pub fn contact_bytes(modes: usize, contacts: usize, method: &TangentialMethod) -> f64 {
    bytes(modes, contacts, method.into())
}

fn bytes(modes: usize, contacts: usize, solver: Solver) -> f64 {
    let (p, m) = (modes as f64, contacts as f64);
    let (matrices, rows) = match solver {
        Solver::Penalty => (0.0, ROWS),
        Solver::GaussSeidel => (LAGRANGE_MATRICES, ROWS + LAGRANGE_ROWS),
        Solver::ActiveSet => (
            LAGRANGE_MATRICES + ACTIVE_SET_MATRICES,
            ROWS + LAGRANGE_ROWS,
        ),
    };
    8.0 * matrices * (2.0 * m).powi(2) + 8.0 * rows * m * p + PER_CONTACT * m
}

/// Bytes a run allocates for the random turbulence `load` on `modes` modes: its modal rows
/// (one row of `p` values per channel, and the channel's signal) and its generator
/// ([`crate::loads::turbulence::generator_bytes`]).
pub fn turbulence_bytes(load: &TurbulentLoad, modes: usize) -> f64 {
    let channels = load.channels(modes);
    8.0 * (channels as f64) * (modes as f64 + 1.0)
        + crate::loads::turbulence::generator_bytes(&load.spectrum, channels, load.f_max)
}

/// Refuses a case whose contacts and random turbulence would need more memory than the
/// system has available (Linux: `MemAvailable`), before anything is allocated: the error
/// names the larger of the two (`contacts` or `turbulence[k]`), gives the figures and the fix.
pub(super) fn check(model: &Model, method: &TangentialMethod) -> Result<()> {
    check_against(model, method, available_memory())
}

fn check_against(model: &Model, method: &TangentialMethod, available: f64) -> Result<()> {
    let p = model.basis.modes();
    let m = model.contacts.len();
    let contacts = contact_bytes(p, m, method);
    let turbulence: Vec<f64> = model
        .turbulence
        .iter()
        .map(|l| turbulence_bytes(l, p))
        .collect();
    let total = contacts + turbulence.iter().sum::<f64>();
    if total <= available {
        return Ok(());
    }
    let others = |part: f64| {
        if total > part {
            format!(" (with the rest of the run, {})", gigabytes(total))
        } else {
            String::new()
        }
    };
    let largest = turbulence
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .filter(|(_, t)| **t > contacts);
    if let Some((k, &bytes)) = largest {
        let channels = model.turbulence[k].channels(p);
        return Err(Error::invalid(
            format!("turbulence[{k}]"),
            format!(
                "its {channels} random channels on {p} modes would need {}{} of memory, more than the {} available: use fewer channels (fewer directions, a longer correlation_length or a larger tolerance)",
                gigabytes(bytes),
                others(bytes),
                gigabytes(available)
            ),
        ));
    }
    let solver = Solver::from(method);
    let at_most = fewer(p, solver, available - (total - contacts));
    let fix = match solver {
        Solver::Penalty => format!("use fewer contacts (at most about {at_most:.0} here)"),
        _ => format!(
            "use fewer contacts (at most about {at_most:.0} with this method), or tangential.method = \"penalty\", whose memory grows as contacts × modes ({} for these)",
            gigabytes(bytes(p, m, Solver::Penalty))
        ),
    };
    Err(Error::invalid(
        "contacts",
        format!(
            "{m} contacts on {p} modes with the {} method would need {}{} of memory, more than the {} available ({}): {fix}",
            method.name(),
            gigabytes(contacts),
            others(contacts),
            gigabytes(available),
            match solver {
                Solver::Penalty => "rows of the modes for each contact",
                _ => "dense matrices of the 2 × contacts tangential unknowns",
            },
        ),
    ))
}

/// The most contacts whose memory fits in `room` bytes (0 when none does).
fn fewer(p: usize, solver: Solver, room: f64) -> f64 {
    if room <= 0.0 {
        return 0.0;
    }
    // bytes(m) = a m² + b m, increasing in m
    let a = 0.5 * (bytes(p, 2, solver) - 2.0 * bytes(p, 1, solver));
    let b = bytes(p, 1, solver) - a;
    let m = if a > 0.0 {
        (-b + (b * b + 4.0 * a * room).sqrt()) / (2.0 * a)
    } else {
        room / b
    };
    m.floor().max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::apps::benchmark::rattling_tube;
    use crate::contact::tangential::{GaussSeidelSettings, PenaltySettings};
    use crate::loads::turbulence::Spectrum;

    fn gs() -> TangentialMethod {
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default())
    }

    #[test]
    fn the_lagrange_methods_grow_as_the_square_of_the_contacts() {
        let penalty = TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e6,
            damping: 0.0,
        });
        // 20 000 contacts: 3 dense 40 000² matrices of 8 bytes, 12.8 GB each
        let bytes = contact_bytes(3, 20_000, &gs());
        assert!(
            (3.0 * 12.8e9..3.0 * 12.8e9 + 1e9).contains(&bytes),
            "{bytes}"
        );
        assert!(contact_bytes(3, 20_000, &penalty) < 1e9);
        // the most contacts that fit is the inverse of the estimate
        for room in [1e6, 1e9, 4e10] {
            let m = fewer(3, Solver::GaussSeidel, room) as usize;
            assert!(contact_bytes(3, m, &gs()) <= room, "{room}");
            assert!(contact_bytes(3, m + 1, &gs()) > room, "{room}");
        }
    }

    #[test]
    fn a_model_beyond_the_memory_is_refused_naming_the_larger_part() {
        let gs = gs();
        let case = rattling_tube(12, 40, gs, 10);
        let needed = contact_bytes(case.model.basis.modes(), 40, &gs);
        assert!(check_against(&case.model, &gs, needed).is_ok());
        let err = check_against(&case.model, &gs, 0.5 * needed).unwrap_err();
        assert_eq!(err.field(), Some("contacts"));
        let message = err.to_string();
        assert!(
            message.contains("40 contacts on 12 modes")
                && message.contains("at most about")
                && message.contains("\"penalty\""),
            "{message}"
        );
        // turbulence of many channels: named when it is the larger part
        let mut model = case.model.clone();
        let p = model.basis.modes();
        model.turbulence.push(crate::loads::TurbulentLoad {
            spectrum: Spectrum::cross_flow(3.0, 750.0, 0.019),
            rows: vec![1.0; 1000 * p],
            seed: 1,
            f_max: 200.0,
        });
        let err = check_against(&model, &gs, needed).unwrap_err();
        assert_eq!(err.field(), Some("turbulence[0]"));
        assert!(err.to_string().contains("1000 random channels"), "{err}");
    }
}
