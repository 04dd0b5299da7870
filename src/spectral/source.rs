//! Where a spectrum comes from, as written in RON files: an embedded asset, a user's CSV file,
//! an inline table, or an analytic shape.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{Extrapolation, SpectralError, Spectrum, Table, WavelengthGrid};

fn one() -> f64 {
    1.0
}

/// A spectrum's source. Analytic shapes are exact at every wavelength; tabulated ones are
/// linearly interpolated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SpectrumSource {
    /// Column of an embedded file (path relative to `assets/`), times `scale`.
    Asset {
        /// e.g. `"water/water_absorption_wasi6.csv"`.
        file: String,
        /// Column name.
        column: String,
        /// Multiplier (default 1).
        #[serde(default = "one")]
        scale: f64,
        /// Outside the data: `Error` (default), `Zero` or `Clamp`.
        #[serde(default)]
        outside: Extrapolation,
    },
    /// Column of a CSV file on disk (`wavelength_nm` plus value columns), times `scale`.
    /// A relative path is taken relative to the RON file that names it.
    Csv {
        /// File path.
        path: PathBuf,
        /// Column name.
        column: String,
        /// Multiplier (default 1).
        #[serde(default = "one")]
        scale: f64,
        /// Outside the data: `Error` (default), `Zero` or `Clamp`.
        #[serde(default)]
        outside: Extrapolation,
    },
    /// Inline samples.
    Table {
        /// Wavelengths, nm, increasing.
        wavelength_nm: Vec<f64>,
        /// Values.
        values: Vec<f64>,
        /// Outside the data: `Error` (default), `Zero` or `Clamp`.
        #[serde(default)]
        outside: Extrapolation,
    },
    /// c · (λ_ref/λ)^n — the usual form of backscattering spectra.
    PowerLaw {
        /// Value at the reference wavelength.
        coefficient: f64,
        /// Reference wavelength, nm.
        reference_nm: f64,
        /// Exponent n.
        exponent: f64,
    },
    /// c · exp(−S (λ − λ_ref)) — CDOM and NAP absorption (Bricaud et al. 1981).
    Exponential {
        /// Value at the reference wavelength.
        coefficient: f64,
        /// Reference wavelength, nm.
        reference_nm: f64,
        /// Slope S, nm⁻¹.
        slope_per_nm: f64,
    },
    /// The same value at every wavelength.
    Constant(f64),
}

impl SpectrumSource {
    /// Values at every wavelength of `grid`. `base_dir` resolves relative CSV paths. A tabulated
    /// source's own `outside` setting wins over `extrapolation` when it is not `Error`.
    ///
    /// ```
    /// use shoal::spectral::{SpectrumSource, WavelengthGrid, Extrapolation};
    /// let g = WavelengthGrid::from_wavelengths(vec![440.0, 540.0]).unwrap();
    /// let s = SpectrumSource::Exponential { coefficient: 1.0, reference_nm: 440.0, slope_per_nm: 0.01 };
    /// let v = s.sample(&g, Extrapolation::Error, None).unwrap();
    /// assert!((v[1] - (-1.0f64).exp()).abs() < 1e-15);
    /// ```
    pub fn sample(
        &self,
        grid: &WavelengthGrid,
        extrapolation: Extrapolation,
        base_dir: Option<&Path>,
    ) -> Result<Vec<f64>, SpectralError> {
        let wl = grid.wavelengths_nm();
        match self {
            Self::Asset { file, column, scale, outside } => {
                let how = pick(*outside, extrapolation);
                Ok(Spectrum::from_asset(file, column)?.scaled(*scale).resample(grid, how)?)
            }
            Self::Csv { path, column, scale, outside } => {
                let how = pick(*outside, extrapolation);
                let full = match base_dir {
                    Some(dir) if path.is_relative() => dir.join(path),
                    _ => path.clone(),
                };
                let table = Table::from_file(&full)?;
                Ok(Spectrum::from_table(&table, column)?.scaled(*scale).resample(grid, how)?)
            }
            Self::Table { wavelength_nm, values, outside } => {
                Spectrum::new("inline table", wavelength_nm.clone(), values.clone())?
                    .resample(grid, pick(*outside, extrapolation))
            }
            Self::PowerLaw { coefficient, reference_nm, exponent } => {
                check_finite("PowerLaw", &[*coefficient, *reference_nm, *exponent])?;
                check_reference("PowerLaw", *reference_nm)?;
                finite_values("PowerLaw", wl.iter().map(|l| coefficient * (reference_nm / l).powf(*exponent)).collect())
            }
            Self::Exponential { coefficient, reference_nm, slope_per_nm } => {
                check_finite("Exponential", &[*coefficient, *reference_nm, *slope_per_nm])?;
                check_reference("Exponential", *reference_nm)?;
                finite_values(
                    "Exponential",
                    wl.iter().map(|l| coefficient * (-slope_per_nm * (l - reference_nm)).exp()).collect(),
                )
            }
            Self::Constant(c) => {
                check_finite("Constant", &[*c])?;
                Ok(vec![*c; wl.len()])
            }
        }
    }
}

fn pick(own: Extrapolation, default: Extrapolation) -> Extrapolation {
    if own == Extrapolation::Error { default } else { own }
}

/// A reference wavelength must be one ([`crate::ranges::SPECTRUM_REFERENCE_NM`]): −1e308 nm
/// would turn the spectrum into zeros or infinities without a word.
fn check_reference(what: &str, reference_nm: f64) -> Result<(), SpectralError> {
    crate::ranges::SPECTRUM_REFERENCE_NM
        .check(reference_nm)
        .map_err(|m| SpectralError::BadSpectrum { name: what.into(), message: format!("reference_nm: {m}") })
}

/// The values of an analytic spectrum, refused when one overflowed (a slope too steep for the
/// grid's span).
fn finite_values(what: &str, values: Vec<f64>) -> Result<Vec<f64>, SpectralError> {
    match values.iter().find(|v| !v.is_finite()) {
        None => Ok(values),
        Some(v) => Err(SpectralError::BadSpectrum {
            name: what.into(),
            message: format!("a value is {v} on the simulation grid: the coefficient, slope or exponent is too large"),
        }),
    }
}

fn check_finite(what: &str, values: &[f64]) -> Result<(), SpectralError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SpectralError::BadSpectrum {
            name: what.into(),
            message: format!("parameters must be finite, got {values:?}"),
        })
    }
}
