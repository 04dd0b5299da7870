//! Fourier kernels of the scattering integral for the SOS solver.
//!
//! Scalar: from Legendre coefficients βₗ by the addition theorem,
//! Pᵐ(μ, μ′) = Σₗ βₗ Λₗᵐ(μ)Λₗᵐ(μ′), so that J = ω/2 ∫ Pᵐ I dμ′ + ω/(4π) Pᵐ(μ, μ₀) e^{−τ/μ₀}.
//!
//! Vector (I, Q, U), Rayleigh: the phase matrix Z = L(ψ_out) F(Θ) L(ψ_in) is built from the
//! geometry of each pair of directions — the rotation angles ψ come from dot products of the
//! meridian-plane and scattering-plane basis vectors, so no sign convention has to be
//! remembered — and projected on cos mΔ / sin mΔ by the trapezoid rule in the azimuth
//! difference Δ (exact: the Rayleigh matrix holds harmonics m ≤ 2 only). Stokes Q = I_ℓ − I_r,
//! ℓ in the meridian plane along ∂k/∂θ, r = ∂k/∂φ; I and Q vary as cos mφ, U as sin mφ. The
//! Rayleigh scattering matrix with depolarisation ρ (Hansen & Travis 1974 eq. 2.15), with
//! Δ = (1−ρ)/(1+ρ/2): F₁₁ = ¾Δ(1+cos²Θ) + 1 − Δ, F₁₂ = −¾Δ sin²Θ, F₂₂ = ¾Δ(1+cos²Θ),
//! F₃₃ = 3/2 Δ cosΘ.
//!
//! ## References
//! - Hovenier, J. W., van der Mee, C., Domke, H. (2004) Transfer of Polarized Light in Planetary
//!   Atmospheres, Springer, §§ 2.3–2.5 (rotation of Stokes parameters, phase matrix).
//! - Hansen, J. E. & Travis, L. D. (1974) Space Sci. Rev. 16, 527–610.
//! - Wiscombe, W. J. (1977) J. Atmos. Sci. 34, 1408 (delta-M truncation of βₗ).

use super::fresnel::{fresnel_matrix, fresnel_reflectance};
use super::quadrature::normalized_legendre;
use super::sos::{Kernel, Streams};

const FOUR_PI: f64 = 4.0 * std::f64::consts::PI;

/// Delta-M truncation (Wiscombe 1977) of Legendre coefficients βₗ (P = Σ βₗ Pₗ) to `n_terms`
/// terms: f = β_{n}/(2n+1), β′ₗ = (βₗ − (2l+1) f)/(1 − f). Returns (β′₀..β′_{n−1}, f).
#[must_use]
pub fn delta_m(beta: &[f64], n_terms: usize) -> (Vec<f64>, f64) {
    let f = beta.get(n_terms).map_or(0.0, |b| b / (2 * n_terms + 1) as f64).max(0.0);
    let scaled = (0..n_terms.min(beta.len())).map(|l| (beta[l] - (2 * l + 1) as f64 * f) / (1.0 - f)).collect();
    (scaled, f)
}

/// Scalar kernel of Fourier term `m` for Legendre coefficients `beta` (already truncated).
#[must_use]
pub fn scalar_kernel(streams: &Streams, beta: &[f64], m: usize, mu0: f64, water_index: f64) -> Kernel<1> {
    let l_max = beta.len().saturating_sub(1);
    let nd = streams.n_dirs();
    let nq = 2 * streams.n();
    let lam = |mu: f64| -> Vec<f64> { if l_max >= m { normalized_legendre(m, l_max, mu) } else { Vec::new() } };
    let dirs: Vec<Vec<f64>> = (0..nd).map(|d| lam(streams.signed_mu(d))).collect();
    let p = |a: &[f64], b: &[f64]| -> f64 {
        a.iter().zip(b).zip(&beta[m.min(beta.len())..]).map(|((x, y), bl)| bl * x * y).sum()
    };
    let sun = lam(mu0);
    let sun_up = lam(-mu0);
    let r0 = fresnel_reflectance(mu0, water_index);
    let mut quad = Vec::with_capacity(nd * nq);
    for i in 0..nd {
        for j in 0..nq {
            let w = streams.weight[j % streams.n()];
            quad.push([[0.5 * w * p(&dirs[i], &dirs[j])]]);
        }
    }
    Kernel {
        quad,
        sun: (0..nd).map(|i| [p(&dirs[i], &sun) / FOUR_PI]).collect(),
        sun_reflected: (0..nd).map(|i| [r0 * p(&dirs[i], &sun_up) / FOUR_PI]).collect(),
    }
}

type Vec3 = [f64; 3];

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Propagation vector (z up) for signed cosine μ (positive downward) and azimuth φ, with its
/// meridian basis (ℓ = ∂k/∂θ, r = ∂k/∂φ normalised).
fn direction(mu: f64, phi: f64) -> (Vec3, Vec3, Vec3) {
    let kz = -mu;
    let s = (1.0 - kz * kz).max(0.0).sqrt();
    let (c, sn) = (phi.cos(), phi.sin());
    let k = [s * c, s * sn, kz];
    let l = [kz * c, kz * sn, -s];
    let r = [-sn, c, 0.0];
    (k, l, r)
}

/// Rayleigh phase matrix (I, Q, U) from direction (μ_in, 0) into (μ_out, Δ), meridian frames.
fn rayleigh_z(mu_out: f64, mu_in: f64, delta: f64, depolarization: f64) -> [[f64; 3]; 3] {
    let (k_in, l_in, r_in) = direction(mu_in, 0.0);
    let (k_out, l_out, _) = direction(mu_out, delta);
    let cos_t = dot(k_in, k_out).clamp(-1.0, 1.0);
    let mut nrm = cross(k_in, k_out);
    let len = dot(nrm, nrm).sqrt();
    if len < 1e-12 {
        nrm = r_in; // forward or backward: any normal gives the same matrix for Rayleigh
    } else {
        nrm = [nrm[0] / len, nrm[1] / len, nrm[2] / len];
    }
    let ls_in = cross(nrm, k_in);
    let ls_out = cross(nrm, k_out);
    let (c1, s1) = (dot(l_in, ls_in), dot(r_in, ls_in));
    let (c2, s2) = (dot(l_out, ls_out), dot(l_out, nrm));
    let rot = |c: f64, s: f64| -> (f64, f64) { (c * c - s * s, 2.0 * s * c) }; // (cos2ψ, sin2ψ)
    let (c2i, s2i) = rot(c1, s1);
    let (c2o, s2o) = rot(c2, s2);
    let d = (1.0 - depolarization) / (1.0 + 0.5 * depolarization);
    let f11 = 0.75 * d * (1.0 + cos_t * cos_t) + 1.0 - d;
    let f12 = -0.75 * d * (1.0 - cos_t * cos_t);
    let f22 = 0.75 * d * (1.0 + cos_t * cos_t);
    let f33 = 1.5 * d * cos_t;
    // F·L(ψ_in): L = [[1,0,0],[0,c,s],[0,-s,c]]
    let fl = [[f11, f12 * c2i, f12 * s2i], [f12, f22 * c2i, f22 * s2i], [0.0, -f33 * s2i, f33 * c2i]];
    // L(ψ_out)·(F·L)
    [
        fl[0],
        [c2o * fl[1][0] + s2o * fl[2][0], c2o * fl[1][1] + s2o * fl[2][1], c2o * fl[1][2] + s2o * fl[2][2]],
        [-s2o * fl[1][0] + c2o * fl[2][0], -s2o * fl[1][1] + c2o * fl[2][1], -s2o * fl[1][2] + c2o * fl[2][2]],
    ]
}

/// Fourier kernel Kᵐ = ∫₀^{2π} [[Z₁₁c, Z₁₂c, −Z₁₃s], [Z₂₁c, Z₂₂c, −Z₂₃s], [Z₃₁s, Z₃₂s, Z₃₃c]] dΔ
/// with c = cos mΔ, s = sin mΔ, for m = 0, 1, 2.
fn rayleigh_fourier(mu_out: f64, mu_in: f64, depolarization: f64) -> [[[f64; 3]; 3]; 3] {
    const N: usize = 16;
    let mut k = [[[0.0; 3]; 3]; 3];
    let h = 2.0 * std::f64::consts::PI / N as f64;
    for step in 0..N {
        let delta = h * step as f64;
        let z = rayleigh_z(mu_out, mu_in, delta, depolarization);
        for (m, km) in k.iter_mut().enumerate() {
            let (c, s) = ((m as f64 * delta).cos(), (m as f64 * delta).sin());
            for r in 0..3 {
                for col in 0..3 {
                    let even = (r < 2) == (col < 2);
                    let v = if even {
                        z[r][col] * c
                    } else if r < 2 {
                        -z[r][col] * s
                    } else {
                        z[r][col] * s
                    };
                    km[r][col] += h * v;
                }
            }
        }
    }
    k
}

/// Vector Rayleigh kernels for m = 0, 1, 2.
#[must_use]
pub fn vector_rayleigh_kernels(streams: &Streams, depolarization: f64, mu0: f64, water_index: f64) -> Vec<Kernel<3>> {
    let nd = streams.n_dirs();
    let nq = 2 * streams.n();
    let mut kernels: Vec<Kernel<3>> = (0..3)
        .map(|_| Kernel { quad: Vec::with_capacity(nd * nq), sun: Vec::new(), sun_reflected: Vec::new() })
        .collect();
    for i in 0..nd {
        let mu_i = streams.signed_mu(i);
        for j in 0..nq {
            let w = streams.weight[j % streams.n()];
            let f = rayleigh_fourier(mu_i, streams.signed_mu(j), depolarization);
            for (m, km) in f.iter().enumerate() {
                let mut b = *km;
                for row in &mut b {
                    for v in row.iter_mut() {
                        *v *= w / FOUR_PI;
                    }
                }
                kernels[m].quad.push(b);
            }
        }
    }
    let r = fresnel_matrix(mu0, water_index);
    let norm = 1.0 / (2.0 * std::f64::consts::PI * FOUR_PI);
    for i in 0..nd {
        let mu_i = streams.signed_mu(i);
        let direct = rayleigh_fourier(mu_i, mu0, depolarization);
        let reflected = rayleigh_fourier(mu_i, -mu0, depolarization);
        for m in 0..3 {
            let col = |k: &[[f64; 3]; 3], c: usize| [k[0][c], k[1][c], k[2][c]];
            let d0 = col(&direct[m], 0);
            kernels[m].sun.push([d0[0] * norm, d0[1] * norm, d0[2] * norm]);
            let (a, b) = (col(&reflected[m], 0), col(&reflected[m], 1));
            kernels[m].sun_reflected.push([
                (a[0] * r[0][0] + b[0] * r[1][0]) * norm,
                (a[1] * r[0][0] + b[1] * r[1][0]) * norm,
                (a[2] * r[0][0] + b[2] * r[1][0]) * norm,
            ]);
        }
    }
    kernels
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vector_kernel_intensity_equals_the_scalar_kernel() {
        // Z₁₁ = F₁₁(Θ) = the scalar phase function: the I→I kernels must equal the Legendre ones.
        // For the reflected sun the vector kernel also carries Z₁₂·R₂₁ (reflected sunlight is
        // polarised), which vanishes at normal incidence where r_ℓ² = r_r²: compare there.
        let streams = Streams::new(4, vec![1.0, 0.8]);
        let rho = 0.0279;
        let beta = super::super::phase::PhaseFunction::Rayleigh { depolarization: rho }.moments(2);
        for mu0 in [0.6, 1.0] {
            let vk = vector_rayleigh_kernels(&streams, rho, mu0, 1.34);
            for m in 0..3 {
                let sk = scalar_kernel(&streams, &beta, m, mu0, 1.34);
                for (a, b) in vk[m].quad.iter().zip(&sk.quad) {
                    assert!((a[0][0] - b[0][0]).abs() < 1e-12, "m={m}: {} vs {}", a[0][0], b[0][0]);
                }
                for (a, b) in vk[m].sun.iter().zip(&sk.sun) {
                    assert!((a[0] - b[0]).abs() < 1e-12, "m={m}: sun {} vs {}", a[0], b[0]);
                }
                if mu0 == 1.0 {
                    for (a, b) in vk[m].sun_reflected.iter().zip(&sk.sun_reflected) {
                        assert!((a[0] - b[0]).abs() < 1e-12, "m={m}: reflected {} vs {}", a[0], b[0]);
                    }
                }
            }
        }
    }

    #[test]
    fn rayleigh_matrix_has_the_assumed_azimuth_symmetry() {
        // I, Q rows/cols even in Δ and U odd: the projections on the other parity vanish, and
        // harmonics above m = 2 are absent.
        let (mu_o, mu_i, rho) = (-0.7, 0.4, 0.0279);
        for delta in [0.3f64, 1.2, 2.5] {
            let a = rayleigh_z(mu_o, mu_i, delta, rho);
            let b = rayleigh_z(mu_o, mu_i, -delta, rho);
            for r in 0..3 {
                for c in 0..3 {
                    let even = (r < 2) == (c < 2);
                    let expect = if even { a[r][c] } else { -a[r][c] };
                    assert!((b[r][c] - expect).abs() < 1e-12, "({r},{c}) at {delta}");
                }
            }
        }
        // Single scattering of unpolarised light at 90° is polarised perpendicular to the
        // scattering plane, with degree (1−ρ)/(1+ρ): Q = I_ℓ − I_r < 0 in the scattering-plane
        // frame. Sunlight travelling horizontally (μ_in = 0, azimuth 0) scattered straight up
        // (μ_out = −1, azimuth 0): the up direction's meridian plane is the scattering plane, so
        // the meridian-frame Q/I must be −(1−ρ)/(1+ρ), sign included.
        for rho in [0.0, 0.0279] {
            let z = rayleigh_z(-1.0, 0.0, 0.0, rho);
            let expected = -(1.0 - rho) / (1.0 + rho);
            assert!((z[1][0] / z[0][0] - expected).abs() < 1e-9, "ρ={rho}: {:?}", z);
            assert!(z[2][0].abs() < 1e-12, "no U for a symmetric geometry");
        }
    }
}
