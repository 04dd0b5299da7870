//! Scene maps from GeoTIFF rasters, and a scene's place on Earth.
//!
//! A scene with `georeference: Some(Raster("bathymetry.tif"))` takes its grid from that raster:
//! width, height, cell size, place and CRS (a projected CRS in metres; cells must be square and
//! the raster north-up). Any map may then be `Raster(path: …, band: 1, scale: …, offset: …,
//! nodata: …, unit: "m")`: the raster is resampled onto the scene's grid through both
//! geotransforms — bilinear for continuous maps, nearest for the land mask (or as asked) — and
//! `scale · value + offset` must be in the unit the scene field is in.
//!
//! A nodata cell (the file's `GDAL_NODATA`, the map's `nodata`, or outside the raster) is allowed
//! only on land; there the map holds the median of its valid cells (the water model does not use
//! it). Anywhere else the scene does not build, and the error counts the cells and names the
//! first: a silently filled depth would be a wrong answer.
//!
//! Bilinear interpolation with missing neighbours uses the valid ones with renormalised weights
//! (GDAL's behaviour for `-r bilinear` with nodata).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::SceneError;
use super::map::Extent;
use crate::geotiff::{Crs, Raster};
use crate::parse::FieldError;

/// Where a scene is on Earth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Georeference {
    /// The grid of this GeoTIFF (relative to the scene file): the scene takes its width, height,
    /// cell size, place and CRS, and `width`, `height` and `cell_m` may be left out.
    Raster(PathBuf),
    /// A projected CRS in metres by EPSG code, and the CRS coordinates of the scene centre (the
    /// scene's own width, height and cell size stand).
    Epsg {
        /// EPSG code of a projected CRS in metres (e.g. 32756, WGS 84 / UTM zone 56S).
        code: u16,
        /// Easting and northing of the scene centre, m.
        centre: (f64, f64),
    },
}

/// The scene frame placed on Earth: scene (x, y) metres ↔ CRS (X, Y) = centre + (x, y).
#[derive(Debug, Clone, PartialEq)]
pub struct GeoFrame {
    /// The CRS (projected, metres).
    pub crs: Crs,
    /// CRS coordinates of the scene centre, m.
    pub centre: (f64, f64),
}

/// How a raster is resampled onto the scene's grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Resampling {
    /// Bilinear (continuous maps: concentrations, depth, fractions).
    Bilinear,
    /// Nearest cell (masks and classes).
    Nearest,
}

/// A map read from a GeoTIFF band (the fields of [`super::MapSpec::Raster`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RasterSource {
    /// The GeoTIFF (relative to the scene file).
    pub path: PathBuf,
    /// Band, from 1.
    pub band: usize,
    /// Map value = scale · file value + offset.
    pub scale: f64,
    /// See `scale`.
    pub offset: f64,
    /// The file value that marks a missing cell (default: the file's own `GDAL_NODATA`).
    pub nodata: Option<f64>,
    /// Unit of scale · value + offset; must be the scene field's unit ("m", "mg m-3", "g m-3",
    /// "m-1", "1" for fractions and the land mask).
    pub unit: String,
    /// Resampling (default: bilinear, nearest for the land mask).
    pub resampling: Option<Resampling>,
}

pub(super) fn one_band() -> usize {
    1
}
pub(super) fn unit_scale() -> f64 {
    1.0
}

fn invalid(field: &str, message: String) -> SceneError {
    SceneError::Invalid(FieldError { field: field.into(), message })
}

/// The unit a scene field's values are in (ASCII, as GeoTIFF files write units).
#[must_use]
pub fn field_unit(field: &str) -> &'static str {
    crate::variable::of(field).map_or("1", |v| v.udunits)
}

/// Units compared the way people write them: `mg m⁻³`, `mg m-3`, `mg/m3`, `mg.m-3` agree.
fn same_unit(a: &str, b: &str) -> bool {
    let norm = |s: &str| {
        let s = crate::geotiff::ascii_text(s).to_lowercase().replace(['.', '*', '·', '^'], " ");
        let s = s.split_whitespace().collect::<Vec<_>>().join("");
        // `1/m` and `/m` are per metre; `/m 3` (from `/m^3`) per cubic metre.
        let s = s.strip_prefix("1/").map_or_else(|| s.clone(), |rest| format!("/{rest}"));
        let s = s.replace("/m3", " m-3").replace("/m", " m-1").replace("m-", " m-");
        let s = s.split_whitespace().collect::<Vec<_>>().join(" ");
        match s.as_str() {
            "" | "fraction" | "-" | "unitless" | "dimensionless" => "1".to_string(),
            "ugl-1" | "ug/l" => "mg m-3".into(),
            "mgl-1" | "mg/l" => "g m-3".into(),
            "metre" | "meter" | "metres" | "meters" => "m".into(),
            _ => s,
        }
    };
    norm(a) == norm(b)
}

/// Rasters read while one scene builds, by resolved path (a file used for several maps is read
/// once).
#[derive(Debug, Default)]
pub struct RasterCache {
    files: Vec<(PathBuf, Arc<Raster>)>,
}

impl RasterCache {
    /// The raster at `path` (relative to `base_dir`; a built-in scene's rasters are embedded).
    pub fn load(&mut self, path: &Path, base_dir: Option<&Path>, field: &str) -> Result<Arc<Raster>, SceneError> {
        let full = match base_dir {
            Some(d) if path.is_relative() => d.join(path),
            _ => path.to_path_buf(),
        };
        if let Some((_, r)) = self.files.iter().find(|(p, _)| *p == full) {
            return Ok(Arc::clone(r));
        }
        let embedded = base_dir.is_none().then(|| crate::assets::raster(&path.to_string_lossy())).flatten();
        // A quarter of the run's memory budget for one file's samples.
        let limit = crate::budget::MachineBudget::from_env().map_err(|m| invalid(field, m))?.raster_limit_samples();
        let raster = match embedded {
            Some(bytes) if !full.exists() => {
                crate::geotiff::read_bytes_limited(bytes, &path.display().to_string(), limit)
            }
            _ => crate::geotiff::read_limited(&full, limit),
        }
        .map_err(|e| invalid(field, format!("GeoTIFF: {e}")))?;
        let raster = Arc::new(raster);
        self.files.push((full, Arc::clone(&raster)));
        Ok(raster)
    }
}

/// The scene's frame and grid from its georeference: `Raster` gives both, `Epsg` only the frame.
pub fn resolve_frame(
    georeference: &Georeference,
    base_dir: Option<&Path>,
    cache: &mut RasterCache,
) -> Result<(GeoFrame, Option<Extent>), SceneError> {
    const FIELD: &str = "georeference";
    match georeference {
        Georeference::Epsg { code, centre } => {
            if !(centre.0.is_finite() && centre.1.is_finite()) {
                return Err(invalid(FIELD, format!("centre {centre:?} must be finite")));
            }
            Ok((GeoFrame { crs: Crs::Projected { epsg: *code }, centre: *centre }, None))
        }
        Georeference::Raster(path) => {
            let r = cache.load(path, base_dir, FIELD)?;
            let name = path.display();
            let Some(g) = r.geotransform else {
                return Err(invalid(FIELD, format!("{name} has no geotransform: it cannot place the scene")));
            };
            if !r.crs.is_metric(r.linear_unit_m) {
                return Err(invalid(
                    FIELD,
                    format!(
                        "{name} is in {} ({}): the scene grid needs a projected CRS in metres; reproject it, e.g. `gdalwarp -t_srs EPSG:32756 -tr 10 10 in.tif out.tif`",
                        r.crs.describe(),
                        if matches!(r.crs, Crs::Geographic { .. }) {
                            "degrees"
                        } else if r.linear_unit_m.is_nan() {
                            "its linear unit is not stated in the file: add ProjLinearUnitsGeoKey, e.g. with `gdal_edit.py -a_srs EPSG:…`"
                        } else {
                            "no metric unit"
                        }
                    ),
                ));
            }
            if g[2] != 0.0 || g[4] != 0.0 || g[1] <= 0.0 || g[5] >= 0.0 {
                return Err(invalid(
                    FIELD,
                    format!("{name} is not north-up (geotransform {g:?}); warp it north-up with gdalwarp"),
                ));
            }
            let (dx, dy) = (g[1], -g[5]);
            if (dx - dy).abs() > 1e-3 * dx {
                return Err(invalid(
                    FIELD,
                    format!("{name} has {dx} × {dy} cells; the scene needs square cells (`gdalwarp -tr {dx} {dx}`)"),
                ));
            }
            let extent = Extent { width: r.width, height: r.height, cell_m: dx };
            let centre = (g[0] + 0.5 * r.width as f64 * dx, g[3] - 0.5 * r.height as f64 * dy);
            Ok((GeoFrame { crs: r.crs.clone(), centre }, Some(extent)))
        }
    }
}

/// Scene (x, y), m → fractional (column, row) of the raster's cell centres.
type Locate = Box<dyn Fn(f64, f64) -> Option<(f64, f64)>>;

/// Where each scene cell centre falls in raster `r`, as fractional (col, row) of cell centres:
/// through both geotransforms, or stretched over the scene when the raster has none.
fn locator(
    r: &Arc<Raster>,
    extent: Extent,
    frame: Option<&GeoFrame>,
    field: &str,
    path: &Path,
) -> Result<Locate, SceneError> {
    let name = path.display();
    let (hx, hy) = extent.half_size_m();
    Ok(match (frame, r.geotransform) {
        (Some(f), Some(_)) => {
            let anonymous =
                |c: &Crs| matches!(c, Crs::LocalMetres { name } if name == crate::geotiff::USER_DEFINED_NAME);
            if anonymous(&r.crs) || anonymous(&f.crs) {
                return Err(invalid(
                    field,
                    format!(
                        "{name} or the scene is in a user-defined CRS with no name, which cannot be matched to the other; give both an EPSG code (`gdal_edit.py -a_srs EPSG:…`)"
                    ),
                ));
            }
            if r.crs != f.crs && r.crs != Crs::None {
                return Err(invalid(
                    field,
                    format!(
                        "{name} is in {}, the scene in {}; reproject it with `gdalwarp -t_srs {}`",
                        r.crs.describe(),
                        f.crs.describe(),
                        f.crs.describe()
                    ),
                ));
            }
            let unit = r.linear_unit_m;
            if !(unit.is_finite() && unit > 0.0) {
                return Err(invalid(
                    field,
                    format!(
                        "{name} ({}) does not state its linear unit: add ProjLinearUnitsGeoKey, e.g. with `gdal_edit.py -a_srs {}`",
                        r.crs.describe(),
                        r.crs.describe()
                    ),
                ));
            }
            let (cx, cy) = f.centre;
            let r = Arc::clone(r);
            Box::new(move |x, y| r.pixel(cx + x / unit, cy + y / unit).map(|(c, row)| (c - 0.5, row - 0.5)))
        }
        (None, Some(_)) => {
            return Err(invalid(
                field,
                format!(
                    "{name} is georeferenced ({}) but the scene is not: give the scene `georeference: Some(Raster(\"{name}\"))` (or `Epsg(code: …, centre: (…, …))`) so the map lands where it belongs",
                    r.crs.describe()
                ),
            ));
        }
        // No geotransform: stretched over the scene, top row north (as `Image` maps are).
        (_, None) => {
            let (w, h) = (r.width as f64, r.height as f64);
            Box::new(move |x, y| Some(((x + hx) / (2.0 * hx) * w - 0.5, (hy - y) / (2.0 * hy) * h - 0.5)))
        }
    })
}

/// The values of `source` on the scene grid `extent` (row 0 = south, as maps store them), NaN
/// where the raster has no data.
pub fn resample(
    source: &RasterSource,
    extent: Extent,
    frame: Option<&GeoFrame>,
    field: &str,
    base_dir: Option<&Path>,
    cache: &mut RasterCache,
) -> Result<Vec<f32>, SceneError> {
    let r = cache.load(&source.path, base_dir, field)?;
    let name = source.path.display();
    if source.band == 0 || source.band > r.bands.len() {
        return Err(invalid(field, format!("band {} of {name}: the file has bands 1–{}", source.band, r.bands.len())));
    }
    for (what, v) in [("scale", source.scale), ("offset", source.offset)] {
        if !v.is_finite() {
            return Err(invalid(field, format!("{what} = {v} is not a finite number")));
        }
    }
    let want = field_unit(field);
    if !same_unit(&source.unit, want) {
        return Err(invalid(
            field,
            format!(
                "unit `{}` is not this map's unit `{want}`; convert with scale and offset and state `unit: \"{want}\"`",
                source.unit
            ),
        ));
    }
    let file_unit = &r.units[source.band - 1];
    if !file_unit.is_empty() && source.scale == 1.0 && source.offset == 0.0 && !same_unit(file_unit, want) {
        return Err(invalid(
            field,
            format!(
                "{name} says band {} is in `{file_unit}`, not `{want}`; give the scale and offset that convert it",
                source.band
            ),
        ));
    }
    let nearest =
        source.resampling.unwrap_or(if field == "land.mask" { Resampling::Nearest } else { Resampling::Bilinear })
            == Resampling::Nearest;
    let band = &r.bands[source.band - 1];
    // Nodata is a stored value, compared at Float32 precision too (see `Raster::is_nodata`);
    // GDAL's own band scale and offset unpack the stored value before the map's.
    let nodata = source.nodata.or(r.nodata);
    let missing = |v: f64| v.is_nan() || nodata.is_some_and(|n| v == n || (v as f32) == (n as f32));
    let (file_scale, file_offset) = r.scales.get(source.band - 1).copied().unwrap_or((1.0, 0.0));
    let value = |col: usize, row: usize| {
        let v = band[row * r.width + col];
        if missing(v) { None } else { Some(source.scale * (file_scale * v + file_offset) + source.offset) }
    };
    let locate = locator(&r, extent, frame, field, &source.path)?;
    let (hx, hy) = extent.half_size_m();
    let (w, h) = (r.width as isize, r.height as isize);
    let mut out = Vec::with_capacity(extent.width * extent.height);
    for row in 0..extent.height {
        let y = -hy + (row as f64 + 0.5) * extent.cell_m;
        for col in 0..extent.width {
            let x = -hx + (col as f64 + 0.5) * extent.cell_m;
            let v = locate(x, y).and_then(|(u, v)| {
                // Beyond the raster's outer edge (half a cell past the outer centres): no data.
                if u < -0.5 || v < -0.5 || u > w as f64 - 0.5 || v > h as f64 - 0.5 {
                    return None;
                }
                let at = |c: isize, r: isize| value(c.clamp(0, w - 1) as usize, r.clamp(0, h - 1) as usize);
                if nearest {
                    return at(u.round() as isize, v.round() as isize);
                }
                let (c0, r0) = (u.floor(), v.floor());
                let (fx, fy) = (u - c0, v - r0);
                let (c0, r0) = (c0 as isize, r0 as isize);
                let mut sum = (0.0, 0.0);
                for (dc, dr, wgt) in
                    [(0, 0, (1.0 - fx) * (1.0 - fy)), (1, 0, fx * (1.0 - fy)), (0, 1, (1.0 - fx) * fy), (1, 1, fx * fy)]
                {
                    if wgt > 0.0
                        && let Some(v) = at(c0 + dc, r0 + dr)
                    {
                        sum = (sum.0 + wgt * v, sum.1 + wgt);
                    }
                }
                (sum.1 > 1e-12).then(|| sum.0 / sum.1)
            });
            out.push(v.map_or(f32::NAN, |v| v as f32));
        }
    }
    Ok(out)
}

/// Where `values` (a map on `extent`, NaN = no data) lacks data outside land, say so; on land,
/// hold the median of the valid cells. `is_land(col, row)` reads the scene's land mask.
pub fn fill_nodata(
    values: &mut [f32],
    extent: Extent,
    field: &str,
    frame: Option<&GeoFrame>,
    is_land: &dyn Fn(usize, usize) -> bool,
) -> Result<(), SceneError> {
    let missing: Vec<usize> = (0..values.len()).filter(|&i| values[i].is_nan()).collect();
    if missing.is_empty() {
        return Ok(());
    }
    let water: Vec<usize> = missing.iter().copied().filter(|&i| !is_land(i % extent.width, i / extent.width)).collect();
    if let Some(&first) = water.first() {
        let (col, row) = (first % extent.width, first / extent.width);
        let (hx, hy) = extent.half_size_m();
        let (x, y) = (-hx + (col as f64 + 0.5) * extent.cell_m, -hy + (row as f64 + 0.5) * extent.cell_m);
        let place = match frame {
            Some(f) => format!("{:.1} E, {:.1} N in {}", f.centre.0 + x, f.centre.1 + y, f.crs.describe()),
            None => format!("({x:.0}, {y:.0}) m from the scene centre"),
        };
        return Err(invalid(
            field,
            format!(
                "{} water cells have no data (nodata or outside the raster), the first at {place}; fill them or mark them as land",
                water.len()
            ),
        ));
    }
    let mut valid: Vec<f32> = values.iter().copied().filter(|v| !v.is_nan()).collect();
    if valid.is_empty() {
        return Err(invalid(field, "the raster has no valid cell over the scene".into()));
    }
    let mid = valid.len() / 2;
    let median = *valid.select_nth_unstable_by(mid, f32::total_cmp).1;
    for i in missing {
        values[i] = median;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_agree_however_they_are_written() {
        for (a, b) in [
            ("mg m⁻³", "mg m-3"),
            ("mg/m3", "mg m-3"),
            ("mg m^-3", "mg m-3"),
            ("µg/L", "mg m-3"),
            ("ug L-1", "mg m-3"),
            ("g/m^3", "g m-3"),
            ("mg/L", "g m-3"),
            ("1/m", "m-1"),
            ("m^-1", "m-1"),
            ("metres", "m"),
            ("", "1"),
            ("fraction", "1"),
        ] {
            assert!(same_unit(a, b), "`{a}` should be `{b}`");
        }
        for (a, b) in [("ft", "m"), ("cm", "m"), ("g m-3", "mg m-3"), ("m-1", "m"), ("%", "1")] {
            assert!(!same_unit(a, b), "`{a}` is not `{b}`");
        }
    }
}
