//! With every mode kept, the modal solution is the physical one (THEORY §1): the same central
//! differences and contacts run on `M ü + C u̇ + K u = f` in physical coordinates (dense
//! matrices) and on the modal coordinates of its mass-normalised modes give the same contact
//! forces and point displacements, for every tangential method.

use fretdyn::contact::friction::Coulomb;
use fretdyn::contact::obstacle::{Obstacle, Plane};
use fretdyn::contact::tangential::{
    ActiveSetSettings, GaussSeidelSettings, PenaltySettings, StickVelocity, TangentialMethod,
};
use fretdyn::contact::{Contact, NormalLaw};
use fretdyn::integrator::simulation::{RunResults, RunSettings, simulate};
use fretdyn::loads::{PointLoad, TimeHistory};
use fretdyn::model::{Model, PhysicalMatrices};
use fretdyn::structure::modal::{ModalBasis, Point};
use nalgebra::{DMatrix, DVector, Vector3};

/// Tiny deterministic generator in [-1, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// A 3-point, 9-DOF structure: random SPD mass and stiffness, Rayleigh damping.
struct Structure {
    m: DMatrix<f64>,
    k: DMatrix<f64>,
    c: DMatrix<f64>,
    alpha: f64,
    beta: f64,
}

fn structure() -> Structure {
    let n = 9;
    let mut g = Lcg(0xfee1_900d);
    let b = DMatrix::from_fn(n, n, |_, _| g.next());
    let m = &b * b.transpose() * 0.2 + DMatrix::identity(n, n);
    let d = DMatrix::from_fn(n, n, |_, _| g.next());
    let k = (&d * d.transpose() + DMatrix::identity(n, n) * 0.5) * 4e4;
    let (alpha, beta) = (2.0, 1e-5);
    let c = &m * alpha + &k * beta;
    Structure {
        m,
        k,
        c,
        alpha,
        beta,
    }
}

/// Mass-normalised modes of `K φ = ω² M φ` (nalgebra, independent of fretdyn's solvers).
fn modes(s: &Structure) -> (Vec<f64>, DMatrix<f64>) {
    let l = s.m.clone().cholesky().unwrap().l();
    let linv = l.clone().try_inverse().unwrap();
    let a = &linv * &s.k * linv.transpose();
    let eig = ((&a + a.transpose()) * 0.5).symmetric_eigen();
    let phi = linv.transpose() * &eig.eigenvectors;
    (eig.eigenvalues.iter().map(|v| v.sqrt()).collect(), phi)
}

/// Point `j` is DOFs 3j..3j+3 (its x, y, z displacement).
fn selection(j: usize, n: usize) -> Vec<f64> {
    let mut rows = vec![0.0; 3 * n];
    for d in 0..3 {
        rows[d * n + 3 * j + d] = 1.0;
    }
    rows
}

fn add_contacts_and_loads(model: &mut Model) {
    // point 0 rubs on a floor, point 2 on a wall with μ_s > μ_d; a harmonic force on point 1
    let planes = [
        (0, Vector3::z(), 2e-4, (0.35, 0.3)),
        (2, -Vector3::x(), 1e-4, (0.3, 0.3)),
    ];
    for (k, (point, normal, gap, (mu_s, mu_d))) in planes.into_iter().enumerate() {
        model.contacts.push(Contact::new(
            format!("c{k}"),
            point,
            Obstacle::Plane(Plane::new(Vector3::zeros(), normal, gap, None, "p").unwrap()),
            NormalLaw::new(2e5, 5.0, "n").unwrap(),
            Coulomb::new(mu_s, mu_d, "f").unwrap(),
        ));
    }
    model.loads.push(
        PointLoad::new(
            1,
            Vector3::new(30.0, 20.0, -40.0),
            TimeHistory::Harmonic {
                frequency_hz: 23.0,
                phase: 0.3,
            },
            "l",
        )
        .unwrap(),
    );
}

fn models() -> (Model, Model, DMatrix<f64>) {
    let s = structure();
    let n = s.m.nrows();
    let points = |rows: &dyn Fn(usize) -> Vec<f64>| -> Vec<Point> {
        (0..3)
            .map(|j| Point {
                name: format!("P{j}"),
                coords: Vector3::zeros(),
                rows: rows(j),
                rotations: Vec::new(),
            })
            .collect()
    };
    let mut physical = Model::physical(
        PhysicalMatrices {
            mass: s.m.clone(),
            damping: s.c.clone(),
            stiffness: s.k.clone(),
        },
        points(&|j| selection(j, n)),
    );
    let (omega, phi) = modes(&s);
    // rows of a point in the modal basis: Φ restricted to its DOFs
    let modal_rows = |j: usize| -> Vec<f64> {
        let mut rows = vec![0.0; 3 * n];
        for d in 0..3 {
            for i in 0..n {
                rows[d * n + i] = phi[(3 * j + d, i)];
            }
        }
        rows
    };
    let mut modal = Model::new(ModalBasis {
        damping_ratio: omega
            .iter()
            .map(|w| 0.5 * (s.alpha / w + s.beta * w))
            .collect(),
        omega,
        points: points(&modal_rows),
        participation: Vec::new(),
    });
    add_contacts_and_loads(&mut physical);
    add_contacts_and_loads(&mut modal);
    // the same initial state: u0, v0 in physical coordinates, q = Φᵀ M u in modal ones
    let mut g = Lcg(7);
    let u0 = DVector::from_fn(n, |_, _| 1e-4 * g.next());
    let v0 = DVector::from_fn(n, |_, _| 0.05 * g.next());
    physical.initial.q = u0.iter().copied().collect();
    physical.initial.qdot = v0.iter().copied().collect();
    let to_modal = phi.transpose() * &s.m;
    modal.initial.q = (&to_modal * &u0).iter().copied().collect();
    modal.initial.qdot = (&to_modal * &v0).iter().copied().collect();
    (physical, modal, phi)
}

fn settings(method: TangentialMethod) -> RunSettings {
    RunSettings {
        dt: 2e-5,
        steps: 20_000,
        method,
        stick_velocity: StickVelocity::HalfStep,
        output_every: 1,
        monitors: Vec::new(),
        statistics: Default::default(),
    }
}

fn max_abs(a: impl Iterator<Item = f64>) -> f64 {
    a.fold(0.0, |m, v| m.max(v.abs()))
}

fn compare(label: &str, phys: &RunResults, modal: &RunResults, phi: &DMatrix<f64>) {
    let (a, b) = (&phys.recorder, &modal.recorder);
    assert_eq!(a.len(), b.len());
    // contact forces
    let fscale = max_abs(a.normal_force.iter().copied());
    assert!(fscale > 1.0, "{label}: no contact force ({fscale})");
    let statuses: Vec<i8> = a.status.iter().copied().collect();
    assert!(
        statuses.contains(&1) && statuses.contains(&2) && statuses.contains(&0),
        "{label}: the run must open, stick and slip"
    );
    let dn = max_abs(
        a.normal_force
            .iter()
            .zip(&b.normal_force)
            .map(|(x, y)| x - y),
    );
    let dt = max_abs(
        a.tangential_force
            .iter()
            .zip(&b.tangential_force)
            .map(|(x, y)| x - y),
    );
    assert!(
        dn <= 1e-8 * fscale,
        "{label}: normal forces differ by {dn:e} (scale {fscale:e})"
    );
    assert!(
        dt <= 1e-8 * fscale,
        "{label}: tangential forces differ by {dt:e}"
    );
    assert_eq!(a.status, b.status, "{label}: statuses differ");
    // displacement of every degree of freedom (all points): u = Φ q
    let n = phi.nrows();
    let mut uscale = 0.0f64;
    let mut du = 0.0f64;
    for i in 0..a.len() {
        let q = DVector::from_iterator(n, b.q.row(i).iter().copied());
        let u = phi * q;
        for d in 0..n {
            uscale = uscale.max(a.q[[i, d]].abs());
            du = du.max((a.q[[i, d]] - u[d]).abs());
        }
    }
    assert!(
        du <= 1e-8 * uscale,
        "{label}: displacements differ by {du:e} (scale {uscale:e})"
    );
    // statistics
    for (ca, cb) in phys.contacts.iter().zip(&modal.contacts) {
        let w = (ca.wear_work_rate - cb.wear_work_rate).abs();
        assert!(
            w <= 1e-8 * ca.wear_work_rate.max(1e-300),
            "{label}: wear {ca:?} vs {cb:?}"
        );
    }
}

#[test]
fn modal_with_all_modes_equals_physical_for_every_method() {
    let (physical, modal, phi) = models();
    for method in [
        TangentialMethod::GaussSeidel(GaussSeidelSettings::default()),
        TangentialMethod::ActiveSet(ActiveSetSettings::default()),
        TangentialMethod::Penalty(PenaltySettings {
            stiffness: 1e5,
            damping: 20.0,
        }),
    ] {
        let p = simulate(&physical, &settings(method)).unwrap();
        let m = simulate(&modal, &settings(method)).unwrap();
        compare(method.name(), &p, &m, &phi);
        // the stability limits agree too (same eigenvalues)
        assert!((p.stable_dt - m.stable_dt).abs() <= 1e-9 * m.stable_dt);
        // and the energies
        let (ea, eb) = (&p.energy, &m.energy);
        assert!((ea.initial - eb.initial).abs() <= 1e-9 * ea.initial);
        assert!((ea.modal_damping - eb.modal_damping).abs() <= 1e-8 * ea.modal_damping);
    }
}
