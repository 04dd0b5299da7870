//! `shoal water`: the water model alone, as CSV — an engineer's check of a spectrum before a
//! scene is built.

use std::path::{Path, PathBuf};

use clap::Args;
use serde::{Deserialize, Serialize};

use super::CliError;
use super::grid::{GridArgs, GridSpec};
use super::output::{Csv, emit};
use crate::spectral::{BandAverager, BandSetSpec};
use crate::water::{
    Bottom, SiopSource, SiopSpec, SubstrateLibrary, SubstrateMix, WaterColumn, WaterGeometry, WaterModel,
};

/// A `shoal water` run as a RON file (`presets/examples/water_heron_sand.ron`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct WaterRun {
    /// SIOP set.
    pub siop: SiopSource,
    /// Chlorophyll-a, mg m⁻³.
    pub chl_mg_m3: f64,
    /// CDOM absorption at the SIOP set's reference wavelength (440 nm for the presets), m⁻¹.
    pub cdom_per_m: f64,
    /// Non-algal particles, g m⁻³.
    pub nap_g_m3: f64,
    /// Depth in m; `None` is optically deep.
    pub depth_m: Option<f64>,
    /// Substrate mixture, e.g. `"sand:0.5,coral:0.5"`.
    pub substrate: String,
    /// A CSV of extra substrate spectra (`wavelength_nm` plus one column per substrate).
    pub substrate_csv: Option<PathBuf>,
    /// Sun zenith angle in air, degrees.
    pub sun_zenith_deg: f64,
    /// View zenith angle in air, degrees.
    pub view_zenith_deg: f64,
    /// Wavelengths (default 350–1000 nm at 1 nm).
    pub grid: Option<GridSpec>,
    /// Band-average the output.
    pub bands: Option<BandSetSpec>,
}

impl Default for WaterRun {
    fn default() -> Self {
        Self {
            siop: SiopSource::Preset("heron_island".into()),
            chl_mg_m3: 1.0,
            cdom_per_m: 0.05,
            nap_g_m3: 1.0,
            depth_m: None,
            substrate: "sand".into(),
            substrate_csv: None,
            sun_zenith_deg: 30.0,
            view_zenith_deg: 0.0,
            grid: None,
            bands: None,
        }
    }
}

/// Flags of `shoal water` (each overrides the spec file's value).
#[derive(Debug, Args)]
pub struct WaterArgs {
    /// A RON run file (see presets/examples/); flags below override its values.
    #[arg(long, value_name = "FILE")]
    pub spec: Option<PathBuf>,
    /// SIOP set: a built-in name, a .ron file or a .csv file of SIOP columns.
    #[arg(long, value_name = "NAME|FILE")]
    pub siop: Option<String>,
    /// Chlorophyll-a, mg m-3 (0 to 10000).
    #[arg(long, value_name = "MG_M3", allow_negative_numbers = true)]
    pub chl: Option<f64>,
    /// CDOM absorption at the SIOP reference wavelength (440 nm for the presets), m-1.
    #[arg(long, value_name = "PER_M", allow_negative_numbers = true)]
    pub cdom: Option<f64>,
    /// Non-algal particles, g m-3 (0 to 10000).
    #[arg(long, value_name = "G_M3", allow_negative_numbers = true)]
    pub nap: Option<f64>,
    /// Depth in m (above 0), or `deep`.
    #[arg(long, value_name = "M|deep", allow_negative_numbers = true)]
    pub depth: Option<String>,
    /// Substrate mixture, e.g. sand:0.5,coral:0.5 (names: see --list-substrates).
    #[arg(long, value_name = "MIX")]
    pub substrate: Option<String>,
    /// A CSV of extra substrate spectra (wavelength_nm plus one column per substrate).
    #[arg(long, value_name = "FILE")]
    pub substrate_csv: Option<PathBuf>,
    /// Sun zenith angle in air, degrees (0 to below 90).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub sun_zenith: Option<f64>,
    /// View zenith angle in air, degrees (0 to below 90).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub view_zenith: Option<f64>,
    /// Accepted for symmetry with `shoal atmosphere` (degrees, checked to lie within ±360); the
    /// Lee et al. model has no azimuthal dependence, so it does not change the output.
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub rel_azimuth: Option<f64>,
    #[command(flatten)]
    pub grid: GridArgs,
    /// Write the CSV to this file (atomically) instead of standard output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// List the substrate and SIOP names and exit.
    #[arg(long)]
    pub list_substrates: bool,
}

/// Read a run file; its relative paths are taken relative to the file's own directory.
fn read_spec(path: &Path) -> Result<(WaterRun, Option<PathBuf>), CliError> {
    let text = crate::infile::read_text(path, crate::infile::RON_MAX_BYTES)
        .map_err(|e| CliError::Input(format!("cannot read {e}")))?;
    let mut run: WaterRun = ron::from_str(&text).map_err(|e| CliError::Input(format!("{}: {e}", path.display())))?;
    let dir = path.parent().map(Path::to_path_buf);
    let near = |p: &PathBuf| dir.as_ref().filter(|_| p.is_relative()).map_or_else(|| p.clone(), |d| d.join(p));
    run.siop = run.siop.relative_to(dir.as_deref());
    run.substrate_csv = run.substrate_csv.as_ref().map(near);
    Ok((run, dir))
}

/// Merge the flags over the spec file. Paths given as flags are relative to the working
/// directory; paths in the spec file were made relative to the spec file when it was read.
fn merged(args: &WaterArgs) -> Result<(WaterRun, Option<PathBuf>), CliError> {
    let (mut run, spec_dir) = match &args.spec {
        Some(p) => read_spec(p)?,
        None => (WaterRun::default(), None),
    };
    if let Some(s) = &args.siop {
        run.siop = if s.ends_with(".ron") {
            SiopSource::File(s.into())
        } else if s.ends_with(".csv") {
            SiopSource::Csv(s.into())
        } else {
            SiopSource::Preset(s.clone())
        };
    }
    run.chl_mg_m3 = args.chl.unwrap_or(run.chl_mg_m3);
    run.cdom_per_m = args.cdom.unwrap_or(run.cdom_per_m);
    run.nap_g_m3 = args.nap.unwrap_or(run.nap_g_m3);
    if let Some(d) = &args.depth {
        run.depth_m = if d.eq_ignore_ascii_case("deep") {
            None
        } else {
            Some(
                d.parse::<f64>()
                    .map_err(|_| CliError::Input(format!("--depth: `{d}` is not a number of metres or `deep`")))?,
            )
        };
    }
    if let Some(s) = &args.substrate {
        run.substrate.clone_from(s);
    }
    if args.substrate_csv.is_some() {
        run.substrate_csv.clone_from(&args.substrate_csv);
    }
    run.sun_zenith_deg = args.sun_zenith.unwrap_or(run.sun_zenith_deg);
    run.view_zenith_deg = args.view_zenith.unwrap_or(run.view_zenith_deg);
    Ok((run, spec_dir))
}

/// Run `shoal water`.
pub fn run(args: &WaterArgs) -> Result<(), CliError> {
    let mut library = SubstrateLibrary::embedded()?;
    if args.list_substrates {
        let mut csv = crate::csvtext::Csv::new(&["substrate", "description"]);
        for e in library.entries() {
            csv.row([&e.name, &e.description]);
        }
        let mut text = csv.finish();
        text.push_str(&format!("# SIOP sets: {}\n", SiopSpec::preset_names().join(", ")));
        return emit(&text, args.out.as_deref());
    }
    let (run, spec_dir) = merged(args)?;
    if let Some(a) = args.rel_azimuth.filter(|a| !(a.is_finite() && a.abs() <= 360.0)) {
        return Err(CliError::Input(format!("--rel-azimuth = {a} is out of range (allowed: -360 to 360 degrees)")));
    }
    let (grid, bands) = args.grid.resolve(run.grid.as_ref(), 1.0)?;
    let bands = match (bands, &run.bands) {
        (Some(b), _) => Some(b),
        (None, Some(spec)) => Some(crate::spectral::BandSet::from_spec(spec)?),
        (None, None) => None,
    };
    let (siop_spec, siop_dir) = run.siop.load(spec_dir.as_deref())?;
    let siop = siop_spec.resolve(&grid, siop_dir.as_deref())?;
    if let Some(csv) = &run.substrate_csv {
        library.add_csv(csv)?;
    }
    let reflectance;
    let bottom = match run.depth_m {
        None => Bottom::OpticallyDeep,
        Some(depth_m) => {
            reflectance = library.mix_on_grid(&SubstrateMix::parse(&run.substrate)?, &grid)?;
            Bottom::Shallow { depth_m, reflectance: &reflectance }
        }
    };
    let column = WaterColumn { chl_mg_m3: run.chl_mg_m3, cdom_per_m: run.cdom_per_m, nap_g_m3: run.nap_g_m3, bottom };
    let geometry = WaterGeometry::from_degrees(run.sun_zenith_deg, run.view_zenith_deg);
    let model = WaterModel::new(siop);
    let r = model.evaluate(&column, &geometry)?;
    let columns = r.columns();
    let names: Vec<String> = columns.iter().map(|(n, _)| (*n).to_string()).collect();
    let csv = match bands {
        None => {
            let mut csv = Csv::new(std::iter::once("wavelength_nm".to_string()).chain(names).collect());
            for (i, w) in grid.wavelengths_nm().iter().enumerate() {
                let mut row = vec![*w];
                row.extend(columns.iter().map(|(_, v)| v[i]));
                csv.row(None, &row)?;
            }
            csv
        }
        Some(bands) => {
            let avg = BandAverager::new(&grid, &bands)?;
            let averaged: Vec<Vec<f64>> = columns.iter().map(|(_, v)| avg.apply(v)).collect();
            let mut csv = Csv::new(["band".to_string(), "centre_nm".to_string()].into_iter().chain(names).collect());
            for (b, band) in bands.bands.iter().enumerate() {
                let mut row = vec![band.centre_nm];
                row.extend(averaged.iter().map(|v| v[b]));
                csv.row(Some(&band.name), &row)?;
            }
            csv
        }
    };
    emit(&csv.render(), args.out.as_deref())
}
