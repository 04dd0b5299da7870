//! The vertical structure of one wavelength's optical column: exponential profiles of molecules
//! and aerosols, the equal-optical-depth levels the SOS solver works on (delta-M scaled), and a
//! fine altitude quadrature for the exact single-scattering integrals.
//!
//! τ(z) above altitude z: τ_R e^{−z/H_R} + τ_a e^{−z/H_a}, with H_R = 8 km and H_a = 2 km by
//! default (OSOAA's GUI and pyOSOAA defaults). In the delta-M scaled column the aerosol part is
//! τ_a(1 − ω_a f) (Wiscombe 1977). Levels are placed at equal steps of scaled optical depth, each
//! found by bisection in altitude (as OSOAA's `OSOAA_ALTI_LAYER`), and carry the local
//! single-scattering albedo and the Rayleigh share of scattering; the source function is linear
//! in τ between levels.
//!
//! ## References
//! - Wiscombe, W. J. (1977) The delta-M method. J. Atmos. Sci. 34, 1408–1422.
//! - Lenoble, J. (ed.) (1985) Radiative Transfer in Scattering and Absorbing Atmospheres:
//!   Standard Computational Procedures, Deepak (successive orders, linear source in layers).

use super::quadrature::gauss_legendre;

/// Optical depths and scale heights of one wavelength's column.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColumnOptics {
    /// Rayleigh optical depth.
    pub tau_rayleigh: f64,
    /// Aerosol optical depth (0 for none).
    pub tau_aerosol: f64,
    /// Aerosol single-scattering albedo.
    pub ssa_aerosol: f64,
    /// Molecular scale height, km.
    pub rayleigh_scale_height_km: f64,
    /// Aerosol scale height, km.
    pub aerosol_scale_height_km: f64,
}

impl ColumnOptics {
    fn densities(&self, z_km: f64) -> (f64, f64) {
        let e_r = self.tau_rayleigh / self.rayleigh_scale_height_km * (-z_km / self.rayleigh_scale_height_km).exp();
        let e_a = self.tau_aerosol / self.aerosol_scale_height_km * (-z_km / self.aerosol_scale_height_km).exp();
        (e_r, e_a)
    }

    /// Optical depth above `z_km`, with the aerosol extinction multiplied by `aerosol_factor`.
    fn tau_above(&self, z_km: f64, aerosol_factor: f64) -> f64 {
        self.tau_rayleigh * (-z_km / self.rayleigh_scale_height_km).exp()
            + aerosol_factor * self.tau_aerosol * (-z_km / self.aerosol_scale_height_km).exp()
    }
}

/// SOS levels of the delta-M scaled column (level 0 at the top, level K at the surface).
#[derive(Debug, Clone, PartialEq)]
pub struct Layering {
    /// Scaled optical depth at each level.
    pub tau: Vec<f64>,
    /// Scaled single-scattering albedo at each level.
    pub omega: Vec<f64>,
    /// Rayleigh share of the (scaled) scattering at each level; the aerosol share is 1 − this.
    pub rayleigh_fraction: Vec<f64>,
}

impl Layering {
    /// Levels for `column` with aerosol truncation fraction `f` (0 without truncation), at most
    /// `max_dtau` scaled optical depth per layer and at least `min_layers` layers.
    #[must_use]
    pub fn new(column: &ColumnOptics, f: f64, max_dtau: f64, min_layers: usize) -> Self {
        let wa = column.ssa_aerosol;
        let factor = 1.0 - wa * f;
        let total = column.tau_above(0.0, factor);
        let k = ((total / max_dtau).ceil() as usize).max(min_layers).max(1);
        let mut tau = Vec::with_capacity(k + 1);
        let mut omega = Vec::with_capacity(k + 1);
        let mut frac = Vec::with_capacity(k + 1);
        for i in 0..=k {
            let target = total * i as f64 / k as f64;
            let z = if i == 0 {
                300.0
            } else if i == k {
                0.0
            } else {
                altitude_of(column, factor, target)
            };
            let (e_r, e_a) = column.densities(z);
            let scat_a = wa * (1.0 - f) * e_a;
            let ext = e_r + factor * e_a;
            tau.push(target);
            omega.push(if ext > 0.0 { (e_r + scat_a) / ext } else { 1.0 });
            frac.push(if e_r + scat_a > 0.0 { e_r / (e_r + scat_a) } else { 1.0 });
        }
        Self { tau, omega, rayleigh_fraction: frac }
    }

    /// Number of layers K.
    #[must_use]
    pub fn n_layers(&self) -> usize {
        self.tau.len() - 1
    }

    /// Scaled optical depth of the whole column.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.tau[self.tau.len() - 1]
    }
}

/// Altitude (km) where the scaled optical depth above equals `target` (bisection, 1e-10 km).
fn altitude_of(column: &ColumnOptics, factor: f64, target: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 300.0);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if column.tau_above(mid, factor) > target {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-10 {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// A quadrature over altitude for single-scattering integrals of the unscaled column:
/// nodes at optical depth τᵢ (from the top) with weights dτ_R,ᵢ and dτ_a,ᵢ (extinction).
#[derive(Debug, Clone, PartialEq)]
pub struct AltitudeQuadrature {
    /// Total optical depth above each node.
    pub tau: Vec<f64>,
    /// Rayleigh optical depth of each node's share.
    pub d_tau_rayleigh: Vec<f64>,
    /// Aerosol (extinction) optical depth of each node's share.
    pub d_tau_aerosol: Vec<f64>,
    /// Total optical depth of the column.
    pub total: f64,
}

impl AltitudeQuadrature {
    /// 16-point Gauss–Legendre on altitude segments 0–0.5–1–2–4–8–16–32–64–128–300 km; integrands
    /// are smooth exponentials, so the quadrature error is below 10⁻¹⁰ of the column.
    #[must_use]
    pub fn new(column: &ColumnOptics) -> Self {
        let (gx, gw) = gauss_legendre(16);
        let edges = [0.0, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 300.0];
        let (mut tau, mut d_r, mut d_a) = (Vec::new(), Vec::new(), Vec::new());
        for seg in edges.windows(2) {
            let (a, b) = (seg[0], seg[1]);
            for (x, w) in gx.iter().zip(&gw) {
                let z = 0.5 * (a + b) + 0.5 * (b - a) * x;
                let (e_r, e_a) = column.densities(z);
                tau.push(column.tau_above(z, 1.0));
                d_r.push(e_r * w * 0.5 * (b - a));
                d_a.push(e_a * w * 0.5 * (b - a));
            }
        }
        Self { tau, d_tau_rayleigh: d_r, d_tau_aerosol: d_a, total: column.tau_above(0.0, 1.0) }
    }

    /// (∫ e^{−c − m τ} dτ_R, ∫ e^{−c − m τ} dτ_a) over the column; the constant `offset` c is
    /// folded into the exponent so that a large e^{−c} and a large e^{+|m|τ} never meet.
    #[must_use]
    pub fn attenuated(&self, m: f64, offset: f64) -> (f64, f64) {
        let mut r = 0.0;
        let mut a = 0.0;
        for i in 0..self.tau.len() {
            let e = (-offset - m * self.tau[i]).exp();
            r += e * self.d_tau_rayleigh[i];
            a += e * self.d_tau_aerosol[i];
        }
        (r, a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn column() -> ColumnOptics {
        ColumnOptics {
            tau_rayleigh: 0.35,
            tau_aerosol: 0.14,
            ssa_aerosol: 0.9,
            rayleigh_scale_height_km: 8.0,
            aerosol_scale_height_km: 2.0,
        }
    }

    #[test]
    fn quadrature_integrates_the_column_and_an_exponential() {
        let c = column();
        let q = AltitudeQuadrature::new(&c);
        let (r, a) = q.attenuated(0.0, 0.0);
        assert!((r - 0.35).abs() < 1e-9 && (a - 0.14).abs() < 1e-9, "{r} {a}");
        // ∫ e^{−mτ} dτ over the whole column = (1 − e^{−mτ*})/m when both share one profile.
        let mut same = c;
        same.aerosol_scale_height_km = 8.0;
        let q = AltitudeQuadrature::new(&same);
        let (r, a) = q.attenuated(2.0, 0.0);
        let total: f64 = 0.49;
        let expected = (1.0 - (-2.0 * total).exp()) / 2.0;
        assert!(((r + a) - expected).abs() < 1e-9, "{} vs {expected}", r + a);
    }

    #[test]
    fn layering_is_equal_in_scaled_depth_and_mixes_by_height() {
        let c = column();
        let l = Layering::new(&c, 0.3, 0.02, 10);
        let total = 0.35 + 0.14 * (1.0 - 0.9 * 0.3);
        assert!((l.total() - total).abs() < 1e-12);
        assert_eq!(l.n_layers(), (total / 0.02).ceil() as usize);
        // Aerosols live low: the top is Rayleigh, the bottom is mostly aerosol.
        assert!(l.rayleigh_fraction[0] > 0.999 && l.rayleigh_fraction[l.n_layers()] < 0.5);
        assert!(l.omega.iter().all(|w| *w > 0.8 && *w <= 1.0));
    }
}
