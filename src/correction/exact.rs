//! The exact correction: each pixel inverted with the band-effective atmosphere of its column
//! (the forward model's own terms), y = (L1 − L_path − G)/(T·Ed), Rrs = y/(1 + S·π·y) (the
//! inversion of [`crate::instrument::sample`]'s L = L_path + G + T·Ed·Rrs/(1 − S·π·Rrs)).
//!
//! The inversion of one pixel (`ExactTerms::pixel`) serves the pass over the image and a
//! diagnostic that compares another product with it pixel by pixel without holding it
//! ([`super::SceneApproximation::compare_with_exact`]).

use ndarray::Array2;

use super::apply::{Level1Input, PixelReader, out_buffers};
use super::{CorrectionError, Reflectance, RrsFlags, assemble, flag_for, slice};
use crate::control::RunControl;
use crate::instrument::{AotNodes, BandAtmosphere, SurfaceMap};

/// What the exact inversion of a pixel reads besides its Level-1.
pub struct ExactTerms<'a> {
    atmosphere: &'a BandAtmosphere,
    /// The glint taken away, per column × band.
    glint: &'a [f64],
    /// The terms at the AOT nodes and the AOT under each pixel (row-major), where the AOT is a map.
    aerosol_map: Option<(&'a AotNodes, &'a [f32])>,
    surface: &'a SurfaceMap,
    cols: usize,
    nb: usize,
}

/// A pixel's own atmosphere where the AOT is a map (empty otherwise).
struct PixelTerms {
    l_path: Vec<f64>,
    t_ed: Vec<f64>,
    s_albedo: Vec<f64>,
}

thread_local! {
    /// [`ExactTerms::pixel_of`]'s work space, one per thread (a pixel at a time, from a
    /// comparison's parallel blocks).
    static WORK: std::cell::RefCell<PixelTerms> =
        const { std::cell::RefCell::new(PixelTerms { l_path: Vec::new(), t_ed: Vec::new(), s_albedo: Vec::new() }) };
}

impl<'a> ExactTerms<'a> {
    /// The terms of an image of `cols` columns and `nb` bands: `glint` is the glint taken away,
    /// per column × band: the scene's own (`None`) or what a processor expects from the wind it
    /// assumes ([`super::expected_glint`]); where the scene's AOT is a map, `aerosol_map` holds
    /// the terms at its AOT nodes and the map under each pixel.
    pub fn new(
        (atmosphere, glint): (&'a BandAtmosphere, Option<&'a [f64]>),
        aerosol_map: Option<(&'a AotNodes, &'a Array2<f32>)>,
        surface: &'a SurfaceMap,
        (cols, nb): (usize, usize),
    ) -> Result<Self, CorrectionError> {
        let aerosol_map = match aerosol_map {
            Some((nodes, aot)) => Some((nodes, slice(aot)?)),
            None => None,
        };
        Ok(Self { atmosphere, glint: glint.unwrap_or(&atmosphere.glint), aerosol_map, surface, cols, nb })
    }

    fn work(&self) -> PixelTerms {
        let n = if self.aerosol_map.is_some() { self.nb } else { 0 };
        PixelTerms { l_path: vec![0.0; n], t_ed: vec![0.0; n], s_albedo: vec![0.0; n] }
    }

    /// Pixel (`r`, `c`)'s Rrs and flags into `out` from its Level-1 radiance and flags (`nb`
    /// values each).
    #[inline]
    fn pixel(&self, (r, c): (usize, usize), l1: (&[f32], &[u8]), out: (&mut [f32], &mut [u8]), work: &mut PixelTerms) {
        let nb = self.nb;
        // The column's slices, all of length nb, so the band loop runs without index checks
        // and the compiler can compute neighbouring bands together.
        let a = self.atmosphere.at(c, 0)..self.atmosphere.at(c, 0) + nb;
        let glint = &self.glint[a.clone()];
        let (l_path, t_ed, s_albedo) = match self.aerosol_map {
            Some((nodes, aot)) => {
                let tau = f64::from(aot[r * self.cols + c]);
                nodes.column_terms(c, tau, &mut work.l_path, &mut work.t_ed, &mut work.s_albedo);
                (&work.l_path[..], &work.t_ed[..], &work.s_albedo[..])
            }
            None => {
                let atm = self.atmosphere;
                (&atm.l_path[a.clone()], &atm.t_ed[a.clone()], &atm.spherical_albedo[a])
            }
        };
        let is_land = !self.surface.is_water(r, c);
        let column = ExactColumn { l1: l1.0, l0_flags: l1.1, is_land, l_path, glint, t_ed, s_albedo };
        crate::simd::throughput(Correct { column: &column, rrs_out: out.0, flag_out: out.1 });
    }

    /// Pixel `p` (row-major) of the Level-1 `l1` (radiance and flags, every pixel's `nb`
    /// values in turn) into `values` and `flags`: the exact Rrs made on the fly, the same bits
    /// as [`correct_exact`]'s.
    pub fn pixel_of(&self, p: usize, (l1, l0_flags): (&[f32], &[u8]), values: &mut [f32], flags: &mut [u8]) {
        let span = p * self.nb..(p + 1) * self.nb;
        let at = (p / self.cols.max(1), p % self.cols.max(1));
        WORK.with_borrow_mut(|work| {
            let n = if self.aerosol_map.is_some() { self.nb } else { 0 };
            if work.l_path.len() != n {
                *work = self.work();
            }
            self.pixel(at, (&l1[span.clone()], &l0_flags[span]), (values, flags), work);
        });
    }
}

/// Exact per-pixel correction of `level1` (see the module docs; [`ExactTerms::new`] states the
/// atmosphere, glint and AOT map it takes). A Level-1 handed over ([`Level1Input::Owned`])
/// becomes the Rrs.
pub fn correct_exact<'a>(
    level1: impl Into<Level1Input<'a>>,
    atmosphere: (&BandAtmosphere, Option<&[f64]>),
    aerosol_map: Option<(&AotNodes, &Array2<f32>)>,
    surface: &SurfaceMap,
    control: &RunControl,
) -> Result<Reflectance, CorrectionError> {
    let level1 = level1.into();
    let (rows, cols, nb) = level1.level1().radiance.dim();
    let terms = ExactTerms::new(atmosphere, aerosol_map, surface, (cols, nb))?;
    let mut held = None;
    let (mut rrs, mut flags, read) = out_buffers(level1, &mut held)?;
    let stride = cols * nb;
    control.fill_rows((rrs.as_mut_slice(), flags.as_mut_slice()), rows, stride, |at, (rrs_row, flag_row)| {
        let r = at.index();
        let base = r * stride;
        let mut work = terms.work();
        let mut reader = PixelReader::new(read, nb);
        for c in 0..cols {
            at.column(c);
            let k = c * nb..(c + 1) * nb;
            let l1 = reader.pixel(base, k.clone(), (rrs_row, flag_row));
            terms.pixel((r, c), l1, (&mut rrs_row[k.clone()], &mut flag_row[k]), &mut work);
        }
        Ok::<_, CorrectionError>(())
    })?;
    assemble(rows, cols, nb, rrs, flags)
}

/// One column's inputs to [`correct_exact`], every slice one value per band.
struct ExactColumn<'a> {
    l1: &'a [f32],
    l0_flags: &'a [u8],
    is_land: bool,
    l_path: &'a [f64],
    glint: &'a [f64],
    t_ed: &'a [f64],
    s_albedo: &'a [f64],
}

impl ExactColumn<'_> {
    /// The exact inversion band by band (see the module docs).
    #[inline(always)]
    fn correct(&self, rrs_out: &mut [f32], flag_out: &mut [u8]) {
        let nb = rrs_out.len();
        let (l1, l0_flags) = (&self.l1[..nb], &self.l0_flags[..nb]);
        let (l_path, glint, t_ed, s_albedo) =
            (&self.l_path[..nb], &self.glint[..nb], &self.t_ed[..nb], &self.s_albedo[..nb]);
        let flag_out = &mut flag_out[..nb];
        for b in 0..nb {
            let y = (f64::from(l1[b]) - l_path[b] - glint[b]) / t_ed[b];
            let value = y / (1.0 + s_albedo[b] * std::f64::consts::PI * y);
            let f = flag_for(l0_flags[b], self.is_land, value);
            flag_out[b] = f;
            rrs_out[b] = if f & RrsFlags::INVALID != 0 { 0.0 } else { value as f32 };
        }
    }
}

/// [`ExactColumn::correct`] as a [`crate::simd::Kernel`]: with AVX2, four divisions per
/// instruction, eight with AVX-512 where [`crate::simd::throughput`] takes it (the same
/// operations at every level, so the same bits).
struct Correct<'a, 'c> {
    column: &'a ExactColumn<'c>,
    rrs_out: &'a mut [f32],
    flag_out: &'a mut [u8],
}

impl crate::simd::Kernel for Correct<'_, '_> {
    type Output = ();

    #[inline(always)]
    fn run<L: crate::simd::Level>(self) {
        self.column.correct(self.rrs_out, self.flag_out);
    }
}
