//! A scientist's own retrieval, run as a program: Shoal writes the corrected Rrs to a NetCDF file
//! (the bands, their noise, the geometry, the land mask; never the truth), runs the program on it
//! with a time limit, and reads the products it writes back into a [`Product`] that is scored,
//! mapped and judged like aLMI's or SAMBUCA's.
//!
//! ```ron
//! External((
//!     name: "oc4",
//!     command: ["python3", "{example:oc4.py}", "{input}", "{output}"],
//!     products: ["chl_mg_m3"],
//! ))
//! ```
//!
//! - `command` is the program and its arguments, run without a shell in a fresh folder of the
//!   system's temporary directory (removed afterwards). In its arguments `{input}` and `{output}`
//!   become the two files' paths, `{dir}` the study file's directory (resolved when a study is read:
//!   a built-in study has none), and `{example:NAME}` a built-in example script (`presets/examples/`)
//!   written into the run's folder — so a built-in study runs from any directory.
//! - The input ([`super::external_io`]) has dimensions (line, pixel, band): `rrs` with its
//!   `_FillValue` where the correction flagged a band invalid or saturated or on land, `land`,
//!   the bands' `wavelength`, `bandwidth`, `band_name` and `nedr`, and per pixel column the
//!   `solar_zenith_angle` and `sensor_zenith_angle` in degrees.
//! - The output must hold every variable of `products` (Shoal's names: `chl_mg_m3`, `nap_g_m3`,
//!   `cdom_per_m`, `depth_m`) as float (line, pixel) of the input's size, NaN or a `_FillValue`
//!   where the algorithm returns nothing. A pixel is returned where every product is finite and
//!   positive (the metrics are in log space).
//! - A program that cannot start, exits with an error, runs past `time_limit_s`, or writes a file
//!   without a product or of another size is an error naming what went wrong, with the end of its
//!   standard error. The engine keeps the rest of the run (the Rrs, the other retrievals) and
//!   reports the failure in place of this retrieval's product.
//!
//! A study file is often someone else's, and an external retrieval runs their program: nothing
//! runs until the user has allowed it ([`allow_all`] from `--allow-external`, [`allow`] for one
//! command from the app's prompt). Allowing is per process and never saved.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use super::RetrievalError;
use super::run::{Product, RetrievalInputs};
use crate::control::RunControl;
use crate::parse::FieldError;

/// A user's program as a retrieval.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExternalSpec {
    /// Name in tables, maps and file names: 1 to 32 ASCII letters, digits and `_`, starting with a
    /// letter (not a built-in retrieval's name: [`super::run::BUILT_IN_NAMES`]).
    pub name: String,
    /// The program and its arguments (see the module documentation for `{input}`, `{output}`,
    /// `{dir}` and `{example:NAME}`). Empty when `function` is given.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub command: Vec<String>,
    /// Instead of a program: a function this process registered ([`super::function`]), given
    /// the program's input in memory.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub function: Option<String>,
    /// The variables the program writes: one or more of `chl_mg_m3`, `nap_g_m3`, `cdom_per_m`,
    /// `depth_m`.
    pub products: Vec<String>,
    /// Bands given to the program, by name (default: every band).
    #[serde(default)]
    pub bands: Option<Vec<String>>,
    /// Wall-clock limit per run, s.
    #[serde(default = "default_time_limit_s")]
    pub time_limit_s: f64,
}

const fn default_time_limit_s() -> f64 {
    ExternalSpec::DEFAULT_TIME_LIMIT_S
}

/// Built-in example scripts an argument may name as `{example:NAME}`.
pub const EXAMPLES: &[(&str, &str)] = &[("oc4.py", include_str!("../../presets/examples/oc4.py"))];

/// Most characters of the program's standard error quoted in an error.
const STDERR_TAIL_CHARS: usize = 3000;

/// Largest output file read back, bytes (a full-resolution product of four maps is ~100 MB).
const MAX_OUTPUT_BYTES: u64 = 4 << 30;

static ALLOW_ALL: AtomicBool = AtomicBool::new(false);
static ALLOWED: Mutex<Vec<Vec<String>>> = Mutex::new(Vec::new());

/// Allow every external retrieval of this process (`--allow-external`).
pub fn allow_all() {
    ALLOW_ALL.store(true, Ordering::SeqCst);
}

/// Allow one command, exactly as written in the spec (the app's prompt).
pub fn allow(command: &[String]) {
    let mut allowed = ALLOWED.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    if !allowed.iter().any(|c| c == command) {
        allowed.push(command.to_vec());
    }
}

/// May `command` run?
#[must_use]
pub fn allowed(command: &[String]) -> bool {
    ALLOW_ALL.load(Ordering::SeqCst)
        || ALLOWED.lock().unwrap_or_else(std::sync::PoisonError::into_inner).iter().any(|c| c == command)
}

impl ExternalSpec {
    /// `time_limit_s` when a file leaves it out, s.
    pub const DEFAULT_TIME_LIMIT_S: f64 = 300.0;

    /// Check the spec's fields (not whether the program exists: that shows when it runs).
    pub fn validate(&self) -> Result<(), RetrievalError> {
        let invalid = |field: &str, message: String| {
            RetrievalError::Invalid(FieldError { field: format!("retrievals[i].External.{field}"), message })
        };
        let name_ok = (1..=32).contains(&self.name.len())
            && self.name.starts_with(|c: char| c.is_ascii_alphabetic())
            && self.name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        let reserved = super::run::BUILT_IN_NAMES;
        if !name_ok || reserved.iter().any(|r| r.eq_ignore_ascii_case(&self.name)) {
            return Err(invalid(
                "name",
                format!(
                    "`{}` (allowed: 1 to 32 ASCII letters, digits and _, starting with a letter; not {}, the built-in retrievals' names)",
                    self.name.escape_debug(),
                    reserved.join(", ")
                ),
            ));
        }
        match (&self.function, self.command.is_empty()) {
            (Some(_), false) => {
                return Err(invalid("function", "and `command` are both given (allowed: one of them)".into()));
            }
            (Some(f), true) if f.trim().is_empty() => {
                return Err(invalid("function", "is empty (allowed: the name a function was registered under)".into()));
            }
            (Some(_), true) => {}
            (None, _) if self.command.is_empty() || self.command[0].trim().is_empty() => {
                return Err(invalid(
                    "command",
                    "is empty (allowed: a program and its arguments, or `function` instead)".into(),
                ));
            }
            (None, _) => {}
        }
        if self.command.len() > 64 || self.command.iter().any(|a| a.len() > 4096) {
            return Err(invalid("command", "is over 64 arguments or an argument over 4096 bytes".into()));
        }
        let known = crate::variable::KEYS;
        if self.products.is_empty() {
            return Err(invalid("products", format!("is empty (allowed: one or more of {})", known.join(", "))));
        }
        for (i, p) in self.products.iter().enumerate() {
            if !known.contains(&p.as_str()) || self.products[..i].contains(p) {
                return Err(invalid(
                    "products",
                    format!("`{}` (allowed: each of {} at most once)", p.escape_debug(), known.join(", ")),
                ));
            }
        }
        for a in &self.command {
            if let Some(rest) = a.split("{example:").nth(1) {
                let name = rest.split('}').next().unwrap_or_default();
                if !EXAMPLES.iter().any(|(n, _)| *n == name) {
                    let names: Vec<&str> = EXAMPLES.iter().map(|(n, _)| *n).collect();
                    return Err(invalid(
                        "command",
                        format!("no built-in example `{}` (there are: {})", name.escape_debug(), names.join(", ")),
                    ));
                }
            }
        }
        crate::ranges::EXTERNAL_TIME_LIMIT_S.check(self.time_limit_s).map_err(|m| invalid("time_limit_s", m))
    }

    /// The spec with `{dir}` replaced by `dir` (the study file's directory), or an error naming the
    /// argument when there is no directory (a built-in study).
    pub fn with_dir(&self, dir: Option<&Path>) -> Result<Self, RetrievalError> {
        let mut out = self.clone();
        for a in &mut out.command {
            if a.contains("{dir}") {
                let Some(d) = dir else {
                    return Err(RetrievalError::Invalid(FieldError {
                        field: "retrievals[i].External.command".into(),
                        message: format!("`{a}` names {{dir}}, but this study has no file to be relative to"),
                    }));
                };
                // A study named by its bare file name (`s.ron`) has the empty path as its
                // directory: that is the current directory.
                let d = if d.as_os_str().is_empty() { Path::new(".") } else { d };
                let d = std::path::absolute(d).unwrap_or_else(|_| d.to_path_buf());
                let d = d.to_string_lossy();
                // The run expands the other placeholders in the result: a folder whose name
                // held one would be expanded a second time.
                if d.contains(['{', '}']) {
                    return Err(RetrievalError::Invalid(FieldError {
                        field: "retrievals[i].External.command".into(),
                        message: format!(
                            "`{a}`: the study's folder `{d}` holds a brace, which placeholders use; move the study to a folder without one"
                        ),
                    }));
                }
                *a = a.replace("{dir}", &d);
            }
        }
        Ok(out)
    }

    /// May this retrieval run now? A function registered by this process may; a program only once
    /// the user has allowed it ([`allowed`]).
    #[must_use]
    pub fn may_run(&self) -> bool {
        match &self.function {
            Some(_) => true,
            None => allowed(&self.command),
        }
    }

    /// What it runs, for messages: the program's command line, or the function's name.
    #[must_use]
    pub fn what_runs(&self) -> String {
        match &self.function {
            Some(f) => format!("the function `{f}`"),
            None => format!("`{}`", self.command.join(" ")),
        }
    }

    fn error(&self, message: impl Into<String>) -> RetrievalError {
        RetrievalError::External { name: self.name.clone(), message: message.into() }
    }
}

/// A fresh folder for one run, removed when dropped.
struct RunFolder(PathBuf);

impl RunFolder {
    fn new() -> std::io::Result<Self> {
        static NEXT: AtomicU64 = AtomicU64::new(0);
        let n = NEXT.fetch_add(1, Ordering::SeqCst);
        let dir = std::env::temp_dir().join(format!("shoal-external-{}-{n}", std::process::id()));
        // A folder left by a killed process of the same id is removed, never reused.
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir(&dir)?;
        Ok(Self(dir))
    }
}

impl Drop for RunFolder {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Run `spec`'s program over `inputs` and read its products.
pub fn retrieve_external(
    spec: &ExternalSpec,
    inputs: &RetrievalInputs<'_>,
    control: &RunControl,
) -> Result<Product, RetrievalError> {
    spec.validate()?;
    if let Some(name) = &spec.function {
        return super::function::retrieve(spec, name, inputs, control);
    }
    if !allowed(&spec.command) {
        return Err(spec.error(format!(
            "runs a program (`{}`); allow it first (`--allow-external` on the command line, or \"Allow\" in the app)",
            spec.command.join(" ")
        )));
    }
    let used = super::external_io::used_bands(spec, inputs)?;
    let folder = RunFolder::new().map_err(|e| spec.error(format!("cannot make a folder to run in: {e}")))?;
    let input = folder.0.join("input.nc");
    let output = folder.0.join("output.nc");
    super::external_io::write_input(spec, inputs, &used, &input).map_err(|m| spec.error(m))?;
    let mut args = Vec::with_capacity(spec.command.len());
    for a in &spec.command {
        args.push(expand(spec, a, &folder.0, &input, &output)?);
    }
    run_program(spec, &args, &folder.0, control)?;
    if !output.exists() {
        // No path in the message: the run's folder is temporary, and the message is part of the
        // run's output (the same run gives the same words).
        return Err(spec.error(
            "the program exited without writing its output: pass `{output}` in its command and write the products there",
        ));
    }
    let products: Vec<&str> = spec.products.iter().map(String::as_str).collect();
    let maps = crate::netcdf::read_maps(&output, &products, MAX_OUTPUT_BYTES)
        .map_err(|m| spec.error(format!("its output: {m}")))?;
    super::external_io::product(spec, inputs, &maps).map_err(|m| spec.error(m))
}

/// One argument with `{input}`, `{output}` and `{example:NAME}` replaced in one pass from left
/// to right: the text put in is never read again, so a path holding a placeholder's name (a
/// temporary folder called `{output}`) stays as it is.
fn expand(
    spec: &ExternalSpec,
    arg: &str,
    folder: &Path,
    input: &Path,
    output: &Path,
) -> Result<String, RetrievalError> {
    if arg.contains("{dir}") {
        return Err(spec.error(format!("`{arg}`: {{dir}} is only known in a study file")));
    }
    let mut out = String::with_capacity(arg.len());
    let mut rest = arg;
    while let Some(at) = rest.find('{') {
        out.push_str(&rest[..at]);
        let tail = &rest[at..];
        let token = tail.find('}').map(|end| &tail[..=end]);
        let value = match token {
            Some("{input}") => Some(input.to_string_lossy().into_owned()),
            Some("{output}") => Some(output.to_string_lossy().into_owned()),
            Some(t) if t.starts_with("{example:") => {
                let name = &t["{example:".len()..t.len() - 1];
                match EXAMPLES.iter().find(|(n, _)| *n == name) {
                    Some((n, text)) => {
                        let path = folder.join(n);
                        std::fs::write(&path, text)
                            .map_err(|e| spec.error(format!("cannot write {}: {e}", path.display())))?;
                        Some(path.to_string_lossy().into_owned())
                    }
                    None => None,
                }
            }
            _ => None,
        };
        match (token, value) {
            (Some(t), Some(v)) => {
                out.push_str(&v);
                rest = &tail[t.len()..];
            }
            // Not a placeholder: the brace is text.
            _ => {
                out.push('{');
                rest = &tail[1..];
            }
        }
    }
    out.push_str(rest);
    Ok(out)
}

/// Run `args` in `folder` to the end, within the time limit, stopping it when the run is cancelled.
fn run_program(
    spec: &ExternalSpec,
    args: &[String],
    folder: &Path,
    control: &RunControl,
) -> Result<(), RetrievalError> {
    let stderr_path = folder.join("stderr.txt");
    let stdout_path = folder.join("stdout.txt");
    let file = |p: &Path| std::fs::File::create(p).map_err(|e| spec.error(format!("{}: {e}", p.display())));
    let mut command = Command::new(&args[0]);
    command.args(&args[1..]).current_dir(folder).stdin(Stdio::null());
    command.stdout(file(&stdout_path)?).stderr(file(&stderr_path)?);
    // Its own process group, so that stopping it stops whatever it started (a shell's commands,
    // Python's worker processes).
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(&mut command, 0);
    let mut child = command.spawn().map_err(|e| spec.error(format!("cannot start `{}`: {e}", args[0])))?;
    let start = Instant::now();
    let limit = Duration::from_secs_f64(spec.time_limit_s);
    let mut wait = Duration::from_millis(2);
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) => {}
            Err(e) => return Err(spec.error(format!("lost the program: {e}"))),
        }
        if control.cancelled() {
            stop(&mut child);
            return Err(RetrievalError::Cancelled);
        }
        if start.elapsed() > limit {
            stop(&mut child);
            return Err(spec.error(format!(
                "stopped after its time limit of {} s (`time_limit_s`){}",
                spec.time_limit_s,
                stderr_tail(&stderr_path)
            )));
        }
        std::thread::sleep(wait);
        wait = (wait * 2).min(Duration::from_millis(50));
    };
    // Whatever the program started and left running (a shell's background job, a worker
    // process) ends with it: its group is stopped after any exit.
    stop_group(child.id());
    if !status.success() {
        return Err(spec.error(format!("`{}` exited with {status}{}", args[0], stderr_tail(&stderr_path))));
    }
    Ok(())
}

/// Stop the program and everything in its process group, then reap it. SIGKILL goes to the group
/// through the POSIX shell's `kill` builtin (`sh` is on every Unix; procps's `kill` is not in a
/// minimal system): std has no safe call for a group, and Shoal denies `unsafe` outside its SIMD
/// kernels.
fn stop(child: &mut std::process::Child) {
    stop_group(child.id());
    let _ = child.kill();
    let _ = child.wait();
}

/// SIGKILL to every process of the group `leader` started (its id is the group's). After the
/// leader has exited the group lives on while any member does, and its id is not reused until
/// it is empty.
fn stop_group(leader: u32) {
    #[cfg(unix)]
    {
        let group = format!("-{leader}");
        let kill = r#"kill -s KILL -- "$0" 2>/dev/null"#;
        let _ = Command::new("sh").args(["-c", kill, &group]).stdout(Stdio::null()).stderr(Stdio::null()).status();
    }
    #[cfg(not(unix))]
    let _ = leader;
}

/// The end of the program's standard error, as ": its standard error ended: …" (empty without).
fn stderr_tail(path: &Path) -> String {
    // The program may have replaced its standard error's file (by a FIFO, say): read only a
    // regular file, and only its first megabytes.
    let text =
        crate::infile::read(path, 16 << 20).map(|b| String::from_utf8_lossy(&b).into_owned()).unwrap_or_default();
    let text = text.trim_end();
    if text.is_empty() {
        return String::new();
    }
    let count = text.chars().count();
    let tail: String = text.chars().skip(count.saturating_sub(STDERR_TAIL_CHARS)).collect();
    let cut = if count > STDERR_TAIL_CHARS { "…" } else { "" };
    format!("; its standard error ended:\n{cut}{tail}")
}
