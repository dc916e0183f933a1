//! **Stage 5 — the model.** What enters: the modal basis ([`crate::structure`]), the contacts
//! ([`crate::contact`]) and the loads ([`crate::loads`]), as the case built them. What leaves:
//! the [`Model`] the integrator steps — modal basis, contacts, loads and initial state,
//! everything a run needs except the numerical settings (THEORY §1, §2).

pub mod equilibrium;
mod structures;

pub use equilibrium::{StaticState, static_equilibrium};
pub use structures::StructureRange;

use nalgebra::DMatrix;

use crate::contact::Contact;
use crate::error::{Error, Result};
use crate::loads::{BaseAcceleration, ModalLoad, PointLoad};
use crate::structure::modal::ModalBasis;

/// Initial modal state `q(0)`, `q̇(0)`.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialState {
    /// Modal displacements.
    pub q: Vec<f64>,
    /// Modal velocities.
    pub qdot: Vec<f64>,
}

/// Mass, damping and stiffness matrices of physical coordinates (symmetric, `M` positive
/// definite), for the physical-coordinates reference solver.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicalMatrices {
    /// Mass matrix `M`.
    pub mass: nalgebra::DMatrix<f64>,
    /// Damping matrix `C`.
    pub damping: nalgebra::DMatrix<f64>,
    /// Stiffness matrix `K`.
    pub stiffness: nalgebra::DMatrix<f64>,
}

/// What the generalized coordinates `q` of a model are.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Coordinates {
    /// Modal coordinates of a mass-normalised basis: `M = I`, `K = Ω²`,
    /// `C = diag(2 ξ_i ω_i)` (THEORY §1). The normal case.
    #[default]
    Modal,
    /// Physical degrees of freedom with their matrices: the same central differences and
    /// contacts on `M q̈ + C q̇ + K q = f`, used to prove that the modal solution is exact when
    /// every mode is kept. The "basis" then holds, for each point, the 3 × n rows that pick
    /// its displacement out of `q`; its frequencies and damping ratios are not used.
    Physical(Box<PhysicalMatrices>),
}

/// A structure on its modal basis with its contacts and loads.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// Modal basis with the rows of every point used.
    pub basis: ModalBasis,
    /// Modal (the normal case) or physical coordinates.
    pub coordinates: Coordinates,
    /// Contacts.
    pub contacts: Vec<Contact>,
    /// Point loads.
    pub loads: Vec<PointLoad>,
    /// Loads given on the modes (modal forces, line loads along a tube).
    pub modal_loads: Vec<ModalLoad>,
    /// Random turbulence loads.
    pub turbulence: Vec<crate::loads::TurbulentLoad>,
    /// Uniform acceleration of the base, if any (displacements are then relative to it).
    pub base_acceleration: Option<BaseAcceleration>,
    /// Fluid-elastic forces of the flow, on the modes (THEORY §13).
    pub fluid_elastic: Option<crate::loads::fluid_elastic::FluidElastic>,
    /// The wear laws and scar geometry of each contact that has them (`docs/WEAR.md`,
    /// THEORY §14): one per contact as a case file builds them, or empty; used after the
    /// run, never in the time-step loop. See [`Model::contact_wear`].
    pub wear: Vec<Option<crate::wear::ContactWear>>,
    /// Initial state.
    pub initial: InitialState,
    /// For a model of several structures ([`Model::union`], THEORY §15), where each one's
    /// modes, points and contacts are; empty for a model of one structure.
    pub structures: Vec<StructureRange>,
}

impl Model {
    /// A model at rest with no contact and no load.
    pub fn new(basis: ModalBasis) -> Self {
        let p = basis.modes();
        Self {
            basis,
            coordinates: Coordinates::Modal,
            contacts: Vec::new(),
            loads: Vec::new(),
            modal_loads: Vec::new(),
            turbulence: Vec::new(),
            base_acceleration: None,
            fluid_elastic: None,
            wear: Vec::new(),
            initial: InitialState {
                q: vec![0.0; p],
                qdot: vec![0.0; p],
            },
            structures: Vec::new(),
        }
    }

    /// A model in physical coordinates: `points` give, for each named point, the 3 × n rows
    /// that pick its displacement out of the n degrees of freedom.
    pub fn physical(
        matrices: PhysicalMatrices,
        points: Vec<crate::structure::modal::Point>,
    ) -> Self {
        let n = matrices.mass.nrows();
        let mut model = Self::new(ModalBasis {
            omega: vec![0.0; n],
            damping_ratio: vec![0.0; n],
            points,
            participation: Vec::new(),
        });
        model.coordinates = Coordinates::Physical(Box::new(matrices));
        model
    }

    /// The wear laws and scar geometry of contact `k`, if it has them.
    pub fn contact_wear(&self, k: usize) -> Option<&crate::wear::ContactWear> {
        self.wear.get(k).and_then(Option::as_ref)
    }

    /// Checks the basis and that every index and vector length is consistent.
    pub fn validate(&self) -> Result<()> {
        self.basis.validate("structure")?;
        let p = self.basis.modes();
        if let Coordinates::Physical(m) = &self.coordinates {
            for (name, a) in [
                ("mass", &m.mass),
                ("damping", &m.damping),
                ("stiffness", &m.stiffness),
            ] {
                if a.nrows() != p || a.ncols() != p || a.iter().any(|v| !v.is_finite()) {
                    return Err(Error::invalid(
                        format!("structure.{name}"),
                        format!("must be a finite {p} × {p} matrix"),
                    ));
                }
            }
            if m.mass.clone().cholesky().is_none() {
                return Err(Error::invalid(
                    "structure.mass",
                    "the mass matrix is not positive definite",
                ));
            }
        }
        if let Some(fe) = &self.fluid_elastic {
            fe.validate(p)?;
        }
        if self.wear.len() > self.contacts.len() {
            return Err(Error::invalid(
                "contacts",
                format!(
                    "{} wear entries for {} contacts: give at most one per contact",
                    self.wear.len(),
                    self.contacts.len()
                ),
            ));
        }
        for (k, w) in self.wear.iter().enumerate() {
            if let Some(w) = w {
                w.validate(&format!("contacts[{k}].wear"))?;
            }
        }
        let np = self.basis.points.len();
        for (k, c) in self.contacts.iter().enumerate() {
            if c.point >= np {
                return Err(Error::invalid(
                    format!("contacts[{k}].point"),
                    "refers to no point of the structure",
                ));
            }
            if let Some(pair) = &c.pair {
                let field = format!("contacts[{k}]");
                let (a, b) = (
                    &self.basis.points[c.point],
                    self.basis.points.get(pair.other),
                );
                let Some(b) = b else {
                    return Err(Error::invalid(
                        format!("{field}.other"),
                        "refers to no point of the model",
                    ));
                };
                // the relative point is derived data: it must be the one of the points now
                let fresh = crate::contact::Pair::new(a, pair.other, b, pair.radii, &field)?;
                if fresh != **pair || c.radius != pair.radii[0] + pair.radii[1] {
                    return Err(Error::invalid(
                        field,
                        "its relative point no longer matches its points' rows (the basis changed after Contact::between): build the contact again",
                    ));
                }
            }
            c.validate(c.point_in(&self.basis.points), &format!("contacts[{k}]"))?;
        }
        for (k, l) in self.loads.iter().enumerate() {
            if l.point >= np {
                return Err(Error::invalid(
                    format!("loads[{k}].point"),
                    "refers to no point of the structure",
                ));
            }
        }
        for (k, l) in self.modal_loads.iter().enumerate() {
            if l.row.len() != p {
                return Err(Error::invalid(
                    format!("modal_loads[{k}].force"),
                    format!("must have one value per mode ({p}), got {}", l.row.len()),
                ));
            }
        }
        for (k, l) in self.turbulence.iter().enumerate() {
            l.validate(p, &format!("turbulence[{k}]"))?;
        }
        if self.base_acceleration.is_some() && self.basis.participation.is_empty() {
            return Err(Error::invalid(
                "base_excitation",
                "the modal basis has no participation factors Φᵀ M r: use a point_mass, pinned_beam or tube structure, or give participation (inline, or 'participation' in the .npz)",
            ));
        }
        for (name, v) in [
            ("initial.q", &self.initial.q),
            ("initial.qdot", &self.initial.qdot),
        ] {
            if v.len() != p {
                return Err(Error::invalid(
                    name,
                    format!("must have one value per mode ({p}), got {}", v.len()),
                ));
            }
            if v.iter().any(|x| !x.is_finite()) {
                return Err(Error::invalid(name, "must be finite numbers"));
            }
        }
        Ok(())
    }

    /// Sets the initial state from a displacement and velocity of one point, with the
    /// minimum-norm modal state that produces them (exact for a point mass).
    pub fn set_initial_from_point(
        &mut self,
        point: usize,
        displacement: nalgebra::Vector3<f64>,
        velocity: nalgebra::Vector3<f64>,
    ) -> Result<()> {
        let p = self.basis.modes();
        let rows = &self.basis.points[point].rows;
        let phi = nalgebra::DMatrix::from_row_slice(3, p, rows);
        let pinv = phi.clone().pseudo_inverse(1e-12).map_err(|e| {
            Error::invalid("initial.point", format!("its rows cannot be inverted: {e}"))
        })?;
        let q = &pinv * nalgebra::DVector::from_column_slice(displacement.as_slice());
        let qd = &pinv * nalgebra::DVector::from_column_slice(velocity.as_slice());
        for (name, target, got) in [
            ("initial.displacement", displacement, &phi * &q),
            ("initial.velocity", velocity, &phi * &qd),
        ] {
            let err = (nalgebra::DVector::from_column_slice(target.as_slice()) - got).norm();
            if err > 1e-9 * target.norm().max(1e-300) {
                return Err(Error::invalid(
                    name,
                    format!(
                        "cannot be produced by the modes at this point (residual {err:.3e}): give initial.q / initial.qdot instead"
                    ),
                ));
            }
        }
        self.initial.q = q.iter().copied().collect();
        self.initial.qdot = qd.iter().copied().collect();
        Ok(())
    }
}

/// The tube's reference model in physical coordinates: here, not in [`crate::structure::tube`],
/// because it builds a [`Model`] (the structure layer is below the model).
impl crate::structure::tube::TubeStructure {
    /// The same finite elements in physical coordinates with Rayleigh damping
    /// `C = α M + β K` — the reference solver of the tests (small models only: dense).
    pub fn physical_model(&self, alpha: f64, beta: f64) -> Result<Model> {
        let assembled = self.beam.assemble()?;
        let n = assembled.mass.nrows();
        let points = self.named_points(&assembled, &DMatrix::<f64>::identity(n, n));
        let damping = &assembled.mass * alpha + &assembled.stiffness * beta;
        let participation: Vec<f64> = assembled.base_inertia.iter().copied().collect();
        let mut model = Model::physical(
            PhysicalMatrices {
                mass: assembled.mass,
                damping,
                stiffness: assembled.stiffness,
            },
            points,
        );
        model.basis.participation = participation;
        Ok(model)
    }
}
