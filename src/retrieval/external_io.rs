//! The files of an external retrieval ([`super::external`]): the NetCDF input Shoal writes for
//! the program, and the program's output read back into a [`Product`].

use std::path::Path;

use ndarray::Array2;
use netcdf3::DataSet;

use super::RetrievalError;
use super::external::ExternalSpec;
use super::run::{Product, ProductFlags, RetrievalInputs};
use crate::correction::RrsFlags;
use crate::netcdf::{
    CUBE, FlagVar, FloatVar, InMemory, MAP, Maps, TextVar, Values, attrs, define_vars, in_memory, masked,
    standard_name, write_file,
};
use crate::parse::FieldError;
use crate::variable::key;

/// The instrument bands the program is given (`bands`, else every band), by index.
pub(super) fn used_bands(spec: &ExternalSpec, inputs: &RetrievalInputs<'_>) -> Result<Vec<usize>, RetrievalError> {
    let Some(names) = &spec.bands else { return Ok((0..inputs.bands.len()).collect()) };
    if names.is_empty() {
        return Err(RetrievalError::Invalid(FieldError {
            field: "retrievals[i].External.bands".into(),
            message: "is empty (leave it out to give every band)".into(),
        }));
    }
    names
        .iter()
        .map(|n| {
            inputs.bands.iter().position(|b| &b.name == n).ok_or_else(|| {
                RetrievalError::Invalid(FieldError {
                    field: "retrievals[i].External.bands".into(),
                    message: format!(
                        "no band `{}` (this instrument has {})",
                        n.escape_debug(),
                        inputs.bands.iter().map(|b| b.name.as_str()).collect::<Vec<_>>().join(", ")
                    ),
                })
            })
        })
        .collect()
}

/// Equivalent width of a band response, nm: ∫w dλ / max w on its uniform grid.
fn equivalent_width_nm(b: &super::BandResponse) -> f64 {
    let n = b.wavelengths_nm.len();
    if n < 2 {
        return 0.0;
    }
    let step = (b.wavelengths_nm[n - 1] - b.wavelengths_nm[0]) / (n - 1) as f64;
    let peak = b.weights.iter().copied().fold(0.0, f64::max);
    if peak > 0.0 { b.weights.iter().sum::<f64>() * step / peak } else { 0.0 }
}

/// Write the program's input file (see [`with_input`]).
pub(super) fn write_input(
    spec: &ExternalSpec,
    inputs: &RetrievalInputs<'_>,
    used: &[usize],
    path: &Path,
) -> Result<(), String> {
    with_input(spec, inputs, used, |ds, parts| write_file(path, ds, parts, false))?
}

/// The input an in-process function is given: the program's input file, held in memory.
pub(super) fn input_in_memory(
    spec: &ExternalSpec,
    inputs: &RetrievalInputs<'_>,
    used: &[usize],
) -> Result<InMemory, String> {
    with_input(spec, inputs, used, in_memory)
}

/// The program's input, handed to `use_it`: the Rrs of `used` bands (fill where invalid,
/// saturated or land), the land mask, the bands, their noise and the geometry. No truth. (No Rrs
/// flags: the fill value carries the ones that matter, and 32-bit flags would double the file.)
fn with_input<R>(
    spec: &ExternalSpec,
    inputs: &RetrievalInputs<'_>,
    used: &[usize],
    use_it: impl FnOnce(&DataSet, (&[FloatVar<'_>], &[FlagVar<'_>], &[TextVar])) -> R,
) -> Result<R, String> {
    let (rows, cols, nb) = inputs.rrs.dim();
    let bands: Vec<&super::BandResponse> = used.iter().map(|&b| &inputs.bands[b]).collect();
    let mut floats = vec![
        FloatVar {
            name: "wavelength".into(),
            dims: vec!["band"],
            attrs: attrs("band response centroid wavelength", "nm", Some("radiation_wavelength")),
            values: Values::ready(bands.iter().map(|b| b.centroid_nm() as f32).collect()),
        },
        FloatVar {
            name: "bandwidth".into(),
            dims: vec!["band"],
            attrs: attrs("band response equivalent width (integral over peak)", "nm", None),
            values: Values::ready(bands.iter().map(|b| equivalent_width_nm(b) as f32).collect()),
        },
        FloatVar {
            name: "nedr".into(),
            dims: vec!["band"],
            attrs: attrs("noise-equivalent delta Rrs of the instrument at the typical radiance", "sr-1", None),
            values: Values::ready(used.iter().map(|&b| inputs.nedr[b] as f32).collect()),
        },
    ];
    let degrees = |f: fn(&crate::water::WaterGeometry) -> f64| -> Vec<f32> {
        (0..cols).map(|c| inputs.geometry.get(c).map_or(f32::NAN, |g| f(g).to_degrees() as f32)).collect()
    };
    floats.push(FloatVar {
        name: "solar_zenith_angle".into(),
        dims: vec!["pixel"],
        attrs: attrs("solar zenith angle at the ground", "degree", Some("solar_zenith_angle")),
        values: Values::ready(degrees(|g| g.sun_zenith_rad)),
    });
    floats.push(FloatVar {
        name: "sensor_zenith_angle".into(),
        dims: vec!["pixel"],
        attrs: attrs("view zenith angle at the ground", "degree", Some("sensor_zenith_angle")),
        values: Values::ready(degrees(|g| g.view_zenith_rad)),
    });
    let n_used = used.len().max(1);
    let value = move |i: usize| {
        let (pixel, k) = (i / n_used, i % n_used);
        let (r, c, b) = (pixel / cols.max(1), pixel % cols.max(1), used[k]);
        debug_assert!(b < nb);
        (inputs.rrs[[r, c, b]], inputs.flags[[r, c, b]], !inputs.surface.is_water(r, c))
    };
    let total = rows * cols * used.len();
    let bad = RrsFlags::INVALID | RrsFlags::SATURATED;
    let mut rrs_attrs = attrs("remote-sensing reflectance above the surface, corrected", "sr-1", standard_name("rrs"));
    rrs_attrs.push(("ancillary_variables", "surface_class".into()));
    rrs_attrs.push((
        "comment",
        "_FillValue where the correction flagged the band invalid or saturated, and off water".into(),
    ));
    floats.push(FloatVar {
        name: "rrs".into(),
        dims: CUBE.to_vec(),
        attrs: rrs_attrs,
        values: Values::lazy(move || {
            masked((0..total).map(|i| value(i).0), |i| {
                let (_, f, land) = value(i);
                f & bad == 0 && !land
            })
        }),
    });
    let flags = vec![FlagVar {
        name: "surface_class".into(),
        dims: MAP.to_vec(),
        long_name: "what covers the pixel centre (only water is retrieved)".into(),
        flags: crate::instrument::SurfaceClass::flags(),
        values: Values::ready(inputs.surface.codes().iter().map(|&v| i32::from(v)).collect()),
        coordinates: "",
    }];
    let mut ds = DataSet::new();
    let bad_def = |e: netcdf3::error::InvalidDataSet| format!("NetCDF definition: {e:?}");
    ds.add_fixed_dim("line", rows).map_err(bad_def)?;
    ds.add_fixed_dim("pixel", cols).map_err(bad_def)?;
    ds.add_fixed_dim("band", used.len()).map_err(bad_def)?;
    define_vars(&mut ds, &floats, &flags)?;
    let band_names: Vec<&str> = bands.iter().map(|b| b.name.as_str()).collect();
    let names = crate::netcdf::band_names(&mut ds, &band_names)?;
    for (k, v) in [
        ("Conventions", "CF-1.8".to_string()),
        ("title", format!("Shoal: corrected Rrs for the external retrieval `{}`", spec.name)),
        ("source", format!("Shoal {} end-to-end simulator", env!("CARGO_PKG_VERSION"))),
        ("band_names", band_names.join(" ")),
        ("products_wanted", spec.products.join(" ")),
        (
            "products_convention",
            "write each wanted product as a float (line, pixel) variable of this file's size, NaN or _FillValue where not returned".into(),
        ),
        ("image_order", "line 0 = first line acquired, pixel 0 = first detector".into()),
    ] {
        ds.add_global_attr_string(k, v).map_err(bad_def)?;
    }
    Ok(use_it(&ds, (&floats, &flags, &[names])))
}

/// The program's output as a [`Product`]: each wanted map (0 where missing), returned where every
/// map is finite and positive, land where the input says so.
pub(super) fn product(spec: &ExternalSpec, inputs: &RetrievalInputs<'_>, maps: &Maps) -> Result<Product, String> {
    let (rows, cols) = inputs.surface.dim();
    if maps.shape != (rows, cols) {
        return Err(format!(
            "its output is {} × {} (line × pixel); the input was {rows} × {cols}",
            maps.shape.0, maps.shape.1
        ));
    }
    // Each wanted product's values, found once.
    let mut columns: Vec<(&str, &[Option<f64>])> = Vec::new();
    for wanted in &spec.products {
        let Some((_, values)) = maps.maps.iter().find(|(n, _)| n == wanted) else {
            return Err(format!(
                "its output has no `{wanted}` (it has: {}); `products` lists what the program must write",
                if maps.names.is_empty() { "no variables".to_string() } else { maps.names.join(", ") }
            ));
        };
        columns.push((wanted.as_str(), values.as_slice()));
    }
    let mut planes: Vec<(&str, Array2<f32>)> = columns
        .iter()
        .map(|(name, values)| {
            (*name, Array2::from_shape_fn((rows, cols), |(r, c)| values[r * cols + c].map_or(0.0, |v| v as f32)))
        })
        .collect();
    let valid = |r: usize, c: usize| columns.iter().all(|(_, v)| v[r * cols + c].is_some_and(|x| x > 0.0));
    let flags = Array2::from_shape_fn((rows, cols), |(r, c)| {
        if !inputs.surface.is_water(r, c) {
            ProductFlags::LAND
        } else if valid(r, c) {
            ProductFlags::RETURNED
        } else {
            ProductFlags::FAILED
        }
    });
    let mut take = |v: &str| planes.iter().position(|(n, _)| *n == v).map(|i| planes.remove(i).1);
    Ok(Product {
        chl_mg_m3: take(key::CHL),
        cdom_per_m: take(key::CDOM),
        nap_g_m3: take(key::NAP),
        depth_m: take(key::DEPTH),
        ..Product::bare(spec.name.clone(), flags)
    })
}
