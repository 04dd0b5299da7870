//! The water model at the instrument's bands, with its analytic Jacobian: the forward model
//! inside the retrievals.
//!
//! A band's Rrs is the weighted mean of the spectral Rrs over the band's response (the same
//! weights the chain's truth uses). Evaluating the Lee/SAMBUCA model at every grid point of every
//! band would cost ~300 evaluations per call; instead each band is integrated with a K-point
//! Gauss rule of its response ([`super::quadrature`]), exact for spectra that are polynomials
//! of degree < 2K across the band. With K = 4 the band Rrs of the scenes' spectra agrees with the
//! full sum to ~1e-5 (see the tests), at a quarter of the cost.
//!
//! Per node, the model is that of [`crate::water`] (Lee et al. 1998, 1999; SAMBUCA):
//! a = a_w + C·a*_ph + G·a*_CDOM + X·a*_NAP, bb = bb_w + C·bb*_ph + X·bb*_NAP, κ = a + bb,
//! u = bb/κ, rrs_dp = (0.084 + 0.17u)u, D_C = 1.03√(1 + 2.4u), D_B = 1.04√(1 + 5.4u),
//! rrs = rrs_dp·(1 − e^{−(1/μw + D_C/μo)κH}) + ρ_b/π·e^{−(1/μw + D_B/μo)κH},
//! Rrs = 0.52·rrs/(1 − 1.7·rrs), with ρ_b = q·ρ₁ + (1 − q)·ρ₂.
//! The derivatives follow by the chain rule: ∂u/∂p = (a·∂bb − bb·∂a)/κ², ∂D_C/∂u = 1.236/√(1 + 2.4u),
//! ∂D_B/∂u = 2.808/√(1 + 5.4u), ∂Rrs/∂rrs = 0.52/(1 − 1.7 rrs)².

use std::path::Path;

use super::RetrievalError;
use super::quadrature::gauss_rule;
use crate::parse::FieldError;
use crate::spectral::WavelengthGrid;
use crate::water::{SiopSpec, SubstrateLibrary, SubstrateMix};

mod nodes;

use nodes::Nodes;

/// A band's response on the simulation grid: the discrete measure its Rrs is averaged over.
#[derive(Debug, Clone, PartialEq)]
pub struct BandResponse {
    /// Band name.
    pub name: String,
    /// Wavelengths, nm.
    pub wavelengths_nm: Vec<f64>,
    /// Weights (any positive scale).
    pub weights: Vec<f64>,
}

impl BandResponse {
    /// Centroid wavelength of the response, nm.
    #[must_use]
    pub fn centroid_nm(&self) -> f64 {
        let total: f64 = self.weights.iter().sum();
        self.wavelengths_nm.iter().zip(&self.weights).map(|(x, w)| x * w).sum::<f64>() / total.max(f64::MIN_POSITIVE)
    }
}

/// The free parameters of one evaluation. Concentrations in mg m⁻³ (chl), m⁻¹ (a_CDOM at the
/// SIOP set's reference wavelength), g m⁻³ (NAP); depth in m (`None`: optically deep).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Parameters {
    /// Chlorophyll-a.
    pub chl: f64,
    /// CDOM absorption at the reference wavelength.
    pub cdom: f64,
    /// Non-algal particles.
    pub nap: f64,
    /// Depth, or `None` for optically deep water.
    pub depth_m: Option<f64>,
    /// Substrate pair (indices into the model's substrates) and the first one's fraction.
    pub substrates: (usize, usize, f64),
}

/// Index of each parameter in a Jacobian row.
pub mod param {
    /// ∂/∂chl.
    pub const CHL: usize = 0;
    /// ∂/∂cdom.
    pub const CDOM: usize = 1;
    /// ∂/∂nap.
    pub const NAP: usize = 2;
    /// ∂/∂depth.
    pub const DEPTH: usize = 3;
    /// ∂/∂q (fraction of the first substrate).
    pub const FRACTION: usize = 4;
}

/// Band-averaged IOP spectra of a SIOP set (what aLMI's linear system uses).
#[derive(Debug, Clone, PartialEq)]
pub struct BandIops {
    /// Pure-water absorption per band.
    pub a_w: Vec<f64>,
    /// Pure-water backscattering per band.
    pub bb_w: Vec<f64>,
    /// a*_ph per band.
    pub a_ph: Vec<f64>,
    /// a*_CDOM per band.
    pub a_cdom: Vec<f64>,
    /// a*_NAP per band.
    pub a_nap: Vec<f64>,
    /// bb*_ph per band.
    pub bb_ph: Vec<f64>,
    /// bb*_NAP per band.
    pub bb_nap: Vec<f64>,
}

/// Working memory of [`BandModel::evaluate_with`] (one per thread).
#[derive(Debug, Clone, Default)]
pub struct ModelScratch {
    rb: Vec<f64>,
    drb: Vec<f64>,
    above: Vec<f64>,
    /// Each node's weighted terms of the five band gradients (with the Jacobian only).
    grad: [Vec<f64>; 5],
}

impl ModelScratch {
    fn resize(&mut self, n: usize) {
        for v in [&mut self.rb, &mut self.drb, &mut self.above].into_iter().chain(&mut self.grad) {
            v.resize(n, 0.0);
        }
    }
}

/// The band model of one SIOP set and substrate list.
#[derive(Debug, Clone, PartialEq)]
pub struct BandModel {
    /// SIOP set name.
    pub siop_name: String,
    /// Band names.
    pub band_names: Vec<String>,
    /// Per band: node range.
    ranges: Vec<std::ops::Range<usize>>,
    /// The node count of every band where they are all the same (a band's nodes are then
    /// `uniform·b..uniform·(b + 1)`), else 0.
    uniform: usize,
    /// Per node: quadrature weight (normalised per band); zero on the padding nodes.
    weight: Vec<f64>,
    a_w: Vec<f64>,
    bb_w: Vec<f64>,
    a_ph: Vec<f64>,
    a_cdom: Vec<f64>,
    a_nap: Vec<f64>,
    bb_ph: Vec<f64>,
    bb_nap: Vec<f64>,
    /// Substrate names and reflectance per node. Every per-node vector holds the bands' nodes
    /// and then copies of the last node up to a multiple of the node loop's vector width
    /// ([`crate::simd::throughput_f64_lanes`]): the loop then runs whole vectors of nodes, never
    /// a scalar remainder, and no band sum reads the padding (`ranges` end before it).
    substrate_names: Vec<String>,
    substrates: Vec<Vec<f64>>,
    /// Refractive index of water.
    pub refractive_index: f64,
}

impl BandModel {
    /// Build the model of `siop` (relative CSV paths from `siop_dir`) with `substrates` from
    /// `library`, integrating each of `bands` with a `nodes_per_band`-point Gauss rule.
    pub fn new(
        siop: &SiopSpec,
        siop_dir: Option<&Path>,
        library: &SubstrateLibrary,
        substrates: &[String],
        bands: &[BandResponse],
        nodes_per_band: usize,
    ) -> Result<Self, RetrievalError> {
        if bands.is_empty() {
            return Err(RetrievalError::Invalid(FieldError {
                field: "bands".into(),
                message: "no band to retrieve from".into(),
            }));
        }
        let mut ranges = Vec::with_capacity(bands.len());
        let mut nodes = Vec::new();
        let mut weight = Vec::new();
        for b in bands {
            let (x, w) = gauss_rule(&b.wavelengths_nm, &b.weights, nodes_per_band);
            if x.is_empty() {
                return Err(RetrievalError::Invalid(FieldError {
                    field: format!("band {}", b.name),
                    message: "the band has no response".into(),
                }));
            }
            let total: f64 = w.iter().sum();
            ranges.push(nodes.len()..nodes.len() + x.len());
            nodes.extend_from_slice(&x);
            weight.extend(w.iter().map(|v| v / total));
        }
        // Sample every spectrum once at the distinct nodes.
        let mut unique = nodes.clone();
        unique.sort_by(f64::total_cmp);
        unique.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        let grid = WavelengthGrid::from_wavelengths(unique.clone())?;
        let s = siop.resolve(&grid, siop_dir)?;
        let padded = nodes.len().next_multiple_of(crate::simd::throughput_f64_lanes());
        let at = |v: &[f64]| -> Vec<f64> {
            let mut at: Vec<f64> =
                nodes.iter().map(|x| v[unique.partition_point(|u| *u < x - 1e-9).min(unique.len() - 1)]).collect();
            at.resize(padded, at[at.len() - 1]);
            at
        };
        weight.resize(padded, 0.0);
        let substrate_spectra = substrates
            .iter()
            .map(|name| {
                let mix = SubstrateMix { parts: vec![(name.clone(), 1.0)] };
                Ok(at(&library.mix_on_grid(&mix, &grid)?))
            })
            .collect::<Result<Vec<_>, RetrievalError>>()?;
        let first = ranges[0].len();
        let uniform = if ranges.iter().all(|r| r.len() == first) { first } else { 0 };
        Ok(Self {
            siop_name: siop.name.clone(),
            band_names: bands.iter().map(|b| b.name.clone()).collect(),
            ranges,
            uniform,
            weight,
            a_w: at(&s.a_w),
            bb_w: at(&s.bb_w),
            a_ph: at(&s.a_ph_star),
            a_cdom: at(&s.a_cdom_star),
            a_nap: at(&s.a_nap_star),
            bb_ph: at(&s.bb_ph_star),
            bb_nap: at(&s.bb_nap_star),
            substrate_names: substrates.to_vec(),
            substrates: substrate_spectra,
            refractive_index: s.water_refractive_index,
        })
    }

    /// Number of bands.
    #[must_use]
    pub fn n_bands(&self) -> usize {
        self.ranges.len()
    }

    /// Substrate names.
    #[must_use]
    pub fn substrate_names(&self) -> &[String] {
        &self.substrate_names
    }

    /// Quadrature nodes in all (not counting the padding).
    #[must_use]
    pub fn n_nodes(&self) -> usize {
        self.ranges.last().map_or(0, |r| r.end)
    }

    /// The band averages of the SIOP spectra.
    #[must_use]
    pub fn band_iops(&self) -> BandIops {
        let avg = |v: &[f64]| -> Vec<f64> {
            self.ranges.iter().map(|r| r.clone().map(|i| self.weight[i] * v[i]).sum()).collect()
        };
        BandIops {
            a_w: avg(&self.a_w),
            bb_w: avg(&self.bb_w),
            a_ph: avg(&self.a_ph),
            a_cdom: avg(&self.a_cdom),
            a_nap: avg(&self.a_nap),
            bb_ph: avg(&self.bb_ph),
            bb_nap: avg(&self.bb_nap),
        }
    }

    /// Band Rrs (above surface, sr⁻¹) of `p` seen with the in-water inverse cosines
    /// (`inv_cos_w`, `inv_cos_o`), into `out`; with `jacobian`, also ∂Rrs_b/∂p (row b, columns
    /// [`param`]). Optically deep water and a substrate pair out of range leave the depth and
    /// fraction columns zero. Allocates its working memory; see [`Self::evaluate_with`].
    pub fn evaluate(&self, p: &Parameters, inv_cos: (f64, f64), out: &mut [f64], jacobian: Option<&mut [[f64; 5]]>) {
        let mut scratch = ModelScratch::default();
        self.evaluate_with(p, inv_cos, out, jacobian, &mut scratch);
    }

    /// [`Self::evaluate`] with caller-owned working memory (the per-pixel path). The node loop
    /// runs over plain arrays without branches, so it vectorises; band sums follow.
    pub fn evaluate_with(
        &self,
        p: &Parameters,
        inv_cos: (f64, f64),
        out: &mut [f64],
        jacobian: Option<&mut [[f64; 5]]>,
        s: &mut ModelScratch,
    ) {
        // Every node, the padding too (see `substrates`).
        let n = self.weight.len();
        s.resize(n);
        let (s1, s2, q) = p.substrates;
        // Bottom reflectance of the pair (zero when there is none) and its q-derivative.
        match (self.substrates.get(s1), self.substrates.get(s2)) {
            (Some(a), Some(b)) => {
                // Every slice cut to n: the loop carries no bounds checks and vectorises.
                let (a, b, rb, drb) = (&a[..n], &b[..n], &mut s.rb[..n], &mut s.drb[..n]);
                for i in 0..n {
                    rb[i] = q * a[i] + (1.0 - q) * b[i];
                    drb[i] = a[i] - b[i];
                }
            }
            (Some(a), None) => {
                s.rb[..n].copy_from_slice(&a[..n]);
                s.drb[..n].fill(0.0);
            }
            _ => {
                s.rb[..n].fill(0.0);
                s.drb[..n].fill(0.0);
            }
        }
        let (h, shallow) = match p.depth_m {
            Some(h) => (h, 1.0),
            None => (0.0, 0.0),
        };
        let with_jacobian = jacobian.is_some();
        crate::simd::throughput(Nodes { model: self, p, inv_cos, h, shallow, with_jacobian, n, s });
        match self.uniform {
            1 => return self.uniform_sums::<1>(out, jacobian, s),
            2 => return self.uniform_sums::<2>(out, jacobian, s),
            3 => return self.uniform_sums::<3>(out, jacobian, s),
            4 => return self.uniform_sums::<4>(out, jacobian, s),
            _ => {}
        }
        let Some(j) = jacobian else {
            for (b, range) in self.ranges.iter().enumerate() {
                out[b] = range.clone().map(|i| self.weight[i] * s.above[i]).sum();
            }
            return;
        };
        // A band's Rrs and its five gradient terms in one loop over its nodes: six independent
        // sums (each in node order, as before) overlap, and the zipped slices carry no bounds
        // checks.
        let [g0, g1, g2, g3, g4] = &s.grad;
        for (b, range) in self.ranges.iter().enumerate() {
            let r = range.clone();
            let terms =
                g0[r.clone()].iter().zip(&g1[r.clone()]).zip(&g2[r.clone()]).zip(&g3[r.clone()]).zip(&g4[r.clone()]);
            let (mut rrs, mut grad) = (-0.0, [0.0; 5]);
            for ((&w, &above), ((((&d0, &d1), &d2), &d3), &d4)) in
                self.weight[r.clone()].iter().zip(&s.above[r]).zip(terms)
            {
                rrs += w * above;
                grad[0] += d0;
                grad[1] += d1;
                grad[2] += d2;
                grad[3] += d3;
                grad[4] += d4;
            }
            out[b] = rrs;
            j[b] = grad;
        }
    }

    /// The band sums of [`Self::evaluate_with`] where every band has `K` nodes: the same sums in
    /// the same order, over fixed-size chunks, so that they carry no loop over ranges and no
    /// bounds check (they took a sixth of a 28-band fit's time as ranges).
    fn uniform_sums<const K: usize>(&self, out: &mut [f64], jacobian: Option<&mut [[f64; 5]]>, s: &ModelScratch) {
        let nb = self.n_bands();
        fn chunks<const K: usize>(v: &[f64], nb: usize) -> &[[f64; K]] {
            &v[..nb * K].as_chunks::<K>().0[..nb]
        }
        let nodes = chunks::<K>(&self.weight, nb).iter().zip(chunks::<K>(&s.above, nb));
        let Some(j) = jacobian else {
            for (o, (w, above)) in out[..nb].iter_mut().zip(nodes) {
                let mut rrs = -0.0;
                for i in 0..K {
                    rrs += w[i] * above[i];
                }
                *o = rrs;
            }
            return;
        };
        let [g0, g1, g2, g3, g4] = &s.grad;
        let c = |g| chunks::<K>(g, nb);
        let terms = c(g0).iter().zip(c(g1)).zip(c(g2)).zip(c(g3)).zip(c(g4));
        for ((o, row), ((w, above), ((((d0, d1), d2), d3), d4))) in
            out[..nb].iter_mut().zip(&mut j[..nb]).zip(nodes.zip(terms))
        {
            let (mut rrs, mut grad) = (-0.0, [0.0; 5]);
            for i in 0..K {
                rrs += w[i] * above[i];
                grad[0] += d0[i];
                grad[1] += d1[i];
                grad[2] += d2[i];
                grad[3] += d3[i];
                grad[4] += d4[i];
            }
            *o = rrs;
            *row = grad;
        }
    }

    /// Band Rrs of the optically deep water with the same constituents (for the substrate
    /// detectability index).
    pub fn evaluate_deep(&self, p: &Parameters, out: &mut [f64]) {
        self.evaluate_deep_with(p, out, &mut ModelScratch::default());
    }

    /// [`Self::evaluate_deep`] with caller-owned working memory.
    pub fn evaluate_deep_with(&self, p: &Parameters, out: &mut [f64], s: &mut ModelScratch) {
        let deep = Parameters { depth_m: None, ..*p };
        self.evaluate_with(&deep, (1.0, 1.0), out, None, s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> BandModel {
        let spec = SiopSpec::preset("heron_island").unwrap();
        let bands: Vec<BandResponse> = [443.0, 490.0, 560.0, 665.0, 709.0]
            .iter()
            .map(|&c| {
                let x: Vec<f64> = (0..41).map(|i| c - 20.0 + f64::from(i)).collect();
                let w = x.iter().map(|x| (-0.5 * ((x - c) / 4.0).powi(2)).exp()).collect();
                BandResponse { name: format!("B{c}"), wavelengths_nm: x, weights: w }
            })
            .collect();
        let lib = SubstrateLibrary::embedded().unwrap();
        BandModel::new(&spec, None, &lib, &["sand".into(), "acropora".into()], &bands, 4).unwrap()
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let m = model();
        let nb = m.n_bands();
        let inv = (1.0 / 0.95, 1.0 / 0.99);
        for depth in [None, Some(3.0)] {
            let p = Parameters { chl: 0.8, cdom: 0.05, nap: 2.0, depth_m: depth, substrates: (0, 1, 0.3) };
            let mut base = vec![0.0; nb];
            let mut jac = vec![[0.0; 5]; nb];
            m.evaluate(&p, inv, &mut base, Some(&mut jac));
            let mut no_jac = vec![0.0; nb];
            m.evaluate(&p, inv, &mut no_jac, None);
            assert_eq!(base, no_jac);
            let bump = |k: usize, h: f64| -> Parameters {
                let mut q = p;
                match k {
                    0 => q.chl += h,
                    1 => q.cdom += h,
                    2 => q.nap += h,
                    3 => q.depth_m = q.depth_m.map(|d| d + h),
                    _ => q.substrates.2 += h,
                }
                q
            };
            for k in 0..5 {
                let x = [p.chl, p.cdom, p.nap, p.depth_m.unwrap_or(1.0), 0.3][k];
                let h = 1e-6 * x.max(1e-3);
                let (mut plus, mut minus) = (vec![0.0; nb], vec![0.0; nb]);
                m.evaluate(&bump(k, h), inv, &mut plus, None);
                m.evaluate(&bump(k, -h), inv, &mut minus, None);
                for b in 0..nb {
                    let fd = (plus[b] - minus[b]) / (2.0 * h);
                    let scale = fd.abs().max(1e-9);
                    assert!(
                        (jac[b][k] - fd).abs() < 1e-5 * scale.max(1e-6),
                        "depth {depth:?} param {k} band {b}: {} vs {fd}",
                        jac[b][k]
                    );
                }
            }
        }
    }

    /// Where every band has the same node count the sums run over fixed-size chunks; they give
    /// the bits of the general path over node ranges, with and without the Jacobian.
    #[test]
    fn uniform_band_sums_are_the_range_sums_to_the_bit() {
        let uniform = model();
        assert_eq!(uniform.uniform, 4);
        let general = BandModel { uniform: 0, ..uniform.clone() };
        let nb = uniform.n_bands();
        for depth in [None, Some(2.5)] {
            let p = Parameters { chl: 1.3, cdom: 0.02, nap: 0.7, depth_m: depth, substrates: (0, 1, 0.6) };
            let run = |m: &BandModel| {
                let (mut rrs, mut plain, mut jac) = (vec![0.0; nb], vec![0.0; nb], vec![[0.0; 5]; nb]);
                m.evaluate(&p, (1.05, 1.01), &mut rrs, Some(&mut jac));
                m.evaluate(&p, (1.05, 1.01), &mut plain, None);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                (bits(&rrs), bits(&plain), bits(&jac.concat()))
            };
            assert_eq!(run(&uniform), run(&general), "depth {depth:?}");
        }
    }
}
