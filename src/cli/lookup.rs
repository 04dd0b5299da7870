//! One rule for what a name on the command line means (`--scene`, `--instrument`, a study): a
//! path (it ends in `.ron` or the file exists), else the user's preset in the library (what the
//! app lists, so a user's file shadows the built-in of its name), else the built-in.

use std::path::{Path, PathBuf};

use super::CliError;
use crate::library::{Entry, Library, LibraryError, PresetKind};

/// How to read one kind of preset.
pub(super) struct Lookup<T> {
    /// Which library folder.
    pub(super) kind: PresetKind,
    /// The flag or argument the name came from, for messages.
    pub(super) flag: &'static str,
    /// Parse a RON text (`origin` names it in errors).
    pub(super) from_ron: fn(text: &str, origin: &str) -> Result<T, CliError>,
    /// Read a library entry.
    pub(super) from_library: fn(&Library, &Entry) -> Result<T, LibraryError>,
    /// A built-in by name.
    pub(super) preset: fn(&str) -> Result<T, CliError>,
}

impl<T> Lookup<T> {
    /// The value `arg` names and the directory its own relative paths are read from.
    pub(super) fn resolve(&self, arg: &str) -> Result<(T, Option<PathBuf>), CliError> {
        if arg.ends_with(".ron") || Path::new(arg).exists() {
            let text = crate::infile::read_text(Path::new(arg), crate::infile::RON_MAX_BYTES)
                .map_err(|e| CliError::Input(format!("{} {e}", self.flag)))?;
            return Ok(((self.from_ron)(&text, arg)?, Path::new(arg).parent().map(Path::to_path_buf)));
        }
        if arg.contains(std::path::MAIN_SEPARATOR) || arg.contains('/') {
            // A path that is not there (a built-in or library name never holds a separator).
            return Err(CliError::Input(format!("{} {arg}: no such file or folder", self.flag)));
        }
        let library = Library::user();
        match library.find(self.kind, arg) {
            Some(entry) => {
                let dir = entry.path.as_deref().and_then(Path::parent).map(Path::to_path_buf);
                let value = (self.from_library)(&library, &entry)
                    .map_err(|e| CliError::Input(format!("{} {arg}: {e}", self.flag)))?;
                Ok((value, dir))
            }
            None => Ok(((self.preset)(arg)?, None)),
        }
    }
}
