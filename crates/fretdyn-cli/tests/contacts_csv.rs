//! `contacts.csv` (the per-contact statistics of `summary.json` as a table) read back with the
//! `csv` crate: one row per contact of the case in its order, every cell the value of
//! `summary.json` bit for bit, names with commas and quotes quoted; and the glossary
//! (docs/CODE_ASTER.md) gives every column with the Code_Aster name the run folder gives.

use std::path::{Path, PathBuf};
use std::process::Command;

use fretdyn::output::contacts_table::{LEFT_OUT, columns};

mod common;
use common::{Scratch, examples};

/// Runs `case` into `dir/out` and returns the folder.
fn run(case: &Path, dir: &Path) -> PathBuf {
    let out = Command::new(env!("CARGO_BIN_EXE_fretdyn"))
        .args([
            "run",
            case.to_str().unwrap(),
            "-o",
            "out",
            "-q",
            "--no-plots",
        ])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir.join("out")
}

/// `contacts.csv` read with the `csv` crate: its header and rows.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header = reader.headers().unwrap().iter().map(String::from).collect();
    let rows = reader
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    (header, rows)
}

/// A JSON value with its numbers kept as the text written: serde_json's default parsing of
/// a 17-digit number may be one unit in the last place off, Rust's `str::parse` is not.
#[derive(Debug, Clone, PartialEq)]
enum Json {
    Object(Vec<(String, Json)>),
    Array(Vec<Json>),
    Number(String),
    Text(String),
    Flag(bool),
    Null,
}

/// A small JSON reader (the whole grammar, strings with their escapes).
struct Reader<'a> {
    text: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn parse(text: &str) -> Json {
        let mut r = Reader {
            text: text.as_bytes(),
            at: 0,
        };
        let v = r.value();
        r.blank();
        assert_eq!(r.at, r.text.len(), "trailing text");
        v
    }

    fn blank(&mut self) {
        while self.at < self.text.len() && self.text[self.at].is_ascii_whitespace() {
            self.at += 1;
        }
    }

    fn eat(&mut self, token: &str) -> bool {
        self.blank();
        if self.text[self.at..].starts_with(token.as_bytes()) {
            self.at += token.len();
            true
        } else {
            false
        }
    }

    fn value(&mut self) -> Json {
        self.blank();
        let first = self.text[self.at];
        match first {
            b'{' => {
                self.at += 1;
                let mut fields = Vec::new();
                if !self.eat("}") {
                    loop {
                        self.blank();
                        let key = self.string();
                        assert!(self.eat(":"));
                        fields.push((key, self.value()));
                        if self.eat("}") {
                            break;
                        }
                        assert!(self.eat(","), "a , or }} at byte {}", self.at);
                    }
                }
                Json::Object(fields)
            }
            b'[' => {
                self.at += 1;
                let mut items = Vec::new();
                if !self.eat("]") {
                    loop {
                        items.push(self.value());
                        if self.eat("]") {
                            break;
                        }
                        assert!(self.eat(","), "a , or ] at byte {}", self.at);
                    }
                }
                Json::Array(items)
            }
            b'"' => Json::Text(self.string()),
            _ if self.eat("true") => Json::Flag(true),
            _ if self.eat("false") => Json::Flag(false),
            _ if self.eat("null") => Json::Null,
            _ => {
                let start = self.at;
                while self.at < self.text.len()
                    && matches!(
                        self.text[self.at],
                        b'-' | b'+' | b'.' | b'e' | b'E' | b'0'..=b'9'
                    )
                {
                    self.at += 1;
                }
                assert!(self.at > start, "a value at byte {start}");
                Json::Number(String::from_utf8(self.text[start..self.at].to_vec()).unwrap())
            }
        }
    }

    fn string(&mut self) -> String {
        assert_eq!(self.text[self.at], b'"');
        self.at += 1;
        let mut bytes = Vec::new();
        loop {
            let b = self.text[self.at];
            self.at += 1;
            match b {
                b'"' => break,
                b'\\' => {
                    let e = self.text[self.at];
                    self.at += 1;
                    match e {
                        b'n' => bytes.push(b'\n'),
                        b't' => bytes.push(b'\t'),
                        b'r' => bytes.push(b'\r'),
                        b'b' => bytes.push(8),
                        b'f' => bytes.push(12),
                        b'u' => {
                            let hex =
                                std::str::from_utf8(&self.text[self.at..self.at + 4]).unwrap();
                            self.at += 4;
                            let c = char::from_u32(u32::from_str_radix(hex, 16).unwrap()).unwrap();
                            bytes.extend(c.to_string().as_bytes());
                        }
                        other => bytes.push(other),
                    }
                }
                other => bytes.push(other),
            }
        }
        String::from_utf8(bytes).unwrap()
    }
}

impl Json {
    fn get(&self, key: &str) -> Option<&Json> {
        match self {
            Json::Object(fields) => fields.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    /// The scalars of an object under their (dotted, when nested) keys; lists are left out.
    fn flatten(&self, prefix: &str, out: &mut Vec<(String, Json)>, lists: &mut Vec<String>) {
        let Json::Object(fields) = self else {
            panic!("an object")
        };
        for (k, v) in fields {
            let key = if prefix.is_empty() {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            };
            match v {
                Json::Object(_) => v.flatten(&key, out, lists),
                Json::Array(_) => lists.push(key),
                scalar => out.push((key, scalar.clone())),
            }
        }
    }
}

/// Every cell of `contacts.csv` in `dir` is the value of `summary.json` beside it, bit for
/// bit, under the same key; the rows are the contacts of `case`, in order.
fn check_against_summary(dir: &Path, case: &Path) {
    let (header, rows) = read_csv(&dir.join("contacts.csv"));
    let summary = Reader::parse(&std::fs::read_to_string(dir.join("summary.json")).unwrap());
    let Some(Json::Array(contacts)) = summary.get("contacts") else {
        panic!("summary.json has its contacts")
    };
    let names: Vec<String> = fretdyn::case::Case::from_file(case)
        .unwrap()
        .model
        .contacts
        .iter()
        .map(|c| c.name.clone())
        .collect();
    assert!(!names.is_empty());
    assert_eq!(rows.len(), names.len(), "one row per contact");
    assert_eq!(contacts.len(), names.len());
    // the documented columns, all of them and in their order: a statistic the summary gains
    // is added to the table of statistics and to the glossary
    let columns = columns();
    let documented: Vec<&str> = columns.iter().map(|c| c.key).collect();
    assert_eq!(header, documented);
    for (k, (row, contact)) in rows.iter().zip(contacts).enumerate() {
        assert_eq!(row.len(), header.len(), "row {k}");
        let cell = |key: &str| &row[header.iter().position(|h| h == key).unwrap()];
        assert_eq!(cell("contact"), &k.to_string());
        assert_eq!(cell("name"), &names[k], "the case's contacts in order");
        let (mut scalars, mut lists) = (Vec::new(), Vec::new());
        contact.flatten("", &mut scalars, &mut lists);
        assert_eq!(lists, LEFT_OUT, "only the documented lists are left out");
        for (key, value) in &scalars {
            assert!(
                header.contains(key),
                "{key} of summary.json is not a column"
            );
            let text = cell(key);
            match value {
                Json::Number(n) if n.contains(['.', 'e', 'E']) => {
                    let (a, b) = (text.parse::<f64>().unwrap(), n.parse::<f64>().unwrap());
                    assert_eq!(
                        a.to_bits(),
                        b.to_bits(),
                        "{key} of contact {k}: {text} ≠ {n}"
                    );
                }
                Json::Number(n) => assert_eq!(text, n, "{key} of contact {k}"),
                Json::Text(s) => assert_eq!(text, s, "{key} of contact {k}"),
                Json::Flag(f) => assert_eq!(text, &f.to_string(), "{key} of contact {k}"),
                Json::Null => assert_eq!(text, "", "{key} of contact {k}"),
                _ => unreachable!(),
            }
        }
        // a column the summary does not have for this contact is empty
        for (key, text) in header.iter().zip(row) {
            if key != "contact" && !scalars.iter().any(|(k, _)| k == key) {
                assert_eq!(text, "", "{key} of contact {k} is not in summary.json");
            }
        }
    }
    // the columns file names every column with its unit and Code_Aster name
    let (h, described) = read_csv(&dir.join("contacts_columns.csv"));
    assert_eq!(h, ["column", "unit", "code_aster", "meaning"]);
    assert_eq!(described.len(), columns.len());
    for (row, c) in described.iter().zip(&columns) {
        assert_eq!(row, &[c.key, c.unit, c.code_aster, c.meaning.as_ref()]);
    }
}

#[test]
fn contacts_csv_is_summary_json_as_a_table() {
    let s = Scratch::new("table");
    // four plane contacts, no wear: the wear volume rates are empty cells
    let case = examples().join("tube_three_span.toml");
    let dir = run(&case, &s.0);
    check_against_summary(&dir, &case);
    let (header, rows) = read_csv(&dir.join("contacts.csv"));
    let rate = header.iter().position(|h| h == "tube_volume_rate").unwrap();
    assert!(rows.iter().all(|r| r[rate].is_empty()));
    // five holes with wear laws: the volume rates are there
    let case = examples().join("tube_multispan_life.toml");
    let dir = s.0.join("life");
    std::fs::create_dir_all(&dir).unwrap();
    let dir = run(&case, &dir);
    check_against_summary(&dir, &case);
    let (_, rows) = read_csv(&dir.join("contacts.csv"));
    assert!(rows.iter().all(|r| r[rate].parse::<f64>().unwrap() > 0.0));
}

#[test]
fn a_name_with_commas_and_quotes_is_quoted() {
    let s = Scratch::new("quoted");
    let name = r#"plate 1, "lower" side"#;
    let case = std::fs::read_to_string(examples().join("v1a_oblique_impact.toml"))
        .unwrap()
        .replace(r#"name = "plane""#, r#"name = 'plate 1, "lower" side'"#);
    assert!(case.contains(name));
    let path = s.0.join("case.toml");
    std::fs::write(&path, case).unwrap();
    let dir = run(&path, &s.0);
    check_against_summary(&dir, &path);
    let (_, rows) = read_csv(&dir.join("contacts.csv"));
    assert_eq!(rows[0][1], name);
    let text = std::fs::read_to_string(dir.join("contacts.csv")).unwrap();
    assert!(text.contains(r#""plate 1, ""lower"" side""#), "{text}");
}

/// docs/CODE_ASTER.md's table of `contacts.csv` gives every column, in order, with the
/// Code_Aster name of [`columns`] (the one `contacts_columns.csv` gives).
#[test]
fn the_glossary_gives_every_column() {
    let doc = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/CODE_ASTER.md"),
    )
    .unwrap();
    let start = doc
        .find("<!-- contacts.csv columns -->")
        .expect("the table of contacts.csv is marked");
    let rows: Vec<Vec<String>> = doc[start..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().trim_matches('`').to_string())
                .collect()
        })
        .collect();
    let columns = columns();
    assert_eq!(rows.len(), columns.len(), "one row per column");
    for (row, c) in rows.iter().zip(&columns) {
        let or_dash = |s: &'static str| if s.is_empty() { "—" } else { s };
        assert_eq!(row[0], c.key);
        assert_eq!(row[1], or_dash(c.unit), "unit of {}", c.key);
        assert_eq!(
            row[2],
            or_dash(c.code_aster),
            "Code_Aster name of {}",
            c.key
        );
    }
}
