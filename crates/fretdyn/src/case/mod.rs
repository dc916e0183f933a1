//! **Stage 1 — the case.** What enters: a TOML case file (every key is documented in
//! `examples/*.toml`; unknown keys are errors). What leaves: the typed [`Model`] and
//! [`RunSettings`] of a [`Case`], built by the stages that follow (THEORY §1–§10 for what
//! each key means).
//!
//! The schema is split by section, each file holding its sections' types and the build of
//! the model from them:
//! - `structure`: `[structure]` and `[initial]`;
//! - `structures`: `[[structures]]`, several structures each with its own sections, built by
//!   the code that builds a one-structure case's;
//! - `contacts`: `[[contacts]]` (their `obstacle` tables in `obstacle`, their `wear` tables
//!   in `wear`);
//! - `loads`: `[[loads]]`, `[[modal_loads]]`, `[[line_loads]]`, `[[turbulence]]`,
//!   `[base_excitation]`;
//! - `flow`: `[flow]` and its `[[flow.zones]]`; `flow_damping`: `[flow.damping]`;
//! - `settings`: `[time]`, `[tangential]`, `[output]`, `[statistics]`;
//! - `life`: `[life]`, the service life of `fretdyn life`;
//! - `stability`: `[stability]`, the support conditions of the Connors check.
//!
//! What the sections share as they are built (a tube's model, the points' abscissae, how a
//! point or a file is named) is in `shared`, below them. This module reads the file, holds
//! the top-level schema (`CaseFile`) and builds the sections in order, each from its own
//! tables (the sections never import this module: no file cycle); [`key_path`] addresses
//! its keys (`contacts[0].friction.mu`) for studies and the Python package.

mod contacts;
pub mod fingerprint;
mod flat_bar;
mod flow;
mod flow_damping;
pub mod key_path;
mod life;
mod loads;
pub mod memory;
mod messages;
mod obstacle;
mod quantities;
mod settings;
mod shared;
mod stability;
mod structure;
mod structures;
mod wear;

pub use shared::TubeModel;
pub(crate) use shared::named_file;
pub use stability::{StabilityChecks, SupportCondition};

use contacts::{ContactSection, build_contacts};
use flow::FlowSection;
use life::LifeSection;
use loads::{BaseSection, LineLoadSection, LoadSection, ModalLoadSection, TurbulenceSection};
use settings::{
    OutputSection, SettingsSections, StatisticsSection, TangentialSection, TimeSection,
};
use stability::StabilitySection;
use structure::{InitialSection, StructureSection};
use structures::{StructureEntry, StructureParts};

use std::path::Path;

use serde::Deserialize;

use crate::error::{Error, Result};
use crate::integrator::simulation::RunSettings;
use crate::loads::flow::{Flow, SUPPORT_INACTIVE, StabilityReport};
use crate::model::Model;

/// A parsed, validated case.
#[derive(Debug, Clone)]
pub struct Case {
    /// Title (from the file, or its stem).
    pub title: String,
    /// The model.
    pub model: Model,
    /// Numerical settings.
    pub settings: RunSettings,
    /// The case as read, echoed in `summary.json`.
    pub echo: serde_json::Value,
    /// Accepted but doubtful input (e.g. an approximately mass-normalised basis).
    pub warnings: Vec<String>,
    /// For a `type = "tube"` structure: its finite-element model and modes (`None` for a case
    /// of several structures).
    pub tube: Option<Box<TubeModel>>,
    /// The `[flow]` section: flow zones sampled on the modes (docs/FLOW.md); `None` for a case
    /// of several structures, whose flows act through the model's loads and fluid-elastic
    /// forces (their Connors check is not made).
    pub flow: Option<Box<Flow>>,
    /// The abscissa `s` along the tube of each point of the basis (same order as
    /// `model.basis.points`), m, where known: a tube's named points (at their node), the
    /// `s_<name>` of a `.npz`, `s = …` of inline points, a pinned beam's stations. The
    /// curvilinear coordinate of the `[[flow.zones]]` (docs/FLOW.md); `fretdyn modes` writes
    /// them as `s_<name>`. In a case of several structures, each along its own structure.
    pub point_abscissae: Vec<Option<f64>>,
    /// The `[life]` section: the service life (THEORY §14.5), for `fretdyn life`.
    pub life: Option<crate::settings::life::LifeSettings>,
    /// The `[stability]` section: the support conditions of the Connors check and the
    /// structure's plane (docs/FLOW.md); `None` without one.
    pub stability_checks: Option<Box<StabilityChecks>>,
}

impl Case {
    /// Reads and validates a case file. Relative paths in it are relative to its folder.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let base = path.parent().unwrap_or(Path::new("."));
        let mut case = Self::from_toml_in(&text, base, Some(path))?;
        if case.title.is_empty() {
            case.title = path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
        }
        Ok(case)
    }

    /// Parses a case from TOML text; `base` resolves relative file names.
    pub fn from_toml_str(text: &str, base: &Path) -> Result<Self> {
        Self::from_toml_in(text, base, None)
    }

    /// [`Self::from_toml_str`] of the text of the case file at `path` when there is one (the
    /// warnings about its values name it).
    fn from_toml_in(text: &str, base: &Path, path: Option<&Path>) -> Result<Self> {
        let (echo_value, mut file) = read_case_file(text)?;
        // values no tube, support or flow has: a warning each; values that cannot be
        // computed with: refused before anything is built
        let mut warnings: Vec<String> = quantities::check(&echo_value)?
            .into_iter()
            .map(|w| match path {
                Some(f) => format!("{}: {w}", f.display()),
                None => w,
            })
            .collect();
        let echo = serde_json::to_value(&echo_value).unwrap_or(serde_json::Value::Null);
        let title = file.title.clone().unwrap_or_default();
        let life_section = file.life.take();
        let stability_section = file.stability.take();
        let (model, settings, tube, flow, point_abscissae) = file.build(base, &mut warnings)?;
        // several structures: no one tube's wall (the criterion is then given in m, and
        // the perforation of a wall is not checked)
        let life = match life_section {
            Some(l) => Some(l.build(tube.as_deref())?),
            None => None,
        };
        let stability_checks = match stability_section {
            Some(s) => Some(Box::new(s.build(tube.as_deref(), &model)?)),
            None => None,
        };
        Ok(Self {
            title,
            model,
            settings,
            echo,
            tube,
            flow,
            warnings,
            point_abscissae,
            life,
            stability_checks,
        })
    }

    /// Builds a case from a model and settings made in code.
    pub fn from_parts(title: &str, model: Model, settings: RunSettings) -> Self {
        Self {
            title: title.to_string(),
            model,
            settings,
            echo: serde_json::Value::Null,
            warnings: Vec::new(),
            tube: None,
            flow: None,
            point_abscissae: Vec::new(),
            life: None,
            stability_checks: None,
        }
    }

    /// The Connors fluid-elastic stability check of every mode of the basis (the supports
    /// inactive; docs/FLOW.md), for a case with a `[flow]` section: the check of a study's
    /// `connors_max_ratio`. With the modes' planes when the structure has one.
    pub fn stability(&self) -> Option<StabilityReport> {
        let plane = self.plane_normal();
        self.flow
            .as_ref()
            .map(|f| f.connors_in(&self.model.basis, SUPPORT_INACTIVE, plane))
    }

    /// [`Case::stability`] followed by the check of the modes of every support condition of
    /// `[stability]` (THEORY §16.3; [`crate::structure::constrained`]), each condition's modes
    /// numbered from 1: what `fretdyn stability` reports. `None` without `[flow]`; an error
    /// when a condition's modes cannot be computed.
    pub fn stability_checks(&self) -> Option<Result<StabilityReport>> {
        let mut report = self.stability()?;
        let (Some(checks), Some(flow)) = (&self.stability_checks, &self.flow) else {
            return Some(Ok(report));
        };
        let plane = self.plane_normal();
        for condition in &checks.conditions {
            // a condition exists only on a tube (the section refuses it otherwise)
            let Some(tube) = &self.tube else {
                break;
            };
            let basis = match tube.structure.constrained_basis(
                &tube.basis,
                &condition.constraints,
                condition.selection,
            ) {
                Ok(b) => b,
                Err(e) => {
                    return Some(Err(Error::invalid(
                        "stability.conditions",
                        format!("condition '{}': {e}", condition.name),
                    )));
                }
            };
            let resampled = flow.resampled((0.0, tube.structure.length()), |s0, s1| {
                tube.structure.flow_stations(&basis, s0, s1)
            });
            report.modes.extend(
                resampled
                    .connors_in(&basis.basis, &condition.name, plane)
                    .modes,
            );
        }
        Some(Ok(report))
    }

    /// The unit normal of the structure's plane: `[stability] plane_normal`, or a planar
    /// tube's.
    pub fn plane_normal(&self) -> Option<nalgebra::Vector3<f64>> {
        match &self.stability_checks {
            Some(c) => c.plane_normal,
            None => self.tube.as_ref().and_then(|t| t.structure.plane_normal()),
        }
    }
}

/// Makes the file names of a case read as TOML (as JSON: [`Case::echo`]) absolute, resolved
/// from `base` as the case resolves them, so that the case reads the same files from any
/// folder. The keys whose values are file names are `structure.file` (a `.npz` modal basis;
/// `structures[i].structure.file` in a case of several) and the `file` of every `history` table (a tabulated load history, `.csv` or `.npy`, of
/// `[[loads]]`, `[[modal_loads]]`, `[[line_loads]]` and `[base_excitation]`); a new key
/// naming a file is added here.
pub fn absolute_file_names(case: &mut serde_json::Value, base: &Path) {
    fn absolute(file: &mut serde_json::Value, base: &Path) {
        if let serde_json::Value::String(name) = file {
            *name = base.join(&*name).to_string_lossy().into_owned();
        }
    }
    fn histories(v: &mut serde_json::Value, base: &Path) {
        match v {
            serde_json::Value::Object(map) => {
                for (k, item) in map.iter_mut() {
                    match (k.as_str(), item.get_mut("file")) {
                        ("history", Some(file)) => absolute(file, base),
                        _ => histories(item, base),
                    }
                }
            }
            serde_json::Value::Array(items) => items.iter_mut().for_each(|i| histories(i, base)),
            _ => {}
        }
    }
    if let Some(file) = case.get_mut("structure").and_then(|s| s.get_mut("file")) {
        absolute(file, base);
    }
    if let Some(serde_json::Value::Array(structures)) = case.get_mut("structures") {
        for entry in structures {
            if let Some(file) = entry.get_mut("structure").and_then(|s| s.get_mut("file")) {
                absolute(file, base);
            }
        }
    }
    histories(case, base);
}

/// Checks that `text` reads as a case file (TOML syntax, known keys, types), without building
/// the case; errors give their line and column.
pub(crate) fn check_case_text(text: &str) -> Result<()> {
    read_case_file(text).map(|_| ())
}

/// The case file as TOML and as its schema.
fn read_case_file(text: &str) -> Result<(toml::Value, CaseFile)> {
    let value: toml::Value = toml::from_str(text).map_err(|e| parse_error(text, &e))?;
    if value.get("base").is_some() && value.get("structure").is_none() {
        return Err(Error::invalid(
            "base",
            "this is a study file (a base case and parameters to vary), not a case file: run it with `fretdyn sweep <file>`",
        ));
    }
    let file: CaseFile = toml::from_str(text).map_err(|e| parse_error(text, &e))?;
    Ok((value, file))
}

/// A TOML error with the line and column (from 1) where it is in `text`; a schema error
/// (a value of the wrong type, an unknown or missing key) names the key as written and says
/// what is expected in plain words (`output.every: must be a whole number ≥ 1 (a number of
/// steps), got -1`), not in serde's.
pub(crate) fn parse_error(text: &str, e: &toml::de::Error) -> Error {
    let (line, column) = match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            (line, column)
        }
        None => (0, 0),
    };
    let raw = e.message().trim().replace('\n', " ");
    let (key, message) = messages::schema_message(text, e.span(), &raw);
    Error::Parse {
        line,
        column,
        key,
        message,
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseFile {
    title: Option<String>,
    time: TimeSection,
    /// One structure: `[structure]` with its sections at the top level; or several:
    /// `[[structures]]`, each with its own (never both).
    structure: Option<StructureSection>,
    #[serde(default)]
    structures: Vec<StructureEntry>,
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
    base_excitation: Option<BaseSection>,
    #[serde(default)]
    tangential: TangentialSection,
    #[serde(default)]
    output: OutputSection,
    #[serde(default)]
    statistics: StatisticsSection,
    life: Option<LifeSection>,
    stability: Option<StabilitySection>,
}

/// What a case file builds: the model, the settings, a tube's finite-element model, the flow,
/// the abscissae of the basis's points.
type Built = (
    Model,
    RunSettings,
    Option<Box<TubeModel>>,
    Option<Box<Flow>>,
    Vec<Option<f64>>,
);

impl CaseFile {
    /// The model and settings, section by section in the order of the file's schema; the
    /// first invalid value is the error.
    fn build(self, base: &Path, warnings: &mut Vec<String>) -> Result<Built> {
        let (model, tube, flow, point_abscissae) = match (
            &self.structure,
            self.structures.is_empty(),
        ) {
            (Some(structure), true) => {
                let one = StructureParts {
                    structure,
                    initial: self.initial.as_ref(),
                    contacts: &self.contacts,
                    loads: &self.loads,
                    line_loads: &self.line_loads,
                    modal_loads: &self.modal_loads,
                    turbulence: &self.turbulence,
                    flow: self.flow.as_ref(),
                    index: 0,
                };
                let (model, tube, flow, abscissae) =
                    one.build(base, self.base_excitation.as_ref(), self.time.dt, warnings)?;
                model.validate()?;
                let mut point_abscissae = abscissae.s;
                point_abscissae.resize(model.basis.points.len(), None);
                (model, tube, flow, point_abscissae)
            }
            (None, false) => {
                let (model, abscissae) = self.build_several(base, warnings)?;
                (model, None, None, abscissae)
            }
            (Some(_), false) => {
                return Err(Error::invalid(
                    "structures",
                    "give either [structure] (one structure) or [[structures]] (several, each named), not both",
                ));
            }
            (None, true) => {
                return Err(Error::invalid(
                    "structure",
                    "missing: give [structure] (one structure), or [[structures]] (several, each with a name and its [structures.structure])",
                ));
            }
        };
        // a preloaded case starts at rest in its static equilibrium (THEORY §16.1)
        let mut model = model;
        crate::model::preload::apply_preloads(&mut model)?;
        let sections = SettingsSections {
            time: &self.time,
            tangential: &self.tangential,
            output: &self.output,
            statistics: &self.statistics,
        };
        let settings = sections.settings(&model)?;
        Ok((model, settings, tube, flow, point_abscissae))
    }

    /// The model of several structures (THEORY §15): each `[[structures]]` entry built as a
    /// one-structure case builds its structure, then their union, then the top-level
    /// `[[contacts]]` between them (points named `structure.point`); and the abscissae of the
    /// points, each along its own structure.
    fn build_several(
        &self,
        base: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<(Model, Vec<Option<f64>>)> {
        for (key, given) in [
            ("initial", self.initial.is_some()),
            ("loads", !self.loads.is_empty()),
            ("line_loads", !self.line_loads.is_empty()),
            ("modal_loads", !self.modal_loads.is_empty()),
            ("turbulence", !self.turbulence.is_empty()),
            ("flow", self.flow.is_some()),
        ] {
            if given {
                return Err(Error::invalid(
                    key,
                    format!(
                        "a case of several structures gives its {key} per structure: move it into the [[structures]] entry it acts on ([structures.{key}])"
                    ),
                ));
            }
        }
        if self.stability.is_some() {
            return Err(Error::invalid(
                "stability",
                "the Connors check of a case of several structures is not supported yet: check each structure in a case of its own ([structure] with its [flow] and [stability])",
            ));
        }
        let mut parts = Vec::with_capacity(self.structures.len());
        let mut point_abscissae = Vec::new();
        for (i, s) in self.structures.iter().enumerate() {
            let field = format!("structures[{i}]");
            let (model, tube, _, mut abscissae) = s
                .parts(i)
                .build(base, self.base_excitation.as_ref(), self.time.dt, warnings)
                .map_err(|e| e.within(&field))?;
            abscissae.s.resize(model.basis.points.len(), None);
            point_abscissae.extend(abscissae.s);
            parts.push((s.name.clone(), model, tube));
        }
        let tubes: Vec<(std::ops::Range<usize>, Option<Box<TubeModel>>)> = {
            let mut first = 0;
            parts
                .iter_mut()
                .map(|(_, m, t)| {
                    let n = m.basis.points.len();
                    first += n;
                    (first - n..first, t.take())
                })
                .collect()
        };
        let mut model = Model::union(parts.into_iter().map(|(n, m, _)| (n, m)).collect())?;
        let tube_of = |point: usize| {
            tubes
                .iter()
                .find(|(r, _)| r.contains(&point))
                .and_then(|(_, t)| t.as_deref())
        };
        build_contacts(&self.contacts, &tube_of, &mut model)?;
        // the points across a bar's width (case/flat_bar.rs) have no abscissa of their own
        point_abscissae.resize(model.basis.points.len(), None);
        model.validate()?;
        Ok((model, point_abscissae))
    }
}
