//! SAMBUCA as the CSIRO package runs it (`sambuca.minimize`, `sambuca_core.forward_model`): the
//! reference mode of [`super::sambuca`], to reproduce published numbers.
//!
//! What the package does, and so what this module does (described in our words in
//! `tests/data/retrieval_reference/sambuca/README.md` §2.5, from runs of the unmodified code):
//!
//! - **Forward model** (Lee et al. 1998, 1999, as `sambuca_core` 1.2.3 writes it) at every
//!   wavelength of the input grid: a = a_w + C·a*_ph + G·a*_CDOM + X·a*_NAP,
//!   bb = bb_w + C·bb*_ph + X·bb*_NAP, κ = a + bb, u = bb/κ, rrs_dp = (0.084 + 0.17u)u,
//!   D_C = 1.03√(1 + 2.4u), D_B = 1.04√(1 + 5.4u),
//!   rrs = rrs_dp(1 − e^{−(1/μw + D_C/μo)κH}) + (ρ/π)e^{−(1/μw + D_B/μo)κH}, ρ = qρ₁ + (1 − q)ρ₂.
//!   Sub-surface rrs throughout: the package has no Rrs(0+) conversion.
//! - **Bands**: closed_rrs_b = Σ_λ F_b(λ)·rrs(λ) / Σ_λ F_b(λ), the full sum over the grid (no
//!   quadrature rule).
//! - **Objective** `distance_f` with NEDR: f = ‖(o − m)/NEDR‖₂ / Σ(o/NEDR) (Brando et al. 2009).
//! - **Fit**: for every substrate pair, in `itertools.combinations` order, SciPy's SLSQP
//!   ([`super::slsqp`]) over linear (chl, CDOM, NAP, depth, q) within the bounds, from
//!   p0 = (p_max − p_min)/2 — half the range, not its middle — with `maxiter` 500, `ftol` 1e-6 and
//!   forward-difference gradients.
//! - **Pair choice**: a pair is kept when it succeeded and its f is below the best so far
//!   (strict: the first pair wins ties); `nit` is summed over all pairs; the success flag is the
//!   kept pair's. If no pair succeeded the result is the *last* pair's x, with no pair kept.
//! - **The stall is kept, not fixed**: from p0's depth (14.95 m with 0.1–30 m bounds) the bottom is
//!   almost invisible, ∂f/∂depth and ∂f/∂q are tiny, SLSQP fits the water as if deep and stops
//!   with success once f changes by less than `ftol`, depth and q still at the start. A fit is
//!   flagged `stalled` when it succeeded with |depth − p0_depth| < 0.01 m (the reference data's
//!   definition).
//!
//! ## References
//! - Brando, V. E. et al. (2009) A physics based retrieval and quality assessment of bathymetry
//!   from suboptimal hyperspectral data. Remote Sens. Environ. 113, 755–770.
//! - Lee, Z. et al. (1998) Appl. Opt. 37, 6329–6338; (1999) Appl. Opt. 38, 3831–3843.
//! - CSIRO `sambuca` 1.0.0 (github.com/stevesagar/sambuca @ d153684) and `sambuca_core` 1.2.3.

use std::path::Path;

use super::RetrievalError;
use super::band_model::BandResponse;
use super::slsqp::{SlsqpOptions, SlsqpStatus, slsqp};
use crate::parse::FieldError;
use crate::spectral::WavelengthGrid;
use crate::water::{SiopSpec, SubstrateLibrary, SubstrateMix};

/// The package's `maxiter`.
pub const MAX_ITERATIONS: u32 = 500;
/// SciPy's default `ftol`, which the package leaves as it is.
pub const FTOL: f64 = 1e-6;
/// A fit that succeeded within this distance of the start depth has stalled, m.
pub const STALL_DEPTH_M: f64 = 0.01;

/// The spectra `sambuca_core.forward_model` is given, on one wavelength grid.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceSpectra {
    /// The grid, nm.
    pub wavelengths_nm: Vec<f64>,
    /// Pure-water absorption, m⁻¹.
    pub a_w: Vec<f64>,
    /// Pure-water backscattering, m⁻¹.
    pub bb_w: Vec<f64>,
    /// a*_ph, m² mg⁻¹.
    pub a_ph_star: Vec<f64>,
    /// a*_CDOM, per unit a_CDOM at the reference wavelength.
    pub a_cdom_star: Vec<f64>,
    /// a*_NAP, m² g⁻¹.
    pub a_nap_star: Vec<f64>,
    /// bb*_ph, m² mg⁻¹.
    pub bb_ph_star: Vec<f64>,
    /// bb*_NAP, m² g⁻¹.
    pub bb_nap_star: Vec<f64>,
    /// Substrate names, in the order pairs are formed.
    pub substrate_names: Vec<String>,
    /// Substrate irradiance reflectances, one per grid wavelength.
    pub substrates: Vec<Vec<f64>>,
}

impl ReferenceSpectra {
    /// `sambuca_core.forward_model`'s default parametrisations on `wavelengths_nm`, with the
    /// given water and phytoplankton absorption and substrates:
    /// a*_CDOM = e^{−0.0168052(λ − 550)} (so CDOM is a_CDOM(550)),
    /// a*_NAP = 0.00433·e^{−0.00977262(λ − 550)}, bb*_ph = 0.00157747·(546/λ)^0.878138,
    /// bb*_NAP = 0.0225353·(546/λ)^0.878138, bb_w = 0.00097·(550/λ)^4.32.
    #[must_use]
    pub fn sambuca_core_defaults(
        wavelengths_nm: Vec<f64>,
        a_w: Vec<f64>,
        a_ph_star: Vec<f64>,
        substrate_names: Vec<String>,
        substrates: Vec<Vec<f64>>,
    ) -> Self {
        let map = |f: &dyn Fn(f64) -> f64| wavelengths_nm.iter().map(|&l| f(l)).collect::<Vec<f64>>();
        let backscatter = |l: f64| (546.0 / l).powf(0.878_138);
        Self {
            a_cdom_star: map(&|l| (-0.016_805_2 * (l - 550.0)).exp()),
            a_nap_star: map(&|l| 0.004_33 * (-0.009_772_62 * (l - 550.0)).exp()),
            bb_ph_star: map(&|l| 0.001_577_47 * backscatter(l)),
            bb_nap_star: map(&|l| 0.022_535_3 * backscatter(l)),
            bb_w: map(&|l| (0.001_94 / 2.0) * (550.0 / l).powf(4.32)),
            wavelengths_nm,
            a_w,
            a_ph_star,
            substrate_names,
            substrates,
        }
    }
}

/// One band: where its response starts on the grid and its weights, normalised to sum 1.
#[derive(Debug, Clone, PartialEq)]
struct Band {
    first: usize,
    weights: Vec<f64>,
}

/// The package's forward model at a sensor's bands.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceModel {
    spectra: ReferenceSpectra,
    bands: Vec<Band>,
    /// The grid indices any band reads.
    span: std::ops::Range<usize>,
    pairs: Vec<(usize, usize)>,
}

/// Working memory of [`ReferenceModel::closed_rrs`].
#[derive(Debug, Clone, Default)]
pub struct ReferenceScratch {
    rrs: Vec<f64>,
    deep: Vec<f64>,
}

impl ReferenceModel {
    /// The model of `spectra` at bands given by their responses on the same grid (`filters[b]`
    /// has one value per grid wavelength; each is normalised by its own sum at use, as SAMBUCA
    /// does).
    pub fn new(spectra: ReferenceSpectra, filters: &[Vec<f64>]) -> Result<Self, RetrievalError> {
        let n = spectra.wavelengths_nm.len();
        let invalid =
            |field: &str, message: String| RetrievalError::Invalid(FieldError { field: field.into(), message });
        for (name, v) in [
            ("a_w", &spectra.a_w),
            ("bb_w", &spectra.bb_w),
            ("a_ph_star", &spectra.a_ph_star),
            ("a_cdom_star", &spectra.a_cdom_star),
            ("a_nap_star", &spectra.a_nap_star),
            ("bb_ph_star", &spectra.bb_ph_star),
            ("bb_nap_star", &spectra.bb_nap_star),
        ] {
            if v.len() != n {
                return Err(invalid(name, format!("{} values for {n} wavelengths", v.len())));
            }
        }
        if spectra.substrates.is_empty() || spectra.substrates.len() != spectra.substrate_names.len() {
            return Err(invalid("substrates", "SAMBUCA needs at least one named substrate".into()));
        }
        if spectra.substrates.iter().any(|s| s.len() != n) {
            return Err(invalid("substrates", format!("every substrate needs {n} values")));
        }
        if filters.is_empty() {
            return Err(invalid("bands", "no band to retrieve from".into()));
        }
        let mut bands = Vec::with_capacity(filters.len());
        let (mut lo, mut hi) = (n, 0);
        for (b, f) in filters.iter().enumerate() {
            let total: f64 = f.iter().sum();
            let first = f.iter().position(|w| *w != 0.0);
            let last = f.iter().rposition(|w| *w != 0.0);
            let (Some(first), Some(last)) = (first, last) else {
                return Err(invalid(&format!("band {}", b + 1), "the band has no response on the grid".into()));
            };
            if f.len() != n || !(total > 0.0) {
                return Err(invalid(&format!("band {}", b + 1), format!("{} weights for {n} wavelengths", f.len())));
            }
            lo = lo.min(first);
            hi = hi.max(last + 1);
            bands.push(Band { first, weights: f[first..=last].iter().map(|w| w / total).collect() });
        }
        let k = spectra.substrates.len();
        let pairs = if k == 1 { vec![(0, 0)] } else { (0..k).flat_map(|i| (i + 1..k).map(move |j| (i, j))).collect() };
        Ok(Self { spectra, bands, span: lo..hi, pairs })
    }

    /// The model of a Shoal SIOP set and substrates at the chain's bands: the SIOP spectra and
    /// the substrates on the simulation grid the band responses are given on, each band's
    /// response as its filter.
    pub fn from_siop(
        siop: &SiopSpec,
        siop_dir: Option<&Path>,
        library: &SubstrateLibrary,
        substrates: &[String],
        bands: &[BandResponse],
    ) -> Result<Self, RetrievalError> {
        let mut grid: Vec<f64> = bands.iter().flat_map(|b| b.wavelengths_nm.iter().copied()).collect();
        grid.sort_by(f64::total_cmp);
        grid.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        if grid.is_empty() {
            return Err(RetrievalError::Invalid(FieldError {
                field: "bands".into(),
                message: "no band to retrieve from".into(),
            }));
        }
        let wgrid = WavelengthGrid::from_wavelengths(grid.clone())?;
        let s = siop.resolve(&wgrid, siop_dir)?;
        let substrate_spectra = substrates
            .iter()
            .map(|name| {
                let mix = SubstrateMix { parts: vec![(name.clone(), 1.0)] };
                Ok(library.mix_on_grid(&mix, &wgrid)?)
            })
            .collect::<Result<Vec<_>, RetrievalError>>()?;
        let filters: Vec<Vec<f64>> = bands
            .iter()
            .map(|b| {
                let mut f = vec![0.0; grid.len()];
                for (x, w) in b.wavelengths_nm.iter().zip(&b.weights) {
                    let i = grid.partition_point(|g| *g < x - 1e-9).min(grid.len() - 1);
                    f[i] += w;
                }
                f
            })
            .collect();
        let spectra = ReferenceSpectra {
            wavelengths_nm: grid,
            a_w: s.a_w,
            bb_w: s.bb_w,
            a_ph_star: s.a_ph_star,
            a_cdom_star: s.a_cdom_star,
            a_nap_star: s.a_nap_star,
            bb_ph_star: s.bb_ph_star,
            bb_nap_star: s.bb_nap_star,
            substrate_names: substrates.to_vec(),
            substrates: substrate_spectra,
        };
        Self::new(spectra, &filters)
    }

    /// Number of bands.
    #[must_use]
    pub fn n_bands(&self) -> usize {
        self.bands.len()
    }

    /// Substrate pairs in the package's order (`itertools.combinations`; one substrate: (0, 0)).
    #[must_use]
    pub fn pairs(&self) -> &[(usize, usize)] {
        &self.pairs
    }

    /// Substrate names.
    #[must_use]
    pub fn substrate_names(&self) -> &[String] {
        &self.spectra.substrate_names
    }

    /// Band sub-surface rrs (sr⁻¹) at p = (chl, cdom, nap, depth_m, q) with substrates `pair`,
    /// seen with the in-water inverse cosines (sun, view); with `deep`, also the optically deep
    /// band rrs (for the substrate detectability index).
    pub fn closed_rrs(
        &self,
        p: &[f64; 5],
        pair: (usize, usize),
        inv_cos: (f64, f64),
        out: &mut [f64],
        deep: Option<&mut [f64]>,
        scratch: &mut ReferenceScratch,
    ) {
        let s = &self.spectra;
        let n = s.wavelengths_nm.len();
        scratch.rrs.resize(n, 0.0);
        // The deep-water sums are only for the SDI, once per pixel; the fit's evaluations skip them.
        let want_deep = deep.is_some();
        if want_deep {
            scratch.deep.resize(n, 0.0);
        }
        let [chl, cdom, nap, depth, q] = *p;
        let (r1, r2) = (&s.substrates[pair.0], &s.substrates[pair.1]);
        let (mu_w, mu_o) = inv_cos;
        for i in self.span.clone() {
            let a = s.a_w[i] + chl * s.a_ph_star[i] + cdom * s.a_cdom_star[i] + nap * s.a_nap_star[i];
            let bb = s.bb_w[i] + chl * s.bb_ph_star[i] + nap * s.bb_nap_star[i];
            let kappa = a + bb;
            let u = bb / kappa;
            let rrs_dp = (0.084 + 0.17 * u) * u;
            let du_column = 1.03 * (1.0 + 2.4 * u).sqrt() * mu_o;
            let du_bottom = 1.04 * (1.0 + 5.4 * u).sqrt() * mu_o;
            let bottom = q * r1[i] + (1.0 - q) * r2[i];
            scratch.rrs[i] = rrs_dp * (1.0 - (-(mu_w + du_column) * kappa * depth).exp())
                + (1.0 / std::f64::consts::PI) * bottom * (-(mu_w + du_bottom) * kappa * depth).exp();
            if want_deep {
                scratch.deep[i] = rrs_dp;
            }
        }
        let band_sum =
            |v: &[f64], b: &Band| -> f64 { b.weights.iter().enumerate().map(|(k, w)| w * v[b.first + k]).sum() };
        for (o, b) in out.iter_mut().zip(&self.bands) {
            *o = band_sum(&scratch.rrs, b);
        }
        if let Some(deep) = deep {
            for (o, b) in deep.iter_mut().zip(&self.bands) {
                *o = band_sum(&scratch.deep, b);
            }
        }
    }
}

/// SAMBUCA's `distance_f` with NEDR: ‖(o − m)/NEDR‖₂ / Σ(o/NEDR) (Brando et al. 2009).
#[must_use]
pub fn distance_f(observed: &[f64], modelled: &[f64], nedr: &[f64]) -> f64 {
    let (mut sq, mut sum) = (0.0, 0.0);
    for ((o, m), e) in observed.iter().zip(modelled).zip(nedr) {
        let (o, m) = (o / e, m / e);
        sq += (o - m) * (o - m);
        sum += o;
    }
    sq.sqrt() / sum
}

/// The package's start: p0 = (p_max − p_min)/2.
#[must_use]
pub fn start(p_min: &[f64; 5], p_max: &[f64; 5]) -> [f64; 5] {
    let mut p0 = [0.0; 5];
    for k in 0..5 {
        p0[k] = (p_max[k] - p_min[k]) / 2.0;
    }
    p0
}

/// One substrate pair's fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairFit {
    /// The pair (indices into the substrates).
    pub pair: (usize, usize),
    /// (chl, cdom, nap, depth, q) at the end.
    pub x: [f64; 5],
    /// f at `x`.
    pub fun: f64,
    /// How SLSQP ended.
    pub status: SlsqpStatus,
    /// SLSQP iterations.
    pub nit: u32,
    /// Succeeded with the depth still within [`STALL_DEPTH_M`] of the start.
    pub stalled: bool,
}

impl PairFit {
    /// SciPy's `success`.
    #[must_use]
    pub fn success(&self) -> bool {
        self.status == SlsqpStatus::Converged
    }
}

/// One pixel's result, as `sambuca.minimize` returns it.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferencePixel {
    /// The kept pair's x (the last pair's when none succeeded).
    pub x: [f64; 5],
    /// f at `x`.
    pub fun: f64,
    /// Index of the kept pair in [`ReferenceModel::pairs`] (`None`: the package's id −1).
    pub kept: Option<usize>,
    /// The kept pair's success.
    pub success: bool,
    /// Iterations summed over all pairs.
    pub nit: u32,
    /// The kept fit stalled.
    pub stalled: bool,
    /// Every pair's fit, in pair order.
    pub fits: Vec<PairFit>,
}

/// Fit one pixel as the package does: `observed` and `nedr` are sub-surface band rrs and its
/// noise equivalent (sr⁻¹), bounds (chl, cdom, nap, depth, q).
#[must_use]
pub fn invert(
    model: &ReferenceModel,
    p_min: &[f64; 5],
    p_max: &[f64; 5],
    observed: &[f64],
    nedr: &[f64],
    inv_cos: (f64, f64),
) -> ReferencePixel {
    let p0 = start(p_min, p_max);
    let options = SlsqpOptions { max_iterations: MAX_ITERATIONS, ftol: FTOL, ..SlsqpOptions::default() };
    let mut scratch = ReferenceScratch::default();
    let mut m = vec![0.0; model.n_bands()];
    let fits: Vec<PairFit> = model
        .pairs()
        .iter()
        .map(|&pair| {
            let objective = |x: &[f64; 5]| {
                model.closed_rrs(x, pair, inv_cos, &mut m, None, &mut scratch);
                distance_f(observed, &m, nedr)
            };
            let r = slsqp(objective, &p0, p_min, p_max, &options);
            let stalled = r.success() && (r.x[3] - p0[3].clamp(p_min[3], p_max[3])).abs() < STALL_DEPTH_M;
            PairFit { pair, x: r.x, fun: r.fun, status: r.status, nit: r.nit, stalled }
        })
        .collect();
    let mut kept: Option<usize> = None;
    let mut best = f64::MAX;
    for (k, fit) in fits.iter().enumerate() {
        if fit.success() && fit.fun < best {
            best = fit.fun;
            kept = Some(k);
        }
    }
    let chosen = &fits[kept.unwrap_or(fits.len() - 1)];
    ReferencePixel {
        x: chosen.x,
        fun: chosen.fun,
        kept,
        success: chosen.success(),
        nit: fits.iter().map(|f| f.nit).sum(),
        stalled: chosen.stalled,
        fits,
    }
}

/// The substrate detectability index at `x` with `pair`: max_b |rrs_b − rrs_dp,b| / NEDR_b, the
/// bottom's signal in units of the noise, as the package's result writer computes it.
#[must_use]
pub fn sdi(model: &ReferenceModel, x: &[f64; 5], pair: (usize, usize), nedr: &[f64], inv_cos: (f64, f64)) -> f64 {
    let nb = model.n_bands();
    let (mut m, mut deep) = (vec![0.0; nb], vec![0.0; nb]);
    model.closed_rrs(x, pair, inv_cos, &mut m, Some(&mut deep), &mut ReferenceScratch::default());
    (0..nb).filter(|&b| nedr[b] > 0.0).map(|b| (m[b] - deep[b]).abs() / nedr[b]).fold(0.0, f64::max)
}
