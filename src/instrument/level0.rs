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
    let mut out = vec![0.0f32; rows * cols * nb];
    control.fill_rows(out.as_mut_slice(), rows, cols * nb, |at, row| {
        let r = at.index();
        let line = viewing.line_index[r];
        for c in 0..cols {
            at.column(c);
            let j = viewing.detector_index[c];
            let mut rng = pixel_rng(seed, Stream::Exposure, line, j);
            for b in 0..nb {
                let l = f64::from(input[(r * cols + c) * nb + b]);
                row[c * nb + b] = detector.expose(j, b, l, t, &mut rng) as f32;
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
            if noise {
                let mut rng = pixel_rng(seed, Stream::Readout, line, viewing.detector_index[c]);
                z[c * nb..(c + 1) * nb].iter_mut().for_each(|z| *z = normal(&mut rng));
            }
        }
        let electrons = &input[r * cols * nb..(r + 1) * cols * nb];
        detector.read_out_run(electrons, &z, dn_row, flag_row, keep_analog.then_some(analog_row));
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
