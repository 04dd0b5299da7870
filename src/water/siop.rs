//! Specific inherent optical properties (SIOP sets): data that describe what a unit of each
//! constituent does to absorption and backscattering. A SIOP set is written in RON (see
//! `presets/siop/`) and resolved onto a wavelength grid before use.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::WaterError;
use crate::parse::ParseError;
use crate::spectral::{Extrapolation, SpectrumSource, WavelengthGrid};

fn default_refractive_index() -> f64 {
    1.34
}

/// A SIOP set as written in RON.
///
/// Concentrations it scales: chlorophyll-a `chl_mg_m3` (mg m⁻³ = µg L⁻¹), CDOM as its absorption
/// at the CDOM reference wavelength `cdom_per_m` (m⁻¹; 440 nm in Shoal's presets, 550 nm in
/// SAMBUCA's defaults), non-algal particles `nap_g_m3` (g m⁻³ = mg L⁻¹).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SiopSpec {
    /// Short name (`"heron_island"`).
    pub name: String,
    /// Where the numbers come from.
    #[serde(default)]
    pub description: String,
    /// Pure-water absorption a_w, m⁻¹.
    pub water_absorption: SpectrumSource,
    /// Pure-water backscattering bb_w, m⁻¹.
    pub water_backscatter: SpectrumSource,
    /// Chlorophyll-specific phytoplankton absorption a*_ph, m² mg⁻¹.
    pub phytoplankton_absorption: SpectrumSource,
    /// Chlorophyll-specific phytoplankton backscattering bb*_ph, m² mg⁻¹.
    pub phytoplankton_backscatter: SpectrumSource,
    /// CDOM absorption per unit of `cdom_per_m` (dimensionless shape, 1 at the reference λ).
    pub cdom_absorption: SpectrumSource,
    /// Mass-specific NAP absorption a*_NAP, m² g⁻¹.
    pub nap_absorption: SpectrumSource,
    /// Mass-specific NAP backscattering bb*_NAP, m² g⁻¹.
    pub nap_backscatter: SpectrumSource,
    /// Refractive index of the water (Snell's law at the surface); default 1.34.
    #[serde(default = "default_refractive_index")]
    pub water_refractive_index: f64,
}

impl SiopSpec {
    /// Read a SIOP set from RON text; `origin` names the file in errors. Relative CSV paths in
    /// it are resolved later, by [`Self::resolve`]'s `base_dir` (the file's directory).
    pub fn from_ron(text: &str, origin: &str) -> Result<Self, WaterError> {
        crate::parse::from_ron(text, origin)
    }

    /// Read a SIOP set from a RON file.
    pub fn from_file(path: &Path) -> Result<Self, WaterError> {
        let text = crate::infile::read_text(path, crate::infile::RON_MAX_BYTES)
            .map_err(|e| WaterError::Parse(ParseError { origin: path.display().to_string(), message: e.message }))?;
        Self::from_ron(&text, &path.display().to_string())
    }

    /// SAMBUCA's default parameterisation (sambuca_core 1.2.3 `forward_model` defaults):
    /// Wallis Lake 2008 a*_ph, the `lw2002` pure-water absorption, bb_w = 0.00097 (550/λ)^4.32,
    /// CDOM and NAP exponentials referenced to 550 nm, backscatter power laws referenced to 546 nm.
    ///
    /// ```
    /// let s = shoal::water::SiopSpec::sambuca_default();
    /// assert_eq!(s.name, "sambuca_default");
    /// ```
    #[must_use]
    pub fn sambuca_default() -> Self {
        let y = 0.878_138;
        Self {
            name: "sambuca_default".into(),
            description: "SAMBUCA (sambuca_core 1.2.3) default SIOPs: Wallis Lake 2008 a*_ph, lw2002 a_w".into(),
            water_absorption: SpectrumSource::Asset {
                file: "water/sambuca_aw_350_900_lw2002.csv".into(),
                column: "a_water".into(),
                scale: 1.0,
                outside: Extrapolation::Error,
            },
            water_backscatter: SpectrumSource::PowerLaw {
                coefficient: 0.00194 / 2.0,
                reference_nm: 550.0,
                exponent: 4.32,
            },
            phytoplankton_absorption: SpectrumSource::Asset {
                file: "phytoplankton/sambuca_WL08_aphy.csv".into(),
                column: "WL08_aphy_star_mean_correct.csv:C2".into(),
                scale: 1.0,
                // The measured spectrum stops at 800 nm; phytoplankton absorb nothing there.
                outside: Extrapolation::Zero,
            },
            phytoplankton_backscatter: SpectrumSource::PowerLaw {
                coefficient: 0.001_577_47,
                reference_nm: 546.0,
                exponent: y,
            },
            cdom_absorption: SpectrumSource::Exponential {
                coefficient: 1.0,
                reference_nm: 550.0,
                slope_per_nm: 0.016_805_2,
            },
            nap_absorption: SpectrumSource::Exponential {
                coefficient: 0.004_33,
                reference_nm: 550.0,
                slope_per_nm: 0.009_772_62,
            },
            nap_backscatter: SpectrumSource::PowerLaw { coefficient: 0.022_535_3, reference_nm: 546.0, exponent: y },
            water_refractive_index: 1.337_84,
        }
    }

    /// A built-in SIOP set by name: `sambuca_default`, or a file in `presets/siop/`
    /// (`heron_island`, `cyanobacteria_reservoir`).
    ///
    /// ```
    /// assert!(shoal::water::SiopSpec::preset("heron_island").is_ok());
    /// assert!(shoal::water::SiopSpec::preset("nile").is_err());
    /// ```
    pub fn preset(name: &str) -> Result<Self, WaterError> {
        crate::parse::preset(name)
    }

    /// Names of the built-in SIOP sets (`sambuca_default` first: it is built in code).
    #[must_use]
    pub fn preset_names() -> Vec<String> {
        crate::parse::preset_names::<Self>()
    }

    /// Resolve onto `grid`. Every spectrum must cover the grid (or say what to do outside its
    /// data) and be finite; a_w must be ≥ 0 and bb_w > 0 (so that u = bb/(a+bb) is defined for
    /// pure water). Specific spectra may dip slightly below zero: measured a*_ph spectra carry
    /// noise in the near-infrared (SAMBUCA's Wallis Lake spectrum reaches −4·10⁻⁴ m² mg⁻¹ at
    /// 749 nm) and SAMBUCA uses them as they are; the model checks a > 0 per evaluation.
    pub fn resolve(&self, grid: &WavelengthGrid, base_dir: Option<&Path>) -> Result<Siop, WaterError> {
        let n = self.water_refractive_index;
        if !(n.is_finite() && (1.0..=1.5).contains(&n)) {
            return Err(WaterError::OutOfRange {
                field: "water_refractive_index".into(),
                value: n,
                allowed: "1.0 to 1.5".into(),
            });
        }
        let take = |field: &str, src: &SpectrumSource, min: f64| -> Result<Vec<f64>, WaterError> {
            let v = src.sample(grid, Extrapolation::Error, base_dir).map_err(|e| WaterError::Siop {
                set: self.name.clone(),
                field: field.into(),
                message: e.to_string(),
            })?;
            if let Some((i, x)) = v.iter().enumerate().find(|(_, x)| !(x.is_finite() && **x >= min)) {
                return Err(WaterError::Siop {
                    set: self.name.clone(),
                    field: field.into(),
                    message: format!("value {x} at {} nm; must be finite and ≥ {min}", grid.wavelength_nm(i)),
                });
            }
            Ok(v)
        };
        // Specific spectra: finite, and not more negative than measurement noise allows.
        let noise = -0.01;
        let siop = Siop {
            name: self.name.clone(),
            grid: grid.clone(),
            a_w: take("water_absorption", &self.water_absorption, 0.0)?,
            bb_w: take("water_backscatter", &self.water_backscatter, 0.0)?,
            a_ph_star: take("phytoplankton_absorption", &self.phytoplankton_absorption, noise)?,
            bb_ph_star: take("phytoplankton_backscatter", &self.phytoplankton_backscatter, noise)?,
            a_cdom_star: take("cdom_absorption", &self.cdom_absorption, noise)?,
            a_nap_star: take("nap_absorption", &self.nap_absorption, noise)?,
            bb_nap_star: take("nap_backscatter", &self.nap_backscatter, noise)?,
            water_refractive_index: n,
        };
        if let Some(i) = siop.bb_w.iter().position(|&b| b <= 0.0) {
            return Err(WaterError::Siop {
                set: self.name.clone(),
                field: "water_backscatter".into(),
                message: format!("must be > 0 (pure water scatters) but is 0 at {} nm", grid.wavelength_nm(i)),
            });
        }
        Ok(siop)
    }
}

/// A SIOP set resolved on a wavelength grid: the spectra the forward model multiplies by the
/// concentrations. Field names follow the glossary in [`crate::water`].
#[derive(Debug, Clone, PartialEq)]
pub struct Siop {
    /// Name of the set.
    pub name: String,
    /// The grid every spectrum below is sampled on.
    pub grid: WavelengthGrid,
    /// Pure-water absorption, m⁻¹.
    pub a_w: Vec<f64>,
    /// Pure-water backscattering, m⁻¹.
    pub bb_w: Vec<f64>,
    /// Chl-specific phytoplankton absorption, m² mg⁻¹.
    pub a_ph_star: Vec<f64>,
    /// Chl-specific phytoplankton backscattering, m² mg⁻¹.
    pub bb_ph_star: Vec<f64>,
    /// CDOM absorption per unit absorption at the reference wavelength (dimensionless).
    pub a_cdom_star: Vec<f64>,
    /// Mass-specific NAP absorption, m² g⁻¹.
    pub a_nap_star: Vec<f64>,
    /// Mass-specific NAP backscattering, m² g⁻¹.
    pub bb_nap_star: Vec<f64>,
    /// Refractive index of water for Snell's law.
    pub water_refractive_index: f64,
}

impl Siop {
    /// The set at some of its grid's wavelengths (`indices`, strictly increasing): the same
    /// values, picked, so a model on the subset gives bit for bit the full grid's values there.
    pub fn subset(&self, indices: &[usize]) -> Result<Self, WaterError> {
        let pick = |v: &[f64]| indices.iter().map(|&i| v[i]).collect::<Vec<f64>>();
        if let Some(&i) = indices.iter().find(|&&i| i >= self.grid.len()) {
            return Err(WaterError::OutOfRange {
                field: "subset index".into(),
                value: i as f64,
                allowed: format!("0 to {}", self.grid.len().saturating_sub(1)),
            });
        }
        let grid = WavelengthGrid::from_wavelengths(pick(self.grid.wavelengths_nm()))?;
        Ok(Self {
            name: self.name.clone(),
            grid,
            a_w: pick(&self.a_w),
            bb_w: pick(&self.bb_w),
            a_ph_star: pick(&self.a_ph_star),
            bb_ph_star: pick(&self.bb_ph_star),
            a_cdom_star: pick(&self.a_cdom_star),
            a_nap_star: pick(&self.a_nap_star),
            bb_nap_star: pick(&self.bb_nap_star),
            water_refractive_index: self.water_refractive_index,
        })
    }
}

/// Where a SIOP set comes from, as scene and run files write it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum SiopSource {
    /// A built-in set (`heron_island`, `cyanobacteria_reservoir`, `sambuca_default`).
    Preset(String),
    /// A SIOP RON file; CSV paths inside it are relative to it.
    File(std::path::PathBuf),
    /// A CSV file with any of the columns a_w, bb_w, a_ph_star, bb_ph_star, a_cdom_star,
    /// a_nap_star, bb_nap_star (against `wavelength_nm`); the others come from `heron_island`.
    Csv(std::path::PathBuf),
    /// A SIOP set written in place; CSV paths inside it are relative to the file that holds it.
    Inline(Box<SiopSpec>),
}

impl SiopSource {
    /// The SIOP set and the directory its own relative CSV paths are taken from. `spec_dir` is the
    /// directory of the file that holds an `Inline` set.
    pub fn load(&self, spec_dir: Option<&Path>) -> Result<(SiopSpec, Option<std::path::PathBuf>), WaterError> {
        Ok(match self {
            Self::Preset(name) => (SiopSpec::preset(name)?, None),
            Self::File(p) => (SiopSpec::from_file(p)?, p.parent().map(Path::to_path_buf)),
            Self::Csv(p) => (SiopSpec::from_csv_columns(p)?, None),
            Self::Inline(s) => ((**s).clone(), spec_dir.map(Path::to_path_buf)),
        })
    }

    /// Make relative paths relative to `dir` (the directory of the file that names them).
    #[must_use]
    pub fn relative_to(self, dir: Option<&Path>) -> Self {
        let near = |p: std::path::PathBuf| match dir {
            Some(d) if p.is_relative() => d.join(p),
            _ => p,
        };
        match self {
            Self::File(p) => Self::File(near(p)),
            Self::Csv(p) => Self::Csv(near(p)),
            other => other,
        }
    }
}

impl SiopSpec {
    /// A SIOP set from a CSV whose columns (any of a_w, bb_w, a_ph_star, bb_ph_star, a_cdom_star,
    /// a_nap_star, bb_nap_star, against `wavelength_nm`) replace those of `heron_island`.
    pub fn from_csv_columns(path: &Path) -> Result<Self, WaterError> {
        let table = crate::spectral::Table::from_file(path)?;
        // Absolute, so that resolving the set never joins a base directory to it again.
        let path = &std::fs::canonicalize(path).map_err(|e| {
            WaterError::Parse(ParseError { origin: path.display().to_string(), message: e.to_string() })
        })?;
        let mut s = Self::preset("heron_island")?;
        s.name = format!("csv:{}", path.display());
        let slots: [(&str, &mut SpectrumSource); 7] = [
            ("a_w", &mut s.water_absorption),
            ("bb_w", &mut s.water_backscatter),
            ("a_ph_star", &mut s.phytoplankton_absorption),
            ("bb_ph_star", &mut s.phytoplankton_backscatter),
            ("a_cdom_star", &mut s.cdom_absorption),
            ("a_nap_star", &mut s.nap_absorption),
            ("bb_nap_star", &mut s.nap_backscatter),
        ];
        // A column the set does not know is refused, not skipped: a misspelt `aph_star` would
        // otherwise leave heron_island's a*_ph in the user's set without a word.
        let known: Vec<&str> = slots.iter().map(|(c, _)| *c).collect();
        if let Some(stray) =
            table.columns.iter().find(|c| c.as_str() != "wavelength_nm" && !known.contains(&c.as_str()))
        {
            return Err(WaterError::Parse(ParseError {
                origin: path.display().to_string(),
                message: format!(
                    "unknown SIOP column `{stray}` (allowed: wavelength_nm, {}); the set's other spectra \
                     come from heron_island, so a misspelt column would silently be replaced",
                    known.join(", ")
                ),
            }));
        }
        let mut used = 0;
        for (column, slot) in slots {
            if table.columns.iter().any(|c| c == column) {
                *slot = SpectrumSource::Csv {
                    path: path.clone(),
                    column: column.into(),
                    scale: 1.0,
                    outside: Default::default(),
                };
                used += 1;
            }
        }
        if used == 0 {
            return Err(WaterError::Parse(ParseError {
                origin: path.display().to_string(),
                message: format!(
                    "no SIOP column found (expected any of a_w, bb_w, a_ph_star, bb_ph_star, a_cdom_star, a_nap_star, bb_nap_star; found {})",
                    table.columns.join(", ")
                ),
            }));
        }
        Ok(s)
    }
}

impl crate::parse::Preset for SiopSpec {
    const FOLDER: &'static str = "siop";
    type Error = WaterError;
    fn parse_error(origin: &str, message: String) -> WaterError {
        WaterError::Parse(ParseError { origin: origin.into(), message })
    }
    fn unknown(name: &str, known: &[String]) -> WaterError {
        WaterError::UnknownName { field: "SIOP set".into(), name: name.into(), known: known.join(", ") }
    }
    fn built_in(name: &str) -> Option<Self> {
        (name == "sambuca_default").then(Self::sambuca_default)
    }
    fn built_in_names() -> Vec<String> {
        vec!["sambuca_default".into()]
    }
}
