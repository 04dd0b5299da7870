//! The app's session on disk: where it is, reading it (a file that does not parse is moved
//! aside, never overwritten), writing it atomically.

use super::model::AppState;

/// Where the session is kept: `session.ron` in the user's Shoal directory (`SHOAL_HOME` when it
/// is set; see [`crate::library::home_dir`]), beside the preset library and the exports.
#[must_use]
pub fn session_path(home: &std::path::Path) -> std::path::PathBuf {
    home.join("session.ron")
}

/// What reading the saved session found.
#[derive(Debug)]
pub enum SavedSession {
    /// No session file: the first start.
    None,
    /// The session as saved.
    Restored(Box<AppState>),
    /// A file that does not parse (an older or damaged session). It has been moved aside to
    /// the path given, so the next save cannot overwrite what the user made; the message says
    /// what was wrong.
    Unreadable {
        /// Why it could not be read.
        message: String,
        /// Where the file now is.
        kept_at: std::path::PathBuf,
    },
}

/// Read the session at `path`; a file that does not parse is renamed to `*.unreadable`.
#[must_use]
pub fn load_session(path: &std::path::Path) -> SavedSession {
    let Ok(text) = std::fs::read_to_string(path) else { return SavedSession::None };
    match ron::from_str::<AppState>(&text) {
        Ok(state) => SavedSession::Restored(Box::new(state)),
        Err(e) => {
            let kept_at = path.with_extension("ron.unreadable");
            let message = crate::parse::describe(&text, &e);
            let moved = std::fs::rename(path, &kept_at);
            SavedSession::Unreadable {
                message: match moved {
                    Ok(()) => message,
                    Err(m) => format!("{message} (and it could not be moved aside: {m})"),
                },
                kept_at,
            }
        }
    }
}

/// Write the session to `path` atomically (a temporary file, synced, then a rename).
pub fn save_session(path: &std::path::Path, state: &AppState) -> Result<(), String> {
    let text = ron::ser::to_string_pretty(state, ron::ser::PrettyConfig::default())
        .map_err(|e| format!("cannot encode the session: {e}"))?;
    crate::study::write_bytes(path, text.as_bytes()).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_session_round_trips_and_a_broken_one_is_kept_aside() {
        let home = std::env::temp_dir().join(format!("shoal-session-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&home);
        let path = session_path(&home);
        assert!(path.starts_with(&home));
        assert!(matches!(load_session(&path), SavedSession::None));
        let mut s = AppState::default();
        s.a.spec.aperture_mm = 77.0;
        save_session(&path, &s).unwrap();
        match load_session(&path) {
            SavedSession::Restored(back) => assert_eq!(*back, s),
            other => panic!("{other:?}"),
        }
        std::fs::write(&path, "AppState(a: 3").unwrap();
        match load_session(&path) {
            SavedSession::Unreadable { kept_at, .. } => {
                assert_eq!(std::fs::read_to_string(&kept_at).unwrap(), "AppState(a: 3");
                assert!(!path.exists(), "the broken file is moved, not left to be overwritten");
            }
            other => panic!("{other:?}"),
        }
        let _ = std::fs::remove_dir_all(&home);
    }
}
