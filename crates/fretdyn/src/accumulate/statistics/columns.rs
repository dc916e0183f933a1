//! The one table of per-contact statistics (THEORY §5), as [`crate::output::variables`] is for
//! the time histories and ripgrep's `flags/defs.rs` for its flags: per statistic of
//! [`ContactStatistics`], its key (the field, the key of `summary.json`, the column of
//! `contacts.csv`), unit, readable name, meaning, Code_Aster name, value, whether its standard
//! error is estimated by batch means (and how to read it from [`StandardErrors`]), and whether
//! `study.csv` and `blocks.csv` have it.
//!
//! Derived from it: the batch-means list [`BATCHED_STATISTICS`] and [`StandardErrors::values`],
//! the columns of `contacts.csv` and `contacts_columns.csv`
//! ([`crate::output::contacts_table`]), the statistics of `study.csv` ([`STUDY_STATISTICS`]),
//! the header and rows of `blocks.csv` ([`block_columns`]), the Python package's
//! `statistics_columns()` and block columns, and the CLI's plot labels. Adding a statistic:
//! its field in [`ContactStatistics`] and how [`super::accumulator`] forms it, and its row
//! here (a batched one also its `_se` field in [`StandardErrors`] and its batch mean in
//! `ContactAccumulator::batch_values`, at its [`Batched::index`]).

use std::fmt;

use super::report::{ContactStatistics, StandardErrors};

/// The value of a statistic: a count or a real number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    /// A count (impacts).
    Count(u64),
    /// A real number.
    Real(f64),
}

impl Value {
    /// The value as a real number.
    pub fn as_f64(self) -> f64 {
        match self {
            Value::Count(n) => n as f64,
            Value::Real(x) => x,
        }
    }
}

/// As Rust writes the number: a count as an integer, a real as the shortest text that reads
/// back to the same `f64` (`blocks.csv`).
impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Count(n) => n.fmt(f),
            Value::Real(x) => x.fmt(f),
        }
    }
}

/// What kind of number a statistic is ([`Value`]'s variants).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A count (an integer in `blocks.csv` and the Python tables).
    Count,
    /// A real number.
    Real,
}

/// How a statistic's standard error is estimated by batch means (THEORY §5).
#[derive(Debug, Clone, Copy)]
pub struct Batched {
    /// Its place among the batch means: in [`BATCHED_STATISTICS`], [`StandardErrors::values`],
    /// the `_se` columns of `contacts.csv` and the checkpoint's batch moments (whose order
    /// must not change). 0 is the wear work rate, whose error a target relative error
    /// checks.
    pub index: usize,
    /// The key of its standard error, `<key>_se` (a field of [`StandardErrors`]).
    pub se_key: &'static str,
    /// Its standard error.
    pub se: fn(&StandardErrors) -> Option<f64>,
    /// Where [`super::batch_means`] writes it.
    pub(super) se_mut: fn(&mut StandardErrors) -> &mut Option<f64>,
    /// An rms: its batch means are mean squares, and `SE(rms) = SE(mean square) / (2 rms)`.
    pub rms: bool,
}

/// A per-contact statistic: a row of [`STATISTICS`].
#[derive(Debug, Clone, Copy)]
pub struct Statistic {
    /// fretdyn's key: the field of [`ContactStatistics`], the key of `summary.json`'s
    /// `contacts[k]`, the column of `contacts.csv` (`<contact>.<key>` in `study.csv`).
    pub key: &'static str,
    /// SI unit (`1` for a number without one).
    pub unit: &'static str,
    /// A short readable name, for labels (a plot's axis: `<long_name> (<unit>)`).
    pub long_name: &'static str,
    /// What it is (the `meaning` of `contacts_columns.csv`).
    pub meaning: &'static str,
    /// What Code_Aster calls it: `PARAMETER (CALCUL)` in the table of `POST_DYNA_MODA_T`
    /// (`CALCUL` names the row of the contact the parameter is read on), or the relation that
    /// gives it from Code_Aster's values; empty when Code_Aster has no such value.
    /// docs/CODE_ASTER.md says where the definitions differ.
    pub code_aster: &'static str,
    /// A count or a real number: the variant of [`Self::value`].
    pub kind: Kind,
    /// Its value in a contact's statistics.
    pub value: fn(&ContactStatistics) -> Value,
    /// Its standard error by batch means, if it has one.
    pub batched: Option<Batched>,
    /// A column of `study.csv` (`<contact>.<key>`, and `<contact>.<key>_se` when batched).
    pub study: bool,
    /// A column of `blocks.csv` (and of the Python `Result.blocks`).
    pub blocks: bool,
}

impl Statistic {
    /// The unit for a label: none for a number without one.
    pub fn label_unit(&self) -> &'static str {
        if self.unit == "1" { "" } else { self.unit }
    }

    /// Also a column of `study.csv`.
    const fn study(mut self) -> Self {
        self.study = true;
        self
    }

    /// Also a column of `blocks.csv`.
    const fn blocks(mut self) -> Self {
        self.blocks = true;
        self
    }

    /// With a standard error by batch means.
    const fn batched(mut self, batched: Batched) -> Self {
        self.batched = Some(batched);
        self
    }
}

/// A row of [`STATISTICS`]: the field `$field` (its key) of kind `Count` or `Real`, its unit,
/// readable name, Code_Aster name and meaning.
macro_rules! statistic {
    ($field:ident, $kind:ident, $unit:expr, $long_name:expr, $code_aster:expr, $meaning:expr $(,)?) => {
        Statistic {
            key: stringify!($field),
            unit: $unit,
            long_name: $long_name,
            meaning: $meaning,
            code_aster: $code_aster,
            kind: Kind::$kind,
            value: |s| Value::$kind(s.$field),
            batched: None,
            study: false,
            blocks: false,
        }
    };
}

/// The batch means' place `$index` of a statistic, its standard error the field `$se` of
/// [`StandardErrors`], `rms` for an rms.
macro_rules! batched {
    ($index:expr, $se:ident $(, $rms:ident)?) => {
        Batched {
            index: $index,
            se_key: stringify!($se),
            se: |e| e.$se,
            se_mut: |e| &mut e.$se,
            rms: batched!(@rms $($rms)?),
        }
    };
    (@rms rms) => { true };
    (@rms) => { false };
}

/// The per-contact statistics, in the order of [`ContactStatistics`]' fields and of the
/// columns of `contacts.csv`, `study.csv` and `blocks.csv`.
pub const STATISTICS: &[Statistic] = &[
    statistic!(
        duration,
        Real,
        "s",
        "duration",
        "INST_FIN - INST_INIT",
        "duration of the statistics window [t_start, t_end]",
    ),
    statistic!(
        impacts,
        Count,
        "1",
        "impacts",
        "number of CALCUL='IMPACT' rows (OPTION='IMPACT')",
        "impacts started in the window (an opening longer than rest_duration ends an impact)",
    )
    .blocks(),
    statistic!(
        impacts_per_second,
        Real,
        "1/s",
        "impact rate",
        "NB_CHOC_S (STAT_CHOC)",
        "impacts per second",
    )
    .batched(batched!(2, impacts_per_second_se))
    .study()
    .blocks(),
    statistic!(
        rebounds_per_impact,
        Real,
        "1",
        "rebounds per impact",
        "NB_REBON_CHOC - 1 (STAT_CHOC)",
        "mean number of rebounds (openings shorter than rest_duration) per finished impact",
    ),
    statistic!(
        contact_duration_mean,
        Real,
        "s",
        "mean impact duration",
        "T_CHOC_MOYEN (STAT_CHOC)",
        "mean duration of the finished impacts, first closing to last opening",
    ),
    statistic!(
        contact_duration_min,
        Real,
        "s",
        "shortest impact duration",
        "T_CHOC_MINI (STAT_CHOC)",
        "shortest finished impact",
    ),
    statistic!(
        contact_duration_max,
        Real,
        "s",
        "longest impact duration",
        "T_CHOC_MAXI (STAT_CHOC)",
        "longest finished impact",
    ),
    statistic!(
        contact_time_fraction,
        Real,
        "1",
        "fraction of the time in contact",
        "%_T_CHOC / 100 (STAT_CHOC)",
        "fraction of the window spent closed",
    )
    .batched(batched!(3, contact_time_fraction_se))
    .study()
    .blocks(),
    statistic!(
        stick_time_fraction,
        Real,
        "1",
        "fraction of the time sticking",
        "",
        "fraction of the window spent closed and sticking",
    )
    .batched(batched!(4, stick_time_fraction_se))
    .study()
    .blocks(),
    statistic!(
        slip_time_fraction,
        Real,
        "1",
        "fraction of the time slipping",
        "",
        "fraction of the window spent closed and sliding",
    )
    .batched(batched!(5, slip_time_fraction_se))
    .study()
    .blocks(),
    statistic!(
        normal_force_mean,
        Real,
        "N",
        "mean normal force",
        "MOYEN_T_TOTAL (FORCE_NORMALE)",
        "mean normal force R_N over the whole window",
    )
    .batched(batched!(6, normal_force_mean_se))
    .study()
    .blocks(),
    statistic!(
        normal_force_mean_in_contact,
        Real,
        "N",
        "mean normal force in contact",
        "MOYEN_T_CHOC (FORCE_NORMALE)",
        "mean normal force over the time spent closed",
    ),
    statistic!(
        normal_force_rms,
        Real,
        "N",
        "RMS normal force",
        "RMS_T_TOTAL (FORCE_NORMALE)",
        "RMS normal force over the whole window",
    )
    .batched(batched!(7, normal_force_rms_se, rms))
    .study()
    .blocks(),
    statistic!(
        normal_force_max,
        Real,
        "N",
        "maximum normal force",
        "MAXI (FORCE_NORMALE); F_MAX_ABS (GLOBAL)",
        "largest normal force",
    )
    .study()
    .blocks(),
    statistic!(
        tangential_force_mean,
        Real,
        "N",
        "mean tangential force",
        "",
        "mean tangential force magnitude |R_T| over the whole window",
    )
    .batched(batched!(8, tangential_force_mean_se)),
    statistic!(
        tangential_force_mean_in_contact,
        Real,
        "N",
        "mean tangential force in contact",
        "",
        "mean |R_T| over the time spent closed",
    ),
    statistic!(
        tangential_force_rms,
        Real,
        "N",
        "RMS tangential force",
        "sqrt(RMS (FORCE_TANG_1)^2 + RMS (FORCE_TANG_2)^2)",
        "RMS of |R_T| over the whole window",
    )
    .batched(batched!(9, tangential_force_rms_se, rms))
    .study()
    .blocks(),
    statistic!(
        tangential_force_max,
        Real,
        "N",
        "maximum tangential force",
        "",
        "largest |R_T|",
    ),
    statistic!(
        wear_work,
        Real,
        "J",
        "wear work",
        "",
        "friction work over the window, integral of |R_T . v_T| dt",
    ),
    statistic!(
        wear_work_rate,
        Real,
        "W",
        "wear work rate",
        "",
        "wear work rate as friction power, (1/T) integral of |R_T . v_T| dt (THEORY §5)",
    )
    .batched(batched!(0, wear_work_rate_se))
    .study()
    .blocks(),
    statistic!(
        normal_wear_work_rate,
        Real,
        "W",
        "wear work rate, R_N|v_T| definition",
        "PUIS_USURE (PUIS_USURE)",
        "wear work rate with the normal force, (1/T) integral of R_N |v_T| dt (Code_Aster's definition)",
    )
    .batched(batched!(1, normal_wear_work_rate_se))
    .study()
    .blocks(),
    statistic!(
        wear_volume,
        Real,
        "m3",
        "wear volume",
        "",
        "Archard wear volume K_wear integral of |R_T . v_T| dt (0 without statistics.wear_coefficient)",
    )
    .blocks(),
    statistic!(
        penetration_max,
        Real,
        "m",
        "largest penetration",
        "",
        "largest penetration (negative: the contact never closed; minus the smallest clearance)",
    ),
    statistic!(
        displacement_mean,
        Real,
        "m",
        "mean displacement",
        "MOYEN (DEPL_RADIAL) in a hole; MOYEN (DEPL_Y or DEPL_Z) between bars",
        "mean radial offset from the hole's centre (holes), or distance to the plane / the bars' mid-plane (planes)",
    ),
    statistic!(
        displacement_rms,
        Real,
        "m",
        "RMS displacement",
        "RMS (DEPL_RADIAL) in a hole; RMS (DEPL_Y or DEPL_Z) between bars",
        "RMS of that displacement",
    ),
    statistic!(
        displacement_min,
        Real,
        "m",
        "smallest displacement",
        "MINI (DEPL_RADIAL) in a hole; MINI (DEPL_Y or DEPL_Z) between bars",
        "smallest value of that displacement",
    ),
    statistic!(
        displacement_max,
        Real,
        "m",
        "largest displacement",
        "MAXI (DEPL_RADIAL) in a hole; MAXI (DEPL_Y or DEPL_Z) between bars",
        "largest value of that displacement",
    ),
    statistic!(
        contact_angle_mean_deg,
        Real,
        "deg",
        "mean contact angle",
        "close to MOYEN (DEPL_ANGULAIRE)",
        "circular mean of the contact angle in the hole's plane over the time spent closed",
    ),
    statistic!(
        contact_angle_spread_deg,
        Real,
        "deg",
        "spread of the contact angle",
        "close to ECART_TYPE (DEPL_ANGULAIRE)",
        "circular standard deviation of that angle",
    ),
];

/// The statistic of `key`, if it is one.
pub fn statistic(key: &str) -> Option<&'static Statistic> {
    STATISTICS.iter().find(|s| s.key == key)
}

/// Statistics with a standard error by batch means.
pub const BATCHED: usize = {
    let mut n = 0;
    let mut i = 0;
    while i < STATISTICS.len() {
        n += STATISTICS[i].batched.is_some() as usize;
        i += 1;
    }
    n
};

/// The row of [`STATISTICS`] of each batch mean, by [`Batched::index`] (checked when
/// compiled: each index once).
const BATCH_ROWS: [usize; BATCHED] = {
    let mut rows = [usize::MAX; BATCHED];
    let mut i = 0;
    while i < STATISTICS.len() {
        if let Some(b) = &STATISTICS[i].batched {
            assert!(
                b.index < BATCHED && rows[b.index] == usize::MAX,
                "the batch indices are 0, 1, … once each"
            );
            rows[b.index] = i;
        }
        i += 1;
    }
    rows
};

/// Statistics whose standard error is estimated by batch means (THEORY §5), in the order of
/// [`Batched::index`] (of [`StandardErrors`]' fields). The two rms values are estimated
/// through the mean squares.
pub const BATCHED_STATISTICS: [&str; BATCHED] = {
    let mut keys = [""; BATCHED];
    let mut i = 0;
    while i < BATCHED {
        keys[i] = STATISTICS[BATCH_ROWS[i]].key;
        i += 1;
    }
    keys
};

/// Statistics of `study.csv`.
pub const STUDY: usize = {
    let mut n = 0;
    let mut i = 0;
    while i < STATISTICS.len() {
        n += STATISTICS[i].study as usize;
        i += 1;
    }
    n
};

/// The statistics of `study.csv`, in the order of [`STATISTICS`]: `<contact>.<key>` per
/// contact, then `<contact>.<key>_se` of those with batch means.
pub const STUDY_STATISTICS: [&str; STUDY] = {
    let mut keys = [""; STUDY];
    let (mut i, mut k) = (0, 0);
    while i < STATISTICS.len() {
        if STATISTICS[i].study {
            keys[k] = STATISTICS[i].key;
            k += 1;
        }
        i += 1;
    }
    keys
};

/// The statistics with batch means, in the order of [`Batched::index`], with how.
pub fn batched_statistics() -> impl Iterator<Item = (&'static Statistic, &'static Batched)> {
    BATCH_ROWS.iter().filter_map(|&row| {
        let s = &STATISTICS[row];
        s.batched.as_ref().map(|b| (s, b))
    })
}

/// The statistics of `blocks.csv`, in their order (after `block`, `t_start`, `t_end`, `name`).
pub fn block_columns() -> impl Iterator<Item = &'static Statistic> {
    STATISTICS.iter().filter(|s| s.blocks)
}

/// The place of `key` among the batch means ([`Batched::index`]); does not compile (in a
/// const) when it has none.
pub(super) const fn batch_index(key: &str) -> usize {
    let mut i = 0;
    while i < BATCHED {
        if same(BATCHED_STATISTICS[i], key) {
            return i;
        }
        i += 1;
    }
    panic!("not a statistic with batch means")
}

/// `a == b`, in a const.
const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

impl StandardErrors {
    /// The standard errors in the order of [`BATCHED_STATISTICS`].
    pub fn values(&self) -> [Option<f64>; BATCHED] {
        std::array::from_fn(|i| STATISTICS[BATCH_ROWS[i]].batched.and_then(|b| (b.se)(self)))
    }
}

impl ContactStatistics {
    /// `(name, value, standard error)` of the statistics of [`BATCHED_STATISTICS`].
    pub fn batched(&self) -> [(&'static str, f64, Option<f64>); BATCHED] {
        std::array::from_fn(|i| {
            let s = &STATISTICS[BATCH_ROWS[i]];
            let se = s.batched.and_then(|b| (b.se)(&self.errors));
            (s.key, (s.value)(self).as_f64(), se)
        })
    }

    /// The statistics of [`BATCHED_STATISTICS`] whose relative standard error `SE/|x|`
    /// exceeds `threshold`, with it (a statistic that is 0 has none). The split of the
    /// contact time into stick and slip is left out: its smaller part is often a few steps
    /// per batch, noisy, and of no consequence for the wear (its error is reported).
    pub fn relative_errors_above(&self, threshold: f64) -> Vec<(&'static str, f64)> {
        self.batched()
            .into_iter()
            .filter(|(name, _, _)| !matches!(*name, "stick_time_fraction" | "slip_time_fraction"))
            .filter_map(|(name, x, se)| {
                let r = se? / x.abs();
                (x != 0.0 && r > threshold).then_some((name, r))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Statistics whose fields all differ: the statistic of row `i` is `i + 1`, its error
    /// `100 + i`; read from their keys, so that a field the table misses fails.
    fn distinct() -> ContactStatistics {
        let mut value = serde_json::json!({
            "name": "c", "peak_force_histogram": [], "batches": 3, "batch_length": 0.5,
            "batches_correlated": false,
        });
        for (i, row) in STATISTICS.iter().enumerate() {
            value[row.key] = serde_json::json!(i + 1);
            if let Some(b) = row.batched {
                value[b.se_key] = serde_json::json!(100.0 + i as f64);
            }
        }
        serde_json::from_value(value).expect("every field of the statistics is in the table")
    }

    /// The table is [`ContactStatistics`]: a row per scalar field, its value the field's
    /// (and the key's in `summary.json`), of its kind; every `<key>_se` of
    /// [`StandardErrors`] is a batched row's, read by its getter; nothing else is reported
    /// but the name, the histogram and the batches.
    #[test]
    fn the_table_is_the_fields_of_the_statistics() {
        let s = distinct();
        let json = serde_json::to_value(&s).unwrap();
        for (i, row) in STATISTICS.iter().enumerate() {
            assert_eq!((row.value)(&s).as_f64(), (i + 1) as f64, "{}", row.key);
            assert_eq!(json[row.key].as_f64(), Some((i + 1) as f64), "{}", row.key);
            let count = matches!((row.value)(&s), Value::Count(_));
            assert_eq!(count, row.kind == Kind::Count, "{}", row.key);
            if let Some(b) = row.batched {
                assert_eq!(b.se_key, format!("{}_se", row.key));
                assert_eq!((b.se)(&s.errors), Some(100.0 + i as f64), "{}", b.se_key);
            }
            assert!(!row.long_name.is_empty() && !row.meaning.is_empty() && !row.unit.is_empty());
        }
        let others = [
            "name",
            "peak_force_histogram",
            "batches",
            "batch_length",
            "batch_autocorrelation",
            "batches_correlated",
        ];
        let mut keys: Vec<&str> = json
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .filter(|k| !others.contains(k))
            .collect();
        let mut table: Vec<&str> = STATISTICS
            .iter()
            .flat_map(|r| std::iter::once(r.key).chain(r.batched.map(|b| b.se_key)))
            .collect();
        keys.sort_unstable();
        table.sort_unstable();
        assert_eq!(keys, table);
        assert_eq!(
            STATISTICS.iter().filter(|r| r.batched.is_some()).count(),
            BATCHED
        );
    }

    /// The batch means keep their order (a checkpoint holds their moments in it; the
    /// `_se` columns of `contacts.csv` follow it), and [`StandardErrors::values`] and
    /// [`ContactStatistics::batched`] are in it.
    #[test]
    fn the_batch_means_keep_their_order() {
        assert_eq!(
            BATCHED_STATISTICS,
            [
                "wear_work_rate",
                "normal_wear_work_rate",
                "impacts_per_second",
                "contact_time_fraction",
                "stick_time_fraction",
                "slip_time_fraction",
                "normal_force_mean",
                "normal_force_rms",
                "tangential_force_mean",
                "tangential_force_rms",
            ]
        );
        let s = distinct();
        let json = serde_json::to_value(&s).unwrap();
        for (i, ((key, x, se), value)) in s.batched().into_iter().zip(s.errors.values()).enumerate()
        {
            assert_eq!(key, BATCHED_STATISTICS[i]);
            assert_eq!(Some(x), json[key].as_f64());
            assert_eq!(se, value);
            assert_eq!(se, json[format!("{key}_se")].as_f64());
        }
        let rms: Vec<&str> = batched_statistics()
            .filter(|(_, b)| b.rms)
            .map(|(s, _)| s.key)
            .collect();
        assert_eq!(rms, ["normal_force_rms", "tangential_force_rms"]);
    }

    /// `study.csv` and `blocks.csv` have the statistics of the table marked for them, in
    /// its order.
    #[test]
    fn study_and_blocks_columns_are_the_marked_rows() {
        let marked = |f: fn(&Statistic) -> bool| -> Vec<&str> {
            STATISTICS.iter().filter(|s| f(s)).map(|s| s.key).collect()
        };
        assert_eq!(STUDY_STATISTICS.to_vec(), marked(|s| s.study));
        let blocks: Vec<&str> = block_columns().map(|s| s.key).collect();
        assert_eq!(blocks, marked(|s| s.blocks));
        assert_eq!(statistic("impacts").map(|s| s.kind), Some(Kind::Count));
        assert!(statistic("peak_force_histogram").is_none());
        assert_eq!(Value::Count(12).to_string(), "12");
        assert_eq!(Value::Real(0.25).to_string(), "0.25");
    }
}
