//! Sensor band sets (from published spectral response functions or Gaussian centre/FWHM) and
//! the `band_from_fine` averaging matrix.

use serde::{Deserialize, Serialize};

use super::{SpectralError, Spectrum, Table};

/// Which unit of a twin-satellite constellation an SRF set belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Platform {
    /// Sentinel-3A (OLCI) or Sentinel-2A (MSI).
    #[default]
    A,
    /// Sentinel-3B (OLCI) or Sentinel-2B (MSI).
    B,
}

/// One Gaussian band: centre and full width at half maximum.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaussianBand {
    /// Band name; defaults to `B<centre>`.
    #[serde(default)]
    pub name: Option<String>,
    /// Centre wavelength, nm.
    pub centre_nm: f64,
    /// Full width at half maximum, nm.
    pub fwhm_nm: f64,
}

/// How a band set is described in RON and on the command line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum BandSetSpec {
    /// Sentinel-3 OLCI mean SRFs (ESA 2016). Default bands Oa01–Oa19, the 19 bands of
    /// Matthews et al. (2023) Table 1 (Oa20/Oa21 lie at 940/1020 nm).
    Olci {
        /// S3A or S3B.
        #[serde(default)]
        platform: Platform,
        /// A subset of band names (`"Oa08"`), or all 19 by default.
        #[serde(default)]
        bands: Option<Vec<String>>,
    },
    /// Sentinel-2 MSI SRFs v4.0 (ESA 2024). Default bands B1–B9 (B10–B12 lie beyond 1000 nm).
    Msi {
        /// S2A or S2B.
        #[serde(default)]
        platform: Platform,
        /// A subset of band names (`"B8A"`), or B1–B9 by default.
        #[serde(default)]
        bands: Option<Vec<String>>,
    },
    /// Custom bands with Gaussian SRFs.
    Gaussian(Vec<GaussianBand>),
    /// Several sets one after the other (an OLCI set and Gaussian SWIR bands); band names must
    /// stay distinct.
    Combined(Vec<BandSetSpec>),
}

impl BandSetSpec {
    /// Parse a command-line name: `olci`, `olci-s3b`, `msi`, `msi-s2b`, or
    /// `gauss:443/20,560/20` (centre/FWHM pairs in nm).
    ///
    /// ```
    /// use shoal::spectral::BandSetSpec;
    /// assert!(BandSetSpec::parse_cli("olci").is_ok());
    /// assert!(BandSetSpec::parse_cli("gauss:443/20,865/40").is_ok());
    /// assert!(BandSetSpec::parse_cli("landsat").is_err());
    /// ```
    pub fn parse_cli(text: &str) -> Result<Self, SpectralError> {
        match text.trim().to_ascii_lowercase().as_str() {
            "olci" | "olci-s3a" => Ok(Self::Olci { platform: Platform::A, bands: None }),
            "olci-s3b" => Ok(Self::Olci { platform: Platform::B, bands: None }),
            "msi" | "msi-s2a" => Ok(Self::Msi { platform: Platform::A, bands: None }),
            "msi-s2b" => Ok(Self::Msi { platform: Platform::B, bands: None }),
            other => {
                let Some(list) = other.strip_prefix("gauss:") else {
                    return Err(SpectralError::Bands(format!(
                        "unknown band set `{text}` (allowed: olci, olci-s3b, msi, msi-s2b, \
                         gauss:CENTRE/FWHM,...)"
                    )));
                };
                let bands = list
                    .split(',')
                    .map(|pair| {
                        let (c, w) = pair
                            .split_once('/')
                            .ok_or_else(|| SpectralError::Bands(format!("`{pair}`: expected CENTRE/FWHM in nm")))?;
                        let parse = |s: &str| {
                            s.trim()
                                .parse::<f64>()
                                .map_err(|_| SpectralError::Bands(format!("`{pair}`: `{s}` is not a number")))
                        };
                        Ok(GaussianBand { name: None, centre_nm: parse(c)?, fwhm_nm: parse(w)? })
                    })
                    .collect::<Result<Vec<_>, SpectralError>>()?;
                Ok(Self::Gaussian(bands))
            }
        }
    }
}

/// One sensor band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Band {
    /// Band name (`"Oa08"`).
    pub name: String,
    /// SRF-weighted centroid wavelength, nm.
    pub centre_nm: f64,
    /// Full width at half maximum of the SRF, nm.
    pub fwhm_nm: f64,
    /// Relative spectral response (zero outside its samples).
    pub srf: Spectrum,
}

/// An ordered set of bands.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandSet {
    /// Name for reports (`"OLCI S3A"`).
    pub name: String,
    /// The bands, in the order cubes use.
    pub bands: Vec<Band>,
}

impl BandSet {
    /// Build the bands a spec describes.
    ///
    /// ```
    /// use shoal::spectral::{BandSet, BandSetSpec};
    /// let olci = BandSet::from_spec(&BandSetSpec::parse_cli("olci").unwrap()).unwrap();
    /// assert_eq!(olci.bands.len(), 19);
    /// assert!((olci.bands[7].centre_nm - 665.0).abs() < 1.5);
    /// ```
    pub fn from_spec(spec: &BandSetSpec) -> Result<Self, SpectralError> {
        /// Band sets read from the embedded response tables (OLCI, MSI), kept once built: the
        /// files never change, and parsing them (~1 ms) is too slow for the app, which builds its
        /// designs' configurations every frame. At most `KEPT` (a user's subsets of bands).
        static BUILT: std::sync::Mutex<Vec<(BandSetSpec, BandSet)>> = std::sync::Mutex::new(Vec::new());
        const KEPT: usize = 64;
        let tabled = matches!(spec, BandSetSpec::Olci { .. } | BandSetSpec::Msi { .. });
        let lock = || BUILT.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if tabled && let Some((_, set)) = lock().iter().find(|(s, _)| s == spec) {
            return Ok(set.clone());
        }
        let set = Self::build(spec)?;
        // Retrieval settings, cubes and reports address bands by name: two bands of one name
        // would make the second unreachable (a look-up takes the first).
        for (i, b) in set.bands.iter().enumerate() {
            if set.bands[..i].iter().any(|a| a.name == b.name) {
                return Err(SpectralError::Bands(format!(
                    "two bands are called `{}`; band names must be unique (name Gaussian bands with `name: Some(\"…\")`)",
                    b.name
                )));
            }
        }
        if tabled {
            let mut built = lock();
            if built.len() >= KEPT {
                built.remove(0);
            }
            built.push((spec.clone(), set.clone()));
        }
        Ok(set)
    }

    fn build(spec: &BandSetSpec) -> Result<Self, SpectralError> {
        match spec {
            BandSetSpec::Olci { platform, bands } => {
                let (path, label) = match platform {
                    Platform::A => ("srf/srf_s3a_olci.csv", "OLCI S3A"),
                    Platform::B => ("srf/srf_s3b_olci.csv", "OLCI S3B"),
                };
                let default: Vec<String> = (1..=19).map(|i| format!("Oa{i:02}")).collect();
                let names = bands.clone().unwrap_or(default);
                let table = Table::from_asset(path)?;
                let key = table.column_index("band")?;
                let bands = names
                    .iter()
                    .map(|n| {
                        let rows = table.filter_eq(key, n);
                        if rows.is_empty() {
                            return Err(SpectralError::Bands(format!("OLCI has no band `{n}` (Oa01–Oa21)")));
                        }
                        let wl = rows.column_f64("wavelength_nm")?;
                        let r = rows.column_f64("response")?;
                        Band::from_srf(n, Spectrum::new(format!("{label} {n}"), wl, r)?)
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(Self { name: label.into(), bands })
            }
            BandSetSpec::Msi { platform, bands } => {
                let (path, label) = match platform {
                    Platform::A => ("srf/srf_s2a_msi.csv", "MSI S2A"),
                    Platform::B => ("srf/srf_s2b_msi.csv", "MSI S2B"),
                };
                let default = ["B1", "B2", "B3", "B4", "B5", "B6", "B7", "B8", "B8A", "B9"];
                let names: Vec<String> =
                    bands.clone().unwrap_or_else(|| default.iter().map(|s| (*s).to_string()).collect());
                let table = Table::from_asset(path)?;
                let bands = names
                    .iter()
                    .map(|n| {
                        let srf = Spectrum::from_table(&table, n)
                            .map_err(|_| SpectralError::Bands(format!("MSI has no band `{n}` (B1–B12, B8A)")))?;
                        Band::from_srf(n, trim_zeros(srf)?)
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(Self { name: label.into(), bands })
            }
            BandSetSpec::Combined(parts) => {
                if parts.is_empty() {
                    return Err(SpectralError::Bands("a combined band set needs at least one part".into()));
                }
                let sets = parts.iter().map(Self::build).collect::<Result<Vec<_>, _>>()?;
                let name = sets.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(" + ");
                Ok(Self { name, bands: sets.into_iter().flat_map(|s| s.bands).collect() })
            }
            BandSetSpec::Gaussian(list) => {
                if list.is_empty() {
                    return Err(SpectralError::Bands("a Gaussian band set needs at least one band".into()));
                }
                let bands = list.iter().map(Band::gaussian).collect::<Result<Vec<_>, _>>()?;
                Ok(Self { name: "Gaussian".into(), bands })
            }
        }
    }

    /// Number of bands.
    #[must_use]
    pub fn len(&self) -> usize {
        self.bands.len()
    }

    /// True when there are no bands.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.bands.is_empty()
    }

    /// Band centres, nm.
    #[must_use]
    pub fn centres_nm(&self) -> Vec<f64> {
        self.bands.iter().map(|b| b.centre_nm).collect()
    }
}

impl Band {
    /// A band from a sampled SRF: centroid and FWHM are derived from it.
    pub fn from_srf(name: &str, srf: Spectrum) -> Result<Self, SpectralError> {
        let peak = srf.values.iter().copied().fold(0.0f64, f64::max);
        if !(peak > 0.0) || srf.values.iter().any(|v| *v < 0.0) {
            return Err(SpectralError::Bands(format!("band `{name}`: SRF must be non-negative with a positive peak")));
        }
        let (mut s0, mut s1) = (0.0, 0.0);
        for w in srf.wavelength_nm.windows(2).zip(srf.values.windows(2)) {
            let (x, y) = w;
            let dx = x[1] - x[0];
            s0 += 0.5 * dx * (y[0] + y[1]);
            s1 += 0.5 * dx * (x[0] * y[0] + x[1] * y[1]);
        }
        let half = 0.5 * peak;
        let first = srf.values.iter().position(|&v| v >= half).unwrap_or(0);
        let last = srf.values.iter().rposition(|&v| v >= half).unwrap_or(0);
        let cross = |i: usize, j: usize| {
            let (x0, x1, y0, y1) = (srf.wavelength_nm[i], srf.wavelength_nm[j], srf.values[i], srf.values[j]);
            if (y1 - y0).abs() < f64::MIN_POSITIVE { x0 } else { x0 + (half - y0) * (x1 - x0) / (y1 - y0) }
        };
        let left = if first > 0 { cross(first - 1, first) } else { srf.wavelength_nm[0] };
        let right = if last + 1 < srf.values.len() { cross(last, last + 1) } else { srf.wavelength_nm[last] };
        Ok(Self { name: name.to_string(), centre_nm: s1 / s0, fwhm_nm: right - left, srf })
    }

    /// A Gaussian band: SRF = exp(−4 ln2 (λ−c)²/FWHM²), sampled to ±2.5 FWHM.
    pub fn gaussian(spec: &GaussianBand) -> Result<Self, SpectralError> {
        /// Where Shoal has spectral data (the solar spectrum, 300–2500 nm).
        const DATA_NM: (f64, f64) = (300.0, 2500.0);
        let (c, w) = (spec.centre_nm, spec.fwhm_nm);
        if !(c.is_finite() && (DATA_NM.0..=DATA_NM.1).contains(&c)) {
            return Err(SpectralError::Bands(format!("centre_nm = {c} is out of range (300 to 2500 nm)")));
        }
        if !(w.is_finite() && (0.1..=300.0).contains(&w)) {
            return Err(SpectralError::Bands(format!("fwhm_nm = {w} is out of range (0.1 to 300 nm)")));
        }
        let name = spec.name.clone().unwrap_or_else(|| format!("B{c:.0}"));
        let response = |x: f64| (-4.0 * std::f64::consts::LN_2 * ((x - c) / w).powi(2)).exp();
        // Centre ± 2.5 FWHM, cut where the data end if the response there is below 1 % of the
        // peak (a 2200 nm band of 187 nm FWHM loses a tail of 0.2 %): what lies beyond would
        // have nothing to multiply.
        let (lo, hi) = ((c - 2.5 * w).max(DATA_NM.0), (c + 2.5 * w).min(DATA_NM.1));
        if response(lo) > 0.01 || response(hi) > 0.01 {
            return Err(SpectralError::Bands(format!(
                "band centred at {c} nm with FWHM {w} nm reaches beyond 300–2500 nm with more than 1 % of its peak \
                 (allowed: the response below 1 % of the peak where the data end)"
            )));
        }
        let n = 201;
        let (wl, v): (Vec<f64>, Vec<f64>) = (0..n)
            .map(|i| {
                let x = lo + (hi - lo) * i as f64 / (n - 1) as f64;
                (x, response(x))
            })
            .unzip();
        Ok(Self { name: name.clone(), centre_nm: c, fwhm_nm: w, srf: Spectrum::new(name, wl, v)? })
    }
}

/// Drop the leading and trailing zero samples of a 1-nm SRF column that spans the whole file.
fn trim_zeros(s: Spectrum) -> Result<Spectrum, SpectralError> {
    let first = s.values.iter().position(|&v| v > 0.0).unwrap_or(0).saturating_sub(1);
    let last = (s.values.iter().rposition(|&v| v > 0.0).unwrap_or(0) + 1).min(s.values.len() - 1);
    Spectrum::new(s.name.clone(), s.wavelength_nm[first..=last].to_vec(), s.values[first..=last].to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::{BandAverager, Extrapolation, WavelengthGrid};

    #[test]
    fn olci_centroids_match_the_esa_table() {
        // olci_bands.csv gives the S3A SRF centroids computed independently (PROVENANCE.md).
        let olci = BandSet::from_spec(&BandSetSpec::Olci { platform: Platform::A, bands: None }).unwrap();
        let t = Table::from_asset("srf/olci_bands.csv").unwrap();
        let centroids = t.column_f64("srf_centroid_nm").unwrap();
        let fwhm = t.column_f64("srf_fwhm_nm").unwrap();
        for (b, (c, w)) in olci.bands.iter().zip(centroids.iter().zip(&fwhm)) {
            assert!((b.centre_nm - c).abs() < 0.01, "{}: {} vs {}", b.name, b.centre_nm, c);
            assert!((b.fwhm_nm - w).abs() < 0.05, "{}: {} vs {}", b.name, b.fwhm_nm, w);
        }
    }

    #[test]
    fn band_average_of_tsis_matches_the_table_e0() {
        // E0 band averages in olci_bands.csv were summed from the SRF and TSIS at 1 nm (rectangle
        // rule); ours integrates SRF × the linear interpolant of TSIS exactly. The two schemes
        // differ by quadrature error of the 1-nm solar sampling, largest where deep Fraunhofer
        // lines sit inside a band (Ca II H&K 393/397 nm in Oa01, Hγ 434 nm in Oa03): 0.25 %
        // below 450 nm, 0.1 % elsewhere.
        let grid = WavelengthGrid::fine();
        let olci = BandSet::from_spec(&BandSetSpec::parse_cli("olci").unwrap()).unwrap();
        let m = BandAverager::new(&grid, &olci).unwrap();
        let e0 = Spectrum::from_asset("solar/solar_tsis1_hsrs_1nm.csv", "irradiance_W_m2_nm")
            .unwrap()
            .resample(&grid, Extrapolation::Error)
            .unwrap();
        let band = m.apply(&e0);
        let expected = Table::from_asset("srf/olci_bands.csv").unwrap().column_f64("E0_tsis_W_m2_nm").unwrap();
        for (i, (got, want)) in band.iter().zip(&expected).enumerate() {
            let tolerance = if olci.bands[i].centre_nm < 450.0 { 2.5e-3 } else { 1e-3 };
            assert!((got / want - 1.0).abs() < tolerance, "band {i}: {got} vs {want}");
        }
    }

    #[test]
    fn coarse_grid_still_averages_a_line_exactly() {
        // A linear spectrum is represented exactly by linear interpolation on any grid, so the
        // band average must equal the SRF centroid's value whatever the step.
        for step in [1.0, 5.0, 10.0] {
            let grid = WavelengthGrid::fine_with_step(step).unwrap();
            let olci = BandSet::from_spec(&BandSetSpec::parse_cli("olci").unwrap()).unwrap();
            let m = BandAverager::new(&grid, &olci).unwrap();
            let line: Vec<f64> = grid.wavelengths_nm().to_vec();
            for (b, v) in olci.bands.iter().zip(m.apply(&line)) {
                assert!((v - b.centre_nm).abs() < 1e-6, "step {step} {}: {v} vs {}", b.name, b.centre_nm);
            }
        }
    }

    #[test]
    fn bands_outside_the_grid_are_refused() {
        let spec = BandSetSpec::Olci { platform: Platform::A, bands: Some(vec!["Oa21".into()]) };
        let olci = BandSet::from_spec(&spec).unwrap();
        let e = BandAverager::new(&WavelengthGrid::fine(), &olci).unwrap_err().to_string();
        assert!(e.contains("Oa21") && e.contains("outside"), "{e}");
    }

    #[test]
    fn msi_and_gaussian_sets_build() {
        let msi = BandSet::from_spec(&BandSetSpec::parse_cli("msi-s2b").unwrap()).unwrap();
        assert_eq!(msi.len(), 10);
        assert!(BandAverager::new(&WavelengthGrid::fine(), &msi).is_ok());
        let g = BandSet::from_spec(&BandSetSpec::parse_cli("gauss:443/20").unwrap()).unwrap();
        assert!((g.bands[0].fwhm_nm - 20.0).abs() < 0.1);
        assert!(BandSetSpec::parse_cli("gauss:443").is_err());
        assert!(BandSet::from_spec(&BandSetSpec::parse_cli("gauss:443/-2").unwrap()).is_err());
    }
}
