//! A run's products as GeoTIFF (`--format geotiff`): Level-1 radiance, Rrs, the truth and each
//! retrieval's maps, one file each, bands described with their units, georeferenced in the
//! scene's CRS (or, for a scene with none, a local frame in metres east and north of its centre).
//!
//! The image is the instrument's: row 0 is the first line acquired, column 0 the first detector.
//! Its pixels lie on the ground along the pushbroom geometry ([`crate::instrument::Viewing`]),
//! which is affine only to first order (the across-track spacing grows off nadir, and a
//! heading rotates the grid). The geotransform is the least-squares affine fit to every pixel
//! centre's ground point; the largest distance between the fit and the true ground point is
//! written as `GEOLOCATION_RESIDUAL_M` so a user can see whether the fit is good enough.

use std::path::Path;

use ndarray::{Array2, Array3};

use super::output::{Outputs, write_bytes};
use super::{StudyError, output};
use crate::engine::RunOutput;
use crate::geotiff::{Crs, Raster};
use crate::instrument::Viewing;
use crate::retrieval::ProductFlags;

/// Written where a product has no value (not returned, land, invalid Rrs): GDAL's usual choice,
/// exact in Float32.
pub const NODATA: f64 = -9999.0;

/// The affine geotransform (GDAL order) of the image's pixel grid in the CRS and the largest
/// distance between a pixel centre's fitted and true ground point, m. `centre` is the CRS
/// position of the scene centre (the scene frame's origin).
#[must_use]
pub fn swath_geotransform(viewing: &Viewing, centre: (f64, f64)) -> ([f64; 6], f64) {
    let (rows, cols) = (viewing.lines(), viewing.columns());
    // On a full grid the column and row indices are uncorrelated, so the least-squares plane
    // X = x̄ + a·(c − c̄) + b·(r − r̄) has a = cov(X, c)/var(c) and b = cov(X, r)/var(r).
    let n = (rows * cols) as f64;
    let (c_mean, r_mean) = (0.5 * (cols as f64 - 1.0), 0.5 * (rows as f64 - 1.0));
    let (mut sx, mut sy, mut sxc, mut syc, mut sxr, mut syr) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for r in 0..rows {
        for c in 0..cols {
            let (x, y) = viewing.ground_m(0, r, c);
            let (dc, dr) = (c as f64 - c_mean, r as f64 - r_mean);
            (sx, sy) = (sx + x, sy + y);
            (sxc, syc, sxr, syr) = (sxc + x * dc, syc + y * dc, sxr + x * dr, syr + y * dr);
        }
    }
    let var = |k: usize| (k * k - 1) as f64 / 12.0 * n; // Σ (i − ī)² over the grid
    // A single line or column has no spacing to fit along it: there the pixel is one GSD (times
    // the decimation) across or along the track.
    let spacing = viewing.gsd_m * viewing.decimation as f64;
    let h = viewing.track_heading_deg().to_radians();
    let (a_x, a_y) =
        if cols > 1 { (sxc / var(cols), syc / var(cols)) } else { (spacing * h.cos(), -spacing * h.sin()) };
    let (b_x, b_y) = if rows > 1 { (sxr / var(rows), syr / var(rows)) } else { (spacing * h.sin(), spacing * h.cos()) };
    let (x_mean, y_mean) = (sx / n, sy / n);
    // Pixel (c, r)'s centre is at corner coordinates (c + 0.5, r + 0.5).
    let x0 = x_mean - a_x * (c_mean + 0.5) - b_x * (r_mean + 0.5);
    let y0 = y_mean - a_y * (c_mean + 0.5) - b_y * (r_mean + 0.5);
    let mut worst = 0.0f64;
    for r in 0..rows {
        for c in 0..cols {
            let (x, y) = viewing.ground_m(0, r, c);
            let (fx, fy) = (
                x0 + a_x * (c as f64 + 0.5) + b_x * (r as f64 + 0.5),
                y0 + a_y * (c as f64 + 0.5) + b_y * (r as f64 + 0.5),
            );
            worst = worst.max((fx - x).hypot(fy - y));
        }
    }
    // Rounding leaves rotation terms of 1e-16 on a north-aligned track: call them zero, so the
    // file says "north-aligned" (PixelScale + Tiepoint) as the geometry is.
    let snap = |v: f64, scale: f64| if v.abs() < 1e-9 * scale { 0.0 } else { v };
    let scale = a_x.hypot(a_y).max(b_x.hypot(b_y));
    ([centre.0 + x0, snap(a_x, scale), snap(b_x, scale), centre.1 + y0, snap(a_y, scale), snap(b_y, scale)], worst)
}

/// The raster skeleton every product file of `out` shares: size, georeference, metadata.
fn base(out: &RunOutput) -> Raster {
    let (rows, cols) = (out.viewing.lines(), out.viewing.columns());
    let mut r = Raster::new(cols, rows, Vec::new());
    let (crs, centre, frame_text) = match &out.scene.frame {
        Some(f) => (
            f.crs.clone(),
            f.centre,
            format!("{} (scene centre at {:.1} E, {:.1} N)", f.crs.describe(), f.centre.0, f.centre.1),
        ),
        None => (
            Crs::LocalMetres { name: "Shoal scene frame (m east and north of the scene centre)".into() },
            (0.0, 0.0),
            "a local frame in metres east and north of the scene centre (the scene has no georeference)".into(),
        ),
    };
    let (g, residual_m) = swath_geotransform(&out.viewing, centre);
    r.geotransform = Some(g);
    r.crs = crs;
    r.metadata = vec![
        ("SHOAL_VERSION".into(), env!("CARGO_PKG_VERSION").into()),
        ("INSTRUMENT".into(), out.config.instrument.name.clone()),
        ("SCENE".into(), out.config.scene.name.clone()),
        ("SEED".into(), out.config.seed.to_string()),
        ("DECIMATION".into(), out.viewing.decimation.to_string()),
        ("GEOLOCATION".into(), format!("affine fit to the pushbroom ground points in {frame_text}")),
        ("GEOLOCATION_RESIDUAL_M".into(), format!("{residual_m:.3}")),
        ("IMAGE_ORDER".into(), "row 0 = first line acquired, column 0 = first detector".into()),
    ];
    r
}

/// Band-major values of a (row, column) map, `NODATA` where `keep` says no.
fn plane(map: &Array2<f32>, keep: &dyn Fn(usize, usize) -> bool) -> Vec<f64> {
    map.indexed_iter().map(|((r, c), v)| if keep(r, c) && v.is_finite() { f64::from(*v) } else { NODATA }).collect()
}

/// Band-major values of band `b` of a (row, column, band) cube.
fn cube_plane(cube: &Array3<f32>, b: usize, keep: &dyn Fn(usize, usize) -> bool) -> Vec<f64> {
    let s = cube.index_axis(ndarray::Axis(2), b);
    s.indexed_iter().map(|((r, c), v)| if keep(r, c) && v.is_finite() { f64::from(*v) } else { NODATA }).collect()
}

fn file(dir: &Path, name: &str, raster: &Raster, o: &mut Outputs) -> Result<(), StudyError> {
    let bytes = crate::geotiff::encode(raster).map_err(|e| StudyError::Io(format!("{name}: {e}")))?;
    write_bytes(&dir.join(name), &bytes)?;
    o.files.push(name.to_string());
    Ok(())
}

/// Write the run's products as GeoTIFF into `dir`, with the same tables, report and resolved
/// configuration as [`super::write_run`] writes beside its `.npy` cubes.
pub fn write_run_geotiff(out: &RunOutput, dir: &Path) -> Result<Outputs, StudyError> {
    let cubes = super::output::kept_cubes(out)?;
    std::fs::create_dir_all(dir).map_err(|e| StudyError::Io(format!("cannot create {}: {e}", dir.display())))?;
    let mut o = Outputs::default();
    let bands = &out.response.bands.bands;
    let truth = &out.truth;
    // The georeference and metadata every file shares, computed once (the affine fit visits
    // every pixel twice).
    let shared = base(out);
    let all = |_: usize, _: usize| true;
    let water = |r: usize, c: usize| truth.surface.is_water(r, c);

    let mut l1 = shared.clone();
    for (b, band) in bands.iter().enumerate() {
        l1.bands.push(cube_plane(&cubes.level1.radiance, b, &all));
        l1.descriptions.push(format!("L1 radiance {} ({:.1} nm)", band.name, band.centre_nm));
        l1.units.push("W m-2 sr-1 nm-1".into());
    }
    l1.nodata = Some(NODATA);
    file(dir, "level1_radiance.tif", &l1, &mut o)?;

    let rrs = &cubes.rrs;
    let valid = |b: usize| move |r: usize, c: usize| rrs.flags[[r, c, b]] & crate::correction::RrsFlags::INVALID == 0;
    let mut rr = shared.clone();
    for (b, band) in bands.iter().enumerate() {
        rr.bands.push(cube_plane(&rrs.rrs, b, &valid(b)));
        rr.descriptions.push(format!("Rrs {} ({:.1} nm)", band.name, band.centre_nm));
        rr.units.push("sr-1".into());
    }
    rr.nodata = Some(NODATA);
    file(dir, "rrs.tif", &rr, &mut o)?;

    let mut t = shared.clone();
    let push = |r: &mut Raster, values: Vec<f64>, what: &str, unit: &str| {
        r.bands.push(values);
        r.descriptions.push(what.to_string());
        r.units.push(unit.to_string());
    };
    push(&mut t, plane(&truth.chl_mg_m3, &water), "true chlorophyll-a", "mg m-3");
    push(&mut t, plane(&truth.nap_g_m3, &water), "true NAP", "g m-3");
    push(&mut t, plane(&truth.cdom_per_m, &water), "true CDOM absorption at 440 nm", "m-1");
    if let Some(d) = &truth.depth_m {
        push(&mut t, plane(d, &water), "true depth", "m");
    }
    if let Some(f) = &truth.substrate_fractions {
        for (k, name) in truth.substrate_names.iter().enumerate() {
            push(&mut t, cube_plane(f, k, &water), &format!("true {name} fraction"), "1");
        }
    }
    let classes: Vec<String> =
        crate::instrument::SurfaceClass::flags().iter().map(|(code, name)| format!("{code} {name}")).collect();
    let description = format!("surface class: {}", classes.join(", "));
    push(&mut t, truth.surface.codes().iter().map(|v| f64::from(*v)).collect(), &description, "1");
    t.nodata = Some(NODATA);
    file(dir, "truth.tif", &t, &mut o)?;

    for ret in &out.retrievals {
        let p = &ret.product;
        let returned = |r: usize, c: usize| p.flags[[r, c]] & ProductFlags::RETURNED != 0;
        let mut m = shared.clone();
        m.metadata.push(("RETRIEVAL".into(), p.name.clone()));
        for (map, what, unit) in [
            (&p.chl_mg_m3, "retrieved chlorophyll-a", "mg m-3"),
            (&p.nap_g_m3, "retrieved NAP", "g m-3"),
            (&p.cdom_per_m, "retrieved CDOM absorption at 440 nm", "m-1"),
        ] {
            if let Some(map) = map {
                push(&mut m, plane(map, &returned), what, unit);
            }
        }
        if let Some(d) = &p.depth_m {
            push(&mut m, plane(d, &returned), "retrieved depth", "m");
        }
        for (key, map) in &p.extras {
            let (long, unit) = crate::netcdf::meaning(key);
            push(&mut m, plane(map, &returned), &format!("retrieved {long}"), unit);
        }
        if let Some(f) = &p.substrate_fractions {
            for (k, name) in p.substrate_names.iter().enumerate() {
                push(&mut m, cube_plane(f, k, &returned), &format!("retrieved {name} fraction"), "1");
            }
        }
        if let Some(s) = &p.sdi {
            push(&mut m, plane(s, &returned), "substrate detectability index", "1");
        }
        push(&mut m, plane(&p.cost, &returned), "cost at the solution", "1");
        push(&mut m, p.flags.iter().map(|v| f64::from(*v)).collect(), "flags (ProductFlags bits)", "1");
        m.nodata = Some(NODATA);
        file(dir, &format!("{}.tif", ret.spec.name()), &m, &mut o)?;
    }
    let tables = output::write_tables(out, dir)?;
    o.files.extend(tables.files);
    Ok(o)
}
