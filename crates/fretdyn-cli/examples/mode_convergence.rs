//! Convergence of a tube's contact forces and wear with the number of modes kept
//! (docs/VERIFICATION.md). Runs examples/tube_clamped_one_support.toml for 0.1 s at
//! Δt = 1e-6 s (stable with every mode) keeping 2 … 114 (all) modes, prints the table and
//! writes mode_convergence.png in the folder given (default: fretdyn_results/mode_convergence;
//! scripts/regenerate_figures.sh copies it to docs/figures).
//!
//! cargo run --release -p fretdyn-cli --example mode_convergence [-- FOLDER]

// The command's own plotting module, shared rather than copied.
#[allow(dead_code)]
#[path = "../src/plot.rs"]
mod plot;

#[path = "../../fretdyn/tests/common/mode_truncation.rs"]
mod mode_truncation;

use std::path::Path;

use fretdyn::case::Case;
use fretdyn::integrator::simulation::simulate;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("examples/tube_clamped_one_support.toml"))
        .expect("example case");
    let counts = [2usize, 4, 8, 12, 16, 24, 32, 48, 114];
    let mut rows = Vec::new();
    for n in counts {
        let t = mode_truncation::with_modes(&text, n);
        let case = Case::from_toml_str(&t, &root.join("examples")).expect("valid case");
        let r = simulate(&case.model, &case.settings).expect("run");
        let c = &r.contacts[0];
        let f_max = case.model.basis.omega.last().copied().unwrap_or(0.0) / std::f64::consts::TAU;
        let impulse = c.normal_force_mean * r.steps as f64 * r.dt;
        rows.push((
            n,
            f_max,
            c.impacts,
            c.normal_force_max,
            impulse,
            c.wear_work_rate,
            c.stick_time_fraction,
        ));
    }
    let reference = *rows.last().expect("rows");
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    println!(
        "| modes | highest mode (Hz) | impacts | max R_N (N) | impulse ∫R_N dt (N·s) | wear work rate (W) | stick fraction | error max R_N | error impulse | error wear rate |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut e_impulse = Vec::new();
    let mut e_wear = Vec::new();
    let mut e_force = Vec::new();
    for &(n, f, imp, rn, impulse, wear, stick) in &rows {
        println!(
            "| {n} | {f:.1} | {imp} | {rn:.3} | {impulse:.6} | {wear:.6e} | {stick:.4} | {:.2e} | {:.2e} | {:.2e} |",
            rel(rn, reference.3),
            rel(impulse, reference.4),
            rel(wear, reference.5)
        );
        if n != reference.0 {
            e_force.push(rel(rn, reference.3));
            e_impulse.push(rel(impulse, reference.4));
            e_wear.push(rel(wear, reference.5));
        }
    }
    let x: Vec<f64> = counts[..counts.len() - 1]
        .iter()
        .map(|&n| n as f64)
        .collect();
    let log = |v: &[f64]| v.iter().map(|e| e.max(1e-12).log10()).collect::<Vec<_>>();
    let (a, b, c) = (log(&e_force), log(&e_impulse), log(&e_wear));
    let dir = std::env::args_os().nth(1).map_or_else(
        || std::path::PathBuf::from("fretdyn_results/mode_convergence"),
        std::path::PathBuf::from,
    );
    std::fs::create_dir_all(&dir).expect("output folder");
    let path = dir.join("mode_convergence.png");
    plot::line_plot(
        &path,
        "Tube with one mid-span support: error against the all-mode (114) solution",
        "modes kept",
        "log10(relative error)",
        &[
            plot::Series {
                label: "max normal force".into(),
                x: &x,
                y: &a,
            },
            plot::Series {
                label: "impulse ∫R_N dt".into(),
                x: &x,
                y: &b,
            },
            plot::Series {
                label: "wear work rate".into(),
                x: &x,
                y: &c,
            },
        ],
        false,
    )
    .expect("figure");
    println!("wrote {}", path.display());
}
