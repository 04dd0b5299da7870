//! An output folder written whole or not at all.
//!
//! A command that writes a results folder (`shoal study --out DIR`, `report`, `sweep`, …) writes
//! into a staging folder beside `DIR` and, only when everything is written, puts it in place of
//! `DIR` ([`OutputDir::commit`]). So a folder never mixes two runs (a study rerun into a folder
//! that held another keeps none of the old files), an interrupted run leaves the previous results
//! as they were, and a run that fails leaves nothing. Folders Shoal wrote carry a marker file
//! ([`MARKER`]); a folder holding anything else is refused before the run starts, never emptied.
//! Staging folders left by a run that was killed (a second Ctrl-C, SIGKILL) are removed by the
//! next run into the same place.

use std::path::{Path, PathBuf};

use super::StudyError;

/// The file that marks a folder as written by Shoal (and complete): the command that wrote it.
pub const MARKER: &str = ".shoal-output";

/// Files by which earlier versions of Shoal marked their folders (no [`MARKER`] then): a folder
/// holding one of them may be replaced too.
const EARLIER_MARKERS: [&str; 6] =
    ["review.json", "sweep.ron", "report.json", "reproduction.csv", "budget.md", "metrics.csv"];

/// A results folder being written: write into [`OutputDir::path`], then [`OutputDir::commit`].
/// Dropped without a commit (an error, a cancellation), it removes what it wrote.
#[derive(Debug)]
pub struct OutputDir {
    target: PathBuf,
    staging: PathBuf,
    command: String,
    committed: bool,
}

fn io(m: String) -> StudyError {
    StudyError::Io(m)
}

/// The user's `--out` cannot be used: their input, not a failure.
fn refused(out: &Path, why: &str) -> StudyError {
    StudyError::Invalid(crate::parse::FieldError { field: "--out".into(), message: format!("{} {why}", out.display()) })
}

/// Why `out` may not be replaced, if it may not.
fn refusal(out: &Path) -> Option<String> {
    let meta = std::fs::symlink_metadata(out).ok()?;
    if meta.file_type().is_symlink() {
        return Some("is a symbolic link; give the folder itself".into());
    }
    if !meta.is_dir() {
        return Some("is a file, not a folder".into());
    }
    if let (Ok(here), Ok(full)) = (std::env::current_dir(), out.canonicalize())
        && here.starts_with(&full)
    {
        return Some("holds the current directory; give a folder of its own".into());
    }
    let entries = match std::fs::read_dir(out) {
        Ok(e) => e.filter_map(Result::ok).map(|e| e.file_name()).collect::<Vec<_>>(),
        Err(e) => return Some(format!("cannot be read: {e}")),
    };
    if entries.is_empty() || entries.iter().any(|n| n == MARKER || EARLIER_MARKERS.iter().any(|m| n == *m)) {
        return None;
    }
    let first = entries.iter().map(|n| n.to_string_lossy().into_owned()).min().unwrap_or_default();
    Some(format!(
        "holds files Shoal did not write ({} entries, such as `{first}`); give a new or empty folder, or one Shoal wrote",
        entries.len()
    ))
}

/// The folder's parent and name (a bare name's parent is the current directory).
fn split(out: &Path) -> Result<(PathBuf, String), StudyError> {
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .filter(|n| n != "." && n != "..")
        .ok_or_else(|| refused(out, "does not name a folder of its own (not `.`, `..` or a root)"))?;
    let parent =
        out.parent().filter(|p| !p.as_os_str().is_empty()).map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    Ok((parent, name))
}

/// Is process `pid` alive? (Linux: its /proc entry; elsewhere every process is taken as alive,
/// so nothing of a running process is ever removed.)
fn alive(pid: u32) -> bool {
    !Path::new("/proc/self").exists() || Path::new(&format!("/proc/{pid}")).exists()
}

/// Remove the staging and old folders that killed runs left beside `name` in `parent`.
fn remove_leftovers(parent: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(parent) else { return };
    for e in entries.filter_map(Result::ok) {
        let file = e.file_name().to_string_lossy().into_owned();
        let pid = [".shoal-partial-", ".shoal-old-"]
            .iter()
            .find_map(|tag| file.strip_prefix(&format!(".{name}{tag}")).and_then(|p| p.parse::<u32>().ok()));
        if let Some(pid) = pid
            && pid != std::process::id()
            && !alive(pid)
        {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

impl OutputDir {
    /// Check that `out` may be written by `command` (`shoal study`) — new, empty, or a folder
    /// Shoal wrote — and open a staging folder beside it. Call before any work, so a refusal
    /// costs nothing.
    pub fn create(out: &Path, command: &str) -> Result<Self, StudyError> {
        if let Some(why) = refusal(out) {
            return Err(refused(out, &why));
        }
        let (parent, name) = split(out)?;
        std::fs::create_dir_all(&parent).map_err(|e| io(format!("cannot create {}: {e}", parent.display())))?;
        remove_leftovers(&parent, &name);
        let staging = parent.join(format!(".{name}.shoal-partial-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&staging);
        std::fs::create_dir(&staging).map_err(|e| io(format!("cannot create {}: {e}", staging.display())))?;
        Ok(Self { target: out.to_path_buf(), staging, command: command.into(), committed: false })
    }

    /// Where to write now.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Where the results will be once committed.
    #[must_use]
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Everything is written: mark the folder and put it in place of the target (whose earlier
    /// contents, if any, are removed).
    pub fn commit(mut self) -> Result<(), StudyError> {
        let marker = format!("{}\nshoal {}\n", self.command, env!("CARGO_PKG_VERSION"));
        super::write_bytes(&self.staging.join(MARKER), marker.as_bytes())?;
        // Checked again: something may have appeared there while the run ran.
        if let Some(why) = refusal(&self.target) {
            // Kept: the run's results are not thrown away for a folder that appeared meanwhile.
            self.committed = true;
            let (target, staging) = (self.target.display(), self.staging.display());
            return Err(io(format!("--out {target} {why}; the results are left in {staging}")));
        }
        let (parent, name) = split(&self.target)?;
        let old = parent.join(format!(".{name}.shoal-old-{}", std::process::id()));
        let had_old = self.target.exists();
        if had_old {
            std::fs::rename(&self.target, &old)
                .map_err(|e| io(format!("cannot move {} aside: {e}", self.target.display())))?;
        }
        if let Err(e) = std::fs::rename(&self.staging, &self.target) {
            if had_old {
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(io(format!("cannot put the results in {}: {e}", self.target.display())));
        }
        self.committed = true;
        if had_old {
            let _ = std::fs::remove_dir_all(&old);
        }
        Ok(())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn temp(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("shoal-outdir-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_rerun_replaces_the_folder_whole_and_a_failed_one_leaves_it() {
        let root = temp("replace");
        let out = root.join("results");
        let first = OutputDir::create(&out, "shoal study a").unwrap();
        std::fs::write(first.path().join("a_only.csv"), "a").unwrap();
        first.commit().unwrap();
        assert!(out.join("a_only.csv").exists() && out.join(MARKER).exists());
        // A second run that fails (dropped without commit): the first results stay, no leftovers.
        let failed = OutputDir::create(&out, "shoal study b").unwrap();
        std::fs::write(failed.path().join("b_only.csv"), "b").unwrap();
        drop(failed);
        assert!(out.join("a_only.csv").exists() && !out.join("b_only.csv").exists());
        assert_eq!(std::fs::read_dir(&root).unwrap().count(), 1, "only the results folder is left");
        // A second run that completes: nothing of the first is left.
        let second = OutputDir::create(&out, "shoal study b").unwrap();
        std::fs::write(second.path().join("b_only.csv"), "b").unwrap();
        second.commit().unwrap();
        assert!(!out.join("a_only.csv").exists() && out.join("b_only.csv").exists());
        assert_eq!(std::fs::read_dir(&root).unwrap().count(), 1);
        let _ = std::fs::remove_dir_all(&root);
    }

    #[test]
    fn a_folder_of_someone_elses_files_is_refused_before_anything_runs() {
        let root = temp("foreign");
        std::fs::write(root.join("thesis.tex"), "mine").unwrap();
        let e = OutputDir::create(&root, "shoal study").unwrap_err().to_string();
        assert!(e.contains("holds files Shoal did not write") && e.contains("thesis.tex"), "{e}");
        assert_eq!(std::fs::read_to_string(root.join("thesis.tex")).unwrap(), "mine");
        let file = root.join("thesis.tex");
        assert!(OutputDir::create(&file, "shoal study").unwrap_err().to_string().contains("is a file"));
        let _ = std::fs::remove_dir_all(&root);
    }

    #[test]
    fn leftovers_of_a_killed_run_are_removed_by_the_next() {
        let root = temp("leftover");
        // PID 0 is never a user process: its staging folder is a killed run's.
        let stale = root.join(".results.shoal-partial-0");
        std::fs::create_dir_all(stale.join("figures")).unwrap();
        std::fs::write(stale.join("figures/a.png.partial"), "half").unwrap();
        let out = OutputDir::create(&root.join("results"), "shoal study").unwrap();
        assert!(!stale.exists());
        out.commit().unwrap();
        let _ = std::fs::remove_dir_all(&root);
    }
}
