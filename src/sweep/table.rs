//! The sweep table (one row per run, retrieval and variable) as CSV, and the merge of shards.
//!
//! The CSV is the sweep's result of record: numbers are written in Rust's shortest round-trip
//! form, rows in run order, so the same runs always give the same bytes — which is what lets
//! `shoal merge` prove that n shards equal one run.

use crate::csvtext::{Csv, records};
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
        const TRAILING: [&str; 11] = [
            "instrument",
            "seed",
            "product",
            "variable",
            "mae_pct",
            "bias_pct",
            "returned_pct",
            "n",
            "saturated_pct",
            "snr_pair_short",
            "snr_pair_long",
        ];
        let header: Vec<&str> =
            ["job", "point"].into_iter().chain(self.parameters.iter().map(String::as_str)).chain(TRAILING).collect();
        let mut csv = Csv::new(&header);
        csv.comment(&format!("# sweep {} | jobs {} | key {}", self.name, self.jobs, self.key));
        if let Some((i, n)) = self.shard {
            csv.comment(&format!("# shard {i}/{n}"));
        }
        for r in &self.rows {
            let mut cells = vec![r.job.to_string(), r.point.to_string()];
            cells.extend(r.values.iter().map(ToString::to_string));
            cells.extend([
                r.instrument.clone(),
                r.seed.to_string(),
                r.product.clone(),
                r.variable.clone(),
                r.mae_pct.to_string(),
                r.bias_pct.to_string(),
                r.returned_pct.to_string(),
                r.n.to_string(),
                r.saturated_pct.to_string(),
                r.snr_pair.map_or(String::new(), |p| p[0].to_string()),
                r.snr_pair.map_or(String::new(), |p| p[1].to_string()),
            ]);
            csv.row(&cells);
        }
        csv.finish()
    }

    /// Read a table written by [`Table::to_csv`]; `origin` names it in errors.
    pub fn from_csv(text: &str, origin: &str) -> Result<Self, StudyError> {
        let bad = |line: usize, m: String| {
            StudyError::Parse(ParseError { origin: origin.into(), message: format!("line {line}: {m}") })
        };
        let head = text.lines().next().ok_or_else(|| bad(1, "empty file".into()))?;
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
        // After the first line, the CSV: `#` lines are comments (the shard's among them), line
        // numbers count from the first line.
        let rest = &text[text.find('\n').map_or(text.len(), |k| k + 1)..];
        for (i, line) in rest.lines().enumerate() {
            if let Some(shard) = line.strip_prefix("# shard ") {
                let s = super::Shard::parse(shard).map_err(|m| bad(i + 2, m))?;
                table.shard = Some((s.index, s.count));
            }
        }
        let mut columns: Vec<String> = Vec::new();
        for record in records(rest) {
            let record = record.map_err(|e| bad(e.line + 1, e.message))?;
            let line = record.line + 1;
            if columns.is_empty() {
                columns = record.fields;
                // Tables written before the `saturated_pct` column end at `n`, before the SNR
                // columns at `saturated_pct`.
                let trailing = match columns.last().map(String::as_str) {
                    Some("snr_pair_long") => 11,
                    Some("saturated_pct") => 9,
                    _ => 8,
                };
                if columns.len() < trailing + 2 || columns[0] != "job" {
                    return Err(bad(line, "expected the column header".into()));
                }
                table.parameters = columns[2..columns.len() - trailing].to_vec();
                continue;
            }
            // As wide as the header: the reader refuses a record that is not.
            let cells = record.fields;
            let np = table.parameters.len();
            let num = |k: usize| -> Result<f64, StudyError> {
                cells[k]
                    .parse::<f64>()
                    .map_err(|_| bad(line, format!("column `{}`: `{}` is not a number", columns[k], cells[k])))
            };
            let int = |k: usize| -> Result<u64, StudyError> {
                cells[k]
                    .parse::<u64>()
                    .map_err(|_| bad(line, format!("column `{}`: `{}` is not a whole number", columns[k], cells[k])))
            };
            table.rows.push(Row {
                job: int(0)? as usize,
                point: int(1)? as usize,
                values: (0..np).map(|k| num(2 + k)).collect::<Result<_, _>>()?,
                instrument: cells[2 + np].clone(),
                seed: int(3 + np)?,
                product: cells[4 + np].clone(),
                variable: cells[5 + np].clone(),
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn table(instrument: &str, product: &str) -> Table {
        let row = |job: usize, snr_pair: Option<[f64; 2]>| Row {
            job,
            point: job,
            values: vec![0.25 * job as f64, 3e-7],
            instrument: instrument.into(),
            seed: 7,
            product: product.into(),
            variable: "chl_mg_m3".into(),
            mae_pct: 12.5,
            bias_pct: -0.125,
            returned_pct: 99.0,
            n: 400,
            saturated_pct: 0.0,
            snr_pair,
        };
        Table {
            name: "focal, ratio".into(),
            key: "abc123".into(),
            jobs: 4,
            shard: Some((1, 2)),
            parameters: vec!["telescope.f_number".into(), "detector.read_noise_e".into()],
            rows: vec![row(1, None), row(3, Some([150.5, 42.0]))],
        }
    }

    #[test]
    fn names_with_commas_and_quotes_write_and_read_back() {
        let t = table("SmallSat (2x, f/4)", "my \"algo\"");
        let text = t.to_csv();
        assert!(text.contains(",\"SmallSat (2x, f/4)\",7,\"my \"\"algo\"\"\",chl_mg_m3,"), "{text}");
        assert_eq!(Table::from_csv(&text, "t").unwrap(), t);
    }

    #[test]
    fn plain_names_write_the_same_bytes_as_ever() {
        let text = table("nominal", "aLMI").to_csv();
        assert_eq!(
            text,
            "# sweep focal, ratio | jobs 4 | key abc123\n# shard 1/2\n\
             job,point,telescope.f_number,detector.read_noise_e,instrument,seed,product,variable,mae_pct,bias_pct,\
             returned_pct,n,saturated_pct,snr_pair_short,snr_pair_long\n\
             1,1,0.25,0.0000003,nominal,7,aLMI,chl_mg_m3,12.5,-0.125,99,400,0,,\n\
             3,3,0.75,0.0000003,nominal,7,aLMI,chl_mg_m3,12.5,-0.125,99,400,0,150.5,42\n"
        );
    }

    #[test]
    fn bad_rows_are_refused_naming_the_line() {
        let text = table("a", "b").to_csv();
        let short = text.replace(",150.5,42\n", ",150.5\n");
        let e = Table::from_csv(&short, "t").unwrap_err().to_string();
        assert!(e.contains("line 5: 14 cells, expected 15"), "{e}");
        let e = Table::from_csv(&text.replace("12.5", "x"), "t").unwrap_err().to_string();
        assert!(e.contains("line 4: column `mae_pct`: `x` is not a number"), "{e}");
        let e = Table::from_csv(&text.replace("# shard 1/2", "# shard 3/2"), "t").unwrap_err().to_string();
        assert!(e.contains("line 2:"), "{e}");
    }
}
