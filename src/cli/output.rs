//! Writing results: CSV to standard output or, atomically, to a file.

use std::io::Write;
use std::path::Path;

use super::CliError;

/// Write `text` to `path` (atomically: [`crate::study::write_bytes`]) or to standard output.
pub fn emit(text: &str, path: Option<&Path>) -> Result<(), CliError> {
    match path {
        None => {
            let mut out = std::io::stdout().lock();
            match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
                // A reader that stops early (`| head`) is not an error.
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
                r => r.map_err(|e| CliError::Run(format!("writing to standard output: {e}"))),
            }
        }
        Some(p) => crate::study::write_bytes(p, text.as_bytes()).map_err(|e| CliError::Run(e.to_string())),
    }
}

/// Shortest round-trip text of a finite number, in exponent form when it is very small or large
/// (`{}` alone would print 1.6e-46 as 47 zeros).
#[must_use]
pub fn number(v: f64) -> String {
    if v != 0.0 && !(1e-4..1e7).contains(&v.abs()) { format!("{v:e}") } else { format!("{v}") }
}

/// A CSV table built row by row; every value must be finite (NaN never reaches the output).
pub struct Csv {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Csv {
    /// A table with these column names.
    pub fn new(header: Vec<String>) -> Self {
        Self { header, rows: Vec::new() }
    }

    /// Add a row: a leading label (may be empty to omit) and numbers. The row must be as wide
    /// as the header.
    pub fn row(&mut self, label: Option<&str>, values: &[f64]) -> Result<(), CliError> {
        let width = values.len() + usize::from(label.is_some());
        if width != self.header.len() {
            return Err(CliError::Run(format!(
                "internal error: a row of {width} cells under {} columns (please report this)",
                self.header.len()
            )));
        }
        if let Some((i, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            let offset = usize::from(label.is_some());
            return Err(CliError::Run(format!(
                "internal error: column `{}` is {v} (please report this with the command line)",
                self.header.get(i + offset).map_or("?", String::as_str)
            )));
        }
        let mut cells: Vec<String> = label.map(str::to_string).into_iter().collect();
        cells.extend(values.iter().map(|v| number(*v)));
        self.rows.push(cells);
        Ok(())
    }

    /// The CSV text (through [`crate::csvtext::Csv`]: a label or column name with a comma is
    /// quoted).
    pub fn render(&self) -> String {
        let mut csv = crate::csvtext::Csv::new(&self.header.iter().map(String::as_str).collect::<Vec<_>>());
        for r in &self.rows {
            csv.row(r);
        }
        csv.finish()
    }
}

/// `--format` of `shoal simulate` and `shoal study`: how cubes and maps are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Format {
    /// NumPy .npy arrays (one per product).
    #[default]
    Npy,
    /// GeoTIFF (one file per product, bands with descriptions and units, georeferenced).
    Geotiff,
    /// NetCDF with CF metadata (one file per instrument: bands as a coordinate, Level-1, Rrs,
    /// the truth, every product and its flags, pixel positions, the configuration).
    Netcdf,
}

impl From<Format> for crate::study::CubeFormat {
    fn from(f: Format) -> Self {
        match f {
            Format::Npy => Self::Npy,
            Format::Geotiff => Self::GeoTiff,
            Format::Netcdf => Self::NetCdf,
        }
    }
}
