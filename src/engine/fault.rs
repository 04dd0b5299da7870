//! Fault injection: make one stage fail at one pixel, to prove that failures are reported with
//! the stage and the pixel and that whoever runs the chain (the CLI, the app) survives them.
//!
//! A [`Fault`] travels in [`super::RunConfig::fault`] (never serialised). The CLI reads one from
//! the environment variable `SHOAL_FAULT` (`STAGE:ROW:COLUMN[:panic|error]`, e.g.
//! `SHOAL_FAULT=level-0:3:5:panic shoal simulate …`); tests set it directly.

use super::Stage;

/// How the injected fault fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultKind {
    /// A panic inside the stage's per-pixel loop at the pixel (stages without one panic on
    /// entry, with no pixel to report).
    Panic,
    /// The stage returns an error naming the pixel.
    Error,
}

/// A fault injected into one stage at one pixel of the simulated image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fault {
    /// The stage that fails.
    pub stage: Stage,
    /// Row of the simulated (possibly decimated) image.
    pub row: usize,
    /// Column of the simulated image.
    pub column: usize,
    /// Panic or error.
    pub kind: FaultKind,
}

impl Fault {
    /// The environment variable the CLI reads.
    pub const ENV: &'static str = "SHOAL_FAULT";

    /// Parse `STAGE:ROW:COLUMN[:panic|error]` (stage names as in the run report).
    ///
    /// ```
    /// use shoal::engine::{Fault, FaultKind, Stage};
    /// let f = Fault::parse("level-0:3:5").unwrap();
    /// assert_eq!((f.stage, f.row, f.column, f.kind), (Stage::Level0, 3, 5, FaultKind::Panic));
    /// assert!(Fault::parse("lens:1:1").unwrap_err().contains("level-0"));
    /// ```
    pub fn parse(text: &str) -> Result<Self, String> {
        let parts: Vec<&str> = text.split(':').map(str::trim).collect();
        let usage = || format!("{} = `{text}`: expected STAGE:ROW:COLUMN[:panic|error]", Self::ENV);
        if !(3..=4).contains(&parts.len()) {
            return Err(usage());
        }
        let stage = Stage::ALL.into_iter().find(|s| s.to_string() == parts[0]).ok_or_else(|| {
            let names: Vec<String> = Stage::ALL.iter().map(ToString::to_string).collect();
            format!("{}: no stage `{}` (stages: {})", Self::ENV, parts[0], names.join(", "))
        })?;
        let row = parts[1].parse().map_err(|_| usage())?;
        let column = parts[2].parse().map_err(|_| usage())?;
        let kind = match parts.get(3).copied() {
            None | Some("panic") => FaultKind::Panic,
            Some("error") => FaultKind::Error,
            Some(_) => return Err(usage()),
        };
        Ok(Self { stage, row, column, kind })
    }

    /// The fault `SHOAL_FAULT` asks for, if it is set.
    pub fn from_env() -> Result<Option<Self>, String> {
        match std::env::var(Self::ENV) {
            Ok(text) if !text.trim().is_empty() => Self::parse(&text).map(Some),
            _ => Ok(None),
        }
    }
}
