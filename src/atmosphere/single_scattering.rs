//! Exact single scattering for a LUT's nodes (the TMS correction of Nakajima & Tanaka 1988, see
//! [`super::rt`]): the path coefficients a LUT interpolates, the column's scatterers, and the
//! scattering angles of one (sun, view) geometry, shared by every wavelength node.

use super::phase::{PhaseFunction, ScatteringAngle};

/// Exact single-scattering ingredients for one (sun, view) pair: for each of the four paths
/// over the Fresnel surface (sun→view; sun→down→surface→view; sun→surface→up→view;
/// sun→surface→down→surface→view), F_p·∫e^{−m_p τ}dτ_R and F_p·∫e^{−m_p τ}dτ_a. They vary smoothly
/// with the zenith angles and not at all with azimuth, so a LUT interpolates them and evaluates
/// the phase functions at the exact scattering angles.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SsCoefficients(pub [[f64; 2]; 4]);

impl SsCoefficients {
    /// Σ wᵢ cᵢ, for interpolation.
    #[must_use]
    pub fn weighted(parts: &[(f64, &Self)]) -> Self {
        let mut out = [[0.0; 2]; 4];
        for (w, c) in parts {
            for (o, v) in out.iter_mut().zip(&c.0) {
                o[0] += w * v[0];
                o[1] += w * v[1];
            }
        }
        Self(out)
    }
}

/// The column's two scatterers, for single-scattering evaluations.
#[derive(Debug, Clone, PartialEq)]
pub struct Scatterers {
    /// Molecular phase function.
    pub rayleigh: PhaseFunction,
    /// Aerosol single-scattering albedo and phase function, if any.
    pub aerosol: Option<(f64, PhaseFunction)>,
}

impl Scatterers {
    /// Single-scattered TOA radiance (unit solar flux) from coefficients `c` at sun/view cosines
    /// μ₀, μ_v and relative azimuth Δφ: (1/(4πμ_v)) Σ_p [P_R(Θ_p) c_p,R + ω_a P_a(Θ_p) c_p,a],
    /// with cos Θ = ∓μ₀μ_v − sinθ₀ sinθ_v cos Δφ (− for paths that change hemisphere).
    #[must_use]
    pub fn single_scattering(&self, c: &SsCoefficients, mu0: f64, muv: f64, relative_azimuth_rad: f64) -> f64 {
        self.single_scattering_at(c, &ScatteringGeometry::new(mu0, muv, relative_azimuth_rad))
    }

    /// [`Self::single_scattering`] at a geometry's angles taken once (the same value).
    #[must_use]
    pub fn single_scattering_at(&self, c: &SsCoefficients, g: &ScatteringGeometry) -> f64 {
        let [opposite, same] = &g.angles;
        // Two scattering angles between the four terms: each phase function read once at each.
        let rayleigh = [self.rayleigh.value_at(opposite), self.rayleigh.value_at(same)];
        let aerosol =
            self.aerosol.as_ref().map(|(ssa, phase)| (*ssa, [phase.value_at(opposite), phase.value_at(same)]));
        let mut total = 0.0;
        for (k, [c_r, c_a]) in c.0.iter().enumerate() {
            let at = usize::from(!(k == 0 || k == 3));
            total += rayleigh[at] * c_r;
            if let Some((ssa, p)) = &aerosol {
                total += ssa * p[at] * c_a;
            }
        }
        total / (4.0 * std::f64::consts::PI * g.muv)
    }
}

/// The two scattering angles of one (sun, view) geometry: Θ of the paths that change hemisphere
/// (cos Θ = −μ₀μ_v − sinθ₀ sinθ_v cos Δφ) and of those that do not (+μ₀μ_v), and μ_v.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScatteringGeometry {
    /// [opposite hemisphere, same hemisphere].
    pub angles: [ScatteringAngle; 2],
    /// View cosine μ_v.
    pub muv: f64,
}

impl ScatteringGeometry {
    /// The angles at sun/view cosines μ₀, μ_v and relative azimuth Δφ.
    #[must_use]
    pub fn new(mu0: f64, muv: f64, relative_azimuth_rad: f64) -> Self {
        let (s0, sv) = ((1.0 - mu0 * mu0).max(0.0).sqrt(), (1.0 - muv * muv).max(0.0).sqrt());
        let horizontal = s0 * sv * relative_azimuth_rad.cos();
        let cos_opposite = -mu0 * muv - horizontal;
        let cos_same = mu0 * muv - horizontal;
        Self { angles: [ScatteringAngle::new(cos_opposite), ScatteringAngle::new(cos_same)], muv }
    }
}
