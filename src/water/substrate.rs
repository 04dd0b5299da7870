//! Benthic substrates: a library of named irradiance-reflectance spectra (embedded SAMBUCA and
//! WASI libraries, plus the user's CSV columns) and mixtures of them.
//!
//! Bottom reflectance outside a spectrum's data (most stop at 850–951 nm) is held at the last
//! value: beyond about 750 nm pure water absorbs more than 2 m⁻¹, so the bottom term
//! exp(−(Kd+kuB)H) is below 10⁻³ for H > 2 m and the held value does not matter.

use std::path::Path;

use super::WaterError;
use crate::parse::ParseError;
use crate::spectral::{Extrapolation, Spectrum, Table, WavelengthGrid};

/// One library entry: the name users type and where the spectrum lives.
#[derive(Debug, Clone, PartialEq)]
pub struct SubstrateEntry {
    /// Name as typed (`"sand"`), lower-case.
    pub name: String,
    /// What it is and where it was measured.
    pub description: String,
    /// The reflectance spectrum (irradiance reflectance, 0–1).
    pub spectrum: Spectrum,
}

/// Embedded substrate spectra: (name, asset file, column, description).
const EMBEDDED: &[(&str, &str, &str, &str)] = &[
    ("acropora", "benthic/sambuca_HI_3.csv", "Acropora", "Heron Island Acropora coral (SAMBUCA HI_3)"),
    ("sand", "benthic/sambuca_HI_3.csv", "sand", "Heron Island coralline sand (SAMBUCA HI_3)"),
    ("turf_algae", "benthic/sambuca_HI_3.csv", "Turf Algae", "Heron Island turf algae (SAMBUCA HI_3)"),
    ("seagrass", "benthic/sambuca_NCC_3subs.csv", "cymodocea.txt:C2", "Cymodocea seagrass (SAMBUCA NCC_3subs)"),
    ("brown_acropora", "benthic/sambuca_NCC_3subs.csv", "brown_acropora", "brown Acropora (SAMBUCA NCC_3subs)"),
    ("ncc_sand", "benthic/sambuca_NCC_3subs.csv", "sand", "sand (SAMBUCA NCC_3subs)"),
    ("mb_white_sand", "benthic/sambuca_Moreton_Bay.csv", "white Sand", "Moreton Bay white sand (SAMBUCA)"),
    ("mb_brown_mud", "benthic/sambuca_Moreton_Bay.csv", "brown Mud", "Moreton Bay brown mud (SAMBUCA)"),
    ("mb_zostera", "benthic/sambuca_Moreton_Bay.csv", "Zostera muelleri", "Moreton Bay Zostera muelleri (SAMBUCA)"),
    ("mb_green_algae", "benthic/sambuca_Moreton_Bay.csv", "green algae", "Moreton Bay green algae (SAMBUCA)"),
    ("wl_bright_sand", "benthic/sambuca_WL5_2008.csv", "bright sand", "Wallis Lake bright sand (SAMBUCA WL5_2008)"),
    ("wl_posidonia", "benthic/sambuca_WL5_2008.csv", "Posidonia", "Wallis Lake Posidonia (SAMBUCA WL5_2008)"),
    ("wasi_sand", "benthic/benthic_reflectance.csv", "sand", "sand, ASU in-water ASD (WASI6 R_b)"),
    ("wasi_coral", "benthic/benthic_reflectance.csv", "coral", "coral, ASU in-water ASD (WASI6 R_b)"),
    ("wasi_cca", "benthic/benthic_reflectance.csv", "cca", "crustose coralline algae (WASI6 R_b)"),
    ("wasi_macroalgae", "benthic/benthic_reflectance.csv", "macroalgae", "macroalgae (WASI6 R_b)"),
    ("wasi_seagrass", "benthic/benthic_reflectance.csv", "seagrass", "Zostera marina seagrass (WASI6 R_b)"),
];

/// Short names accepted for convenience, used only when no entry has the typed name itself: a
/// user's own `coral` column always wins over the alias.
const ALIASES: &[(&str, &str)] = &[("coral", "acropora"), ("algae", "turf_algae")];

/// A set of named substrate spectra.
#[derive(Debug, Clone, Default)]
pub struct SubstrateLibrary {
    entries: Vec<SubstrateEntry>,
}

impl SubstrateLibrary {
    /// The embedded library (SAMBUCA Heron Island, NCC, Moreton Bay, Wallis Lake; WASI6).
    ///
    /// ```
    /// let lib = shoal::water::SubstrateLibrary::embedded().unwrap();
    /// assert!(lib.get("coral").is_ok());
    /// assert!(lib.get("lava").is_err());
    /// ```
    pub fn embedded() -> Result<Self, WaterError> {
        // Parsed once per process (the files are compiled in and never change); each call
        // returns a copy the caller may extend with its own spectra.
        static PARSED: std::sync::OnceLock<Result<SubstrateLibrary, WaterError>> = std::sync::OnceLock::new();
        PARSED.get_or_init(Self::parse_embedded).clone()
    }

    fn parse_embedded() -> Result<Self, WaterError> {
        let entries = EMBEDDED
            .iter()
            .map(|(name, file, column, description)| {
                Ok(SubstrateEntry {
                    name: (*name).to_string(),
                    description: (*description).to_string(),
                    spectrum: Spectrum::from_asset(file, column).map_err(WaterError::from)?,
                })
            })
            .collect::<Result<_, WaterError>>()?;
        Ok(Self { entries })
    }

    /// Add every value column of a user CSV (`wavelength_nm` plus one column per substrate),
    /// named by its column header (lower-cased). The user's names win: a column called like a
    /// built-in entry (`sand`) or an alias (`coral`) replaces it for every later look-up, and
    /// its description says so. Two columns that are the same name once lower-cased are refused
    /// (which one was meant cannot be known).
    pub fn add_csv(&mut self, path: &Path) -> Result<(), WaterError> {
        let table = Table::from_file(path)?;
        let columns: Vec<&String> = table.columns.iter().filter(|c| c.as_str() != "wavelength_nm").collect();
        for (i, a) in columns.iter().enumerate() {
            if let Some(b) = columns[..i].iter().find(|b| b.eq_ignore_ascii_case(a)) {
                return Err(WaterError::Parse(ParseError {
                    origin: path.display().to_string(),
                    message: format!(
                        "columns `{b}` and `{a}` name the same substrate (names are case-insensitive); rename one"
                    ),
                }));
            }
        }
        for column in columns {
            let spectrum = Spectrum::from_table(&table, column)?;
            let name = column.to_ascii_lowercase();
            let replaced = self.entries.iter().position(|e| e.name == name);
            let alias = ALIASES.iter().find(|(a, _)| *a == name).map(|(_, t)| *t);
            let note = match (replaced, alias) {
                (Some(_), _) => format!(" (replaces the built-in `{name}`)"),
                (None, Some(target)) => format!(" (replaces the alias `{name}` for `{target}`)"),
                (None, None) => String::new(),
            };
            let entry = SubstrateEntry {
                name,
                description: format!("user spectrum {}:{column}{note}", path.display()),
                spectrum,
            };
            match replaced {
                Some(i) => self.entries[i] = entry,
                None => self.entries.push(entry),
            }
        }
        Ok(())
    }

    /// The entry called `name` (case-insensitive). An entry of that very name wins; only when
    /// there is none are `coral` and `algae` read as aliases of `acropora` and `turf_algae`.
    pub fn get(&self, name: &str) -> Result<&SubstrateEntry, WaterError> {
        let lower = name.trim().to_ascii_lowercase();
        let exact = self.entries.iter().find(|e| e.name == lower);
        let aliased = || {
            let target = ALIASES.iter().find(|(a, _)| *a == lower).map(|(_, t)| *t)?;
            self.entries.iter().find(|e| e.name == target)
        };
        exact.or_else(aliased).ok_or_else(|| WaterError::UnknownName {
            field: "substrate".into(),
            name: name.to_string(),
            known: self.names().join(", "),
        })
    }

    /// All names, in library order.
    #[must_use]
    pub fn names(&self) -> Vec<String> {
        self.entries.iter().map(|e| e.name.clone()).collect()
    }

    /// All entries.
    #[must_use]
    pub fn entries(&self) -> &[SubstrateEntry] {
        &self.entries
    }

    /// Reflectance of a mixture on `grid`: ρ_b = Σ fᵢ ρᵢ (linear areal mixing, as in SAMBUCA).
    /// Measured spectra carry noise that dips below zero where the bottom is dark (HI_3
    /// Acropora reaches −3·10⁻⁴ in the near-infrared); a reflectance cannot be negative, so such
    /// values count as 0.
    pub fn mix_on_grid(&self, mix: &SubstrateMix, grid: &WavelengthGrid) -> Result<Vec<f64>, WaterError> {
        let mut out = vec![0.0; grid.len()];
        for (name, fraction) in &mix.parts {
            let r = self.get(name)?.spectrum.resample(grid, Extrapolation::Clamp)?;
            for (o, v) in out.iter_mut().zip(r) {
                *o += fraction * v.max(0.0);
            }
        }
        Ok(out)
    }
}

/// Areal fractions of named substrates; they sum to 1.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SubstrateMix {
    /// (name, fraction) pairs.
    pub parts: Vec<(String, f64)>,
}

impl SubstrateMix {
    /// Parse `sand:0.5,coral:0.5` (a lone name means fraction 1). Fractions must lie in 0–1
    /// and sum to 1 within 0.001.
    ///
    /// ```
    /// use shoal::water::SubstrateMix;
    /// assert!(SubstrateMix::parse("sand:0.5,coral:0.5").is_ok());
    /// assert!(SubstrateMix::parse("sand").is_ok());
    /// assert!(SubstrateMix::parse("sand:0.5,coral:0.2").is_err());
    /// ```
    pub fn parse(text: &str) -> Result<Self, WaterError> {
        let parts = text
            .split(',')
            .filter(|p| !p.trim().is_empty())
            .map(|part| match part.split_once(':') {
                None => Ok((part.trim().to_string(), 1.0)),
                Some((name, f)) => {
                    let value = f.trim().parse::<f64>().map_err(|_| WaterError::OutOfRange {
                        field: format!("substrate fraction of `{}`", name.trim()),
                        value: f64::NAN,
                        allowed: format!("a number from 0 to 1 (got `{}`)", f.trim()),
                    })?;
                    Ok((name.trim().to_string(), value))
                }
            })
            .collect::<Result<Vec<_>, WaterError>>()?;
        let mix = Self { parts };
        mix.validate()?;
        Ok(mix)
    }

    /// Check fractions: each in 0–1, sum 1 ± 0.001, at least one part.
    pub fn validate(&self) -> Result<(), WaterError> {
        if self.parts.is_empty() {
            return Err(WaterError::OutOfRange {
                field: "substrate".into(),
                value: 0.0,
                allowed: "at least one substrate name".into(),
            });
        }
        for (name, f) in &self.parts {
            if !(f.is_finite() && (0.0..=1.0).contains(f)) {
                return Err(WaterError::OutOfRange {
                    field: format!("substrate fraction of `{name}`"),
                    value: *f,
                    allowed: "0 to 1".into(),
                });
            }
        }
        let sum: f64 = self.parts.iter().map(|(_, f)| f).sum();
        if (sum - 1.0).abs() > 1e-3 {
            return Err(WaterError::OutOfRange {
                field: "substrate fractions (sum)".into(),
                value: sum,
                allowed: "fractions summing to 1 (±0.001)".into(),
            });
        }
        Ok(())
    }
}
