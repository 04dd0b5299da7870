//! The app's session on disk: where it is, reading it (a file that cannot be read is moved aside
//! under a name of its own, never overwritten), checking what was read field by field, writing it
//! atomically, and the lock that keeps a second window from overwriting the first one's session.

use std::path::{Path, PathBuf};

use super::model::{AppState, Slot, fallback_requirements};
use crate::spectral::SpectrumSource;

/// Where the session is kept: `session.ron` in the user's Shoal directory (`SHOAL_HOME` when it
/// is set; see [`crate::library::home_dir`]), beside the preset library and the exports.
#[must_use]
pub fn session_path(home: &Path) -> PathBuf {
    home.join("session.ron")
}

/// What reading the saved session found.
#[derive(Debug)]
pub enum SavedSession {
    /// No session file: the first start.
    None,
    /// The session as saved, with what had to be reset in it (empty: nothing).
    Restored(Box<AppState>, Vec<String>),
    /// A file that cannot be read (not UTF-8, not RON, an older or damaged session). It has been
    /// moved aside to the path given, so the next save cannot overwrite what the user made; the
    /// message says what was wrong.
    Unreadable {
        /// Why it could not be read.
        message: String,
        /// Where the file now is.
        kept_at: PathBuf,
    },
}

/// A free name for an unreadable session: `session.ron.unreadable`, then `….unreadable.2`, …,
/// so an earlier one kept aside is never overwritten.
fn aside_name(path: &Path) -> PathBuf {
    let first = path.with_extension("ron.unreadable");
    (1..10_000)
        .map(|i| if i == 1 { first.clone() } else { path.with_extension(format!("ron.unreadable.{i}")) })
        .find(|p| !p.exists())
        .unwrap_or(first)
}

/// Read the session at `path`. A file that cannot be read as a session is renamed to a free
/// `*.unreadable*` name; one that reads is checked field by field ([`repair`]).
#[must_use]
pub fn load_session(path: &Path) -> SavedSession {
    // A session is the app's own file, but it may be a colleague's copy: a regular file within
    // the RON limit. Anything else that is there (too large, a FIFO, a folder) is unreadable and
    // moved aside like a damaged file, so the next save cannot replace it.
    let bytes = match crate::infile::read(path, crate::infile::RON_MAX_BYTES) {
        Ok(bytes) => Ok(bytes),
        Err(_) if std::fs::symlink_metadata(path).is_err() => return SavedSession::None,
        Err(e) => Err(e.message),
    };
    let parsed = bytes.and_then(|bytes| match String::from_utf8(bytes) {
        Ok(text) => AppState::from_session_text(&text),
        Err(e) => Err(format!("byte {} is not UTF-8 text", e.utf8_error().valid_up_to())),
    });
    match parsed {
        Ok(mut state) => {
            let reset = repair(&mut state);
            SavedSession::Restored(Box::new(state), reset)
        }
        Err(message) => {
            let kept_at = aside_name(path);
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

/// Check a restored session field by field, as the app's editors would have: each part that
/// is out of range (a hand-edited or damaged file: a NaN aperture, a negative step) is reset to
/// its default and named in the list returned, so the rest of the session is kept.
pub fn repair(state: &mut AppState) -> Vec<String> {
    // A session from before designs were a list gets its A and B as designs; indices in range.
    state.settle();
    let defaults = AppState::default();
    let mut reset = Vec::new();
    for (i, slot) in state.designs.iter_mut().enumerate() {
        let (name, default) = (super::model::label(i), &defaults.designs[i.min(defaults.designs.len() - 1)]);
        if let Err(e) = slot.spec.validate() {
            let back = [&slot.original, &default.spec].into_iter().find(|s| s.validate().is_ok()).cloned();
            let back = back.unwrap_or_else(|| default.spec.clone());
            reset.push(format!("instrument {name} ({e}): back to {}", back.name));
            *slot = Slot { preset: slot.preset.clone(), original: back.clone(), spec: back };
        } else if slot.original.validate().is_err() {
            slot.original = slot.spec.clone();
        }
    }
    if let Err(e) = state.scene.validate() {
        reset.push(format!("scene ({e}): back to {}", defaults.scene_name));
        (state.scene, state.scene_name) = (defaults.scene.clone(), defaults.scene_name.clone());
    }
    if let Err(e) = state.fidelity.validate() {
        reset.push(format!("fidelity ({e}): back to the defaults"));
        state.fidelity = defaults.fidelity.clone();
    }
    if let Some(SpectrumSource::Constant(v) | SpectrumSource::PowerLaw { coefficient: v, .. }) = &state.snr_reference
        && !(v.is_finite() && *v > 0.0)
    {
        reset.push(format!("SNR reference radiance ({v}): back to the scene's median water radiance"));
        state.snr_reference = None;
    }
    if let Some(SpectrumSource::Table { wavelength_nm, values, .. }) = &state.snr_reference
        && (wavelength_nm.len() != values.len()
            || values.iter().chain(wavelength_nm).any(|v| !(v.is_finite() && *v > 0.0)))
    {
        reset.push("SNR reference spectrum: back to the scene's median water radiance".into());
        state.snr_reference = None;
    }
    if let Err(e) = state.calibration.validate() {
        reset.push(format!("calibration ({e}): back to the defaults"));
        state.calibration = defaults.calibration.clone();
    }
    if let Err(e) = state.requirements.validate() {
        reset.push(format!("requirements ({e}): back to the defaults"));
        state.requirements = fallback_requirements();
    }
    // Each retrieval checked as a study would check it: aLMI's or SAMBUCA's settings out of range
    // go back to the defaults; a study's own retrieval that does not check out is dropped.
    let (mut kept, mut selected) = (Vec::new(), 0);
    for (i, mut r) in std::mem::take(&mut state.retrievals).into_iter().enumerate() {
        if let Err(e) = r.validate() {
            reset.push(format!("retrieval {} settings ({e}): back to the defaults", r.title()));
            let builtin = super::retrievals::built_in(Default::default(), Default::default());
            match builtin.into_iter().find(|b| b.name() == r.name()) {
                Some(b) => r = b,
                None => continue,
            }
        }
        if i == state.selected_retrieval {
            selected = kept.len();
        }
        kept.push(r);
    }
    (state.retrievals, state.selected_retrieval) = (kept, selected);
    reset
}

/// Write the session to `path` atomically (a temporary file, synced, then a rename).
pub fn save_session(path: &Path, state: &AppState) -> Result<(), String> {
    let text = ron::ser::to_string_pretty(state, ron::ser::PrettyConfig::default())
        .map_err(|e| format!("cannot encode the session: {e}"))?;
    crate::study::write_bytes(path, text.as_bytes()).map_err(|e| e.to_string())
}

/// The session's lock: a file beside the session naming the process that owns it. The window
/// that holds it saves the session; a second window started meanwhile does not (it is told so),
/// so whichever closes last cannot overwrite the other's work. A lock left by a process that no
/// longer runs is taken over.
#[derive(Debug)]
pub struct SessionLock {
    path: PathBuf,
}

/// Is process `pid` running? (Linux: its /proc entry. Elsewhere, a lock is always taken as
/// held: the second window then saves nothing, which loses no one's work.)
fn running(pid: u32) -> bool {
    !Path::new("/proc/self").exists() || Path::new(&format!("/proc/{pid}")).exists()
}

impl SessionLock {
    /// Take the lock beside `session`, or say which running process holds it.
    pub fn acquire(session: &Path) -> Result<Self, String> {
        let path = session.with_extension("lock");
        if let Some(parent) = path.parent() {
            let _ = std::fs::create_dir_all(parent);
        }
        for _ in 0..2 {
            match std::fs::OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(mut f) => {
                    use std::io::Write as _;
                    let _ = write!(f, "{}", std::process::id());
                    return Ok(Self { path });
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let holder = crate::infile::read_text(&path, 64).ok().and_then(|t| t.trim().parse::<u32>().ok());
                    match holder {
                        Some(pid) if running(pid) && pid != std::process::id() => {
                            return Err(format!("another Shoal window (process {pid}) has the session open"));
                        }
                        // Left by a process that is gone (or unreadable): take it over.
                        _ => {
                            let _ = std::fs::remove_file(&path);
                        }
                    }
                }
                Err(e) => return Err(format!("cannot create {}: {e}", path.display())),
            }
        }
        Err(format!("cannot take {}", path.display()))
    }
}

impl Drop for SessionLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn home(tag: &str) -> PathBuf {
        let home = std::env::temp_dir().join(format!("shoal-session-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&home);
        std::fs::create_dir_all(&home).unwrap_or_else(|e| panic!("{e}"));
        home
    }

    #[test]
    fn a_session_saved_before_the_schema_version_is_restored() {
        let home = home("old");
        let path = session_path(&home);
        let today = AppState { decimations: vec![16, 2], ..AppState::default() };
        let text = ron::to_string(&today).unwrap_or_else(|e| panic!("{e}"));
        // As an older app saved it: no version, the decimations called `levels`.
        let old =
            text.replace(&format!("schema_version:{},", crate::schema::VERSION), "").replace("decimations:", "levels:");
        assert!(!old.contains("schema_version") && old.contains("levels:[16,2]"), "{old}");
        std::fs::write(&path, old).unwrap_or_else(|e| panic!("{e}"));
        match load_session(&path) {
            SavedSession::Restored(back, _) => assert_eq!(back.decimations, vec![16, 2]),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn the_session_round_trips_and_a_broken_one_is_kept_aside() {
        let home = home("trip");
        let path = session_path(&home);
        assert!(path.starts_with(&home));
        assert!(matches!(load_session(&path), SavedSession::None));
        let mut s = AppState::default();
        s.designs[0].spec.aperture_mm = 77.0;
        save_session(&path, &s).unwrap();
        match load_session(&path) {
            SavedSession::Restored(back, reset) => assert_eq!((*back, reset), (s, Vec::new())),
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

    #[test]
    fn a_non_utf8_session_is_kept_and_a_second_unreadable_one_does_not_overwrite_the_first() {
        let home = home("utf8");
        let path = session_path(&home);
        let mut text = ron::to_string(&AppState::default()).unwrap().into_bytes();
        text.insert(10, 0xFF);
        std::fs::write(&path, &text).unwrap();
        let SavedSession::Unreadable { message, kept_at: first } = load_session(&path) else { panic!("read") };
        assert!(message.contains("not UTF-8"), "{message}");
        assert_eq!(std::fs::read(&first).unwrap(), text, "kept byte for byte");
        std::fs::write(&path, "AppState(").unwrap();
        let SavedSession::Unreadable { kept_at: second, .. } = load_session(&path) else { panic!("read") };
        assert_ne!(first, second);
        assert_eq!(std::fs::read(&first).unwrap(), text, "the first one kept aside is untouched");
        assert_eq!(std::fs::read_to_string(&second).unwrap(), "AppState(");
        let _ = std::fs::remove_dir_all(&home);
    }

    #[test]
    fn a_session_too_large_or_not_a_file_is_moved_aside_not_replaced() {
        let home = home("special");
        let path = session_path(&home);
        // 100 MB of zeros (sparse): refused before a byte is read, and kept.
        std::fs::File::create(&path).unwrap().set_len(100 << 20).unwrap();
        let SavedSession::Unreadable { message, kept_at } = load_session(&path) else { panic!("read") };
        assert!(message.contains("allowed: at most"), "{message}");
        assert_eq!(std::fs::metadata(&kept_at).unwrap().len(), 100 << 20);
        assert!(!path.exists());
        std::fs::create_dir(&path).unwrap();
        let SavedSession::Unreadable { message, kept_at } = load_session(&path) else { panic!("read") };
        assert!(message.contains("directory"), "{message}");
        assert!(kept_at.is_dir() && !path.exists());
        let _ = std::fs::remove_dir_all(&home);
    }

    #[test]
    fn a_nan_in_the_session_is_reset_with_its_field_named_and_the_rest_kept() {
        let mut s = AppState::default();
        s.designs[0].spec.aperture_mm = f64::NAN;
        s.designs[1].spec.read_noise_e = 12.0;
        s.fidelity.spectral_step_nm = -1.0;
        s.noise_seed = 9;
        let reset = repair(&mut s);
        assert_eq!(reset.len(), 2, "{reset:?}");
        assert!(reset[0].starts_with("instrument A (") && reset[0].contains("aperture_mm"), "{reset:?}");
        assert!(reset[1].starts_with("fidelity (") && reset[1].contains("spectral_step_nm"), "{reset:?}");
        assert_eq!(s.designs[0].spec, AppState::default().designs[0].spec);
        assert_eq!((s.designs[1].spec.read_noise_e, s.noise_seed), (12.0, 9), "valid fields are kept");
        assert!(repair(&mut s).is_empty(), "a repaired session is valid");
    }

    #[test]
    fn one_window_holds_the_lock_and_a_stale_lock_is_taken_over() {
        let home = home("lock");
        let path = session_path(&home);
        let lock = SessionLock::acquire(&path).unwrap();
        // The same process asking again (a second window in this process) takes it over; a lock
        // naming another running process is refused. PID 1 always runs.
        std::fs::write(path.with_extension("lock"), "1").unwrap();
        let e = SessionLock::acquire(&path).unwrap_err();
        assert!(e.contains("process 1"), "{e}");
        // PID 0 is never a user process: a stale lock.
        std::fs::write(path.with_extension("lock"), "0").unwrap();
        let again = SessionLock::acquire(&path).unwrap();
        drop(lock);
        drop(again);
        assert!(!path.with_extension("lock").exists());
        let _ = std::fs::remove_dir_all(&home);
    }
}
