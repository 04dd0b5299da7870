//! SAMBUCA-style shallow-water inversion (Brando et al. 2009; Lee et al. 1999 forward model):
//! per pixel, bounded nonlinear least squares over chl, CDOM, NAP, depth and the fraction q of
//! the first substrate of a pair, for every substrate pair; the best fit over pairs wins.
//!
//! Objectives (as in the SAMBUCA Python code, `sambuca/error.py`), with o and m the observed and
//! modelled band Rrs, both divided by the noise-equivalent ΔRrs when noise weighting is on:
//!
//! - `F` (Brando's distance): f = ‖o − m‖ / Σ o;
//! - `AlphaF`: α·f, α = arccos(o·m / (‖o‖‖m‖)), the spectral angle;
//! - `Lsq`: ‖o − m‖ (never noise-weighted in SAMBUCA; here weighted when asked).
//!
//! `F` and `Lsq` are least-squares problems and are solved by bounded Levenberg–Marquardt with
//! the analytic Jacobian ([`super::band_model`]); `AlphaF` is polished from the `F` solution by
//! projected BFGS on its analytic gradient. Concentrations and depth are optimised in log space
//! (they span decades; a relative step is the natural one), q linearly.
//!
//! **Starts.** The reference code starts once, at mid-range: where the bottom is out of sight
//! from there, depth and fractions have no gradient and it reports success at the start; and in
//! noise-free closure it often ends at a worse fit than the truth. Shoal starts every pair shallow
//! (2 m, mid-range concentrations in log space), where the bottom is in sight and every parameter
//! has a gradient, and adds a deep start (the depth's upper bound) wherever the best shallow fit
//! leaves the bottom undetectable (`Starts::Adaptive`, the default; `ShallowAndDeep` always does
//! both). The closure test shows the fit ends no worse than the truth.
//!
//! **Warm pairs.** The pairs share the water column: only the bottom's composition differs. So
//! each pair after the first starts from the best fit so far (its concentrations and depth, the
//! fraction at 0.5), which lies near the next pair's minimum wherever the bottom term is a small
//! change, unless one of those four sits on its bound: a fit pinned to a bound is where the
//! optimiser got stuck, and started from there the next pair can stay in the same poor basin.
//! The deep start stays cold (its purpose is the other basin). `warm_pairs: false` starts every
//! pair shallow; `tests/physics/sambuca_starts.rs` shows both reach the same minima on the
//! bench's pixels.
//!
//! **Substrate detectability index** (SAMBUCA; Sen2Coral): SDI = max_b |Rrs_b − Rrs_dp,b| / NEΔRrs_b
//! at the solution, the bottom's contribution in units of the noise; below 1 the bottom is not
//! detectable and the depth is unreliable.
//!
//! ## References
//! - Brando, V. E. et al. (2009) A physics based retrieval and quality assessment of bathymetry
//!   from suboptimal hyperspectral data. Remote Sens. Environ. 113, 755–770.
//! - Lee, Z. et al. (1999) Appl. Opt. 38, 3831–3843.

use serde::{Deserialize, Serialize};

use super::band_model::{BandModel, ModelScratch, Parameters};
use super::optimise::{Row, Tolerances, Workspace, levenberg_marquardt_in, projected_bfgs};

/// Which distance is minimised.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Objective {
    /// Brando's f = ‖o − m‖/Σo.
    F,
    /// Spectral angle × f.
    AlphaF,
    /// ‖o − m‖.
    Lsq,
}

/// Bounds of the free parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Bounds {
    /// Chlorophyll-a, mg m⁻³ (lower bound above 0: log space).
    pub chl_mg_m3: (f64, f64),
    /// CDOM absorption at the reference wavelength, m⁻¹.
    pub cdom_per_m: (f64, f64),
    /// NAP, g m⁻³.
    pub nap_g_m3: (f64, f64),
    /// Depth, m.
    pub depth_m: (f64, f64),
}

impl Default for Bounds {
    fn default() -> Self {
        Self { chl_mg_m3: (0.001, 300.0), cdom_per_m: (1e-5, 10.0), nap_g_m3: (1e-4, 200.0), depth_m: (0.1, 30.0) }
    }
}

/// Where each substrate pair's fit starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Starts {
    /// Shallow only (2 m, mid-range concentrations).
    Shallow,
    /// Shallow and deep (the depth's upper bound), every pixel.
    ShallowAndDeep,
    /// Shallow, and deep where the shallow fit leaves the bottom undetectable (SDI < 1).
    Adaptive,
}

/// Fewest valid bands a pixel is fitted with (fewer bands than parameters is allowed, as
/// SAMBUCA fits 5 parameters to 4-band imagery; the damping keeps the step defined).
pub const MIN_BANDS: usize = 3;

/// SAMBUCA settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SambucaSettings {
    /// The objective.
    pub objective: Objective,
    /// Divide the spectra by the noise-equivalent ΔRrs of each band.
    pub noise_weighting: bool,
    /// Bounds.
    pub bounds: Bounds,
    /// Iteration limit per start.
    pub max_iterations: u32,
    /// Gauss nodes per band in the forward model.
    pub nodes_per_band: usize,
    /// Which starts each pair gets.
    pub starts: Starts,
    /// Start each pair after the first from the best fit so far where none of its
    /// concentrations or depth sits on a bound (see the module's "Warm pairs").
    pub warm_pairs: bool,
    /// Shoal's inversion (`Improved`, the design default) or the CSIRO package's
    /// (`Reference`: [`super::sambuca_reference`]). The reference mode fixes what the package
    /// fixes — objective `distance_f` with the noise-equivalent ΔRrs, one start at
    /// (p_max − p_min)/2, SLSQP with 500 iterations, the full band sum — so `objective`,
    /// `noise_weighting`, `max_iterations`, `nodes_per_band`, `starts` and `warm_pairs` are then
    /// ignored; the bounds are used.
    pub mode: super::Mode,
}

impl Default for SambucaSettings {
    fn default() -> Self {
        Self {
            objective: Objective::F,
            noise_weighting: true,
            bounds: Bounds::default(),
            max_iterations: 100,
            nodes_per_band: 3,
            starts: Starts::Adaptive,
            warm_pairs: true,
            mode: super::Mode::Improved,
        }
    }
}

/// Per-pixel result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SambucaPixel {
    /// Chlorophyll-a, mg m⁻³.
    pub chl: f64,
    /// CDOM, m⁻¹.
    pub cdom: f64,
    /// NAP, g m⁻³.
    pub nap: f64,
    /// Depth, m.
    pub depth_m: f64,
    /// Substrate pair (indices into the model's substrates).
    pub pair: (u8, u8),
    /// Fraction of the pair's first substrate.
    pub fraction: f64,
    /// Objective at the solution.
    pub objective: f64,
    /// Substrate detectability index.
    pub sdi: f64,
    /// Iterations over all starts and pairs.
    pub iterations: u32,
    /// The winning start converged.
    pub converged: bool,
    /// A solution exists (enough valid bands).
    pub ok: bool,
}

impl SambucaPixel {
    /// No solution.
    pub const FAILED: Self = Self {
        chl: 0.0,
        cdom: 0.0,
        nap: 0.0,
        depth_m: 0.0,
        pair: (0, 0),
        fraction: 0.0,
        objective: f64::INFINITY,
        sdi: 0.0,
        iterations: 0,
        converged: false,
        ok: false,
    };
}

/// What one pixel's inversion needs besides the model: observations and geometry.
#[derive(Debug, Clone, Copy)]
pub struct Observation<'a> {
    /// Observed band Rrs, sr⁻¹.
    pub rrs: &'a [f64],
    /// Which bands are valid.
    pub valid: &'a [bool],
    /// Noise-equivalent ΔRrs per band, sr⁻¹.
    pub nedr: &'a [f64],
    /// In-water inverse cosines (sun, view).
    pub inv_cos: (f64, f64),
}

/// Value of the objective for modelled `m` against the observation.
#[must_use]
pub fn objective_value(objective: Objective, obs: &Observation<'_>, weights: &[f64], m: &[f64]) -> f64 {
    let (mut num, mut sum_o, mut oo, mut mm, mut om) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for b in 0..m.len() {
        if weights[b] == 0.0 {
            continue;
        }
        let (o, mv) = (obs.rrs[b] * weights[b], m[b] * weights[b]);
        num += (o - mv) * (o - mv);
        sum_o += o;
        oo += o * o;
        mm += mv * mv;
        om += o * mv;
    }
    match objective {
        Objective::Lsq => num.sqrt(),
        Objective::F => num.sqrt() / sum_o.abs().max(1e-30),
        Objective::AlphaF => {
            let c = (om / (oo * mm).sqrt().max(1e-30)).clamp(-1.0, 1.0);
            c.acos() * num.sqrt() / sum_o.abs().max(1e-30)
        }
    }
}

/// The working arrays of a pixel's inversion ([`invert_in`]), kept from pixel to pixel so that
/// a row allocates them once.
#[derive(Debug, Clone, Default)]
pub struct Scratch {
    /// Per band: the residual weight (0 for a band left out).
    weights: Vec<f64>,
    /// The model's Rrs and its Jacobian.
    m: Vec<f64>,
    jac: Vec<[f64; 5]>,
    /// The optically deep Rrs (the SDI).
    deep: Vec<f64>,
    model: ModelScratch,
    /// The optimiser's working arrays.
    work: Workspace,
}

/// Working state of one pixel's inversion.
struct Pixel<'a> {
    model: &'a BandModel,
    settings: &'a SambucaSettings,
    obs: &'a Observation<'a>,
    s: &'a mut Scratch,
    scale: f64,
    lo: [f64; 5],
    hi: [f64; 5],
    iterations: u32,
}

fn to_params(z: &[f64], pair: (usize, usize)) -> Parameters {
    Parameters {
        chl: z[0].exp(),
        cdom: z[1].exp(),
        nap: z[2].exp(),
        depth_m: Some(z[3].exp()),
        substrates: (pair.0, pair.1, z[4]),
    }
}

impl Pixel<'_> {
    /// Fit `pair` from `start` (optimisation variables); the result as a pixel.
    fn fit(&mut self, pair: (usize, usize), start: &[f64; 5]) -> SambucaPixel {
        let nb = self.model.n_bands();
        let tol = Tolerances { max_iterations: self.settings.max_iterations, ..Tolerances::default() };
        let (model, obs, scale) = (self.model, self.obs, self.scale);
        let Scratch { weights, m, jac, model: scratch, work, .. } = &mut *self.s;
        let weights = &*weights;
        let residuals = |z: &[f64], r: &mut [f64], jrows: &mut [Row]| -> bool {
            let p = to_params(z, pair);
            model.evaluate_with(&p, obs.inv_cos, m, Some(jac), scratch);
            let dz = [p.chl, p.cdom, p.nap, p.depth_m.unwrap_or(1.0), 1.0];
            // Zipped slices instead of indices: no bounds check in the loop (the same arithmetic).
            let rows = r.iter_mut().zip(jrows.iter_mut()).zip(&weights[..nb]).zip(&jac[..nb]);
            for ((((r_b, j_row), &w_b), jac_b), (&m_b, &o_b)) in rows.zip(m[..nb].iter().zip(&obs.rrs[..nb])) {
                let w = scale * w_b;
                *r_b = w * (m_b - o_b);
                for ((j, &d), &dz_k) in j_row[..5].iter_mut().zip(jac_b).zip(&dz) {
                    *j = w * d * dz_k;
                }
            }
            r.iter().all(|v| v.is_finite())
        };
        let mut sol = levenberg_marquardt_in(work, residuals, (start, &self.lo, &self.hi), nb, &tol);
        self.iterations += sol.iterations;
        if self.settings.objective == Objective::AlphaF {
            let f = |z: &[f64], g: &mut [f64]| -> Option<f64> {
                let p = to_params(z, pair);
                model.evaluate_with(&p, obs.inv_cos, m, Some(jac), scratch);
                let dz = [p.chl, p.cdom, p.nap, p.depth_m.unwrap_or(1.0), 1.0];
                let value = alpha_f_with_gradient(obs, weights, m, jac, &dz, g);
                value.is_finite().then_some(value)
            };
            let polished = projected_bfgs(f, &sol.x, &self.lo, &self.hi, &tol);
            self.iterations += polished.iterations;
            sol = polished;
        }
        let p = to_params(&sol.x, pair);
        self.model.evaluate_with(&p, obs.inv_cos, m, None, scratch);
        let value = objective_value(self.settings.objective, obs, weights, m);
        SambucaPixel {
            chl: p.chl,
            cdom: p.cdom,
            nap: p.nap,
            depth_m: p.depth_m.unwrap_or(0.0),
            pair: (u8::try_from(pair.0).unwrap_or(u8::MAX), u8::try_from(pair.1.min(255)).unwrap_or(u8::MAX)),
            fraction: sol.x[4],
            objective: value,
            sdi: 0.0,
            iterations: 0,
            converged: sol.converged,
            ok: value.is_finite(),
        }
    }

    /// The substrate detectability index of a solution.
    fn sdi(&mut self, best: &SambucaPixel) -> f64 {
        let nb = self.model.n_bands();
        let p = Parameters {
            chl: best.chl,
            cdom: best.cdom,
            nap: best.nap,
            depth_m: Some(best.depth_m),
            substrates: (
                usize::from(best.pair.0),
                if best.pair.1 == u8::MAX { usize::MAX } else { usize::from(best.pair.1) },
                best.fraction,
            ),
        };
        let Scratch { m, deep, model: scratch, .. } = &mut *self.s;
        deep.resize(nb, 0.0);
        self.model.evaluate_with(&p, self.obs.inv_cos, m, None, scratch);
        self.model.evaluate_deep_with(&p, deep, scratch);
        (0..nb)
            .filter(|&b| self.obs.nedr[b] > 0.0)
            .map(|b| (m[b] - deep[b]).abs() / self.obs.nedr[b])
            .fold(0.0, f64::max)
    }
}

/// Invert one pixel with `model`.
#[must_use]
pub fn invert(model: &BandModel, settings: &SambucaSettings, obs: &Observation<'_>) -> SambucaPixel {
    invert_in(&mut Scratch::default(), model, settings, obs)
}

/// [`invert`] in `scratch` (whatever it held: the same pixel), for loops over pixels.
#[must_use]
pub fn invert_in(
    scratch: &mut Scratch,
    model: &BandModel,
    settings: &SambucaSettings,
    obs: &Observation<'_>,
) -> SambucaPixel {
    let nb = model.n_bands();
    scratch.weights.clear();
    scratch.weights.extend((0..nb).map(|b| {
        let ok = obs.valid[b] && obs.rrs[b].is_finite();
        if !ok {
            0.0
        } else if settings.noise_weighting {
            if obs.nedr[b] > 0.0 { 1.0 / obs.nedr[b] } else { 0.0 }
        } else {
            1.0
        }
    }));
    let weights = &scratch.weights;
    let n_valid = weights.iter().filter(|w| **w > 0.0).count();
    let sum_o: f64 = (0..nb).map(|b| obs.rrs[b] * weights[b]).sum();
    if n_valid < MIN_BANDS || !(sum_o > 0.0) {
        return SambucaPixel::FAILED;
    }
    // F divides by Σo, a constant per pixel: the same minimiser as weighted least squares.
    let scale = match settings.objective {
        Objective::Lsq => 1.0,
        Objective::F | Objective::AlphaF => 1.0 / sum_o,
    };
    let bnd = &settings.bounds;
    let lo = [bnd.chl_mg_m3.0.ln(), bnd.cdom_per_m.0.ln(), bnd.nap_g_m3.0.ln(), bnd.depth_m.0.ln(), 0.0];
    let hi = [bnd.chl_mg_m3.1.ln(), bnd.cdom_per_m.1.ln(), bnd.nap_g_m3.1.ln(), bnd.depth_m.1.ln(), 1.0];
    let n_sub = model.substrate_names().len();
    // Every substrate pair (i < j), in order, or the one substrate alone.
    let pairs = || {
        let one = (n_sub < 2).then_some((0, usize::MAX));
        one.into_iter().chain((0..n_sub).flat_map(move |i| (i + 1..n_sub).map(move |j| (i, j))))
    };
    let mid = |k: usize| 0.5 * (lo[k] + hi[k]);
    let start = |depth_ln: f64| [mid(0), mid(1), mid(2), depth_ln, 0.5];
    let shallow = start(2.0f64.clamp(bnd.depth_m.0, bnd.depth_m.1).ln());
    let deep = start(hi[3]);
    scratch.m.resize(nb, 0.0);
    scratch.jac.resize(nb, [0.0; 5]);
    let mut px = Pixel { model, settings, obs, s: scratch, scale, lo, hi, iterations: 0 };
    let mut best = SambucaPixel::FAILED;
    let keep = |candidate: SambucaPixel, best: &mut SambucaPixel| {
        if candidate.ok && candidate.objective < best.objective {
            *best = candidate;
        }
    };
    for pair in pairs() {
        let from = if settings.warm_pairs { warm_start(&best, &lo, &hi).unwrap_or(shallow) } else { shallow };
        let fit = px.fit(pair, &from);
        keep(fit, &mut best);
    }
    if best.ok {
        best.sdi = px.sdi(&best);
    }
    // The deep start: always, or where the shallow start left the bottom undetectable (depth and
    // fractions then have no gradient, and a start's neighbourhood is all the fit has seen).
    let deep_too = match settings.starts {
        Starts::Shallow => false,
        Starts::ShallowAndDeep => true,
        Starts::Adaptive => !best.ok || best.sdi < 1.0,
    };
    if deep_too {
        let before = best.objective;
        for pair in pairs() {
            let fit = px.fit(pair, &deep);
            keep(fit, &mut best);
        }
        if best.objective < before {
            best.sdi = px.sdi(&best);
        }
    }
    best.iterations = px.iterations;
    best
}

/// The start a pair takes from the best fit so far (module docs, "Warm pairs"): its
/// concentrations and depth in log space and the fraction at 0.5, or `None` where there is no fit
/// yet or one of the four sits on its bound (within 10⁻⁶ in log space, the round trip through
/// `exp` and `ln`).
fn warm_start(best: &SambucaPixel, lo: &[f64; 5], hi: &[f64; 5]) -> Option<[f64; 5]> {
    if !best.ok {
        return None;
    }
    let z = [best.chl.ln(), best.cdom.ln(), best.nap.ln(), best.depth_m.ln(), 0.5];
    (0..4).all(|k| z[k] > lo[k] + 1e-6 && z[k] < hi[k] - 1e-6).then_some(z)
}

/// α·f and its gradient with respect to the optimisation variables (∂m/∂z = ∂m/∂p · dp/dz).
fn alpha_f_with_gradient(
    obs: &Observation<'_>,
    w: &[f64],
    m: &[f64],
    jac: &[[f64; 5]],
    dz: &[f64; 5],
    grad: &mut [f64],
) -> f64 {
    let nb = m.len();
    let (mut num, mut sum_o, mut oo, mut mm, mut om) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for b in 0..nb {
        let (o, mv) = (obs.rrs[b] * w[b], m[b] * w[b]);
        num += (o - mv) * (o - mv);
        sum_o += o;
        oo += o * o;
        mm += mv * mv;
        om += o * mv;
    }
    let norm = num.sqrt();
    let f = norm / sum_o;
    let (no, nm) = (oo.sqrt(), mm.sqrt().max(1e-300));
    let c = (om / (no * nm)).clamp(-1.0, 1.0);
    let alpha = c.acos();
    // dα/dm_b = −1/√(1−c²) · (o_b/(‖o‖‖m‖) − c·m_b/‖m‖²), df/dm_b = (m_b − o_b)/(‖o−m‖·Σo).
    let s = (1.0 - c * c).max(1e-24).sqrt();
    for g in grad.iter_mut() {
        *g = 0.0;
    }
    for b in 0..nb {
        if w[b] == 0.0 {
            continue;
        }
        let (o, mv) = (obs.rrs[b] * w[b], m[b] * w[b]);
        let d_alpha = -(o / (no * nm) - c * mv / (nm * nm)) / s;
        let d_f = if norm > 0.0 { (mv - o) / (norm * sum_o) } else { 0.0 };
        let d_value = d_alpha * f + alpha * d_f;
        for k in 0..5 {
            grad[k] += d_value * w[b] * jac[b][k] * dz[k];
        }
    }
    alpha * f
}
