//! One wavelength's radiative transfer: path radiance (Fourier coefficients of the multiple
//! scattering plus exact single scattering), downwelling irradiance at the surface, upward
//! transmittance and spherical albedo.
//!
//! Method (each step cited where it is implemented):
//! - the aerosol phase function is delta-M truncated to 2N Legendre terms for the multiple
//!   scattering (Wiscombe 1977), and the single-scattered radiance is computed exactly with the
//!   full phase function and unscaled optical depths, for the four single-scattering paths over
//!   a Fresnel surface (sun→view, sun→surface→view, surface→view, surface→surface→view): the TMS
//!   correction of Nakajima & Tanaka (1988);
//! - the scalar treatment of Rayleigh scattering errs by −7 % to +2.5 % in the path radiance
//!   (worst in the blue at small sun zenith, OSOAA reference); the same column is solved for
//!   (I, Q, U) in the Fourier terms m ≤ 2 with the Rayleigh phase matrix and the aerosol as a
//!   depolarising scatterer, and the difference ΔIᵐ = Iᵐ_vector − Iᵐ_scalar (all orders including
//!   the first: skylight scattered once and reflected by the surface is polarised) corrects the
//!   scalar result. Molecular scattering dominates the polarisation error (Gordon, Brown & Evans
//!   1988), and computing it in the actual column dilutes it as aerosol loads grow;
//! - T_up(μ) multiplies the water-leaving radiance the water model gives — Lee et al.'s
//!   Rrs = 0.52 rrs/(1 − 1.7 rrs), whose 0.52 holds the surface transmission near nadir — to give
//!   the water's TOA signal in the view μ. The water-leaving radiance is that of an isotropic
//!   in-water field, L(μ) ∝ 1 − R_F(μ) (Mobley 1994, §4.2), over the Fresnel surface;
//!   T_up(μ) = [s(μ)e^{−τ/μ} + diffuse(μ)]/s(1) with s(μ) = 1 − R_F(μ): at nadir this is the
//!   ordinary (direct + diffuse) transmittance, and at grazing views it carries the Fresnel
//!   falloff of Lw, so it never exceeds 1. S is the fraction of an isotropic upward source
//!   returned down to a black surface.
//!
//! Radiances here are normalised to a solar flux of 1 normal to the beam: L = I·E₀.
//!
//! ## References
//! - Nakajima, T. & Tanaka, M. (1988) Algorithms for radiative intensity calculations in
//!   moderately thick atmospheres using a truncation approximation. JQSRT 40, 51–69.
//! - Gordon, H. R., Brown, J. W., Evans, R. H. (1988) Exact Rayleigh scattering calculations for
//!   use with the Nimbus-7 Coastal Zone Color Scanner. Appl. Opt. 27, 862–871.
//! - Wiscombe, W. J. (1977) The delta-M method. J. Atmos. Sci. 34, 1408–1422.

use serde::{Deserialize, Serialize};

use super::fresnel::{fresnel_matrix, fresnel_reflectance};
use super::kernel_cache::{phase_moments, rayleigh_kernels};
use super::kernels::{delta_m, scalar_kernel};
use super::phase::PhaseFunction;
use super::profile::{AltitudeQuadrature, ColumnOptics, Layering};
pub use super::single_scattering::{Scatterers, SsCoefficients};
use super::sos::{Drive, Kernel, OrderSettings, Streams, solve};

/// Accuracy settings of the radiative transfer: each costs time (see `shoal bench`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct RtAccuracy {
    /// Gauss streams per hemisphere (2–48).
    pub streams: usize,
    /// Largest scattering order; 1 is the single-scattering mode.
    pub max_orders: usize,
    /// Largest number of Fourier terms in azimuth (1–96); capped at 2·streams.
    pub fourier_terms: usize,
    /// Largest scaled optical depth of one layer.
    pub max_layer_depth: f64,
    /// Fewest layers.
    pub min_layers: usize,
    /// An order adding less than this fraction of the sum ends the series.
    pub order_tolerance: f64,
    /// Add the vector-minus-scalar Rayleigh correction.
    pub polarization_correction: bool,
}

impl Default for RtAccuracy {
    fn default() -> Self {
        Self {
            streams: 12,
            max_orders: 60,
            fourier_terms: 24,
            max_layer_depth: 0.02,
            min_layers: 12,
            order_tolerance: 1e-4,
            polarization_correction: true,
        }
    }
}

impl RtAccuracy {
    /// The named presets of the cost table: `single`, `fast`, `default`, `high`.
    #[must_use]
    pub fn preset(name: &str) -> Option<Self> {
        let d = Self::default();
        match name {
            "single" => Some(Self { max_orders: 1, polarization_correction: false, ..d }),
            "fast" => Some(Self {
                streams: 6,
                fourier_terms: 12,
                max_layer_depth: 0.05,
                min_layers: 6,
                order_tolerance: 1e-3,
                ..d
            }),
            "default" => Some(d),
            "high" => Some(Self {
                streams: 24,
                fourier_terms: 48,
                max_layer_depth: 0.01,
                min_layers: 26,
                order_tolerance: 1e-5,
                ..d
            }),
            _ => None,
        }
    }

    /// Check ranges ([`crate::ranges`]); the message names the field and the allowed range.
    pub fn validate(&self) -> Result<(), super::AtmosphereError> {
        use super::check;
        use crate::ranges as r;
        check(&r::ACCURACY_STREAMS, self.streams as f64)?;
        check(&r::ACCURACY_MAX_ORDERS, self.max_orders as f64)?;
        check(&r::ACCURACY_FOURIER_TERMS, self.fourier_terms as f64)?;
        check(&r::ACCURACY_MAX_LAYER_DEPTH, self.max_layer_depth)?;
        check(&r::ACCURACY_MIN_LAYERS, self.min_layers as f64)?;
        check(&r::ACCURACY_ORDER_TOLERANCE, self.order_tolerance)
    }

    fn orders(&self) -> OrderSettings {
        OrderSettings { max_orders: self.max_orders, tolerance: self.order_tolerance }
    }
}

/// The optical column of one wavelength.
#[derive(Debug, Clone, PartialEq)]
pub struct WavelengthColumn {
    /// Wavelength, nm.
    pub wavelength_nm: f64,
    /// Rayleigh optical depth.
    pub tau_rayleigh: f64,
    /// Depolarisation ratio of air.
    pub depolarization: f64,
    /// Aerosol optical depth, single-scattering albedo and phase function, if any.
    pub aerosol: Option<(f64, f64, PhaseFunction)>,
    /// Molecular scale height, km.
    pub rayleigh_scale_height_km: f64,
    /// Aerosol scale height, km.
    pub aerosol_scale_height_km: f64,
    /// Refractive index of the water surface.
    pub water_index: f64,
}

impl WavelengthColumn {
    /// Forward-scattering optical depths (molecules, aerosols): ω·η·τ, with η the share of each
    /// phase function in the forward hemisphere ([`PhaseFunction::forward_fraction`]; ½ for
    /// molecules, whose ω is 1). In the single-scattering limit the diffuse part of a beam's
    /// transmission is Σ ω·η·τ/μ over the scatterers (Liou 2002, *An Introduction to Atmospheric
    /// Radiation*, 2nd ed., §6.3; the split 6S makes between Rayleigh and aerosol diffuse
    /// transmittances, Vermote et al. 1997), so these weigh the two environment functions.
    #[must_use]
    pub fn forward_scattering(&self) -> (f64, f64) {
        let aerosol = self.aerosol.as_ref().map_or(0.0, |(tau, ssa, phase)| ssa * phase.forward_fraction() * tau);
        (0.5 * self.tau_rayleigh, aerosol)
    }

    fn optics(&self) -> ColumnOptics {
        let (tau_a, ssa) = self.aerosol.as_ref().map_or((0.0, 1.0), |(t, w, _)| (*t, *w));
        ColumnOptics {
            tau_rayleigh: self.tau_rayleigh,
            tau_aerosol: tau_a,
            ssa_aerosol: ssa,
            rayleigh_scale_height_km: self.rayleigh_scale_height_km,
            aerosol_scale_height_km: self.aerosol_scale_height_km,
        }
    }

    /// Layering and truncated aerosol moments for `n` streams: (layering, β′ or None).
    fn scaled(&self, acc: &RtAccuracy) -> (Layering, Option<Vec<f64>>) {
        let n_terms = 2 * acc.streams;
        match &self.aerosol {
            Some((_, _, phase)) => {
                let (beta, f) = delta_m(&phase_moments(phase, n_terms), n_terms);
                (Layering::new(&self.optics(), f, acc.max_layer_depth, acc.min_layers), Some(beta))
            }
            None => (Layering::new(&self.optics(), 0.0, acc.max_layer_depth, acc.min_layers), None),
        }
    }

    /// Total (unscaled) optical depth.
    #[must_use]
    pub fn total_tau(&self) -> f64 {
        self.tau_rayleigh + self.aerosol.as_ref().map_or(0.0, |a| a.0)
    }
}

/// Σₘ (2 − δₘ₀) cₘ cos mψ with ψ = π − Δφ (azimuth of travel relative to the solar beam).
#[must_use]
pub fn fourier_sum(coefficients: &[f64], relative_azimuth_rad: f64) -> f64 {
    let psi = std::f64::consts::PI - relative_azimuth_rad;
    coefficients.iter().enumerate().map(|(m, c)| if m == 0 { *c } else { 2.0 * c * (m as f64 * psi).cos() }).sum()
}

/// [`fourier_sum`] with cos mψ given (`cos_m_psi[m]`, at least as many as the coefficients): the
/// same sum, the cosines taken once for many sums at one azimuth.
#[must_use]
pub fn fourier_sum_with(coefficients: &[f64], cos_m_psi: &[f64]) -> f64 {
    coefficients.iter().zip(cos_m_psi).enumerate().map(|(m, (c, cos))| if m == 0 { *c } else { 2.0 * c * cos }).sum()
}

/// Path radiance and irradiance for one sun position over a set of view cosines.
#[derive(Debug, Clone, PartialEq)]
pub struct SunSolution {
    /// Cosine of the solar zenith angle.
    pub mu0: f64,
    /// View cosines.
    pub user_mu: Vec<f64>,
    /// Fourier coefficients of the multiple-scattered TOA radiance, `[view][m]` (polarisation
    /// correction included), normalised to a unit solar flux.
    pub ms_fourier: Vec<Vec<f64>>,
    /// Single-scattering coefficients per view.
    pub ss: Vec<SsCoefficients>,
    /// The scatterers (for single scattering at any angle).
    pub scatterers: Scatterers,
    /// Direct downwelling irradiance at 0⁺ per unit solar flux, μ₀ e^{−τ/μ₀} (unscaled τ).
    pub ed_direct: f64,
    /// Diffuse downwelling irradiance at 0⁺ per unit solar flux (Fresnel surface, black water).
    pub ed_diffuse: f64,
    /// Scattering orders used in the m = 0 term.
    pub orders: usize,
    /// Per view, the TOA path's Q and U Fourier coefficients from the vector solution (all
    /// orders), `[Q₀, Q₁, Q₂, U₁, U₂]` ([`super::stokes`]); empty without the vector solution.
    pub qu_fourier: Vec<[f64; 5]>,
}

impl SunSolution {
    /// Normalised TOA path radiance I (L = I·E₀) for view `i` at relative azimuth Δφ (view − sun,
    /// radians; 0 puts the sensor on the sun's side).
    #[must_use]
    pub fn radiance(&self, i: usize, relative_azimuth_rad: f64) -> f64 {
        fourier_sum(&self.ms_fourier[i], relative_azimuth_rad) + self.single_scattering(i, relative_azimuth_rad)
    }

    /// The exact single-scattered part of [`Self::radiance`].
    #[must_use]
    pub fn single_scattering(&self, i: usize, relative_azimuth_rad: f64) -> f64 {
        self.scatterers.single_scattering(&self.ss[i], self.mu0, self.user_mu[i], relative_azimuth_rad)
    }

    /// Total Ed(0⁺) per unit solar flux.
    #[must_use]
    pub fn ed(&self) -> f64 {
        self.ed_direct + self.ed_diffuse
    }
}

fn fresnel_blocks(mus: &[f64], n: f64) -> Vec<[[f64; 1]; 1]> {
    mus.iter().map(|&m| [[fresnel_reflectance(m, n)]]).collect()
}

fn fresnel_blocks3(mus: &[f64], n: f64) -> Vec<[[f64; 3]; 3]> {
    mus.iter().map(|&m| fresnel_matrix(m, n)).collect()
}

/// Solve the solar problem for sun cosine `mu0` and view cosines `user_mu`.
#[must_use]
pub fn solve_sun(column: &WavelengthColumn, mu0: f64, user_mu: &[f64], acc: &RtAccuracy) -> SunSolution {
    let streams = Streams::new(acc.streams, user_mu.to_vec());
    let (layering, beta_a) = column.scaled(acc);
    let rayleigh_phase = PhaseFunction::Rayleigh { depolarization: column.depolarization };
    let n = column.water_index;
    let surf_q = fresnel_blocks(&streams.mu, n);
    let surf_u = fresnel_blocks(user_mu, n);
    let nadir_only = user_mu.iter().all(|m| *m > 1.0 - 1e-12);
    // Only m = 0 is needed when the views are all nadir (higher terms vanish there) or in the
    // single-scattering mode (the path radiance is then the exact single scattering alone, and
    // the irradiance needs only m = 0).
    let m_max = if nadir_only || acc.max_orders == 1 {
        0
    } else if beta_a.is_some() {
        acc.fourier_terms.min(2 * acc.streams) - 1
    } else {
        2.min(acc.fourier_terms - 1)
    };
    let polarize = acc.polarization_correction && acc.max_orders > 1;
    // The molecular kernels depend on the streams, sun and surface alone: shared by the solves
    // of every wavelength (and every LUT) at this sun.
    let rayleigh = rayleigh_kernels(&streams, mu0, column.depolarization, n);
    let vector = if polarize { rayleigh.vector(&streams) } else { &[] };
    let (vq, vu) = (fresnel_blocks3(&streams.mu, n), fresnel_blocks3(user_mu, n));
    let mut ms_fourier = vec![Vec::new(); user_mu.len()];
    let mut qu_fourier = vec![[0.0; 5]; if polarize { user_mu.len() } else { 0 }];
    let (mut ed_diffuse, mut orders, mut small) = (0.0, 0, 0);
    for m in 0..=m_max {
        let kr = rayleigh.scalar(&streams, m);
        let ka = beta_a.as_ref().map(|b| scalar_kernel(&streams, b, m, mu0, n));
        let f = solve(&streams, &layering, &kr, ka.as_ref(), &surf_q, &surf_u, &Drive::Sun { mu0 }, acc.orders());
        if m == 0 {
            ed_diffuse = irradiance(&streams, &f.surface_down);
            orders = f.orders;
        }
        for (coeffs, v) in ms_fourier.iter_mut().zip(&f.toa_user) {
            coeffs.push(v[0]);
        }
        // Polarisation (m ≤ 2): the same column solved for (I, Q, U), with the Rayleigh phase
        // matrix and the aerosol as a depolarising scatterer (intensity kernel only). Only
        // molecular scattering creates polarisation, so both solutions agree for m > 2; the
        // difference, all orders including the first, corrects the scalar result.
        if let Some(kv) = vector.get(m) {
            let kav = ka.as_ref().map(embed_intensity);
            let fv = solve(&streams, &layering, kv, kav.as_ref(), &vq, &vu, &Drive::Sun { mu0 }, acc.orders());
            for (i, coeffs) in ms_fourier.iter_mut().enumerate() {
                let delta = (fv.toa_user[i][0] + fv.toa_user_first[i][0]) - (f.toa_user[i][0] + f.toa_user_first[i][0]);
                if let Some(c) = coeffs.last_mut() {
                    *c += delta;
                }
                // The path's own polarisation, kept for the instrument's polarisation sensitivity.
                let total = |s: usize| fv.toa_user[i][s] + fv.toa_user_first[i][s];
                qu_fourier[i][m] = total(1);
                if m > 0 {
                    qu_fourier[i][2 + m] = total(2);
                }
            }
            if m == 0 {
                ed_diffuse += irradiance(&streams, &fv.surface_down) - irradiance(&streams, &f.surface_down);
            }
        }
        // Stop once two successive terms are negligible against the m = 0 term.
        let peak0 = ms_fourier.iter().map(|c| c[0].abs()).fold(0.0, f64::max);
        let peak = f.toa_user.iter().map(|v| v[0].abs()).fold(0.0, f64::max);
        if m > 2 {
            small = if peak <= 1e-5 * peak0 { small + 1 } else { 0 };
            if small >= 2 {
                break;
            }
        }
    }
    // Delta-M: the scaled direct beam μ₀e^{−τ′/μ₀} carries the truncated forward peak, so the
    // total is scaled direct + scaled diffuse; the true direct beam uses the unscaled depth and
    // the forward peak is reported as diffuse light.
    let ed_direct = mu0 * (-column.total_tau() / mu0).exp();
    let ed_total = mu0 * (-layering.total() / mu0).exp() + ed_diffuse;
    let quad = AltitudeQuadrature::new(&column.optics());
    let ss = user_mu.iter().map(|&muv| ss_paths(&quad, mu0, muv, n)).collect();
    SunSolution {
        mu0,
        user_mu: user_mu.to_vec(),
        ms_fourier,
        ss,
        scatterers: Scatterers {
            rayleigh: rayleigh_phase,
            aerosol: column.aerosol.as_ref().map(|(_, w, p)| (*w, p.clone())),
        },
        ed_direct,
        ed_diffuse: ed_total - ed_direct,
        orders,
        qu_fourier,
    }
}

/// A scalar kernel as the intensity element of a (I, Q, U) kernel: a scatterer that neither
/// creates nor carries polarisation.
fn embed_intensity(k: &Kernel<1>) -> Kernel<3> {
    let block = |v: f64| [[v, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
    let vec3 = |v: f64| [v, 0.0, 0.0];
    Kernel {
        quad: k.quad.iter().map(|b| block(b[0][0])).collect(),
        sun: k.sun.iter().map(|v| vec3(v[0])).collect(),
        sun_reflected: k.sun_reflected.iter().map(|v| vec3(v[0])).collect(),
    }
}

/// Diffuse irradiance 2π Σ wⱼ μⱼ I⁰(μⱼ) from the m = 0 downward radiance.
fn irradiance<const S: usize>(streams: &Streams, down: &[[f64; S]]) -> f64 {
    2.0 * std::f64::consts::PI
        * streams.mu.iter().zip(&streams.weight).zip(down).map(|((m, w), v)| m * w * v[0]).sum::<f64>()
}

/// The four single-scattering paths over a Fresnel surface for view cosine μ_v: attenuation
/// exponents m_p and factors F_p (see the module docs), integrated over the profile. The
/// factors' exponentials are folded into the integrals (F_p e^{−m_p τ} = R·e^{−c_p − m_p τ}) so
/// that no term underflows while its partner overflows.
fn ss_paths(q: &AltitudeQuadrature, mu0: f64, muv: f64, n: f64) -> SsCoefficients {
    let t = q.total;
    let (r0, rv) = (fresnel_reflectance(mu0, n), fresnel_reflectance(muv, n));
    let specs = [
        (1.0, 0.0, 1.0 / mu0 + 1.0 / muv),
        (rv, 2.0 * t / muv, 1.0 / mu0 - 1.0 / muv),
        (r0, 2.0 * t / mu0, 1.0 / muv - 1.0 / mu0),
        (r0 * rv, 2.0 * t * (1.0 / mu0 + 1.0 / muv), -(1.0 / mu0 + 1.0 / muv)),
    ];
    let mut paths = [[0.0; 2]; 4];
    for (p, (reflectance, offset, m)) in paths.iter_mut().zip(specs) {
        let (r, a) = q.attenuated(m, offset);
        *p = [reflectance * r, reflectance * a];
    }
    SsCoefficients(paths)
}

/// Upward transmittance and spherical albedo.
#[derive(Debug, Clone, PartialEq)]
pub struct Transmittance {
    /// View cosines.
    pub user_mu: Vec<f64>,
    /// Total (direct + diffuse) upward transmittance per view cosine (see the module docs).
    pub t_up: Vec<f64>,
    /// Direct part s(μ)/s(1)·e^{−τ/μ} (unscaled τ; s(μ)/s(1) ≈ 1 below 60° view).
    pub t_up_direct: Vec<f64>,
    /// Spherical albedo of the atmosphere.
    pub spherical_albedo: f64,
}

/// Upward transmittance for `user_mu` and the spherical albedo (m = 0 problems).
#[must_use]
pub fn solve_transmittance(column: &WavelengthColumn, user_mu: &[f64], acc: &RtAccuracy) -> Transmittance {
    let streams = Streams::new(acc.streams, user_mu.to_vec());
    let (layering, beta_a) = column.scaled(acc);
    let n = column.water_index;
    // (The sun's cosine does not enter these m = 0 problems: 0.5 is a placeholder.)
    let rayleigh = rayleigh_kernels(&streams, 0.5, column.depolarization, n);
    let kr = rayleigh.scalar(&streams, 0);
    let ka = beta_a.as_ref().map(|b| scalar_kernel(&streams, b, 0, 0.5, n));
    let tau_scaled = layering.total();
    // Water-leaving radiance of an isotropic in-water field, normalised to 1 at nadir.
    let shape = |mu: f64| (1.0 - fresnel_reflectance(mu, n)) / (1.0 - fresnel_reflectance(1.0, n));
    let drive = Drive::Bottom { quad: streams.mu.iter().map(|&m| [shape(m)]).collect() };
    let f = solve(
        &streams,
        &layering,
        &kr,
        ka.as_ref(),
        &fresnel_blocks(&streams.mu, n),
        &fresnel_blocks(user_mu, n),
        &drive,
        acc.orders(),
    );
    let t_up = user_mu.iter().zip(&f.toa_user).map(|(&mu, v)| shape(mu) * (-tau_scaled / mu).exp() + v[0]).collect();
    // An isotropic unit source over a black surface: the fraction returned down is S.
    let black_q = vec![[[0.0]]; streams.n()];
    let black_u = vec![[[0.0]]; user_mu.len()];
    let iso = Drive::Bottom { quad: vec![[1.0]; streams.n()] };
    let g = solve(&streams, &layering, &kr, ka.as_ref(), &black_q, &black_u, &iso, acc.orders());
    let spherical_albedo = irradiance(&streams, &g.surface_down) / std::f64::consts::PI;
    Transmittance {
        user_mu: user_mu.to_vec(),
        t_up,
        t_up_direct: user_mu.iter().map(|&mu| shape(mu) * (-column.total_tau() / mu).exp()).collect(),
        spherical_albedo,
    }
}
