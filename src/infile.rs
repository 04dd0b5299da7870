//! Reading a file someone else made: presets, studies, survey rasters, spectra, shard records,
//! NetCDF products, an external program's output, figures in a results folder. Every such read
//! goes through here, so that each is
//! - **a regular file**: a FIFO, a device, a socket or a directory is refused by name before it is
//!   opened for reading (opening a FIFO would block until a writer came, for ever in a shared
//!   folder), and the open itself never blocks (`O_NONBLOCK`), so a file swapped for a FIFO
//!   between the check and the open is refused too;
//! - **bounded**: the size is checked against the caller's limit before a byte is read, and the
//!   read stops at the limit if the file grows meanwhile.
//!
//! Messages name the file and what is allowed: `survey.tif: is a FIFO, not a regular file`,
//! `evaluations.ron: is 70.3 MB (allowed: at most 64.0 MB)`.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Limit for a RON file (preset, study, sweep, session, shard record's text): far above any
/// real one (the largest built-in study is a few kB; a shard record of 100 000 evaluations is
/// tens of MB).
pub const RON_MAX_BYTES: u64 = 64 << 20;
/// Limit for a text table (a spectrum CSV, `--toa` spectra, an SIOP table).
pub const TABLE_MAX_BYTES: u64 = 64 << 20;

/// A file that could not be read, or is not one Shoal reads: the path and why.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct InFileError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong and what is allowed.
    pub message: String,
}

fn error(path: &Path, message: impl Into<String>) -> InFileError {
    InFileError { path: path.to_path_buf(), message: message.into() }
}

/// What kind of file `t` is, for a refusal.
fn kind(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_block_device() || t.is_char_device() {
            return "a device";
        }
    }
    if t.is_dir() { "a directory" } else { "not a regular file" }
}

/// `bytes` as MB with one decimal.
fn mb(bytes: u64) -> String {
    format!("{:.1} MB", bytes as f64 / 1e6)
}

/// Open `path` for reading if it is a regular file of at most `max_bytes`; its size.
pub fn open(path: &Path, max_bytes: u64) -> Result<(File, u64), InFileError> {
    // Follows symbolic links: a link to a regular file is that file.
    let meta = std::fs::metadata(path).map_err(|e| error(path, e.to_string()))?;
    if !meta.is_file() {
        return Err(error(path, format!("is {}, not a regular file", kind(meta.file_type()))));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK);
    let file = options.open(path).map_err(|e| error(path, e.to_string()))?;
    // Checked again on the open handle: the path may have been replaced since.
    let meta = file.metadata().map_err(|e| error(path, e.to_string()))?;
    if !meta.is_file() {
        return Err(error(path, format!("is {}, not a regular file", kind(meta.file_type()))));
    }
    let size = meta.len();
    if size > max_bytes {
        return Err(error(path, format!("is {} (allowed: at most {})", mb(size), mb(max_bytes))));
    }
    Ok((file, size))
}

/// The bytes of `path`, a regular file of at most `max_bytes`.
pub fn read(path: &Path, max_bytes: u64) -> Result<Vec<u8>, InFileError> {
    let (file, size) = open(path, max_bytes)?;
    let mut bytes = Vec::with_capacity(usize::try_from(size).unwrap_or(0));
    // One byte past the limit tells a file that grew after the check.
    file.take(max_bytes.saturating_add(1)).read_to_end(&mut bytes).map_err(|e| error(path, e.to_string()))?;
    if bytes.len() as u64 > max_bytes {
        return Err(error(path, format!("grew past {} while being read", mb(max_bytes))));
    }
    Ok(bytes)
}

/// The text of `path`, a regular UTF-8 file of at most `max_bytes`.
pub fn read_text(path: &Path, max_bytes: u64) -> Result<String, InFileError> {
    let bytes = read(path, max_bytes)?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        error(path, format!("is not UTF-8 text (byte {at})"))
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn tempdir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("shoal-infile-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn reads_a_regular_file_within_its_limit() {
        let d = tempdir("regular");
        let p = d.join("a.ron");
        std::fs::write(&p, "Instrument(name: \"x\")").unwrap();
        assert_eq!(read_text(&p, 1000).unwrap(), "Instrument(name: \"x\")");
        let e = read(&p, 10).unwrap_err();
        assert!(e.to_string().ends_with("a.ron: is 0.0 MB (allowed: at most 0.0 MB)"), "{e}");
        std::fs::write(&p, [0xff, 0xfe, 0x41]).unwrap();
        assert!(read_text(&p, 100).unwrap_err().message.contains("not UTF-8"));
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn refuses_directories_and_missing_files() {
        let d = tempdir("dir");
        assert_eq!(read(&d, 100).unwrap_err().message, "is a directory, not a regular file");
        assert!(read(&d.join("none"), 100).is_err());
        let _ = std::fs::remove_dir_all(&d);
    }

    #[cfg(unix)]
    #[test]
    fn refuses_a_fifo_without_blocking() {
        let d = tempdir("fifo");
        let p = d.join("products.nc");
        let made = std::process::Command::new("mkfifo").arg(&p).status();
        if !made.is_ok_and(|s| s.success()) {
            eprintln!("skipped: mkfifo is not available");
            return;
        }
        let start = std::time::Instant::now();
        let e = read(&p, 100).unwrap_err();
        assert_eq!(e.message, "is a FIFO, not a regular file");
        assert!(start.elapsed().as_secs_f64() < 5.0);
        let _ = std::fs::remove_dir_all(&d);
    }
}
