//! Whole-image exposure and readout: band radiance cube → electrons cube → Level-0.
//!
//! Two stages, so that a change of the electronics (gain, bias, ADC bits, read noise) re-runs
//! only the readout and never the photon counts. Each pixel draws its noise from its own
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

/// `radiance` with each coarse plane's bands replaced by their mean over the plane's pixel (the
/// k × k block of grid pixels, as far as the grid is simulated); `None` without coarse planes.
fn block_means(detector: &Detector, radiance: &[f32], viewing: &Viewing, cols: usize, nb: usize) -> Option<Vec<f32>> {
    let coarse: Vec<usize> = (0..nb).filter(|&b| detector.plane(b).block() > 1).collect();
    if coarse.is_empty() {
        return None;
    }
    let rows = radiance.len() / (cols * nb).max(1);
    let mut out = radiance.to_vec();
    let dense = |index: &[usize], k: usize| -> (Vec<usize>, usize) {
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
    };
    for &b in &coarse {
        let k = detector.plane(b).block();
        let (row_id, n_r) = dense(&viewing.line_index[..rows], k);
        let (col_id, n_c) = dense(&viewing.detector_index[..cols], k);
        let (mut sum, mut count) = (vec![0.0f64; n_r * n_c], vec![0u32; n_r * n_c]);
        for r in 0..rows {
            for c in 0..cols {
                let i = row_id[r] * n_c + col_id[c];
                sum[i] += f64::from(radiance[(r * cols + c) * nb + b]);
                count[i] += 1;
            }
        }
        for r in 0..rows {
            for c in 0..cols {
                let i = row_id[r] * n_c + col_id[c];
                out[(r * cols + c) * nb + b] = (sum[i] / f64::from(count[i].max(1))) as f32;
            }
        }
    }
    Some(out)
}

fn shape_error(e: ndarray::ShapeError) -> InstrumentError {
    InstrumentError::Invalid(FieldError { field: "cube".into(), message: e.to_string() })
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
    let t = detector.exposure_s();
    let input = radiance.as_standard_layout();
    let input = input.as_slice().ok_or_else(|| {
        InstrumentError::Invalid(FieldError { field: "cube".into(), message: "not contiguous".into() })
    })?;
    // A coarse focal plane's pixel sees the mean radiance of its block.
    let averaged = block_means(detector, input, viewing, cols, nb);
    let input = averaged.as_deref().unwrap_or(input);
    let every_band_on_grid = on_grid(detector);
    let mut out = vec![0.0f32; rows * cols * nb];
    control.fill_rows(out.as_mut_slice(), rows, cols * nb, |at, row| {
        let r = at.index();
        let line = viewing.line_index[r];
        let mut e = vec![0.0f64; nb];
        for c in 0..cols {
            at.column(c);
            let j = viewing.detector_index[c];
            let pixel = &input[(r * cols + c) * nb..(r * cols + c + 1) * nb];
            if every_band_on_grid {
                // The pixel's own generator, band after band, straight into the row (the loop
                // the one-plane instruments of the default study spend their Level-0 time in).
                let mut rng = pixel_rng(seed, Stream::Exposure, line, j);
                for (b, o) in row[c * nb..(c + 1) * nb].iter_mut().enumerate() {
                    *o = detector.expose(j, b, f64::from(pixel[b]), t, &mut rng) as f32;
                }
                continue;
            }
            draw_bands(detector, seed, Stream::Exposure, line, j, &mut e, |b, rng| {
                detector.expose(j, b, f64::from(pixel[b]), t, rng)
            });
            for (o, v) in row[c * nb..(c + 1) * nb].iter_mut().zip(&e) {
                *o = *v as f32;
            }
        }
        Ok::<_, InstrumentError>(())
    })?;
    Array3::from_shape_vec((rows, cols, nb), out).map_err(shape_error)
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
    let input = electrons.as_standard_layout();
    let input = input.as_slice().ok_or_else(|| {
        InstrumentError::Invalid(FieldError { field: "cube".into(), message: "not contiguous".into() })
    })?;
    let keep_analog = !detector.mode().quantise;
    let noise = detector.mode().noise;
    let bands: Vec<usize> = (0..nb).collect();
    let every_band_on_grid = on_grid(detector);
    let n = rows * cols * nb;
    let mut dn = vec![0u16; n];
    let mut flags = vec![0u8; n];
    let mut analog = vec![0.0f32; if keep_analog { n } else { 0 }];
    let outputs = (dn.as_mut_slice(), flags.as_mut_slice(), analog.as_mut_slice());
    control.fill_rows(outputs, rows, cols * nb, |at, (dn_row, flag_row, analog_row)| {
        let r = at.index();
        let line = viewing.line_index[r];
        // The row's read-noise draws first, pixel by pixel from each pixel's generator, then
        // the arithmetic over the whole row in vector lanes. Every column is visited, with the
        // noise off too, so that a fault armed at a pixel fires there.
        let mut z = vec![0.0; cols * nb];
        for c in 0..cols {
            at.column(c);
            if noise && every_band_on_grid {
                let mut rng = pixel_rng(seed, Stream::Readout, line, viewing.detector_index[c]);
                z[c * nb..(c + 1) * nb].iter_mut().for_each(|z| *z = normal(&mut rng));
            } else if noise {
                let j = viewing.detector_index[c];
                draw_bands(detector, seed, Stream::Readout, line, j, &mut z[c * nb..(c + 1) * nb], |_, rng| {
                    normal(rng)
                });
            }
        }
        let electrons = &input[r * cols * nb..(r + 1) * cols * nb];
        detector.read_out_run(&bands, electrons, &z, dn_row, flag_row, keep_analog.then_some(analog_row));
        Ok::<_, InstrumentError>(())
    })?;
    let (saturated, zero_counts) = count_flags(&flags);
    let shape = (rows, cols, nb);
    Ok(Level0 {
        dn: Array3::from_shape_vec(shape, dn).map_err(shape_error)?,
        analog: if keep_analog { Some(Array3::from_shape_vec(shape, analog).map_err(shape_error)?) } else { None },
        flags: Array3::from_shape_vec(shape, flags).map_err(shape_error)?,
        saturated,
        zero_counts,
    })
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
