//! The atmosphere as a scene describes it (RON), validated into an [`Atmosphere`] that answers
//! every term of the TOA signal at a wavelength and geometry.
//!
//! TOA radiance over water (Vermote et al. 1997; Gordon & Wang 1994):
//! L_TOA = L_path + T_up·Lw/(1 − S·ρ_w) (+ glint when the scene asks for it), with
//! Lw = Rrs·Ed(0⁺), ρ_w ≈ π·Rrs, and gases multiplying the sun–surface–sensor paths.

use serde::{Deserialize, Serialize};

use super::aerosol::mixture_optics;
use super::check;
use super::fresnel::SEA_REFRACTIVE_INDEX;
use super::gas::{AirMasses, GasAmounts, along_paths, transmittance as gas_transmittance, two_way_transmittance};
use super::glint::glint_radiance_norm;
use super::rayleigh::{AIR_DEPOLARIZATION, RayleighColumn, RayleighDepth, STANDARD_PRESSURE_HPA};
use super::rt::{RtAccuracy, WavelengthColumn, solve_sun, solve_transmittance};
use super::wmo::AerosolType;
use super::{AtmosphereError, solar};
use crate::spectral::{Extrapolation, Spectrum};

/// Gas factors along one geometry, one per wavelength ([`Atmosphere::gas_legs`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GasLegs {
    /// The sun's leg, T(m₀).
    pub down: Vec<f64>,
    /// The upward factor T(m₀ + m_v)/T(m₀), at most 1.
    pub up_after_down: Vec<f64>,
    /// The wavelengths, nm.
    pub wavelengths_nm: Vec<f64>,
    /// The geometry's cos θ₀.
    pub mu0: f64,
    /// The geometry's cos θ_v.
    pub muv: f64,
    /// The atmosphere's [`Atmosphere::gas_key`].
    pub key: Option<(GasAmounts, f64)>,
}

/// The sea surface.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub enum SeaSurface {
    /// A flat Fresnel interface (no glint).
    #[default]
    Flat,
    /// Wind-roughened: the sky is still reflected by the flat Fresnel interface, and Cox–Munk
    /// sun glint is added as a separate term.
    Wind {
        /// Wind speed at 10 m, m s⁻¹ (0–30).
        speed_m_s: f64,
    },
}

impl SeaSurface {
    /// Parse `flat` or `wind:5`.
    pub fn parse(text: &str) -> Result<Self, AtmosphereError> {
        let t = text.trim().to_ascii_lowercase();
        if t == "flat" {
            return Ok(Self::Flat);
        }
        let bad = || AtmosphereError::OutOfRange {
            field: "surface".into(),
            value: f64::NAN,
            allowed: format!("`flat` or `wind:SPEED` in m/s (got `{text}`)"),
        };
        let speed = t.strip_prefix("wind:").ok_or_else(bad)?.parse::<f64>().map_err(|_| bad())?;
        Ok(Self::Wind { speed_m_s: speed })
    }
}

/// The atmosphere as written in a scene file or given on the command line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct AtmosphereSpec {
    /// Aerosol model.
    pub aerosol: AerosolType,
    /// Aerosol optical thickness at 550 nm (0–5).
    pub aot550: f64,
    /// Surface pressure, hPa (500–1100).
    pub pressure_hpa: f64,
    /// Gas absorption on (O3, O2, H2O) or off.
    pub gases: bool,
    /// Gas column amounts when `gases` is on.
    pub gas_amounts: GasAmounts,
    /// Sea surface state.
    pub surface: SeaSurface,
    /// Rayleigh optical-depth formula.
    pub rayleigh: RayleighDepth,
    /// Latitude of the scene, degrees (gravity in the Rayleigh depth).
    pub latitude_deg: f64,
    /// Molecular scale height, km.
    pub rayleigh_scale_height_km: f64,
    /// Aerosol scale height, km.
    pub aerosol_scale_height_km: f64,
    /// Refractive index of the water surface.
    pub water_refractive_index: f64,
    /// Day of year for the Sun–Earth distance (1–366).
    pub day_of_year: u32,
    /// Radiative-transfer accuracy settings.
    pub accuracy: RtAccuracy,
}

impl Default for AtmosphereSpec {
    fn default() -> Self {
        Self {
            aerosol: AerosolType::Maritime,
            aot550: 0.1,
            pressure_hpa: STANDARD_PRESSURE_HPA,
            gases: false,
            gas_amounts: GasAmounts::default(),
            surface: SeaSurface::Flat,
            rayleigh: RayleighDepth::Bodhaine,
            latitude_deg: 45.0,
            rayleigh_scale_height_km: 8.0,
            aerosol_scale_height_km: 2.0,
            water_refractive_index: SEA_REFRACTIVE_INDEX,
            day_of_year: 172,
            accuracy: RtAccuracy::default(),
        }
    }
}

fn range(field: &str, value: f64, lo: f64, hi: f64, unit: &str) -> Result<(), AtmosphereError> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(AtmosphereError::OutOfRange { field: field.into(), value, allowed: format!("{lo} to {hi}{unit}") })
    }
}

impl AtmosphereSpec {
    /// Check every field against its documented range ([`crate::ranges`]).
    pub fn validate(&self) -> Result<(), AtmosphereError> {
        use crate::ranges as r;
        check(&r::ATMOSPHERE_AOT550, self.aot550)?;
        check(&r::ATMOSPHERE_PRESSURE_HPA, self.pressure_hpa)?;
        check(&r::ATMOSPHERE_OZONE_ATM_CM, self.gas_amounts.ozone_atm_cm)?;
        check(&r::ATMOSPHERE_WATER_VAPOUR_CM, self.gas_amounts.water_vapour_cm)?;
        if let SeaSurface::Wind { speed_m_s } = self.surface {
            check(&r::ATMOSPHERE_WIND_SPEED_M_S, speed_m_s)?;
        }
        if let super::wmo::AerosolType::Mixture(f) = self.aerosol {
            let fields = [
                &r::ATMOSPHERE_MIXTURE_DUST_LIKE,
                &r::ATMOSPHERE_MIXTURE_WATER_SOLUBLE,
                &r::ATMOSPHERE_MIXTURE_OCEANIC,
                &r::ATMOSPHERE_MIXTURE_SOOT,
            ];
            for (range, (_, _, v)) in fields.into_iter().zip(f.named()) {
                check(range, v)?;
            }
            let total: f64 = f.named().iter().map(|n| n.2).sum();
            if total <= 0.0 {
                return Err(AtmosphereError::OutOfRange {
                    field: "aerosol.Mixture".into(),
                    value: total,
                    allowed: "fractions summing to more than 0".into(),
                });
            }
        }
        if let super::wmo::AerosolType::LogNormal(d) = self.aerosol {
            d.validate()?;
        }
        check(&r::ATMOSPHERE_LATITUDE_DEG, self.latitude_deg)?;
        check(&r::ATMOSPHERE_RAYLEIGH_SCALE_HEIGHT_KM, self.rayleigh_scale_height_km)?;
        check(&r::ATMOSPHERE_AEROSOL_SCALE_HEIGHT_KM, self.aerosol_scale_height_km)?;
        check(&r::ATMOSPHERE_WATER_REFRACTIVE_INDEX, self.water_refractive_index)?;
        check(&r::ATMOSPHERE_DAY_OF_YEAR, f64::from(self.day_of_year))?;
        self.accuracy.validate()
    }

    /// Validate and bind the solar spectrum.
    pub fn build(&self) -> Result<Atmosphere, AtmosphereError> {
        self.validate()?;
        Ok(Atmosphere { spec: self.clone(), e0: solar::tsis1()? })
    }
}

/// Sun and view geometry in radians (degrees only at the edges).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// Solar zenith angle, rad, 0–89° (see [`Self::validate`]).
    pub sun_zenith_rad: f64,
    /// View zenith angle, rad, 0–85°.
    pub view_zenith_rad: f64,
    /// View azimuth minus sun azimuth, rad (0: sensor on the sun's side; π: glint side).
    pub relative_azimuth_rad: f64,
}

impl Geometry {
    /// From degrees.
    #[must_use]
    pub fn from_degrees(sun_zenith: f64, view_zenith: f64, relative_azimuth: f64) -> Self {
        Self {
            sun_zenith_rad: sun_zenith.to_radians(),
            view_zenith_rad: view_zenith.to_radians(),
            relative_azimuth_rad: relative_azimuth.to_radians(),
        }
    }

    /// Sun zenith at most 89° (the plane-parallel model has no meaning at the horizon), view
    /// zenith at most 85°, azimuth within ±360° ([`crate::ranges`]: `GEOMETRY_*`).
    pub fn validate(&self) -> Result<(), AtmosphereError> {
        use crate::ranges as r;
        // Degrees as the user wrote them: the radian round trip's last-digit noise removed.
        let in_degrees = |range: &crate::ranges::Range, rad: f64| check(range, (rad.to_degrees() * 1e9).round() / 1e9);
        in_degrees(&r::GEOMETRY_SUN_ZENITH_DEG, self.sun_zenith_rad)?;
        in_degrees(&r::GEOMETRY_VIEW_ZENITH_DEG, self.view_zenith_rad)?;
        in_degrees(&r::GEOMETRY_RELATIVE_AZIMUTH_DEG, self.relative_azimuth_rad)
    }
}

/// Every atmospheric term at one wavelength and geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AtmosphereTerms {
    /// Wavelength, nm.
    pub wavelength_nm: f64,
    /// Extraterrestrial irradiance on the day, W m⁻² nm⁻¹.
    pub e0_w_m2_nm: f64,
    /// Rayleigh optical depth.
    pub tau_rayleigh: f64,
    /// Aerosol optical depth.
    pub tau_aerosol: f64,
    /// Path radiance incl. Fresnel-reflected sky light over black water, W m⁻² sr⁻¹ nm⁻¹.
    pub l_path_w_m2_sr_nm: f64,
    /// Path reflectance π L_path/(E₀ μ₀).
    pub rho_path: f64,
    /// Total downward transmittance Ed(0⁺)/(E₀ μ₀) (gases included).
    pub t_down: f64,
    /// Direct downward transmittance e^{−τ/μ₀}·T_gas (the diffuse part is `t_down − t_down_direct`).
    pub t_down_direct: f64,
    /// Total upward transmittance of the water-leaving radiance (see `rt::solve_transmittance`);
    /// its gas factor is the upward leg given the sun's, T(m₀ + m_v)/T(m₀), so that
    /// `ed_0plus_w_m2_nm · t_up` carries the two-way gas transmittance.
    pub t_up: f64,
    /// Direct upward transmittance e^{−τ/μ_v}·T_gas.
    pub t_up_direct: f64,
    /// Spherical albedo of the atmosphere.
    pub spherical_albedo: f64,
    /// Downwelling irradiance just above the surface (black water), W m⁻² nm⁻¹.
    pub ed_0plus_w_m2_nm: f64,
    /// Gas transmittance sun→surface→sensor, T(m₀ + m_v).
    pub t_gas: f64,
    /// Sun-glint radiance at TOA (0 for a flat surface), W m⁻² sr⁻¹ nm⁻¹.
    pub l_glint_w_m2_sr_nm: f64,
}

/// RT results per unit solar flux (normal to the beam) and without gases, for one wavelength
/// and geometry: what a LUT stores and what scenes interpolate across wavelength before applying
/// the 1-nm solar spectrum and the gases.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Normalised {
    /// Wavelength, nm.
    pub wavelength_nm: f64,
    /// Rayleigh optical depth.
    pub tau_rayleigh: f64,
    /// Aerosol optical depth.
    pub tau_aerosol: f64,
    /// Cosine of the sun zenith angle.
    pub mu0: f64,
    /// Cosine of the view zenith angle.
    pub muv: f64,
    /// Path radiance I (L = I·E₀).
    pub radiance: f64,
    /// Ed(0⁺) per unit flux (black water, Fresnel surface).
    pub ed: f64,
    /// Upward transmittance (see `rt::solve_transmittance`).
    pub t_up: f64,
    /// Its direct part.
    pub t_up_direct: f64,
    /// Spherical albedo.
    pub spherical_albedo: f64,
    /// Glint radiance per unit flux (0 for a flat surface).
    pub glint: f64,
    /// Molecules' and aerosols' forward-scattering optical depths, ω·η·τ with η the phase
    /// function's forward-hemisphere share: the single-scattering weights of their diffuse
    /// transmission (the adjacency effect mixes their environment functions by these).
    pub forward_scattering: (f64, f64),
}

/// A validated atmosphere.
#[derive(Debug, Clone)]
pub struct Atmosphere {
    spec: AtmosphereSpec,
    e0: Spectrum,
}

impl Atmosphere {
    /// The spec it was built from.
    #[must_use]
    pub fn spec(&self) -> &AtmosphereSpec {
        &self.spec
    }

    /// Extraterrestrial irradiance at `wavelength_nm` on the spec's day, W m⁻² nm⁻¹.
    pub fn e0(&self, wavelength_nm: f64) -> Result<f64, AtmosphereError> {
        Ok(self.e0.value_at(wavelength_nm, Extrapolation::Error)? * solar::sun_distance_factor(self.spec.day_of_year))
    }

    /// The optical column at `wavelength_nm` (325–2500 nm, the aerosol table's range).
    pub fn column(&self, wavelength_nm: f64) -> Result<WavelengthColumn, AtmosphereError> {
        use crate::ranges::{MAX_SIMULATED_NM, MIN_SIMULATED_NM};
        range("wavelength_nm", wavelength_nm, MIN_SIMULATED_NM, MAX_SIMULATED_NM, " nm")?;
        let s = &self.spec;
        let site =
            RayleighColumn { pressure_hpa: s.pressure_hpa, latitude_deg: s.latitude_deg, ..RayleighColumn::default() };
        let aerosol = if s.aot550 > 0.0 {
            mixture_optics(s.aerosol, wavelength_nm)?.map(|o| (s.aot550 * o.extinction_ratio, o.ssa, o.phase))
        } else {
            None
        };
        Ok(WavelengthColumn {
            wavelength_nm,
            tau_rayleigh: s.rayleigh.tau(wavelength_nm, &site),
            depolarization: AIR_DEPOLARIZATION,
            aerosol,
            rayleigh_scale_height_km: s.rayleigh_scale_height_km,
            aerosol_scale_height_km: s.aerosol_scale_height_km,
            water_index: s.water_refractive_index,
        })
    }

    /// One-way gas transmittance along zenith cosine `mu` (1 when gases are off).
    pub fn gas(&self, wavelength_nm: f64, mu: f64) -> Result<f64, AtmosphereError> {
        if self.spec.gases {
            gas_transmittance(wavelength_nm, mu, &self.spec.gas_amounts, self.spec.pressure_hpa)
        } else {
            Ok(1.0)
        }
    }

    /// Sun–surface–sensor gas transmittance T(m₀ + m_v) (1 when gases are off; see
    /// `gas::two_way_transmittance`).
    pub fn gas_two_way(&self, wavelength_nm: f64, mu0: f64, muv: f64) -> Result<f64, AtmosphereError> {
        if self.spec.gases {
            two_way_transmittance(wavelength_nm, mu0, muv, &self.spec.gas_amounts, self.spec.pressure_hpa)
        } else {
            Ok(1.0)
        }
    }

    /// The upward leg's gas factor given the sun's: T(m₀ + m_v)/T(m₀), so that Ed(0⁺) (which
    /// carries T(m₀)) times the upward transmittance carries the two-way T(m₀ + m_v).
    pub fn gas_up_after_down(&self, wavelength_nm: f64, mu0: f64, muv: f64) -> Result<f64, AtmosphereError> {
        let down = self.gas(wavelength_nm, mu0)?;
        let both = self.gas_two_way(wavelength_nm, mu0, muv)?;
        Ok(if down > 0.0 { (both / down).min(1.0) } else { 0.0 })
    }

    /// The gas factors of a spectrum seen along one geometry: at each of `wavelengths_nm`, the
    /// sun's leg T(m₀) ([`Self::gas`]) and the upward factor ([`Self::gas_up_after_down`]) — the
    /// same values, with the air masses computed once and each wavelength's absorption
    /// coefficients looked up once for both paths.
    pub fn gas_legs(&self, wavelengths_nm: &[f64], mu0: f64, muv: f64) -> Result<GasLegs, AtmosphereError> {
        let n = wavelengths_nm.len();
        if !self.spec.gases {
            return Ok(GasLegs {
                down: vec![1.0; n],
                up_after_down: vec![1.0; n],
                wavelengths_nm: wavelengths_nm.to_vec(),
                mu0,
                muv,
                key: None,
            });
        }
        let paths = [AirMasses::one_way(mu0), AirMasses::two_way(mu0, muv)];
        let (mut down, mut up_after_down) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let mut t = [0.0; 2];
        for &w in wavelengths_nm {
            along_paths(w, &paths, &self.spec.gas_amounts, self.spec.pressure_hpa, &mut t)?;
            let [d, both] = t;
            down.push(d);
            up_after_down.push(if d > 0.0 { (both / d).min(1.0) } else { 0.0 });
        }
        Ok(GasLegs { down, up_after_down, wavelengths_nm: wavelengths_nm.to_vec(), mu0, muv, key: self.gas_key() })
    }

    /// What the gas factors depend on besides the geometry and the wavelength: `None` when the
    /// gases are off. Two atmospheres with the same key have the same [`Self::gas_legs`].
    #[must_use]
    pub fn gas_key(&self) -> Option<(GasAmounts, f64)> {
        self.spec.gases.then_some((self.spec.gas_amounts, self.spec.pressure_hpa))
    }

    /// All terms at one wavelength and geometry, by a direct RT solve (what `shoal atmosphere`
    /// prints; scenes use the LUT).
    pub fn terms(&self, wavelength_nm: f64, g: &Geometry) -> Result<AtmosphereTerms, AtmosphereError> {
        g.validate()?;
        let column = self.column(wavelength_nm)?;
        let (mu0, muv) = (g.sun_zenith_rad.cos(), g.view_zenith_rad.cos());
        let acc = &self.spec.accuracy;
        let sun = solve_sun(&column, mu0, &[muv], acc);
        let up = solve_transmittance(&column, &[muv], acc);
        let radiance = sun.radiance(0, g.relative_azimuth_rad);
        let glint = self.glint(g, column.total_tau());
        let n = Normalised {
            wavelength_nm,
            tau_rayleigh: column.tau_rayleigh,
            tau_aerosol: column.aerosol.as_ref().map_or(0.0, |a| a.0),
            mu0,
            muv,
            radiance,
            ed: sun.ed(),
            t_up: up.t_up[0],
            t_up_direct: up.t_up_direct[0],
            spherical_albedo: up.spherical_albedo,
            glint,
            forward_scattering: column.forward_scattering(),
        };
        self.assemble(&n)
    }

    /// Sun glint per unit solar flux at `g` through a column of optical depth `tau` (0 for a
    /// flat surface).
    pub fn glint(&self, g: &Geometry, tau: f64) -> f64 {
        match self.spec.surface {
            SeaSurface::Flat => 0.0,
            SeaSurface::Wind { speed_m_s } => glint_radiance_norm(
                g.sun_zenith_rad,
                g.view_zenith_rad,
                g.relative_azimuth_rad,
                speed_m_s,
                self.spec.water_refractive_index,
                tau,
            ),
        }
    }

    /// Combine normalised RT results with E₀ and gases into physical terms.
    pub fn assemble(&self, n: &Normalised) -> Result<AtmosphereTerms, AtmosphereError> {
        let e0 = self.e0(n.wavelength_nm)?;
        let tg0 = self.gas(n.wavelength_nm, n.mu0)?;
        let t_gas = self.gas_two_way(n.wavelength_nm, n.mu0, n.muv)?;
        let tgv = self.gas_up_after_down(n.wavelength_nm, n.mu0, n.muv)?;
        let l_path = n.radiance * e0 * t_gas;
        Ok(AtmosphereTerms {
            wavelength_nm: n.wavelength_nm,
            e0_w_m2_nm: e0,
            tau_rayleigh: n.tau_rayleigh,
            tau_aerosol: n.tau_aerosol,
            l_path_w_m2_sr_nm: l_path,
            rho_path: std::f64::consts::PI * l_path / (e0 * n.mu0),
            t_down: n.ed / n.mu0 * tg0,
            t_down_direct: (-(n.tau_rayleigh + n.tau_aerosol) / n.mu0).exp() * tg0,
            t_up: n.t_up * tgv,
            t_up_direct: n.t_up_direct * tgv,
            spherical_albedo: n.spherical_albedo,
            ed_0plus_w_m2_nm: n.ed * e0 * tg0,
            t_gas,
            l_glint_w_m2_sr_nm: n.glint * e0 * t_gas,
        })
    }
}
