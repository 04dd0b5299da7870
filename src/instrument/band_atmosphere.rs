//! The band-effective atmosphere of each output column: path radiance, glint, Ed, T·Ed and
//! spherical albedo through each band's photon weights (the formulas are in the module docs of
//! [`super::sample`]), and the weights the truth and the band nodes use.

use rayon::prelude::*;

use super::InstrumentError;
use super::geometry::Viewing;
use super::response::Response;
use crate::toa::{PathOptics, PathSpectrum, SceneOptics};

/// Per band of a group: first grid index and weights on the grid from there.
pub type BandWeights = Vec<(usize, Vec<f64>)>;

/// The atmosphere seen by each output column through each band's response.
#[derive(Debug, Clone)]
pub struct BandAtmosphere {
    /// Bands.
    pub n_bands: usize,
    /// Per group, per output column: the atmosphere on the group's grid.
    pub paths: Vec<Vec<PathSpectrum>>,
    /// Per column × band: band-effective path radiance, W m⁻² sr⁻¹ nm⁻¹.
    pub l_path: Vec<f64>,
    /// Per column × band: band-effective glint radiance.
    pub glint: Vec<f64>,
    /// Per column × band: band-effective Ed(0⁺), W m⁻² nm⁻¹.
    pub ed: Vec<f64>,
    /// Per column × band: (T_up·Ed)_b.
    pub t_ed: Vec<f64>,
    /// Per column × band: band-effective spherical albedo.
    pub spherical_albedo: Vec<f64>,
    /// Per group, per column: weights of the truth Rrs for each band of the group.
    pub truth_weights: Vec<Vec<BandWeights>>,
    /// Per group (empty where the optics has no band nodes), per column, per band of the group:
    /// the band's weights on the nodes' values (see [`NodeWeights`]).
    pub node_weights: Vec<Vec<Vec<NodeWeights>>>,
    /// Per group (empty where the optics has no band nodes), per column: S·π at each band node,
    /// side by side so the per-pixel f = Rrs/(1 − S·π·Rrs) runs over contiguous values.
    pub node_s_pi: Vec<Vec<Vec<f64>>>,
}

/// A band's weights on per-pixel spectra known only at band nodes.
///
/// The pixel's f(λ) = Rrs/(1 − S·π·Rrs) and Rrs(λ) are taken as linear between neighbouring
/// nodes (constant beyond the first and last), f(λ) ≈ Σₙ φₙ(λ)·fₙ with hat functions φₙ, so the
/// band integrals of the module docs become sums over nodes with weights computed once per
/// column on the full grid:
///
/// L_b = L_path,b + G_b + Σₙ Cₙ·fₙ,  Cₙ = Σ_λ w_b T_up Ed φₙ / Σ_λ w_b;  Rrs_b = Σₙ Dₙ·Rrsₙ,  Dₙ = Σ_λ w_b T_up Ed φₙ / Σ_λ w_b T_up Ed.
///
/// The atmosphere, the solar spectrum and the response keep their full-grid detail; only the
/// water's smooth spectrum is interpolated (its error is measured in the cost table:
/// `shoal bench --accuracy`).
#[derive(Debug, Clone, Default)]
pub struct NodeWeights {
    /// First node the weights apply to.
    pub first: usize,
    /// Cₙ from node `first` on, W m⁻² sr⁻¹ nm⁻¹ per unit f (sr⁻¹).
    pub radiance: Vec<f64>,
    /// Dₙ from node `first` on (they sum to 1).
    pub truth: Vec<f64>,
}

/// Per grid index of a group: the nodes either side and the weight of the upper one (linear in
/// wavelength; constant beyond the end nodes).
fn node_brackets(wavelengths_nm: &[f64], nodes: &[usize]) -> Vec<(usize, usize, f64)> {
    let last = nodes.len() - 1;
    (0..wavelengths_nm.len())
        .map(|i| {
            let n1 = nodes.partition_point(|&v| v <= i);
            if n1 == 0 {
                (0, 0, 0.0)
            } else if n1 > last {
                (last, last, 0.0)
            } else {
                let (a, b) = (wavelengths_nm[nodes[n1 - 1]], wavelengths_nm[nodes[n1]]);
                (n1 - 1, n1, (wavelengths_nm[i] - a) / (b - a))
            }
        })
        .collect()
}

impl BandAtmosphere {
    /// Build the band-effective atmosphere of every output column.
    pub fn new(optics: &[SceneOptics], viewing: &Viewing, response: &Response) -> Result<Self, InstrumentError> {
        let nb = response.n_bands();
        let nc = viewing.columns();
        let mut out = Self {
            n_bands: nb,
            paths: Vec::new(),
            l_path: vec![0.0; nc * nb],
            glint: vec![0.0; nc * nb],
            ed: vec![0.0; nc * nb],
            t_ed: vec![0.0; nc * nb],
            spherical_albedo: vec![0.0; nc * nb],
            truth_weights: Vec::new(),
            node_weights: Vec::new(),
            node_s_pi: Vec::new(),
        };
        for (gi, group) in response.groups.iter().enumerate() {
            let paths: Vec<PathSpectrum> = viewing.looks[gi]
                .par_iter()
                .map(|look| optics[gi].path_spectrum(&look.geometry))
                .collect::<Result<_, _>>()
                .map_err(|e| InstrumentError::Scene(e.into()))?;
            let mut truth = Vec::with_capacity(nc);
            let nodes = optics[gi].band_nodes();
            let brackets = nodes.map(|n| node_brackets(group.grid.wavelengths_nm(), n));
            let mut node_weights = Vec::new();
            for (c, path) in paths.iter().enumerate() {
                let mut column_nodes = Vec::new();
                let j = viewing.detector_index[c];
                let mut per_band = Vec::with_capacity(group.bands.len());
                for (k, &b) in group.bands.iter().enumerate() {
                    let (first, w) = response.weights(gi, k, j);
                    let span = first..first + w.len();
                    let m = band_means(path, first, w);
                    let (te, te_sum, total) = (&m.te, m.te_sum, m.total);
                    let i = c * nb + b;
                    out.l_path[i] = m.l_path;
                    out.glint[i] = m.glint;
                    out.ed[i] = m.ed;
                    out.t_ed[i] = m.t_ed;
                    out.spherical_albedo[i] = m.spherical_albedo;
                    let tw = if te_sum > 0.0 {
                        te.iter().map(|v| v / te_sum).collect()
                    } else {
                        vec![1.0 / w.len() as f64; w.len()]
                    };
                    if let Some(brackets) = &brackets {
                        column_nodes.push(band_node_weights(&brackets[span.clone()], te, total, &tw));
                    }
                    per_band.push((first, tw));
                }
                truth.push(per_band);
                if brackets.is_some() {
                    node_weights.push(column_nodes);
                }
            }
            let node_s_pi = match nodes {
                Some(nodes) => paths
                    .iter()
                    .map(|p| nodes.iter().map(|&i| p.spherical_albedo[i] * std::f64::consts::PI).collect())
                    .collect(),
                None => Vec::new(),
            };
            out.paths.push(paths);
            out.truth_weights.push(truth);
            out.node_weights.push(node_weights);
            out.node_s_pi.push(node_s_pi);
        }
        Ok(out)
    }

    /// Whether group `g` samples the water at band nodes.
    #[must_use]
    pub fn has_nodes(&self, g: usize) -> bool {
        self.node_weights.get(g).is_some_and(|w| !w.is_empty())
    }

    /// Index of (column, band) in the per-column arrays.
    #[must_use]
    pub fn at(&self, column: usize, band: usize) -> usize {
        column * self.n_bands + band
    }
}

/// [`NodeWeights`] of one band: `brackets` of its grid points, `te` = w·T_up·Ed on them,
/// `total` = Σw, `truth` the truth's weights on them (te/Σte).
fn band_node_weights(brackets: &[(usize, usize, f64)], te: &[f64], total: f64, truth: &[f64]) -> NodeWeights {
    let lo = brackets.iter().map(|b| b.0).min().unwrap_or(0);
    let hi = brackets.iter().map(|b| b.1).max().unwrap_or(0);
    let mut out = NodeWeights { first: lo, radiance: vec![0.0; hi + 1 - lo], truth: vec![0.0; hi + 1 - lo] };
    for ((&(n0, n1, t), &v), &tw) in brackets.iter().zip(te).zip(truth) {
        out.radiance[n0 - lo] += v * (1.0 - t) / total;
        out.radiance[n1 - lo] += v * t / total;
        out.truth[n0 - lo] += tw * (1.0 - t);
        out.truth[n1 - lo] += tw * t;
    }
    out
}

/// One band's photon-weighted means over a column's atmosphere (module docs of [`super::sample`]):
/// `w` the band's weights on the grid from index `first`.
#[derive(Debug, Clone, PartialEq)]
pub struct BandMeans {
    /// Σw, photons J⁻¹.
    pub total: f64,
    /// L_path,b = Σ w L_path / Σw.
    pub l_path: f64,
    /// G_b = Σ w L_glint / Σw.
    pub glint: f64,
    /// Ed,b = Σ w Ed / Σw.
    pub ed: f64,
    /// (T·Ed)_b = Σ w T_up Ed / Σw.
    pub t_ed: f64,
    /// S_b = Σ w T_up Ed S / Σ w T_up Ed (0 where T·Ed vanishes).
    pub spherical_albedo: f64,
    /// w·T_up·Ed on the band's grid points.
    pub te: Vec<f64>,
    /// Σ w·T_up·Ed.
    pub te_sum: f64,
}

/// [`BandMeans`] of the band with weights `w` from grid index `first`, through `path`.
#[must_use]
pub fn band_means(path: &PathSpectrum, first: usize, w: &[f64]) -> BandMeans {
    let te: Vec<f64> = te_of(path, first, w).collect();
    let te_sum: f64 = te.iter().sum();
    let [l_path, t_ed, spherical_albedo, glint] = means_with(path, first, w, (te.iter().copied(), te_sum));
    let total: f64 = w.iter().sum();
    let ed = w.iter().zip(&path.ed[first..first + w.len()]).map(|(a, x)| a * x).sum::<f64>() / total;
    BandMeans { total, l_path, glint, ed, t_ed, spherical_albedo, te, te_sum }
}

/// [L_path, T·Ed, S, glint] of [`band_means`], the same values, without holding w·T_up·Ed: what
/// the band terms read.
#[must_use]
fn band_terms_only(path: &PathSpectrum, first: usize, w: &[f64]) -> [f64; 4] {
    means_with(path, first, w, (te_of(path, first, w), te_of(path, first, w).sum()))
}

/// w·T_up·Ed on the band's grid points.
fn te_of<'a>(path: &'a PathSpectrum, first: usize, w: &'a [f64]) -> impl Iterator<Item = f64> + 'a {
    let span = first..first + w.len();
    w.iter().zip(&path.t_up[span.clone()]).zip(&path.ed[span]).map(|((a, t), e)| a * t * e)
}

/// [L_path, T·Ed, S, glint] from w·T_up·Ed (`te`) and its sum.
fn means_with(
    path: &PathSpectrum,
    first: usize,
    w: &[f64],
    (te, te_sum): (impl Iterator<Item = f64>, f64),
) -> [f64; 4] {
    let span = first..first + w.len();
    let total: f64 = w.iter().sum();
    let dot = |v: &[f64]| w.iter().zip(&v[span.clone()]).map(|(a, x)| a * x).sum::<f64>() / total;
    let spherical_albedo = if te_sum > 0.0 {
        te.zip(&path.spherical_albedo[span.clone()]).map(|(a, s)| a * s).sum::<f64>() / te_sum
    } else {
        0.0
    };
    [dot(&path.l_path), te_sum / total, spherical_albedo, dot(&path.glint)]
}

/// Band-effective atmosphere of every column: index column·bands + band.
#[derive(Debug, Clone, Default)]
pub struct BandTerms {
    /// Path radiance, W m⁻² sr⁻¹ nm⁻¹.
    pub l_path: Vec<f64>,
    /// (T_up·Ed), W m⁻² nm⁻¹.
    pub t_ed: Vec<f64>,
    /// Spherical albedo.
    pub spherical_albedo: Vec<f64>,
    /// Sun-glint radiance, W m⁻² sr⁻¹ nm⁻¹ (zeros unless the scene has glint).
    pub glint: Vec<f64>,
}

impl BandTerms {
    /// The glint added to the path radiance: the terms a processor that takes the expected glint
    /// away inverts with (L − L_path − G).
    pub fn fold_glint_into_path(&mut self) {
        for (l, g) in self.l_path.iter_mut().zip(&self.glint) {
            *l += g;
        }
    }
}

/// The band terms of every column for one atmosphere (the photon-weighted means of
/// `BandAtmosphere`, without what only the forward model needs): [`band_terms_of_each`] of one.
pub fn band_terms(
    optics: &[SceneOptics],
    viewing: &Viewing,
    response: &Response,
    across_track: Option<usize>,
) -> Result<BandTerms, InstrumentError> {
    let paths: Vec<&PathOptics> = optics.iter().map(SceneOptics::path).collect();
    let mut terms = band_terms_of_each(&[paths], viewing, response, across_track)?;
    Ok(terms.remove(0))
}

/// The band terms of every column for each of several atmospheres (`atmospheres[a][g]`: the
/// atmosphere `a` bound to geometry group `g`'s grid). Where every detector has the same
/// response (no smile) and the columns are a swath (`across_track`: `Some(k)`), the terms are
/// computed at k columns spread over it ([`TERM_COLUMNS`], or [`term_columns`] of a preview) and
/// interpolated linearly between them: they follow the view zenith, which changes smoothly
/// across track. Otherwise (a user's spectra, one per column, `shoal correct`: `None`) every
/// column is computed. The gas factors of a column's geometry are
/// computed once for all the atmospheres that share the first's gases (the image-based
/// correction's family: one atmosphere per aerosol model and AOT node, the same gases).
pub fn band_terms_of_each(
    atmospheres: &[Vec<&PathOptics>],
    viewing: &Viewing,
    response: &Response,
    across_track: Option<usize>,
) -> Result<Vec<BandTerms>, InstrumentError> {
    let Some(first_atmosphere) = atmospheres.first() else { return Ok(Vec::new()) };
    let nb = response.n_bands();
    let nc = viewing.columns();
    let one_response = response.smile_class.iter().all(|&c| c == response.smile_class.first().copied().unwrap_or(0));
    let sampled: Vec<usize> = match across_track {
        Some(k) if one_response && k >= 2 && nc > k => {
            let mut v: Vec<usize> = (0..k).map(|i| i * (nc - 1) / (k - 1)).collect();
            v.dedup();
            v
        }
        _ => (0..nc).collect(),
    };
    let empty = |n: usize| BandTerms {
        l_path: vec![0.0; n * nb],
        t_ed: vec![0.0; n * nb],
        spherical_albedo: vec![0.0; n * nb],
        glint: vec![0.0; n * nb],
    };
    let mut at_sampled: Vec<BandTerms> = atmospheres.iter().map(|_| empty(sampled.len())).collect();
    let scene_error = |e: crate::atmosphere::AtmosphereError| InstrumentError::Scene(e.into());
    for (gi, group) in response.groups.iter().enumerate() {
        // The grid points some band of the group weighs (in any smile class): all the terms read.
        let mut needed = vec![false; group.grid.len()];
        for (first, w) in group.weights.iter().flatten() {
            for m in needed.iter_mut().skip(*first).take(w.len()) {
                *m = true;
            }
        }
        // Per sampled column, per atmosphere: (entry, [L_path, T·Ed, S, glint]) of each band.
        type Means = Vec<(usize, [f64; 4])>;
        let columns: Vec<Vec<Means>> = sampled
            .par_iter()
            .enumerate()
            .map(|(si, &c)| {
                let look = &viewing.looks[gi][c];
                let j = viewing.detector_index[c];
                let legs = first_atmosphere[gi].gas_legs(&look.geometry).map_err(scene_error)?;
                atmospheres
                    .iter()
                    .map(|paths| {
                        let path = paths[gi].band_path_with(&look.geometry, &legs, &needed).map_err(scene_error)?;
                        Ok(group
                            .bands
                            .iter()
                            .enumerate()
                            .map(|(k, &b)| {
                                let (first, w) = response.weights(gi, k, j);
                                (si * nb + b, band_terms_only(&path, first, w))
                            })
                            .collect())
                    })
                    .collect::<Result<Vec<Means>, InstrumentError>>()
            })
            .collect::<Result<_, InstrumentError>>()?;
        for per_atmosphere in columns {
            for (terms, means) in at_sampled.iter_mut().zip(per_atmosphere) {
                for (i, [l, te, s, g]) in means {
                    (terms.l_path[i], terms.t_ed[i], terms.spherical_albedo[i], terms.glint[i]) = (l, te, s, g);
                }
            }
        }
    }
    if sampled.len() == nc {
        return Ok(at_sampled);
    }
    Ok(at_sampled.iter().map(|at| across_columns(at, &sampled, nc, nb)).collect())
}

/// The terms at every one of `nc` columns, linear between the `sampled` columns' `at`.
fn across_columns(at: &BandTerms, sampled: &[usize], nc: usize, nb: usize) -> BandTerms {
    let mut out = BandTerms {
        l_path: vec![0.0; nc * nb],
        t_ed: vec![0.0; nc * nb],
        spherical_albedo: vec![0.0; nc * nb],
        glint: vec![0.0; nc * nb],
    };
    for c in 0..nc {
        let s1 = sampled.partition_point(|&x| x < c).clamp(1, sampled.len() - 1);
        let (a, z) = (sampled[s1 - 1], sampled[s1]);
        let t = if z > a { (c - a) as f64 / (z - a) as f64 } else { 0.0 };
        for b in 0..nb {
            let (i0, i1, o) = ((s1 - 1) * nb + b, s1 * nb + b, c * nb + b);
            out.l_path[o] = at.l_path[i0] + t * (at.l_path[i1] - at.l_path[i0]);
            out.t_ed[o] = at.t_ed[i0] + t * (at.t_ed[i1] - at.t_ed[i0]);
            out.spherical_albedo[o] = at.spherical_albedo[i0] + t * (at.spherical_albedo[i1] - at.spherical_albedo[i0]);
            out.glint[o] = at.glint[i0] + t * (at.glint[i1] - at.glint[i0]);
        }
    }
    out
}

/// Columns at which [`band_terms`] computes the family's terms when it may interpolate. Against
/// every column's terms, Sentinel-3 OLCI's 7.8° half swath leaves 4·10⁻⁵ of the path radiance
/// (test `term_columns`).
pub const TERM_COLUMNS: usize = 33;

/// Columns of the family's terms at a preview that keeps every `decimation`-th detector: 33 at
/// full resolution, 17 at 1/2, 9 from 1/4 on. A preview reruns the family whenever the swath's
/// geometry changes (a pixel pitch or focal length slider); 9 columns leave 4·10⁻⁴ of OLCI's path
/// radiance (about 0.4 % of its blue Rrs over dark water) and 9·10⁻⁶ of the CubeSat's.
#[must_use]
pub fn term_columns(decimation: usize) -> usize {
    ((TERM_COLUMNS - 1) / decimation.max(1) + 1).max(9)
}
