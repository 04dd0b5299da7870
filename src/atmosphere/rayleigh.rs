//! Rayleigh optical depth of the molecular atmosphere.
//!
//! Shoal's default is Bodhaine et al. (1999), the full calculation (their eqs. 4–29): Peck &
//! Reeder (1972) refractive index of air with a CO₂ correction, Bates (1984) King factors,
//! σ = 24π³(n²−1)²/(λ⁴Nₛ²(n²+2)²)·F_air and τ_R = σ·P·A/(m_a·g). For comparisons with OSOAA,
//! which uses a Hansen–Travis-type fit, [`RayleighDepth::OsoaaHansenTravis`] reproduces that
//! code's τ_R (1.5–3 % below Bodhaine's).
//!
//! ## References
//! - Bodhaine, B. A., Wood, N. B., Dutton, E. G., Slusser, J. R. (1999) On Rayleigh optical depth
//!   calculations. J. Atmos. Oceanic Technol. 16, 1854–1861.
//! - Peck, E. R. & Reeder, K. (1972) Dispersion of air. J. Opt. Soc. Am. 62, 958–962.
//! - Bates, D. R. (1984) Rayleigh scattering by air. Planet. Space Sci. 32, 785–790.
//! - Hansen, J. E. & Travis, L. D. (1974) Space Sci. Rev. 16, 527–610; OSOAA V2.0
//!   `OSOAA_PROFILE.F`: τ_R = (P/1013)·10⁻⁴(84.35λ⁻⁴ − 1.225λ⁻⁵ + 1.4λ⁻⁶), λ in µm.
//! - Young, A. T. (1980) Revised depolarization corrections for atmospheric extinction.
//!   Appl. Opt. 19, 3427–3428 (ρ = 0.0279).

use serde::{Deserialize, Serialize};

/// Depolarisation ratio of air used in the phase function (Young 1980; OSOAA's CTE_MDF_AIR).
pub const AIR_DEPOLARIZATION: f64 = 0.0279;
/// Standard sea-level pressure, hPa.
pub const STANDARD_PRESSURE_HPA: f64 = 1013.25;

/// Which formula gives the Rayleigh optical depth.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum RayleighDepth {
    /// Bodhaine et al. (1999) full calculation (Shoal's default).
    #[default]
    Bodhaine,
    /// OSOAA V2.0's fit, for like-for-like comparison with that code.
    OsoaaHansenTravis,
}

/// Site parameters of the Rayleigh column.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RayleighColumn {
    /// Surface pressure, hPa.
    pub pressure_hpa: f64,
    /// Latitude, degrees (gravity).
    pub latitude_deg: f64,
    /// Surface altitude, m.
    pub altitude_m: f64,
    /// CO₂ volume mixing ratio, ppm.
    pub co2_ppm: f64,
}

impl Default for RayleighColumn {
    fn default() -> Self {
        Self { pressure_hpa: STANDARD_PRESSURE_HPA, latitude_deg: 45.0, altitude_m: 0.0, co2_ppm: 360.0 }
    }
}

impl RayleighDepth {
    /// τ_R at `wavelength_nm` for `column`.
    ///
    /// ```
    /// use shoal::atmosphere::{RayleighColumn, RayleighDepth};
    /// // Bodhaine et al. (1999) check value: τ_R(550 nm) = 0.09707 at sea level, 45°, 360 ppm.
    /// let t = RayleighDepth::Bodhaine.tau(550.0, &RayleighColumn::default());
    /// assert!((t - 0.09707).abs() < 5e-5);
    /// ```
    #[must_use]
    pub fn tau(self, wavelength_nm: f64, column: &RayleighColumn) -> f64 {
        match self {
            Self::Bodhaine => bodhaine_tau(wavelength_nm, column),
            Self::OsoaaHansenTravis => {
                let l = wavelength_nm * 1e-3;
                column.pressure_hpa / 1013.0 * 1e-4 * (84.35 / l.powi(4) - 1.225 / l.powi(5) + 1.4 / l.powi(6))
            }
        }
    }
}

/// Bodhaine et al. (1999) full formula (eqs. 4–29): τ_R = σ P A/(m_a g).
#[must_use]
pub fn bodhaine_tau(wavelength_nm: f64, c: &RayleighColumn) -> f64 {
    let l_um = wavelength_nm * 1e-3;
    let l2 = 1.0 / (l_um * l_um); // λ⁻², µm⁻²
    let co2 = c.co2_ppm * 1e-6;
    // Peck & Reeder (1972) at 300 ppm CO₂, then the CO₂ correction (Bodhaine eqs. 17–19).
    let n300 = 1.0 + 1e-8 * (8060.51 + 2_480_990.0 / (132.274 - l2) + 17_455.7 / (39.329_57 - l2));
    let n = 1.0 + (n300 - 1.0) * (1.0 + 0.54 * (co2 - 0.0003));
    // King factors (Bates 1984; Bodhaine eqs. 5, 6, 23).
    let f_n2 = 1.034 + 3.17e-4 * l2;
    let f_o2 = 1.096 + 1.385e-3 * l2 + 1.448e-4 * l2 * l2;
    let co2_pct = c.co2_ppm * 1e-4;
    let f_air = (78.084 * f_n2 + 20.946 * f_o2 + 0.934 + co2_pct * 1.15) / (78.084 + 20.946 + 0.934 + co2_pct);
    // Cross-section per molecule, cm² (λ in cm, Ns = 2.546899e19 cm⁻³).
    let l_cm = wavelength_nm * 1e-7;
    let ns = 2.546_899e19;
    let n2 = n * n;
    let sigma = 24.0 * std::f64::consts::PI.powi(3) * (n2 - 1.0).powi(2)
        / (l_cm.powi(4) * ns * ns * (n2 + 2.0).powi(2))
        * f_air;
    // Mean molecular weight (eq. 20) and gravity (List 1968, eqs. 10–11).
    let m_a = 15.0556 * co2 + 28.9595;
    let cos2phi = (2.0 * c.latitude_deg.to_radians()).cos();
    let g0 = 980.6160 * (1.0 - 0.002_637_3 * cos2phi + 0.000_005_9 * cos2phi * cos2phi);
    let zc = 0.737_37 * c.altitude_m + 5517.56;
    let g = g0 - (3.085_462e-4 + 2.27e-7 * cos2phi) * zc + (7.254e-11 + 1e-13 * cos2phi) * zc * zc
        - (1.517e-17 + 6e-20 * cos2phi) * zc.powi(3);
    let pressure_dyn_cm2 = c.pressure_hpa * 1000.0;
    sigma * pressure_dyn_cm2 * 6.022_136_7e23 / (m_a * g)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::Table;

    #[test]
    fn bodhaine_matches_the_tabulated_full_formula() {
        // assets/atmosphere/rayleigh_optical_depth_bodhaine1999.csv: an independent evaluation of
        // the same full formula; agreement to 1e-5 relative (its values carry 6 digits).
        let t = Table::from_asset("atmosphere/rayleigh_optical_depth_bodhaine1999.csv").unwrap();
        let wl = t.column_f64("wavelength_nm").unwrap();
        let full = t.column_f64("tau_r_full").unwrap();
        for (w, f) in wl.iter().zip(&full) {
            let ours = bodhaine_tau(*w, &RayleighColumn::default());
            assert!((ours / f - 1.0).abs() < 1e-5, "{w} nm: {ours} vs {f}");
        }
        // Paper check values at 443 and 865 nm.
        let c = RayleighColumn::default();
        assert!((bodhaine_tau(443.0, &c) - 0.2359).abs() < 1e-4);
        assert!((bodhaine_tau(865.0, &c) - 0.01549).abs() < 1e-5);
    }

    #[test]
    fn osoaa_fit_reproduces_the_reference_depths() {
        // tau_ray_osoaa column of tests/data/osoaa/path_compare.csv at 1013.25 hPa.
        let c = RayleighColumn::default();
        for (w, t) in [(400.0, 0.351_796), (560.5, 0.087_786), (865.4, 0.015_124)] {
            let ours = RayleighDepth::OsoaaHansenTravis.tau(w, &c);
            assert!((ours - t).abs() < 1e-6, "{w}: {ours} vs {t}");
        }
    }
}
