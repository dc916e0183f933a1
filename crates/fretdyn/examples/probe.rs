use fretdyn::simulation::simulate;
use fretdyn::tangential::*;
use fretdyn::verification::*;
fn main() {
    for alpha in [20.0, 1e-7, 60.0] {
        let v1 = V1::reference(alpha);
        for (name, m) in methods(&[1e5, 1e6, 1e7]) {
            for sv in [StickVelocity::HalfStep, StickVelocity::FullStep] {
                if sv == StickVelocity::FullStep && !m.is_lagrange() {
                    continue;
                }
                let r = simulate(&v1.model(), &v1.settings(m, sv)).unwrap();
                let meas = measure(&v1, &r);
                println!(
                    "alpha={alpha} {name} {sv:?} {:?} stats={:?}",
                    meas, r.solver
                );
            }
        }
    }
}
