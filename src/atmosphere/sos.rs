//! Successive orders of scattering (SOS) for one Fourier term of the azimuthal expansion, in a
//! plane-parallel column over a flat Fresnel surface; generic over the number of Stokes
//! components `S` (1: scalar intensity; 3: I, Q, U).
//!
//! Radiance is expanded as I(τ, μ, φ) = Σₘ (2 − δₘ₀) Iᵐ(τ, μ) cos mφ (U with sin mφ), φ the
//! azimuth of travel measured from the solar beam's. For each m the source of order n + 1 is
//! Jᵐ_{n+1}(τ, μ) = ω(τ) ∫ Kᵐ(τ; μ, μ′) Iᵐ_n(τ, μ′) dμ′ (Gauss quadrature in μ′), the first-order
//! source is the attenuated solar beam (and its Fresnel reflection), and each order's radiance
//! follows from the formal solution. The first-order source a(τ)·e^{−τ/μ₀} is integrated exactly
//! for its exponential factor, with its smooth amplitude a(τ) linear between levels (at low sun
//! the exponential varies much faster than the levels are spaced); higher orders use J linear in
//! τ between levels: I(τ_b) = I(τ_a)e^{−x} + J_a·c_a(x) + J_b·c_b(x), x = Δτ/|μ|,
//! c_a = (1 − e^{−x}(1 + x))/x, c_b = 1 − e^{−x} − c_a. At the surface the upward radiance is the Fresnel reflection of the
//! downward radiance in the mirror direction (same Fourier term: specular reflection keeps the
//! azimuth of travel). Orders are summed until an order adds less than `tolerance` of the sum,
//! or a geometric tail I_n·r/(1 − r) closes the series once its estimated error is below that
//! tolerance. Radiance in the user (output) directions is computed once, from the summed field, so
//! it costs one transfer whatever the number of orders.
//!
//! ## References
//! - Lenoble, J., Herman, M., Deuzé, J. L., Lafrance, B., Santer, R., Tanré, D. (2007) A successive
//!   order of scattering code for solving the vector equation of transfer in the earth's
//!   atmosphere with aerosols. J. Quant. Spectrosc. Radiat. Transfer 107, 479–507.
//! - Chami, M. et al. (2015) OSOAA. Opt. Express 23, 27829 (geometric tail test, linear source).
//! - Chandrasekhar, S. (1950) Radiative Transfer, Oxford, §§ 6, 17 (Fourier decomposition).

use super::profile::Layering;
use super::sos_transfer::{Block, Field, Transfer, mat_vec, transfer, transfer_solar};

/// Quadrature and output directions. Direction index d: 0..n down (quadrature), n..2n up,
/// 2n..2n+u down (user), 2n+u..2n+2u up (user). Signed cosines are positive downward.
#[derive(Debug, Clone, PartialEq)]
pub struct Streams {
    /// Gauss nodes μⱼ on (0, 1), ascending.
    pub mu: Vec<f64>,
    /// Gauss weights (sum 1 per hemisphere).
    pub weight: Vec<f64>,
    /// Output cosines (view directions), in (0, 1].
    pub user_mu: Vec<f64>,
}

impl Streams {
    /// `n` Gauss streams per hemisphere plus the output cosines `user_mu`.
    #[must_use]
    pub fn new(n: usize, user_mu: Vec<f64>) -> Self {
        let (mu, weight) = super::quadrature::gauss_half(n);
        Self { mu, weight, user_mu }
    }

    /// Streams per hemisphere.
    #[must_use]
    pub fn n(&self) -> usize {
        self.mu.len()
    }

    /// All directions (quadrature and user, both hemispheres).
    #[must_use]
    pub fn n_dirs(&self) -> usize {
        2 * self.mu.len() + 2 * self.user_mu.len()
    }

    /// Signed cosine of direction `d` (positive downward).
    #[must_use]
    pub fn signed_mu(&self, d: usize) -> f64 {
        let (n, u) = (self.mu.len(), self.user_mu.len());
        if d < n {
            self.mu[d]
        } else if d < 2 * n {
            -self.mu[d - n]
        } else if d < 2 * n + u {
            self.user_mu[d - 2 * n]
        } else {
            -self.user_mu[d - 2 * n - u]
        }
    }
}

/// One Fourier term's scattering kernels for one scatterer (Rayleigh or aerosol):
/// J_i = ω (Σⱼ quad[i][j]·Iⱼ + sun[i]·e^{−τ/μ₀} + sun_reflected[i]·e^{−(2τ*−τ)/μ₀}), quadrature
/// weights and normalisation included, the solar flux normal to the beam being 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Kernel<const S: usize> {
    /// n_dirs × 2n blocks (row: any direction; column: quadrature direction).
    pub quad: Vec<[[f64; S]; S]>,
    /// Response to the unpolarised direct solar beam, per direction.
    pub sun: Vec<[f64; S]>,
    /// Response to the Fresnel-reflected solar beam (Fresnel matrix included), per direction.
    pub sun_reflected: Vec<[f64; S]>,
}

/// What drives the radiation field.
#[derive(Debug, Clone, PartialEq)]
pub enum Drive<const S: usize> {
    /// The sun at cosine μ₀, flux 1 normal to the beam (its Fresnel reflection is in the
    /// kernels' `sun_reflected`).
    Sun {
        /// Cosine of the solar zenith angle.
        mu0: f64,
    },
    /// Radiance emitted upward at the surface in the up quadrature directions (its direct
    /// transmission to the user directions is added by the caller).
    Bottom {
        /// Emitted radiance per quadrature stream.
        quad: Vec<[f64; S]>,
    },
}

/// Settings of one solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrderSettings {
    /// Largest scattering order summed.
    pub max_orders: usize,
    /// Stop when an order adds less than this fraction of the running sum.
    pub tolerance: f64,
}

/// Result of one Fourier term.
#[derive(Debug, Clone, PartialEq)]
pub struct FourierField<const S: usize> {
    /// Upward radiance at the top in the user directions from the diffuse field: orders 2 to
    /// `max_orders` for a solar drive (order 1 is left to the exact single-scattering term),
    /// scattered orders 1 to `max_orders` for a bottom drive. Direct and single-scattered parts
    /// are added by the caller.
    pub toa_user: Vec<[f64; S]>,
    /// For a solar drive, the first-order upward radiance at the top in the user directions in
    /// this layered model, surface reflections included; zero for a bottom drive. The
    /// polarisation correction needs it: light scattered once and reflected by the surface is
    /// already polarised.
    pub toa_user_first: Vec<[f64; S]>,
    /// Downward diffuse radiance at the surface in the quadrature directions (all orders ≥ 1).
    pub surface_down: Vec<[f64; S]>,
    /// Upward diffuse radiance at the top in the quadrature directions (all scattered orders).
    pub toa_up: Vec<[f64; S]>,
    /// Number of orders computed.
    pub orders: usize,
}

/// Smooth amplitudes of the first-order solar source on directions `rows` (kernel row indices):
/// a = ω(f_R K_R,sun + f_a K_a,sun), b = ω(f_R K_R,refl + f_a K_a,refl) per level.
fn solar_amplitudes<const S: usize>(
    layering: &Layering,
    rayleigh: &Kernel<S>,
    aerosol: Option<&Kernel<S>>,
    rows: std::ops::Range<usize>,
) -> (Field<S>, Field<S>) {
    let levels = layering.tau.len();
    let mut a = vec![vec![[0.0; S]; rows.len()]; levels];
    let mut b = a.clone();
    for k in 0..levels {
        let w = layering.omega[k];
        let (wr, wa) = (w * layering.rayleigh_fraction[k], w * (1.0 - layering.rayleigh_fraction[k]));
        for (i, row) in rows.clone().enumerate() {
            for s in 0..S {
                a[k][i][s] = wr * rayleigh.sun[row][s];
                b[k][i][s] = wr * rayleigh.sun_reflected[row][s];
                if let Some(ak) = aerosol {
                    a[k][i][s] += wa * ak.sun[row][s];
                    b[k][i][s] += wa * ak.sun_reflected[row][s];
                }
            }
        }
    }
    (a, b)
}

fn add<const S: usize>(acc: &mut [Vec<[f64; S]>], f: &[Vec<[f64; S]>], scale: f64) {
    for (a_k, f_k) in acc.iter_mut().zip(f) {
        for (a, v) in a_k.iter_mut().zip(f_k) {
            for s in 0..S {
                a[s] += scale * v[s];
            }
        }
    }
}

/// Solve one Fourier term.
///
/// `rayleigh` and `aerosol` are the kernels of the two scatterers; `surface_quad` and
/// `surface_user` the Fresnel matrices per quadrature and user cosine (zero for a black surface).
#[allow(clippy::too_many_arguments, clippy::too_many_lines)]
pub fn solve<const S: usize>(
    streams: &Streams,
    layering: &Layering,
    rayleigh: &Kernel<S>,
    aerosol: Option<&Kernel<S>>,
    surface_quad: &[Block<S>],
    surface_user: &[Block<S>],
    drive: &Drive<S>,
    settings: OrderSettings,
) -> FourierField<S> {
    let n = streams.n();
    let nq = 2 * n;
    let u = streams.user_mu.len();
    let kk = layering.n_layers();
    let levels = kk + 1;
    let tq = Transfer::new(layering, &streams.mu);
    let scat = |k: usize| -> (f64, f64) {
        let w = layering.omega[k];
        let fr = layering.rayleigh_fraction[k];
        (w * fr, w * (1.0 - fr))
    };
    // Per-level mixed quadrature kernel (quad rows only): ω(f_R K_R + f_a K_a).
    let mixed: Vec<Vec<Block<S>>> = (0..levels)
        .map(|k| {
            let (wr, wa) = scat(k);
            (0..nq * nq)
                .map(|idx| {
                    let mut b = rayleigh.quad[idx];
                    for r in 0..S {
                        for c in 0..S {
                            b[r][c] *= wr;
                            if let Some(a) = aerosol {
                                b[r][c] += wa * a.quad[idx][r][c];
                            }
                        }
                    }
                    b
                })
                .collect()
        })
        .collect();
    let scatter_quad = |field: &[Vec<[f64; S]>], out: &mut [Vec<[f64; S]>]| {
        for k in 0..levels {
            let kernel = &mixed[k];
            for i in 0..nq {
                let mut acc = [0.0; S];
                for (b, v) in kernel[i * nq..(i + 1) * nq].iter().zip(&field[k]) {
                    let p = mat_vec(b, v);
                    for s in 0..S {
                        acc[s] += p[s];
                    }
                }
                out[k][i] = acc;
            }
        }
    };
    let zero: Field<S> = vec![vec![[0.0; S]; nq]; levels];
    let mut j_cur = zero.clone();
    let mut field = zero.clone();
    let mut sum = zero.clone();
    // The summed field whose scattering feeds the user directions.
    let mut feed = zero;
    let total_tau = layering.total();
    let mut orders;
    match drive {
        Drive::Sun { mu0 } => {
            let (a, b) = solar_amplitudes(layering, rayleigh, aerosol, 0..nq);
            transfer_solar(layering, &streams.mu, *mu0, surface_quad, &a, &b, &mut field);
            orders = 1;
            add(&mut sum, &field, 1.0);
        }
        Drive::Bottom { quad } => {
            // Order 0: emitted radiance attenuated upward; it scatters into order 1.
            for k in 0..levels {
                for jdx in 0..n {
                    let att = (-(total_tau - layering.tau[k]) / streams.mu[jdx]).exp();
                    for s in 0..S {
                        field[k][n + jdx][s] = quad[jdx][s] * att;
                    }
                }
            }
            orders = 0;
        }
    }
    // Orders below `max_orders` feed the user directions, so that these receive exactly orders
    // up to `max_orders` (one more scattering happens on the way to them).
    let norm = |f: &[Vec<[f64; S]>]| -> f64 { (0..n).map(|j| f[0][n + j][0].abs() + f[kk][j][0].abs()).sum() };
    let mut prev_norm = norm(&field);
    let mut prev_ratio = f64::NAN;
    let mut total_norm = if orders == 1 { prev_norm } else { 0.0 };
    while orders < settings.max_orders {
        add(&mut feed, &field, 1.0);
        scatter_quad(&field, &mut j_cur);
        transfer(&tq, surface_quad, &j_cur, &mut field);
        orders += 1;
        let this = norm(&field);
        add(&mut sum, &field, 1.0);
        total_norm += this;
        if total_norm <= 0.0 || this <= settings.tolerance * total_norm {
            add(&mut feed, &field, 1.0);
            break;
        }
        // Geometric tail (OSOAA's test, `OSOAA_SOS_CORE.F`): with r₁, r₂ the last two ratios of
        // successive orders, the tail g·r₂/(1−r₂) is uncertain by about g·|r₂−r₁|/(1−r₂)²; close
        // the series when that is below the tolerance of the sum.
        let ratio = this / prev_norm;
        let tail_error = (ratio - prev_ratio).abs() / (1.0 - ratio).powi(2) * this / total_norm;
        if orders >= 3 && ratio < 0.98 && tail_error < settings.tolerance {
            let tail = ratio / (1.0 - ratio);
            add(&mut sum, &field, tail);
            add(&mut feed, &field, 1.0 + tail);
            break;
        }
        prev_ratio = ratio;
        prev_norm = this;
    }
    let mut toa_user = vec![[0.0; S]; u];
    let mut toa_user_first = vec![[0.0; S]; u];
    if u > 0 {
        let tu = Transfer::new(layering, &streams.user_mu);
        let mut j_user = vec![vec![[0.0; S]; 2 * u]; levels];
        for k in 0..levels {
            let (wr, wa) = scat(k);
            for i in 0..2 * u {
                let row = nq + i;
                let mut acc = [0.0; S];
                for jdx in 0..nq {
                    let pr = mat_vec(&rayleigh.quad[row * nq + jdx], &feed[k][jdx]);
                    for s in 0..S {
                        acc[s] += wr * pr[s];
                    }
                    if let Some(a) = aerosol {
                        let pa = mat_vec(&a.quad[row * nq + jdx], &feed[k][jdx]);
                        for s in 0..S {
                            acc[s] += wa * pa[s];
                        }
                    }
                }
                j_user[k][i] = acc;
            }
        }
        let mut out = vec![vec![[0.0; S]; 2 * u]; levels];
        transfer(&tu, surface_user, &j_user, &mut out);
        toa_user.copy_from_slice(&out[0][u..2 * u]);
        if let Drive::Sun { mu0 } = drive {
            let (a, b) = solar_amplitudes(layering, rayleigh, aerosol, nq..nq + 2 * u);
            transfer_solar(layering, &streams.user_mu, *mu0, surface_user, &a, &b, &mut out);
            toa_user_first.copy_from_slice(&out[0][u..2 * u]);
        }
    }
    FourierField { toa_user, toa_user_first, surface_down: sum[kk][..n].to_vec(), toa_up: sum[0][n..].to_vec(), orders }
}

#[cfg(test)]
mod tests {
    use super::super::kernels::scalar_kernel;
    use super::super::phase::PhaseFunction;
    use super::super::profile::{ColumnOptics, Layering};
    use super::*;

    fn setup(tau: f64, dtau: f64) -> (Streams, Layering, Kernel<1>, Vec<[[f64; 1]; 1]>) {
        let streams = Streams::new(16, vec![0.5, 0.8, 1.0]);
        let column = ColumnOptics {
            tau_rayleigh: tau,
            tau_aerosol: 0.0,
            ssa_aerosol: 1.0,
            rayleigh_scale_height_km: 8.0,
            aerosol_scale_height_km: 2.0,
        };
        let layering = Layering::new(&column, 0.0, dtau, 1);
        let beta = PhaseFunction::Rayleigh { depolarization: 0.0279 }.moments(2);
        let k = scalar_kernel(&streams, &beta, 0, 0.6, 1.34);
        // Black surface: no Fresnel, and the reflected-sun source vanishes with it.
        let k = Kernel { sun_reflected: vec![[0.0]; k.sun.len()], ..k };
        (streams, layering, k, vec![[[0.0]]; 16])
    }

    fn flux(streams: &Streams, radiance: &[[f64; 1]]) -> f64 {
        2.0 * std::f64::consts::PI
            * streams.mu.iter().zip(&streams.weight).zip(radiance).map(|((m, w), v)| m * w * v[0]).sum::<f64>()
    }

    #[test]
    fn conservative_atmosphere_conserves_energy() {
        // ω = 1 over a black surface: reflected + transmitted (direct + diffuse) = incident μ₀.
        // The linear-in-τ source is a second-order scheme: the energy defect must fall as Δτ².
        let mu0 = 0.6;
        let settings = OrderSettings { max_orders: 400, tolerance: 1e-10 };
        for tau in [0.05, 0.35, 1.0] {
            let defect = |dtau: f64| {
                let (streams, layering, k, black) = setup(tau, dtau);
                let f = solve(&streams, &layering, &k, None, &black, &[[[0.0]]; 3], &Drive::Sun { mu0 }, settings);
                let up = flux(&streams, &f.toa_up);
                let down = flux(&streams, &f.surface_down) + mu0 * (-tau / mu0).exp();
                ((up + down) / mu0 - 1.0).abs()
            };
            let (coarse, fine) = (defect(0.01), defect(0.0025));
            assert!(fine < 2e-5, "τ={tau}: defect {fine:e} at Δτ = 0.0025");
            assert!(coarse < 2e-4, "τ={tau}: defect {coarse:e} at Δτ = 0.01");
            if coarse > 1e-6 {
                assert!(coarse / fine > 8.0, "τ={tau}: {coarse:e} → {fine:e} is not second order");
            }
        }
    }

    #[test]
    fn transmittance_is_reciprocal() {
        // Chandrasekhar (1950) §12: over a black surface, the transmittance for sun at μ equals
        // the TOA radiance from a unit isotropic source at the bottom, seen at μ.
        let tau = 0.35;
        let (streams, layering, k, black) = setup(tau, 0.01);
        let settings = OrderSettings { max_orders: 400, tolerance: 1e-9 };
        let iso = Drive::Bottom { quad: vec![[1.0]; 16] };
        let up = solve(&streams, &layering, &k, None, &black, &[[[0.0]]; 3], &iso, settings);
        for (i, &mu) in streams.user_mu.clone().iter().enumerate() {
            let t_up = (-tau / mu).exp() + up.toa_user[i][0];
            let beta = PhaseFunction::Rayleigh { depolarization: 0.0279 }.moments(2);
            let ks = scalar_kernel(&streams, &beta, 0, mu, 1.34);
            let ks = Kernel { sun_reflected: vec![[0.0]; ks.sun.len()], ..ks };
            let d = solve(&streams, &layering, &ks, None, &black, &[[[0.0]]; 3], &Drive::Sun { mu0: mu }, settings);
            let t_down = (flux(&streams, &d.surface_down) + mu * (-tau / mu).exp()) / mu;
            assert!((t_up / t_down - 1.0).abs() < 5e-4, "μ={mu}: T_up {t_up} vs T_down {t_down}");
        }
    }
}
