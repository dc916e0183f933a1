//! Synthetic multi-contact cases for benchmarks and solver cross-checks: a pinned–pinned tube
//! (analytic modes, [`ModalBasis::pinned_beam`]) with any number of modes and of point–plane
//! supports, excited by a harmonic force so that it rattles and rubs on every support.

use nalgebra::Vector3;

use crate::case::Case;
use crate::contact::friction::Coulomb;
use crate::contact::obstacle::{Obstacle, Plane};
use crate::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use crate::contact::{Contact, NormalLaw};
use crate::integrator::simulation::RunSettings;
use crate::integrator::stability::stable_time_step;
use crate::loads::{PointLoad, TimeHistory};
use crate::model::Model;
use crate::structure::modal::{ModalBasis, PinnedBeam};

/// Tube properties: PWR-like 19.05 × 1.09 mm steel tube, water inside and outside.
const LENGTH: f64 = 2.0;
const BENDING_STIFFNESS: f64 = 498.0; // E I, N·m²
const MASS_PER_LENGTH: f64 = 1.0; // tube + inner water + added mass, kg/m
const AXIAL_STIFFNESS: f64 = 1.23e7; // E A, N

/// The three tangential methods the benchmarks compare: the penalty law (`K_T = 1e6 N/m`,
/// `C_T = 2000 kg/s`, THEORY §4.1), the Active Set (§4.3) and Gauss–Seidel (§4.4) with their
/// default settings.
pub fn methods() -> [TangentialMethod; 3] {
    [
        TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e6,
            damping: 2000.0,
        }),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
    ]
}

/// A pinned tube of length 2 m with `modes` modes (4 axial, the rest bending, half per plane)
/// and `contacts` plane supports spread along it, alternating ±y and ±z, 0.1 mm clearance,
/// `K_N = 1e6 N/m`, `μ = 0.3`, 1 % damping; two harmonic forces drive it in y and z. Δt is a
/// fifth of the stable limit; `steps` steps.
pub fn rattling_tube(modes: usize, contacts: usize, method: TangentialMethod, steps: u64) -> Case {
    let axial_modes = 4;
    let per_plane = (modes.saturating_sub(axial_modes)).div_ceil(2).max(1);
    let mut stations: Vec<(String, f64)> = (0..contacts)
        .map(|j| {
            (
                format!("support{j}"),
                LENGTH * (j as f64 + 0.5) / contacts as f64,
            )
        })
        .collect();
    stations.push(("load".into(), 0.31 * LENGTH));
    let basis = ModalBasis::pinned_beam(
        &PinnedBeam {
            length: LENGTH,
            bending_stiffness: BENDING_STIFFNESS,
            mass_per_length: MASS_PER_LENGTH,
            modes_per_plane: per_plane,
            axial_stiffness: AXIAL_STIFFNESS,
            axial_modes,
            damping_ratio: 0.01,
        },
        &stations,
    )
    .expect("valid synthetic tube");
    let f1 = basis.omega[0] / std::f64::consts::TAU;
    let mut model = Model::new(basis);
    for j in 0..contacts {
        let (normal, tangent) = match j % 4 {
            0 => (-Vector3::y(), Vector3::x()),
            1 => (-Vector3::z(), Vector3::x()),
            2 => (Vector3::y(), Vector3::x()),
            _ => (Vector3::z(), Vector3::x()),
        };
        model.contacts.push(Contact::new(
            format!("support{j}"),
            j,
            Obstacle::Plane(
                Plane::new(
                    Vector3::new(stations[j].1, 0.0, 0.0),
                    normal,
                    1e-4,
                    Some(tangent),
                    "support",
                )
                .expect("valid plane"),
            ),
            NormalLaw::new(1e6, 0.0, "support").expect("K_N > 0"),
            Coulomb::new(0.3, 0.3, "support").expect("valid μ"),
        ));
    }
    let load = contacts; // index of the load point
    for (force, phase) in [
        (Vector3::new(2.0, 20.0, 0.0), 0.0),
        (Vector3::new(0.0, 0.0, 20.0), 1.3),
    ] {
        model.loads.push(
            PointLoad::new(
                load,
                force,
                TimeHistory::Harmonic {
                    frequency_hz: 1.1 * f1,
                    phase,
                },
                "load",
            )
            .expect("valid load"),
        );
    }
    let dt = 0.2 * stable_time_step(&model, &method);
    Case::from_parts(
        &format!(
            "rattling tube, {} modes, {contacts} supports",
            2 * per_plane + axial_modes
        ),
        model,
        RunSettings {
            dt,
            steps,
            method,
            stick_velocity: StickVelocity::HalfStep,
            output_every: 100,
            monitors: Vec::new(),
            statistics: Default::default(),
        },
    )
}
