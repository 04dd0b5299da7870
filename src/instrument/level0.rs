//! Whole-image exposure and readout: band radiance cube → electrons cube → Level-0.
//!
//! Two stages, so that a change of the electronics (gain, bias, ADC bits, read noise) re-runs
//! only the readout and never the photon counts; or one pass row by row
//! ([`expose_and_digitise`]) for a run that keeps no cubes. Each pixel draws its noise from its own
//! generator (see [`super::detector`]): results do not depend on the number of threads.

use ndarray::Array3;

use super::InstrumentError;
use super::detector::{Detector, Stream, normal, pixel_rng};
use super::geometry::Viewing;
use crate::control::RunControl;
use crate::parse::FieldError;

/// Level-0: raw counts with flags.
#[derive(Debug, Clone, PartialEq)]
pub struct Level0 {
    /// Digital numbers, (row, column, band).
    pub dn: Array3<u16>,
    /// The analogue DN before quantisation, kept only when quantisation is off (the ideal-ADC
    /// closure setting), so Level-1 can be computed without quantisation error.
    pub analog: Option<Array3<f32>>,
    /// [`super::Flags`] per pixel and band.
    pub flags: Array3<u8>,
    /// Values flagged [`super::Flags::SATURATED`].
    pub saturated: usize,
    /// Values flagged [`super::Flags::ZERO`].
    pub zero_counts: usize,
    /// What on-board compression did to the counts (`None`: not compressed).
    pub compression: Option<super::compression::CompressionReport>,
}

impl Level0 {
    /// The value calibration uses at (row, column, band).
    #[must_use]
    pub fn value(&self, r: usize, c: usize, b: usize) -> f64 {
        match &self.analog {
            Some(a) => f64::from(a[[r, c, b]]),
            None => f64::from(self.dn[[r, c, b]]),
        }
    }
}

/// The generator of a coarse focal plane's pixel: plane `plane`, native line `line` and detector
/// `detector` (the grid's divided by the plane's block), kept apart from the first plane's by
/// the plane in the seed. Every grid pixel of the block draws the same values.
fn plane_rng(seed: u64, stream: Stream, plane: usize, line: usize, detector: usize) -> rand::rngs::Xoshiro256PlusPlus {
    pixel_rng(super::detector::mix64(seed ^ (plane as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)), stream, line, detector)
}

/// Does every band sample the grid pixel by pixel (one focal plane, or no coarse one)? Then a
/// pixel's draws come from its own generator in band order, with no lookup per band.
fn on_grid(detector: &Detector) -> bool {
    detector.planes().iter().all(|p| p.block() == 1)
}

/// Draw one value per band of the pixel at grid `line`, `detector` into `out` with `draw`: the
/// bands of planes that sample the grid pixel by pixel from the pixel's own generator in band
/// order (a one-plane instrument's draws are what they were before focal planes existed), each
/// coarse plane's bands from its block's generator ([`plane_rng`]).
fn draw_bands(
    detector: &Detector,
    seed: u64,
    stream: Stream,
    line: usize,
    j: usize,
    out: &mut [f64],
    mut draw: impl FnMut(usize, &mut rand::rngs::Xoshiro256PlusPlus) -> f64,
) {
    let mut rng = pixel_rng(seed, stream, line, j);
    for (b, o) in out.iter_mut().enumerate() {
        if detector.plane(b).block() == 1 {
            *o = draw(b, &mut rng);
        }
    }
    for (p, plane) in detector.planes().iter().enumerate().filter(|(_, q)| q.block() > 1) {
        let k = plane.block();
        let mut rng = plane_rng(seed, stream, p, line / k, j / k);
        for (b, o) in out.iter_mut().enumerate() {
            if detector.plane_index(b) == p {
                *o = draw(b, &mut rng);
            }
        }
    }
}

/// The block of each grid line (or detector) `index` for blocks `k` wide, numbered from 0 in
/// the order they come, and their number: consecutive grid lines in one plane pixel share an
/// id, so each block row is a run of grid rows.
fn block_ids(index: &[usize], k: usize) -> (Vec<usize>, usize) {
    let mut ids = Vec::with_capacity(index.len());
    let (mut last, mut n) = (usize::MAX, 0);
    for &v in index {
        if v / k != last {
            last = v / k;
            n += 1;
        }
        ids.push(n - 1);
    }
    (ids, n)
}

/// Each coarse focal plane's pixel values: the mean radiance of the k × k block of grid pixels a
/// plane pixel reads (as far as the grid is simulated), held once per block and band. (A copy of
/// the cube with the means spread over its blocks held the cube twice: 0.8 GB for Sentinel-2
/// MSI's 16 million pixels.)
struct BlockMeans {
    /// One table per block size.
    groups: Vec<Blocks>,
    /// Band b's table and slot in it; `None` for a band that samples the grid pixel by pixel.
    of_band: Vec<Option<(usize, usize)>>,
}

/// The blocks of one size k: the block row of each grid row, the block column of each grid
/// column, and the means, `[block row][block column][slot]` with a slot per band of that size.
struct Blocks {
    row_id: Vec<usize>,
    col_id: Vec<usize>,
    n_c: usize,
    slots: usize,
    means: Vec<f32>,
}

impl BlockMeans {
    /// The block means of `radiance` (rows of `cols` pixels of `nb` bands; grid row r is line
    /// `lines[r]`, grid column c detector `detectors[c]`), band b's blocks `block[b]` lines and
    /// detectors wide; `None` without a block wider than 1. Each block's sum runs over its rows,
    /// then its columns, in order (in parallel over block rows, so the same sums whatever the
    /// threads).
    fn new(block: &[usize], radiance: &[f32], (lines, detectors): (&[usize], &[usize]), cols: usize) -> Option<Self> {
        use rayon::prelude::*;
        let nb = block.len();
        let mut sizes: Vec<usize> = block.iter().copied().filter(|&k| k > 1).collect();
        if sizes.is_empty() {
            return None;
        }
        sizes.sort_unstable();
        sizes.dedup();
        let rows = radiance.len() / (cols * nb).max(1);
        let mut of_band = vec![None; nb];
        let groups = sizes
            .iter()
            .enumerate()
            .map(|(g, &k)| {
                let bands: Vec<usize> = (0..nb).filter(|&b| block[b] == k).collect();
                for (slot, &b) in bands.iter().enumerate() {
                    of_band[b] = Some((g, slot));
                }
                let (row_id, n_r) = block_ids(&lines[..rows], k);
                let (col_id, n_c) = block_ids(&detectors[..cols], k);
                let mut first_row = vec![rows; n_r + 1];
                for (r, &id) in row_id.iter().enumerate().rev() {
                    first_row[id] = r;
                }
                let slots = bands.len();
                let mut means = vec![0.0f32; n_r * n_c * slots];
                means.par_chunks_mut((n_c * slots).max(1)).enumerate().for_each(|(block_row, out)| {
                    let (mut sum, mut count) = (vec![0.0f64; n_c * slots], vec![0u32; n_c]);
                    for r in first_row[block_row]..first_row[block_row + 1] {
                        for (c, &id) in col_id.iter().enumerate() {
                            let pixel = &radiance[(r * cols + c) * nb..(r * cols + c + 1) * nb];
                            for (s, &b) in bands.iter().enumerate() {
                                sum[id * slots + s] += f64::from(pixel[b]);
                            }
                            count[id] += 1;
                        }
                    }
                    for (i, (o, s)) in out.iter_mut().zip(&sum).enumerate() {
                        *o = (s / f64::from(count[i / slots].max(1))) as f32;
                    }
                });
                Blocks { row_id, col_id, n_c, slots, means }
            })
            .collect();
        Some(Self { groups, of_band })
    }

    /// The value band `b` of grid pixel (`r`, `c`) reads: its block's mean, or `own` for a band
    /// that samples the grid pixel by pixel.
    #[inline]
    fn value(&self, r: usize, c: usize, b: usize, own: f32) -> f32 {
        match self.of_band[b] {
            None => own,
            Some((g, slot)) => {
                let t = &self.groups[g];
                t.means[(t.row_id[r] * t.n_c + t.col_id[c]) * t.slots + slot]
            }
        }
    }
}

fn shape_error(e: ndarray::ShapeError) -> InstrumentError {
    InstrumentError::Invalid(FieldError { field: "cube".into(), message: e.to_string() })
}

/// The radiance cube as one slice (row, column, band), and the means a coarse focal plane's
/// pixels see ([`BlockMeans`]).
fn exposure_input<'a>(
    detector: &Detector,
    radiance: &'a Array3<f32>,
    viewing: &Viewing,
) -> Result<(&'a [f32], Option<BlockMeans>), InstrumentError> {
    let (_, cols, nb) = radiance.dim();
    let input = radiance.as_slice().ok_or_else(|| {
        InstrumentError::Invalid(FieldError { field: "cube".into(), message: "not contiguous".into() })
    })?;
    let block: Vec<usize> = (0..nb).map(|b| detector.plane(b).block()).collect();
    let indices = (viewing.line_index.as_slice(), viewing.detector_index.as_slice());
    Ok((input, BlockMeans::new(&block, input, indices, cols)))
}

/// Row `r`'s electrons from `input` (the row's radiance, column after column of `nb` bands;
/// a coarse plane's bands read their block's mean from `means`) into `row`: photo-electrons,
/// dark signal, shot noise, full well.
fn expose_row(
    detector: &Detector,
    (input, means, nb): (&[f32], Option<&BlockMeans>, usize),
    viewing: &Viewing,
    seed: u64,
    at: &mut crate::control::RowGuard<'_>,
    row: &mut [f32],
) {
    let r = at.index();
    let cols = row.len() / nb.max(1);
    let t = detector.exposure_s();
    let line = viewing.line_index[r];
    let mut e = vec![0.0f64; nb];
    let every_band_on_grid = on_grid(detector);
    for c in 0..cols {
        at.column(c);
        let j = viewing.detector_index[c];
        let pixel = &input[c * nb..(c + 1) * nb];
        if every_band_on_grid {
            // The pixel's own generator, band after band, straight into the row (the loop
            // the one-plane instruments of the default study spend their Level-0 time in).
            let mut rng = pixel_rng(seed, Stream::Exposure, line, j);
            for (b, o) in row[c * nb..(c + 1) * nb].iter_mut().enumerate() {
                *o = detector.expose(j, b, f64::from(pixel[b]), t, &mut rng) as f32;
            }
            continue;
        }
        let seen = |b: usize| means.map_or(pixel[b], |m| m.value(r, c, b, pixel[b]));
        draw_bands(detector, seed, Stream::Exposure, line, j, &mut e, |b, rng| {
            detector.expose(j, b, f64::from(seen(b)), t, rng)
        });
        for (o, v) in row[c * nb..(c + 1) * nb].iter_mut().zip(&e) {
            *o = *v as f32;
        }
    }
}

/// Electrons collected by every pixel from `radiance` (row, column, band) at the nominal
/// exposure: photo-electrons, dark signal, shot noise, full well.
pub fn expose_cube(
    detector: &Detector,
    radiance: &Array3<f32>,
    viewing: &Viewing,
    seed: u64,
    control: &RunControl,
) -> Result<Array3<f32>, InstrumentError> {
    let (rows, cols, nb) = radiance.dim();
    let (input, means) = exposure_input(detector, radiance, viewing)?;
    let mut out = vec![0.0f32; rows * cols * nb];
    control.fill_rows(out.as_mut_slice(), rows, cols * nb, |at, row| {
        let r = at.index();
        let row_input = &input[r * cols * nb..(r + 1) * cols * nb];
        expose_row(detector, (row_input, means.as_ref(), nb), viewing, seed, at, row);
        Ok::<_, InstrumentError>(())
    })?;
    Array3::from_shape_vec((rows, cols, nb), out).map_err(shape_error)
}

/// One row of Level-0 outputs: counts, flags and (without quantisation) the analogue signal.
type Level0Row<'r> = (&'r mut [u16], &'r mut [u8], &'r mut [f32]);

/// Row `r` of `electrons` read out into `outputs`: read noise, gain, bias, ADC; flags.
fn read_out_row(
    detector: &Detector,
    (electrons, nb): (&[f32], usize),
    viewing: &Viewing,
    seed: u64,
    at: &mut crate::control::RowGuard<'_>,
    (dn_row, flag_row, analog_row): Level0Row<'_>,
) {
    let r = at.index();
    let cols = electrons.len() / nb.max(1);
    let line = viewing.line_index[r];
    let noise = detector.mode().noise;
    // The row's read-noise draws first, pixel by pixel from each pixel's generator, then the
    // arithmetic over the whole row in vector lanes. Every column is visited, with the noise
    // off too, so that a fault armed at a pixel fires there.
    let mut z = vec![0.0; cols * nb];
    let every_band_on_grid = on_grid(detector);
    for c in 0..cols {
        at.column(c);
        if noise && every_band_on_grid {
            let mut rng = pixel_rng(seed, Stream::Readout, line, viewing.detector_index[c]);
            z[c * nb..(c + 1) * nb].iter_mut().for_each(|z| *z = normal(&mut rng));
        } else if noise {
            let j = viewing.detector_index[c];
            draw_bands(detector, seed, Stream::Readout, line, j, &mut z[c * nb..(c + 1) * nb], |_, rng| normal(rng));
        }
    }
    // One converter per band; per column too where the response curve differs between columns.
    let elements: Vec<(usize, usize)> = if detector.curve_varies_by_column() {
        (0..cols).flat_map(|c| (0..nb).map(move |b| (viewing.detector_index[c], b))).collect()
    } else {
        (0..nb).map(|b| (0, b)).collect()
    };
    let keep_analog = !detector.mode().quantise;
    detector.read_out_run(&elements, electrons, &z, dn_row, flag_row, keep_analog.then_some(analog_row));
}

/// Level-0 buffers for `n` values, and the cube they make.
struct Level0Buffers {
    dn: Vec<u16>,
    flags: Vec<u8>,
    analog: Vec<f32>,
}

impl Level0Buffers {
    fn new(detector: &Detector, n: usize) -> Self {
        let keep_analog = !detector.mode().quantise;
        Self { dn: vec![0; n], flags: vec![0; n], analog: vec![0.0; if keep_analog { n } else { 0 }] }
    }

    fn into_level0(self, shape: (usize, usize, usize)) -> Result<Level0, InstrumentError> {
        let (saturated, zero_counts) = count_flags(&self.flags);
        let analog = (!self.analog.is_empty()).then_some(self.analog);
        Ok(Level0 {
            dn: Array3::from_shape_vec(shape, self.dn).map_err(shape_error)?,
            analog: analog.map(|a| Array3::from_shape_vec(shape, a)).transpose().map_err(shape_error)?,
            flags: Array3::from_shape_vec(shape, self.flags).map_err(shape_error)?,
            saturated,
            zero_counts,
            compression: None,
        })
    }
}

/// Read out every pixel: read noise, gain, bias, ADC; flags for saturation and zero counts.
pub fn digitise_cube(
    detector: &Detector,
    electrons: &Array3<f32>,
    viewing: &Viewing,
    seed: u64,
    control: &RunControl,
) -> Result<Level0, InstrumentError> {
    let (rows, cols, nb) = electrons.dim();
    let input = electrons.as_slice().ok_or_else(|| {
        InstrumentError::Invalid(FieldError { field: "cube".into(), message: "not contiguous".into() })
    })?;
    let mut out = Level0Buffers::new(detector, rows * cols * nb);
    let outputs = (out.dn.as_mut_slice(), out.flags.as_mut_slice(), out.analog.as_mut_slice());
    control.fill_rows(outputs, rows, cols * nb, |at, row| {
        let r = at.index();
        read_out_row(detector, (&input[r * cols * nb..(r + 1) * cols * nb], nb), viewing, seed, at, row);
        Ok::<_, InstrumentError>(())
    })?;
    out.into_level0((rows, cols, nb))
}

/// [`expose_cube`] then [`digitise_cube`] row by row, without the electrons cube: the same
/// counts and flags bit for bit (each pixel draws from its own generators, one per stream),
/// for a run that would not keep the electrons anyway (it cannot rerun only the readout).
pub fn expose_and_digitise(
    detector: &Detector,
    radiance: &Array3<f32>,
    viewing: &Viewing,
    seed: u64,
    control: &RunControl,
) -> Result<Level0, InstrumentError> {
    let (rows, cols, nb) = radiance.dim();
    let (input, means) = exposure_input(detector, radiance, viewing)?;
    let mut out = Level0Buffers::new(detector, rows * cols * nb);
    let outputs = (out.dn.as_mut_slice(), out.flags.as_mut_slice(), out.analog.as_mut_slice());
    control.fill_rows(outputs, rows, cols * nb, |at, row| {
        let r = at.index();
        let mut electrons = vec![0.0f32; cols * nb];
        let row_input = &input[r * cols * nb..(r + 1) * cols * nb];
        expose_row(detector, (row_input, means.as_ref(), nb), viewing, seed, at, &mut electrons);
        read_out_row(detector, (&electrons, nb), viewing, seed, at, row);
        Ok::<_, InstrumentError>(())
    })?;
    out.into_level0((rows, cols, nb))
}

/// Values flagged saturated and zero, counted in one parallel pass (two filtered counts on one
/// thread were 4 % of a preview after a gain change).
fn count_flags(flags: &[u8]) -> (usize, usize) {
    use super::Flags;
    use rayon::prelude::*;
    flags
        .par_chunks(1 << 16)
        .map(|chunk| {
            chunk.iter().fold((0, 0), |(s, z), &f| {
                (s + usize::from(f & Flags::SATURATED != 0), z + usize::from(f & Flags::ZERO != 0))
            })
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

#[cfg(test)]
mod tests;
