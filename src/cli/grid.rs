//! Wavelength selection shared by `shoal water` and `shoal atmosphere`.

use clap::Args;
use serde::{Deserialize, Serialize};

use super::CliError;
use crate::spectral::{BandSet, BandSetSpec, WavelengthGrid};

/// Which wavelengths to compute, as written in a RON spec.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum GridSpec {
    /// A uniform grid.
    Range {
        /// First wavelength, nm.
        start_nm: f64,
        /// Last wavelength (at most), nm.
        end_nm: f64,
        /// Step, nm.
        step_nm: f64,
    },
    /// An explicit list, nm.
    List(Vec<f64>),
}

/// Wavelength flags.
#[derive(Debug, Clone, Args, Default)]
pub struct GridArgs {
    /// Grid step in nm over the range (default: 1 nm for water, 5 nm for the atmosphere).
    #[arg(long, value_name = "NM")]
    pub step: Option<f64>,
    /// Range START:END in nm (default 350:1000).
    #[arg(long, value_name = "START:END")]
    pub range: Option<String>,
    /// Explicit wavelengths in nm, comma-separated (e.g. 412.5,442.5,490).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub wavelengths: Option<Vec<f64>>,
    /// Band-average the output: olci, olci-s3b, msi, msi-s2b, or gauss:CENTRE/FWHM,...
    #[arg(long, value_name = "SET")]
    pub bands: Option<String>,
}

impl GridArgs {
    /// Resolve the flags (over an optional spec) into a grid and optional band set.
    pub fn resolve(
        &self,
        spec: Option<&GridSpec>,
        default_step: f64,
    ) -> Result<(WavelengthGrid, Option<BandSet>), CliError> {
        let grid = if let Some(list) = &self.wavelengths {
            WavelengthGrid::from_wavelengths(list.clone())?
        } else if self.range.is_some() || self.step.is_some() {
            let (start, end) = match &self.range {
                None => (350.0, 1000.0),
                Some(r) => {
                    let bad = || CliError::Input(format!("--range: expected START:END in nm, got `{r}`"));
                    let (a, b) = r.split_once(':').ok_or_else(bad)?;
                    (a.trim().parse().map_err(|_| bad())?, b.trim().parse().map_err(|_| bad())?)
                }
            };
            let step = self.step.unwrap_or(default_step);
            if !(step.is_finite() && (0.1..=50.0).contains(&step)) {
                return Err(CliError::Input(format!("--step = {step} is out of range (allowed: 0.1 to 50 nm)")));
            }
            WavelengthGrid::uniform(start, end, step)?
        } else {
            match spec {
                Some(GridSpec::Range { start_nm, end_nm, step_nm }) => {
                    WavelengthGrid::uniform(*start_nm, *end_nm, *step_nm)?
                }
                Some(GridSpec::List(list)) => WavelengthGrid::from_wavelengths(list.clone())?,
                None => WavelengthGrid::uniform(350.0, 1000.0, default_step)?,
            }
        };
        let bands = match &self.bands {
            None => None,
            Some(name) => Some(BandSet::from_spec(&BandSetSpec::parse_cli(name)?)?),
        };
        Ok((grid, bands))
    }
}
