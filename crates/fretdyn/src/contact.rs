//! A contact: a structure point, an obstacle, the normal penalty law and the Coulomb
//! coefficients (THEORY §3, §4).

use crate::error::{Error, Result};
use crate::friction::Coulomb;
use crate::obstacle::{ContactFrame, Obstacle};

/// Normal penalty law `R_N = max(0, K_N δ + C_N δ̇)` for `δ > 0`, `R_N = 0` otherwise (THEORY §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalLaw {
    /// Contact stiffness `K_N`, N/m (for a tube: the ovalisation stiffness).
    pub stiffness: f64,
    /// Contact damping `C_N`, N·s/m (0: elastic impact).
    pub damping: f64,
}

impl NormalLaw {
    /// Validated constructor; `field` prefixes error messages.
    pub fn new(stiffness: f64, damping: f64, field: &str) -> Result<Self> {
        if !(stiffness.is_finite() && stiffness > 0.0) {
            return Err(Error::invalid(
                format!("{field}.stiffness"),
                format!("must be a positive contact stiffness K_N in N/m (got {stiffness})"),
            ));
        }
        if !(damping.is_finite() && damping >= 0.0) {
            return Err(Error::invalid(
                format!("{field}.damping"),
                format!("must be a contact damping C_N ≥ 0 in N·s/m (got {damping})"),
            ));
        }
        Ok(Self { stiffness, damping })
    }

    /// Normal force magnitude for penetration `δ` and penetration rate `δ̇`; 0 when open and
    /// never tensile.
    #[inline]
    pub fn force(&self, penetration: f64, penetration_rate: f64) -> f64 {
        if penetration > 0.0 {
            (self.stiffness * penetration + self.damping * penetration_rate).max(0.0)
        } else {
            0.0
        }
    }
}

/// One contact of the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// Name, used in outputs.
    pub name: String,
    /// Index of the structure point in the modal basis.
    pub point: usize,
    /// The obstacle.
    pub obstacle: Obstacle,
    /// Normal penalty law.
    pub normal: NormalLaw,
    /// Static and dynamic friction coefficients.
    pub friction: Coulomb,
}

impl Contact {
    /// Frame of the obstacle at the point's physical position.
    #[inline]
    pub fn frame(&self, x: &nalgebra::Vector3<f64>) -> ContactFrame {
        self.obstacle.frame(x)
    }
}
