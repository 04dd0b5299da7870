//! The NIR water-leaving reflectance of turbid water, estimated from the red band, for the
//! image-based correction's aerosol pair (Bailey, Franz & Werdell 2010, as NASA's l2gen
//! implements it in `get_rhown_nir.c` and iterates it in `atmocor2.c`).
//!
//! The black-pixel assumption fails where particles make the water bright at 700–900 nm: the
//! water's own signal at the pair's bands is then read as aerosol. Per pass, from the Rrs of
//! the previous pass (zero at the first, so the first pass is the black-pixel fit):
//!
//! 1. rrs = Rrs/(0.52 + 1.7·Rrs) below the surface (Lee et al. 2002, eq. 4) at 443, 555 and
//!    670 nm;
//! 2. a(670) = a_w(670) + exp(0.9389·ln chl − 3.7589) (the NOMAD fit of l2gen, clamped to
//!    [0, 0.5] m⁻¹; chl from OC4, clamped to 0.2–30 mg m⁻³);
//! 3. u(670) from rrs(670) and bb_p(670) = u·a/(1 − u) − bb_w(670);
//! 4. η = 2·(1 − 1.2·exp(−0.9·rrs(443)/rrs(555))), clamped to [0, 1] (Lee et al. 2002);
//! 5. at each NIR band, bb = bb_p(670)·(670/λ)^η + bb_w(λ), a = a_w(λ), u = bb/(a + bb), and
//!    Rrs = 0.52·rrs/(1 − 1.7·rrs).
//!
//! l2gen relates rrs and u through Morel's tabulated f/Q; Shoal has no such table and uses
//! rrs = g₀·u + g₁·u² with g₀ = 0.0949, g₁ = 0.0794 (Gordon et al. 1988, as QAA does, Lee et al.
//! 2002) in both directions, so that the relation's form cancels where u is small. The pass's
//! NIR water radiance enters the next as (1 − 0.33)·new + 0.33·previous, that damped value then
//! scaled by the ramp: 0 where chl ≤ 0.7 mg m⁻³, 1 from 1.3 (l2gen's damping, then its ramp,
//! in that order). Where OC4 fails (a blue or green Rrs not positive), the pass is reseeded as
//! l2gen's `atmocor2.c` does for turbid water: chl 10 mg m⁻³ and the red band's whole
//! Rayleigh-corrected radiance taken as the water's (once, and a second time as the last pass).
//! Passes stop when Rrs(670) changes by less than 2 % or after ten (l2gen's `nir_chg` and
//! `aer_iter_max`).
//!
//! a_w is WOPP v3 (Röttgers et al.; Mason et al. 2016), bb_w Zhang et al. (2009) seawater, both
//! averaged over each band's response: the processor's own tables, not the scene's SIOPs.
//!
//! ## References
//! - Bailey, S. W., Franz, B. A. & Werdell, P. J. (2010) Estimation of near-infrared
//!   water-leaving reflectance for satellite ocean color data processing. Opt. Express 18,
//!   7521–7527.
//! - Lee, Z., Carder, K. L. & Arnone, R. A. (2002) Deriving inherent optical properties from
//!   water color: a multiband quasi-analytical algorithm. Appl. Opt. 41, 5755–5772.
//! - Gordon, H. R. et al. (1988) A semianalytic radiance model of ocean color. J. Geophys. Res.
//!   93, 10909–10924.
//! - O'Reilly, J. E. et al. (1998) Ocean color chlorophyll algorithms for SeaWiFS. J. Geophys.
//!   Res. 103, 24937–24953 (OC4; the OC4v6 coefficients of NASA's 2010 reprocessing).

use super::CorrectionError;
use super::image::invalid;
use crate::spectral::{BandAverager, BandSet, Extrapolation, Spectrum, WavelengthGrid};

/// Gordon et al. (1988) rrs(u) coefficients.
const G0: f64 = 0.0949;
const G1: f64 = 0.0794;
/// OC4v6 polynomial in log10 of the maximum blue-to-green ratio.
const OC4: [f64; 5] = [0.3272, -2.9940, 2.7218, -1.2259, -0.5683];
/// l2gen's damping of the NIR estimate between passes.
pub const DAMPING: f64 = 0.33;
/// l2gen's convergence: relative change of Rrs(670) between passes.
pub const CONVERGED: f64 = 0.02;
/// l2gen's `aer_iter_max`.
pub const MAX_PASSES: usize = 10;
/// The chlorophyll, mg m⁻³, l2gen reseeds a pass with where OC4 fails (`atmocor2.c`).
pub const TURBID_SEED_CHL: f64 = 10.0;

/// The band model and the bands it reads.
#[derive(Debug, Clone)]
pub struct NirWater {
    /// Bands near 443, 555 and 670 nm (l2gen: within 5, 15 and 50 nm).
    pub blue: usize,
    /// Green band.
    pub green: usize,
    /// Red band.
    pub red: usize,
    /// OC4's blue bands present (near 443, 490, 510 nm).
    blues: Vec<usize>,
    /// Pure-water absorption per band, m⁻¹.
    a_w: Vec<f64>,
    /// Pure-water backscattering per band, m⁻¹.
    bb_w: Vec<f64>,
    /// Band centres, nm.
    centres_nm: Vec<f64>,
}

fn nearest(centres: &[f64], target: f64, within: f64) -> Option<usize> {
    centres
        .iter()
        .enumerate()
        .map(|(i, c)| (i, (c - target).abs()))
        .filter(|&(_, d)| d <= within)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

impl NirWater {
    /// The model for a band set; an error names the bands it lacks.
    pub fn new(bands: &BandSet) -> Result<Self, CorrectionError> {
        let centres = bands.centres_nm();
        let need = |target: f64, within: f64| {
            nearest(&centres, target, within).ok_or_else(|| {
                invalid(
                    "correction.image.nir_iteration",
                    format!(
                        "needs a band within {within} nm of {target} nm (Bailey et al. 2010 read 443, 555 and 670 nm); \
                         turn it off for this design"
                    ),
                )
            })
        };
        let (blue, green, red) = (need(443.0, 5.0)?, need(555.0, 15.0)?, need(670.0, 50.0)?);
        let blues = [443.0, 490.0, 510.0].iter().filter_map(|&t| nearest(&centres, t, 5.0)).collect();
        let fail = |e: crate::spectral::SpectralError| invalid("correction.image.nir_iteration", e.to_string());
        let grid = WavelengthGrid::uniform(350.0, 2500.0, 1.0).map_err(fail)?;
        let averager = BandAverager::new(&grid, bands).map_err(fail)?;
        let on_grid = |file: &str, column: &str| -> Result<Vec<f64>, CorrectionError> {
            let s = Spectrum::from_asset(file, column).map_err(fail)?;
            Ok(averager.apply(&s.resample(&grid, Extrapolation::Clamp).map_err(fail)?))
        };
        Ok(Self {
            blue,
            green,
            red,
            blues,
            a_w: on_grid("water/water_absorption_wasi6.csv", "a_w_per_m")?,
            bb_w: on_grid("water/water_scattering_pure.csv", "bb_sw_S35")?,
            centres_nm: centres,
        })
    }

    /// OC4 chlorophyll, mg m⁻³, from above-surface Rrs; None where a ratio is not positive.
    #[must_use]
    pub fn chl_oc4(&self, rrs: impl Fn(usize) -> f64) -> Option<f64> {
        let green = rrs(self.green);
        let blue = self.blues.iter().map(|&b| rrs(b)).fold(f64::NEG_INFINITY, f64::max);
        if !(green > 0.0 && blue > 0.0) {
            return None;
        }
        let x = (blue / green).log10();
        let poly = OC4.iter().rev().fold(0.0, |acc, &c| acc * x + c);
        Some(10f64.powf(poly))
    }

    /// The above-surface Rrs, sr⁻¹, of the bands `nir` from the above-surface Rrs of the
    /// previous pass (`rrs(b)`) and its OC4 chlorophyll `chl_mg_m3`, or None where the model
    /// gives no NIR signal (Rrs(670) ≤ 0, bb_p ≤ 0).
    pub fn estimate(&self, rrs: impl Fn(usize) -> f64, chl_mg_m3: f64, nir: [usize; 2]) -> Option<[f64; 2]> {
        let below = |r: f64| r / (0.52 + 1.7 * r);
        let red = rrs(self.red);
        if red <= 0.0 {
            return None;
        }
        let chl = chl_mg_m3.clamp(0.2, 30.0);
        let a_red = self.a_w[self.red] + (0.9389 * chl.ln() - 3.7589).exp().clamp(0.0, 0.5);
        let u_red = u_from_rrs(below(red))?;
        let bbp_red = u_red * a_red / (1.0 - u_red) - self.bb_w[self.red];
        if bbp_red <= 0.0 {
            return None;
        }
        let (rb, rg) = (below(rrs(self.blue)), below(rrs(self.green)));
        let eta = if rb > 0.0 && rg > 0.0 { (2.0 * (1.0 - 1.2 * (-0.9 * rb / rg).exp())).clamp(0.0, 1.0) } else { 0.0 };
        let lambda_red = self.centres_nm[self.red];
        Some(nir.map(|b| {
            let bb = bbp_red * (lambda_red / self.centres_nm[b]).powf(eta) + self.bb_w[b];
            let u = bb / (self.a_w[b] + bb);
            let r = G0 * u + G1 * u * u;
            0.52 * r / (1.0 - 1.7 * r)
        }))
    }

    /// l2gen's ramp: the NIR estimate's weight at chlorophyll `chl`.
    #[must_use]
    pub fn ramp(chl: f64) -> f64 {
        ((chl - 0.7) / 0.6).clamp(0.0, 1.0)
    }
}

/// u = bb/(a + bb) from below-surface rrs by the inverse of rrs = g₀·u + g₁·u².
fn u_from_rrs(rrs: f64) -> Option<f64> {
    let disc = G0 * G0 + 4.0 * G1 * rrs;
    let u = (-G0 + disc.sqrt()) / (2.0 * G1);
    (u > 0.0 && u < 1.0).then_some(u)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn u_inverts_the_quadratic() {
        for u in [0.001, 0.05, 0.2] {
            let r = G0 * u + G1 * u * u;
            assert!((u_from_rrs(r).unwrap() - u).abs() < 1e-12);
        }
    }

    #[test]
    fn ramp_follows_l2gen() {
        assert_eq!(NirWater::ramp(0.5), 0.0);
        assert!((NirWater::ramp(1.0) - 0.5).abs() < 1e-12);
        assert_eq!(NirWater::ramp(2.0), 1.0);
    }
}
