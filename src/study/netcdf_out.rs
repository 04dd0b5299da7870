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

use std::cell::RefCell;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::Path;
use std::rc::Rc;

use netcdf3::{DataSet, FileWriter, Version};

use super::StudyError;
use super::output::Outputs;
use crate::correction::RrsFlags;
use crate::engine::RunOutput;
use crate::retrieval::ProductFlags;

/// The file a run's NetCDF product is written to.
pub const FILE: &str = "products.nc";

/// Auxiliary coordinates of a (line, pixel) map: every pixel's ground position.
const MAP_COORDINATES: &str = "y x";
/// Auxiliary coordinates of a (line, pixel, band) cube: the ground position and the bands.
const CUBE_COORDINATES: &str = "y x wavelength bandwidth";

/// CF standard names of Shoal's product variables (those CF has).
fn standard_name(variable: &str) -> Option<&'static str> {
    Some(match variable {
        "chl_mg_m3" => "mass_concentration_of_chlorophyll_a_in_sea_water",
        "nap_g_m3" => "mass_concentration_of_suspended_matter_in_sea_water",
        "depth_m" => "sea_floor_depth_below_sea_surface",
        "rrs" => "surface_ratio_of_upwelling_radiance_emerging_from_sea_water_to_downwelling_radiative_flux_in_air",
        _ => return None,
    })
}

/// What a product variable is, and its unit (UDUNITS).
fn meaning(variable: &str) -> (&'static str, &'static str) {
    match variable {
        "chl_mg_m3" => ("chlorophyll-a concentration", "mg m-3"),
        "nap_g_m3" => ("non-algal particle (suspended matter) concentration", "g m-3"),
        "cdom_per_m" => ("CDOM absorption coefficient at the SIOP set's reference wavelength", "m-1"),
        "depth_m" => ("water depth", "m"),
        _ => ("", "1"),
    }
}

/// A float variable of the data set with its data: (name, dimensions, attributes, values).
struct FloatVar {
    name: String,
    dims: Vec<&'static str>,
    attrs: Vec<(&'static str, String)>,
    values: Vec<f32>,
}

/// An integer flag variable: name, dimensions, what it is, masks and meanings, values. 32-bit:
/// CF wants the masks in the variable's type, Shoal's product flags use all eight bits of a byte
/// (128 is no NC_BYTE), and the `netcdf3` crate pads a 1- or 2-byte attribute list with fill
/// values where the format wants zero bytes (its own reader then refuses the header; ncdump
/// accepts it): 4-byte attributes need no padding.
struct FlagVar {
    name: String,
    dims: Vec<&'static str>,
    long_name: String,
    flags: Vec<(i32, &'static str)>,
    values: Vec<i32>,
    /// Auxiliary coordinates (the `coordinates` attribute).
    coordinates: &'static str,
}

/// Written where a value has no meaning (land, not returned, invalid Rrs), declared as
/// `_FillValue` (readers such as xarray turn it into NaN): the GeoTIFF products' no-data value.
/// Not NaN itself: the `netcdf3` crate finds a variable by comparing its attributes, and a NaN
/// attribute never equals itself.
pub const FILL: f32 = -9999.0;

/// `keep`-masked values of a map, [`FILL`] elsewhere (and where not finite).
fn masked(values: impl Iterator<Item = f32>, keep: impl Fn(usize) -> bool) -> Vec<f32> {
    values.enumerate().map(|(i, v)| if keep(i) && v.is_finite() { v } else { FILL }).collect()
}

/// A shared, seekable, buffered file: the writer owns one handle, Shoal keeps the other to flush
/// and sync it once the writer has closed.
#[derive(Clone)]
struct Shared(Rc<RefCell<BufWriter<std::fs::File>>>);

impl Write for Shared {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.borrow_mut().flush()
    }
}

impl Seek for Shared {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.0.borrow_mut().seek(pos)
    }
}

/// Dimensions of a (line, pixel, band) cube and a (line, pixel) map.
const CUBE: [&str; 3] = ["line", "pixel", "band"];
const MAP: [&str; 2] = ["line", "pixel"];

/// `long_name`, `units` and, where CF has one, `standard_name`.
fn attrs(long: &str, units: &str, standard: Option<&str>) -> Vec<(&'static str, String)> {
    let mut a = vec![("long_name", long.to_string()), ("units", units.to_string())];
    if let Some(s) = standard {
        a.push(("standard_name", s.to_string()));
    }
    a
}

/// Write `out`'s products into `dir/products.nc` (atomically: a temporary file, synced, then
/// renamed).
pub fn write_netcdf(out: &RunOutput, dir: &Path, o: &mut Outputs) -> Result<(), StudyError> {
    let (rows, cols, nb) = out.level1.radiance.dim();
    let mut floats: Vec<FloatVar> = Vec::new();
    let mut flags: Vec<FlagVar> = Vec::new();
    coordinate_vars(out, &mut floats);
    radiometry_vars(out, &mut floats, &mut flags);
    truth_vars(out, &mut floats, &mut flags);
    retrieval_vars(out, &mut floats, &mut flags);
    let data_set = define(out, (rows, cols, nb), &floats, &flags)?;
    let path = dir.join(FILE);
    write_file(&path, &data_set, &floats, &flags)?;
    o.files.push(FILE.to_string());
    Ok(())
}

/// The bands, and every pixel's ground position.
fn coordinate_vars(out: &RunOutput, floats: &mut Vec<FloatVar>) {
    let (rows, cols, _) = out.level1.radiance.dim();
    let bands = &out.response.bands.bands;
    floats.push(FloatVar {
        name: "wavelength".into(),
        dims: vec!["band"],
        attrs: attrs("band centre wavelength", "nm", Some("radiation_wavelength")),
        values: bands.iter().map(|b| b.centre_nm as f32).collect(),
    });
    floats.push(FloatVar {
        name: "bandwidth".into(),
        dims: vec!["band"],
        attrs: attrs("band full width at half maximum", "nm", None),
        values: bands.iter().map(|b| b.fwhm_nm as f32).collect(),
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
        values: ground.iter().map(|g| (x0 + g.0) as f32).collect(),
    });
    floats.push(FloatVar {
        name: "y".into(),
        dims: MAP.to_vec(),
        attrs: attrs(y_long, "m", std_or_none(y_std)),
        values: ground.iter().map(|g| (y0 + g.1) as f32).collect(),
    });
}

/// Level-1 and Rrs with its flags.
fn radiometry_vars(out: &RunOutput, floats: &mut Vec<FloatVar>, flags: &mut Vec<FlagVar>) {
    let cube_coordinates = ("coordinates", CUBE_COORDINATES.to_string());
    let mut l1 = attrs("top-of-atmosphere radiance (Level-1, calibrated)", "W m-2 sr-1 nm-1", None);
    l1.push(cube_coordinates.clone());
    floats.push(FloatVar {
        name: "level1_radiance".into(),
        dims: CUBE.to_vec(),
        attrs: l1,
        values: masked(out.level1.radiance.iter().copied(), |_| true),
    });
    let rrs = &out.correction.rrs;
    let rrs_flags = rrs.flags.as_slice().unwrap_or_default();
    let mut a = attrs("remote-sensing reflectance above the surface, corrected", "sr-1", standard_name("rrs"));
    a.push(cube_coordinates.clone());
    floats.push(FloatVar {
        name: "rrs".into(),
        dims: CUBE.to_vec(),
        attrs: a,
        values: masked(rrs.rrs.iter().copied(), |i| rrs_flags.get(i).is_some_and(|f| f & RrsFlags::INVALID == 0)),
    });
    flags.push(FlagVar {
        name: "rrs_flags".into(),
        dims: CUBE.to_vec(),
        long_name: "Rrs quality flags".into(),
        flags: vec![
            (i32::from(RrsFlags::NEGATIVE), "negative"),
            (i32::from(RrsFlags::SATURATED), "saturated"),
            (i32::from(RrsFlags::INVALID), "invalid"),
        ],
        values: rrs_flags.iter().map(|&f| i32::from(f)).collect(),
        coordinates: CUBE_COORDINATES,
    });
}

/// The truth, and the aerosol an image-based correction found.
fn truth_vars(out: &RunOutput, floats: &mut Vec<FloatVar>, flags: &mut Vec<FlagVar>) {
    let truth = &out.radiance.truth;
    let nb = out.level1.radiance.dim().2;
    let water = |i: usize| truth.land.as_slice().is_some_and(|l| l[i] == 0);
    let coordinates = ("coordinates", MAP_COORDINATES.to_string());
    let cube_coordinates = ("coordinates", CUBE_COORDINATES.to_string());
    let mut a =
        attrs("true remote-sensing reflectance above the surface (band-weighted)", "sr-1", standard_name("rrs"));
    a.push(cube_coordinates.clone());
    let nbw = nb.max(1);
    floats.push(FloatVar {
        name: "true_rrs".into(),
        dims: CUBE.to_vec(),
        attrs: a,
        values: masked(truth.rrs_above.iter().copied(), |i| water(i / nbw)),
    });
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
            values: masked(values.iter().copied(), water),
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
            values: aot.iter().copied().collect(),
        });
    }
    flags.push(FlagVar {
        name: "land".into(),
        dims: MAP.to_vec(),
        long_name: "land under the pixel centre".into(),
        flags: vec![(1, "land")],
        values: truth.land.iter().map(|&v| i32::from(v)).collect(),
        coordinates: MAP_COORDINATES,
    });

    if let Some(a) = &out.correction.aerosol {
        let mut at = attrs("aerosol optical thickness at 550 nm found by the correction", "1", None);
        at.push(coordinates.clone());
        floats.push(FloatVar {
            name: "retrieved_aot550".into(),
            dims: MAP.to_vec(),
            attrs: at,
            values: masked(a.aot550.iter().copied(), |_| true),
        });
    }
}

/// Every retrieval's products and flags.
fn retrieval_vars(out: &RunOutput, floats: &mut Vec<FloatVar>, flags: &mut Vec<FlagVar>) {
    let coordinates = ("coordinates", MAP_COORDINATES.to_string());
    for ret in &out.retrievals {
        let p = &ret.product;
        let stem = ret.spec.name();
        let pf = p.flags.as_slice().unwrap_or_default();
        let returned = |i: usize| pf.get(i).is_some_and(|f| f & ProductFlags::RETURNED != 0);
        let mut maps: Vec<(&str, &ndarray::Array2<f32>)> =
            vec![("chl_mg_m3", &p.chl_mg_m3), ("nap_g_m3", &p.nap_g_m3), ("cdom_per_m", &p.cdom_per_m)];
        if let Some(d) = &p.depth_m {
            maps.push(("depth_m", d));
        }
        for (variable, values) in maps {
            let (long, units) = meaning(variable);
            let mut a = attrs(&format!("{long} retrieved by {}", p.name), units, standard_name(variable));
            a.push(coordinates.clone());
            a.push(("ancillary_variables", format!("{stem}_flags")));
            floats.push(FloatVar {
                name: format!("{stem}_{variable}"),
                dims: MAP.to_vec(),
                attrs: a,
                values: masked(values.iter().copied(), returned),
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
            values: pf.iter().map(|&f| i32::from(f)).collect(),
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
) -> Result<DataSet, StudyError> {
    let bad = |e: netcdf3::error::InvalidDataSet| StudyError::Io(format!("NetCDF definition: {e:?}"));
    let mut ds = DataSet::new();
    ds.add_fixed_dim("line", rows).map_err(bad)?;
    ds.add_fixed_dim("pixel", cols).map_err(bad)?;
    ds.add_fixed_dim("band", nb).map_err(bad)?;
    for v in floats {
        ds.add_var_f32(&v.name, &v.dims).map_err(bad)?;
        for (k, value) in &v.attrs {
            ds.add_var_attr_string(&v.name, k, value).map_err(bad)?;
        }
        if v.dims.len() > 1 {
            ds.add_var_attr_f32(&v.name, "_FillValue", vec![FILL]).map_err(bad)?;
        }
    }
    for f in flags {
        ds.add_var_i32(&f.name, &f.dims).map_err(bad)?;
        ds.add_var_attr_string(&f.name, "long_name", &f.long_name).map_err(bad)?;
        if f.flags.len() == 1 {
            ds.add_var_attr_i32(&f.name, "flag_values", vec![0, f.flags[0].0]).map_err(bad)?;
            ds.add_var_attr_string(&f.name, "flag_meanings", format!("not_{} {}", f.flags[0].1, f.flags[0].1))
                .map_err(bad)?;
        } else {
            ds.add_var_attr_i32(&f.name, "flag_masks", f.flags.iter().map(|x| x.0).collect()).map_err(bad)?;
            let meanings: Vec<&str> = f.flags.iter().map(|x| x.1).collect();
            ds.add_var_attr_string(&f.name, "flag_meanings", meanings.join(" ")).map_err(bad)?;
        }
        ds.add_var_attr_string(&f.name, "coordinates", f.coordinates).map_err(bad)?;
    }
    let config = out.config.to_ron().map_err(|e| StudyError::Io(e.to_string()))?;
    let geolocation = match &out.scene.frame {
        Some(f) => format!("pushbroom ground points in {} (scene centre at {:.3}, {:.3})", f.crs.describe(), f.centre.0, f.centre.1),
        None => "pushbroom ground points in the scene's local frame (metres east and north of its centre; the scene has no georeference)".into(),
    };
    let band_names: Vec<&str> = out.response.bands.bands.iter().map(|b| b.name.as_str()).collect();
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
    Ok(ds)
}

/// Write the data set and its values to `path` through a temporary file, synced, then renamed.
fn write_file(path: &Path, ds: &DataSet, floats: &[FloatVar], flags: &[FlagVar]) -> Result<(), StudyError> {
    let tmp = path.with_extension("nc.partial");
    let fail = |m: String| StudyError::Io(format!("cannot write {}: {m}", path.display()));
    let result = (|| -> Result<(), StudyError> {
        let file = std::fs::File::create(&tmp).map_err(|e| fail(e.to_string()))?;
        let shared = Shared(Rc::new(RefCell::new(BufWriter::with_capacity(1 << 20, file))));
        let mut writer = FileWriter::open_seek_write(&tmp.to_string_lossy(), Box::new(shared.clone()))
            .map_err(|e| fail(format!("{e:?}")))?;
        writer.set_def(ds, Version::Offset64Bit, 0).map_err(|e| fail(format!("{e:?}")))?;
        for v in floats {
            writer.write_var_f32(&v.name, &v.values).map_err(|e| fail(format!("{}: {e:?}", v.name)))?;
        }
        for f in flags {
            writer.write_var_i32(&f.name, &f.values).map_err(|e| fail(format!("{}: {e:?}", f.name)))?;
        }
        writer.close().map_err(|e| fail(format!("{e:?}")))?;
        let mut buffered = shared.0.borrow_mut();
        buffered.flush().map_err(|e| fail(e.to_string()))?;
        buffered.get_ref().sync_all().map_err(|e| fail(e.to_string()))?;
        Ok(())
    })();
    match result.and_then(|()| std::fs::rename(&tmp, path).map_err(|e| fail(e.to_string()))) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}
