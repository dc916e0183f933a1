//! A case given as a Python dict (JSON text from the Python side) written as TOML text for the
//! case parser, keeping the key path of every line, so that a parse error at a line of that
//! text is reported by the key path of the dict (`time.dt`, `contacts[0].normal.stiffness`)
//! instead of a position in a text the user never saw.
//!
//! A line refers to its table in the dict (no copy): the memory is the dict's and the text's.
//! A dict nested deeper than a key path can go ([`MAX_PARTS`]) is refused, naming the path
//! where it goes deeper, before any text is written: each table's header names its whole
//! path, so that the text of a chain of tables grows as the square of its depth.

use fretdyn::case::key_path::{MAX_PARTS, abbreviated};
use serde_json::{Map, Value};

/// What a line of the TOML text holds: the key path, and the table it opens (a header `[a.b]`,
/// `[[a]]`, or the first line, for the root) if it does rather than hold a `key = value`.
struct Line<'a> {
    path: String,
    table: Option<&'a Map<String, Value>>,
}

/// The TOML text of a dict and what each of its lines holds.
pub struct Document<'a> {
    pub text: String,
    lines: Vec<Line<'a>>,
}

impl<'a> Document<'a> {
    /// Writes the dict `root`; an error names the key path of a value TOML cannot hold, or of
    /// a value nested deeper than [`MAX_PARTS`] keys and indices.
    pub fn from_json(root: &'a Map<String, Value>) -> Result<Self, String> {
        deep(root, "", 0)?;
        let mut doc = Document {
            text: String::new(),
            lines: Vec::new(),
        };
        doc.push(
            "# a case from a Python dict".into(),
            String::new(),
            Some(root),
        );
        doc.table(root, "", &mut Vec::new())?;
        Ok(doc)
    }

    fn push(&mut self, text: String, path: String, table: Option<&'a Map<String, Value>>) {
        self.text.push_str(&text);
        self.text.push('\n');
        self.lines.push(Line { path, table });
    }

    /// The entries of a table: its values, then its tables and arrays of tables (whose
    /// headers, `header.key`, are absolute as TOML wants; `header` is the table's, as it is
    /// when this returns).
    fn table(
        &mut self,
        map: &'a Map<String, Value>,
        path: &str,
        header: &mut Vec<String>,
    ) -> Result<(), String> {
        for (k, v) in map {
            if !is_table(v) && !is_table_array(v) {
                let p = join(path, k);
                let text = format!("{} = {}", key(k), inline(v, &p)?);
                self.push(text, p, None);
            }
        }
        for (k, v) in map {
            let p = join(path, k);
            header.push(key(k));
            if let Value::Object(m) = v {
                self.push(format!("[{}]", header.join(".")), p.clone(), Some(m));
                self.table(m, &p, header)?;
            } else if let (true, Value::Array(items)) = (is_table_array(v), v) {
                for (i, item) in items.iter().enumerate() {
                    let pi = format!("{p}[{i}]");
                    if let Value::Object(m) = item {
                        self.push(format!("[[{}]]", header.join(".")), pi.clone(), Some(m));
                        self.table(m, &pi, header)?;
                    }
                }
            }
            header.pop();
        }
        Ok(())
    }

    /// The key path of the dict for a parse error at `line` (1-based) with `message`: the
    /// path the line holds. An error reported at a table (a tagged table such as an obstacle
    /// is read whole) is narrowed to the key: for a missing or unknown field, the table's path
    /// and the field (the table's path alone when the unknown field is the table itself:
    /// one of its name without other keys among those the message expects); for
    /// a value of the wrong type, the one value of the table shown as the message shows it
    /// (`string "big"`), when only one is.
    pub fn path_at(&self, line: usize, message: &str) -> Option<String> {
        let held = self.lines.get(line.checked_sub(1)?)?;
        let Some(table) = held.table else {
            return Some(held.path.clone());
        };
        let field = |prefix: &str| {
            message
                .strip_prefix(prefix)
                .and_then(|rest| rest.split('`').next())
        };
        if let Some(f) = field("unknown field `") {
            // a table the case does not have is reported at its own header; so is an unknown
            // key of a table read whole (a tagged table, the obstacle): the table's path alone
            // for a table of that name, unless the table has other keys among those expected
            // (`[time.a]` holding a table `a`: the unknown `time.a`; `obstacle` holding a key
            // `obstacle` beside `gap`: `….obstacle.obstacle`)
            let own = held.path.rsplit(['.', ']']).next() == Some(f);
            let expected: Vec<&str> = message
                .split_once(", expected")
                .map(|(_, list)| list.split('`').skip(1).step_by(2).collect())
                .unwrap_or_default();
            let inside = table
                .keys()
                .any(|k| k != f && expected.contains(&k.as_str()));
            return Some(if own && !inside {
                held.path.clone()
            } else {
                join(&held.path, f)
            });
        }
        if let Some(f) = field("missing field `") {
            return Some(join(&held.path, f));
        }
        let unexpected = ["invalid type: ", "invalid value: "]
            .iter()
            .find_map(|p| message.strip_prefix(p))
            .and_then(|rest| rest.split_once(", expected"))
            .map(|(shown, _)| shown);
        let mut found = Vec::new();
        if let Some(shown) = unexpected {
            for (k, v) in table {
                leaves_shown_as(v, &join(&held.path, k), shown, &mut found);
            }
        }
        match found.as_slice() {
            [one] => Some(one.clone()),
            _ if held.path.is_empty() => None,
            _ => Some(held.path.clone()),
        }
    }
}

/// Refuses a value of `map` (at `path`, `depth` keys and indices below the root) whose key
/// path has more than [`MAX_PARTS`] parts, naming that path ([`abbreviated`] when long).
fn deep(map: &Map<String, Value>, path: &str, depth: usize) -> Result<(), String> {
    for (k, v) in map {
        within(v, &join(path, k), depth + 1)?;
    }
    Ok(())
}

fn within(v: &Value, path: &str, depth: usize) -> Result<(), String> {
    if depth > MAX_PARTS {
        return Err(format!(
            "{}: nested more than {MAX_PARTS} keys and indices deep: no key of a case is that deep (a key path has at most {MAX_PARTS} parts)",
            abbreviated(path)
        ));
    }
    match v {
        Value::Object(m) => deep(m, path, depth),
        Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                // an element's path has one part more: numbers are checked at the first
                if i == 0 || item.is_object() || item.is_array() {
                    within(item, &format!("{path}[{i}]"), depth + 1)?;
                }
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// The paths of the values under `v` that serde shows as `shown` in an error ("unexpected"
/// values: `string "a"`, `boolean `true``, `integer `5``, `floating point `1.5``).
fn leaves_shown_as(v: &Value, path: &str, shown: &str, found: &mut Vec<String>) {
    let as_shown = match v {
        Value::String(s) => format!("string {s:?}"),
        Value::Bool(b) => format!("boolean `{b}`"),
        Value::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) => format!("integer `{i}`"),
            (None, Some(f)) => format!("floating point `{f:?}`"),
            _ => String::new(),
        },
        Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                leaves_shown_as(item, &format!("{path}[{i}]"), shown, found);
            }
            return;
        }
        Value::Object(map) => {
            for (k, item) in map {
                leaves_shown_as(item, &join(path, k), shown, found);
            }
            return;
        }
        Value::Null => return,
    };
    if as_shown == shown {
        found.push(path.to_string());
    }
}

fn is_table(v: &Value) -> bool {
    v.is_object()
}

/// A non-empty array of dicts: an array of tables `[[…]]`.
fn is_table_array(v: &Value) -> bool {
    matches!(v, Value::Array(items) if !items.is_empty() && items.iter().all(Value::is_object))
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// A key, bare when TOML allows it, else quoted.
fn key(k: &str) -> String {
    let bare = !k.is_empty()
        && k.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare { k.to_string() } else { quoted(k) }
}

/// A TOML basic string.
fn quoted(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if (c as u32) < 0x20 || c as u32 == 0x7f => {
                out.push_str(&format!("\\u{:04X}", c as u32));
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A value on one line: numbers, strings, booleans, arrays and inline tables.
fn inline(v: &Value, path: &str) -> Result<String, String> {
    Ok(match v {
        Value::Null => {
            return Err(format!(
                "{path}: None is not a value of a case (leave the key out)"
            ));
        }
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) => i.to_string(),
            (None, Some(f)) if f.is_nan() => "nan".into(),
            (None, Some(f)) if f.is_infinite() => (if f > 0.0 { "inf" } else { "-inf" }).into(),
            // Debug of an f64 always has a '.' or an exponent: a TOML float
            (None, Some(f)) => format!("{f:?}"),
            (None, None) => n.to_string(),
        },
        Value::String(s) => quoted(s),
        Value::Array(items) => {
            let items = items
                .iter()
                .enumerate()
                .map(|(i, item)| inline(item, &format!("{path}[{i}]")))
                .collect::<Result<Vec<_>, _>>()?;
            format!("[{}]", items.join(", "))
        }
        Value::Object(map) => {
            let entries = map
                .iter()
                .map(|(k, item)| Ok(format!("{} = {}", key(k), inline(item, &join(path, k))?)))
                .collect::<Result<Vec<_>, String>>()?;
            if entries.is_empty() {
                "{}".into()
            } else {
                format!("{{ {} }}", entries.join(", "))
            }
        }
    })
}
