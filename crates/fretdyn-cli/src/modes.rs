//! `fretdyn modes CASE.toml`: the frequency table of a case's modal basis, the basis as
//! `.npz`, and (for a tube) a picture of its first mode shapes.

use std::path::{Path, PathBuf};

use fretdyn::case::{Case, TubeModel};
use fretdyn::structure::beam::Dof;

use crate::Failure;
use crate::out::outln;
use crate::plot::{Layout, Mark, Panel, Series, YScale, stacked};

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
        plot_shapes(&png, &case, tube, shown).map_err(Failure::failed)?;
        outln!("wrote {}", png.display())?;
    }
    Ok(())
}

/// What `mode_shapes.png` is drawn from, written beside it so that `fretdyn plot DIR` draws
/// it again: the title, the abscissa of the nodes, per mode its frequency and translations,
/// and the supports (restrained nodes, contacts' points) by abscissa.
pub const SHAPES_FILE: &str = "mode_shapes.json";

/// A translation below this fraction of a mode's largest all along the tube is not drawn
/// (it would be a line along the axis) but named in the panel's title.
pub const NEGLIGIBLE: f64 = 1e-3;

/// Translations of the first `shown` modes against the abscissa along the tube, to
/// [`SHAPES_FILE`] and `mode_shapes.png`.
fn plot_shapes(path: &Path, case: &Case, tube: &TubeModel, shown: usize) -> Result<(), String> {
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
    let modes: Vec<serde_json::Value> = (0..n)
        .map(|m| {
            let [ux, uy, uz] = [Dof::Ux, Dof::Uy, Dof::Uz]
                .map(|d| order.iter().map(|&k| value(k, d, m)).collect::<Vec<f64>>());
            serde_json::json!({
                "frequency_hz": tube.basis.modes.omega[m] / std::f64::consts::TAU,
                "u_x": ux, "u_y": uy, "u_z": uz,
            })
        })
        .collect();
    let restrained: Vec<f64> = tube
        .structure
        .beam
        .restraints
        .iter()
        .filter_map(|(node, _)| order.iter().position(|k| k == node).map(|i| s[i]))
        .collect();
    let contacts: Vec<serde_json::Value> = case
        .model
        .contacts
        .iter()
        .filter_map(|c| {
            case.point_abscissae
                .get(c.point)
                .copied()
                .flatten()
                .map(|at| serde_json::json!({"name": c.name, "s": at}))
        })
        .collect();
    let json = serde_json::json!({
        "title": case.title,
        "abscissa": s,
        "modes": modes,
        "restrained": restrained,
        "contacts": contacts,
    });
    let dir = path.parent().unwrap_or(Path::new("."));
    let file = dir.join(SHAPES_FILE);
    fretdyn::files::write_text_atomically(&file, &format!("{json:#}\n"))
        .map_err(|e| e.to_string())?;
    draw_folder(dir).map(|_| ())
}

/// A translation of a mode along the tube: its name (`u_x`) and values.
type Component<'a> = (&'a str, Vec<f64>);

/// `mode_shapes.png` of the modes folder `dir`, from its [`SHAPES_FILE`]: a panel per mode,
/// its translations normalised by the largest (a mode's scale is arbitrary), the supports as
/// vertical lines; a component that is zero along the whole tube is left out of the legend
/// (named in the panel's title) rather than drawn along the axis.
pub fn draw_folder(dir: &Path) -> Result<PathBuf, String> {
    let file = dir.join(SHAPES_FILE);
    let json: serde_json::Value = std::fs::read_to_string(&file)
        .map_err(|e| e.to_string())
        .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
        .map_err(|e| format!("{}: {e}", file.display()))?;
    let numbers = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array()
            .map(|a| a.iter().filter_map(serde_json::Value::as_f64).collect())
            .unwrap_or_default()
    };
    let s = numbers(&json["abscissa"]);
    let title = json["title"].as_str().unwrap_or("tube");
    let modes = json["modes"].as_array().cloned().unwrap_or_default();
    // each mode normalised by its largest translation
    let columns: Vec<(f64, Vec<Component>)> = modes
        .iter()
        .map(|m| {
            let parts: Vec<(&str, Vec<f64>)> = ["u_x", "u_y", "u_z"]
                .into_iter()
                .map(|k| (k, numbers(&m[k])))
                .collect();
            let largest = parts
                .iter()
                .flat_map(|(_, v)| v.iter())
                .fold(0.0f64, |a, v| a.max(v.abs()));
            let scaled = parts
                .into_iter()
                .map(|(k, v)| {
                    let v = v
                        .iter()
                        .map(|x| if largest > 0.0 { x / largest } else { 0.0 })
                        .collect();
                    (k, v)
                })
                .collect();
            (m["frequency_hz"].as_f64().unwrap_or(f64::NAN), scaled)
        })
        .collect();
    let mut marks: Vec<Mark> = numbers(&json["restrained"])
        .into_iter()
        .map(|x| Mark::At {
            label: "supports (restrained nodes)".into(),
            x,
        })
        .collect();
    if let Some(contacts) = json["contacts"].as_array() {
        marks.extend(contacts.iter().filter_map(|c| {
            c["s"].as_f64().map(|x| Mark::At {
                label: "contacts (plates, bars)".into(),
                x,
            })
        }));
    }
    let panels: Vec<Panel> = columns
        .iter()
        .enumerate()
        .map(|(m, (f, parts))| {
            // a component below 0.1 % of the largest all along (under a pixel: a line along
            // the axis) is named in the title instead
            let (shown, zero): (Vec<_>, Vec<_>) = parts
                .iter()
                .partition(|(_, v)| v.iter().any(|x| x.abs() > NEGLIGIBLE));
            let zero: Vec<String> = zero.iter().map(|(k, _)| format!("{k} ≈ 0")).collect();
            let note = if zero.is_empty() {
                String::new()
            } else {
                format!(" ({})", zero.join(", "))
            };
            Panel {
                title: format!("mode {} — {f:.3} Hz{note}", m + 1),
                series: shown
                    .iter()
                    .map(|(k, v)| Series {
                        label: k.to_string(),
                        x: &s,
                        y: v,
                    })
                    .collect(),
                errors: Vec::new(),
                marks: marks.clone(),
            }
        })
        .collect();
    let path = dir.join("mode_shapes.png");
    stacked(
        &path,
        &format!("{title} — mode shapes"),
        "abscissa along the tube (m)",
        "displacement / largest (normalised)",
        &panels,
        &Layout {
            y_scale: YScale::Linear,
            ..Layout::default()
        },
    )?;
    Ok(path)
}
