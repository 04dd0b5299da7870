//! A configuration's fields by path — the one reflection layer, through serde, for any type that
//! serialises (a run configuration, an instrument, a study, the app's session):
//!
//! - [`number`] and [`with_numbers`]: read and set numbers by path (sweeps, the design search, the
//!   app's parameter editor);
//! - [`flatten`]: every leaf with its path (the review pack's parameter table);
//! - [`diff`]: what changed between two values (the captions of edited designs);
//! - [`strings`]: every text it holds (the files a configuration names).
//!
//! Objects are walked in the order of their fields' names (serde_json's map is sorted), not the
//! order a type declares them. A path is the fields' names joined by dots, a list's entries by
//! their index:
//! `instrument.aperture_mm`, `scene.atmosphere.aot550`, `correction.image.pair_nm.1`,
//! `instrument.effects.0.StrayLight.halo_fraction` (an enum's variant is a field of its own, as
//! serde writes it). The names are the file's: what a study file, a sweep and the pack show is one
//! name.

use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

/// `value` as a tree of fields, or why not (a map with keys that are not text).
///
/// # Errors
/// serde cannot represent `value` as JSON.
fn tree(value: &impl Serialize) -> Result<Value, String> {
    serde_json::to_value(value).map_err(|e| format!("cannot represent the configuration: {e}"))
}

/// The node at `path` of `tree`, if there is one.
fn node<'a>(tree: &'a Value, path: &str) -> Option<&'a Value> {
    if path.is_empty() {
        return Some(tree);
    }
    path.split('.').try_fold(tree, |node, key| match node {
        Value::Object(map) => map.get(key),
        Value::Array(items) => items.get(key.parse::<usize>().ok()?),
        _ => None,
    })
}

/// The number at `path` of `value` (`None`: no such field, or not a number there — a field of
/// another instrument kind, a map).
#[must_use]
pub fn number(value: &impl Serialize, path: &str) -> Option<f64> {
    node(&tree(value).ok()?, path)?.as_f64()
}

/// The numbers at each of `paths` of `value`, in order (NaN where there is none), from one pass
/// over its fields.
#[must_use]
pub fn numbers<'p>(value: &impl Serialize, paths: impl IntoIterator<Item = &'p str>) -> Vec<f64> {
    let tree = tree(value).unwrap_or(Value::Null);
    paths.into_iter().map(|p| node(&tree, p).and_then(Value::as_f64).unwrap_or(f64::NAN)).collect()
}

/// `value` with the number at each path set, or what is wrong with the first that cannot be (no
/// such field, with the fields there named; not a number; a whole number given a fraction). The
/// result is read back through serde, so a value its type refuses is refused here; it is not
/// validated against the ranges (the caller's validator does that).
///
/// # Errors
/// As above, naming the path.
pub fn with_numbers<T: Serialize + DeserializeOwned>(value: &T, settings: &[(&str, f64)]) -> Result<T, String> {
    let mut tree = tree(value)?;
    // Optional numbers left unset (absent from the tree, or null), each with the error to give
    // if it does not read back.
    let mut unset = Vec::new();
    for &(path, v) in settings {
        if let Some(error) = set(&mut tree, path, v)? {
            unset.push((path, v, error));
        }
    }
    let out: T = match serde_json::from_value(tree) {
        Ok(out) => out,
        // A field the type does not have: say so, with the fields it has there.
        Err(_) if !unset.is_empty() => return Err(unset.swap_remove(0).2),
        Err(e) => return Err(format!("`{settings:?}`: {e}")),
    };
    // An unset field is set only where the type reads it there: a name it does not have (a
    // misspelt path) is not silently dropped by a type that ignores unknown fields.
    if !unset.is_empty() {
        let back = self::tree(&out)?;
        for (path, v, error) in unset {
            if node(&back, path).and_then(Value::as_f64) != Some(v) {
                return Err(error);
            }
        }
    }
    Ok(out)
}

/// Set the number at `path` of `tree`. `Some(error)`: the path's last field was absent or null
/// (an optional number left unset, which serde writes as nothing or null) and now holds the
/// number; `error` is what to say if the type does not read it back.
fn set(tree: &mut Value, path: &str, value: f64) -> Result<Option<String>, String> {
    let finite = |v: f64| {
        serde_json::Number::from_f64(v).map(Value::Number).ok_or_else(|| format!("`{path}`: {v} is not finite"))
    };
    let keys: Vec<&str> = path.split('.').collect();
    let mut node = tree;
    for (i, key) in keys.iter().enumerate() {
        node = match node {
            Value::Object(map) => {
                let known: Vec<String> = map.keys().cloned().collect();
                let missing = format!("`{path}`: no field `{key}` here (fields: {})", known.join(", "));
                if i + 1 == keys.len() && map.get(*key).is_none_or(Value::is_null) {
                    map.insert((*key).to_string(), finite(value)?);
                    return Ok(Some(missing));
                }
                map.get_mut(*key).ok_or(missing)?
            }
            Value::Array(items) => {
                let n = items.len();
                let i: usize = key.parse().map_err(|_| format!("`{path}`: `{key}` must be an index 0..{n} here"))?;
                items.get_mut(i).ok_or_else(|| format!("`{path}`: index {i} out of 0..{n}"))?
            }
            other => return Err(format!("`{path}`: `{key}` is inside a value that has no fields ({other})")),
        };
    }
    let Value::Number(n) = node else {
        return Err(format!("`{path}` is not a number (it holds {node})"));
    };
    *node = if n.is_f64() {
        finite(value)?
    } else {
        if value.fract() != 0.0 || !(0.0..=9.0e15).contains(&value) {
            return Err(format!("`{path}` is a whole number; {value} is not (use a list of whole values)"));
        }
        Value::from(value as u64)
    };
    Ok(None)
}

/// A leaf of [`flatten`]: its value as text, or a list summarised.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Leaf {
    /// The path ([`crate::fields`]'s module docs).
    pub path: String,
    /// The value as text: a string as it is, a number as serde writes it, a list of more than six
    /// entries or of structures as "N entries (digest …)" (its entries follow up to 40).
    pub text: String,
}

/// Every leaf of `value` with its path, fields in the order of their names.
#[must_use]
pub fn flatten(value: &impl Serialize) -> Vec<Leaf> {
    let mut out = Vec::new();
    if let Ok(tree) = tree(value) {
        flatten_into("", &tree, &mut out);
    }
    out
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() { key.to_string() } else { format!("{prefix}.{key}") }
}

fn flatten_into(prefix: &str, v: &Value, out: &mut Vec<Leaf>) {
    match v {
        Value::Object(map) => {
            for (k, v) in map {
                flatten_into(&join(prefix, k), v, out);
            }
        }
        Value::Array(items) if items.iter().any(|i| i.is_object() || i.is_array()) || items.len() > 6 => {
            // The digest makes two lists of the same length but other contents differ here too
            // (their entries are listed only up to 40).
            let digest = v
                .to_string()
                .bytes()
                .fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3));
            out.push(Leaf {
                path: prefix.to_string(),
                text: format!("{} entries (digest {:08x})", items.len(), digest >> 32),
            });
            if items.len() <= 40 {
                for (i, item) in items.iter().enumerate() {
                    flatten_into(&join(prefix, &i.to_string()), item, out);
                }
            }
        }
        Value::String(s) => out.push(Leaf { path: prefix.to_string(), text: s.clone() }),
        other => out.push(Leaf { path: prefix.to_string(), text: other.to_string() }),
    }
}

/// One difference [`diff`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    /// The path of the field that changed.
    pub path: String,
    /// What it was.
    pub before: Value,
    /// What it is (`Null` where the field is gone).
    pub after: Value,
}

/// The fields of `now` that differ from `then`, deepest first where both have the same structure:
/// objects field by field (both sides' fields, in the order of their names), lists of the same length entry by entry; a list
/// whose length changed, or a value whose kind changed, is one change at its path.
#[must_use]
pub fn diff(now: &impl Serialize, then: &impl Serialize) -> Vec<Change> {
    let mut out = Vec::new();
    if let (Ok(a), Ok(b)) = (tree(then), tree(now)) {
        diff_into("", &a, &b, &mut out);
    }
    out
}

fn diff_into(prefix: &str, before: &Value, after: &Value, out: &mut Vec<Change>) {
    if before == after {
        return;
    }
    match (before, after) {
        (Value::Object(a), Value::Object(b)) => {
            for k in b.keys().chain(a.keys().filter(|k| !b.contains_key(*k))) {
                let (x, y) = (a.get(k).unwrap_or(&Value::Null), b.get(k).unwrap_or(&Value::Null));
                diff_into(&join(prefix, k), x, y, out);
            }
        }
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => {
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                diff_into(&join(prefix, &i.to_string()), x, y, out);
            }
        }
        _ => out.push(Change { path: prefix.to_string(), before: before.clone(), after: after.clone() }),
    }
}

/// Every text value `value` holds (file names among them; not the fields' names), fields in the
/// order of their names.
#[must_use]
pub fn strings(value: &impl Serialize) -> Vec<String> {
    fn walk(v: &Value, out: &mut Vec<String>) {
        match v {
            Value::String(s) => out.push(s.clone()),
            Value::Array(items) => items.iter().for_each(|i| walk(i, out)),
            Value::Object(map) => map.values().for_each(|v| walk(v, out)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    if let Ok(tree) = tree(value) {
        walk(&tree, &mut out);
    }
    out
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
    struct Inner {
        f: f64,
        n: u32,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
    enum Kind {
        A { x: f64 },
        B,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
    struct Config {
        name: String,
        inner: Inner,
        list: Vec<f64>,
        kinds: Vec<Kind>,
    }

    #[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Optional {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        left_out: Option<f64>,
        #[serde(default)]
        null: Option<f64>,
    }

    /// Optional numbers left unset (not written, or written as null) are set by path; a name the
    /// type does not have is refused with the fields it has, whether it denies unknown fields or
    /// ignores them.
    #[test]
    fn unset_optional_numbers_are_set_and_unknown_names_refused() {
        let none = Optional { left_out: None, null: None };
        let set = with_numbers(&none, &[("left_out", 0.005), ("null", 2.0)]).unwrap();
        assert_eq!(set, Optional { left_out: Some(0.005), null: Some(2.0) });
        let e = with_numbers(&none, &[("left_uot", 1.0)]).unwrap_err();
        assert!(e.contains("no field `left_uot`") && e.contains("null"), "{e}");
        let e = with_numbers(&base(), &[("inner.g", 1.0)]).unwrap_err();
        assert!(e.contains("no field `g`") && e.contains("f, n"), "{e}");
        assert!(with_numbers(&none, &[("left_out", f64::NAN)]).unwrap_err().contains("not finite"));
    }

    fn base() -> Config {
        Config {
            name: "x.csv".into(),
            inner: Inner { f: 1.5, n: 3 },
            list: vec![1.0, 2.0],
            kinds: vec![Kind::A { x: 0.25 }, Kind::B],
        }
    }

    #[test]
    fn numbers_are_read_and_set_by_path() {
        let c = base();
        assert_eq!(number(&c, "inner.f"), Some(1.5));
        assert_eq!(number(&c, "list.1"), Some(2.0));
        assert_eq!(number(&c, "kinds.0.A.x"), Some(0.25));
        assert_eq!(number(&c, "name"), None);
        assert!(numbers(&c, ["inner.n", "nothing"])[1].is_nan());
        let set = with_numbers(&c, &[("inner.f", 2.5), ("inner.n", 4.0), ("kinds.0.A.x", 0.5)]).unwrap();
        let mut want = base();
        (want.inner.f, want.inner.n, want.kinds[0]) = (2.5, 4, Kind::A { x: 0.5 });
        assert_eq!(set, want, "nothing else changes");
    }

    #[test]
    fn a_path_that_cannot_be_set_is_named() {
        let e = with_numbers(&base(), &[("inner.g", 1.0)]).unwrap_err();
        assert!(e.contains("no field `g`") && e.contains("f, n"), "{e}");
        assert!(with_numbers(&base(), &[("inner.n", 1.5)]).unwrap_err().contains("whole number"));
        assert!(with_numbers(&base(), &[("name", 1.0)]).unwrap_err().contains("not a number"));
        assert!(with_numbers(&base(), &[("list.5", 1.0)]).unwrap_err().contains("out of 0..2"));
        assert!(with_numbers(&base(), &[("inner.f", f64::NAN)]).unwrap_err().contains("not finite"));
    }

    #[test]
    fn flatten_names_every_leaf_by_the_path_that_sets_it() {
        let leaves = flatten(&base());
        let paths: Vec<&str> = leaves.iter().map(|l| l.path.as_str()).collect();
        assert_eq!(paths, ["inner.f", "inner.n", "kinds", "kinds.0.A.x", "kinds.1", "list", "name"]);
        assert!(leaves[2].text.starts_with("2 entries (digest "), "{:?}", leaves[2]);
        assert_eq!(leaves[5].text, "[1.0,2.0]", "a short list of numbers is one leaf");
        for l in &leaves {
            if let Ok(v) = l.text.parse::<f64>() {
                assert_eq!(number(&base(), &l.path), Some(v), "{}", l.path);
            }
        }
    }

    #[test]
    fn diff_finds_the_deepest_field_that_changed() {
        let mut now = base();
        now.inner.f = 2.0;
        now.kinds[0] = Kind::A { x: 0.5 };
        now.list.push(3.0);
        let paths: Vec<String> = diff(&now, &base()).into_iter().map(|c| c.path).collect();
        assert_eq!(paths, ["inner.f", "kinds.0.A.x", "list"]);
        assert!(diff(&base(), &base()).is_empty());
    }

    #[test]
    fn strings_lists_every_text() {
        assert_eq!(strings(&base()), ["B", "x.csv"], "a unit variant is written as text");
    }
}
