//! The polarisation of the path radiance at the top of the atmosphere: Stokes Q and U from the
//! vector solution's Fourier terms, and their rotation into an instrument's frame.
//!
//! The vector solver ([`super::rt`]) works in the meridian-plane frame of each direction
//! (Q = I_ℓ − I_r, ℓ in the meridian plane along ∂k/∂θ): I and Q vary as cos mψ and U as sin mψ,
//! with ψ = π − Δφ the azimuth of travel relative to the solar beam, the same expansion as the
//! intensity ([`super::rt::fourier_sum`]). Only molecules polarise there (the aerosol is a
//! depolarising scatterer in the vector solution), so the terms stop at m = 2, as the Rayleigh
//! phase matrix does (Hovenier, van der Mee & Domke 2004, §2.5).
//!
//! A frame turned by α about the direction of travel sees
//! Q′ = Q cos 2α + U sin 2α, U′ = −Q sin 2α + U cos 2α (Hovenier et al. 2004, eq. 1.41; Chandrasekhar
//! 1960, §15).
//!
//! ## References
//! - Hovenier, J. W., van der Mee, C., Domke, H. (2004) Transfer of Polarized Light in Planetary
//!   Atmospheres. Springer.
//! - Chandrasekhar, S. (1960) Radiative Transfer. Dover.

/// Q at relative azimuth Δφ (view − sun, rad) from `[Q₀, Q₁, Q₂, U₁, U₂]`:
/// Q₀ + 2Q₁ cos ψ + 2Q₂ cos 2ψ, ψ = π − Δφ.
#[must_use]
pub fn q_sum(c: &[f64; 5], relative_azimuth_rad: f64) -> f64 {
    let psi = std::f64::consts::PI - relative_azimuth_rad;
    c[0] + 2.0 * c[1] * psi.cos() + 2.0 * c[2] * (2.0 * psi).cos()
}

/// U at relative azimuth Δφ from `[Q₀, Q₁, Q₂, U₁, U₂]`: 2U₁ sin ψ + 2U₂ sin 2ψ, ψ = π − Δφ.
#[must_use]
pub fn u_sum(c: &[f64; 5], relative_azimuth_rad: f64) -> f64 {
    let psi = std::f64::consts::PI - relative_azimuth_rad;
    2.0 * c[3] * psi.sin() + 2.0 * c[4] * (2.0 * psi).sin()
}

/// (Q, U) seen from a frame turned by `alpha_rad` from the meridian plane.
#[must_use]
pub fn rotate(q: f64, u: f64, alpha_rad: f64) -> (f64, f64) {
    let (s, c) = (2.0 * alpha_rad).sin_cos();
    (q * c + u * s, -q * s + u * c)
}

/// Degree of linear polarisation √(Q² + U²)/I (0 where I is not positive).
#[must_use]
pub fn dolp(i: f64, q: f64, u: f64) -> f64 {
    if i > 0.0 { q.hypot(u) / i } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_keeps_the_polarised_intensity_and_turns_twice_as_fast() {
        let (q, u) = (0.3, -0.1);
        for alpha in [0.2f64, 1.0, 2.5] {
            let (q2, u2) = rotate(q, u, alpha);
            assert!((q2.hypot(u2) - q.hypot(u)).abs() < 1e-15);
        }
        let (q2, u2) = rotate(q, u, std::f64::consts::FRAC_PI_2);
        assert!((q2 + q).abs() < 1e-15 && (u2 + u).abs() < 1e-15, "a quarter turn flips Q and U");
    }
}
