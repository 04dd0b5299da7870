//! The semi-analytical shallow-water reflectance model of Lee et al. (1998, 1999) as coded in
//! SAMBUCA (`sambuca_core.forward_model`), with every intermediate returned.

use super::kernel::{self, Spectra};
use super::{Siop, WaterError};
use crate::ranges::limits;
use crate::simd::Baseline;
use crate::units::PI;

/// Constituent concentrations and the bottom, for one water column.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaterColumn<'a> {
    /// Chlorophyll-a, mg m⁻³ (= µg L⁻¹).
    pub chl_mg_m3: f64,
    /// CDOM absorption at the SIOP set's CDOM reference wavelength, m⁻¹.
    pub cdom_per_m: f64,
    /// Non-algal particles (suspended minerals), g m⁻³ (= mg L⁻¹).
    pub nap_g_m3: f64,
    /// The bottom: optically deep, or a depth and a substrate reflectance on the SIOP grid.
    pub bottom: Bottom<'a>,
}

/// What lies under the water column.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bottom<'a> {
    /// No bottom signal: the bottom term is never evaluated.
    OpticallyDeep,
    /// A bottom at `depth_m` with irradiance reflectance `reflectance` (0–1, on the SIOP grid).
    Shallow {
        /// Depth, m.
        depth_m: f64,
        /// Substrate irradiance reflectance ρ_b(λ) on the SIOP grid.
        reflectance: &'a [f64],
    },
}

/// Sun and view zenith angles in air, radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaterGeometry {
    /// Solar zenith angle in air, rad, in [0, 90°).
    pub sun_zenith_rad: f64,
    /// View (off-nadir) zenith angle in air, rad, in [0, 90°).
    pub view_zenith_rad: f64,
}

impl WaterGeometry {
    /// Geometry from angles in degrees (the edge unit).
    #[must_use]
    pub fn from_degrees(sun_zenith_deg: f64, view_zenith_deg: f64) -> Self {
        Self { sun_zenith_rad: sun_zenith_deg.to_radians(), view_zenith_rad: view_zenith_deg.to_radians() }
    }

    /// Check both angles lie in [0, 90°).
    pub fn validate(&self) -> Result<(), WaterError> {
        for (field, v) in [("sun_zenith", self.sun_zenith_rad), ("view_zenith", self.view_zenith_rad)] {
            if !(v.is_finite() && (0.0..limits::MAX_ZENITH_RAD).contains(&v)) {
                return Err(WaterError::OutOfRange {
                    field: format!("{field} (deg)"),
                    value: v.to_degrees(),
                    allowed: "0 to below 90 degrees".into(),
                });
            }
        }
        Ok(())
    }

    /// Under-water angles by Snell's law: θ_w = asin(sin θ/n). Returns (1/cos θ_w(sun), 1/cos θ_w(view)).
    #[must_use]
    pub fn inverse_cosines_in_water(&self, refractive_index: f64) -> (f64, f64) {
        let inv_n = 1.0 / refractive_index;
        let theta_w = (inv_n * self.sun_zenith_rad.sin()).asin();
        let theta_o = (inv_n * self.view_zenith_rad.sin()).asin();
        (1.0 / theta_w.cos(), 1.0 / theta_o.cos())
    }
}

impl WaterColumn<'_> {
    /// Check concentrations and depth against [`limits`] and that the substrate spectrum has
    /// one value per grid wavelength, each in [0, 1].
    pub fn validate(&self, n_wavelengths: usize) -> Result<(), WaterError> {
        self.validate_scalars(n_wavelengths)?;
        if let Bottom::Shallow { reflectance, .. } = self.bottom {
            // A pass without an early exit (it vectorises; NaN and ±∞ fail both comparisons or
            // the second), then the search for the message.
            let in_range = reflectance.iter().fold(true, |ok, &r| ok & (0.0..=1.0).contains(&r));
            if !in_range && let Some(r) = reflectance.iter().find(|r| !(r.is_finite() && (0.0..=1.0).contains(*r))) {
                return Err(WaterError::OutOfRange {
                    field: "substrate reflectance".into(),
                    value: *r,
                    allowed: "0 to 1".into(),
                });
            }
        }
        Ok(())
    }

    /// [`Self::validate`] but for the reflectance's values (the per-pixel kernels check those
    /// in their loop).
    fn validate_scalars(&self, n_wavelengths: usize) -> Result<(), WaterError> {
        let check = |field: &str, v: f64, max: f64, unit: &str| {
            if v.is_finite() && (0.0..=max).contains(&v) {
                Ok(())
            } else {
                Err(WaterError::OutOfRange { field: field.into(), value: v, allowed: format!("0 to {max} {unit}") })
            }
        };
        check("chl (mg m-3)", self.chl_mg_m3, limits::MAX_CHL_MG_M3, "mg m-3")?;
        check("cdom (m-1)", self.cdom_per_m, limits::MAX_CDOM_PER_M, "m-1")?;
        check("nap (g m-3)", self.nap_g_m3, limits::MAX_NAP_G_M3, "g m-3")?;
        if let Bottom::Shallow { depth_m, reflectance } = self.bottom {
            if !(depth_m.is_finite() && depth_m > 0.0 && depth_m <= limits::MAX_DEPTH_M) {
                return Err(WaterError::OutOfRange {
                    field: "depth (m)".into(),
                    value: depth_m,
                    allowed: format!("above 0 and at most {} m", limits::MAX_DEPTH_M),
                });
            }
            if reflectance.len() != n_wavelengths {
                return Err(WaterError::OutOfRange {
                    field: "substrate reflectance length".into(),
                    value: reflectance.len() as f64,
                    allowed: format!("{n_wavelengths} values, one per grid wavelength"),
                });
            }
        }
        Ok(())
    }
}

/// Every quantity the forward model computes, per grid wavelength. Units: m⁻¹ for a, bb, κ and
/// the K's; sr⁻¹ for the reflectances; u and ρ_b dimensionless.
#[derive(Debug, Clone, PartialEq)]
pub struct WaterReflectance {
    /// Total absorption a.
    pub a: Vec<f64>,
    /// Pure-water absorption a_w.
    pub a_w: Vec<f64>,
    /// Phytoplankton absorption a_ph = chl·a*_ph.
    pub a_ph: Vec<f64>,
    /// CDOM absorption a_CDOM = cdom·a*_CDOM.
    pub a_cdom: Vec<f64>,
    /// NAP absorption a_NAP = nap·a*_NAP.
    pub a_nap: Vec<f64>,
    /// Total backscattering bb.
    pub bb: Vec<f64>,
    /// Pure-water backscattering bb_w.
    pub bb_w: Vec<f64>,
    /// Phytoplankton backscattering bb_ph = chl·bb*_ph.
    pub bb_ph: Vec<f64>,
    /// NAP backscattering bb_NAP = nap·bb*_NAP.
    pub bb_nap: Vec<f64>,
    /// κ = a + bb.
    pub kappa: Vec<f64>,
    /// u = bb/(a + bb).
    pub u: Vec<f64>,
    /// Diffuse attenuation of downwelling light, Kd = κ/cos θ_w.
    pub kd: Vec<f64>,
    /// Upward attenuation of water-column light, kuC = κ·D_u^C/cos θ_o.
    pub kuc: Vec<f64>,
    /// Upward attenuation of bottom-reflected light, kuB = κ·D_u^B/cos θ_o.
    pub kub: Vec<f64>,
    /// Optically deep sub-surface remote-sensing reflectance rrs_dp = (0.084 + 0.17u)u.
    pub rrs_deep: Vec<f64>,
    /// Bottom (substrate mixture) reflectance ρ_b; empty for optically deep water.
    pub r_substratum: Vec<f64>,
    /// Sub-surface remote-sensing reflectance rrs(0⁻).
    pub rrs: Vec<f64>,
    /// Above-surface remote-sensing reflectance Rrs(0⁺) = 0.52 rrs/(1 − 1.7 rrs).
    pub rrs_above: Vec<f64>,
}

impl WaterReflectance {
    /// Sub-surface irradiance reflectance R(0⁻) = Q·rrs (SAMBUCA's `r_0_minus`, Q = π there).
    #[must_use]
    pub fn r_0_minus(&self, q_factor: f64) -> Vec<f64> {
        self.rrs.iter().map(|r| q_factor * r).collect()
    }

    /// Named columns in output order, names carrying units, for CSV output.
    #[must_use]
    pub fn columns(&self) -> Vec<(&'static str, &[f64])> {
        let mut c: Vec<(&'static str, &[f64])> = vec![
            ("a_per_m", &self.a),
            ("a_w_per_m", &self.a_w),
            ("a_ph_per_m", &self.a_ph),
            ("a_cdom_per_m", &self.a_cdom),
            ("a_nap_per_m", &self.a_nap),
            ("bb_per_m", &self.bb),
            ("bb_w_per_m", &self.bb_w),
            ("bb_ph_per_m", &self.bb_ph),
            ("bb_nap_per_m", &self.bb_nap),
            ("kappa_per_m", &self.kappa),
            ("u", &self.u),
            ("kd_per_m", &self.kd),
            ("kuc_per_m", &self.kuc),
            ("kub_per_m", &self.kub),
            ("rrs_deep_per_sr", &self.rrs_deep),
        ];
        if !self.r_substratum.is_empty() {
            c.push(("r_substratum", &self.r_substratum));
        }
        c.push(("rrs_0minus_per_sr", &self.rrs));
        c.push(("rrs_above_per_sr", &self.rrs_above));
        c
    }
}

/// Above-surface from sub-surface remote-sensing reflectance, Rrs = 0.52 rrs/(1 − 1.7 rrs)
/// (Lee, Carder & Arnone 2002, Appl. Opt. 41, 5755, eq. 4).
///
/// ```
/// let r = shoal::water::rrs_above_from_below(0.01);
/// assert!((shoal::water::rrs_below_from_above(r) - 0.01).abs() < 1e-17);
/// ```
#[inline]
#[must_use]
pub fn rrs_above_from_below(rrs: f64) -> f64 {
    0.52 * rrs / (1.0 - 1.7 * rrs)
}

/// The exact inverse of [`rrs_above_from_below`]: rrs = Rrs/(0.52 + 1.7 Rrs).
#[inline]
#[must_use]
pub fn rrs_below_from_above(rrs_above: f64) -> f64 {
    rrs_above / (0.52 + 1.7 * rrs_above)
}

/// The forward model bound to one resolved SIOP set.
#[derive(Debug, Clone)]
pub struct WaterModel {
    siop: Siop,
}

impl WaterModel {
    /// Bind a resolved SIOP set.
    #[must_use]
    pub fn new(siop: Siop) -> Self {
        Self { siop }
    }

    /// The SIOP set (and its grid).
    #[must_use]
    pub fn siop(&self) -> &Siop {
        &self.siop
    }

    /// Evaluate the model with every intermediate (allocates; for plots, CSV and tests).
    ///
    /// Lee et al. (1998) eqs. 1–4 and Lee et al. (1999) eqs. 5–11, as coded in SAMBUCA:
    /// - a = a_w + chl·a*_ph + cdom·a*_CDOM + nap·a*_NAP ; bb = bb_w + chl·bb*_ph + nap·bb*_NAP
    /// - κ = a + bb ; u = bb/κ ; rrs_dp = (0.084 + 0.170u)u
    /// - D_u^C = 1.03(1 + 2.4u)^½ ; D_u^B = 1.04(1 + 5.4u)^½
    /// - rrs = rrs_dp[1 − e^{−(1/cosθ_w + D_u^C/cosθ_o)κH}] + (ρ_b/π) e^{−(1/cosθ_w + D_u^B/cosθ_o)κH}
    pub fn evaluate(&self, column: &WaterColumn<'_>, geometry: &WaterGeometry) -> Result<WaterReflectance, WaterError> {
        let s = &self.siop;
        let n = s.grid.len();
        column.validate(n)?;
        geometry.validate()?;
        let (inv_cos_w, inv_cos_o) = geometry.inverse_cosines_in_water(s.water_refractive_index);
        let (chl, cdom, nap) = (column.chl_mg_m3, column.cdom_per_m, column.nap_g_m3);
        let scale = |spec: &[f64], c: f64| spec.iter().map(|x| c * x).collect::<Vec<f64>>();
        let a_ph = scale(&s.a_ph_star, chl);
        let a_cdom = scale(&s.a_cdom_star, cdom);
        let a_nap = scale(&s.a_nap_star, nap);
        let bb_ph = scale(&s.bb_ph_star, chl);
        let bb_nap = scale(&s.bb_nap_star, nap);
        let a: Vec<f64> = (0..n).map(|i| s.a_w[i] + a_ph[i] + a_cdom[i] + a_nap[i]).collect();
        let bb: Vec<f64> = (0..n).map(|i| s.bb_w[i] + bb_ph[i] + bb_nap[i]).collect();
        if let Some(i) = (0..n).find(|&i| !(a[i] > 0.0 && bb[i] > 0.0)) {
            return Err(self.non_physical(i, a[i], bb[i]));
        }
        let kappa: Vec<f64> = a.iter().zip(&bb).map(|(a, b)| a + b).collect();
        let u: Vec<f64> = bb.iter().zip(&kappa).map(|(b, k)| b / k).collect();
        let du_c: Vec<f64> = u.iter().map(|u| 1.03 * (1.0 + 2.4 * u).sqrt()).collect();
        let du_b: Vec<f64> = u.iter().map(|u| 1.04 * (1.0 + 5.4 * u).sqrt()).collect();
        let rrs_deep: Vec<f64> = u.iter().map(|u| (0.084 + 0.17 * u) * u).collect();
        let kd: Vec<f64> = kappa.iter().map(|k| k * inv_cos_w).collect();
        let kuc: Vec<f64> = kappa.iter().zip(&du_c).map(|(k, d)| k * d * inv_cos_o).collect();
        let kub: Vec<f64> = kappa.iter().zip(&du_b).map(|(k, d)| k * d * inv_cos_o).collect();
        let (rrs, r_substratum) = match column.bottom {
            Bottom::OpticallyDeep => (rrs_deep.clone(), Vec::new()),
            Bottom::Shallow { depth_m, reflectance } => {
                let rrs = (0..n)
                    .map(|i| {
                        let kh = kappa[i] * depth_m;
                        rrs_deep[i] * (1.0 - (-(inv_cos_w + du_c[i] * inv_cos_o) * kh).exp())
                            + reflectance[i] / PI * (-(inv_cos_w + du_b[i] * inv_cos_o) * kh).exp()
                    })
                    .collect();
                (rrs, reflectance.to_vec())
            }
        };
        let rrs_above = rrs.iter().map(|r| rrs_above_from_below(*r)).collect();
        Ok(WaterReflectance {
            a,
            a_w: s.a_w.clone(),
            a_ph,
            a_cdom,
            a_nap,
            bb,
            bb_w: s.bb_w.clone(),
            bb_ph,
            bb_nap,
            kappa,
            u,
            kd,
            kuc,
            kub,
            rrs_deep,
            r_substratum,
            rrs,
            rrs_above,
        })
    }

    /// The checks of [`Self::rrs_above_into`] made before its kernel runs (shared with the
    /// single-precision kernel, [`super::SingleWater`]): the column's concentrations, depth and
    /// reflectance length, the geometry, the output length. The kernels check the rest in their
    /// loop (a > 0, bb > 0, 0 ≤ ρ_b ≤ 1); [`Self::diagnose`] names what failed.
    pub(super) fn check(
        &self,
        column: &WaterColumn<'_>,
        geometry: &WaterGeometry,
        out_len: usize,
    ) -> Result<(), WaterError> {
        let n = self.siop.grid.len();
        column.validate_scalars(n)?;
        geometry.validate()?;
        if out_len != n {
            return Err(WaterError::OutOfRange {
                field: "output length".into(),
                value: out_len as f64,
                allowed: format!("{n} (one per grid wavelength)"),
            });
        }
        Ok(())
    }

    /// What made a kernel's in-loop check fail for `column`: a substrate reflectance outside
    /// [0, 1], or the first wavelength where a or bb is not positive (computed as `evaluate`
    /// computes them: double precision, unfused). `None` if neither holds.
    pub(super) fn diagnose(&self, column: &WaterColumn<'_>) -> Option<WaterError> {
        if let Err(e) = column.validate(self.siop.grid.len()) {
            return Some(e);
        }
        let k = self.spectra(column);
        (0..self.siop.grid.len()).find_map(|i| {
            let (a, bb) = (kernel::absorption::<f64, Baseline>(&k, i), kernel::backscattering::<f64, Baseline>(&k, i));
            (!(a > 0.0 && bb > 0.0)).then(|| self.non_physical(i, a, bb))
        })
    }

    /// Whether a > 0 and bb > 0 at every wavelength of the grid, computed as `evaluate`
    /// computes them (the single-precision kernel's check where rounding could flip a sign).
    pub(super) fn all_positive(&self, column: &WaterColumn<'_>) -> bool {
        let k = self.spectra(column);
        (0..self.siop.grid.len()).fold(true, |ok, i| {
            let (a, bb) = (kernel::absorption::<f64, Baseline>(&k, i), kernel::backscattering::<f64, Baseline>(&k, i));
            ok & (a > 0.0) & (bb > 0.0)
        })
    }

    fn spectra<'a>(&'a self, column: &WaterColumn<'_>) -> Spectra<'a, f64> {
        let (s, n) = (&self.siop, self.siop.grid.len());
        Spectra {
            a_w: &s.a_w[..n],
            bb_w: &s.bb_w[..n],
            a_ph: &s.a_ph_star[..n],
            a_cdom: &s.a_cdom_star[..n],
            a_nap: &s.a_nap_star[..n],
            bb_ph: &s.bb_ph_star[..n],
            bb_nap: &s.bb_nap_star[..n],
            chl: column.chl_mg_m3,
            cdom: column.cdom_per_m,
            nap: column.nap_g_m3,
        }
    }

    /// Above-surface Rrs only, without allocating: the per-pixel path. Same formulas as
    /// [`Self::evaluate`], with fused multiply-adds and [`super::fast_exp`]'s fused build
    /// (≤ 4.5·10⁻¹⁶ relative), on the widest vector instructions the CPU has
    /// ([`crate::simd::widest`]); it agrees with `evaluate` to a few parts in 10¹⁵. Inputs are
    /// validated as in `evaluate`, including a > 0 and bb > 0 (on an error `out` holds no
    /// answer).
    pub fn rrs_above_into(
        &self,
        column: &WaterColumn<'_>,
        geometry: &WaterGeometry,
        out: &mut [f64],
    ) -> Result<(), WaterError> {
        self.check(column, geometry, out.len())?;
        let spectra = self.spectra(column);
        let floor = match column.bottom {
            Bottom::OpticallyDeep => kernel::Floor::Deep,
            Bottom::Shallow { depth_m, reflectance } => {
                // Only the bottom's path needs the angles under water (two arcsines, two sines and
                // two cosines: a third of a deep pixel's time at the band nodes, were they taken
                // for every pixel).
                let (inv_cos_w, inv_cos_o) = geometry.inverse_cosines_in_water(self.siop.water_refractive_index);
                kernel::Floor::Shallow { depth_m, inv_cos_w, inv_cos_o, rb: reflectance }
            }
        };
        if crate::simd::widest(kernel::Evaluation { spectra: &spectra, floor, out }) {
            Ok(())
        } else {
            Err(self.diagnose(column).unwrap_or_else(|| self.non_physical_somewhere()))
        }
    }

    /// The message when the kernel's check failed and [`Self::diagnose`] found nothing: a or bb
    /// within a rounding of zero, positive as `evaluate` computes it and not as the kernel does
    /// (in single precision, or with fused multiply-adds).
    pub(super) fn non_physical_somewhere(&self) -> WaterError {
        WaterError::Siop {
            set: self.siop.name.clone(),
            field: "total absorption/backscattering".into(),
            message: "a or bb is within a rounding of zero at some wavelength for these \
                      concentrations, not positive as the per-pixel kernel rounds it (a specific \
                      spectrum is too negative there)"
                .into(),
        }
    }

    fn non_physical(&self, i: usize, a: f64, bb: f64) -> WaterError {
        WaterError::Siop {
            set: self.siop.name.clone(),
            field: "total absorption/backscattering".into(),
            message: format!(
                "a = {a:e}, bb = {bb:e} m-1 at {} nm are not positive for these concentrations \
                 (a specific spectrum is too negative there)",
                self.siop.grid.wavelength_nm(i)
            ),
        }
    }
}
