//! The runs of the modal ≡ physical tube tests: a case's settings with a tangential method,
//! every step recorded.

use fretdyn::case::Case;
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use fretdyn::integrator::simulation::{RunResults, RunSettings, simulate};
use fretdyn::model::Model;

/// Both Lagrange methods.
pub fn lagrange() -> [TangentialMethod; 2] {
    [
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
    ]
}

/// The tangential penalty law of the tube tests.
pub fn penalty() -> TangentialMethod {
    TangentialMethod::Penalty(PenaltySettings {
        stiffness: 2e5,
        damping: 10.0,
    })
}

/// `model` run with `case`'s time settings and `method`, every step recorded.
pub fn run(model: &Model, case: &Case, method: TangentialMethod) -> RunResults {
    let settings = RunSettings {
        method,
        stick_velocity: StickVelocity::HalfStep,
        output_every: 1,
        monitors: Vec::new(),
        statistics: Default::default(),
        ..case.settings.clone()
    };
    simulate(model, &settings).expect("valid run")
}

/// The largest magnitude.
pub fn max_abs(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |m, x| m.max(x.abs()))
}
