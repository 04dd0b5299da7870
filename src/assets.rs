//! Cited data embedded in the binary, so that `shoal` runs from any directory.
//!
//! Every file under `assets/` keeps the provenance header it came with (`# name/units/source/
//! citation/license/processing` lines); `assets/PROVENANCE.md` is the index and
//! `assets/licenses/` holds the licence texts the data require (CSIRO for the SAMBUCA spectra,
//! Apache-2.0 for the WASI spectra).

/// One embedded data file: its path below `assets/` and its text.
#[derive(Debug, Clone, Copy)]
pub struct Asset {
    /// Path relative to `assets/`, e.g. `"water/water_absorption_wasi6.csv"`.
    pub path: &'static str,
    /// The whole file, provenance header included.
    pub text: &'static str,
}

macro_rules! embed {
    ($($path:literal),* $(,)?) => {
        &[$(Asset { path: $path, text: include_str!(concat!("../assets/", $path)) }),*]
    };
}

/// All embedded data files.
pub const ALL: &[Asset] = embed![
    "solar/solar_tsis1_hsrs_1nm.csv",
    "water/water_absorption_wasi6.csv",
    "water/water_absorption_wopp_v3.csv",
    "water/water_scattering_pure.csv",
    "water/sambuca_aw_350_900_lw2002.csv",
    "srf/srf_s3a_olci.csv",
    "srf/srf_s3b_olci.csv",
    "srf/srf_s2a_msi.csv",
    "srf/srf_s2b_msi.csv",
    "srf/olci_bands.csv",
    "phytoplankton/aph_specific_wasi6_classes.csv",
    "phytoplankton/aph_bricaud1998_coefficients.csv",
    "phytoplankton/bbph_norm_wasi6.csv",
    "phytoplankton/sambuca_WL08_aphy.csv",
    "phytoplankton/sambuca_aphy_star_ALL.csv",
    "phytoplankton/sambuca_SIOPMatrix.csv",
    "phytoplankton/sambuca_SIOP_aphy.csv",
    "benthic/benthic_reflectance.csv",
    "benthic/sambuca_HI_3.csv",
    "benthic/sambuca_NCC_3subs.csv",
    "benthic/sambuca_Moreton_Bay.csv",
    "benthic/sambuca_WL5_2008.csv",
    "atmosphere/aerosol_6sv_models.csv",
    "atmosphere/ozone_absorption_anderson.csv",
    "atmosphere/atmosphere_gas_absorption_wasi6.csv",
    "atmosphere/rayleigh_optical_depth_bodhaine1999.csv",
    "atmosphere/wmo_aerosol_mie.csv",
    "atmosphere/aerosol_6sv_components.csv",
    "atmosphere/gas_transmittance_6sv.csv",
];

macro_rules! embed_presets {
    ($($path:literal),* $(,)?) => {
        &[$(Asset { path: $path, text: include_str!(concat!("../presets/", $path)) }),*]
    };
}

/// Built-in presets (RON files under `presets/`), embedded so that names resolve anywhere.
pub const PRESETS: &[Asset] = embed_presets![
    "budgets/default.ron",
    "budgets/cubesat_class.ron",
    "siop/heron_island.ron",
    "siop/cyanobacteria_reservoir.ron",
    "siop/almi_1.ron",
    "siop/almi_2.ron",
    "siop/almi_3.ron",
    "siop/almi_4.ron",
    "siop/almi_5.ron",
    "siop/almi_6.ron",
    "siop/almi_7.ron",
    "siop/almi_8.ron",
    "scenes/lake_hume_bloom.ron",
    "scenes/lake_hume_dust.ron",
    "scenes/lake_hume_haze.ron",
    "scenes/lake_hume_smoke.ron",
    "scenes/lake_hume_clouds.ron",
    "scenes/clear_water.ron",
    "scenes/heron_island_reef.ron",
    "scenes/aquaculture_turbidity.ron",
    "scenes/reservoir_chl_cdom.ron",
    "scenes/paper_heron_island.ron",
    "scenes/paper_lake_hume.ron",
    "scenes/reef_survey_raster.ron",
    "instruments/nominal.ron",
    "instruments/cubesat.ron",
    "instruments/smallsat.ron",
    "instruments/hyperspectral.ron",
    "instruments/filter_imager.ron",
    "instruments/sentinel2a_msi.ron",
    "instruments/landsat8_oli.ron",
    "instruments/smallsat_swir.ron",
    "instruments/sentinel3a_olci.ron",
    "instruments/modis_aqua.ron",
    "studies/cubesat_vs_smallsat.ron",
    "studies/cubesat_design_lake_hume.ron",
    "studies/msi_vs_smallsat.ron",
    "studies/cubesat_vs_smallsat_image.ron",
    "studies/cubesat_vs_smallsat_dsf.ron",
    "studies/lake_hume_dust_image.ron",
    "studies/lake_hume_haze_dsf.ron",
    "studies/lake_hume_smoke_image.ron",
    "studies/lake_hume_clouds_image.ron",
    "studies/lake_hume_swir_image.ron",
    "studies/lake_hume_nominal.ron",
    "studies/lake_hume_oc4.ron",
    "studies/four_designs_lake_hume.ron",
    "studies/lake_hume_qaa.ron",
    "studies/heron_island_depth.ron",
    "studies/paper_heron_island.ron",
    "studies/paper_lake_hume.ron",
    "studies/reef_survey_depth.ron",
    "seasons/lake_hume_year.ron",
    "seasons/heron_island_year.ron",
    "sweeps/aperture_lake_hume.ron",
    "sweeps/nir_snr_sweep.ron",
    "sweeps/nir_snr_sweep_clear.ron",
];

/// Names of the built-in presets in `folder` (`"instruments"`, `"scenes"`, …), in embedding order.
#[must_use]
pub fn preset_names(folder: &str) -> Vec<String> {
    PRESETS
        .iter()
        .filter_map(|a| {
            a.path.strip_prefix(folder).and_then(|p| p.strip_prefix('/')).and_then(|p| p.strip_suffix(".ron"))
        })
        .map(str::to_string)
        .collect()
}

/// The built-in preset at `path` (relative to `presets/`), if there is one.
#[must_use]
pub fn preset(path: &str) -> Option<&'static Asset> {
    PRESETS.iter().find(|a| a.path == path)
}

/// The embedded file at `path` (relative to `assets/`), if there is one.
///
/// ```
/// assert!(shoal::assets::find("solar/solar_tsis1_hsrs_1nm.csv").is_some());
/// assert!(shoal::assets::find("no/such.csv").is_none());
/// ```
#[must_use]
pub fn find(path: &str) -> Option<&'static Asset> {
    let found = ALL.iter().find(|a| a.path == path);
    if let Some(a) = found
        && let Ok(mut used) = USED.lock()
        && !used.contains(&a.path)
    {
        used.push(a.path);
    }
    found
}

/// The data files [`find`] has handed out in this process, in first-use order: what a set of
/// results was made from, for the review pack's provenance.
static USED: std::sync::Mutex<Vec<&'static str>> = std::sync::Mutex::new(Vec::new());

/// The embedded data files read so far in this process.
#[must_use]
pub fn used() -> Vec<&'static str> {
    USED.lock().map(|u| u.clone()).unwrap_or_default()
}

/// `assets/PROVENANCE.md`, the index of the embedded data.
pub const PROVENANCE_MD: &str = include_str!("../assets/PROVENANCE.md");

/// The rows of the provenance index: (files, content, source, licence), markdown stripped of
/// backticks.
#[must_use]
pub fn provenance() -> Vec<(String, String, String, String)> {
    PROVENANCE_MD
        .lines()
        .filter(|l| l.starts_with("| `"))
        .filter_map(|l| {
            let cells: Vec<String> = l.trim_matches('|').split(" | ").map(|c| c.trim().replace('`', "")).collect();
            match cells.as_slice() {
                [files, content, source, licence] => {
                    Some((files.clone(), content.clone(), source.clone(), licence.clone()))
                }
                _ => None,
            }
        })
        .collect()
}

/// The paths of all embedded files, for error messages and `--list` output.
pub fn paths() -> impl Iterator<Item = &'static str> {
    ALL.iter().map(|a| a.path)
}

/// GeoTIFF rasters of the built-in scenes (under `presets/scenes/`), made by the project:
/// `tests/chain/rasters.rs` writes them and checks the shipped files are what it writes.
const RASTERS: &[(&str, &[u8])] = &[
    ("rasters/reef_survey_bathymetry.tif", include_bytes!("../presets/scenes/rasters/reef_survey_bathymetry.tif")),
    ("rasters/reef_survey_habitat.tif", include_bytes!("../presets/scenes/rasters/reef_survey_habitat.tif")),
];

/// The embedded raster a built-in scene names by `path` (relative to `presets/scenes/`), if any.
#[must_use]
pub fn raster(path: &str) -> Option<&'static [u8]> {
    RASTERS.iter().find(|(p, _)| *p == path).map(|(_, b)| *b)
}

/// DejaVu Sans (Bitstream Vera licence, assets/fonts), the one font of the figures and the
/// app's fallback for the glyphs egui's default font lacks (superscripts such as m⁻³, e⁻).
pub const DEJAVU_SANS_TTF: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
