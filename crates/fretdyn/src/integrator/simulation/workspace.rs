//! What a run rebuilds from the model and the settings ([`Workspace`]): the integrator's
//! constants, the loads' rows and generators, the contacts' frame rows, the tangential
//! solvers and the buffers the phases of a step write and read within it. None of it is
//! carried from one step to the next (that is the [`State`](super::state::State)), except the
//! fluid-elastic force's past displacements ([`FluidElasticForce`], taken by a checkpoint
//! beside the state).

use nalgebra::Vector2;

use super::contact_kinds;
use super::contact_state::ContactState;
use super::state::State;
use crate::accumulate::energy::EnergyBalance;
use crate::accumulate::monitor::MonitorSums;
use crate::accumulate::statistics::ContactStatisticsState;
use crate::contact::delassus::TangentialProblem;
use crate::contact::frame_rows::FrameRows;
use crate::contact::friction::Slide;
use crate::contact::tangential::active_set::{ActiveSet, History};
use crate::contact::tangential::penalty::PenaltyContact;
use crate::contact::tangential::{SolverStatistics, TangentialMethod};
use crate::error::{Error, Result};
use crate::integrator::central_difference::{CentralDifference, ModalState};
use crate::loads::fluid_elastic::FluidElasticForce;
use crate::loads::stepped::SteppedHistory;
use crate::loads::turbulence::RandomChannels;
use crate::model::Model;
use crate::numerics::PaddedRows;
use crate::settings::RunSettings;
use crate::structure::modal::project_add;

/// The buffers and constants of a run's steps, rebuilt from the model and the settings.
pub(super) struct Workspace<'m> {
    /// The integrator's constants and predicted velocity.
    pub(super) cd: CentralDifference,
    /// The contacts closed at this step, in order (set by detection): the phases after it
    /// visit these only.
    pub(super) closed: Vec<usize>,
    pub(super) tangential: Tangential,
    /// Rows (3 × p) of the contact points on the tube surface, one block per contact (used
    /// only by contacts with a radius), updated with the normal at each step (once for a
    /// plane).
    pub(super) surface_rows: Vec<f64>,
    /// Per contact: the frame rows of a plane or bars, `None` for a hole.
    pub(super) frame_rows: Vec<Option<FrameRows>>,
    /// The common step's detection ([`contact_kinds::CommonContacts`]): every contact's
    /// normal row `n·Φ_c` ([`FrameRows::row`]), laid out for one pass over `q` that forms
    /// all their dot products ([`crate::numerics::Lanes::padded_dots`]). Empty for the general
    /// step.
    pub(super) normal_rows: PaddedRows,
    /// Work space of that detection: `normal_rows q`, one value per contact.
    pub(super) normal_dots: Vec<f64>,
    /// The fluid-elastic force with its past displacements, when the model has one.
    pub(super) fluid: Option<FluidElasticForce>,
    /// Modal loads `Φ_lᵀ F_l`, one row of p per load.
    pub(super) load_rows: Vec<f64>,
    /// The time history of each row of `load_rows`, in order.
    pub(super) load_histories: Vec<SteppedHistory<'m>>,
    /// Signal generators of the turbulent loads, one per load.
    pub(super) turbulence: Vec<RandomChannels>,
    /// The turbulence signals at the current time.
    pub(super) signals: Vec<f64>,
    /// The external modal force of the step.
    pub(super) external: Vec<f64>,
    /// The modal force of the step, contacts included (when one is closed).
    pub(super) force: Vec<f64>,
    /// The contacts' names.
    pub(super) names: Vec<String>,
    /// The last step before the statistics window, at whose end the window opens
    /// (`u64::MAX`: never).
    pub(super) window_opens: u64,
    /// Stability limit of the time step, s.
    pub(super) stable_dt: f64,
    /// [`accumulation_bound`] of the settings.
    pub(super) accumulation_bound: f64,
    /// Run the steps as code compiled for AVX2 and FMA.
    pub(super) wide: bool,
    /// Run the contact phases compiled for the common case ([`contact_kinds`]).
    pub(super) common_contacts: bool,
}

/// The tangential method's solver and work space (its memory from step to step is in the
/// [`State`]).
#[allow(clippy::large_enum_variant)]
pub(super) enum Tangential {
    Penalty {
        settings: crate::contact::tangential::PenaltySettings,
    },
    Lagrange {
        problem: TangentialProblem,
        solver: LagrangeSolver,
        theta_dt: f64,
        lambda: Vec<Vector2<f64>>,
        slide: Vec<Slide>,
        /// Work space of the singularity check.
        work: Vec<f64>,
    },
}

pub(super) enum LagrangeSolver {
    GaussSeidel(crate::contact::tangential::GaussSeidelSettings),
    ActiveSet(Box<ActiveSet>),
}

impl<'m> Workspace<'m> {
    /// Everything the steps of `model` with `settings` need (`stable_dt`: the stability
    /// limit, checked), allocated once.
    pub(super) fn new(model: &'m Model, settings: &RunSettings, stable_dt: f64) -> Result<Self> {
        let p = model.basis.modes();
        let nc = model.contacts.len();
        let cd = CentralDifference::new(model, settings.dt);
        let fluid = match &model.fluid_elastic {
            Some(fe) => {
                let (needed, available) = (
                    FluidElasticForce::ring_bytes(fe, settings.dt, p),
                    crate::structure::beam::available_memory(),
                );
                if needed > 0.5 * available {
                    return Err(Error::invalid(
                        "flow",
                        format!(
                            "the fluid-elastic delay of {:e} s is {:.0} time steps: the past displacements would need {}, more than half of the {} of memory available; check the velocity (τ = μ D / U) or the time step",
                            fe.longest_delay(),
                            fe.longest_delay() / settings.dt,
                            crate::structure::beam::gigabytes(needed),
                            crate::structure::beam::gigabytes(available)
                        ),
                    ));
                }
                Some(FluidElasticForce::new(fe, settings.dt, &model.initial.q))
            }
            None => None,
        };
        let mut load_rows = vec![0.0; p * model.loads.len()];
        for (l, load) in model.loads.iter().enumerate() {
            project_add(
                &model.basis.points[load.point].rows,
                &load.force,
                &mut load_rows[l * p..(l + 1) * p],
            );
        }
        for load in &model.modal_loads {
            load_rows.extend_from_slice(&load.row);
        }
        if let Some(base) = &model.base_acceleration {
            load_rows.extend(base.modal_row(&model.basis.participation));
        }
        let turbulence = model
            .turbulence
            .iter()
            .enumerate()
            .map(|(k, l)| {
                RandomChannels::new(
                    &l.spectrum,
                    l.channels(p),
                    l.seed,
                    l.f_max,
                    &format!("turbulence[{k}]"),
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let channels = model
            .turbulence
            .iter()
            .map(|l| l.channels(p))
            .max()
            .unwrap_or(0);
        let tangential = match settings.method {
            TangentialMethod::Penalty(s) => Tangential::Penalty { settings: s },
            TangentialMethod::GaussSeidel(s) => {
                Tangential::lagrange(model, &cd, settings, LagrangeSolver::GaussSeidel(s))
            }
            TangentialMethod::ActiveSet(s) => Tangential::lagrange(
                model,
                &cd,
                settings,
                LagrangeSolver::ActiveSet(Box::new(ActiveSet::new(s, nc))),
            ),
        };
        let frame_rows: Vec<Option<FrameRows>> = model
            .contacts
            .iter()
            .map(|c| FrameRows::new(c, c.point_in(&model.basis.points)))
            .collect();
        let mut surface_rows = vec![0.0; 3 * p * nc];
        for (k, (c, rows)) in model.contacts.iter().zip(&frame_rows).enumerate() {
            if let Some(rows) = rows
                && c.at_surface()
            {
                // a plane: the normal, and so the surface rows, never change
                c.surface_rows(
                    c.point_in(&model.basis.points),
                    &rows.frame(0.0).normal,
                    &mut surface_rows[3 * p * k..3 * p * (k + 1)],
                );
            }
        }
        let common_contacts =
            contact_kinds::is_common(&model.contacts, &frame_rows, &settings.method);
        let normal_rows = if common_contacts {
            let rows: Vec<&[f64]> = frame_rows.iter().flatten().map(|r| r.row(0)).collect();
            PaddedRows::new(p, rows.into_iter())
        } else {
            PaddedRows::default()
        };
        Ok(Self {
            cd,
            closed: Vec::with_capacity(nc),
            tangential,
            surface_rows,
            frame_rows,
            normal_dots: vec![0.0; normal_rows.rows()],
            normal_rows,
            fluid,
            load_rows,
            load_histories: (model.loads.iter().map(|l| &l.history))
                .chain(model.modal_loads.iter().map(|l| &l.history))
                .chain(model.base_acceleration.iter().map(|b| &b.history))
                .map(|h| SteppedHistory::new(h, settings.dt))
                .collect(),
            turbulence,
            signals: vec![0.0; channels],
            external: vec![0.0; p],
            force: vec![0.0; p],
            names: model.contacts.iter().map(|c| c.name.clone()).collect(),
            window_opens: settings
                .statistics
                .first_window_step(settings.steps, settings.dt)
                .map_or(u64::MAX, |first| first - 1),
            stable_dt,
            accumulation_bound: accumulation_bound(settings),
            wide: wide_vectors(),
            common_contacts,
        })
    }

    /// The state before the first step of `model` with `settings`: the initial displacement
    /// and velocity, every contact open with its frame at t = 0 (a plane's or bars'), nothing
    /// accumulated.
    pub(super) fn initial_state(&self, model: &Model, settings: &RunSettings) -> State {
        let nc = model.contacts.len();
        let mut contacts = vec![ContactState::blank(); nc];
        for (state, rows) in contacts.iter_mut().zip(&self.frame_rows) {
            if let Some(rows) = rows {
                state.frame = rows.frame(0.0);
            }
        }
        let lagrange = matches!(self.tangential, Tangential::Lagrange { .. });
        State {
            step: 0,
            next_sample: settings.output_every,
            modal: ModalState::new(&model.initial.q, &model.initial.qdot),
            contacts,
            penalty: if lagrange {
                Vec::new()
            } else {
                vec![PenaltyContact::default(); nc]
            },
            history: if lagrange {
                vec![History::default(); nc]
            } else {
                Vec::new()
            },
            previous_lambda: if lagrange {
                vec![Vector2::zeros(); nc]
            } else {
                Vec::new()
            },
            statistics: ContactStatisticsState::new(
                nc,
                &settings.statistics,
                settings.steps,
                settings.dt,
            ),
            solver: SolverStatistics::default(),
            energy: EnergyBalance::default(),
            wear_map: None,
            monitors: vec![MonitorSums::default(); settings.monitors.len()],
        }
    }
}

impl Tangential {
    fn lagrange(
        model: &Model,
        cd: &CentralDifference,
        settings: &RunSettings,
        solver: LagrangeSolver,
    ) -> Self {
        let nc = model.contacts.len();
        let mut problem = TangentialProblem::new(model.basis.modes(), nc);
        for (k, c) in model.contacts.iter().enumerate() {
            if let Some(t) = c.fixed_tangents() {
                let point = c.point_in(&model.basis.points);
                let mut rows = point.rows.clone();
                if c.at_surface() {
                    // a plane: the normal never changes
                    c.surface_rows(point, &c.frame(&point.coords, 0.0).normal, &mut rows);
                }
                problem.fix_rows(k, &t, &rows, |l, out| cd.apply_a_inv(l, out));
            }
        }
        Tangential::Lagrange {
            problem,
            solver,
            theta_dt: settings.stick_velocity.theta() * settings.dt,
            lambda: vec![Vector2::zeros(); nc],
            slide: vec![Slide::Stick; nc],
            work: vec![0.0; 4 * nc * nc + 8 * nc],
        }
    }
}

/// Largest value a step may add to a running sum of the statistics or of the energy balance
/// (a force, a square, a power, a penetration): `f64::MAX / (8 (N + 1) max(1, Δt))` for `N`
/// steps, so that no sum of the run can overflow — a step above it has diverged. (About
/// 2e298 for a billion steps: no physical value comes near it.)
pub(super) fn accumulation_bound(settings: &RunSettings) -> f64 {
    f64::MAX / (8.0 * (settings.steps as f64 + 1.0) * settings.dt.max(1.0))
}

/// Rows (3 × p) through which contact `k` sees the modal coordinates: the point's, or the
/// surface point's ([`crate::contact::Contact::surface_rows`], updated with the normal by
/// detection). A free function, so that it borrows two fields only.
#[inline]
pub(super) fn contact_rows<'a>(model: &'a Model, surface_rows: &'a [f64], k: usize) -> &'a [f64] {
    let c = &model.contacts[k];
    if c.at_surface() {
        let p = model.basis.modes();
        &surface_rows[3 * p * k..3 * p * (k + 1)]
    } else {
        &c.point_in(&model.basis.points).rows
    }
}

/// The modal force of the step: the external force when no contact is closed, else the one
/// the contact forces formed (`force`).
#[inline(always)]
pub(super) fn modal_force<'a>(
    closed: &[usize],
    external: &'a [f64],
    force: &'a [f64],
) -> &'a [f64] {
    if closed.is_empty() { external } else { force }
}

/// Whether the processor runs AVX2 and FMA code.
fn wide_vectors() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
