//! The basic aerosol models as 6SV builds them: its own component tables
//! (`assets/atmosphere/aerosol_6sv_components.csv`, copied from 6SV 1.0B's DUST.f, WATE.f,
//! OCEA.f and SOOT.f) mixed by its rule (AEROSO.f; Vermote et al. 1997, Kotchenova et al. 2006).
//!
//! 6SV's four components are the WMO ones with the size distributions and refractive indices of
//! d'Almeida, Koepke & Shettle (1991), not WCP-55's, which OSOAA and [`super::aerosol`] use: its
//! continental model puts 0.012 % of its particles in the dust-like mode and 51 % in soot, where
//! WCP-55's has 2.3·10⁻⁴ % and 6 %, so that its extinction keeps 22 % of its 550 nm value at
//! 2250 nm, WCP-55's 15 %. With the models computed from these tables, Shoal's aerosol is 6SV's
//! (its extinction, single-scattering albedo and phase function), so that a comparison with 6SV or
//! with a processor whose tables come from 6SV (ACOLITE's dark-spectrum fitting) is a comparison
//! of the radiative transfer alone.
//!
//! The mixture of volume fractions cᵢ: c_ij = (cᵢ/vᵢ)/Σⱼ(cⱼ/vⱼ) with 6SV's volume per particle
//! vᵢ, K_ext = Σ c_ij ext_i, K_sca = Σ c_ij sca_i, P = Σ c_ij sca_i P_i / K_sca (AEROSO.f);
//! between 6SV's 20 wavelengths the coefficients are interpolated log–log in λ and the phase
//! function linearly, as [`super::aerosol`] does with its own table. The phase functions are
//! tabulated at 6SV's 83 quadrature cosines (−1, the 80-point Gauss–Legendre nodes, 0 and 1).

use std::sync::OnceLock;

use super::AtmosphereError;
use super::aerosol::{AerosolOptics, ComponentOptics, mix};
use super::wmo::Component;
use crate::spectral::Table;

/// Path of the 6SV component table below `assets/`.
pub const SIXS_ASSET: &str = "atmosphere/aerosol_6sv_components.csv";

/// 6SV's wavelengths, nm (its `wldis`).
pub const SIXS_WAVELENGTHS_NM: [f64; 20] = [
    350.0, 400.0, 412.0, 443.0, 470.0, 488.0, 515.0, 550.0, 590.0, 633.0, 670.0, 694.0, 760.0, 860.0, 1240.0, 1536.0,
    1650.0, 1950.0, 2250.0, 3750.0,
];

/// The shortest wavelength the models are given at, nm: below 6SV's first (350 nm) the first
/// interval's power law is extended, as 6SV's INTERP.f extends its end intervals; Shoal
/// simulates from 325 nm ([`crate::ranges::MIN_SIMULATED_NM`]).
pub const SIXS_MIN_NM: f64 = 325.0;

/// 6SV's volume per particle of each component (`vi_m` of DUST.f, WATE.f, OCEA.f, SOOT.f): the
/// mixing weight cᵢ/vᵢ. The table carries the same values (a test checks them).
#[must_use]
pub fn sixs_volume(c: Component) -> f64 {
    match c {
        Component::DustLike => 18.285_989_8,
        Component::WaterSoluble => 0.001_827_373_05,
        Component::Oceanic => 4.998_090_27,
        Component::Soot => 6.056_304_12e-5,
    }
}

/// Points of 6SV's phase-function quadrature (`nqdef_p`).
const ANGLES: usize = 83;

/// The parsed table: per component, its rows at [`SIXS_WAVELENGTHS_NM`] and 6SV's volume per
/// particle vᵢ. A row's "cross-sections" are 6SV's extinction and scattering coefficients:
/// proportional to the component's per-particle cross-sections by one factor for all four, the
/// only thing a mixture's ratios read.
#[derive(Debug)]
pub struct SixsTable {
    angles_deg: Vec<f64>,
    components: Vec<(Component, Vec<ComponentOptics>, f64)>,
}

/// 6SV's quadrature angles, degrees, rising from 0 to 180 (the table's `p_83` down to `p_1`).
fn angles_deg() -> Vec<f64> {
    let (x, _) = super::quadrature::gauss_legendre(ANGLES - 3);
    let half = x.len() / 2;
    let mut mu = vec![-1.0];
    mu.extend_from_slice(&x[..half]);
    mu.push(0.0);
    mu.extend_from_slice(&x[half..]);
    mu.push(1.0);
    mu.iter().rev().map(|m: &f64| m.clamp(-1.0, 1.0).acos().to_degrees()).collect()
}

impl SixsTable {
    /// The embedded table, parsed once.
    pub fn embedded() -> Result<&'static Self, AtmosphereError> {
        static TABLE: OnceLock<Result<SixsTable, AtmosphereError>> = OnceLock::new();
        TABLE.get_or_init(|| Self::parse(&Table::from_asset(SIXS_ASSET)?)).as_ref().map_err(Clone::clone)
    }

    fn parse(t: &Table) -> Result<Self, AtmosphereError> {
        let keys = t.column_str("component")?;
        let (wl, ext, sca, vi) =
            (t.column_f64("wavelength_nm")?, t.column_f64("ext")?, t.column_f64("sca")?, t.column_f64("vi")?);
        let p: Vec<Vec<f64>> = (1..=ANGLES).map(|k| t.column_f64(&format!("p_{k}"))).collect::<Result<_, _>>()?;
        let mut components = Vec::new();
        for c in Component::ALL {
            let mut rows = Vec::new();
            let mut volume = f64::NAN;
            for w in SIXS_WAVELENGTHS_NM {
                let i = (0..t.len())
                    .find(|&i| keys[i] == c.key() && (wl[i] - w).abs() < 1e-9)
                    .ok_or_else(|| AtmosphereError::Data(format!("{SIXS_ASSET}: no row for {} at {w} nm", c.key())))?;
                volume = vi[i];
                // The file runs from μ = −1 (180°) to μ = 1 (0°); the rows rise in angle.
                rows.push(ComponentOptics {
                    c_ext_um2: ext[i],
                    c_sca_um2: sca[i],
                    p11: p.iter().rev().map(|col| col[i]).collect(),
                });
            }
            components.push((c, rows, volume));
        }
        Ok(Self { angles_deg: angles_deg(), components })
    }

    /// 6SV's volume per particle of `c` (its mixing weight cᵢ/vᵢ).
    #[must_use]
    pub fn volume(&self, c: Component) -> f64 {
        self.components.iter().find(|(k, ..)| *k == c).map_or(f64::NAN, |(_, _, v)| *v)
    }

    /// The optics of the mixture of `number_fractions` (c_ij, [`crate::atmosphere::AerosolType::number_fractions`])
    /// at `wavelength_nm` ([`SIXS_MIN_NM`]–3750 nm), by 6SV's rule (see the module docs).
    pub fn mixture(
        &self,
        number_fractions: &[(Component, f64)],
        wavelength_nm: f64,
    ) -> Result<AerosolOptics, AtmosphereError> {
        let (lo, hi) = (SIXS_MIN_NM, SIXS_WAVELENGTHS_NM[SIXS_WAVELENGTHS_NM.len() - 1]);
        if !(lo..=hi).contains(&wavelength_nm) {
            return Err(AtmosphereError::OutOfRange {
                field: "wavelength_nm (6SV aerosol)".into(),
                value: wavelength_nm,
                allowed: format!("{lo} to {hi} nm"),
            });
        }
        let parts: Vec<(&[ComponentOptics], f64)> = number_fractions
            .iter()
            .filter_map(|(c, n)| {
                self.components.iter().find(|(k, ..)| k == c).map(|(_, rows, _)| (rows.as_slice(), *n))
            })
            .collect();
        mix(&parts, &SIXS_WAVELENGTHS_NM, &self.angles_deg, wavelength_nm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_angles_are_6svs_quadrature_and_the_table_reads() {
        let a = angles_deg();
        assert_eq!(a.len(), 83);
        assert_eq!((a[0], a[41], a[82]), (0.0, 90.0, 180.0));
        // The 80-point rule's node nearest the forward direction: 1.7116°.
        assert!((a[1] - 1.7116207).abs() < 1e-6, "{}", a[1]);
        let t = SixsTable::embedded().unwrap();
        // DUST.f's vi_m and its 550 nm coefficients; the constants are the table's.
        for c in Component::ALL {
            assert_eq!(t.volume(c), sixs_volume(c), "{c:?}");
        }
        let dust = &t.components[0].1[7];
        assert_eq!((dust.c_ext_um2, dust.c_sca_um2), (8.519962, 6.215003));
        // P(180°) of the water-soluble component at 350 nm (WATE.f's first entry).
        assert_eq!(t.components[1].1[0].p11[82], 0.4078);
    }
}

#[cfg(test)]
mod range_tests {
    use super::*;
    use crate::atmosphere::AerosolType;

    #[test]
    fn between_and_beyond_6svs_wavelengths() {
        let t = SixsTable::embedded().unwrap();
        let n = AerosolType::Continental6sv.number_fractions();
        let at = |w: f64| t.mixture(&n, w).unwrap();
        // At its own wavelengths the ratio is 6SV's (aerosol_6sv_models.csv: 1.4977 at 350 nm,
        // 0.2172 at 2250 nm); between 1240 and 1536 nm it lies between them.
        assert!((at(350.0).extinction_ratio - 1.4977).abs() < 1e-4);
        assert!((at(2250.0).extinction_ratio - 0.2172).abs() < 1e-4);
        let mid = at(1400.0).extinction_ratio;
        assert!(mid < at(1240.0).extinction_ratio && mid > at(1536.0).extinction_ratio, "{mid}");
        // Below 350 nm the first interval's power law goes on (continental: Ångström 0.79 between 350 and 400 nm).
        let below = at(325.0).extinction_ratio;
        let alpha = (1.4977_f64 / 1.3479).ln() / (400.0_f64 / 350.0).ln();
        assert!((below / (1.4977 * (325.0_f64 / 350.0).powf(-alpha)) - 1.0).abs() < 1e-3, "{below}");
        assert!((0.0..1.0).contains(&at(325.0).ssa));
        // Outside: an error naming the field and the range, never a NaN.
        for w in [300.0, 4000.0, f64::NAN] {
            let e = t.mixture(&n, w).unwrap_err().to_string();
            assert!(e.contains("6SV aerosol") && e.contains("325 to 3750"), "{e}");
        }
    }
}
