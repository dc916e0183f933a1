//! `wear = { tube = …, support = …, scar = … }` of a `[[contacts]]` entry: the wear law of
//! each body and the scar geometry (`docs/WEAR.md`, THEORY §14).

use serde::Deserialize;

use super::obstacle::ObstacleInput;
use crate::error::{Error, Result, number};
use crate::wear::{ContactWear, HoleScar, Scar, WearLaw, WearWork};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct WearInput {
    /// The work the laws take: "friction" (default) or "normal".
    #[serde(default)]
    work: WorkInput,
    tube: LawInput,
    support: LawInput,
    scar: ScarInput,
}

#[derive(Debug, Deserialize)]
#[serde(tag = "law", rename_all = "snake_case", deny_unknown_fields)]
enum LawInput {
    Archard {
        coefficient: f64,
    },
    Decaying {
        a: f64,
        b: f64,
        s: f64,
        n: f64,
    },
    Table {
        work_rate: Vec<f64>,
        volume_rate: Vec<f64>,
    },
}

#[derive(Debug, Deserialize, Clone, Copy, Default)]
#[serde(rename_all = "snake_case")]
enum WorkInput {
    #[default]
    Friction,
    Normal,
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum ShapeInput {
    Crescent,
    Uniform,
}

#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
enum ScarInput {
    FlatBar {
        width: f64,
        #[serde(default)]
        tilt_deg: f64,
        tube_radius: Option<f64>,
    },
    DrilledHole {
        thickness: f64,
        shape: ShapeInput,
        tube_radius: Option<f64>,
    },
    BroachedHole {
        thickness: f64,
        lobes: u32,
        land_width: Option<f64>,
        tube_radius: Option<f64>,
    },
    Tube {
        other_radius: f64,
        crossing_deg: f64,
        length: Option<f64>,
        tube_radius: Option<f64>,
    },
}

impl LawInput {
    fn law(&self) -> WearLaw {
        match self {
            LawInput::Archard { coefficient } => WearLaw::Archard {
                coefficient: *coefficient,
            },
            LawInput::Decaying { a, b, s, n } => WearLaw::Decaying {
                a: *a,
                b: *b,
                s: *s,
                n: *n,
            },
            LawInput::Table {
                work_rate,
                volume_rate,
            } => WearLaw::Table {
                work_rate: work_rate.clone(),
                volume_rate: volume_rate.clone(),
            },
        }
    }
}

impl WearInput {
    /// The contact's wear: `radius` is the contact's `radius` key (0 if absent), `obstacle`
    /// its obstacle (the scar must suit it; a drilled hole takes its clearance), `field` the
    /// contact (`contacts[k]`).
    pub(super) fn build(
        &self,
        radius: f64,
        obstacle: &ObstacleInput,
        field: &str,
    ) -> Result<ContactWear> {
        let field = format!("{field}.wear");
        let sf = format!("{field}.scar");
        let (kind, written) = match self.scar {
            ScarInput::FlatBar { tube_radius, .. } => ("flat_bar", tube_radius),
            ScarInput::DrilledHole { tube_radius, .. } => ("drilled_hole", tube_radius),
            ScarInput::BroachedHole { tube_radius, .. } => ("broached_hole", tube_radius),
            ScarInput::Tube { tube_radius, .. } => ("tube", tube_radius),
        };
        let suits = matches!(
            (&self.scar, obstacle),
            (
                ScarInput::FlatBar { .. } | ScarInput::Tube { .. },
                ObstacleInput::Plane { .. } | ObstacleInput::BiPlane { .. },
            ) | (ScarInput::Tube { .. }, ObstacleInput::Cylinder { .. })
                | (ScarInput::DrilledHole { .. }, ObstacleInput::Circle { .. })
                | (
                    ScarInput::BroachedHole { .. },
                    ObstacleInput::Polygon { .. }
                )
        );
        if !suits {
            let needs = match self.scar {
                ScarInput::FlatBar { .. } => "a plane or bi_plane",
                ScarInput::Tube { .. } => "a plane, bi_plane or cylinder",
                ScarInput::DrilledHole { .. } => "a circle",
                ScarInput::BroachedHole { .. } => "a polygon",
            };
            return Err(Error::invalid(
                format!("{sf}.type"),
                format!(
                    "a '{kind}' scar needs {needs} obstacle, this contact's obstacle is a {}: give the scar type of the support (flat_bar or tube for planes, tube for a cylinder, drilled_hole for a circle, broached_hole for a polygon)",
                    obstacle_name(obstacle)
                ),
            ));
        }
        let tube_radius = match (radius > 0.0, written) {
            (true, None) => radius,
            (true, Some(r)) if r == radius => radius,
            (true, Some(r)) => {
                return Err(Error::invalid(
                    format!("{sf}.tube_radius"),
                    format!(
                        "{} m differs from the contact's radius {} m: give the tube's outer radius once",
                        number(r),
                        number(radius)
                    ),
                ));
            }
            (false, Some(r)) => r,
            (false, None) => {
                return Err(Error::invalid(
                    format!("{sf}.tube_radius"),
                    "the scar needs the tube's outer radius: give the contact's radius (m) or scar.tube_radius",
                ));
            }
        };
        let scar = match self.scar {
            ScarInput::FlatBar {
                width, tilt_deg, ..
            } => Scar::FlatBar {
                tube_radius,
                width,
                tilt: tilt_deg.to_radians(),
            },
            ScarInput::DrilledHole {
                thickness, shape, ..
            } => {
                let ObstacleInput::Circle { clearance, .. } = *obstacle else {
                    unreachable!("checked above: a drilled hole has a circle obstacle")
                };
                Scar::DrilledHole {
                    tube_radius,
                    thickness,
                    clearance,
                    shape: match shape {
                        ShapeInput::Crescent => HoleScar::Crescent,
                        ShapeInput::Uniform => HoleScar::Uniform,
                    },
                }
            }
            ScarInput::BroachedHole {
                thickness,
                lobes,
                land_width,
                ..
            } => Scar::BroachedHole {
                tube_radius,
                thickness,
                lobes,
                land_width,
            },
            ScarInput::Tube {
                other_radius,
                crossing_deg,
                length,
                ..
            } => Scar::Tube {
                tube_radius,
                other_radius,
                crossing: crossing_deg.to_radians(),
                length,
            },
        };
        let wear = ContactWear {
            tube: self.tube.law(),
            support: self.support.law(),
            scar,
            work: match self.work {
                WorkInput::Friction => WearWork::Friction,
                WorkInput::Normal => WearWork::Normal,
            },
        };
        wear.validate(&field)?;
        Ok(wear)
    }
}

fn obstacle_name(o: &ObstacleInput) -> &'static str {
    match o {
        ObstacleInput::Plane { .. } => "plane",
        ObstacleInput::Circle { .. } => "circle",
        ObstacleInput::BiPlane { .. } => "bi_plane",
        ObstacleInput::Polygon { .. } => "polygon",
        ObstacleInput::Cylinder { .. } => "cylinder",
    }
}
