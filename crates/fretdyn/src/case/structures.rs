//! `[[structures]]`: several structures in one case (THEORY §15), each named and given with
//! the sections a one-structure case gives its structure at the top level —
//! `[structures.structure]`, `[structures.initial]`, `[[structures.contacts]]`,
//! `[[structures.loads]]`, `[[structures.line_loads]]`, `[[structures.modal_loads]]`,
//! `[[structures.turbulence]]`, `[structures.flow]` — and built by the same code
//! ([`StructureParts::build`]): one model per structure, their union
//! ([`crate::model::Model::union`]) the case's model. A one-structure case is the same build
//! of its top-level sections.

use std::path::Path;

use serde::Deserialize;

use super::contacts::{ContactSection, build_contacts};
use super::flow::FlowSection;
use super::loads::{
    BaseSection, LineLoadSection, LoadSection, LoadSections, ModalLoadSection, TurbulenceSection,
};
use super::shared::{Abscissae, TubeModel};
use super::structure::{InitialSection, StructureSection};
use crate::error::Result;
use crate::loads::flow::Flow;
use crate::model::Model;

/// One `[[structures]]` entry: its name (the prefix of its points and contacts,
/// `tube_a.mid`) and its structure's sections, named as at the top level of a one-structure
/// case.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct StructureEntry {
    pub name: String,
    structure: StructureSection,
    initial: Option<InitialSection>,
    #[serde(default)]
    contacts: Vec<ContactSection>,
    #[serde(default)]
    loads: Vec<LoadSection>,
    #[serde(default)]
    line_loads: Vec<LineLoadSection>,
    #[serde(default)]
    modal_loads: Vec<ModalLoadSection>,
    #[serde(default)]
    turbulence: Vec<TurbulenceSection>,
    flow: Option<FlowSection>,
}

impl StructureEntry {
    /// Its sections, as structure `index` of the case.
    pub(super) fn parts(&self, index: usize) -> StructureParts<'_> {
        StructureParts {
            structure: &self.structure,
            initial: self.initial.as_ref(),
            contacts: &self.contacts,
            loads: &self.loads,
            line_loads: &self.line_loads,
            modal_loads: &self.modal_loads,
            turbulence: &self.turbulence,
            flow: self.flow.as_ref(),
            index,
        }
    }
}

/// The sections of one structure: the top level of a one-structure case, or a
/// `[[structures]]` entry.
pub(super) struct StructureParts<'a> {
    pub structure: &'a StructureSection,
    pub initial: Option<&'a InitialSection>,
    pub contacts: &'a [ContactSection],
    pub loads: &'a [LoadSection],
    pub line_loads: &'a [LineLoadSection],
    pub modal_loads: &'a [ModalLoadSection],
    pub turbulence: &'a [TurbulenceSection],
    pub flow: Option<&'a FlowSection>,
    /// Its index among the structures (0 for a one-structure case): the default seeds of its
    /// turbulence.
    pub index: usize,
}

/// What one structure's sections build: its model, a tube's finite-element model, the flow,
/// the abscissae of its points.
type BuiltStructure = (Model, Option<Box<TubeModel>>, Option<Box<Flow>>, Abscissae);

impl StructureParts<'_> {
    /// The structure's model (its basis, contacts, flow, loads, fluid-elastic forces and
    /// initial state, in this order), with the case's base excitation and time step `dt`
    /// (the band limit of turbulence); the first invalid value is the error, its field as
    /// the structure's sections name it (`contacts[0].point`).
    pub(super) fn build(
        &self,
        base: &Path,
        base_excitation: Option<&BaseSection>,
        dt: f64,
        warnings: &mut Vec<String>,
    ) -> Result<BuiltStructure> {
        let (basis, tube, abscissae) = self.structure.build(base, warnings)?;
        basis.validate("structure")?;
        let mut model = Model::new(basis);
        build_contacts(self.contacts, &|_| tube.as_deref(), &mut model)?;
        let mut flow = match self.flow {
            Some(f) => Some(Box::new(f.build(tube.as_deref(), &abscissae, &model)?)),
            None => None,
        };
        // `[flow.damping] in_run`: the fluid's damping terms join the run's modal damping
        if let Some(f) = &mut flow {
            let (d, m) = (f.diameter, f.mass_per_length);
            if let Some(damping) = &mut f.damping {
                let basis = &mut model.basis;
                damping.add_to_run(&basis.omega, &mut basis.damping_ratio, d, m);
            }
        }
        let loads = LoadSections {
            loads: self.loads,
            modal_loads: self.modal_loads,
            line_loads: self.line_loads,
            turbulence: self.turbulence,
            base_excitation,
            dt,
            structure: self.index,
        };
        loads.build(base, tube.as_deref(), flow.as_deref(), &mut model)?;
        if let Some(f) = &flow {
            let hz: Vec<f64> = model
                .basis
                .omega
                .iter()
                .map(|w| w / std::f64::consts::TAU)
                .collect();
            model.fluid_elastic = f.fluid_elastic(&hz);
        }
        if let Some(initial) = self.initial {
            initial.build(&mut model)?;
        }
        Ok((model, tube, flow, abscissae))
    }
}
