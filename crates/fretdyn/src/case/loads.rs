//! `[[loads]]`, `[[modal_loads]]`, `[[line_loads]]`, `[[turbulence]]`, `[base_excitation]`:
//! histories (inline or tables read from files) and their projection on the modes
//! (THEORY §8, §10).

use std::path::Path;

use serde::Deserialize;

use super::shared::{TubeModel, named_file, point_index, v3};
use crate::error::{Error, Result, number};
use crate::loads::flow::{Flow, FlowZone};
use crate::loads::spatial_correlation::{covariance_factor, line_covariance};
use crate::loads::turbulence::Spectrum;
use crate::loads::{BaseAcceleration, ModalLoad, PointLoad, Sine, TimeHistory, TurbulentLoad};
use crate::model::Model;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LoadSection {
    point: String,
    force: [f64; 3],
    #[serde(default)]
    history: HistoryInput,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BaseSection {
    acceleration: [f64; 3],
    #[serde(default)]
    history: HistoryInput,
}

/// `[[line_loads]]`: a uniform force per unit length on an arc-length span of a tube.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LineLoadSection {
    /// `[s0, s1]`, m along the tube from its first point (default: the whole tube).
    span: Option<[f64; 2]>,
    force_per_length: [f64; 3],
    #[serde(default)]
    history: HistoryInput,
}

/// `[[modal_loads]]`: a generalized force given on the modes.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ModalLoadSection {
    force: Vec<f64>,
    #[serde(default)]
    history: HistoryInput,
}

/// `[[turbulence]]`: random turbulence along a span of a tube (docs/LOADS.md).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TurbulenceSection {
    span: Option<[f64; 2]>,
    /// A `[[flow.zones]]` name: the span is the zone's, and a cross-flow spectrum takes the
    /// velocity and density it does not give from the zone (docs/FLOW.md).
    zone: Option<String>,
    /// Directions of the force (each gets independent signals), e.g. the two transverse axes.
    directions: Vec<[f64; 3]>,
    /// Correlation length λ of `exp(−|Δs|/λ)`, m (`inf`: fully correlated).
    correlation_length: f64,
    /// Default: [`default_seed`] of the structure's index and the entry's.
    seed: Option<u64>,
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
pub(super) enum SpectrumInput {
    /// One-sided PSD of the force per unit length, (N/m)²/Hz.
    Table {
        frequency_hz: Vec<f64>,
        psd: Vec<f64>,
    },
    /// Code_Aster's SPEC_LONG_COR_2 cross-flow spectrum (docs/LOADS.md).
    CrossFlow {
        /// Default: the zone's (constant) gap velocity.
        velocity: Option<f64>,
        /// Default: the zone's density.
        density: Option<f64>,
        /// Default: the tube's outer diameter.
        diameter: Option<f64>,
        phi0: Option<f64>,
        beta: Option<f64>,
        reduced_cutoff: Option<f64>,
    },
}

impl SpectrumInput {
    /// The spectrum; a cross-flow spectrum takes the velocity and density it does not give
    /// from `zone` (its gap velocity, which must then be constant, and its density).
    fn spectrum(
        &self,
        tube_diameter: f64,
        zone: Option<&FlowZone>,
        field: &str,
    ) -> Result<Spectrum> {
        Ok(match self {
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
                let velocity = match (velocity, zone) {
                    (Some(v), _) => *v,
                    (None, Some(z)) => z.velocity.constant().ok_or_else(|| {
                        Error::invalid(
                            format!("{field}.spectrum.velocity"),
                            format!(
                                "zone '{}' has a velocity profile, and the cross-flow spectrum needs one velocity: give spectrum.velocity (m/s), or split the zone into zones of constant velocity",
                                z.name
                            ),
                        )
                    })?,
                    (None, None) => {
                        return Err(Error::invalid(
                            format!("{field}.spectrum.velocity"),
                            "give the cross-flow velocity in m/s, or zone = \"<name>\" to take it from a [[flow.zones]]",
                        ));
                    }
                };
                let density = match (density, zone) {
                    (Some(v), _) => *v,
                    (None, Some(z)) => z.density,
                    (None, None) => {
                        return Err(Error::invalid(
                            format!("{field}.spectrum.density"),
                            "give the fluid density in kg/m³, or zone = \"<name>\" to take it from a [[flow.zones]]",
                        ));
                    }
                };
                let (velocity, density) = (&velocity, &density);
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
        })
    }
}

#[derive(Debug, Default, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub(super) enum HistoryInput {
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
                    (None, Some(f)) => {
                        let key = format!("{field}.history.file");
                        read_table(&named_file(base, f, &key, "the case file")?, &key)?
                    }
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

/// Refuses a band limit above the Nyquist frequency `1/(2Δt)` of the time step (when Δt is
/// a valid step; its own errors come first). The signals are read once a step: power above
/// `1/(2Δt)` would fold into the band below it, and the generator would compute thousands of
/// samples per step (a run of hours for `f_max = 1e9` Hz at Δt = 1e-5 s). It is refused rather
/// than capped: a cap would change the load (its variance `∫₀^{f_max} S df`) without the case
/// saying so, and a study varying `time.dt` would vary the load with it.
fn check_band_limit(f_max: f64, dt: f64, field: &str) -> Result<()> {
    if !(dt.is_finite() && dt > 0.0) {
        return Ok(());
    }
    let nyquist = 0.5 / dt;
    // (0.5 / 1e-5 is 49999.999999999993: the Nyquist frequency as written is allowed)
    if f_max > nyquist * (1.0 + 1e-12) {
        return Err(Error::invalid(
            format!("{field}.f_max"),
            format!(
                "{} Hz is above the Nyquist frequency 1/(2 time.dt) = {} Hz of the time step (time.dt = {} s): the forces are sampled once a step, so they cannot carry power above it; set f_max ≤ {} Hz (a few times the highest frequency of interest is enough), or a smaller time.dt",
                number(f_max),
                number(nyquist),
                number(dt),
                number(nyquist)
            ),
        ));
    }
    Ok(())
}

/// The load sections of a case file, and its time step (the band limit of turbulence).
pub(super) struct LoadSections<'a> {
    pub loads: &'a [LoadSection],
    pub modal_loads: &'a [ModalLoadSection],
    pub line_loads: &'a [LineLoadSection],
    pub turbulence: &'a [TurbulenceSection],
    pub base_excitation: Option<&'a BaseSection>,
    pub dt: f64,
    /// The structure's index in the case (0 for a one-structure case): the default seeds.
    pub structure: usize,
}

/// The seed of `[[turbulence]]` entry `k` of structure `structure` (0 for a one-structure
/// case, `i` for `structures[i]`) that gives none: `1000·structure + k`. Entries, and the same
/// entry of two identical structures, get distinct seeds, hence independent signals (two
/// neighbouring tubes with one seed would see the same turbulence, fully correlated); an
/// explicit `seed` is kept as written.
pub(super) fn default_seed(structure: usize, k: usize) -> u64 {
    1000 * structure as u64 + k as u64
}

impl LoadSections<'_> {
    /// `[[loads]]`, `[[modal_loads]]`, `[[line_loads]]`, `[[turbulence]]` and
    /// `[base_excitation]`, projected on the modes (THEORY §8, §10).
    pub(super) fn build(
        &self,
        base: &Path,
        tube: Option<&TubeModel>,
        flow: Option<&Flow>,
        model: &mut Model,
    ) -> Result<()> {
        for (k, l) in self.loads.iter().enumerate() {
            let field = format!("loads[{k}]");
            let pt = point_index(&l.point, format!("{field}.point"), model)?;
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
            tube.ok_or_else(|| {
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
                        "must be [s0, s1] with 0 ≤ s0 < s1 ≤ {} m (the tube's length along its axis)",
                        number(length)
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
            let zone = match &l.zone {
                None => None,
                Some(name) => {
                    let names = || -> Vec<&str> {
                        flow.map_or(Vec::new(), |f| {
                            f.zones.iter().map(|z| z.name.as_str()).collect()
                        })
                    };
                    let zone = flow.and_then(|f| f.zone(name)).ok_or_else(|| {
                        Error::invalid(
                            format!("{field}.zone"),
                            format!(
                                "unknown zone '{name}': the [[flow.zones]] are {:?}",
                                names()
                            ),
                        )
                    })?;
                    if l.span.is_some() {
                        return Err(Error::invalid(
                            format!("{field}.span"),
                            "give either span or zone (whose span it takes), not both",
                        ));
                    }
                    Some(zone)
                }
            };
            let (s0, s1) = match zone {
                Some(z) => (z.span[0], z.span[1]),
                None => span_of(l.span, t, &field)?,
            };
            let spectrum =
                l.spectrum
                    .spectrum(t.structure.beam.tube.section.outer_diameter, zone, &field)?;
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
                seed: l.seed.unwrap_or(default_seed(self.structure, k)),
                f_max: l.f_max,
            };
            load.validate(modes, &field)?;
            check_band_limit(l.f_max, self.dt, &field)?;
            model.turbulence.push(load);
        }
        if let Some(b) = self.base_excitation {
            model.base_acceleration = Some(BaseAcceleration::new(
                v3(b.acceleration),
                b.history.history(base, "base_excitation")?,
                "base_excitation",
            )?);
        }
        Ok(())
    }
}
