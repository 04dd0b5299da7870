//! The WMO (1983) basic aerosol components and their mixtures, with the parameters OSOAA V2.0
//! uses (file `fic/Data_WMO_cor_2015_12_16`, routines `SOS_INIT_PARAMWMO` and
//! `OSOAA_AEROSOLS.F`), so that Shoal's aerosol optics match the reference code.
//!
//! | component | r_m (µm) | σ_g | V (µm³) | α_max |
//! |---|---|---|---|---|
//! | dust-like (DL) | 0.5 | 2.99 | 113.98352 | 4000 |
//! | water-soluble (WS) | 0.005 | 2.99 | 113.98352·10⁻⁶ | 50 |
//! | oceanic (OC) | 0.3 | 2.51 | 5.14441 | 800 |
//! | soot (SO) | 0.0118 | 2.00 | 59.77755·10⁻⁶ | 10 |
//!
//! Mixtures are volume fractions C (continental 0.70 DL + 0.29 WS + 0.01 SO; maritime 0.05 WS +
//! 0.95 OC; urban 0.17 DL + 0.61 WS + 0.22 SO), turned into number fractions Nᵢ = Cᵢ/Vᵢ.
//!
//! ## References
//! - WMO (1983) Radiation Commission of IAMAP meeting of experts on aerosols and their climatic
//!   effects, WCP-55 (Deepak & Gerber, eds.).
//! - d'Almeida, G. A., Koepke, P., Shettle, E. P. (1991) Atmospheric Aerosols: Global
//!   Climatology and Radiative Characteristics, Deepak.
//! - Chami, M., Lafrance, B., Fougnie, B., Chowdhary, J., Harmel, T., Waquet, F. (2015) OSOAA: a
//!   vector radiative transfer model of coupled atmosphere-ocean system for a rough sea surface
//!   application to the estimates of the directional variations of the water leaving
//!   reflectance to better process multi-angular satellite sensors data over the ocean.
//!   Opt. Express 23, 27829–27852.

use super::Complex;
use super::mie::LogNormal;
use super::user_aerosol::{AerosolMode, SizeDistribution};

/// A WMO basic component.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Component {
    /// Dust-like.
    DustLike,
    /// Water-soluble.
    WaterSoluble,
    /// Oceanic (sea salt).
    Oceanic,
    /// Soot.
    Soot,
}

impl Component {
    /// All components, in table order.
    pub const ALL: [Self; 4] = [Self::DustLike, Self::WaterSoluble, Self::Oceanic, Self::Soot];

    /// Short name used in the table file.
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::DustLike => "dust_like",
            Self::WaterSoluble => "water_soluble",
            Self::Oceanic => "oceanic",
            Self::Soot => "soot",
        }
    }

    /// Size distribution (OSOAA `Data_WMO`: r_m, log₁₀σ_g; α_max from `OSOAA.h`).
    #[must_use]
    pub fn distribution(self) -> LogNormal {
        let ln10 = std::f64::consts::LN_10;
        let (mode_radius_um, log10_sigma, alpha_max) = match self {
            Self::DustLike => (0.5, 0.47567, 4000.0),
            Self::WaterSoluble => (0.005, 0.47567, 50.0),
            Self::Oceanic => (0.3, 0.39967, 800.0),
            // log₁₀ σ_g for σ_g = 2.00, as OSOAA's data file writes it (not the constant log₁₀ 2).
            #[allow(clippy::approx_constant)]
            Self::Soot => (0.0118, 0.30103, 10.0),
        };
        LogNormal { mode_radius_um, ln_sigma: log10_sigma * ln10, alpha_max }
    }

    /// Volume per particle V (µm³) as OSOAA uses it to turn volume into number fractions.
    #[must_use]
    pub fn volume_um3(self) -> f64 {
        match self {
            Self::DustLike => 113.983_52,
            Self::WaterSoluble => 113.983_52e-6,
            Self::Oceanic => 5.144_41,
            Self::Soot => 59.777_55e-6,
        }
    }

    /// Refractive index n + i·k at `wavelength_um`: OSOAA's table (WMO 1983 values, 0.2–2.5 µm
    /// here), linearly interpolated in λ, then rounded to 3 decimals (real) and 5 decimals
    /// (imaginary) as OSOAA does.
    #[must_use]
    pub fn refractive_index(self, wavelength_um: f64) -> Complex {
        let table: &[(f64, f64, f64)] = match self {
            Self::DustLike => &[
                (0.20, 1.53, 0.07),
                (0.25, 1.53, 0.03),
                (0.30, 1.53, 0.008),
                (0.337, 1.53, 0.008),
                (0.40, 1.53, 0.008),
                (0.488, 1.53, 0.008),
                (0.515, 1.53, 0.008),
                (0.55, 1.53, 0.008),
                (0.633, 1.53, 0.008),
                (0.694, 1.53, 0.008),
                (0.86, 1.52, 0.008),
                (1.06, 1.52, 0.008),
                (1.3, 1.46, 0.008),
                (1.536, 1.4, 0.008),
                (1.8, 1.33, 0.008),
                (2.0, 1.26, 0.008),
                (2.25, 1.22, 0.009),
                (2.5, 1.18, 0.009),
            ],
            Self::WaterSoluble => &[
                (0.20, 1.53, 0.07),
                (0.25, 1.53, 0.03),
                (0.30, 1.53, 0.003),
                (0.337, 1.53, 0.005),
                (0.40, 1.53, 0.005),
                (0.488, 1.53, 0.005),
                (0.515, 1.53, 0.005),
                (0.55, 1.53, 0.006),
                (0.633, 1.53, 0.006),
                (0.694, 1.53, 0.007),
                (0.86, 1.52, 0.012),
                (1.06, 1.52, 0.017),
                (1.3, 1.51, 0.02),
                (1.536, 1.51, 0.023),
                (1.8, 1.46, 0.017),
                (2.0, 1.42, 0.008),
                (2.25, 1.42, 0.01),
                (2.5, 1.42, 0.012),
            ],
            Self::Oceanic => &[
                (0.20, 1.429, 0.000_03),
                (0.25, 1.404, 0.0),
                (0.30, 1.395, 0.0),
                (0.337, 1.392, 0.0),
                (0.40, 1.385, 0.0),
                (0.488, 1.382, 0.0),
                (0.515, 1.381, 0.0),
                (0.55, 1.381, 0.0),
                (0.633, 1.377, 0.0),
                (0.694, 1.376, 0.0),
                (0.86, 1.372, 0.0),
                (1.06, 1.367, 0.000_06),
                (1.3, 1.365, 0.000_14),
                (1.536, 1.359, 0.000_24),
                (1.8, 1.351, 0.000_31),
                (2.0, 1.347, 0.001_07),
                (2.25, 1.334, 0.000_85),
                (2.5, 1.309, 0.002_39),
            ],
            Self::Soot => &[
                (0.20, 1.50, 0.35),
                (0.25, 1.62, 0.45),
                (0.30, 1.74, 0.47),
                (0.337, 1.75, 0.47),
                (0.40, 1.75, 0.46),
                (0.488, 1.75, 0.45),
                (0.515, 1.75, 0.45),
                (0.55, 1.75, 0.44),
                (0.633, 1.75, 0.43),
                (0.694, 1.75, 0.43),
                (0.86, 1.75, 0.43),
                (1.06, 1.75, 0.44),
                (1.3, 1.76, 0.45),
                (1.536, 1.77, 0.46),
                (1.8, 1.79, 0.48),
                (2.0, 1.8, 0.49),
                (2.25, 1.81, 0.5),
                (2.5, 1.82, 0.51),
            ],
        };
        let w = wavelength_um.clamp(table[0].0, table[table.len() - 1].0);
        let j = table.partition_point(|t| t.0 <= w).clamp(1, table.len() - 1);
        let (a, b) = (table[j - 1], table[j]);
        let t = (w - a.0) / (b.0 - a.0);
        let re = a.1 + t * (b.1 - a.1);
        let im = a.2 + t * (b.2 - a.2);
        Complex::new((re * 1e3).round() / 1e3, (im * 1e5).round() / 1e5)
    }
}

/// The aerosol mixtures Shoal offers (WMO models as in OSOAA and 6S).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum AerosolType {
    /// No aerosol (Rayleigh atmosphere).
    None,
    /// WMO maritime: 0.05 water-soluble + 0.95 oceanic by volume.
    Maritime,
    /// WMO continental: 0.70 dust-like + 0.29 water-soluble + 0.01 soot by volume.
    Continental,
    /// WMO urban: 0.17 dust-like + 0.61 water-soluble + 0.22 soot by volume.
    Urban,
    /// A user's mixture of the four WMO components by volume (OSOAA's user-defined WMO model,
    /// `-AER.WMO.Model 4`; 6S's "user defined" basic components): an aerosol outside the
    /// correction's family.
    Mixture(WmoFractions),
    /// A user's own size distribution: one or two log-normal modes with their refractive
    /// indices ([`super::user_aerosol`]).
    LogNormal(SizeDistribution),
    /// 6SV's maritime model: the same volume fractions as [`Self::Maritime`] of 6SV's own
    /// components (d'Almeida et al. 1991 size distributions; [`super::aerosol_6sv`]).
    Maritime6sv,
    /// 6SV's continental model: [`Self::Continental`]'s volume fractions of 6SV's components;
    /// its extinction keeps 22 % of its 550 nm value at 2250 nm where WCP-55's keeps 15 %.
    Continental6sv,
    /// 6SV's urban model: [`Self::Urban`]'s volume fractions of 6SV's components.
    Urban6sv,
}

/// Volume fractions of the WMO components; they are normalised by their sum.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WmoFractions {
    /// Dust-like.
    pub dust_like: f64,
    /// Water-soluble.
    pub water_soluble: f64,
    /// Oceanic.
    pub oceanic: f64,
    /// Soot.
    pub soot: f64,
}

impl Default for WmoFractions {
    /// WMO continental's fractions.
    fn default() -> Self {
        Self { dust_like: 0.70, water_soluble: 0.29, oceanic: 0.0, soot: 0.01 }
    }
}

impl WmoFractions {
    /// The fractions with their field names, in the order of [`Component`]s.
    #[must_use]
    pub fn named(&self) -> [(&'static str, Component, f64); 4] {
        [
            ("dust_like", Component::DustLike, self.dust_like),
            ("water_soluble", Component::WaterSoluble, self.water_soluble),
            ("oceanic", Component::Oceanic, self.oceanic),
            ("soot", Component::Soot, self.soot),
        ]
    }
}

impl AerosolType {
    /// Parse `none|maritime|continental|urban|maritime-6sv|continental-6sv|urban-6sv|mixture:DL,WS,OC,SO` (volume fractions of
    /// dust-like, water-soluble, oceanic and soot) or `lognormal:R,SG,N,K` (one mode: modal
    /// radius µm, geometric standard deviation, refractive index) with, for two modes,
    /// `,R,SG,N,K,F` for the coarse mode and its volume fraction.
    pub fn parse(text: &str) -> Result<Self, String> {
        let text = text.trim().to_ascii_lowercase();
        if let Some(list) = text.strip_prefix("lognormal:") {
            let usage = "lognormal:R,SG,N,K (modal radius um, geometric sd, refractive index real, imaginary), then R,SG,N,K,F for a coarse mode and its volume fraction";
            let v: Vec<f64> = list
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|e| format!("lognormal:{list}: {e} ({usage})"))?;
            let mode = |m: &[f64]| AerosolMode {
                mode_radius_um: m[0],
                sigma_g: m[1],
                refractive_real: m[2],
                refractive_imag: m[3],
            };
            return match v.len() {
                4 => {
                    Ok(Self::LogNormal(SizeDistribution { fine: mode(&v), coarse: None, coarse_volume_fraction: 0.0 }))
                }
                9 => Ok(Self::LogNormal(SizeDistribution {
                    fine: mode(&v[..4]),
                    coarse: Some(mode(&v[4..8])),
                    coarse_volume_fraction: v[8],
                })),
                n => Err(format!("lognormal:{list}: {n} numbers ({usage})")),
            };
        }
        if let Some(list) = text.strip_prefix("mixture:") {
            let v: Vec<f64> =
                list.split(',').map(|x| x.trim().parse::<f64>()).collect::<Result<_, _>>().map_err(|e| {
                    format!("mixture:{list}: {e} (four volume fractions: dust-like, water-soluble, oceanic, soot)")
                })?;
            let [dust_like, water_soluble, oceanic, soot] = v[..] else {
                return Err(format!("mixture:{list}: four volume fractions (dust-like, water-soluble, oceanic, soot)"));
            };
            return Ok(Self::Mixture(WmoFractions { dust_like, water_soluble, oceanic, soot }));
        }
        match text.as_str() {
            "none" => Ok(Self::None),
            "maritime" => Ok(Self::Maritime),
            "continental" => Ok(Self::Continental),
            "urban" => Ok(Self::Urban),
            "maritime-6sv" => Ok(Self::Maritime6sv),
            "continental-6sv" => Ok(Self::Continental6sv),
            "urban-6sv" => Ok(Self::Urban6sv),
            other => Err(format!(
                "unknown aerosol model `{other}` (allowed: none, maritime, continental, urban, maritime-6sv, continental-6sv, urban-6sv, mixture:DL,WS,OC,SO, lognormal:R,SG,N,K[,R,SG,N,K,F])"
            )),
        }
    }

    /// A short name (`continental`, `mixture 0.50/0.30/0.20/0.00`).
    #[must_use]
    pub fn name(&self) -> String {
        match self {
            Self::Mixture(f) => {
                format!("mixture {:.2}/{:.2}/{:.2}/{:.2}", f.dust_like, f.water_soluble, f.oceanic, f.soot)
            }
            Self::LogNormal(d) => {
                let mode = |m: &AerosolMode| format!("{} um x{}", m.mode_radius_um, m.sigma_g);
                match d.coarse {
                    Some(c) => format!(
                        "log-normal {} + {} ({:.0} % coarse)",
                        mode(&d.fine),
                        mode(&c),
                        100.0 * d.coarse_volume_fraction
                    ),
                    None => format!("log-normal {}", mode(&d.fine)),
                }
            }
            Self::Maritime6sv => "maritime-6sv".into(),
            Self::Continental6sv => "continental-6sv".into(),
            Self::Urban6sv => "urban-6sv".into(),
            other => format!("{other:?}").to_lowercase(),
        }
    }

    /// 6SV's model of the same volume fractions, for the three basic models (`None` otherwise):
    /// what [`super::aerosol_6sv`] mixes.
    #[must_use]
    pub fn sixs(self) -> Option<Self> {
        match self {
            Self::Maritime6sv => Some(Self::Maritime),
            Self::Continental6sv => Some(Self::Continental),
            Self::Urban6sv => Some(Self::Urban),
            _ => None,
        }
    }

    /// Volume fractions of the WMO components (OSOAA_AEROSOLS.F), summing to 1 (none for a
    /// user's size distribution); a 6SV model's are its WMO namesake's (6SV's AEROSO.f).
    #[must_use]
    pub fn volume_fractions(self) -> Vec<(Component, f64)> {
        match self {
            Self::None | Self::LogNormal(_) => vec![],
            Self::Maritime | Self::Maritime6sv => vec![(Component::WaterSoluble, 0.05), (Component::Oceanic, 0.95)],
            Self::Continental | Self::Continental6sv => {
                vec![(Component::DustLike, 0.70), (Component::WaterSoluble, 0.29), (Component::Soot, 0.01)]
            }
            Self::Urban | Self::Urban6sv => {
                vec![(Component::DustLike, 0.17), (Component::WaterSoluble, 0.61), (Component::Soot, 0.22)]
            }
            Self::Mixture(f) => {
                let named = f.named();
                let total: f64 = named.iter().map(|n| n.2).sum();
                named.iter().filter(|n| n.2 > 0.0).map(|n| (n.1, n.2 / total)).collect()
            }
        }
    }

    /// Number fractions Nᵢ = (Cᵢ/Vᵢ)/Σⱼ(Cⱼ/Vⱼ), with WCP-55's volumes per particle Vᵢ or, for
    /// a 6SV model, 6SV's ([`super::aerosol_6sv::sixs_volume`]).
    #[must_use]
    pub fn number_fractions(self) -> Vec<(Component, f64)> {
        let volume =
            |c: Component| if self.sixs().is_some() { super::aerosol_6sv::sixs_volume(c) } else { c.volume_um3() };
        let v = self.volume_fractions();
        let total: f64 = v.iter().map(|(c, f)| f / volume(*c)).sum();
        v.iter().map(|(c, f)| (*c, f / volume(*c) / total)).collect()
    }
}
