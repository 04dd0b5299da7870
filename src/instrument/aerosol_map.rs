//! A scene whose aerosol optical thickness varies over the image (`aot550_map`): the forward
//! model's atmosphere pixel by pixel.
//!
//! The aerosol model stays the scene atmosphere's; its optical thickness τ(x, y) follows the
//! map. The band-effective atmosphere of every column — L_path,b, (T·Ed)_b and S_b, the
//! photon-weighted means of [`super::band_atmosphere`] — is computed at AOT nodes spanning the
//! map ([`node_values`]: at most [`NODE_STEP`] apart) and, at a pixel's τ, interpolated with
//! quadratic Lagrange weights over the three nearest nodes ([`weights`]; path radiance is not
//! linear in τ, so a linear interpolation would leave percent-level errors).
//!
//! The sampling stage first computes a pixel's band radiance L through the reference
//! atmosphere (the scene atmosphere's own `aot550`, [`BandAtmosphere`]), then exchanges the
//! atmosphere band by band (Vermote et al. 1997, the Lambertian-coupled target):
//!
//! y = (L − L_path,ref − G)/(T·Ed)_ref,  x = y/(1 + S_ref·π·y),
//! L(τ) = L_path(τ) + G + (T·Ed)(τ)·x/(1 − S(τ)·π·x).
//!
//! x is the pixel's band reflectance (Rrs over water, ρ/π over land), so the exchange is exact
//! for the band-level model. What it leaves out, each small and stated: the change with τ of the
//! within-band weights T_up·Ed (a second-order term; `tests/chain/aerosol_map.rs` measures the
//! whole exchange against a scene whose constant AOT is the target value), the change of sun
//! glint with τ (glint stays the reference atmosphere's), the change of the adjacency term
//! (computed through the reference atmosphere), and τ varying inside one pixel's spatial
//! response (the pixel centre's τ is used).
//!
//! ## References
//! - Vermote, E. F., Tanré, D., Deuzé, J. L., Herman, M., Morcrette, J.-J. (1997) Second
//!   simulation of the satellite signal in the solar spectrum, 6S: an overview. IEEE TGRS 35,
//!   675–686.

use super::InstrumentError;
use super::band_atmosphere::{BandAtmosphere, BandTerms, band_terms_of_each};
use super::geometry::Viewing;
use super::response::Response;
use crate::toa::PathOptics;

/// Largest spacing of the AOT nodes. Quadratic interpolation over nodes 0.05 apart leaves
/// below 10⁻⁴ relative error in path radiance (the closure test's measure).
pub const NODE_STEP: f64 = 0.05;

/// The band-effective atmosphere of every column at AOT nodes spanning a scene's map.
#[derive(Debug, Clone)]
pub struct AotNodes {
    /// AOT(550) nodes, increasing.
    pub aot550: Vec<f64>,
    /// Per node: the band terms of every column (index column·bands + band).
    pub terms: Vec<BandTerms>,
    /// Bands.
    pub n_bands: usize,
}

/// AOT nodes for a map spanning `lo`–`hi`: at least three, at most [`NODE_STEP`] apart, the
/// first at `lo` (so a constant map is reproduced at a node exactly).
#[must_use]
pub fn node_values(lo: f64, hi: f64) -> Vec<f64> {
    let lo = lo.max(0.0);
    let span = (hi - lo).max(1e-3);
    let n = ((span / NODE_STEP).ceil() as usize).max(2);
    (0..=n).map(|i| lo + span * i as f64 / n as f64).collect()
}

/// Quadratic Lagrange weights of `tau` over the three nodes nearest it (τ clamped to the
/// nodes' range; with two nodes, linear).
#[must_use]
pub fn weights(nodes: &[f64], tau: f64) -> [(usize, f64); 3] {
    let n = nodes.len();
    if n == 1 {
        return [(0, 1.0), (0, 0.0), (0, 0.0)];
    }
    let tau = tau.clamp(nodes[0], nodes[n - 1]);
    if n == 2 {
        let f = (tau - nodes[0]) / (nodes[1] - nodes[0]);
        return [(0, 1.0 - f), (1, f), (1, 0.0)];
    }
    let k = nodes.partition_point(|&v| v <= tau).clamp(1, n - 1) - 1;
    // The segment [k, k+1] and its nearer neighbour.
    let first = if k == 0 {
        0
    } else if k + 2 >= n {
        n - 3
    } else if tau - nodes[k] < nodes[k + 1] - tau {
        k - 1
    } else {
        k
    };
    let (a, b, c) = (nodes[first], nodes[first + 1], nodes[first + 2]);
    [
        (first, (tau - b) * (tau - c) / ((a - b) * (a - c))),
        (first + 1, (tau - a) * (tau - c) / ((b - a) * (b - c))),
        (first + 2, (tau - a) * (tau - b) / ((c - a) * (c - b))),
    ]
}

impl AotNodes {
    /// The band terms at each node: `paths[k]` is the atmosphere at `aot550[k]` bound to each
    /// geometry group's grid. Every column is computed (no across-track interpolation: this is
    /// the forward model); the gas factors of a column's geometry once for all the nodes.
    pub fn build(
        aot550: Vec<f64>,
        paths: &[Vec<PathOptics>],
        viewing: &Viewing,
        response: &Response,
    ) -> Result<Self, InstrumentError> {
        let paths: Vec<Vec<&PathOptics>> = paths.iter().map(|p| p.iter().collect()).collect();
        let terms = band_terms_of_each(&paths, viewing, response, None)?;
        Ok(Self { aot550, terms, n_bands: response.n_bands() })
    }

    /// (L_path, T·Ed, S) of entry `i` (column·bands + band) under the weights `w`.
    #[inline]
    fn at(&self, w: &[(usize, f64); 3], i: usize) -> (f64, f64, f64) {
        let (mut lp, mut te, mut s) = (0.0, 0.0, 0.0);
        for &(k, wk) in w {
            let t = &self.terms[k];
            lp += wk * t.l_path[i];
            te += wk * t.t_ed[i];
            s += wk * t.spherical_albedo[i];
        }
        (lp, te, s)
    }

    /// Column `column`'s terms at optical thickness `tau`, one value per band.
    pub fn column_terms(&self, column: usize, tau: f64, l_path: &mut [f64], t_ed: &mut [f64], s_albedo: &mut [f64]) {
        let w = weights(&self.aot550, tau);
        for b in 0..self.n_bands {
            (l_path[b], t_ed[b], s_albedo[b]) = self.at(&w, column * self.n_bands + b);
        }
    }

    /// Exchange the reference atmosphere of `reference` for the one at `tau` in one pixel's band
    /// radiance (`radiance`, one value per band, W m⁻² sr⁻¹ nm⁻¹) of column `column`.
    pub fn exchange(&self, reference: &BandAtmosphere, column: usize, tau: f64, radiance: &mut [f32]) {
        let w = weights(&self.aot550, tau);
        let pi = std::f64::consts::PI;
        for (b, value) in radiance.iter_mut().enumerate().take(self.n_bands) {
            let i = reference.at(column, b);
            let te_ref = reference.t_ed[i];
            if te_ref <= 0.0 {
                continue;
            }
            let glint = reference.glint[i];
            let y = (f64::from(*value) - reference.l_path[i] - glint) / te_ref;
            let x = y / (1.0 + reference.spherical_albedo[i] * pi * y);
            let (lp, te, s) = self.at(&w, i);
            *value = (lp + glint + te * x / (1.0 - s * pi * x)) as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_span_the_map_and_start_at_its_minimum() {
        let n = node_values(0.05, 0.3);
        assert_eq!(n.len(), 6);
        assert!((n[0] - 0.05).abs() < 1e-15 && (n[5] - 0.3).abs() < 1e-12);
        assert!(n.windows(2).all(|w| w[1] - w[0] <= NODE_STEP + 1e-12));
        let c = node_values(0.1, 0.1);
        assert_eq!(c.len(), 3);
        assert_eq!(c[0], 0.1);
    }

    #[test]
    fn quadratic_weights_reproduce_a_parabola() {
        let nodes = [0.0, 0.05, 0.1, 0.15, 0.2];
        let f = |t: f64| 3.0 + 2.0 * t - 5.0 * t * t;
        for tau in [0.0, 0.01, 0.07, 0.124, 0.2, 0.3, -0.1] {
            let w = weights(&nodes, tau);
            let v: f64 = w.iter().map(|&(k, wk)| wk * f(nodes[k])).sum();
            let t = tau.clamp(0.0, 0.2);
            assert!((v - f(t)).abs() < 1e-12, "τ {tau}: {v} vs {}", f(t));
        }
        assert_eq!(weights(&nodes, 0.05)[1], (1, 1.0));
    }
}
