//! aLMI, the adaptive linear matrix inversion (Brando et al. 2012; the public Python code of
//! GeoscienceAustralia/DEA-Water-Quality).
//!
//! Per band: sub-surface rrs = Rrs/(0.52 + 1.7·Rrs); u from rrs = g0·u + g1·u² (the positive
//! root); and, since u = bb/(a + bb) ⇔ a·u = bb·(1 − u), a linear equation in the concentrations:
//!
//! Σ_c C_c·(a*_c·u − bb*_c·(1 − u)) = bb_w·(1 − u) − a_w·u,  c ∈ {chl, CDOM, NAP}.
//!
//! The system is solved for every SIOP set; the set whose solution predicts the observed rrs best
//! (cost √mean(Δrrs²)/mean(rrs), as in the reference) is kept. Where the reference solves
//! without constraint and throws away any solution with a concentration below 1e-5 — so that a
//! truly absent constituent, scattering around zero, makes it pick a wrong set or return nothing —
//! Shoal solves with the non-negativity constraint ([`super::nnls`]): an absent constituent comes
//! out as exactly zero and the pixel is kept. A band with an invalid Rrs (non-finite, ≤ 0, or a
//! saturated/invalid flag) is left out of that pixel's system rather than failing the pixel, as
//! long as at least three bands remain.
//!
//! g0 = 0.084, g1 = 0.17 (Lee et al. 1999, the constants of the reference's configuration files
//! and of Shoal's forward model). SIOPs are band-averaged over each band's response.
//!
//! ## References
//! - Brando, V. E., Dekker, A. G., Park, Y. J., Schroeder, T. (2012) Adaptive semianalytical
//!   inversion of ocean color radiometry in optically complex waters. Appl. Opt. 51, 2808–2833.
//! - Lee, Z. et al. (1999) Appl. Opt. 38, 3831–3843.

use serde::{Deserialize, Serialize};

pub use super::Mode;
use super::band_model::BandIops;
use super::nnls::{finite, nnls3};
use crate::water::rrs_below_from_above;

/// aLMI settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AlmiSettings {
    /// Linear coefficient of rrs(u).
    pub g0: f64,
    /// Quadratic coefficient of rrs(u).
    pub g1: f64,
    /// Bands to use, by name (`None`: every band from 400 to 780 nm outside the O₂ A band).
    pub bands: Option<Vec<String>>,
    /// Weight each band's equation by its noise, propagated from the Rrs noise through u (one
    /// reweighting pass, generalised least squares), and rank SIOP sets by the noise-normalised
    /// rrs misfit. Off: the reference's unweighted solve and relative-RMSE ranking.
    pub noise_weighting: bool,
    /// Shoal's inversion (`Improved`, the design default) or the reference code's, step for step
    /// (`Reference`: [`super::almi_reference`]; `noise_weighting` is then ignored).
    pub mode: Mode,
}

impl Default for AlmiSettings {
    fn default() -> Self {
        Self { g0: 0.084, g1: 0.17, bands: None, noise_weighting: true, mode: Mode::Improved }
    }
}

/// Per-pixel outcome flags of aLMI.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AlmiFlags;

impl AlmiFlags {
    /// The unconstrained solution of the chosen set was already non-negative.
    pub const PHYSICAL: u8 = 1;
    /// At least one constituent sits at the zero bound.
    pub const AT_BOUND: u8 = 2;
    /// No solution: too few valid bands or no finite system.
    pub const FAILED: u8 = 4;
    /// Reference mode: a band failed the Rrs > 1e-6 screen (with `FAILED`).
    pub const SCREENED: u8 = 8;
    /// Reference mode: every SIOP set was dropped (with `FAILED`).
    pub const NO_VALID_SET: u8 = 16;
}

/// One SIOP set as aLMI sees it: band-averaged IOPs of the bands in use.
#[derive(Debug, Clone, PartialEq)]
pub struct AlmiSet {
    /// Name.
    pub name: String,
    /// Band IOPs (already restricted to the bands in use).
    pub iops: BandIops,
}

/// The result for one pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlmiPixel {
    /// Chlorophyll-a, mg m⁻³ (0 when at the bound or failed).
    pub chl: f64,
    /// CDOM absorption at the reference wavelength, m⁻¹.
    pub cdom: f64,
    /// NAP, g m⁻³.
    pub nap: f64,
    /// Index of the chosen SIOP set.
    pub set: Option<u8>,
    /// Cost of the chosen set.
    pub cost: f64,
    /// [`AlmiFlags`].
    pub flags: u8,
}

impl AlmiPixel {
    /// A failed pixel.
    pub const FAILED: Self =
        Self { chl: 0.0, cdom: 0.0, nap: 0.0, set: None, cost: f64::INFINITY, flags: AlmiFlags::FAILED };
}

/// u from sub-surface rrs: the positive root of g1·u² + g0·u − rrs = 0.
#[must_use]
pub fn u_from_rrs(rrs: f64, g0: f64, g1: f64) -> f64 {
    (-g0 + (g0 * g0 + 4.0 * g1 * rrs).sqrt()) / (2.0 * g1)
}

/// A pixel's per-band quantities, shared by [`invert`] and the lane version
/// ([`super::almi_lanes`]): the bands in use, sub-surface rrs, u, and the noise σ of rrs and u.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Prepared {
    /// Indices of the bands in use (the first `m`).
    pub used: [usize; MAX_BANDS],
    /// Bands in use.
    pub m: usize,
    /// Sub-surface rrs per band in use.
    pub rrs: [f64; MAX_BANDS],
    /// u per band in use.
    pub u: [f64; MAX_BANDS],
    /// σ of u per band in use (1 without noise weighting).
    pub sigma_u: [f64; MAX_BANDS],
    /// 1/σ of rrs per band in use (1 without noise weighting): the cost multiplies by it, one
    /// division per band rather than one per band and SIOP set.
    pub inv_sigma_rrs: [f64; MAX_BANDS],
    /// Mean rrs over the bands in use.
    pub mean_rrs: f64,
    /// Work space of [`Self::prepare`]: above-water Rrs and noise of the bands in use.
    above: [f64; MAX_BANDS],
    noise: [f64; MAX_BANDS],
}

impl Default for Prepared {
    fn default() -> Self {
        Self {
            used: [0; MAX_BANDS],
            m: 0,
            rrs: [0.0; MAX_BANDS],
            u: [0.0; MAX_BANDS],
            sigma_u: [1.0; MAX_BANDS],
            inv_sigma_rrs: [1.0; MAX_BANDS],
            mean_rrs: 0.0,
            above: [0.0; MAX_BANDS],
            noise: [0.0; MAX_BANDS],
        }
    }
}

impl Prepared {
    /// Fill from one pixel; false if fewer than three bands are usable or an rrs is not positive.
    /// Only the first `m` entries of each array are written and read, so one `Prepared` serves
    /// pixel after pixel (zeroing its 3 kB for each pixel was 5 % of aLMI's time).
    #[inline(always)]
    pub fn prepare(&mut self, settings: &AlmiSettings, rrs_above: &[f64], valid: &[bool], nedr: &[f64]) -> bool {
        let (g0, g1) = (settings.g0, settings.g1);
        let n = rrs_above.len().min(MAX_BANDS);
        self.m = 0;
        for k in 0..n {
            if valid[k] && rrs_above[k].is_finite() && rrs_above[k] > 0.0 {
                self.used[self.m] = k;
                self.m += 1;
            }
        }
        if self.m < 3 {
            return false;
        }
        let m = self.m;
        // Each quantity in its own loop over the bands, with no early exit inside, so that the
        // compiler can run bands side by side (this function was 11 % of aLMI's time in perf;
        // split, aLMI runs 2–6 % faster than with one loop per band, at 8 and 14 bands). The
        // same operations per band, so the same bits.
        for (a, &k) in self.above[..m].iter_mut().zip(&self.used[..m]) {
            *a = rrs_above[k];
        }
        let above = &self.above[..m];
        for (r, &a) in self.rrs[..m].iter_mut().zip(above) {
            *r = rrs_below_from_above(a);
        }
        // (`finite` is `is_finite()` as a comparison, which vectorises beside r > 0.)
        if !self.rrs[..m].iter().fold(true, |ok, r| ok & finite(*r) & (*r > 0.0)) {
            return false;
        }
        for (u, &r) in self.u[..m].iter_mut().zip(&self.rrs[..m]) {
            *u = u_from_rrs(r, g0, g1);
        }
        if settings.noise_weighting {
            // σ of rrs and of u per band, from the Rrs noise (rrs = R/(0.52 + 1.7R):
            // drrs/dR = 0.52/(0.52 + 1.7R)²).
            for (n, &k) in self.noise[..m].iter_mut().zip(&self.used[..m]) {
                *n = nedr.get(k).copied().unwrap_or(0.0);
            }
            let bands =
                self.inv_sigma_rrs[..m].iter_mut().zip(&mut self.sigma_u[..m]).zip(above.iter().zip(&self.noise[..m]));
            for (((inv_sigma_rrs, sigma_u), (&a, &n)), &u) in bands.zip(&self.u[..m]) {
                let d = 0.52 + 1.7 * a;
                let sigma_rrs = (n * 0.52 / (d * d)).max(1e-12);
                *inv_sigma_rrs = 1.0 / sigma_rrs;
                *sigma_u = sigma_rrs / (g0 + 2.0 * g1 * u);
            }
        } else {
            self.inv_sigma_rrs[..m].fill(1.0);
            self.sigma_u[..m].fill(1.0);
        }
        self.mean_rrs = self.rrs[..m].iter().sum::<f64>() / m as f64;
        true
    }
}

/// Invert one pixel: `rrs_above[k]` and `valid[k]` for the bands in use (same order as the
/// sets' IOPs); `nedr[k]`, the noise-equivalent ΔRrs of each band, weights the equations when
/// the settings ask for noise weighting.
#[must_use]
pub fn invert(sets: &[AlmiSet], settings: &AlmiSettings, rrs_above: &[f64], valid: &[bool], nedr: &[f64]) -> AlmiPixel {
    let (g0, g1) = (settings.g0, settings.g1);
    let mut p = Prepared::default();
    if !p.prepare(settings, rrs_above, valid, nedr) {
        return AlmiPixel::FAILED;
    }
    let Prepared { ref used, m, ref rrs, ref u, ref sigma_u, ref inv_sigma_rrs, mean_rrs, .. } = p;
    let used = &used[..m];
    let mut best = AlmiPixel::FAILED;
    // Per set: the rows of the system (r, y) and a + bb's pieces, computed once per pixel and set
    // and used by both solves and the cost (they were rebuilt for each before).
    let mut r = [[0.0; 3]; MAX_BANDS];
    let mut y = [0.0; MAX_BANDS];
    for (s, set) in sets.iter().enumerate() {
        let o = &set.iops;
        for (i, &k) in used.iter().enumerate() {
            let (u, v) = (u[i], 1.0 - u[i]);
            r[i] = [o.a_ph[k] * u - o.bb_ph[k] * v, o.a_cdom[k] * u, o.a_nap[k] * u - o.bb_nap[k] * v];
            y[i] = o.bb_w[k] * v - o.a_w[k] * u;
        }
        let kappa = |i: usize, x: &[f64; 3]| -> (f64, f64) {
            let k = used[i];
            let a = o.a_w[k] + x[0] * o.a_ph[k] + x[1] * o.a_cdom[k] + x[2] * o.a_nap[k];
            let bb = o.bb_w[k] + x[0] * o.bb_ph[k] + x[2] * o.bb_nap[k];
            (a, bb)
        };
        // The weighted normal equations (G symmetric: six sums, not nine).
        let solve = |w2: Option<&[f64]>| -> Option<([f64; 3], f64, [f64; 3])> {
            let (mut g00, mut g01, mut g02, mut g11, mut g12, mut g22) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            let (mut b0, mut b1, mut b2, mut yy) = (0.0, 0.0, 0.0, 0.0);
            for i in 0..m {
                let w = w2.map_or(1.0, |w| w[i]);
                let [r0, r1, r2] = r[i];
                let (wr0, wr1, wr2, wy) = (w * r0, w * r1, w * r2, w * y[i]);
                g00 += wr0 * r0;
                g01 += wr0 * r1;
                g02 += wr0 * r2;
                g11 += wr1 * r1;
                g12 += wr1 * r2;
                g22 += wr2 * r2;
                b0 += wr0 * y[i];
                b1 += wr1 * y[i];
                b2 += wr2 * y[i];
                yy += wy * y[i];
            }
            nnls3(&[[g00, g01, g02], [g01, g11, g12], [g02, g12, g22]], &[b0, b1, b2], yy)
        };
        let Some(mut sol) = solve(None) else { continue };
        if settings.noise_weighting {
            // Generalised least squares by one reweighting: the equation u·κ − bb errs by κ·σ_u,
            // with κ from the unweighted solution (κ varies slowly with the concentrations; a
            // second pass changes chl by < 0.1 % on the Lake Hume scene).
            let mut w2 = [1.0; MAX_BANDS];
            for (i, w) in w2[..m].iter_mut().enumerate() {
                let (a, bb) = kappa(i, &sol.0);
                let w1 = 1.0 / ((a + bb) * sigma_u[i]).max(1e-300);
                *w = w1 * w1;
            }
            if let Some(next) = solve(Some(&w2[..m])) {
                sol = next;
            }
        }
        let (x, _, unconstrained) = sol;
        // Cost in rrs space (noise-normalised when weighting): the forward model with x.
        let mut sq = 0.0;
        for i in 0..m {
            let (a, bb) = kappa(i, &x);
            let up = bb / (a + bb);
            let d = (g0 + g1 * up) * up - rrs[i];
            sq += if settings.noise_weighting { (d * inv_sigma_rrs[i]).powi(2) } else { d * d };
        }
        let cost = if settings.noise_weighting { (sq / m as f64).sqrt() } else { (sq / m as f64).sqrt() / mean_rrs };
        if cost.is_finite() && cost < best.cost {
            let physical = unconstrained.iter().all(|v| *v >= 0.0);
            let at_bound = x.contains(&0.0);
            best = AlmiPixel {
                chl: x[0],
                cdom: x[1],
                nap: x[2],
                set: u8::try_from(s).ok(),
                cost,
                flags: if physical { AlmiFlags::PHYSICAL } else { 0 } | if at_bound { AlmiFlags::AT_BOUND } else { 0 },
            };
        }
    }
    best
}

/// Most bands aLMI takes (the per-pixel arrays live on the stack).
pub const MAX_BANDS: usize = 64;

#[cfg(test)]
mod tests {
    use super::*;

    fn set(scale_nap: f64) -> AlmiSet {
        // Five bands of plausible band-averaged IOPs (m⁻¹ and specific units).
        AlmiSet {
            name: format!("nap×{scale_nap}"),
            iops: BandIops {
                a_w: vec![0.007, 0.015, 0.062, 0.43, 0.80],
                bb_w: vec![0.0024, 0.0016, 0.0010, 0.0005, 0.0004],
                a_ph: vec![0.060, 0.040, 0.015, 0.018, 0.004],
                a_cdom: vec![1.0, 0.45, 0.14, 0.028, 0.012],
                a_nap: vec![0.045, 0.030, 0.014, 0.005, 0.003],
                bb_ph: vec![0.0011, 0.0010, 0.0009, 0.0008, 0.0007],
                bb_nap: vec![
                    0.0095 * scale_nap,
                    0.0087 * scale_nap,
                    0.0079 * scale_nap,
                    0.0066 * scale_nap,
                    0.0062 * scale_nap,
                ],
            },
        }
    }

    fn forward(set: &AlmiSet, c: (f64, f64, f64), s: &AlmiSettings) -> Vec<f64> {
        let o = &set.iops;
        (0..5)
            .map(|k| {
                let a = o.a_w[k] + c.0 * o.a_ph[k] + c.1 * o.a_cdom[k] + c.2 * o.a_nap[k];
                let bb = o.bb_w[k] + c.0 * o.bb_ph[k] + c.2 * o.bb_nap[k];
                let u = bb / (a + bb);
                crate::water::rrs_above_from_below((s.g0 + s.g1 * u) * u)
            })
            .collect()
    }

    #[test]
    fn noise_free_closure_with_the_right_set() {
        let s = AlmiSettings::default();
        let sets = vec![set(0.5), set(1.0), set(2.0)];
        for truth in [(10.0, 1.0, 10.0), (0.15, 0.003, 1.0), (100.0, 0.2, 0.5)] {
            let rrs = forward(&sets[1], truth, &s);
            let p = invert(&sets, &s, &rrs, &[true; 5], &[1e-4; 5]);
            assert_eq!(p.set, Some(1));
            for (got, want) in [(p.chl, truth.0), (p.cdom, truth.1), (p.nap, truth.2)] {
                assert!((got / want - 1.0).abs() < 1e-6, "{got} vs {want}");
            }
            assert!(p.flags & AlmiFlags::PHYSICAL != 0);
        }
    }

    #[test]
    fn an_absent_constituent_is_zero_not_a_failure() {
        let s = AlmiSettings::default();
        let sets = vec![set(1.0)];
        let rrs = forward(&sets[0], (5.0, 0.0, 3.0), &s);
        let p = invert(&sets, &s, &rrs, &[true; 5], &[1e-4; 5]);
        assert!(p.flags & AlmiFlags::FAILED == 0);
        assert!(p.cdom.abs() < 1e-9, "{}", p.cdom);
        assert!((p.chl / 5.0 - 1.0).abs() < 1e-6 && (p.nap / 3.0 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn invalid_bands_are_skipped_and_too_few_fail() {
        let s = AlmiSettings::default();
        let sets = vec![set(1.0)];
        let mut rrs = forward(&sets[0], (5.0, 0.5, 3.0), &s);
        rrs[4] = f64::NAN;
        let p = invert(&sets, &s, &rrs, &[true, true, true, true, true], &[1e-4; 5]);
        assert!(p.flags & AlmiFlags::FAILED == 0 && (p.chl / 5.0 - 1.0).abs() < 1e-6);
        let p = invert(&sets, &s, &rrs, &[true, false, false, true, true], &[1e-4; 5]);
        assert_eq!(p.flags, AlmiFlags::FAILED);
        assert!(p.chl.is_finite());
    }
}
