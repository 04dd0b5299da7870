//! The readout's arithmetic: one formula ([`value`]) for one value ([`Detector::read_out`]) and
//! for runs of values in vector lanes ([`Detector::read_out_run`]: Level-0;
//! [`Detector::read_out_frames`]: the calibration's and the SNR patch's frames).
//!
//! Level-0 reads out every value of a cube: 1.87 M of them in a 256-pixel-wide preview, 30 M at
//! full resolution. One value at a time at the baseline level, its rounding (a saturating
//! float-to-integer conversion and back) and its branches kept the loop scalar, and the
//! arithmetic took as long as the normal draws (`perf` on a preview after a gain change).
//! Level-0 takes a row's draws first and runs the arithmetic over the
//! row in a [`Kernel`], at the widest level the CPU has: in cache, 0.9 ns per value at AVX-512
//! and 1.6 ns at AVX2, against 2.3 ns at AVX2 with the rounding by conversion (a harness, one
//! core, AMD EPYC Zen 4). Level-0 of that preview went from 7.9 to 4.9 ms.

use rand::rngs::Xoshiro256PlusPlus;

use super::{Detector, Exposure, Flags, Readout, normal};
use crate::instrument::effects::nonlinearity::Curve;
use crate::simd::{self, Kernel, Level};

/// One run of values to read out (see [`Detector::read_out_run`]); electrons in `f32` (the
/// cube) or `f64` (frames drawn by [`Detector::read_out_frames`]).
struct Run<'a, E> {
    /// The converter of each lane, cycling: value i is read by `lanes[i % lanes.len()]`.
    lanes: &'a [Adc],
    electrons: &'a [E],
    z: &'a [f64],
    dn: &'a mut [u16],
    flags: &'a mut [u8],
    analog: Option<&'a mut [f32]>,
}

/// Read out `electrons` with the standard normal read-noise draw `z` (not read with the noise
/// off): response curve, read noise, gain, bias and the ADC (Janesick 2007, ch. 2–3; see
/// [`super`]).
///
/// - measured electrons e′ = f(e), the element's curve (e itself unless the instrument states a
///   non-linearity: [`crate::instrument::effects::nonlinearity`]);
/// - analogue value a = (e′ + σ_read·z)/gain + bias, DN;
/// - DN = round(a) = ⌊a + ½⌋ (the floor of the sum a + ½ as rounded in `f64`), clipped to
///   0 … `dn_max` (= 2^bits − 1, an integer ≤ 2¹⁶ − 1);
/// - flags: saturated where the well filled (electrons ≥ well, not for an ideal radiometer) or
///   the ADC reached its top (the ADC's part only with quantisation on); zero where it read 0
///   (only with quantisation on).
///
/// Written for vector lanes: a is clamped to [0, dn_max] before it is rounded, which gives the
/// same DN as rounding then clipping (rounding is monotone and leaves the integer `dn_max` in
/// place); NaN fails a > 0 and reads 0, +∞ reads `dn_max`. The floor of the clamped a + ½ is
/// then taken without a float-to-integer conversion ([`floor_small`]). The test
/// `the_vectorised_readout_is_the_one_value_readout` holds this to the formula as written above
/// (round half up after the sum, then clip) on every edge.
#[inline(always)]
pub(super) fn value(adc: Adc, electrons: f64, z: f64) -> Readout {
    // The response curve acts on the collected electrons; the well is judged on them.
    let measured = if adc.curve.is_linear() { electrons } else { adc.curve.apply(electrons) };
    let noisy = if adc.noise { measured + adc.read_noise_e * z } else { measured };
    let analog = noisy * adc.dn_per_e + adc.bias_dn;
    let clamped = if analog > 0.0 { analog.min(adc.dn_max) } else { 0.0 };
    let (dn, dn_f) = floor_small(clamped + 0.5);
    let well = !adc.ideal && electrons >= adc.well_e;
    let top = adc.quantise && dn_f >= adc.dn_max;
    let zero = adc.quantise && dn_f <= 0.0;
    let flags = (u8::from(well || top) * Flags::SATURATED) | (u8::from(zero) * Flags::ZERO);
    let analog = if adc.quantise || adc.ideal { analog } else { analog.min(adc.dn_max) };
    Readout { dn, analog_dn: analog as f32, flags }
}

/// ⌊y⌋ of 0 ≤ y < 2¹⁶, as an integer and as a float, with no float-to-integer conversion.
///
/// Adding 2⁵² to 0 ≤ y < 2⁵² rounds y to the nearest integer (ties to even): from 2⁵² on, a
/// double's last mantissa bit is worth 1, and the addition's result is that integer plus 2⁵²
/// exactly, its mantissa's low bits the integer itself (Muller et al. 2018, *Handbook of
/// Floating-Point Arithmetic*, 2nd ed.: the classic "adding and subtracting 2^(p−1)" rounding).
/// Where that nearest integer r exceeds y, the floor is r − 1. Rust's `as` conversions
/// saturate and map NaN to 0, which AVX2 cannot do in its lanes: with `as`, the compiler
/// converted each lane with scalar code.
#[inline(always)]
fn floor_small(y: f64) -> (u16, f64) {
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    let shifted = y + TWO_52;
    let nearest = shifted - TWO_52;
    let above = nearest > y;
    // The mantissa's low 16 bits are r mod 2¹⁶. With r ≤ 2¹⁶, and r ≥ 1 wherever r > y ≥ 0,
    // the wrapping subtraction leaves ⌊y⌋ < 2¹⁶ exactly.
    let dn = (shifted.to_bits() as u16).wrapping_sub(u16::from(above));
    (dn, if above { nearest - 1.0 } else { nearest })
}

/// What [`value`] reads of a [`Detector`], copied out of it: in locals, the loop need not read
/// them again after each byte it stores (a `u8` store may alias any byte of the detector, and
/// with the fields read through the reference the loop stayed scalar).
#[derive(Clone, Copy, PartialEq)]
pub(super) struct Adc {
    noise: bool,
    quantise: bool,
    /// An ideal radiometer: no well, no clipping of the analogue value.
    ideal: bool,
    read_noise_e: f64,
    dn_per_e: f64,
    bias_dn: f64,
    dn_max: f64,
    well_e: f64,
    curve: Curve,
}

impl Adc {
    /// The same converter with response curve `curve` (an exposure's: its detector's own).
    #[inline(always)]
    pub(super) fn with_curve(self, curve: Curve) -> Self {
        Self { curve, ..self }
    }

    /// The converter of detector `j`'s band `b` (its focal plane's, with the element's curve).
    #[inline(always)]
    pub(super) fn of(d: &Detector, j: usize, b: usize) -> Self {
        let p = d.plane(b);
        Self {
            noise: d.mode.noise,
            quantise: d.mode.quantise,
            ideal: d.ideal,
            read_noise_e: p.read_noise_e,
            dn_per_e: p.dn_per_e,
            bias_dn: p.bias_dn,
            dn_max: p.dn_max,
            well_e: p.well_e,
            curve: d.curve(j, b),
        }
    }
}

impl<E: Copy + Into<f64>> Kernel for Run<'_, E> {
    type Output = ();

    #[inline(always)]
    fn run<L: Level>(self) {
        let Run { lanes, electrons, z, dn, flags, mut analog } = self;
        if lanes.len() > 1 {
            // Several focal planes: each value's converter by its lane (scalar; one-plane
            // instruments keep the vector loop below).
            for i in 0..electrons.len() {
                let r = value(lanes[i % lanes.len()], electrons[i].into(), z[i]);
                (dn[i], flags[i]) = (r.dn, r.flags);
                if let Some(a) = analog.as_deref_mut().and_then(|a| a.get_mut(i)) {
                    *a = r.analog_dn;
                }
            }
            return;
        }
        let adc = lanes[0];
        let inputs = electrons.iter().zip(z);
        match analog {
            None => {
                for ((&e, &z), (dn, flags)) in inputs.zip(dn.iter_mut().zip(flags.iter_mut())) {
                    let r = value(adc, e.into(), z);
                    (*dn, *flags) = (r.dn, r.flags);
                }
            }
            Some(analog) => {
                for (((&e, &z), (dn, flags)), analog) in inputs.zip(dn.iter_mut().zip(flags.iter_mut())).zip(analog) {
                    let r = value(adc, e.into(), z);
                    (*dn, *flags, *analog) = (r.dn, r.flags, r.analog_dn);
                }
            }
        }
    }
}

impl Detector {
    /// Read out a run of values whose standard normal read-noise draws are given:
    /// `electrons[i]` and `z[i]` to `dn[i]`, `flags[i]` and, when given, `analog[i]`, value i
    /// being of element (detector, band) `elements[i % elements.len()]`. The values
    /// [`Self::read_out`] gives with the same draws (tested), computed in vector lanes when every
    /// element shares one converter (one focal plane, one response curve). With the noise off
    /// the draws are not read.
    ///
    /// # Panics
    /// If the slices' lengths differ or `elements` is empty.
    pub fn read_out_run<E: Copy + Into<f64>>(
        &self,
        elements: &[(usize, usize)],
        electrons: &[E],
        z: &[f64],
        dn: &mut [u16],
        flags: &mut [u8],
        analog: Option<&mut [f32]>,
    ) {
        let n = electrons.len();
        assert!(
            z.len() == n && dn.len() == n && flags.len() == n && analog.as_ref().is_none_or(|a| a.len() == n),
            "readout run: slices of different lengths"
        );
        let lanes: Vec<Adc> = elements.iter().map(|&(j, b)| Adc::of(self, j, b)).collect();
        let lanes: &[Adc] = if lanes.iter().all(|a| *a == lanes[0]) { &lanes[..1] } else { &lanes };
        simd::widest(Run { lanes, electrons, z, dn, flags, analog });
    }

    /// `frames` frames of `exposures[b]` for each band `b` in `bands` of detector `detector`,
    /// read out: frame `f`'s
    /// generator `rng_of(f)` draws each band's electrons then its read noise, in the order of
    /// `bands`, exactly as [`Exposure::draw`] then [`Self::read_out`] would; the readouts are
    /// then computed in vector lanes ([`Self::read_out_run`]) and handed to
    /// `each(frame, band, readout)` in frame order. For the frame loops of the calibration and
    /// the SNR patch (a preview after a gain change reads out 0.73 M dark-frame values and
    /// 0.3 M SNR-patch values). Frames are taken in blocks of at most `FRAME_BLOCK_VALUES`
    /// (16 384) values, so the memory held does not grow with the frames or the bands.
    pub fn read_out_frames(
        &self,
        detector: usize,
        exposures: &[Exposure],
        bands: &[usize],
        frames: usize,
        rng_of: impl Fn(usize) -> Xoshiro256PlusPlus,
        mut each: impl FnMut(usize, usize, Readout),
    ) {
        if bands.is_empty() {
            return;
        }
        let per_block = (FRAME_BLOCK_VALUES / bands.len()).max(1);
        let elements: Vec<(usize, usize)> = bands.iter().map(|&b| (detector, b)).collect();
        let n = per_block.min(frames) * bands.len();
        let (mut electrons, mut z) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let (mut dn, mut flags, mut analog) = (vec![0u16; n], vec![0u8; n], vec![0.0f32; n]);
        for first in (0..frames).step_by(per_block) {
            let block = first..(first + per_block).min(frames);
            electrons.clear();
            z.clear();
            for f in block.clone() {
                let mut rng = rng_of(f);
                for &b in bands {
                    electrons.push(exposures[b].draw(&mut rng));
                    z.push(if self.mode.noise { normal(&mut rng) } else { 0.0 });
                }
            }
            let m = electrons.len();
            self.read_out_run(&elements, &electrons, &z, &mut dn[..m], &mut flags[..m], Some(&mut analog[..m]));
            for (i, ((&dn, &flags), &analog_dn)) in dn.iter().zip(&flags).zip(&analog).take(m).enumerate() {
                each(block.start + i / bands.len(), bands[i % bands.len()], Readout { dn, analog_dn, flags });
            }
        }
    }
}

/// Values [`Detector::read_out_frames`] holds at once (about 23 bytes each): 16 384 covers the
/// calibration's 100 frames × 19 bands and the SNR patch's 128 × 19 in one block.
const FRAME_BLOCK_VALUES: usize = 1 << 14;
