//! The image-based correction: the aerosol from the instrument's own long bands, as a real
//! processor finds it, knowing nothing of the scene's true atmosphere.
//!
//! **Two-band model selection** (Gordon & Wang 1994; Ahmad et al. 2010, as NASA's l2gen runs
//! it; Wang & Shi 2007 with a SWIR pair). A family of aerosol models, each tabulated at a few
//! optical depths: for every model m and AOT(550) node τ_k, Shoal's own atmosphere (WMO Mie
//! optics, successive orders) gives the band-effective path radiance L_path(m, τ_k), (T_up·Ed)
//! and spherical albedo S of every column, through each band's response — the same radiative
//! transfer as the forward model, so the family is exact where the scene's aerosol is a member.
//! Per pixel, with A(λ) = L1(λ) − L_path(λ; τ = 0) the aerosol's part of the signal and the
//! water taken as black at the pair's bands (their Rrs left in A is the black-pixel error):
//!
//! 1. for each model, τ_m such that A_m(λ_l; τ_m) = A(λ_l) at the long band (quadratic in the
//!    signal over the three nearest nodes; beyond the last node, the last segment extended;
//!    below zero, τ_m = 0);
//! 2. each model's ε_m = A_m(λ_s; τ_m)/A(λ_l), against the measured ε = A(λ_s)/A(λ_l);
//! 3. the two models whose ε_m bracket ε, weighted w = (ε − ε₁)/(ε₂ − ε₁) (the nearest model
//!    alone outside the family's range, and the pixel flagged);
//! 4. every band's L_path, T·Ed and S as that mixture of the two models at their τ_m, then the
//!    exact inversion Rrs = y/(1 + S·π·y), y = (L1 − L_path)/(T·Ed).
//!
//! Noise and calibration error at the pair's bands enter every band's Rrs through A: this is
//! how a design's NIR/SWIR SNR reaches the products (Wang & Gordon 2018).
//!
//! ## References
//! - Gordon, H. R. & Wang, M. (1994) Appl. Opt. 33, 443–452.
//! - Ahmad, Z. et al. (2010) New aerosol models for the retrieval of aerosol optical thickness
//!   and normalized water-leaving radiances from the SeaWiFS and MODIS sensors over coastal
//!   regions and open oceans. Appl. Opt. 49, 5545–5560.
//! - Wang, M. & Shi, W. (2007) The NIR-SWIR combined atmospheric correction approach for MODIS
//!   ocean color data processing. Opt. Express 15, 15722–15733.
//! - Wang, M. & Gordon, H. R. (2018) Sensor performance requirements for atmospheric correction
//!   of satellite ocean color remote sensing. Opt. Express 26, 7390–7403.

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use super::family::{AerosolFamily, BandTerms};
use super::{CorrectionError, Reflectance, RrsFlags, assemble, flag_for, slice};
use crate::atmosphere::AerosolType;
use crate::calibration::Level1;
use crate::control::RunControl;
use crate::parse::FieldError;

/// Settings of the image-based correction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImageCorrection {
    /// Centres of the short and long band of the aerosol pair, nm: the instrument's bands
    /// nearest them are used (l2gen's 748/869 for MODIS, 779/865 for OLCI; 1240/2130 or
    /// 1610/2200 as a SWIR pair).
    pub pair_nm: [f64; 2],
    /// The aerosol models of the family.
    pub models: Vec<AerosolType>,
    /// AOT(550) nodes of the family's tables (0 is always added).
    pub aot_nodes: Vec<f64>,
}

impl Default for ImageCorrection {
    fn default() -> Self {
        Self {
            pair_nm: [779.0, 865.0],
            models: vec![AerosolType::Maritime, AerosolType::Continental, AerosolType::Urban],
            aot_nodes: vec![0.05, 0.1, 0.2, 0.4, 0.8],
        }
    }
}

pub(super) fn invalid(field: &str, message: String) -> CorrectionError {
    CorrectionError::Invalid(FieldError { field: field.into(), message })
}

impl ImageCorrection {
    /// Check the settings against [`crate::ranges`].
    pub fn validate(&self) -> Result<(), CorrectionError> {
        let r = &crate::ranges::CORRECTION_PAIR_NM;
        for v in self.pair_nm {
            r.check(v).map_err(|m| invalid(r.path, m))?;
        }
        if self.pair_nm[0] >= self.pair_nm[1] {
            return Err(invalid(r.path, format!("{:?}: the short band first, then the long one", self.pair_nm)));
        }
        if self.models.is_empty() || self.models.contains(&AerosolType::None) {
            return Err(invalid(
                "correction.image.models",
                "one or more of maritime, continental, urban (none is the family's τ = 0)".into(),
            ));
        }
        let a = &crate::ranges::CORRECTION_AOT_NODE;
        for &v in &self.aot_nodes {
            a.check(v).map_err(|m| invalid(a.path, m))?;
        }
        if self.aot_nodes.is_empty() || self.aot_nodes.windows(2).any(|w| w[1] <= w[0]) {
            return Err(invalid(a.path, format!("{:?}: one or more nodes, increasing", self.aot_nodes)));
        }
        Ok(())
    }

    /// The instrument's bands nearest the pair's centres (short, long).
    pub fn pair(&self, centres_nm: &[f64]) -> Result<(usize, usize), CorrectionError> {
        let nearest = |target: f64| -> Result<usize, CorrectionError> {
            let (i, d) = centres_nm
                .iter()
                .enumerate()
                .map(|(i, c)| (i, (c - target).abs()))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .ok_or_else(|| invalid("correction.image.pair_nm", "the instrument has no bands".into()))?;
            if d > PAIR_TOLERANCE_NM {
                let have: Vec<String> = centres_nm.iter().map(|c| format!("{c:.0}")).collect();
                return Err(invalid(
                    "correction.image.pair_nm",
                    format!(
                        "no band within {PAIR_TOLERANCE_NM} nm of {target} nm (the instrument's centres: {} nm)",
                        have.join(", ")
                    ),
                ));
            }
            Ok(i)
        };
        let (s, l) = (nearest(self.pair_nm[0])?, nearest(self.pair_nm[1])?);
        if s == l {
            return Err(invalid("correction.image.pair_nm", format!("both ends pick the same band ({s})")));
        }
        Ok((s, l))
    }
}

/// Relative margin beyond the family's ε range before a pixel counts as outside it.
const EDGE: f64 = 0.005;

/// How far a pair's centre may be from the band it picks, nm.
pub const PAIR_TOLERANCE_NM: f64 = 30.0;

/// What the correction found in each pixel.
#[derive(Debug, Clone)]
pub struct AerosolRetrieval {
    /// AOT(550), NaN where not retrieved (land, invalid pair bands).
    pub aot550: Array2<f32>,
    /// Ångström exponent 443–865 nm of the mixture, NaN where not retrieved.
    pub angstrom: Array2<f32>,
    /// Pixels whose measured ε lay outside the family's range (the nearest model used).
    pub outside_family: usize,
}

/// Where the measured long-band aerosol signal lies in a model's table: up to three nodes and
/// their weights, so that any tabulated quantity at the model's τ is Σ wᵢ·vᵢ. `a_long[k]` is the
/// model's aerosol signal at the long band at node k (increasing with τ). Inside the table the
/// weights are the quadratic Lagrange basis in the signal itself over the three nearest nodes
/// (path radiance is close to, but not, linear in τ: a linear interpolation between AOT nodes
/// 0.1 and 0.2 left 3 % at 400 nm and 10 % at 665 nm in Rrs); beyond the last node the last
/// segment is extended; a signal at or below zero is τ = 0.
fn locate(a_long: &[f64], measured: f64) -> [(usize, f64); 3] {
    let n = a_long.len();
    if measured <= 0.0 || n < 2 {
        return [(0, 1.0), (0, 0.0), (0, 0.0)];
    }
    if measured >= a_long[n - 1] || n == 2 {
        let (k0, k1) = (n - 2, n - 1);
        let span = a_long[k1] - a_long[k0];
        let f = if span > 0.0 { (measured - a_long[k0]) / span } else { 0.0 };
        return [(k0, 1.0 - f), (k1, f), (k1, 0.0)];
    }
    // The segment holding the signal, and its nearer neighbour as the third node.
    let k = (0..n - 1).find(|&k| measured <= a_long[k + 1]).unwrap_or(n - 2);
    let first = if k == 0 {
        0
    } else if k + 2 >= n {
        n - 3
    } else if measured - a_long[k] < a_long[k + 1] - measured {
        k - 1
    } else {
        k
    };
    let x = [a_long[first], a_long[first + 1], a_long[first + 2]];
    let basis = |i: usize| {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        (measured - x[j]) * (measured - x[l]) / ((x[i] - x[j]) * (x[i] - x[l]))
    };
    if (x[1] - x[0]) * (x[2] - x[1]) * (x[2] - x[0]) <= 0.0 {
        // Nodes not strictly increasing (a degenerate table): linear in the segment.
        let span = a_long[k + 1] - a_long[k];
        let f = if span > 0.0 { (measured - a_long[k]) / span } else { 0.0 };
        return [(k, 1.0 - f), (k + 1, f), (k + 1, 0.0)];
    }
    [(first, basis(0)), (first + 1, basis(1)), (first + 2, basis(2))]
}

/// Σ wᵢ·vᵢ of `value(k)` over the located nodes.
fn weighted(nodes: &[(usize, f64); 3], value: impl Fn(usize) -> f64) -> f64 {
    nodes.iter().map(|&(k, w)| if w == 0.0 { 0.0 } else { w * value(k) }).sum()
}

/// Correct `level1` with the family: see the module docs.
pub fn correct_image(
    level1: &Level1,
    family: &AerosolFamily,
    pair: (usize, usize),
    land: &Array2<u8>,
    control: &RunControl,
) -> Result<(Reflectance, AerosolRetrieval), CorrectionError> {
    let (rows, cols, nb) = level1.radiance.dim();
    if nb != family.n_bands || family.terms.is_empty() {
        return Err(invalid("correction.image", format!("the family has {} bands, Level-1 {nb}", family.n_bands)));
    }
    let (l1, l0_flags, land_s) = (slice(&level1.radiance)?, slice(&level1.flags)?, slice(land)?);
    let (s_band, l_band) = pair;
    let nm = family.models.len();
    let stride = cols * nb;
    let per_row = control.map_rows(rows, |at| {
        let r = at.index();
        let base = r * stride;
        let (mut rrs_row, mut flag_row) = (vec![0.0f32; stride], vec![0u8; stride]);
        let (mut aot_row, mut alpha_row) = (vec![f32::NAN; cols], vec![f32::NAN; cols]);
        let mut outside = 0usize;
        let mut located = vec![[(0usize, 1.0f64), (0, 0.0), (0, 0.0)]; nm];
        let mut eps = vec![0.0; nm];
        let mut a_long = vec![0.0; family.aot550.len()];
        let mut order: Vec<usize> = Vec::with_capacity(nm);
        let mut entries: Vec<(&BandTerms, f64)> = Vec::with_capacity(6);
        for c in 0..cols {
            at.column(c);
            let px = &l1[base + c * nb..base + (c + 1) * nb];
            let fl = &l0_flags[base + c * nb..base + (c + 1) * nb];
            let is_land = land_s[r * cols + c] != 0;
            let i = |b: usize| c * nb + b;
            let rayleigh = &family.terms[0][0];
            let a_l = f64::from(px[l_band]) - rayleigh.l_path[i(l_band)];
            let a_s = f64::from(px[s_band]) - rayleigh.l_path[i(s_band)];
            let usable = !is_land && fl[l_band] == 0 && fl[s_band] == 0;
            // Each model's τ and ε for this pixel.
            for m in 0..nm {
                for (k, t) in family.terms[m].iter().enumerate() {
                    a_long[k] = t.l_path[i(l_band)] - rayleigh.l_path[i(l_band)];
                }
                located[m] = locate(&a_long, a_l);
                let short =
                    weighted(&located[m], |k| family.terms[m][k].l_path[i(s_band)] - rayleigh.l_path[i(s_band)]);
                eps[m] = if a_l > 0.0 { short / a_l } else { 0.0 };
            }
            let measured = if a_l > 0.0 { a_s / a_l } else { 0.0 };
            // The bracketing pair (by ε), or the nearest model outside the family's range.
            order.clear();
            order.extend(0..nm);
            order.sort_by(|&a, &b| eps[a].total_cmp(&eps[b]));
            let (m1, m2, w, out) = match order.windows(2).find(|p| eps[p[0]] <= measured && measured <= eps[p[1]]) {
                Some(p) => {
                    let d = eps[p[1]] - eps[p[0]];
                    (p[0], p[1], if d > 0.0 { (measured - eps[p[0]]) / d } else { 0.0 }, false)
                }
                None if nm == 1 || measured < eps[order[0]] => (order[0], order[0], 0.0, nm > 1),
                None => (order[nm - 1], order[nm - 1], 0.0, true),
            };
            // Counted as outside only beyond half a per cent of the family's range: a member's
            // own pixels sit on its edge and the water's NIR signal moves them across it.
            let (lo, hi) = (eps[order[0]], eps[order[nm - 1]]);
            if out && usable && a_l > 0.0 && (measured < lo * (1.0 - EDGE) || measured > hi * (1.0 + EDGE)) {
                outside += 1;
            }
            // The pixel's atmosphere as at most six weighted table entries (two models, three
            // nodes each), then every band from them.
            entries.clear();
            for (m, share) in [(m1, 1.0 - w), (m2, w)] {
                for &(k, weight) in &located[m] {
                    if share * weight != 0.0 {
                        entries.push((&family.terms[m][k], share * weight));
                    }
                }
            }
            for b in 0..nb {
                let (mut lp, mut te, mut s) = (0.0, 0.0, 0.0);
                for &(t, weight) in &entries {
                    lp += weight * t.l_path[i(b)];
                    te += weight * t.t_ed[i(b)];
                    s += weight * t.spherical_albedo[i(b)];
                }
                let y = (f64::from(px[b]) - lp) / te;
                let value = y / (1.0 + s * std::f64::consts::PI * y);
                let f = flag_for(fl[b], is_land || !usable, value);
                flag_row[c * nb + b] = f;
                rrs_row[c * nb + b] = if f & RrsFlags::INVALID != 0 { 0.0 } else { value as f32 };
            }
            if usable {
                let tau = |m: usize| weighted(&located[m], |k| family.aot550[k]).max(0.0);
                aot_row[c] = ((1.0 - w) * tau(m1) + w * tau(m2)) as f32;
                alpha_row[c] = ((1.0 - w) * family.angstrom[m1] + w * family.angstrom[m2]) as f32;
            }
        }
        Ok::<_, CorrectionError>((rrs_row, flag_row, aot_row, alpha_row, outside))
    })?;
    let (mut rrs, mut flags) = (Vec::with_capacity(rows * stride), Vec::with_capacity(rows * stride));
    let (mut aot, mut alpha, mut outside) = (Vec::with_capacity(rows * cols), Vec::with_capacity(rows * cols), 0);
    for (a, b, c, d, e) in per_row {
        rrs.extend_from_slice(&a);
        flags.extend_from_slice(&b);
        aot.extend_from_slice(&c);
        alpha.extend_from_slice(&d);
        outside += e;
    }
    let shape = (rows, cols);
    let bad = |e: ndarray::ShapeError| invalid("cube", e.to_string());
    let retrieval = AerosolRetrieval {
        aot550: Array2::from_shape_vec(shape, aot).map_err(bad)?,
        angstrom: Array2::from_shape_vec(shape, alpha).map_err(bad)?,
        outside_family: outside,
    };
    Ok((assemble(rows, cols, nb, rrs, flags)?, retrieval))
}
