//! Gas transmittance. Up to 1000 nm (ozone, oxygen, water vapour) by the clear-sky model of
//! Gregg & Carder (1990) as used in WASI (Gege 2012), with the WASI absorption coefficients;
//! from 1000 to 2500 nm (water vapour and the mixed gases O₂, CO₂, CH₄, N₂O, CO) from a table of
//! 6SV's band-model transmittances against the path amount ([`super::gas_swir`]). Up to 1000 nm:
//!
//! - T_O3 = exp(−a_oz H_oz M_oz), M_oz = 1.0035/(cos²θ + 0.007)^½ (Paltridge & Platt 1976)
//! - T_O2 = exp(−1.41 a_ox M′/(1 + 118.3 a_ox M′)^0.45)
//! - T_H2O = exp(−0.2385 a_wv W M/(1 + 20.07 a_wv W M)^0.45)
//!
//! with M the relative air mass (Kasten & Young 1989) and M′ = M·P/1013.25. Absorption is
//! treated as decoupled from scattering (6S practice, Vermote et al. 1997): the sun–surface path
//! is multiplied by the one-way transmittance, and the whole sun–surface–sensor path (path
//! radiance, the water-leaving signal at the sensor) by the two-way transmittance of the summed
//! air masses ([`two_way_transmittance`]).
//!
//! ## References
//! - Gregg, W. W. & Carder, K. L. (1990) A simple spectral solar irradiance model for cloudless
//!   maritime atmospheres. Limnol. Oceanogr. 35, 1657–1675.
//! - Gege, P. (2012) Analytic model for the direct and diffuse components of downwelling spectral
//!   irradiance in water. Appl. Opt. 51, 1407–1419.
//! - Kasten, F. & Young, A. T. (1989) Revised optical air mass tables and approximation formula.
//!   Appl. Opt. 28, 4735–4738.
//! - Vermote, E. F. et al. (1997) Second Simulation of the Satellite Signal in the Solar Spectrum,
//!   6S: an overview. IEEE TGRS 35, 675–686.

use std::sync::OnceLock;

use serde::{Deserialize, Serialize};

use super::AtmosphereError;
use crate::spectral::{Extrapolation, Spectrum};

const ASSET: &str = "atmosphere/atmosphere_gas_absorption_wasi6.csv";

/// Column amounts of the absorbing gases.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GasAmounts {
    /// Total ozone, atm-cm (0.3 atm-cm = 300 DU).
    pub ozone_atm_cm: f64,
    /// Precipitable water, cm.
    pub water_vapour_cm: f64,
}

impl Default for GasAmounts {
    fn default() -> Self {
        Self { ozone_atm_cm: 0.3, water_vapour_cm: 2.0 }
    }
}

struct Coefficients {
    a_oz: Spectrum,
    a_ox: Spectrum,
    a_wv: Spectrum,
}

fn coefficients() -> Result<&'static Coefficients, AtmosphereError> {
    static C: OnceLock<Result<Coefficients, AtmosphereError>> = OnceLock::new();
    C.get_or_init(|| {
        Ok(Coefficients {
            a_oz: Spectrum::from_asset(ASSET, "a_oz_per_cm")?,
            a_ox: Spectrum::from_asset(ASSET, "a_ox_per_cm")?,
            a_wv: Spectrum::from_asset(ASSET, "a_wv_per_cm")?,
        })
    })
    .as_ref()
    .map_err(Clone::clone)
}

/// Relative optical air mass for zenith angle θ (Kasten & Young 1989).
#[must_use]
pub fn air_mass(cos_zenith: f64) -> f64 {
    let theta_deg = cos_zenith.clamp(0.0, 1.0).acos().to_degrees();
    1.0 / (cos_zenith + 0.505_72 * (96.079_95 - theta_deg).powf(-1.6364))
}

/// Ozone's relative air mass for zenith cosine `mu`, M_oz = 1.0035/(μ² + 0.007)^½ (Paltridge &
/// Platt 1976, as in Gregg & Carder 1990).
fn ozone_air_mass(mu: f64) -> f64 {
    1.0035 / (mu * mu + 0.007).sqrt()
}

/// Gas transmittance along a path of relative air mass `m` (ozone's `m_oz`): the path's amounts
/// enter each band model whole, not as a product of legs.
fn along(wavelength_nm: f64, m: f64, m_oz: f64, gases: &GasAmounts, pressure_hpa: f64) -> Result<f64, AtmosphereError> {
    let mut t = [0.0];
    along_paths(wavelength_nm, &[AirMasses { m, m_oz }], gases, pressure_hpa, &mut t)?;
    Ok(t[0])
}

/// The relative air masses of one path: for the band models (Kasten & Young 1989) and for ozone
/// (Paltridge & Platt 1976). They depend on the geometry alone, so a spectrum computes them once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct AirMasses {
    m: f64,
    m_oz: f64,
}

impl AirMasses {
    /// The path down (or up) at zenith cosine `mu`.
    #[must_use]
    pub(super) fn one_way(mu: f64) -> Self {
        Self { m: air_mass(mu), m_oz: ozone_air_mass(mu) }
    }

    /// The sun–surface–sensor path: the legs' air masses summed ([`two_way_transmittance`]).
    #[must_use]
    pub(super) fn two_way(mu0: f64, muv: f64) -> Self {
        Self { m: air_mass(mu0) + air_mass(muv), m_oz: ozone_air_mass(mu0) + ozone_air_mass(muv) }
    }
}

/// The transmittance along each of `paths` at `wavelength_nm` into `out` (one per path): the
/// formulas of the module docs, the absorption coefficients looked up once for all the paths.
pub(super) fn along_paths(
    wavelength_nm: f64,
    paths: &[AirMasses],
    gases: &GasAmounts,
    pressure_hpa: f64,
    out: &mut [f64],
) -> Result<(), AtmosphereError> {
    if wavelength_nm > super::gas_swir::FROM_NM {
        for (t, p) in out.iter_mut().zip(paths) {
            *t = super::gas_swir::transmittance(
                wavelength_nm,
                gases.water_vapour_cm * p.m,
                p.m * pressure_hpa / 1013.25,
            )?;
        }
        return Ok(());
    }
    let c = coefficients()?;
    let a_oz = c.a_oz.value_at(wavelength_nm, Extrapolation::Error)?;
    let a_ox = c.a_ox.value_at(wavelength_nm, Extrapolation::Error)?;
    let a_wv = c.a_wv.value_at(wavelength_nm, Extrapolation::Error)?;
    for (t, &AirMasses { m, m_oz }) in out.iter_mut().zip(paths) {
        let m_p = m * pressure_hpa / 1013.25;
        let t_oz = (-a_oz * gases.ozone_atm_cm * m_oz).exp();
        let t_ox = (-1.41 * a_ox * m_p / (1.0 + 118.3 * a_ox * m_p).powf(0.45)).exp();
        let w = gases.water_vapour_cm;
        let t_wv = (-0.2385 * a_wv * w * m / (1.0 + 20.07 * a_wv * w * m).powf(0.45)).exp();
        *t = t_oz * t_ox * t_wv;
    }
    Ok(())
}

/// One-way gas transmittance at `wavelength_nm` along a path of zenith cosine `mu`.
pub fn transmittance(
    wavelength_nm: f64,
    mu: f64,
    gases: &GasAmounts,
    pressure_hpa: f64,
) -> Result<f64, AtmosphereError> {
    along(wavelength_nm, air_mass(mu), ozone_air_mass(mu), gases, pressure_hpa)
}

/// Sun–surface–sensor gas transmittance: the band models at the two legs' air masses summed,
/// T(m₀ + m_v). A band model's transmittance is not a product of its legs' (the lines that
/// absorb on the way down are the same lines on the way up, so the second leg takes less:
/// T(m₀ + m_v) > T(m₀)·T(m_v)), and 6S computes the two-way transmittance this way (Vermote et
/// al. 1997). In the saturated 2.2 µm CH₄ and H₂O bands the product is up to 8 % too low.
pub fn two_way_transmittance(
    wavelength_nm: f64,
    mu0: f64,
    muv: f64,
    gases: &GasAmounts,
    pressure_hpa: f64,
) -> Result<f64, AtmosphereError> {
    along(wavelength_nm, air_mass(mu0) + air_mass(muv), ozone_air_mass(mu0) + ozone_air_mass(muv), gases, pressure_hpa)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oxygen_a_band_absorbs_and_the_blue_does_not() {
        let g = GasAmounts::default();
        let t_760 = transmittance(761.0, 1.0, &g, 1013.25).unwrap();
        let t_560 = transmittance(560.0, 1.0, &g, 1013.25).unwrap();
        let t_443 = transmittance(443.0, 1.0, &g, 1013.25).unwrap();
        assert!(t_760 < 0.6, "O2 A band: {t_760}");
        assert!(t_560 > 0.95 && t_560 < 0.99, "Chappuis ozone at 560 nm: {t_560}");
        assert!(t_443 > 0.99, "{t_443}");
        assert!((air_mass(1.0) - 1.0).abs() < 1e-3);
    }
}
