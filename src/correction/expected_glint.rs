//! The glint a processor expects from the wind it assumes, for the exact correction: the scene's
//! band glint of each column carried from the scene's wind to the assumed one.
//!
//! The forward model's glint at wavelength λ and geometry g is
//!
//! L_g(λ) = E₀(λ)·t_gas(λ)·ρ_g(g, W)·μ₀/π·e^(−τ(λ)/μ₀)·e^(−τ(λ)/μ_v)
//!
//! ([`crate::atmosphere::glint_radiance_norm`]), where the wind W enters only the Cox–Munk glint
//! reflectance ρ_g = π·r_F(ω)·p(β; σ²)/(4·μ₀·μ_v·cos⁴β), through the slope variance
//! σ² = 0.003 + 0.00512·W (Cox & Munk 1954), and ρ_g does not depend on λ (one refractive index).
//! At one geometry the glint at another wind W′ is therefore the scene's glint times
//! ρ_g(g, W′)/ρ_g(g, W) at every wavelength; the band weighting (a weighted sum) and the LUT's
//! log-linear interpolation between wavelength nodes keep that factor, so the band glint is
//!
//! G_b(W′) = G_b(W)·ρ_g(g_b, W′)/ρ_g(g_b, W),
//!
//! with g_b the geometry of the band's group in that column (a filter imager's rows see the
//! ground from different angles). Where the scene's glint is zero — ρ_g(W) underflows beyond
//! tan²β/σ² ≈ 745, a facet tilt β above 56° in calm water and more in wind — the expected glint
//! is taken as zero. At that tilt ρ_g is at most 5·10⁻⁹ for an assumed wind of 20 m/s and
//! 4·10⁻⁶ for 30 m/s (Fresnel reflectance 0.1), against a water Rrs·π of 10⁻³ to 10⁻²; only a
//! calm sea read with the largest wind the ranges allow (30 + 20 m/s) would miss up to 6·10⁻⁴.
//!
//! ## References
//! - Cox, C. & Munk, W. (1954) Measurement of the roughness of the sea surface from photographs
//!   of the sun's glitter. J. Opt. Soc. Am. 44, 838–850.
//! - Wang, M. & Bailey, S. W. (2001) Correction of sun glint contamination on the SeaWiFS ocean
//!   and atmosphere products. Appl. Opt. 40, 4790–4798 (the glint a processor takes away, from
//!   the wind of ancillary data).

use super::{Reflectance, RrsFlags};
use crate::atmosphere::{Geometry, glint_radiance_norm};
use crate::instrument::{BandAtmosphere, Response, SurfaceMap, Viewing};

/// The band glint per column × band (the index of [`BandAtmosphere::glint`]) that a processor
/// assuming `assumed_wind_m_s` expects over a scene whose glint `atmosphere` holds at
/// `wind_m_s`, over water of refractive index `n`.
#[must_use]
pub fn expected_glint(
    atmosphere: &BandAtmosphere,
    viewing: &Viewing,
    response: &Response,
    (wind_m_s, assumed_wind_m_s): (f64, f64),
    n: f64,
) -> Vec<f64> {
    let nb = atmosphere.n_bands;
    let mut out = atmosphere.glint.clone();
    for (group, looks) in response.groups.iter().zip(&viewing.looks) {
        for (c, look) in looks.iter().enumerate() {
            let factor = wind_factor(&look.geometry, wind_m_s, assumed_wind_m_s, n);
            for &b in &group.bands {
                if let Some(g) = out.get_mut(c * nb + b) {
                    *g *= factor;
                }
            }
        }
    }
    out
}

/// Per column: the normalised glint radiance L_GN = ρ_g·μ₀/π (sr⁻¹; Wang & Bailey 2001: the
/// glint per unit solar flux, without the path's attenuation) that a processor assuming
/// `wind_m_s` expects at the column's geometry over water of refractive index `n`, the largest
/// over the geometry groups (a filter imager's rows see the ground from different angles). What
/// l2gen compares with `glint_thresh` to set HIGLINT.
#[must_use]
pub fn column_lgn(viewing: &Viewing, wind_m_s: f64, n: f64) -> Vec<f64> {
    let lgn = |g: &Geometry| {
        glint_radiance_norm(g.sun_zenith_rad, g.view_zenith_rad, g.relative_azimuth_rad, wind_m_s, n, 0.0)
    };
    (0..viewing.columns())
        .map(|c| viewing.looks.iter().filter_map(|g| g.get(c)).map(|l| lgn(&l.geometry)).fold(0.0, f64::max))
        .collect()
}

/// Leave out the water pixels of the columns `high_glint` names, as a processor masks HIGLINT:
/// every band flagged [`RrsFlags::GLINT`] and [`RrsFlags::INVALID`], its Rrs 0. Pixels that are
/// not water in `surface` (land, or screened out as cloud) keep their flags. Returns the pixels
/// left out.
pub fn mark_high_glint(rrs: &mut Reflectance, high_glint: &dyn Fn(usize) -> bool, surface: &SurfaceMap) -> usize {
    let (rows, cols, nb) = rrs.rrs.dim();
    let mut marked = 0;
    for c in (0..cols).filter(|&c| high_glint(c)) {
        for r in (0..rows).filter(|&r| surface.is_water(r, c)) {
            for b in 0..nb {
                rrs.flags[[r, c, b]] |= RrsFlags::GLINT | RrsFlags::INVALID;
                rrs.rrs[[r, c, b]] = 0.0;
            }
            marked += 1;
        }
    }
    marked
}

/// ρ_g(g, W′)/ρ_g(g, W) (see the module docs): 0 where the scene's glint is zero.
#[must_use]
pub fn wind_factor(g: &Geometry, wind_m_s: f64, assumed_wind_m_s: f64, n: f64) -> f64 {
    let rho = |w: f64| glint_radiance_norm(g.sun_zenith_rad, g.view_zenith_rad, g.relative_azimuth_rad, w, n, 0.0);
    let scene = rho(wind_m_s);
    if scene > 0.0 && scene.is_finite() { rho(assumed_wind_m_s) / scene } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The factor carries the glint of any path (τ > 0, the attenuated glint the forward model
    /// adds) from one wind to the other exactly, at geometries near and far from the specular
    /// direction: the wind enters ρ_g alone.
    #[test]
    fn the_factor_carries_the_attenuated_glint_to_the_other_wind() {
        let n = 1.34;
        let mut worst: f64 = 0.0;
        for sun_deg in [10.0f64, 30.0, 60.0] {
            for view_deg in [0.0f64, 15.0, 40.0] {
                for az_deg in [0.0f64, 90.0, 180.0] {
                    let g = Geometry {
                        sun_zenith_rad: sun_deg.to_radians(),
                        view_zenith_rad: view_deg.to_radians(),
                        relative_azimuth_rad: az_deg.to_radians(),
                    };
                    for (w, w2) in [(5.0, 6.0), (5.0, 3.0), (0.5, 12.0), (8.0, 0.0)] {
                        for tau in [0.0, 0.12, 0.6] {
                            let glint = |wind: f64| {
                                glint_radiance_norm(
                                    g.sun_zenith_rad,
                                    g.view_zenith_rad,
                                    g.relative_azimuth_rad,
                                    wind,
                                    n,
                                    tau,
                                )
                            };
                            let (at_w, at_w2) = (glint(w), glint(w2));
                            if at_w > 1e-280 {
                                let carried = at_w * wind_factor(&g, w, w2, n);
                                worst = worst.max((carried - at_w2).abs() / at_w2.max(1e-300));
                            }
                        }
                    }
                }
            }
        }
        // Rounding only: a product and a quotient of the same terms.
        assert!(worst < 1e-12, "worst relative difference {worst:e}");
    }

    /// The same wind is a factor of one; far from the specular direction the factor grows with
    /// the assumed wind (more slopes tilt far enough) and near it falls (the glitter spreads).
    #[test]
    fn the_factor_follows_cox_munk_s_slope_variance() {
        let n = 1.34;
        let at = |sun: f64, view: f64, az: f64| Geometry {
            sun_zenith_rad: f64::to_radians(sun),
            view_zenith_rad: f64::to_radians(view),
            relative_azimuth_rad: f64::to_radians(az),
        };
        let far = at(60.0, 0.0, 180.0);
        let specular = at(30.0, 30.0, 180.0);
        assert_eq!(wind_factor(&far, 5.0, 5.0, n), 1.0);
        assert!(wind_factor(&far, 5.0, 7.0, n) > 1.5, "{}", wind_factor(&far, 5.0, 7.0, n));
        assert!(wind_factor(&specular, 5.0, 7.0, n) < 1.0);
        // The specular point: p(0; σ²) = 1/(πσ²), so the factor is σ²(W)/σ²(W′) (Cox–Munk).
        let sigma2 = |w: f64| 0.003 + 0.00512 * w;
        let want = sigma2(5.0) / sigma2(7.0);
        assert!((wind_factor(&specular, 5.0, 7.0, n) / want - 1.0).abs() < 1e-9);
    }
}
