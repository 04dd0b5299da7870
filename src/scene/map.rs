//! Scene maps: the spatial pattern of one water parameter (or a substrate fraction, or the land
//! mask), as written in a scene file and as sampled at any ground position.
//!
//! Coordinates are metres in the scene frame: origin at the scene centre, x east, y north. A map
//! spans width × height cells of `cell_m`; outside it the edge values continue.

use std::path::PathBuf;
use std::sync::Arc;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::SceneError;
use super::grf::gaussian_random_field;
use super::raster::{GeoFrame, RasterCache, RasterSource, Resampling, resample};
use crate::parse::FieldError;

/// The statistical distribution of a random field's values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Distribution {
    /// Normal: mean + std·g.
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        std: f64,
    },
    /// Log-normal: median·exp(σ·g) — for concentrations, which are positive and skewed.
    LogNormal {
        /// Median (geometric mean).
        median: f64,
        /// Standard deviation of the natural logarithm.
        sigma_ln: f64,
    },
}

/// A shape on a background, for bathymetry and patches.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Shape {
    /// An ellipse that sets `value` inside, blending over `edge_m` (logistic edge).
    Ellipse {
        /// Centre (x, y), m.
        centre_m: (f64, f64),
        /// Semi-axes (along its own x, y), m.
        radii_m: (f64, f64),
        /// Rotation anticlockwise from east, degrees.
        #[serde(default)]
        angle_deg: f64,
        /// Value inside.
        value: f64,
        /// Width of the transition, m (0: sharp).
        #[serde(default)]
        edge_m: f64,
    },
    /// A Gaussian bump added to what lies below: amplitude·exp(−r²/(2σ²)).
    Blob {
        /// Centre (x, y), m.
        centre_m: (f64, f64),
        /// Width σ, m.
        sigma_m: f64,
        /// Height (may be negative: a hole).
        amplitude: f64,
    },
    /// A straight ridge (or channel) with a Gaussian cross-section added to what lies below.
    Ridge {
        /// One end (x, y), m.
        from_m: (f64, f64),
        /// Other end (x, y), m.
        to_m: (f64, f64),
        /// Cross-section width σ, m.
        width_m: f64,
        /// Height on the ridge line (negative: a channel).
        amplitude: f64,
    },
}

/// How a map is described in a scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum MapSpec {
    /// The same value everywhere.
    Constant(f64),
    /// Linear from `from` at one edge to `to` at the opposite edge, along the direction
    /// `angle_deg` anticlockwise from east (0: west → east; 90: south → north).
    Gradient {
        /// Value at the starting edge.
        from: f64,
        /// Value at the far edge.
        to: f64,
        /// Direction, degrees anticlockwise from east.
        #[serde(default)]
        angle_deg: f64,
    },
    /// A Gaussian random field (spectral synthesis), optionally clamped.
    RandomField {
        /// Value distribution.
        distribution: Distribution,
        /// Correlation length ℓ of C(r) = exp(−r²/2ℓ²), m.
        correlation_m: f64,
        /// Random seed (the same seed gives the same field).
        seed: u64,
        /// Values are clamped to this range, if given.
        #[serde(default)]
        clamp: Option<(f64, f64)>,
    },
    /// Shapes applied in order over a constant background.
    Shapes {
        /// Background value.
        background: f64,
        /// Shapes, applied in order.
        shapes: Vec<Shape>,
    },
    /// A greyscale image stretched over the scene: black → `min`, white → `max`. A relative path
    /// is taken relative to the scene file.
    Image {
        /// PNG file.
        path: PathBuf,
        /// Value of black.
        min: f64,
        /// Value of white.
        max: f64,
    },
    /// A band of a GeoTIFF, resampled onto the scene's grid through both georeferences (see
    /// [`super::raster`]): `Raster(path: "bathymetry.tif", band: 1, unit: "m")`.
    Raster {
        /// The GeoTIFF (relative to the scene file).
        path: PathBuf,
        /// Band, from 1.
        #[serde(default = "super::raster::one_band")]
        band: usize,
        /// Map value = scale · file value + offset.
        #[serde(default = "super::raster::unit_scale")]
        scale: f64,
        /// See `scale`.
        #[serde(default)]
        offset: f64,
        /// The file value that marks a missing cell (default: the file's `GDAL_NODATA`).
        #[serde(default)]
        nodata: Option<f64>,
        /// Unit of scale · value + offset: the scene field's ("m", "mg m-3", "g m-3", "m-1",
        /// "1" for fractions and the land mask).
        unit: String,
        /// Resampling (default: bilinear; nearest for the land mask).
        #[serde(default)]
        resampling: Option<Resampling>,
    },
}

/// What building a map needs besides its spec: where relative paths start, where the scene is
/// on Earth, and the rasters already read.
#[derive(Debug, Default)]
pub struct MapContext<'a> {
    /// Directory of the scene file.
    pub base_dir: Option<&'a std::path::Path>,
    /// The scene's place on Earth, if georeferenced.
    pub frame: Option<&'a GeoFrame>,
    /// Rasters read so far.
    pub cache: RasterCache,
}

/// The raster extent maps are defined on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    /// Cells along x (east).
    pub width: usize,
    /// Cells along y (north).
    pub height: usize,
    /// Cell size, m.
    pub cell_m: f64,
}

impl Extent {
    /// Scene half-widths (x, y), m.
    #[must_use]
    pub fn half_size_m(&self) -> (f64, f64) {
        (0.5 * self.width as f64 * self.cell_m, 0.5 * self.height as f64 * self.cell_m)
    }

    /// Fractional cell coordinates of (x, y) metres (cell centres at integers).
    fn cell(&self, x_m: f64, y_m: f64) -> (f64, f64) {
        let (hx, hy) = self.half_size_m();
        ((x_m + hx) / self.cell_m - 0.5, (y_m + hy) / self.cell_m - 0.5)
    }
}

/// A map ready to sample.
#[derive(Debug, Clone)]
pub struct Map {
    kind: Kind,
    extent: Extent,
}

#[derive(Debug, Clone)]
enum Kind {
    Constant(f64),
    Gradient { from: f64, to: f64, dir: (f64, f64) },
    Shapes { background: f64, shapes: Vec<Shape> },
    Raster(Arc<Vec<f32>>),
}

fn finite(field: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(SceneError::Invalid(FieldError { field: field.into(), message: format!("{v} is not a finite number") }))
    }
}

impl Map {
    /// Bytes the map holds (a raster's cells; an analytic map holds none).
    #[must_use]
    pub fn bytes(&self) -> usize {
        match &self.kind {
            Kind::Raster(cells) => cells.len() * std::mem::size_of::<f32>(),
            _ => 0,
        }
    }

    /// Build a map over `extent`; `field` names it in errors, `ctx` resolves files. A raster
    /// map may hold NaN where its file has no data (see [`super::raster::fill_nodata`]).
    pub fn build(spec: &MapSpec, extent: Extent, field: &str, ctx: &mut MapContext<'_>) -> Result<Self, SceneError> {
        let base_dir = ctx.base_dir;
        let kind = match spec {
            MapSpec::Constant(v) => {
                finite(field, *v)?;
                Kind::Constant(*v)
            }
            MapSpec::Gradient { from, to, angle_deg } => {
                for v in [from, to, angle_deg] {
                    finite(field, *v)?;
                }
                let a = angle_deg.to_radians();
                Kind::Gradient { from: *from, to: *to, dir: (a.cos(), a.sin()) }
            }
            MapSpec::RandomField { distribution, correlation_m, seed, clamp } => {
                let bad = |m: String| SceneError::Invalid(FieldError { field: field.into(), message: m });
                if !(correlation_m.is_finite() && *correlation_m > 0.0) {
                    return Err(bad(format!("correlation_m = {correlation_m} must be above 0")));
                }
                let g = gaussian_random_field(extent.width, extent.height, extent.cell_m, *correlation_m, *seed);
                let to_value: Box<dyn Fn(f32) -> f64 + Send + Sync> = match *distribution {
                    Distribution::Normal { mean, std } => {
                        finite(field, mean)?;
                        if !(std.is_finite() && std >= 0.0) {
                            return Err(bad(format!("std = {std} must be ≥ 0")));
                        }
                        Box::new(move |x| mean + std * f64::from(x))
                    }
                    Distribution::LogNormal { median, sigma_ln } => {
                        if !(median.is_finite() && median > 0.0 && sigma_ln.is_finite() && sigma_ln >= 0.0) {
                            return Err(bad(format!(
                                "log-normal needs median > 0 and sigma_ln ≥ 0 (got {median}, {sigma_ln})"
                            )));
                        }
                        Box::new(move |x| median * (sigma_ln * f64::from(x)).exp())
                    }
                };
                if let Some((lo, hi)) = clamp
                    && !(lo.is_finite() && hi.is_finite() && lo <= hi)
                {
                    return Err(bad(format!("clamp ({lo}, {hi}) must be finite with min ≤ max")));
                }
                let values = g
                    .par_iter()
                    .map(|x| {
                        let v = to_value(*x);
                        clamp.map_or(v, |(lo, hi)| v.clamp(lo, hi)) as f32
                    })
                    .collect();
                Kind::Raster(Arc::new(values))
            }
            MapSpec::Shapes { background, shapes } => {
                finite(field, *background)?;
                for s in shapes {
                    validate_shape(field, s)?;
                }
                Kind::Shapes { background: *background, shapes: shapes.clone() }
            }
            MapSpec::Image { path, min, max } => {
                finite(field, *min)?;
                finite(field, *max)?;
                let full = match base_dir {
                    Some(d) if path.is_relative() => d.join(path),
                    _ => path.clone(),
                };
                let img = image::open(&full).map_err(|e| {
                    SceneError::Invalid(FieldError {
                        field: field.into(),
                        message: format!("image file `{}`: {e}", full.display()),
                    })
                })?;
                let grey = img.to_luma16();
                let (iw, ih) = grey.dimensions();
                let raw = grey.into_raw();
                // Stretch the image over the raster (bilinear), top image row = north edge.
                let mut values = Vec::with_capacity(extent.width * extent.height);
                for row in 0..extent.height {
                    for col in 0..extent.width {
                        let u = (col as f64 + 0.5) / extent.width as f64 * f64::from(iw) - 0.5;
                        let v = (1.0 - (row as f64 + 0.5) / extent.height as f64) * f64::from(ih) - 0.5;
                        let at = |x: i64, y: i64| {
                            let x = x.clamp(0, i64::from(iw) - 1) as usize;
                            let y = y.clamp(0, i64::from(ih) - 1) as usize;
                            f64::from(raw[y * iw as usize + x]) / 65535.0
                        };
                        let (x0, y0) = (u.floor(), v.floor());
                        let (fx, fy) = (u - x0, v - y0);
                        let (x0, y0) = (x0 as i64, y0 as i64);
                        let g = at(x0, y0) * (1.0 - fx) * (1.0 - fy)
                            + at(x0 + 1, y0) * fx * (1.0 - fy)
                            + at(x0, y0 + 1) * (1.0 - fx) * fy
                            + at(x0 + 1, y0 + 1) * fx * fy;
                        values.push((min + (max - min) * g) as f32);
                    }
                }
                Kind::Raster(Arc::new(values))
            }
            MapSpec::Raster { path, band, scale, offset, nodata, unit, resampling } => {
                let source = RasterSource {
                    path: path.clone(),
                    band: *band,
                    scale: *scale,
                    offset: *offset,
                    nodata: *nodata,
                    unit: unit.clone(),
                    resampling: *resampling,
                };
                Kind::Raster(Arc::new(resample(&source, extent, ctx.frame, field, base_dir, &mut ctx.cache)?))
            }
        };
        Ok(Self { kind, extent })
    }

    /// The value at scene coordinates (x, y) metres.
    #[must_use]
    pub fn value_at(&self, x_m: f64, y_m: f64) -> f64 {
        match &self.kind {
            Kind::Constant(v) => *v,
            Kind::Gradient { from, to, dir } => {
                let (hx, hy) = self.extent.half_size_m();
                // Projection on the direction, scaled so the scene's extreme corners span 0–1.
                let reach = hx * dir.0.abs() + hy * dir.1.abs();
                let t = if reach > 0.0 { 0.5 + 0.5 * (x_m * dir.0 + y_m * dir.1) / reach } else { 0.5 };
                from + (to - from) * t.clamp(0.0, 1.0)
            }
            Kind::Shapes { background, shapes } => shapes.iter().fold(*background, |v, s| apply_shape(s, v, x_m, y_m)),
            Kind::Raster(values) => {
                let e = &self.extent;
                let (cx, cy) = e.cell(x_m, y_m);
                let cx = cx.clamp(0.0, (e.width - 1) as f64);
                let cy = cy.clamp(0.0, (e.height - 1) as f64);
                let (x0, y0) = (cx.floor() as usize, cy.floor() as usize);
                let (x1, y1) = ((x0 + 1).min(e.width - 1), (y0 + 1).min(e.height - 1));
                let (fx, fy) = (cx - x0 as f64, cy - y0 as f64);
                let at = |x: usize, y: usize| f64::from(values[y * e.width + x]);
                at(x0, y0) * (1.0 - fx) * (1.0 - fy)
                    + at(x1, y0) * fx * (1.0 - fy)
                    + at(x0, y1) * (1.0 - fx) * fy
                    + at(x1, y1) * fx * fy
            }
        }
    }

    /// The raster's cell values (row 0 south), if the map is a raster.
    #[must_use]
    pub fn cells(&self) -> Option<&[f32]> {
        match &self.kind {
            Kind::Raster(values) => Some(values.as_slice()),
            _ => None,
        }
    }

    /// The raster's cell values (row 0 south), if the map is a raster, for filling no-data
    /// cells.
    pub fn cells_mut(&mut self) -> Option<&mut [f32]> {
        match &mut self.kind {
            Kind::Raster(values) => Some(Arc::make_mut(values).as_mut_slice()),
            _ => None,
        }
    }

    /// The constant value, if the map is constant (stages use it to skip per-pixel work).
    #[must_use]
    pub fn constant(&self) -> Option<f64> {
        match self.kind {
            Kind::Constant(v) => Some(v),
            _ => None,
        }
    }

    /// Smallest and largest value over the scene's cell centres (for validation and colour
    /// scales).
    #[must_use]
    pub fn range(&self) -> (f64, f64) {
        match &self.kind {
            Kind::Constant(v) => (*v, *v),
            Kind::Raster(values) => values
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(f64::from(*v)), hi.max(f64::from(*v)))),
            _ => {
                let e = &self.extent;
                let (hx, hy) = e.half_size_m();
                let (nx, ny) = (e.width.min(512), e.height.min(512));
                let mut lo = f64::INFINITY;
                let mut hi = f64::NEG_INFINITY;
                for j in 0..ny {
                    for i in 0..nx {
                        let x = -hx + (i as f64 + 0.5) * 2.0 * hx / nx as f64;
                        let y = -hy + (j as f64 + 0.5) * 2.0 * hy / ny as f64;
                        let v = self.value_at(x, y);
                        lo = lo.min(v);
                        hi = hi.max(v);
                    }
                }
                (lo, hi)
            }
        }
    }
}

fn validate_shape(field: &str, s: &Shape) -> Result<(), SceneError> {
    let positive = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(SceneError::Invalid(FieldError {
                field: format!("{field}: {name}"),
                message: format!("{v} must be above 0"),
            }))
        }
    };
    match s {
        Shape::Ellipse { centre_m, radii_m, angle_deg, value, edge_m } => {
            positive("radii_m", radii_m.0)?;
            positive("radii_m", radii_m.1)?;
            for v in [centre_m.0, centre_m.1, *angle_deg, *value, *edge_m] {
                finite(field, v)?;
            }
        }
        Shape::Blob { centre_m, sigma_m, amplitude } => {
            positive("sigma_m", *sigma_m)?;
            for v in [centre_m.0, centre_m.1, *amplitude] {
                finite(field, v)?;
            }
        }
        Shape::Ridge { from_m, to_m, width_m, amplitude } => {
            positive("width_m", *width_m)?;
            for v in [from_m.0, from_m.1, to_m.0, to_m.1, *amplitude] {
                finite(field, v)?;
            }
        }
    }
    Ok(())
}

fn apply_shape(s: &Shape, below: f64, x: f64, y: f64) -> f64 {
    match s {
        Shape::Ellipse { centre_m, radii_m, angle_deg, value, edge_m } => {
            let (dx, dy) = (x - centre_m.0, y - centre_m.1);
            let (c, sn) = (angle_deg.to_radians().cos(), angle_deg.to_radians().sin());
            let (u, v) = ((dx * c + dy * sn) / radii_m.0, (-dx * sn + dy * c) / radii_m.1);
            let r = u.hypot(v);
            // Signed distance to the rim, roughly in metres along the mean radius.
            let d = (r - 1.0) * 0.5 * (radii_m.0 + radii_m.1);
            let inside =
                if *edge_m > 0.0 { 1.0 / (1.0 + (d / (0.25 * edge_m)).exp()) } else { f64::from(u8::from(r <= 1.0)) };
            below + inside * (value - below)
        }
        Shape::Blob { centre_m, sigma_m, amplitude } => {
            let r2 = (x - centre_m.0).powi(2) + (y - centre_m.1).powi(2);
            below + amplitude * (-r2 / (2.0 * sigma_m * sigma_m)).exp()
        }
        Shape::Ridge { from_m, to_m, width_m, amplitude } => {
            let (ax, ay) = (to_m.0 - from_m.0, to_m.1 - from_m.1);
            let len2 = ax * ax + ay * ay;
            let t = if len2 > 0.0 { (((x - from_m.0) * ax + (y - from_m.1) * ay) / len2).clamp(0.0, 1.0) } else { 0.0 };
            let d2 = (x - from_m.0 - t * ax).powi(2) + (y - from_m.1 - t * ay).powi(2);
            below + amplitude * (-d2 / (2.0 * width_m * width_m)).exp()
        }
    }
}

#[cfg(test)]
mod tests;
