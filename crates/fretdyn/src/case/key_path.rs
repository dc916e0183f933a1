//! Key paths into a case file: `time.dt`, `contacts[0].friction.mu`, `contacts.0.friction.mu`,
//! `contacts.*.obstacle.clearance` (`*`: every element of an array). Studies set their
//! parameters by these paths ([`crate::apps::study`]), and so does the Python package's
//! `Case.with_`: one parser for both.
//!
//! A path is parts separated by dots; a part is a key, an index (`0`, or `[0]` after a key),
//! or `*` (`[*]` after a key). Errors name the path as far as it exists, in the notation
//! `contacts[0].obstacle`, and what is there instead.

use std::fmt;

/// One part of a [`KeyPath`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Part {
    /// A key of a table.
    Key(String),
    /// An element of an array (or, in a table, the key of that number).
    Index(usize),
    /// Every element of an array.
    Every,
}

/// A parsed key path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyPath {
    /// The path as given.
    pub text: String,
    /// Its parts, from the root.
    pub parts: Vec<Part>,
}

/// What a key path meets that it cannot go through. `at` is the path up to the part that
/// fails (`contacts[0].obstacl`), `parent` the path before it (`contacts[0]`, empty for the
/// case itself).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum KeyPathError {
    /// The text is not a key path.
    #[error(
        "'{text}' is not a key path: {reason} (write keys and indices as time.dt, contacts[0].friction.mu or contacts.*.obstacle.clearance)"
    )]
    Syntax {
        /// The path as given.
        text: String,
        /// What is wrong.
        reason: &'static str,
    },
    /// A table has no such key.
    #[error("{at}: no such key; {} has {}", describe(parent), list(known))]
    NoSuchKey {
        at: String,
        parent: String,
        /// The keys the table has.
        known: Vec<String>,
    },
    /// An array has no such element (or is empty, for `*`).
    #[error("{at}: no such element; {} has {}", describe(parent), elements(*len))]
    NoSuchElement {
        at: String,
        parent: String,
        /// Elements of the array.
        len: usize,
    },
    /// A key was given where there is an array.
    #[error(
        "{at}: {} is a list of {len}: give an index ({parent}[0]) or * for every element",
        describe(parent)
    )]
    NotATable {
        at: String,
        parent: String,
        /// Elements of the array.
        len: usize,
    },
    /// An index or `*` was given where there is a table.
    #[error(
        "{at}: {} is a table, not a list: give one of its keys ({})",
        describe(parent),
        list(known)
    )]
    NotAList {
        at: String,
        parent: String,
        /// The keys the table has.
        known: Vec<String>,
    },
    /// The path goes on below a value.
    #[error("{at}: {parent} is a value ({value}), not a table or a list")]
    Value {
        at: String,
        parent: String,
        /// The value, as TOML.
        value: String,
    },
}

fn describe(parent: &str) -> String {
    if parent.is_empty() {
        "the case".to_string()
    } else {
        parent.to_string()
    }
}

fn list(keys: &[String]) -> String {
    if keys.is_empty() {
        "no keys".to_string()
    } else {
        keys.join(", ")
    }
}

fn elements(len: usize) -> String {
    match len {
        0 => "no elements".to_string(),
        1 => "1 element (index 0)".to_string(),
        n => format!("{n} elements (indices 0 to {})", n - 1),
    }
}

/// What setting a path does where a key of a table is missing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Missing {
    /// The path must exist (studies: a parameter's key is checked against the base case).
    Refuse,
    /// Missing keys are added (tables for the parts before the last): the case's parser then
    /// says whether the case has such a key (`Case.with_` of the Python package).
    Create,
}

impl KeyPath {
    /// Parses `text`.
    pub fn parse(text: &str) -> Result<Self, KeyPathError> {
        let syntax = |reason| KeyPathError::Syntax {
            text: text.to_string(),
            reason,
        };
        let mut parts = Vec::new();
        for piece in text.split('.') {
            let (head, mut rest) = match piece.find('[') {
                Some(i) => piece.split_at(i),
                None => (piece, ""),
            };
            match head {
                "" if rest.is_empty() => return Err(syntax("it has an empty part")),
                "" if parts.is_empty() => return Err(syntax("it starts with an index")),
                "" => {}
                "*" => parts.push(Part::Every),
                h if h.bytes().all(|b| b.is_ascii_digit()) => {
                    parts.push(Part::Index(
                        h.parse().map_err(|_| syntax("an index is too large"))?,
                    ));
                }
                h => parts.push(Part::Key(h.to_string())),
            }
            while !rest.is_empty() {
                let Some(close) = rest.find(']') else {
                    return Err(syntax("a [ is not closed"));
                };
                let inside = &rest[1..close];
                parts.push(match inside {
                    "*" => Part::Every,
                    i if !i.is_empty() && i.bytes().all(|b| b.is_ascii_digit()) => {
                        Part::Index(i.parse().map_err(|_| syntax("an index is too large"))?)
                    }
                    _ => return Err(syntax("an index in [ ] is a number or *")),
                });
                rest = &rest[close + 1..];
                if !rest.is_empty() && !rest.starts_with('[') {
                    return Err(syntax("a ] is followed by neither . nor ["));
                }
            }
        }
        Ok(Self {
            text: text.to_string(),
            parts,
        })
    }

    /// Sets the value at this path in `root` (every element for a `*`) to `value`.
    pub fn set(
        &self,
        root: &mut toml::Value,
        value: &toml::Value,
        missing: Missing,
    ) -> Result<(), KeyPathError> {
        set(root, &self.parts, value, missing, String::new())
    }

    /// Every concrete path of this one in `root`, each `*` replaced by the indices of its
    /// array, in the dotted notation of study tables (`contacts.0.obstacle.clearance`).
    pub fn expand(&self, root: &toml::Value) -> Result<Vec<String>, KeyPathError> {
        let mut out = Vec::new();
        expand(root, &self.parts, String::new(), String::new(), &mut out)?;
        Ok(out)
    }
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

/// `trail` extended by `part`, in the notation `contacts[0].obstacle`.
fn shown(trail: &str, part: &Part) -> String {
    match part {
        Part::Key(k) if trail.is_empty() => k.clone(),
        Part::Key(k) => format!("{trail}.{k}"),
        Part::Index(i) => format!("{trail}[{i}]"),
        Part::Every => format!("{trail}[*]"),
    }
}

/// The table key a part stands for (an index in a table is the key of that number).
fn next_key(part: &Part) -> String {
    match part {
        Part::Key(k) => k.clone(),
        Part::Index(i) => i.to_string(),
        Part::Every => "*".to_string(),
    }
}

fn keys(t: &toml::Table) -> Vec<String> {
    t.keys().cloned().collect()
}

/// What is wrong with going through `v` by `part` (for the parts `v` cannot take).
fn misfit(v: &toml::Value, part: &Part, trail: &str) -> KeyPathError {
    let at = shown(trail, part);
    let parent = trail.to_string();
    match (v, part) {
        (toml::Value::Table(t), Part::Key(_)) => KeyPathError::NoSuchKey {
            at,
            parent,
            known: keys(t),
        },
        (toml::Value::Table(t), _) => KeyPathError::NotAList {
            at,
            parent,
            known: keys(t),
        },
        (toml::Value::Array(items), Part::Key(_)) => KeyPathError::NotATable {
            at,
            parent,
            len: items.len(),
        },
        (toml::Value::Array(items), _) => KeyPathError::NoSuchElement {
            at,
            parent,
            len: items.len(),
        },
        (other, _) => KeyPathError::Value {
            at,
            parent,
            value: other.to_string(),
        },
    }
}

fn set(
    v: &mut toml::Value,
    parts: &[Part],
    value: &toml::Value,
    missing: Missing,
    trail: String,
) -> Result<(), KeyPathError> {
    let Some((head, rest)) = parts.split_first() else {
        *v = value.clone();
        return Ok(());
    };
    let next = shown(&trail, head);
    match (&mut *v, head) {
        (toml::Value::Array(items), Part::Every) if !items.is_empty() => {
            for (i, item) in items.iter_mut().enumerate() {
                set(item, rest, value, missing, format!("{trail}[{i}]"))?;
            }
            Ok(())
        }
        (toml::Value::Array(items), Part::Index(i)) if *i < items.len() => {
            set(&mut items[*i], rest, value, missing, next)
        }
        (toml::Value::Table(t), Part::Key(_) | Part::Index(_)) => {
            let k = next_key(head);
            if !t.contains_key(&k) {
                let creates = missing == Missing::Create && matches!(head, Part::Key(_));
                let below_is_key = matches!(rest.first(), None | Some(Part::Key(_)));
                if !(creates && below_is_key) {
                    return Err(misfit(v, head, &trail));
                }
                t.insert(k.clone(), toml::Value::Table(toml::Table::new()));
            }
            let item = t.get_mut(&k).expect("present or just inserted");
            set(item, rest, value, missing, next)
        }
        _ => Err(misfit(v, head, &trail)),
    }
}

fn expand(
    v: &toml::Value,
    parts: &[Part],
    dotted: String,
    trail: String,
    out: &mut Vec<String>,
) -> Result<(), KeyPathError> {
    let Some((head, rest)) = parts.split_first() else {
        out.push(dotted);
        return Ok(());
    };
    let join = |p: &str| {
        if dotted.is_empty() {
            p.to_string()
        } else {
            format!("{dotted}.{p}")
        }
    };
    match (v, head) {
        (toml::Value::Array(items), Part::Every) if !items.is_empty() => {
            for (i, item) in items.iter().enumerate() {
                let t = format!("{trail}[{i}]");
                expand(item, rest, join(&i.to_string()), t, out)?;
            }
            Ok(())
        }
        (toml::Value::Array(items), Part::Index(i)) if *i < items.len() => expand(
            &items[*i],
            rest,
            join(&i.to_string()),
            shown(&trail, head),
            out,
        ),
        (toml::Value::Table(t), Part::Key(k)) if t.contains_key(k) => {
            expand(&t[k], rest, join(k), shown(&trail, head), out)
        }
        (toml::Value::Table(t), Part::Index(i)) if t.contains_key(&i.to_string()) => expand(
            &t[&i.to_string()],
            rest,
            join(&i.to_string()),
            shown(&trail, head),
            out,
        ),
        _ => Err(misfit(v, head, &trail)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case() -> toml::Value {
        toml::from_str(
            "[time]\ndt = 1e-6\n[[contacts]]\nname = \"a\"\nobstacle = { type = \"circle\", clearance = 1e-4 }\n\
             [[contacts]]\nname = \"b\"\nobstacle = { type = \"circle\", clearance = 2e-4 }\n",
        )
        .unwrap()
    }

    fn set(v: &mut toml::Value, key: &str, x: f64, missing: Missing) -> Result<(), String> {
        KeyPath::parse(key)
            .and_then(|p| p.set(v, &toml::Value::Float(x), missing))
            .map_err(|e| e.to_string())
    }

    #[test]
    fn brackets_and_dots_are_the_same_path() {
        for key in [
            "contacts[1].obstacle.clearance",
            "contacts.1.obstacle.clearance",
        ] {
            let mut v = case();
            set(&mut v, key, 3e-4, Missing::Refuse).unwrap();
            assert_eq!(
                v["contacts"][1]["obstacle"]["clearance"].as_float(),
                Some(3e-4)
            );
            assert_eq!(
                v["contacts"][0]["obstacle"]["clearance"].as_float(),
                Some(1e-4)
            );
        }
        for key in [
            "contacts.*.obstacle.clearance",
            "contacts[*].obstacle.clearance",
        ] {
            let mut v = case();
            set(&mut v, key, 5e-4, Missing::Refuse).unwrap();
            for c in 0..2 {
                assert_eq!(
                    v["contacts"][c]["obstacle"]["clearance"].as_float(),
                    Some(5e-4)
                );
            }
            let p = KeyPath::parse(key).unwrap();
            assert_eq!(
                p.expand(&case()).unwrap(),
                [
                    "contacts.0.obstacle.clearance",
                    "contacts.1.obstacle.clearance"
                ]
            );
        }
    }

    #[test]
    fn errors_name_the_path_as_far_as_it_exists_and_what_is_there() {
        let cases = [
            (
                "contacts[0].obstacle.clearanc",
                "contacts[0].obstacle.clearanc: no such key; contacts[0].obstacle has clearance, type",
            ),
            (
                "contacts[2].obstacle.clearance",
                "contacts[2]: no such element; contacts has 2 elements (indices 0 to 1)",
            ),
            (
                "contacts.obstacle",
                "contacts.obstacle: contacts is a list of 2: give an index (contacts[0]) or * for every element",
            ),
            (
                "time[0]",
                "time[0]: time is a table, not a list: give one of its keys (dt)",
            ),
            (
                "time.dt.x",
                "time.dt.x: time.dt is a value (0.000001), not a table or a list",
            ),
            ("tim.dt", "tim: no such key; the case has contacts, time"),
        ];
        for (key, message) in cases {
            let mut v = case();
            assert_eq!(set(&mut v, key, 1.0, Missing::Refuse).unwrap_err(), message);
        }
        for bad in [
            "",
            "time..dt",
            "[0].x",
            "contacts[0",
            "contacts[x]",
            "contacts[0]x",
        ] {
            assert!(matches!(
                KeyPath::parse(bad),
                Err(KeyPathError::Syntax { .. })
            ));
        }
    }

    #[test]
    fn create_adds_missing_keys_and_tables_but_no_elements() {
        let mut v = case();
        set(&mut v, "output.every", 10.0, Missing::Create).unwrap();
        assert_eq!(v["output"]["every"].as_float(), Some(10.0));
        set(&mut v, "contacts.*.friction.mu", 0.2, Missing::Create).unwrap();
        assert_eq!(v["contacts"][1]["friction"]["mu"].as_float(), Some(0.2));
        // the same path refused when it must exist
        let mut w = case();
        assert!(set(&mut w, "output.every", 10.0, Missing::Refuse).is_err());
        // an element is never created, nor a list
        assert!(set(&mut v, "contacts[2].name", 1.0, Missing::Create).is_err());
        assert!(set(&mut v, "loads[0].force", 1.0, Missing::Create).is_err());
    }
}
