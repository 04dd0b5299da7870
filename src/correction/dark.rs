//! Dark-spectrum fitting (Vanhellemont & Ruddick 2018; Vanhellemont 2019), as ACOLITE runs it:
//! one atmosphere per tile (or per scene), from the darkest pixels of every band, assuming that
//! in at least one band some pixels of the tile reflect (almost) nothing.
//!
//! Per tile, with the aerosol's part of the signal A(λ) = L1(λ) − L_path(λ; τ = 0) (each pixel
//! against its own column's Rayleigh path radiance; ACOLITE fits the full path reflectance of
//! the scene-average geometry instead):
//!
//! 1. the **dark spectrum**: per band, the intercept at rank 0 of a straight line fitted to the
//!    `pixels` darkest values against their rank (ACOLITE's `intercept` option), over every
//!    pixel of the tile, land included, with valid Level-0;
//! 2. per model m and band λ, the AOT τ_m(λ) whose aerosol signal at the tile's centre column
//!    equals the dark value (quadratic in the signal over the three nearest nodes, as the
//!    band-pair fit does); the model's AOT is the lowest over the bands, τ_m = min τ_m(λ);
//! 3. the model whose signal at τ_m is closest to the dark spectrum (root-mean-square
//!    difference in reflectance, ρ = π·A/(T·Ed) of the Rayleigh atmosphere) at the two bands of
//!    lowest τ_m(λ) (ACOLITE's `min_drmsd`);
//! 4. every pixel of the tile corrected with that model at τ_m, through its own column's
//!    terms (the exact inversion of [`super::correct_exact`]).
//!
//! Bands are fitted only inside `wave_range_nm` and where the two-way gas transmittance at the
//! tile's centre reaches `min_gas_transmittance` (ACOLITE's `min_tgas_aot`, which is what keeps
//! the water-vapour and O₂ bands out). A tile with less than 10 % of its pixels valid in a
//! fitted band takes the scene's fit (ACOLITE's `dsf_min_tile_cover`); pixels left out for high
//! glint count neither as valid nor in the tile's size, so a scene mostly in glint is fitted
//! from the part outside it.
//!
//! With tiles and `smooth_tiles` (ACOLITE's defaults, `tiles_interp` in its `shared` module),
//! the scene takes the tiles' most common model; that model's tile AOTs are smoothed with a
//! 3 × 3 box (edges mirrored, as scipy's `uniform_filter`) and interpolated bilinearly between
//! tile centres to every pixel (constant beyond the outermost centres), and each pixel is
//! corrected at its own AOT. ACOLITE interpolates the tiles' atmospheric terms instead of their
//! AOT; the terms are smooth in AOT, so the two differ at second order. Without smoothing,
//! tiles are blocks, each with its own model and AOT.
//!
//! ## References
//! - Vanhellemont, Q. & Ruddick, K. (2018) Atmospheric correction of metre-scale optical
//!   satellite data for inland and coastal water applications. Remote Sens. Environ. 216,
//!   586–597.
//! - Vanhellemont, Q. (2019) Adaptation of the dark spectrum fitting atmospheric correction for
//!   aquatic applications of the Landsat and Sentinel-2 archives. Remote Sens. Environ. 225,
//!   175–192.

use rayon::prelude::*;

use super::family::AerosolFamily;
use super::image::{Mixture, PackedFamily, invalid, locate, weighted};
use super::{CorrectionError, slice};
use crate::atmosphere::AerosolType;
use crate::calibration::Level1;
use crate::control::RunControl;
use crate::spectral::BandSet;
use serde::{Deserialize, Serialize};

/// Settings of dark-spectrum fitting (this module).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DarkSpectrumSettings {
    /// Tile side, pixels; 0: one atmosphere for the whole scene (ACOLITE's `fixed`, as
    /// published).
    pub tile_px: usize,
    /// Darkest pixels per band whose linear fit against rank gives the dark value at rank 0
    /// (ACOLITE's `intercept` option; 200 in its MSI, OLI and OLCI settings).
    pub pixels: usize,
    /// Bands whose two-way gas transmittance is below this are not fitted (ACOLITE's
    /// `min_tgas_aot`, 0.85).
    pub min_gas_transmittance: f64,
    /// Bands fitted, nm (ACOLITE's `dsf_wave_range`).
    pub wave_range_nm: [f64; 2],
    /// With tiles: one model for the scene (the tiles' most common), its tile AOTs smoothed
    /// with a 3 × 3 box and interpolated between tile centres to every pixel (ACOLITE's
    /// defaults `dsf_aot_most_common_model`, `dsf_tile_smoothing`, kernel 3, linear). Off:
    /// blocks, each tile its own model and AOT.
    pub smooth_tiles: bool,
}

impl Default for DarkSpectrumSettings {
    fn default() -> Self {
        Self {
            tile_px: 0,
            pixels: 200,
            min_gas_transmittance: 0.85,
            wave_range_nm: [400.0, 2500.0],
            smooth_tiles: true,
        }
    }
}

/// What dark-spectrum fitting found in one tile.
#[derive(Debug, Clone, PartialEq)]
pub struct TileFit {
    /// Rows of the tile, [first, end).
    pub rows: [usize; 2],
    /// Columns of the tile, [first, end).
    pub cols: [usize; 2],
    /// Index of the chosen model in the family.
    pub model_index: usize,
    /// The chosen model.
    pub model: AerosolType,
    /// AOT(550) of the fit.
    pub aot550: f64,
    /// The two bands of lowest AOT (the second equal to the first with one fitted band).
    pub bands: [usize; 2],
    /// Root-mean-square difference of the model's and the dark reflectance at those bands.
    pub rmsd_reflectance: f64,
    /// The dark spectrum's aerosol signal per band, W m⁻² sr⁻¹ nm⁻¹ (NaN where not fitted).
    pub dark: Vec<f64>,
    /// The tile took the scene's fit (too few valid pixels of its own).
    pub from_scene: bool,
    /// Every model's AOT(550) in this tile (the lowest over the bands), in the family's order.
    pub aot550_models: Vec<f64>,
}

impl TileFit {
    /// The tile's atmosphere as table entries of the family (`packed`: its terms).
    pub(super) fn mixture<'f>(&self, family: &AerosolFamily, packed: &'f PackedFamily) -> Mixture<'f> {
        let nodes = locate(&family.aot550, self.aot550);
        let m = self.model_index;
        Mixture {
            entries: nodes.iter().filter(|n| n.1 != 0.0).map(|&(k, w)| (&packed.terms[m][k][..], w)).collect(),
            aot550: self.aot550,
            angstrom: family.angstrom[m],
            outside: false,
            passes: 1,
            epsilon: f64::NAN,
            long_signal: f64::NAN,
        }
    }
}

/// Least-squares straight line through (rank, value) of the `n` smallest of `values`; its value
/// at rank 0 (ACOLITE's `intercept` dark spectrum). `values` is reordered.
fn intercept(values: &mut [f64], n: usize) -> f64 {
    let n = n.min(values.len());
    if n == 0 {
        return f64::NAN;
    }
    if n < values.len() {
        values.select_nth_unstable_by(n - 1, f64::total_cmp);
    }
    let darkest = &mut values[..n];
    darkest.sort_by(f64::total_cmp);
    if n == 1 {
        return darkest[0];
    }
    let mean_x = (n - 1) as f64 / 2.0;
    let mean_y = darkest.iter().sum::<f64>() / n as f64;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, y) in darkest.iter().enumerate() {
        let dx = i as f64 - mean_x;
        sxy += dx * (y - mean_y);
        sxx += dx * dx;
    }
    mean_y - sxy / sxx * mean_x
}

/// The tiles of a rows × cols image for a tile side (0: one tile), as near equal as may be.
fn tiles(rows: usize, cols: usize, side: usize) -> Vec<([usize; 2], [usize; 2])> {
    let split = |n: usize| -> Vec<[usize; 2]> {
        let k = if side == 0 { 1 } else { n.div_ceil(side).max(1) };
        (0..k).map(|i| [i * n / k, (i + 1) * n / k]).collect()
    };
    let (rs, cs) = (split(rows), split(cols));
    rs.iter().flat_map(|&r| cs.iter().map(move |&c| (r, c))).collect()
}

/// The tile of every pixel, row-major.
#[must_use]
pub fn tile_index(fits: &[TileFit], rows: usize, cols: usize) -> Vec<usize> {
    let mut index = vec![0; rows * cols];
    for (t, f) in fits.iter().enumerate() {
        for r in f.rows[0]..f.rows[1] {
            index[r * cols + f.cols[0]..r * cols + f.cols[1]].fill(t);
        }
    }
    index
}

/// Fit every tile of `level1`; see the module docs.
pub fn fit_tiles(
    level1: &Level1,
    family: &AerosolFamily,
    settings: &DarkSpectrumSettings,
    bands: &BandSet,
    control: &RunControl,
    skip_column: &(dyn Fn(usize) -> bool + Sync),
) -> Result<Vec<TileFit>, CorrectionError> {
    let (rows, cols, nb) = level1.radiance.dim();
    let centres = bands.centres_nm();
    let rayleigh = &family.terms[0][0];
    let fitted: Vec<usize> = (0..nb)
        .filter(|&b| {
            let c = centres[b];
            let gas = family.gas_two_way[(cols / 2) * nb + b];
            c >= settings.wave_range_nm[0] && c <= settings.wave_range_nm[1] && gas >= settings.min_gas_transmittance
        })
        .collect();
    if fitted.is_empty() {
        return Err(invalid(
            "correction.image.dark",
            format!(
                "no band within {:?} nm has a two-way gas transmittance of at least {}",
                settings.wave_range_nm, settings.min_gas_transmittance
            ),
        ));
    }
    let (l1, flags) = (slice(&level1.radiance)?, slice(&level1.flags)?);
    let fit = |rr: [usize; 2], cc: [usize; 2]| -> Option<TileFit> {
        // The pixels the processor looks at: those left out for high glint do not count, in the
        // 10 % below as in the dark spectrum (a tile wholly in glint falls back to the scene's fit).
        let kept: Vec<usize> = (cc[0]..cc[1]).filter(|&c| !skip_column(c)).collect();
        let area = (rr[1] - rr[0]) * kept.len();
        // The terms the dark spectrum is compared with: the tile's centre column, or the column
        // nearest it outside the glint (whose pixels alone make the dark spectrum).
        let mid = (cc[0] + cc[1]) / 2;
        let centre = *kept.iter().min_by_key(|&&c| c.abs_diff(mid))?;
        let mut dark = vec![f64::NAN; nb];
        let mut values = Vec::with_capacity(area);
        for &b in &fitted {
            values.clear();
            for r in rr[0]..rr[1] {
                for &c in &kept {
                    let i = (r * cols + c) * nb + b;
                    let v = f64::from(l1[i]);
                    if flags[i] == 0 && v.is_finite() && v > 0.0 {
                        values.push(v - rayleigh.l_path[c * nb + b]);
                    }
                }
            }
            if values.len() * 10 < area {
                return None;
            }
            dark[b] = intercept(&mut values, settings.pixels);
        }
        // Each model's AOT (lowest over the bands) and its distance to the dark spectrum.
        let at = |b: usize| centre * nb + b;
        let signal = |m: usize, b: usize, k: usize| family.terms[m][k].l_path[at(b)] - rayleigh.l_path[at(b)];
        let mut best: Option<(f64, usize, f64, [usize; 2])> = None;
        let mut aot550_models = Vec::with_capacity(family.models.len());
        for m in 0..family.models.len() {
            let mut per_band: Vec<(f64, usize)> = fitted
                .iter()
                .map(|&b| {
                    let curve: Vec<f64> = (0..family.aot550.len()).map(|k| signal(m, b, k)).collect();
                    (weighted(&locate(&curve, dark[b]), |k| family.aot550[k]).max(0.0), b)
                })
                .collect();
            per_band.sort_by(|a, b| a.0.total_cmp(&b.0));
            let tau = per_band[0].0;
            aot550_models.push(tau);
            let two = [per_band[0].1, per_band.get(1).map_or(per_band[0].1, |p| p.1)];
            let nodes = locate(&family.aot550, tau);
            let rho = |b: usize, x: f64| std::f64::consts::PI * x / rayleigh.t_ed[at(b)];
            let rmsd = (two
                .iter()
                .map(|&b| (rho(b, weighted(&nodes, |k| signal(m, b, k))) - rho(b, dark[b])).powi(2))
                .sum::<f64>()
                / 2.0)
                .sqrt();
            if best.is_none_or(|x| rmsd < x.0) {
                best = Some((rmsd, m, tau, two));
            }
        }
        let (rmsd, m, tau, two) = best?;
        Some(TileFit {
            rows: rr,
            cols: cc,
            model_index: m,
            model: family.models[m],
            aot550: tau,
            bands: two,
            rmsd_reflectance: rmsd,
            dark,
            from_scene: false,
            aot550_models,
        })
    };
    let scene = fit([0, rows], [0, cols]).ok_or_else(|| {
        invalid(
            "correction.image.dark",
            "fewer than 10 % of the scene's pixels outside high glint have valid Level-1 in a fitted band".into(),
        )
    })?;
    if settings.tile_px == 0 || (settings.tile_px >= rows && settings.tile_px >= cols) {
        return Ok(vec![scene]);
    }
    let out: Vec<Option<TileFit>> = tiles(rows, cols, settings.tile_px)
        .into_par_iter()
        .map(|(rr, cc)| if control.cancelled() { None } else { fit(rr, cc) })
        .collect();
    if control.cancelled() {
        return Err(CorrectionError::Cancelled);
    }
    Ok(out
        .into_iter()
        .zip(tiles(rows, cols, settings.tile_px))
        .map(|(f, (rr, cc))| f.unwrap_or_else(|| TileFit { rows: rr, cols: cc, from_scene: true, ..scene.clone() }))
        .collect())
}

/// Tiles smoothed and interpolated to every pixel (see the module docs).
pub(super) struct Smoothed {
    /// The scene's model (the tiles' most common).
    pub model_index: usize,
    /// AOT(550) of every pixel, row-major.
    pub aot550: Vec<f64>,
}

impl Smoothed {
    /// Pixel `i`'s atmosphere as table entries of the family (`packed`: its terms).
    pub(super) fn fill<'f>(&self, family: &AerosolFamily, packed: &'f PackedFamily, i: usize, mix: &mut Mixture<'f>) {
        let (m, tau) = (self.model_index, self.aot550[i]);
        let nodes = locate(&family.aot550, tau);
        mix.entries.extend(nodes.iter().filter(|n| n.1 != 0.0).map(|&(k, w)| (&packed.terms[m][k][..], w)));
        (mix.aot550, mix.angstrom, mix.passes) = (tau, family.angstrom[m], 1);
    }
}

/// The tiles of `fits` smoothed and interpolated to a rows × cols image; `None` with one tile
/// or when smoothing is off.
pub(super) fn smoothed(
    fits: &[TileFit],
    settings: &DarkSpectrumSettings,
    rows: usize,
    cols: usize,
) -> Option<Smoothed> {
    if !settings.smooth_tiles || fits.len() < 2 {
        return None;
    }
    // The tile grid (fits are row-major over `tiles`).
    let mut row_edges: Vec<[usize; 2]> = fits.iter().map(|f| f.rows).collect();
    let mut col_edges: Vec<[usize; 2]> = fits.iter().map(|f| f.cols).collect();
    row_edges.sort_unstable();
    row_edges.dedup();
    col_edges.sort_unstable();
    col_edges.dedup();
    let (nr, nc) = (row_edges.len(), col_edges.len());
    if nr * nc != fits.len() {
        return None;
    }
    let n_models = fits[0].aot550_models.len();
    let mut votes = vec![0usize; n_models];
    for f in fits {
        votes[f.model_index] += 1;
    }
    // The most common model; a tie goes to the family's first.
    let model_index = (0..n_models).max_by_key(|&m| (votes[m], std::cmp::Reverse(m)))?;
    let grid: Vec<f64> = fits.iter().map(|f| f.aot550_models[model_index]).collect();
    // 3 × 3 box with mirrored edges (index −1 reads 0, n reads n − 1).
    let at = |r: isize, c: isize| {
        let r = r.clamp(0, nr as isize - 1) as usize;
        let c = c.clamp(0, nc as isize - 1) as usize;
        grid[r * nc + c]
    };
    let box3: Vec<f64> = (0..nr * nc)
        .map(|i| {
            let (r, c) = ((i / nc) as isize, (i % nc) as isize);
            let mut sum = 0.0;
            for dr in -1..=1 {
                for dc in -1..=1 {
                    sum += at(r + dr, c + dc);
                }
            }
            sum / 9.0
        })
        .collect();
    let centre = |e: &[usize; 2]| (e[0] + e[1]) as f64 / 2.0;
    let row_c: Vec<f64> = row_edges.iter().map(centre).collect();
    let col_c: Vec<f64> = col_edges.iter().map(centre).collect();
    // Bracketing centres and the weight of the upper one, constant beyond the ends.
    let bracket = |centres: &[f64], x: f64| -> (usize, usize, f64) {
        let k = centres.partition_point(|&v| v <= x);
        if k == 0 {
            (0, 0, 0.0)
        } else if k == centres.len() {
            (k - 1, k - 1, 0.0)
        } else {
            (k - 1, k, (x - centres[k - 1]) / (centres[k] - centres[k - 1]))
        }
    };
    let mut aot550 = vec![0.0; rows * cols];
    for r in 0..rows {
        let (r0, r1, fr) = bracket(&row_c, r as f64 + 0.5);
        for c in 0..cols {
            let (c0, c1, fc) = bracket(&col_c, c as f64 + 0.5);
            let v = |rr: usize, cc: usize| box3[rr * nc + cc];
            aot550[r * cols + c] =
                (1.0 - fr) * ((1.0 - fc) * v(r0, c0) + fc * v(r0, c1)) + fr * ((1.0 - fc) * v(r1, c0) + fc * v(r1, c1));
        }
    }
    Some(Smoothed { model_index, aot550 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intercept_of_a_line_is_its_start() {
        let mut v: Vec<f64> = (0..500).rev().map(|i| 2.0 + 0.01 * f64::from(i)).collect();
        assert!((intercept(&mut v, 200) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn tiles_cover_the_image_once() {
        let t = tiles(10, 7, 4);
        assert_eq!(t.len(), 3 * 2);
        let area: usize = t.iter().map(|(r, c)| (r[1] - r[0]) * (c[1] - c[0])).sum();
        assert_eq!(area, 70);
        assert_eq!(tiles(10, 7, 0), vec![([0, 10], [0, 7])]);
    }

    fn fit(rows: [usize; 2], cols: [usize; 2], model_index: usize, aot: [f64; 2]) -> TileFit {
        TileFit {
            rows,
            cols,
            model_index,
            model: AerosolType::Maritime,
            aot550: aot[model_index],
            bands: [0, 0],
            rmsd_reflectance: 0.0,
            dark: Vec::new(),
            from_scene: false,
            aot550_models: aot.to_vec(),
        }
    }

    #[test]
    fn smoothing_takes_the_common_model_and_keeps_a_gradient_linear_inside() {
        // 4 × 4 tiles of 10 px; model 1 in most tiles; its AOT rises by 0.01 per tile column.
        let fits: Vec<TileFit> = tiles(40, 40, 10)
            .into_iter()
            .enumerate()
            .map(|(i, (r, c))| {
                let m = usize::from(i % 5 != 0);
                fit(r, c, m, [0.5, 0.1 + 0.01 * (c[0] / 10) as f64])
            })
            .collect();
        let settings = DarkSpectrumSettings { tile_px: 10, ..DarkSpectrumSettings::default() };
        let s = smoothed(&fits, &settings, 40, 40).unwrap();
        assert_eq!(s.model_index, 1);
        // Between the inner tile centres (pixel centres 15 and 25) the box keeps the gradient
        // (0.11 and 0.12 there), and the interpolation is linear: 0.001 per pixel.
        let v = |r: usize, c: usize| s.aot550[r * 40 + c];
        assert!((v(20, 24) - v(20, 15) - 0.009).abs() < 1e-12, "{} {}", v(20, 15), v(20, 24));
        assert!((v(20, 19) - 0.1145).abs() < 1e-12, "{}", v(20, 19));
        // Rows do not matter; the edges hold the mirrored box's value.
        assert!((v(3, 19) - v(37, 19)).abs() < 1e-12);
        assert!((v(20, 0) - (0.1 + (2.0 * 0.0 + 0.01) / 3.0)).abs() < 1e-12, "{}", v(20, 0));
        let off = DarkSpectrumSettings { smooth_tiles: false, ..settings };
        assert!(smoothed(&fits, &off, 40, 40).is_none());
    }
}
