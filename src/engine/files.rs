//! The files a run reads, fingerprinted for the cache keys.
//!
//! A configuration names some inputs by path: a SIOP set or its CSV columns, a substrate library,
//! a map image or GeoTIFF raster, a spectrum. The stage keys hash the configuration, so without
//! this a file edited on disk under the same name would leave every key unchanged and the cache
//! would serve products computed from the old file — a silent wrong answer in the app, where the
//! engine lives for the whole session.
//!
//! [`fingerprint`] finds the files without a list of the fields that hold paths (a list a new
//! field could miss): every text value of the configuration ([`crate::fields::strings`]) that
//! names an existing file — as given, or relative to the scene's directory — counts,
//! and so does every quoted string inside such a file when it is small text (a SIOP file names
//! its CSV columns relative to itself, whatever its extension). A file up to [`HASHED_BYTES`]
//! enters the fingerprint with its contents; a larger one (a raster) with its length,
//! modification and status-change times and inode, so that an edit keeping length and
//! modification time (`cp -p`, `rsync -a`) still counts. A string that happens to name a file
//! no stage reads only makes the keys more cautious.

use std::collections::BTreeMap;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::{Path, PathBuf};

use serde::Serialize;

/// How deep references are followed: the configuration's files, and the files one of them
/// names (a SIOP file's CSV columns).
const DEPTH: usize = 2;

/// Files up to this size are hashed whole (and searched for the files they name): the SIOP,
/// substrate and spectrum files, a few kilobytes each. Keys are built on every slider move.
pub const HASHED_BYTES: u64 = 1 << 20;

/// A hash of every file `part` (a part of a run's configuration) refers to, as given or under
/// `base_dir` (see the module docs); 0 when it refers to none.
#[must_use]
pub fn fingerprint(part: &impl Serialize, base_dir: Option<&Path>) -> u64 {
    let mut bases: Vec<PathBuf> = base_dir.iter().map(|d| d.to_path_buf()).collect();
    bases.push(PathBuf::new());
    let mut files = BTreeMap::new();
    // Every text the configuration holds is tried as a file name ([`crate::fields::strings`]).
    for text in crate::fields::strings(part) {
        add_file(&text, &bases, &mut files, DEPTH);
    }
    if files.is_empty() {
        return 0;
    }
    let mut h = DefaultHasher::new();
    files.hash(&mut h);
    h.finish()
}

/// The pieces of a referenced file's `text` between double quotes (every other piece: paths hold
/// no escaped quotes, and a wrong piece names no file and adds nothing).
fn quoted_strings(text: &str) -> impl Iterator<Item = &str> {
    text.split('"').skip(1).step_by(2)
}

/// What identifies a file's version: its contents when small, else its metadata.
#[derive(Hash)]
enum State {
    Contents(Vec<u8>),
    /// Length, modification time, and (on Unix) status-change time and inode.
    Metadata {
        len: u64,
        modified: Option<std::time::SystemTime>,
        identity: (i64, i64, u64),
    },
    Unreadable,
}

fn state_of(path: &Path) -> State {
    let Ok(meta) = std::fs::metadata(path) else { return State::Unreadable };
    if meta.len() <= HASHED_BYTES
        && let Ok(bytes) = crate::infile::read(path, HASHED_BYTES)
    {
        return State::Contents(bytes);
    }
    State::Metadata { len: meta.len(), modified: meta.modified().ok(), identity: identity(&meta) }
}

#[cfg(unix)]
fn identity(meta: &std::fs::Metadata) -> (i64, i64, u64) {
    use std::os::unix::fs::MetadataExt;
    (meta.ctime(), meta.ctime_nsec(), meta.ino())
}

#[cfg(not(unix))]
fn identity(_: &std::fs::Metadata) -> (i64, i64, u64) {
    (0, 0, 0)
}

/// Add `name` (as given, or under one of `bases`) if it is a file, with its state, and what it
/// names in turn (each file is read once).
fn add_file(name: &str, bases: &[PathBuf], files: &mut BTreeMap<PathBuf, State>, depth: usize) {
    if depth == 0 || name.is_empty() || name.len() > 4096 || name.contains('\n') {
        return;
    }
    let given = Path::new(name);
    let candidates: Vec<PathBuf> =
        if given.is_absolute() { vec![given.to_path_buf()] } else { bases.iter().map(|b| b.join(given)).collect() };
    for path in candidates {
        if !path.is_file() || files.contains_key(&path) {
            continue;
        }
        let state = state_of(&path);
        let base = vec![path.parent().map(Path::to_path_buf).unwrap_or_default()];
        let text = match &state {
            State::Contents(bytes) => std::str::from_utf8(bytes).ok().map(str::to_owned),
            _ => None,
        };
        files.insert(path, state);
        for quoted in text.iter().flat_map(|t| quoted_strings(t)) {
            add_file(quoted, &base, files, depth - 1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneSpec;
    use crate::water::SiopSource;

    #[test]
    fn a_siop_file_and_the_csv_it_names_move_the_fingerprint() {
        let dir = std::env::temp_dir().join(format!("shoal-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut scene = SceneSpec::preset("lake_hume_bloom").unwrap();
        let none = fingerprint(&scene, Some(&dir));
        assert_eq!(none, 0, "a built-in scene names no file");
        let csv = dir.join("a_ph.csv");
        std::fs::write(&csv, "wavelength_nm,a_ph_star\n400,0.03\n700,0.01\n").unwrap();
        std::fs::write(dir.join("siop.ron"), "(name: \"mine\", a_ph_star: Csv(\"a_ph.csv\"))").unwrap();
        scene.siop = SiopSource::File("siop.ron".into());
        let with_file = fingerprint(&scene, Some(&dir));
        assert_ne!(with_file, none);
        assert_eq!(with_file, fingerprint(&scene, Some(&dir)), "nothing changed, the same fingerprint");
        assert_eq!(fingerprint(&scene, None), 0, "relative to another directory it names no file");
        // The CSV the SIOP file names, relative to itself, rewritten with a new length.
        std::fs::write(&csv, "wavelength_nm,a_ph_star\n400,0.031\n700,0.01\n").unwrap();
        let edited = fingerprint(&scene, Some(&dir));
        assert_ne!(edited, with_file, "an edit of the nested CSV");
        // A same-length edit with the old modification time restored (as `cp -p` would leave
        // it): small files are hashed whole.
        let modified = std::fs::metadata(&csv).unwrap().modified().unwrap();
        std::fs::write(&csv, "wavelength_nm,a_ph_star\n400,0.032\n700,0.01\n").unwrap();
        std::fs::File::options().write(true).open(&csv).unwrap().set_modified(modified).unwrap();
        assert_ne!(fingerprint(&scene, Some(&dir)), edited, "same length, same time, new contents");
        // A SIOP file under another extension still has its CSVs followed.
        std::fs::rename(dir.join("siop.ron"), dir.join("siop.txt")).unwrap();
        scene.siop = SiopSource::File("siop.txt".into());
        let renamed = fingerprint(&scene, Some(&dir));
        std::fs::write(&csv, "wavelength_nm,a_ph_star\n400,0.033\n700,0.01\n").unwrap();
        assert_ne!(fingerprint(&scene, Some(&dir)), renamed, "the CSV a .txt SIOP file names");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
