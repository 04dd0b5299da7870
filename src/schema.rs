//! The version of Shoal's file formats, and the one place where files written by an older Shoal
//! are brought up to date.
//!
//! Run configurations (`config.ron` beside every output) and the app's session carry
//! `schema_version`; presets, studies and sweeps may (a file without it is version 1, the format
//! before the field existed). [`migrate`] reads the version and renames the fields renamed since,
//! as text, before the file is parsed — so every type keeps `deny_unknown_fields` and no type
//! carries aliases. A file from a newer Shoal is refused with both versions named, rather than
//! misread.
//!
//! To rename a field: bump [`VERSION`], add a row to [`RENAMES`], and add a test of an old file.
//! A change of shape that a rename cannot express is read by the type itself, from legacy fields
//! that are never written, and listed in [`RESHAPES`].

use std::borrow::Cow;

/// The format this Shoal writes.
pub const VERSION: u32 = 4;

/// The version of a file that does not say (written before `schema_version` existed).
pub const UNVERSIONED: u32 = 1;

/// [`VERSION`], for `#[serde(default = "crate::schema::current")]`.
#[must_use]
pub const fn current() -> u32 {
    VERSION
}

/// Fields renamed: (the version that renamed it, old name, new name, where it lives).
pub const RENAMES: &[(u32, &str, &str, &str)] = &[
    (2, "exposures", "lines", "an instrument: lines (exposures) along track"),
    (2, "levels", "decimations", "the app's session: preview decimations"),
];

/// Changes of shape since version 1 that are not renames: (the version, what changed, where it is
/// read).
pub const RESHAPES: &[(u32, &str, &str)] = &[
    (
        3,
        "the app's session: instruments `a` and `b` (and `editing_instrument: A|B`) became the list `designs` (and `editing_design`)",
        "src/app/migrate.rs, tests/ui/session.rs",
    ),
    (
        4,
        "the app's session: `retrieval: Almi|Sambuca|External` with the settings `almi`, `sambuca` and `external` became the list `retrievals` (and `selected_retrieval`); sessions of version 3 may hold either",
        "src/app/migrate.rs, tests/ui/session.rs",
    ),
];

/// The `schema_version: N` a RON text states at its outermost level, if it does.
fn stated_version(text: &str) -> Result<Option<u32>, String> {
    let mut found = None;
    for_each_key(text, |key, _, depth, rest| {
        if key == "schema_version" && depth == 1 && found.is_none() {
            let digits: String = rest.trim_start().chars().take_while(char::is_ascii_digit).collect();
            found = Some(digits.parse::<u32>().map_err(|_| {
                format!(
                    "`schema_version` is not a whole number: {}",
                    rest.trim_start().chars().take(12).collect::<String>()
                )
            }));
        }
    });
    found.transpose()
}

/// `text` with the fields renamed after its `schema_version` given their new names; an error for a
/// file from a newer Shoal.
pub fn migrate(text: &str) -> Result<Cow<'_, str>, String> {
    let version = stated_version(text)?.unwrap_or(UNVERSIONED);
    if version > VERSION {
        return Err(format!(
            "written by a newer Shoal (schema_version {version}; this one reads up to {VERSION}): update Shoal to read it"
        ));
    }
    let renames: Vec<(&str, &str)> =
        RENAMES.iter().filter(|(since, ..)| *since > version).map(|(_, old, new, _)| (*old, *new)).collect();
    if renames.is_empty() {
        return Ok(Cow::Borrowed(text));
    }
    let mut edits: Vec<(usize, usize, &str)> = Vec::new();
    for_each_key(text, |key, start, _, _| {
        if let Some((_, new)) = renames.iter().find(|(old, _)| *old == key) {
            edits.push((start, start + key.len(), new));
        }
    });
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    for (start, end, new) in edits {
        out.push_str(&text[at..start]);
        out.push_str(new);
        at = end;
    }
    out.push_str(&text[at..]);
    Ok(Cow::Owned(out))
}

/// Call `f(key, start, depth, rest)` for every field key of a RON text (an identifier followed
/// by `:`, not `::`), outside strings and comments: `start` is its byte offset, `depth` counts
/// the brackets around it and `rest` is the text after its colon.
fn for_each_key<'a>(text: &'a str, mut f: impl FnMut(&'a str, usize, usize, &'a str)) {
    let bytes = text.as_bytes();
    let (mut i, mut depth) = (0, 0usize);
    while i < bytes.len() {
        match bytes[i] {
            b'"' => i = skip_string(bytes, i + 1),
            b'r' if matches!(bytes.get(i + 1), Some(b'"' | b'#')) => i = skip_raw_string(bytes, i + 1),
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                i = text[i..].find('\n').map_or(bytes.len(), |n| i + n);
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                i = text[i + 2..].find("*/").map_or(bytes.len(), |n| i + 2 + n + 2);
            }
            b'(' | b'[' | b'{' => {
                depth += 1;
                i += 1;
            }
            b')' | b']' | b'}' => {
                depth = depth.saturating_sub(1);
                i += 1;
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                let start = i;
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                let after = text[i..].trim_start();
                if after.starts_with(':') && !after.starts_with("::") {
                    f(&text[start..i], start, depth, &after[1..]);
                }
            }
            _ => i += 1,
        }
    }
}

/// The index after the string whose contents start at `i` (escapes skipped).
fn skip_string(bytes: &[u8], mut i: usize) -> usize {
    while i < bytes.len() {
        match bytes[i] {
            b'\\' => i += 2,
            b'"' => return i + 1,
            _ => i += 1,
        }
    }
    bytes.len()
}

/// The index after a raw string `r#…"…"#…` whose hashes start at `i`.
fn skip_raw_string(bytes: &[u8], mut i: usize) -> usize {
    let mut hashes = 0;
    while bytes.get(i) == Some(&b'#') {
        hashes += 1;
        i += 1;
    }
    i += 1; // the opening quote
    while i < bytes.len() {
        if bytes[i] == b'"' && bytes[i + 1..].iter().take(hashes).filter(|&&b| b == b'#').count() == hashes {
            return i + 1 + hashes;
        }
        i += 1;
    }
    bytes.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unversioned_file_gets_the_renamed_fields_and_nothing_else() {
        let old = r#"InstrumentSpec(
    name: "exposures: 3",   // exposures: in a string and a comment stay
    /* levels: */ exposures: 2000,
    nested: (levels: [24, 4, 1]),
)"#;
        let new = migrate(old).unwrap();
        assert!(new.contains("lines: 2000") && new.contains("decimations: [24, 4, 1]"), "{new}");
        assert!(new.contains(r#""exposures: 3""#) && new.contains("/* levels: */"), "{new}");
        assert!(!new.contains("exposures: 2000"), "{new}");
    }

    #[test]
    fn a_current_file_is_left_alone_and_a_newer_one_is_refused() {
        let current = format!("(schema_version: {VERSION}, lines: 10, exposures_s: 0.1)");
        let current = current.as_str();
        assert!(matches!(migrate(current).unwrap(), Cow::Borrowed(_)));
        // A version-2 file with a field that happens to be called as an old one is not renamed.
        let v2 = "(schema_version: 2, nested: (levels: 3))";
        assert_eq!(migrate(v2).unwrap(), v2);
        let newer = migrate("(schema_version: 9, lines: 10)").unwrap_err();
        assert!(newer.contains("schema_version 9") && newer.contains(&format!("up to {VERSION}")), "{newer}");
        // Only the outermost level states the version.
        assert_eq!(stated_version("(inner: (schema_version: 7))").unwrap(), None);
        assert!(migrate("(schema_version: two)").unwrap_err().contains("whole number"));
    }

    #[test]
    fn raw_strings_and_paths_are_not_keys() {
        let text = r##"(path: r#"a "levels: b"#, kind: std::thing, levels: 1)"##;
        let new = migrate(text).unwrap();
        assert_eq!(new, r##"(path: r#"a "levels: b"#, kind: std::thing, decimations: 1)"##);
    }
}
