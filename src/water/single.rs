//! The per-pixel water kernel in single precision: the formulas of
//! [`WaterModel::rrs_above_into`] (Lee et al. 1998, 1999, as coded in SAMBUCA) on `f32` lanes.
//!
//! A fidelity setting (`Fidelity::water_single_precision`, off by default): a vector register
//! holds twice as many `f32` as `f64` values, and the CPU divides and takes square roots of them
//! faster. Measured per call with 451 wavelengths on one core (`shoal bench --only water`, AMD
//! EPYC Zen 4, AVX-512 build): 647 k/s against 275 k/s shallow (2.4×), 3.7 M/s against 2.2 M/s
//! optically deep (1.7×); the checks and conversions around the kernel stay in `f64`.
//! Rrs differs from the double-precision kernel by a few parts in 10⁷ (tested below: within
//! 2·10⁻⁶ relative over shallow and deep columns, concentrations from zero to extreme, and sun
//! and view angles to 80°), far below any instrument's noise; its effect on the products is
//! the cost table's row (`shoal bench --accuracy`). The checks are the double-precision
//! model's, so bad input gets the same messages.

use super::WaterError;
use super::kernel::Spectra;
use super::model::{Bottom, WaterColumn, WaterGeometry, WaterModel};

/// A water model's spectra in `f32`, with the model itself for its checks.
#[derive(Debug, Clone)]
pub struct SingleWater {
    model: WaterModel,
    a_w: Vec<f32>,
    bb_w: Vec<f32>,
    a_ph: Vec<f32>,
    a_cdom: Vec<f32>,
    a_nap: Vec<f32>,
    bb_ph: Vec<f32>,
    bb_nap: Vec<f32>,
}

/// The concentrations and geometry of one evaluation.
#[derive(Debug, Clone, Copy)]
struct Column {
    chl: f32,
    cdom: f32,
    nap: f32,
    depth_m: f32,
    inv_cos_w: f32,
    inv_cos_o: f32,
}

impl SingleWater {
    /// The single-precision kernel of `model`.
    #[must_use]
    pub fn new(model: &WaterModel) -> Self {
        let s = model.siop();
        let f = |v: &[f64]| v.iter().map(|&x| x as f32).collect();
        Self {
            model: model.clone(),
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
    /// but in single precision; `bottom` is a work buffer for the substrate reflectance.
    pub fn rrs_above_into(
        &self,
        column: &WaterColumn<'_>,
        geometry: &WaterGeometry,
        bottom: &mut Vec<f32>,
        out: &mut [f64],
    ) -> Result<(), WaterError> {
        self.model.check(column, geometry, out.len())?;
        let mut c = Column {
            chl: column.chl_mg_m3 as f32,
            cdom: column.cdom_per_m as f32,
            nap: column.nap_g_m3 as f32,
            depth_m: 0.0,
            inv_cos_w: 0.0,
            inv_cos_o: 0.0,
        };
        match column.bottom {
            Bottom::OpticallyDeep => dispatch(self, &c, None, out),
            Bottom::Shallow { depth_m, reflectance } => {
                let (w, o) = geometry.inverse_cosines_in_water(self.model.siop().water_refractive_index);
                (c.depth_m, c.inv_cos_w, c.inv_cos_o) = (depth_m as f32, w as f32, o as f32);
                bottom.clear();
                bottom.extend(reflectance.iter().map(|&r| r as f32));
                dispatch(self, &c, Some(bottom), out);
            }
        }
        Ok(())
    }
}

/// exp(x) in single precision: x = k·ln 2 + r with |r| ≤ ln 2/2, e^r by its Taylor series to
/// r⁷ (truncation ≤ 8·10⁻⁹ relative), 2^k from the exponent bits; within 3·10⁻⁷ relative (about
/// 2.5 f32 ulps: the roundings of the steps). Clamped to the f32 range.
#[inline(always)]
pub(super) fn exp_f32(x: f32) -> f32 {
    // 1.5·2²³: adding it rounds to an integer held in the low mantissa bits.
    const SHIFT: f32 = 12_582_912.0;
    const LN2_HI: f32 = 0.693_145_75;
    const LN2_LO: f32 = 1.428_606_8e-6;
    let x = x.clamp(-87.0, 88.0);
    let t = x * std::f32::consts::LOG2_E + SHIFT;
    let k = t - SHIFT;
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let r2 = r * r;
    let high = (1.0 / 24.0 + r * (1.0 / 120.0)) + r2 * (1.0 / 720.0 + r * (1.0 / 5040.0));
    let p = (1.0 + r) + r2 * ((0.5 + r * (1.0 / 6.0)) + r2 * high);
    p * f32::from_bits(t.to_bits().wrapping_add(127) << 23)
}

/// The kernel on `f32` lanes: deep when `rb` is `None` ([`super::kernel`], the equations the
/// double-precision kernel runs).
#[inline(always)]
fn kernel(w: &SingleWater, c: &Column, rb: Option<&[f32]>, out: &mut [f64]) {
    let spectra = Spectra {
        a_w: &w.a_w,
        bb_w: &w.bb_w,
        a_ph: &w.a_ph,
        a_cdom: &w.a_cdom,
        a_nap: &w.a_nap,
        bb_ph: &w.bb_ph,
        bb_nap: &w.bb_nap,
        chl: c.chl,
        cdom: c.cdom,
        nap: c.nap,
    };
    match rb {
        None => super::kernel::deep(&spectra, out),
        Some(rb) => super::kernel::shallow(&spectra, c.depth_m, c.inv_cos_w, c.inv_cos_o, rb, out),
    }
}

/// The widest build the CPU runs (chosen at run time, like the double-precision kernel).
fn dispatch(w: &SingleWater, c: &Column, rb: Option<&[f32]>, out: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    {
        if simd::avx512_available() {
            simd::avx512(w, c, rb, out);
            return;
        }
        if simd::avx2_available() {
            simd::avx2(w, c, rb, out);
            return;
        }
    }
    kernel(w, c, rb, out);
}

#[cfg(target_arch = "x86_64")]
mod simd {
    use super::{Column, SingleWater, kernel};

    pub fn avx512_available() -> bool {
        std::arch::is_x86_feature_detected!("avx512f") && avx2_available()
    }

    pub fn avx2_available() -> bool {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }

    #[target_feature(enable = "avx512f,avx2,fma")]
    fn avx512_kernel(w: &SingleWater, c: &Column, rb: Option<&[f32]>, out: &mut [f64]) {
        kernel(w, c, rb, out);
    }

    #[target_feature(enable = "avx2,fma")]
    fn avx2_kernel(w: &SingleWater, c: &Column, rb: Option<&[f32]>, out: &mut [f64]) {
        kernel(w, c, rb, out);
    }

    pub fn avx512(w: &SingleWater, c: &Column, rb: Option<&[f32]>, out: &mut [f64]) {
        debug_assert!(avx512_available());
        // SAFETY: callers check `avx512_available()`: the CPU executes AVX-512F, AVX2 and FMA.
        #[allow(unsafe_code)]
        unsafe {
            avx512_kernel(w, c, rb, out);
        }
    }

    pub fn avx2(w: &SingleWater, c: &Column, rb: Option<&[f32]>, out: &mut [f64]) {
        debug_assert!(avx2_available());
        // SAFETY: callers check `avx2_available()`: the CPU executes AVX2 and FMA instructions.
        #[allow(unsafe_code)]
        unsafe {
            avx2_kernel(w, c, rb, out);
        }
    }
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
            let (got, want) = (f64::from(exp_f32(x)), f64::from(x).exp());
            assert!(((got - want) / want).abs() < 3e-7, "exp({x}) = {got}, not {want}");
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
        let (mut want, mut got, mut work) = (vec![0.0; grid.len()], vec![0.0; grid.len()], Vec::new());
        let mut worst = 0.0f64;
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
                }
            }
        }
        assert!(worst < 2e-6, "largest relative difference {worst:e}");
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
        let got = single.rrs_above_into(&column, &g, &mut Vec::new(), &mut out).unwrap_err().to_string();
        assert_eq!(got, want);
        assert!(single.rrs_above_into(&column, &g, &mut Vec::new(), &mut [0.0; 3]).is_err());
    }
}
