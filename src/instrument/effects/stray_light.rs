//! Spatial stray light: light scattered by the optics' surfaces into a far-field halo around
//! every pixel's point-spread function, and a veil from sources beyond the field of view.
//!
//! The halo's shape is the Harvey scatter model in image space (Harvey 1976; Peterson 2004): a
//! surface scatters into angles β with BSDF ∝ (1 + (β/l)²)^(−s/2), so the in-field halo on the
//! ground at distance r is h(r) ∝ (1 + (r/r₀)²)^(−s/2), with r₀ the knee (`knee_m`) and s the
//! slope (`slope`, 1–4 for polished optics), out to the halo's extent R (`radius_m`). The share
//! it carries, f (`halo_fraction` at 550 nm), is the total integrated scatter, which for
//! micro-roughness σ grows as TIS = (4πσ/λ)² (Bennett & Porteus 1961): f(λ) = f·(550/λ)^p with
//! p = `wavelength_exponent` (2 by default). The veil from beyond the field (ghosts and
//! out-of-field sources: Metop-3MI's and OLCI's "out-of-field" term) carries a share f_o
//! (`out_of_field_fraction`) of a scene taken as bright on average as the image.
//!
//! Each band b sees, with H the halo normalised to 1 on the pixel grid and L̄ the image mean:
//!
//! L′ = (1 − f_b − f_o)·L + f_b·(H ⊗ L) + f_o·L̄
//!
//! so a uniform scene is unchanged (the calibration on a uniform source absorbs the effect) and
//! light moves from bright to dark: a lake shore, the half-bright, half-dark field of the 3MI
//! stray-light test, sees land light on the water. The processor knows the halo with a relative
//! error e and inverts L′ = (I + D)L by the fixed point Lₖ₊₁ = L′ − D̂Lₖ (Zong et al. 2006:
//! (I + D)⁻¹ by its series), until a step moves no pixel by 1e-6 of the brightest: a step
//! shrinks the error by about the share the halo and veil take, f_b + f_o < 1, so the steps
//! run are as many as that share needs (20 up to 0.5).
//!
//! ## References
//! - Harvey, J. E. (1976) Light-scattering characteristics of optical surfaces. PhD thesis,
//!   University of Arizona.
//! - Peterson, G. L. (2004) Analytic expressions for in-field scattered light distributions.
//!   Proc. SPIE 5178, 184–193.
//! - Bennett, H. E., Porteus, J. O. (1961) Relation between surface roughness and specular
//!   reflectance at normal incidence. J. Opt. Soc. Am. 51, 123–129.
//! - Zong, Y. et al. (2006) Appl. Opt. 45, 1111–1119.

use ndarray::{Array2, Array3, Axis};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::convolve::KernelSpectrum;
use super::{Context, Effect, InstrumentError, Knowledge, check};
use crate::control::RunControl;
use crate::ranges as r;

fn two() -> f64 {
    2.0
}

/// Spatial stray light as an instrument file states it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrayLight {
    /// Share of the light the halo spreads at 550 nm (0–0.5).
    pub halo_fraction: f64,
    /// Knee of the halo's profile on the ground, m.
    pub knee_m: f64,
    /// Power-law slope s of the profile beyond the knee.
    pub slope: f64,
    /// Extent of the halo on the ground, m.
    pub radius_m: f64,
    /// Share of the light that comes from beyond the field of view as a uniform veil.
    #[serde(default)]
    pub out_of_field_fraction: f64,
    /// Exponent p of the halo's wavelength law f·(550/λ)^p.
    #[serde(default = "two")]
    pub wavelength_exponent: f64,
    /// What the Level-1 processor knows of it.
    #[serde(default)]
    pub correction: Knowledge,
}

/// Sub-samples per pixel side when the halo is integrated over each pixel.
const SUBSAMPLES: usize = 4;

impl StrayLight {
    /// Halo share in a band centred at `centre_nm`, scaled by `factor` (the processor's belief).
    fn halo_share(&self, centre_nm: f64, factor: f64) -> f64 {
        factor * self.halo_fraction * (550.0 / centre_nm).powf(self.wavelength_exponent)
    }

    /// The unnormalised profile h(r).
    fn profile(&self, r_m: f64) -> f64 {
        if r_m > self.radius_m { 0.0 } else { (1.0 + (r_m / self.knee_m).powi(2)).powf(-0.5 * self.slope) }
    }

    /// The halo on a grid of `spacing_m` (along, across): each cell the mean of the profile over
    /// its area (SUBSAMPLES² points), normalised to 1; odd sizes, centred.
    #[must_use]
    pub fn kernel(&self, spacing_m: (f64, f64)) -> Array2<f64> {
        let half = |d: f64| (self.radius_m / d).ceil() as usize;
        let (hr, hc) = (half(spacing_m.0), half(spacing_m.1));
        let step = |d: f64| d / SUBSAMPLES as f64;
        let mut k = Array2::from_shape_fn((2 * hr + 1, 2 * hc + 1), |(i, j)| {
            let (y0, x0) = ((i as f64 - hr as f64 - 0.5) * spacing_m.0, (j as f64 - hc as f64 - 0.5) * spacing_m.1);
            let mut sum = 0.0;
            for a in 0..SUBSAMPLES {
                for b in 0..SUBSAMPLES {
                    let y = y0 + (a as f64 + 0.5) * step(spacing_m.0);
                    let x = x0 + (b as f64 + 0.5) * step(spacing_m.1);
                    sum += self.profile(x.hypot(y));
                }
            }
            sum
        });
        let total = k.sum();
        k.mapv_inplace(|v| v / total);
        k
    }

    /// The 3MI figure on the pixel grid the chain uses: the stray signal at `distance_m` into the
    /// dark half of a half-bright, half-dark field, relative to the bright half's radiance (the
    /// halo's share of the kernel's columns beyond that distance, plus half the veil), in a band
    /// centred at `centre_nm`.
    #[must_use]
    pub fn grid_edge_ratio(&self, spacing_m: (f64, f64), distance_m: f64, centre_nm: f64) -> f64 {
        let k = self.kernel(spacing_m);
        let hc = k.ncols() / 2;
        let cells = (distance_m / spacing_m.1).round() as usize;
        let beyond: f64 = k.axis_iter(Axis(1)).enumerate().filter(|(j, _)| *j > hc + cells).map(|(_, c)| c.sum()).sum();
        self.halo_share(centre_nm, 1.0) * beyond + 0.5 * self.out_of_field_fraction
    }

    /// The same figure for the continuous halo (what a review states): the share of h beyond a
    /// straight edge at `distance_m`, ∫_d^R h(r)·2 arccos(d/r)·r dr / ∫_0^R h(r)·2π r dr, by the
    /// midpoint rule on 2000 radii; cheap enough to draw every frame.
    #[must_use]
    pub fn edge_ratio(&self, distance_m: f64, centre_nm: f64) -> f64 {
        let n = 2000;
        let dr = self.radius_m / n as f64;
        let (mut beyond, mut total) = (0.0, 0.0);
        for i in 0..n {
            let r = (i as f64 + 0.5) * dr;
            let h = self.profile(r) * r * dr;
            total += 2.0 * std::f64::consts::PI * h;
            if r > distance_m {
                beyond += 2.0 * (distance_m / r).acos() * h;
            }
        }
        self.halo_share(centre_nm, 1.0) * beyond / total + 0.5 * self.out_of_field_fraction
    }

    /// The stray part D·L = f(H⊗L − L) + f_o(L̄ − L) of every band, shares scaled by `factor`
    /// (L′ = L + D·L).
    fn stray(&self, cube: &Array3<f32>, ctx: &Context, factor: f64, spectrum: &KernelSpectrum) -> Vec<Array2<f32>> {
        let bands: Vec<usize> = (0..cube.dim().2).collect();
        bands
            .par_iter()
            .map(|&b| {
                let band = cube.index_axis(Axis(2), b);
                let f = self.halo_share(ctx.centres_nm[b], factor);
                let fo = factor * self.out_of_field_fraction;
                let mean = band.iter().map(|&v| f64::from(v)).sum::<f64>() / band.len().max(1) as f64;
                let halo = spectrum.convolve(band);
                // D·L = f(H⊗L − L) + f_o(L̄ − L)
                Array2::from_shape_fn(band.dim(), |(r, c)| {
                    let l = f64::from(band[(r, c)]);
                    (f * (halo[(r, c)] - l) + fo * (mean - l)) as f32
                })
            })
            .collect()
    }

    /// The largest share of a band's light the halo and the veil take (at most 1, checked): what
    /// the correction's iteration contracts its error by per step.
    fn shares_below_one(&self, ctx: &Context, factor: f64, at: &str) -> Result<f64, InstrumentError> {
        let worst = ctx.centres_nm.iter().map(|&c| self.halo_share(c, factor)).fold(0.0, f64::max);
        let total = worst + factor * self.out_of_field_fraction;
        if total < 1.0 {
            Ok(total)
        } else {
            Err(InstrumentError::Invalid(crate::parse::FieldError {
                field: format!("{at}.halo_fraction"),
                message: format!(
                    "the halo and the out-of-field veil take {total:.2} of the light in the bluest band \
                     (halo_fraction·(550/λ)^wavelength_exponent + out_of_field_fraction must stay below 1)"
                ),
            }))
        }
    }
}

impl Effect for StrayLight {
    fn name(&self) -> &'static str {
        "StrayLight"
    }

    fn role(&self) -> super::Role {
        super::Role::Optics
    }

    fn validate(&self, at: &str) -> Result<(), InstrumentError> {
        check(&r::STRAY_HALO_FRACTION, self.halo_fraction, &format!("{at}.halo_fraction"))?;
        check(&r::STRAY_KNEE_M, self.knee_m, &format!("{at}.knee_m"))?;
        check(&r::STRAY_SLOPE, self.slope, &format!("{at}.slope"))?;
        check(&r::STRAY_RADIUS_M, self.radius_m, &format!("{at}.radius_m"))?;
        check(&r::STRAY_OUT_OF_FIELD, self.out_of_field_fraction, &format!("{at}.out_of_field_fraction"))?;
        check(&r::STRAY_WAVELENGTH_EXPONENT, self.wavelength_exponent, &format!("{at}.wavelength_exponent"))?;
        self.correction.validate(&r::STRAY_KNOWLEDGE_ERROR, at)
    }

    fn apply(&self, cube: &mut Array3<f32>, ctx: &Context, control: &RunControl) -> Result<(), InstrumentError> {
        self.shares_below_one(ctx, 1.0, "effects[].StrayLight")?;
        let (rows, cols, _) = cube.dim();
        let spectrum = KernelSpectrum::new(&self.kernel(ctx.spacing_m), (rows, cols));
        if control.cancelled() {
            return Err(InstrumentError::Cancelled);
        }
        let stray = self.stray(cube, ctx, 1.0, &spectrum);
        for (b, s) in stray.iter().enumerate() {
            let mut band = cube.index_axis_mut(Axis(2), b);
            band.zip_mut_with(s, |l, &d| *l += d);
        }
        Ok(())
    }

    fn correct(&self, cube: &mut Array3<f32>, ctx: &Context, control: &RunControl) -> Result<(), InstrumentError> {
        let factor = self.correction.factor();
        if factor == 0.0 {
            return Ok(());
        }
        let share = self.shares_below_one(ctx, factor, "effects[].StrayLight.correction")?;
        let (rows, cols, _) = cube.dim();
        let spectrum = KernelSpectrum::new(&self.kernel(ctx.spacing_m), (rows, cols));
        let measured = cube.clone();
        let peak = measured.iter().map(|v| v.abs()).fold(0.0f32, f32::max).max(f32::MIN_POSITIVE);
        // Lₖ₊₁ = L′ − D̂·Lₖ, from L₀ = L′, until a step moves no pixel by 1e-6 of the peak. A
        // step shrinks the error by at most the share the halo and veil take (‖D̂‖ ≤ share on an
        // image whose light it only moves), so ln(10⁻⁶)/ln(share) steps reach it: 20 up to a
        // share of 0.5, 131 at 0.9.
        let steps = ((1e-6f64).ln() / share.max(1e-3).ln()).ceil().clamp(20.0, 2000.0) as usize;
        for _ in 0..steps {
            if control.cancelled() {
                return Err(InstrumentError::Cancelled);
            }
            let stray = self.stray(cube, ctx, factor, &spectrum);
            let mut moved = 0.0f32;
            for (b, s) in stray.iter().enumerate() {
                let mut band = cube.index_axis_mut(Axis(2), b);
                let m = measured.index_axis(Axis(2), b);
                ndarray::Zip::from(&mut band).and(&m).and(s).for_each(|l, &lm, &d| {
                    let next = lm - d;
                    moved = moved.max((next - *l).abs());
                    *l = next;
                });
            }
            if moved <= 1e-6 * peak {
                break;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn halo(f: f64) -> StrayLight {
        StrayLight {
            halo_fraction: f,
            knee_m: 60.0,
            slope: 2.5,
            radius_m: 1500.0,
            out_of_field_fraction: 0.0,
            wavelength_exponent: 0.0,
            correction: Knowledge::default(),
        }
    }

    fn ctx(centres: &[f64]) -> Context<'_> {
        Context { spacing_m: (30.0, 30.0), pixel_m: 30.0, centres_nm: centres, stokes: None }
    }

    #[test]
    fn a_point_source_keeps_its_energy_and_spreads_the_halo_share() {
        let s = halo(0.05);
        let centres = [550.0];
        let mut cube = Array3::<f32>::zeros((121, 121, 1));
        cube[(60, 60, 0)] = 1000.0;
        s.apply(&mut cube, &ctx(&centres), &RunControl::new()).unwrap();
        let total: f64 = cube.iter().map(|&v| f64::from(v)).sum();
        // The halo (radius 50 pixels) lies inside the image: nothing is lost (f32 sums).
        assert!((total - 1000.0).abs() < 1e-3, "{total}");
        // Beyond the source's own pixel: the halo share less the halo's own central cell.
        let k = s.kernel((30.0, 30.0));
        let own = k[(k.nrows() / 2, k.ncols() / 2)];
        let outside = total - f64::from(cube[(60, 60, 0)]);
        let expected = 1000.0 * 0.05 * (1.0 - own);
        assert!((outside - expected).abs() < 1e-3 * expected, "{outside} vs {expected}");
    }

    #[test]
    fn a_half_bright_field_shows_the_encircled_energy_complement() {
        // The 3MI test: bright (100) west of a straight edge, dark (0) east of it; the dark side
        // at distance d reads f·(halo share beyond d), the edge ratio, to f32 rounding.
        let s = halo(0.05);
        let centres = [550.0];
        let (rows, cols) = (40, 200);
        let mut cube = Array3::<f32>::from_shape_fn((rows, cols, 1), |(_, c, _)| if c < 100 { 100.0 } else { 0.0 });
        s.apply(&mut cube, &ctx(&centres), &RunControl::new()).unwrap();
        for d_px in [1usize, 3, 10, 30] {
            let measured = f64::from(cube[(20, 100 + d_px - 1, 0)]) / 100.0;
            // The first dark column is 0.5 pixel past the edge: distance (d − ½)·GSD from it,
            // and the ratio counts kernel columns beyond d − 1 cells.
            let expected = s.grid_edge_ratio((30.0, 30.0), (d_px as f64 - 1.0) * 30.0, 550.0);
            assert!((measured - expected).abs() < 1e-6 + 1e-4 * expected, "{d_px}: {measured} vs {expected}");
        }
        // And the figure falls with distance as the halo does; the continuous halo's agrees
        // with the grid's within the pixel's own size (a quarter, at 10 pixels).
        let near = s.edge_ratio(60.0, 550.0);
        let far = s.edge_ratio(900.0, 550.0);
        assert!(near > 5.0 * far && far > 0.0, "{near} {far}");
        let (grid, continuous) = (s.grid_edge_ratio((30.0, 30.0), 300.0, 550.0), s.edge_ratio(315.0, 550.0));
        assert!((grid / continuous - 1.0).abs() < 0.25, "{grid} vs {continuous}");
        assert!((s.edge_ratio(0.0, 550.0) - 0.025).abs() < 1e-3, "half the halo lies past the edge itself");
    }

    #[test]
    fn a_uniform_scene_is_unchanged_and_the_known_halo_is_removed() {
        let mut s = halo(0.08);
        s.out_of_field_fraction = 0.02;
        s.wavelength_exponent = 2.0;
        let centres = [443.0, 865.0];
        let control = RunControl::new();
        let mut flat = Array3::<f32>::from_elem((20, 30, 2), 50.0);
        s.apply(&mut flat, &ctx(&centres), &control).unwrap();
        assert!(flat.iter().all(|&v| (v - 50.0).abs() < 1e-3), "a uniform scene keeps its radiance");
        // A shore: the processor that knows the halo exactly gives the scene back; one that
        // believes it 20 % too strong leaves a residual of that order, of the opposite sign.
        let truth = Array3::<f32>::from_shape_fn((40, 60, 2), |(r, c, b)| {
            if c + r / 4 < 25 { 200.0 - 100.0 * b as f32 } else { 5.0 + b as f32 }
        });
        let mut seen = truth.clone();
        s.apply(&mut seen, &ctx(&centres), &control).unwrap();
        let err = |a: &Array3<f32>| a.iter().zip(&truth).map(|(x, t)| f64::from((x - t).abs())).fold(0.0, f64::max);
        let stray = err(&seen);
        let mut exact = seen.clone();
        s.correct(&mut exact, &ctx(&centres), &control).unwrap();
        assert!(err(&exact) < 1e-3 * stray, "exact knowledge: {} of {stray}", err(&exact));
        s.correction.error = 0.2;
        let mut wrong = seen.clone();
        s.correct(&mut wrong, &ctx(&centres), &control).unwrap();
        let left = err(&wrong);
        assert!(left > 0.1 * stray && left < 0.35 * stray, "20 % knowledge error leaves {left} of {stray}");
        s.correction.corrected = false;
        let mut none = seen.clone();
        s.correct(&mut none, &ctx(&centres), &control).unwrap();
        assert_eq!(none, seen, "an uncorrected effect stays");
    }

    /// A halo and veil that take 80 % of the light: the iteration shrinks its error by about
    /// 0.8 per step, so the 20 steps it once stopped at left 1 % of the stray light; it now
    /// runs the 62 the share needs and gives the scene back to 1e-4 of the stray light.
    #[test]
    fn a_strong_halo_is_still_removed_to_the_bound() {
        let mut s = halo(0.5);
        s.out_of_field_fraction = 0.3;
        let centres = [550.0];
        let control = RunControl::new();
        let truth = Array3::<f32>::from_shape_fn((40, 60, 1), |(r, c, _)| if c + r / 4 < 25 { 200.0 } else { 5.0 });
        let mut seen = truth.clone();
        s.apply(&mut seen, &ctx(&centres), &control).unwrap();
        let err = |a: &Array3<f32>| a.iter().zip(&truth).map(|(x, t)| f64::from((x - t).abs())).fold(0.0, f64::max);
        let stray = err(&seen);
        s.correct(&mut seen, &ctx(&centres), &control).unwrap();
        assert!(err(&seen) < 1e-4 * stray, "{} of {stray} left", err(&seen));
    }

    #[test]
    fn shares_that_take_all_the_light_are_refused() {
        let mut s = halo(0.5);
        s.wavelength_exponent = 4.0;
        s.out_of_field_fraction = 0.3;
        let mut cube = Array3::<f32>::zeros((4, 4, 1));
        let e = s.apply(&mut cube, &ctx(&[400.0]), &RunControl::new()).unwrap_err();
        assert!(e.to_string().contains("halo_fraction"), "{e}");
    }
}
