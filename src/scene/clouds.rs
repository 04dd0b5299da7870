//! Clouds over a scene and their shadows on the water: a broken cloud layer at one height whose
//! cover is the fraction the scene asks for, and the geometry that decides, for a ground point
//! seen along a line of sight, whether the instrument sees cloud, the surface in the cloud's
//! shadow, or the surface in the sun.
//!
//! - **Where the clouds are**: a Gaussian random field (`grf`, correlation length `size_m`)
//!   thresholded at its (1 − cover) quantile, so that exactly `cover` of the field's cells are
//!   cloud; between cells the field is interpolated bilinearly and the edge is where it crosses
//!   the threshold. The field is periodic over its raster, so the shadow of a cloud just outside
//!   the scene falls as it would from the cloud opposite (no edge without clouds). Thresholded
//!   Gaussian fields are the standard stochastic model of broken cloud fields (Evans & Wiscombe
//!   2004; Hogan & Kew 2005 use the same construction for cloud-cover statistics).
//! - **What the instrument sees** at ground point p along a view (θv, φv, φv the sensor's
//!   azimuth seen from the ground): the line of sight crosses the cloud layer at height h at
//!   p + h·tan θv·(sin φv, cos φv) (east, north). Cloud there: the pixel is cloud (parallax).
//! - **Shadow**: the sun's ray to p crosses the layer at p + h·tan θs·(sin φs, cos φs). Cloud
//!   there: p lies in the cloud's shadow, lit by the diffuse sky only (the direct beam is
//!   blocked; the cloud's own darkening of the diffuse sky is not modelled).
//! - **Brightness**: the cloud reflects as a Lambertian layer of albedo R from the two-stream
//!   solution for a conservatively scattering layer of optical thickness τ and asymmetry g
//!   (Lacis & Hansen 1974, their non-absorbing layer): R = √3(1 − g)τ / (2 + √3(1 − g)τ), g = 0.85 for water
//!   droplets. Spectrally flat, which holds from the visible to ~1.2 µm; droplet absorption
//!   lowers R in the SWIR windows (1.6, 2.2 µm), not modelled here. The layer reflects from the
//!   surface's level through the whole atmosphere above it (`toa`), which overstates the
//!   molecular attenuation above a cloud top: clouds stay 10⁻¹-bright, what matters for
//!   saturation, stray light and the processor's cloud test.
//!
//! ## References
//! - Lacis, A. A. & Hansen, J. E. (1974) A parameterization for the absorption of solar radiation
//!   in the Earth's atmosphere. J. Atmos. Sci. 31, 118–133.
//! - Evans, K. F. & Wiscombe, W. J. (2004) An algorithm for generating stochastic cloud fields
//!   from radar profile statistics. Atmos. Res. 72, 263–289.
//! - Hogan, R. J. & Kew, S. F. (2005) A 3D stochastic cloud model for investigating the radiative
//!   properties of inhomogeneous cirrus clouds. Q. J. R. Meteorol. Soc. 131, 2585–2608.

use serde::{Deserialize, Serialize};

use super::SceneError;
use super::grf::gaussian_random_field;
use super::map::Extent;
use crate::parse::FieldError;

/// Asymmetry parameter of cloud droplets in the visible (Lacis & Hansen 1974).
pub const DROPLET_ASYMMETRY: f64 = 0.85;

/// Cells per correlation length of the cloud raster (finer adds nothing the bilinear edge does
/// not already give).
const CELLS_PER_SIZE: f64 = 8.0;

/// Cells of the cloud raster at most (a 4096² field: 64 MB while it is synthesised).
const MAX_CELLS: usize = 1 << 24;

/// A broken cloud layer over the scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudLayer {
    /// Fraction of the scene under cloud, 0–1.
    pub cover: f64,
    /// Typical cloud size: the correlation length of the field, m.
    #[serde(default = "default_size_m")]
    pub size_m: f64,
    /// Height of the cloud layer above the water, m: sets the shadow's and the parallax's offsets.
    #[serde(default = "default_height_m")]
    pub height_m: f64,
    /// Optical thickness at 550 nm (its albedo follows, see the module docs).
    #[serde(default = "default_optical_thickness")]
    pub optical_thickness: f64,
    /// Random seed of the field.
    #[serde(default)]
    pub seed: u64,
}

fn default_size_m() -> f64 {
    1000.0
}
fn default_height_m() -> f64 {
    1500.0
}
fn default_optical_thickness() -> f64 {
    20.0
}

impl Default for CloudLayer {
    fn default() -> Self {
        Self {
            cover: 0.3,
            size_m: default_size_m(),
            height_m: default_height_m(),
            optical_thickness: default_optical_thickness(),
            seed: 0,
        }
    }
}

impl CloudLayer {
    /// Check every number against its range.
    pub fn validate(&self) -> Result<(), SceneError> {
        use crate::ranges as r;
        for (range, v) in [
            (&r::SCENE_CLOUDS_COVER, self.cover),
            (&r::SCENE_CLOUDS_SIZE_M, self.size_m),
            (&r::SCENE_CLOUDS_HEIGHT_M, self.height_m),
            (&r::SCENE_CLOUDS_OPTICAL_THICKNESS, self.optical_thickness),
        ] {
            range
                .check(v)
                .map_err(|message| SceneError::Invalid(FieldError { field: range.field("scene.").into(), message }))?;
        }
        Ok(())
    }

    /// The layer's Lambertian albedo: the two-stream reflectance of a conservatively scattering
    /// layer (Lacis & Hansen 1974).
    #[must_use]
    pub fn albedo(&self) -> f64 {
        let x = 3f64.sqrt() * (1.0 - DROPLET_ASYMMETRY) * self.optical_thickness;
        x / (2.0 + x)
    }
}

/// What the instrument sees at a ground point along a line of sight.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sky {
    /// The surface, in the sun.
    Clear,
    /// A cloud between the surface and the sensor.
    Cloud,
    /// The surface, in a cloud's shadow.
    Shadow,
}

/// The cloud layer, rasterised.
#[derive(Debug, Clone)]
pub struct CloudField {
    spec: CloudLayer,
    /// Field values, row-major, row 0 at the south edge.
    values: Vec<f32>,
    width: usize,
    height: usize,
    cell_m: f64,
    /// Cloud where the field is above this.
    threshold: f32,
    /// Offset of the sun's ray at the layer, m (east, north).
    sun_offset_m: (f64, f64),
}

impl CloudField {
    /// The layer of `spec` over a scene of `extent` with the sun at (`sun_zenith_rad`,
    /// `sun_azimuth_rad`).
    pub fn build(
        spec: &CloudLayer,
        extent: Extent,
        sun_zenith_rad: f64,
        sun_azimuth_rad: f64,
    ) -> Result<Self, SceneError> {
        spec.validate()?;
        let (hx, hy) = extent.half_size_m();
        let cell_m = extent.cell_m.max(spec.size_m / CELLS_PER_SIZE);
        let width = ((2.0 * hx / cell_m).ceil() as usize).max(1);
        let height = ((2.0 * hy / cell_m).ceil() as usize).max(1);
        if width.saturating_mul(height) > MAX_CELLS {
            return Err(SceneError::Invalid(FieldError {
                field: "scene.clouds.size_m".into(),
                message: format!(
                    "{} m clouds over a {:.0} × {:.0} m scene need {width} × {height} cells (at most {MAX_CELLS}); give larger clouds",
                    spec.size_m,
                    2.0 * hx,
                    2.0 * hy
                ),
            }));
        }
        let values = gaussian_random_field(width, height, cell_m, spec.size_m, spec.seed);
        let threshold = quantile_threshold(&values, spec.cover);
        let reach = spec.height_m * sun_zenith_rad.tan();
        Ok(Self {
            spec: spec.clone(),
            values,
            width,
            height,
            cell_m,
            threshold,
            sun_offset_m: (reach * sun_azimuth_rad.sin(), reach * sun_azimuth_rad.cos()),
        })
    }

    /// The spec it was built from.
    #[must_use]
    pub fn spec(&self) -> &CloudLayer {
        &self.spec
    }

    /// Bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        self.values.len() * 4
    }

    /// Share of the raster's cells under cloud.
    #[must_use]
    pub fn cell_cover(&self) -> f64 {
        self.values.iter().filter(|v| **v > self.threshold).count() as f64 / self.values.len().max(1) as f64
    }

    /// Is there cloud in the layer above (x, y) m (scene frame)?
    #[must_use]
    pub fn cloud_at(&self, x_m: f64, y_m: f64) -> bool {
        self.value_at(x_m, y_m) > self.threshold
    }

    /// What a sensor at view zenith `view_zenith_rad` and azimuth `view_azimuth_rad` (the
    /// sensor's, seen from the ground) sees at ground point (x, y).
    #[must_use]
    pub fn sky_at(&self, x_m: f64, y_m: f64, view_zenith_rad: f64, view_azimuth_rad: f64) -> Sky {
        let reach = self.spec.height_m * view_zenith_rad.tan();
        if self.cloud_at(x_m + reach * view_azimuth_rad.sin(), y_m + reach * view_azimuth_rad.cos()) {
            Sky::Cloud
        } else if self.cloud_at(x_m + self.sun_offset_m.0, y_m + self.sun_offset_m.1) {
            Sky::Shadow
        } else {
            Sky::Clear
        }
    }

    /// The field at (x, y), bilinear between cell centres, periodic over the raster.
    fn value_at(&self, x_m: f64, y_m: f64) -> f32 {
        let (w, h) = (self.width as f64, self.height as f64);
        // Cell coordinates from the south-west corner, cell centres at k + ½.
        let fx = (x_m / self.cell_m + 0.5 * w - 0.5).rem_euclid(w);
        let fy = (y_m / self.cell_m + 0.5 * h - 0.5).rem_euclid(h);
        let (c0, r0) = (fx.floor() as usize % self.width, fy.floor() as usize % self.height);
        let (c1, r1) = ((c0 + 1) % self.width, (r0 + 1) % self.height);
        let (tx, ty) = ((fx - fx.floor()) as f32, (fy - fy.floor()) as f32);
        let v = |r: usize, c: usize| self.values[r * self.width + c];
        let south = v(r0, c0) + tx * (v(r0, c1) - v(r0, c0));
        let north = v(r1, c0) + tx * (v(r1, c1) - v(r1, c0));
        south + ty * (north - south)
    }
}

/// The value above which `cover` of `values` lie (every value for cover 1, none for cover 0).
fn quantile_threshold(values: &[f32], cover: f64) -> f32 {
    if cover <= 0.0 || values.is_empty() {
        return f32::INFINITY;
    }
    if cover >= 1.0 {
        return f32::NEG_INFINITY;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f32::total_cmp);
    let clear = ((1.0 - cover) * sorted.len() as f64).round() as usize;
    if clear == 0 {
        return f32::NEG_INFINITY;
    }
    sorted[clear - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn extent() -> Extent {
        Extent { width: 200, height: 150, cell_m: 60.0 }
    }

    #[test]
    fn the_field_covers_the_fraction_asked_for() {
        for cover in [0.0, 0.1, 0.35, 0.8, 1.0] {
            let spec = CloudLayer { cover, ..CloudLayer::default() };
            let f = CloudField::build(&spec, extent(), 0.5, 0.0).unwrap();
            // Exactly, on the raster's cells (to one cell in 3 750).
            assert!((f.cell_cover() - cover).abs() < 1.0 / 3000.0, "{cover}: {}", f.cell_cover());
            // At random points between the cells: within 0.02 (the bilinear edge moves each
            // boundary by under a cell; 20 000 points give ±0.004 sampling spread).
            let mut rng = 12345u64;
            let mut next = || {
                rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (rng >> 11) as f64 / (1u64 << 53) as f64
            };
            let (hx, hy) = extent().half_size_m();
            let n = 20_000;
            let hits = (0..n).filter(|_| f.cloud_at((2.0 * next() - 1.0) * hx, (2.0 * next() - 1.0) * hy)).count();
            assert!((hits as f64 / n as f64 - cover).abs() < 0.02, "{cover}: {hits}");
        }
    }

    #[test]
    fn the_shadow_falls_away_from_the_sun_by_height_times_tan_zenith() {
        // Sun at 45° zenith in the east (azimuth 90°): a point is shadowed by the cloud
        // height_m east of it, and sees at nadir the cloud above it.
        let spec = CloudLayer { cover: 0.3, height_m: 1200.0, ..CloudLayer::default() };
        let f = CloudField::build(&spec, extent(), 45f64.to_radians(), 90f64.to_radians()).unwrap();
        let (mut shadows, mut clouds) = (0, 0);
        for i in 0..4000 {
            let (x, y) = (-5000.0 + 2.5 * i as f64, 137.0 + 0.3 * i as f64);
            let sky = f.sky_at(x, y, 0.0, 0.0);
            let cloud_east = f.cloud_at(x + 1200.0, y);
            assert_eq!(sky == Sky::Cloud, f.cloud_at(x, y), "({x}, {y})");
            assert_eq!(sky == Sky::Shadow, !f.cloud_at(x, y) && cloud_east, "({x}, {y})");
            shadows += usize::from(sky == Sky::Shadow);
            clouds += usize::from(sky == Sky::Cloud);
        }
        assert!(shadows > 100 && clouds > 100, "{shadows} {clouds}");
        // A sensor 30° off nadir in the north sees the cloud height·tan 30° north of the point.
        let reach = 1200.0 * 30f64.to_radians().tan();
        for i in 0..2000 {
            let (x, y) = (-3000.0 + 3.0 * i as f64, -800.0);
            let seen = f.sky_at(x, y, 30f64.to_radians(), 0.0) == Sky::Cloud;
            assert_eq!(seen, f.cloud_at(x, y + reach), "({x}, {y})");
        }
    }

    #[test]
    fn albedo_follows_lacis_and_hansen() {
        // τ = 20, g = 0.85: x = √3·0.15·20 = 5.196, R = 5.196/7.196 = 0.7221.
        let spec = CloudLayer { optical_thickness: 20.0, ..CloudLayer::default() };
        assert!((spec.albedo() - 0.722_08).abs() < 1e-4, "{}", spec.albedo());
        let thin = CloudLayer { optical_thickness: 1.0, ..CloudLayer::default() };
        assert!((thin.albedo() - 0.115_0).abs() < 1e-3, "{}", thin.albedo());
    }

    #[test]
    fn bad_numbers_are_refused_naming_the_field() {
        for (spec, field) in [
            (CloudLayer { cover: 1.5, ..CloudLayer::default() }, "cover"),
            (CloudLayer { cover: f64::NAN, ..CloudLayer::default() }, "cover"),
            (CloudLayer { size_m: 0.0, ..CloudLayer::default() }, "size_m"),
            (CloudLayer { height_m: -1.0, ..CloudLayer::default() }, "height_m"),
            (CloudLayer { optical_thickness: 0.0, ..CloudLayer::default() }, "optical_thickness"),
        ] {
            let e = CloudField::build(&spec, extent(), 0.5, 0.0).unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
        // Clouds too small for a large scene: refused before the raster is made.
        let tiny = CloudLayer { size_m: 10.0, ..CloudLayer::default() };
        let big = Extent { width: 20_000, height: 20_000, cell_m: 10.0 };
        assert!(CloudField::build(&tiny, big, 0.5, 0.0).unwrap_err().to_string().contains("size_m"));
    }
}
