//! Atmospheric correction, Level-1 → Rrs (Matthews et al. 2023, §2.2.4 and Appendix A).
//!
//! **Exact, per pixel.** The atmosphere the forward model used is known: per detector and band,
//! the band-effective path radiance L_path,b, glint G_b, (T_up·Ed)_b and spherical albedo S_b
//! (see [`crate::instrument::sample`]). Inverting L1 = L_path + G + (T·Ed)·Rrs/(1 − S·π·Rrs)
//! (Vermote et al. 1997, eq. for a Lambertian-coupled target):
//!
//! y = (L1 − L_path − G)/(T·Ed)_b,  Rrs = y/(1 + S_b·π·y).
//!
//! Adjacency is not part of the LUT and is not removed: where a scene has it, it shows as error,
//! as it would for a real processor that ignores it.
//!
//! **The paper's per-scene approximation.** Twenty random water pixels give the view geometry;
//! at each, the path radiance is what remains of the noise-free TOA radiance once the
//! transmitted water-leaving radiance is taken away, L_path = L_TOA − T_up·Lw (eq. A1); their
//! mean path radiance, T_up and Ed(0⁺) are then applied to every pixel: Lw = (L1 − L_path)/T_up
//! (A2), Rrs = Lw/Ed(0⁺) (A3). It ignores the view-angle variation across the swath and the
//! surface–atmosphere coupling term; its error against the exact correction is reported.
//!
//! ## References
//! - Matthews, M. W. et al. (2023) Sensors 23, 7824, Appendix A (equations A1–A3).
//! - Vermote, E. F. et al. (1997) 6S: an overview. IEEE TGRS 35, 675–686.

mod apply;
pub mod clouds;
pub mod dark;
mod difference;
mod exact;
pub mod expected_glint;
pub mod family;
pub mod image;
mod method;
mod mixture;
pub mod nir_water;
mod nodes;
mod pair;
mod rrs_metrics;

pub use apply::Level1Input;
pub use clouds::{CloudScreen, Sun, screen_image};
pub use dark::DarkSpectrumSettings;
pub use dark::TileFit;
pub use difference::{BandDifference, compare};
pub use exact::{ExactTerms, correct_exact};
pub use expected_glint::{column_lgn, expected_glint, mark_high_glint};
pub use family::{AerosolFamily, FamilyLuts};
pub use image::{AerosolFit, AerosolRetrieval, ImageCorrection, MISSION_PAIRS_NM, correct_image};
pub use method::{CorrectionSpec, Method, PRESETS, Preset};
pub use rrs_metrics::{
    BandRrsMetrics, RRS_SAMPLES, TruthRrsSample, band_rrs_metrics, compare_with_truth, pooled_rrs_error,
};

use ndarray::Array3;
use rand::SeedableRng;
use rand::rngs::Xoshiro256PlusPlus;
use serde::Serialize;

use crate::calibration::Level1;
use crate::control::RunControl;
use crate::instrument::{BandAtmosphere, Flags, SurfaceMap};
use crate::parse::FieldError;

/// Errors from the atmospheric correction stage; each names the field and what is allowed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum CorrectionError {
    /// A setting or an input with an invalid value.
    #[error(transparent)]
    Invalid(#[from] FieldError),
    /// The run was cancelled (a newer request superseded it).
    #[error("cancelled")]
    Cancelled,
}

impl crate::control::Cancellable for CorrectionError {
    fn cancelled() -> Self {
        Self::Cancelled
    }

    fn is_cancelled(&self) -> bool {
        matches!(self, Self::Cancelled)
    }
}

/// Flags of the Rrs product (per pixel and band).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RrsFlags;

impl RrsFlags {
    /// Rrs came out negative (noise or over-corrected path radiance).
    pub const NEGATIVE: u8 = 1;
    /// The Level-0 value was saturated.
    pub const SATURATED: u8 = 2;
    /// No valid Rrs: land, zero counts or a non-finite value.
    pub const INVALID: u8 = 4;
    /// Left out by the processor's cloud screen (cloud or cloud shadow; with `INVALID`).
    pub const CLOUD: u8 = 8;
    /// Left out for high glint: the normalised glint L_GN the processor expects from the wind
    /// it assumes exceeds its threshold (l2gen's HIGLINT; with `INVALID`).
    pub const GLINT: u8 = 16;
}

impl CorrectionSpec {
    /// Check `approx_points` against [`crate::ranges::CORRECTION_APPROX_POINTS`], the exact
    /// correction's wind error against [`crate::ranges::CORRECTION_EXACT_GLINT_WIND_ERROR`], its
    /// high-glint threshold against [`crate::ranges::CORRECTION_EXACT_GLINT_THRESHOLD`] and the
    /// image-based correction's settings.
    pub fn validate(&self) -> Result<(), CorrectionError> {
        let threshold = self.glint_threshold_per_sr.map(|t| (&crate::ranges::CORRECTION_EXACT_GLINT_THRESHOLD, t));
        for (range, value) in [
            (&crate::ranges::CORRECTION_APPROX_POINTS, self.approx_points as f64),
            (&crate::ranges::CORRECTION_EXACT_GLINT_WIND_ERROR, self.glint_wind_error_m_s),
        ]
        .into_iter()
        .chain(threshold)
        {
            range
                .check(value)
                .map_err(|message| CorrectionError::Invalid(FieldError { field: range.path.into(), message }))?;
        }
        if let Some(image) = self.image() {
            image.validate()?;
        }
        Ok(())
    }
}

/// Remote-sensing reflectance with flags.
#[derive(Debug, Clone, PartialEq)]
pub struct Reflectance {
    /// Rrs, sr⁻¹, (row, column, band); flagged INVALID pixels hold 0.
    pub rrs: Array3<f32>,
    /// [`RrsFlags`].
    pub flags: Array3<u8>,
}

/// The per-scene terms of the paper's approximation, per band.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneApproximation {
    /// Sampled pixels (row, column).
    pub points: Vec<(usize, usize)>,
    /// Mean path radiance (A1), per band.
    pub l_path: Vec<f64>,
    /// Mean upward transmittance, per band.
    pub t_up: Vec<f64>,
    /// Mean Ed(0⁺), per band.
    pub ed: Vec<f64>,
}

#[inline(always)]
pub(crate) fn flag_for(level0_flags: u8, land: bool, value: f64) -> u8 {
    // Without branches (selects), and finiteness as a comparison: the flags of a column's bands
    // are then computed side by side.
    let saturated = level0_flags & Flags::SATURATED != 0;
    let invalid = land | (level0_flags & (Flags::ZERO | Flags::DEFECTIVE) != 0) | !(value.abs() < f64::INFINITY);
    let negative = !invalid & (value < 0.0);
    (u8::from(saturated) * RrsFlags::SATURATED)
        | (u8::from(invalid) * RrsFlags::INVALID)
        | (u8::from(negative) * RrsFlags::NEGATIVE)
}

/// The contiguous data of a standard-layout array.
pub(crate) fn slice<T, D: ndarray::Dimension>(a: &ndarray::Array<T, D>) -> Result<&[T], CorrectionError> {
    a.as_slice().ok_or_else(|| {
        CorrectionError::Invalid(FieldError { field: "cube".into(), message: "not in standard layout".into() })
    })
}

pub(crate) fn assemble(
    rows: usize,
    cols: usize,
    nb: usize,
    rrs: Vec<f32>,
    flags: Vec<u8>,
) -> Result<Reflectance, CorrectionError> {
    let bad =
        |e: ndarray::ShapeError| CorrectionError::Invalid(FieldError { field: "cube".into(), message: e.to_string() });
    Ok(Reflectance {
        rrs: Array3::from_shape_vec((rows, cols, nb), rrs).map_err(bad)?,
        flags: Array3::from_shape_vec((rows, cols, nb), flags).map_err(bad)?,
    })
}

/// The correction of an image with no water (an overcast look, a view of land): every pixel
/// INVALID, and SATURATED too where Level-1 is, as any method flags a pixel that is not water.
pub fn no_water(level1: &Level1) -> Result<Reflectance, CorrectionError> {
    let (rows, cols, nb) = level1.radiance.dim();
    let flags = slice(&level1.flags)?.iter().map(|&f| flag_for(f, true, 0.0)).collect();
    assemble(rows, cols, nb, vec![0.0; rows * cols * nb], flags)
}

/// [`no_water`] compared with the exact correction ([`compare`]), both made pixel by pixel as
/// the comparison reads them: the per-scene method's diagnostic over an image with no water.
/// `None` when a Level-1 array is not contiguous.
#[must_use]
pub fn no_water_compared_with_exact(level1: &Level1, terms: &ExactTerms<'_>) -> Option<Vec<BandDifference>> {
    compared_with_exact(level1, terms, |_, (_, l0_flags), values, flags| {
        values.fill(0.0);
        for (f, &l0) in flags.iter_mut().zip(l0_flags) {
            *f = flag_for(l0, true, 0.0);
        }
    })
}

/// A product made pixel by pixel by `product(p, pixel's Level-1 radiance and flags, values,
/// flags)` compared with the exact correction made pixel by pixel with `terms` ([`compare`]'s
/// figures; neither is held whole). `None` when a Level-1 array is not contiguous.
fn compared_with_exact(
    level1: &Level1,
    terms: &ExactTerms<'_>,
    product: impl Fn(usize, apply::Read<'_>, &mut [f32], &mut [u8]) + Sync,
) -> Option<Vec<BandDifference>> {
    let (rows, cols, nb) = level1.radiance.dim();
    let (l1, l0_flags) = (slice(&level1.radiance).ok()?, slice(&level1.flags).ok()?);
    let pixel = |p: usize, values: &mut [f32], flags: &mut [u8]| {
        let span = p * nb..(p + 1) * nb;
        product(p, (&l1[span.clone()], &l0_flags[span]), values, flags);
    };
    let exact = |p: usize, values: &mut [f32], flags: &mut [u8]| terms.pixel_of(p, (l1, l0_flags), values, flags);
    Some(difference::compare_both_pixels(&pixel, &exact, rows * cols, nb))
}

impl SceneApproximation {
    /// The paper's per-scene terms from `points` random water pixels (seeded), using the
    /// noise-free TOA radiance and the true Rrs of those pixels: open water, out of the clouds'
    /// shadows, wherever the image has some. `None` when the image holds no water at all (an
    /// overcast look, a view of land): there is nothing to estimate the terms from, and nothing
    /// they would correct.
    pub fn new(
        toa_radiance: &Array3<f32>,
        truth_rrs: &Array3<f32>,
        atmosphere: &BandAtmosphere,
        surface: &SurfaceMap,
        points: usize,
        seed: u64,
    ) -> Result<Option<Self>, CorrectionError> {
        let (rows, cols, nb) = toa_radiance.dim();
        if points == 0 {
            return Err(CorrectionError::Invalid(FieldError {
                field: "correction.approx_points".into(),
                message: "0 water pixels asked for: the approximation needs at least 1".into(),
            }));
        }
        // Open water only where there is some: in a cloud's shadow the direct sun is missing from
        // the water's irradiance, and A1 would take the missing part for path radiance.
        let n_open = (0..rows * cols).filter(|&i| surface.is_open_water_at(i)).count();
        let sampled = |i: usize| if n_open > 0 { surface.is_open_water_at(i) } else { surface.is_water_at(i) };
        let n_water = if n_open > 0 { n_open } else { surface.water_count() };
        if n_water == 0 {
            return Ok(None);
        }
        // Distinct water pixels drawn uniformly: indices among the water pixels, then located.
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0xA7C0_11EC);
        let mut picks: Vec<usize> = rand::seq::index::sample(&mut rng, n_water, points.min(n_water)).into_vec();
        picks.sort_unstable();
        let mut chosen = Vec::with_capacity(picks.len());
        let mut k = 0;
        for i in 0..rows * cols {
            if sampled(i) {
                if picks.binary_search(&k).is_ok() {
                    chosen.push((i / cols, i % cols));
                }
                k += 1;
            }
        }
        let n = chosen.len() as f64;
        let (mut l_path, mut t_up, mut ed) = (vec![0.0; nb], vec![0.0; nb], vec![0.0; nb]);
        for &(r, c) in &chosen {
            for b in 0..nb {
                let i = atmosphere.at(c, b);
                let (e, te, s) = (atmosphere.ed[i], atmosphere.t_ed[i], atmosphere.spherical_albedo[i]);
                let rrs = f64::from(truth_rrs[[r, c, b]]);
                // Water-leaving radiance with the surface–atmosphere coupling, as an RT code gives it.
                let lw = rrs * e / (1.0 - s * std::f64::consts::PI * rrs);
                let t = te / e;
                l_path[b] += (f64::from(toa_radiance[[r, c, b]]) - t * lw) / n;
                t_up[b] += t / n;
                ed[b] += e / n;
            }
        }
        Ok(Some(Self { points: chosen, l_path, t_up, ed }))
    }

    /// Band `b`'s Rrs and flags from its Level-1 radiance and flags (A1–A3 inverted).
    #[inline]
    fn value(&self, b: usize, level1: f32, level1_flags: u8, land: bool) -> (f32, u8) {
        let lw = (f64::from(level1) - self.l_path[b]) / self.t_up[b];
        let value = lw / self.ed[b];
        let f = flag_for(level1_flags, land, value);
        (if f & RrsFlags::INVALID != 0 { 0.0 } else { value as f32 }, f)
    }

    /// One pixel's Rrs and flags into `out` from its Level-1 radiance and flags (`nb` values
    /// each; `land`: the pixel is not water).
    #[inline]
    fn pixel(&self, (l1, l1_flags): apply::Read<'_>, land: bool, (values, flags): (&mut [f32], &mut [u8])) {
        for b in 0..values.len() {
            (values[b], flags[b]) = self.value(b, l1[b], l1_flags[b], land);
        }
    }

    /// [`Self::correct`] compared with the exact correction made pixel by pixel with `terms` (the
    /// same values as [`correct_exact`]'s cube; [`compare`]'s figures): neither product is held,
    /// so either can then write its Rrs over the Level-1. `None` when a Level-1 array is not
    /// contiguous.
    #[must_use]
    pub fn compare_with_exact(
        &self,
        level1: &Level1,
        surface: &SurfaceMap,
        terms: &exact::ExactTerms<'_>,
    ) -> Option<Vec<BandDifference>> {
        let cols = level1.radiance.dim().1.max(1);
        compared_with_exact(level1, terms, |p, l1, values, flags| {
            self.pixel(l1, !surface.is_water(p / cols, p % cols), (values, flags));
        })
    }

    /// Apply the per-scene terms to every pixel (A2, A3). A Level-1 handed over
    /// ([`Level1Input::Owned`]) becomes the Rrs: each value is read before it is overwritten.
    pub fn correct<'a>(
        &self,
        level1: impl Into<Level1Input<'a>>,
        surface: &SurfaceMap,
        control: &RunControl,
    ) -> Result<Reflectance, CorrectionError> {
        let level1 = level1.into();
        let (rows, cols, nb) = level1.level1().radiance.dim();
        let mut held = None;
        let (mut rrs, mut flags, read) = apply::out_buffers(level1, &mut held)?;
        let stride = cols * nb;
        control.fill_rows((rrs.as_mut_slice(), flags.as_mut_slice()), rows, stride, |at, (rrs_row, flag_row)| {
            let r = at.index();
            let base = r * stride;
            let mut reader = apply::PixelReader::new(read, nb);
            for c in 0..cols {
                at.column(c);
                let k = c * nb..(c + 1) * nb;
                let l1 = reader.pixel(base, k.clone(), (rrs_row, flag_row));
                self.pixel(l1, !surface.is_water(r, c), (&mut rrs_row[k.clone()], &mut flag_row[k]));
            }
            Ok::<_, CorrectionError>(())
        })?;
        assemble(rows, cols, nb, rrs, flags)
    }
}
