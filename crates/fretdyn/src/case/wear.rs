//! `wear = { tube = …, support = …, scar = … }` of a `[[contacts]]` entry: the wear law of
//! each body and the scar geometry (`docs/WEAR.md`, THEORY §14).

use serde::Deserialize;

use super::obstacle::ObstacleInput;
use crate::contact::flat_bar::FlatBar;
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
        /// Required unless the contact gives the bar's `width` (then equal to it).
        width: Option<f64>,
        /// 0 by default, or the contact's `twist_deg` (then equal to its magnitude).
        tilt_deg: Option<f64>,
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
        /// Required for a contact with an obstacle; a two-body contact's defaults to the
        /// radius of its side B.
        other_radius: Option<f64>,
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
    /// The contact's wear: `radius` is the contact's `radius` key (0 if absent), `bar` its
    /// flat bar if it gives a width (a `flat_bar` scar takes its width and its twist as the
    /// tilt), `obstacle` its obstacle (the scar must suit it; a drilled hole takes its
    /// clearance), `field` the contact (`contacts[k]`).
    pub(super) fn build(
        &self,
        radius: f64,
        bar: Option<&FlatBar>,
        obstacle: &ObstacleInput,
        field: &str,
    ) -> Result<ContactWear> {
        self.build_for(radius, None, bar, obstacle, field)
    }

    /// The wear of a two-body contact (THEORY §15, [`ContactWear`]): `tube` is the law of
    /// body A (the contact's point), `support` the law of body B (its other point), the scar
    /// A's against B; `radii = [R_A, R_B]` are the pair's surface radii (0 if absent), the
    /// tube's radius `R_A` (or `scar.tube_radius`) and, for a `tube` scar, the other tube's
    /// `R_B` (or `scar.other_radius`; both given must agree); `obstacle` the pair's relative
    /// obstacle, `field` the contact. A tube against a flat bar has the tube as body A.
    pub(super) fn build_pair(
        &self,
        radii: [f64; 2],
        obstacle: &ObstacleInput,
        field: &str,
    ) -> Result<ContactWear> {
        self.build_for(radii[0], Some(radii[1]), None, obstacle, field)
    }

    /// [`Self::build`] with `other`, side B's radius of a two-body contact (`None` for a
    /// contact with an obstacle).
    fn build_for(
        &self,
        radius: f64,
        other: Option<f64>,
        bar: Option<&FlatBar>,
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
        let side_a = if other.is_some() { " of side A" } else { "" };
        let tube_radius = match (radius > 0.0, written) {
            (true, None) => radius,
            (true, Some(r)) if r == radius => radius,
            (true, Some(r)) => {
                return Err(Error::invalid(
                    format!("{sf}.tube_radius"),
                    format!(
                        "{} m differs from the contact's radius{side_a} {} m: give the tube's outer radius once",
                        number(r),
                        number(radius)
                    ),
                ));
            }
            (false, Some(r)) => r,
            (false, None) => {
                return Err(Error::invalid(
                    format!("{sf}.tube_radius"),
                    format!(
                        "the scar needs the tube's outer radius: give the contact's radius{side_a} (m) or scar.tube_radius"
                    ),
                ));
            }
        };
        let scar = match self.scar {
            ScarInput::FlatBar {
                width, tilt_deg, ..
            } => {
                let (width, tilt) = flat_bar_scar(width, tilt_deg, bar, &sf)?;
                Scar::FlatBar {
                    tube_radius,
                    width,
                    tilt,
                }
            }
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
                other_radius: match (other.filter(|r| *r > 0.0), other_radius) {
                    (None, Some(r)) => r,
                    (Some(b), None) => b,
                    (Some(b), Some(r)) if r == b => b,
                    (Some(b), Some(r)) => {
                        return Err(Error::invalid(
                            format!("{sf}.other_radius"),
                            format!(
                                "{} m differs from the contact's radius of side B {} m: give the other tube's outer radius once",
                                number(r),
                                number(b)
                            ),
                        ));
                    }
                    (None, None) => {
                        let how = if other.is_some() {
                            "the contact's radius of side B (m) or scar.other_radius"
                        } else {
                            "scar.other_radius (m)"
                        };
                        return Err(Error::invalid(
                            format!("{sf}.other_radius"),
                            format!("the scar needs the other tube's outer radius: give {how}"),
                        ));
                    }
                },
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

/// A flat-bar scar's width and tilt (rad): as written, or the contact's bar's width and the
/// magnitude of its twist (both given, they must agree: the scar is the bar's); `sf` names
/// the scar.
fn flat_bar_scar(
    width: Option<f64>,
    tilt_deg: Option<f64>,
    bar: Option<&FlatBar>,
    sf: &str,
) -> Result<(f64, f64)> {
    let Some(bar) = bar else {
        let Some(width) = width else {
            return Err(Error::invalid(
                format!("{sf}.width"),
                "a flat_bar scar needs the bar's width along the tube, m (or give the contact's width)",
            ));
        };
        return Ok((width, tilt_deg.unwrap_or(0.0).to_radians()));
    };
    if let Some(w) = width.filter(|w| *w != bar.width) {
        return Err(Error::invalid(
            format!("{sf}.width"),
            format!(
                "{} m differs from the contact's width {} m: give the bar's width once",
                number(w),
                number(bar.width)
            ),
        ));
    }
    let twist = bar.twist.abs();
    if let Some(t) = tilt_deg.filter(|t| t.to_radians() != twist) {
        return Err(Error::invalid(
            format!("{sf}.tilt_deg"),
            format!(
                "{} differs from the magnitude of the contact's twist_deg {}: a bar's scar is tilted by its twist (remove tilt_deg)",
                number(t),
                number(twist.to_degrees())
            ),
        ));
    }
    Ok((bar.width, twist))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn wear(scar: &str) -> WearInput {
        toml::from_str(&format!(
            "tube = {{ law = \"archard\", coefficient = 2e-15 }}\nsupport = {{ law = \"archard\", coefficient = 1e-15 }}\nscar = {scar}\n"
        ))
        .unwrap()
    }

    fn plane() -> ObstacleInput {
        toml::from_str("type = \"plane\"\nnormal = [0.0, 0.0, 1.0]\n").unwrap()
    }

    /// A two-body contact's tube scar takes side A's radius as the tube's and side B's as
    /// the other tube's; given twice they must agree; a contact with an obstacle must give
    /// the other tube's radius.
    #[test]
    fn a_pair_s_tube_scar_takes_the_radii_of_its_two_sides() {
        let tube = wear("{ type = \"tube\", crossing_deg = 90.0 }");
        let w = tube.build_pair([0.01, 0.008], &plane(), "c").unwrap();
        assert_eq!(
            w.scar,
            Scar::Tube {
                tube_radius: 0.01,
                other_radius: 0.008,
                crossing: std::f64::consts::FRAC_PI_2,
                length: None
            }
        );
        assert_eq!(w.tube, WearLaw::Archard { coefficient: 2e-15 });
        assert_eq!(w.support, WearLaw::Archard { coefficient: 1e-15 });
        let e = tube.build(0.01, None, &plane(), "c").unwrap_err();
        assert_eq!(e.field(), Some("c.wear.scar.other_radius"));
        let e = tube.build_pair([0.01, 0.0], &plane(), "c").unwrap_err();
        assert_eq!(e.field(), Some("c.wear.scar.other_radius"));
        assert!(e.to_string().contains("side B"), "{e}");
        let both = wear("{ type = \"tube\", crossing_deg = 90.0, other_radius = 0.009 }");
        let e = both.build_pair([0.01, 0.008], &plane(), "c").unwrap_err();
        assert_eq!(e.field(), Some("c.wear.scar.other_radius"));
        let w = both.build_pair([0.01, 0.0], &plane(), "c").unwrap();
        assert!(matches!(w.scar, Scar::Tube { other_radius, .. } if other_radius == 0.009));
        // a bar: side A is the tube
        let bar = wear("{ type = \"flat_bar\", width = 0.02 }");
        let w = bar.build_pair([0.01, 0.003], &plane(), "c").unwrap();
        assert_eq!(w.scar.tube_radius(), 0.01);
    }
}
