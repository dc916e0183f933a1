//! The fingerprint of a case: what a result was computed from. It is the case as resolved (its
//! TOML after a study's parameters are set, in a canonical form: comments, key order and
//! layout do not count) and the content of every file the case reads (the `.npz` modal basis
//! `structure.file` and the tables `history.file` of the loads; [`super::absolute_file_names`]
//! lists the same keys). A study's row, a resumed run and a resumed service life are tied to
//! it: a result is reused only with the inputs that made it.
//!
//! The hash is FNV-1a over 64-bit words (the bytes' little-endian words, then the tail byte
//! by byte): stable across platforms and versions of Rust, a fingerprint, not a security
//! measure.

use std::path::Path;

/// The hashes of files read once ([`Fingerprint::of_cached`]).
#[derive(Debug, Default)]
pub struct FileHashes(std::collections::HashMap<std::path::PathBuf, Option<u64>>);

/// A case's fingerprint, with its parts (to say which changed).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Fingerprint {
    /// Hash of the canonical TOML of the case.
    pub case: u64,
    /// Each file the case names, as written, and the hash of its content (`None` when it
    /// cannot be read: the case then fails to build, with its own message).
    pub files: Vec<(String, Option<u64>)>,
}

impl Fingerprint {
    /// The fingerprint of a case given as TOML; `base` resolves its relative file names.
    pub fn of(case: &toml::Value, base: &Path) -> Self {
        Self::of_cached(case, base, &mut FileHashes::default())
    }

    /// [`Self::of`] with the files' hashes kept in `cache` (the runs of a study read the
    /// same files: each is read once).
    pub fn of_cached(case: &toml::Value, base: &Path, cache: &mut FileHashes) -> Self {
        let text = canonical(case);
        let files = file_names(case)
            .into_iter()
            .map(|name| {
                let path = base.join(&name);
                let hash = *cache
                    .0
                    .entry(path)
                    .or_insert_with_key(|p| std::fs::read(p).ok().map(|b| hash(&b)));
                (name, hash)
            })
            .collect();
        Self {
            case: hash(text.as_bytes()),
            files,
        }
    }

    /// The whole fingerprint as one number.
    pub fn value(&self) -> u64 {
        let mut bytes = self.case.to_le_bytes().to_vec();
        for (name, h) in &self.files {
            bytes.extend_from_slice(name.as_bytes());
            bytes.push(0);
            bytes.extend_from_slice(&h.unwrap_or(0).to_le_bytes());
            bytes.push(h.is_some() as u8);
        }
        hash(&bytes)
    }

    /// [`Self::value`] as text: `fp` and 16 hexadecimal digits (never read as a number by a
    /// CSV reader).
    pub fn text(&self) -> String {
        format!("fp{:016x}", self.value())
    }
}

/// The canonical TOML of a case: tables with sorted keys (as `toml::Value` holds them), no
/// comments.
pub fn canonical(case: &toml::Value) -> String {
    toml::to_string(case).unwrap_or_else(|_| format!("{case:?}"))
}

/// The file names a case reads, as written in it, in a fixed order: `structure.file` (or each
/// `structures[i].structure.file`), then the `file` of every `history` table, depth first in
/// key order.
pub fn file_names(case: &toml::Value) -> Vec<String> {
    fn histories(v: &toml::Value, out: &mut Vec<String>) {
        match v {
            toml::Value::Table(map) => {
                for (k, item) in map {
                    match (k.as_str(), item.get("file")) {
                        ("history", Some(toml::Value::String(f))) => out.push(f.clone()),
                        _ => histories(item, out),
                    }
                }
            }
            toml::Value::Array(items) => items.iter().for_each(|i| histories(i, out)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    if let Some(toml::Value::String(f)) = case.get("structure").and_then(|s| s.get("file")) {
        out.push(f.clone());
    }
    if let Some(toml::Value::Array(structures)) = case.get("structures") {
        for entry in structures {
            if let Some(toml::Value::String(f)) = entry.get("structure").and_then(|s| s.get("file"))
            {
                out.push(f.clone());
            }
        }
    }
    histories(case, &mut out);
    out
}

/// FNV-1a over the 64-bit little-endian words of `bytes`, then its last bytes one by one.
pub fn hash(bytes: &[u8]) -> u64 {
    const PRIME: u64 = 0x100000001b3;
    let mut h: u64 = 0xcbf29ce484222325 ^ bytes.len() as u64;
    let mut words = bytes.chunks_exact(8);
    for w in &mut words {
        let w = u64::from_le_bytes(w.try_into().expect("8 bytes"));
        h = (h ^ w).wrapping_mul(PRIME);
    }
    for b in words.remainder() {
        h = (h ^ u64::from(*b)).wrapping_mul(PRIME);
    }
    h
}

/// The leaves where two cases differ, as `key: old → new` (`(none)` for a key one lacks), at
/// most `limit` of them, in key order; the key paths are written as in a study
/// (`contacts.0.friction.mu`).
pub fn differences(old: &toml::Value, new: &toml::Value, limit: usize) -> Vec<String> {
    fn walk(
        old: Option<&toml::Value>,
        new: Option<&toml::Value>,
        path: &str,
        out: &mut Vec<String>,
    ) {
        use toml::Value::{Array, Table};
        let join = |k: &str| {
            if path.is_empty() {
                k.to_string()
            } else {
                format!("{path}.{k}")
            }
        };
        match (old, new) {
            (Some(Table(a)), Some(Table(b))) => {
                let keys: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
                for k in keys {
                    walk(a.get(k), b.get(k), &join(k), out);
                }
            }
            (Some(Array(a)), Some(Array(b))) if a.len() == b.len() => {
                for (i, (x, y)) in a.iter().zip(b).enumerate() {
                    walk(Some(x), Some(y), &join(&i.to_string()), out);
                }
            }
            (a, b) if a != b => {
                let show = |v: Option<&toml::Value>| v.map_or("(none)".to_string(), short);
                out.push(format!("{path}: {} → {}", show(a), show(b)));
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(Some(old), Some(new), "", &mut out);
    if out.len() > limit {
        let more = out.len() - limit;
        out.truncate(limit);
        out.push(format!("and {more} more"));
    }
    out
}

/// A value in a message: as TOML writes it, shortened when long (a table or an array).
fn short(v: &toml::Value) -> String {
    let text = match v {
        toml::Value::Table(_) => "a table".to_string(),
        toml::Value::Array(a) => format!("an array of {}", a.len()),
        other => other.to_string(),
    };
    if text.chars().count() > 60 {
        format!("{}…", text.chars().take(60).collect::<String>())
    } else {
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(text: &str) -> toml::Value {
        toml::from_str(text).unwrap()
    }

    /// Comments, layout and key order do not change the fingerprint; a value does, and so
    /// does the content of a file the case reads (not its folder).
    #[test]
    fn the_fingerprint_follows_the_values_and_the_files() {
        let dir = std::env::temp_dir().join(format!("fretdyn_fingerprint_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("f.csv"), "0,1\n1,2\n").unwrap();
        let a = case(
            "[structure]\nfile = \"b.npz\"\n[[loads]]\nhistory = { file = \"f.csv\" }\nforce = [1, 0, 0]\n",
        );
        let b = case(
            "# a comment\n[[loads]]\nforce = [1, 0, 0]\nhistory = { file = \"f.csv\" }\n[structure]\nfile = \"b.npz\"\n",
        );
        assert_eq!(file_names(&a), ["b.npz", "f.csv"]);
        let fa = Fingerprint::of(&a, &dir);
        assert_eq!(fa, Fingerprint::of(&b, &dir));
        assert_eq!(fa.files[0].1, None);
        assert!(fa.files[1].1.is_some());
        assert!(fa.text().starts_with("fp") && fa.text().len() == 18);
        // a value
        let c = case(
            "[structure]\nfile = \"b.npz\"\n[[loads]]\nhistory = { file = \"f.csv\" }\nforce = [2, 0, 0]\n",
        );
        assert_ne!(Fingerprint::of(&c, &dir).value(), fa.value());
        // the content of a file
        std::fs::write(dir.join("f.csv"), "0,1\n1,3\n").unwrap();
        let changed = Fingerprint::of(&a, &dir);
        assert_eq!(changed.case, fa.case);
        assert_ne!(changed.files[1].1, fa.files[1].1);
        assert_ne!(changed.value(), fa.value());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_hash_sees_every_byte() {
        let base: Vec<u8> = (0..37).collect();
        let h = hash(&base);
        for i in 0..base.len() {
            let mut b = base.clone();
            b[i] ^= 1;
            assert_ne!(hash(&b), h, "byte {i}");
        }
        assert_ne!(hash(&base[..36]), h);
        assert_ne!(hash(&[]), hash(&[0]));
    }

    #[test]
    fn differences_name_the_keys_that_changed() {
        let old = case("[time]\ndt = 1e-5\n[[contacts]]\nfriction = { mu = 0.3 }\n");
        let new =
            case("[time]\ndt = 1e-5\nduration = 2.0\n[[contacts]]\nfriction = { mu = 0.6 }\n");
        assert_eq!(
            differences(&old, &new, 5),
            [
                "contacts.0.friction.mu: 0.3 → 0.6",
                "time.duration: (none) → 2.0"
            ]
        );
        assert_eq!(differences(&old, &new, 1)[1], "and 1 more");
        assert!(differences(&old, &old, 5).is_empty());
    }
}
