//! Tabulated spectra and their interpolation onto a grid.

use serde::{Deserialize, Serialize};

use super::{SpectralError, Table, WavelengthGrid};

/// What to do when a spectrum is asked for a wavelength outside its data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Extrapolation {
    /// Refuse: an error names the spectrum, the wavelength and the covered range.
    #[default]
    Error,
    /// Hold the first/last value (used for benthic reflectance beyond 850–950 nm, where the
    /// water column hides the bottom anyway; the choice is recorded in the SIOP/substrate docs).
    Clamp,
    /// Zero outside the data (used for spectral response functions).
    Zero,
}

/// A spectrum tabulated at strictly increasing wavelengths, linearly interpolated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Spectrum {
    /// Name for messages (`"a_w (WASI6)"`).
    pub name: String,
    /// Wavelengths, nm, strictly increasing.
    pub wavelength_nm: Vec<f64>,
    /// Values, in the unit the owner documents.
    pub values: Vec<f64>,
}

impl Spectrum {
    /// Build and check a spectrum: equal lengths, at least two points, increasing wavelengths,
    /// finite values.
    ///
    /// ```
    /// use shoal::spectral::{Spectrum, Extrapolation};
    /// let s = Spectrum::new("demo", vec![400.0, 500.0], vec![1.0, 3.0]).unwrap();
    /// assert_eq!(s.value_at(450.0, Extrapolation::Error).unwrap(), 2.0);
    /// assert!(s.value_at(600.0, Extrapolation::Error).is_err());
    /// ```
    pub fn new(name: impl Into<String>, wavelength_nm: Vec<f64>, values: Vec<f64>) -> Result<Self, SpectralError> {
        let name = name.into();
        let bad = |message: String| SpectralError::BadSpectrum { name: name.clone(), message };
        if wavelength_nm.len() != values.len() {
            return Err(bad(format!("{} wavelengths but {} values", wavelength_nm.len(), values.len())));
        }
        if wavelength_nm.len() < 2 {
            return Err(bad("needs at least two points".into()));
        }
        if let Some(p) = wavelength_nm.windows(2).find(|p| !(p[1] > p[0])) {
            return Err(bad(format!("wavelengths must increase strictly ({} then {})", p[0], p[1])));
        }
        if let Some((w, v)) = wavelength_nm.iter().zip(&values).find(|(_, v)| !v.is_finite()) {
            return Err(bad(format!("value at {w} nm is {v}")));
        }
        Ok(Self { name, wavelength_nm, values })
    }

    /// Column `column` of `table` against its `wavelength_nm` column. Rows holding the
    /// missing-value marker `-999` are dropped.
    pub fn from_table(table: &Table, column: &str) -> Result<Self, SpectralError> {
        let wl = table.column_f64("wavelength_nm")?;
        let v = table.column_f64(column)?;
        let (wl, v): (Vec<f64>, Vec<f64>) = wl.into_iter().zip(v).filter(|(_, v)| (*v - -999.0).abs() > 1e-9).unzip();
        Self::new(format!("{}:{column}", table.source), wl, v)
    }

    /// Column `column` of the embedded asset `path`.
    ///
    /// ```
    /// let aw = shoal::spectral::Spectrum::from_asset("water/water_absorption_wasi6.csv", "a_w_per_m").unwrap();
    /// assert!(aw.value_at(550.0, Default::default()).unwrap() > 0.05);
    /// ```
    pub fn from_asset(path: &str, column: &str) -> Result<Self, SpectralError> {
        /// Columns of embedded files already parsed. The files are compiled in and never change,
        /// so each (file, column) is parsed once per process: parsing them was nearly all of the
        /// 1.6 ms each SIOP set took to resolve, eight sets per retrieval model.
        static PARSED: std::sync::Mutex<Vec<(&'static str, String, Spectrum)>> = std::sync::Mutex::new(Vec::new());
        let asset = Table::asset(path)?;
        let lock = || PARSED.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some((_, _, s)) = lock().iter().find(|(p, c, _)| *p == asset.path && c == column) {
            return Ok(s.clone());
        }
        let s = Self::from_table(&Table::parse(asset.text, asset.path)?, column)?;
        lock().push((asset.path, column.to_string(), s.clone()));
        Ok(s)
    }

    /// Wavelength range covered, nm.
    #[must_use]
    pub fn range_nm(&self) -> (f64, f64) {
        (self.wavelength_nm[0], self.wavelength_nm[self.wavelength_nm.len() - 1])
    }

    /// Linear interpolation at `wavelength_nm`.
    pub fn value_at(&self, wavelength_nm: f64, extrapolation: Extrapolation) -> Result<f64, SpectralError> {
        let (lo, hi) = self.range_nm();
        // Tolerate a rounding hair outside the range (grids built by repeated addition).
        let eps = 1e-9 * hi.abs();
        if wavelength_nm < lo - eps || wavelength_nm > hi + eps || wavelength_nm.is_nan() {
            return match extrapolation {
                Extrapolation::Error => {
                    Err(SpectralError::OutOfRange { name: self.name.clone(), wavelength_nm, min_nm: lo, max_nm: hi })
                }
                Extrapolation::Zero => Ok(0.0),
                Extrapolation::Clamp if wavelength_nm < lo => Ok(self.values[0]),
                Extrapolation::Clamp => Ok(self.values[self.values.len() - 1]),
            };
        }
        let x = wavelength_nm.clamp(lo, hi);
        let j = self.wavelength_nm.partition_point(|&w| w <= x).clamp(1, self.wavelength_nm.len() - 1);
        let (x0, x1) = (self.wavelength_nm[j - 1], self.wavelength_nm[j]);
        let (y0, y1) = (self.values[j - 1], self.values[j]);
        let t = (x - x0) / (x1 - x0);
        Ok(y0 + t * (y1 - y0))
    }

    /// Values on every wavelength of `grid`.
    pub fn resample(&self, grid: &WavelengthGrid, extrapolation: Extrapolation) -> Result<Vec<f64>, SpectralError> {
        grid.wavelengths_nm().iter().map(|&w| self.value_at(w, extrapolation)).collect()
    }

    /// The spectrum with every value multiplied by `factor`.
    #[must_use]
    pub fn scaled(mut self, factor: f64) -> Self {
        for v in &mut self.values {
            *v *= factor;
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_at_nodes_and_between() {
        let s = Spectrum::new("t", vec![400.0, 410.0, 430.0], vec![1.0, 2.0, 0.0]).unwrap();
        assert_eq!(s.value_at(400.0, Extrapolation::Error).unwrap(), 1.0);
        assert_eq!(s.value_at(410.0, Extrapolation::Error).unwrap(), 2.0);
        assert_eq!(s.value_at(420.0, Extrapolation::Error).unwrap(), 1.0);
        assert_eq!(s.value_at(430.0, Extrapolation::Error).unwrap(), 0.0);
        assert_eq!(s.value_at(300.0, Extrapolation::Clamp).unwrap(), 1.0);
        assert_eq!(s.value_at(900.0, Extrapolation::Zero).unwrap(), 0.0);
    }

    #[test]
    fn rejects_unsorted_and_non_finite() {
        assert!(Spectrum::new("t", vec![400.0, 400.0], vec![1.0, 2.0]).is_err());
        assert!(Spectrum::new("t", vec![400.0, 401.0], vec![1.0, f64::NAN]).is_err());
        assert!(Spectrum::new("t", vec![400.0], vec![1.0]).is_err());
    }

    #[test]
    fn out_of_range_message_names_spectrum_and_range() {
        let s = Spectrum::new("a_w", vec![400.0, 700.0], vec![0.0, 1.0]).unwrap();
        let e = s.value_at(900.0, Extrapolation::Error).unwrap_err().to_string();
        assert!(e.contains("a_w") && e.contains("400") && e.contains("700") && e.contains("900"), "{e}");
    }
}
