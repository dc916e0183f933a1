//! Key paths into a case file: `time.dt`, `contacts[0].friction.mu`, `contacts.0.friction.mu`,
//! `contacts.*.obstacle.clearance` (`*`: every element of an array). Studies set their
//! parameters by these paths ([`crate::apps::study`]), and so does the Python package's
//! `Case.with_`: one parser for both.
//!
//! A path is parts separated by dots; a part is a key, an index (`0`, or `[0]` after a key),
//! or `*` (`[*]` after a key). Errors name the path as far as it exists, in the notation
//! `contacts[0].obstacle`, and what is there instead.
//!
//! A path has at most [`MAX_PARTS`] parts, and parsing, setting and expanding it take time and
//! memory in proportion to its length: no key of a case is deeper, and a path built by
//! mistake (a loop appending to it) is refused at once instead of making a case as deep. A
//! path longer than [`SHOWN_CHARS`] characters is named in messages by its start and its
//! length ([`abbreviated`]).

use std::fmt;

/// The most parts a key path has. A case has no key deeper than a few parts
/// (`structure.points[0].rows[2][5]` has six); a dict given for a case is bound by it too.
pub const MAX_PARTS: usize = 64;

/// The longest key path a message names whole, in characters; a longer one is named by its
/// first [`SHOWN_CHARS`]` / 2` characters and its length.
pub const SHOWN_CHARS: usize = 200;

/// `text` as a message names a key path: whole when it has at most [`SHOWN_CHARS`]
/// characters, else its start followed by `… (a key path of N characters, the first M
/// shown)`, so that a message never silently shows part of a path.
pub fn abbreviated(text: &str) -> String {
    match start_of_long(text) {
        None => text.to_string(),
        Some((start, chars)) => format!(
            "{start}… (a key path of {chars} characters, the first {} shown)",
            SHOWN_CHARS / 2
        ),
    }
}

/// A value as a message shows it: whole up to [`SHOWN_CHARS`] characters, else its start, `…`
/// and its length (an array of ten thousand frequencies is not repeated in a message).
fn value_shown(text: &str) -> String {
    match start_of_long(text) {
        None => text.to_string(),
        Some((start, chars)) => format!("{start}… ({chars} characters)"),
    }
}

/// The first [`SHOWN_CHARS`]` / 2` characters of a text longer than [`SHOWN_CHARS`], and its
/// length in characters; `None` for a shorter text.
fn start_of_long(text: &str) -> Option<(&str, usize)> {
    text.char_indices().nth(SHOWN_CHARS)?;
    let end = text
        .char_indices()
        .nth(SHOWN_CHARS / 2)
        .map_or(text.len(), |(i, _)| i);
    Some((&text[..end], text.chars().count()))
}

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
        "'{}' is not a key path: {reason} (write keys and indices as time.dt, contacts[0].friction.mu or contacts.*.obstacle.clearance)",
        abbreviated(text)
    )]
    Syntax {
        /// The path as given.
        text: String,
        /// What is wrong.
        reason: &'static str,
    },
    /// The path has more than [`MAX_PARTS`] parts.
    #[error(
        "{}: a key path has at most {MAX_PARTS} parts and this one has more: no key of a case is that deep (write the path of one key, as time.dt or contacts[0].friction.mu)",
        abbreviated(text)
    )]
    TooDeep {
        /// The path as given.
        text: String,
    },
    /// A table has no such key.
    #[error(
        "{}: no such key; {} has {}",
        abbreviated(at),
        describe(parent),
        list(known)
    )]
    NoSuchKey {
        at: String,
        parent: String,
        /// The keys the table has.
        known: Vec<String>,
    },
    /// An array has no such element (or is empty, for `*`).
    #[error(
        "{}: no such element; {} has {}",
        abbreviated(at),
        describe(parent),
        elements(*len)
    )]
    NoSuchElement {
        at: String,
        parent: String,
        /// Elements of the array.
        len: usize,
    },
    /// A key was given where there is an array.
    #[error(
        "{}: {} is a list of {len}: give an index ({}[0]) or * for every element",
        abbreviated(at),
        describe(parent),
        abbreviated(parent)
    )]
    NotATable {
        at: String,
        parent: String,
        /// Elements of the array.
        len: usize,
    },
    /// An index or `*` was given where there is a table.
    #[error(
        "{}: {} is a table, not a list: give one of its keys ({})",
        abbreviated(at),
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
    #[error(
        "{}: {} is a value ({}), not a table or a list",
        abbreviated(at),
        abbreviated(parent),
        value_shown(value)
    )]
    Value {
        at: String,
        parent: String,
        /// The value, as TOML.
        value: String,
    },
}

impl KeyPathError {
    /// The path up to the part that fails (`contacts[0].obstacl`), in the notation
    /// `contacts[0].obstacle`; `None` for a text that is no key path.
    pub fn at(&self) -> Option<&str> {
        match self {
            KeyPathError::Syntax { .. } | KeyPathError::TooDeep { .. } => None,
            KeyPathError::NoSuchKey { at, .. }
            | KeyPathError::NoSuchElement { at, .. }
            | KeyPathError::NotATable { at, .. }
            | KeyPathError::NotAList { at, .. }
            | KeyPathError::Value { at, .. } => Some(at),
        }
    }
}

fn describe(parent: &str) -> String {
    if parent.is_empty() {
        "the case".to_string()
    } else {
        abbreviated(parent)
    }
}

fn list(keys: &[String]) -> String {
    if keys.is_empty() {
        "no keys".to_string()
    } else {
        value_shown(&keys.join(", "))
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
    /// Parses `text`; a path of more than [`MAX_PARTS`] parts is refused as soon as its part
    /// [`MAX_PARTS`]` + 1` is read.
    pub fn parse(text: &str) -> Result<Self, KeyPathError> {
        let syntax = |reason| KeyPathError::Syntax {
            text: text.to_string(),
            reason,
        };
        let too_deep = || KeyPathError::TooDeep {
            text: text.to_string(),
        };
        let mut parts = Vec::new();
        for piece in text.split('.') {
            if parts.len() > MAX_PARTS {
                return Err(too_deep());
            }
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
                if parts.len() > MAX_PARTS {
                    return Err(too_deep());
                }
            }
        }
        if parts.len() > MAX_PARTS {
            return Err(too_deep());
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
        set(root, &self.parts, value, missing, &mut String::new())
    }

    /// Every concrete path of this one in `root`, each `*` replaced by the indices of its
    /// array, in the dotted notation of study tables (`contacts.0.obstacle.clearance`).
    pub fn expand(&self, root: &toml::Value) -> Result<Vec<String>, KeyPathError> {
        let mut out = Vec::new();
        expand(
            root,
            &self.parts,
            &mut String::new(),
            &mut String::new(),
            &mut out,
        )?;
        Ok(out)
    }
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

/// `trail` extended by `part`, in the notation `contacts[0].obstacle`.
fn push(trail: &mut String, part: &Part) {
    use std::fmt::Write;
    match part {
        Part::Key(k) if trail.is_empty() => trail.push_str(k),
        Part::Key(k) => {
            trail.push('.');
            trail.push_str(k);
        }
        Part::Index(i) => {
            let _ = write!(trail, "[{i}]");
        }
        Part::Every => trail.push_str("[*]"),
    }
}

/// `dotted` extended by `key`, in the dotted notation of study tables
/// (`contacts.0.obstacle`).
fn push_dotted(dotted: &mut String, key: &str) {
    if !dotted.is_empty() {
        dotted.push('.');
    }
    dotted.push_str(key);
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

/// What is wrong with going through `v` by `part` (for the parts `v` cannot take); `trail` is
/// the path to `v`.
fn misfit(v: &toml::Value, part: &Part, trail: &str) -> KeyPathError {
    let mut at = trail.to_string();
    push(&mut at, part);
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

/// Sets `parts` below `v` to `value`. `trail`, the path to `v`, is one buffer extended and
/// cut back part by part (not a new string per part: a path's time and memory are linear in
/// its length), as it is when this returns.
fn set(
    v: &mut toml::Value,
    parts: &[Part],
    value: &toml::Value,
    missing: Missing,
    trail: &mut String,
) -> Result<(), KeyPathError> {
    let Some((head, rest)) = parts.split_first() else {
        *v = value.clone();
        return Ok(());
    };
    let len = trail.len();
    match (&mut *v, head) {
        (toml::Value::Array(items), Part::Every) if !items.is_empty() => {
            for (i, item) in items.iter_mut().enumerate() {
                push(trail, &Part::Index(i));
                set(item, rest, value, missing, trail)?;
                trail.truncate(len);
            }
            Ok(())
        }
        (toml::Value::Array(items), Part::Index(i)) if *i < items.len() => {
            push(trail, head);
            set(&mut items[*i], rest, value, missing, trail)?;
            trail.truncate(len);
            Ok(())
        }
        (toml::Value::Table(t), Part::Key(_) | Part::Index(_)) => {
            let k = next_key(head);
            if !t.contains_key(&k) {
                let creates = missing == Missing::Create && matches!(head, Part::Key(_));
                let below_is_key = matches!(rest.first(), None | Some(Part::Key(_)));
                if !(creates && below_is_key) {
                    return Err(misfit(v, head, trail));
                }
                t.insert(k.clone(), toml::Value::Table(toml::Table::new()));
            }
            let item = t.get_mut(&k).expect("present or just inserted");
            push(trail, head);
            set(item, rest, value, missing, trail)?;
            trail.truncate(len);
            Ok(())
        }
        _ => Err(misfit(v, head, trail)),
    }
}

/// Every concrete path of `parts` below `v` into `out`: `dotted` and `trail`, the path to `v`
/// in the notations `contacts.0.obstacle` and `contacts[0].obstacle`, are buffers extended
/// and cut back part by part, as in [`set`].
fn expand(
    v: &toml::Value,
    parts: &[Part],
    dotted: &mut String,
    trail: &mut String,
    out: &mut Vec<String>,
) -> Result<(), KeyPathError> {
    let Some((head, rest)) = parts.split_first() else {
        out.push(dotted.clone());
        return Ok(());
    };
    let (len_dotted, len_trail) = (dotted.len(), trail.len());
    let mut down =
        |item: &toml::Value, key: &str, part: &Part, dotted: &mut String, trail: &mut String| {
            push_dotted(dotted, key);
            push(trail, part);
            expand(item, rest, dotted, trail, out)?;
            dotted.truncate(len_dotted);
            trail.truncate(len_trail);
            Ok(())
        };
    match (v, head) {
        (toml::Value::Array(items), Part::Every) if !items.is_empty() => {
            for (i, item) in items.iter().enumerate() {
                down(item, &i.to_string(), &Part::Index(i), dotted, trail)?;
            }
            Ok(())
        }
        (toml::Value::Array(items), Part::Index(i)) if *i < items.len() => {
            down(&items[*i], &i.to_string(), head, dotted, trail)
        }
        (toml::Value::Table(t), Part::Key(k)) if t.contains_key(k) => {
            down(&t[k], k, head, dotted, trail)
        }
        (toml::Value::Table(t), Part::Index(i)) if t.contains_key(&i.to_string()) => {
            down(&t[&i.to_string()], &i.to_string(), head, dotted, trail)
        }
        _ => Err(misfit(v, head, trail)),
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
    fn a_path_deeper_than_the_bound_is_refused_at_once() {
        // a path built by mistake: 10 000 parts, refused after reading 65 of them (it took
        // 24 GB through Case.with_ before)
        let long = vec!["a"; 10_000].join(".");
        let e = KeyPath::parse(&long).unwrap_err();
        assert!(matches!(e, KeyPathError::TooDeep { .. }), "{e:?}");
        assert_eq!(
            e.to_string(),
            format!(
                "{}… (a key path of 19999 characters, the first 100 shown): a key path has at most 64 parts and this one has more: no key of a case is that deep (write the path of one key, as time.dt or contacts[0].friction.mu)",
                &long[..100]
            )
        );
        // the bound counts indices in brackets as parts, and holds exactly
        let at_bound = format!("contacts{}", "[0]".repeat(MAX_PARTS - 1));
        assert_eq!(KeyPath::parse(&at_bound).unwrap().parts.len(), MAX_PARTS);
        let beyond = format!("contacts{}", "[0]".repeat(MAX_PARTS));
        assert!(matches!(
            KeyPath::parse(&beyond),
            Err(KeyPathError::TooDeep { .. })
        ));
        let dots = vec!["a"; MAX_PARTS + 1].join(".");
        assert!(matches!(
            KeyPath::parse(&dots),
            Err(KeyPathError::TooDeep { .. })
        ));
        assert!(KeyPath::parse(&dots[2..]).is_ok());
        // a short path that is too deep is named whole
        let e = KeyPath::parse(&dots).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("{dots}: a key path has at most 64 parts")),
            "{e}"
        );
    }

    #[test]
    fn a_long_legal_path_takes_time_and_memory_in_proportion_to_its_length() {
        // 64 parts of 100 000 characters (6.4 MB): set and expand build no string per part
        // (with one per part, 208 MB were held at the deepest part, 2 GB for parts of 1 MB)
        let part = "k".repeat(100_000);
        let text = vec![part.as_str(); MAX_PARTS].join(".");
        let mut v = case();
        let path = KeyPath::parse(&text).map_err(|e| e.to_string());
        let set = path
            .as_ref()
            .map(|p| p.set(&mut v, &toml::Value::Float(1.0), Missing::Create));
        assert!(matches!(set, Ok(Ok(()))));
        let mut leaf = &v;
        for _ in 0..MAX_PARTS {
            leaf = &leaf[part.as_str()];
        }
        assert_eq!(leaf.as_float(), Some(1.0));
        let expanded = path
            .as_ref()
            .map(|p| p.expand(&v).map_err(|e| e.to_string()));
        assert!(matches!(expanded, Ok(Ok(paths)) if paths == [text.clone()]));
        // an error below it names the path by its start and its length
        let key = vec![part.as_str(); MAX_PARTS - 1].join(".");
        let below = format!("{key}.x");
        let mut w = case();
        let _ =
            KeyPath::parse(&key).map(|p| p.set(&mut w, &toml::Value::Float(1.0), Missing::Create));
        let e = KeyPath::parse(&below)
            .and_then(|p| p.set(&mut w, &toml::Value::Float(2.0), Missing::Refuse))
            .map_err(|e| e.to_string())
            .unwrap_err();
        let start = &below[..100];
        assert_eq!(
            e,
            format!(
                "{start}… (a key path of {} characters, the first 100 shown): {start}… (a key path of {} characters, the first 100 shown) is a value (1.0), not a table or a list",
                below.len(),
                key.len()
            )
        );
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
