//! A run's products as one self-describing NetCDF file (`--format netcdf`), the form water-quality
//! scientists read with xarray: dimensions (line, pixel, band), the bands' centres and widths as
//! coordinates, Level-1 radiance, Rrs and its flags, the truth, every retrieval's products and
//! flags, the ground position of every pixel, and the run's configuration as attributes,
//! following the CF conventions (CF-1.8) with CF standard names where CF has them.
//!
//! The file is NetCDF-3 in its 64-bit-offset form (any NetCDF reader opens it; a variable may
//! exceed 2 GiB), written by the pure-Rust `netcdf3` crate so that no C library is needed. Values
//! without a meaning (land, not returned, invalid Rrs) are [`FILL`], declared as `_FillValue`. Row 0
//! is the first line acquired, column 0 the first detector, as in every Shoal product.
//!
//! ## References
//! - Eaton, B. et al. (2020) NetCDF Climate and Forecast (CF) Metadata Conventions, version 1.8.
//! - CF Standard Name Table (chlorophyll, suspended matter, remote-sensing reflectance, depth).
//! - Unidata, The NetCDF Classic and 64-bit Offset File Formats (NetCDF-3).

use std::path::Path;

use netcdf3::DataSet;

use super::StudyError;
use super::output::Outputs;
use crate::correction::RrsFlags;
use crate::engine::{Cubes, RunOutput};
use crate::netcdf::{
    CUBE, FlagVar, FloatVar, InMemory, MAP, TextVar, Values, attrs, define_vars, in_memory, masked, meaning,
    standard_name, write_file,
};
use crate::retrieval::ProductFlags;

/// The file a run's NetCDF product is written to.
pub const FILE: &str = "products.nc";

pub use crate::netcdf::FILL;

/// Auxiliary coordinates of a (line, pixel) map: every pixel's ground position.
const MAP_COORDINATES: &str = "y x";
/// Auxiliary coordinates of a (line, pixel, band) cube: the ground position and the bands.
const CUBE_COORDINATES: &str = "y x wavelength bandwidth band_name";

/// Write `out`'s products into `dir/products.nc` (atomically: a temporary file, synced, then
/// renamed).
pub fn write_netcdf(out: &RunOutput, dir: &Path, o: &mut Outputs) -> Result<(), StudyError> {
    let path = dir.join(FILE);
    with_products(out, true, |data_set, parts| write_file(&path, data_set, parts, true).map_err(StudyError::Io))??;
    o.files.push(FILE.to_string());
    Ok(())
}

/// `out`'s products as [`write_netcdf`] writes them, held in memory (the Python package's
/// datasets: the same variables, attributes and values as the file). Without `cubes`, the file
/// less its four (line, pixel, band) variables (Level-1, Rrs, its flags, the true Rrs): what a
/// run of an engine that keeps no cubes ([`crate::engine::Engine::lean`]) can give.
pub fn products_in_memory(out: &RunOutput, cubes: bool) -> Result<InMemory, StudyError> {
    with_products(out, cubes, in_memory)
}

/// The file's variables and data set, handed to `use_them`: one description for the file and the
/// data set in memory.
fn with_products<R>(
    out: &RunOutput,
    with_cubes: bool,
    use_them: impl FnOnce(&DataSet, (&[FloatVar<'_>], &[FlagVar<'_>], &[TextVar])) -> R,
) -> Result<R, StudyError> {
    let cubes = if with_cubes { Some(super::output::kept_cubes(out)?) } else { None };
    let (rows, cols, nb) = cubes.map_or(out.report.shape, |c| c.level1.radiance.dim());
    let mut floats: Vec<FloatVar> = Vec::new();
    let mut flags: Vec<FlagVar> = Vec::new();
    coordinate_vars(out, &mut floats);
    if let Some(c) = cubes {
        radiometry_vars(c, &mut floats, &mut flags);
    }
    truth_vars(out, cubes, &mut floats, &mut flags);
    retrieval_vars(out, &mut floats, &mut flags);
    let (data_set, names) = define(out, (rows, cols, nb), &floats, &flags)?;
    Ok(use_them(&data_set, (&floats, &flags, &[names])))
}

/// The bands, and every pixel's ground position.
fn coordinate_vars<'a>(out: &'a RunOutput, floats: &mut Vec<FloatVar<'a>>) {
    let (rows, cols, _) = out.report.shape;
    let bands = &out.response.bands.bands;
    floats.push(FloatVar {
        name: "wavelength".into(),
        dims: vec!["band"],
        attrs: attrs("band centre wavelength", "nm", Some("radiation_wavelength")),
        values: Values::ready(bands.iter().map(|b| b.centre_nm as f32).collect()),
    });
    floats.push(FloatVar {
        name: "bandwidth".into(),
        dims: vec!["band"],
        attrs: attrs("band full width at half maximum", "nm", None),
        values: Values::ready(bands.iter().map(|b| b.fwhm_nm as f32).collect()),
    });
    let projected = out.scene.frame.as_ref().filter(|f| matches!(f.crs, crate::geotiff::Crs::Projected { .. }));
    let (x0, y0) = projected.map_or((0.0, 0.0), |f| f.centre);
    let ground: Vec<(f64, f64)> =
        (0..rows).flat_map(|r| (0..cols).map(move |c| (r, c))).map(|(r, c)| out.viewing.ground_m(0, r, c)).collect();
    let (x_long, y_long, x_std, y_std) = match projected {
        Some(_) => (
            "easting of the pixel centre",
            "northing of the pixel centre",
            "projection_x_coordinate",
            "projection_y_coordinate",
        ),
        None => (
            "metres east of the scene centre (the scene's local frame)",
            "metres north of the scene centre (the scene's local frame)",
            "",
            "",
        ),
    };
    let std_or_none = |s: &'static str| (!s.is_empty()).then_some(s);
    floats.push(FloatVar {
        name: "x".into(),
        dims: MAP.to_vec(),
        attrs: attrs(x_long, "m", std_or_none(x_std)),
        values: Values::ready(ground.iter().map(|g| (x0 + g.0) as f32).collect()),
    });
    floats.push(FloatVar {
        name: "y".into(),
        dims: MAP.to_vec(),
        attrs: attrs(y_long, "m", std_or_none(y_std)),
        values: Values::ready(ground.iter().map(|g| (y0 + g.1) as f32).collect()),
    });
}

/// Level-1 and Rrs with its flags.
fn radiometry_vars<'a>(cubes: &'a Cubes, floats: &mut Vec<FloatVar<'a>>, flags: &mut Vec<FlagVar<'a>>) {
    let cube_coordinates = ("coordinates", CUBE_COORDINATES.to_string());
    let mut l1 = attrs("top-of-atmosphere radiance (Level-1, calibrated)", "W m-2 sr-1 nm-1", None);
    l1.push(cube_coordinates.clone());
    floats.push(FloatVar {
        name: "level1_radiance".into(),
        dims: CUBE.to_vec(),
        attrs: l1,
        values: Values::lazy(move || masked(cubes.level1.radiance.iter().copied(), |_| true)),
    });
    let rrs = &cubes.rrs;
    let rrs_flags = rrs.flags.as_slice().unwrap_or_default();
    let mut a = attrs("remote-sensing reflectance above the surface, corrected", "sr-1", standard_name("rrs"));
    a.push(cube_coordinates.clone());
    floats.push(FloatVar {
        name: "rrs".into(),
        dims: CUBE.to_vec(),
        attrs: a,
        values: Values::lazy(move || {
            masked(rrs.rrs.iter().copied(), |i| rrs_flags.get(i).is_some_and(|f| f & RrsFlags::INVALID == 0))
        }),
    });
    flags.push(FlagVar {
        name: "rrs_flags".into(),
        dims: CUBE.to_vec(),
        long_name: "Rrs quality flags".into(),
        flags: vec![
            (i32::from(RrsFlags::NEGATIVE), "negative"),
            (i32::from(RrsFlags::SATURATED), "saturated"),
            (i32::from(RrsFlags::INVALID), "invalid"),
            (i32::from(RrsFlags::CLOUD), "cloud"),
            (i32::from(RrsFlags::GLINT), "high_glint"),
        ],
        values: Values::lazy(move || rrs_flags.iter().map(|&f| i32::from(f)).collect()),
        coordinates: CUBE_COORDINATES,
    });
}

/// The truth, and the aerosol an image-based correction found.
fn truth_vars<'a>(
    out: &'a RunOutput,
    cubes: Option<&'a Cubes>,
    floats: &mut Vec<FloatVar<'a>>,
    flags: &mut Vec<FlagVar<'a>>,
) {
    let truth = &out.truth;
    let water = |i: usize| truth.surface.is_water_at(i);
    let coordinates = ("coordinates", MAP_COORDINATES.to_string());
    if let Some(cubes) = cubes {
        let true_rrs = &*cubes.radiance.truth_rrs;
        let nb = cubes.level1.radiance.dim().2;
        let mut a =
            attrs("true remote-sensing reflectance above the surface (band-weighted)", "sr-1", standard_name("rrs"));
        a.push(("coordinates", CUBE_COORDINATES.to_string()));
        let nbw = nb.max(1);
        floats.push(FloatVar {
            name: "true_rrs".into(),
            dims: CUBE.to_vec(),
            attrs: a,
            values: Values::lazy(move || masked(true_rrs.iter().copied(), |i| water(i / nbw))),
        });
    }
    let mut truth_maps: Vec<(&str, &ndarray::Array2<f32>)> =
        vec![("chl_mg_m3", &truth.chl_mg_m3), ("nap_g_m3", &truth.nap_g_m3), ("cdom_per_m", &truth.cdom_per_m)];
    if let Some(d) = &truth.depth_m {
        truth_maps.push(("depth_m", d));
    }
    for (variable, values) in truth_maps {
        let (long, units) = meaning(variable);
        let mut a = attrs(&format!("true {long}"), units, standard_name(variable));
        a.push(coordinates.clone());
        floats.push(FloatVar {
            name: format!("true_{variable}"),
            dims: MAP.to_vec(),
            attrs: a,
            values: Values::lazy(move || masked(values.iter().copied(), water)),
        });
    }
    if let Some(aot) = &truth.aot550 {
        let mut a = attrs(
            "true aerosol optical thickness at 550 nm",
            "1",
            Some("atmosphere_optical_thickness_due_to_ambient_aerosol_particles"),
        );
        a.push(coordinates.clone());
        floats.push(FloatVar {
            name: "true_aot550".into(),
            dims: MAP.to_vec(),
            attrs: a,
            values: Values::ready(aot.iter().copied().collect()),
        });
    }
    flags.push(FlagVar {
        name: "surface_class".into(),
        dims: MAP.to_vec(),
        long_name: "what covers the pixel centre".into(),
        flags: crate::instrument::SurfaceClass::flags(),
        values: Values::ready(truth.surface.codes().iter().map(|&v| i32::from(v)).collect()),
        coordinates: MAP_COORDINATES,
    });

    if let Some(a) = &out.correction.aerosol {
        let mut at = attrs("aerosol optical thickness at 550 nm found by the correction", "1", None);
        at.push(coordinates.clone());
        floats.push(FloatVar {
            name: "retrieved_aot550".into(),
            dims: MAP.to_vec(),
            attrs: at,
            values: Values::ready(masked(a.aot550.iter().copied(), |_| true)),
        });
    }
}

/// Every retrieval's products and flags.
fn retrieval_vars<'a>(out: &'a RunOutput, floats: &mut Vec<FloatVar<'a>>, flags: &mut Vec<FlagVar<'a>>) {
    let coordinates = ("coordinates", MAP_COORDINATES.to_string());
    for ret in &out.retrievals {
        let p = &ret.product;
        let stem = ret.spec.name();
        let pf = p.flags.as_slice().unwrap_or_default();
        let returned = |i: usize| pf.get(i).is_some_and(|f| f & ProductFlags::RETURNED != 0);
        for (variable, values) in p.maps() {
            let (long, units) = meaning(variable);
            let mut a = attrs(&format!("{long} retrieved by {}", p.name), units, standard_name(variable));
            a.push(coordinates.clone());
            a.push(("ancillary_variables", format!("{stem}_flags")));
            floats.push(FloatVar {
                name: format!("{stem}_{variable}"),
                dims: MAP.to_vec(),
                attrs: a,
                values: Values::lazy(move || masked(values.iter().copied(), returned)),
            });
        }
        flags.push(FlagVar {
            name: format!("{stem}_flags"),
            dims: MAP.to_vec(),
            long_name: format!("{} retrieval flags", p.name),
            flags: vec![
                (i32::from(ProductFlags::RETURNED), "returned"),
                (i32::from(ProductFlags::PHYSICAL), "physical"),
                (i32::from(ProductFlags::AT_BOUND), "at_bound"),
                (i32::from(ProductFlags::CONVERGED), "converged"),
                (i32::from(ProductFlags::BOTTOM_VISIBLE), "bottom_visible"),
                (i32::from(ProductFlags::FAILED), "failed"),
                (i32::from(ProductFlags::LAND), "land"),
                (i32::from(ProductFlags::STALLED), "stalled"),
            ],
            values: Values::lazy(move || pf.iter().map(|&f| i32::from(f)).collect()),
            coordinates: MAP_COORDINATES,
        });
    }
}

/// The data set's dimensions, variables and attributes.
fn define(
    out: &RunOutput,
    (rows, cols, nb): (usize, usize, usize),
    floats: &[FloatVar],
    flags: &[FlagVar],
) -> Result<(DataSet, crate::netcdf::TextVar), StudyError> {
    let bad = |e: netcdf3::error::InvalidDataSet| StudyError::Io(format!("NetCDF definition: {e:?}"));
    let mut ds = DataSet::new();
    ds.add_fixed_dim("line", rows).map_err(bad)?;
    ds.add_fixed_dim("pixel", cols).map_err(bad)?;
    ds.add_fixed_dim("band", nb).map_err(bad)?;
    define_vars(&mut ds, floats, flags).map_err(StudyError::Io)?;
    let band_names: Vec<&str> = out.response.bands.bands.iter().map(|b| b.name.as_str()).collect();
    let names = crate::netcdf::band_names(&mut ds, &band_names).map_err(StudyError::Io)?;
    let config = out.config.to_ron().map_err(|e| StudyError::Io(e.to_string()))?;
    let geolocation = match &out.scene.frame {
        Some(f) => format!("pushbroom ground points in {} (scene centre at {:.3}, {:.3})", f.crs.describe(), f.centre.0, f.centre.1),
        None => "pushbroom ground points in the scene's local frame (metres east and north of its centre; the scene has no georeference)".into(),
    };
    let globals = [
        ("Conventions", "CF-1.8".to_string()),
        ("title", format!("Shoal simulation: {} over {}", out.config.instrument.name, out.config.scene.name)),
        (
            "source",
            format!(
                "Shoal {} end-to-end simulator (scene, atmosphere, instrument, correction, retrieval)",
                env!("CARGO_PKG_VERSION")
            ),
        ),
        ("references", "Matthews, M. W. et al. (2023) Sensors 23, 7824".into()),
        ("instrument", out.config.instrument.name.clone()),
        ("scene", out.config.scene.name.clone()),
        ("seed", out.config.seed.to_string()),
        ("decimation", out.viewing.decimation.to_string()),
        ("band_names", band_names.join(" ")),
        ("image_order", "line 0 = first line acquired, pixel 0 = first detector".into()),
        ("geolocation", geolocation),
        ("shoal_configuration", config),
    ];
    for (k, v) in globals {
        ds.add_global_attr_string(k, v).map_err(bad)?;
    }
    Ok((ds, names))
}
