//! A search's evaluations on disk (`evaluations.ron`), so that the Latin-hypercube start can run
//! as shards on a cluster (`--shard i/n`) and a later search can resume from them (`--resume`).
//! A record says what it was evaluated for (study, parameters, resolution, seeds, optimiser
//! seed); one that does not match the search resuming from it is refused, naming what differs.
//! Records come from other machines and other people: every number is checked finite and every
//! design's parameter count against the search's before it is used.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{Dimension, Evaluation};
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
pub fn vars_of(vars: &[Dimension]) -> Vec<(String, f64, f64)> {
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

    /// Read `dir/evaluations.ron`: a regular file of at most [`crate::infile::RON_MAX_BYTES`].
    pub fn read(dir: &Path) -> Result<Self, StudyError> {
        let path = dir.join(FILE);
        let field = format!("--resume {}", dir.display());
        let text = crate::infile::read_text(&path, crate::infile::RON_MAX_BYTES)
            .map_err(|e| refused(&field, e.to_string()))?;
        Self::parse(&text, &path.display().to_string(), &field)
    }

    /// Parse a record's text from `origin`; errors are of `field`.
    pub fn parse(text: &str, origin: &str, field: &str) -> Result<Self, StudyError> {
        ron::from_str(text).map_err(|e| refused(field, format!("{origin}: {}", crate::parse::describe(text, &e))))
    }

    /// Check that this record was made for `expected` (everything but the evaluations) and holds
    /// at most 100 000 evaluations; [`Record::check_evaluations`] checks each of them.
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
        Ok(())
    }

    /// Check every evaluation as the search it joins would have made it: each value inside its
    /// parameter's range (a whole number for an integer parameter, a listed value for a choice),
    /// the constraints keyed as `plan` says (every required key present, no other key, each
    /// excess finite and within ±[`MAX_EXCESS`]), the MAE keyed by Shoal's own variables, the
    /// decimation and seed count the record states, a positive finite cost, finite non-negative
    /// seconds, and the budget in `currency` with finite numbers. The first evaluation that is not
    /// is refused, naming its field.
    pub fn check_evaluations(
        &self,
        vars: &[super::Dimension],
        plan: &(Vec<String>, Vec<String>),
        currency: &str,
        origin: &str,
    ) -> Result<(), StudyError> {
        let field = format!("--resume {origin}");
        for (i, e) in self.evaluations.iter().enumerate() {
            check_one(e, self, vars, plan, currency)
                .map_err(|(what, why)| refused(&format!("{field}: evaluations[{i}].{what}"), why))?;
        }
        Ok(())
    }
}

/// The largest normalised excess a constraint may report (an MAE of 10⁸ times its limit).
pub const MAX_EXCESS: f64 = 1e8;
/// The largest cost and the longest run a record may report.
const MAX_COST: f64 = 1e12;
const MAX_SECONDS: f64 = 1e7;

/// Why one evaluation does not belong to the search: (field, what is wrong and allowed).
fn check_one(
    e: &Evaluation,
    record: &Record,
    vars: &[super::Dimension],
    (possible, required): &(Vec<String>, Vec<String>),
    currency: &str,
) -> Result<(), (String, String)> {
    let bad = |f: &str, m: String| Err((f.to_string(), m));
    if e.x.len() != vars.len() {
        return bad("x", format!("{} values (allowed: one per --vary parameter, {})", e.x.len(), vars.len()));
    }
    for (j, (x, v)) in e.x.iter().zip(vars).enumerate() {
        let (lo, hi) = v.bounds();
        let inside = match &v.kind {
            super::Domain::Continuous(..) => x.is_finite() && (lo..=hi).contains(x),
            super::Domain::Integer(..) => x.is_finite() && (lo..=hi).contains(x) && x.fract() == 0.0,
            super::Domain::Choice(list) => list.contains(x),
        };
        if !inside {
            return bad(&format!("x[{j}]"), format!("{x} is outside --vary {} ({lo} to {hi})", v.path));
        }
    }
    if e.decimation != record.decimation {
        return bad("decimation", format!("{} (allowed: the record's {})", e.decimation, record.decimation));
    }
    if e.seeds != record.seeds.len() || e.seeds_passed > e.seeds {
        return bad(
            "seeds",
            format!(
                "{} passed of {} (allowed: at most {n} of {n}, the record's seeds)",
                e.seeds_passed,
                e.seeds,
                n = record.seeds.len()
            ),
        );
    }
    if !(e.seconds.is_finite() && (0.0..=MAX_SECONDS).contains(&e.seconds)) {
        return bad("seconds", format!("{} (allowed: 0 to {MAX_SECONDS})", e.seconds));
    }
    if let Some(c) = e.cost
        && !(c.is_finite() && c > 0.0 && c <= MAX_COST)
    {
        return bad("cost", format!("{c} (allowed: above 0 up to {MAX_COST})"));
    }
    for (k, (name, g)) in e.constraints.iter().enumerate() {
        if !possible.contains(name) || e.constraints[..k].iter().any(|(n, _)| n == name) {
            return bad(
                "constraints",
                format!("`{}` (allowed: each of {} at most once)", name.escape_debug(), possible.join(", ")),
            );
        }
        if !(g.is_finite() && g.abs() <= MAX_EXCESS) {
            return bad("constraints", format!("`{name}` exceeds by {g} (allowed: finite, within ±{MAX_EXCESS})"));
        }
    }
    if e.error.is_none()
        && let Some(missing) = required.iter().find(|k| !e.constraints.iter().any(|(n, _)| n == *k))
    {
        return bad("constraints", format!("has no `{missing}`, which every design of this search reports"));
    }
    for (k, (name, mae)) in e.mae_pct.iter().enumerate() {
        // Metrics variables are Shoal's keys and per-substrate depths (`depth_m_over_sand`);
        // none becomes a file name (the fronts are drawn for the study's own variables).
        let known = crate::variable::of(name).is_some() || name.starts_with(crate::variable::key::DEPTH);
        if !known || crate::parse::check_name("", name).is_err() || e.mae_pct[..k].iter().any(|(n, _)| n == name) {
            return bad("mae_pct", format!("`{}` (allowed: each metrics variable at most once)", name.escape_debug()));
        }
        // NaN: nothing was returned on any seed.
        if !(mae.is_nan() || (mae.is_finite() && *mae >= 0.0)) {
            return bad("mae_pct", format!("`{name}` is {mae} (allowed: 0 or more, or NaN for nothing returned)"));
        }
    }
    if let Some(error) = &e.error
        && (error.chars().count() > 4096 || error.chars().any(|c| c.is_control() && c != '\n'))
    {
        return bad("error", "is over 4096 characters or holds control characters".into());
    }
    if let Some(b) = &e.budget {
        check_budget(b, currency).map_err(|m| ("budget".to_string(), m))?;
    }
    Ok(())
}

/// A budget in the study's `currency` whose numbers are finite and whose texts are short and
/// printable (they reach `design.md` and the review page).
fn check_budget(b: &crate::instrument::budgets::DesignBudget, currency: &str) -> Result<(), String> {
    if b.currency != currency {
        return Err(format!("in `{}` (allowed: the study's {currency})", b.currency.escape_debug()));
    }
    let e = &b.envelope;
    let d = &b.data;
    let mut numbers =
        vec![e.length_mm, e.cross_section_mm, d.rate_mbit_s, d.image_gbit, d.daily_gbit, d.downlink_gbit_day];
    numbers.extend(b.cost.ota);
    numbers.extend(e.mass_kg);
    numbers.extend(e.power_w);
    if numbers.iter().any(|v| !v.is_finite()) {
        return Err("holds a number that is not finite".into());
    }
    for text in [b.cost.note.as_deref(), e.fits.as_deref()].into_iter().flatten() {
        if text.chars().count() > 512 || text.chars().any(char::is_control) {
            return Err("holds a text over 512 characters or with control characters".into());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn record() -> (Record, Vec<Dimension>) {
        let vars = vec![Dimension::parse("aperture_mm=40:200").unwrap()];
        let e = Evaluation {
            x: vec![100.0],
            cost: Some(2.5),
            constraints: vec![("chl_mg_m3 returned %".into(), -0.2), ("SNR, worst band".into(), 0.1)],
            seeds_passed: 0,
            seeds: 1,
            mae_pct: vec![("chl_mg_m3".into(), 37.0), ("depth_m_over_sand".into(), f64::NAN)],
            budget: None,
            decimation: 8,
            seconds: 1.5,
            error: None,
            warnings: Vec::new(),
        };
        let r = Record {
            study: "s".into(),
            instrument: "cubesat".into(),
            vars: vars_of(&vars),
            decimation: 8,
            seeds: vec![1],
            seed: 1,
            evaluations: vec![e],
        };
        (r, vars)
    }

    #[test]
    fn a_forged_evaluation_is_refused_naming_its_field() {
        let plan = (
            vec!["chl_mg_m3 returned %".to_string(), "SNR, worst band".to_string()],
            vec!["chl_mg_m3 returned %".to_string(), "SNR, worst band".to_string()],
        );
        let (genuine, vars) = record();
        genuine.check_evaluations(&vars, &plan, "EUR", "shard").unwrap();
        let forge = |f: &dyn Fn(&mut Evaluation)| {
            let mut r = genuine.clone();
            f(&mut r.evaluations[0]);
            r.check_evaluations(&vars, &plan, "EUR", "shard").unwrap_err().to_string()
        };
        type Forgery<'a> = (&'a dyn Fn(&mut Evaluation), &'a str);
        let cases: Vec<Forgery<'_>> = vec![
            (&|e| e.x[0] = 5000.0, "evaluations[0].x[0]"),
            (&|e| e.x.push(1.0), "evaluations[0].x"),
            (&|e| e.constraints.clear(), "evaluations[0].constraints"),
            (&|e| e.constraints[0].1 = -1e308, "evaluations[0].constraints"),
            (&|e| e.constraints[0].0 = "../x".into(), "evaluations[0].constraints"),
            (&|e| e.cost = Some(-5.0), "evaluations[0].cost"),
            (&|e| e.seconds = f64::NAN, "evaluations[0].seconds"),
            (&|e| e.decimation = 2, "evaluations[0].decimation"),
            (&|e| e.seeds_passed = 3, "evaluations[0].seeds"),
            (&|e| e.mae_pct[0].0 = "../../front".into(), "evaluations[0].mae_pct"),
            (&|e| e.mae_pct[0].1 = -1.0, "evaluations[0].mae_pct"),
        ];
        for (f, field) in cases {
            let e = forge(f);
            assert!(e.contains(field), "{field}: {e}");
        }
        // A failed design carries no constraints; it is still a record of the search.
        let mut failed = genuine.clone();
        failed.evaluations[0].constraints.clear();
        failed.evaluations[0].error = Some("invalid parameters".into());
        failed.check_evaluations(&vars, &plan, "EUR", "shard").unwrap();
    }
}
