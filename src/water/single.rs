//! The per-pixel water kernel in single precision: the formulas of
//! [`WaterModel::rrs_above_into`] (Lee et al. 1998, 1999, as coded in SAMBUCA) on `f32` lanes.
//!
//! A fidelity setting (`Fidelity::water_single_precision`, on by default with band nodes): a vector register
//! holds twice as many `f32` as `f64` values, and the CPU divides and takes square roots of them
//! faster. Measured per call with 451 wavelengths on one core (`shoal bench --only water`, AMD
//! EPYC Zen 4, AVX-512 build, SAMBUCA's default set): 1.10 M/s against 559 k/s shallow (2.0×),
//! 4.1 M/s against 2.9 M/s optically deep (1.4×), its checks included. The checks are decided in `f64` where `f32` could decide them
//! differently: the substrate reflectance's range (tested before rounding), and the sign of a
//! and bb at the wavelengths where the SIOP set can make them ≤ 0.
//! Rrs differs from the double-precision kernel by a few parts in 10⁷ (tested below: within
//! 2·10⁻⁶ relative over shallow and deep columns, concentrations from zero to extreme, and sun
//! and view angles to 80°), far below any instrument's noise; its effect on the products is
//! the cost table's row (`shoal bench --accuracy`). The checks are the double-precision
//! model's, so bad input gets the same messages.

use super::WaterError;
use super::kernel::{Evaluation, Floor, Spectra};
use super::model::{Bottom, WaterColumn, WaterGeometry, WaterModel};
use crate::simd::{Level, mad};

/// A water model's spectra in `f32`, with the model itself for its checks.
#[derive(Debug, Clone)]
pub struct SingleWater {
    model: WaterModel,
    /// The set at the wavelengths where the sign of a or bb is checked in `f64` (see
    /// [`Self::new`]).
    sign_in_double: Option<WaterModel>,
    a_w: Vec<f32>,
    bb_w: Vec<f32>,
    a_ph: Vec<f32>,
    a_cdom: Vec<f32>,
    a_nap: Vec<f32>,
    bb_ph: Vec<f32>,
    bb_nap: Vec<f32>,
}

/// Work buffers of [`SingleWater::rrs_above_into`], kept by the caller between calls (one per
/// thread): the substrate reflectance and Rrs in `f32`.
#[derive(Debug, Clone, Default)]
pub struct SingleScratch {
    bottom: Vec<f32>,
    rrs: Vec<f32>,
}

impl SingleWater {
    /// The single-precision kernel of `model`.
    #[must_use]
    pub fn new(model: &WaterModel) -> Self {
        let s = model.siop();
        let f = |v: &[f64]| v.iter().map(|&x| x as f32).collect();
        // Where the set could give a ≤ 0 or bb ≤ 0 for some valid column: a pure-water value not
        // positive, or a specific spectrum negative (none in the built-in sets; some
        // wavelengths of SAMBUCA's default). There the sign is decided in `f64`, as `evaluate`
        // decides it: near zero, `f32` rounding could flip it either way. The set at those
        // wavelengths is a model of its own, so the check is one short loop without gathers.
        let positive = |v: f64| v.is_finite() && v > 0.0;
        let non_negative = |v: f64| v.is_finite() && v >= 0.0;
        let specific = [&s.a_ph_star, &s.a_cdom_star, &s.a_nap_star, &s.bb_ph_star, &s.bb_nap_star];
        let risky: Vec<usize> = (0..s.grid.len())
            .filter(|&i| !(positive(s.a_w[i]) && positive(s.bb_w[i]) && specific.iter().all(|v| non_negative(v[i]))))
            .collect();
        let sign_in_double = if risky.is_empty() { None } else { s.subset(&risky).ok().map(WaterModel::new) };
        Self {
            model: model.clone(),
            sign_in_double,
            a_w: f(&s.a_w),
            bb_w: f(&s.bb_w),
            a_ph: f(&s.a_ph_star),
            a_cdom: f(&s.a_cdom_star),
            a_nap: f(&s.a_nap_star),
            bb_ph: f(&s.bb_ph_star),
            bb_nap: f(&s.bb_nap_star),
        }
    }

    /// Above-surface Rrs into `out` (one per grid wavelength), as [`WaterModel::rrs_above_into`]
    /// but in single precision.
    ///
    /// The kernel writes `f32` into `scratch`, and the passes before and after it narrow the
    /// substrate reflectance and widen Rrs, all on the widest vector instructions the CPU has
    /// ([`crate::simd::widest`]): with only `f32` in the kernel's loop the compiler fills whole
    /// registers (16 lanes with AVX-512; an `f64` in the loop held it to 8).
    pub fn rrs_above_into(
        &self,
        column: &WaterColumn<'_>,
        geometry: &WaterGeometry,
        scratch: &mut SingleScratch,
        out: &mut [f64],
    ) -> Result<(), WaterError> {
        self.model.check(column, geometry, out.len())?;
        let n = out.len();
        let SingleScratch { bottom, rrs } = scratch;
        rrs.resize(n, 0.0);
        let mut pass = Pass {
            water: self,
            chl: column.chl_mg_m3 as f32,
            cdom: column.cdom_per_m as f32,
            nap: column.nap_g_m3 as f32,
            shallow: None,
            rrs,
            out,
        };
        if let Bottom::Shallow { depth_m, reflectance } = column.bottom {
            let (w, o) = geometry.inverse_cosines_in_water(self.model.siop().water_refractive_index);
            bottom.resize(n, 0.0);
            pass.shallow = Some(ShallowBottom {
                depth_m: depth_m as f32,
                inv_cos_w: w as f32,
                inv_cos_o: o as f32,
                reflectance,
                narrowed: bottom,
            });
        }
        let signs_agree = self.sign_in_double.as_ref().is_none_or(|m| m.all_positive(column));
        if crate::simd::widest(pass) && signs_agree {
            Ok(())
        } else {
            Err(self.model.diagnose(column).unwrap_or_else(|| self.model.non_physical_somewhere()))
        }
    }
}

/// One single-precision evaluation as a [`crate::simd::Kernel`]: narrow ρ_b, run the kernel,
/// widen Rrs. Its output is the kernel's check.
struct Pass<'a> {
    water: &'a SingleWater,
    chl: f32,
    cdom: f32,
    nap: f32,
    shallow: Option<ShallowBottom<'a>>,
    rrs: &'a mut [f32],
    out: &'a mut [f64],
}

/// A shallow column's bottom for [`Pass`]: depth and under-water paths, ρ_b, and the buffer ρ_b
/// is narrowed into.
struct ShallowBottom<'a> {
    depth_m: f32,
    inv_cos_w: f32,
    inv_cos_o: f32,
    reflectance: &'a [f64],
    narrowed: &'a mut [f32],
}

impl crate::simd::Kernel for Pass<'_> {
    type Output = bool;

    #[inline(always)]
    fn run<L: Level>(self) -> bool {
        let w = self.water;
        let spectra = Spectra {
            a_w: &w.a_w,
            bb_w: &w.bb_w,
            a_ph: &w.a_ph,
            a_cdom: &w.a_cdom,
            a_nap: &w.a_nap,
            bb_ph: &w.bb_ph,
            bb_nap: &w.bb_nap,
            chl: self.chl,
            cdom: self.cdom,
            nap: self.nap,
        };
        let mut in_range = true;
        let floor = match self.shallow {
            None => Floor::Deep,
            Some(ShallowBottom { depth_m, inv_cos_w, inv_cos_o, reflectance, narrowed: bottom }) => {
                // The range is checked on the `f64` value: 1 + 10⁻⁹ rounds to 1 in `f32`, and
                // −10⁻³⁰⁰ to −0.
                for (b, &r) in bottom.iter_mut().zip(reflectance) {
                    in_range &= (0.0..=1.0).contains(&r);
                    *b = r as f32;
                }
                Floor::Shallow { depth_m, inv_cos_w, inv_cos_o, rb: bottom }
            }
        };
        let ok = Evaluation { spectra: &spectra, floor, out: &mut *self.rrs }.run::<L>() & in_range;
        for (o, &r) in self.out.iter_mut().zip(self.rrs.iter()) {
            *o = f64::from(r);
        }
        ok
    }
}

/// exp(x) in single precision: x = k·ln 2 + r with |r| ≤ ln 2/2, e^r by its Taylor series to
/// r⁷ (truncation ≤ 8·10⁻⁹ relative), 2^k from the exponent bits; within 3·10⁻⁷ relative (about
/// 2.5 f32 ulps: the roundings of the steps). Clamped to the f32 range. The steps are fused
/// multiply-adds where level `L` has FMA ([`crate::simd::mad`]).
#[inline(always)]
pub(super) fn exp_f32<L: Level>(x: f32) -> f32 {
    let mad = mad::<L, f32>;
    // 1.5·2²³: adding it rounds to an integer held in the low mantissa bits.
    const SHIFT: f32 = 12_582_912.0;
    const LN2_HI: f32 = 0.693_145_75;
    const LN2_LO: f32 = 1.428_606_8e-6;
    let x = x.clamp(-87.0, 88.0);
    let t = mad(x, std::f32::consts::LOG2_E, SHIFT);
    let k = t - SHIFT;
    let r = mad(k, -LN2_LO, mad(k, -LN2_HI, x));
    let r2 = r * r;
    let high = mad(r, 1.0 / 120.0, 1.0 / 24.0) + r2 * mad(r, 1.0 / 5040.0, 1.0 / 720.0);
    let p = mad(r2, mad(r, 1.0 / 6.0, 0.5) + r2 * high, 1.0 + r);
    p * f32::from_bits(t.to_bits().wrapping_add(127) << 23)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::WavelengthGrid;
    use crate::water::{SiopSpec, SubstrateLibrary, SubstrateMix};

    #[test]
    fn exp_f32_is_within_three_parts_in_ten_million() {
        for i in -8700..=8800 {
            let x = i as f32 * 0.01;
            let want = f64::from(x).exp();
            for got in [exp_f32::<crate::simd::Baseline>(x), exp_f32::<crate::simd::Avx2>(x)] {
                let got = f64::from(got);
                assert!(((got - want) / want).abs() < 3e-7, "exp({x}) = {got}, not {want}");
            }
        }
    }

    #[test]
    fn single_precision_rrs_is_the_double_precision_rrs_within_2e_6() {
        let grid = WavelengthGrid::uniform(350.0, 800.0, 1.0).unwrap();
        let model = WaterModel::new(SiopSpec::sambuca_default().resolve(&grid, None).unwrap());
        let single = SingleWater::new(&model);
        let rb = SubstrateLibrary::embedded()
            .unwrap()
            .mix_on_grid(&SubstrateMix::parse("ncc_sand:0.5,brown_acropora:0.5").unwrap(), &grid)
            .unwrap();
        let (mut want, mut got, mut work) = (vec![0.0; grid.len()], vec![0.0; grid.len()], SingleScratch::default());
        let (mut worst, mut worst_fused) = (0.0f64, 0.0f64);
        for (chl, cdom, nap) in [(0.0, 0.0, 0.0), (0.1, 0.01, 0.1), (5.0, 0.5, 5.0), (100.0, 5.0, 200.0)] {
            for depth in [None, Some(0.1), Some(2.0), Some(15.0), Some(60.0)] {
                for (sun, view) in [(0.0, 0.0), (30.0, 10.0), (80.0, 60.0)] {
                    let bottom =
                        depth.map_or(Bottom::OpticallyDeep, |d| Bottom::Shallow { depth_m: d, reflectance: &rb });
                    let column = WaterColumn { chl_mg_m3: chl, cdom_per_m: cdom, nap_g_m3: nap, bottom };
                    let g = WaterGeometry::from_degrees(sun, view);
                    model.rrs_above_into(&column, &g, &mut want).unwrap();
                    single.rrs_above_into(&column, &g, &mut work, &mut got).unwrap();
                    for (a, b) in want.iter().zip(&got) {
                        worst = worst.max(((b - a) / a).abs());
                    }
                    let full = model.evaluate(&column, &g).unwrap().rrs_above;
                    for (a, b) in want.iter().zip(&full) {
                        worst_fused = worst_fused.max(((b - a) / a).abs());
                    }
                }
            }
        }
        assert!(worst < 2e-6, "largest relative difference {worst:e}");
        // The per-pixel double-precision path fuses its multiply-adds and uses `fast_exp`;
        // `evaluate` does neither. About twenty roundings apart: measured 1.6·10⁻¹⁵ over these
        // columns, allowed 4·10⁻¹⁵.
        assert!(worst_fused < 4e-15, "per-pixel path against evaluate: {worst_fused:e}");
    }

    /// The per-pixel kernels check a > 0, bb > 0 and 0 ≤ ρ_b ≤ 1 inside their loop; a failure
    /// must still give `evaluate`'s message, in both precisions, for deep and shallow columns.
    #[test]
    fn in_loop_checks_give_the_messages_of_evaluate() {
        let grid = WavelengthGrid::uniform(400.0, 700.0, 10.0).unwrap();
        let mut siop = SiopSpec::sambuca_default().resolve(&grid, None).unwrap();
        let g = WaterGeometry::from_degrees(30.0, 20.0);
        let n = grid.len();
        let mut out = vec![0.0; n];
        let mut scratch = SingleScratch::default();
        let run = |model: &WaterModel, column: &WaterColumn<'_>, out: &mut [f64], scratch: &mut SingleScratch| {
            let want = model.evaluate(column, &g).unwrap_err().to_string();
            let fast = model.rrs_above_into(column, &g, out).unwrap_err().to_string();
            let single = SingleWater::new(model).rrs_above_into(column, &g, scratch, out).unwrap_err().to_string();
            assert_eq!(fast, want);
            assert_eq!(single, want);
            want
        };
        // A substrate reflectance above 1, then not a number, at one wavelength.
        let model = WaterModel::new(siop.clone());
        // 1 + 10⁻⁹ and −10⁻³⁰⁰ round into [0, 1] in f32: the range is checked before.
        for bad in [1.5, f64::NAN, -0.1, 1.0 + 1e-9, -1e-300] {
            let mut rb = vec![0.2; n];
            rb[n / 2] = bad;
            let column = WaterColumn {
                chl_mg_m3: 1.0,
                cdom_per_m: 0.1,
                nap_g_m3: 1.0,
                bottom: Bottom::Shallow { depth_m: 3.0, reflectance: &rb },
            };
            let e = run(&model, &column, &mut out, &mut scratch);
            assert!(e.contains("substrate reflectance") && e.contains("0 to 1"), "{e}");
        }
        // A specific absorption negative enough at 550 nm that a < 0 for chl = 10.
        siop.a_ph_star[15] = -1.0;
        let model = WaterModel::new(siop);
        let rb = vec![0.2; n];
        for bottom in [Bottom::OpticallyDeep, Bottom::Shallow { depth_m: 3.0, reflectance: &rb }] {
            let column = WaterColumn { chl_mg_m3: 10.0, cdom_per_m: 0.1, nap_g_m3: 1.0, bottom };
            let e = run(&model, &column, &mut out, &mut scratch);
            assert!(e.contains("not positive") && e.contains("550 nm"), "{e}");
            // With chl = 0 the same set is valid, and both kernels answer.
            let fine = WaterColumn { chl_mg_m3: 0.0, ..column };
            model.rrs_above_into(&fine, &g, &mut out).unwrap();
            assert!(out.iter().all(|v| v.is_finite() && *v > 0.0));
            SingleWater::new(&model).rrs_above_into(&fine, &g, &mut scratch, &mut out).unwrap();
            assert!(out.iter().all(|v| v.is_finite() && *v > 0.0));
        }
    }

    #[test]
    fn bad_input_gets_the_double_precision_message() {
        let grid = WavelengthGrid::uniform(400.0, 700.0, 10.0).unwrap();
        let model = WaterModel::new(SiopSpec::sambuca_default().resolve(&grid, None).unwrap());
        let single = SingleWater::new(&model);
        let column = WaterColumn { chl_mg_m3: -1.0, cdom_per_m: 0.1, nap_g_m3: 1.0, bottom: Bottom::OpticallyDeep };
        let g = WaterGeometry::from_degrees(30.0, 0.0);
        let mut out = vec![0.0; grid.len()];
        let want = model.rrs_above_into(&column, &g, &mut out).unwrap_err().to_string();
        let got = single.rrs_above_into(&column, &g, &mut SingleScratch::default(), &mut out).unwrap_err().to_string();
        assert_eq!(got, want);
        assert!(single.rrs_above_into(&column, &g, &mut SingleScratch::default(), &mut [0.0; 3]).is_err());
    }
}
