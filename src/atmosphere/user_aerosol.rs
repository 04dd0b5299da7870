//! An aerosol from a user's own size distribution: one or two log-normal modes, each with its
//! modal radius, geometric standard deviation and (spectrally flat) refractive index, mixed by
//! volume — OSOAA's mono-modal and bi-modal log-normal models (`-AER.Model 1` and `3`, fine and
//! coarse modes with a coarse volume fraction), the form AERONET inversions report (Dubovik &
//! King 2000). An aerosol outside any WMO model and outside an image-based correction's family.
//!
//! Each mode's optics come from Shoal's Mie code ([`super::mie`], on OSOAA's size grid) at the
//! component table's wavelengths ([`super::aerosol::TABLE_WAVELENGTHS_NM`]), once per mode and
//! process (a few seconds on two cores; cached), and are then mixed and interpolated exactly as
//! the WMO components are ([`super::aerosol::mixture_optics`]).
//!
//! Sizes are integrated up to r_max = r_m·exp(2σ² + 4σ) (σ = ln σ_g): four standard deviations
//! past the median of the cross-section-weighted distribution, whose median is r_m·exp(2σ²).
//! r_max is capped at [`R_MAX_UM`]; the means are per particle of the distribution truncated
//! there, as OSOAA truncates its components at their α_max. A mode with more than
//! [`MAX_VOLUME_BEYOND_CAP`] of its volume beyond the cap is refused: its number fraction (from
//! the untruncated volume) would no longer match the volume fraction asked for.
//!
//! ## References
//! - Chami, M. et al. (2015) OSOAA: a vector radiative transfer model of coupled
//!   atmosphere-ocean system for a rough sea surface. Opt. Express 23, 27829–27852 (user
//!   log-normal models).
//! - Dubovik, O. & King, M. D. (2000) A flexible inversion algorithm for retrieval of aerosol
//!   optical properties from Sun and sky radiance measurements. J. Geophys. Res. 105,
//!   20673–20696 (bi-modal log-normal volume size distributions).

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::AtmosphereError;
use super::Complex;
use super::aerosol::{ComponentOptics, TABLE_WAVELENGTHS_NM, table_angles_deg};
use super::mie::{LogNormal, SizeGrid, integrate_lognormal};

/// Largest radius integrated, µm (α = 580 at 325 nm).
pub const R_MAX_UM: f64 = 30.0;

/// Largest share of a mode's volume allowed beyond [`R_MAX_UM`].
pub const MAX_VOLUME_BEYOND_CAP: f64 = 0.02;

/// P(Z > z) of a standard normal variable, from erfc (Abramowitz & Stegun 1964, 7.1.26:
/// |error| ≤ 1.5e-7).
fn normal_upper_tail(z: f64) -> f64 {
    let x = z.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * x);
    let poly =
        t * (0.254_829_592 + t * (-0.284_496_736 + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erfc = poly * (-x * x).exp();
    if z >= 0.0 { 0.5 * erfc } else { 1.0 - 0.5 * erfc }
}

/// One log-normal mode of a user's aerosol: number distribution
/// dN/dr ∝ exp(−½(ln(r/r_m)/ln σ_g)²)/r.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AerosolMode {
    /// Modal (median) radius of the number distribution r_m, µm.
    pub mode_radius_um: f64,
    /// Geometric standard deviation σ_g (> 1).
    pub sigma_g: f64,
    /// Real part of the refractive index (the same at every wavelength).
    pub refractive_real: f64,
    /// Imaginary part of the refractive index (absorption; the same at every wavelength).
    pub refractive_imag: f64,
}

/// A user's size distribution: a fine mode and, optionally, a coarse one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SizeDistribution {
    /// The fine mode.
    pub fine: AerosolMode,
    /// The coarse mode, if any.
    #[serde(default)]
    pub coarse: Option<AerosolMode>,
    /// Share of the aerosol volume in the coarse mode (0–1; unused without one).
    #[serde(default)]
    pub coarse_volume_fraction: f64,
}

impl AerosolMode {
    /// σ = ln σ_g.
    fn ln_sigma(&self) -> f64 {
        self.sigma_g.ln()
    }

    /// Volume per particle, µm³: (4/3)π r_m³ exp(9σ²/2), the log-normal's third moment.
    #[must_use]
    pub fn volume_um3(&self) -> f64 {
        let s = self.ln_sigma();
        4.0 / 3.0 * std::f64::consts::PI * self.mode_radius_um.powi(3) * (4.5 * s * s).exp()
    }

    /// Share of the mode's volume beyond [`R_MAX_UM`]: the volume distribution is log-normal with
    /// median r_m·exp(3σ²) and the same σ.
    #[must_use]
    pub fn volume_beyond_cap(&self) -> f64 {
        let s = self.ln_sigma();
        let volume_median = self.mode_radius_um * (3.0 * s * s).exp();
        normal_upper_tail((R_MAX_UM / volume_median).ln() / s)
    }

    /// Largest radius integrated, µm (module docs).
    #[must_use]
    pub fn r_max_um(&self) -> f64 {
        let s = self.ln_sigma();
        (self.mode_radius_um * (2.0 * s * s + 4.0 * s).exp()).min(R_MAX_UM)
    }

    /// The mode's optics at `wavelength_nm` from the Mie code.
    #[must_use]
    pub fn compute(&self, wavelength_nm: f64, mu: &[f64]) -> ComponentOptics {
        let w_um = wavelength_nm * 1e-3;
        let dist = LogNormal {
            mode_radius_um: self.mode_radius_um,
            ln_sigma: self.ln_sigma(),
            alpha_max: 2.0 * std::f64::consts::PI * self.r_max_um() / w_um,
        };
        let m = Complex::new(self.refractive_real, self.refractive_imag);
        let bulk = integrate_lognormal(&dist, w_um, m, mu, SizeGrid::Osoaa);
        ComponentOptics { c_ext_um2: bulk.c_ext_um2, c_sca_um2: bulk.c_sca_um2, p11: bulk.p11 }
    }

    /// The mode's optics at every wavelength of the component table, computed once per process.
    pub fn table(&self) -> Arc<Vec<ComponentOptics>> {
        type Cache = Mutex<HashMap<[u64; 4], Arc<Vec<ComponentOptics>>>>;
        static CACHE: OnceLock<Cache> = OnceLock::new();
        let key = [self.mode_radius_um, self.sigma_g, self.refractive_real, self.refractive_imag].map(f64::to_bits);
        let cache = CACHE.get_or_init(Cache::default);
        if let Some(t) = cache.lock().unwrap_or_else(std::sync::PoisonError::into_inner).get(&key) {
            return t.clone();
        }
        let mu: Vec<f64> = table_angles_deg().iter().map(|a| a.to_radians().cos()).collect();
        let rows: Vec<ComponentOptics> = TABLE_WAVELENGTHS_NM.par_iter().map(|&w| self.compute(w, &mu)).collect();
        let rows = Arc::new(rows);
        cache.lock().unwrap_or_else(std::sync::PoisonError::into_inner).insert(key, rows.clone());
        rows
    }
}

impl SizeDistribution {
    /// The modes with their number fractions Nᵢ = (Cᵢ/Vᵢ)/Σⱼ(Cⱼ/Vⱼ) from the volume fractions Cᵢ.
    #[must_use]
    pub fn number_fractions(&self) -> Vec<(AerosolMode, f64)> {
        let parts: Vec<(AerosolMode, f64)> = match self.coarse {
            Some(c) if self.coarse_volume_fraction > 0.0 => {
                vec![(self.fine, 1.0 - self.coarse_volume_fraction), (c, self.coarse_volume_fraction)]
            }
            _ => vec![(self.fine, 1.0)],
        };
        let parts: Vec<(AerosolMode, f64)> = parts.into_iter().filter(|p| p.1 > 0.0).collect();
        let total: f64 = parts.iter().map(|(m, v)| v / m.volume_um3()).sum();
        parts.iter().map(|(m, v)| (*m, v / m.volume_um3() / total)).collect()
    }

    /// Check every number against [`crate::ranges`].
    pub fn validate(&self) -> Result<(), AtmosphereError> {
        use crate::ranges as r;
        let modes = [("fine", Some(self.fine)), ("coarse", self.coarse)];
        for (name, mode) in modes {
            let Some(m) = mode else { continue };
            for (range, v) in [
                (&r::AEROSOL_MODE_RADIUS_UM, m.mode_radius_um),
                (&r::AEROSOL_MODE_SIGMA_G, m.sigma_g),
                (&r::AEROSOL_MODE_REFRACTIVE_REAL, m.refractive_real),
                (&r::AEROSOL_MODE_REFRACTIVE_IMAG, m.refractive_imag),
            ] {
                if !range.contains(v) {
                    let leaf = range.path.rsplit('.').next().unwrap_or(range.path);
                    return Err(AtmosphereError::OutOfRange {
                        field: format!("aerosol.LogNormal.{name}.{leaf}"),
                        value: v,
                        allowed: range.allowed(),
                    });
                }
            }
            let beyond = m.volume_beyond_cap();
            if beyond > MAX_VOLUME_BEYOND_CAP {
                return Err(AtmosphereError::OutOfRange {
                    field: format!("aerosol.LogNormal.{name}.mode_radius_um"),
                    value: m.mode_radius_um,
                    allowed: format!(
                        "a mode with at most {:.0} % of its volume beyond {R_MAX_UM} µm (this one, with sigma_g {}, has {:.0} %): a smaller radius or a narrower mode",
                        100.0 * MAX_VOLUME_BEYOND_CAP,
                        m.sigma_g,
                        100.0 * beyond
                    ),
                });
            }
        }
        let f = &r::AEROSOL_COARSE_VOLUME_FRACTION;
        if !f.contains(self.coarse_volume_fraction) {
            return Err(AtmosphereError::OutOfRange {
                field: "aerosol.LogNormal.coarse_volume_fraction".into(),
                value: self.coarse_volume_fraction,
                allowed: f.allowed(),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_wmo_oceanic_distribution_is_allowed() {
        // r_m 0.3 µm, σ_g 2.51: 1.3 % of its volume beyond 30 µm, inside the 2 % allowed.
        let oceanic = AerosolMode { mode_radius_um: 0.3, sigma_g: 2.51, refractive_real: 1.381, refractive_imag: 0.0 };
        assert!(oceanic.volume_beyond_cap() < MAX_VOLUME_BEYOND_CAP, "{}", oceanic.volume_beyond_cap());
        let d = SizeDistribution { fine: oceanic, coarse: None, coarse_volume_fraction: 0.0 };
        assert!(d.validate().is_ok());
    }

    #[test]
    fn the_normal_tail_and_the_cap() {
        // Φ tables: P(Z > 0) = 0.5, P(Z > 1.96) = 0.025, P(Z > −1) = 0.8413.
        assert!((normal_upper_tail(0.0) - 0.5).abs() < 1e-7);
        assert!((normal_upper_tail(1.959_964) - 0.025).abs() < 1e-6);
        assert!((normal_upper_tail(-1.0) - 0.841_345).abs() < 1e-6);
        // r_m 2 µm, σ_g 2.5: volume median 2·exp(3·0.8396) = 24.7 µm, so ~40 % beyond 30 µm.
        let coarse = AerosolMode { mode_radius_um: 2.0, sigma_g: 2.5, refractive_real: 1.5, refractive_imag: 0.0 };
        assert!((coarse.volume_beyond_cap() - 0.41).abs() < 0.02, "{}", coarse.volume_beyond_cap());
        let d = SizeDistribution { fine: coarse, coarse: None, coarse_volume_fraction: 0.0 };
        assert!(d.validate().unwrap_err().to_string().contains("beyond 30 µm"));
        // The smoke preset's coarse mode keeps all but 0.14 % (measured).
        let smoke = AerosolMode { mode_radius_um: 0.67, sigma_g: 2.08, refractive_real: 1.51, refractive_imag: 0.021 };
        assert!(smoke.volume_beyond_cap() < 2e-3, "{}", smoke.volume_beyond_cap());
    }

    #[test]
    fn volume_is_the_third_moment() {
        // A narrow mode holds particles of its modal radius.
        let m = AerosolMode { mode_radius_um: 0.2, sigma_g: 1.0001, refractive_real: 1.5, refractive_imag: 0.0 };
        let sphere = 4.0 / 3.0 * std::f64::consts::PI * 0.2f64.powi(3);
        assert!((m.volume_um3() / sphere - 1.0).abs() < 1e-6);
        // Equal volumes: the number fraction goes to the smaller particles by V_coarse/V_fine.
        let d = SizeDistribution {
            fine: AerosolMode { sigma_g: 1.5, ..m },
            coarse: Some(AerosolMode { mode_radius_um: 1.0, sigma_g: 1.5, ..m }),
            coarse_volume_fraction: 0.5,
        };
        let n = d.number_fractions();
        assert!((n[0].1 / n[1].1 - 125.0).abs() < 1e-9, "{n:?}");
    }
}
