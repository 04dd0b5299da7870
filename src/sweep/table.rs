//! The sweep table (one row per run, retrieval and variable) as CSV, and the merge of shards.
//!
//! The CSV is the sweep's result of record: numbers are written in Rust's shortest round-trip
//! form, rows in run order, so the same runs always give the same bytes — which is what lets
//! `shoal merge` prove that n shards equal one run.

use crate::parse::{FieldError, ParseError};
use crate::study::StudyError;

/// One row: a run's metrics for one variable of one retrieval.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Run index in the sweep's fixed order.
    pub job: usize,
    /// Point index.
    pub point: usize,
    /// The parameters' values at the point.
    pub values: Vec<f64>,
    /// Instrument label.
    pub instrument: String,
    /// Noise seed.
    pub seed: u64,
    /// Retrieval (aLMI, SAMBUCA).
    pub product: String,
    /// Variable (`chl_mg_m3`, …).
    pub variable: String,
    /// Log-space MAE, %.
    pub mae_pct: f64,
    /// Log-space bias, %.
    pub bias_pct: f64,
    /// Pixels returned, % of candidates.
    pub returned_pct: f64,
    /// Pixels compared.
    pub n: usize,
    /// Level-0 pixel-bands saturated (the well or the ADC full), % — where a curve jumps because
    /// the design saturates, the table says so. Tables written before the column read 0.
    pub saturated_pct: f64,
    /// SNR measured on a uniform patch at the scene's median water radiance
    /// ([`crate::instrument::measured_snr`]) at the image-based correction's aerosol pair
    /// (short, long band): what a NIR/SWIR sweep varies. `None` (empty cells) without a
    /// band-pair correction, and in tables written before the columns.
    pub snr_pair: Option<[f64; 2]>,
}

/// A sweep table: identity, the runs it holds, and its rows.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Sweep name.
    pub name: String,
    /// Fingerprint of the resolved sweep (shards of different sweeps do not merge).
    pub key: String,
    /// Runs in the whole sweep.
    pub jobs: usize,
    /// The shard this table holds (`None`: all runs).
    pub shard: Option<(usize, usize)>,
    /// Parameter paths (column names).
    pub parameters: Vec<String>,
    /// Rows in run order.
    pub rows: Vec<Row>,
}

impl Table {
    /// The CSV text.
    #[must_use]
    pub fn to_csv(&self) -> String {
        let mut s = format!("# sweep {} | jobs {} | key {}\n", self.name, self.jobs, self.key);
        if let Some((i, n)) = self.shard {
            s.push_str(&format!("# shard {i}/{n}\n"));
        }
        s.push_str("job,point,");
        for p in &self.parameters {
            s.push_str(p);
            s.push(',');
        }
        s.push_str("instrument,seed,product,variable,mae_pct,bias_pct,returned_pct,n,saturated_pct,snr_pair_short,snr_pair_long\n");
        for r in &self.rows {
            s.push_str(&format!("{},{},", r.job, r.point));
            for v in &r.values {
                s.push_str(&format!("{v},"));
            }
            s.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{}\n",
                r.instrument,
                r.seed,
                r.product,
                r.variable,
                r.mae_pct,
                r.bias_pct,
                r.returned_pct,
                r.n,
                r.saturated_pct,
                r.snr_pair.map_or(String::new(), |p| p[0].to_string()),
                r.snr_pair.map_or(String::new(), |p| p[1].to_string()),
            ));
        }
        s
    }

    /// Read a table written by [`Table::to_csv`]; `origin` names it in errors.
    pub fn from_csv(text: &str, origin: &str) -> Result<Self, StudyError> {
        let bad = |line: usize, m: String| {
            StudyError::Parse(ParseError { origin: origin.into(), message: format!("line {line}: {m}") })
        };
        let mut lines = text.lines().enumerate();
        let (_, head) = lines.next().ok_or_else(|| bad(1, "empty file".into()))?;
        let fields: Vec<&str> = head.trim_start_matches("# sweep ").split(" | ").collect();
        let [name, jobs, key] = fields.as_slice() else { return Err(bad(1, "not a sweep table header".into())) };
        let jobs: usize = jobs.trim_start_matches("jobs ").parse().map_err(|_| bad(1, format!("bad `{jobs}`")))?;
        let mut table = Table {
            name: (*name).to_string(),
            key: key.trim_start_matches("key ").to_string(),
            jobs,
            shard: None,
            parameters: Vec::new(),
            rows: Vec::new(),
        };
        let mut columns = Vec::new();
        for (i, line) in lines {
            if let Some(shard) = line.strip_prefix("# shard ") {
                let s = super::Shard::parse(shard).map_err(|m| bad(i + 1, m))?;
                table.shard = Some((s.index, s.count));
                continue;
            }
            if columns.is_empty() {
                columns = line.split(',').map(str::to_string).collect();
                // Tables written before the `saturated_pct` column end at `n`, before the SNR
                // columns at `saturated_pct`.
                let trailing = match columns.last().map(String::as_str) {
                    Some("snr_pair_long") => 11,
                    Some("saturated_pct") => 9,
                    _ => 8,
                };
                if columns.len() < trailing + 2 || columns[0] != "job" {
                    return Err(bad(i + 1, "expected the column header".into()));
                }
                table.parameters = columns[2..columns.len() - trailing].to_vec();
                continue;
            }
            let cells: Vec<&str> = line.split(',').collect();
            if cells.len() != columns.len() {
                return Err(bad(i + 1, format!("{} cells, expected {}", cells.len(), columns.len())));
            }
            let np = table.parameters.len();
            let num = |k: usize| -> Result<f64, StudyError> {
                cells[k]
                    .parse::<f64>()
                    .map_err(|_| bad(i + 1, format!("column `{}`: `{}` is not a number", columns[k], cells[k])))
            };
            let int = |k: usize| -> Result<u64, StudyError> {
                cells[k]
                    .parse::<u64>()
                    .map_err(|_| bad(i + 1, format!("column `{}`: `{}` is not a whole number", columns[k], cells[k])))
            };
            table.rows.push(Row {
                job: int(0)? as usize,
                point: int(1)? as usize,
                values: (0..np).map(|k| num(2 + k)).collect::<Result<_, _>>()?,
                instrument: cells[2 + np].to_string(),
                seed: int(3 + np)?,
                product: cells[4 + np].to_string(),
                variable: cells[5 + np].to_string(),
                mae_pct: num(6 + np)?,
                bias_pct: num(7 + np)?,
                returned_pct: num(8 + np)?,
                n: int(9 + np)? as usize,
                saturated_pct: if cells.len() > 10 + np { num(10 + np)? } else { 0.0 },
                snr_pair: if cells.len() > 12 + np && !cells[11 + np].is_empty() {
                    Some([num(11 + np)?, num(12 + np)?])
                } else {
                    None
                },
            });
        }
        Ok(table)
    }
}

/// Join shard tables into the whole sweep's table. Refuses tables of different sweeps, runs
/// present twice, and missing runs (naming the first few).
pub fn merge(parts: &[Table]) -> Result<Table, StudyError> {
    let first = parts.first().ok_or_else(|| {
        StudyError::Invalid(FieldError { field: "tables".into(), message: "nothing to merge".into() })
    })?;
    for p in parts {
        if p.key != first.key || p.name != first.name || p.jobs != first.jobs || p.parameters != first.parameters {
            return Err(StudyError::Invalid(FieldError {
                field: "tables".into(),
                message: format!(
                    "`{}` (key {}) and `{}` (key {}) are different sweeps",
                    first.name, first.key, p.name, p.key
                ),
            }));
        }
    }
    let mut owner: Vec<Option<usize>> = vec![None; first.jobs];
    for (t, p) in parts.iter().enumerate() {
        let mut jobs: Vec<usize> = p.rows.iter().map(|r| r.job).collect();
        jobs.dedup();
        for j in jobs {
            let slot = owner.get_mut(j).ok_or_else(|| {
                StudyError::Invalid(FieldError {
                    field: "tables".into(),
                    message: format!("run {j} is outside the sweep's {} runs", first.jobs),
                })
            })?;
            if let Some(other) = slot {
                return Err(StudyError::Invalid(FieldError {
                    field: "tables".into(),
                    message: format!("run {j} is in table {other} and table {t}"),
                }));
            }
            *slot = Some(t);
        }
    }
    let missing: Vec<usize> = owner.iter().enumerate().filter(|(_, o)| o.is_none()).map(|(j, _)| j).collect();
    if !missing.is_empty() {
        let shown: Vec<String> = missing.iter().take(8).map(ToString::to_string).collect();
        return Err(StudyError::Invalid(FieldError {
            field: "tables".into(),
            message: format!(
                "{} of {} runs missing (runs {}{})",
                missing.len(),
                first.jobs,
                shown.join(", "),
                if missing.len() > 8 { ", …" } else { "" }
            ),
        }));
    }
    let mut rows: Vec<Row> = parts.iter().flat_map(|p| p.rows.iter().cloned()).collect();
    // Stable: rows of one run keep their order.
    rows.sort_by_key(|r| r.job);
    Ok(Table { shard: None, rows, ..first.clone() })
}
