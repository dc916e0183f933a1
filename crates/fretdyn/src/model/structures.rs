//! Several structures in one model (THEORY §15): each reduced on its own modes, the model's
//! basis their union. With `q = (q_1, …, q_S)` the modal coordinates of the structures side
//! by side, the mass, damping and stiffness are block diagonal, a point of structure `s` has
//! rows `Φ = [0 … Φ_s … 0]`, and only the two-body contacts couple the blocks (their rows
//! `Φ_A − Φ_B`, [`crate::contact::Pair`]). Nothing else changes: the integrator steps the
//! union as one model.

use std::ops::Range;

use nalgebra::DMatrix;

use super::{Coordinates, InitialState, Model, PhysicalMatrices};
use crate::error::{Error, Result};
use crate::loads::fluid_elastic::{FluidElastic, ModalMatrix};
use crate::structure::modal::{ModalBasis, Point};

/// Where one structure of a model of several is: its name and the ranges of its modes,
/// points and contacts in the model's (contacts between structures come after every
/// structure's own).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StructureRange {
    /// Name (the prefix of its points and contacts: `tube_a.tsp1`).
    pub name: String,
    /// Its modes in the model's modal coordinates.
    pub modes: Range<usize>,
    /// Its points in the model's basis.
    pub points: Range<usize>,
    /// Its own contacts (with obstacles, or between two of its points) in the model's.
    pub contacts: Range<usize>,
}

impl Model {
    /// The model of several structures side by side (THEORY §15), from each one's own model:
    /// bases block diagonal, points and contacts named `structure.name`, loads, turbulence and
    /// fluid-elastic forces acting on their structure's modes only, initial states side by
    /// side. Two-body contacts between structures are added afterwards
    /// ([`crate::contact::Contact::between`] on the union's points).
    ///
    /// Every structure must have modal coordinates, or every one physical coordinates; a base
    /// excitation, if any, must be the same for all (and every structure must then have
    /// participation factors).
    pub fn union(parts: Vec<(String, Model)>) -> Result<Model> {
        if parts.is_empty() {
            return Err(Error::invalid("structures", "give at least one structure"));
        }
        for (i, (name, model)) in parts.iter().enumerate() {
            let field = format!("structures[{i}]");
            if name.is_empty() || name.contains('.') || name.contains(char::is_whitespace) {
                return Err(Error::invalid(
                    format!("{field}.name"),
                    format!(
                        "'{name}' must be a non-empty name without dots or spaces (it prefixes the structure's points: name.point)"
                    ),
                ));
            }
            if let Some(j) = parts[..i].iter().position(|(n, _)| n == name) {
                return Err(Error::invalid(
                    format!("{field}.name"),
                    format!(
                        "'{name}' is already the name of structures[{j}]: give each structure its own"
                    ),
                ));
            }
            model.validate().map_err(|e| e.within(&field))?;
        }
        let sizes: Vec<usize> = parts.iter().map(|(_, m)| m.basis.modes()).collect();
        let total: usize = sizes.iter().sum();
        let offsets: Vec<usize> = sizes
            .iter()
            .scan(0, |acc, p| {
                let o = *acc;
                *acc += p;
                Some(o)
            })
            .collect();
        let pad = |row: &[f64], s: usize| -> Vec<f64> {
            let mut out = vec![0.0; total];
            out[offsets[s]..offsets[s] + sizes[s]].copy_from_slice(row);
            out
        };
        // a 3 × p row-major block (rows, rotations, participation) widened to 3 × total
        let pad3 = |rows: &[f64], s: usize| -> Vec<f64> {
            if rows.is_empty() {
                return Vec::new();
            }
            (0..3)
                .flat_map(|d| pad(&rows[d * sizes[s]..(d + 1) * sizes[s]], s))
                .collect()
        };
        let mut basis = ModalBasis {
            omega: Vec::with_capacity(total),
            damping_ratio: Vec::with_capacity(total),
            points: Vec::new(),
            participation: Vec::new(),
        };
        let mut model = Model::new(ModalBasis {
            omega: vec![0.0; total],
            damping_ratio: vec![0.0; total],
            points: Vec::new(),
            participation: Vec::new(),
        });
        let physical = parts
            .iter()
            .filter(|(_, m)| matches!(m.coordinates, Coordinates::Physical(_)))
            .count();
        if physical != 0 && physical != parts.len() {
            return Err(Error::invalid(
                "structures",
                "mixes modal and physical coordinates: reduce every structure on its modes, or none",
            ));
        }
        let with_participation = parts
            .iter()
            .filter(|(_, m)| !m.basis.participation.is_empty())
            .count();
        let base = parts[0].1.base_acceleration.clone();
        if let Some(i) = parts.iter().position(|(_, m)| m.base_acceleration != base) {
            return Err(Error::invalid(
                format!("structures[{i}].base_excitation"),
                "differs from the first structure's: the base moves every structure alike",
            ));
        }
        let mut matrices = [
            DMatrix::<f64>::zeros(total, total),
            DMatrix::<f64>::zeros(total, total),
            DMatrix::<f64>::zeros(total, total),
        ];
        let mut fluid = FluidElastic {
            delayed: Vec::new(),
            damping: Vec::new(),
        };
        let mut any_fluid = false;
        let mut q = Vec::with_capacity(total);
        let mut qdot = Vec::with_capacity(total);
        let mut participation = [Vec::new(), Vec::new(), Vec::new()];
        for (s, (name, part)) in parts.into_iter().enumerate() {
            let (o, p) = (offsets[s], sizes[s]);
            let first_point = basis.points.len();
            let first_contact = model.contacts.len();
            basis.omega.extend(&part.basis.omega);
            basis.damping_ratio.extend(&part.basis.damping_ratio);
            if with_participation == sizes.len() {
                for (d, out) in participation.iter_mut().enumerate() {
                    out.extend(&part.basis.participation[d * p..(d + 1) * p]);
                }
            }
            basis
                .points
                .extend(part.basis.points.iter().map(|pt| Point {
                    name: format!("{name}.{}", pt.name),
                    coords: pt.coords,
                    rows: pad3(&pt.rows, s),
                    rotations: pad3(&pt.rotations, s),
                }));
            if let Coordinates::Physical(m) = &part.coordinates {
                for (big, small) in matrices.iter_mut().zip([&m.mass, &m.damping, &m.stiffness]) {
                    big.view_mut((o, o), (p, p)).copy_from(small);
                }
            }
            let mut wear = part.wear;
            wear.resize(part.contacts.len(), None);
            for mut c in part.contacts {
                c.name = format!("{name}.{}", c.name);
                c.point += first_point;
                if let Some(pair) = c.pair.take() {
                    let (a, b) = (
                        &basis.points[c.point],
                        &basis.points[first_point + pair.other],
                    );
                    let other = first_point + pair.other;
                    let field = format!("structures[{s}].contacts '{}'", c.name);
                    c.pair = Some(Box::new(crate::contact::Pair::new(
                        a, other, b, pair.radii, &field,
                    )?));
                }
                model.contacts.push(c);
            }
            model.wear.extend(wear);
            for mut l in part.loads {
                l.point += first_point;
                model.loads.push(l);
            }
            for mut l in part.modal_loads {
                l.row = pad(&l.row, s);
                model.modal_loads.push(l);
            }
            for mut l in part.turbulence {
                l.rows = l.rows.chunks_exact(p).flat_map(|r| pad(r, s)).collect();
                model.turbulence.push(l);
            }
            if let Some(fe) = part.fluid_elastic {
                any_fluid = true;
                let widen = |m: ModalMatrix| match m {
                    ModalMatrix::Diagonal(d) => ModalMatrix::Diagonal(pad(&d, s)),
                    ModalMatrix::Dense(d) => {
                        let mut out = vec![0.0; total * total];
                        for (i, row) in d.chunks_exact(p).enumerate() {
                            out[(o + i) * total + o..(o + i) * total + o + p].copy_from_slice(row);
                        }
                        ModalMatrix::Dense(out)
                    }
                };
                for mut g in fe.delayed {
                    g.name = format!("{name}.{}", g.name);
                    g.stiffness = widen(g.stiffness);
                    fluid.delayed.push(g);
                }
                fluid.damping.extend(fe.damping.into_iter().map(widen));
            }
            q.extend(&part.initial.q);
            qdot.extend(&part.initial.qdot);
            model.structures.push(StructureRange {
                name,
                modes: o..o + p,
                points: first_point..basis.points.len(),
                contacts: first_contact..model.contacts.len(),
            });
        }
        if with_participation == sizes.len() {
            basis.participation = participation.concat();
        }
        model.basis = basis;
        if physical != 0 {
            let [mass, damping, stiffness] = matrices;
            model.coordinates = Coordinates::Physical(Box::new(PhysicalMatrices {
                mass,
                damping,
                stiffness,
            }));
        }
        model.base_acceleration = base;
        model.fluid_elastic = any_fluid.then_some(fluid);
        model.initial = InitialState { q, qdot };
        model.validate()?;
        Ok(model)
    }

    /// The structure that point `point` belongs to, for a model of several (`None` for a model
    /// of one structure).
    pub fn structure_of_point(&self, point: usize) -> Option<&StructureRange> {
        self.structures.iter().find(|s| s.points.contains(&point))
    }
}
