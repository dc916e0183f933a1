//! Errors of the TOML schema in a person's words. The `toml` crate reports an error as serde
//! words it (`invalid value: integer `-1`, expected u64`) at a byte span of the file; this
//! module finds the key at that span as the user wrote it (`output.every`,
//! `contacts[0].friction.mu`) and says what is expected in plain words
//! (`must be a whole number ≥ 1, got -1`). [`super::parse_error`] uses it for case files and
//! study files alike.
//!
//! The key comes from the file's own tree with the span of every key and value, read with
//! the spans the `toml` crate gives `toml::Spanned` (see [`spanned_form`]). A value inside a
//! tagged table (`obstacle = { type = "plane", … }`, `[structure]`) is reported at the
//! table by serde: the key is then the one value below the table that the message shows
//! (`string "z"`, a list of 2 values), when exactly one matches.

use std::ops::Range;
use std::sync::OnceLock;

use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};

use super::quantities;

/// What a schema error is at: the key as written (`contacts[0].obstacle.gap`), and the text
/// of its value in the file when the error is about one value.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Place {
    pub key: String,
    pub written: Option<String>,
}

/// The key path and plain-words message of the schema error `message` at `span` of `text`
/// (`None` for the key when it cannot be found: a syntax error, a span-less error).
pub(super) fn schema_message(
    text: &str,
    span: Option<Range<usize>>,
    message: &str,
) -> (Option<String>, String) {
    let tree = toml::from_str::<Node>(text).ok();
    let place = match (&tree, span) {
        (Some(tree), Some(span)) => place_of(tree, text, &span, message),
        _ => None,
    };
    plain_words(message, place.as_ref())
}

// ---------------------------------------------------------------------------------------------
// The file's tree with its spans
// ---------------------------------------------------------------------------------------------

/// A value of the file with the byte span the parser gives it (`None` for a table made by a
/// dotted header, `[a.b]` without `[a]`, which has no text of its own).
#[derive(Debug)]
struct Located {
    span: Option<Range<usize>>,
    node: Node,
}

#[derive(Debug)]
enum Node {
    /// A table: its keys (each with its span) and values.
    Table(Vec<(Located, Located)>),
    Array(Vec<Located>),
    Leaf(Leaf),
}

/// A value as serde shows it in an error's "unexpected" part.
#[derive(Debug, Clone, PartialEq)]
enum Leaf {
    Str(String),
    Int(i64),
    Float(f64),
    Bool(bool),
    Other,
}

/// The struct name and field names by which `toml::Spanned` asks the `toml` deserializer for
/// a value's span: read from `toml::Spanned` itself (a deserializer that records what it is
/// asked), so that they follow the crate's version rather than being copied here.
fn spanned_form() -> (&'static str, &'static [&'static str]) {
    static FORM: OnceLock<(&'static str, &'static [&'static str])> = OnceLock::new();
    *FORM.get_or_init(|| {
        let mut form = ("", &[][..]);
        let _ = toml::Spanned::<()>::deserialize(Recorder(&mut form));
        form
    })
}

/// A deserializer that records the name and fields of the struct it is asked for.
struct Recorder<'a>(&'a mut (&'static str, &'static [&'static str]));

impl<'de> Deserializer<'de> for Recorder<'_> {
    type Error = de::value::Error;

    fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Self::Error> {
        Err(de::Error::custom("not a struct"))
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        fields: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Self::Error> {
        *self.0 = (name, fields);
        Err(de::Error::custom("recorded"))
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        option unit unit_struct newtype_struct seq tuple tuple_struct map enum identifier
        ignored_any
    }
}

impl<'de> Deserialize<'de> for Located {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (name, fields) = spanned_form();
        d.deserialize_struct(name, fields, LocatedVisitor)
    }
}

impl<'de> Deserialize<'de> for Node {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(LocatedVisitor).map(|l| l.node)
    }
}

struct LocatedVisitor;

fn unspanned(node: Node) -> Located {
    Located { span: None, node }
}

impl<'de> Visitor<'de> for LocatedVisitor {
    type Value = Located;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a TOML value")
    }

    fn visit_bool<E: de::Error>(self, v: bool) -> Result<Located, E> {
        Ok(unspanned(Node::Leaf(Leaf::Bool(v))))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Located, E> {
        Ok(unspanned(Node::Leaf(Leaf::Int(v))))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Located, E> {
        Ok(unspanned(Node::Leaf(
            i64::try_from(v).map_or(Leaf::Other, Leaf::Int),
        )))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Located, E> {
        Ok(unspanned(Node::Leaf(Leaf::Float(v))))
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Located, E> {
        Ok(unspanned(Node::Leaf(Leaf::Str(v.to_string()))))
    }
    fn visit_unit<E: de::Error>(self) -> Result<Located, E> {
        Ok(unspanned(Node::Leaf(Leaf::Other)))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Located, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element::<Located>()? {
            items.push(item);
        }
        Ok(unspanned(Node::Array(items)))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Located, A::Error> {
        let (_, fields) = spanned_form();
        let mut entries = Vec::new();
        // the first key says whether this is a value with its span or a table
        let Some(first) = map.next_key::<Located>()? else {
            return Ok(unspanned(Node::Table(entries)));
        };
        if matches!(&first.node, Node::Leaf(Leaf::Str(k)) if fields.first() == Some(&k.as_str())) {
            let start: usize = map.next_value()?;
            let _ = map.next_key::<String>()?;
            let end: usize = map.next_value()?;
            let _ = map.next_key::<String>()?;
            let node: Node = map.next_value()?;
            return Ok(Located {
                span: Some(start..end),
                node,
            });
        }
        entries.push((first, map.next_value::<Located>()?));
        while let Some(key) = map.next_key::<Located>()? {
            entries.push((key, map.next_value::<Located>()?));
        }
        Ok(unspanned(Node::Table(entries)))
    }
}

/// A key or a value of the tree with its path (`contacts[0].friction.mu`) and span.
struct Entry<'a> {
    path: String,
    span: Range<usize>,
    /// The entry of a key (its span is the key's text, not its value's).
    is_key: bool,
    /// The value (of the key, for a key's entry).
    value: &'a Node,
}

/// The entries of the values of `node`, at `path`.
fn entries<'a>(node: &'a Node, path: &str, out: &mut Vec<Entry<'a>>) {
    match node {
        Node::Table(items) => {
            for (k, v) in items {
                let Node::Leaf(Leaf::Str(name)) = &k.node else {
                    continue;
                };
                let child = join(path, name);
                // the key itself (an unknown key is reported at it)
                if let Some(span) = &k.span {
                    out.push(Entry {
                        path: child.clone(),
                        span: span.clone(),
                        is_key: true,
                        value: &v.node,
                    });
                }
                located(v, child, out);
            }
        }
        Node::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                located(v, format!("{path}[{i}]"), out);
            }
        }
        Node::Leaf(_) => {}
    }
}

fn located<'a>(l: &'a Located, path: String, out: &mut Vec<Entry<'a>>) {
    entries(&l.node, &path, out);
    if let Some(span) = &l.span {
        out.push(Entry {
            path,
            span: span.clone(),
            is_key: false,
            value: &l.node,
        });
    }
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// The key of the error at `span`: the smallest key or value of the file whose span holds
/// the error's start; below a table or a list, the one value the message shows (a tagged
/// table's values are reported at the table), if exactly one does.
fn place_of(tree: &Node, text: &str, span: &Range<usize>, message: &str) -> Option<Place> {
    let mut all = Vec::new();
    entries(tree, "", &mut all);
    let at = span.start;
    let best = all
        .iter()
        .filter(|e| e.span.start <= at && (at < e.span.end || e.span == *span))
        .min_by_key(|e| e.span.end - e.span.start)?;
    let written = |e: &Entry| {
        (!e.is_key).then_some(())?;
        text.get(e.span.clone())
            .map(|t| t.trim().to_string())
            .filter(|t| t.len() <= 60 && !t.contains('\n'))
    };
    let is_leaf = |n: &Node| matches!(n, Node::Leaf(_));
    let Some(shown) = Shown::of(message) else {
        return Some(Place {
            key: best.path.clone(),
            written: is_leaf(best.value).then(|| written(best)).flatten(),
        });
    };
    if shown.matches(&best.path, best.value)
        && (is_leaf(best.value) || !matches!(shown, Shown::Leaf(_)))
    {
        return Some(Place {
            key: best.path.clone(),
            written: written(best),
        });
    }
    let below: Vec<&Entry> = all
        .iter()
        .filter(|e| {
            e.path.len() > best.path.len()
                && e.path.starts_with(&best.path)
                && (best.path.is_empty()
                    || matches!(e.path.as_bytes()[best.path.len()], b'.' | b'['))
                && shown.matches(&e.path, e.value)
        })
        .collect();
    // a key and its value are two entries of one path: the value's is the last
    let mut paths: Vec<&str> = below.iter().map(|e| e.path.as_str()).collect();
    paths.sort_unstable();
    paths.dedup();
    if paths.len() > 1 && matches!(shown, Shown::AnyArray | Shown::Table) {
        // a list or a table where a number is expected: the keys that take one number
        paths.retain(|p| quantities::quantity(p).is_some());
    }
    if let [one] = paths[..] {
        let value = below.iter().rev().find(|e| e.path == one).expect("found");
        return Some(Place {
            key: value.path.clone(),
            written: written(value),
        });
    }
    Some(Place {
        key: best.path.clone(),
        written: None,
    })
}

/// The value an error message shows as unexpected.
#[derive(Debug, Clone, PartialEq)]
enum Shown {
    Leaf(Leaf),
    /// "sequence"
    AnyArray,
    /// "invalid length n"
    Array(usize),
    /// "map"
    Table,
    /// The value of the key `name` (an untagged enum's, whose error names no value).
    Key(&'static str),
}

impl Shown {
    /// The unexpected value of serde's `invalid type: …, expected …`, `invalid value: …,
    /// expected …`, `invalid length n, expected …` and `unknown variant `…``.
    fn of(message: &str) -> Option<Self> {
        if let Some(name) = message.strip_prefix("data did not match any variant of untagged enum ")
        {
            return UNTAGGED
                .iter()
                .find(|(enum_name, _, _)| *enum_name == name.trim())
                .map(|(_, key, _)| Shown::Key(key));
        }
        if let Some(rest) = message.strip_prefix("invalid length ") {
            return rest
                .split(',')
                .next()
                .and_then(|n| n.trim().parse().ok())
                .map(Shown::Array);
        }
        if let Some(rest) = message.strip_prefix("unknown variant `") {
            return rest
                .split('`')
                .next()
                .map(|v| Shown::Leaf(Leaf::Str(v.to_string())));
        }
        let rest = ["invalid type: ", "invalid value: "]
            .iter()
            .find_map(|p| message.strip_prefix(p))?;
        let (unexpected, _) = rest.rsplit_once(", expected ")?;
        let quoted = |prefix: &str| {
            unexpected
                .strip_prefix(prefix)
                .and_then(|r| r.strip_prefix('`'))
                .and_then(|r| r.strip_suffix('`'))
        };
        Some(match unexpected {
            "sequence" => Shown::AnyArray,
            "map" => Shown::Table,
            _ => Shown::Leaf(if let Some(i) = quoted("integer ") {
                Leaf::Int(i.parse().ok()?)
            } else if let Some(x) = quoted("floating point ") {
                Leaf::Float(x.parse().ok()?)
            } else if let Some(b) = quoted("boolean ") {
                Leaf::Bool(b.parse().ok()?)
            } else if let Some(s) = unexpected.strip_prefix("string ") {
                Leaf::Str(unquote(s)?)
            } else {
                return None;
            }),
        })
    }

    fn matches(&self, path: &str, node: &Node) -> bool {
        match (self, node) {
            (Shown::Key(key), _) => path.rsplit('.').next() == Some(key),
            (Shown::Leaf(Leaf::Float(a)), Node::Leaf(Leaf::Float(b))) => {
                a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
            }
            (Shown::Leaf(a), Node::Leaf(b)) => a == b,
            (Shown::AnyArray, Node::Array(_)) => true,
            (Shown::Array(n), Node::Array(items)) => items.len() == *n,
            (Shown::Table, Node::Table(_)) => true,
            _ => false,
        }
    }
}

/// The string of serde's `"…"` (Rust's debug form; escapes other than `\"` and `\\` are
/// kept as they are).
fn unquote(s: &str) -> Option<String> {
    let inner = s.strip_prefix('"')?.strip_suffix('"')?;
    Some(inner.replace("\\\"", "\"").replace("\\\\", "\\"))
}

// ---------------------------------------------------------------------------------------------
// serde's words into a person's
// ---------------------------------------------------------------------------------------------

/// The key and message of a schema error in plain words: `must be a whole number ≥ 1
/// (a number of steps), got -1`, `unknown key (check its spelling); the keys of time are dt,
/// duration`, `must be one of "penalty", "active_set", "gauss_seidel", got "newton"`. A
/// message that is not serde's (a TOML syntax error) is returned as it is.
fn plain_words(message: &str, place: Option<&Place>) -> (Option<String>, String) {
    let key = place.map(|p| p.key.clone());
    let written = place.and_then(|p| p.written.clone());
    let known = key.as_deref().and_then(quantities::expected);
    let expected_of =
        |serde_words: &str| known.clone().unwrap_or_else(|| expected_words(serde_words));
    // invalid type / invalid value: the value does not fit the key
    if let Some(rest) = ["invalid type: ", "invalid value: "]
        .iter()
        .find_map(|p| message.strip_prefix(p))
        && let Some((unexpected, expected)) = rest.rsplit_once(", expected ")
    {
        let got = written.unwrap_or_else(|| unexpected_words(unexpected));
        return (key, format!("must be {}, got {got}", expected_of(expected)));
    }
    if let Some(rest) = message.strip_prefix("invalid length ")
        && let Some((n, expected)) = rest.split_once(", expected ")
    {
        let got = written.unwrap_or_else(|| format!("a list of {n}"));
        return (
            key,
            format!("must be {}, got {got}", expected_words(expected)),
        );
    }
    if let Some(rest) = message.strip_prefix("unknown field `")
        && let Some((field, known)) = rest.split_once('`')
    {
        // a tagged table (`obstacle = { type = …, … }`) reports its unknown key at the
        // table: the key is the table's path and the field
        let key = match key {
            Some(k) if k == field || k.ends_with(&format!(".{field}")) => k,
            Some(k) => join(&k, field),
            None => field.to_string(),
        };
        let parent = match key.rsplit_once('.') {
            Some((parent, _)) => parent.to_string(),
            None => "the file".to_string(),
        };
        let known = names(known);
        let message = if known.is_empty() {
            format!("unknown key: {parent} takes no keys")
        } else {
            format!(
                "unknown key (check its spelling): the keys of {parent} are {}",
                known.join(", ")
            )
        };
        return (Some(key), message);
    }
    if let Some(rest) = message.strip_prefix("unknown variant `")
        && let Some((variant, known)) = rest.split_once('`')
    {
        let known: Vec<String> = names(known).iter().map(|n| format!("\"{n}\"")).collect();
        let got = written.unwrap_or_else(|| format!("\"{variant}\""));
        return (
            key,
            match known.len() {
                0 => format!("takes no value here, got {got}"),
                1 => format!("must be {}, got {got}", known[0]),
                _ => format!("must be one of {}, got {got}", known.join(", ")),
            },
        );
    }
    if let Some(rest) = message.strip_prefix("missing field `")
        && let Some((field, _)) = rest.split_once('`')
    {
        let (key, table) = match key {
            // a section: [time]
            Some(k) if !k.contains(['.', '[']) => (format!("{k}.{field}"), format!("[{k}]")),
            Some(k) => (format!("{k}.{field}"), k),
            None => (field.to_string(), "the file".to_string()),
        };
        return (
            Some(key),
            format!("is missing: add {field} = … to {table} (the examples show its meaning)"),
        );
    }
    if let Some(rest) = message.strip_prefix("duplicate field `")
        && let Some((field, _)) = rest.split_once('`')
    {
        let key = key.map_or(field.to_string(), |k| {
            if k.ends_with(field) {
                k
            } else {
                format!("{k}.{field}")
            }
        });
        return (Some(key), "is given twice: keep one".to_string());
    }
    if let Some(name) = message.strip_prefix("data did not match any variant of untagged enum ") {
        let expected = match UNTAGGED.iter().find(|(n, _, _)| *n == name.trim()) {
            Some((_, _, words)) => words.to_string(),
            None => format!("one of the forms of {} shown in the examples", name.trim()),
        };
        let got = written.map_or(String::new(), |w| format!(", got {w}"));
        return (key, format!("must be {expected}{got}"));
    }
    if message == "wanted string or table" {
        let got = written.map_or(String::new(), |w| format!(", got {w}"));
        return (
            key,
            format!("must be a name in double quotes (the examples list the names){got}"),
        );
    }
    (key, message.to_string())
}

/// The untagged enums of the schema: their name, the key that takes them and what they
/// take, in words (serde's error names the enum only).
const UNTAGGED: &[(&str, &str, &str)] = &[(
    "DampingInput",
    "damping_ratio",
    "a damping ratio (a number, e.g. 0.01) or a list of damping ratios, one per mode",
)];

/// The names of serde's `expected one of `a`, `b``, `expected `a` or `b``, `expected `a``.
fn names(list: &str) -> Vec<String> {
    list.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// What serde says it expected, in plain words.
fn expected_words(expected: &str) -> String {
    let e = expected.trim();
    match e {
        "f64" | "f32" => return "a number".into(),
        "u8" | "u16" | "u32" | "u64" | "u128" | "usize" => return "a whole number ≥ 0".into(),
        "i8" | "i16" | "i32" | "i64" | "i128" | "isize" => return "a whole number".into(),
        "a boolean" => return "true or false".into(),
        "a string" | "a borrowed string" | "a character" | "a str" => {
            return "a text in double quotes".into();
        }
        "a sequence" => return "a list [ … ]".into(),
        "a map" | "a table" => return "a table { … }".into(),
        _ => {}
    }
    for prefix in [
        "an array of length ",
        "a tuple of size ",
        "a tuple of length ",
    ] {
        if let Some(n) = e.strip_prefix(prefix) {
            return format!("a list of {n} values [ … ]");
        }
    }
    if [
        "struct ",
        "internally tagged enum ",
        "struct variant ",
        "map ",
    ]
    .iter()
    .any(|p| e.starts_with(p))
    {
        return "a table { … }".into();
    }
    e.replace('`', "")
}

/// serde's unexpected value (`integer `-1``, `floating point `1.5``, `string "a"`,
/// `boolean `true``, `sequence`, `map`) as a person would write it.
fn unexpected_words(unexpected: &str) -> String {
    let quoted = |prefix: &str| {
        unexpected
            .strip_prefix(prefix)
            .and_then(|r| r.strip_prefix('`'))
            .and_then(|r| r.strip_suffix('`'))
    };
    if let Some(v) = quoted("integer ").or_else(|| quoted("boolean ")) {
        return v.to_string();
    }
    if let Some(v) = quoted("floating point ") {
        return v
            .parse::<f64>()
            .map_or_else(|_| v.to_string(), crate::error::number);
    }
    if let Some(s) = unexpected.strip_prefix("string ") {
        return s.to_string();
    }
    match unexpected {
        "sequence" => "a list".into(),
        "map" => "a table".into(),
        "unit value" => "nothing".into(),
        other => other.replace('`', ""),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spanned_form_is_read_from_toml() {
        let (name, fields) = spanned_form();
        assert!(!name.is_empty() && fields.len() == 3, "{name} {fields:?}");
    }

    /// The key at a span, in tables with headers, dotted headers (no span of their own),
    /// arrays of tables, inline tables and arrays.
    #[test]
    fn the_key_at_a_span_is_found_as_written() {
        let text = "a = 1\n[b]\nc = [1, 2]\n[x.y]\nz = \"q\"\n[[d]]\ne = { f = 'x' }\n[[d]]\ne = { f = 'y' }\n";
        let tree: Node = toml::from_str(text).unwrap();
        let at = |needle: &str| {
            let start = text.find(needle).unwrap();
            place_of(&tree, text, &(start..start + needle.len()), "").map(|p| p.key)
        };
        assert_eq!(at("2]").as_deref(), Some("b.c[1]"));
        assert_eq!(at("\"q\"").as_deref(), Some("x.y.z"));
        assert_eq!(at("'y'").as_deref(), Some("d[1].e.f"));
        assert_eq!(at("c =").as_deref(), Some("b.c"));
        // a value below a table that serde reports at the table
        let start = text.find("e = { f = 'y'").unwrap() + 4;
        let place = place_of(
            &tree,
            text,
            &(start..start + 11),
            "invalid type: string \"y\", expected f64",
        )
        .unwrap();
        assert_eq!(place.key, "d[1].e.f");
        assert_eq!(place.written.as_deref(), Some("'y'"));
    }

    #[test]
    fn serde_words_become_plain_words() {
        let place = Place {
            key: "output.every".into(),
            written: Some("-1".into()),
        };
        assert_eq!(
            plain_words("invalid value: integer `-1`, expected u64", Some(&place)).1,
            "must be a whole number ≥ 1 (a number of steps), got -1"
        );
        let place = Place {
            key: "x.flag".into(),
            written: None,
        };
        for (serde, words) in [
            (
                "invalid type: integer `1`, expected a boolean",
                "must be true or false, got 1",
            ),
            (
                "invalid type: floating point `0.30000000000000004`, expected usize",
                "must be a whole number ≥ 0, got 0.3",
            ),
            (
                "invalid type: string \"a\", expected a sequence",
                "must be a list [ … ], got \"a\"",
            ),
            (
                "invalid length 2, expected an array of length 3",
                "must be a list of 3 values [ … ], got a list of 2",
            ),
            (
                "unknown variant `x`, expected `a` or `b`",
                "must be one of \"a\", \"b\", got \"x\"",
            ),
        ] {
            assert_eq!(plain_words(serde, Some(&place)).1, words);
        }
        // a message of the TOML syntax is kept
        assert_eq!(
            plain_words("invalid floating-point number", None),
            (None, "invalid floating-point number".to_string())
        );
    }
}
