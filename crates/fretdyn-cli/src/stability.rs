//! `fretdyn stability CASE.toml`: the Connors fluid-elastic stability check of every mode of a
//! case with a `[flow]` section (docs/FLOW.md) — the basis's modes (supports inactive), then
//! those of each support condition of `[stability]` — printed and written as
//! `stability.json` and `stability.csv`. The library computes
//! ([`fretdyn::Case::stability_checks`]); this prints.

use std::path::{Path, PathBuf};

use fretdyn::Case;
use fretdyn::loads::flow::StabilityReport;

use crate::Failure;
use crate::out::{errln, outln};

/// Entry point of `fretdyn stability`.
pub fn main(path: &Path, output: Option<PathBuf>) -> Result<(), Failure> {
    let case = Case::from_file(path).map_err(|e| Failure::input(e.in_file(path)))?;
    for w in &case.warnings {
        errln!("warning: {w}");
    }
    let Some(report) = case.stability_checks() else {
        if !case.model.structures.is_empty() {
            return Err(Failure::input(format!(
                "{}: structures: the Connors check of a case of several structures is not supported yet: check each structure in a case of its own ([structure] with its [flow])",
                path.display()
            )));
        }
        return Err(Failure::input(format!(
            "{}: flow: the case has no [flow] section: add one with its [[flow.zones]] (docs/FLOW.md)",
            path.display()
        )));
    };
    let report = report.map_err(|e| Failure::input(e.in_file(path)))?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "case".into());
    let dir = output
        .unwrap_or_else(|| PathBuf::from("fretdyn_results").join(format!("{stem}_stability")));
    std::fs::create_dir_all(&dir).map_err(|e| {
        Failure::failed(format!("{}: cannot create the folder: {e}", dir.display()))
    })?;
    print(&case.title, &report)?;
    let json = dir.join("stability.json");
    let text = serde_json::to_string_pretty(&report)
        .map_err(|e| Failure::failed(format!("{}: {e}", json.display())))?;
    std::fs::write(&json, text + "\n")
        .map_err(|e| Failure::failed(format!("{}: {e}", json.display())))?;
    let csv = dir.join("stability.csv");
    std::fs::write(&csv, report.to_csv())
        .map_err(|e| Failure::failed(format!("{}: {e}", csv.display())))?;
    outln!("wrote {} and {}", json.display(), csv.display())?;
    Ok(())
}

/// The table of the modes.
fn print(title: &str, report: &StabilityReport) -> Result<(), Failure> {
    outln!(
        "{title}: Connors check, K = {}, D = {} m, m = {:.6} kg/m",
        report.connors_constant,
        report.diameter,
        report.mass_per_length
    )?;
    let width = report
        .modes
        .iter()
        .map(|m| m.condition.chars().count())
        .max()
        .unwrap_or(0)
        .max("condition".len());
    outln!(
        "{:<width$} {:<12} {:>5} {:>12} {:>9} {:>12} {:>10} {:>10} {:>8}  zone (ρ_ref)",
        "condition",
        "plane",
        "mode",
        "f (Hz)",
        "ζ",
        "U_eff (m/s)",
        "U_c (m/s)",
        "U_eff/U_c",
        ""
    )?;
    for m in &report.modes {
        let ratio = m
            .ratio
            .map_or_else(|| "-".to_string(), |r| format!("{r:.4}"));
        outln!(
            "{:<width$} {:<12} {:>5} {:>12.4} {:>9.4} {:>12.4} {:>10.4} {:>10} {:>8}  {} ({:.4} kg/m³)",
            m.condition,
            m.plane.map_or("-", |p| p.name()),
            m.mode,
            m.frequency_hz,
            m.damping_ratio,
            m.effective_velocity,
            m.critical_velocity,
            ratio,
            if m.unstable() { "UNSTABLE" } else { "" },
            m.reference_zone,
            m.reference_density
        )?;
    }
    for (_, line) in crate::run::connors_summary(report) {
        outln!("{line}")?;
    }
    Ok(())
}
