//! `contacts.csv`: the per-contact statistics of `summary.json` (THEORY §5) as a table, one row
//! per contact in the order of the case file, for `pandas.read_csv` or `numpy.genfromtxt` in
//! one call; and `contacts_columns.csv`, which gives every column's unit, meaning and
//! Code_Aster name (`POST_DYNA_MODA_T`'s table; the glossary is docs/CODE_ASTER.md).
//!
//! The table is formed from the `contacts` list of the summary as written to `summary.json`,
//! so that every cell is the summary's value: a number at full precision (the shortest text
//! that reads back to the same `f64`), a count as an integer, `true`/`false`, and an empty cell
//! where the summary has `null` or no such key (a standard error with fewer than 2 batches,
//! the volume rates of a contact without `wear`). The columns are [`columns`] (derived from the
//! table of statistics, [`crate::accumulate::statistics::columns`]), always all of them and in
//! that order, so that the tables of several runs stack (a model of several structures or
//! with two-body contacts has [`POINT_COLUMNS`] after `name`); a key that the summary gains and
//! [`columns`] does not know yet follows them (nested objects flattened with dotted
//! names). Lists ([`LEFT_OUT`]: the peak-force histogram, whose bins differ per contact) stay
//! in `summary.json` only. Written with the `csv` crate: a name with a comma, a quote or a
//! line break is quoted.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use serde_json::{Map, Value};

use crate::accumulate::statistics::{STATISTICS, batched_statistics};
use crate::error::Result;
use crate::files::write_atomically;

/// The table of per-contact statistics, beside `summary.json`.
pub const CONTACTS_FILE: &str = "contacts.csv";
/// The unit, meaning and Code_Aster name of each column of [`CONTACTS_FILE`].
pub const COLUMNS_FILE: &str = "contacts_columns.csv";

/// A column of `contacts.csv`.
#[derive(Debug, Clone, PartialEq, Eq)]
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
    pub meaning: Cow<'static, str>,
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
        meaning: Cow::Borrowed(meaning),
    }
}

/// The columns before the statistics: the contact's index and name.
const CONTACT_COLUMNS: [Column; 2] = [
    column(
        "contact",
        "1",
        "",
        "index of the contact in the case file (0 is the first [[contacts]]), as in impacts.csv",
    ),
    column("name", "", "INTITULE", "contact name"),
];

/// The columns after the name in a model of several structures or with two-body contacts
/// (THEORY §15), when the summary's contacts have them.
pub const POINT_COLUMNS: [Column; 2] = [
    column(
        "point",
        "",
        "NOEUD_1",
        "the structure point of the contact (point A of a two-body contact)",
    ),
    column(
        "other_point",
        "",
        "NOEUD_2",
        "point B of a two-body contact (the forces act on point, their opposite on it; positions and slip are relative, of point with respect to it); empty for an obstacle",
    ),
];

/// The columns after the statistics: the wear volume rates of a contact with `wear`
/// ([`crate::output::summary`]).
const WEAR_COLUMNS: [Column; 2] = [
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
];

/// The last columns: the batches of the standard errors
/// ([`crate::accumulate::statistics::StandardErrors`]).
const BATCH_COLUMNS: [Column; 4] = [
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

/// The columns of `contacts.csv`, in order: the contact's index and name, then the
/// statistics of the table [`STATISTICS`] (the fields of
/// [`crate::accumulate::statistics::ContactStatistics`]), the wear volume rates of a contact
/// with `wear`, and the standard errors by batch means in the order of
/// [`crate::accumulate::statistics::BATCHED_STATISTICS`] with their batches (THEORY §5).
pub fn columns() -> Vec<Column> {
    let statistics = STATISTICS.iter().map(|s| Column {
        key: s.key,
        unit: s.unit,
        code_aster: s.code_aster,
        meaning: Cow::Borrowed(s.meaning),
    });
    let errors = batched_statistics().map(|(s, b)| Column {
        key: b.se_key,
        unit: s.unit,
        code_aster: "",
        // the first says how
        meaning: Cow::Owned(format!(
            "standard error of {}{}",
            s.key,
            if b.index == 0 { " by batch means" } else { "" }
        )),
    });
    CONTACT_COLUMNS
        .into_iter()
        .chain(statistics)
        .chain(WEAR_COLUMNS)
        .chain(errors)
        .chain(BATCH_COLUMNS)
        .collect()
}

/// Keys of `summary.json`'s `contacts[k]` that are lists, not one value per contact: they stay
/// in `summary.json` only (the histogram's bins differ from contact to contact; its impacts are
/// the rows of `impacts.csv`, with their `peak_force`).
pub const LEFT_OUT: &[&str] = &["peak_force_histogram"];

/// The header and the rows of `contacts.csv` from a summary (as [`super::output::summary`]
/// makes it): [`columns`], then any other key the summary's contacts have, sorted.
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
    let mut header: Vec<String> = columns().iter().map(|c| c.key.to_string()).collect();
    if contacts
        .iter()
        .any(|c| c.contains_key(POINT_COLUMNS[1].key))
    {
        let at = CONTACT_COLUMNS.len();
        header.splice(at..at, POINT_COLUMNS.iter().map(|c| c.key.to_string()));
    }
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
        let columns: Vec<Column> = columns().into_iter().chain(POINT_COLUMNS).collect();
        for key in &header {
            let c = columns.iter().find(|c| c.key == key);
            csv.write_record([
                key.as_str(),
                c.map_or("", |c| c.unit),
                c.map_or("", |c| c.code_aster),
                c.map_or("", |c| &c.meaning),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accumulate::statistics::{BATCHED_STATISTICS, ContactStatistics};

    /// The columns are the table of statistics in its order, between the contact and the
    /// wear volume rates, then a `<key>_se` per statistic with batch means in their order
    /// (with its unit), then the batches; and a summary's contact has no scalar that is
    /// not a column (a field of the statistics missing from the table would be one).
    #[test]
    fn the_columns_are_the_table_of_statistics() {
        let columns = columns();
        let keys: Vec<&str> = columns.iter().map(|c| c.key).collect();
        let n = STATISTICS.len();
        assert_eq!(keys[..2], ["contact", "name"]);
        let statistics: Vec<&str> = STATISTICS.iter().map(|s| s.key).collect();
        assert_eq!(keys[2..2 + n], statistics[..]);
        assert_eq!(
            keys[2 + n..4 + n],
            ["tube_volume_rate", "support_volume_rate"]
        );
        let errors: Vec<String> = BATCHED_STATISTICS
            .iter()
            .map(|k| format!("{k}_se"))
            .collect();
        assert_eq!(keys[4 + n..4 + n + errors.len()], errors[..]);
        for (s, b) in batched_statistics() {
            let c = columns.iter().find(|c| c.key == b.se_key).unwrap();
            assert_eq!(c.unit, s.unit, "{}", b.se_key);
            assert!(c.meaning.contains(s.key));
        }
        assert_eq!(
            keys[4 + n + errors.len()..],
            [
                "batches",
                "batch_length",
                "batch_autocorrelation",
                "batches_correlated"
            ]
        );
        let mut contact: serde_json::Value = serde_json::json!({
            "name": "a", "peak_force_histogram": [], "batches": 3, "batch_length": 0.5,
            "batches_correlated": false, "batch_autocorrelation": 0.1,
        });
        for s in STATISTICS {
            contact[s.key] = serde_json::json!(1);
            if let Some(b) = s.batched {
                contact[b.se_key] = serde_json::json!(0.5);
            }
        }
        let statistics: ContactStatistics = serde_json::from_value(contact).unwrap();
        let (header, rows) = contacts_table(&serde_json::json!({ "contacts": [statistics] }));
        assert_eq!(header, keys, "no column but the table's");
        assert_eq!(rows[0][2 + n], "", "no wear: an empty cell");
    }
}
