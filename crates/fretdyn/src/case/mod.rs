//! Case files: the human-readable TOML input, parsed at the edge into the typed [`Model`] and
//! [`RunSettings`]. Every key is documented in `examples/*.toml`; unknown keys are errors.

use std::path::Path;

use nalgebra::{Vector2, Vector3};
use serde::Deserialize;

use crate::contact::friction::{Coulomb, LocalSolve};
use crate::contact::motion::Motion;
use crate::contact::obstacle::{BiPlane, Circle, Obstacle, Plane, Polygon};
use crate::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use crate::contact::{Contact, NormalLaw};
use crate::error::{Error, Result, number};
use crate::integrator::simulation::RunSettings;
use crate::integrator::stability::checked_stable_time_step;
use crate::loads::spatial_correlation::{covariance_factor, line_covariance};
use crate::loads::turbulence::Spectrum;
use crate::loads::{BaseAcceleration, ModalLoad, PointLoad, Sine, TimeHistory, TurbulentLoad};
use crate::model::Model;
use crate::results::statistics::StatisticsSettings;
use crate::structure::beam::{
    BeamModel, Dof, Fluid, Material, Mesh, Restraint, Theory, Tube, TubeSection, clamped, pinned,
};
use crate::structure::eigen::ModeSelection;
use crate::structure::modal::{ModalBasis, PinnedBeam, Point, check_damping_ratio};
use crate::structure::tube::{Damping, NamedPoint, TubeBasis, TubeStructure, node_at};

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
    /// For a `type = "tube"` structure: its finite-element model and modes.
    pub tube: Option<Box<TubeModel>>,
}

impl Case {
    /// Reads and validates a case file. Relative paths in it are relative to its folder.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let base = path.parent().unwrap_or(Path::new("."));
        let mut case = Self::from_toml_str(&text, base)?;
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
        let (echo_value, file) = read_case_file(text)?;
        let echo = serde_json::to_value(&echo_value).unwrap_or(serde_json::Value::Null);
        let title = file.title.clone().unwrap_or_default();
        let mut warnings = Vec::new();
        let (model, settings, tube) = file.build(base, &mut warnings)?;
        Ok(Self {
            title,
            model,
            settings,
            echo,
            tube,
            warnings,
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
        }
    }
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

/// A TOML error with the line and column (from 1) where it is in `text`.
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
    Error::Parse {
        line,
        column,
        message: e.message().trim().replace('\n', " "),
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseFile {
    title: Option<String>,
    time: TimeSection,
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
    base_excitation: Option<BaseSection>,
    #[serde(default)]
    tangential: TangentialSection,
    #[serde(default)]
    output: OutputSection,
    #[serde(default)]
    statistics: StatisticsSection,
}

/// `[statistics]`: the window, blocks, impact definition and wear coefficient (THEORY §5).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct StatisticsSection {
    #[serde(default)]
    t_start: f64,
    t_end: Option<f64>,
    block: Option<f64>,
    #[serde(default)]
    rest_duration: f64,
    #[serde(default)]
    wear_coefficient: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TimeSection {
    dt: f64,
    duration: f64,
}

#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
enum StructureSection {
    PointMass {
        mass: f64,
        #[serde(default = "default_point_name")]
        point: String,
        #[serde(default)]
        position: [f64; 3],
    },
    Modal {
        frequencies_hz: Option<Vec<f64>>,
        damping_ratio: Option<DampingInput>,
        file: Option<String>,
        #[serde(default)]
        points: Vec<PointInput>,
        /// 3 rows (x, y, z) of p values `Φᵀ M r`.
        participation: Option<Vec<Vec<f64>>>,
    },
    Tube(Box<TubeInput>),
    PinnedBeam {
        length: f64,
        bending_stiffness: f64,
        mass_per_length: f64,
        modes_per_plane: usize,
        #[serde(default)]
        axial_stiffness: f64,
        #[serde(default)]
        axial_modes: usize,
        #[serde(default)]
        damping_ratio: f64,
        points: Vec<StationInput>,
    },
}

/// `type = "tube"`: a beam finite-element tube (see `examples/tube_clamped_one_support.toml`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TubeInput {
    outer_diameter: f64,
    wall_thickness: f64,
    young_modulus: f64,
    poisson_ratio: f64,
    density: f64,
    #[serde(default)]
    inner_fluid_density: f64,
    #[serde(default)]
    outer_fluid_density: f64,
    #[serde(default)]
    added_mass_coefficient: f64,
    #[serde(default)]
    theory: TheoryName,
    mesh_size: f64,
    path: Option<Vec<[f64; 3]>>,
    u_bend: Option<UBendInput>,
    modes: Option<usize>,
    max_frequency_hz: Option<f64>,
    damping_ratio: Option<DampingInput>,
    rayleigh: Option<RayleighInput>,
    #[serde(default)]
    supports: Vec<SupportInput>,
    #[serde(default)]
    points: Vec<TubePointInput>,
}

#[derive(Debug, Default, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum TheoryName {
    #[default]
    EulerBernoulli,
    Timoshenko,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct UBendInput {
    leg_length: f64,
    radius: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RayleighInput {
    alpha: f64,
    beta: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SupportInput {
    at: [f64; 3],
    #[serde(rename = "type")]
    kind: SupportKind,
    stiffness: Option<[f64; 6]>,
    #[serde(default)]
    fixed: Vec<Dof>,
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum SupportKind {
    Clamped,
    Pinned,
    Springs,
    Dofs,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TubePointInput {
    name: String,
    at: [f64; 3],
    #[serde(default)]
    offset: [f64; 3],
}

fn default_point_name() -> String {
    "mass".to_string()
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum DampingInput {
    Constant(f64),
    PerMode(Vec<f64>),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PointInput {
    name: String,
    #[serde(default)]
    coords: [f64; 3],
    rows: Vec<Vec<f64>>,
    #[serde(default)]
    rotations: Vec<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StationInput {
    name: String,
    x: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct InitialSection {
    point: Option<String>,
    displacement: Option<[f64; 3]>,
    velocity: Option<[f64; 3]>,
    q: Option<Vec<f64>>,
    qdot: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ContactSection {
    name: Option<String>,
    point: String,
    obstacle: ObstacleInput,
    #[serde(default)]
    radius: f64,
    motion: Option<MotionInput>,
    normal: NormalInput,
    friction: FrictionInput,
}

#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
enum MotionInput {
    Velocity {
        velocity: [f64; 3],
    },
    Harmonic {
        amplitude: [f64; 3],
        frequency_hz: f64,
        #[serde(default)]
        phase_deg: f64,
    },
    Table {
        table: Vec<[f64; 4]>,
    },
}

impl MotionInput {
    fn motion(&self) -> Motion {
        match self {
            MotionInput::Velocity { velocity } => Motion::Velocity(v3(*velocity)),
            MotionInput::Harmonic {
                amplitude,
                frequency_hz,
                phase_deg,
            } => Motion::Harmonic {
                amplitude: v3(*amplitude),
                frequency_hz: *frequency_hz,
                phase: phase_deg.to_radians(),
            },
            MotionInput::Table { table } => Motion::Table {
                times: table.iter().map(|r| r[0]).collect(),
                displacements: table
                    .iter()
                    .map(|r| Vector3::new(r[1], r[2], r[3]))
                    .collect(),
            },
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
enum ObstacleInput {
    Plane {
        #[serde(default)]
        origin: [f64; 3],
        normal: [f64; 3],
        #[serde(default)]
        gap: f64,
        tangent: Option<[f64; 3]>,
    },
    Circle {
        centre: [f64; 3],
        axis: [f64; 3],
        clearance: f64,
    },
    BiPlane {
        #[serde(default)]
        origin: [f64; 3],
        normal: [f64; 3],
        gap: f64,
        tangent: Option<[f64; 3]>,
    },
    Polygon {
        centre: [f64; 3],
        axis: [f64; 3],
        reference: Option<[f64; 3]>,
        /// In-plane vertices `[x1, x2]` along (reference, axis × reference), m.
        vertices: Option<Vec<[f64; 2]>>,
        /// Vertices as `[angle_deg, radius]` pairs.
        polar: Option<Vec<[f64; 2]>>,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct NormalInput {
    stiffness: f64,
    #[serde(default)]
    damping: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FrictionInput {
    mu: Option<f64>,
    mu_static: Option<f64>,
    mu_dynamic: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LoadSection {
    point: String,
    force: [f64; 3],
    #[serde(default)]
    history: HistoryInput,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct BaseSection {
    acceleration: [f64; 3],
    #[serde(default)]
    history: HistoryInput,
}

/// `[[line_loads]]`: a uniform force per unit length on an arc-length span of a tube.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LineLoadSection {
    /// `[s0, s1]`, m along the tube from its first point (default: the whole tube).
    span: Option<[f64; 2]>,
    force_per_length: [f64; 3],
    #[serde(default)]
    history: HistoryInput,
}

/// `[[modal_loads]]`: a generalized force given on the modes.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModalLoadSection {
    force: Vec<f64>,
    #[serde(default)]
    history: HistoryInput,
}

/// `[[turbulence]]`: random turbulence along a span of a tube (docs/LOADS.md).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TurbulenceSection {
    span: Option<[f64; 2]>,
    /// Directions of the force (each gets independent signals), e.g. the two transverse axes.
    directions: Vec<[f64; 3]>,
    /// Correlation length λ of `exp(−|Δs|/λ)`, m (`inf`: fully correlated).
    correlation_length: f64,
    seed: u64,
    f_max: f64,
    spectrum: SpectrumInput,
    /// Fraction of the correlation matrix's trace that the kept channels may leave out.
    #[serde(default = "default_correlation_tolerance")]
    tolerance: f64,
}

fn default_correlation_tolerance() -> f64 {
    1e-3
}

#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
enum SpectrumInput {
    /// One-sided PSD of the force per unit length, (N/m)²/Hz.
    Table {
        frequency_hz: Vec<f64>,
        psd: Vec<f64>,
    },
    /// Code_Aster's SPEC_LONG_COR_2 cross-flow spectrum (docs/LOADS.md).
    CrossFlow {
        velocity: f64,
        density: f64,
        /// Default: the tube's outer diameter.
        diameter: Option<f64>,
        phi0: Option<f64>,
        beta: Option<f64>,
        reduced_cutoff: Option<f64>,
    },
}

impl SpectrumInput {
    fn spectrum(&self, tube_diameter: f64) -> Spectrum {
        match self {
            SpectrumInput::Table { frequency_hz, psd } => Spectrum::Table {
                frequency_hz: frequency_hz.clone(),
                psd: psd.clone(),
            },
            SpectrumInput::CrossFlow {
                velocity,
                density,
                diameter,
                phi0,
                beta,
                reduced_cutoff,
            } => {
                let d = diameter.unwrap_or(tube_diameter);
                let Spectrum::CrossFlow {
                    phi0: p0,
                    beta: b0,
                    reduced_cutoff: r0,
                    ..
                } = Spectrum::cross_flow(*velocity, *density, d)
                else {
                    unreachable!("cross_flow builds a CrossFlow spectrum")
                };
                Spectrum::CrossFlow {
                    velocity: *velocity,
                    density: *density,
                    diameter: d,
                    phi0: phi0.unwrap_or(p0),
                    beta: beta.unwrap_or(b0),
                    reduced_cutoff: reduced_cutoff.unwrap_or(r0),
                }
            }
        }
    }
}

#[derive(Debug, Default, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
enum HistoryInput {
    #[default]
    Constant,
    Harmonic {
        frequency_hz: f64,
        #[serde(default)]
        phase_deg: f64,
    },
    /// `terms = [[amplitude, frequency_hz, phase_deg], ...]`.
    Sines { terms: Vec<[f64; 3]> },
    /// `table = [[t, value], ...]`, or `file` = a CSV (two columns t, value) or a `.npy`
    /// (N × 2) file, relative to the case file.
    Table {
        table: Option<Vec<[f64; 2]>>,
        file: Option<String>,
    },
}

impl HistoryInput {
    fn history(&self, base: &Path, field: &str) -> Result<TimeHistory> {
        let history = match self {
            HistoryInput::Constant => TimeHistory::Constant,
            HistoryInput::Harmonic {
                frequency_hz,
                phase_deg,
            } => TimeHistory::Harmonic {
                frequency_hz: *frequency_hz,
                phase: phase_deg.to_radians(),
            },
            HistoryInput::Sines { terms } => TimeHistory::Sines(
                terms
                    .iter()
                    .map(|[a, f, p]| Sine {
                        amplitude: *a,
                        frequency_hz: *f,
                        phase: p.to_radians(),
                    })
                    .collect(),
            ),
            HistoryInput::Table { table, file } => {
                let rows = match (table, file) {
                    (Some(t), None) => t.clone(),
                    (None, Some(f)) => read_table(&base.join(f), &format!("{field}.history.file"))?,
                    _ => {
                        return Err(Error::invalid(
                            format!("{field}.history"),
                            "a table history needs either table = [[t, value], ...] or file = \"….csv\" / \"….npy\"",
                        ));
                    }
                };
                TimeHistory::Table {
                    times: rows.iter().map(|r| r[0]).collect(),
                    values: rows.iter().map(|r| r[1]).collect(),
                }
            }
        };
        history.validate(&format!("{field}.history"))?;
        Ok(history)
    }
}

/// Rows `[t, value]` of a CSV (comma, semicolon or blank separated; `#` comments and a header
/// line allowed) or a `.npy` (N × 2, float64) file. A row that is not two finite numbers, a
/// time that is not after the previous one, are errors naming the file and its line (the row
/// of a `.npy`).
fn read_table(path: &Path, field: &str) -> Result<Vec<[f64; 2]>> {
    let is_npy = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"));
    let at = |place: String, message: String| {
        Error::invalid(field, format!("{} {place}: {message}", path.display()))
    };
    // each row with where it is: "line n" of a CSV, "row n" of a .npy (from 1)
    let mut rows: Vec<([f64; 2], String)> = Vec::new();
    if is_npy {
        let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
        let a: ndarray::Array2<f64> = ndarray_npy::ReadNpyExt::read_npy(file).map_err(|e| {
            Error::invalid(
                field,
                format!("{}: {e} (expected an N × 2 float64 array)", path.display()),
            )
        })?;
        if a.ncols() != 2 {
            return Err(Error::invalid(
                field,
                format!(
                    "{}: has {} columns, expected 2 (t, value)",
                    path.display(),
                    a.ncols()
                ),
            ));
        }
        rows.extend(
            a.rows()
                .into_iter()
                .enumerate()
                .map(|(k, r)| ([r[0], r[1]], format!("row {}", k + 1))),
        );
    } else {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        for (k, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let cols: Vec<&str> = line
                .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
                .filter(|c| !c.is_empty())
                .collect();
            let parsed: Option<Vec<f64>> = cols.iter().map(|c| c.parse().ok()).collect();
            match parsed {
                Some(v) if v.len() == 2 => rows.push(([v[0], v[1]], format!("line {}", k + 1))),
                None if rows.is_empty() => continue, // a header line
                _ => {
                    return Err(at(
                        format!("line {}", k + 1),
                        format!("expected two numbers t, value (got '{line}')"),
                    ));
                }
            }
        }
    }
    if rows.len() < 2 {
        return Err(Error::invalid(
            field,
            format!(
                "{}: has {} row(s) of numbers: a table needs at least 2 rows t, value",
                path.display(),
                rows.len()
            ),
        ));
    }
    for (k, ([t, v], place)) in rows.iter().enumerate() {
        if !(t.is_finite() && v.is_finite()) {
            return Err(at(
                place.clone(),
                format!(
                    "t = {}, value = {}: both must be finite numbers",
                    number(*t),
                    number(*v)
                ),
            ));
        }
        if k > 0 && *t <= rows[k - 1].0[0] {
            return Err(at(
                place.clone(),
                format!(
                    "t = {} s is not after the previous time {} s: times must be strictly increasing",
                    number(*t),
                    number(rows[k - 1].0[0])
                ),
            ));
        }
    }
    Ok(rows.into_iter().map(|(r, _)| r).collect())
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct TangentialSection {
    #[serde(default)]
    method: MethodName,
    #[serde(default)]
    stick_velocity: StickVelocityName,
    penalty: Option<PenaltyInput>,
    #[serde(default)]
    gauss_seidel: GaussSeidelInput,
    #[serde(default)]
    active_set: ActiveSetInput,
}

#[derive(Debug, Default, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum MethodName {
    Penalty,
    ActiveSet,
    #[default]
    GaussSeidel,
}

#[derive(Debug, Default, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum StickVelocityName {
    #[default]
    HalfStep,
    FullStep,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PenaltyInput {
    stiffness: f64,
    #[serde(default)]
    damping: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct GaussSeidelInput {
    #[serde(default = "default_tolerance")]
    tolerance: f64,
    #[serde(default = "default_residual_tolerance")]
    residual_tolerance: f64,
    #[serde(default = "default_max_sweeps")]
    max_sweeps: usize,
    #[serde(default)]
    local_solve: LocalSolveName,
    #[serde(default = "yes")]
    warm_start: bool,
}

impl Default for GaussSeidelInput {
    fn default() -> Self {
        let d = GaussSeidelSettings::default();
        Self {
            tolerance: d.tolerance,
            residual_tolerance: d.residual_tolerance,
            max_sweeps: d.max_sweeps,
            local_solve: LocalSolveName::Exact,
            warm_start: d.warm_start,
        }
    }
}

fn default_tolerance() -> f64 {
    GaussSeidelSettings::default().tolerance
}
fn default_residual_tolerance() -> f64 {
    GaussSeidelSettings::default().residual_tolerance
}
fn default_max_sweeps() -> usize {
    GaussSeidelSettings::default().max_sweeps
}
fn yes() -> bool {
    true
}

#[derive(Debug, Default, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum LocalSolveName {
    #[default]
    Exact,
    Radial,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ActiveSetInput {
    #[serde(default = "default_max_iterations")]
    max_iterations: usize,
}

impl Default for ActiveSetInput {
    fn default() -> Self {
        Self {
            max_iterations: default_max_iterations(),
        }
    }
}

fn default_max_iterations() -> usize {
    ActiveSetSettings::default().max_iterations
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct OutputSection {
    #[serde(default = "one")]
    every: u64,
}

impl Default for OutputSection {
    fn default() -> Self {
        Self { every: 1 }
    }
}

fn one() -> u64 {
    1
}

fn v3(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

impl TubeInput {
    fn structure(&self) -> Result<TubeStructure> {
        let tube = Tube {
            section: TubeSection {
                outer_diameter: self.outer_diameter,
                wall_thickness: self.wall_thickness,
            },
            material: Material {
                young_modulus: self.young_modulus,
                poisson_ratio: self.poisson_ratio,
                density: self.density,
            },
            fluid: Fluid {
                inner_density: self.inner_fluid_density,
                outer_density: self.outer_fluid_density,
                added_mass_coefficient: self.added_mass_coefficient,
            },
            theory: match self.theory {
                TheoryName::EulerBernoulli => Theory::EulerBernoulli,
                TheoryName::Timoshenko => Theory::Timoshenko,
            },
        };
        tube.validate("structure")?;
        if !(self.mesh_size.is_finite() && self.mesh_size > 0.0) {
            return Err(Error::invalid(
                "structure.mesh_size",
                format!(
                    "must be a positive element length in m (got {})",
                    self.mesh_size
                ),
            ));
        }
        let mesh = match (&self.path, &self.u_bend) {
            (Some(path), None) => {
                let vertices: Vec<Vector3<f64>> = path.iter().map(|v| v3(*v)).collect();
                Mesh::polyline(&vertices, self.mesh_size)?
            }
            (None, Some(u)) => Mesh::u_bend(u.leg_length, u.radius, self.mesh_size)?,
            _ => {
                return Err(Error::invalid(
                    "structure",
                    "a tube needs either path = [[x, y, z], …] (straight segments) or u_bend = { leg_length, radius }",
                ));
            }
        };
        let tolerance = 1e-3 * self.mesh_size;
        let mut restraints = Vec::new();
        for (k, sup) in self.supports.iter().enumerate() {
            let field = format!("structure.supports[{k}]");
            let node = node_at(&mesh, &v3(sup.at), tolerance, &format!("{field}.at"))?;
            if !sup.fixed.is_empty() && !matches!(sup.kind, SupportKind::Dofs) {
                return Err(Error::invalid(
                    format!("{field}.fixed"),
                    "only type = \"dofs\" takes a list of fixed DOFs",
                ));
            }
            let r = match (sup.kind, sup.stiffness) {
                (SupportKind::Clamped, None) => clamped(),
                (SupportKind::Pinned, None) => pinned(),
                (SupportKind::Dofs, springs) => {
                    let mut r = match springs {
                        Some(k) => spring_restraints(&k, &field)?,
                        None => [Restraint::Free; 6],
                    };
                    for d in &sup.fixed {
                        r[*d as usize] = Restraint::Fixed;
                    }
                    r
                }
                (SupportKind::Springs, Some(k)) => spring_restraints(&k, &field)?,
                (SupportKind::Springs, None) => {
                    return Err(Error::invalid(
                        format!("{field}.stiffness"),
                        "type = \"springs\" needs stiffness = [kx, ky, kz, krx, kry, krz] (N/m, N·m/rad; 0 = free)",
                    ));
                }
                (_, Some(_)) => {
                    return Err(Error::invalid(
                        format!("{field}.stiffness"),
                        "only type = \"springs\" or \"dofs\" takes stiffnesses",
                    ));
                }
            };
            restraints.push((node, r));
        }
        let mut points = Vec::new();
        for (k, pt) in self.points.iter().enumerate() {
            let field = format!("structure.points[{k}]");
            let node = node_at(&mesh, &v3(pt.at), tolerance, &format!("{field}.at"))?;
            let offset = v3(pt.offset);
            if offset.iter().any(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    format!("{field}.offset"),
                    "must be 3 finite numbers",
                ));
            }
            points.push(NamedPoint {
                name: pt.name.clone(),
                node,
                offset,
            });
        }
        let selection = match (self.modes, self.max_frequency_hz) {
            (Some(n), None) if n > 0 => ModeSelection::Count(n),
            (None, Some(f)) if f.is_finite() && f > 0.0 => ModeSelection::BelowHz(f),
            _ => {
                return Err(Error::invalid(
                    "structure.modes",
                    "give either modes = N (the N lowest modes) or max_frequency_hz = F (every mode below F), N and F positive",
                ));
            }
        };
        let damping = match (&self.damping_ratio, &self.rayleigh) {
            (Some(DampingInput::Constant(x)), None) => {
                check_damping_ratio(*x, "structure.damping_ratio")?;
                Damping::Constant(*x)
            }
            (Some(DampingInput::PerMode(v)), None) => Damping::PerMode(v.clone()),
            (None, Some(r)) => {
                for (v, key, unit) in [(r.alpha, "alpha", "1/s"), (r.beta, "beta", "s")] {
                    if !(v.is_finite() && v >= 0.0) {
                        return Err(Error::invalid(
                            format!("structure.rayleigh.{key}"),
                            format!(
                                "must be a finite coefficient ≥ 0 in {unit} of C = αM + βK (got {})",
                                number(v)
                            ),
                        ));
                    }
                }
                Damping::Rayleigh {
                    alpha: r.alpha,
                    beta: r.beta,
                }
            }
            (None, None) => Damping::Constant(0.0),
            (Some(_), Some(_)) => {
                return Err(Error::invalid(
                    "structure.rayleigh",
                    "give either damping_ratio or rayleigh = { alpha, beta }, not both",
                ));
            }
        };
        Ok(TubeStructure {
            beam: BeamModel {
                mesh,
                tube,
                restraints,
            },
            points,
            selection,
            damping,
        })
    }
}

/// Refuses, before they are allocated, more analytic modes than the memory holds: the rows
/// of `points` points (3 per mode each) and the dense matrices of the stable time step.
fn check_mode_count(modes: usize, points: usize) -> Result<()> {
    let needed = crate::integrator::stability::memory_bytes(modes)
        + 8.0 * 3.0 * modes as f64 * points.max(1) as f64;
    let available = crate::structure::beam::available_memory();
    if needed > available {
        return Err(Error::invalid(
            "structure.modes_per_plane",
            format!(
                "gives {modes} modes, which would need {} of memory, more than the {} available: keep fewer modes",
                crate::structure::beam::gigabytes(needed),
                crate::structure::beam::gigabytes(available)
            ),
        ));
    }
    Ok(())
}

/// Grounded springs `[kx, ky, kz, krx, kry, krz]` (0 = free).
fn spring_restraints(k: &[f64; 6], field: &str) -> Result<[Restraint; 6]> {
    if let Some(v) = k.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(Error::invalid(
            format!("{field}.stiffness"),
            format!("spring stiffnesses must be ≥ 0 (got {v})"),
        ));
    }
    Ok(k.map(|v| {
        if v > 0.0 {
            Restraint::Spring(v)
        } else {
            Restraint::Free
        }
    }))
}

/// A tube case keeps its finite-element model and full modes (for `fretdyn modes`).
#[derive(Debug, Clone)]
pub struct TubeModel {
    /// The structure as described in the case.
    pub structure: TubeStructure,
    /// Its modes.
    pub basis: TubeBasis,
}

impl CaseFile {
    fn build(
        self,
        base: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<(Model, RunSettings, Option<Box<TubeModel>>)> {
        let (basis, tube) = self.structure.build(base, warnings)?;
        basis.validate("structure")?;
        let mut model = Model::new(basis);
        let point = |name: &str, field: String, model: &Model| {
            model.basis.point_index(name).ok_or_else(|| {
                let known: Vec<&str> = model.basis.points.iter().map(|p| p.name.as_str()).collect();
                Error::invalid(
                    field,
                    format!("unknown point '{name}': the structure has {known:?}"),
                )
            })
        };
        for (k, c) in self.contacts.iter().enumerate() {
            let field = format!("contacts[{k}]");
            let pt = point(&c.point, format!("{field}.point"), &model)?;
            let obstacle = match c.obstacle {
                ObstacleInput::Plane {
                    origin,
                    normal,
                    gap,
                    tangent,
                } => Obstacle::Plane(Plane::new(
                    v3(origin),
                    v3(normal),
                    gap,
                    tangent.map(v3),
                    &format!("{field}.obstacle"),
                )?),
                ObstacleInput::Circle {
                    centre,
                    axis,
                    clearance,
                } => Obstacle::Circle(Circle::new(
                    v3(centre),
                    v3(axis),
                    clearance,
                    &format!("{field}.obstacle"),
                )?),
                ObstacleInput::BiPlane {
                    origin,
                    normal,
                    gap,
                    tangent,
                } => Obstacle::BiPlane(BiPlane::new(
                    v3(origin),
                    v3(normal),
                    gap,
                    tangent.map(v3),
                    &format!("{field}.obstacle"),
                )?),
                ObstacleInput::Polygon {
                    centre,
                    axis,
                    reference,
                    ref vertices,
                    ref polar,
                } => {
                    let vertices = match (vertices, polar) {
                        (Some(v), None) => v.iter().map(|p| Vector2::new(p[0], p[1])).collect(),
                        (None, Some(p)) => Polygon::polar(
                            &p.iter()
                                .map(|p| (p[0].to_radians(), p[1]))
                                .collect::<Vec<_>>(),
                        ),
                        _ => {
                            return Err(Error::invalid(
                                format!("{field}.obstacle"),
                                "a polygonal hole needs either vertices ([x1, x2] pairs, m) or polar ([angle_deg, radius] pairs), not both",
                            ));
                        }
                    };
                    Obstacle::Polygon(Polygon::new(
                        v3(centre),
                        v3(axis),
                        reference.map(v3),
                        vertices,
                        &format!("{field}.obstacle"),
                    )?)
                }
            };
            let normal = NormalLaw::new(
                c.normal.stiffness,
                c.normal.damping,
                &format!("{field}.normal"),
            )?;
            let ff = format!("{field}.friction");
            let (mu_s, mu_d) = match (c.friction.mu, c.friction.mu_static, c.friction.mu_dynamic) {
                (Some(mu), None, None) => (mu, mu),
                (None, Some(s), Some(d)) => (s, d),
                (None, Some(s), None) => (s, s),
                (None, None, Some(d)) => (d, d),
                _ => {
                    return Err(Error::invalid(
                        ff,
                        "give either mu, or mu_static and mu_dynamic",
                    ));
                }
            };
            // errors name the key written: `mu` stands for both coefficients, and a lone
            // `mu_static` (or `mu_dynamic`) for the other one too
            let written = match (c.friction.mu, c.friction.mu_static, c.friction.mu_dynamic) {
                (Some(_), _, _) => Some("mu"),
                (None, Some(_), None) => Some("mu_static"),
                (None, None, Some(_)) => Some("mu_dynamic"),
                _ => None,
            };
            let friction = Coulomb::new(mu_s, mu_d, &ff).map_err(|e| match (e, written) {
                (Error::Invalid { message, .. }, Some(key)) => {
                    Error::invalid(format!("{ff}.{key}"), message)
                }
                (e, _) => e,
            })?;
            let name = c.name.clone().unwrap_or_else(|| format!("contact{k}"));
            if let Some(j) = model.contacts.iter().position(|o| o.name == name) {
                return Err(Error::invalid(
                    format!("{field}.name"),
                    format!(
                        "'{name}' is already the name of contacts[{j}]: contact names must be unique (they label the outputs)"
                    ),
                ));
            }
            if let (Some(t), true) = (tube.as_deref(), c.radius > 0.0) {
                let outer = 0.5 * t.structure.beam.tube.section.outer_diameter;
                if c.radius > outer * (1.0 + 1e-9) {
                    return Err(Error::invalid(
                        format!("{field}.radius"),
                        format!(
                            "{} m is larger than the tube's outer radius {} m (structure.outer_diameter/2): give the outer radius in m",
                            number(c.radius),
                            number(outer)
                        ),
                    ));
                }
            }
            let mut contact = Contact::new(name, pt, obstacle, normal, friction);
            contact.radius = c.radius;
            if let Some(m) = &c.motion {
                contact.motion = m.motion();
            }
            contact.validate(&model.basis.points[pt], &field)?;
            model.contacts.push(contact);
        }
        for (k, l) in self.loads.iter().enumerate() {
            let field = format!("loads[{k}]");
            let pt = point(&l.point, format!("{field}.point"), &model)?;
            let history = l.history.history(base, &field)?;
            model
                .loads
                .push(PointLoad::new(pt, v3(l.force), history, &field)?);
        }
        let modes = model.basis.modes();
        for (k, l) in self.modal_loads.iter().enumerate() {
            let field = format!("modal_loads[{k}]");
            let history = l.history.history(base, &field)?;
            model
                .modal_loads
                .push(ModalLoad::new(l.force.clone(), history, modes, &field)?);
        }
        let tube_of = |field: &str| {
            tube.as_deref().ok_or_else(|| {
                Error::invalid(
                    field.to_string(),
                    "needs a structure of type = \"tube\" (a line along which to spread it); on another structure give point loads or modal_loads",
                )
            })
        };
        let span_of = |span: Option<[f64; 2]>, t: &TubeModel, field: &str| {
            let length = t.structure.length();
            let [s0, s1] = span.unwrap_or([0.0, length]);
            if !(s0.is_finite()
                && s1.is_finite()
                && 0.0 <= s0
                && s0 < s1
                && s1 <= length * (1.0 + 1e-12))
            {
                return Err(Error::invalid(
                    format!("{field}.span"),
                    format!(
                        "must be [s0, s1] with 0 ≤ s0 < s1 ≤ {length} m (the tube's length along its axis)"
                    ),
                ));
            }
            Ok((s0, s1))
        };
        for (k, l) in self.line_loads.iter().enumerate() {
            let field = format!("line_loads[{k}]");
            let t = tube_of(&field)?;
            let (s0, s1) = span_of(l.span, t, &field)?;
            let f = v3(l.force_per_length);
            if f.iter().any(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    format!("{field}.force_per_length"),
                    "must be 3 finite numbers, in N/m",
                ));
            }
            let mut row = vec![0.0; modes];
            for node in t.structure.line_nodes(&t.basis, s0, s1) {
                crate::structure::modal::project_add(&node.rows, &(f * node.weight), &mut row);
            }
            let history = l.history.history(base, &field)?;
            model
                .modal_loads
                .push(ModalLoad::new(row, history, modes, &field)?);
        }
        for (k, l) in self.turbulence.iter().enumerate() {
            let field = format!("turbulence[{k}]");
            let t = tube_of(&field)?;
            let (s0, s1) = span_of(l.span, t, &field)?;
            let spectrum = l
                .spectrum
                .spectrum(t.structure.beam.tube.section.outer_diameter);
            let nodes = t.structure.line_nodes(&t.basis, s0, s1);
            let (_, cells) = t.structure.line_cells(s0, s1);
            let factor = line_covariance(nodes.len(), &cells, l.correlation_length)
                .and_then(|c| covariance_factor(c, l.tolerance))
                .map_err(|e| match e {
                    Error::Invalid { field: f, message } => {
                        Error::invalid(format!("{field}.{f}"), message)
                    }
                    other => other,
                })?;
            if l.directions.is_empty() {
                return Err(Error::invalid(
                    format!("{field}.directions"),
                    "give at least one direction of the force, e.g. [[0, 1, 0], [0, 0, 1]]",
                ));
            }
            let mut rows = Vec::new();
            for (d, dir) in l.directions.iter().enumerate() {
                let e = v3(*dir);
                let norm = e.norm();
                if !(norm.is_finite() && norm > 0.0) {
                    return Err(Error::invalid(
                        format!("{field}.directions[{d}]"),
                        "must be a non-zero finite vector",
                    ));
                }
                let e = e / norm;
                for j in 0..factor.ncols() {
                    let mut row = vec![0.0; modes];
                    for (i, node) in nodes.iter().enumerate() {
                        crate::structure::modal::project_add(
                            &node.rows,
                            &(e * factor[(i, j)]),
                            &mut row,
                        );
                    }
                    rows.extend(row);
                }
            }
            let load = TurbulentLoad {
                spectrum,
                rows,
                seed: l.seed,
                f_max: l.f_max,
            };
            load.validate(modes, &field)?;
            model.turbulence.push(load);
        }
        if let Some(b) = &self.base_excitation {
            model.base_acceleration = Some(BaseAcceleration::new(
                v3(b.acceleration),
                b.history.history(base, "base_excitation")?,
                "base_excitation",
            )?);
        }
        if let Some(init) = &self.initial {
            let p = model.basis.modes();
            match (&init.point, &init.q, &init.qdot) {
                (Some(name), None, None) => {
                    let pt = point(name, "initial.point".into(), &model)?;
                    for (key, v, unit) in [
                        ("displacement", init.displacement, "m"),
                        ("velocity", init.velocity, "m/s"),
                    ] {
                        if let Some(v) = v.filter(|v| v.iter().any(|x| !x.is_finite())) {
                            return Err(Error::invalid(
                                format!("initial.{key}"),
                                format!(
                                    "must be 3 finite numbers [x, y, z] in {unit} (got [{}, {}, {}])",
                                    v[0], v[1], v[2]
                                ),
                            ));
                        }
                    }
                    model.set_initial_from_point(
                        pt,
                        v3(init.displacement.unwrap_or_default()),
                        v3(init.velocity.unwrap_or_default()),
                    )?;
                }
                (None, q, qd) if init.displacement.is_none() && init.velocity.is_none() => {
                    model.initial.q = q.clone().unwrap_or_else(|| vec![0.0; p]);
                    model.initial.qdot = qd.clone().unwrap_or_else(|| vec![0.0; p]);
                }
                _ => {
                    return Err(Error::invalid(
                        "initial",
                        "give either point with displacement/velocity, or q/qdot (modal), not both",
                    ));
                }
            }
        }
        model.validate()?;

        let t = &self.tangential;
        let method = match t.method {
            MethodName::Penalty => {
                let p = t.penalty.as_ref().ok_or_else(|| {
                    Error::invalid(
                        "tangential.penalty",
                        "method = \"penalty\" needs [tangential.penalty] with stiffness (K_T, N/m) and damping (C_T, N·s/m)",
                    )
                })?;
                TangentialMethod::Penalty(PenaltySettings {
                    stiffness: p.stiffness,
                    damping: p.damping,
                })
            }
            MethodName::GaussSeidel => TangentialMethod::GaussSeidel(t.gauss_seidel.settings()),
            MethodName::ActiveSet => TangentialMethod::ActiveSet(ActiveSetSettings {
                max_iterations: t.active_set.max_iterations,
                fallback: t.gauss_seidel.settings(),
            }),
        };
        let dt = self.time.dt;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::invalid(
                "time.dt",
                format!("must be a positive time step in s (got {dt})"),
            ));
        }
        let duration = self.time.duration;
        if !(duration.is_finite() && duration > 0.0) {
            return Err(Error::invalid(
                "time.duration",
                format!("must be a positive duration in s (got {duration})"),
            ));
        }
        if duration < dt * (1.0 - 1e-9) {
            return Err(Error::invalid(
                "time.duration",
                format!(
                    "{} s is shorter than one step (time.dt = {} s): the run would do no step; set duration ≥ dt",
                    number(duration),
                    number(dt)
                ),
            ));
        }
        let statistics = &self.statistics;
        // a step counts in the window when its middle is after t_start (THEORY §5): the last
        // step's middle is half a step before the end
        let last_middle = ((duration / dt).round() - 0.5) * dt;
        if statistics.t_start >= last_middle {
            return Err(Error::invalid(
                "statistics.t_start",
                format!(
                    "{} s is not before the end of the run (time.duration = {} s): the statistics window would hold no step; set t_start < duration",
                    number(statistics.t_start),
                    number(duration)
                ),
            ));
        }
        if let Some(block) = statistics
            .block
            .filter(|b| *b > 0.0 && *b < dt * (1.0 - 1e-9))
        {
            return Err(Error::invalid(
                "statistics.block",
                format!(
                    "{} s is shorter than one step (time.dt = {} s): a block holds whole steps; set block ≥ dt (e.g. a tenth of the window)",
                    number(block),
                    number(dt)
                ),
            ));
        }
        let steps = (duration / dt).round();
        if steps > 1e12 {
            return Err(Error::invalid(
                "time.duration",
                format!("gives {steps:e} steps of {dt} s: more than 1e12 steps"),
            ));
        }
        let settings = RunSettings {
            dt,
            steps: steps as u64,
            method,
            stick_velocity: match t.stick_velocity {
                StickVelocityName::HalfStep => StickVelocity::HalfStep,
                StickVelocityName::FullStep => StickVelocity::FullStep,
            },
            output_every: self.output.every,
            statistics: StatisticsSettings {
                t_start: self.statistics.t_start,
                t_end: self.statistics.t_end.unwrap_or(f64::INFINITY),
                block: self.statistics.block,
                rest_duration: self.statistics.rest_duration,
                wear_coefficient: self.statistics.wear_coefficient,
            },
        };
        settings.validate()?;
        // a model without a usable stable time step (a unit slip: a mass of 1e-320 kg, a
        // radius of 1e200 m) is refused here, naming its cause; a Δt above a usable limit is
        // left to the run, which says the limit
        let stable_dt = checked_stable_time_step(&model, &settings.method)?;
        if duration / stable_dt > 1e12 {
            return Err(Error::invalid(
                "time.dt",
                format!(
                    "the stable limit of central differences is {stable_dt:.3e} s (a highest frequency of about {:.3e} Hz, docs/THEORY.md §2): {} s would take more than 1e12 steps; check the units of the structure (masses, densities, sizes, Young's modulus) and of the contact stiffnesses",
                    2.0 / (std::f64::consts::TAU * stable_dt),
                    number(duration)
                ),
            ));
        }
        Ok((model, settings, tube))
    }
}

impl GaussSeidelInput {
    fn settings(&self) -> GaussSeidelSettings {
        GaussSeidelSettings {
            tolerance: self.tolerance,
            residual_tolerance: self.residual_tolerance,
            max_sweeps: self.max_sweeps,
            local_solve: match self.local_solve {
                LocalSolveName::Exact => LocalSolve::Exact,
                LocalSolveName::Radial => LocalSolve::Radial,
            },
            warm_start: self.warm_start,
        }
    }
}

impl StructureSection {
    fn build(
        &self,
        base: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<(ModalBasis, Option<Box<TubeModel>>)> {
        if let StructureSection::Tube(t) = self {
            let structure = t.structure()?;
            let basis = structure.modal_basis()?;
            return Ok((
                basis.basis.clone(),
                Some(Box::new(TubeModel { structure, basis })),
            ));
        }
        self.build_basis(base, warnings).map(|b| (b, None))
    }

    fn build_basis(&self, base: &Path, warnings: &mut Vec<String>) -> Result<ModalBasis> {
        match self {
            StructureSection::Tube(_) => unreachable!("handled by build"),
            StructureSection::PointMass {
                mass,
                point,
                position,
            } => ModalBasis::point_mass(*mass, point, v3(*position)),
            StructureSection::PinnedBeam {
                length,
                bending_stiffness,
                mass_per_length,
                modes_per_plane,
                axial_stiffness,
                axial_modes,
                damping_ratio,
                points,
            } => check_damping_ratio(*damping_ratio, "structure.damping_ratio")
                .and_then(|_| {
                    check_mode_count(
                        modes_per_plane
                            .saturating_mul(2)
                            .saturating_add(*axial_modes),
                        points.len(),
                    )
                })
                .and_then(|_| {
                    ModalBasis::pinned_beam(
                        &PinnedBeam {
                            length: *length,
                            bending_stiffness: *bending_stiffness,
                            mass_per_length: *mass_per_length,
                            modes_per_plane: *modes_per_plane,
                            axial_stiffness: *axial_stiffness,
                            axial_modes: *axial_modes,
                            damping_ratio: *damping_ratio,
                        },
                        &points
                            .iter()
                            .map(|s| (s.name.clone(), s.x))
                            .collect::<Vec<_>>(),
                    )
                }),
            StructureSection::Modal {
                frequencies_hz,
                damping_ratio,
                file,
                points,
                participation,
            } => {
                let mut basis = match (file, frequencies_hz) {
                    (Some(f), None) => {
                        let file = crate::structure::basis_file::read_basis_npz(&base.join(f))?;
                        warnings.extend(file.warnings);
                        file.basis
                    }
                    (None, Some(freq)) => ModalBasis {
                        omega: freq.iter().map(|f| f * std::f64::consts::TAU).collect(),
                        damping_ratio: vec![0.0; freq.len()],
                        points: Vec::new(),
                        participation: Vec::new(),
                    },
                    _ => {
                        return Err(Error::invalid(
                            "structure",
                            "a modal structure needs either frequencies_hz (inline) or file (a .npz basis), not both",
                        ));
                    }
                };
                let p = basis.modes();
                match damping_ratio {
                    Some(DampingInput::Constant(x)) => {
                        check_damping_ratio(*x, "structure.damping_ratio")?;
                        basis.damping_ratio = vec![*x; p]
                    }
                    Some(DampingInput::PerMode(v)) => basis.damping_ratio = v.clone(),
                    None => {}
                }
                for (j, pt) in points.iter().enumerate() {
                    if !(pt.rotations.is_empty()
                        || pt.rotations.len() == 3 && pt.rotations.iter().all(|r| r.len() == p))
                    {
                        return Err(Error::invalid(
                            format!("structure.points[{j}].rotations"),
                            format!(
                                "must be 3 rows (θx, θy, θz) of {p} values each, one value per mode"
                            ),
                        ));
                    }
                    if pt.rows.len() != 3 || pt.rows.iter().any(|r| r.len() != p) {
                        return Err(Error::invalid(
                            format!("structure.points[{j}].rows"),
                            format!(
                                "must be 3 rows (x, y, z) of {p} values each, one value per mode"
                            ),
                        ));
                    }
                    basis.points.push(Point {
                        name: pt.name.clone(),
                        coords: v3(pt.coords),
                        rows: pt.rows.concat(),
                        rotations: pt.rotations.concat(),
                    });
                }
                if let Some(g) = participation {
                    if g.len() != 3 || g.iter().any(|r| r.len() != p) {
                        return Err(Error::invalid(
                            "structure.participation",
                            format!("must be 3 rows (x, y, z) of {p} values Φᵀ M r, one per mode"),
                        ));
                    }
                    basis.participation = g.concat();
                }
                Ok(basis)
            }
        }
    }
}
