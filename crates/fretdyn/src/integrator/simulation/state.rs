//! What a run carries from one step to the next ([`State`]): everything the steps after step
//! `n` depend on, held by the run as it goes and written by a checkpoint as it is — a field
//! added here is checkpointed, none can be forgotten. The rest of a run is rebuilt from the
//! model and the settings ([`super::workspace`]): the loads are pure functions of time.

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

use super::contact_state::ContactState;
use crate::accumulate::energy::EnergyBalance;
use crate::accumulate::monitor::MonitorSums;
use crate::accumulate::statistics::ContactStatisticsState;
use crate::accumulate::wear_map::WearMap;
use crate::contact::tangential::active_set::History;
use crate::contact::tangential::penalty::PenaltyContact;
use crate::contact::tangential::{SolverStatistics, TangentialMethod};
use crate::error::{Error, Result};
use crate::integrator::central_difference::ModalState;
use crate::loads::fluid_elastic::DelayHistory;
use crate::model::Model;
use crate::settings::RunSettings;

/// The state of a run after its `step` steps: a run continued from it continues bit for bit
/// as the run it was taken from ([`super::Simulation::snapshot`],
/// [`super::Simulation::resume`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// Steps done.
    pub(super) step: u64,
    /// The step of the next output sample (a multiple of `output_every`).
    pub(super) next_sample: u64,
    /// `q`, `q̇`, `q̈` of the step.
    pub(super) modal: ModalState,
    /// Per contact: its frame, forces, velocities and status.
    pub(super) contacts: Vec<ContactState>,
    /// The penalty tangential law: each contact's anchor (empty with the Lagrange methods).
    pub(super) penalty: Vec<PenaltyContact>,
    /// The Lagrange methods: each contact's status and slip direction at the previous step
    /// (empty with the penalty law).
    pub(super) history: Vec<History>,
    /// The Lagrange methods: each contact's multiplier at the previous step, the warm start
    /// (empty with the penalty law).
    pub(super) previous_lambda: Vec<Vector2<f64>>,
    /// The statistics' running sums, impacts under way and finished rows not yet drained.
    pub(super) statistics: ContactStatisticsState,
    /// The tangential solvers' counters.
    pub(super) solver: SolverStatistics,
    /// The energy balance's running sums.
    #[serde(with = "energy_numbers")]
    pub(super) energy: EnergyBalance,
    /// Where the friction work was done, when tracked
    /// ([`super::Simulation::track_wear`]).
    pub(super) wear_map: Option<WearMap>,
    /// The displacement monitors' sums over the window's output samples.
    pub(super) monitors: Vec<MonitorSums>,
}

impl State {
    /// Steps done.
    pub fn step(&self) -> u64 {
        self.step
    }

    /// The end time of the step at which the run met its target relative error, if it did
    /// (the run ended there).
    pub fn target_met(&self) -> Option<f64> {
        self.statistics.target_met()
    }

    /// Checks that the state is one of a run of `model` with `settings` (its sizes and its
    /// tangential method): the error says what does not match.
    pub(super) fn check_fits(&self, model: &Model, settings: &RunSettings) -> Result<()> {
        let p = model.basis.modes();
        let nc = model.contacts.len();
        let mismatch = |what: &str| {
            Error::invalid(
                "checkpoint",
                format!(
                    "its {what} does not match the case: was the case file changed since the run started?"
                ),
            )
        };
        let m = &self.modal;
        if m.q.len() != p || m.qd.len() != p || m.qdd.len() != p {
            return Err(mismatch("number of modes"));
        }
        if self.contacts.len() != nc || !self.statistics.has_contacts(nc) {
            return Err(mismatch("number of contacts"));
        }
        let tangential = if matches!(settings.method, TangentialMethod::Penalty(_)) {
            self.penalty.len() == nc && self.history.is_empty() && self.previous_lambda.is_empty()
        } else {
            self.penalty.is_empty() && self.history.len() == nc && self.previous_lambda.len() == nc
        };
        if !tangential {
            return Err(mismatch("tangential method"));
        }
        if self.monitors.len() != settings.monitors.len() {
            return Err(mismatch("number of monitors"));
        }
        Ok(())
    }
}

/// What a checkpoint holds: the [`State`], and the past displacements of the fluid-elastic
/// delays, which live in the force that reads them
/// ([`crate::loads::fluid_elastic::FluidElasticForce`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// The state of the run.
    pub state: State,
    /// The past displacements of the fluid-elastic delays, when the model has them.
    pub fluid: Option<DelayHistory>,
}

impl Snapshot {
    /// Steps done.
    pub fn step(&self) -> u64 {
        self.state.step
    }

    /// [`State::target_met`].
    pub fn target_met(&self) -> Option<f64> {
        self.state.target_met()
    }

    /// Binary encoding (CBOR: exact for every `f64`).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut bytes = Vec::new();
        ciborium::into_writer(self, &mut bytes).expect("a snapshot always serializes");
        bytes
    }

    /// Decodes [`Self::to_bytes`]; `None` when the bytes are not a snapshot.
    pub fn from_bytes(bytes: &[u8]) -> Option<Self> {
        ciborium::from_reader(bytes).ok()
    }
}

/// The energy balance as every number it holds, its running maxima included (its own
/// serialisation is the summary's).
mod energy_numbers {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use crate::accumulate::energy::{EnergyBalance, EnergyRaw};

    pub fn serialize<S: Serializer>(e: &EnergyBalance, s: S) -> Result<S::Ok, S::Error> {
        e.raw().serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<EnergyBalance, D::Error> {
        EnergyRaw::deserialize(d).map(|r| EnergyBalance::from_raw(&r))
    }
}
