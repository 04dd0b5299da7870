//! `shoal correct --toa FILE.csv`: the image-based atmospheric correction run on TOA radiance
//! spectra a user brings — one row per pixel with its geometry and band radiances — so that
//! Shoal's correction can be checked against another code's TOA radiance (6SV, OSOAA, a
//! sensor's Level-1). Each row is one "column" of the correction's family (its own geometry,
//! no across-track interpolation); dark-spectrum fitting treats the rows as one scene.
//!
//! Input columns: `sun_zenith_deg`, `view_zenith_deg`, `relative_azimuth_deg` (view minus sun
//! azimuth; 180: the sensor opposite the sun) and one column per band of `--instrument`, named as
//! its bands (`Oa01`, …), in W m⁻² sr⁻¹ µm⁻¹. The atmosphere (pressure, gases, day of year)
//! and the water the family's LUTs are built over come from `--scene`; its aerosol is not used.
//! Output: `rrs.csv` (per row: Rrs per band, sr⁻¹, empty where flagged; AOT(550) and Ångström
//! exponent found) in `--out`.

use std::path::PathBuf;

use ndarray::Array3;

use super::CliError;
use crate::atmosphere::{AerosolType, Geometry};
use crate::calibration::Level1;
use crate::correction::{AerosolFamily, FamilyLuts, ImageCorrection, RrsFlags, correct_image};
use crate::engine::Fidelity;
use crate::instrument::{Look, Response, Viewing};
use crate::scene::Scene;
use crate::spectral::Table;

/// Arguments of `shoal correct`.
#[derive(Debug, clap::Args)]
pub struct CorrectArgs {
    /// TOA radiance spectra, CSV: geometry columns and one column per band (W m⁻² sr⁻¹ µm⁻¹).
    #[arg(long)]
    toa: PathBuf,
    /// The instrument whose bands the spectra are: a built-in name or an instrument RON file.
    #[arg(long)]
    instrument: String,
    /// The scene whose atmosphere (pressure, gases, date) the correction's LUTs use.
    #[arg(long, default_value = "lake_hume_bloom")]
    scene: String,
    /// The correction: `pair` (779/865 nm band pair with the NIR iteration), `pair-black`
    /// (without it), `swir` (1610/2200 nm), `dark` (dark-spectrum fitting over all rows) — the
    /// app's image-based choices — or a RON `ImageCorrection`.
    #[arg(long, default_value = "pair")]
    correction: String,
    /// Output directory (rrs.csv).
    #[arg(long, default_value = "results/correct")]
    out: PathBuf,
}

/// Rows read at most. Each row is a column of the family's tables: 16 atmospheres × 3 terms ×
/// 8 bytes per band, 7.3 kB for 19 bands, so 10 000 rows hold 73 MB of tables (100 000 would
/// hold 730 MB: refused before any work).
const MAX_ROWS: usize = 10_000;

/// The correction `text` names: an image-based preset of [`crate::correction::PRESETS`] (the
/// app's menu offers the same), or a RON `ImageCorrection`. The exact and per-scene corrections
/// need the truth a spectrum file does not carry.
fn settings(text: &str) -> Result<ImageCorrection, CliError> {
    use crate::correction::{Method, PRESETS, Preset};
    let image_keys = || {
        PRESETS.iter().filter(|p| matches!((p.make)(), Method::Image(_))).map(|p| p.key).collect::<Vec<_>>().join(", ")
    };
    match Preset::of(text).map(|p| (p, (p.make)())) {
        Ok((_, Method::Image(image))) => Ok(image),
        Ok((p, _)) => Err(CliError::Input(format!(
            "--correction {}: the {} correction needs the simulation's own atmosphere; spectra are corrected \
             from their bands: one of {}",
            p.key,
            p.label,
            image_keys()
        ))),
        Err(_) => ron::from_str::<ImageCorrection>(text)
            .map_err(|e| CliError::Input(format!("--correction: {e} (or one of {})", image_keys()))),
    }
}

/// `shoal correct`.
pub fn run(args: &CorrectArgs) -> Result<(), CliError> {
    let image = settings(&args.correction)?;
    image.validate().map_err(|e| CliError::Input(e.to_string()))?;
    let instrument = super::simulate::INSTRUMENTS.resolve(&args.instrument)?.0;
    let (scene_spec, dir) = super::simulate::SCENES.resolve(&args.scene)?;
    let table = Table::from_file(&args.toa).map_err(|e| CliError::Input(format!("--toa: {e}")))?;
    let column = |name: &str| table.column_f64(name).map_err(|e| CliError::Input(format!("--toa: {e}")));
    let (sza, vza, raa) = (column("sun_zenith_deg")?, column("view_zenith_deg")?, column("relative_azimuth_deg")?);
    let rows = sza.len();
    if rows == 0 || rows > MAX_ROWS {
        return Err(CliError::Input(format!("--toa: {rows} rows (allowed: 1 to {MAX_ROWS})")));
    }
    // Dark-spectrum fitting fits a line to each band's darkest `pixels` of the whole set: with
    // fewer rows it would extrapolate below the darkest spectrum and read no aerosol.
    if image.fit == crate::correction::AerosolFit::DarkSpectrum && rows < image.dark.pixels {
        return Err(CliError::Input(format!(
            "--correction dark: {rows} spectra, but dark-spectrum fitting needs at least correction.image.dark.pixels = {} (an image's darkest pixels, not a handful of spectra); use pair or pair-black",
            image.dark.pixels
        )));
    }
    let fid = Fidelity::default();
    let response = Response::new(&instrument, fid.spectral_step_nm)?;
    let names: Vec<String> = response.bands.bands.iter().map(|b| b.name.clone()).collect();
    let nb = names.len();
    let mut radiance = Array3::<f32>::zeros((1, rows, nb));
    for (b, name) in names.iter().enumerate() {
        for (r, v) in column(name)?.into_iter().enumerate() {
            if !(v.is_finite() && v >= 0.0) {
                return Err(CliError::Input(format!("--toa: row {}, column {name}: {v} (allowed: ≥ 0)", r + 1)));
            }
            radiance[[0, r, b]] = (v / 1000.0) as f32; // µm⁻¹ → nm⁻¹
        }
    }
    let mut looks = Vec::with_capacity(rows);
    for r in 0..rows {
        let sun = &crate::ranges::GEOMETRY_SUN_ZENITH_DEG;
        let view = &crate::ranges::GEOMETRY_VIEW_ZENITH_DEG;
        let row = |e: String| CliError::Input(format!("--toa: row {}: {e}", r + 1));
        sun.check(sza[r]).map_err(|e| row(format!("sun_zenith_deg {e}")))?;
        view.check(vza[r]).map_err(|e| row(format!("view_zenith_deg {e}")))?;
        if !raa[r].is_finite() {
            return Err(row(format!("relative_azimuth_deg {}", raa[r])));
        }
        looks.push(Look {
            dx_m: 0.0,
            dy_m: 0.0,
            geometry: Geometry::from_degrees(sza[r], vza[r], raa[r]),
            view_azimuth_rad: raa[r].to_radians(),
        });
    }
    // The scene is built for its atmosphere and water: sized against the budget first, with the
    // family's radiative transfer and tables.
    super::within_budget(&crate::engine::resources::correct_demand(&scene_spec, &image, rows, nb))?;
    let out = crate::study::OutputDir::create(&args.out, "shoal correct")?;
    let control = super::interrupt::control();
    let groups = response.groups.len();
    let max_vza = vza.iter().copied().fold(0.0, f64::max);
    let viewing = Viewing {
        decimation: 1,
        line_index: vec![0],
        detector_index: vec![0; rows],
        track_m: vec![(0.0, 0.0)],
        looks: vec![looks; groups],
        gsd_m: 0.0,
        line_period_s: 0.0,
        ground_speed_m_s: 0.0,
        time_offset_s: vec![0.0; groups],
        max_view_zenith_deg: max_vza,
        cropped: (0, 0),
    };
    let sun_range = (sza.iter().copied().fold(f64::INFINITY, f64::min), sza.iter().copied().fold(0.0, f64::max));
    let mut axes = crate::engine::lut_axes_covering(&response, sun_range, max_vza, &fid);
    // A radiative-transfer solve per sun node: where the rows have fewer distinct sun zeniths
    // than the grid over their range has nodes, the family is built at exactly those (each row
    // then reads its own node, with no interpolation in the sun's angle).
    let mut suns = sza.clone();
    suns.sort_by(f64::total_cmp);
    suns.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    if suns.len() < axes.sun_zenith_deg.len() {
        axes.sun_zenith_deg = suns;
    }
    let scene = Scene::build(&scene_spec, dir.as_deref()).map_err(|e| CliError::Input(format!("--scene: {e}")))?;
    let mut atmosphere = scene_spec.atmosphere.clone();
    atmosphere.day_of_year = scene.day_of_year;
    (atmosphere.aerosol, atmosphere.aot550) = (AerosolType::None, 0.0);
    let fail = |e: crate::correction::CorrectionError| CliError::Input(e.to_string());
    let luts = FamilyLuts::build(&image, &atmosphere, &axes, &control).map_err(fail)?;
    let family = AerosolFamily::tabulate(&luts, &scene, &response, &viewing, None, &control).map_err(fail)?;
    let level1 = Level1 { radiance, flags: Array3::zeros((1, rows, nb)) };
    let water = crate::instrument::SurfaceMap::all_water((1, rows));
    let (rrs, aerosol) = correct_image(&level1, &family, &image, &response.bands, &water, &control).map_err(fail)?;
    let columns: Vec<String> = std::iter::once("row".to_string())
        .chain(names.iter().map(|n| format!("rrs_{n}_per_sr")))
        .chain(["aot550".to_string(), "angstrom".to_string()])
        .collect();
    let mut csv = crate::csvtext::Csv::new(&columns.iter().map(String::as_str).collect::<Vec<_>>());
    for r in 0..rows {
        let mut cells = vec![(r + 1).to_string()];
        for b in 0..nb {
            let valid = rrs.flags[[0, r, b]] & RrsFlags::INVALID == 0;
            cells.push(if valid { format!("{:.6e}", rrs.rrs[[0, r, b]]) } else { String::new() });
        }
        cells.push(format!("{:.4}", aerosol.aot550[[0, r]]));
        cells.push(format!("{:.3}", aerosol.angstrom[[0, r]]));
        csv.row(&cells);
    }
    crate::study::write_bytes(&out.path().join("rrs.csv"), csv.finish().as_bytes())?;
    out.commit()?;
    eprintln!("{rows} spectra corrected ({}) into {}", image.label(), args.out.display());
    Ok(())
}
