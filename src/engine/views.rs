//! What the app shows of a run's cubes, at a bounded size: the pupil radiance, the true Rrs, the
//! Level-1 radiance and the corrected Rrs of every band at every `stride`-th line and detector,
//! their values unchanged. An engine that keeps views ([`super::Engine::for_app`]) takes them
//! while each cube is at hand and lets the cube go, so a design costs its products and at most
//! [`VIEW_BYTES`] (its share of [`ALL_VIEW_BYTES`] beyond four designs), not its cubes (a
//! 101-band spectrograph's full cubes are 3.2 GB).
//!
//! A map is read back at full resolution with each kept pixel standing for the `stride × stride`
//! block it starts (nearest neighbour), and a spectrum is read at the kept pixel of the block.

use ndarray::{Array2, Array3, ArrayView3, s};

use super::footprint::{Footprint, array_bytes};
use crate::calibration::Level1;
use crate::correction::Reflectance;
use crate::instrument::RadianceCube;

/// The most a run's views may hold, bytes: the stride is the smallest that keeps them under it.
/// At 2 (every other line and detector) for the paper's 19-band, 1024 × 2000 CubeSat (175 MB);
/// at 4 for the 101-band spectrograph (170 MB).
pub const VIEW_BYTES: usize = 192 << 20;

/// The most the views of all the designs the app holds may take together, bytes: each run's
/// views get an equal share, at most [`VIEW_BYTES`] ([`view_bytes_per_run`]). Up to four designs
/// keep [`VIEW_BYTES`] each; eight keep half of it (every third pixel of the paper's CubeSat,
/// 78 MB), as each design's maps on screen shrink with their number: eight designs' four map
/// panels at 1920 pixels are ~370 pixels wide, the CubeSat's third-pixel view 341.
pub const ALL_VIEW_BYTES: usize = 4 * VIEW_BYTES;

/// Each run's share of [`ALL_VIEW_BYTES`] when the app holds `designs` designs, at most
/// [`VIEW_BYTES`].
#[must_use]
pub fn view_bytes_per_run(designs: usize) -> usize {
    VIEW_BYTES.min(ALL_VIEW_BYTES / designs.max(1))
}

/// Bytes of the views per kept pixel and band: four f32 cubes and two u8 flag cubes.
pub const VIEW_BYTES_PER_PIXEL_BAND: usize = 4 * 4 + 2;

/// The smallest stride whose views of a `rows × cols × bands` image fit `budget` bytes.
#[must_use]
pub fn stride_for(rows: usize, cols: usize, bands: usize, budget: usize) -> usize {
    let bytes = |s: usize| rows.div_ceil(s) * cols.div_ceil(s) * bands * VIEW_BYTES_PER_PIXEL_BAND;
    (1..=rows.max(cols).max(1)).find(|&s| bytes(s) <= budget).unwrap_or(rows.max(cols).max(1))
}

/// Every `stride`-th line and detector of a run's cubes.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeViews {
    /// Lines and detectors between kept pixels (1: every pixel).
    pub stride: usize,
    /// The full image's lines and detectors.
    pub full: (usize, usize),
    /// Pupil radiance, W m⁻² sr⁻¹ nm⁻¹ (kept lines, kept detectors, band).
    pub toa: Array3<f32>,
    /// The true Rrs, sr⁻¹.
    pub truth_rrs: Array3<f32>,
    /// Level-1 radiance, W m⁻² sr⁻¹ nm⁻¹, and its flags.
    pub level1: Array3<f32>,
    /// Level-1 flags.
    pub level1_flags: Array3<u8>,
    /// Corrected Rrs, sr⁻¹.
    pub rrs: Array3<f32>,
    /// Rrs flags.
    pub rrs_flags: Array3<u8>,
}

/// Every `stride`-th line and detector of `cube`, owned.
fn every<T: Clone>(cube: &ArrayView3<'_, T>, stride: usize) -> Array3<T> {
    let st = stride as isize;
    cube.slice(s![..;st, ..;st, ..]).to_owned()
}

/// Which view a map is read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewOf {
    /// The pupil radiance.
    Toa,
    /// The true Rrs.
    TruthRrs,
    /// Level-1 radiance.
    Level1,
    /// Corrected Rrs.
    Rrs,
}

impl CubeViews {
    /// The views of a run's pupil radiance and true Rrs at `stride` (Level-1 and Rrs empty until
    /// [`Self::keep_level1`] and [`Self::keep_rrs`]).
    #[must_use]
    pub fn of_radiance(radiance: &RadianceCube, stride: usize) -> Self {
        let stride = stride.max(1);
        let (rows, cols, _) = radiance.radiance.dim();
        let empty = || Array3::zeros((0, 0, 0));
        Self {
            stride,
            full: (rows, cols),
            toa: every(&radiance.radiance.view(), stride),
            truth_rrs: every(&radiance.truth_rrs.view(), stride),
            level1: empty(),
            level1_flags: Array3::zeros((0, 0, 0)),
            rrs: empty(),
            rrs_flags: Array3::zeros((0, 0, 0)),
        }
    }

    /// Keep the view of Level-1.
    pub fn keep_level1(&mut self, level1: &Level1) {
        self.level1 = every(&level1.radiance.view(), self.stride);
        self.level1_flags = every(&level1.flags.view(), self.stride);
    }

    /// Keep the view of the corrected Rrs.
    pub fn keep_rrs(&mut self, rrs: &Reflectance) {
        self.rrs = every(&rrs.rrs.view(), self.stride);
        self.rrs_flags = every(&rrs.flags.view(), self.stride);
    }

    /// The same views cut to fit `budget` bytes, or `None` when they already fit: every k-th
    /// kept line and detector for the smallest k that fits, so that the result is exactly the
    /// views a run at stride `k · stride` takes (a design among more designs than when it ran
    /// gets a smaller share without running again, [`super::Engine::set_view_bytes`]). The
    /// stride may come out coarser than [`stride_for`] would give a new run (every 4th pixel
    /// from every 2nd where every 3rd would fit), never finer.
    #[must_use]
    pub fn within(&self, budget: usize) -> Option<Self> {
        if self.bytes() <= budget {
            return None;
        }
        let (rows, cols, _) = self.toa.dim();
        let per_pixel = self.bytes() / (rows * cols).max(1);
        let bytes = |k: usize| rows.div_ceil(k) * cols.div_ceil(k) * per_pixel;
        let most = rows.max(cols).max(1);
        let k = (2..=most).find(|&k| bytes(k) <= budget).unwrap_or(most);
        Some(Self {
            stride: self.stride * k,
            full: self.full,
            toa: every(&self.toa.view(), k),
            truth_rrs: every(&self.truth_rrs.view(), k),
            level1: every(&self.level1.view(), k),
            level1_flags: every(&self.level1_flags.view(), k),
            rrs: every(&self.rrs.view(), k),
            rrs_flags: every(&self.rrs_flags.view(), k),
        })
    }

    /// The kept pixel standing for full-resolution pixel `(r, c)`.
    #[must_use]
    pub fn kept(&self, (r, c): (usize, usize)) -> (usize, usize) {
        (r / self.stride * self.stride, c / self.stride * self.stride)
    }

    fn cube(&self, of: ViewOf) -> &Array3<f32> {
        match of {
            ViewOf::Toa => &self.toa,
            ViewOf::TruthRrs => &self.truth_rrs,
            ViewOf::Level1 => &self.level1,
            ViewOf::Rrs => &self.rrs,
        }
    }

    /// Band `band` of a view at full resolution (each kept pixel repeated over its block), with
    /// the flags of Level-1 or Rrs (zero for the truth and the pupil radiance); `None` when the
    /// view was not kept or has no such band.
    #[must_use]
    pub fn band(&self, of: ViewOf, band: usize) -> Option<(Array2<f32>, Array2<u8>)> {
        let cube = self.cube(of);
        if band >= cube.dim().2 {
            return None;
        }
        let flags = match of {
            ViewOf::Level1 => Some(&self.level1_flags),
            ViewOf::Rrs => Some(&self.rrs_flags),
            ViewOf::Toa | ViewOf::TruthRrs => None,
        };
        let st = self.stride;
        let values = Array2::from_shape_fn(self.full, |(r, c)| cube[[r / st, c / st, band]]);
        let flags = Array2::from_shape_fn(self.full, |(r, c)| flags.map_or(0, |f| f[[r / st, c / st, band]]));
        Some((values, flags))
    }

    /// Band `band` of a view at the kept pixel standing for `(r, c)`, with its flag.
    #[must_use]
    pub fn at(&self, of: ViewOf, (r, c): (usize, usize), band: usize) -> Option<(f32, u8)> {
        let (i, j) = (r / self.stride, c / self.stride);
        let value = *self.cube(of).get([i, j, band])?;
        let flag = match of {
            ViewOf::Level1 => *self.level1_flags.get([i, j, band])?,
            ViewOf::Rrs => *self.rrs_flags.get([i, j, band])?,
            ViewOf::Toa | ViewOf::TruthRrs => 0,
        };
        Some((value, flag))
    }
}

impl Footprint for CubeViews {
    fn bytes(&self) -> usize {
        array_bytes(&self.toa)
            + array_bytes(&self.truth_rrs)
            + array_bytes(&self.level1)
            + array_bytes(&self.level1_flags)
            + array_bytes(&self.rrs)
            + array_bytes(&self.rrs_flags)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stride_is_the_smallest_that_fits() {
        // The paper's CubeSat: 2000 lines × 1024 detectors × 19 bands is 700 MB at full
        // resolution; every other pixel is 175 MB, under the 192 MiB budget.
        assert_eq!(stride_for(2000, 1024, 19, VIEW_BYTES), 2);
        // The 101-band spectrograph, 1500 × 1000: 2.7 GB in full, 170 MB at every 4th pixel.
        assert_eq!(stride_for(1500, 1000, 101, VIEW_BYTES), 4);
        // A preview that fits keeps every pixel.
        assert_eq!(stride_for(500, 256, 19, VIEW_BYTES), 1);
        // A budget nothing fits: one pixel.
        assert_eq!(stride_for(10, 10, 3, 0), 10);
        assert_eq!(stride_for(0, 0, 3, 0), 1);
    }

    #[test]
    fn eight_designs_share_what_four_keep() {
        assert_eq!(view_bytes_per_run(0), VIEW_BYTES);
        assert_eq!(view_bytes_per_run(2), VIEW_BYTES);
        assert_eq!(view_bytes_per_run(4), VIEW_BYTES);
        assert_eq!(view_bytes_per_run(8), VIEW_BYTES / 2);
        // The paper's CubeSat among eight: every third pixel (78 MB).
        assert_eq!(stride_for(2000, 1024, 19, view_bytes_per_run(8)), 3);
        // From five designs on, all of them together stay within the whole budget.
        assert!((5..=8).all(|d| d * view_bytes_per_run(d) <= ALL_VIEW_BYTES));
    }

    #[test]
    fn views_cut_to_a_smaller_share_are_the_views_of_a_coarser_run() {
        let (rows, cols, bands) = (20, 11, 3);
        let cube =
            |seed: f32| Array3::from_shape_fn((rows, cols, bands), |(r, c, b)| seed + (100 * r + 10 * c + b) as f32);
        let flags = Array3::from_shape_fn((rows, cols, bands), |(r, c, b)| ((r + c + b) % 3) as u8);
        let at = |stride: usize| CubeViews {
            stride,
            full: (rows, cols),
            toa: every(&cube(0.0).view(), stride),
            truth_rrs: every(&cube(0.5).view(), stride),
            level1: every(&cube(0.25).view(), stride),
            level1_flags: every(&flags.view(), stride),
            rrs: every(&cube(0.75).view(), stride),
            rrs_flags: every(&flags.view(), stride),
        };
        let two = at(2);
        // Fits: kept as it is.
        assert_eq!(two.within(two.bytes()), None);
        // Every 3rd pixel of the full cubes would fit 1 byte less than every 2nd's; from the
        // kept every-2nd pixels the next that can be cut is every 4th, the run's own at 4.
        let cut = two.within(two.bytes() - 1).unwrap();
        assert_eq!(cut, at(4));
        assert!(cut.bytes() < two.bytes());
        // A budget nothing fits: one pixel per band, still the run's own.
        let one = two.within(0).unwrap();
        assert_eq!(one.stride, 2 * 10);
        assert_eq!(one.toa.dim(), (1, 1, bands));
        assert_eq!(one.toa[[0, 0, 2]], 2.0);
    }

    #[test]
    fn a_band_at_full_resolution_repeats_each_kept_pixel_over_its_block() {
        let full = Array3::from_shape_fn((5, 3, 2), |(r, c, b)| (100 * r + 10 * c + b) as f32);
        let kept = every(&full.view(), 2);
        assert_eq!(kept.dim(), (3, 2, 2));
        let views = CubeViews {
            stride: 2,
            full: (5, 3),
            toa: kept.clone(),
            truth_rrs: kept.clone(),
            level1: kept.clone(),
            level1_flags: kept.mapv(|v| u8::from(v > 200.0)),
            rrs: kept,
            rrs_flags: Array3::zeros((3, 2, 2)),
        };
        let (band1, flags) = views.band(ViewOf::Level1, 1).unwrap();
        assert_eq!(band1.dim(), (5, 3));
        // (3, 2) is in the block kept at (2, 2): value 100·2 + 10·2 + 1.
        assert_eq!(band1[[3, 2]], 221.0);
        assert_eq!(flags[[3, 2]], 1);
        assert_eq!(band1[[4, 1]], 401.0);
        assert_eq!(views.kept((3, 1)), (2, 0));
        assert_eq!(views.at(ViewOf::Toa, (3, 1), 0), Some((200.0, 0)));
        assert_eq!(views.band(ViewOf::Rrs, 2), None);
        assert_eq!(views.bytes(), 4 * 12 * 4 + 2 * 12);
    }
}
