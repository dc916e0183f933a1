//! `contacts.csv`: the per-contact statistics of `summary.json` (THEORY §5) as a table, one row
//! per contact in the order of the case file, for `pandas.read_csv` or `numpy.genfromtxt` in
//! one call; and `contacts_columns.csv`, which gives every column's unit, meaning and
//! Code_Aster name (`POST_DYNA_MODA_T`'s table; the glossary is docs/CODE_ASTER.md).
//!
//! The table is formed from the `contacts` list of the summary as written to `summary.json`,
//! so that every cell is the summary's value: a number at full precision (the shortest text
//! that reads back to the same `f64`), a count as an integer, `true`/`false`, and an empty cell
//! where the summary has `null` or no such key (a standard error with fewer than 2 batches,
//! the volume rates of a contact without `wear`). The columns are [`COLUMNS`], always all of
//! them and in that order, so that the tables of several runs stack; a key that the summary
//! gains and [`COLUMNS`] does not know yet follows them (nested objects flattened with dotted
//! names). Lists ([`LEFT_OUT`]: the peak-force histogram, whose bins differ per contact) stay
//! in `summary.json` only. Written with the `csv` crate: a name with a comma, a quote or a
//! line break is quoted.

use std::path::{Path, PathBuf};

use serde_json::{Map, Value};

use crate::error::Result;
use crate::files::write_atomically;

/// The table of per-contact statistics, beside `summary.json`.
pub const CONTACTS_FILE: &str = "contacts.csv";
/// The unit, meaning and Code_Aster name of each column of [`CONTACTS_FILE`].
pub const COLUMNS_FILE: &str = "contacts_columns.csv";

/// A column of `contacts.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Column {
    /// fretdyn's key: the header, and the key of `summary.json`'s `contacts[k]`.
    pub key: &'static str,
    /// SI unit (`1` for a number without one).
    pub unit: &'static str,
    /// What Code_Aster calls it: `PARAMETER (CALCUL)` in the table of `POST_DYNA_MODA_T`
    /// (`CALCUL` names the row of the contact the parameter is read on), or the relation that
    /// gives it from Code_Aster's values; empty when Code_Aster has no such value.
    /// docs/CODE_ASTER.md says where the definitions differ.
    pub code_aster: &'static str,
    /// What it is.
    pub meaning: &'static str,
}

const fn column(
    key: &'static str,
    unit: &'static str,
    code_aster: &'static str,
    meaning: &'static str,
) -> Column {
    Column {
        key,
        unit,
        code_aster,
        meaning,
    }
}

/// The columns of `contacts.csv`, in order: the contact's index and name, then the fields of
/// [`crate::accumulate::statistics::ContactStatistics`], the wear volume rates of a contact with
/// `wear`, and the standard errors by batch means with their batches (THEORY §5).
pub const COLUMNS: &[Column] = &[
    column(
        "contact",
        "1",
        "",
        "index of the contact in the case file (0 is the first [[contacts]]), as in impacts.csv",
    ),
    column("name", "", "INTITULE", "contact name"),
    column(
        "duration",
        "s",
        "INST_FIN - INST_INIT",
        "duration of the statistics window [t_start, t_end]",
    ),
    column(
        "impacts",
        "1",
        "number of CALCUL='IMPACT' rows (OPTION='IMPACT')",
        "impacts started in the window (an opening longer than rest_duration ends an impact)",
    ),
    column(
        "impacts_per_second",
        "1/s",
        "NB_CHOC_S (STAT_CHOC)",
        "impacts per second",
    ),
    column(
        "rebounds_per_impact",
        "1",
        "NB_REBON_CHOC - 1 (STAT_CHOC)",
        "mean number of rebounds (openings shorter than rest_duration) per finished impact",
    ),
    column(
        "contact_duration_mean",
        "s",
        "T_CHOC_MOYEN (STAT_CHOC)",
        "mean duration of the finished impacts, first closing to last opening",
    ),
    column(
        "contact_duration_min",
        "s",
        "T_CHOC_MINI (STAT_CHOC)",
        "shortest finished impact",
    ),
    column(
        "contact_duration_max",
        "s",
        "T_CHOC_MAXI (STAT_CHOC)",
        "longest finished impact",
    ),
    column(
        "contact_time_fraction",
        "1",
        "%_T_CHOC / 100 (STAT_CHOC)",
        "fraction of the window spent closed",
    ),
    column(
        "stick_time_fraction",
        "1",
        "",
        "fraction of the window spent closed and sticking",
    ),
    column(
        "slip_time_fraction",
        "1",
        "",
        "fraction of the window spent closed and sliding",
    ),
    column(
        "normal_force_mean",
        "N",
        "MOYEN_T_TOTAL (FORCE_NORMALE)",
        "mean normal force R_N over the whole window",
    ),
    column(
        "normal_force_mean_in_contact",
        "N",
        "MOYEN_T_CHOC (FORCE_NORMALE)",
        "mean normal force over the time spent closed",
    ),
    column(
        "normal_force_rms",
        "N",
        "RMS_T_TOTAL (FORCE_NORMALE)",
        "RMS normal force over the whole window",
    ),
    column(
        "normal_force_max",
        "N",
        "MAXI (FORCE_NORMALE); F_MAX_ABS (GLOBAL)",
        "largest normal force",
    ),
    column(
        "tangential_force_mean",
        "N",
        "",
        "mean tangential force magnitude |R_T| over the whole window",
    ),
    column(
        "tangential_force_mean_in_contact",
        "N",
        "",
        "mean |R_T| over the time spent closed",
    ),
    column(
        "tangential_force_rms",
        "N",
        "sqrt(RMS (FORCE_TANG_1)^2 + RMS (FORCE_TANG_2)^2)",
        "RMS of |R_T| over the whole window",
    ),
    column("tangential_force_max", "N", "", "largest |R_T|"),
    column(
        "wear_work",
        "J",
        "",
        "friction work over the window, integral of |R_T . v_T| dt",
    ),
    column(
        "wear_work_rate",
        "W",
        "",
        "wear work rate as friction power, (1/T) integral of |R_T . v_T| dt (THEORY §5)",
    ),
    column(
        "normal_wear_work_rate",
        "W",
        "PUIS_USURE (PUIS_USURE)",
        "wear work rate with the normal force, (1/T) integral of R_N |v_T| dt (Code_Aster's definition)",
    ),
    column(
        "wear_volume",
        "m3",
        "",
        "Archard wear volume K_wear integral of |R_T . v_T| dt (0 without statistics.wear_coefficient)",
    ),
    column(
        "penetration_max",
        "m",
        "",
        "largest penetration (negative: the contact never closed; minus the smallest clearance)",
    ),
    column(
        "displacement_mean",
        "m",
        "MOYEN (DEPL_RADIAL) in a hole; MOYEN (DEPL_Y or DEPL_Z) between bars",
        "mean radial offset from the hole's centre (holes), or distance to the plane / the bars' mid-plane (planes)",
    ),
    column(
        "displacement_rms",
        "m",
        "RMS (DEPL_RADIAL) in a hole; RMS (DEPL_Y or DEPL_Z) between bars",
        "RMS of that displacement",
    ),
    column(
        "displacement_min",
        "m",
        "MINI (DEPL_RADIAL) in a hole; MINI (DEPL_Y or DEPL_Z) between bars",
        "smallest value of that displacement",
    ),
    column(
        "displacement_max",
        "m",
        "MAXI (DEPL_RADIAL) in a hole; MAXI (DEPL_Y or DEPL_Z) between bars",
        "largest value of that displacement",
    ),
    column(
        "contact_angle_mean_deg",
        "deg",
        "close to MOYEN (DEPL_ANGULAIRE)",
        "circular mean of the contact angle in the hole's plane over the time spent closed",
    ),
    column(
        "contact_angle_spread_deg",
        "deg",
        "close to ECART_TYPE (DEPL_ANGULAIRE)",
        "circular standard deviation of that angle",
    ),
    column(
        "tube_volume_rate",
        "m3/s",
        "V_USUR_TUBE / INST (POST_USURE)",
        "tube wear volume rate by the contact's wear law at the run's wear work rate (contacts with wear)",
    ),
    column(
        "support_volume_rate",
        "m3/s",
        "V_USUR_OBST / INST (POST_USURE)",
        "support wear volume rate by its wear law (contacts with wear)",
    ),
    column(
        "wear_work_rate_se",
        "W",
        "",
        "standard error of wear_work_rate by batch means",
    ),
    column(
        "normal_wear_work_rate_se",
        "W",
        "",
        "standard error of normal_wear_work_rate",
    ),
    column(
        "impacts_per_second_se",
        "1/s",
        "",
        "standard error of impacts_per_second",
    ),
    column(
        "contact_time_fraction_se",
        "1",
        "",
        "standard error of contact_time_fraction",
    ),
    column(
        "stick_time_fraction_se",
        "1",
        "",
        "standard error of stick_time_fraction",
    ),
    column(
        "slip_time_fraction_se",
        "1",
        "",
        "standard error of slip_time_fraction",
    ),
    column(
        "normal_force_mean_se",
        "N",
        "",
        "standard error of normal_force_mean",
    ),
    column(
        "normal_force_rms_se",
        "N",
        "",
        "standard error of normal_force_rms",
    ),
    column(
        "tangential_force_mean_se",
        "N",
        "",
        "standard error of tangential_force_mean",
    ),
    column(
        "tangential_force_rms_se",
        "N",
        "",
        "standard error of tangential_force_rms",
    ),
    column(
        "batches",
        "1",
        "",
        "whole batches the standard errors are formed from",
    ),
    column("batch_length", "s", "", "duration of a batch"),
    column(
        "batch_autocorrelation",
        "1",
        "",
        "lag-1 autocorrelation r1 of the batch means of the wear work rate",
    ),
    column(
        "batches_correlated",
        "",
        "",
        "true when r1 > 2/sqrt(batches): the batches are too short and the errors underestimated",
    ),
];

/// Keys of `summary.json`'s `contacts[k]` that are lists, not one value per contact: they stay
/// in `summary.json` only (the histogram's bins differ from contact to contact; its impacts are
/// the rows of `impacts.csv`, with their `peak_force`).
pub const LEFT_OUT: &[&str] = &["peak_force_histogram"];

/// The header and the rows of `contacts.csv` from a summary (as [`super::output::summary`]
/// makes it): [`COLUMNS`], then any other key the summary's contacts have, sorted.
pub fn contacts_table(summary: &Value) -> (Vec<String>, Vec<Vec<String>>) {
    let contacts: Vec<Map<String, Value>> = summary["contacts"]
        .as_array()
        .map(|list| {
            list.iter()
                .map(|c| {
                    let mut flat = Map::new();
                    if let Some(object) = c.as_object() {
                        flatten("", object, &mut flat);
                    }
                    flat
                })
                .collect()
        })
        .unwrap_or_default();
    let mut header: Vec<String> = COLUMNS.iter().map(|c| c.key.to_string()).collect();
    let mut others: Vec<&String> = contacts
        .iter()
        .flat_map(|c| c.keys())
        .filter(|k| !header.iter().any(|h| h == *k))
        .collect();
    others.sort();
    others.dedup();
    header.extend(others.into_iter().cloned());
    let rows = contacts
        .iter()
        .enumerate()
        .map(|(k, c)| {
            header
                .iter()
                .map(|key| match key.as_str() {
                    "contact" => k.to_string(),
                    key => cell(c.get(key)),
                })
                .collect()
        })
        .collect();
    (header, rows)
}

/// Writes `contacts.csv` and `contacts_columns.csv` in `dir` from a summary (atomically: a
/// failed write leaves no truncated file).
pub fn write_contacts_csv(dir: &Path, summary: &Value) -> Result<PathBuf> {
    let (header, rows) = contacts_table(summary);
    let path = dir.join(CONTACTS_FILE);
    write_atomically(&path, |file| {
        let mut csv = csv::Writer::from_writer(std::io::BufWriter::new(file));
        csv.write_record(&header).map_err(std::io::Error::other)?;
        for row in &rows {
            csv.write_record(row).map_err(std::io::Error::other)?;
        }
        csv.flush()
    })?;
    write_atomically(&dir.join(COLUMNS_FILE), |file| {
        let mut csv = csv::Writer::from_writer(std::io::BufWriter::new(file));
        csv.write_record(["column", "unit", "code_aster", "meaning"])
            .map_err(std::io::Error::other)?;
        for key in &header {
            let c = COLUMNS.iter().find(|c| c.key == key);
            csv.write_record([
                key.as_str(),
                c.map_or("", |c| c.unit),
                c.map_or("", |c| c.code_aster),
                c.map_or("", |c| c.meaning),
            ])
            .map_err(std::io::Error::other)?;
        }
        csv.flush()
    })?;
    Ok(path)
}

/// The scalars of `object` under their keys (`prefix.key` inside a nested object); lists are
/// left out.
fn flatten(prefix: &str, object: &Map<String, Value>, out: &mut Map<String, Value>) {
    for (key, value) in object {
        let key = if prefix.is_empty() {
            key.clone()
        } else {
            format!("{prefix}.{key}")
        };
        match value {
            Value::Object(inner) => flatten(&key, inner, out),
            Value::Array(_) => {}
            scalar => {
                out.insert(key, scalar.clone());
            }
        }
    }
}

/// A summary value as a cell: a count as an integer, a real at full precision (the shortest
/// decimal that reads back to the same `f64`), a flag as `true`/`false`, nothing for `null`.
fn cell(value: Option<&Value>) -> String {
    match value {
        None | Some(Value::Null) => String::new(),
        Some(Value::Bool(b)) => b.to_string(),
        Some(Value::Number(n)) => match (n.as_u64(), n.as_i64(), n.as_f64()) {
            (Some(u), _, _) => u.to_string(),
            (None, Some(i), _) => i.to_string(),
            (None, None, Some(x)) => format!("{x:?}"),
            (None, None, None) => n.to_string(),
        },
        Some(Value::String(s)) => s.clone(),
        Some(other) => other.to_string(),
    }
}
