//! A case given as a Python dict (JSON text from the Python side) written as TOML text for the
//! case parser, keeping the key path of every line, so that a parse error at a line of that
//! text is reported by the key path of the dict (`time.dt`, `contacts[0].normal.stiffness`)
//! instead of a position in a text the user never saw.

use serde_json::{Map, Value};

/// What a line of the TOML text holds: the key path, and the table it opens (a header `[a.b]`,
/// `[[a]]`, or the first line, for the root) if it does rather than hold a `key = value`.
struct Line {
    path: String,
    table: Option<Map<String, Value>>,
}

/// The TOML text of a dict and what each of its lines holds.
pub struct Document {
    pub text: String,
    lines: Vec<Line>,
}

impl Document {
    /// Writes the dict `root`; an error names the key path of a value TOML cannot hold.
    pub fn from_json(root: &Map<String, Value>) -> Result<Self, String> {
        let mut doc = Document {
            text: String::new(),
            lines: Vec::new(),
        };
        doc.push(
            "# a case from a Python dict".into(),
            String::new(),
            Some(root.clone()),
        );
        doc.table(root, "", &[])?;
        Ok(doc)
    }

    fn push(&mut self, text: String, path: String, table: Option<Map<String, Value>>) {
        self.text.push_str(&text);
        self.text.push('\n');
        self.lines.push(Line { path, table });
    }

    /// The entries of a table: its values, then its tables and arrays of tables (whose
    /// headers, `header.key`, are absolute as TOML wants).
    fn table(
        &mut self,
        map: &Map<String, Value>,
        path: &str,
        header: &[String],
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
            let mut h = header.to_vec();
            h.push(key(k));
            if let Value::Object(m) = v {
                self.push(format!("[{}]", h.join(".")), p.clone(), Some(m.clone()));
                self.table(m, &p, &h)?;
            } else if let (true, Value::Array(items)) = (is_table_array(v), v) {
                for (i, item) in items.iter().enumerate() {
                    let pi = format!("{p}[{i}]");
                    if let Value::Object(m) = item {
                        self.push(format!("[[{}]]", h.join(".")), pi.clone(), Some(m.clone()));
                        self.table(m, &pi, &h)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// The key path of the dict for a parse error at `line` (1-based) with `message`: the
    /// path the line holds. An error reported at a table (a tagged table such as an obstacle
    /// is read whole) is narrowed to the key: for a missing or unknown field, the table's path
    /// and the field (the table's path alone when the unknown field is the table itself); for
    /// a value of the wrong type, the one value of the table shown as the message shows it
    /// (`string "big"`), when only one is.
    pub fn path_at(&self, line: usize, message: &str) -> Option<String> {
        let held = self.lines.get(line.checked_sub(1)?)?;
        let Some(table) = &held.table else {
            return Some(held.path.clone());
        };
        let field = ["missing field `", "unknown field `"]
            .iter()
            .find_map(|p| message.strip_prefix(p))
            .and_then(|rest| rest.split('`').next());
        if let Some(f) = field {
            // a table the case does not have is reported at its own header
            let own = held.path.rsplit(['.', ']']).next() == Some(f);
            return Some(if own && !table.contains_key(f) {
                held.path.clone()
            } else {
                join(&held.path, f)
            });
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
