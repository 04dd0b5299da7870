//! The preset library: the built-in presets and the user's own, listed, loaded and saved.
//!
//! The user's presets live in `SHOAL_HOME/presets/{instruments,scenes,studies}/NAME.ron`, where
//! `SHOAL_HOME` is the environment variable of that name, else `$XDG_CONFIG_HOME/shoal`, else
//! `~/.config/shoal`. Saving is atomic (a temporary file, then a rename) and never overwrites a
//! file unless asked; a broken file is reported with its line, column and field, and never stops
//! the caller.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::instrument::InstrumentSpec;
use crate::scene::SceneSpec;
use crate::study::{StudySpec, write_bytes};

/// What a preset holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PresetKind {
    /// An instrument.
    Instrument,
    /// A scene.
    Scene,
    /// A study.
    Study,
}

fn builtin_names(kind: PresetKind) -> Vec<String> {
    match kind {
        PresetKind::Instrument => InstrumentSpec::preset_names(),
        PresetKind::Scene => SceneSpec::preset_names(),
        PresetKind::Study => StudySpec::preset_names(),
    }
}

impl PresetKind {
    fn noun(self) -> &'static str {
        match self {
            Self::Instrument => "instrument",
            Self::Scene => "scene",
            Self::Study => "study",
        }
    }

    fn folder(self) -> &'static str {
        match self {
            Self::Instrument => "instruments",
            Self::Scene => "scenes",
            Self::Study => "studies",
        }
    }
}

/// One entry of the library.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Entry {
    /// Name (file stem).
    pub name: String,
    /// Built in (embedded) or the user's file.
    pub builtin: bool,
    /// The user's file, if not built in.
    pub path: Option<PathBuf>,
    /// Its `description` field (empty when it has none or cannot be read).
    pub description: String,
}

/// The `description: "…"` of a preset's RON text (empty without one), read without parsing
/// the whole preset (a listing shows it beside the name).
#[must_use]
pub fn description_of(text: &str) -> String {
    let Some(at) = text.find("description:") else { return String::new() };
    let rest = text[at + "description:".len()..].trim_start();
    let Some(body) = rest.strip_prefix('"') else { return String::new() };
    let mut out = String::new();
    let mut chars = body.chars();
    while let Some(c) = chars.next() {
        match c {
            '"' => return out,
            '\\' => out.extend(chars.next()),
            c => out.push(c),
        }
    }
    String::new()
}

/// Errors of the library: the message names the file and what went wrong.
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
pub enum LibraryError {
    /// A file that does not parse or validate (the message has line, column and field).
    #[error("{0}")]
    Invalid(String),
    /// A file that exists and would be overwritten.
    #[error("{0} exists; choose another name or allow overwriting")]
    Exists(String),
    /// Reading or writing failed.
    #[error("{0}")]
    Io(String),
    /// A name a built-in preset already has (saving it would hide the built-in).
    #[error("`{name}` is a built-in {kind}; save yours under another name")]
    Builtin {
        /// The name asked for.
        name: String,
        /// "instrument", "scene" or "study".
        kind: &'static str,
    },
    /// A name that cannot be a file name.
    #[error("preset name `{0}`: use letters, digits, `-` and `_` (1 to 64 characters)")]
    BadName(String),
}

/// The library rooted at a user directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Library {
    /// The user's preset directory.
    pub dir: PathBuf,
}

/// The user's Shoal directory: `SHOAL_HOME`, else `$XDG_CONFIG_HOME/shoal`, else `~/.config/shoal`.
#[must_use]
pub fn home_dir() -> PathBuf {
    if let Some(h) = std::env::var_os("SHOAL_HOME") {
        return PathBuf::from(h);
    }
    if let Some(x) = std::env::var_os("XDG_CONFIG_HOME") {
        return PathBuf::from(x).join("shoal");
    }
    std::env::var_os("HOME").map_or_else(|| PathBuf::from(".shoal"), |h| PathBuf::from(h).join(".config").join("shoal"))
}

/// Where the app's exports go by default, a folder the user sees: `SHOAL_HOME/exports` when
/// `SHOAL_HOME` is set, else `~/Documents/Shoal` (or `~/Shoal` without a Documents folder).
#[must_use]
pub fn export_dir() -> PathBuf {
    if let Some(h) = std::env::var_os("SHOAL_HOME") {
        return PathBuf::from(h).join("exports");
    }
    match std::env::var_os("HOME").map(PathBuf::from) {
        Some(home) if home.join("Documents").is_dir() => home.join("Documents").join("Shoal"),
        Some(home) => home.join("Shoal"),
        None => home_dir().join("exports"),
    }
}

fn valid_name(name: &str) -> bool {
    !name.is_empty() && name.len() <= 64 && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

impl Library {
    /// The library in the user's Shoal directory.
    #[must_use]
    pub fn user() -> Self {
        Self { dir: home_dir().join("presets") }
    }

    /// A library rooted at `dir` (tests, other installations).
    #[must_use]
    pub fn at(dir: &Path) -> Self {
        Self { dir: dir.to_path_buf() }
    }

    /// Built-in names of `kind`, then the user's, sorted within each. The user's file wins: a
    /// file called like a built-in preset (left by an older Shoal, or copied in by hand) takes
    /// the built-in's place in the list, so a name always means one preset.
    #[must_use]
    pub fn list(&self, kind: PresetKind) -> Vec<Entry> {
        let builtin = builtin_names(kind);
        let mut out: Vec<Entry> = builtin
            .into_iter()
            .map(|name| {
                let text = crate::assets::preset(&format!("{}/{name}.ron", kind.folder())).map(|a| a.text);
                Entry { description: text.map(description_of).unwrap_or_default(), name, builtin: true, path: None }
            })
            .collect();
        let mut user: Vec<Entry> = std::fs::read_dir(self.dir.join(kind.folder()))
            .into_iter()
            .flatten()
            .flatten()
            .filter_map(|e| {
                let path = e.path();
                (path.extension().and_then(|x| x.to_str()) == Some("ron"))
                    .then(|| {
                        path.file_stem().and_then(|s| s.to_str()).map(|s| Entry {
                            name: s.to_string(),
                            builtin: false,
                            path: Some(path.clone()),
                            // A user's file larger than a preset can be is not read for this.
                            description: crate::infile::read_text(&path, 1 << 20)
                                .ok()
                                .map(|t| description_of(&t))
                                .unwrap_or_default(),
                        })
                    })
                    .flatten()
            })
            .collect();
        user.sort_by(|a, b| a.name.cmp(&b.name));
        out.retain(|b| !user.iter().any(|u| u.name == b.name));
        out.extend(user);
        out
    }

    /// The entry `name` of `kind` as [`Self::list`] resolves it (the user's file first).
    #[must_use]
    pub fn find(&self, kind: PresetKind, name: &str) -> Option<Entry> {
        self.list(kind).into_iter().find(|e| e.name == name)
    }

    fn read(entry: &Entry) -> Result<(String, String), LibraryError> {
        let path = entry.path.as_ref().ok_or_else(|| LibraryError::Invalid(format!("`{}` has no file", entry.name)))?;
        let text = crate::infile::read_text(path, crate::infile::RON_MAX_BYTES)
            .map_err(|e| LibraryError::Io(e.to_string()))?;
        Ok((text, path.display().to_string()))
    }

    /// Load an instrument entry (validated).
    pub fn load_instrument(&self, entry: &Entry) -> Result<InstrumentSpec, LibraryError> {
        let spec = if entry.builtin {
            InstrumentSpec::preset(&entry.name).map_err(|e| LibraryError::Invalid(e.to_string()))?
        } else {
            let (text, origin) = Self::read(entry)?;
            InstrumentSpec::from_ron(&text, &origin).map_err(|e| LibraryError::Invalid(e.to_string()))?
        };
        spec.validate().map_err(|e| LibraryError::Invalid(format!("{}: {e}", entry.name)))?;
        Ok(spec)
    }

    /// Load a scene entry (parsed and checked).
    pub fn load_scene(&self, entry: &Entry) -> Result<SceneSpec, LibraryError> {
        let spec = if entry.builtin {
            SceneSpec::preset(&entry.name).map_err(|e| LibraryError::Invalid(e.to_string()))?
        } else {
            let (text, origin) = Self::read(entry)?;
            SceneSpec::from_ron(&text, &origin).map_err(|e| LibraryError::Invalid(e.to_string()))?
        };
        spec.validate().map_err(|e| LibraryError::Invalid(format!("{}: {e}", entry.name)))?;
        Ok(spec)
    }

    /// Load a study entry.
    pub fn load_study(&self, entry: &Entry) -> Result<StudySpec, LibraryError> {
        if entry.builtin {
            StudySpec::preset(&entry.name).map_err(|e| LibraryError::Invalid(e.to_string()))
        } else {
            let (text, origin) = Self::read(entry)?;
            StudySpec::from_ron(&text, &origin).map_err(|e| LibraryError::Invalid(e.to_string()))
        }
    }

    fn save<T: Serialize>(
        &self,
        kind: PresetKind,
        name: &str,
        value: &T,
        overwrite: bool,
    ) -> Result<PathBuf, LibraryError> {
        if !valid_name(name) {
            return Err(LibraryError::BadName(name.to_string()));
        }
        if builtin_names(kind).iter().any(|b| b == name) {
            return Err(LibraryError::Builtin { name: name.to_string(), kind: kind.noun() });
        }
        let path = self.dir.join(kind.folder()).join(format!("{name}.ron"));
        if path.exists() && !overwrite {
            return Err(LibraryError::Exists(path.display().to_string()));
        }
        let text = ron::ser::to_string_pretty(value, ron::ser::PrettyConfig::default().struct_names(true))
            .map_err(|e| LibraryError::Io(format!("{name}: {e}")))?;
        write_bytes(&path, format!("// Saved by Shoal.\n{text}\n").as_bytes())
            .map_err(|e| LibraryError::Io(e.to_string()))?;
        Ok(path)
    }

    /// Save an instrument as the user's preset `name` (refuses to overwrite unless asked).
    pub fn save_instrument(&self, name: &str, spec: &InstrumentSpec, overwrite: bool) -> Result<PathBuf, LibraryError> {
        self.save(PresetKind::Instrument, name, spec, overwrite)
    }

    /// Save a study as the user's preset `name`.
    pub fn save_study(&self, name: &str, spec: &StudySpec, overwrite: bool) -> Result<PathBuf, LibraryError> {
        self.save(PresetKind::Study, name, spec, overwrite)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp() -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("shoal-lib-{}-{:?}", std::process::id(), std::thread::current().id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn a_description_is_read_from_the_text_without_parsing_it() {
        assert_eq!(
            description_of("X(name: \"a\", description: \"Lake \\\"Hume\\\" bloom\", b: 1)"),
            "Lake \"Hume\" bloom"
        );
        assert_eq!(description_of("X(name: \"a\")"), "");
        assert_eq!(description_of("X(description: \"cut"), "", "an unterminated string is no description");
    }

    #[test]
    fn save_list_reload_and_refuse_to_overwrite() {
        let lib = Library::at(&temp());
        let mut spec = InstrumentSpec::preset("cubesat").unwrap();
        spec.aperture_mm = 80.0;
        let path = lib.save_instrument("my_cube", &spec, false).unwrap();
        assert!(path.exists());
        assert!(matches!(lib.save_instrument("my_cube", &spec, false), Err(LibraryError::Exists(_))));
        assert!(lib.save_instrument("my_cube", &spec, true).is_ok());
        assert!(matches!(lib.save_instrument("../evil", &spec, false), Err(LibraryError::BadName(_))));
        let entries = lib.list(PresetKind::Instrument);
        assert!(entries.iter().any(|e| e.name == "nominal" && e.builtin));
        let mine = entries.iter().find(|e| e.name == "my_cube").unwrap();
        assert_eq!(lib.load_instrument(mine).unwrap(), spec);
        let _ = std::fs::remove_dir_all(&lib.dir);
    }

    #[test]
    fn a_broken_file_names_line_and_field() {
        let lib = Library::at(&temp());
        let dir = lib.dir.join("instruments");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("broken.ron"), "InstrumentSpec(\n  name: \"b\",\n  apertur_mm: 3.0,\n)").unwrap();
        let entry = lib.list(PresetKind::Instrument).into_iter().find(|e| e.name == "broken").unwrap();
        let e = lib.load_instrument(&entry).unwrap_err().to_string();
        assert!(e.contains("broken.ron") && e.contains("3:") && e.contains("apertur_mm"), "{e}");
        let _ = std::fs::remove_dir_all(&lib.dir);
    }
}
