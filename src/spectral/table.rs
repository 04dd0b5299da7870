//! Reading the comma-separated tables Shoal ships and accepts from users.
//!
//! Format: any number of `#` comment lines (the provenance header), then one header row of
//! column names, then rows of comma-separated values. Blank lines are skipped. A column is
//! read as numbers only when asked for, so tables may carry text columns (station codes).

use super::SpectralError;

/// A parsed table: column names and rows of raw cells, with their source line numbers.
#[derive(Debug, Clone)]
pub struct Table {
    /// Where the table came from (asset path or file path), for error messages.
    pub source: String,
    /// Column names from the header row, trimmed.
    pub columns: Vec<String>,
    rows: Vec<(usize, Vec<String>)>,
}

/// The cells of one CSV line, trimmed; a cell in double quotes may hold commas, and `""` inside
/// it is one quote (RFC 4180).
fn split_cells(line: &str) -> Vec<String> {
    let mut cells = Vec::new();
    let mut cell = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(ch) = chars.next() {
        match (ch, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cell.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => cells.push(std::mem::take(&mut cell).trim().to_string()),
            (c, _) => cell.push(c),
        }
    }
    cells.push(cell.trim().to_string());
    cells
}

impl Table {
    /// Parse `text`; `source` names it in errors.
    ///
    /// ```
    /// let t = shoal::spectral::Table::parse("# comment\nwavelength_nm,x\n400,1\n500,2\n", "demo").unwrap();
    /// assert_eq!(t.column_f64("x").unwrap(), vec![1.0, 2.0]);
    /// // A quoted cell may hold commas.
    /// let t = shoal::spectral::Table::parse("id,note\n1,\"clear, deep\"\n", "demo").unwrap();
    /// assert_eq!(t.column_str("note").unwrap(), vec!["clear, deep"]);
    /// ```
    pub fn parse(text: &str, source: &str) -> Result<Self, SpectralError> {
        let mut header: Option<Vec<String>> = None;
        let mut rows = Vec::new();
        for (index, line) in text.lines().enumerate() {
            let line_no = index + 1;
            let trimmed = line.trim();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            let cells = split_cells(trimmed);
            match &header {
                None => header = Some(cells),
                Some(h) => {
                    if cells.len() != h.len() {
                        return Err(SpectralError::Table {
                            origin: source.to_string(),
                            line: line_no,
                            message: format!("row has {} cells but the header has {} columns", cells.len(), h.len()),
                        });
                    }
                    rows.push((line_no, cells));
                }
            }
        }
        let columns = header.ok_or_else(|| SpectralError::Table {
            origin: source.to_string(),
            line: 0,
            message: "no header row (expected e.g. `wavelength_nm,value`)".into(),
        })?;
        // Two columns of one name: a look-up would silently take the first.
        for (i, c) in columns.iter().enumerate() {
            if columns[..i].contains(c) {
                let line = text.lines().position(|l| !l.trim().is_empty() && !l.trim().starts_with('#')).unwrap_or(0);
                return Err(SpectralError::Table {
                    origin: source.to_string(),
                    line: line + 1,
                    message: format!("column `{c}` appears twice in the header; column names must be unique"),
                });
            }
        }
        Ok(Self { source: source.to_string(), columns, rows })
    }

    /// Parse an embedded asset (path relative to `assets/`).
    pub fn from_asset(path: &str) -> Result<Self, SpectralError> {
        let asset = Self::asset(path)?;
        Self::parse(asset.text, asset.path)
    }

    /// The embedded asset `path` (its use recorded for the provenance list), or an error listing
    /// the known ones.
    pub(crate) fn asset(path: &str) -> Result<&'static crate::assets::Asset, SpectralError> {
        crate::assets::find(path).ok_or_else(|| SpectralError::UnknownAsset {
            name: path.to_string(),
            known: crate::assets::paths().collect::<Vec<_>>().join(", "),
        })
    }

    /// Read a table from a file on disk.
    pub fn from_file(path: &std::path::Path) -> Result<Self, SpectralError> {
        let text = crate::infile::read_text(path, crate::infile::TABLE_MAX_BYTES)
            .map_err(|e| SpectralError::Io { path: path.display().to_string(), message: e.message })?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Number of data rows.
    #[must_use]
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// True when the table has no data rows.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Index of column `name`, or an error listing the columns there are.
    pub fn column_index(&self, name: &str) -> Result<usize, SpectralError> {
        self.columns.iter().position(|c| c == name).ok_or_else(|| SpectralError::UnknownColumn {
            origin: self.source.clone(),
            column: name.to_string(),
            known: self.columns.join(", "),
        })
    }

    /// Column `name` as text cells.
    pub fn column_str(&self, name: &str) -> Result<Vec<&str>, SpectralError> {
        let i = self.column_index(name)?;
        Ok(self.rows.iter().map(|(_, cells)| cells[i].as_str()).collect())
    }

    /// Column `name` as numbers; a cell that is not a finite number is an error naming its line.
    pub fn column_f64(&self, name: &str) -> Result<Vec<f64>, SpectralError> {
        let i = self.column_index(name)?;
        self.rows
            .iter()
            .map(|(line, cells)| {
                let cell = &cells[i];
                cell.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| SpectralError::Table {
                    origin: self.source.clone(),
                    line: *line,
                    message: format!("column `{name}`: `{cell}` is not a finite number"),
                })
            })
            .collect()
    }

    /// Rows whose column `key` equals `value`, as a new table (used for long-format files
    /// such as the OLCI SRFs: `band,wavelength_nm,response`).
    #[must_use]
    pub fn filter_eq(&self, key_index: usize, value: &str) -> Self {
        Self {
            source: self.source.clone(),
            columns: self.columns.clone(),
            rows: self.rows.iter().filter(|(_, c)| c[key_index] == value).cloned().collect(),
        }
    }
}
