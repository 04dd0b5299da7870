//! `shoal atmosphere`: the atmosphere alone, as CSV per wavelength or band.
//!
//! Band values are SRF averages: E₀, L_path and Ed(0⁺) are averaged directly; the
//! dimensionless terms (T_up, T_down, S, T_gas) are E₀-weighted averages, ⟨E₀·T⟩/⟨E₀⟩, which is
//! what a band-integrating radiometer sees; ρ_path and T_down are recomputed from the band
//! averages.

use std::path::{Path, PathBuf};

use clap::Args;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::CliError;
use super::grid::{GridArgs, GridSpec};
use super::output::{Csv, emit};
use crate::atmosphere::{
    AerosolType, AtmosphereSpec, AtmosphereTerms, Geometry, RayleighDepth, RtAccuracy, SeaSurface,
};
use crate::spectral::{BandAverager, BandSetSpec};

/// A `shoal atmosphere` run as a RON file (`presets/examples/atmosphere_lake_hume.ron`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct AtmosphereRun {
    /// The atmosphere.
    pub atmosphere: AtmosphereSpec,
    /// Sun zenith angle, degrees (0–89).
    pub sun_zenith_deg: f64,
    /// View zenith angle, degrees (0–85).
    pub view_zenith_deg: f64,
    /// View azimuth minus sun azimuth, degrees (0: sensor on the sun's side; 180: glint side).
    pub relative_azimuth_deg: f64,
    /// Wavelengths (default 350–1000 nm every 5 nm).
    pub grid: Option<GridSpec>,
    /// Band-average the output.
    pub bands: Option<BandSetSpec>,
}

impl Default for AtmosphereRun {
    fn default() -> Self {
        Self {
            atmosphere: AtmosphereSpec::default(),
            sun_zenith_deg: 30.0,
            view_zenith_deg: 0.0,
            relative_azimuth_deg: 90.0,
            grid: None,
            bands: None,
        }
    }
}

/// Flags of `shoal atmosphere` (each overrides the spec file's value).
#[derive(Debug, Args)]
pub struct AtmosphereArgs {
    /// A RON run file (see presets/examples/); flags below override its values.
    #[arg(long, value_name = "FILE")]
    pub spec: Option<PathBuf>,
    /// Aerosol model: none, maritime, continental, urban (WCP-55 components), maritime-6sv,
    /// continental-6sv, urban-6sv (6SV's components), mixture:DL,WS,OC,SO or lognormal:R,SG,N,K.
    #[arg(long, value_name = "MODEL")]
    pub aerosol: Option<String>,
    /// Aerosol optical thickness at 550 nm (0 to 5).
    #[arg(long, value_name = "AOT", allow_negative_numbers = true)]
    pub aot550: Option<f64>,
    /// Sea surface: flat, or wind:SPEED (m/s, 0 to 30) to add Cox-Munk sun glint.
    #[arg(long, value_name = "flat|wind:SPEED")]
    pub surface: Option<String>,
    /// Gas absorption (ozone, oxygen, water vapour): on or off.
    #[arg(long, value_name = "on|off")]
    pub gases: Option<String>,
    /// Total ozone, atm-cm (0 to 1; 0.3 = 300 DU).
    #[arg(long, value_name = "ATM_CM", allow_negative_numbers = true)]
    pub ozone: Option<f64>,
    /// Precipitable water, cm (0 to 10).
    #[arg(long, value_name = "CM", allow_negative_numbers = true)]
    pub water_vapour: Option<f64>,
    /// Surface pressure, hPa (500 to 1100).
    #[arg(long, value_name = "HPA", allow_negative_numbers = true)]
    pub pressure: Option<f64>,
    /// Sun zenith angle, degrees (0 to 89).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub sun_zenith: Option<f64>,
    /// View zenith angle, degrees (0 to 85).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub view_zenith: Option<f64>,
    /// View azimuth minus sun azimuth, degrees (0: sensor on the sun's side; 180: glint side).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub rel_azimuth: Option<f64>,
    /// Date YYYY-MM-DD (Sun-Earth distance).
    #[arg(long, value_name = "DATE")]
    pub date: Option<String>,
    /// Rayleigh optical depth: bodhaine (default) or osoaa (for comparisons with OSOAA).
    #[arg(long, value_name = "FORMULA")]
    pub rayleigh: Option<String>,
    /// Accuracy preset: single, fast, default or high.
    #[arg(long, value_name = "PRESET")]
    pub accuracy: Option<String>,
    #[command(flatten)]
    pub grid: GridArgs,
    /// Write the CSV to this file (atomically) instead of standard output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}

/// Day of year of `YYYY-MM-DD`.
fn day_of_year(date: &str) -> Result<u32, CliError> {
    let bad = || CliError::Input(format!("--date: expected YYYY-MM-DD, got `{date}`"));
    let parts: Vec<&str> = date.trim().split('-').collect();
    let [y, m, d] = parts.as_slice() else {
        return Err(bad());
    };
    let (y, m, d): (u32, u32, u32) =
        (y.parse().map_err(|_| bad())?, m.parse().map_err(|_| bad())?, d.parse().map_err(|_| bad())?);
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    let days = [31, if leap { 29 } else { 28 }, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
    if !(1..=12).contains(&m) || d == 0 || d > days[(m - 1) as usize] {
        return Err(CliError::Input(format!("--date: `{date}` is not a calendar date")));
    }
    Ok(days[..(m - 1) as usize].iter().sum::<u32>() + d)
}

fn merged(args: &AtmosphereArgs) -> Result<AtmosphereRun, CliError> {
    let mut run = match &args.spec {
        Some(p) => read_spec(p)?,
        None => AtmosphereRun::default(),
    };
    let a = &mut run.atmosphere;
    if let Some(s) = &args.aerosol {
        a.aerosol = AerosolType::parse(s).map_err(CliError::Input)?;
    }
    a.aot550 = args.aot550.unwrap_or(a.aot550);
    if let Some(s) = &args.surface {
        a.surface = SeaSurface::parse(s)?;
    }
    if let Some(g) = &args.gases {
        a.gases = match g.as_str() {
            "on" => true,
            "off" => false,
            other => {
                return Err(CliError::Input(format!("--gases: `{other}` (allowed: on, off)")));
            }
        };
    }
    a.gas_amounts.ozone_atm_cm = args.ozone.unwrap_or(a.gas_amounts.ozone_atm_cm);
    a.gas_amounts.water_vapour_cm = args.water_vapour.unwrap_or(a.gas_amounts.water_vapour_cm);
    a.pressure_hpa = args.pressure.unwrap_or(a.pressure_hpa);
    if let Some(d) = &args.date {
        a.day_of_year = day_of_year(d)?;
    }
    if let Some(r) = &args.rayleigh {
        a.rayleigh = match r.as_str() {
            "bodhaine" => RayleighDepth::Bodhaine,
            "osoaa" => RayleighDepth::OsoaaHansenTravis,
            other => {
                return Err(CliError::Input(format!("--rayleigh: `{other}` (allowed: bodhaine, osoaa)")));
            }
        };
    }
    if let Some(p) = &args.accuracy {
        a.accuracy = RtAccuracy::preset(p)
            .ok_or_else(|| CliError::Input(format!("--accuracy: `{p}` (allowed: single, fast, default, high)")))?;
    }
    run.sun_zenith_deg = args.sun_zenith.unwrap_or(run.sun_zenith_deg);
    run.view_zenith_deg = args.view_zenith.unwrap_or(run.view_zenith_deg);
    run.relative_azimuth_deg = args.rel_azimuth.unwrap_or(run.relative_azimuth_deg);
    Ok(run)
}

fn read_spec(path: &Path) -> Result<AtmosphereRun, CliError> {
    let text = crate::infile::read_text(path, crate::infile::RON_MAX_BYTES)
        .map_err(|e| CliError::Input(format!("cannot read {e}")))?;
    ron::from_str(&text).map_err(|e| CliError::Input(format!("{}: {e}", path.display())))
}

const COLUMNS: [&str; 13] = [
    "e0_w_m2_nm",
    "l_path_w_m2_sr_nm",
    "rho_path",
    "t_up",
    "t_up_direct",
    "t_down",
    "t_down_direct",
    "spherical_albedo",
    "ed_0plus_w_m2_nm",
    "tau_rayleigh",
    "tau_aerosol",
    "t_gas",
    "l_glint_w_m2_sr_nm",
];

fn values(t: &AtmosphereTerms) -> [f64; 13] {
    [
        t.e0_w_m2_nm,
        t.l_path_w_m2_sr_nm,
        t.rho_path,
        t.t_up,
        t.t_up_direct,
        t.t_down,
        t.t_down_direct,
        t.spherical_albedo,
        t.ed_0plus_w_m2_nm,
        t.tau_rayleigh,
        t.tau_aerosol,
        t.t_gas,
        t.l_glint_w_m2_sr_nm,
    ]
}

/// Run `shoal atmosphere`.
pub fn run(args: &AtmosphereArgs) -> Result<(), CliError> {
    let run = merged(args)?;
    let g = Geometry::from_degrees(run.sun_zenith_deg, run.view_zenith_deg, run.relative_azimuth_deg);
    g.validate()?;
    let band_mode = args.grid.bands.is_some() || run.bands.is_some();
    let (grid, bands) = args.grid.resolve(run.grid.as_ref(), if band_mode { 1.0 } else { 5.0 })?;
    let bands = match (bands, &run.bands) {
        (Some(b), _) => Some(b),
        (None, Some(spec)) => Some(crate::spectral::BandSet::from_spec(spec)?),
        (None, None) => None,
    };
    let averager = bands.as_ref().map(|b| BandAverager::new(&grid, b)).transpose()?;
    // In band mode only the wavelengths some band responds to are solved.
    let needed: Vec<bool> = match &averager {
        None => vec![true; grid.len()],
        Some(a) => {
            let dense = a.to_dense();
            (0..grid.len()).map(|i| dense.column(i).iter().any(|w| *w != 0.0)).collect()
        }
    };
    let solves = needed.iter().filter(|n| **n).count();
    // Ranges first (their message names the field), then the work they add up to.
    run.atmosphere.validate()?;
    super::within_budget(&crate::engine::resources::atmosphere_command_demand(&run.atmosphere, solves))?;
    let atm = run.atmosphere.build()?;
    let wl = grid.wavelengths_nm();
    let terms: Vec<Option<AtmosphereTerms>> = (0..grid.len())
        .into_par_iter()
        .map(|i| if needed[i] { atm.terms(wl[i], &g).map(Some) } else { Ok(None) })
        .collect::<Result<_, _>>()?;
    let mut csv;
    match (&bands, &averager) {
        (Some(bands), Some(avg)) => {
            csv = Csv::new(["band", "centre_nm"].iter().chain(COLUMNS.iter()).map(|s| (*s).to_string()).collect());
            let col = |f: &dyn Fn(&AtmosphereTerms) -> f64| -> Vec<f64> {
                terms.iter().map(|t| t.as_ref().map_or(0.0, f)).collect()
            };
            let e0 = avg.apply(&col(&|t| t.e0_w_m2_nm));
            let weighted = |f: &dyn Fn(&AtmosphereTerms) -> f64| -> Vec<f64> {
                avg.apply(&col(&|t| t.e0_w_m2_nm * f(t))).iter().zip(&e0).map(|(a, b)| a / b).collect()
            };
            let (l_path, ed, glint) = (
                avg.apply(&col(&|t| t.l_path_w_m2_sr_nm)),
                avg.apply(&col(&|t| t.ed_0plus_w_m2_nm)),
                avg.apply(&col(&|t| t.l_glint_w_m2_sr_nm)),
            );
            let (t_up, t_up_dir, s, t_gas) = (
                weighted(&|t| t.t_up),
                weighted(&|t| t.t_up_direct),
                weighted(&|t| t.spherical_albedo),
                weighted(&|t| t.t_gas),
            );
            let t_down_dir = weighted(&|t| t.t_down_direct);
            let (tau_r, tau_a) = (avg.apply(&col(&|t| t.tau_rayleigh)), avg.apply(&col(&|t| t.tau_aerosol)));
            let mu0 = g.sun_zenith_rad.cos();
            for (b, band) in bands.bands.iter().enumerate() {
                let rho = std::f64::consts::PI * l_path[b] / (e0[b] * mu0);
                let t_down = ed[b] / (e0[b] * mu0);
                let row = [
                    band.centre_nm,
                    e0[b],
                    l_path[b],
                    rho,
                    t_up[b],
                    t_up_dir[b],
                    t_down,
                    t_down_dir[b],
                    s[b],
                    ed[b],
                    tau_r[b],
                    tau_a[b],
                    t_gas[b],
                    glint[b],
                ];
                csv.row(Some(&band.name), &row)?;
            }
        }
        _ => {
            csv = Csv::new(std::iter::once("wavelength_nm").chain(COLUMNS).map(str::to_string).collect());
            for t in terms.iter().flatten() {
                let mut row = vec![t.wavelength_nm];
                row.extend(values(t));
                csv.row(None, &row)?;
            }
        }
    }
    emit(&csv.render(), args.out.as_deref())
}

#[cfg(test)]
mod tests {
    use super::day_of_year;

    #[test]
    fn dates_map_to_days() {
        assert_eq!(day_of_year("2023-06-21").unwrap(), 172);
        assert_eq!(day_of_year("2024-12-31").unwrap(), 366);
        assert!(day_of_year("2023-02-30").is_err());
        assert!(day_of_year("21 June").is_err());
    }
}
