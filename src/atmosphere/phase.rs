//! Scattering phase functions: Rayleigh (analytic) and tabulated (aerosol Mie), their values at
//! a scattering angle and their Legendre expansion P(cosΘ) = Σₗ βₗ Pₗ(cosΘ), normalised so that
//! ½∫P dcosΘ = 1 (β₀ = 1, β₁ = 3g).
//!
//! ## References
//! - Chandrasekhar, S. (1950) Radiative Transfer, Oxford, §17 (Rayleigh phase function).
//! - Hansen, J. E. & Travis, L. D. (1974) Light scattering in planetary atmospheres. Space Sci.
//!   Rev. 16, 527–610 (depolarisation: P = 1 + β₂P₂ with β₂ = (1−ρ)/(2+ρ)).

use super::AtmosphereError;
use super::quadrature::gauss_legendre;

/// A phase function.
#[derive(Debug, Clone, PartialEq)]
pub enum PhaseFunction {
    /// Rayleigh scattering with depolarisation ratio ρ: P = 1 + β₂P₂(cosΘ), β₂ = (1−ρ)/(2+ρ).
    Rayleigh {
        /// Depolarisation ratio ρ (0.0279 for air, Young 1980; OSOAA's CTE_MDF_AIR).
        depolarization: f64,
    },
    /// Tabulated at increasing scattering angles (radians); interpolated linearly in angle on
    /// ln P (phase functions vary exponentially in the forward peak).
    Tabulated {
        /// Scattering angles, rad, from 0 to π.
        angles_rad: Vec<f64>,
        /// ln P at those angles.
        ln_values: Vec<f64>,
    },
}

/// A scattering angle Θ: its cosine and Θ itself (radians, the cosine clamped to [−1, 1]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScatteringAngle {
    /// cos Θ as given.
    pub cos: f64,
    /// Θ, radians.
    pub theta_rad: f64,
}

impl ScatteringAngle {
    /// The angle with cosine `cos_theta`.
    #[must_use]
    pub fn new(cos_theta: f64) -> Self {
        Self { cos: cos_theta, theta_rad: cos_theta.clamp(-1.0, 1.0).acos() }
    }
}

impl PhaseFunction {
    /// A tabulated phase function from angles in degrees (0…180) and values; renormalised so
    /// that ½∫P dcosΘ = 1 exactly under the interpolation used.
    pub fn from_table(angles_deg: &[f64], values: &[f64]) -> Result<Self, AtmosphereError> {
        let ok = angles_deg.len() == values.len()
            && angles_deg.len() >= 2
            && angles_deg.first().is_some_and(|a| a.abs() < 1e-12)
            && angles_deg.last().is_some_and(|a| (a - 180.0).abs() < 1e-12)
            && angles_deg.windows(2).all(|w| w[1] > w[0])
            && values.iter().all(|v| v.is_finite() && *v > 0.0);
        if !ok {
            return Err(AtmosphereError::Data(
                "phase function table: angles must rise from 0 to 180 degrees with positive values".into(),
            ));
        }
        let mut p = Self::Tabulated {
            angles_rad: angles_deg.iter().map(|a| a.to_radians()).collect(),
            ln_values: values.iter().map(|v| v.ln()).collect(),
        };
        let norm = p.moments(0)[0];
        if let Self::Tabulated { ln_values, .. } = &mut p {
            for v in ln_values.iter_mut() {
                *v -= norm.ln();
            }
        }
        Ok(p)
    }

    /// P at scattering angle with cosine `cos_theta`.
    #[must_use]
    pub fn value(&self, cos_theta: f64) -> f64 {
        self.value_at(&ScatteringAngle::new(cos_theta))
    }

    /// P at `angle`: [`Self::value`] with the angle's arccosine taken once for many phase
    /// functions (a LUT's wavelength nodes all scatter through the same angles).
    #[must_use]
    pub fn value_at(&self, angle: &ScatteringAngle) -> f64 {
        match self {
            Self::Rayleigh { depolarization } => {
                let b2 = rayleigh_beta2(*depolarization);
                let cos_theta = angle.cos;
                1.0 + b2 * 0.5 * (3.0 * cos_theta * cos_theta - 1.0)
            }
            Self::Tabulated { angles_rad, ln_values } => {
                let theta = angle.theta_rad;
                let j = angles_rad.partition_point(|&a| a <= theta).clamp(1, angles_rad.len() - 1);
                let t = (theta - angles_rad[j - 1]) / (angles_rad[j] - angles_rad[j - 1]);
                (ln_values[j - 1] + t * (ln_values[j] - ln_values[j - 1])).exp()
            }
        }
    }

    /// Expansion coefficients β₀..β_{l_max} (β₀ = 1 after normalisation, β₁ = 3g).
    #[must_use]
    pub fn moments(&self, l_max: usize) -> Vec<f64> {
        match self {
            Self::Rayleigh { depolarization } => {
                let mut b = vec![0.0; l_max + 1];
                b[0] = 1.0;
                if l_max >= 2 {
                    b[2] = rayleigh_beta2(*depolarization);
                }
                b
            }
            Self::Tabulated { angles_rad, .. } => {
                // βₗ = (2l+1)/2 ∫ P(μ) Pₗ(μ) dμ, Gauss–Legendre on every table interval (in angle).
                let (gx, gw) = gauss_legendre(12);
                let mut beta = vec![0.0; l_max + 1];
                for w in angles_rad.windows(2) {
                    let (a, b) = (w[0], w[1]);
                    for (x, wt) in gx.iter().zip(&gw) {
                        let theta = 0.5 * (a + b) + 0.5 * (b - a) * x;
                        let mu = theta.cos();
                        // dμ = sinθ dθ
                        let weight = wt * 0.5 * (b - a) * theta.sin() * self.value(mu);
                        add_legendre(&mut beta, weight, mu);
                    }
                }
                beta.iter().enumerate().map(|(l, v)| (2 * l + 1) as f64 / 2.0 * v).collect()
            }
        }
    }

    /// The share of scattered light sent into the forward hemisphere, η = ½∫₀¹ P(μ) dμ
    /// (μ = cosΘ; ½ for any phase function symmetric about 90°, Rayleigh's included).
    ///
    /// ```
    /// use shoal::atmosphere::PhaseFunction;
    /// let r = PhaseFunction::Rayleigh { depolarization: 0.0279 };
    /// assert!((r.forward_fraction() - 0.5).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn forward_fraction(&self) -> f64 {
        match self {
            // ∫₀¹ P₂(μ) dμ = 0.
            Self::Rayleigh { .. } => 0.5,
            Self::Tabulated { angles_rad, .. } => {
                let (gx, gw) = gauss_legendre(12);
                let half = std::f64::consts::FRAC_PI_2;
                let mut sum = 0.0;
                for w in angles_rad.windows(2) {
                    let (a, b) = (w[0], w[1].min(half));
                    if a >= half {
                        break;
                    }
                    for (x, wt) in gx.iter().zip(&gw) {
                        let theta = 0.5 * (a + b) + 0.5 * (b - a) * x;
                        sum += wt * 0.5 * (b - a) * theta.sin() * self.value(theta.cos());
                    }
                }
                0.5 * sum
            }
        }
    }

    /// Asymmetry parameter g = β₁/3.
    #[must_use]
    pub fn asymmetry(&self) -> f64 {
        self.moments(1).get(1).copied().unwrap_or(0.0) / 3.0
    }
}

/// β₂ of the Rayleigh phase function with depolarisation ratio ρ: (1−ρ)/(2+ρ)
/// (Hansen & Travis 1974 eq. 2.15; OSOAA's β₂ = A/2 with A = 2(1−ρ)/(2+ρ)).
#[must_use]
pub fn rayleigh_beta2(depolarization: f64) -> f64 {
    (1.0 - depolarization) / (2.0 + depolarization)
}

/// βₗ += w·Pₗ(μ) for l = 0..β.len(): the Legendre recurrence of
/// [`super::quadrature::legendre_polynomials`], the same operations in the same order, without
/// its vector (allocated per quadrature point, it was a third of the moments' time in perf).
#[inline]
fn add_legendre(beta: &mut [f64], weight: f64, mu: f64) {
    let (mut before, mut last) = (0.0, 1.0);
    for (l, bl) in beta.iter_mut().enumerate() {
        let p = match l {
            0 => 1.0,
            1 => mu,
            _ => {
                let lf = l as f64;
                ((2.0 * lf - 1.0) * mu * last - (lf - 1.0) * before) / lf
            }
        };
        *bl += weight * p;
        if l > 0 {
            (before, last) = (last, p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_in_place_recurrence_is_the_polynomials_bit_for_bit() {
        for mu in [-1.0, -0.73, 0.0, 0.31, 0.999, 1.0] {
            let mut beta = [0.25; 25];
            add_legendre(&mut beta, 0.7, mu);
            let p = super::super::quadrature::legendre_polynomials(24, mu);
            for (l, (b, pl)) in beta.iter().zip(&p).enumerate() {
                assert_eq!(b.to_bits(), (0.25 + 0.7 * pl).to_bits(), "l = {l}, μ = {mu}");
            }
        }
    }

    #[test]
    fn tabulated_rayleigh_reproduces_analytic_moments() {
        // On the aerosol table's 2° spacing, ln-linear interpolation of a smooth phase function
        // errs by ~(Δθ)²/8·|d²lnP/dθ²| ≈ 1e-4; the moments inherit that.
        let r = PhaseFunction::Rayleigh { depolarization: 0.0279 };
        let angles: Vec<f64> = (0..=90).map(|i| 2.0 * f64::from(i)).collect();
        let values: Vec<f64> = angles.iter().map(|a: &f64| r.value(a.to_radians().cos())).collect();
        let t = PhaseFunction::from_table(&angles, &values).unwrap();
        let (bt, br) = (t.moments(6), r.moments(6));
        for l in 0..=6 {
            assert!((bt[l] - br[l]).abs() < 5e-4, "l={l}: {} vs {}", bt[l], br[l]);
        }
        // OSOAA: β₂ = A/2, A = 2(1−δ)/(2+δ) with δ = 0.0279 → 0.479363.
        assert!((br[2] - 0.479_363).abs() < 1e-6, "OSOAA's β₂ for air: {}", br[2]);
    }

    #[test]
    fn forward_fraction_of_isotropic_and_henyey_greenstein_phase_functions() {
        // Isotropic: exactly half forward.
        let angles: Vec<f64> = (0..=90).map(|i| 2.0 * f64::from(i)).collect();
        let iso = PhaseFunction::from_table(&angles, &vec![1.0; angles.len()]).unwrap();
        assert!((iso.forward_fraction() - 0.5).abs() < 1e-12);
        // Henyey–Greenstein, g = 0.7 (normalised ½∫P dμ = 1): ½∫₀¹ P dμ =
        // (1+g)/(2g) − (1−g²)/(2g√(1+g²)) = 0.915851 (integrated by hand from P = (1−g²)/(1+g²−2gμ)^{3/2}).
        let g: f64 = 0.7;
        let fine: Vec<f64> = (0..=1800).map(|i| 0.1 * f64::from(i)).collect();
        let hg: Vec<f64> =
            fine.iter().map(|a| (1.0 - g * g) / (1.0 + g * g - 2.0 * g * a.to_radians().cos()).powf(1.5)).collect();
        let p = PhaseFunction::from_table(&fine, &hg).unwrap();
        let exact = (1.0 + g) / (2.0 * g) - (1.0 - g * g) / (2.0 * g * (1.0 + g * g).sqrt());
        assert!((exact - 0.915_851).abs() < 1e-6, "{exact}");
        // 1e-4: ln-linear interpolation on a 0.1° table and 12-point Gauss–Legendre per interval.
        assert!((p.forward_fraction() - exact).abs() < 1e-4, "{} vs {exact}", p.forward_fraction());
    }
}
