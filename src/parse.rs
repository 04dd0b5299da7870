//! Messages for malformed RON files: where (line and column), which field was being read, and
//! what was wrong — so that a broken preset can be fixed from the message alone.

/// Describe a RON error in `text`: `line 12, column 17, field `aperture_mm`: Expected float`.
///
/// The field is the nearest `name:` before the error position (on its line or an earlier one);
/// it is left out when none is found or the message already names it.
#[must_use]
pub fn describe(text: &str, error: &ron::error::SpannedError) -> String {
    let pos = error.span.start;
    let message = error.code.to_string();
    let mut out = format!("line {}, column {}", pos.line, pos.col);
    if let Some(field) = field_before(text, pos.line, pos.col)
        && !message.contains(&format!("`{field}`"))
    {
        out.push_str(&format!(", field `{field}`"));
    }
    out.push_str(": ");
    out.push_str(&message);
    out
}

/// The last `identifier:` before line `line` (1-based), column `col` (1-based, characters).
fn field_before(text: &str, line: usize, col: usize) -> Option<String> {
    let lines: Vec<&str> = text.lines().take(line.max(1)).collect();
    for (i, l) in lines.iter().enumerate().rev() {
        let part: String =
            if i + 1 == line { l.chars().take(col.saturating_sub(1)).collect() } else { (*l).to_string() };
        // Ignore comments.
        let part = part.split("//").next().unwrap_or_default();
        if let Some(name) = last_key(part) {
            return Some(name);
        }
    }
    None
}

/// The last `name:` in `s` (a Rust-style identifier followed by optional spaces and a colon).
fn last_key(s: &str) -> Option<String> {
    let chars: Vec<char> = s.chars().collect();
    let mut found = None;
    for (i, &c) in chars.iter().enumerate() {
        if c != ':' {
            continue;
        }
        let mut end = i;
        while end > 0 && chars[end - 1] == ' ' {
            end -= 1;
        }
        let mut start = end;
        while start > 0 && (chars[start - 1].is_ascii_alphanumeric() || chars[start - 1] == '_') {
            start -= 1;
        }
        if start < end && !chars[start].is_ascii_digit() {
            found = Some(chars[start..end].iter().collect());
        }
    }
    found
}

/// A field with an invalid value: the field's path and what is wrong and allowed. Every stage's
/// error carries it as its `Invalid` variant, so a message reads the same wherever it comes from.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct FieldError {
    /// The field (`aperture_mm`, `maps.depth_m`).
    pub field: String,
    /// What is wrong and what is allowed.
    pub message: String,
}

/// A file that does not parse: its name and the parser's message (line, column, field, from
/// [`describe`]). Every loader's error carries it as its `Parse` variant.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{origin}: {message}")]
pub struct ParseError {
    /// File name.
    pub origin: String,
    /// Parser message (line, column, field).
    pub message: String,
}

/// A type read from RON files and shipped as built-in presets (`presets/FOLDER/NAME.ron`,
/// embedded by [`crate::assets`]). Implementing it gives the type [`from_ron`], [`preset`] and
/// [`preset_names`], with the same messages as every other preset kind: the file and line of a
/// parse error, the known names after an unknown one.
pub trait Preset: serde::de::DeserializeOwned {
    /// Folder below `presets/` (`"scenes"`).
    const FOLDER: &'static str;
    /// The type's error.
    type Error;
    /// The error for text from `origin` that does not parse (`message` from [`describe`]).
    fn parse_error(origin: &str, message: String) -> Self::Error;
    /// The error for a built-in name that does not exist; `known` lists those that do.
    fn unknown(name: &str, known: &[String]) -> Self::Error;
    /// Built-in presets that are not files (none unless a type says so), listed first.
    fn built_in(_name: &str) -> Option<Self> {
        None
    }
    /// The names of [`Preset::built_in`]'s presets.
    fn built_in_names() -> Vec<String> {
        Vec::new()
    }
}

/// Parse `text` as a `T`, brought up to date first ([`crate::schema::migrate`]); `origin` names
/// the file in errors.
pub fn from_ron<T: Preset>(text: &str, origin: &str) -> Result<T, T::Error> {
    let text = crate::schema::migrate(text).map_err(|m| T::parse_error(origin, m))?;
    ron::from_str(&text).map_err(|e| T::parse_error(origin, describe(&text, &e)))
}

/// The built-in `T` called `name`.
pub fn preset<T: Preset>(name: &str) -> Result<T, T::Error> {
    if let Some(p) = T::built_in(name) {
        return Ok(p);
    }
    let path = format!("{}/{name}.ron", T::FOLDER);
    match crate::assets::preset(&path) {
        Some(asset) => from_ron(asset.text, &format!("presets/{path}")),
        None => Err(T::unknown(name, &preset_names::<T>())),
    }
}

/// The names of the built-in `T`s.
#[must_use]
pub fn preset_names<T: Preset>() -> Vec<String> {
    let mut names = T::built_in_names();
    names.extend(crate::assets::preset_names(T::FOLDER));
    names
}

/// Longest name that becomes a file or folder name.
pub const MAX_NAME_CHARS: usize = 64;

/// Check that `name` (of `field`) can become one file or folder name and nothing more: 1 to
/// [`MAX_NAME_CHARS`] letters, digits, spaces and `_ - . + ( ) ,`, not starting with a dot or a
/// space and not ending with one. Names come from presets and studies other people made: one
/// that held `/`, `..` or a control character would write outside the output folder.
///
/// ```
/// use shoal::parse::check_name;
/// assert!(check_name("instrument.name", "SmallSat (2x)").is_ok());
/// let e = check_name("instrument.name", "../../X").unwrap_err();
/// assert_eq!(e.field, "instrument.name");
/// ```
pub fn check_name(field: &str, name: &str) -> Result<(), FieldError> {
    let allowed = |c: char| c.is_alphanumeric() || " _-.+(),".contains(c);
    let count = name.chars().count();
    let problem = if count == 0 {
        Some("is empty".to_string())
    } else if count > MAX_NAME_CHARS {
        Some(format!("has {count} characters"))
    } else if let Some(c) = name.chars().find(|c| !allowed(*c)) {
        Some(format!("holds {:?}", c))
    } else if name.starts_with(['.', ' ']) || name.ends_with(['.', ' ']) {
        Some("starts or ends with a dot or a space".to_string())
    } else {
        None
    };
    match problem {
        None => Ok(()),
        Some(p) => Err(FieldError {
            field: field.into(),
            message: format!(
                "`{}` {p} (a name becomes a file name: 1 to {MAX_NAME_CHARS} letters, digits, spaces and _ - . + ( ) ,, not starting or ending with a dot or a space)",
                name.escape_debug()
            ),
        }),
    }
}

/// `dir` joined with `name`, once [`check_name`] has accepted it.
pub fn join_name(dir: &std::path::Path, field: &str, name: &str) -> Result<std::path::PathBuf, FieldError> {
    check_name(field, name)?;
    Ok(dir.join(name))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn names_the_line_and_the_field() {
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct S {
            name: String,
            aperture_mm: f64,
        }
        let text = "(\n    name: \"a\", // a comment: here\n    aperture_mm: \"wide\",\n)";
        let e = ron::from_str::<S>(text).unwrap_err();
        let m = describe(text, &e);
        assert!(m.starts_with("line 3, column 17, field `aperture_mm`: "), "{m}");
    }

    #[test]
    fn a_name_is_one_file_name_or_refused() {
        for good in ["cubesat", "SmallSat (2x)", "Sentinel-2A MSI", "a.b", "été_1", "x+y,z"] {
            assert!(check_name("n", good).is_ok(), "{good}");
        }
        for bad in
            ["", "..", ".", "../../X", "a/b", "a\\b", ".hidden", "trailing ", "nul\0", "tab\t", "x:y", &"a".repeat(65)]
        {
            let e = check_name("instrument.name", bad).unwrap_err();
            assert_eq!(e.field, "instrument.name");
            assert!(e.message.contains("a name becomes a file name"), "{bad}: {e}");
        }
        let dir = std::path::Path::new("/out");
        assert_eq!(join_name(dir, "n", "cubesat").unwrap(), dir.join("cubesat"));
        assert!(join_name(dir, "n", "../x").is_err());
    }

    #[test]
    fn finds_the_field_on_an_earlier_line() {
        assert_eq!(field_before("(\n  bands: [\n    1.0,\n    x\n", 4, 5).as_deref(), Some("bands"));
        assert_eq!(field_before("(1, 2)", 1, 3), None);
    }
}
