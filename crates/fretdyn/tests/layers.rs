//! The library's layering (`docs/ARCHITECTURE.md`, "Layers"), checked on its source text:
//!
//! 1. **Folders import downwards only.** Every top-level module of `crates/fretdyn/src` has a
//!    rank in [`LAYERS`]; a module may import (by `use` or by a `crate::…` path) only modules of
//!    a lower rank or its own folder. A new top-level module fails until it is given its place.
//! 2. **No cycle between files.** Inside a folder, the files' imports form no cycle: a `mod.rs`
//!    that `pub use`s its children is fine, a `mod.rs` that holds code its children import while
//!    it imports them is not.
//! 3. **No file over [`MAX_LINES`] lines** unless its top doc comment (`//!`) says why it is
//!    "one concept".
//!
//! The imports are read from the text (comments, strings and `#[cfg(test)]` modules left out):
//! `use crate::…`, `use super::…`, `use self::…`, `use child::…` with their `{…}` groups, and
//! every `crate::a::b` and `super::a::b` path in the code.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The top-level modules from the lowest layer to the highest.
const LAYERS: &[&str] = &[
    "error",
    "files",
    "numerics",
    "structure",
    "loads",
    "contact",
    "wear",
    "model",
    "settings",
    "accumulate",
    "integrator",
    "case",
    "output",
    "apps",
    "testing",
    ROOT,
    "prelude",
];

/// The crate root (`lib.rs`) in [`LAYERS`]: its re-exports are for users and for the prelude,
/// not for the layers below (they import the module that holds an item).
const ROOT: &str = "(crate root)";

/// Longest library file without a reason.
const MAX_LINES: usize = 800;

/// A module path (`contact::tangential::active_set`; the crate root is empty) and its file.
struct Source {
    module: Vec<String>,
    path: PathBuf,
    text: String,
}

fn sources() -> Vec<Source> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = Vec::new();
    let mut stack = vec![root.clone()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(&root).unwrap().with_extension("");
                let mut module: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if matches!(module.last().map(String::as_str), Some("mod" | "lib")) {
                    module.pop();
                }
                let text = std::fs::read_to_string(&path).unwrap();
                out.push(Source { module, path, text });
            }
        }
    }
    out.sort_by(|a, b| a.module.cmp(&b.module));
    out
}

/// The code without comments, string and char literals (each replaced by a space) and without
/// the `#[cfg(test)]` items.
fn code_only(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        let rest = &text[i..];
        if rest.starts_with("//") {
            i += rest.find('\n').unwrap_or(rest.len());
        } else if rest.starts_with("/*") {
            i += rest.find("*/").map_or(rest.len(), |k| k + 2);
        } else if let Some(hashes) = raw_string_start(rest) {
            let close = format!("\"{}", "#".repeat(hashes));
            let open = 2 + hashes;
            i += open
                + rest[open..]
                    .find(&close)
                    .map_or(rest.len(), |k| k + close.len());
            out.push(' ');
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push(' ');
        } else if b[i] == b'\'' && char_literal_len(rest).is_some() {
            i += char_literal_len(rest).unwrap();
            out.push(' ');
        } else {
            let c = rest.chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    strip_test_items(&out)
}

/// `r"`, `r#"`, `br"`…: the number of `#`.
fn raw_string_start(s: &str) -> Option<usize> {
    let s = s.strip_prefix('b').unwrap_or(s);
    let s = s.strip_prefix('r')?;
    let hashes = s.len() - s.trim_start_matches('#').len();
    s[hashes..].starts_with('"').then_some(hashes)
}

/// Length of a char literal at the start of `s` (`'a'`, `'\n'`, `'{'`), `None` for a lifetime.
fn char_literal_len(s: &str) -> Option<usize> {
    let mut chars = s.char_indices().skip(1);
    let (_, c) = chars.next()?;
    if c == '\\' {
        let end = s[2..].find('\'')?;
        return Some(end + 3);
    }
    let (k, close) = chars.next()?;
    (close == '\'').then_some(k + 1)
}

/// The text without each `#[cfg(test)]` item (the attribute through the item's closing brace
/// or semicolon).
fn strip_test_items(code: &str) -> String {
    let mut out = String::new();
    let mut rest = code;
    while let Some(k) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..k]);
        let item = &rest[k..];
        let mut depth = 0usize;
        let mut end = item.len();
        for (j, c) in item.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = j + 1;
                        break;
                    }
                }
                ';' if depth == 0 => {
                    end = j + 1;
                    break;
                }
                _ => {}
            }
        }
        rest = &item[end..];
    }
    out.push_str(rest);
    out
}

/// The paths a `use` tree names: `a::{b, c::{d, e as f}}` → `a::b`, `a::c::d`, `a::c::e`.
fn expand(tree: &str) -> Vec<String> {
    let tree = tree.trim();
    let Some(open) = tree.find('{') else {
        let path = tree.split(" as ").next().unwrap().trim();
        return vec![path.trim_end_matches("::").to_string()];
    };
    let prefix = tree[..open].trim().trim_end_matches("::");
    let inner = &tree[open + 1..tree.rfind('}').unwrap()];
    let mut items = Vec::new();
    let (mut depth, mut start) = (0, 0);
    for (j, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&inner[start..j]);
                start = j + 1;
            }
            _ => {}
        }
    }
    items.push(&inner[start..]);
    items
        .into_iter()
        .filter(|item| !item.trim().is_empty())
        .flat_map(expand)
        .map(|p| match (prefix.is_empty(), p.as_str()) {
            (true, _) => p,
            (false, "self") => prefix.to_string(),
            (false, _) => format!("{prefix}::{p}"),
        })
        .collect()
}

/// One import: the path as written and whether it is a re-export (`pub use`).
struct Import {
    path: String,
    reexport: bool,
}

fn imports(code: &str) -> Vec<Import> {
    let mut out = Vec::new();
    // `use` statements
    let words: Vec<(usize, &str)> = code
        .match_indices(|c: char| !(c.is_alphanumeric() || c == '_'))
        .scan(0, |start, (k, sep)| {
            let word = (*start, &code[*start..k]);
            *start = k + sep.len();
            Some(word)
        })
        .filter(|(_, w)| !w.is_empty())
        .collect();
    for &(k, word) in &words {
        if word != "use" {
            continue;
        }
        let end = k + code[k..].find(';').unwrap();
        let before = code[..k].trim_end();
        let reexport = before.ends_with("pub")
            || (before.ends_with(')') && {
                let open = before.rfind('(').unwrap();
                before[..open].trim_end().ends_with("pub")
            });
        for path in expand(&code[k + 3..end]) {
            out.push(Import { path, reexport });
        }
    }
    // inline `crate::…` and `super::…` paths
    let inline = code
        .match_indices("crate::")
        .chain(code.match_indices("super::"));
    for (k, _) in inline {
        let preceded = code[..k].chars().next_back();
        if preceded.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        let tail = &code[k..];
        let len = tail
            .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
            .unwrap_or(tail.len());
        out.push(Import {
            path: tail[..len].trim_end_matches(':').to_string(),
            reexport: false,
        });
    }
    out
}

/// The module `from` imports through `path`: the longest module that prefixes the absolute
/// path.
fn resolve(from: &[String], path: &str, modules: &BTreeSet<Vec<String>>) -> Option<Vec<String>> {
    let mut segments: Vec<String> = Vec::new();
    let parts: Vec<&str> = path.split("::").map(str::trim).collect();
    match parts[0] {
        "crate" => {}
        "self" => segments.extend(from.iter().cloned()),
        "super" => segments.extend(from[..from.len().saturating_sub(1)].iter().cloned()),
        child => {
            // `use child::…` from a module with that child; anything else is another crate
            let mut candidate = from.to_vec();
            candidate.push(child.to_string());
            if !modules.contains(&candidate) {
                return None;
            }
            segments = from.to_vec();
        }
    }
    let skip = usize::from(matches!(parts[0], "crate" | "self" | "super"));
    for part in &parts[skip..] {
        match *part {
            "super" => {
                segments.pop();
            }
            "self" | "" => {}
            p => segments.push(p.to_string()),
        }
    }
    (0..=segments.len())
        .rev()
        .map(|k| segments[..k].to_vec())
        .find(|m| modules.contains(m))
}

fn is_ancestor(a: &[String], b: &[String]) -> bool {
    b.len() > a.len() && b.starts_with(a)
}

/// Every module's imported modules (itself and re-exports of its own descendants left out).
fn import_graph(sources: &[Source]) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let modules: BTreeSet<Vec<String>> = sources.iter().map(|s| s.module.clone()).collect();
    sources
        .iter()
        .map(|s| {
            let targets = imports(&code_only(&s.text))
                .into_iter()
                .filter_map(|i| {
                    let target = resolve(&s.module, &i.path, &modules)?;
                    let skip =
                        target == s.module || (i.reexport && is_ancestor(&s.module, &target));
                    (!skip).then_some(target)
                })
                .collect();
            (s.module.clone(), targets)
        })
        .collect()
}

/// The strongly connected components with more than one module (Tarjan).
fn cycles(graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<String>> {
    struct Tarjan<'g> {
        graph: &'g BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        index: BTreeMap<&'g [String], (usize, usize)>,
        stack: Vec<&'g [String]>,
        on_stack: BTreeSet<&'g [String]>,
        found: Vec<Vec<String>>,
    }
    impl<'g> Tarjan<'g> {
        fn visit(&mut self, v: &'g [String]) {
            let n = self.index.len();
            self.index.insert(v, (n, n));
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.graph.get(v).into_iter().flatten() {
                let w = w.as_slice();
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let low = self.index[w].1.min(self.index[v].1);
                    self.index.get_mut(v).unwrap().1 = low;
                } else if self.on_stack.contains(w) {
                    let low = self.index[w].0.min(self.index[v].1);
                    self.index.get_mut(v).unwrap().1 = low;
                }
            }
            if self.index[v].0 == self.index[v].1 {
                let mut component = Vec::new();
                loop {
                    let w = self.stack.pop().unwrap();
                    self.on_stack.remove(w);
                    component.push(w.join("::"));
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.found.push(component);
                }
            }
        }
    }
    let mut t = Tarjan {
        graph,
        index: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        found: Vec::new(),
    };
    for v in graph.keys() {
        if !t.index.contains_key(v.as_slice()) {
            t.visit(v);
        }
    }
    t.found
}

#[test]
fn folders_import_only_lower_layers() {
    let sources = sources();
    let graph = import_graph(&sources);
    let rank = |m: &[String]| {
        let top = m.first().map_or(ROOT, String::as_str);
        LAYERS.iter().position(|l| *l == top)
    };
    let mut wrong = Vec::new();
    for (from, targets) in &graph {
        if from.is_empty() {
            continue; // lib.rs declares and re-exports
        }
        let Some(r) = rank(from) else {
            wrong.push(format!(
                "{}: a top-level module without a layer: add it to LAYERS",
                from[0]
            ));
            continue;
        };
        for to in targets {
            if to.first() != from.first() && rank(to).is_none_or(|t| t >= r) {
                wrong.push(format!(
                    "{} imports {} (a higher or unranked layer)",
                    from.join("::"),
                    if to.is_empty() {
                        ROOT.to_string()
                    } else {
                        to.join("::")
                    }
                ));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "imports against the layers:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn no_import_cycle_between_files() {
    let graph = import_graph(&sources());
    let found = cycles(&graph);
    assert!(found.is_empty(), "import cycles between files: {found:?}");
}

#[test]
fn long_files_say_why_they_are_one_concept() {
    let long: Vec<String> = sources()
        .iter()
        .filter(|s| s.text.lines().count() > MAX_LINES)
        .filter(|s| {
            let header: String = s
                .text
                .lines()
                .take_while(|l| l.starts_with("//!"))
                .collect::<Vec<_>>()
                .join(" ")
                .to_lowercase();
            !header.contains("one concept")
        })
        .map(|s| format!("{} ({} lines)", s.path.display(), s.text.lines().count()))
        .collect();
    assert!(
        long.is_empty(),
        "files over {MAX_LINES} lines whose top doc comment does not say why they are one concept (split them, or say why): {long:?}"
    );
}

/// The checker itself: a cycle, an upward import and a re-export are seen as they should be.
#[test]
fn the_checker_sees_cycles_and_ignores_what_is_not_code() {
    let paths: Vec<String> = expand("crate::a::{b, c::{d, e as f}, self}");
    assert_eq!(
        paths,
        [
            "crate::a::b",
            "crate::a::c::d",
            "crate::a::c::e",
            "crate::a"
        ]
    );
    let code = code_only(
        "// use crate::x;\nlet s = \"crate::y\";\npub use child::Z;\nuse crate::w::V;\nfn f() { super::s::g() }\n#[cfg(test)]\nmod tests { use crate::t; }\n",
    );
    let found: Vec<(String, bool)> = imports(&code)
        .into_iter()
        .map(|i| (i.path, i.reexport))
        .collect();
    assert_eq!(
        found,
        [
            ("child::Z".to_string(), true),
            ("crate::w::V".to_string(), false),
            ("crate::w::V".to_string(), false),
            ("super::s::g".to_string(), false)
        ]
    );
    let m = |s: &str| s.split("::").map(String::from).collect::<Vec<_>>();
    let graph: BTreeMap<_, BTreeSet<_>> = [
        (m("a"), [m("b")].into()),
        (m("b"), [m("c")].into()),
        (m("c"), [m("a")].into()),
        (m("d"), [m("a")].into()),
    ]
    .into();
    assert_eq!(cycles(&graph), [["a", "b", "c"]]);
}
