//! The files a run reads, fingerprinted for the cache keys.
//!
//! A configuration names some inputs by path: a SIOP set or its CSV columns, a substrate library,
//! a map image or GeoTIFF raster, a spectrum. The stage keys hash the configuration, so without
//! this a file edited on disk under the same name would leave every key unchanged and the cache
//! would serve products computed from the old file — a silent wrong answer in the app, where the
//! engine lives for the whole session.
//!
//! [`fingerprint`] finds the files without a list of the fields that hold paths (a list a new
//! field could miss): every string in the configuration, serialised, that names an existing file
//! — as given, or relative to the scene's directory — counts, and so does every quoted string
//! inside such a file when it is RON (a SIOP file names its CSV columns relative to itself). Each
//! file enters the fingerprint with its path, length and modification time; contents are not
//! read (a raster may be large, and the key is built for every slider move). A string that
//! happens to name a file no stage reads only makes the keys more cautious.

use std::collections::BTreeSet;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::{Path, PathBuf};

use serde::Serialize;

/// How deep references are followed: the configuration's files, and the files a RON file among
/// them names (a SIOP file's CSV columns).
const DEPTH: usize = 2;

/// A hash of the path, length and modification time of every file `part` (a part of a run's
/// configuration) refers to, as given or under `base_dir` (see the module docs); 0 when it
/// refers to none.
#[must_use]
pub fn fingerprint(part: &impl Serialize, base_dir: Option<&Path>) -> u64 {
    let mut strings = Vec::new();
    if let Ok(value) = serde_json::to_value(part) {
        collect_strings(&value, &mut strings);
    }
    let mut files = BTreeSet::new();
    let mut bases: Vec<PathBuf> = base_dir.iter().map(|d| d.to_path_buf()).collect();
    bases.push(PathBuf::new());
    for s in &strings {
        add_file(s, &bases, &mut files, DEPTH);
    }
    if files.is_empty() {
        return 0;
    }
    let mut h = DefaultHasher::new();
    for path in &files {
        path.hash(&mut h);
        if let Ok(meta) = std::fs::metadata(path) {
            meta.len().hash(&mut h);
            meta.modified().ok().hash(&mut h);
        }
    }
    h.finish()
}

fn collect_strings(value: &serde_json::Value, out: &mut Vec<String>) {
    match value {
        serde_json::Value::String(s) => out.push(s.clone()),
        serde_json::Value::Array(items) => items.iter().for_each(|v| collect_strings(v, out)),
        serde_json::Value::Object(map) => map.values().for_each(|v| collect_strings(v, out)),
        _ => {}
    }
}

/// Add `name` (as given, or under one of `bases`) if it is a file, and what it names in turn.
fn add_file(name: &str, bases: &[PathBuf], files: &mut BTreeSet<PathBuf>, depth: usize) {
    if depth == 0 || name.is_empty() || name.len() > 4096 || name.contains('\n') {
        return;
    }
    let given = Path::new(name);
    let candidates: Vec<PathBuf> =
        if given.is_absolute() { vec![given.to_path_buf()] } else { bases.iter().map(|b| b.join(given)).collect() };
    for path in candidates {
        if !path.is_file() || !files.insert(path.clone()) {
            continue;
        }
        if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ron"))
            && let Ok(text) = std::fs::read_to_string(&path)
        {
            let base = vec![path.parent().map(Path::to_path_buf).unwrap_or_default()];
            // The quoted strings: every other piece between double quotes (paths in these
            // files have no escaped quotes; a wrong piece names no file and adds nothing).
            for quoted in text.split('"').skip(1).step_by(2) {
                add_file(quoted, &base, files, depth - 1);
            }
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
        // The same bytes with a later modification time count as an edit too.
        let later = std::time::SystemTime::now() + std::time::Duration::from_secs(5);
        std::fs::File::options().write(true).open(&csv).unwrap().set_modified(later).unwrap();
        assert_ne!(fingerprint(&scene, Some(&dir)), edited, "a touch");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
