//! A search's evaluations on disk (`evaluations.ron`), so that the Latin-hypercube start can run
//! as shards on a cluster (`--shard i/n`) and a later search can resume from them (`--resume`).
//! A record says what it was evaluated for (study, parameters, resolution, seeds, optimiser
//! seed); one that does not match the search resuming from it is refused, naming what differs.
//! Records come from other machines and other people: every number is checked finite and every
//! design's parameter count against the search's before it is used.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{Evaluation, Variable};
use crate::parse::FieldError;
use crate::study::StudyError;

/// The file a search writes its evaluations to.
pub const FILE: &str = "evaluations.ron";

/// What a set of evaluations was made for, and the evaluations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Record {
    /// Study name.
    pub study: String,
    /// Instrument the search started from.
    pub instrument: String,
    /// Varied fields: (path, lowest, highest).
    pub vars: Vec<(String, f64, f64)>,
    /// Decimation of the evaluations.
    pub decimation: usize,
    /// Noise seeds of each evaluation.
    pub seeds: Vec<u64>,
    /// Seed of the Latin-hypercube start.
    pub seed: u64,
    /// The designs.
    pub evaluations: Vec<Evaluation>,
}

/// The varied fields as a record holds them.
#[must_use]
pub fn vars_of(vars: &[Variable]) -> Vec<(String, f64, f64)> {
    vars.iter()
        .map(|v| {
            let (lo, hi) = v.bounds();
            (v.path.clone(), lo, hi)
        })
        .collect()
}

fn refused(field: &str, message: String) -> StudyError {
    StudyError::Invalid(FieldError { field: field.into(), message })
}

impl Record {
    /// Write to `dir/evaluations.ron`.
    pub fn write(&self, dir: &Path) -> Result<(), StudyError> {
        let text = ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())
            .map_err(|e| StudyError::Io(format!("cannot write the evaluations: {e}")))?;
        crate::study::write_bytes(&dir.join(FILE), text.as_bytes())
    }

    /// Read `dir/evaluations.ron` (at most 64 MB).
    pub fn read(dir: &Path) -> Result<Self, StudyError> {
        let path = dir.join(FILE);
        let field = format!("--resume {}", dir.display());
        let size = std::fs::metadata(&path).map_err(|e| refused(&field, format!("{}: {e}", path.display())))?.len();
        if size > 64 << 20 {
            return Err(refused(&field, format!("{} is {size} bytes (allowed: at most 64 MB)", path.display())));
        }
        let text = std::fs::read_to_string(&path).map_err(|e| refused(&field, format!("{}: {e}", path.display())))?;
        ron::from_str(&text)
            .map_err(|e| refused(&field, format!("{}: {}", path.display(), crate::parse::describe(&text, &e))))
    }

    /// Check that this record was made for `expected` (everything but the evaluations), and that
    /// every evaluation has one finite value per parameter and finite numbers.
    pub fn check_matches(&self, expected: &Self, origin: &str) -> Result<(), StudyError> {
        let field = format!("--resume {origin}");
        for (what, same) in [
            ("study", self.study == expected.study),
            ("instrument", self.instrument == expected.instrument),
            ("--vary", self.vars == expected.vars),
            ("--decimation", self.decimation == expected.decimation),
            ("seeds", self.seeds == expected.seeds),
            ("--seed", self.seed == expected.seed),
        ] {
            if !same {
                return Err(refused(&field, format!("its {what} differs from this search's")));
            }
        }
        if self.evaluations.len() > 100_000 {
            return Err(refused(&field, format!("{} evaluations (allowed: at most 100000)", self.evaluations.len())));
        }
        for (i, e) in self.evaluations.iter().enumerate() {
            let finite =
                e.x.iter().chain(e.cost.iter()).chain(e.constraints.iter().map(|(_, g)| g)).all(|v| v.is_finite());
            if e.x.len() != self.vars.len() || !finite || e.seeds_passed > e.seeds {
                return Err(refused(
                    &field,
                    format!(
                        "evaluation {} is malformed (parameters, costs and excesses must be finite, one value per parameter)",
                        i + 1
                    ),
                ));
            }
        }
        Ok(())
    }
}
