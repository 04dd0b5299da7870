//! The image-based correction's per-pixel pass: every pixel's aerosol fit, then every band
//! inverted with the pixel's mixture ([`super::image`] states the method).
//!
//! The Level-1 it reads is either borrowed, and the Rrs goes to new buffers, or handed over
//! ([`Level1Input::Owned`]), and the Rrs is written over it pixel by pixel: each pixel's
//! radiance and flags are copied out before its Rrs is written, so the Rrs is the same either
//! way, and the run holds one cube where it held two (1 GB for Sentinel-2 MSI's 16 million
//! pixels of 13 bands).

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use ndarray::{Array2, Array3};

use super::image::{AerosolRetrieval, Mixture, Pixel};
use super::mixture::invert;
use super::{CorrectionError, Reflectance, RrsFlags, assemble, flag_for, slice};
use crate::calibration::Level1;
use crate::control::{OwnRows, RunControl};
use crate::instrument::SurfaceMap;

/// The Level-1 a correction reads.
pub enum Level1Input<'a> {
    /// Borrowed: the Rrs goes to buffers of its own.
    Borrowed(&'a Level1),
    /// Shared with another holder (a cache): read, as borrowed.
    Shared(Arc<Level1>),
    /// Handed over: the Rrs and its flags are written over its radiance and flags.
    Owned(Level1),
}

impl<'a> From<&'a Level1> for Level1Input<'a> {
    fn from(level1: &'a Level1) -> Self {
        Self::Borrowed(level1)
    }
}

impl From<Level1> for Level1Input<'_> {
    fn from(level1: Level1) -> Self {
        Self::Owned(level1)
    }
}

impl From<Arc<Level1>> for Level1Input<'_> {
    /// Handed over where nothing else holds it, else shared.
    fn from(level1: Arc<Level1>) -> Self {
        match Arc::try_unwrap(level1) {
            Ok(own) => Self::Owned(own),
            Err(shared) => Self::Shared(shared),
        }
    }
}

impl Level1Input<'_> {
    /// The Level-1 to read.
    #[must_use]
    pub fn level1(&self) -> &Level1 {
        match self {
            Self::Borrowed(l) => l,
            Self::Shared(l) => l,
            Self::Owned(l) => l,
        }
    }
}

/// The elements of `a` in standard (row-major) order, without a copy where `a` is laid out so.
fn into_flat<T: Clone>(a: Array3<T>) -> Vec<T> {
    if a.is_standard_layout() {
        let n = a.len();
        let (v, offset) = a.into_raw_vec_and_offset();
        if offset.unwrap_or(0) == 0 && v.len() == n {
            return v;
        }
        let start = offset.unwrap_or(0);
        return v[start..start + n].to_vec();
    }
    a.iter().cloned().collect()
}

/// A Level-1 read in place: its radiance and flags, contiguous.
pub(super) type Read<'a> = (&'a [f32], &'a [u8]);

/// A per-pixel pass's Rrs and flag buffers, and the Level-1 it reads (see [`out_buffers`]).
pub(super) type OutBuffers<'h> = (Vec<f32>, Vec<u8>, Option<Read<'h>>);

/// The Rrs and flag buffers of a per-pixel pass over `level1`, and the Level-1 to read each
/// pixel from: a handed-over Level-1's own buffers (read `None`: each pixel is copied out before
/// it is overwritten, [`PixelReader`]), else new ones, with the Level-1 kept in `held`.
pub(super) fn out_buffers<'h, 'a: 'h>(
    level1: Level1Input<'a>,
    held: &'h mut Option<Level1Input<'a>>,
) -> Result<OutBuffers<'h>, CorrectionError> {
    match level1 {
        Level1Input::Owned(Level1 { radiance, flags }) => Ok((into_flat(radiance), into_flat(flags), None)),
        other => {
            let l = held.insert(other).level1();
            let n = l.radiance.len();
            Ok((vec![0.0; n], vec![0; n], Some((slice(&l.radiance)?, slice(&l.flags)?))))
        }
    }
}

/// One row's pixels as a per-pixel pass reads them: from the Level-1, or copied out of the row
/// the pass is about to overwrite.
pub(super) struct PixelReader<'h> {
    read: Option<Read<'h>>,
    l1: Vec<f32>,
    flags: Vec<u8>,
}

impl<'h> PixelReader<'h> {
    /// A reader of pixels of `nb` bands.
    pub(super) fn new(read: Option<Read<'h>>, nb: usize) -> Self {
        let own = if read.is_some() { 0 } else { nb };
        Self { read, l1: vec![0.0; own], flags: vec![0; own] }
    }

    /// The Level-1 radiance and flags of the pixel at `span` of the row starting at `base`
    /// (`rrs_row`, `flag_row`: the row's output, which holds the Level-1 in place).
    #[inline]
    pub(super) fn pixel(
        &mut self,
        base: usize,
        span: std::ops::Range<usize>,
        (rrs_row, flag_row): (&[f32], &[u8]),
    ) -> (&[f32], &[u8]) {
        match self.read {
            Some((l1, flags)) => (&l1[base + span.start..base + span.end], &flags[base + span.start..base + span.end]),
            None => {
                self.l1.copy_from_slice(&rrs_row[span.clone()]);
                self.flags.copy_from_slice(&flag_row[span]);
                (&self.l1, &self.flags)
            }
        }
    }
}

/// Every pixel through `fit` (which fills the pixel's [`Mixture`] and says whether the pixel is
/// usable), then every band inverted with that mixture; rows in parallel, each with its own
/// scratch `S` (so the result does not depend on the threads). Also returns each pixel's measured
/// aerosol signal at the band pair's long band (NaN where none: not kept, only read to place the
/// members' ε).
pub(super) fn apply<'f, S: Default>(
    level1: Level1Input<'_>,
    surface: &SurfaceMap,
    control: &RunControl,
    fit: impl Fn(&Pixel<'_>, &mut Mixture<'f>, &mut S) -> bool + Sync,
) -> Result<(Reflectance, AerosolRetrieval, Vec<f32>), CorrectionError> {
    let (rows, cols, nb) = level1.level1().radiance.dim();
    let stride = cols * nb;
    // Written in place, row by row (rows of per-row vectors joined at the end held the cube
    // twice); over the Level-1 itself when it is handed over.
    let mut held = None;
    let (mut rrs, mut flags, read) = out_buffers(level1, &mut held)?;
    let (mut aot, mut alpha) = (vec![f32::NAN; rows * cols], vec![f32::NAN; rows * cols]);
    let (mut eps, mut long) = (vec![f32::NAN; rows * cols], vec![f32::NAN; rows * cols]);
    let (outside, passes) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let maps = (OwnRows(aot.as_mut_slice()), OwnRows(alpha.as_mut_slice()));
    let pair = (OwnRows(eps.as_mut_slice()), OwnRows(long.as_mut_slice()));
    let outputs = ((rrs.as_mut_slice(), flags.as_mut_slice()), maps, pair);
    control.fill_rows(
        outputs,
        rows,
        stride,
        |at, ((rrs_row, flag_row), (aot_row, alpha_row), (eps_row, long_row))| {
            let r = at.index();
            let base = r * stride;
            let (mut row_outside, mut row_passes) = (0usize, 0usize);
            let mut scratch = S::default();
            let mut mix = Mixture::default();
            let (mut lp, mut te, mut sa) = (vec![0.0f64; nb], vec![0.0f64; nb], vec![0.0f64; nb]);
            let mut reader = PixelReader::new(read, nb);
            for c in 0..cols {
                at.column(c);
                let span = c * nb..(c + 1) * nb;
                let (l1, l0_flags) = reader.pixel(base, span.clone(), (rrs_row, flag_row));
                let p = Pixel { row: r, col: c, nb, l1, flags: l0_flags, land: !surface.is_water(r, c) };
                mix.entries.clear();
                (mix.outside, mix.passes, mix.epsilon, mix.long_signal) = (false, 1, f64::NAN, f64::NAN);
                let usable = fit(&p, &mut mix, &mut scratch) && !p.land;
                mix.column_terms(span.clone(), &mut lp, &mut te, &mut sa);
                for b in 0..nb {
                    let value = invert(f64::from(p.l1[b]), lp[b], te[b], sa[b]);
                    let f = flag_for(p.flags[b], !usable, value);
                    flag_row[span.start + b] = f;
                    rrs_row[span.start + b] = if f & RrsFlags::INVALID != 0 { 0.0 } else { value as f32 };
                }
                if usable {
                    aot_row[c] = mix.aot550 as f32;
                    alpha_row[c] = mix.angstrom as f32;
                    eps_row[c] = mix.epsilon as f32;
                    long_row[c] = mix.long_signal as f32;
                    row_outside += usize::from(mix.outside);
                    row_passes += mix.passes;
                }
            }
            outside.fetch_add(row_outside, Ordering::Relaxed);
            passes.fetch_add(row_passes, Ordering::Relaxed);
            Ok::<_, CorrectionError>(())
        },
    )?;
    let (outside, passes) = (outside.into_inner(), passes.into_inner());
    let retrieved = aot.iter().filter(|v| v.is_finite()).count();
    let shape = (rows, cols);
    let bad = |e: ndarray::ShapeError| super::image::invalid("cube", e.to_string());
    let mut eps: Vec<f64> = eps.into_iter().filter(|v| v.is_finite()).map(f64::from).collect();
    let mut q = |p: f64| crate::metrics::nearest_rank(&mut eps, p);
    let epsilon = (q(0.5), q(0.05), q(0.95));
    let retrieval = AerosolRetrieval {
        aot550: Array2::from_shape_vec(shape, aot).map_err(bad)?,
        angstrom: Array2::from_shape_vec(shape, alpha).map_err(bad)?,
        outside_family: outside,
        passes_mean: if retrieved == 0 { 0.0 } else { passes as f64 / retrieved as f64 },
        tiles: Vec::new(),
        high_glint: 0,
        glint_removed: false,
        epsilon,
        members_epsilon: Vec::new(),
    };
    Ok((assemble(rows, cols, nb, rrs, flags)?, retrieval, long))
}
