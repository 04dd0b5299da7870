//! The processor's cloud and shadow screen: which pixels of an image the correction leaves out
//! because a cloud covers them or shades the water.
//!
//! - **Cloud**: the Rayleigh-corrected reflectance at the band nearest 865 nm above a threshold,
//!   ρ_rc = π(L − L_r − G)/(T·Ed)_r with the family's τ = 0 member as the Rayleigh atmosphere,
//!   or that band saturated. G is the glint the processor expects through that atmosphere,
//!   where it takes glint away (0 otherwise): l2gen's cloud albedo subtracts it the same way
//!   (`setflags.c`: ρ_s − π·TLg/(μ0·F0) at `cloud_wave`), so a glinting sea is not read as
//!   cloud. This is l2gen's cloud albedo test (`cloud_wave` 865/869 nm, `cloud_thresh` 0.027;
//!   Wang & Shi 2006 for its use over turbid water, where bright water can pass it: the
//!   threshold is a setting).
//! - **Shadow**: each cloud pixel's shadow projected on the image from an assumed cloud height
//!   h: the cloud seen at ground point p lies at p + h·tan θv·(sin φv, cos φv) and shades the
//!   ground at that point − h·tan θs·(sin φs, cos φs) (Fmask's geometric shadow projection,
//!   Zhu & Woodcock 2012, which searches h; here it is fixed). Where the scene's clouds are at
//!   another height the projection misses part of the shadow, and that water is retrieved from
//!   darker light.
//!
//! The screen runs where the scene has clouds (`scene.clouds`); a clear scene's products are
//! those of a processor without one.
//!
//! ## References
//! - Wang, M. & Shi, W. (2006) Cloud masking for ocean color data processing in the coastal
//!   regions. IEEE Trans. Geosci. Remote Sens. 44, 3196–3205.
//! - Zhu, Z. & Woodcock, C. E. (2012) Object-based cloud and cloud shadow detection in Landsat
//!   imagery. Remote Sens. Environ. 118, 83–94.

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use super::CorrectionError;
use super::image::invalid;
use crate::calibration::Level1;
use crate::instrument::band_atmosphere::BandTerms;
use crate::instrument::{SurfaceClass, SurfaceMap, Viewing};
use crate::spectral::BandSet;

/// The wavelength of the cloud test, nm (l2gen's `cloud_wave`).
pub const CLOUD_TEST_NM: f64 = 865.0;

/// Settings of the processor's cloud and shadow screen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CloudScreen {
    /// Cloud where the Rayleigh-corrected reflectance at the band nearest 865 nm exceeds this
    /// (l2gen's `cloud_thresh`, 0.027).
    pub threshold: f64,
    /// Cloud height the shadow projection assumes, m (0: no shadow is screened).
    pub height_m: f64,
}

impl Default for CloudScreen {
    fn default() -> Self {
        Self { threshold: 0.027, height_m: 1500.0 }
    }
}

impl CloudScreen {
    /// Check the settings against [`crate::ranges`].
    pub fn validate(&self) -> Result<(), CorrectionError> {
        for (r, v) in [
            (&crate::ranges::CORRECTION_CLOUD_THRESHOLD, self.threshold),
            (&crate::ranges::CORRECTION_CLOUD_HEIGHT_M, self.height_m),
        ] {
            r.check(v).map_err(|m| invalid(r.path, m))?;
        }
        Ok(())
    }
}

/// The sun as the processor knows it (the image's metadata): zenith and azimuth, rad.
#[derive(Debug, Clone, Copy)]
pub struct Sun {
    /// Zenith angle, rad.
    pub zenith_rad: f64,
    /// Azimuth, rad clockwise from north.
    pub azimuth_rad: f64,
}

/// The screen of `level1`: true where the processor flags cloud or cloud shadow. `rayleigh` is
/// the family's τ = 0 member's band terms (every column), with the expected glint folded into
/// its path radiance where the processor takes glint away
/// ([`BandTerms::fold_glint_into_path`]); pixels `surface` calls land are never flagged (the
/// processor knows its land mask, nothing else of the truth).
pub fn screen_image(
    level1: &Level1,
    rayleigh: &BandTerms,
    bands: &BandSet,
    viewing: &Viewing,
    sun: Sun,
    settings: &CloudScreen,
    surface: &SurfaceMap,
) -> Result<Array2<bool>, CorrectionError> {
    let (rows, cols, nb) = level1.radiance.dim();
    let k = bands
        .centres_nm()
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1 - CLOUD_TEST_NM).abs().total_cmp(&(b.1 - CLOUD_TEST_NM).abs()))
        .map(|(k, _)| k)
        .ok_or_else(|| invalid("correction.image.clouds", "no bands".into()))?;
    if rayleigh.l_path.len() < cols * nb || rayleigh.t_ed.len() < cols * nb {
        return Err(invalid("correction.image.clouds", format!("Rayleigh terms for {cols} columns are missing")));
    }
    let saturated = crate::instrument::Flags::SATURATED;
    let land = |r: usize, c: usize| surface.at(r, c) == SurfaceClass::Land;
    let cloud = Array2::from_shape_fn((rows, cols), |(r, c)| {
        if land(r, c) {
            return false;
        }
        let i = c * nb + k;
        let rho =
            std::f64::consts::PI * (f64::from(level1.radiance[[r, c, k]]) - rayleigh.l_path[i]) / rayleigh.t_ed[i];
        rho > settings.threshold || level1.flags[[r, c, k]] & saturated != 0
    });
    let mut screened = cloud.clone();
    if settings.height_m > 0.0 && rows > 0 && cols > 0 {
        let heading = viewing.track_heading_deg();
        let reach_sun = settings.height_m * sun.zenith_rad.tan();
        let to_shadow = (-reach_sun * sun.azimuth_rad.sin(), -reach_sun * sun.azimuth_rad.cos());
        for ((r, c), _) in cloud.indexed_iter().filter(|(_, is)| **is) {
            let (x, y) = viewing.ground_m(0, r, c);
            let look = &viewing.looks[0][c];
            let reach_view = settings.height_m * look.geometry.view_zenith_rad.tan();
            let cloud_x = x + reach_view * look.view_azimuth_rad.sin();
            let cloud_y = y + reach_view * look.view_azimuth_rad.cos();
            if let Some((rs, cs)) = viewing.nearest_pixel(cloud_x + to_shadow.0, cloud_y + to_shadow.1, heading)
                && !land(rs, cs)
            {
                screened[[rs, cs]] = true;
            }
        }
    }
    Ok(screened)
}
