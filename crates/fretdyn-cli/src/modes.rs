//! `fretdyn modes CASE.toml`: the frequency table of a case's modal basis, the basis as
//! `.npz`, and (for a tube) a picture of its first mode shapes.

use std::path::{Path, PathBuf};

use fretdyn::case::{Case, TubeModel};
use fretdyn::structure::beam::Dof;

use crate::Failure;
use crate::out::outln;
use crate::plot::{Series, panels_plot};

/// Entry point of `fretdyn modes`.
pub fn main(path: &Path, output: Option<PathBuf>, shown: usize) -> Result<(), Failure> {
    let case = Case::from_file(path).map_err(|e| Failure::input(e.in_file(path)))?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "case".into());
    let dir =
        output.unwrap_or_else(|| PathBuf::from("fretdyn_results").join(format!("{stem}_modes")));
    std::fs::create_dir_all(&dir).map_err(|e| {
        Failure::failed(format!("{}: cannot create the folder: {e}", dir.display()))
    })?;
    let basis = &case.model.basis;
    outln!("{}: {} modes", case.title, basis.modes())?;
    outln!("{:>5} {:>14} {:>10}", "mode", "frequency (Hz)", "damping")?;
    for (i, (w, xi)) in basis.omega.iter().zip(&basis.damping_ratio).enumerate() {
        outln!(
            "{:>5} {:>14.6} {:>10.4}",
            i + 1,
            w / std::f64::consts::TAU,
            xi
        )?;
    }
    if let Some(tube) = &case.tube {
        let a = &tube.basis.assembled;
        outln!(
            "finite elements: {} nodes, {} elements, {} free DOFs; max |ΦᵀMΦ − I| = {:.2e}",
            tube.structure.beam.mesh.nodes.len(),
            tube.structure.beam.mesh.elements.len(),
            a.mass.nrows(),
            fretdyn::structure::eigen::orthonormality_error(&a.mass, &tube.basis.modes.shapes)
        )?;
    }
    let npz = dir.join("basis.npz");
    fretdyn::structure::basis_file::write_basis_npz_with_abscissae(
        &npz,
        basis,
        &case.point_abscissae,
    )
    .map_err(|e| Failure::failed(e.to_string()))?;
    let with_s = if case.point_abscissae.iter().any(Option::is_some) {
        ", s_<point>"
    } else {
        ""
    };
    outln!(
        "wrote {} (keys: frequencies_hz, damping_ratio, rows_<point>, coords_<point>{with_s})",
        npz.display()
    )?;
    if let Some(tube) = &case.tube {
        let png = dir.join("mode_shapes.png");
        plot_shapes(&png, &case.title, tube, shown).map_err(Failure::failed)?;
        outln!("wrote {}", png.display())?;
    }
    Ok(())
}

/// Translations of the first `shown` modes against the abscissa along the tube.
fn plot_shapes(path: &Path, title: &str, tube: &TubeModel, shown: usize) -> Result<(), String> {
    let mesh = &tube.structure.beam.mesh;
    let a = &tube.basis.assembled;
    let shapes = &tube.basis.modes.shapes;
    // nodes in path order: follow the elements from node 0
    let order: Vec<usize> = (0..mesh.nodes.len()).collect();
    let mut s = vec![0.0; order.len()];
    for k in 1..order.len() {
        s[k] = s[k - 1] + (mesh.nodes[order[k]] - mesh.nodes[order[k - 1]]).norm();
    }
    let value = |node: usize, dof: Dof, mode: usize| {
        a.reduced_index(node, dof)
            .map_or(0.0, |i| shapes[(i, mode)])
    };
    let n = shown.min(shapes.ncols());
    let mut columns: Vec<[Vec<f64>; 3]> = Vec::new();
    for m in 0..n {
        columns.push(
            [Dof::Ux, Dof::Uy, Dof::Uz].map(|d| order.iter().map(|&k| value(k, d, m)).collect()),
        );
    }
    let panels: Vec<(String, Vec<Series>)> = columns
        .iter()
        .enumerate()
        .map(|(m, [ux, uy, uz])| {
            (
                format!(
                    "mode {} — {:.3} Hz",
                    m + 1,
                    tube.basis.modes.omega[m] / std::f64::consts::TAU
                ),
                vec![
                    Series {
                        label: "u_x".into(),
                        x: &s,
                        y: ux,
                    },
                    Series {
                        label: "u_y".into(),
                        x: &s,
                        y: uy,
                    },
                    Series {
                        label: "u_z".into(),
                        x: &s,
                        y: uz,
                    },
                ],
            )
        })
        .collect();
    panels_plot(
        path,
        &format!("{title} — mode shapes (mass-normalised)"),
        "abscissa along the tube (m)",
        "displacement",
        &panels,
    )
}
